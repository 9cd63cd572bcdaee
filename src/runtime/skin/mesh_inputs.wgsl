// The rig's eq. 7.6 at the mesh's texture coordinates (runtime/mesh_skin_inputs.rs): per covered pixel
// H = g * (sum_i w_i * bias_i(uv) + H0(uv) * sum_i w_i * scale_i(uv)), every map read bilinearly (texel centres at
// (i + 0.5) / size, clamp to edge) in f32 arithmetic. CPU twin: runtime/cpu/mesh_skin_inputs.rs.

struct Params {
    // frame width, height, rig width, rig height
    size: vec4<f32>,
    // H0 width, height, targets, global scale g
    cfg: vec4<f32>,
    weights: array<vec4<f32>, 2>,
};

@group(0) @binding(0) var<uniform> p: Params;
// u, v, covered (0 or 1), 0 per pixel
@group(0) @binding(1) var<storage, read_write> uvc: array<vec4<f32>>;
// (scale, bias) per texel, target-major, rows top first
@group(0) @binding(2) var<storage, read_write> rig: array<vec2<f32>>;
@group(0) @binding(3) var<storage, read_write> h0: array<f32>;
@group(0) @binding(4) var<storage, read_write> hb: array<f32>;

// `Taps` and `taps` (bilinear texel indices and weights) come from bilinear_taps.wgsl, prepended.

fn rig_at(k: u32, t: Taps) -> vec2<f32> {
    let w = u32(p.size.z);
    let base = k * w * u32(p.size.w);
    let a = rig[base + t.i.z * w + t.i.x];
    let b = rig[base + t.i.z * w + t.i.y];
    let c = rig[base + t.i.w * w + t.i.x];
    let d = rig[base + t.i.w * w + t.i.y];
    let top = a + (b - a) * t.f.x;
    let bottom = c + (d - c) * t.f.x;
    return top + (bottom - top) * t.f.y;
}

fn h0_at(t: Taps) -> f32 {
    let w = u32(p.cfg.x);
    let a = h0[t.i.z * w + t.i.x];
    let b = h0[t.i.z * w + t.i.y];
    let c = h0[t.i.w * w + t.i.x];
    let d = h0[t.i.w * w + t.i.y];
    let top = a + (b - a) * t.f.x;
    let bottom = c + (d - c) * t.f.x;
    return top + (bottom - top) * t.f.y;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.x);
    if (id.x >= w || id.y >= u32(p.size.y)) {
        return;
    }
    let i = id.y * w + id.x;
    let c = uvc[i];
    if (c.z < 0.5) {
        hb[i] = 0.0;
        return;
    }
    let tr = taps(c.x, c.y, p.size.z, p.size.w);
    var scale = 0.0;
    var bias = 0.0;
    for (var k = 0u; k < u32(p.cfg.z); k = k + 1u) {
        let wk = p.weights[k / 4u][k % 4u];
        let sb = rig_at(k, tr);
        scale = scale + wk * sb.x;
        bias = bias + wk * sb.y;
    }
    let th = taps(c.x, c.y, p.cfg.x, p.cfg.y);
    hb[i] = p.cfg.w * (bias + h0_at(th) * scale); // eq. 7.6
}
