//! Texture-space diffusion, TAP 2009's "TS" shader (d'Eon, Luebke and Enderton, "Efficient Rendering of Human
//! Skin", EGSR 2007) in `rtbake run skin --shader ts`, with the three optimisations of Jimenez's thesis ch. 3
//! (culled, depth-sized and clipped irradiance maps; maths in [`crate::shading::texture_space`]).
//!
//! Per head of the row (each head has its own maps, as the thesis' multi-head scenes):
//! 1. **Irradiance map**: the head's mesh rasterised at its texture coordinates into a `T`×`T` map (host side,
//!    [`crate::shading::texture_space::rasterise_uv`], once per mesh and map size: [`uv_map_of`]); each texel is lit exactly as the screen-space shaders'
//!    pixels are — albedo from the skin LUT at the texel's H0 and melanin, Lambert key light + ambient on the
//!    texel's view-space normal, plus the back light's T(s)·E with the shadow map's thickness at the texel's
//!    surface point (stored with the reflected light and blurred with it, thesis §5.4; [`crate::runtime::skin::lighting`]'s
//!    `lit_geometry`, on the GPU skin-inputs pass when there is a device) — so only the diffusion differs between
//!    shaders. Alpha = 1 on shaded texels, 0 on uncovered ones and,
//!    with the optimisations, on culled (N·V < cos 105°, §3.2) and clipped (outside the view frustum, eq. 3.3–3.4)
//!    ones. With the depth-based optimisation `T` = min(d_ref/d, 1)·`T_max` (eq. 3.1–3.2).
//! 2. **Stretch map**: |∂P/∂u|, |∂P/∂v| of each texel's triangle in mm per texel.
//! 3. **Blurs** (GPU compute pass, `skin/texture_space.wgsl`, or the CPU twin [`crate::runtime::skin::texture_space_cpu`]):
//!    the 6 Gaussians of the baked fit (`DemoAssets::blurs`) chained with incremental variances, u then v, 7 taps
//!    each `σᵢ / stretch` texels apart, alpha-0 texels skipped (Listing 3.3) and excluded from their neighbours'
//!    sums; the weighted sum Σ wᵢ·blurᵢ (wᵢ of the fit, normalised per channel) accumulated as they go.
//! 4. **Final pass**: each visible pixel of the head samples the sum at its uv (bilinear); pixels with no shaded
//!    texel in reach keep their unblurred diffuse. The specular layer is composited as for the other shaders
//!    (`demo::composite`).
//!
//! The UV rasterisation runs on the host once per mesh and map size ([`uv_map_of`]). On a device the frame is
//! recorded into one command encoder, submitted once and read back once (the RGBA8 frame and the per-head counts of
//! [`TsStats`]), with the passes of the screen-space shaders' one-encoder frame (a scan's surface maps, the wrinkle
//! pass, `--msaa 4`; `one_encoder`): the G-buffer, the shadow map and the per-pixel geometry of `frame_geometry`
//! (the surface maps, wrinkles and MSAA resolve recorded there), the UV map uploaded once per device, culling,
//! clipping, the texels' normal map (the surface-map pass over the texels' MikkTSpace frame), thickness and
//! lighting, the 12 blur passes, the gather at each pixel's uv, the specular layer, post-scatter albedo, bloom, the
//! tone map and the MSAA coverage blend all on the device. With
//! [`crate::runtime::skin::shade_frame::set_shading_in_one_encoder`] off (the per-pass path, for A/B comparison),
//! culling, clipping and the texels' normal map run on the host (counted, not timed, by the Table 3.1 figures:
//! [`TsStats`]) and each pass is submitted and read back on its own: the G-buffer and shadow map, the surface maps,
//! the wrinkle pass, the rig at uv, the frame's skin inputs, per head the texels' skin inputs and the blurs with the
//! gather, bloom (6 submissions for one head with bloom and no maps).
//!
//! `d_ref` of eq. 3.1 ("dependent of both model scale and frame resolution", thesis §3.3) is taken as the distance
//! at which one pixel of the frame covers four texels of the `T_max` map ([`d_ref_m`]).

use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::mesh::Mesh;
use crate::runtime::backend::Backend;
use crate::runtime::gpu;
use crate::runtime::skin::heads::{self, row_of_heads};
use crate::runtime::skin::inputs::{RigScaleBiasMaps, SkinFrame};
use crate::runtime::skin::lighting::{composite, lit_geometry, DemoAssets, Geometry};
use crate::runtime::skin::mesh_inputs::RigPose;
use crate::runtime::skin::passes::SkinPasses;
use crate::runtime::skin::settings::{SkinRenderSettings, HEAD_SPACING_M};
pub use crate::runtime::skin::settings::{TsSettings, DEFAULT_MAP_SIZE, MAX_MAP_SIZE, MIN_MAP_SIZE};
use crate::runtime::skin::shade_frame::shades_in_one_encoder;
use crate::runtime::skin::surface_maps_cpu::{self, mapped_normal};
use crate::runtime::skin::texture_space_cpu;
use crate::runtime::RuntimeError;
use crate::shading::texture_space::{
    depth_sized_map, frustum_planes_eye, inside_frustum, is_culled, nearest_corner_distance, normalised_weights,
    rasterise_uv, rasterise_uv_attribute, UvMap,
};
use nalgebra::{Vector3, Vector4};
use std::collections::HashMap;
use std::sync::{Arc, LazyLock, Mutex};
use wgpu::util::DeviceExt;

/// UV maps kept across frames, keyed by the mesh's content and the map size (the mesh's rasterisation at its
/// texture coordinates does not change with the camera, the lights or the pose): the last [`UV_MAPS_KEPT`].
static UV_MAPS: LazyLock<Mutex<Vec<KeptUvMap>>> = LazyLock::new(|| Mutex::new(Vec::new()));
/// (mesh hash, map size) and the map.
type KeptUvMap = ((u64, u32), Arc<UvMap>);
/// UV maps kept (a depth-sized frame of several heads uses a few sizes of one mesh).
const UV_MAPS_KEPT: usize = 8;

/// A 64-bit hash of everything [`rasterise_uv`] reads of `mesh` (all of it: [`Mesh::content_key`]).
pub(crate) fn mesh_key(mesh: &Mesh) -> u64 {
    mesh.content_key()
}

