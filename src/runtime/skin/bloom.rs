//! Bloom on the final HDR frame before tone mapping (thesis ch. 4: "similar to d'Eon and Luebke 2007, following
//! Pharr and Humphreys 2004", performed on the final image; d'Eon & Luebke, "Advanced Techniques for Realistic
//! Real-Time Skin Rendering", GPU Gems 3 ch. 14, 2007; Pharr & Humphreys, *Physically Based Rendering*, 2004,
//! the bloom of its image film: `out = (1 − w)·I + w·(K * I)` with a wide kernel K).
//!
//! rtbake blooms only the part of the frame above a threshold, so that skin below it keeps its detail, and spreads
//! it with a downsampled pyramid as engines do (Jimenez, "Next Generation Post Processing in Call of Duty: Advanced
//! Warfare", SIGGRAPH 2014 course *Advances in Real-Time Rendering*: 13-tap downsample, 3×3 tent upsample):
//!
//! ```text
//! B   = max(I − threshold, 0)                               (per channel, linear HDR radiance)
//! D_0 = B,  D_l = F13(D_{l−1}) at half the size (⌈w/2⌉×⌈h/2⌉), l = 1..N
//!       F13 = 0.5 · box(centre 4×4) + 0.125 · (four overlapping 2×2 boxes round the centre)
//!           = 13 bilinear reads; as texel weights: 1/32 corners, 1/16 edges, 1/8 centre of a 6×6 footprint
//! U_N = a·D_N,  U_l = a·D_l + T(U_{l+1}),  a = 1/N             (T: 3×3 tent (1 2 1)²/16 of bilinear reads)
//! K*B = T(U_1)   (at full resolution; = Σ_l a · (D_l brought back up through l tents))
//! out = I + weight · (K*B − B)
//! ```
//!
//! Every filter is normalised, so bloom only redistributes: Σ out = Σ I away from the image border (texels beyond a
//! level read 0, so light blurred off the frame leaves it). The pyramid's depth scales with the frame height:
//! N = round(log₂(coarsest_of_height · height)) clamped to 1..=[`MAX_LEVELS`] (N = 3 at 720 lines: levels of
//! 640×360, 320×180, 160×90). Jimenez's Karis average on the first downsample (against fireflies) is not applied:
//! the frame is deterministic and has none. Parameters ([`BloomParams::default`], chosen here, not from the papers, for a
//! 720-line frame of heads under a 1.6 key light): threshold 1.0 (the tone map `1 − e^−L` puts L = 1 at 63 % white),
//! weight 0.25, coarsest level at 1.2 % of the frame height (the widest of the three Gaussians, σ = 8.6 px at 720
//! lines, that the full-resolution blur before the pyramid used).
//!
//! **How it differs from the full-resolution blur it replaced** (B blurred by three separable Gaussians, σ = 0.25 %,
//! 0.6 % and 1.2 % of the height, mixed 0.5/0.3/0.2: 93 taps per axis and 48 bytes of intermediates per pixel at
//! 720 lines): the pyramid weights its levels equally, so a little more light goes far and less stays within a
//! pixel or two of its source (a softer, wider halo); it is not shift-invariant to the pixel (the 2× grids), and it
//! reads 13 + 9·4 texels per level instead of 93 per axis, its largest buffer being the frame itself. Measured on a
//! 384×216 test frame (dim noise, a 12×12 highlight at L = 3, a bright stripe, hot pixels at L = 30; per-channel
//! tone map 1 − e^−L): RMSE 0.0022 over the frame, 0.0077 over the 6995 pixels bloom moves, worst 0.165 at the hot
//! pixels, which the old blur kept half of within σ = 0.54 px (`bloom_pyramid_against_the_full_resolution_blur`
//! in tests/it/skin_passes.rs, which holds the old blur as its reference).
//!
//! Stages over flat f32 buffers (`skin/bloom.wgsl`: `down` for l = 1..N, `up` for l = N−1..1, the level a
//! per-dispatch argument, then `combine`), one submission ([`bloom`]) or recorded into a frame's encoder
//! (`record`);
//! CPU twin [`crate::runtime::skin::bloom_cpu`] (the same sums in the same order).

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
    /// Texel size of the pyramid's coarsest level as a fraction of the frame height (sets the depth N).
    pub coarsest_of_height: f32,
}

impl Default for BloomParams {
    fn default() -> Self {
        BloomParams { threshold: 1.0, weight: 0.25, coarsest_of_height: 0.012 }
    }
}

/// Most levels of the pyramid.
pub const MAX_LEVELS: u32 = 6;

impl BloomParams {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_range("bloom threshold", self.threshold as f64, 0.0, 1e6, "")?;
        check_range("bloom weight", self.weight as f64, 0.0, 1.0, "")?;
        check_range(
            "bloom coarsest_of_height",
            self.coarsest_of_height as f64,
            1e-5,
            0.25,
            "(fraction of the frame height)",
        )?;
        Ok(())
    }

    /// Levels N below the frame for a frame `height` pixels tall: round(log₂(coarsest_of_height · height)) in
    /// 1..=[`MAX_LEVELS`].
    pub fn levels(&self, height: u32) -> u32 {
        ((self.coarsest_of_height as f64 * height as f64).log2().round().max(1.0) as u32).min(MAX_LEVELS)
    }
}

/// Sizes of levels 1..=`levels` below a `width`×`height` frame (each ⌈half⌉ of the one above).
pub fn level_sizes(width: u32, height: u32, levels: u32) -> Vec<(u32, u32)> {
    let mut d = (width, height);
    (0..levels)
        .map(|_| {
            d = (d.0.div_ceil(2), d.1.div_ceil(2));
            d
        })
        .collect()
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    size: [f32; 4],
    lv: [f32; 4],
}

