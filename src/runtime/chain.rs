//! Whole-image entry points used by the command and the demo: run a pass on the [`Backend`] the caller names (the
//! GPU pass or its CPU twin) on an `Image<u8>` or linear f32 frame, return the result. Pure with respect to files
//! (the caller reads and writes them).

use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::runtime::aa::edges::{AaInputs, EdgeSettings};
use crate::runtime::aa::mlaa::{Mlaa, MlaaAreaMap, MlaaOptions};
use crate::runtime::aa::mlaa_cpu;
use crate::runtime::aa::modes::{opaque, ModeFrame, SmaaMode, SmaaModes, TemporalResolve};
use crate::runtime::aa::modes_cpu::SmaaModesCpu;
use crate::runtime::aa::smaa::{Smaa, SmaaOptions, SmaaTextures};
use crate::runtime::aa::smaa_cpu;
use crate::runtime::backend::{Backend, Prepared};
use crate::runtime::device::Gpu;
use crate::runtime::loader::BakedRig;
use crate::runtime::sampler::FilterPrecision;
use crate::runtime::skin::bloom::{self, BloomParams};
use crate::runtime::skin::mesh_inputs::{self, RigAtUv, RigPose};
use crate::runtime::skin::mesh_raster::MeshGBuffer;
use crate::runtime::skin::wrinkles::{self, WrinkleMaps};
use crate::runtime::skin::{bloom_cpu, mesh_inputs_cpu, wrinkles_cpu};
use crate::runtime::sss::gaussian::{GaussianBlurs, GaussianSss, GaussianSssParams};
use crate::runtime::sss::importance::{ImportanceSamples, ImportanceSss, ImportanceSssParams};
use crate::runtime::sss::separable::{SeparableSss, SssKernel, SssParams};
use crate::runtime::sss::separable_tiled::SeparableSssTiled;
use crate::runtime::sss::{self, gaussian_cpu, importance_cpu, separable_cpu, PassShape};
use crate::runtime::transport::mc_gpu::TransportGpu;
use crate::runtime::RuntimeError;

/// A morphological antialiasing method with its lookup textures.
pub enum Antialiasing {
    Smaa(SmaaTextures),
    Mlaa(MlaaAreaMap),
}

