//! The geometry of a `run skin` frame computed on the device, recorded into the frame's command encoder so that
//! the G-buffer is never read back (thesis ch. 5 Listing 5.1 for thickness from a shadow map; Kelemen and
//! Szirmay-Kalos 2001 for the specular layer, [`crate::shading::kelemen`]): the view's G-buffer and the back light's
//! shadow map are rasterised ([`crate::runtime::skin::mesh_raster`]), copied into buffers, and one compute pass
//! (`frame_geometry.wgsl`, f32) writes per pixel what `heads::geometry` computes on the host:
//! the skin-inputs maps (melanin, H0, thickness), the normals, the SSS pass's linear depth, the lit layer's texels
//! (normal, skin, specular) and the (u, v, covered) the rig at uv reads. The host code stays the reference (its
//! CPU twin, the per-pass path and texture-space diffusion).
//!
//! The passes that replace the normals before any lighting are recorded into the same encoder, in the host's
//! order: a scan's surface maps ([`crate::runtime::skin::surface_maps`], thesis §7.6: the view G-buffer
//! rasterised from the MikkTSpace-split mesh with its tangents, the albedo map left in the lit layer's texels for
//! post-scatter texturing), then the wrinkle pass ([`crate::runtime::skin::wrinkles`], Listing 8.1); the geometry
//! pass's `unpack` entry first writes the per-pixel frame ((u, v, covered), normal, tangent) they read, and its
//! `main` then takes their normals for thickness, specular and shading. With 4× MSAA the G-buffer is rasterised
//! multisampled and resolved ([`RasterJob::samples`]) and decoded by its coverage as the host's `resolve_coverage`
//! does; the coverage stays in `uvc` for the blend after the tone map.

use crate::mesh::camera::Camera;
use crate::mesh::Mesh;
use crate::runtime::compute_chain::{self, Stage};
use crate::runtime::frame_pool;
use crate::runtime::gpu;
use crate::runtime::skin::compute_raster::{self, RasterShape};
use crate::runtime::skin::heads::light_camera;
use crate::runtime::skin::lighting::{DemoAssets, KEY_LIGHT_INTENSITY};
use crate::runtime::skin::mesh_inputs::{self, RigPose};
use crate::runtime::skin::mesh_raster::{self, MeshBuffers, RasterJob};
use crate::runtime::skin::passes::Wrinkles;
use crate::runtime::skin::settings::{SHADOW_MAP_SIZE, SHADOW_SHRINK_MM, WORLD_UNITS_PER_M};
use crate::runtime::skin::surface_maps::SurfaceMaps;
use crate::runtime::skin::{surface_maps, wrinkles};
use crate::runtime::RuntimeError;
use std::sync::Arc;

/// What the device geometry of a frame needs: the heads' mesh seen by `camera` at `width`×`height` with `msaa`
/// samples per pixel (1 or 4), the melanin of every covered pixel, the pose of the baked rig whose hemoglobin the
/// frame writes later (H0 0 here; None: the procedural H0 of the host code), and the passes on the normals: a
/// scan's surface maps and the wrinkle pass (None: not run).
pub(crate) struct FrameGeometryJob<'a> {
    pub(crate) mesh: &'a Mesh,
    pub(crate) camera: Camera,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) melanin: f32,
    pub(crate) rig_pose: Option<RigPose>,
    pub(crate) msaa: u32,
    pub(crate) surface_maps: Option<&'a SurfaceMaps>,
    pub(crate) wrinkles: Option<&'a Wrinkles>,
}

impl FrameGeometryJob<'_> {
    /// Whether the frame's albedo comes from a map (left in the lit layer's texels).
    pub(crate) fn has_albedo_map(&self) -> bool {
        self.surface_maps.is_some_and(|m| m.albedo.is_some())
    }
}

/// The geometry on the device: (u, v, covered, coverage) per pixel; the skin-inputs maps and normals in rows of
/// `vec4_row` texels; per pixel (normal, skin), (albedo or 0, specular); the SSS depth in rows of `depth_row`
/// texels.
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
    surf: [f32; 4],
}

const SOURCE: &str = include_str!("frame_geometry.wgsl");

/// A mesh as the frame rasterises it: its tangents ([`crate::mesh::tangents::vertex_tangents`]) or, for a
/// normal-mapped view, the MikkTSpace split (`split`) and its tangents
/// ([`crate::mesh::tangents::mikktspace_tangents`]).
struct PreparedMesh {
    split: Option<Mesh>,
    tangents: Vec<[f32; 4]>,
}

