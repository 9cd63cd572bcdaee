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
//!    albedo · irradiance instead); the back light's transmittance stored with the reflected light and blurred with
//!    it (thesis §5.4); the Kelemen/Szirmay-Kalos specular layer added
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
    /// d'Eon et al.'s texture-space diffusion (TAP's "TS") with the thesis ch. 3 optimisations switchable
    /// ([`super::texture_space`]).
    Ts(super::texture_space::TsSettings),
}

/// The stretch parameters of the SS Full shader (eq. 4.1–4.4 / TAP 2009 eq. 2–3).
///
/// Thesis §4.2: "The value of α is influenced by the size of the object in 3D space, the field-of-view used to
/// render the scene and the viewport size"; its α = 31.5 was "chosen empirically for a head 1.0 units tall, a
/// field-of-view of 20° and a viewport height of 720 pixels". The world unit here is a head height
/// ([`WORLD_UNITS_PER_M`]) and the chain scales α with the viewport height; [`StretchPreset::apply`] scales the
/// printed α from the 20° field of view to the camera's ([`ALPHA_FOV_DEG`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum StretchPreset {
    /// The bake's fit parameters (the thesis' α = 31.5, β = 800, γ = 0.001 unless the bake says otherwise).
    #[default]
    Thesis,
    /// TAP 2009 §4: "empirically fixed values of α = 11 and β = 800", with no clamp of the depth derivative (its
    /// field of view taken as the thesis' 20°).
    Tap2009,
    /// α from the camera, so that every Gaussian of the fit has its physical width in mm at the pixel's depth, as
    /// in texture space and in the physically scaled SS Jittered pass: α = 720 · (world units per mm) /
    /// (2 tan(fov/2)) (a tap step of σ pixels for a Gaussian of σ mm); β and γ as the bake's. The thesis' and
    /// TAP's empirical α set "the global subsurface scattering level in the image" (§4.2) above this.
    Physical,
}

/// Vertical field of view (degrees) for which the thesis states α (§4.2).
pub const ALPHA_FOV_DEG: f32 = 20.0;

