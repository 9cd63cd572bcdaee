//! The mesh G-buffer pass of the skin renderer (TAP 2009 §5 renders heads, thesis ch. 3–5 shades them):
//! a wgpu render pipeline with a `Depth32Float` depth buffer (less-than test, back faces culled, counter-clockwise
//! front faces) that writes per pixel the view-space unit normal and the linear view depth in mm
//! (`Rgba16Float`), the texture coordinates with a coverage flag (`Rgba16Float`) and the view-space tangent of
//! [`crate::mesh::tangents`] with its handedness (`Rgba16Float`, interpolated, not renormalised) — the inputs the
//! screen-space passes, texture-space diffusion and the wrinkle pass need. Its CPU twin is [`crate::runtime::skin::mesh_raster_cpu`]; both return a
//! [`MeshGBuffer`].
//!
//! MSAA ([`RasterJob::samples`] 4, `run skin --msaa 4`): multisampled targets and depth buffer, the
//! fragment shaded once per pixel at its centre and stored in the samples it covers, the hardware resolve averaging
//! the samples; uncovered samples hold zeros, so the resolved coverage flag is the covered fraction and the
//! attributes divided by it are the mean over the covered samples (the normal renormalised). 4× needs
//! `MULTISAMPLE_X4` and `MULTISAMPLE_RESOLVE` for `Rgba16Float` and `Depth32Float`, checked through the formats'
//! guaranteed `TextureFormatFeatures` for the device's features.

use crate::error::InvalidInput;
use crate::mesh::camera::Camera;
use crate::mesh::Mesh;
use crate::runtime::frame_pool;
use crate::runtime::gpu;
use crate::runtime::RuntimeError;
use wgpu::util::DeviceExt;

/// A rasterised mesh, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshGBuffer {
    pub width: u32,
    pub height: u32,
    /// View-space unit normal (camera looks down −z); zero where nothing is covered.
    pub normal_view: Vec<[f32; 3]>,
    /// Linear view depth, mm (distance along the view axis); 0 where nothing is covered.
    pub depth_mm: Vec<f32>,
    pub uv: Vec<[f32; 2]>,
    pub covered: Vec<bool>,
    /// View-space tangent (xyz, interpolated: not unit, not exactly perpendicular to the normal) and handedness w
    /// ([`crate::mesh::tangents`]); zero where nothing is covered.
    pub tangent_view: Vec<[f32; 4]>,
    /// Covered fraction of the pixel: 0 or 1 with one sample, k/4 with 4× MSAA.
    pub coverage: Vec<f32>,
}

impl MeshGBuffer {
    pub(crate) fn empty(width: u32, height: u32) -> Self {
        let n = (width * height) as usize;
        MeshGBuffer {
            width,
            height,
            normal_view: vec![[0.0; 3]; n],
            depth_mm: vec![0.0; n],
            uv: vec![[0.0; 2]; n],
            covered: vec![false; n],
            tangent_view: vec![[0.0; 4]; n],
            coverage: vec![0.0; n],
        }
    }
}

/// Column-major camera uniform: view-projection, view, (mm per unit, 0, 0, 0).
pub(crate) fn camera_uniform(mesh: &Mesh, camera: &Camera, width: u32, height: u32) -> [f32; 36] {
    let view = camera.view();
    let vp = camera.projection(width as f32 / height as f32) * view;
    let mut u = [0.0f32; 36];
    u[..16].copy_from_slice(vp.as_slice());
    u[16..32].copy_from_slice(view.as_slice());
    u[32] = mesh.mm_per_unit;
    u
}

/// Sample counts of the G-buffer raster (`--msaa`).
pub const SAMPLE_COUNTS: [u32; 2] = [1, 4];

/// The G-buffer's targets: normal+depth, uv+coverage and tangent, each RGBA f16.
const GBUFFER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Number of [`GBUFFER_FORMAT`] targets.
const GBUFFER_TARGETS: u32 = 3;
/// Bytes per pixel of the G-buffer: its three RGBA f16 targets and the f32 depth buffer (the largest per-pixel
/// footprint of the skin frame's images, checked against the adapter's limits before a frame is rendered).
pub const GBUFFER_BYTES_PER_TEXEL: u32 = GBUFFER_TARGETS * 8 + 4;