/// Converts a decoded 8-bit image with 1–4 channels to RGBA8 (grey replicated, missing alpha = 255).
pub fn to_rgba8(img: &Image<u8>) -> Result<Image<u8>, InvalidInput> {
    let ch = img.channels as usize;
    if !(1..=4).contains(&ch) {
        return Err(InvalidInput::new("input", format!("must have 1 to 4 channels, got {ch}")));
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
pub fn antialias<'g>(
    gpu: impl Into<Backend<'g>>,
    img: &Image<u8>,
    aa: &Antialiasing,
) -> Result<Image<u8>, RuntimeError> {
    if img.channels != 4 {
        return Err(InvalidInput::new("image", format!("must be RGBA8, got {} channels", img.channels)).into());
    }
    let (w, h) = (img.width, img.height);
    crate::error::check_size("input", w as u64, h as u64)?;
    let gpu = gpu.into();
    let data = match aa {
        Antialiasing::Smaa(t) => gpu.run(
            |g| Smaa::new(&g.device, &g.queue, w, h, t)?.run(&g.device, &g.queue, &img.data),
            || Ok(smaa_cpu::smaa(&img.data, w, h, t, FilterPrecision::Exact).output),
        )?,
        Antialiasing::Mlaa(m) => gpu.run(
            |g| Mlaa::new(&g.device, &g.queue, w, h, m)?.run(&g.device, &g.queue, &img.data),
            || Ok(mlaa_cpu::mlaa(&img.data, w, h, m, FilterPrecision::Exact).output),
        )?,
    };
    Ok(Image::from_vec(w, h, 4, data))
}

/// Records `aa` into `enc` over a frame already on the device, leaving the antialiased frame in its place: `frame`
/// holds `w`×`h` packed RGBA8 pixels (sRGB-encoded, top row first; see
/// [`ThreePass::encode_on_buffer`](crate::runtime::aa::three_pass::ThreePass::encode_on_buffer)). The device form of
/// [`antialias`] (the same bytes) for a frame shaded in `enc`: no submission and no read-back of its own.
pub fn record_antialias(
    g: &Gpu,
    enc: &mut wgpu::CommandEncoder,
    frame: &wgpu::Buffer,
    (w, h): (u32, u32),
    aa: &Antialiasing,
) -> Result<(), RuntimeError> {
    crate::error::check_size("input", w as u64, h as u64)?;
    match aa {
        Antialiasing::Smaa(t) => Smaa::new(&g.device, &g.queue, w, h, t)?.encode_on_buffer(&g.device, enc, frame)?,
        Antialiasing::Mlaa(m) => Mlaa::new(&g.device, &g.queue, w, h, m)?.encode_on_buffer(&g.device, enc, frame)?,
    }
    Ok(())
}

/// As [`antialias`] with an edge detector other than luma, predicated thresholding and/or a matte/stencil mask
/// ([`crate::runtime::aa::edges`]): `inputs.depth` when `edges` need it, `inputs.mask` (one byte per pixel, ≥ 128 = inside)
/// masks the pass when present.
pub fn antialias_with<'g>(
    gpu: impl Into<Backend<'g>>,
    img: &Image<u8>,
    aa: &Antialiasing,
    edges: &EdgeSettings,
    inputs: &AaInputs,
) -> Result<Image<u8>, RuntimeError> {
    if img.channels != 4 {
        return Err(InvalidInput::new("image", format!("must be RGBA8, got {} channels", img.channels)).into());
    }
    let (w, h) = (img.width, img.height);
    crate::error::check_size("input", w as u64, h as u64)?;
    let masked = inputs.mask.is_some();
    let gpu = gpu.into();
    let exact = FilterPrecision::Exact;
    let data = match aa {
        Antialiasing::Smaa(t) => {
            let options = SmaaOptions { edges: *edges, masked, ..Default::default() };
            gpu.run(
                |g| {
                    Smaa::with_options(&g.device, &g.queue, w, h, t, &options)?
                        .run_with(&g.device, &g.queue, &img.data, inputs)
                },
                || Ok(smaa_cpu::smaa_with_options(&img.data, (w, h), t, exact, &options, inputs)?.output),
            )?
        }
        Antialiasing::Mlaa(m) => {
            let options = MlaaOptions { edges: *edges, masked };
            gpu.run(
                |g| {
                    Mlaa::with_options(&g.device, &g.queue, w, h, m, &options)?
                        .run_with(&g.device, &g.queue, &img.data, inputs)
                },
                || Ok(mlaa_cpu::mlaa_with_options(&img.data, (w, h), m, exact, &options, inputs)?.output),
            )?
        }
    };
    Ok(Image::from_vec(w, h, 4, data))
}

/// Peak memory (bytes) and wall time (s) of `rtbake run smaa|mlaa` on a `w`×`h` image, decoding and encoding
/// included (the budget check, before the pass): times measured with the release build on the project's 2-core
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
    let slower = if edges.is_plain_luma() || edges.detector == crate::runtime::aa::edges::EdgeDetector::Depth {
        1.0
    } else {
        2.0
    };
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
pub fn subsurface<'g>(
    gpu: impl Into<Backend<'g>>,
    rgba: &[f32],
    depth_linear: &[f32],
    (w, h): (u32, u32),
    method: &Subsurface,
) -> Result<Vec<f32>, RuntimeError> {
    crate::error::check_size("width/height", w as u64, h as u64)?;
    let gpu = gpu.into();
    match method {
        Subsurface::Separable { kernel, params } => gpu.run(
            |g| SubsurfaceGpu::new(g, (w, h), method)?.run(g, rgba, depth_linear),
            || Ok(separable_cpu::separable_sss(rgba, depth_linear, w, h, kernel, params)),
        ),
        Subsurface::Gaussians { blurs, params } => gpu.run(
            |g| SubsurfaceGpu::new(g, (w, h), method)?.run(g, rgba, depth_linear),
            || Ok(gaussian_cpu::gaussian_sss(rgba, depth_linear, w, h, blurs, &params.for_viewport_height(h))),
        ),
        Subsurface::Importance { samples, params } => gpu.run(
            |g| SubsurfaceGpu::new(g, (w, h), method)?.run(g, rgba, depth_linear),
            || {
                samples.validate()?;
                params.validate()?;
                Ok(importance_cpu::importance_sss(rgba, depth_linear, w, h, samples, params))
            },
        ),
    }
}

