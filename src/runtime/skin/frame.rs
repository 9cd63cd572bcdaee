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
//!    ([`crate::runtime::skin::mesh_raster::rasterise_samples`]) and partly covered pixels are blended with the background by
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

use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::mesh::Mesh;
use crate::runtime::backend::Backend;
use crate::runtime::skin::heads::{blend_coverage, geometry, row_of_heads, BACKGROUND};
use crate::runtime::skin::inputs::RigScaleBiasMaps;
use crate::runtime::skin::lighting::{render_geometry, DemoAssets, SssMethod};
use crate::runtime::skin::passes::SkinPasses;
use crate::runtime::skin::settings::{SkinRenderSettings, SkinShader, WORLD_UNITS_PER_M};
use crate::runtime::sss::importance::{ImportanceSamples, ImportanceSssParams};
use crate::runtime::RuntimeError;

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
