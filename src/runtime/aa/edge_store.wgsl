// The edge texture the compute edge passes write (`cs_edges` of three_pass.wgsl, `cs_edges_*` of edges.wgsl),
// included by both: the texture the weights pass then filters, written with `textureStore`, no buffer and no copy.
// Its format is `rg8unorm` where the adapter allows it as a storage texture, else `rgba8unorm` (WebGPU's portable
// storage format; B and A written 0 and never read): the host substitutes the format in the declaration below
// (`runtime/aa/three_pass.rs`, `EdgeFormat`). Edge values are exactly 0 or 1, so R and G hold the bytes the fragment
// pass renders into its `Rg8Unorm` target. Each thread detects the edges of two adjacent pixels.
// The including shader declares `P` with `rt` = (1/width, 1/height, width, height).

@group(0) @binding(8) var edges_out: texture_storage_2d<rg8unorm, write>;

// The same pass zeroes the weights of its pixels and lists its edge pixels for the weights pass (the compute form
// of the stencil SMAA's weights pass runs under, thesis §9.3), so the edges are never read back for it: one global
// atomic per workgroup, the list in no particular order (each listed pixel writes only its own weights). Pixels
// without an edge keep zero weights in both shapes (`weights_px` returns 0 there).
struct EdgeList {
    count: atomic<u32>,
    // x | y << 16 of each edge pixel.
    pixels: array<u32>,
}

@group(0) @binding(9) var weights_out: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(11) var<storage, read_write> edge_list: EdgeList;

var<workgroup> group_count: atomic<u32>;
var<workgroup> group_base: u32;

// Writes the edges `e0`, `e1` of thread `id`'s pixel pair (x = 2·id.x and the pixel right of it; a pixel beyond
// the frame is skipped), zeroes their weights and lists the edge pixels. Every thread of the 8×8 workgroup (`li`
// its index) calls it from uniform control flow (barriers).
fn emit_edge_pair(id: vec2<u32>, li: u32, e0: vec2<f32>, e1: vec2<f32>) {
    let size = vec2<u32>(P.rt.zw);
    let x0 = 2u * id.x;
    let in0 = x0 < size.x && id.y < size.y;
    let in1 = x0 + 1u < size.x && id.y < size.y;
    let edge0 = in0 && (e0.x > 0.0 || e0.y > 0.0);
    let edge1 = in1 && (e1.x > 0.0 || e1.y > 0.0);
    if (in0) {
        textureStore(edges_out, vec2<u32>(x0, id.y), vec4<f32>(e0, 0.0, 0.0));
        textureStore(weights_out, vec2<u32>(x0, id.y), vec4<f32>(0.0));
    }
    if (in1) {
        textureStore(edges_out, vec2<u32>(x0 + 1u, id.y), vec4<f32>(e1, 0.0, 0.0));
        textureStore(weights_out, vec2<u32>(x0 + 1u, id.y), vec4<f32>(0.0));
    }
    if (li == 0u) {
        atomicStore(&group_count, 0u);
    }
    workgroupBarrier();
    let n = u32(edge0) + u32(edge1);
    var slot = 0u;
    if (n > 0u) {
        slot = atomicAdd(&group_count, n);
    }
    workgroupBarrier();
    if (li == 0u) {
        group_base = atomicAdd(&edge_list.count, atomicLoad(&group_count));
    }
    workgroupBarrier();
    let base = group_base;
    if (edge0) {
        edge_list.pixels[base + slot] = x0 | (id.y << 16u);
    }
    if (edge1) {
        edge_list.pixels[base + slot + u32(edge0)] = (x0 + 1u) | (id.y << 16u);
    }
}

// The left pixel of thread `id`'s pair (a pair beyond the frame reads clamped texels, its results unused).
fn edge_pair_origin(id: vec2<u32>) -> vec2<i32> {
    return vec2<i32>(2 * i32(id.x), i32(id.y));
}
