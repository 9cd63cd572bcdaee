//! The shading of a skin frame resident on the GPU, as an engine records a frame: for a screen-space `run skin`
//! frame the G-buffer, the shadow map and the geometry computed from them (`frame_geometry`, with a scan's surface
//! maps, the wrinkle pass and MSAA), the rig's hemoglobin at the
//! mesh's uv when the frame leaves it here (`mesh_inputs::record_into_skin_maps`, writing H into the skin-inputs
//! maps), the skin-inputs pass, the lit diffuse layer, the SSS pass of the shader, the composite with post-scatter albedo (thesis §7.6) and the unblurred
//! specular layer, bloom (thesis ch. 4), the tone map and, with MSAA, the coverage blend are recorded into **one** command encoder, hand textures
//! and buffers from pass to pass on the device, and are submitted once; the host reads back only the final RGBA8
//! frame. The stages, their order and their arithmetic are those of [`crate::runtime::skin::lighting`]
//! (`lit_geometry`, `shade`, `composite`), which stays the CPU twin and the per-pass path (each pass submitted
//! and read back on its own, for inspection and A/B comparison): `render_geometry` picks one.
//!
//! With the geometry on the device, the skin-inputs pass is a compute pass (`SkinInputs::record_compute`) that
//! reads the geometry's maps and normals buffers and writes its two `Rgba16Float` images straight into the buffer
//! `shade_frame.wgsl` reads. Where a texture pass and a buffer pass meet, the data is converted on the device: with
//! the host's geometry the skin-inputs targets (`Rgba16Float`), and the SSS pass's output, are copied into buffers
//! with padded rows and unpacked by
//! `shade_frame.wgsl`, which also packs the lit layer as the SSS pass's half-float input (a buffer-to-texture copy).
//! `shade_frame.wgsl` runs through `compute_chain::record`, bloom through `bloom::record`.
//!
//! The frame's buffers, textures and uniform blocks come from the device's frame pool
//! ([`crate::runtime::frame_pool`]) and go back to it after the frame's submission and read-back, so a
//! steady-state frame allocates nothing; a reused buffer holds a former frame's data, so every pass writes what it
//! reads, and the RGBA8 frame starts as the uniform background colour filled on the device (an image background is
//! uploaded). `shade_on_device` leaves the frame on the device ([`DeviceFrame`], read back on demand).

use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::runtime::backend::Backend;
use crate::runtime::chain::{Antialiasing, Subsurface, SubsurfaceGpu};
use crate::runtime::compute_chain::{self, Stage};
use crate::runtime::device::Gpu;
use crate::runtime::gpu;
use crate::runtime::skin::bloom::{self, BloomBuffers};
use crate::runtime::skin::frame_geometry::{self, FrameGeometryJob};
use crate::runtime::skin::inputs::{maps_texels, MapsFrom, SkinInputs};
use crate::runtime::skin::lighting::{self, lit_geometry, subsurface_of, SssMethod};
use crate::runtime::skin::lighting::{DemoAssets, Geometry, KEY_LIGHT_INTENSITY, TRANSMITTANCE_INTENSITY};
use crate::runtime::skin::mesh_inputs::{self, RigAtUv};
use crate::runtime::RuntimeError;

thread_local! {
    static SHADING_IN_ONE_ENCODER: std::cell::Cell<bool> = const { std::cell::Cell::new(true) };
}

/// On a device, frames rendered on the calling thread record their shading into one command encoder with one
/// read-back (true, the default), or run each pass with its own submission and read-back (false: the per-pass
/// path, for inspecting the stages and for benchmarks that compare the two in one run). The CPU twins are the
/// same either way.
pub fn set_shading_in_one_encoder(on: bool) {
    SHADING_IN_ONE_ENCODER.with(|c| c.set(on));
}

/// Whether a frame rendered on `gpu` from this thread records its shading into one command encoder: on a device
/// with [`set_shading_in_one_encoder`] on. Such a frame leaves the rig at uv to that encoder too
/// ([`crate::runtime::skin::lighting::Geometry`]'s `rig_at_uv`).
pub(crate) fn shades_in_one_encoder(gpu: Backend<'_>) -> bool {
    gpu.is_gpu() && SHADING_IN_ONE_ENCODER.with(|c| c.get())
}

