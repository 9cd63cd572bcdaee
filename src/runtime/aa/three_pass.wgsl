// The three morphological antialiasing passes of SMAA (smaa.wgsl) and MLAA (mlaa.wgsl) as compute passes (edges
// and blending over 8×8-thread workgroups, the weights over a list of the edge pixels): the same per-pixel functions
// `edges_px`, `weights_px` and `blend_px` as the fragment entry points, so every arithmetic step is the fragment
// path's. Appended after smaa.wgsl or mlaa.wgsl by
// `runtime/aa/three_pass.rs`; the including shader declares `P` with `rt` = (1/width, 1/height, width, height).
//
// Why compute: on GPUs whose graphics pipeline reaches only part of the chip (NVIDIA H100/H200: two TPCs of the
// whole GPU run pixel shaders), a full-screen fragment pass runs on a few SMs, a compute pass on all of them.
//
// Edges: two pixels per thread into the edges texture of edge_store.wgsl (prepended with this file), which also
// zeroes the weights and lists the edge pixels for the weights pass.

@group(0) @binding(10) var color_out: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8)
fn cs_edges(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = edge_pair_origin(id.xy);
    emit_edge_pair(id.xy, li, edges_px(p), edges_px(p + vec2<i32>(1, 0)));
}

// Weights on the edge pixels the edges pass listed (edge_store.wgsl): one thread turns the count into the indirect
// dispatch, and `cs_weights_list` runs `weights_px` on the listed pixels, packed 64 to a workgroup, so no lane waits
// on a pixel without an edge.
@group(0) @binding(12) var<storage, read_write> weights_args: array<u32, 3>;

// Threads per workgroup of `cs_weights_list`, and the most workgroups one dispatch dimension takes.
const LIST_GROUP: u32 = 64u;
const MAX_GROUPS_X: u32 = 65535u;

@compute @workgroup_size(1)
fn cs_edge_args() {
    let groups = (atomicLoad(&edge_list.count) + LIST_GROUP - 1u) / LIST_GROUP;
    weights_args[0] = min(groups, MAX_GROUPS_X);
    weights_args[1] = (groups + MAX_GROUPS_X - 1u) / MAX_GROUPS_X;
    weights_args[2] = 1u;
}

@compute @workgroup_size(LIST_GROUP)
fn cs_weights_list(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let i = (group.y * groups.x + group.x) * LIST_GROUP + li;
    if (i >= atomicLoad(&edge_list.count)) {
        return;
    }
    let packed = edge_list.pixels[i];
    let p = vec2<u32>(packed & 0xffffu, packed >> 16u);
    textureStore(weights_out, p, weights_px(vec2<f32>(p) + vec2<f32>(0.5, 0.5)));
}

@compute @workgroup_size(8, 8)
fn cs_blend(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id.xy >= vec2<u32>(P.rt.zw))) {
        return;
    }
    textureStore(color_out, id.xy, blend_px(vec2<i32>(id.xy)));
}

// Blending and the matte / stencil in one pass (edges.wgsl's `mask_px` after `cs_blend`, without the blended image's
// round trip through memory): inside the mask (≥ 128/255) the blended pixel, outside the input pixel unchanged.
@group(0) @binding(13) var mask_tex: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn cs_blend_masked(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id.xy >= vec2<u32>(P.rt.zw))) {
        return;
    }
    let p = vec2<i32>(id.xy);
    var c = textureLoad(color_tex, p, 0);
    if (textureLoad(mask_tex, p, 0).r >= 0.5) {
        c = blend_px(p);
    }
    textureStore(color_out, id.xy, c);
}
