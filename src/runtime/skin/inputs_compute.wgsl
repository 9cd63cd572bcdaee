// The skin-inputs pass as a compute pass (`SkinInputs::record_compute`, through `compute_chain::record`): the maps
// and normals as Rgba32Float rows, the rig, LUT and T(s) table as the half floats their textures hold, and the
// two outputs written as Rgba16Float rows (albedo + H, then T(s)·E + E; rows padded) straight into the buffer the
// frame's next pass reads. The arithmetic is inputs_common.wgsl's `skin_inputs`, as the fragment pass's.
//
// Prepended by the host module: inputs_common.wgsl.

@group(0) @binding(0) var<uniform> P: Params;
// (Cm, H0, thickness mm, unused) per pixel, rows of P.rows.x.
@group(0) @binding(1) var<storage, read_write> maps: array<vec4<f32>>;
// (normal, unused) per pixel, rows of P.rows.x.
@group(0) @binding(2) var<storage, read_write> normals: array<vec4<f32>>;
// Rig layers, one after the other: (scale, bias) as two halves per u32.
@group(0) @binding(3) var<storage, read_write> rig: array<u32>;
// The albedo LUT and the T(s) table: Rgba16Float texels, two u32 each.
@group(0) @binding(4) var<storage, read_write> albedo_lut: array<u32>;
@group(0) @binding(5) var<storage, read_write> t_table: array<u32>;
// The two output images, Rgba16Float, rows of P.rows.y u32.
@group(0) @binding(6) var<storage, read_write> out: array<u32>;

fn maps_at(p: vec2<i32>) -> vec4<f32> {
    return maps[u32(p.y) * u32(P.rows.x) + u32(p.x)];
}

fn normal_at(p: vec2<i32>) -> vec3<f32> {
    return normals[u32(p.y) * u32(P.rows.x) + u32(p.x)].xyz;
}

fn rig_texel(layer: i32, x: i32, y: i32) -> vec2<f32> {
    let w = u32(P.rows.z);
    return unpack2x16float(rig[(u32(layer) * u32(P.rows.w) + u32(y)) * w + u32(x)]);
}

fn lut_texel(x: i32, y: i32) -> vec3<f32> {
    let j = 2u * (u32(y) * u32(P.lut.x) + u32(x));
    return vec3<f32>(unpack2x16float(albedo_lut[j]), unpack2x16float(albedo_lut[j + 1u]).x);
}

fn t_texel(i: i32) -> vec3<f32> {
    let j = 2u * u32(i);
    return vec3<f32>(unpack2x16float(t_table[j]), unpack2x16float(t_table[j + 1u]).x);
}

fn store16(k: u32, p: vec2<u32>, v: vec4<f32>) {
    let j = (k * u32(P.rt.w) + p.y) * u32(P.rows.y) + 2u * p.x;
    out[j] = pack2x16float(v.xy);
    out[j + 1u] = pack2x16float(v.zw);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= u32(P.rt.z) || id.y >= u32(P.rt.w)) {
        return;
    }
    let s = skin_inputs(vec2<i32>(id.xy));
    store16(0u, id.xy, s.albedo);
    store16(1u, id.xy, s.transmitted);
}