/// `mesh` rasterised at its texture coordinates into a `size`² map, once per mesh and size (every time while
/// [`gpu::object_cache_enabled`] is off).
pub fn uv_map_of(mesh: &Mesh, size: u32) -> Arc<UvMap> {
    if !gpu::object_cache_enabled() {
        return Arc::new(rasterise_uv(mesh, size));
    }
    let key = (mesh_key(mesh), size);
    if let Some((_, m)) = UV_MAPS.lock().unwrap_or_else(|e| e.into_inner()).iter().find(|(k, _)| *k == key) {
        return m.clone();
    }
    let map = Arc::new(rasterise_uv(mesh, size));
    let mut kept = UV_MAPS.lock().unwrap_or_else(|e| e.into_inner());
    if !kept.iter().any(|(k, _)| *k == key) {
        if kept.len() == UV_MAPS_KEPT {
            kept.remove(0);
        }
        kept.push((key, map.clone()));
    }
    map
}

/// Bytes of each of the three irradiance-map buffers (chain, temporary, weighted sum) of a `size`² map on the GPU:
/// one RGBA f32 per texel, the largest buffer of the texture-space pass apart from the per-pixel gather.
pub fn map_buffer_bytes(size: u32) -> u64 {
    size as u64 * size as u64 * 16
}

/// Bytes of the gathered-irradiance buffer for `pixels` covered pixels of one head (one RGBA f32 each, at least
/// one): at most 16 bytes per pixel of the frame.
pub fn gather_buffer_bytes(pixels: u64) -> u64 {
    (pixels * 16).max(16)
}

/// Peak host memory of the texture-space pass with a `map_size`² map, bytes: the UV map (33 B per texel), the
/// texels' skin frame and lit layers (~80 B) and the irradiance map (16 B), doubled for the per-size map cache and
/// the depth-sized maps.
pub fn memory_estimate_bytes(map_size: u32) -> u64 {
    2 * 130 * map_size as u64 * map_size as u64
}

/// The work of one head's texture-space pass (Table 3.1's optimisations save on these).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TsHeadStats {
    /// Irradiance map edge used, texels.
    pub map_size: u32,
    /// Distance from the eye to the head's nearest bounding-box corner, m (eq. 3.1's d).
    pub distance_m: f32,
    /// Texels covered by the UV layout.
    pub covered_texels: u64,
    /// Covered texels culled (§3.2) — their fragments discarded.
    pub culled_texels: u64,
    /// Covered, not culled texels clipped (§3.4).
    pub clipped_texels: u64,
    /// Texels lit and blurred: covered − culled − clipped.
    pub shaded_texels: u64,
    /// Visible pixels of the head in the frame.
    pub pixels: u64,
}

/// Per-head statistics of a frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TsStats {
    pub heads: Vec<TsHeadStats>,
    /// eq. 3.1's d_ref, m.
    pub d_ref_m: f32,
}

impl TsStats {
    /// Texels lit and blurred over all heads.
    pub fn shaded_texels(&self) -> u64 {
        self.heads.iter().map(|h| h.shaded_texels).sum()
    }

    /// Texel blur evaluations over all heads: 12 passes (6 Gaussians × u, v) per shaded texel.
    pub fn blur_evaluations(&self) -> u64 {
        12 * self.shaded_texels()
    }

    /// Texels allocated over all heads (T² per head).
    pub fn map_texels(&self) -> u64 {
        self.heads.iter().map(|h| h.map_size as u64 * h.map_size as u64).sum()
    }
}

/// Renders `mesh` (repeated `s.heads` times) with texture-space diffusion (RGBA8, sRGB-encoded) and the work done,
/// with no extra pass ([`SkinPasses::none`], as `skin_render::render`).
pub fn render<'g>(
    gpu: impl Into<Backend<'g>>,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    ts: TsSettings,
    assets: &DemoAssets,
) -> Result<(Image<u8>, TsStats), RuntimeError> {
    let gpu: Backend = gpu.into();
    render_with(gpu, mesh, s, ts, &SkinPasses::none(), assets)
}