/// Bytes of the storage buffers [`bloom`] binds for a `width`×`height` frame with `p`, in binding order: the HDR
/// frame (RGBA f32), the pyramid D_1..D_N and its accumulation U_1..U_N (RGBA f32, under a third of the frame
/// each) and the result (RGBA f32).
pub fn storage_buffer_bytes(width: u32, height: u32, p: &BloomParams) -> [u64; 4] {
    let n = width as u64 * height as u64;
    let pyramid: u64 = level_sizes(width, height, p.levels(height)).iter().map(|&(w, h)| w as u64 * h as u64).sum();
    [16 * n, 16 * pyramid, 16 * pyramid, 16 * n]
}

/// The largest buffer [`bloom`] allocates for a `width`×`height` frame, bytes: the frame itself, 16 bytes per
/// pixel (checked against the adapter's storage-binding limit before a frame is rendered).
pub fn largest_buffer_bytes(width: u32, height: u32) -> u64 {
    compute_chain::vec4_per_pixel_bytes(width, height)
}

/// The uniform block and the dispatches of bloom over a `width`×`height` frame with `p`.
fn stages(width: u32, height: u32, p: &BloomParams) -> (Params, Vec<Stage<'static>>) {
    let levels = p.levels(height);
    let params = Params {
        size: [width as f32, height as f32, p.threshold, p.weight],
        lv: [levels as f32, 1.0 / levels as f32, 0.0, 0.0],
    };
    let sizes = level_sizes(width, height, levels);
    let at = |entry, l: u32| {
        let (w, h) = sizes[l as usize - 1];
        Stage { entry, groups: compute_chain::groups_8x8(w, h), args: [l, 0, 0, 0] }
    };
    let mut stages: Vec<Stage<'static>> = (1..=levels).map(|l| at("down", l)).collect();
    stages.extend((1..levels).rev().map(|l| at("up", l)));
    stages.push(Stage::new("combine", compute_chain::groups_8x8(width, height)));
    (params, stages)
}

/// GPU buffers of bloom for one frame size, in binding order: the HDR frame (RGBA f32, written by the frame's
/// composite), the pyramid and its accumulation, the result (RGBA f32; its alpha is not written).
pub(crate) struct BloomBuffers(pub(crate) [wgpu::Buffer; 4]);

impl BloomBuffers {
    pub(crate) fn new(device: &wgpu::Device, width: u32, height: u32, p: &BloomParams) -> Result<Self, RuntimeError> {
        p.validate()?;
        let bytes = storage_buffer_bytes(width, height, p);
        compute_chain::check_buffers(device, "bloom", &bytes)?;
        // From the frame pool: every level's texels are written (`down`, `up`) before they are read.
        Ok(Self(bytes.map(|b| crate::runtime::frame_pool::storage_buffer(device, "bloom", b))))
    }
}

/// Records bloom of the HDR frame in `b.0[0]` into `b.0[3]` (rgb) into `enc`: no submission, no read-back.
pub(crate) fn record(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    width: u32,
    height: u32,
    p: &BloomParams,
    b: &BloomBuffers,
) {
    let (params, stages) = stages(width, height, p);
    let bound: Vec<&wgpu::Buffer> = b.0.iter().collect();
    compute_chain::record(device, enc, "bloom", SOURCE, bytemuck::bytes_of(&params), &bound, &stages);
}

const SOURCE: &str = include_str!("bloom.wgsl");

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
    let (params, stages) = stages(width, height, p);
    let bytes = storage_buffer_bytes(width, height, p);
    let out = compute_chain::run(
        device,
        queue,
        "bloom",
        SOURCE,
        bytemuck::bytes_of(&params),
        &[
            Buffer::Data(bytemuck::cast_slice(hdr_rgba)),
            Buffer::Zeroed(bytes[1]),
            Buffer::Zeroed(bytes[2]),
            Buffer::Zeroed(bytes[3]),
        ],
        &stages,
        3,
    )?;
    let mut out: Vec<f32> = bytemuck::cast_slice(&out).to_vec();
    // Alpha passes through.
    for i in 0..n {
        out[4 * i + 3] = hdr_rgba[4 * i + 3];
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_buffer_is_the_frame_and_the_pyramid_is_under_two_thirds_of_it() {
        let p = BloomParams::default();
        for (w, h) in [(8, 8), (37, 21), (1280, 720), (2560, 1440)] {
            let bytes = storage_buffer_bytes(w, h, &p);
            assert_eq!(bytes[0], (4 * w * h) as u64 * 4);
            assert_eq!(*bytes.iter().max().unwrap(), largest_buffer_bytes(w, h), "{w}x{h}");
            assert!(3 * bytes[1] <= bytes[0] + 16 * 3 * (w + h + 8) as u64, "{w}x{h}: {bytes:?}");
        }
    }

    #[test]
    fn the_pyramid_deepens_with_the_frame_height() {
        let p = BloomParams::default();
        p.validate().unwrap();
        // 0.012 · 720 = 8.64 → log₂ = 3.11 → 3 levels: 640×360, 320×180, 160×90.
        assert_eq!(p.levels(720), 3);
        assert_eq!(level_sizes(1280, 720, 3), vec![(640, 360), (320, 180), (160, 90)]);
        assert_eq!(p.levels(1440), 4);
        assert_eq!(p.levels(96), 1);
        assert_eq!(level_sizes(37, 21, 2), vec![(19, 11), (10, 6)]);
        assert!(BloomParams { weight: 1.5, ..p }.validate().is_err());
        assert!(BloomParams { coarsest_of_height: 0.0, ..p }.validate().is_err());
    }
}
