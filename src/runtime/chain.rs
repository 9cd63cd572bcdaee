//! Whole-image entry points used by the command and the demo: pick the GPU pass or its CPU reference, run it on
//! an `Image<u8>`, return an `Image<u8>`. Pure with respect to files (the caller reads and writes them).

use super::cpu::{self, FilterPrecision};
use super::device::Gpu;
use super::gaussian_sss::{GaussianBlurs, GaussianSss, GaussianSssParams};
use super::importance_sss::{ImportanceSamples, ImportanceSss, ImportanceSssParams};
use super::mlaa::{Mlaa, MlaaAreaMap, MlaaOptions};
use super::separable_sss::{SeparableSss, SssKernel, SssParams};
use super::smaa::{Smaa, SmaaOptions, SmaaTextures};
use super::smaa_edges::{AaInputs, EdgeSettings};
use super::RuntimeError;
use crate::error::InvalidInput;
use crate::image_buf::Image;

/// A morphological antialiasing method with its lookup textures.
pub enum Antialiasing {
    Smaa(SmaaTextures),
    Mlaa(MlaaAreaMap),
}

/// Converts a decoded 8-bit image with 1–4 channels to RGBA8 (grey replicated, missing alpha = 255).
pub fn to_rgba8(img: &Image<u8>) -> Result<Image<u8>, InvalidInput> {
    let ch = img.channels as usize;
    if !(1..=4).contains(&ch) {
        return Err(InvalidInput::new("--input", format!("must have 1 to 4 channels, got {ch}")));
    }
    let mut out = Vec::with_capacity(img.data.len() / ch * 4);
    for p in img.data.chunks(ch) {
        let px = match ch {
            1 => [p[0], p[0], p[0], 255],
            2 => [p[0], p[0], p[0], p[1]],
            3 => [p[0], p[1], p[2], 255],
            _ => [p[0], p[1], p[2], p[3]],
        };
        out.extend_from_slice(&px);
    }
    Ok(Image::from_vec(img.width, img.height, 4, out))
}

/// Antialiases an RGBA8 (sRGB-encoded) image on `gpu`, or with the CPU reference when `gpu` is `None`.
pub fn antialias(gpu: Option<&Gpu>, img: &Image<u8>, aa: &Antialiasing) -> Result<Image<u8>, RuntimeError> {
    if img.channels != 4 {
        return Err(InvalidInput::new("image", format!("must be RGBA8, got {} channels", img.channels)).into());
    }
    let (w, h) = (img.width, img.height);
    crate::error::check_size("--input", w as u64, h as u64)?;
    let data = match (gpu, aa) {
        (Some(g), Antialiasing::Smaa(t)) => {
            Smaa::new(&g.device, &g.queue, w, h, t)?.run(&g.device, &g.queue, &img.data)?
        }
        (Some(g), Antialiasing::Mlaa(m)) => {
            Mlaa::new(&g.device, &g.queue, w, h, m)?.run(&g.device, &g.queue, &img.data)?
        }
        (None, Antialiasing::Smaa(t)) => cpu::smaa::smaa(&img.data, w, h, t, FilterPrecision::Exact).output,
        (None, Antialiasing::Mlaa(m)) => cpu::mlaa::mlaa(&img.data, w, h, m, FilterPrecision::Exact).output,
    };
    Ok(Image::from_vec(w, h, 4, data))
}

/// As [`antialias`] with an edge detector other than luma, predicated thresholding and/or a matte/stencil mask
/// ([`super::smaa_edges`]): `inputs.depth` when `edges` need it, `inputs.mask` (one byte per pixel, ≥ 128 = inside)
/// masks the pass when present.
pub fn antialias_with(
    gpu: Option<&Gpu>,
    img: &Image<u8>,
    aa: &Antialiasing,
    edges: &EdgeSettings,
    inputs: &AaInputs,
) -> Result<Image<u8>, RuntimeError> {
    if img.channels != 4 {
        return Err(InvalidInput::new("image", format!("must be RGBA8, got {} channels", img.channels)).into());
    }
    let (w, h) = (img.width, img.height);
    crate::error::check_size("--input", w as u64, h as u64)?;
    let masked = inputs.mask.is_some();
    let data = match (gpu, aa) {
        (Some(g), Antialiasing::Smaa(t)) => {
            let options = SmaaOptions { edges: *edges, masked, ..Default::default() };
            Smaa::with_options(&g.device, &g.queue, w, h, t, &options)?
                .run_with(&g.device, &g.queue, &img.data, inputs)?
        }
        (Some(g), Antialiasing::Mlaa(m)) => {
            let options = MlaaOptions { edges: *edges, masked };
            Mlaa::with_options(&g.device, &g.queue, w, h, m, &options)?
                .run_with(&g.device, &g.queue, &img.data, inputs)?
        }
        (None, Antialiasing::Smaa(t)) => {
            let options = SmaaOptions { edges: *edges, masked, ..Default::default() };
            cpu::smaa::smaa_with_options(&img.data, (w, h), t, FilterPrecision::Exact, &options, inputs)?.output
        }
        (None, Antialiasing::Mlaa(m)) => {
            let options = MlaaOptions { edges: *edges, masked };
            cpu::mlaa::mlaa_with_options(&img.data, (w, h), m, FilterPrecision::Exact, &options, inputs)?.output
        }
    };
    Ok(Image::from_vec(w, h, 4, data))
}

