//! `rtbake run skin`: heads rendered from a triangle mesh through the skin chain (issue 14; TAP 2009 §5–6 compares
//! shaders on heads; thesis ch. 4–6 for the screen-space passes, ch. 5 Listing 5.1 for thickness from a shadow map).
//!
//! 1. The mesh (the procedural [`crate::mesh::head::default_head`] or a glTF/OBJ), repeated `heads` times 0.25 m
//!    apart along x, is rasterised into a G-buffer ([`super::mesh_raster`], GPU or its CPU twin).
//! 2. A 512² shadow map from the back light (TAP 2009 used 512²) gives the thickness the light crosses to reach
//!    each visible point: the point's distance from the light minus the shadow map's nearest distance along the
//!    same ray (Listing 5.1), in mm.
//! 3. Skin inputs per pixel: melanin `melanin` (uniform), hemoglobin H of the baked rig's eq. 7.6 (weights and
//!    the global anger/fear state of [`SkinPasses::rig_pose`]) evaluated at the mesh's texture coordinates
//!    ([`super::mesh_skin_inputs`]: the face maps are texture-space maps), view-space normals, thickness; the
//!    skin-inputs pass then runs with a neutral rig (scale 1, bias 0), so its hemoglobin is that H (its own rig
//!    lookup samples screen space, right for the screen-space demo and wrong for a mesh).
//!    With [`SkinPasses::wrinkles`], the wrinkle pass of Listing 8.1 ([`super::wrinkle_pass`]) replaces the
//!    G-buffer's normals before any lighting.
//!    With `--msaa 4` ([`SkinPasses::msaa`]) the G-buffer is rasterised with 4 samples per pixel
//!    ([`super::mesh_raster::rasterise_samples`]) and partly covered pixels are blended with the background by
//!    their coverage after shading (the shadow map stays at 1 sample).
//! 4. The demo's shading in the thesis' order: Lambert key light; the SSS pass of `shader` (none, separable or
//!    the screen-space sum of Gaussians) on the diffuse irradiance, view depth in head-sized world units
//!    ([`WORLD_UNITS_PER_M`]); skin colour (albedo from the skin LUT) applied **after** the SSS pass
//!    (post-scatter texturing, thesis §7.6: "to avoid blurring the albedo twice"; the procedural demo blurs
//!    albedo · irradiance instead); back-lit transmittance added; the Kelemen/Szirmay-Kalos specular layer added
//!    after the SSS pass, never blurred (ch. 4, separate render targets; the demo has none); bloom on the final
//!    HDR frame before tone mapping ([`SkinPasses::bloom`], ch. 4; the demo has none); tone-mapped and encoded
//!    over a grey background.

use super::cpu;
use super::demo::{
    back_light_view, key_light_view, render_geometry, DemoAssets, Geometry, SssMethod, KEY_LIGHT_INTENSITY,
};
use super::device::Gpu;
use super::gaussian_sss::GaussianSssParams;
use super::importance_sss::{ImportanceSamples, ImportanceSssParams};
use super::mesh_raster::{self, MeshGBuffer};
use super::skin_inputs::{RigScaleBiasMaps, SkinFrame};
use super::skin_passes::SkinPasses;
use super::RuntimeError;
use crate::error::{check_range, InvalidInput};
use crate::image_buf::Image;
use crate::mesh::camera::Camera;
use crate::mesh::Mesh;
use nalgebra::{Matrix4, Vector3, Vector4};

/// The skin shaders of `run skin` available so far.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkinShader {
    /// Diffuse lighting with no subsurface scattering (TAP's "No SSS").
    None,
    /// Screen-space sum of Gaussians (TAP's "SS Full", thesis ch. 4) with the baked fit.
    SsFull,
    /// Separable SSS (thesis ch. 6) with the baked kernel.
    Separable,
    /// TAP's "SS Jittered": Hable et al.'s 13 jittered taps ([`crate::sss_sampling::jittered::hable13`] of
    /// d'Eon's 6 Gaussians) in one disk pass (the importance-sampled pass, physically scaled by depth).
    SsJittered,
}

