//! The GPU's fixed-function texture sampling and number formats emulated on the CPU, shared by every pass's CPU
//! twin (the `*_cpu.rs` file beside each pass, rayon, no adapter needed).
//!
//! Each twin mirrors its WGSL shader step for step in f32, so the GPU/CPU comparison tests measure the
//! hardware, not two different algorithms. Texture fetches go through [`Tex8`], which emulates the fixed-function
//! sampler: point loads with clamp-to-edge and bilinear fetches with a selectable precision model
//! ([`FilterPrecision`]): real GPUs filter in (nearly) full float precision, while lavapipe/llvmpipe filter 8-bit
//! textures with 8-bit weights and return 8-bit results.

/// How a bilinear fetch of an 8-bit texture is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FilterPrecision {
    /// f32 weights and result (what the algorithms assume; desktop GPUs are within ~1e-3 of this).
    #[default]
    Exact,
    /// Weights rounded to 1/256 and every lerp result rounded to 1/255, as measured on lavapipe / llvmpipe
    /// (Mesa's 8-bit AoS filtering path).
    Unorm8,
}

impl FilterPrecision {
    /// The model that matches an adapter: `Unorm8` for Mesa's software rasterisers, `Exact` otherwise.
    pub fn for_adapter(name: &str, device_type_is_cpu: bool) -> Self {
        if device_type_is_cpu || name.to_lowercase().contains("llvmpipe") {
            Self::Unorm8
        } else {
            Self::Exact
        }
    }
}

/// A read-only 8-bit UNORM texture (top row first, `ch` interleaved channels) with sampler emulation.
#[derive(Clone, Copy)]
pub struct Tex8<'a> {
    pub w: u32,
    pub h: u32,
    pub ch: u32,
    pub data: &'a [u8],
}

impl<'a> Tex8<'a> {
    pub fn new(w: u32, h: u32, ch: u32, data: &'a [u8]) -> Self {
        assert_eq!(data.len(), (w * h * ch) as usize, "texture size");
        Self { w, h, ch, data }
    }

    /// Texel (x, y) channel c with clamp-to-edge, as a float in [0, 1] (`textureLoad` of a clamped coordinate).
    #[inline]
    pub fn load(&self, x: i32, y: i32, c: u32) -> f32 {
        let x = x.clamp(0, self.w as i32 - 1) as usize;
        let y = y.clamp(0, self.h as i32 - 1) as usize;
        UNORM8_F32[self.data[(y * self.w as usize + x) * self.ch as usize + c as usize] as usize]
    }

    /// Nearest fetch of channels 0 and 1 at normalised coordinates (clamp-to-edge).
    #[inline]
    pub fn sample2_nearest(&self, u: f32, v: f32) -> [f32; 2] {
        let x = (u * self.w as f32).floor() as i32;
        let y = (v * self.h as f32).floor() as i32;
        [self.load(x, y, 0), if self.ch > 1 { self.load(x, y, 1) } else { 0.0 }]
    }