/// [`render`] with the passes of `passes` (rig pose, wrinkles and MSAA of the G-buffer, bloom), as
/// `skin_render::render_with` applies them to the screen-space shaders. The rig pose and wrinkles shape the
/// screen-space G-buffer whose pixels gather the blurred map (the texels use the mesh's vertex normals and H0).
pub fn render_with<'g>(
    gpu: impl Into<Backend<'g>>,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    ts: TsSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> Result<(Image<u8>, TsStats), RuntimeError> {
    let gpu: Backend = gpu.into();
    s.validate()?;
    ts.validate()?;
    let heads = row_of_heads(mesh, s.heads)?;
    if shades_in_one_encoder(gpu) {
        let rig_pose =
            assets.baked_rig.as_ref().map(|r| passes.rig_pose.clone().unwrap_or(RigPose::neutral(r.names.len())));
        let frame_assets = frame_assets(assets, passes);
        let key = mesh_key(mesh);
        let on_device = |g| one_encoder::render(g, mesh, key, &heads, s, ts, passes, rig_pose, &frame_assets);
        if let Some(frame) = gpu.run(on_device, || Ok(None))? {
            return Ok(frame);
        }
    }
    let (geo, g, shadow) = heads::geometry(gpu, &heads, s, passes, assets, false)?;
    let assets = frame_assets(assets, passes);
    let lit = lit_geometry(gpu, geo, &assets)?;
    let cam = s.camera();
    let (w, h) = (s.width, s.height);
    let view = cam.view();
    let inv_view = view.try_inverse().expect("a look-at view is invertible");
    let rot = view.fixed_view::<3, 3>(0, 0).into_owned();
    let mmu = mesh.mm_per_unit;
    let spacing = HEAD_SPACING_M * 1000.0 / mmu;
    let centre = 0.5 * (s.heads - 1) as f32;
    // The head of each visible pixel, from its world-space x.
    let mut pixels_of: Vec<Vec<usize>> = vec![Vec::new(); s.heads as usize];
    for i in 0..(w * h) as usize {
        if !g.covered[i] {
            continue;
        }
        let ray = heads::view_ray(&cam, w, h, i);
        let d = g.depth_mm[i] / mmu;
        let p = inv_view * Vector4::new(ray[0] * d, ray[1] * d, -d, 1.0);
        let k = (p.x / spacing + centre).round().clamp(0.0, (s.heads - 1) as f32) as usize;
        pixels_of[k].push(i);
    }
    let planes = frustum_planes_eye(&cam.projection(w as f32 / h as f32));
    let mut maps: HashMap<u32, Arc<UvMap>> = HashMap::new();
    let base = maps.entry(ts.map_size).or_insert_with(|| uv_map_of(mesh, ts.map_size));
    let d_ref_m = d_ref_m(base, h, cam.fov_y_deg);
    let weights = normalised_weights(&assets.blurs.blend);
    let sigmas = &assets.blurs.incremental_sigma_mm;
    let (lo, hi) = mesh.bounds();
    // A normal map perturbs each texel's normal in its MikkTSpace frame, as the G-buffer's pixels
    // (`surface_maps`); the split mesh has the same triangles in the same order, so the same texels.
    let normal_map = passes.surface_maps.as_ref().and_then(|m| m.normal.as_ref());
    let split = normal_map.map(|_| crate::mesh::tangents::mikktspace_tangents(mesh));
    let mut pass = gpu.prepare(|g| TextureSpaceDiffusion::new(&g.device), || Ok(()))?;
    let mut diffuse = lit.diffuse.clone();
    let mut stats = TsStats { heads: Vec::new(), d_ref_m };
    for (k, pixels) in pixels_of.iter().enumerate() {
        let dx = (k as f32 - centre) * spacing;
        let (lo_k, hi_k) = ([lo[0] + dx, lo[1], lo[2]], [hi[0] + dx, hi[1], hi[2]]);
        let distance_m = nearest_corner_distance(cam.eye, lo_k, hi_k) * mmu / 1000.0;
        let size = if ts.depth_sized { depth_sized_map(ts.map_size, d_ref_m, distance_m) } else { ts.map_size };
        let uv = maps.entry(size).or_insert_with(|| uv_map_of(mesh, size));
        let mut st = TsHeadStats { map_size: size, distance_m, pixels: pixels.len() as u64, ..Default::default() };
        // The texels as a frame for the lighting of the screen-space shaders.
        let n = (size * size) as usize;
        let mut frame = SkinFrame {
            width: size,
            height: size,
            melanin: vec![0.0; n],
            h0: vec![0.0; n],
            thickness_mm: vec![assets.luts.s_max_mm; n],
            normals: vec![[0.0, 0.0, 1.0]; n],
        };
        let texel_tangents = split.as_ref().map(|(m, t)| rasterise_uv_attribute(m, t, size));
        let mut shaded = vec![false; n];
        #[allow(clippy::needless_range_loop)] // t indexes the UV map and the texel frame alike
        for t in 0..n {
            if !uv.covered[t] {
                continue;
            }
            st.covered_texels += 1;
            let p = uv.position[t];
            let pw = [p[0] + dx, p[1], p[2]];
            let nw = uv.normal[t];
            if ts.cull && is_culled(nw, [0, 1, 2].map(|a| cam.eye[a] - pw[a])) {
                st.culled_texels += 1;
                continue;
            }
            let pe = view * Vector4::new(pw[0], pw[1], pw[2], 1.0);
            if ts.clip && !inside_frustum(&planes, [pe.x, pe.y, pe.z]) {
                st.clipped_texels += 1;
                continue;
            }
            shaded[t] = true;
            st.shaded_texels += 1;
            let (u, v) =
                (((t as u32 % size) as f32 + 0.5) / size as f32, ((t as u32 / size) as f32 + 0.5) / size as f32);
            frame.melanin[t] = s.melanin;
            // As `skin_render::geometry` at a pixel with this uv.
            frame.h0[t] = match &assets.baked_rig {
                Some(r) => r.h0_at(u, v),
                None => 0.006 * ((u * 400.0).sin() * (v * 300.0).cos()),
            };
            let nw = match (normal_map, &texel_tangents) {
                (Some(nm), Some(tt)) => mapped_normal(nw, tt[t], surface_maps_cpu::sample(nm, u, v)),
                _ => nw,
            };
            let nv = rot * Vector3::from(nw);
            frame.normals[t] = [nv.x, nv.y, nv.z];
            // The back light's transmittance joins the texel's light before the blurs (thesis §5.4), with the
            // thickness the shadow map gives at the texel's surface point (Listing 5.1).
            frame.thickness_mm[t] = shadow.thickness_mm(pw, nw).min(assets.luts.s_max_mm);
        }
        stats.heads.push(st);
        if st.shaded_texels == 0 {
            continue;
        }
        let texels =
            Geometry { frame, depth: vec![1.0; n], skin: shaded, specular: None, albedo: None, rig_at_uv: None };
        let irr = lit_geometry(gpu, texels, &assets)?.diffuse;
        let irr: Vec<[f32; 4]> = irr.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let uvs: Vec<[f32; 2]> = pixels.iter().map(|&i| g.uv[i]).collect();
        let stretch = &uv.stretch_mm_per_texel;
        let out = pass.run(
            |g, p| p.run(&g.device, &g.queue, &irr, stretch, size, sigmas, &weights, &uvs),
            |_| {
                let sum = texture_space_cpu::blur_sum(&irr, stretch, size, sigmas, &weights);
                Ok(texture_space_cpu::gather(&sum, size, &uvs))
            },
        )?;
        for (&i, o) in pixels.iter().zip(&out) {
            if o[3] > 0.0 {
                diffuse[4 * i..4 * i + 3].copy_from_slice(&o[..3]);
            }
        }
    }
    let background = heads::BACKGROUND.repeat((w * h) as usize);
    for (px, a) in diffuse.chunks_exact_mut(4).zip(lit.albedo.chunks_exact(4)) {
        for c in 0..3 {
            px[c] *= a[c];
        }
    }
    let mut img = composite(gpu, &lit.geo, &diffuse, background, assets.bloom.as_ref(), None)?;
    heads::blend_coverage(&mut img, &g.coverage);
    Ok((img, stats))
}