/// Refuses a sample count other than 1 or 4 (`--msaa`).
pub fn check_samples(samples: u32) -> Result<(), InvalidInput> {
    if !SAMPLE_COUNTS.contains(&samples) {
        return Err(InvalidInput::new("msaa", format!("must be 1 or 4 samples per pixel, got {samples}")));
    }
    Ok(())
}

/// Checks what both rasterisers take besides the mesh: one tangent per vertex, 1 or 4 samples per pixel.
pub(crate) fn check_raster_inputs(mesh: &Mesh, tangents: &[[f32; 4]], samples: u32) -> Result<(), InvalidInput> {
    if tangents.len() != mesh.positions.len() {
        return Err(InvalidInput::new("tangents", "need one tangent per vertex of the mesh"));
    }
    check_samples(samples)
}

/// Renders `mesh` seen by `camera` into a `width`×`height` G-buffer on the GPU, one sample per pixel, with the
/// mesh's own vertex tangents ([`crate::mesh::tangents::vertex_tangents`]); [`rasterise_jobs`] takes MSAA, the
/// caller's tangents (e.g. MikkTSpace's for a normal-mapped scan) and several G-buffers in one submission.
pub fn rasterise(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mesh: &Mesh,
    camera: &Camera,
    width: u32,
    height: u32,
) -> Result<MeshGBuffer, RuntimeError> {
    let tangents = crate::mesh::tangents::vertex_tangents(mesh);
    let job = RasterJob { mesh, tangents: &tangents, camera, width, height, samples: 1 };
    Ok(rasterise_jobs(device, queue, &[job])?.remove(0))
}

/// One G-buffer to rasterise: `mesh` with its per-vertex `tangents` seen by `camera`, `width`×`height`, `samples`
/// per pixel (1, or 4 for MSAA: see the module doc).
pub struct RasterJob<'a> {
    pub mesh: &'a Mesh,
    pub tangents: &'a [[f32; 4]],
    pub camera: &'a Camera,
    pub width: u32,
    pub height: u32,
    pub samples: u32,
}

/// The G-buffers of `jobs` (a frame's view and its shadow map, say), recorded into one command encoder, submitted
/// once and read back with one wait.
pub fn rasterise_jobs(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    jobs: &[RasterJob<'_>],
) -> Result<Vec<MeshGBuffer>, RuntimeError> {
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("mesh") });
    let targets = jobs.iter().map(|j| record(device, &mut enc, j)).collect::<Result<Vec<_>, _>>()?;
    let all: Vec<&wgpu::Texture> = targets.iter().flatten().collect();
    let read = gpu::read_textures(device, queue, enc, &all)?;
    Ok(jobs
        .iter()
        .zip(read.chunks_exact(3))
        .map(|(j, t)| {
            let [a, b, c] = [0, 1, 2].map(|k| gpu::f16_to_f32(&t[k]));
            decode(j.width, j.height, j.samples, &a, &b, &c)
        })
        .collect())
}

/// A mesh's vertices (position, normal, uv, tangent: 12 f32 each) and its triangles' indices on the device, for
/// the render pass (vertex and index buffers) and the compute rasteriser (storage buffers).
#[derive(Clone)]
pub(crate) struct MeshBuffers {
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
}

