//! `rtbake run skin`: heads rendered from a triangle mesh through the skin chain (TAP 2009 §5–6 compares
//! shaders on heads; thesis ch. 4–6 for the screen-space passes, ch. 5 Listing 5.1 for thickness from a shadow map).
//!
//! 1. The mesh (the procedural [`crate::mesh::head::default_head`] or a glTF/OBJ), repeated `heads` times 0.25 m
//!    apart along x, is rasterised into a G-buffer ([`crate::runtime::skin::mesh_raster`], GPU or its CPU twin).
//! 2. A 512² shadow map from the back light (TAP 2009 used 512²) gives the thickness the light crosses to reach
//!    each visible point: the point's distance from the light minus the shadow map's nearest distance along the
//!    same ray (Listing 5.1), in mm.
//! 3. Skin inputs per pixel: melanin `melanin` (uniform), hemoglobin H of the baked rig's eq. 7.6 (weights and
//!    the global anger/fear state of [`SkinPasses::rig_pose`]) evaluated at the mesh's texture coordinates
//!    ([`crate::runtime::skin::mesh_inputs`]: the face maps are texture-space maps), view-space normals, thickness; the
//!    skin-inputs pass then runs with a neutral rig (scale 1, bias 0), so its hemoglobin is that H (its own rig
//!    lookup samples screen space, right for the screen-space demo and wrong for a mesh).
//!    With [`SkinPasses::wrinkles`], the wrinkle pass of Listing 8.1 ([`crate::runtime::skin::wrinkles`]) replaces the
//!    G-buffer's normals before any lighting.
//!    With `--msaa 4` ([`SkinPasses::msaa`]) the G-buffer is rasterised with 4 samples per pixel
//!    ([`crate::runtime::skin::mesh_raster::RasterJob::samples`]) and partly covered pixels are blended with the background by
//!    their coverage after shading (the shadow map stays at 1 sample).
//! 4. The demo's shading in the thesis' order: Lambert key light; the SSS pass of `shader` (none, separable or
//!    the screen-space sum of Gaussians) on the diffuse irradiance, view depth in head-sized world units
//!    ([`WORLD_UNITS_PER_M`]); skin colour (albedo from the skin LUT) applied **after** the SSS pass
//!    (post-scatter texturing, thesis §7.6: "to avoid blurring the albedo twice"; the procedural demo blurs
//!    albedo · irradiance instead); the back light's transmittance stored with the reflected light and blurred with
//!    it (thesis §5.4); the Kelemen/Szirmay-Kalos specular layer added
//!    after the SSS pass, never blurred (ch. 4, separate render targets; the demo has none); bloom on the final
//!    HDR frame before tone mapping ([`SkinPasses::bloom`], ch. 4; the demo has none); tone-mapped and encoded
//!    over a grey background.
//!
//! On a device every screen-space frame is one command encoder, submitted once and read back once as the RGBA8
//! frame: the G-buffer and the shadow map are rasterised into it, a scan's surface maps and the wrinkle pass
//! replace the normals there, thickness, the specular layer and the per-pixel skin inputs are computed from them
//! on the device (`frame_geometry`, the GPU twin of steps 2–3; with `--msaa 4` from the resolved G-buffer divided
//! by its coverage), then the rig at uv and everything from the skin-inputs pass to the tone map, and with MSAA the
//! coverage blend ([`crate::runtime::skin::shade_frame`]). The host's geometry (steps 2–3 on the host, the wrinkle
//! pass and the surface maps one submission each, the coverage blend after the read-back) is the CPU twin's
//! reference and the per-pass path
//! ([`crate::runtime::skin::shade_frame::set_shading_in_one_encoder`] off), which submits and reads back each pass on its
//! own, for A/B comparison. Texture-space diffusion
//! ([`crate::runtime::skin::texture_space`]) is one submission and one read-back under the same conditions.
//! [`render_on_device_with`] renders a screen-space frame without the read-back ([`DeviceFrame`], read back on
//! demand); the frame's buffers and textures come from the device's frame pool ([`crate::runtime::frame_pool`]).

