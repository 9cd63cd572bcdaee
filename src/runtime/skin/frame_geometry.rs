//! The geometry of a `run skin` frame computed on the device, recorded into the frame's command encoder so that
//! the G-buffer is never read back (thesis ch. 5 Listing 5.1 for thickness from a shadow map; Kelemen and
//! Szirmay-Kalos 2001 for the specular layer, [`crate::shading::kelemen`]): the view's G-buffer and the back light's
//! shadow map are rasterised ([`crate::runtime::skin::mesh_raster`]), copied into buffers, and one compute pass
//! (`frame_geometry.wgsl`, f32) writes per pixel what `heads::geometry` computes on the host:
//! the skin-inputs maps (melanin, H0, thickness), the normals, the SSS pass's linear depth, the lit layer's texels
//! (normal, skin, specular) and the (u, v, covered) the rig at uv reads. The host code stays the reference (its
//! CPU twin and the path for MSAA, wrinkles, a scan's surface maps and texture-space diffusion).

use crate::mesh::camera::Camera;
use crate::mesh::Mesh;
use crate::runtime::compute_chain::{self, Stage};
use crate::runtime::gpu;
use crate::runtime::skin::heads::light_camera;
use crate::runtime::skin::lighting::{DemoAssets, KEY_LIGHT_INTENSITY};
use crate::runtime::skin::mesh_inputs::RigPose;
use crate::runtime::skin::mesh_raster::{self, RasterJob};
use crate::runtime::skin::settings::{SHADOW_MAP_SIZE, SHADOW_SHRINK_MM, WORLD_UNITS_PER_M};
use crate::runtime::RuntimeError;

/// What the device geometry of a frame needs: the heads' mesh seen by `camera` at `width`×`height` (one sample),
/// the melanin of every covered pixel, and the pose of the baked rig whose hemoglobin the frame writes later (H0 0
/// here; None: the procedural H0 of the host code).
pub(crate) struct FrameGeometryJob<'a> {
    pub(crate) mesh: &'a Mesh,
    pub(crate) camera: Camera,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) melanin: f32,
    pub(crate) rig_pose: Option<RigPose>,
}

/// The geometry on the device: (u, v, covered, 0) per pixel; the skin-inputs maps and normals in rows of
/// `vec4_row` texels; per pixel (normal, skin), (albedo 0, specular); the SSS depth in rows of `depth_row` texels.
pub(crate) struct DeviceGeometry {
    pub(crate) uvc: wgpu::Buffer,
    pub(crate) skin_maps: wgpu::Buffer,
    pub(crate) normals: wgpu::Buffer,
    pub(crate) texels: wgpu::Buffer,
    pub(crate) depth: wgpu::Buffer,
    pub(crate) vec4_row: u32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    inv_view: [f32; 16],
    light_vp: [f32; 16],
    light_view: [f32; 16],
    size: [f32; 4],
    rows: [f32; 4],
    cfg: [f32; 4],
    key: [f32; 4],
    misc: [f32; 4],
}

const SOURCE: &str = include_str!("frame_geometry.wgsl");

/// Bytes of one padded row of a `width`-texel image of `bytes_per_texel` in a texture copy.
fn padded_row(width: u32, bytes_per_texel: u32) -> u32 {
    (width * bytes_per_texel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
}

/// Records the G-buffer, the shadow map and the geometry pass of `job` into `enc`, with `assets`' lights and
/// thickness range: no submission, no read-back.
pub(crate) fn record(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    job: &FrameGeometryJob<'_>,
    assets: &DemoAssets,
) -> Result<DeviceGeometry, RuntimeError> {
    let (w, h, s) = (job.width, job.height, SHADOW_MAP_SIZE);
    let light = light_camera(&job.camera, assets.lights.back_view);
    let tangents = crate::mesh::tangents::vertex_tangents(job.mesh);
    let raster =
        |camera, width, height| RasterJob { mesh: job.mesh, tangents: &tangents, camera, width, height, samples: 1 };
    let view = mesh_raster::record(device, enc, &raster(&job.camera, w, h))?;
    let shadow = mesh_raster::record(device, enc, &raster(&light, s, s))?;
    let what = "frame geometry";
    let (view_row, shadow_row) = (gpu::padded_row_bytes(&view[0]) as u64, gpu::padded_row_bytes(&shadow[0]) as u64);
    let (vec4_row, depth_row) = (padded_row(w, 16), padded_row(w, 4));
    let n = w as u64 * h as u64;
    let sizes = [
        2 * view_row * h as u64,
        2 * shadow_row * s as u64,
        16 * n,
        vec4_row as u64 * h as u64,
        vec4_row as u64 * h as u64,
        32 * n,
        depth_row as u64 * h as u64,
    ];
    compute_chain::check_buffers(device, what, &sizes)?;
    let bufs: Vec<wgpu::Buffer> = sizes.iter().map(|&b| compute_chain::storage_buffer(device, what, b, None)).collect();
    gpu::encode_texture_to_buffer(enc, &view[0], &bufs[0], 0);
    gpu::encode_texture_to_buffer(enc, &view[1], &bufs[0], view_row * h as u64);
    gpu::encode_texture_to_buffer(enc, &shadow[0], &bufs[1], 0);
    gpu::encode_texture_to_buffer(enc, &shadow[1], &bufs[1], shadow_row * s as u64);
    let inv_view = job.camera.view().try_inverse().expect("a look-at view is invertible");
    let light_view = light.view();
    let mat = |m: nalgebra::Matrix4<f32>| -> [f32; 16] { m.as_slice().try_into().expect("4x4") };
    let key = assets.lights.key_view;
    let params = Params {
        inv_view: mat(inv_view),
        light_vp: mat(light.projection(1.0) * light_view),
        light_view: mat(light_view),
        size: [w as f32, h as f32, s as f32, (0.5 * job.camera.fov_y_deg.to_radians()).tan()],
        rows: [(view_row / 4) as f32, (shadow_row / 4) as f32, (vec4_row / 16) as f32, (depth_row / 4) as f32],
        cfg: [job.mesh.mm_per_unit, SHADOW_SHRINK_MM, job.melanin, assets.luts.s_max_mm],
        key: [key[0], key[1], key[2], KEY_LIGHT_INTENSITY],
        misc: [if job.rig_pose.is_some() { 1.0 } else { 0.0 }, WORLD_UNITS_PER_M, 0.0, 0.0],
    };
    let bound: Vec<&wgpu::Buffer> = bufs.iter().collect();
    let stages = [Stage::new("main", compute_chain::groups_8x8(w, h))];
    compute_chain::record(device, enc, what, SOURCE, bytemuck::bytes_of(&params), &bound, &stages);
    let mut it = bufs.into_iter().skip(2);
    let mut next = || it.next().expect("seven buffers");
    Ok(DeviceGeometry {
        uvc: next(),
        skin_maps: next(),
        normals: next(),
        texels: next(),
        depth: next(),
        vec4_row: vec4_row / 16,
    })
}