/// The tables of a texture-space frame, as `skin_render::render_with`'s: a neutral rig (scale 1, bias 0),
/// post-scatter texturing (the maps hold irradiance; each pixel's albedo multiplies what it gathers, thesis §7.6) and
/// the passes' bloom.
fn frame_assets(assets: &DemoAssets, passes: &SkinPasses) -> DemoAssets {
    let mut assets = assets.clone();
    assets.rig = RigScaleBiasMaps { width: 2, height: 2, targets: vec![vec![[1.0, 0.0]; 4]] };
    assets.rig_weights = vec![1.0];
    assets.post_scatter_albedo = true;
    assets.bloom = passes.bloom;
    assets
}

/// eq. 3.1's d_ref for a frame `height_px` tall with a vertical field of view `fov_y_deg`: the distance (m) at which
/// one pixel covers four texels of `map` along the coarser texel direction, max(stretch_u, stretch_v), of the median
/// texel; closer than d_ref the map keeps its full size. (Two texels per pixel changed the image at 2 m by more
/// than switching SSS off does — RMSE 0.0032 vs 0.0022, `tests/it/skin_ts.rs` — four keep it at 0.0014.)
pub fn d_ref_m(map: &UvMap, height_px: u32, fov_y_deg: f32) -> f32 {
    let mut s: Vec<f32> =
        map.stretch_mm_per_texel.iter().zip(&map.covered).filter(|(_, &c)| c).map(|(st, _)| st[0].max(st[1])).collect();
    if s.is_empty() {
        return f32::INFINITY;
    }
    let mid = s.len() / 2;
    let median = *s.select_nth_unstable_by(mid, f32::total_cmp).1;
    // Pixel footprint at distance d: d · 2 tan(fov/2) / height_px (m) = 4 · median (mm) / 1000.
    4.0 * median / 1000.0 * height_px as f32 / (2.0 * (0.5 * fov_y_deg.to_radians()).tan())
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurParams {
    size: u32,
    dir: u32,
    accumulate: u32,
    pad0: u32,
    sigma_mm: [f32; 4],
    weight: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GatherParams {
    size: u32,
    count: u32,
    pad: [u32; 2],
}

/// The GPU blur and gather pipelines (`skin/texture_space.wgsl`).
pub struct TextureSpaceDiffusion {
    blur: wgpu::ComputePipeline,
    gather: wgpu::ComputePipeline,
}

const SHADER: &str = include_str!("texture_space.wgsl");
/// Gather workgroups per dispatch row (the shader's `65535u * 64u` stride).
const GATHER_ROW_GROUPS: u32 = 65535;

impl TextureSpaceDiffusion {
    pub fn new(device: &wgpu::Device) -> Result<Self, RuntimeError> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = gpu::shader(device, "texture space", SHADER);
        let pipe = |entry: &str| gpu::compute_pipeline(device, &module, entry);
        let (blur, gather) = (pipe("blur"), pipe("gather"));
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RuntimeError::Gpu(format!("texture-space shader: {e}")));
        }
        Ok(Self { blur, gather })
    }

    /// Records the chained u/v blurs of the irradiance map in `chain` (premultiplied RGBA f32, `size`×`size`,
    /// alpha 0 = not shaded) into `enc`, ping-ponging with `temp`, and adds each Gaussian's result weighted by
    /// `weights` to `sum` (zero at the start): no submission, no read-back.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record_blurs(
        &self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        [chain, temp, sum]: [&wgpu::Buffer; 3],
        stretch: &wgpu::Buffer,
        size: u32,
        incremental_sigma_mm: &[f32],
        weights: &[[f32; 3]],
    ) {
        let groups = size.div_ceil(8);
        let layout = self.blur.get_bind_group_layout(0);
        for (sigma, w) in incremental_sigma_mm.iter().zip(weights) {
            for (dir, src, dst) in [(0u32, chain, temp), (1, temp, chain)] {
                let p = BlurParams {
                    size,
                    dir,
                    accumulate: dir,
                    pad0: 0,
                    sigma_mm: [*sigma, 0.0, 0.0, 0.0],
                    weight: [w[0], w[1], w[2], 0.0],
                };
                let ubuf = crate::runtime::frame_pool::uniform_buffer(device, "ts blur", bytemuck::bytes_of(&p));
                let bind = gpu::bind_group(
                    device,
                    "ts blur",
                    &layout,
                    &[
                        (0, ubuf.as_entire_binding()),
                        (1, src.as_entire_binding()),
                        (2, dst.as_entire_binding()),
                        (3, stretch.as_entire_binding()),
                        (4, sum.as_entire_binding()),
                    ],
                );
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("ts blur"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.blur);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups(groups, groups, 1);
            }
        }
    }

    /// The chained blurs of `irradiance` (premultiplied RGBA, `size`×`size`, alpha 0 = not shaded), their sum
    /// weighted by `weights`, sampled at `uvs`: (rgb, 1) per uv, zeros where no shaded texel is in reach. Same
    /// results as [`crate::runtime::skin::texture_space_cpu::blur_sum`] then [`crate::runtime::skin::texture_space_cpu::gather`].
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        irradiance: &[[f32; 4]],
        stretch_mm_per_texel: &[[f32; 2]],
        size: u32,
        incremental_sigma_mm: &[f32],
        weights: &[[f32; 3]],
        uvs: &[[f32; 2]],
    ) -> Result<Vec<[f32; 4]>, RuntimeError> {
        let map_bytes = map_buffer_bytes(size);
        let limit = device.limits().max_storage_buffer_binding_size;
        if map_bytes > limit {
            return Err(InvalidInput::new(
                "ts_map_size",
                format!("{size}² RGBA f32 is {map_bytes} bytes, over the adapter's storage-binding limit {limit}"),
            )
            .into());
        }
        let storage = |label: &str, bytes: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            })
        };
        let a = storage("ts chain", bytemuck::cast_slice(irradiance));
        let b = storage("ts temp", &vec![0u8; map_bytes as usize]);
        let acc = storage("ts sum", &vec![0u8; map_bytes as usize]);
        let stretch = storage("ts stretch", bytemuck::cast_slice(stretch_mm_per_texel));
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("ts") });
        self.record_blurs(device, &mut enc, [&a, &b, &acc], &stretch, size, incremental_sigma_mm, weights);
        let count = uvs.len() as u32;
        // A head with no visible pixel still has its maps blurred (as d'Eon's shader); its uv list is padded to one
        // entry because wgpu refuses empty bindings.
        let padded: Vec<[f32; 2]> = if uvs.is_empty() { vec![[0.0; 2]] } else { uvs.to_vec() };
        let uv_buf = storage("ts uvs", bytemuck::cast_slice(&padded));
        let out_bytes = gather_buffer_bytes(uvs.len() as u64);
        let out = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ts gathered"),
            size: out_bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ts readback"),
            size: out_bytes,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let gp = GatherParams { size, count, pad: [0; 2] };
        let ubuf = gpu::uniform_buffer(device, "ts gather", bytemuck::bytes_of(&gp));
        let bind = gpu::bind_group(
            device,
            "ts gather",
            &self.gather.get_bind_group_layout(0),
            &[
                (5, ubuf.as_entire_binding()),
                (6, acc.as_entire_binding()),
                (7, uv_buf.as_entire_binding()),
                (8, out.as_entire_binding()),
            ],
        );
        {
            let mut pass = enc
                .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("ts gather"), timestamp_writes: None });
            pass.set_pipeline(&self.gather);
            pass.set_bind_group(0, &bind, &[]);
            let groups = count.div_ceil(64).max(1);
            pass.dispatch_workgroups(groups.min(GATHER_ROW_GROUPS), groups.div_ceil(GATHER_ROW_GROUPS), 1);
        }
        enc.copy_buffer_to_buffer(&out, 0, &readback, 0, out_bytes);
        gpu::submit(queue, enc.finish());
        let bytes = gpu::map_read(device, &readback)?;
        let v: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        Ok(v[..uvs.len()].to_vec())
    }
}