/// The shaded frame of `geo` over `background` (RGBA8 sRGB of the frame's size): the lit diffuse layer through
/// `method` (None: no SSS; the transmitted light is in that layer), tone-mapped and encoded.
pub(crate) fn render_geometry(
    gpu: Backend<'_>,
    geo: Geometry,
    assets: &DemoAssets,
    method: Option<SssMethod>,
    background: Vec<u8>,
    aa: Option<&Antialiasing>,
) -> Result<Image<u8>, RuntimeError> {
    // Both closures are FnOnce; the one that runs takes the frame.
    let parts = std::cell::Cell::new(Some((geo, background)));
    let take = || parts.take().expect("one backend runs");
    let per_pass = |(geo, background): (Geometry, Vec<u8>)| {
        if geo.rig_at_uv.is_some() {
            return Err(RuntimeError::Gpu("the rig at uv is left to a frame that is not shaded in one encoder".into()));
        }
        let lit = lit_geometry(gpu, geo, assets)?;
        lighting::shade(gpu, lit, assets, method, background, aa)
    };
    gpu.run(
        // On a device: every stage recorded into one command encoder, one read-back.
        |g| {
            if !SHADING_IN_ONE_ENCODER.with(|c| c.get()) {
                return per_pass(take());
            }
            let (geo, background) = take();
            let sss = subsurface_of(assets, method)?;
            shade(g, FrameSource::Host(&geo), assets, sss.as_ref(), Background::Image(background), aa)
        },
        || per_pass(take()),
    )
}

/// The shaded frame of `job` (see [`render_geometry`]) with its geometry rasterised and computed on the device in
/// the shading's own command encoder ([`FrameSource::Device`]): one submission, one read-back. Only for a frame
/// that [`shades_in_one_encoder`]; the CPU twins take the host's [`Geometry`].
pub(crate) fn render_on_device(
    gpu: Backend<'_>,
    job: &FrameGeometryJob<'_>,
    assets: &DemoAssets,
    method: Option<SssMethod>,
    background: Background,
) -> Result<Image<u8>, RuntimeError> {
    gpu.run(
        |g| shade(g, FrameSource::Device(job), assets, subsurface_of(assets, method)?.as_ref(), background, None),
        || Err(RuntimeError::Gpu("a frame whose geometry is computed on the device needs a device".into())),
    )
}

const SOURCE: &str = concat!(include_str!("../aa/srgb.wgsl"), include_str!("shade_frame.wgsl"));

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    size: [f32; 4],
    key: [f32; 4],
    cfg: [f32; 4],
    cover: [f32; 4],
    fill: [f32; 4],
}

/// Per pixel of `geo` the two vec4 `shade_frame.wgsl` reads: (view-space normal, skin 1/0), (albedo map, specular).
fn geometry_texels(geo: &Geometry) -> Vec<f32> {
    let n = geo.skin.len();
    let mut out = vec![0.0f32; 8 * n];
    for (i, px) in out.chunks_exact_mut(8).enumerate() {
        let nv = geo.frame.normals[i];
        px[..3].copy_from_slice(&nv);
        px[3] = if geo.skin[i] { 1.0 } else { 0.0 };
        if let Some(a) = &geo.albedo {
            px[4..7].copy_from_slice(&a[i]);
        }
        px[7] = geo.specular.as_ref().map_or(0.0, |s| s[i]);
    }
    out
}

/// Where a frame's geometry comes from: the host's [`Geometry`] (the reference), or the device's, rasterised and
/// computed in the frame's own command encoder (`frame_geometry`, with a scan's surface maps, the wrinkle pass and
/// MSAA: no G-buffer read-back).
pub(crate) enum FrameSource<'a> {
    Host(&'a Geometry),
    Device(&'a FrameGeometryJob<'a>),
}

/// What a frame is drawn over: one colour (RGBA8 sRGB; filled on the device, nothing uploaded) or an image
/// (RGBA8 sRGB of the frame's size, uploaded).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Background {
    Uniform([u8; 4]),
    Image(Vec<u8>),
}

/// A shaded frame left on the device: its RGBA8 sRGB texels (row-major, top row first, tightly packed) in a
/// buffer of the frame pool, which goes back to the pool when this is dropped
/// ([`crate::runtime::frame_pool::FrameScope::detach`]). Nothing is read back until [`DeviceFrame::read_back`].
#[derive(Debug)]
pub struct DeviceFrame {
    rgba: crate::runtime::frame_pool::PooledBuffer,
    width: u32,
    height: u32,
}

