// The rig's eq. 7.6 at the mesh's texture coordinates (runtime/skin/mesh_inputs.rs): per covered pixel
// H = g * (sum_i w_i * bias_i(uv) + H0(uv) * sum_i w_i * scale_i(uv)), every map read bilinearly (texel centres at
// (i + 0.5) / size, clamp to edge) in f32 arithmetic. CPU twin: runtime/skin/mesh_inputs_cpu.rs.

struct Params {
    // frame width, height, rig width, rig height
    size: vec4<f32>,
    // H0 width, height, targets, global scale g
    cfg: vec4<f32>,
    weights: array<vec4<f32>, 2>,
    // per dispatch (compute_chain's stage arguments): `into_skin_maps`' row stride in texels, 0, 0, 0
    stage: vec4<u32>,
};

// (scale, bias) per texel, target-major, rows top first
@group(0) @binding(2) var<storage, read_write> rig: array<vec2<f32>>;
@group(0) @binding(3) var<storage, read_write> h0: array<f32>;
@group(0) @binding(4) var<storage, read_write> hb: array<f32>;
// Bound only where the frame's shading records this pass (`record_into_skin_maps`): the skin-inputs maps
// (Cm, H0, thickness mm, 0) per texel, rows of `p.stage.x` texels (a texture copy's padded rows).
@group(0) @binding(5) var<storage, read_write> skin_maps: array<vec4<f32>>;

// Prepended by the host module: `p` (binding 0, this `Params`), `uvc` and the entry point `main`, which calls
// `covered` and `uncovered` below per pixel (pixel_frame.wgsl); `Taps`, `taps`, `tap_index` and `bilerp*`
// (bilinear_taps.wgsl).

fn rig_at(k: u32, t: Taps) -> vec2<f32> {
    let w = u32(p.size.z);
    let base = k * w * u32(p.size.w);
    let q = tap_index(t, base, w);
    return bilerp2(t, rig[q.x], rig[q.y], rig[q.z], rig[q.w]);
}

fn h0_at(t: Taps) -> f32 {
    let q = tap_index(t, 0u, u32(p.cfg.x));
    return bilerp1(t, h0[q.x], h0[q.y], h0[q.z], h0[q.w]);
}

fn uncovered(i: u32) {
    hb[i] = 0.0;
}

fn covered(i: u32, uv: vec2<f32>) {
    let tr = taps(uv.x, uv.y, p.size.z, p.size.w);
    var scale = 0.0;
    var bias = 0.0;
    for (var k = 0u; k < u32(p.cfg.z); k = k + 1u) {
        let wk = p.weights[k / 4u][k % 4u];
        let sb = rig_at(k, tr);
        scale = scale + wk * sb.x;
        bias = bias + wk * sb.y;
    }
    let th = taps(uv.x, uv.y, p.cfg.x, p.cfg.y);
    hb[i] = p.cfg.w * (bias + h0_at(th) * scale); // eq. 7.6
}

// After `main`: H into the skin-inputs maps' hemoglobin channel, which the skin-inputs pass reads with a neutral rig.
@compute @workgroup_size(8, 8, 1)
fn into_skin_maps(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= u32(p.size.x) || id.y >= u32(p.size.y)) {
        return;
    }
    skin_maps[id.y * p.stage.x + id.x].y = hb[id.y * u32(p.size.x) + id.x];
}
