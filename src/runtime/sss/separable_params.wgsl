// The uniform block and colour input of the separable SSS pass, shared by its fragment form (separable.wgsl) and its
// compute form (separable_tiled.wgsl), prepended to each by its Rust module; the Rust mirror is
// `sss::separable::Params` (one value serves both forms).

struct Params {
    // (1/width, 1/height, width, height)
    rt: vec4<f32>,
    // x: sssWidth, y: 1/tan(0.5·FOVy), z: follow surface (0/1), w: number of taps
    cfg: vec4<f32>,
    // xy: direction
    dir: vec4<f32>,
    taps: array<vec4<f32>, 64>,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var color_tex: texture_2d<f32>;
