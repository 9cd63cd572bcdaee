// The frame bindings and depth fetches shared by the screen-space SSS fragment passes (separable.wgsl,
// importance.wgsl, gaussian.wgsl; prepended to each by its Rust module, `SssInputs::blur_group` binds them): the
// linear depth at binding 2 (r32float: not filterable without FLOAT32_FILTERABLE, so the bilinear fetch is written
// out with four loads) and the bilinear clamp-to-edge sampler at binding 6. The including shader declares `P` with
// `rt` = (1/width, 1/height, width, height).

@group(0) @binding(2) var depth_tex: texture_2d<f32>;
@group(0) @binding(6) var lin: sampler;

// Clamp-to-edge load of the depth at texel `p`.
fn depth_load(p: vec2<i32>) -> f32 {
    let size = vec2<i32>(P.rt.zw);
    return textureLoad(depth_tex, clamp(p, vec2<i32>(0, 0), size - vec2<i32>(1, 1)), 0).r;
}

// Bilinear, clamp-to-edge fetch of the depth at normalised coordinates.
fn depth_at(uv: vec2<f32>) -> f32 {
    let x = uv * P.rt.zw - vec2<f32>(0.5, 0.5);
    let x0 = floor(x);
    let f = x - x0;
    let p = vec2<i32>(x0);
    let top = mix(depth_load(p), depth_load(p + vec2<i32>(1, 0)), f.x);
    let bottom = mix(depth_load(p + vec2<i32>(0, 1)), depth_load(p + vec2<i32>(1, 1)), f.x);
    return mix(top, bottom, f.y);
}
