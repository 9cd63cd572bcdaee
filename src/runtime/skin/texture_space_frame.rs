//! A texture-space diffusion frame ([`crate::runtime::skin::texture_space`]; d'Eon, Luebke and Enderton 2007, thesis
//! ch. 3) recorded into **one** command encoder, submitted once, with one read-back: the RGBA8 frame and, after it,
//! the per-head counts of [`TsStats`]. The stages and their arithmetic are those of the per-pass path
//! (`texture_space::render_with`, each pass submitted and read back on its own, which stays the reference, the CPU
//! twin and the path for MSAA, the wrinkle pass and a scan's surface maps):
//!
//! 1. The frame's geometry on the device (`frame_geometry`, as the screen-space shaders' default frame): the G-buffer,
//!    the back light's shadow map, per pixel (u, v, covered), the skin-inputs maps with the rig's hemoglobin at the
//!    mesh's uv, the normals, the specular layer and the view depth; then the frame's skin-inputs pass and its
//!    unblurred diffuse layer (`shade_frame.wgsl`'s `lit`, post-scatter: irradiance alone).
//! 2. Per head, its irradiance map of `T`×`T` texels (`T` from eq. 3.1–3.2 with the depth-based optimisation): the UV
//!    map's positions, normals and coverage (rasterised on the host once per mesh and size, uploaded once per device:
//!    [`crate::runtime::gpu::cached`]) give each texel its view normal, its culling (Listing 3.2) and clipping (eq.
//!    3.3–3.4) and its thickness through the shadow map (Listing 5.1) (`texture_space_frame.wgsl`'s `texels`); the
//!    skin-inputs pass and `lit` light the texels as the frame's pixels; the 12 chained blurs accumulate the weighted
//!    sum (`texture_space.wgsl`); `gather` samples it at the uv of each of the head's pixels.
//! 3. `shade_frame.wgsl`'s `composite` (post-scatter albedo, the unblurred specular layer), bloom and `tonemap`.

use crate::image_buf::Image;
use crate::mesh::Mesh;
use crate::runtime::compute_chain::{self, groups_8x8, storage_buffer, Stage};
use crate::runtime::device::Gpu;
use crate::runtime::gpu;
use crate::runtime::skin::bloom::{self, BloomBuffers};
use crate::runtime::skin::frame_geometry::{self, FrameGeometryJob};
use crate::runtime::skin::heads::{light_camera, BACKGROUND};
use crate::runtime::skin::inputs::SkinInputs;
use crate::runtime::skin::lighting::{DemoAssets, KEY_LIGHT_INTENSITY, TRANSMITTANCE_INTENSITY};
use crate::runtime::skin::mesh_inputs::{self, RigAtUv, RigPose};
use crate::runtime::skin::settings::{
    SkinRenderSettings, TsSettings, HEAD_SPACING_M, SHADOW_MAP_SIZE, SHADOW_SHRINK_MM, WORLD_UNITS_PER_M,
};
use crate::runtime::skin::texture_space::{d_ref_m, uv_map_of, TextureSpaceDiffusion, TsHeadStats, TsStats};
use crate::runtime::RuntimeError;
use crate::shading::texture_space::{
    depth_sized_map, frustum_planes_eye, nearest_corner_distance, normalised_weights, CULL_ANGLE_DEG,
};
use std::collections::HashMap;

/// `shade_frame.wgsl` (its stages `lit`, `composite` and `tonemap` shade the texels and the frame here).
const SHADE_SOURCE: &str = concat!(include_str!("../aa/srgb.wgsl"), include_str!("shade_frame.wgsl"));
/// `texture_space_frame.wgsl` with the bilinear taps it samples the blurred map with.
const FRAME_SOURCE: &str = concat!(include_str!("bilinear_taps.wgsl"), include_str!("texture_space_frame.wgsl"));
/// Storage buffers `texture_space_frame.wgsl` binds.
pub(crate) const FRAME_BUFFERS: u32 = 10;
/// Counts per head in the read-back (covered, culled, clipped, shaded texels, pixels).
const COUNTS: usize = 5;

/// `shade_frame.wgsl`'s uniform block: width, height, u32 per padded Rgba16Float row, post-scatter albedo; the key
/// light, albedo map (0: the skin LUT's); key and back-light intensities, bloom, SSS (0: none).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadeParams {
    size: [f32; 4],
    key: [f32; 4],
    cfg: [f32; 4],
}

/// `texture_space_frame.wgsl`'s uniform block (field by field as there).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FrameParams {
    view: [f32; 16],
    inv_view: [f32; 16],
    light_vp: [f32; 16],
    light_view: [f32; 16],
    planes: [[f32; 4]; 6],
    eye: [f32; 4],
    size: [f32; 4],
    cfg: [f32; 4],
    head: [f32; 4],
    flags: [f32; 4],
    rows: [f32; 4],
}

