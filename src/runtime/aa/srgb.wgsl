// Colour conventions shared by the antialiasing passes (edges.wgsl, mlaa.wgsl, smaa.wgsl, modes.wgsl; prepended to
// each by its Rust module): colour images are Rgba8Unorm holding sRGB-encoded values, luma is taken on those values
// with the Rec. 709 weights (thesis eq. 9.2), and blending happens in linear light through the sRGB transfer
// functions (IEC 61966-2-1). CPU twins: `aa/smaa_cpu.rs` (`srgb_to_linear`, `linear_to_srgb`, `LUMA`).

const LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    return select(1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * c, c <= vec3<f32>(0.0031308));
}