use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::mesh::Mesh;
use crate::runtime::backend::Backend;
use crate::runtime::device::Gpu;
use crate::runtime::skin::frame_geometry::FrameGeometryJob;
use crate::runtime::skin::heads::{blend_coverage, geometry, row_of_heads, BACKGROUND};
use crate::runtime::skin::inputs::RigScaleBiasMaps;
use crate::runtime::skin::lighting::subsurface_of;
use crate::runtime::skin::lighting::{DemoAssets, SssMethod};
use crate::runtime::skin::mesh_inputs::RigPose;
use crate::runtime::skin::passes::SkinPasses;
use crate::runtime::skin::settings::{SkinRenderSettings, SkinShader, WORLD_UNITS_PER_M};
pub use crate::runtime::skin::shade_frame::DeviceFrame;
use crate::runtime::skin::shade_frame::{render_geometry, render_on_device, shade_on_device, shades_in_one_encoder};
use crate::runtime::skin::shade_frame::{Background, FrameSource};
use crate::runtime::sss::importance::{ImportanceSamples, ImportanceSssParams};
use crate::runtime::RuntimeError;

/// The largest `w`×`h` frame with `width`:`height`'s aspect (scaled down from it) for which `fits` holds.
pub(crate) fn largest_fitting(width: u32, height: u32, fits: impl Fn(u32, u32) -> bool) -> Option<(u32, u32)> {
    let (mut w, mut h) = (width, height);
    // Halve to a size that fits, then grow back in 1 % steps: a few dozen pure evaluations.
    while !fits(w, h) {
        if w <= 1 && h <= 1 {
            return None;
        }
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
    let scaled = |k: f64| (((width as f64 * k) as u32).max(1), ((height as f64 * k) as u32).max(1));
    let mut k = w as f64 / width as f64;
    while k < 1.0 {
        let next = scaled((k * 1.01).min(1.0));
        if !fits(next.0, next.1) || next == (w, h) {
            break;
        }
        (w, h) = next;
        k = (k * 1.01).min(1.0);
    }
    // Then single pixels, keeping the aspect as closely as whole pixels allow.
    while w < width && fits(w + 1, (((w + 1) as u64 * height as u64) / width as u64).max(1) as u32) {
        w += 1;
        h = ((w as u64 * height as u64) / width as u64).max(1) as u32;
    }
    Some((w, h))
}

/// Checks every GPU pass of the `run skin` frame `s` with `passes` against the adapter's `limits` — before any
/// work, so an over-limit frame is refused at once instead of after rendering — and refuses with the pass, the
/// limit, the largest frame of the same aspect that fits and the flags that avoid it (`--width/--height`,
/// `--bloom off`, `--ts-map-size`, `--cpu`: the CPU twins have no such limit). Each pass's footprint comes from the
/// function beside it: the G-buffer ([`mesh_raster::GBUFFER_BYTES_PER_TEXEL`], the largest per-pixel image, as
/// the SSS passes' textures are smaller), the rig at uv ([`mesh_inputs::largest_buffer_bytes`]), the wrinkle pass
/// ([`wrinkles::largest_buffer_bytes`]) and, for it or a scan's surface maps, the G-buffer's three targets copied
/// for them on the device, the texture-space gather ([`texture_space::gather_buffer_bytes`]), bloom ([`bloom::largest_buffer_bytes`]) and the texture-space irradiance
/// map ([`texture_space::map_buffer_bytes`]).
///
/// [`mesh_raster::GBUFFER_BYTES_PER_TEXEL`]: crate::runtime::skin::mesh_raster::GBUFFER_BYTES_PER_TEXEL
/// [`mesh_inputs::largest_buffer_bytes`]: crate::runtime::skin::mesh_inputs::largest_buffer_bytes
/// [`wrinkles::largest_buffer_bytes`]: crate::runtime::skin::wrinkles::largest_buffer_bytes
/// [`bloom::largest_buffer_bytes`]: crate::runtime::skin::bloom::largest_buffer_bytes
/// [`texture_space::gather_buffer_bytes`]: crate::runtime::skin::texture_space::gather_buffer_bytes
/// [`texture_space::map_buffer_bytes`]: crate::runtime::skin::texture_space::map_buffer_bytes
pub fn check_frame_fits(
    limits: &wgpu::Limits,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
) -> Result<(), InvalidInput> {
    use crate::runtime::device::readback_bytes;
    use crate::runtime::skin::{bloom, mesh_inputs, mesh_raster, texture_space, wrinkles};
    let (w, h) = (s.width, s.height);
    let edge = limits.max_texture_dimension_2d;
    let storage = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    let gbuffer = mesh_raster::GBUFFER_BYTES_PER_TEXEL;
    let gbuffer_fits =
        |w: u32, h: u32| w <= edge && h <= edge && readback_bytes(w, h, gbuffer) <= limits.max_buffer_size;
    // Per-pixel storage buffers of the passes this frame runs: (pass, bytes of a w×h frame, way out).
    type PerPixel = (&'static str, fn(u32, u32) -> u64, &'static str);
    let mut per_pixel: Vec<PerPixel> = Vec::new();
    if passes.rig_pose.is_some() {
        per_pixel.push(("the rig at uv (`rig_weights`)", mesh_inputs::largest_buffer_bytes, ""));
    }
    if passes.wrinkles.is_some() {
        per_pixel.push(("the wrinkle pass (`wrinkles`)", wrinkles::largest_buffer_bytes, ""));
    }
    if passes.wrinkles.is_some() || passes.surface_maps.is_some() {
        // On a device the two read the G-buffer's three targets, copied into one buffer with padded rows.
        let copy: fn(u32, u32) -> u64 = |w, h| 3 * readback_bytes(w, h, 8);
        per_pixel.push(("the G-buffer copy of the surface-map and wrinkle passes", copy, ""));
    }
    if matches!(s.shader, SkinShader::Ts(_)) {
        // A head covering every pixel gathers one RGBA f32 per pixel.
        let gather: fn(u32, u32) -> u64 = |w, h| texture_space::gather_buffer_bytes(w as u64 * h as u64);
        per_pixel.push(("the texture-space gather (`shader` ts)", gather, ""));
    }
    if passes.bloom.is_some() {
        per_pixel.push(("bloom", bloom::largest_buffer_bytes, ", or `bloom` off"));
    }
    let all_fit = |w: u32, h: u32| gbuffer_fits(w, h) && per_pixel.iter().all(|(_, bytes, _)| bytes(w, h) <= storage);
    let largest = || match largest_fitting(w, h, all_fit) {
        Some((fw, fh)) => format!("`width` {fw} `height` {fh} is the largest frame of this aspect that fits"),
        None => "no frame of this aspect fits".to_string(),
    };
    let flag = "width/height";
    if !gbuffer_fits(w, h) {
        return Err(InvalidInput::new(
            flag,
            format!(
                "{w}x{h}: the G-buffer ({gbuffer} bytes per pixel, a {}-byte read-back) exceeds this GPU's limits \
                (max_texture_dimension_2d {edge}, max_buffer_size {}); {}; or `cpu` (the CPU twins have no such \
                limit)",
                readback_bytes(w, h, gbuffer),
                limits.max_buffer_size,
                largest()
            ),
        ));
    }
    for (pass, bytes, way_out) in &per_pixel {
        let b = bytes(w, h);
        if b > storage {
            return Err(InvalidInput::new(
                flag,
                format!(
                    "{w}x{h}: {pass} needs a {b}-byte storage buffer, over this GPU's limit of {storage} bytes \
                    (max_storage_buffer_binding_size); {}{way_out}; or `cpu` (the CPU twins have no such limit)",
                    largest()
                ),
            ));
        }
    }
    if let Some(maps) = &passes.surface_maps {
        maps.check_fits(storage)?;
    }
    if let SkinShader::Ts(ts) = s.shader {
        // With --ts-opt depth, --ts-map-size is the largest map (T_max); every map is at most that.
        let b = texture_space::map_buffer_bytes(ts.map_size);
        if b > storage || ts.map_size > edge {
            let mut fit = ts.map_size.min(edge);
            while texture_space::map_buffer_bytes(fit) > storage {
                fit -= 1;
            }
            return Err(InvalidInput::new(
                "ts_map_size",
                format!(
                    "{}: the {0}² irradiance map needs {b}-byte storage buffers, over this GPU's limit of {storage} \
                    bytes (max_storage_buffer_binding_size) or its {edge}-texel edge; use `ts_map_size` {fit} or \
                    less, or `cpu` (the CPU twins have no such limit)",
                    ts.map_size
                ),
            ));
        }
    }
    Ok(())
}

/// Wall time of `run skin` with `s` on a software adapter (lavapipe, llvmpipe), PNG included: an upper bound of what
/// was measured with the debug build on the project's 2-core machine (lavapipe: llvmpipe 15 through Vulkan;
/// separable shader and bloom unless named): 0.76 s at 512², 2.79 s at 1024², 2.94 s for 4 heads at 1024², `--shader ts` 2.73 s at 512² and
/// 4.33 s at 1024², 7.79 s for 4 heads at 512², 30.4 s, 29.8 s and 35.1 s (no bloom) for 16 heads at 512², 1024²
/// and 2880² (1024² maps). 1.5 s of start-up, 3 µs per pixel and, for the
/// texture-space shader, 2.5 µs per irradiance-map texel per head.
pub fn software_adapter_time_estimate_seconds(s: &SkinRenderSettings) -> f64 {
    let pixels = s.width as f64 * s.height as f64;
    let maps = match s.shader {
        SkinShader::Ts(ts) => s.heads as f64 * ts.map_size as f64 * ts.map_size as f64,
        _ => 0.0,
    };
    1.5 + 3.0e-6 * pixels + 2.5e-6 * maps
}

/// The 13 jittered taps of d'Eon's 6-Gaussian skin as the disk pass's samples; the follow-surface cut-off is 1.5×
/// the widest tap.
pub fn jittered_samples() -> Result<ImportanceSamples, InvalidInput> {
    let taps = crate::sss_sampling::jittered::hable13(&crate::diffusion::sum_of_gaussians::deon6())?;
    let widest = taps.iter().map(|t| t.r_mm()).fold(0.0, f64::max);
    Ok(ImportanceSamples {
        offsets_mm: taps.iter().map(|t| [t.x_mm as f32, t.y_mm as f32, t.r_mm() as f32, 0.0]).collect(),
        weights: taps.iter().map(|t| [t.weight[0] as f32, t.weight[1] as f32, t.weight[2] as f32, 0.0]).collect(),
        cutoff_mm: (1.5 * widest) as f32,
    })
}

/// Renders `mesh` as `s` says with the baked tables of `assets` (RGBA8, sRGB-encoded): the SSS shader alone,
/// [`SkinPasses::none`] (no bloom: `run skin`'s defaults are [`SkinPasses::default`], through [`render_with`]).
pub fn render<'g>(
    gpu: impl Into<Backend<'g>>,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    assets: &DemoAssets,
) -> Result<Image<u8>, RuntimeError> {
    let gpu: Backend = gpu.into();
    render_with(gpu, mesh, s, &SkinPasses::none(), assets)
}