/// Bytes of a padded row of `width` texels of `bytes_per_texel` in a texture copy.
fn padded_row(width: u32, bytes_per_texel: u32) -> u64 {
    (width * bytes_per_texel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) as u64 * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64
}

/// The UV map of `mesh` at `size` on the device, (position, covered), (normal, 0) per texel, and its stretch
/// (mm per texel along u, v): built once per device, mesh and size.
fn device_uv_map(device: &wgpu::Device, mesh: &Mesh, mesh_key: u64, size: u32) -> (wgpu::Buffer, wgpu::Buffer) {
    gpu::cached(device, "texture-space uv map", &(mesh_key, size), || {
        let uv = uv_map_of(mesh, size);
        let texels: Vec<[f32; 4]> = (0..uv.covered.len())
            .flat_map(|t| {
                let (p, n) = (uv.position[t], uv.normal[t]);
                [[p[0], p[1], p[2], uv.covered[t] as u8 as f32], [n[0], n[1], n[2], 0.0]]
            })
            .collect();
        let what = "texture-space uv map";
        (
            storage_buffer(device, what, 32 * texels.len() as u64 / 2, Some(bytemuck::cast_slice(&texels))),
            storage_buffer(device, what, 8 * uv.covered.len() as u64, Some(bytemuck::cast_slice(&uv.stretch_mm_per_texel))),
        )
    })
}

/// The per-frame buffers of one irradiance-map size (heads of the same size reuse them, one after the other).
struct MapBuffers {
    inputs: SkinInputs,
    uv_map: wgpu::Buffer,
    stretch: wgpu::Buffer,
    /// The texels' skin-inputs maps and normals (padded rows), their (normal, shaded), (0) for `lit`, and the
    /// skin-inputs pass's output (two Rgba16Float images, padded rows).
    maps: wgpu::Buffer,
    normals: wgpu::Buffer,
    geo: wgpu::Buffer,
    skin16: wgpu::Buffer,
    /// The blurs' chain (the lit irradiance map first), its ping-pong partner and the weighted sum.
    chain: wgpu::Buffer,
    temp: wgpu::Buffer,
    sum: wgpu::Buffer,
    /// Bytes per padded row of an Rgba32Float and of an Rgba16Float image of the map.
    row32: u64,
    row16: u64,
}

impl MapBuffers {
    fn new(g: &Gpu, mesh: &Mesh, mesh_key: u64, size: u32, assets: &DemoAssets) -> Result<Self, RuntimeError> {
        let (device, queue) = (&g.device, &g.queue);
        let mut inputs = SkinInputs::new(device, queue, size, size, &assets.luts, &assets.rig)?;
        inputs.upload_lights(queue, &assets.rig_weights, assets.lights.back_view)?;
        let (row32, row16) = (padded_row(size, 16), padded_row(size, 8));
        let t = size as u64 * size as u64;
        let what = "ts_map_size";
        let sizes = [row32 * size as u64, 32 * t, 2 * row16 * size as u64, 16 * t];
        compute_chain::check_buffers(device, what, &sizes)?;
        let make = |bytes| storage_buffer(device, what, bytes, None);
        let (uv_map, stretch) = device_uv_map(device, mesh, mesh_key, size);
        Ok(Self {
            inputs,
            uv_map,
            stretch,
            maps: make(sizes[0]),
            normals: make(sizes[0]),
            geo: make(sizes[1]),
            skin16: make(sizes[2]),
            chain: make(sizes[3]),
            temp: make(sizes[3]),
            sum: make(sizes[3]),
            row32,
            row16,
        })
    }
}