/// Peak memory (bytes) and wall time (s) of `rtbake run smaa|mlaa` on a `w`×`h` image, decoding and encoding
/// included (issue 15's budget check, before the pass): times measured with the release build on the project's 2-core
/// machine at 1024² on the CPU path (SMAA 0.41 s, MLAA 0.78 s), doubled; the GPU path takes a tenth of the CPU time
/// plus 1 s of device set-up and the same host buffers. Memory: 24 bytes per pixel + 32 MiB, from peak RSS measured
/// on the CPU path (4096²: SMAA 11 B/px, MLAA 14 B/px; SMAA at 16384²: 4.1 GB, 15.3 B/px), so the largest input
/// `--help` allows (16384², 6 GiB) is served under the default budget.
pub fn antialias_estimate(w: u32, h: u32, aa: &Antialiasing, gpu: bool) -> (u64, f64) {
    let px = w as f64 * h as f64;
    let cpu_s_per_px = match aa {
        Antialiasing::Smaa(_) => 0.8e-6,
        Antialiasing::Mlaa(_) => 1.6e-6,
    };
    let seconds = if gpu { 1.0 + 0.1 * cpu_s_per_px * px } else { 0.2 + cpu_s_per_px * px };
    (24 * w as u64 * h as u64 + (32 << 20), seconds)
}

/// [`antialias_estimate`] with the edge options of [`antialias_with`]: per pixel, 16 more bytes for a detector other
/// than plain luma (the CPU twin's per-pixel colour, 12 B), 8 for the depth (decoded f32 and the file) and 6 for a
/// mask (the byte and the composite); time as for luma plus 100 % for colour/predication (measured at 1080p on the
/// CPU path, dev profile, 2 cores: luma 100 ms, colour 161 ms, predicated luma 169 ms, depth 98 ms, mask 109 ms).
/// Peak RSS measured at 1080p on the CPU path: 37 MB plain, 68 MB with colour + predication + depth + mask (the
/// estimate says 83 MB and 145 MB).
pub fn antialias_estimate_with(
    w: u32,
    h: u32,
    aa: &Antialiasing,
    gpu: bool,
    edges: &EdgeSettings,
    masked: bool,
) -> (u64, f64) {
    let (bytes, seconds) = antialias_estimate(w, h, aa, gpu);
    let px = w as u64 * h as u64;
    let per_px = if edges.is_plain_luma() { 0 } else { 16 }
        + if edges.needs_depth() { 8 } else { 0 }
        + if masked { 6 } else { 0 };
    let slower =
        if edges.is_plain_luma() || edges.detector == super::smaa_edges::EdgeDetector::Depth { 1.0 } else { 2.0 };
    (bytes + per_px * px, seconds * slower)
}

/// Peak memory (bytes) and wall time (s) of `rtbake run sss` on a `w`×`h` frame, EXR decoding and encoding included:
/// measured with the release build on the project's 2-core machine at 1024² on the CPU path (separable 0.49 s and
/// 103 MB, sum of Gaussians 0.84 s and 136 MB), doubled; the GPU path as for [`antialias_estimate`]. The importance
/// pass is not measured: the separable figure scaled by its fetches (N samples against the separable's 2 × 17).
pub fn subsurface_estimate(w: u32, h: u32, method: &Subsurface, gpu: bool) -> (u64, f64) {
    let px = w as f64 * h as f64;
    let (cpu_s_per_px, bytes_per_px) = match method {
        Subsurface::Separable { .. } => (1.0e-6, 200),
        Subsurface::Gaussians { .. } => (1.7e-6, 260),
        // Measured at 1024² (release, CPU twin): 0.40 s at N = 40, 1.39 s at 200, 6.37 s at 1024 (5.9 ns per sample
        // and pixel) and 87 MB; doubled.
        Subsurface::Importance { samples, .. } => (0.15e-6 + 12e-9 * samples.offsets_mm.len() as f64, 200),
    };
    let seconds = if gpu { 1.0 + 0.1 * cpu_s_per_px * px } else { 0.2 + cpu_s_per_px * px };
    (bytes_per_px * w as u64 * h as u64 + (32 << 20), seconds)
}

/// A screen-space subsurface-scattering method with its baked data.
pub enum Subsurface<'a> {
    /// Separable SSS (thesis ch. 6) with a baked kernel.
    Separable { kernel: &'a SssKernel, params: &'a SssParams },
    /// Sum-of-Gaussians screen-space SSS (thesis ch. 4); `params.alpha` as stated for the 720-pixel viewport of
    /// eq. 4.1 — [`subsurface`] scales it to the image height.
    Gaussians { blurs: &'a GaussianBlurs, params: GaussianSssParams },
    /// Importance-sampled disk kernel (`crate::sss_sampling`), one pass.
    Importance { samples: &'a ImportanceSamples, params: &'a ImportanceSssParams },
}