/// [`render`] with the passes of `passes` (rig pose, …).
pub fn render_with<'g>(
    gpu: impl Into<Backend<'g>>,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> Result<Image<u8>, RuntimeError> {
    let gpu: Backend = gpu.into();
    if let SkinShader::Ts(ts) = s.shader {
        return crate::runtime::skin::texture_space::render_with(gpu, mesh, s, ts, passes, assets).map(|(img, _)| img);
    }
    let (heads, assets_used, method) = screen_space_frame(mesh, s, passes, assets)?;
    if shades_in_one_encoder(gpu) {
        // The geometry computed on the device in the shading's encoder: the G-buffer is never read back.
        let job = device_job(&heads, s, passes, assets);
        return render_on_device(gpu, &job, &assets_used, method, Background::Uniform(BACKGROUND));
    }
    // The CPU twin, or the per-pass path on a device: the rig at uv evaluated with the geometry.
    let background = BACKGROUND.repeat((s.width * s.height) as usize);
    let (geo, g, _) = geometry(gpu, &heads, s, passes, assets, false)?;
    let mut frame = render_geometry(gpu, geo, &assets_used, method, background, None)?;
    blend_coverage(&mut frame, &g.coverage);
    Ok(frame)
}

/// [`render_with`] on a device, its frame left there: the one-encoder frame submitted without a read-back, as an
/// engine presents a frame it never copies to the host. [`DeviceFrame::read_back`] copies it out on demand (the
/// same bytes as [`render_with`]'s). For the screen-space shaders (texture-space diffusion is refused, naming
/// `shader`).
pub fn render_on_device_with(
    g: &Gpu,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> Result<DeviceFrame, RuntimeError> {
    if let SkinShader::Ts(_) = s.shader {
        let msg = "a frame left on the device is rendered by the screen-space shaders (none, ss-full, ss-jittered, \
                   separable)";
        return Err(InvalidInput::new("shader", msg).into());
    }
    let (heads, assets_used, method) = screen_space_frame(mesh, s, passes, assets)?;
    let job = device_job(&heads, s, passes, assets);
    let sss = subsurface_of(&assets_used, method)?;
    shade_on_device(g, FrameSource::Device(&job), &assets_used, sss.as_ref(), Background::Uniform(BACKGROUND))
}

/// A screen-space frame's heads, the assets its shading uses (a neutral rig, the shader's parameters, the passes'
/// bloom) and its SSS method.
fn screen_space_frame(
    mesh: &Mesh,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> Result<(Mesh, DemoAssets, Option<SssMethod>), RuntimeError> {
    s.validate()?;
    let heads = row_of_heads(mesh, s.heads)?;
    let mut assets = assets.clone();
    // A neutral rig (scale 1, bias 0): see the module doc.
    assets.rig = RigScaleBiasMaps { width: 2, height: 2, targets: vec![vec![[1.0, 0.0]; 4]] };
    assets.rig_weights = vec![1.0];
    assets.sss.fovy_deg = s.camera().fov_y_deg;
    assets.bloom = passes.bloom;
    assets.post_scatter_albedo = true;
    let method = match s.shader {
        SkinShader::None => None,
        SkinShader::SsFull => {
            assets.gaussian_params = s.stretch.apply(assets.gaussian_params, s.camera().fov_y_deg);
            Some(SssMethod::Gaussians)
        }
        SkinShader::Separable => Some(SssMethod::Separable),
        SkinShader::SsJittered => {
            assets.importance = Some(jittered_samples()?);
            assets.importance_params = ImportanceSssParams {
                mm_per_world_unit: 1000.0 / WORLD_UNITS_PER_M,
                fovy_deg: s.camera().fov_y_deg,
                follow_surface: true,
            };
            Some(SssMethod::Importance)
        }
        SkinShader::Ts(_) => unreachable!("texture-space diffusion is rendered elsewhere"),
    };
    Ok((heads, assets, method))
}

/// The device geometry of a frame of `heads` (the original `assets`' baked rig posed by `passes`).
pub(crate) fn device_job<'a>(
    heads: &'a Mesh,
    s: &SkinRenderSettings,
    passes: &'a SkinPasses,
    assets: &DemoAssets,
) -> FrameGeometryJob<'a> {
    let rig_pose =
        assets.baked_rig.as_ref().map(|r| passes.rig_pose.clone().unwrap_or(RigPose::neutral(r.names.len())));
    FrameGeometryJob {
        mesh: heads,
        camera: s.camera(),
        width: s.width,
        height: s.height,
        melanin: s.melanin,
        rig_pose,
        msaa: passes.msaa,
        surface_maps: passes.surface_maps.as_ref(),
        wrinkles: passes.wrinkles.as_ref(),
    }
}