/// The stretch parameters of the SS Full shader (eq. 4.1–4.4 / TAP 2009 eq. 2–3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum StretchPreset {
    /// The bake's fit parameters (the thesis' α = 31.5, β = 800, γ = 0.001 unless the bake says otherwise).
    #[default]
    Thesis,
    /// TAP 2009 §4: "empirically fixed values of α = 11 and β = 800", with no clamp of the depth derivative.
    Tap2009,
}

impl StretchPreset {
    /// The parameters for `base` (the bake's).
    pub fn apply(self, base: GaussianSssParams) -> GaussianSssParams {
        match self {
            StretchPreset::Thesis => base,
            // γ = f32::MAX: min(|∂d|, γ) = |∂d|, TAP's eq. 2–3 have no clamp.
            StretchPreset::Tap2009 => GaussianSssParams { alpha: 11.0, beta: 800.0, gamma: f32::MAX, ..base },
        }
    }
}

/// Heads side by side, centre to centre, metres.
pub const HEAD_SPACING_M: f32 = 0.25;
/// Shadow-map edge, texels (TAP 2009: "a shadow map resolution of 512x512").
pub const SHADOW_MAP_SIZE: u32 = 512;
/// Listing 5.1's shrink of the position along the normal before the shadow-map lookup, mm.
pub const SHADOW_SHRINK_MM: f32 = 5.0;
/// World units of the SSS passes per metre: their parameters (sssWidth, α, β) are stated for a head one world
/// unit tall (`runtime::gaussian_sss`), and the default head is 0.21 m tall.
pub const WORLD_UNITS_PER_M: f32 = 1.0 / 0.21;
/// The background colour, RGBA8 sRGB.
const BACKGROUND: [u8; 4] = [46, 48, 52, 255];
/// Most heads per frame (TAP 2009 Table III measures 1, 3 and 5).
pub const MAX_HEADS: u32 = 16;

/// What `run skin` renders.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkinRenderSettings {
    pub shader: SkinShader,
    pub heads: u32,
    /// Camera distance from the heads' plane, metres.
    pub distance_m: f32,
    pub width: u32,
    pub height: u32,
    /// Melanin volume fraction Cm (uniform over the skin).
    pub melanin: f32,
    /// Stretch parameters of `SkinShader::SsFull`.
    pub stretch: StretchPreset,
}

impl SkinRenderSettings {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_range("--heads", self.heads, 1, MAX_HEADS, "")?;
        check_range("--distance", self.distance_m as f64, 0.2, 100.0, "m")?;
        check_range("--melanin", self.melanin as f64, 0.0, 0.5, "(volume fraction)")?;
        crate::error::check_size("--width/--height", self.width as u64, self.height as u64)?;
        Ok(())
    }

    /// The camera: on +z looking at the row of heads' centre.
    pub fn camera(&self) -> Camera {
        Camera::facing(self.distance_m).expect("distance validated")
    }
}

