// The uniform block, source binding, stretch and 7-tap weights of the screen-space sum-of-Gaussians pass (TAP 2009;
// thesis ch. 4, Listing 4.1), shared by its fragment form (gaussian.wgsl) and its compute form (gaussian_tiled.wgsl),
// prepended to each by its Rust module; the Rust mirror is `sss::gaussian::Params` (one value serves both forms).

struct Params {
    // (1/width, 1/height, width, height)
    rt: vec4<f32>,
    // x: α (sssLevel), y: β (correction), z: γ (maxdd), w: lod factor
    stretch: vec4<f32>,
    // x: std dev of the incremental blur sqrt(vᵢ − vᵢ₋₁) (mm), y: sqrt(vᵢ) (mm), zw: direction
    blur: vec4<f32>,
    // Compute form only: rgb the blend constant w′ᵢ of eq. 4.8, w: 1 when the vertical pass writes RT1 (0 for the
    // last Gaussian, whose RT1 nothing reads)
    blend: vec4<f32>,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var src_tex: texture_2d<f32>;

// The blur's half-width (pixels per mm of the incremental σ, times that σ: s·a·sqrt(vᵢ − vᵢ₋₁)) at a pixel of
// linear depth `d`, matte (local SSS level) `a` and fine depth derivative `dd` along the pass, or −1 where the
// Gaussian is skipped: the matte and the depth LOD test of eq. 4.6.
fn stretch_width(d: f32, dd: f32, a: f32) -> f32 {
    if (a == 0.0 || d >= P.stretch.w * P.blur.y * P.stretch.x) {
        return -1.0;
    }
    let s = P.stretch.x / (d + P.stretch.y * min(abs(dd), P.stretch.z)); // eq. 4.1/4.2
    let s_local = s * a; // eq. 4.3/4.4
    return s_local * P.blur.x;
}

const W: array<f32, 7> = array<f32, 7>(0.006, 0.061, 0.242, 0.382, 0.242, 0.061, 0.006);
