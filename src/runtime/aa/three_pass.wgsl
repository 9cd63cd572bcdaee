// The three morphological antialiasing passes of SMAA (smaa.wgsl) and MLAA (mlaa.wgsl) as compute passes (edges
// and blending over 8×8-thread workgroups, the weights over a list of the edge pixels): the same per-pixel functions
// `edges_px`, `weights_px` and `blend_px` as the fragment entry points, so every arithmetic step is the fragment
// path's. Appended after smaa.wgsl or mlaa.wgsl by
// `runtime/aa/three_pass.rs`; the including shader declares `P` with `rt` = (1/width, 1/height, width, height).
//
// Why compute: on GPUs whose graphics pipeline reaches only part of the chip (NVIDIA H100/H200: two TPCs of the
// whole GPU run pixel shaders), a full-screen fragment pass runs on a few SMs, a compute pass on all of them.
//
// Edges: `Rg8Unorm` is not a storage format WebGPU guarantees, so each thread detects the edges of two adjacent
// pixels and writes them as one u32 (bytes R0 G0 R1 G1, the texture's layout) into a buffer with rows of
// `edge_row_bytes` (256-byte aligned), which the host copies into the `Rg8Unorm` edges texture the weights pass
// filters. Edge values are exactly 0 or 1, so the bytes are those the fragment pass renders.

@group(0) @binding(8) var<storage, read_write> edge_rows: array<u32>;
@group(0) @binding(9) var weights_out: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(10) var color_out: texture_storage_2d<rgba8unorm, write>;

// Bytes per row of the edge buffer: 2 bytes per pixel, rounded up to the 256 bytes a buffer-to-texture copy needs
// (the host's `edge_row_bytes`).
fn edge_row_words() -> u32 {
    let w = u32(P.rt.z);
    return ((2u * w + 255u) / 256u) * 256u / 4u;
}

@compute @workgroup_size(8, 8)
fn cs_edges(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(P.rt.zw);
    let x0 = 2u * id.x;
    if (x0 >= size.x || id.y >= size.y) {
        return;
    }
    let e0 = edges_px(vec2<i32>(i32(x0), i32(id.y)));
    var e1 = vec2<f32>(0.0);
    if (x0 + 1u < size.x) {
        e1 = edges_px(vec2<i32>(i32(x0) + 1, i32(id.y)));
    }
    edge_rows[id.y * edge_row_words() + id.x] = pack4x8unorm(vec4<f32>(e0, e1));
}

// Weights on edge pixels only (the compute form of the stencil SMAA's weights pass runs under, thesis §9.3): a list
// pass writes zero weights everywhere and appends each edge pixel to `edge_list` (one global atomic per workgroup),
// one thread turns the count into the indirect dispatch, and `cs_weights_list` runs `weights_px` on the listed pixels,
// packed 64 to a workgroup. Pixels without an edge have zero weights in both shapes (`weights_px` returns 0 there).
struct EdgeList {
    count: atomic<u32>,
    // x | y << 16 of each edge pixel, in no particular order (each pixel writes only its own weights).
    pixels: array<u32>,
}

@group(0) @binding(11) var<storage, read_write> edge_list: EdgeList;
@group(0) @binding(12) var<storage, read_write> weights_args: array<u32, 3>;

// Threads per workgroup of `cs_weights_list`, and the most workgroups one dispatch dimension takes.
const LIST_GROUP: u32 = 64u;
const MAX_GROUPS_X: u32 = 65535u;

var<workgroup> group_count: atomic<u32>;
var<workgroup> group_base: u32;

@compute @workgroup_size(8, 8)
fn cs_edge_list(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    var is_edge = false;
    if (all(id.xy < vec2<u32>(P.rt.zw))) {
        let e = textureLoad(edges_tex, vec2<i32>(id.xy), 0).rg;
        is_edge = e.x > 0.0 || e.y > 0.0;
        textureStore(weights_out, id.xy, vec4<f32>(0.0));
    }
    if (li == 0u) {
        atomicStore(&group_count, 0u);
    }
    workgroupBarrier();
    var slot = 0u;
    if (is_edge) {
        slot = atomicAdd(&group_count, 1u);
    }
    workgroupBarrier();
    if (li == 0u) {
        group_base = atomicAdd(&edge_list.count, atomicLoad(&group_count));
    }
    workgroupBarrier();
    if (is_edge) {
        edge_list.pixels[group_base + slot] = id.x | (id.y << 16u);
    }
}

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