/// The GPU pass [`subsurface`] runs for a method, built for one frame size: its input, output and recorded passes
/// ([`crate::runtime::sss::SssPass`]), so a frame can record it into its own command encoder.
pub(crate) enum SubsurfaceGpu {
    Separable(SeparableSss),
    Tiled(SeparableSssTiled),
    Gaussians(Box<GaussianSss>),
    Importance(ImportanceSss),
}

/// `$body` with `$p` bound to the [`crate::runtime::sss::SssPass`] of any [`SubsurfaceGpu`].
macro_rules! with_pass {
    ($s:expr, $p:ident => $body:expr) => {
        match $s {
            SubsurfaceGpu::Separable($p) => $body,
            SubsurfaceGpu::Tiled($p) => $body,
            SubsurfaceGpu::Gaussians($p) => $body,
            SubsurfaceGpu::Importance($p) => $body,
        }
    };
}

impl SubsurfaceGpu {
    /// The pass of `method` for a `w`×`h` frame on `g`.
    pub(crate) fn new(g: &Gpu, (w, h): (u32, u32), method: &Subsurface) -> Result<Self, RuntimeError> {
        let d = &g.device;
        // Compute passes on GPUs; the fragment passes on software adapters, where workgroup barriers are emulated
        // and the tiles are slower (same arithmetic, same twin); `RTBAKE_SSS_PASSES` overrides either.
        let shape = sss::shape_for_adapter(g.is_software())?;
        Ok(match method {
            Subsurface::Separable { kernel, params } if shape == PassShape::Fragment => {
                Self::Separable(SeparableSss::new(d, w, h, kernel, params)?)
            }
            Subsurface::Separable { kernel, params } => Self::Tiled(SeparableSssTiled::new(d, w, h, kernel, params)?),
            // The α·h/720 viewport scaling of eq. 4.1, the same for both backends.
            Subsurface::Gaussians { blurs, params } => Self::Gaussians(Box::new(GaussianSss::with_shape(
                d,
                (w, h),
                blurs,
                &params.for_viewport_height(h),
                shape,
            )?)),
            Subsurface::Importance { samples, params } => {
                Self::Importance(ImportanceSss::with_shape(d, (w, h), samples, params, shape)?)
            }
        })
    }

    /// Uploads a frame, runs the pass and reads back RGBA f32.
    pub(crate) fn run(&self, g: &Gpu, rgba: &[f32], depth: &[f32]) -> Result<Vec<f32>, RuntimeError> {
        with_pass!(self, p => p.run(&g.device, &g.queue, rgba, depth))
    }

    /// The irradiance input (`Rgba16Float`).
    pub(crate) fn input(&self) -> &wgpu::Texture {
        with_pass!(self, p => p.input())
    }

    /// The blurred result (`Rgba16Float`).
    pub(crate) fn output(&self) -> &wgpu::Texture {
        with_pass!(self, p => p.output())
    }

    /// Uploads the linear depth alone.
    pub(crate) fn upload_depth(&self, queue: &wgpu::Queue, depth: &[f32]) -> Result<(), InvalidInput> {
        with_pass!(self, p => p.upload_depth(queue, depth))
    }

    /// The linear depth the pass reads (`R32Float`).
    pub(crate) fn depth(&self) -> &wgpu::Texture {
        with_pass!(self, p => p.depth())
    }

    /// Records the pass.
    pub(crate) fn encode(&self, enc: &mut wgpu::CommandEncoder) {
        with_pass!(self, p => p.encode(enc, None))
    }
}

/// Monte Carlo photon transport ([`crate::transport::mc`]) on `gpu` ([`crate::runtime::transport::mc_gpu`], f32, the same
/// random streams) or with the CPU reference when `gpu` is `None`; `progress(fraction done)` as the run advances.
pub fn transport<'g>(
    gpu: impl Into<Backend<'g>>,
    stack: &crate::transport::McStack,
    settings: &crate::transport::McSettings,
    progress: &dyn Fn(f64),
) -> Result<crate::transport::McResult, RuntimeError> {
    gpu.into().run(
        |g| TransportGpu::new(&g.device)?.simulate(&g.device, &g.queue, stack, settings, progress),
        || Ok(crate::transport::mc::simulate_with_progress(stack, settings, progress)),
    )
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
        crate::runtime::transport::mc_gpu::memory_estimate_bytes(settings, layers)
    } else {
        settings.memory_estimate_bytes(layers)
    };
    (bytes, settings.time_estimate_seconds(threads))
}

