// The three morphological antialiasing passes of SMAA (smaa.wgsl) and MLAA (mlaa.wgsl) as compute passes over
// 8×8-thread workgroups: the same per-pixel functions `edges_px`, `weights_px` and `blend_px` as the fragment entry
// points, so every arithmetic step is the fragment path's. Appended after smaa.wgsl or mlaa.wgsl by
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

@compute @workgroup_size(8, 8)
fn cs_weights(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id.xy >= vec2<u32>(P.rt.zw))) {
        return;
    }
    textureStore(weights_out, id.xy, weights_px(vec2<f32>(id.xy) + vec2<f32>(0.5, 0.5)));
}

@compute @workgroup_size(8, 8)
fn cs_blend(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id.xy >= vec2<u32>(P.rt.zw))) {
        return;
    }
    textureStore(color_out, id.xy, blend_px(vec2<i32>(id.xy)));
}
