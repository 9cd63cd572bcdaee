// Edge detectors of SMAA and MLAA other than plain luma, and the matte/stencil composite.
// Thesis ch. 9 (§9.3, Listing 9.1: depth edges, threshold) and ch. 10 (§10.4.1: colour edges, local contrast
// adaptation eq. 10.1); predicated thresholding as documented in SMAA.hlsl (SMAA_PREDICATION_*). Written for rtbake
// from those descriptions; the CPU mirror is `runtime/aa/edges_cpu.rs` (keep every arithmetic step in sync).
// The host module is `runtime/aa/edges.rs`.
//
// Outputs as the passes' own `fs_edges`: R = edge on the left boundary, G = edge on the top boundary, 0 or 1.
// Pixel positions are integer texel coordinates, loads clamp to the edge.
//
// Each detector is a per-pixel function (`*_px`) called by a fragment entry point (`fs_*`, the fragment shape of
// three_pass.rs) and a compute one (`cs_*`, its compute shape: two pixels per thread into the edges texture of
// edge_store.wgsl, which also zeroes the weights and lists the edge pixels), so both shapes write the same bytes.
// The compute shape masks in its blending pass (`cs_blend_masked` of three_pass.wgsl, the same selection as
// `mask_px`).
//
// Prepended by the host module: vs_fullscreen (../fullscreen.wgsl), LUMA (srgb.wgsl); appended: edge_store.wgsl.

struct Params {
    // (1/width, 1/height, width, height)
    rt: vec4<f32>,
    // x: luma/colour threshold T, y: local contrast adaptation factor (0: none), z: metric (0 luma, 1 colour)
    cfg: vec4<f32>,
    // x: predication threshold, y: predication scale, z: predication strength, w: depth threshold
    pred: vec4<f32>,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var color_tex: texture_2d<f32>;
@group(0) @binding(2) var depth_tex: texture_2d<f32>;
@group(0) @binding(3) var aa_tex: texture_2d<f32>;
@group(0) @binding(4) var mask_tex: texture_2d<f32>;

fn clamp_px(p: vec2<i32>) -> vec2<i32> {
    return clamp(p, vec2<i32>(0, 0), vec2<i32>(P.rt.zw) - vec2<i32>(1, 1));
}

fn color_at(p: vec2<i32>) -> vec3<f32> {
    return textureLoad(color_tex, clamp_px(p), 0).rgb;
}

fn depth_at(p: vec2<i32>) -> f32 {
    return textureLoad(depth_tex, clamp_px(p), 0).r;
}

// Contrast of two sRGB-encoded colours: |luma difference| (eq. 9.2 weights) or the largest channel difference.
fn contrast(a: vec3<f32>, b: vec3<f32>) -> f32 {
    if (P.cfg.z > 0.5) {
        let t = abs(a - b);
        return max(max(t.r, t.g), t.b);
    }
    return abs(dot(a, LUMA) - dot(b, LUMA));
}

// Luma or colour edges against `threshold` (left, top), then eq. 10.1's local contrast adaptation when
// P.cfg.y > 0: an edge survives if P.cfg.y times its contrast reaches the largest of the neighbouring edges'.
fn color_edges(p: vec2<i32>, threshold: vec2<f32>) -> vec2<f32> {
    let c = color_at(p);
    let c_left = color_at(p + vec2<i32>(-1, 0));
    let c_top = color_at(p + vec2<i32>(0, -1));
    let delta = vec2<f32>(contrast(c, c_left), contrast(c, c_top));
    var edges = step(threshold, delta);
    if (edges.x + edges.y == 0.0 || P.cfg.y <= 0.0) {
        return edges;
    }
    let c_right = color_at(p + vec2<i32>(1, 0));
    let c_bottom = color_at(p + vec2<i32>(0, 1));
    var max_delta = max(delta, vec2<f32>(contrast(c, c_right), contrast(c, c_bottom)));
    let c_leftleft = color_at(p + vec2<i32>(-2, 0));
    let c_toptop = color_at(p + vec2<i32>(0, -2));
    max_delta = max(max_delta, vec2<f32>(contrast(c_left, c_leftleft), contrast(c_top, c_toptop)));
    let final_delta = max(max_delta.x, max_delta.y);
    return edges * step(vec2<f32>(final_delta), P.cfg.y * delta);
}

fn color_edges_px(p: vec2<i32>) -> vec2<f32> {
    return color_edges(p, vec2<f32>(P.cfg.x));
}

// Predicated thresholding: T' = scale · T · (1 − strength · [depth edge]) per boundary.
fn color_edges_predicated_px(p: vec2<i32>) -> vec2<f32> {
    let d = depth_at(p);
    let d_delta = abs(vec2<f32>(d - depth_at(p + vec2<i32>(-1, 0)), d - depth_at(p + vec2<i32>(0, -1))));
    let pred_edges = step(vec2<f32>(P.pred.x), d_delta);
    let threshold = P.pred.y * P.cfg.x * (vec2<f32>(1.0) - P.pred.z * pred_edges);
    return color_edges(p, threshold);
}

// Listing 9.1 (MLAA's depth variant; also SMAA's depth detector): |D − D_left|, |D − D_top| against the threshold.
fn depth_edges_px(p: vec2<i32>) -> vec2<f32> {
    let d = depth_at(p);
    let delta = abs(vec2<f32>(d - depth_at(p + vec2<i32>(-1, 0)), d - depth_at(p + vec2<i32>(0, -1))));
    return step(vec2<f32>(P.pred.w), delta);
}

// Matte / stencil: inside the mask (≥ 128/255) the antialiased pixel, outside the input pixel unchanged.
fn mask_px(p: vec2<i32>) -> vec4<f32> {
    if (textureLoad(mask_tex, p, 0).r >= 0.5) {
        return textureLoad(aa_tex, p, 0);
    }
    return textureLoad(color_tex, p, 0);
}

fn frag_px(pos: vec4<f32>) -> vec2<i32> {
    return vec2<i32>(floor(pos.xy));
}

@fragment
fn fs_edges_color(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(color_edges_px(frag_px(pos)), 0.0, 0.0);
}

@fragment
fn fs_edges_color_predicated(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(color_edges_predicated_px(frag_px(pos)), 0.0, 0.0);
}

@fragment
fn fs_edges_depth(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(depth_edges_px(frag_px(pos)), 0.0, 0.0);
}

@fragment
fn fs_mask(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return mask_px(frag_px(pos));
}

@compute @workgroup_size(8, 8)
fn cs_edges_color(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = edge_pair_origin(id.xy);
    emit_edge_pair(id.xy, li, color_edges_px(p), color_edges_px(p + vec2<i32>(1, 0)));
}

@compute @workgroup_size(8, 8)
fn cs_edges_color_predicated(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = edge_pair_origin(id.xy);
    emit_edge_pair(id.xy, li, color_edges_predicated_px(p), color_edges_predicated_px(p + vec2<i32>(1, 0)));
}

@compute @workgroup_size(8, 8)
fn cs_edges_depth(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = edge_pair_origin(id.xy);
    emit_edge_pair(id.xy, li, depth_edges_px(p), depth_edges_px(p + vec2<i32>(1, 0)));
}