    /// Bilinear fetch of channels 0 and 1 at normalised coordinates (u, v), clamp-to-edge
    /// (`textureSampleLevel` with a linear, clamped sampler).
    #[inline]
    pub fn sample2(&self, u: f32, v: f32, prec: FilterPrecision) -> [f32; 2] {
        let x = u * self.w as f32 - 0.5;
        let y = v * self.h as f32 - 0.5;
        let (x0, y0) = (floor(x), floor(y));
        let (mut fx, mut fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i32, y0 as i32);
        if prec == FilterPrecision::Unorm8 {
            fx = (fx * 256.0).round() / 256.0;
            fy = (fy * 256.0).round() / 256.0;
        }
        // The four texels' offsets once (clamp-to-edge), then one table read per texel and channel.
        let (wm, hm) = (self.w as i32 - 1, self.h as i32 - 1);
        let (xa, xb) = (x0.clamp(0, wm) as usize, x0.saturating_add(1).clamp(0, wm) as usize);
        let (ya, yb) =
            (y0.clamp(0, hm) as usize * self.w as usize, y0.saturating_add(1).clamp(0, hm) as usize * self.w as usize);
        let ch = self.ch as usize;
        let (i00, i10, i01, i11) = ((ya + xa) * ch, (ya + xb) * ch, (yb + xa) * ch, (yb + xb) * ch);
        let mut out = [0.0f32; 2];
        for (c, o) in out.iter_mut().enumerate().take(ch.min(2)) {
            let t00 = UNORM8_F32[self.data[i00 + c] as usize];
            let t10 = UNORM8_F32[self.data[i10 + c] as usize];
            let t01 = UNORM8_F32[self.data[i01 + c] as usize];
            let t11 = UNORM8_F32[self.data[i11 + c] as usize];
            *o = match prec {
                FilterPrecision::Exact => {
                    let top = t00 + (t10 - t00) * fx;
                    let bottom = t01 + (t11 - t01) * fx;
                    top + (bottom - top) * fy
                }
                FilterPrecision::Unorm8 => {
                    let q = |v: f32| (v * 255.0).round() / 255.0;
                    let top = q(t00 * (1.0 - fx) + t10 * fx);
                    let bottom = q(t01 * (1.0 - fx) + t11 * fx);
                    q(top * (1.0 - fy) + bottom * fy)
                }
            };
        }
        out
    }
}

/// `x.floor()`, without the libm call that baseline x86-64 (no SSE4.1 `roundss`) makes for it: below 2²³ in
/// magnitude the truncation to an integer, less one where it rounded up (a zero keeps the sign of `x`); every other value (integral already,
/// infinite or NaN) goes to `floor` itself. Same result for every input.
#[inline(always)]
fn floor(x: f32) -> f32 {
    if x.abs() < 8_388_608.0 {
        let t = x as i32 as f32;
        if t > x {
            t - 1.0
        } else {
            t.copysign(x) // −0.0 stays −0.0
        }
    } else {
        x.floor()
    }
}

/// `v as f32 / 255.0` for every byte `v`: an 8-bit UNORM texel as the shader reads it (the same correctly rounded
/// quotient, looked up instead of divided).
pub const UNORM8_F32: [f32; 256] = {
    let mut t = [0.0f32; 256];
    let mut i = 0;
    while i < 256 {
        t[i] = i as f32 / 255.0;
        i += 1;
    }
    t
};

/// Stores a float in an 8-bit UNORM render target (clamp, round to nearest).
#[inline]
pub fn unorm8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// sRGB transfer function (IEC 61966-2-1), encoded → linear; same formula as the shaders.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear → sRGB-encoded; same formula as the shaders.
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

#[inline]
pub(crate) fn wgsl_round(v: f32) -> f32 {
    // WGSL `round` rounds half to even; Rust `round` rounds half away from zero. Use the WGSL rule.
    v.round_ties_even()
}

/// Rounds to f16 and back, as an `Rgba16Float` render target stores a value.
pub(crate) fn f16r(v: f32) -> f32 {
    half::f16::from_f32(v).to_f32()
}

/// A row-major f32 image of `ch` interleaved channels with the GPU's clamp-to-edge loads and bilinear fetches at
/// normalised coordinates (texel centres at (i + 0.5)/w, f32 weights): the texture reads of the SSS twins.
pub(crate) struct Img<'a> {
    pub w: u32,
    pub h: u32,
    pub ch: usize,
    pub data: &'a [f32],
}

impl Img<'_> {
    pub fn load(&self, x: i32, y: i32, c: usize) -> f32 {
        let x = x.clamp(0, self.w as i32 - 1) as usize;
        let y = y.clamp(0, self.h as i32 - 1) as usize;
        self.data[(y * self.w as usize + x) * self.ch + c]
    }
    pub fn bilinear(&self, u: f32, v: f32, c: usize) -> f32 {
        let x = u * self.w as f32 - 0.5;
        let y = v * self.h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i32, y0 as i32);
        let top = self.load(x0, y0, c) + (self.load(x0 + 1, y0, c) - self.load(x0, y0, c)) * fx;
        let bottom = self.load(x0, y0 + 1, c) + (self.load(x0 + 1, y0 + 1, c) - self.load(x0, y0 + 1, c)) * fx;
        top + (bottom - top) * fy
    }
}

