//! What `run skin` renders: the SSS shader ([`SkinShader`], with the texture-space shader's [`TsSettings`]), the
//! heads, camera and skin, and SS Full's stretch presets (eq. 4.1–4.4, TAP 2009 eq. 2–3), validated before any
//! work.

use crate::error::{check_range, InvalidInput};
use crate::mesh::camera::Camera;
use crate::runtime::sss::gaussian::GaussianSssParams;

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
    /// ([`crate::runtime::skin::texture_space`]).
    Ts(TsSettings),
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
    Thesis,
    /// TAP 2009 §4: "empirically fixed values of α = 11 and β = 800", with no clamp of the depth derivative (its
    /// field of view taken as the thesis' 20°). The default, as TAP's finding (SS Full ≈ TS) was made with it.
    /// On the Lee Perry-Smith scan with its maps (TAP's 12 conditions, 640×360, 30° camera) no preset is closest
    /// to TS everywhere: mean RMSE 0.0067 (this), 0.0064 ([`StretchPreset::Thesis`], closer at zoom),
    /// 0.0069 ([`StretchPreset::Physical`]); this one is closer at far and in two of the four near conditions.
    #[default]
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
        check_range("heads", self.heads, 1, MAX_HEADS, "")?;
        check_range("distance_m", self.distance_m as f64, 0.2, 100.0, "m")?;
        check_range("melanin", self.melanin as f64, 0.0, 0.5, "(volume fraction)")?;
        crate::error::check_size("width/height", self.width as u64, self.height as u64)?;
        Ok(())
    }

    /// The camera: on +z looking at the row of heads' centre.
    pub fn camera(&self) -> Camera {
        Camera::facing(self.distance_m).expect("distance validated")
    }
}

/// Smallest `--ts-map-size`, texels.
pub const MIN_MAP_SIZE: u32 = 32;
/// Largest `--ts-map-size`, texels: d'Eon et al.'s and the thesis' `T_max` (a 2048² RGBA f32 map is 64 MiB, within
/// wgpu's default 128 MiB storage-binding limit; 4096² is not).
pub const MAX_MAP_SIZE: u32 = 2048;
/// Default `--ts-map-size`, texels.
pub const DEFAULT_MAP_SIZE: u32 = 1024;

/// The texture-space shader's settings: irradiance map edge (`T_max` with the depth-based optimisation) and which
/// ch. 3 optimisations run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TsSettings {
    pub map_size: u32,
    /// §3.2: texels whose normal is more than 105° from the view vector are occluded and not blurred.
    pub cull: bool,
    /// §3.3, eq. 3.1–3.2: map edge scaled by min(d_ref/d, 1) per head.
    pub depth_sized: bool,
    /// §3.4, eq. 3.3–3.4: texels outside the view frustum are clipped.
    pub clip: bool,
}

impl Default for TsSettings {
    fn default() -> Self {
        Self { map_size: DEFAULT_MAP_SIZE, cull: false, depth_sized: false, clip: false }
    }
}

impl TsSettings {
    /// All three optimisations on.
    pub fn optimised(map_size: u32) -> Self {
        Self { map_size, cull: true, depth_sized: true, clip: true }
    }

    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_range("ts_map_size", self.map_size, MIN_MAP_SIZE, MAX_MAP_SIZE, "texels")?;
        Ok(())
    }
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