mod one_encoder {
    //! A texture-space diffusion frame ([`crate::runtime::skin::texture_space`]; d'Eon, Luebke and Enderton 2007, thesis
    //! ch. 3) recorded into **one** command encoder, submitted once, with one read-back: the RGBA8 frame and, after it,
    //! the per-head counts of [`TsStats`]. The stages and their arithmetic are those of the per-pass path
    //! (`texture_space::render_with`, each pass submitted and read back on its own, which stays the reference and the
    //! CPU twin):
    //!
    //! 1. The frame's geometry on the device (`frame_geometry`, as the screen-space shaders' frame): the G-buffer (with
    //!    `--msaa 4` multisampled and resolved), the back light's shadow map, a scan's surface maps and the wrinkle
    //!    pass on the pixels' normals, per pixel (u, v, covered, coverage), the skin-inputs maps with the rig's
    //!    hemoglobin at the mesh's uv, the normals, the albedo map, the specular layer and the view depth; then the
    //!    frame's skin-inputs pass and its unblurred diffuse layer (`shade_frame.wgsl`'s `lit`, post-scatter:
    //!    irradiance alone).
    //! 2. Per head, its irradiance map of `T`×`T` texels (`T` from eq. 3.1–3.2 with the depth-based optimisation): the UV
    //!    map's positions, normals and coverage (rasterised on the host once per mesh and size, uploaded once per device:
    //!    [`crate::runtime::gpu::cached`]) give each texel its view normal, its culling (Listing 3.2) and clipping (eq.
    //!    3.3–3.4) and its thickness through the shadow map (Listing 5.1) (`texture_space_frame.wgsl`'s `texels`); with
    //!    a normal map the texels' normals are first bent by the surface-map pass (`surface_maps::record`, the
    //!    pixels' pass) run over the texels as its frame — (texel centre uv, covered), the UV map's normal and the
    //!    MikkTSpace tangent of the split mesh rasterised at the texels, uploaded once per device, mesh and size — in
    //!    world space (the frame is a rotation of the view's, which the mapping commutes with); the skin-inputs pass
    //!    and `lit` light the texels as the frame's pixels; the 12 chained blurs accumulate the weighted sum
    //!    (`texture_space.wgsl`); `gather` samples it at the uv of each of the head's pixels.
    //! 3. `shade_frame.wgsl`'s `composite` (post-scatter albedo: the albedo map's where the frame has one, the unblurred
    //!    specular layer), bloom, `tonemap` and, with MSAA, `coverage` (partly covered pixels blended with the
    //!    background, as the host's `blend_coverage`).

    use super::{d_ref_m, uv_map_of, TextureSpaceDiffusion, TsHeadStats, TsStats};
    use crate::image_buf::Image;
    use crate::mesh::Mesh;
    use crate::runtime::compute_chain::{self, groups_8x8, storage_buffer, Stage};
    use crate::runtime::device::Gpu;
    use crate::runtime::frame_pool;
    use crate::runtime::gpu;
    use crate::runtime::skin::bloom::{self, BloomBuffers};
    use crate::runtime::skin::frame_geometry::{self, FrameGeometryJob};
    use crate::runtime::skin::heads::{light_camera, BACKGROUND};
    use crate::runtime::skin::inputs::SkinInputs;
    use crate::runtime::skin::lighting::{DemoAssets, KEY_LIGHT_INTENSITY, TRANSMITTANCE_INTENSITY};
    use crate::runtime::skin::mesh_inputs::RigPose;
    use crate::runtime::skin::passes::SkinPasses;
    use crate::runtime::skin::settings::{
        SkinRenderSettings, TsSettings, HEAD_SPACING_M, SHADOW_MAP_SIZE, SHADOW_SHRINK_MM, WORLD_UNITS_PER_M,
    };
    use crate::runtime::skin::surface_maps;
    use crate::runtime::RuntimeError;
    use crate::shading::texture_space::{
        depth_sized_map, frustum_planes_eye, nearest_corner_distance, normalised_weights, rasterise_uv_attribute,
        CULL_ANGLE_DEG,
    };
    use std::collections::HashMap;