/// `heads` copies of `mesh`, `HEAD_SPACING_M` apart along x, centred on x = 0 (mesh units are converted with
/// `mm_per_unit`).
pub fn row_of_heads(mesh: &Mesh, heads: u32) -> Result<Mesh, InvalidInput> {
    if heads == 1 {
        return Ok(mesh.clone());
    }
    let spacing = HEAD_SPACING_M * 1000.0 / mesh.mm_per_unit;
    let n = mesh.positions.len() as u32;
    let (mut pos, mut nrm, mut uvs, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for k in 0..heads {
        let dx = (k as f32 - 0.5 * (heads - 1) as f32) * spacing;
        pos.extend(mesh.positions.iter().map(|p| [p[0] + dx, p[1], p[2]]));
        nrm.extend_from_slice(&mesh.normals);
        uvs.extend_from_slice(&mesh.uvs);
        idx.extend(mesh.indices.iter().map(|i| i + k * n));
    }
    Mesh::new("--heads", pos, nrm, uvs, idx, mesh.mm_per_unit)
}

fn rasterise(gpu: Option<&Gpu>, mesh: &Mesh, cam: &Camera, w: u32, h: u32) -> Result<MeshGBuffer, RuntimeError> {
    match gpu {
        Some(g) => mesh_raster::rasterise(&g.device, &g.queue, mesh, cam, w, h),
        None => Ok(cpu::mesh_raster::rasterise(mesh, cam, w, h)),
    }
}

/// The light camera of the shadow map: 1.5 m from the heads towards the back light, looking at them.
fn light_camera(cam: &Camera) -> Camera {
    // View → world for directions: the transpose of the view rotation.
    let view = cam.view();
    let l = Vector3::from(back_light_view());
    let rot = view.fixed_view::<3, 3>(0, 0).transpose();
    let dir = rot * l;
    let target = Vector3::from(cam.target);
    let eye = target + dir * 1.5;
    Camera { eye: eye.into(), target: cam.target, up: [0.0, 1.0, 0.0], fov_y_deg: 40.0, near: 0.3, far: 3.0 }
}

/// Per covered pixel, the thickness (mm) the back light crosses to reach it (Listing 5.1), from a shadow map.
/// The view-space ray through the centre of pixel `i` of a `w`×`h` image, scaled to view depth 1 (z = −1).
fn view_ray(cam: &Camera, w: u32, h: u32, i: usize) -> [f32; 3] {
    let t = (0.5 * cam.fov_y_deg.to_radians()).tan();
    let aspect = w as f32 / h as f32;
    let (px, py) = ((i as u32 % w) as f32 + 0.5, (i as u32 / w) as f32 + 0.5);
    let (xn, yn) = (px / w as f32 * 2.0 - 1.0, 1.0 - py / h as f32 * 2.0);
    [xn * t * aspect, yn * t, -1.0]
}

fn thickness_mm(g: &MeshGBuffer, cam: &Camera, shadow: &MeshGBuffer, light: &Camera, mm_per_unit: f32) -> Vec<f32> {
    let (w, h) = (g.width, g.height);
    let inv_view = cam.view().try_inverse().expect("a look-at view is invertible");
    let light_view = light.view();
    let light_vp: Matrix4<f32> = light.projection(1.0) * light_view;
    let s = SHADOW_MAP_SIZE as f32;
    let mut out = vec![0.0f32; (w * h) as usize];
    for (i, o) in out.iter_mut().enumerate() {
        if !g.covered[i] {
            continue;
        }
        let ray = view_ray(cam, w, h, i);
        let depth = g.depth_mm[i] / mm_per_unit;
        let p_view = Vector4::new(ray[0] * depth, ray[1] * depth, -depth, 1.0);
        // Listing 5.1: the position shrunk along the normal before the shadow-map lookup (5 mm), so the surface
        // facing the light does not read its own depth back as a thickness (acne).
        let n = g.normal_view[i];
        let shrink = SHADOW_SHRINK_MM / mm_per_unit;
        let p_view = p_view - Vector4::new(n[0], n[1], n[2], 0.0) * shrink;
        let p = inv_view * p_view;
        let c = light_vp * p;
        let (sx, sy) = ((c.x / c.w * 0.5 + 0.5) * s, (0.5 - c.y / c.w * 0.5) * s);
        let d_light_mm = -(light_view * p).z * mm_per_unit;
        let (ix, iy) = (sx.floor() as i64, sy.floor() as i64);
        let inside = (0..SHADOW_MAP_SIZE as i64).contains(&ix) && (0..SHADOW_MAP_SIZE as i64).contains(&iy);
        let j = (iy * SHADOW_MAP_SIZE as i64 + ix) as usize;
        *o = if inside && shadow.covered[j] { (d_light_mm - shadow.depth_mm[j]).max(0.0) } else { 0.0 };
    }
    out
}

/// The Kelemen/Szirmay-Kalos specular of skin under the key light per covered pixel (view space: V points from
/// the surface to the eye at the origin), scaled like the diffuse layer's key light.
pub fn specular_layer(g: &MeshGBuffer, cam: &Camera) -> Vec<f32> {
    use crate::shading::kelemen::{specular, SKIN_F0, SKIN_RHO_S, SKIN_ROUGHNESS};
    let (w, h) = (g.width, g.height);
    let l = key_light_view();
    (0..(w * h) as usize)
        .map(|i| {
            if !g.covered[i] {
                return 0.0;
            }
            // The view ray through the pixel, reversed: from the surface to the eye.
            let ray = view_ray(cam, w, h, i);
            let d = [-ray[0], -ray[1], 1.0];
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let v = [d[0] / len, d[1] / len, d[2] / len];
            KEY_LIGHT_INTENSITY * specular(g.normal_view[i], l, v, SKIN_ROUGHNESS, SKIN_RHO_S, SKIN_F0)
        })
        .collect()
}

/// The geometry of the heads' frame (see the module doc): skin inputs, view depth in metres, skin mask.
fn geometry(
    gpu: Option<&Gpu>,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> Result<(Geometry, Vec<f32>), RuntimeError> {
    let cam = s.camera();
    let mut g = match gpu {
        Some(d) => mesh_raster::rasterise_samples(&d.device, &d.queue, mesh, &cam, s.width, s.height, passes.msaa)?,
        None => cpu::mesh_raster::rasterise_samples(mesh, &cam, s.width, s.height, passes.msaa)?,
    };
    if let Some(w) = &passes.wrinkles {
        g.normal_view = super::wrinkle_pass::wrinkled_normals_for(gpu, &g, &w.maps, &w.zone_weights)?;
    }
    let light = light_camera(&cam);
    let shadow = rasterise(gpu, mesh, &light, SHADOW_MAP_SIZE, SHADOW_MAP_SIZE)?;
    let thickness = thickness_mm(&g, &cam, &shadow, &light, mesh.mm_per_unit);
    let specular = specular_layer(&g, &cam);
    let n = (s.width * s.height) as usize;
    let mut frame = SkinFrame {
        width: s.width,
        height: s.height,
        melanin: vec![0.0; n],
        h0: vec![0.0; n],
        thickness_mm: vec![assets.luts.s_max_mm; n],
        normals: vec![[0.0, 0.0, 1.0]; n],
    };
    let hemoglobin = match &assets.baked_rig {
        Some(r) => {
            let neutral = super::mesh_skin_inputs::RigPose::neutral(r.names.len());
            let pose = passes.rig_pose.as_ref().unwrap_or(&neutral);
            Some(super::mesh_skin_inputs::hemoglobin_for_gbuffer(gpu, &g, r, pose)?)
        }
        None => None,
    };
    let mut depth = vec![100.0f32; n];
    for i in 0..n {
        if !g.covered[i] {
            continue;
        }
        frame.melanin[i] = s.melanin;
        frame.h0[i] = match &hemoglobin {
            Some(hb) => hb[i],
            None => 0.006 * ((g.uv[i][0] * 400.0).sin() * (g.uv[i][1] * 300.0).cos()),
        };
        frame.thickness_mm[i] = thickness[i].min(assets.luts.s_max_mm);
        frame.normals[i] = g.normal_view[i];
        depth[i] = g.depth_mm[i] / 1000.0 * WORLD_UNITS_PER_M;
    }
    let coverage = std::mem::take(&mut g.coverage);
    Ok((Geometry { frame, depth, skin: g.covered, specular: Some(specular) }, coverage))
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
pub fn render(
    gpu: Option<&Gpu>,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    assets: &DemoAssets,
) -> Result<Image<u8>, RuntimeError> {
    render_with(gpu, mesh, s, &SkinPasses::none(), assets)
}

/// [`render`] with the passes of `passes` (rig pose, …).
pub fn render_with(
    gpu: Option<&Gpu>,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> Result<Image<u8>, RuntimeError> {
    s.validate()?;
    let heads = row_of_heads(mesh, s.heads)?;
    let (geo, coverage) = geometry(gpu, &heads, s, passes, assets)?;
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
            assets.gaussian_params = s.stretch.apply(assets.gaussian_params);
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
    };
    let background = BACKGROUND.repeat((s.width * s.height) as usize);
    let mut frame = render_geometry(gpu, geo, &assets, method, background, None)?;
    // MSAA: partly covered pixels blend the shaded skin with the background by their coverage, in linear light.
    for (i, &cov) in coverage.iter().enumerate().filter(|(_, &c)| c > 0.0 && c < 1.0) {
        for (px, &bg) in frame.data[4 * i..4 * i + 3].iter_mut().zip(&BACKGROUND) {
            let skin = cpu::srgb_to_linear(*px as f32 / 255.0);
            let bg = cpu::srgb_to_linear(bg as f32 / 255.0);
            *px = cpu::unorm8(cpu::linear_to_srgb(cov * skin + (1.0 - cov) * bg));
        }
    }
    Ok(frame)
}
