//! Bloom on the final HDR frame before tone mapping (thesis ch. 4: "similar to d'Eon and Luebke 2007, following
//! Pharr and Humphreys 2004", performed on the final image; d'Eon & Luebke, "Advanced Techniques for Realistic
//! Real-Time Skin Rendering", GPU Gems 3 ch. 14, 2007; Pharr & Humphreys, *Physically Based Rendering*, 2004,
//! the bloom of its image film: `out = (1 − w)·I + w·(K * I)` with a wide kernel K).
//!
//! rtbake blooms only the part of the frame above a threshold, so that skin below it keeps its detail:
//!
//! ```text
//! B   = max(I − threshold, 0)                               (per channel, linear HDR radiance)
//! K*B = Σ_k a_k · G_σk * B,   Σ a_k = 1                      (three separable Gaussians, as d'Eon & Luebke sum them)
//! out = I + weight · (K*B − B)
//! ```
//!
//! With `threshold = 0` this is Pharr & Humphreys' `(1 − w)·I + w·K*I`. Bloom only redistributes: each Gaussian is
//! normalised to 1 over its taps, so Σ out = Σ I away from the image border (taps beyond the border read 0, so
//! light blurred off the frame leaves it). Parameters ([`BloomParams::default`], chosen here, not from the
//! papers, for a 720-line frame of heads under a 1.6 key light; the radii scale with the frame height): threshold
//! 1.0 (the tone map `1 − e^−L` puts L = 1 at 63 % white), weight 0.25, σ = 0.25 %, 0.6 % and 1.2 % of the frame
//! height (1.8, 4.3 and 8.6 pixels at 720 lines) mixed 0.5, 0.3, 0.2; taps to ⌈3σ⌉ (13 + 27 + 53 taps per axis
//! at 720 lines).
//!
//! Three compute stages over flat f32 buffers (`skin/bloom.wgsl`: B, the three horizontal blurs in one walk
//! over the widest radius, then the vertical ones summed and combined); CPU twin [`crate::runtime::skin::bloom_cpu`] (the same
//! per-blur sums in the same order).

use crate::error::{check_range, InvalidInput};
use crate::runtime::compute_chain::{self, Buffer, Stage};
use crate::runtime::RuntimeError;

/// The parameter that switches bloom (its flag is in the CLI's table).
pub const BLOOM_PARAM: &str = "bloom";

/// Bloom parameters (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BloomParams {
    /// Linear HDR radiance above which a channel blooms.
    pub threshold: f32,
    /// Fraction of the bright part redistributed, 0..=1.
    pub weight: f32,
    /// Standard deviations of the three Gaussians as fractions of the frame height.
    pub sigma_of_height: [f32; 3],
    /// Mix of the three blurs (sum 1).
    pub mix: [f32; 3],
}

impl Default for BloomParams {
    fn default() -> Self {
        BloomParams { threshold: 1.0, weight: 0.25, sigma_of_height: [0.0025, 0.006, 0.012], mix: [0.5, 0.3, 0.2] }
    }
}

/// Most taps on one side of a blur.
pub const MAX_RADIUS_PX: u32 = 512;

impl BloomParams {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_range("bloom threshold", self.threshold as f64, 0.0, 1e6, "")?;
        check_range("bloom weight", self.weight as f64, 0.0, 1.0, "")?;
        for s in self.sigma_of_height {
            check_range("bloom sigma", s as f64, 1e-5, 0.25, "(fraction of the frame height)")?;
        }
        let sum: f32 = self.mix.iter().sum();
        if self.mix.iter().any(|a| a.is_nan() || *a < 0.0) || (sum - 1.0).abs() > 1e-4 {
            return Err(InvalidInput::new("bloom mix", format!("must be >= 0 and sum to 1, got {:?}", self.mix)));
        }
        Ok(())
    }

    /// The three kernels for a frame `height` pixels tall: taps `-r..=r`, `r = min(⌈3σ⌉, MAX_RADIUS_PX)`,
    /// Gaussian weights normalised to sum 1.
    pub fn kernels(&self, height: u32) -> [Vec<f32>; 3] {
        std::array::from_fn(|k| gaussian_taps(self.sigma_of_height[k] as f64 * height as f64))
    }
}

/// Normalised Gaussian taps of standard deviation `sigma_px` at `-r..=r`, `r = ⌈3σ⌉` (at least 1).
pub fn gaussian_taps(sigma_px: f64) -> Vec<f32> {
    let r = ((3.0 * sigma_px).ceil() as u32).clamp(1, MAX_RADIUS_PX) as i64;
    let w: Vec<f64> = (-r..=r).map(|x| (-(x * x) as f64 / (2.0 * sigma_px * sigma_px)).exp()).collect();
    let sum: f64 = w.iter().sum();
    w.iter().map(|v| (v / sum) as f32).collect()
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    size: [f32; 4],
    radius: [f32; 4],
    mix: [f32; 4],
}

