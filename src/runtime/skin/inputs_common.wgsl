// Skin shading inputs (thesis ch. 7 and 5): per pixel,
//   hemoglobin  H = Σ wᵢ·biasᵢ(uv) + H0 · Σ wᵢ·scaleᵢ(uv)                       (eq. 7.6; scale/bias bilinear)
//   albedo      = skinLUT(u = cbrt(Cm/0.5), v = cbrt(H/0.32))                   (eq. 7.7, normalised, node-inclusive)
//   transmitted = T(s) · E,  E = max(0.3 + dot(−N, L), 0)                       (eq. 5.12/5.13; T node-inclusive on [0, s_max])
// Node-inclusive lookup of t ∈ [0, 1] in an n-texel axis: texel coordinate t·(n−1) + 0.5. Fetches are bilinear,
// clamp-to-edge, in f32 arithmetic (texel centres at (i + ½)/size), as the CPU twin `runtime/skin/inputs_cpu.rs`.
//
// The arithmetic shared by the fragment pass (inputs.wgsl) and the compute pass (inputs_compute.wgsl): each
// module that appends this one defines where the texels come from,
//   maps_at(p) -> vec4 (Cm, H0, thickness mm, 0), normal_at(p) -> vec3,
//   rig_texel(layer, x, y) -> vec2 (scale, bias), lut_texel(x, y) -> vec3, t_texel(i) -> vec3,
// the former two at pixel p, the others at clamped texel indices.

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
    // compute pass: x vec4 per padded row of the maps and normals, y u32 per padded row of an output image;
    // both: z, w the rig maps' width and height
    rows: vec4<f32>,
}

// Albedo (rgb) and hemoglobin H (a); T(s)·E (rgb) and E (a).
struct SkinTexels {
    albedo: vec4<f32>,
    transmitted: vec4<f32>,
}

fn node(t: f32, n: f32) -> f32 {
    return (clamp(t, 0.0, 1.0) * (n - 1.0) + 0.5) / n;
}

// Lower texel index, the other one and the weight of the upper along one axis of n texels at normalised t.
fn taps(t: f32, n: f32) -> vec3<f32> {
    let x = t * n - 0.5;
    let x0 = floor(x);
    return vec3<f32>(clamp(x0, 0.0, n - 1.0), clamp(x0 + 1.0, 0.0, n - 1.0), x - x0);
}

fn rig_bilinear(layer: i32, uv: vec2<f32>) -> vec2<f32> {
    let tx = taps(uv.x, P.rows.z);
    let ty = taps(uv.y, P.rows.w);
    let a = rig_texel(layer, i32(tx.x), i32(ty.x));
    let b = rig_texel(layer, i32(tx.y), i32(ty.x));
    let c = rig_texel(layer, i32(tx.x), i32(ty.y));
    let d = rig_texel(layer, i32(tx.y), i32(ty.y));
    let top = a + (b - a) * tx.z;
    let bottom = c + (d - c) * tx.z;
    return top + (bottom - top) * ty.z;
}

fn lut_bilinear(uv: vec2<f32>) -> vec3<f32> {
    let tx = taps(uv.x, P.lut.x);
    let ty = taps(uv.y, P.lut.y);
    let a = lut_texel(i32(tx.x), i32(ty.x));
    let b = lut_texel(i32(tx.y), i32(ty.x));
    let c = lut_texel(i32(tx.x), i32(ty.y));
    let d = lut_texel(i32(tx.y), i32(ty.y));
    let top = a + (b - a) * tx.z;
    let bottom = c + (d - c) * tx.z;
    return top + (bottom - top) * ty.z;
}

// T(s) along its one row (the vertical weight of a one-texel axis is a blend of a row with itself).
fn t_linear(t: f32) -> vec3<f32> {
    let tx = taps(t, P.lut.z);
    let a = t_texel(i32(tx.x));
    let b = t_texel(i32(tx.y));
    return a + (b - a) * tx.z;
}

// The skin inputs of pixel p (x right, y down).
fn skin_inputs(p: vec2<i32>) -> SkinTexels {
    let uv = (vec2<f32>(p) + 0.5) * P.rt.xy;
    let m = maps_at(p);
    let n = normal_at(p);
    var sum_bias = 0.0;
    var sum_scale = 0.0;
    let k = i32(P.cfg.x);
    for (var i = 0; i < k; i = i + 1) {
        let w = P.weights[i / 4][i % 4];
        let sb = rig_bilinear(i, uv);
        sum_scale = sum_scale + w * sb.x;
        sum_bias = sum_bias + w * sb.y;
    }
    let h = sum_bias + m.y * sum_scale; // eq. 7.6
    let u = pow(clamp(m.x / 0.5, 0.0, 1.0), 1.0 / 3.0);
    let v = pow(clamp(h / 0.32, 0.0, 1.0), 1.0 / 3.0);
    let albedo = lut_bilinear(vec2<f32>(node(u, P.lut.x), node(v, P.lut.y)));
    let e = max(0.3 + dot(-n, P.light.xyz), 0.0); // eq. 5.13
    let t = t_linear(node(m.z / P.lut.w, P.lut.z));
    return SkinTexels(vec4<f32>(albedo, h), vec4<f32>(t * e, e));
}