impl StretchPreset {
    /// The parameters for `base` (the bake's) on a camera of vertical field of view `fovy_deg`, for the chain's
    /// 720-pixel α ([`GaussianSssParams::for_viewport_height`]).
    pub fn apply(self, base: GaussianSssParams, fovy_deg: f32) -> GaussianSssParams {
        let half_tan = (0.5 * fovy_deg.to_radians()).tan();
        let fov_scale = (0.5 * ALPHA_FOV_DEG.to_radians()).tan() / half_tan;
        match self {
            StretchPreset::Thesis => GaussianSssParams { alpha: base.alpha * fov_scale, ..base },
            // γ = f32::MAX: min(|∂d|, γ) = |∂d|, TAP's eq. 2–3 have no clamp.
            StretchPreset::Tap2009 => {
                GaussianSssParams { alpha: 11.0 * fov_scale, beta: 800.0, gamma: f32::MAX, ..base }
            }
            StretchPreset::Physical => {
                let world_units_per_mm = WORLD_UNITS_PER_M / 1000.0;
                GaussianSssParams { alpha: 720.0 * world_units_per_mm / (2.0 * half_tan), ..base }
            }
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

/// The view-space ray through the centre of pixel `i` of a `w`×`h` image, scaled to view depth 1 (z = −1).
pub(crate) fn view_ray(cam: &Camera, w: u32, h: u32, i: usize) -> [f32; 3] {
    let t = (0.5 * cam.fov_y_deg.to_radians()).tan();
    let aspect = w as f32 / h as f32;
    let (px, py) = ((i as u32 % w) as f32 + 0.5, (i as u32 / w) as f32 + 0.5);
    let (xn, yn) = (px / w as f32 * 2.0 - 1.0, 1.0 - py / h as f32 * 2.0);
    [xn * t * aspect, yn * t, -1.0]
}

/// The back light's shadow map (linear depth in mm from the light), and the thickness it gives (Listing 5.1).
pub(crate) struct ShadowMap {
    map: MeshGBuffer,
    light_view: Matrix4<f32>,
    light_vp: Matrix4<f32>,
    mm_per_unit: f32,
}

impl ShadowMap {
    /// `mesh` rasterised from the back light's camera of the frame seen by `cam`.
    pub(crate) fn new(gpu: Option<&Gpu>, mesh: &Mesh, cam: &Camera) -> Result<Self, RuntimeError> {
        let light = light_camera(cam);
        let map = rasterise(gpu, mesh, &light, SHADOW_MAP_SIZE, SHADOW_MAP_SIZE)?;
        let light_view = light.view();
        Ok(Self { map, light_view, light_vp: light.projection(1.0) * light_view, mm_per_unit: mesh.mm_per_unit })
    }

    /// The thickness (mm) the back light crosses to reach the surface point `p_world` with unit normal `n_world`
    /// (mesh units): Listing 5.1's distance between the point, shrunk 5 mm along its normal so that the surface
    /// facing the light does not read its own depth back as a thickness (acne), and the shadow map's nearest
    /// surface along the same light ray; 0 outside the map or where it saw nothing.
    pub(crate) fn thickness_mm(&self, p_world: [f32; 3], n_world: [f32; 3]) -> f32 {
        let shrink = SHADOW_SHRINK_MM / self.mm_per_unit;
        let p = Vector4::new(
            p_world[0] - n_world[0] * shrink,
            p_world[1] - n_world[1] * shrink,
            p_world[2] - n_world[2] * shrink,
            1.0,
        );
        let c = self.light_vp * p;
        let s = SHADOW_MAP_SIZE as f32;
        let (sx, sy) = ((c.x / c.w * 0.5 + 0.5) * s, (0.5 - c.y / c.w * 0.5) * s);
        let d_light_mm = -(self.light_view * p).z * self.mm_per_unit;
        let (ix, iy) = (sx.floor() as i64, sy.floor() as i64);
        let inside = (0..SHADOW_MAP_SIZE as i64).contains(&ix) && (0..SHADOW_MAP_SIZE as i64).contains(&iy);
        let j = (iy * SHADOW_MAP_SIZE as i64 + ix) as usize;
        if inside && self.map.covered[j] {
            (d_light_mm - self.map.depth_mm[j]).max(0.0)
        } else {
            0.0
        }
    }
}

/// Per covered pixel of `g` (seen by `cam`), the thickness (mm) the back light crosses to reach it
/// ([`ShadowMap::thickness_mm`] of the pixel's world position and normal).
fn thickness_mm(g: &MeshGBuffer, cam: &Camera, shadow: &ShadowMap, mm_per_unit: f32) -> Vec<f32> {
    let (w, h) = (g.width, g.height);
    let inv_view = cam.view().try_inverse().expect("a look-at view is invertible");
    let mut out = vec![0.0f32; (w * h) as usize];
    for (i, o) in out.iter_mut().enumerate() {
        if !g.covered[i] {
            continue;
        }
        let ray = view_ray(cam, w, h, i);
        let depth = g.depth_mm[i] / mm_per_unit;
        let p = inv_view * Vector4::new(ray[0] * depth, ray[1] * depth, -depth, 1.0);
        let nv = g.normal_view[i];
        let n = inv_view * Vector4::new(nv[0], nv[1], nv[2], 0.0);
        *o = shadow.thickness_mm([p.x, p.y, p.z], [n.x, n.y, n.z]);
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

/// The geometry of the heads' frame (see the module doc): skin inputs, view depth in metres, skin mask; the
/// G-buffer it came from and the back light's shadow map.
pub(crate) fn geometry(
    gpu: Option<&Gpu>,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> Result<(Geometry, MeshGBuffer, ShadowMap), RuntimeError> {
    let cam = s.camera();
    let mut g = match gpu {
        Some(d) => mesh_raster::rasterise_samples(&d.device, &d.queue, mesh, &cam, s.width, s.height, passes.msaa)?,
        None => cpu::mesh_raster::rasterise_samples(mesh, &cam, s.width, s.height, passes.msaa)?,
    };
    if let Some(w) = &passes.wrinkles {
        g.normal_view = super::wrinkle_pass::wrinkled_normals_for(gpu, &g, &w.maps, &w.zone_weights)?;
    }
    let shadow = ShadowMap::new(gpu, mesh, &cam)?;
    let thickness = thickness_mm(&g, &cam, &shadow, mesh.mm_per_unit);
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
    let skin = g.covered.clone();
    Ok((Geometry { frame, depth, skin, specular: Some(specular) }, g, shadow))
}

/// MSAA: partly covered pixels of `frame` blend the shaded skin with the background by their `coverage`, in linear
/// light.
pub(crate) fn blend_coverage(frame: &mut Image<u8>, coverage: &[f32]) {
    for (i, &cov) in coverage.iter().enumerate().filter(|(_, &c)| c > 0.0 && c < 1.0) {
        for (px, &bg) in frame.data[4 * i..4 * i + 3].iter_mut().zip(&BACKGROUND) {
            let skin = cpu::srgb_to_linear(*px as f32 / 255.0);
            let bg = cpu::srgb_to_linear(bg as f32 / 255.0);
            *px = cpu::unorm8(cpu::linear_to_srgb(cov * skin + (1.0 - cov) * bg));
        }
    }
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
    if let SkinShader::Ts(ts) = s.shader {
        return super::texture_space::render_with(gpu, mesh, s, ts, passes, assets).map(|(img, _)| img);
    }
    s.validate()?;
    let heads = row_of_heads(mesh, s.heads)?;
    let (geo, g, _) = geometry(gpu, &heads, s, passes, assets)?;
    let coverage = g.coverage;
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
        SkinShader::Ts(_) => unreachable!("texture-space diffusion returned above"),
    };
    let background = BACKGROUND.repeat((s.width * s.height) as usize);
    let mut frame = render_geometry(gpu, geo, &assets, method, background, None)?;
    blend_coverage(&mut frame, &coverage);
    Ok(frame)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretch_presets_scale_alpha_with_the_field_of_view() {
        let base = GaussianSssParams::default();
        // At the thesis' own 20° the printed values are unchanged.
        assert_eq!(StretchPreset::Thesis.apply(base, 20.0), base);
        let tap = StretchPreset::Tap2009.apply(base, 20.0);
        assert!((tap.alpha - 11.0).abs() < 1e-5 && tap.beta == 800.0 && tap.gamma == f32::MAX);
        // A wider field of view shows a head smaller: α shrinks by tan(10°)/tan(15°) at 30°.
        let wide = StretchPreset::Thesis.apply(base, 30.0);
        let expected = 31.5 * (10.0f32.to_radians().tan() / 15.0f32.to_radians().tan());
        assert!((wide.alpha - expected).abs() < 1e-4, "{} vs {expected}", wide.alpha);
        // Physical: a tap step of σ pixels for a Gaussian of σ mm. At depth d world units a length L mm spans
        // L·(world units per mm)·h/(2·d·tan(fov/2)) pixels; the chain's step is α·(h/720)·σ/d.
        let phys = StretchPreset::Physical.apply(base, 30.0);
        let (h, d, sigma_mm) = (720.0f32, 2.0f32, 1.5f32);
        let step_px = phys.alpha * (h / 720.0) * sigma_mm / d;
        let projected_px = sigma_mm * (WORLD_UNITS_PER_M / 1000.0) * h / (2.0 * d * 15.0f32.to_radians().tan());
        assert!((step_px - projected_px).abs() < 1e-4 * projected_px, "{step_px} vs {projected_px}");
        assert_eq!((phys.beta, phys.gamma), (base.beta, base.gamma));
    }
}
