// The skin-inputs pass as a full-screen fragment pass (the per-pass path, `SkinInputs::run`): textures in, two
// Rgba16Float targets out; the arithmetic is inputs_common.wgsl's `skin_inputs`. CPU twin:
// `runtime/skin/inputs_cpu.rs`.
//
// Prepended by the host module: vs_fullscreen (../fullscreen.wgsl), inputs_common.wgsl.

@group(0) @binding(0) var<uniform> P: Params;
// (Cm, H0, thickness mm, unused), rgba32float, loaded.
@group(0) @binding(1) var maps_tex: texture_2d<f32>;
// Normal (xyz), rgba32float, loaded.
@group(0) @binding(2) var normal_tex: texture_2d<f32>;
// Rig layers: (scale, bias) rg16float.
@group(0) @binding(3) var rig_tex: texture_2d_array<f32>;
@group(0) @binding(4) var albedo_lut: texture_2d<f32>;
@group(0) @binding(5) var t_table: texture_2d<f32>;

fn maps_at(p: vec2<i32>) -> vec4<f32> {
    return textureLoad(maps_tex, p, 0);
}

fn normal_at(p: vec2<i32>) -> vec3<f32> {
    return textureLoad(normal_tex, p, 0).xyz;
}

fn rig_texel(layer: i32, x: i32, y: i32) -> vec2<f32> {
    return textureLoad(rig_tex, vec2<i32>(x, y), layer, 0).rg;
}

fn lut_texel(x: i32, y: i32) -> vec3<f32> {
    return textureLoad(albedo_lut, vec2<i32>(x, y), 0).rgb;
}

fn t_texel(i: i32) -> vec3<f32> {
    return textureLoad(t_table, vec2<i32>(i, 0), 0).rgb;
}

struct Out {
    // rgb: albedo, a: hemoglobin H
    @location(0) albedo: vec4<f32>,
    // rgb: T(s)·E, a: E
    @location(1) transmitted: vec4<f32>,
}

@fragment
fn fs_skin(@builtin(position) pos: vec4<f32>) -> Out {
    let s = skin_inputs(vec2<i32>(floor(pos.xy)));
    return Out(s.albedo, s.transmitted);
}