/// Prepared meshes kept across frames, keyed by (the mesh's content hash, MikkTSpace split or not): the tangents
/// and the split read only the mesh, never the camera, the lights or the pose.
static PREPARED: gpu::Kept<(u64, bool), Arc<PreparedMesh>> = gpu::Kept::new(MESHES_KEPT);
/// Uploaded meshes kept across frames, keyed by (device, the mesh's content hash, MikkTSpace split or not): room
/// for a few devices (a test process renders on several at once).
static UPLOADED: gpu::Kept<(wgpu::Device, u64, bool), MeshBuffers> = gpu::Kept::new(4 * MESHES_KEPT);
/// Meshes kept (a frame uses one, split for the view when it has a normal map; a benchmark or test a few).
const MESHES_KEPT: usize = 4;

/// `mesh` (content hash `key`) prepared for the rasterisers, split for MikkTSpace or not: once per mesh while kept,
/// every frame while [`gpu::object_cache_enabled`] is off.
fn prepared_mesh(mesh: &Mesh, key: u64, mikktspace: bool) -> Arc<PreparedMesh> {
    PREPARED.get_or_insert_with((key, mikktspace), || {
        Arc::new(if mikktspace {
            let (split, tangents) = crate::mesh::tangents::mikktspace_tangents(mesh);
            PreparedMesh { split: Some(split), tangents }
        } else {
            PreparedMesh { split: None, tangents: crate::mesh::tangents::vertex_tangents(mesh) }
        })
    })
}

/// The vertex and index buffers of `job`, whose mesh and tangents are [`prepared_mesh`]`(mesh, key, mikktspace)`,
/// on `device`: uploaded once per device and prepared mesh while kept.
fn mesh_buffers(
    device: &wgpu::Device,
    job: &RasterJob<'_>,
    key: u64,
    mikktspace: bool,
) -> Result<MeshBuffers, RuntimeError> {
    UPLOADED.get_or_try_insert_with((device.clone(), key, mikktspace), || {
        mesh_raster::upload_mesh(device, job.mesh, job.tangents)
    })
}