/// Bytes of the storage buffers [`bloom`] binds for a `width`×`height` frame with `p`, in binding order: the HDR
/// frame (RGBA f32), the three Gaussians' taps, the three thresholded and blurred RGBA f32 planes (one per
/// Gaussian, the largest), and the horizontal and vertical blur results (RGBA f32).
pub fn storage_buffer_bytes(width: u32, height: u32, p: &BloomParams) -> [u64; 5] {
    let n = width as u64 * height as u64;
    let taps: usize = p.kernels(height).iter().map(Vec::len).sum();
    [16 * n, 4 * taps as u64, 3 * 16 * n, 16 * n, 16 * n]
}

/// The largest buffer [`bloom`] allocates for a `width`×`height` frame, bytes: the three blurred planes, 48 bytes
/// per pixel (checked against the adapter's storage-binding limit before a frame is rendered).
pub fn largest_buffer_bytes(width: u32, height: u32) -> u64 {
    3 * 16 * width as u64 * height as u64
}

/// Blooms a `width`×`height` linear HDR frame (RGBA, alpha passed through) on the GPU.
pub fn bloom(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    width: u32,
    height: u32,
    hdr_rgba: &[f32],
    p: &BloomParams,
) -> Result<Vec<f32>, RuntimeError> {
    p.validate()?;
    let n = (width * height) as usize;
    if hdr_rgba.len() != 4 * n {
        return Err(InvalidInput::new("bloom input", format!("needs {width}x{height} RGBA values")).into());
    }
    let kernels = p.kernels(height);
    let radius = |k: usize| ((kernels[k].len() - 1) / 2) as f32;
    let params = Params {
        size: [width as f32, height as f32, p.threshold, p.weight],
        radius: [radius(0), radius(1), radius(2), 0.0],
        mix: [p.mix[0], p.mix[1], p.mix[2], 0.0],
    };
    let taps: Vec<f32> = kernels.concat();
    let bytes = storage_buffer_bytes(width, height, p);
    let out = compute_chain::run(
        device,
        queue,
        "bloom",
        include_str!("bloom.wgsl"),
        bytemuck::bytes_of(&params),
        &[
            Buffer::Data(bytemuck::cast_slice(hdr_rgba)),
            Buffer::Data(bytemuck::cast_slice(&taps)),
            Buffer::Zeroed(bytes[2]),
            Buffer::Zeroed(bytes[3]),
            Buffer::Zeroed(bytes[4]),
        ],
        &[
            Stage { entry: "bright", groups: compute_chain::groups_8x8(width, height) },
            Stage { entry: "h_blur", groups: compute_chain::groups_8x8(width, height) },
            Stage { entry: "v_blur", groups: compute_chain::groups_8x8(width, height) },
        ],
        3,
    )?;
    Ok(bytemuck::cast_slice(&out).to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_buffer_is_the_one_bloom_allocates() {
        let p = BloomParams::default();
        for (w, h) in [(8, 8), (37, 21), (2560, 1440)] {
            let bytes = storage_buffer_bytes(w, h, &p);
            // The data buffers hold exactly what bloom uploads: the RGBA f32 frame and the concatenated taps.
            assert_eq!(bytes[0], (4 * w * h) as u64 * 4);
            assert_eq!(bytes[1], p.kernels(h).concat().len() as u64 * 4);
            assert_eq!(*bytes.iter().max().unwrap(), largest_buffer_bytes(w, h), "{w}x{h}");
        }
        // The figure a 2560x1440 frame was refused with by a software adapter after rendering.
        assert_eq!(largest_buffer_bytes(2560, 1440), 176_947_200);
    }

    #[test]
    fn kernels_are_normalised_and_scale_with_the_frame() {
        let p = BloomParams::default();
        p.validate().unwrap();
        let k = p.kernels(720);
        for t in &k {
            assert!((t.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            assert!(t.len() % 2 == 1);
        }
        // σ = 8.64 px at 720 lines: r = ⌈25.92⌉ = 26.
        assert_eq!(k[2].len(), 2 * 26 + 1);
        assert_eq!(p.kernels(1440)[0].len(), 2 * 11 + 1);
        assert!(BloomParams { weight: 1.5, ..p }.validate().is_err());
        assert!(BloomParams { mix: [0.5, 0.5, 0.5], ..p }.validate().is_err());
    }
}