#[cfg(test)]
mod limits_tests {
    use super::*;
    use crate::runtime::skin::bloom::largest_buffer_bytes as bloom_bytes;
    use crate::runtime::skin::settings::{StretchPreset, TsSettings};

    fn settings(shader: SkinShader, width: u32, height: u32) -> SkinRenderSettings {
        SkinRenderSettings {
            shader,
            heads: 1,
            distance_m: 0.6,
            width,
            height,
            melanin: 0.02,
            stretch: StretchPreset::Thesis,
        }
    }

    /// A software adapter's limits: 128 MiB storage bindings, 8192-texel textures.
    fn limits() -> wgpu::Limits {
        wgpu::Limits {
            max_storage_buffer_binding_size: 1 << 27,
            max_buffer_size: 1 << 31,
            max_texture_dimension_2d: 8192,
            ..wgpu::Limits::downlevel_defaults()
        }
    }

    fn suggested(msg: &str) -> (u32, u32) {
        let rest = &msg[msg.find("`width` ").expect(msg) + 8..];
        let w: u32 = rest.split_whitespace().next().unwrap().parse().unwrap();
        let h: u32 = rest.split("`height` ").nth(1).unwrap().split_whitespace().next().unwrap().parse().unwrap();
        (w, h)
    }

    #[test]
    fn bloom_over_the_storage_limit_is_refused_naming_the_flags_and_the_largest_frame() {
        let l = limits();
        // The pyramid's largest buffer is the frame (16 bytes per pixel): 2560x1440 (refused with the
        // full-resolution blur's 176947200-byte buffer) now fits; 4096x2304 does not.
        assert_eq!(check_frame_fits(&l, &settings(SkinShader::Separable, 2560, 1440), &SkinPasses::default()), Ok(()));
        let s = settings(SkinShader::Separable, 4096, 2304);
        let err = check_frame_fits(&l, &s, &SkinPasses::default()).unwrap_err();
        assert_eq!(err.param, "width/height");
        for part in ["bloom", "150994944", "134217728", "`bloom` off", "`cpu`", "max_storage_buffer_binding_size"] {
            assert!(err.message.contains(part), "{part}: {err}");
        }
        let (w, h) = suggested(&err.message);
        assert!(bloom_bytes(w, h) <= 1 << 27, "{w}x{h}");
        // The next wider frame of the same aspect does not fit.
        assert!(bloom_bytes(w + 1, (w + 1) * 2304 / 4096) > 1 << 27, "{w}x{h} is not the largest");
        // 16:9 kept to a pixel.
        assert!((w as f64 / h as f64 - 16.0 / 9.0).abs() < 0.01, "{w}x{h}");
        // Without bloom the same frame fits; so does the suggested one with bloom.
        assert_eq!(check_frame_fits(&l, &s, &SkinPasses::none()), Ok(()));
        assert_eq!(check_frame_fits(&l, &settings(SkinShader::Separable, w, h), &SkinPasses::default()), Ok(()));
    }

