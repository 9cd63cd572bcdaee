// Skin shading inputs (thesis ch. 7 and 5): per pixel,
//   hemoglobin  H = Σ wᵢ·biasᵢ(uv) + H0 · Σ wᵢ·scaleᵢ(uv)                       (eq. 7.6; scale/bias sampled bilinearly)
//   albedo      = skinLUT(u = cbrt(Cm/0.5), v = cbrt(H/0.32))                   (eq. 7.7, normalised, node-inclusive)
//   transmitted = T(s) · E,  E = max(0.3 + dot(−N, L), 0)                       (eq. 5.12/5.13; T node-inclusive on [0, s_max])
// Node-inclusive lookup of t ∈ [0, 1] in an n-texel axis: texel coordinate t·(n−1) + 0.5.
// CPU twin: `runtime/skin/inputs_cpu.rs`.
//
// Prepended by the host module: vs_fullscreen (../fullscreen.wgsl).

struct Params {
    // (1/width, 1/height, width, height)
    rt: vec4<f32>,
    // xyz: L (unit, from the surface towards the light)
    light: vec4<f32>,
    // x: LUT width (melanin), y: LUT height (hemoglobin), z: T(s) texels, w: s_max (mm)
    lut: vec4<f32>,
    // x: number of rig targets
    cfg: vec4<f32>,
    weights: array<vec4<f32>, 2>,
}

@group(0) @binding(0) var<uniform> P: Params;
// (Cm, H0, thickness mm, unused), rgba32float, loaded.
@group(0) @binding(1) var maps_tex: texture_2d<f32>;
// Normal (xyz), rgba32float, loaded.
@group(0) @binding(2) var normal_tex: texture_2d<f32>;
// Rig layers: (scale, bias) rg16float.
@group(0) @binding(3) var rig_tex: texture_2d_array<f32>;
@group(0) @binding(4) var albedo_lut: texture_2d<f32>;
@group(0) @binding(5) var t_table: texture_2d<f32>;
@group(0) @binding(6) var lin: sampler;

struct Out {
    // rgb: albedo, a: hemoglobin H
    @location(0) albedo: vec4<f32>,
    // rgb: T(s)·E, a: E
    @location(1) transmitted: vec4<f32>,
}

fn node(t: f32, n: f32) -> f32 {
    return (clamp(t, 0.0, 1.0) * (n - 1.0) + 0.5) / n;
}

@fragment
fn fs_skin(@builtin(position) pos: vec4<f32>) -> Out {
    let p = vec2<i32>(floor(pos.xy));
    let uv = pos.xy * P.rt.xy;
    let m = textureLoad(maps_tex, p, 0);
    let n = textureLoad(normal_tex, p, 0).xyz;
    var sum_bias = 0.0;
    var sum_scale = 0.0;
    let k = i32(P.cfg.x);
    for (var i = 0; i < k; i = i + 1) {
        let w = P.weights[i / 4][i % 4];
        let sb = textureSampleLevel(rig_tex, lin, uv, i, 0.0).rg;
        sum_scale = sum_scale + w * sb.x;
        sum_bias = sum_bias + w * sb.y;
    }
    let h = sum_bias + m.y * sum_scale; // eq. 7.6
    let u = pow(clamp(m.x / 0.5, 0.0, 1.0), 1.0 / 3.0);
    let v = pow(clamp(h / 0.32, 0.0, 1.0), 1.0 / 3.0);
    let albedo = textureSampleLevel(albedo_lut, lin, vec2<f32>(node(u, P.lut.x), node(v, P.lut.y)), 0.0).rgb;
    let e = max(0.3 + dot(-n, P.light.xyz), 0.0); // eq. 5.13
    let t = textureSampleLevel(t_table, lin, vec2<f32>(node(m.z / P.lut.w, P.lut.z), 0.5), 0.0).rgb;
    return Out(vec4<f32>(albedo, h), vec4<f32>(t * e, e));
}