/// Uploads `mesh` with its per-vertex `tangents` (counted in [`gpu::buffers_uploaded_on_this_thread`]), refusing a
/// mesh over the adapter's buffer limit.
pub(crate) fn upload_mesh(
    device: &wgpu::Device,
    mesh: &Mesh,
    tangents: &[[f32; 4]],
) -> Result<MeshBuffers, RuntimeError> {
    let vertex_bytes = mesh.positions.len() as u64 * 48;
    if vertex_bytes.max(mesh.indices.len() as u64 * 4) > device.limits().max_buffer_size {
        return Err(InvalidInput::new(
            "mesh",
            format!("{vertex_bytes} bytes of vertices exceed the adapter's buffer limit"),
        )
        .into());
    }
    let mut vertices = Vec::with_capacity(mesh.positions.len() * 12);
    for (((p, n), t), tg) in mesh.positions.iter().zip(&mesh.normals).zip(&mesh.uvs).zip(tangents) {
        vertices.extend_from_slice(&[p[0], p[1], p[2], n[0], n[1], n[2], t[0], t[1], tg[0], tg[1], tg[2], tg[3]]);
    }
    let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("mesh vertices"),
        contents: bytemuck::cast_slice(&vertices),
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE,
    });
    let indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("mesh indices"),
        contents: bytemuck::cast_slice(&mesh.indices),
        usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::STORAGE,
    });
    gpu::count_buffer_upload();
    gpu::count_buffer_upload();
    Ok(MeshBuffers { vertices, indices })
}

/// Records the G-buffer pass of `job` into `enc`; returns its three targets (normal + depth, uv + coverage,
/// tangent; resolved when multisampled). The mesh is uploaded here; [`record_uploaded`] takes it uploaded.
pub(crate) fn record(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    job: &RasterJob<'_>,
) -> Result<[wgpu::Texture; 3], RuntimeError> {
    check_job(device, job)?;
    let buffers = upload_mesh(device, job.mesh, job.tangents)?;
    record_uploaded(device, enc, job, &buffers)
}

/// Refuses what the device cannot rasterise of `job` (tangents, sample count, camera, image size) before any work.
pub(crate) fn check_job(device: &wgpu::Device, job: &RasterJob<'_>) -> Result<(), RuntimeError> {
    let RasterJob { mesh, tangents, camera, width, height, samples } = *job;
    check_raster_inputs(mesh, tangents, samples)?;
    if samples > 1 {
        use wgpu::TextureFormatFeatureFlags as Fl;
        for f in [wgpu::TextureFormat::Rgba16Float, wgpu::TextureFormat::Depth32Float] {
            let flags = f.guaranteed_format_features(device.features()).flags;
            let resolve = f.has_depth_aspect() || flags.contains(Fl::MULTISAMPLE_RESOLVE);
            if !flags.sample_count_supported(samples) || !resolve {
                return Err(InvalidInput::new("msaa", format!("{samples}x is not supported for {f:?} here")).into());
            }
        }
    }
    camera.validate()?;
    crate::runtime::device::check_image_fits(device, width, height, GBUFFER_BYTES_PER_TEXEL)?;
    Ok(())
}