/// SMAA 1x/S2x/T2x/4x over a frame sequence, on the GPU ([`SmaaModes`]) or its CPU twin ([`SmaaModesCpu`]).
pub struct SmaaSequence<'g>(Prepared<'g, Box<SmaaModes>, Box<SmaaModesCpu>>);

impl<'g> SmaaSequence<'g> {
    /// `gpu: None` = the CPU twin.
    pub fn new(
        gpu: impl Into<Backend<'g>>,
        (w, h): (u32, u32),
        luts: &SmaaTextures,
        mode: SmaaMode,
        resolve: TemporalResolve,
    ) -> Result<Self, RuntimeError> {
        let exact = FilterPrecision::Exact;
        Ok(Self(gpu.into().prepare(
            |g| Ok(Box::new(SmaaModes::new(&g.device, &g.queue, w, h, luts, mode, resolve)?)),
            || Ok(Box::new(SmaaModesCpu::new(w, h, luts, exact, mode, resolve)?)),
        )?))
    }

    /// Runs one frame; returns the displayed image (RGBA8, sRGB-encoded, alpha 255).
    pub fn run_frame(&mut self, frame: &ModeFrame<'_>) -> Result<Vec<u8>, RuntimeError> {
        let out = self.0.run(|g, p| p.run_frame(&g.device, &g.queue, frame), |p| Ok(p.run_frame(frame)?))?;
        Ok(opaque(out))
    }
}

/// Bloom ([`crate::runtime::skin::bloom::bloom`]) on `gpu`, or its CPU twin.
pub fn bloom_for<'g>(
    gpu: impl Into<Backend<'g>>,
    width: u32,
    height: u32,
    hdr_rgba: &[f32],
    p: &BloomParams,
) -> Result<Vec<f32>, RuntimeError> {
    gpu.into().run(
        |g| bloom::bloom(&g.device, &g.queue, width, height, hdr_rgba, p),
        || Ok(bloom_cpu::bloom(width, height, hdr_rgba, p)?),
    )
}

/// H per pixel of the G-buffer `g` for the baked rig in `pose` ([`mesh_inputs::hemoglobin_at_uv`]) on `gpu`, or its
/// CPU twin.
pub fn hemoglobin_for_gbuffer<'g>(
    gpu: impl Into<Backend<'g>>,
    g: &MeshGBuffer,
    rig: &BakedRig,
    pose: &RigPose,
) -> Result<Vec<f32>, RuntimeError> {
    let maps = RigAtUv { rig: &rig.rig, h0: &rig.h0, pose };
    gpu.into().run(
        |d| mesh_inputs::hemoglobin_at_uv(&d.device, &d.queue, g.width, g.height, &g.uv, &g.covered, &maps),
        || mesh_inputs_cpu::hemoglobin_at_uv(&g.uv, &g.covered, &maps),
    )
}

/// The wrinkle pass's normals ([`wrinkles::wrinkled_normals`]) on `gpu`, or its CPU twin.
pub fn wrinkled_normals_for<'g>(
    gpu: impl Into<Backend<'g>>,
    g: &MeshGBuffer,
    maps: &WrinkleMaps,
    weights: &[f32; 8],
) -> Result<Vec<[f32; 3]>, RuntimeError> {
    gpu.into().run(
        |d| wrinkles::wrinkled_normals(&d.device, &d.queue, g, maps, weights),
        || Ok(wrinkles_cpu::wrinkled_normals(g, maps, weights)?),
    )
}

/// The scan's surface maps at the G-buffer's uv ([`crate::runtime::skin::surface_maps`]) on `gpu`.
pub fn surface_pixels_for<'g>(
    gpu: impl Into<Backend<'g>>,
    g: &MeshGBuffer,
    maps: &crate::runtime::skin::surface_maps::SurfaceMaps,
) -> Result<crate::runtime::skin::surface_maps::SurfacedPixels, RuntimeError> {
    gpu.into().run(
        |d| crate::runtime::skin::surface_maps::surface_pixels(&d.device, &d.queue, g, maps),
        || Ok(crate::runtime::skin::surface_maps_cpu::surface_pixels(g, maps)),
    )
}