    /// `shade_frame.wgsl` (its stages `lit`, `composite` and `tonemap` shade the texels and the frame here).
    const SHADE_SOURCE: &str = concat!(include_str!("../aa/srgb.wgsl"), include_str!("shade_frame.wgsl"));
    /// `texture_space_frame.wgsl` with the bilinear taps it samples the blurred map with.
    const FRAME_SOURCE: &str = concat!(include_str!("bilinear_taps.wgsl"), include_str!("texture_space_frame.wgsl"));
    /// Storage buffers `texture_space_frame.wgsl` binds.
    const FRAME_BUFFERS: u32 = 11;
    /// Counts per head in the read-back (covered, culled, clipped, shaded texels, pixels).
    const COUNTS: usize = 5;

    /// `shade_frame.wgsl`'s uniform block: width, height, u32 per padded Rgba16Float row, post-scatter albedo; the key
    /// light, albedo map (0: the skin LUT's); key and back-light intensities, bloom, SSS (0: none); the background,
    /// coverage blend (0: none).
    #[repr(C)]
    #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
    struct ShadeParams {
        size: [f32; 4],
        key: [f32; 4],
        cfg: [f32; 4],
        cover: [f32; 4],
        /// The uniform background fill of `shade_frame.wgsl`'s `background` stage, unused here (zero).
        fill: [f32; 4],
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
        maps: [f32; 4],
    }