    #[test]
    fn a_mapped_frame_whose_g_buffer_copy_is_over_the_storage_limit_is_refused() {
        use crate::runtime::skin::surface_maps::{SurfaceMap, SurfaceMaps};
        let l = limits();
        let map = SurfaceMap { width: 2, height: 2, texels: vec![[0.0, 0.0, 1.0, 0.0]; 4].into() };
        let mapped =
            SkinPasses { surface_maps: Some(SurfaceMaps { albedo: None, normal: Some(map) }), ..SkinPasses::none() };
        // 3 targets × 8 bytes × 2880×1620 = 111974400 bytes fit in 128 MiB; 3840×2160 (199065600) does not.
        assert_eq!(check_frame_fits(&l, &settings(SkinShader::Separable, 2880, 1620), &mapped), Ok(()));
        let s = settings(SkinShader::Separable, 3840, 2160);
        assert_eq!(check_frame_fits(&l, &s, &SkinPasses::none()), Ok(()));
        let err = check_frame_fits(&l, &s, &mapped).unwrap_err();
        assert_eq!(err.param, "width/height");
        assert!(err.message.contains("G-buffer copy") && err.message.contains("199065600"), "{err}");
        let (w, h) = suggested(&err.message);
        assert!(3 * crate::runtime::device::readback_bytes(w, h, 8) <= 1 << 27, "{w}x{h}");
    }

    #[test]
    fn a_frame_beyond_the_texture_edge_and_an_oversized_irradiance_map_are_refused() {
        let l = wgpu::Limits { max_texture_dimension_2d: 2048, ..limits() };
        let err = check_frame_fits(&l, &settings(SkinShader::None, 4096, 1024), &SkinPasses::none()).unwrap_err();
        assert!(err.message.contains("G-buffer") && err.message.contains("`cpu`"), "{err}");
        assert_eq!(suggested(&err.message), (2048, 512));
        let small = wgpu::Limits { max_storage_buffer_binding_size: 1 << 20, ..limits() };
        let ts = SkinShader::Ts(TsSettings { map_size: 1024, ..Default::default() });
        let err = check_frame_fits(&small, &settings(ts, 64, 64), &SkinPasses::none()).unwrap_err();
        assert_eq!(err.param, "ts_map_size");
        // 256² RGBA f32 is exactly 1 MiB.
        assert!(err.message.contains("`ts_map_size` 256 ") && err.message.contains("`cpu`"), "{err}");
    }
}
