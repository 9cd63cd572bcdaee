// The edge rows the compute edge passes write (`cs_edges` of three_pass.wgsl, `cs_edges_*` of edges.wgsl), included
// by both. `Rg8Unorm` is not a storage format WebGPU guarantees, so each thread detects the edges of two adjacent
// pixels and writes them as one u32 (bytes R0 G0 R1 G1, the texture's layout) into a buffer with rows of
// `edge_row_bytes` (256-byte aligned), which the host copies into the `Rg8Unorm` edges texture the weights pass
// filters. Edge values are exactly 0 or 1, so the bytes are those the fragment pass renders.
// The including shader declares `P` with `rt` = (1/width, 1/height, width, height).

@group(0) @binding(8) var<storage, read_write> edge_rows: array<u32>;

// Bytes per row of the edge buffer: 2 bytes per pixel, rounded up to the 256 bytes a buffer-to-texture copy needs
// (the host's `edge_row_bytes`).
fn edge_row_words() -> u32 {
    let w = u32(P.rt.z);
    return ((2u * w + 255u) / 256u) * 256u / 4u;
}

// Whether the pixel pair of thread `id` (x = 2·id.x and the pixel right of it) starts inside the frame.
fn edge_pair_in_frame(id: vec2<u32>) -> bool {
    return 2u * id.x < u32(P.rt.z) && id.y < u32(P.rt.w);
}

// The left pixel of thread `id`'s pair.
fn edge_pair_origin(id: vec2<u32>) -> vec2<i32> {
    return vec2<i32>(2 * i32(id.x), i32(id.y));
}

// Writes the edges of thread `id`'s pair; the right one is zero when it lies beyond the last column (those bytes are
// row padding, never copied).
fn store_edge_pair(id: vec2<u32>, e0: vec2<f32>, e1: vec2<f32>) {
    let right = select(vec2<f32>(0.0), e1, 2u * id.x + 1u < u32(P.rt.z));
    edge_rows[id.y * edge_row_words() + id.x] = pack4x8unorm(vec4<f32>(e0, right));
}