    /// Bytes of a padded row of `width` texels of `bytes_per_texel` in a texture copy.
    fn padded_row(width: u32, bytes_per_texel: u32) -> u64 {
        (width * bytes_per_texel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) as u64
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64
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
                storage_buffer(
                    device,
                    what,
                    8 * uv.covered.len() as u64,
                    Some(bytemuck::cast_slice(&uv.stretch_mm_per_texel)),
                ),
            )
        })
    }

    /// The texels of `mesh`'s UV map at `size` as the surface-map pass's frame (`view_frame.wgsl`): per texel (u, v
    /// of its centre, covered, 1), (the UV map's normal, 0) and the MikkTSpace tangent and handedness of the split
    /// mesh rasterised there (the host's per-pass loop reads the same), world space; built once per device, mesh
    /// and size.
    fn device_texel_frame(device: &wgpu::Device, mesh: &Mesh, mesh_key: u64, size: u32) -> [wgpu::Buffer; 3] {
        gpu::cached(device, "texture-space texel frame", &(mesh_key, size), || {
            let uv = uv_map_of(mesh, size);
            let (split, tangents) = crate::mesh::tangents::mikktspace_tangents(mesh);
            let tangents = rasterise_uv_attribute(&split, &tangents, size);
            let centre = |k: u32| (k as f32 + 0.5) / size as f32;
            let uvc: Vec<[f32; 4]> = (0..size * size)
                .map(|t| [centre(t % size), centre(t / size), uv.covered[t as usize] as u8 as f32, 1.0])
                .collect();
            let normals: Vec<[f32; 4]> = uv.normal.iter().map(|n| [n[0], n[1], n[2], 0.0]).collect();
            let what = "texture-space texel frame";
            [uvc, normals, tangents].map(|v| {
                let bytes: &[u8] = bytemuck::cast_slice(&v);
                storage_buffer(device, what, bytes.len() as u64, Some(bytes))
            })
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
        /// With a normal map: the texels as the surface-map pass's frame and its output (the bent normal, the
        /// albedo per texel); without: None and a 16-byte stand-in.
        texel_frame: Option<[wgpu::Buffer; 3]>,
        mapped: wgpu::Buffer,
        /// Bytes per padded row of an Rgba32Float and of an Rgba16Float image of the map.
        row32: u64,
        row16: u64,
    }

    impl MapBuffers {
        fn new(
            g: &Gpu,
            mesh: &Mesh,
            mesh_key: u64,
            size: u32,
            normal_map: bool,
            assets: &DemoAssets,
        ) -> Result<Self, RuntimeError> {
            let (device, queue) = (&g.device, &g.queue);
            let mut inputs = SkinInputs::for_compute(device, size, size, &assets.luts, &assets.rig)?;
            inputs.upload_lights(queue, &assets.rig_weights, assets.lights.back_view)?;
            let (row32, row16) = (padded_row(size, 16), padded_row(size, 8));
            let t = size as u64 * size as u64;
            let what = "ts_map_size";
            let sizes = [row32 * size as u64, 32 * t, 2 * row16 * size as u64, 16 * t];
            compute_chain::check_buffers(device, what, &sizes)?;
            // From the frame pool (content left by a former frame): `texels` writes every texel of maps, normals
            // and geo, the skin-inputs pass skin16, `lit` chain, the blurs temp, the frame clears sum, the
            // surface-map pass every texel of mapped.
            let make = |bytes| frame_pool::storage_buffer(device, what, bytes);
            let (uv_map, stretch) = device_uv_map(device, mesh, mesh_key, size);
            let texel_frame = normal_map.then(|| device_texel_frame(device, mesh, mesh_key, size));
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
                texel_frame,
                mapped: make(if normal_map { sizes[1] } else { 16 }),
                row32,
                row16,
            })
        }
    }

    /// `texture_space::render_with`'s frame of `mesh` (the row `heads` of it) on `g` in one command encoder, with
    /// `passes`' MSAA, wrinkle pass and surface maps: see the module doc; None where the device binds too few or too
    /// small storage buffers for it. `assets` are the frame's (neutral rig, post-scatter albedo, the passes' bloom);
    /// `rig_pose` the baked rig's pose when the bake has one.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn render(
        g: &Gpu,
        mesh: &Mesh,
        mesh_key: u64,
        heads: &Mesh,
        s: &SkinRenderSettings,
        ts: TsSettings,
        passes: &SkinPasses,
        rig_pose: Option<RigPose>,
        assets: &DemoAssets,
    ) -> Result<Option<(Image<u8>, TsStats)>, RuntimeError> {
        let (device, queue) = (&g.device, &g.queue);
        let limits = device.limits();
        // Every texel map's largest buffer, (normal, shaded), (0) per texel, within a storage binding.
        // (With a normal map also the surface-map pass's output over the texels.)
        let largest = 32 * ts.map_size as u64 * ts.map_size as u64;
        if limits.max_storage_buffers_per_shader_stage < FRAME_BUFFERS
            || largest > limits.max_storage_buffer_binding_size
        {
            return Ok(None);
        }
        let what = "texture-space frame";
        let cam = s.camera();
        let (w, h) = (s.width, s.height);
        let n = w as u64 * h as u64;
        // The pixels' passes as the screen-space shaders' frame records them.
        let job = FrameGeometryJob {
            mesh: heads,
            camera: cam,
            width: w,
            height: h,
            melanin: s.melanin,
            rig_pose,
            msaa: passes.msaa,
            surface_maps: passes.surface_maps.as_ref(),
            wrinkles: passes.wrinkles.as_ref(),
        };
        // The texels' normals bent by the normal map (the albedo map waits for the pixels: post-scatter).
        let normal_map = passes.surface_maps.as_ref().filter(|m| m.normal.is_some());
        // The frame's buffers come from the device's frame pool and go back to it after the read-back.
        let _frame = frame_pool::FrameScope::open(device, queue);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(what) });
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        // 1. The frame's geometry, skin inputs and unblurred diffuse layer.
        let d = frame_geometry::record(device, &mut enc, &job, assets)?;
        let mut inputs = SkinInputs::for_compute(device, w, h, &assets.luts, &assets.rig)?;
        inputs.upload_lights(queue, &assets.rig_weights, assets.lights.back_view)?;
        d.record_rig_at_uv(device, &mut enc, &job, assets)?;
        let row16 = inputs.half_row_bytes();
        let bloom_buffers = match &assets.bloom {
            Some(p) => Some(BloomBuffers::new(device, w, h, p)?),
            None => None,
        };
        let sizes = [2 * row16 * h as u64, 16 * n, 4 * n];
        compute_chain::check_buffers(device, what, &sizes)?;
        // Pooled: skin16 and diffuse are written over the whole frame before they are read (the skin-inputs pass,
        // `lit`), rgba is filled with the background by `background` below.
        let skin16 = frame_pool::storage_buffer(device, what, sizes[0]);
        let diffuse = frame_pool::storage_buffer(device, what, sizes[1]);
        let rgba = frame_pool::storage_buffer(device, what, sizes[2]);
        // Bindings a stage does not read (no SSS pass; on the texels, nothing past the lit layer).
        let unused = || frame_pool::storage_buffer(device, what, 16);
        let (hdr, bloomed) = match &bloom_buffers {
            // Without bloom, hdr is written by `composite` over the whole frame.
            Some(b) => (b.0[0].clone(), b.0[3].clone()),
            None => (frame_pool::storage_buffer(device, what, sizes[1]), unused()),
        };
        inputs.record_compute(device, &mut enc, [&d.skin_maps, &d.normals], &skin16);
        let key = assets.lights.key_view;
        let flag = |b: bool| b as u8 as f32;
        let bloom_on = flag(bloom_buffers.is_some());
        // The texels: no albedo map (post-scatter), no coverage blend.
        let shade_params = |width: u32, height: u32, row16: u64| ShadeParams {
            size: [width as f32, height as f32, (row16 / 4) as f32, 1.0],
            key: [key[0], key[1], key[2], 0.0],
            cfg: [KEY_LIGHT_INTENSITY, TRANSMITTANCE_INTENSITY, bloom_on, 0.0],
            cover: [0.0; 4],
            fill: [0.0; 4],
        };
        let shade = |enc: &mut wgpu::CommandEncoder, p: &ShadeParams, bound: &[&wgpu::Buffer], entry: &str, size| {
            let stages = [Stage::new(entry, size)];
            compute_chain::record(device, enc, what, SHADE_SOURCE, bytemuck::bytes_of(p), bound, &stages);
        };
        // The frame: the albedo map's albedo where it has one, MSAA's partly covered pixels blended after the tone
        // map (`coverage` reads `uvc`'s coverage).
        let blend_coverage = job.msaa > 1;
        let screen = ShadeParams {
            key: [key[0], key[1], key[2], flag(job.has_albedo_map())],
            cover: {
                let bg = BACKGROUND.map(|c| c as f32 / 255.0);
                [bg[0], bg[1], bg[2], flag(blend_coverage)]
            },
            fill: BACKGROUND.map(|c| c as f32 / 255.0),
            ..shade_params(w, h, row16)
        };
        let sss16 = unused();
        let frame_bound = [&skin16, &d.texels, &diffuse, &sss16, &hdr, &bloomed, &rgba, &d.uvc];
        // The uniform background filled on the device (the frame's buffer is pooled: no upload).
        shade(&mut enc, &screen, &frame_bound, "background", groups_8x8(w, h));
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
        let counts = frame_pool::storage_buffer(device, what, (4 * COUNTS) as u64 * s.heads as u64);
        // Counted with atomics: zero at the frame's start.
        enc.clear_buffer(&counts, 0, None);
        let shadow_row = padded_row(SHADOW_MAP_SIZE, 8);
        let depth_row = padded_row(w, 4);
        let texel_unused = [unused(), unused(), unused(), unused(), unused()];
        let mut maps: HashMap<u32, MapBuffers> = HashMap::new();
        let mut stats = TsStats { heads: Vec::new(), d_ref_m };
        for k in 0..s.heads {
            let dx = (k as f32 - centre) * spacing;
            let (lo_k, hi_k) = ([lo[0] + dx, lo[1], lo[2]], [hi[0] + dx, hi[1], hi[2]]);
            let distance_m = nearest_corner_distance(cam.eye, lo_k, hi_k) * mmu / 1000.0;
            let size = if ts.depth_sized { depth_sized_map(ts.map_size, d_ref_m, distance_m) } else { ts.map_size };
            stats.heads.push(TsHeadStats { map_size: size, distance_m, ..Default::default() });
            if let std::collections::hash_map::Entry::Vacant(e) = maps.entry(size) {
                let m = e.insert(MapBuffers::new(g, mesh, mesh_key, size, normal_map.is_some(), assets)?);
                // The texels' normals bent by the normal map, once per size (a head's offset is a translation).
                if let (Some(maps), Some(frame)) = (normal_map, &m.texel_frame) {
                    let frame = [&frame[0], &frame[1], &frame[2]];
                    surface_maps::record(device, &mut enc, (size, size), frame, maps, &m.mapped)?;
                }
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
                maps: [flag(normal_map.is_some()), 0.0, 0.0, 0.0],
            };
            let bound = [
                &m.uv_map, &d.shadow, &m.maps, &m.normals, &m.geo, &counts, &d.uvc, &d.depth, &m.sum, &diffuse,
                &m.mapped,
            ];
            let uniform = bytemuck::bytes_of(&params);
            let record_stage = |enc: &mut wgpu::CommandEncoder, entry, groups| {
                let stages = [Stage { entry, groups, args: [k, 0, 0, 0] }];
                compute_chain::record(device, enc, what, FRAME_SOURCE, uniform, &bound, &stages);
            };
            record_stage(&mut enc, "texels", groups_8x8(size, size));
            m.inputs.record_compute(device, &mut enc, [&m.maps, &m.normals], &m.skin16);
            let [a, b, c, e, f] = &texel_unused;
            let texel_bound = [&m.skin16, &m.geo, &m.chain, a, b, c, e, f];
            shade(&mut enc, &shade_params(size, size, m.row16), &texel_bound, "lit", groups_8x8(size, size));
            enc.clear_buffer(&m.sum, 0, None);
            blurs.record_blurs(device, &mut enc, [&m.chain, &m.temp, &m.sum], &m.stretch, size, sigmas, &weights);
            record_stage(&mut enc, "gather", groups_8x8(w, h));
        }
        // 3. Composite, bloom, tone map; the frame and the counts read back together.
        shade(&mut enc, &screen, &frame_bound, "composite", groups_8x8(w, h));
        if let (Some(p), Some(b)) = (&assets.bloom, &bloom_buffers) {
            bloom::record(device, &mut enc, w, h, p, b);
        }
        shade(&mut enc, &screen, &frame_bound, "tonemap", groups_8x8(w, h));
        if blend_coverage {
            shade(&mut enc, &screen, &frame_bound, "coverage", groups_8x8(w, h));
        }
        let readback = frame_pool::readback_buffer(device, rgba.size() + counts.size());
        enc.copy_buffer_to_buffer(&rgba, 0, &readback, 0, rgba.size());
        enc.copy_buffer_to_buffer(&counts, 0, &readback, rgba.size(), counts.size());
        gpu::submit(queue, enc.finish());
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RuntimeError::Gpu(format!("{what}: {e}")));
        }
        let out = gpu::map_read(device, &readback)?;
        let counted: Vec<u64> = out[rgba.size() as usize..]
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64)
            .collect();
        for (st, c) in stats.heads.iter_mut().zip(counted.chunks_exact(COUNTS)) {
            (st.covered_texels, st.culled_texels, st.clipped_texels, st.shaded_texels, st.pixels) =
                (c[0], c[1], c[2], c[3], c[4]);
        }
        Ok(Some((Image::from_vec(w, h, 4, out[..4 * n as usize].to_vec()), stats)))
    }

    #[cfg(test)]
    mod tests {
        use super::*;
        use crate::runtime::skin::surface_maps::{SurfaceMap, SurfaceMaps};
        use crate::runtime::skin::surface_maps_cpu::{mapped_normal, sample};

        /// The texels' normals the one-encoder frame bends on the device (the surface-map pass over the texel frame
        /// of [`device_texel_frame`]) against the host's per-pass loop (`render_with`: the split mesh's MikkTSpace
        /// tangents rasterised at the texels, [`mapped_normal`] of the UV map's normal and the map's bilinear value
        /// at the texel's centre): within 1e-4 on every covered texel of the procedural head's 128² map, and bent
        /// by more than 2.5° on most of them (the bump map acts).
        #[test]
        fn the_texels_normals_bent_on_the_device_match_the_hosts() {
            let g = crate::runtime::device::create_headless(&Default::default()).expect("an adapter (lavapipe)");
            let mesh = crate::mesh::head::default_head();
            let size = 128;
            let s = 32u32;
            let bumps = (0..s * s).map(|i| {
                let (a, b) = (0.4 * ((i % s) as f32 * 0.8).sin(), 0.4 * ((i / s) as f32 * 0.6).cos());
                let l = (a * a + b * b + 1.0).sqrt();
                [a / l, b / l, 1.0 / l, 0.0]
            });
            let map = SurfaceMap { width: s, height: s, texels: bumps.collect::<Vec<_>>().into() };
            let maps = SurfaceMaps { albedo: None, normal: Some(map.clone()) };
            let frame = device_texel_frame(&g.device, &mesh, mesh.content_key(), size);
            let out = storage_buffer(&g.device, "test", 32 * size as u64 * size as u64, None);
            let mut enc = g.device.create_command_encoder(&Default::default());
            let bound = [&frame[0], &frame[1], &frame[2]];
            surface_maps::record(&g.device, &mut enc, (size, size), bound, &maps, &out).unwrap();
            let readback = g.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("test read-back"),
                size: out.size(),
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            enc.copy_buffer_to_buffer(&out, 0, &readback, 0, out.size());
            gpu::submit(&g.queue, enc.finish());
            let bytes = gpu::map_read(&g.device, &readback).unwrap();
            let device: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
            let uv = uv_map_of(&mesh, size);
            let (split, t) = crate::mesh::tangents::mikktspace_tangents(&mesh);
            let tangents = rasterise_uv_attribute(&split, &t, size);
            let (mut covered, mut bent) = (0, 0);
            for i in (0..uv.covered.len()).filter(|&i| uv.covered[i]) {
                let centre = |k: usize| (k as f32 + 0.5) / size as f32;
                let (u, v) = (centre(i % size as usize), centre(i / size as usize));
                let host = mapped_normal(uv.normal[i], tangents[i], sample(&map, u, v));
                let d = device[2 * i];
                let worst = (0..3).map(|k| (d[k] - host[k]).abs()).fold(0.0, f32::max);
                assert!(worst <= 1e-4, "texel {i}: {d:?} on the device, {host:?} on the host");
                covered += 1;
                let n = uv.normal[i];
                bent += (n[0] * host[0] + n[1] * host[1] + n[2] * host[2] < 0.999) as usize;
            }
            assert!(covered > 5000 && 2 * bent > covered, "{bent} of {covered} texels bent");
        }
    }
}