/// [`record`] with `job`'s mesh and tangents already on the device in `buffers` ([`upload_mesh`] of them).
pub(crate) fn record_uploaded(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    job: &RasterJob<'_>,
    buffers: &MeshBuffers,
) -> Result<[wgpu::Texture; 3], RuntimeError> {
    check_job(device, job)?;
    let RasterJob { mesh, camera, width, height, samples, .. } = *job;
    let ubuf = frame_pool::uniform_buffer(
        device,
        "mesh camera",
        bytemuck::cast_slice(&camera_uniform(mesh, camera, width, height)),
    );
    let module = gpu::shader(device, "mesh_raster", include_str!("mesh_raster.wgsl"));
    let gformat = GBUFFER_FORMAT;
    let pipeline = gpu::cached(device, "mesh g-buffer pipeline", &(&module, samples), || {
        gpu::create_render_pipeline(
            device,
            &wgpu::RenderPipelineDescriptor {
                label: Some("mesh g-buffer"),
                layout: None,
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_mesh"),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: 48,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x4],
                    })],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: Some(wgpu::Face::Back),
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                multisample: wgpu::MultisampleState { count: samples, ..Default::default() },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_mesh"),
                    compilation_options: Default::default(),
                    targets: &[
                        Some(wgpu::ColorTargetState {
                            format: gformat,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        }),
                        Some(wgpu::ColorTargetState {
                            format: gformat,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        }),
                        Some(wgpu::ColorTargetState {
                            format: gformat,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        }),
                    ],
                }),
                multiview_mask: None,
                cache: None,
            },
        )
    });
    let bind =
        gpu::bind_group(device, "mesh camera", &pipeline.get_bind_group_layout(0), &[(0, ubuf.as_entire_binding())]);
    // Kept across frames by the frame pool when a frame is open (every texel is cleared by the pass's load op).
    let g0 = frame_pool::target(device, "normal+depth", width, height, gformat);
    let g1 = frame_pool::target(device, "uv+cover", width, height, gformat);
    let g2 = frame_pool::target(device, "tangent", width, height, gformat);
    let attachment = |label, format| {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        frame_pool::texture(device, ((width, height, 1), format, usage, samples), || {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        })
    };
    let ms: Vec<wgpu::TextureView> = if samples > 1 {
        ["normal+depth ms", "uv+cover ms", "tangent ms"]
            .iter()
            .map(|l| attachment(*l, gformat).create_view(&Default::default()))
            .collect()
    } else {
        Vec::new()
    };
    let depth = attachment("mesh depth", wgpu::TextureFormat::Depth32Float);
    let (v0, v1, v2, vd) = (
        g0.create_view(&Default::default()),
        g1.create_view(&Default::default()),
        g2.create_view(&Default::default()),
        depth.create_view(&Default::default()),
    );
    {
        let attach = |k: usize, single| {
            let (view, resolve_target) = if samples > 1 { (&ms[k], Some(single)) } else { (single, None) };
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("mesh g-buffer"),
            color_attachments: &[attach(0, &v0), attach(1, &v1), attach(2, &v2)],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &vd,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.set_vertex_buffer(0, buffers.vertices.slice(..));
        pass.set_index_buffer(buffers.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..mesh.indices.len() as u32, 0, 0..1);
    }
    Ok([g0, g1, g2])
}

/// The G-buffer from its three targets read back as f32 (see [`record`]).
pub(crate) fn decode(width: u32, height: u32, samples: u32, a: &[f32], b: &[f32], c: &[f32]) -> MeshGBuffer {
    let mut g = MeshGBuffer::empty(width, height);
    if samples > 1 {
        resolve_coverage(&mut g, a, b, c);
        return g;
    }
    for i in 0..(width * height) as usize {
        if b[4 * i + 2] > 0.5 {
            g.covered[i] = true;
            g.coverage[i] = 1.0;
            g.normal_view[i] = [a[4 * i], a[4 * i + 1], a[4 * i + 2]];
            g.depth_mm[i] = a[4 * i + 3];
            g.uv[i] = [b[4 * i], b[4 * i + 1]];
            g.tangent_view[i] = [c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]];
        }
    }
    g
}

/// The G-buffer from the resolved (sample-averaged) targets: coverage = the averaged flag, attributes = averaged
/// value / coverage (the mean over the covered samples), the normal renormalised. Shared with the CPU twin.
pub(crate) fn resolve_coverage(g: &mut MeshGBuffer, a: &[f32], b: &[f32], c: &[f32]) {
    for i in 0..(g.width * g.height) as usize {
        let cov = b[4 * i + 2];
        if cov <= 0.0 {
            continue;
        }
        let n = [a[4 * i] / cov, a[4 * i + 1] / cov, a[4 * i + 2] / cov];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if len.is_nan() || len <= 0.0 {
            continue;
        }
        g.covered[i] = true;
        g.coverage[i] = cov;
        g.normal_view[i] = n.map(|v| v / len);
        g.depth_mm[i] = a[4 * i + 3] / cov;
        g.uv[i] = [b[4 * i] / cov, b[4 * i + 1] / cov];
        g.tangent_view[i] = std::array::from_fn(|k| c[4 * i + k] / cov);
    }
}

#[cfg(test)]
mod gbuffer_size_tests {
    use super::*;

    #[test]
    fn gbuffer_bytes_per_texel_are_its_formats() {
        let colour = GBUFFER_FORMAT.block_copy_size(None).unwrap();
        let depth = wgpu::TextureFormat::Depth32Float.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)).unwrap();
        assert_eq!(GBUFFER_BYTES_PER_TEXEL, GBUFFER_TARGETS * colour + depth);
    }
}
