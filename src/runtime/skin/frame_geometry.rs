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
    /// The back light's shadow map as copied from its G-buffer (texture-space diffusion's texels read it).
    pub(crate) shadow: wgpu::Buffer,
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
    let shadow = bufs[1].clone();
    let mut it = bufs.into_iter().skip(2);
    let mut next = || it.next().expect("seven buffers");
    Ok(DeviceGeometry {
        uvc: next(),
        skin_maps: next(),
        normals: next(),
        texels: next(),
        depth: next(),
        vec4_row: vec4_row / 16,
        shadow,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::backend::Backend;
    use crate::runtime::skin::heads;
    use crate::runtime::skin::passes::SkinPasses;
    use crate::runtime::skin::settings::{SkinRenderSettings, SkinShader, StretchPreset};

    /// The f32 contents of `buf` after `enc` runs (one submission).
    fn read(g: &crate::runtime::device::Gpu, mut enc: wgpu::CommandEncoder, bufs: &[&wgpu::Buffer]) -> Vec<Vec<f32>> {
        let copies: Vec<wgpu::Buffer> = bufs
            .iter()
            .map(|b| {
                let c = g.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("test read-back"),
                    size: b.size(),
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                });
                enc.copy_buffer_to_buffer(b, 0, &c, 0, b.size());
                c
            })
            .collect();
        gpu::submit(&g.queue, enc.finish());
        copies.iter().map(|c| bytemuck::cast_slice(&gpu::map_read(&g.device, c).unwrap()).to_vec()).collect()
    }

    /// The device's per-pixel geometry against the host's (`heads::geometry`, from the same device G-buffer):
    /// coverage and normals equal, depth to f32 rounding, the specular layer within 1e-4, the hemoglobin (the
    /// procedural H0, or the baked rig's at the mesh's uv written by the rig pass) within 2e-4, and thickness
    /// (Listing 5.1) within 0.01 mm on ≥ 99 % of the pixels the back light reaches (thickness under s_max on the
    /// host, 20 or more of them; a shadow-map texel may flip where f32 arithmetic differs).
    #[test]
    fn the_device_geometry_matches_the_hosts() {
        let g = crate::runtime::device::create_headless(&Default::default()).expect("an adapter (lavapipe)");
        let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/baked"));
        let baked = DemoAssets::load(dir).unwrap();
        assert!(baked.baked_rig.is_some(), "the committed bake has the example rig");
        for with_rig in [false, true] {
            let mut assets = baked.clone();
            if !with_rig {
                assets.baked_rig = None;
            }
            device_geometry_matches_the_hosts(&g, &assets);
        }
    }

    fn device_geometry_matches_the_hosts(g: &crate::runtime::device::Gpu, assets: &DemoAssets) {
        let mesh = crate::mesh::head::default_head();
        let (w, h) = (320, 192);
        let s = SkinRenderSettings {
            shader: SkinShader::None,
            heads: 1,
            distance_m: 0.6,
            width: w,
            height: h,
            melanin: 0.02,
            stretch: StretchPreset::Thesis,
        };
        let (geo, _, _) = heads::geometry(Backend::Gpu(g), &mesh, &s, &SkinPasses::none(), assets, false).unwrap();
        let rig_pose = assets.baked_rig.as_ref().map(|r| RigPose::neutral(r.names.len()));
        let job = FrameGeometryJob { mesh: &mesh, camera: s.camera(), width: w, height: h, melanin: 0.02, rig_pose };
        let mut enc = g.device.create_command_encoder(&Default::default());
        let d = record(&g.device, &mut enc, &job, assets).unwrap();
        if let (Some(r), Some(pose)) = (&assets.baked_rig, &job.rig_pose) {
            let maps = crate::runtime::skin::mesh_inputs::RigAtUv { rig: &r.rig, h0: &r.h0, pose };
            let (uvc, sm, row) = (&d.uvc, &d.skin_maps, d.vec4_row);
            crate::runtime::skin::mesh_inputs::record_into_skin_map_buffer(
                &g.device,
                &mut enc,
                (w, h),
                &maps,
                uvc,
                sm,
                row,
            )
            .unwrap();
        }
        let r = read(g, enc, &[&d.skin_maps, &d.normals, &d.texels, &d.depth]);
        let (maps, normals, texels, depth) = (&r[0], &r[1], &r[2], &r[3]);
        let (row4, row1) = (4 * d.vec4_row as usize, padded_row(w, 4) as usize / 4);
        let (mut covered, mut thick_ok, mut lit_through) = (0, 0, 0);
        let s_max = assets.luts.s_max_mm;
        for i in 0..(w * h) as usize {
            let (x, y) = (i % w as usize, i / w as usize);
            let m = &maps[y * row4 + 4 * x..y * row4 + 4 * x + 4];
            assert_eq!(texels[8 * i + 3] == 1.0, geo.skin[i], "coverage at {x},{y}");
            let nv = &normals[y * row4 + 4 * x..y * row4 + 4 * x + 3];
            assert_eq!(nv, geo.frame.normals[i].as_slice(), "normal at {x},{y}");
            assert_eq!(&texels[8 * i..8 * i + 3], nv);
            let dd = depth[y * row1 + x];
            assert!((dd - geo.depth[i]).abs() <= 1e-5 * geo.depth[i], "depth at {x},{y}: {dd} vs {}", geo.depth[i]);
            assert_eq!(m[0], geo.frame.melanin[i]);
            let h0 = geo.frame.h0[i];
            assert!((m[1] - h0).abs() <= 2e-4, "H at {x},{y} (rig {}): {} vs {h0}", job.rig_pose.is_some(), m[1]);
            let spec = geo.specular.as_ref().unwrap()[i];
            assert!((texels[8 * i + 7] - spec).abs() <= 1e-4 * spec.max(1.0), "specular at {x},{y}");
            if geo.skin[i] {
                covered += 1;
                let t = geo.frame.thickness_mm[i];
                if t < s_max {
                    lit_through += 1;
                    thick_ok += ((m[2] - t).abs() <= 0.01) as usize;
                }
            } else {
                assert_eq!(m[2], s_max);
            }
        }
        assert!(covered > 1000, "{covered} covered pixels");
        assert!(lit_through >= 20, "the back light reaches {lit_through} pixels");
        assert!(thick_ok as f64 >= 0.99 * lit_through as f64, "{thick_ok} of {lit_through} thicknesses agree");
    }
}