impl DeviceFrame {
    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The buffer holding the frame's RGBA8 texels (at least 4·width·height bytes; storage, copy source).
    pub fn buffer(&self) -> &wgpu::Buffer {
        self.rgba.buffer()
    }

    /// Copies the frame to the host (one submission, one read-back, counted in
    /// [`gpu::read_backs_on_this_thread`]).
    pub fn read_back(&self, g: &Gpu) -> Result<Image<u8>, RuntimeError> {
        let n = 4 * self.width as u64 * self.height as u64;
        let _frame = crate::runtime::frame_pool::FrameScope::open(&g.device, &g.queue);
        let readback = crate::runtime::frame_pool::readback_buffer(&g.device, self.buffer().size());
        let mut enc = g.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
        enc.copy_buffer_to_buffer(self.buffer(), 0, &readback, 0, self.buffer().size());
        gpu::submit(&g.queue, enc.finish());
        let mut out = gpu::map_read(&g.device, &readback)?;
        out.truncate(n as usize);
        Ok(Image::from_vec(self.width, self.height, 4, out))
    }
}

thread_local! {
    static HOST_SPLIT: std::cell::Cell<Option<HostSplit>> = const { std::cell::Cell::new(None) };
}

/// Where the host's time of the last one-encoder frame on this thread went, ms: recording and submitting its
/// commands, waiting for the GPU, and copying the read-back out of the mapped buffer (0 for a frame left on the
/// device, whose wait is the caller's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostSplit {
    pub record_submit_ms: f64,
    pub wait_ms: f64,
    pub copy_ms: f64,
}

/// The host split of the last one-encoder frame shaded on this thread (None before the first).
pub fn last_host_split() -> Option<HostSplit> {
    HOST_SPLIT.with(|c| c.get())
}

/// The frame of `source` shaded through `sss` (None: no SSS pass) over `background`, with `assets`' tables,
/// lights, post-scatter switch and bloom: one submission, one read-back (the RGBA8 frame).
pub(crate) fn shade(
    g: &Gpu,
    source: FrameSource<'_>,
    assets: &DemoAssets,
    sss: Option<&Subsurface>,
    background: Background,
    aa: Option<&Antialiasing>,
) -> Result<Image<u8>, RuntimeError> {
    let t0 = std::time::Instant::now();
    let (device, queue) = (&g.device, &g.queue);
    // The frame's buffers and textures come from the device's pool and go back to it when this closes, after
    // the read-back.
    let _frame = crate::runtime::frame_pool::FrameScope::open(device, queue);
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let (mut enc, rgba, (w, h)) = record(g, source, assets, sss, background)?;
    if let Some(aa) = aa {
        // The demo's SMAA/MLAA on the frame in the same encoder: still one submission and one read-back.
        crate::runtime::chain::record_antialias(g, &mut enc, &rgba, (w, h), aa)?;
    }
    let readback = crate::runtime::frame_pool::readback_buffer(device, rgba.size());
    enc.copy_buffer_to_buffer(&rgba, 0, &readback, 0, rgba.size());
    gpu::submit(queue, enc.finish());
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(RuntimeError::Gpu(format!("skin frame: {e}")));
    }
    let t1 = std::time::Instant::now();
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| RuntimeError::Gpu(format!("poll: {e}")))?;
    let t2 = std::time::Instant::now();
    let mut out = gpu::map_read(device, &readback)?;
    out.truncate(4 * w as usize * h as usize);
    let ms = |a: std::time::Instant, b: std::time::Instant| (b - a).as_secs_f64() * 1e3;
    let split =
        HostSplit { record_submit_ms: ms(t0, t1), wait_ms: ms(t1, t2), copy_ms: ms(t2, std::time::Instant::now()) };
    HOST_SPLIT.with(|c| c.set(Some(split)));
    Ok(Image::from_vec(w, h, 4, out))
}

/// [`shade`] without the read-back: the frame is submitted and left on the device ([`DeviceFrame`]).
pub(crate) fn shade_on_device(
    g: &Gpu,
    source: FrameSource<'_>,
    assets: &DemoAssets,
    sss: Option<&Subsurface>,
    background: Background,
) -> Result<DeviceFrame, RuntimeError> {
    let t0 = std::time::Instant::now();
    let (device, queue) = (&g.device, &g.queue);
    let frame = crate::runtime::frame_pool::FrameScope::open(device, queue);
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let (enc, rgba, (width, height)) = record(g, source, assets, sss, background)?;
    gpu::submit(queue, enc.finish());
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(RuntimeError::Gpu(format!("skin frame: {e}")));
    }
    let record_submit_ms = t0.elapsed().as_secs_f64() * 1e3;
    HOST_SPLIT.with(|c| c.set(Some(HostSplit { record_submit_ms, wait_ms: 0.0, copy_ms: 0.0 })));
    Ok(DeviceFrame { rgba: frame.detach(rgba), width, height })
}

