// SMAA S2x / T2x / 4x resolves (thesis ch. 10, §10.4.3–10.4.4; Jimenez et al., Eurographics 2012):
// - fs_average: the S2x resolve, the mean of the two per-sample SMAA outputs in linear light;
// - fs_resolve: the temporal resolve of T2x and 4x, eq. 10.6–10.7: the previous SMAA'd frame is reprojected to
//   p − v (nearest texel, v = velocity in pixels per frame) and blended with weight
//   w = 0.5 · max(0, 1 − K · sqrt(| ‖v_c‖ − ‖v_p‖ |)), c = (1 − w) · c_c + w · c_p,
//   with ‖v‖ in normalised screen units carried in the alpha channel as a = sqrt(5 ‖v‖) (so that SMAA, which blends
//   alpha like colour, propagates velocity to the antialiased pixels, as the thesis prescribes); or the plain 50/50
//   blend without reprojection.
// Written for rtbake from the thesis' equations; the CPU twin is `runtime/aa/modes_cpu.rs` (keep in sync).
// Each resolve is a per-pixel function (`average_px`, `resolve_px`) called by a fragment entry point (`fs_*`) and a
// compute one (`cs_*`, 8×8 workgroups into a storage texture): the two pass shapes of three_pass.rs, same bytes.
// Colour textures are Rgba8Unorm holding sRGB-encoded values; the velocity texture is Rg32Float (px/frame).
//
// Prepended by the host module: vs_fullscreen (../fullscreen.wgsl), srgb_to_linear and linear_to_srgb (srgb.wgsl).

struct Params {
    // (1/width, 1/height, width, height)
    rt: vec4<f32>,
    // x: K of eq. 10.6; y: 1 = plain 50/50 blend (no reprojection), 0 = velocity-weighted reprojection;
    // z: 1 when a previous frame exists (else the current frame passes through).
    resolve: vec4<f32>,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var a_tex: texture_2d<f32>;
@group(0) @binding(2) var b_tex: texture_2d<f32>;
@group(0) @binding(3) var velocity_tex: texture_2d<f32>;
@group(0) @binding(4) var out_tex: texture_storage_2d<rgba8unorm, write>;

fn lin(c: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(srgb_to_linear(c.rgb), c.a);
}

// Linear-light lerp of two sRGB-encoded colours (alpha linear), re-encoded.
fn blend(cur: vec4<f32>, prev: vec4<f32>, w: f32) -> vec4<f32> {
    let c = lin(cur) + (lin(prev) - lin(cur)) * w;
    return vec4<f32>(linear_to_srgb(c.rgb), c.a);
}

// The S2x resolve at pixel `p`.
fn average_px(p: vec2<i32>) -> vec4<f32> {
    return blend(textureLoad(a_tex, p, 0), textureLoad(b_tex, p, 0), 0.5);
}

// The temporal resolve at pixel `p` (whose centre is p + 0.5, the fragment position).
fn resolve_px(p: vec2<i32>) -> vec4<f32> {
    let cur = textureLoad(a_tex, p, 0);
    if (P.resolve.z < 0.5) {
        return cur;
    }
    if (P.resolve.y > 0.5) {
        return blend(cur, textureLoad(b_tex, p, 0), 0.5);
    }
    let v = textureLoad(velocity_tex, p, 0).xy;
    let size = vec2<i32>(P.rt.zw);
    let centre = vec2<f32>(p) + vec2<f32>(0.5, 0.5);
    let q = clamp(vec2<i32>(floor(centre - v)), vec2<i32>(0, 0), size - vec2<i32>(1, 1));
    let prev = textureLoad(b_tex, q, 0);
    let delta = abs(cur.a * cur.a - prev.a * prev.a) / 5.0;
    let w = 0.5 * clamp(1.0 - P.resolve.x * sqrt(delta), 0.0, 1.0);
    return blend(cur, prev, w);
}

@fragment
fn fs_average(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return average_px(vec2<i32>(floor(pos.xy)));
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return resolve_px(vec2<i32>(floor(pos.xy)));
}

@compute @workgroup_size(8, 8)
fn cs_average(@builtin(global_invocation_id) id: vec3<u32>) {
    if (all(id.xy < vec2<u32>(P.rt.zw))) {
        textureStore(out_tex, id.xy, average_px(vec2<i32>(id.xy)));
    }
}

@compute @workgroup_size(8, 8)
fn cs_resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if (all(id.xy < vec2<u32>(P.rt.zw))) {
        textureStore(out_tex, id.xy, resolve_px(vec2<i32>(id.xy)));
    }
}