/// Blurs linear RGBA f32 `rgba` (alpha = SSS strength) with linear depth `depth_linear` (one value per pixel, the
/// units of the kernel's / α's world scale) on `gpu`, or with the CPU reference when `gpu` is `None`.
pub fn subsurface(
    gpu: Option<&Gpu>,
    rgba: &[f32],
    depth_linear: &[f32],
    (w, h): (u32, u32),
    method: &Subsurface,
) -> Result<Vec<f32>, RuntimeError> {
    crate::error::check_size("--width/--height", w as u64, h as u64)?;
    Ok(match (gpu, method) {
        (Some(g), Subsurface::Separable { kernel, params }) => {
            SeparableSss::new(&g.device, w, h, kernel, params)?.run(&g.device, &g.queue, rgba, depth_linear)?
        }
        (None, Subsurface::Separable { kernel, params }) => {
            cpu::separable_sss::separable_sss(rgba, depth_linear, w, h, kernel, params)
        }
        (Some(g), Subsurface::Gaussians { blurs, params }) => {
            let gp = params.for_viewport_height(h);
            GaussianSss::new(&g.device, w, h, blurs, &gp)?.run(&g.device, &g.queue, rgba, depth_linear)?
        }
        (None, Subsurface::Gaussians { blurs, params }) => {
            cpu::gaussian_sss::gaussian_sss(rgba, depth_linear, w, h, blurs, &params.for_viewport_height(h))
        }
        (Some(g), Subsurface::Importance { samples, params }) => {
            ImportanceSss::new(&g.device, w, h, samples, params)?.run(&g.device, &g.queue, rgba, depth_linear)?
        }
        (None, Subsurface::Importance { samples, params }) => {
            samples.validate()?;
            params.validate()?;
            cpu::importance_sss::importance_sss(rgba, depth_linear, w, h, samples, params)
        }
    })
}

/// Monte Carlo photon transport ([`crate::transport::mc`]) on `gpu` ([`super::transport_gpu`], f32, the same
/// random streams) or with the CPU reference when `gpu` is `None`; `progress(fraction done)` as the run advances.
pub fn transport(
    gpu: Option<&Gpu>,
    stack: &crate::transport::McStack,
    settings: &crate::transport::McSettings,
    progress: &dyn Fn(f64),
) -> Result<crate::transport::McResult, RuntimeError> {
    match gpu {
        Some(g) => {
            super::transport_gpu::TransportGpu::new(&g.device)?.simulate(&g.device, &g.queue, stack, settings, progress)
        }
        None => Ok(crate::transport::mc::simulate_with_progress(stack, settings, progress)),
    }
}

/// Peak host memory (bytes) and an upper wall time (s) of [`transport`]: the CPU path's figures
/// ([`crate::transport::McSettings::time_estimate_seconds`] on `threads`) also bound a software adapter
/// (llvmpipe runs the shader on the same cores); a hardware GPU is faster, so the time is an upper estimate there.
pub fn transport_estimate(
    settings: &crate::transport::McSettings,
    layers: usize,
    gpu: bool,
    threads: usize,
) -> (u64, f64) {
    let bytes = if gpu {
        super::transport_gpu::memory_estimate_bytes(settings, layers)
    } else {
        settings.memory_estimate_bytes(layers)
    };
    (bytes, settings.time_estimate_seconds(threads))
}

/// SMAA 1x/S2x/T2x/4x over a frame sequence, on the GPU ([`super::smaa_modes::SmaaModes`]) or its CPU twin
/// ([`super::cpu::smaa_modes::SmaaModesCpu`]).
pub enum SmaaSequence<'g> {
    Gpu(&'g Gpu, Box<super::smaa_modes::SmaaModes>),
    Cpu(Box<super::cpu::smaa_modes::SmaaModesCpu>),
}

impl<'g> SmaaSequence<'g> {
    /// `gpu: None` = the CPU twin.
    pub fn new(
        gpu: Option<&'g Gpu>,
        (w, h): (u32, u32),
        luts: &super::smaa::SmaaTextures,
        mode: super::smaa_modes::SmaaMode,
        resolve: super::smaa_modes::TemporalResolve,
    ) -> Result<Self, RuntimeError> {
        Ok(match gpu {
            Some(g) => Self::Gpu(
                g,
                Box::new(super::smaa_modes::SmaaModes::new(&g.device, &g.queue, w, h, luts, mode, resolve)?),
            ),
            None => Self::Cpu(Box::new(super::cpu::smaa_modes::SmaaModesCpu::new(
                w,
                h,
                luts,
                super::cpu::FilterPrecision::Exact,
                mode,
                resolve,
            )?)),
        })
    }

    /// Runs one frame; returns the displayed image (RGBA8, sRGB-encoded, alpha 255).
    pub fn run_frame(&mut self, frame: &super::smaa_modes::ModeFrame<'_>) -> Result<Vec<u8>, RuntimeError> {
        let out = match self {
            Self::Gpu(g, p) => p.run_frame(&g.device, &g.queue, frame)?,
            Self::Cpu(p) => p.run_frame(frame)?,
        };
        Ok(super::smaa_modes::opaque(out))
    }
}
