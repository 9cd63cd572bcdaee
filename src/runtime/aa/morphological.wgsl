// Fetches shared by the two morphological antialiasing passes, MLAA (mlaa.wgsl, thesis ch. 9) and SMAA (smaa.wgsl,
// thesis ch. 10), prepended to each after srgb.wgsl by its Rust module. The including shader declares `P` with
// `rt` = (1/width, 1/height, width, height), `color_tex`, `edges_tex`, `blend_tex` and the bilinear sampler `lin`.
// Texel loads clamp to the edge.

// Luma of the sRGB-encoded colour at texel `p` (the luma edge detection of both passes).
fn luma_at(p: vec2<i32>) -> f32 {
    let size = vec2<i32>(P.rt.zw);
    let q = clamp(p, vec2<i32>(0, 0), size - vec2<i32>(1, 1));
    return dot(textureLoad(color_tex, q, 0).rgb, LUMA);
}

// Bilinear fetch of the edges texture at a position in pixel units.
fn edges_at(p: vec2<f32>) -> vec2<f32> {
    return textureSampleLevel(edges_tex, lin, p * P.rt.xy, 0.0).rg;
}

// The colour at texel `p` in linear light (alpha as stored).
fn color_lin(p: vec2<i32>) -> vec4<f32> {
    let size = vec2<i32>(P.rt.zw);
    let c = textureLoad(color_tex, clamp(p, vec2<i32>(0, 0), size - vec2<i32>(1, 1)), 0);
    return vec4<f32>(srgb_to_linear(c.rgb), c.a);
}

// The blending weights at texel `p`.
fn blend_at(p: vec2<i32>) -> vec4<f32> {
    let size = vec2<i32>(P.rt.zw);
    return textureLoad(blend_tex, clamp(p, vec2<i32>(0, 0), size - vec2<i32>(1, 1)), 0);
}