/// Bilinear, clamp-to-edge read of a row-major `w`×`h` map of `C` channels at normalised (u, v), texel centres at
/// (i + ½)/size, in f32: the fetches of `skin/inputs.wgsl` and of `bilinear_taps.wgsl` + `rig_at`/`h0_at`/`pd_at`.
pub(crate) fn bilinear<const C: usize>(data: &[[f32; C]], w: u32, h: u32, u: f32, v: f32) -> [f32; C] {
    let (x, y) = (u * w as f32 - 0.5, v * h as f32 - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (xi, yi) = (x0 as i32, y0 as i32);
    let (wm, hm) = (w as i32 - 1, h as i32 - 1);
    let (i0, i1) = (xi.clamp(0, wm) as usize, (xi + 1).clamp(0, wm) as usize);
    let (j0, j1) = (yi.clamp(0, hm) as usize, (yi + 1).clamp(0, hm) as usize);
    let w = w as usize;
    let (a, b, c, d) = (data[j0 * w + i0], data[j0 * w + i1], data[j1 * w + i0], data[j1 * w + i1]);
    std::array::from_fn(|k| {
        let top = a[k] + (b[k] - a[k]) * fx;
        let bottom = c[k] + (d[k] - c[k]) * fx;
        top + (bottom - top) * fy
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values measured on lavapipe (Mesa 22.3, llvmpipe): a 255 → 0 step sampled at fractions 0.25, 0.125,
    /// 0.375, 0.1, 0.7 returned 191, 223, 159, 229, 77 (/255).
    #[test]
    fn unorm8_model_reproduces_lavapipe_bilinear() {
        let data = [255u8, 0];
        let t = Tex8::new(2, 1, 1, &data);
        for (f, want) in [(0.25f32, 191u8), (0.125, 223), (0.375, 159), (0.1, 229), (0.7, 77)] {
            let u = (0.5 + f) / 2.0;
            let got = t.sample2(u, 0.5, FilterPrecision::Unorm8)[0];
            assert_eq!((got * 255.0).round() as u8, want, "fraction {f}");
            let exact = t.sample2(u, 0.5, FilterPrecision::Exact)[0];
            assert!((exact - (1.0 - f)).abs() < 1e-6);
        }
    }

    #[test]
    fn loads_clamp_to_edge_and_nearest_matches_texel() {
        let data = [10u8, 20, 30, 40];
        let t = Tex8::new(2, 2, 1, &data);
        assert_eq!(t.load(-5, -5, 0), 10.0 / 255.0);
        assert_eq!(t.load(9, 9, 0), 40.0 / 255.0);
        assert_eq!(t.sample2_nearest(0.74, 0.26,)[0], 20.0 / 255.0);
    }

    #[test]
    fn unorm8_table_is_the_quotient() {
        for v in 0..=255u8 {
            assert_eq!(UNORM8_F32[v as usize].to_bits(), (v as f32 / 255.0).to_bits());
        }
    }

    #[test]
    fn floor_is_f32_floor() {
        let mut xs = vec![0.0f32, -0.0, 0.5, -0.5, 1.0, -1.0, 8_388_607.5, -8_388_607.5, 8_388_608.0, 1e30, -1e30];
        xs.extend([f32::INFINITY, f32::NEG_INFINITY, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, f32::EPSILON]);
        xs.extend((0..20_000).map(|i| (i as f32 - 10_000.0) * 0.173_1));
        for x in xs {
            assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "{x}");
        }
        assert!(floor(f32::NAN).is_nan());
    }

    #[test]
    fn srgb_round_trip() {
        for i in 0..=255u8 {
            let v = i as f32 / 255.0;
            assert_eq!(unorm8(linear_to_srgb(srgb_to_linear(v))), i);
        }
    }
}