/// Records the frame of `source` (see [`shade`]) into a new command encoder: the encoder, the RGBA8 buffer the
/// frame ends in (tightly packed rows) and the frame's size. Every buffer and texture comes from the frame pool
/// when a frame is open ([`crate::runtime::frame_pool`]): each pass below writes every texel it or a later pass
/// reads before reading it, and the one buffer that starts with content, the RGBA8 frame, is filled first (the
/// background colour by the `background` entry point, or the uploaded image).
fn record(
    g: &Gpu,
    source: FrameSource<'_>,
    assets: &DemoAssets,
    sss: Option<&Subsurface>,
    background: Background,
) -> Result<(wgpu::CommandEncoder, wgpu::Buffer, (u32, u32)), RuntimeError> {
    let (device, queue) = (&g.device, &g.queue);
    let has_albedo = match &source {
        FrameSource::Host(geo) => geo.albedo.is_some(),
        FrameSource::Device(job) => job.has_albedo_map(),
    };
    // With MSAA on the device, partly covered pixels are blended with the background after the tone map.
    let blend_coverage = matches!(&source, FrameSource::Device(job) if job.msaa > 1);
    let (w, h) = match &source {
        FrameSource::Host(geo) => (geo.frame.width, geo.frame.height),
        FrameSource::Device(job) => (job.width, job.height),
    };
    let n = w as u64 * h as u64;
    if let Background::Image(b) = &background {
        if b.len() as u64 != 4 * n {
            return Err(InvalidInput::new("background", format!("must be {w}x{h} RGBA8")).into());
        }
    }
    let what = "skin frame";
    // The fragment pass's textures only where the host's geometry is uploaded into them.
    let mut inputs = match &source {
        FrameSource::Host(_) => SkinInputs::new(device, queue, w, h, &assets.luts, &assets.rig)?,
        FrameSource::Device(_) => SkinInputs::for_compute(device, w, h, &assets.luts, &assets.rig)?,
    };
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(what) });
    gpu::profile_mark(device, &mut enc, "frame start");
    let blur = match sss {
        Some(m) => Some(SubsurfaceGpu::new(g, (w, h), m)?),
        None => None,
    };
    let (light, weights) = (assets.lights.back_view, &assets.rig_weights);
    // The skin-inputs maps and normals as buffers (the device's geometry: the compute pass reads them), or None
    // (the host's: uploaded into the fragment pass's textures).
    let mut maps_normals = None;
    let (geo_buf, coverage) = match source {
        FrameSource::Host(geo) => {
            match (&geo.rig_at_uv, &assets.baked_rig) {
                (Some(px), Some(r)) => {
                    // The rig's H at the mesh's uv goes into the skin-inputs maps on the device.
                    inputs.upload(queue, &geo.frame, weights, light, MapsFrom::Device)?;
                    let maps = RigAtUv { rig: &r.rig, h0: &r.h0, pose: &px.pose };
                    let texels = maps_texels(&geo.frame);
                    let target = inputs.maps();
                    mesh_inputs::record_into_skin_maps(
                        device, &mut enc, w, h, &px.uv, &geo.skin, &maps, &texels, target,
                    )?;
                }
                (Some(_), None) => {
                    return Err(InvalidInput::new("hemoglobin rig", "the rig at uv needs a baked rig").into())
                }
                (None, _) => inputs.upload(queue, &geo.frame, weights, light, MapsFrom::Frame)?,
            }
            if let Some(b) = &blur {
                b.upload_depth(queue, &geo.depth)?;
            }
            let texels = geometry_texels(geo);
            let texels = compute_chain::storage_buffer(device, what, 32 * n, Some(bytemuck::cast_slice(&texels)));
            // The host blends its coverage after the read-back (`heads::blend_coverage`): nothing to bind.
            (texels, compute_chain::storage_buffer(device, what, 16, None))
        }
        FrameSource::Device(job) => {
            let d = frame_geometry::record(device, &mut enc, job, assets)?;
            inputs.upload_lights(queue, weights, light)?;
            d.record_rig_at_uv(device, &mut enc, job, assets)?;
            maps_normals = Some((d.skin_maps, d.normals));
            if let Some(b) = &blur {
                gpu::encode_buffer_to_texture(&mut enc, &d.depth, 0, b.depth());
            }
            (d.texels, d.uvc)
        }
    };
    let bloom_buffers = match &assets.bloom {
        Some(p) => Some(BloomBuffers::new(device, w, h, p)?),
        None => None,
    };
    // Half-float images (the skin-inputs targets, the SSS frame) share one padded row: all are w×h Rgba16Float.
    let row = inputs.half_row_bytes();
    let sizes = [2 * row * h as u64, 32 * n, 16 * n, row * h as u64, 16 * n, 16, 4 * n];
    compute_chain::check_buffers(device, what, &sizes)?;
    let make = |k: usize| crate::runtime::frame_pool::storage_buffer(device, what, sizes[k]);
    let skin16 = make(0);
    let diffuse = make(2);
    let sss16 = make(3);
    let rgba = make(6);
    // Bloom reads the HDR frame from its first buffer and leaves its result in its last.
    let (hdr, bloomed) = match &bloom_buffers {
        Some(b) => (b.0[0].clone(), b.0[3].clone()),
        None => (make(4), make(5)),
    };
    let key = assets.lights.key_view;
    let flag = |b: bool| if b { 1.0 } else { 0.0 };
    let uniform_bg = match &background {
        Background::Uniform(c) => Some(*c),
        Background::Image(_) => None,
    };
    let params = Params {
        size: [w as f32, h as f32, (row / 4) as f32, flag(assets.post_scatter_albedo)],
        key: [key[0], key[1], key[2], flag(has_albedo)],
        cfg: [KEY_LIGHT_INTENSITY, TRANSMITTANCE_INTENSITY, flag(bloom_buffers.is_some()), flag(blur.is_some())],
        cover: {
            let bg = crate::runtime::skin::heads::BACKGROUND.map(|c| c as f32 / 255.0);
            [bg[0], bg[1], bg[2], flag(blend_coverage)]
        },
        fill: uniform_bg.unwrap_or([0; 4]).map(|c| c as f32 / 255.0),
    };
    let bound = [&skin16, &geo_buf, &diffuse, &sss16, &hdr, &bloomed, &rgba, &coverage];
    let groups = compute_chain::groups_8x8(w, h);
    let stages = |names: &[&'static str]| names.iter().map(|e| Stage::new(e, groups)).collect::<Vec<_>>();
    let uniform = bytemuck::bytes_of(&params);
    // The RGBA8 frame starts as the background: filled on the device (a reused buffer holds a former frame), or
    // the image uploaded.
    match &background {
        Background::Uniform(_) => {
            compute_chain::record(device, &mut enc, what, SOURCE, uniform, &bound, &stages(&["background"]))
        }
        Background::Image(b) => queue.write_buffer(&rgba, 0, b),
    }
    match &maps_normals {
        Some((maps, normals)) => inputs.record_compute(device, &mut enc, [maps, normals], &skin16),
        None => {
            inputs.encode(&mut enc);
            gpu::encode_texture_to_buffer(&mut enc, inputs.albedo(), &skin16, 0);
            gpu::encode_texture_to_buffer(&mut enc, inputs.transmitted(), &skin16, row * h as u64);
        }
    }
    match &blur {
        Some(b) => {
            compute_chain::record(device, &mut enc, what, SOURCE, uniform, &bound, &stages(&["lit", "pack"]));
            gpu::encode_buffer_to_texture(&mut enc, &sss16, 0, b.input());
            b.encode(&mut enc);
            gpu::encode_texture_to_buffer(&mut enc, b.output(), &sss16, 0);
            compute_chain::record(device, &mut enc, what, SOURCE, uniform, &bound, &stages(&["composite"]));
        }
        None => compute_chain::record(device, &mut enc, what, SOURCE, uniform, &bound, &stages(&["lit", "composite"])),
    }
    if let (Some(p), Some(b)) = (&assets.bloom, &bloom_buffers) {
        bloom::record(device, &mut enc, w, h, p, b);
    }
    let last: &[&str] = if blend_coverage { &["tonemap", "coverage"] } else { &["tonemap"] };
    compute_chain::record(device, &mut enc, what, SOURCE, uniform, &bound, &stages(last));
    Ok((enc, rgba, (w, h)))
}