/// Bytes of one padded row of a `width`-texel image of `bytes_per_texel` in a texture copy.
fn padded_row(width: u32, bytes_per_texel: u32) -> u32 {
    (width * bytes_per_texel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
}

impl DeviceGeometry {
    /// The rig at uv (eq. 7.6 with `job`'s pose, thesis §7.7) into this frame's skin-inputs maps: the screen-space
    /// and the texture-space frame's step 3; nothing without a pose or without `assets`' baked rig.
    pub(crate) fn record_rig_at_uv(
        &self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        job: &FrameGeometryJob<'_>,
        assets: &DemoAssets,
    ) -> Result<(), RuntimeError> {
        let (Some(pose), Some(r)) = (&job.rig_pose, &assets.baked_rig) else { return Ok(()) };
        let maps = mesh_inputs::RigAtUv { rig: &r.rig, h0: &r.h0, pose };
        let size = (job.width, job.height);
        mesh_inputs::record_into_skin_map_buffer(device, enc, size, &maps, &self.uvc, &self.skin_maps, self.vec4_row)
    }
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
    let key = job.mesh.content_key();
    let plain = prepared_mesh(job.mesh, key, false);
    // A normal map is baked in MikkTSpace: the view sees the mesh split where its corners' frames disagree, with
    // those tangents (as the host's `heads::geometry`); the shadow map needs no tangents.
    let mikk = job.surface_maps.map(|_| prepared_mesh(job.mesh, key, true));
    let view_mesh = mikk.as_ref().unwrap_or(&plain);
    let split = view_mesh.split.as_ref().unwrap_or(job.mesh);
    let view_job = RasterJob {
        mesh: split,
        tangents: &view_mesh.tangents,
        camera: &job.camera,
        width: w,
        height: h,
        samples: job.msaa,
    };
    let tangents = &plain.tangents;
    let shadow_job = RasterJob { mesh: job.mesh, tangents, camera: &light, width: s, height: s, samples: 1 };
    mesh_raster::check_job(device, &view_job)?;
    mesh_raster::check_job(device, &shadow_job)?;
    let view_mesh = mesh_buffers(device, &view_job, key, mikk.is_some())?;
    let shadow_mesh = mesh_buffers(device, &shadow_job, key, false)?;
    let what = "frame geometry";
    let (view_row, shadow_row) = (padded_row(w, 8) as u64, padded_row(s, 8) as u64);
    let (vec4_row, depth_row) = (padded_row(w, 16), padded_row(w, 4));
    let n = w as u64 * h as u64;
    // The surface and wrinkle passes read the tangent target and the per-pixel normals too.
    let per_pixel_frame = job.surface_maps.is_some() || job.wrinkles.is_some();
    let view_targets = if per_pixel_frame { 3 } else { 2 };
    let sizes = [
        view_targets * view_row * h as u64,
        2 * shadow_row * s as u64,
        16 * n,
        vec4_row as u64 * h as u64,
        vec4_row as u64 * h as u64,
        32 * n,
        depth_row as u64 * h as u64,
        if per_pixel_frame { 16 * n } else { 16 },
    ];
    compute_chain::check_buffers(device, what, &sizes)?;
    // Bindings 1..=8 of frame_geometry.wgsl: view_g, shadow_g, uvc, skin_maps, normals, geo, depth, nrm; from the
    // frame pool (not zero when reused: the copies below and `unpack`/`main` write every texel the passes read).
    let bufs: Vec<wgpu::Buffer> = sizes.iter().map(|&b| frame_pool::storage_buffer(device, what, b)).collect();
    let (uvc, normals, texels, nrm) = (&bufs[2], &bufs[4], &bufs[5], &bufs[7]);
    // The G-buffer and the shadow map in bufs[0] and bufs[1]: rasterised there by compute, or by the render pass
    // and copied.
    let software = device.adapter_info().device_type == wgpu::DeviceType::Cpu;
    let compute = RasterShape::current(software)? == RasterShape::Compute
        && compute_raster::fits(device, &view_job, &view_mesh)
        && compute_raster::fits(device, &shadow_job, &shadow_mesh);
    if compute {
        let rows = |buffer, row: u64, targets| compute_raster::GBufferRows { buffer, row_bytes: row as u32, targets };
        compute_raster::record(
            device,
            enc,
            "view raster",
            &view_job,
            &view_mesh,
            &rows(&bufs[0], view_row, view_targets as u32),
        )?;
        compute_raster::record(
            device,
            enc,
            "shadow raster",
            &shadow_job,
            &shadow_mesh,
            &rows(&bufs[1], shadow_row, 2),
        )?;
    } else {
        let view = mesh_raster::record_uploaded(device, enc, &view_job, &view_mesh)?;
        gpu::profile_mark(device, enc, "view G-buffer rasterised");
        let shadow = mesh_raster::record_uploaded(device, enc, &shadow_job, &shadow_mesh)?;
        gpu::profile_mark(device, enc, "shadow map rasterised");
        for (k, target) in view.iter().take(view_targets as usize).enumerate() {
            gpu::encode_texture_to_buffer(enc, target, &bufs[0], k as u64 * view_row * h as u64);
        }
        gpu::encode_texture_to_buffer(enc, &shadow[0], &bufs[1], 0);
        gpu::encode_texture_to_buffer(enc, &shadow[1], &bufs[1], shadow_row * s as u64);
    }
    let inv_view = job.camera.view().try_inverse().expect("a look-at view is invertible");
    let light_view = light.view();
    let mat = |m: nalgebra::Matrix4<f32>| -> [f32; 16] { m.as_slice().try_into().expect("4x4") };
    let key = assets.lights.key_view;
    let flag = |b: bool| if b { 1.0 } else { 0.0 };
    let params = Params {
        inv_view: mat(inv_view),
        light_vp: mat(light.projection(1.0) * light_view),
        light_view: mat(light_view),
        size: [w as f32, h as f32, s as f32, (0.5 * job.camera.fov_y_deg.to_radians()).tan()],
        rows: [(view_row / 4) as f32, (shadow_row / 4) as f32, (vec4_row / 16) as f32, (depth_row / 4) as f32],
        cfg: [job.mesh.mm_per_unit, SHADOW_SHRINK_MM, job.melanin, assets.luts.s_max_mm],
        key: [key[0], key[1], key[2], KEY_LIGHT_INTENSITY],
        misc: [flag(job.rig_pose.is_some()), WORLD_UNITS_PER_M, 0.0, 0.0],
        surf: [flag(per_pixel_frame), flag(job.has_albedo_map()), flag(job.msaa > 1), 0.0],
    };
    let bound: Vec<&wgpu::Buffer> = bufs.iter().collect();
    let groups = compute_chain::groups_8x8(w, h);
    let uniform = bytemuck::bytes_of(&params);
    if per_pixel_frame {
        compute_chain::record(device, enc, what, SOURCE, uniform, &bound, &[Stage::new("unpack", groups)]);
        // (u, v, covered, coverage), the normal and (in the normals buffer until `main` writes it) the tangent.
        let frame = [uvc, nrm, normals];
        if let Some(maps) = job.surface_maps {
            // Per pixel (normal, 0), (albedo, 0) into the lit layer's texels, where `main` reads the albedo.
            surface_maps::record(device, enc, (w, h), frame, maps, texels)?;
            compute_chain::record(device, enc, what, SOURCE, uniform, &bound, &[Stage::new("take_normals", groups)]);
        }
        if let Some(wr) = job.wrinkles {
            let out = frame_pool::storage_buffer(device, what, 16 * n);
            wrinkles::record(device, enc, (w, h), frame, &wr.maps, &wr.zone_weights, &out)?;
            enc.copy_buffer_to_buffer(&out, 0, nrm, 0, 16 * n);
        }
    }
    compute_chain::record(device, enc, what, SOURCE, uniform, &bound, &[Stage::new("main", groups)]);
    let shadow = bufs[1].clone();
    let mut it = bufs.into_iter().skip(2);
    let mut next = || it.next().expect("eight buffers");
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

    /// A device for one test, the tests taking turns (adapters enumerated from two threads at once can fail on
    /// the GL backend).
    fn device() -> (std::sync::MutexGuard<'static, ()>, crate::runtime::device::Gpu) {
        static TURN: std::sync::Mutex<()> = std::sync::Mutex::new(());
        let turn = TURN.lock().unwrap_or_else(|e| e.into_inner());
        (turn, crate::runtime::device::create_headless(&Default::default()).expect("an adapter (lavapipe)"))
    }

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
        let (_one_at_a_time, g) = device();
        let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/baked"));
        let baked = DemoAssets::load(dir).unwrap();
        assert!(baked.baked_rig.is_some(), "the committed bake has the example rig");
        for with_rig in [false, true] {
            let mut assets = baked.clone();
            if !with_rig {
                assets.baked_rig = None;
            }
            device_geometry_matches_the_hosts(&g, &assets, &SkinPasses::none());
        }
    }

    /// A 24×24 albedo map of stripes across u and a 32×32 tangent-space normal map of bumps (unit vectors tilted
    /// ±0.4 in x and y).
    fn synthetic_maps() -> crate::runtime::skin::surface_maps::SurfaceMaps {
        use crate::runtime::skin::surface_maps::{SurfaceMap, SurfaceMaps};
        let albedo = (0..24 * 24u32)
            .map(|i| if (i % 24) % 6 < 2 { [0.25, 0.12, 0.08, 0.0] } else { [0.6, 0.4, 0.3, 0.0] })
            .collect::<Vec<_>>();
        let bumps = (0..32 * 32u32)
            .map(|i| {
                let (a, b) = (0.4 * ((i % 32) as f32 * 0.8).sin(), 0.4 * ((i / 32) as f32 * 0.6).cos());
                let l = (a * a + b * b + 1.0).sqrt();
                [a / l, b / l, 1.0 / l, 0.0]
            })
            .collect::<Vec<_>>();
        SurfaceMaps {
            albedo: Some(SurfaceMap { width: 24, height: 24, texels: albedo.into() }),
            normal: Some(SurfaceMap { width: 32, height: 32, texels: bumps.into() }),
        }
    }

    /// The device geometry with a scan's surface maps, the wrinkle pass, and both (the surface maps first, as the
    /// host runs them), and 4× MSAA alone and with both, recorded into the frame's encoder against the host's
    /// geometry from the same rasteriser and the same passes run one submission each: the same checks as without
    /// them (with MSAA the normals within 1e-5: the device divides the resolved G-buffer by its coverage in its own
    /// f32 arithmetic), the coverage equal, the albedo map's texels equal (within 1e-5 with MSAA),
    /// and the normals bent by the passes (by the bump map on most covered pixels, by the wrinkles in their zones;
    /// none without passes), so the passes did run on the device.
    #[test]
    fn the_device_geometry_with_surface_maps_wrinkles_and_msaa_matches_the_hosts() {
        use crate::runtime::skin::passes::Wrinkles;
        use crate::runtime::skin::wrinkles::{parse_wrinkle_weights, WrinkleMaps};
        let (_one_at_a_time, g) = device();
        let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/baked"));
        let assets = DemoAssets::load(dir).unwrap();
        let wrinkles = Wrinkles {
            maps: WrinkleMaps::load(dir).unwrap().into(),
            zone_weights: parse_wrinkle_weights("joy=1,surprise=1,anger=1").unwrap(),
        };
        let mapped = SkinPasses { surface_maps: Some(synthetic_maps()), ..SkinPasses::none() };
        let wrinkled = SkinPasses { wrinkles: Some(wrinkles), ..SkinPasses::none() };
        let both = SkinPasses { surface_maps: mapped.surface_maps.clone(), ..wrinkled.clone() };
        let msaa = SkinPasses { msaa: 4, ..SkinPasses::none() };
        let all = SkinPasses { msaa: 4, ..both.clone() };
        for passes in [mapped, wrinkled, both, msaa, all] {
            device_geometry_matches_the_hosts(&g, &assets, &passes);
        }
    }

    /// The device geometry of one frame rasterised by compute against the same frame rasterised by the render
    /// pass (both recorded by [`record`]), with and without the rig: the coverage equal on all but a few pixels
    /// (measured: none), and on the pixels both cover the normals within f16 storage (dot ≥ 0.999), the SSS depth
    /// within 0.5 mm (an f16 step at 600 mm), the specular layer within 2e-3 (measured: 3e-4) and the thickness
    /// within 1.05 mm on ≥ 99 % of the pixels the back light reaches: the shadow map, rasterised by compute too,
    /// stores the light's depth as f16, one step of which is 1 mm at 1–2 m (measured: up to 1.003 mm, most equal).
    /// The tests' frame: the default head alone at 0.6 m, 320×192, no SSS.
    fn frame_320x192() -> SkinRenderSettings {
        SkinRenderSettings {
            shader: SkinShader::None,
            heads: 1,
            distance_m: 0.6,
            width: 320,
            height: 192,
            melanin: 0.02,
            stretch: StretchPreset::Thesis,
        }
    }

    #[test]
    fn the_compute_raster_geometry_matches_the_render_pass_geometry() {
        let (_one_at_a_time, g) = device();
        let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/baked"));
        let assets = DemoAssets::load(dir).unwrap();
        let mesh = crate::mesh::head::default_head();
        let s = frame_320x192();
        let (w, h) = (s.width, s.height);
        let none = SkinPasses::none();
        let job = crate::runtime::skin::frame::device_job(&mesh, &s, &none, &assets);
        let geometry = |shape| {
            RasterShape::set_on_this_thread(Some(shape));
            let mut enc = g.device.create_command_encoder(&Default::default());
            let d = record(&g.device, &mut enc, &job, &assets).unwrap();
            RasterShape::set_on_this_thread(None);
            read(&g, enc, &[&d.skin_maps, &d.normals, &d.texels, &d.depth, &d.uvc])
        };
        let (c, r) = (geometry(RasterShape::Compute), geometry(RasterShape::Render));
        let (row4, row1) = (4 * padded_row(w, 16) as usize / 16, padded_row(w, 4) as usize / 4);
        let (mut coverage, mut both, mut lit_through, mut thick_ok) = (0, 0, 0, 0);
        let (mut min_dot, mut depth_mm, mut spec) = (1.0f32, 0.0f32, 0.0f32);
        for i in 0..(w * h) as usize {
            let (x, y) = (i % w as usize, i / w as usize);
            let covered = [c[4][4 * i + 3], r[4][4 * i + 3]];
            if covered[0] != covered[1] {
                coverage += 1;
                continue;
            }
            if covered[0] == 0.0 {
                continue;
            }
            both += 1;
            let k = y * row4 + 4 * x;
            let (n, m) = (&c[1][k..k + 3], &r[1][k..k + 3]);
            min_dot = min_dot.min(n[0] * m[0] + n[1] * m[1] + n[2] * m[2]);
            depth_mm = depth_mm.max((c[3][y * row1 + x] - r[3][y * row1 + x]).abs());
            spec = spec.max((c[2][8 * i + 7] - r[2][8 * i + 7]).abs());
            let t = r[0][k + 2];
            if t < assets.luts.s_max_mm {
                lit_through += 1;
                thick_ok += ((c[0][k + 2] - t).abs() <= 1.05) as usize;
            }
        }
        assert!(both > 1000, "{both} pixels covered by both");
        assert!(coverage <= 8, "{coverage} pixels covered by one shape only");
        assert!(min_dot >= 0.999, "normals: min dot {min_dot}");
        assert!(depth_mm <= 0.5, "depth differs by {depth_mm} mm");
        assert!(spec <= 2e-3, "specular differs by {spec}");
        assert!(lit_through >= 20, "the back light reaches {lit_through} pixels");
        assert!(thick_ok as f64 >= 0.99 * lit_through as f64, "{thick_ok} of {lit_through} thicknesses agree");
    }

    fn device_geometry_matches_the_hosts(g: &crate::runtime::device::Gpu, assets: &DemoAssets, passes: &SkinPasses) {
        // The host's geometry reads the render pass's G-buffer: the device frame takes the same rasteriser, so the
        // rest of the geometry must agree exactly (the compute rasteriser is compared with it above).
        RasterShape::set_on_this_thread(Some(RasterShape::Render));
        let mesh = crate::mesh::head::default_head();
        let s = frame_320x192();
        let (w, h) = (s.width, s.height);
        let (geo, gbuf, _) = heads::geometry(Backend::Gpu(g), &mesh, &s, passes, assets, false).unwrap();
        // The normals without the passes on the normals, to see that they bend them.
        let unbent = SkinPasses { msaa: passes.msaa, ..SkinPasses::none() };
        let (plain, _, _) = heads::geometry(Backend::Gpu(g), &mesh, &s, &unbent, assets, false).unwrap();
        let job = crate::runtime::skin::frame::device_job(&mesh, &s, passes, assets);
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
        let r = read(g, enc, &[&d.skin_maps, &d.normals, &d.texels, &d.depth, &d.uvc]);
        let (maps, normals, texels, depth, uvc) = (&r[0], &r[1], &r[2], &r[3], &r[4]);
        // Exact with one sample (the same f16 texels, the same passes); MSAA divides by the coverage on each side.
        let tol = if passes.msaa > 1 { 1e-5 } else { 0.0 };
        let near = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol);
        let (row4, row1) = (4 * d.vec4_row as usize, padded_row(w, 4) as usize / 4);
        let (mut covered, mut thick_ok, mut lit_through, mut bent) = (0, 0, 0, 0);
        let s_max = assets.luts.s_max_mm;
        for i in 0..(w * h) as usize {
            let (x, y) = (i % w as usize, i / w as usize);
            let m = &maps[y * row4 + 4 * x..y * row4 + 4 * x + 4];
            assert_eq!(texels[8 * i + 3] == 1.0, geo.skin[i], "coverage at {x},{y}");
            let nv = &normals[y * row4 + 4 * x..y * row4 + 4 * x + 3];
            assert!(
                near(nv, geo.frame.normals[i].as_slice()),
                "normal at {x},{y}: {nv:?} vs {:?}",
                geo.frame.normals[i]
            );
            assert_eq!(uvc[4 * i + 3], gbuf.coverage[i], "coverage at {x},{y}");
            assert_eq!(&texels[8 * i..8 * i + 3], nv);
            let albedo = geo.albedo.as_ref().map_or([0.0; 3], |a| a[i]);
            assert!(near(&texels[8 * i + 4..8 * i + 7], albedo.as_slice()), "albedo at {x},{y}");
            let n0 = plain.frame.normals[i];
            // Turned by more than about 2.5° (the G-buffer's normals are f16, not exactly unit).
            let len = |v: &[f32]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let cos = (n0[0] * nv[0] + n0[1] * nv[1] + n0[2] * nv[2]) / (len(&n0) * len(nv)).max(1e-12);
            bent += (geo.skin[i] && cos < 0.999) as usize;
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
        // The bump map bends most of the head; the wrinkle zones a few hundred pixels of it (measured: 290).
        let least = if passes.surface_maps.is_some() { covered / 2 } else { 100 * passes.wrinkles.is_some() as usize };
        assert!(bent >= least && (least > 0 || bent == 0), "{bent} of {covered} normals bent");
        assert!(lit_through >= 20, "the back light reaches {lit_through} pixels");
        assert!(thick_ok as f64 >= 0.99 * lit_through as f64, "{thick_ok} of {lit_through} thicknesses agree");
        RasterShape::set_on_this_thread(None);
    }
}