/// `texture_space::render_with`'s frame of `mesh` (the row `heads` of it) on `g` in one command encoder: see the
/// module doc. `assets` are the frame's (neutral rig, post-scatter albedo, the passes' bloom); `rig_pose` the baked
/// rig's pose when the bake has one.
#[allow(clippy::too_many_arguments)]
pub(crate) fn render(
    g: &Gpu,
    mesh: &Mesh,
    mesh_key: u64,
    heads: &Mesh,
    s: &SkinRenderSettings,
    ts: TsSettings,
    rig_pose: Option<RigPose>,
    assets: &DemoAssets,
) -> Result<(Image<u8>, TsStats), RuntimeError> {
    let (device, queue) = (&g.device, &g.queue);
    let what = "texture-space frame";
    let cam = s.camera();
    let (w, h) = (s.width, s.height);
    let n = w as u64 * h as u64;
    let job = FrameGeometryJob { mesh: heads, camera: cam, width: w, height: h, melanin: s.melanin, rig_pose };
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(what) });
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    // 1. The frame's geometry, skin inputs and unblurred diffuse layer.
    let d = frame_geometry::record(device, &mut enc, &job, assets)?;
    let mut inputs = SkinInputs::new(device, queue, w, h, &assets.luts, &assets.rig)?;
    inputs.upload_lights(queue, &assets.rig_weights, assets.lights.back_view)?;
    if let (Some(pose), Some(r)) = (&job.rig_pose, &assets.baked_rig) {
        let maps = RigAtUv { rig: &r.rig, h0: &r.h0, pose };
        mesh_inputs::record_into_skin_map_buffer(device, &mut enc, (w, h), &maps, &d.uvc, &d.skin_maps, d.vec4_row)?;
    }
    gpu::encode_buffer_to_texture(&mut enc, &d.skin_maps, 0, inputs.maps());
    gpu::encode_buffer_to_texture(&mut enc, &d.normals, 0, inputs.normals());
    inputs.encode(&mut enc);
    let row16 = gpu::padded_row_bytes(inputs.albedo()) as u64;
    let bloom_buffers = match &assets.bloom {
        Some(p) => Some(BloomBuffers::new(device, w, h, p)?),
        None => None,
    };
    let sizes = [2 * row16 * h as u64, 16 * n, 4 * n];
    compute_chain::check_buffers(device, what, &sizes)?;
    let skin16 = storage_buffer(device, what, sizes[0], None);
    let diffuse = storage_buffer(device, what, sizes[1], None);
    let rgba = storage_buffer(device, what, sizes[2], Some(&BACKGROUND.repeat(n as usize)));
    // Bindings a stage does not read (no SSS pass; on the texels, nothing past the lit layer).
    let unused = || storage_buffer(device, what, 16, None);
    let (hdr, bloomed) = match &bloom_buffers {
        Some(b) => (b.0[0].clone(), b.0[3].clone()),
        None => (storage_buffer(device, what, sizes[1], None), unused()),
    };
    gpu::encode_texture_to_buffer(&mut enc, inputs.albedo(), &skin16, 0);
    gpu::encode_texture_to_buffer(&mut enc, inputs.transmitted(), &skin16, row16 * h as u64);
    let key = assets.lights.key_view;
    let bloom_on = bloom_buffers.is_some() as u8 as f32;
    let shade_params = |width: u32, height: u32, row16: u64| ShadeParams {
        size: [width as f32, height as f32, (row16 / 4) as f32, 1.0],
        key: [key[0], key[1], key[2], 0.0],
        cfg: [KEY_LIGHT_INTENSITY, TRANSMITTANCE_INTENSITY, bloom_on, 0.0],
    };
    let shade = |enc: &mut wgpu::CommandEncoder, p: &ShadeParams, bound: &[&wgpu::Buffer], entry: &str, size| {
        let stages = [Stage::new(entry, size)];
        compute_chain::record(device, enc, what, SHADE_SOURCE, bytemuck::bytes_of(p), bound, &stages);
    };
    let screen = shade_params(w, h, row16);
    let sss16 = unused();
    let frame_bound = [&skin16, &d.texels, &diffuse, &sss16, &hdr, &bloomed, &rgba];
    shade(&mut enc, &screen, &frame_bound, "lit", groups_8x8(w, h));
    // 2. Per head, its irradiance map lit, blurred and gathered.
    let view = cam.view();
    let inv_view = view.try_inverse().expect("a look-at view is invertible");
    let light = light_camera(&cam, assets.lights.back_view);
    let mat = |m: nalgebra::Matrix4<f32>| -> [f32; 16] { m.as_slice().try_into().expect("4x4") };
    let planes = frustum_planes_eye(&cam.projection(w as f32 / h as f32)).map(|p| [p.x, p.y, p.z, p.w]);
    let mmu = mesh.mm_per_unit;
    let spacing = HEAD_SPACING_M * 1000.0 / mmu;
    let centre = 0.5 * (s.heads - 1) as f32;
    let d_ref_m = d_ref_m(&uv_map_of(mesh, ts.map_size), h, cam.fov_y_deg);
    let weights = normalised_weights(&assets.blurs.blend);
    let sigmas = &assets.blurs.incremental_sigma_mm;
    let (lo, hi) = mesh.bounds();
    let blurs = TextureSpaceDiffusion::new(device)?;
    let counts = storage_buffer(device, what, (4 * COUNTS) as u64 * s.heads as u64, None);
    let shadow_row = padded_row(SHADOW_MAP_SIZE, 8);
    let depth_row = padded_row(w, 4);
    let flag = |b: bool| b as u8 as f32;
    let texel_unused = [unused(), unused(), unused(), unused()];
    let mut maps: HashMap<u32, MapBuffers> = HashMap::new();
    let mut stats = TsStats { heads: Vec::new(), d_ref_m };
    for k in 0..s.heads {
        let dx = (k as f32 - centre) * spacing;
        let (lo_k, hi_k) = ([lo[0] + dx, lo[1], lo[2]], [hi[0] + dx, hi[1], hi[2]]);
        let distance_m = nearest_corner_distance(cam.eye, lo_k, hi_k) * mmu / 1000.0;
        let size = if ts.depth_sized { depth_sized_map(ts.map_size, d_ref_m, distance_m) } else { ts.map_size };
        stats.heads.push(TsHeadStats { map_size: size, distance_m, ..Default::default() });
        if !maps.contains_key(&size) {
            maps.insert(size, MapBuffers::new(g, mesh, mesh_key, size, assets)?);
        }
        let m = &maps[&size];
        let params = FrameParams {
            view: mat(view),
            inv_view: mat(inv_view),
            light_vp: mat(light.projection(1.0) * light.view()),
            light_view: mat(light.view()),
            planes,
            eye: [cam.eye[0], cam.eye[1], cam.eye[2], 0.0],
            size: [size as f32, w as f32, h as f32, (0.5 * cam.fov_y_deg.to_radians()).tan()],
            cfg: [mmu, SHADOW_SHRINK_MM, s.melanin, assets.luts.s_max_mm],
            head: [dx, spacing, centre, (s.heads - 1) as f32],
            flags: [flag(ts.cull), flag(ts.clip), CULL_ANGLE_DEG.to_radians().cos(), WORLD_UNITS_PER_M],
            rows: [(m.row32 / 16) as f32, (depth_row / 4) as f32, SHADOW_MAP_SIZE as f32, (shadow_row / 4) as f32],
        };
        let bound = [&m.uv_map, &d.shadow, &m.maps, &m.normals, &m.geo, &counts, &d.uvc, &d.depth, &m.sum, &diffuse];
        let stage = |entry, groups| [Stage { entry, groups, args: [k, 0, 0, 0] }];
        let uniform = bytemuck::bytes_of(&params);
        compute_chain::record(device, &mut enc, what, FRAME_SOURCE, uniform, &bound, &stage("texels", groups_8x8(size, size)));
        gpu::encode_buffer_to_texture(&mut enc, &m.maps, 0, m.inputs.maps());
        gpu::encode_buffer_to_texture(&mut enc, &m.normals, 0, m.inputs.normals());
        m.inputs.encode(&mut enc);
        gpu::encode_texture_to_buffer(&mut enc, m.inputs.albedo(), &m.skin16, 0);
        gpu::encode_texture_to_buffer(&mut enc, m.inputs.transmitted(), &m.skin16, m.row16 * size as u64);
        let [a, b, c, e] = &texel_unused;
        let texel_bound = [&m.skin16, &m.geo, &m.chain, a, b, c, e];
        shade(&mut enc, &shade_params(size, size, m.row16), &texel_bound, "lit", groups_8x8(size, size));
        enc.clear_buffer(&m.sum, 0, None);
        blurs.record_blurs(device, &mut enc, [&m.chain, &m.temp, &m.sum], &m.stretch, size, sigmas, &weights);
        compute_chain::record(device, &mut enc, what, FRAME_SOURCE, uniform, &bound, &stage("gather", groups_8x8(w, h)));
    }
    // 3. Composite, bloom, tone map; the frame and the counts read back together.
    shade(&mut enc, &screen, &frame_bound, "composite", groups_8x8(w, h));
    if let (Some(p), Some(b)) = (&assets.bloom, &bloom_buffers) {
        bloom::record(device, &mut enc, w, h, p, b);
    }
    shade(&mut enc, &screen, &frame_bound, "tonemap", groups_8x8(w, h));
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: rgba.size() + counts.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    enc.copy_buffer_to_buffer(&rgba, 0, &readback, 0, rgba.size());
    enc.copy_buffer_to_buffer(&counts, 0, &readback, rgba.size(), counts.size());
    gpu::submit(queue, enc.finish());
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(RuntimeError::Gpu(format!("{what}: {e}")));
    }
    let out = gpu::map_read(device, &readback)?;
    let counted: Vec<u64> =
        out[rgba.size() as usize..].chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64).collect();
    for (st, c) in stats.heads.iter_mut().zip(counted.chunks_exact(COUNTS)) {
        (st.covered_texels, st.culled_texels, st.clipped_texels, st.shaded_texels, st.pixels) =
            (c[0], c[1], c[2], c[3], c[4]);
    }
    Ok((Image::from_vec(w, h, 4, out[..4 * n as usize].to_vec()), stats))
}
