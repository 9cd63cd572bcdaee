//! The renderer's shared lighting and compositing, every skin frame goes through it (the procedural
//! [`crate::runtime::skin::demo`], heads from a mesh in [`crate::runtime::skin::frame`], and texture-space diffusion's
//! texels): skin inputs (rig → hemoglobin → albedo LUT, T(s)·E) → diffuse lighting with the transmitted light
//! stored beside the reflected light (thesis §5.4) → the SSS pass (separable, the screen-space sum of Gaussians or
//! the importance-sampled kernel), which blurs both → post-scatter albedo, the unblurred specular layer, bloom →
//! tone map, sRGB encode → SMAA / MLAA. Every stage runs on the GPU passes, or on their CPU twins.
//!
//! Every table comes from the bake directory through the manifest-checked [`crate::runtime::loader`]: the skin colour
//! LUT, T(s), the separable kernel, the sum-of-Gaussians fit and the example hemoglobin rig with its H0
//! ([`DemoAssets::load`]). A bake without the rig falls back to [`synthetic_rig`] (two targets at 16×16)
//! with a procedural H0, and [`DemoAssets::rig_source`] says so.

use crate::baked_layout::path;
use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::runtime::backend::Backend;
use crate::runtime::chain::{self, Antialiasing};
use crate::runtime::loader::{self, BakedDir, LutError};
use crate::runtime::sampler;
use crate::runtime::skin::inputs::{RigScaleBiasMaps, SkinFrame, SkinInputs, SkinLuts};
use crate::runtime::sss::gaussian::{GaussianBlurs, GaussianSssParams};
use crate::runtime::sss::importance::{ImportanceSamples, ImportanceSssParams};
use crate::runtime::sss::separable::{SssKernel, SssParams};
use crate::runtime::RuntimeError;
use std::path::Path;

/// Which subsurface-scattering pass the demo runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SssMethod {
    /// Separable SSS (thesis ch. 6) with the baked kernel.
    Separable,
    /// Screen-space sum of Gaussians (thesis ch. 4) with the baked fit.
    Gaussians,
    /// Importance-sampled disk kernel (Unity HDRP's sampling) with the baked skin1 kernel of 40 samples.
    Importance,
}

/// The tables the demo renders with.
#[derive(Clone, Debug)]
pub struct DemoAssets {
    pub luts: SkinLuts,
    pub kernel: SssKernel,
    pub sss: SssParams,
    pub blurs: GaussianBlurs,
    pub gaussian_params: GaussianSssParams,
    pub rig: RigScaleBiasMaps,
    /// One weight per rig target (eq. 7.6), summing to 1.
    pub rig_weights: Vec<f32>,
    /// Target names, same order as the weights.
    pub rig_names: Vec<String>,
    /// The baked rig with its H0, when the bake has one.
    pub baked_rig: Option<loader::BakedRig>,
    /// Where the rig came from, for the command's report.
    pub rig_source: String,
    /// The baked importance kernel ([`path::IMPORTANCE_KERNEL_DEFAULT`]), when the bake has it.
    pub importance: Option<ImportanceSamples>,
    /// Scale and follow-surface settings of the importance-sampled pass (the demo's defaults).
    pub importance_params: ImportanceSssParams,
    /// Bloom on the final HDR frame before tone mapping ([`crate::runtime::skin::bloom`]); None (the demo's default): no bloom.
    pub bloom: Option<crate::runtime::skin::bloom::BloomParams>,
    /// Post-scatter texturing (thesis §7.6, after d'Eon et al. 2007): the SSS pass blurs the irradiance alone and
    /// the albedo multiplies it afterwards, so skin colour is not blurred; false (the demo): the pass blurs
    /// albedo · irradiance (pre-scatter texturing, as the screen-space passes of ch. 4 take a rendered image).
    pub post_scatter_albedo: bool,
    /// The key light (Lambert, specular) and the light whose transmittance the back of the head lets through
    /// (shadow-map thickness, eq. 5.13), view space; [`SceneLights::default`]: the demo's fixed pair.
    pub lights: SceneLights,
}

/// Directions to the lights, view space, unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneLights {
    /// To the key light: Lambert diffuse and the specular layer.
    pub key_view: [f32; 3],
    /// To the light seen through the head: the shadow map's thickness and E = max(0.3 − N·L, 0) of eq. 5.13.
    pub back_view: [f32; 3],
}

impl Default for SceneLights {
    /// The demo's fixed lights: a key light above left in front, a back light behind right.
    fn default() -> Self {
        SceneLights { key_view: key_light_view(), back_view: back_light_view() }
    }
}

impl SceneLights {
    /// TAP 2009 §6's single light (their stimuli: "a single light source") at azimuth ϕ and elevation θ around the
    /// head ([`crate::mesh::framing::light_direction`]: 0° in front of the head, on the camera's side), seen by
    /// `camera`: it is both the key light and the light transmitted through thin parts (thesis §5.3 uses the one
    /// light for both). Out-of-range angles are refused naming `--light-azimuth` / `--light-elevation`.
    pub fn single(
        azimuth_deg: f32,
        elevation_deg: f32,
        camera: &crate::mesh::camera::Camera,
    ) -> Result<Self, InvalidInput> {
        let w = crate::mesh::framing::light_direction(
            azimuth_deg,
            elevation_deg,
            "light_azimuth_deg",
            "light_elevation_deg",
        )?;
        let view = camera.view();
        let r = view.fixed_view::<3, 3>(0, 0) * nalgebra::Vector3::from(w);
        let v = normalise([r.x, r.y, r.z]);
        Ok(SceneLights { key_view: v, back_view: v })
    }
}

impl DemoAssets {
    /// Loads the default baked tables from `dir` (paths in [`loader`]); kernel width from the kernel file.
    pub fn load(dir: &Path) -> Result<Self, LutError> {
        Self::load_with_kernel(dir, path::SEPARABLE_KERNEL_DEFAULT)
    }

    /// As [`DemoAssets::load`] with another kernel file of the bake directory.
    pub fn load_with_kernel(dir: &Path, kernel_path: &str) -> Result<Self, LutError> {
        let baked = BakedDir::open(dir)?;
        let luts = baked.skin_luts(path::SKIN_LUT, path::TRANSMITTANCE_DEFAULT)?;
        let k = baked.separable_kernel(kernel_path)?;
        let g = baked.gaussians(path::GAUSSIANS_DEFAULT)?;
        let sss = SssParams { sss_width: k.sss_width.unwrap_or(SssParams::default().sss_width), ..Default::default() };
        let listed = baked.manifest().entry(path::RIG_EXAMPLE).is_some();
        let importance = match baked.manifest().entry(path::IMPORTANCE_KERNEL_DEFAULT) {
            Some(_) => Some(baked.importance_kernel(path::IMPORTANCE_KERNEL_DEFAULT)?),
            None => None,
        };
        let (rig, rig_weights, rig_names, baked_rig, rig_source) = if listed {
            let b = baked.hemoglobin_rig(path::RIG_EXAMPLE)?;
            // 60 % neutral, 40 % joy (or the second target) — a mild flush.
            let mut wts = vec![0.0f32; b.rig.targets.len()];
            let joy = b.names.iter().position(|n| n == "joy").unwrap_or(wts.len() - 1);
            wts[0] = 0.6;
            wts[joy] += 0.4;
            let names = b.names.clone();
            (b.rig.clone(), wts, names, Some(b), format!("baked {}", path::RIG_EXAMPLE))
        } else {
            let src = format!("synthetic (no {} in the bake)", path::RIG_EXAMPLE);
            (synthetic_rig(), vec![0.4, 0.6], vec!["neutral".into(), "blush".into()], None, src)
        };
        Ok(Self {
            luts,
            kernel: k.kernel,
            sss,
            blurs: g.blurs,
            gaussian_params: g.params,
            rig,
            rig_weights,
            rig_names,
            baked_rig,
            rig_source,
            importance,
            importance_params: ImportanceSssParams::default(),
            bloom: None,
            post_scatter_albedo: false,
            lights: SceneLights::default(),
        })
    }
}

/// Where the light seen through thin parts comes from (`run skin --transmittance`, thesis §5.3 and §5.6 compare
/// these): every mode reads the thickness s from the back light's shadow map (Listing 5.1).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum TransmittanceMode {
    /// The baked T(s) of the skin's sum of Gaussians (thesis eq. 5.12, the translucent-shadow-map path).
    #[default]
    ShadowMap,
    /// Green's Beer–Lambert T(s) = exp(−s·σt) (GPU Gems ch. 16, thesis §5.3) through the same thickness.
    Green(crate::transmittance::BeerLambert),
    /// No transmitted light.
    Off,
}

impl TransmittanceMode {
    /// Green's law with Jensen et al. 2001's skin1: σt′ = σa + σs′ = (0.772, 1.05, 1.49) mm⁻¹.
    pub fn green_skin1() -> Self {
        let m = crate::diffusion::materials::find("skin1").expect("Jensen 2001 lists skin1");
        let b =
            crate::transmittance::BeerLambert::from_reduced("transmittance", m.sigma_a_per_mm, m.sigma_s_prime_per_mm)
                .expect("skin1's coefficients are in range");
        TransmittanceMode::Green(b)
    }
}

impl DemoAssets {
    /// Replaces the T(s) table the skin-inputs pass reads (same layout: s = s_max·i/(n−1)) by `mode`'s.
    pub fn set_transmittance(&mut self, mode: TransmittanceMode) {
        let n = self.luts.transmittance.len();
        let s_max = self.luts.s_max_mm as f64;
        match mode {
            TransmittanceMode::ShadowMap => {}
            TransmittanceMode::Off => self.luts.transmittance = vec![[0.0; 3]; n],
            TransmittanceMode::Green(b) => {
                self.luts.transmittance =
                    (0..n).map(|i| b.at(s_max * i as f64 / (n.max(2) - 1) as f64).map(|t| t as f32)).collect();
            }
        }
    }

    /// Sets the rig weights from a JSON object `{"target name": weight, …}` (`--rig-weights`): every name must
    /// be a target of the rig, weights finite, and their sum 1 ± 1e-3 (eq. 7.6 blends the targets); targets not
    /// named get 0.
    pub fn set_rig_weights(&mut self, json: &serde_json::Value) -> Result<(), InvalidInput> {
        let param = "rig_weights";
        let obj = json.as_object().ok_or_else(|| {
            InvalidInput::new(param, "must be a JSON object {\"target name\": weight, ...}".to_string())
        })?;
        let mut w = vec![0.0f32; self.rig_names.len()];
        for (name, v) in obj {
            let i = self.rig_names.iter().position(|n| n == name).ok_or_else(|| {
                InvalidInput::new(param, format!("unknown target {name:?}; the rig has {:?}", self.rig_names))
            })?;
            let x = v.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                InvalidInput::new(param, format!("weight of {name:?} must be a finite number, got {v}"))
            })?;
            w[i] = x as f32;
        }
        let sum: f32 = w.iter().sum();
        if (sum - 1.0).abs() > 1e-3 {
            return Err(InvalidInput::new(param, format!("weights must sum to 1 (eq. 7.6), got {sum}")));
        }
        self.rig_weights = w;
        Ok(())
    }
}

/// A synthetic two-target rig (neutral, blush) at 16×16: (scale, bias) per texel, eq. 7.6.
pub fn synthetic_rig() -> RigScaleBiasMaps {
    let s = 16u32;
    let neutral = vec![[1.0f32, 0.06]; (s * s) as usize];
    let blush = (0..s * s)
        .map(|i| {
            let (x, y) = ((i % s) as f32 / s as f32 - 0.5, (i / s) as f32 / s as f32 - 0.55);
            let cheeks = (-((x.abs() - 0.2).powi(2) + y * y) / 0.02).exp();
            [1.0 + 0.8 * cheeks, 0.06 + 0.12 * cheeks]
        })
        .collect();
    RigScaleBiasMaps { width: s, height: s, targets: vec![neutral, blush] }
}

/// A frame's geometry before shading: the skin inputs per pixel, the linear depth the SSS passes read (world
/// units of the kernel's `sss_width`) and which pixels are skin.
pub(crate) struct Geometry {
    pub(crate) frame: SkinFrame,
    pub(crate) depth: Vec<f32>,
    pub(crate) skin: Vec<bool>,
    /// Specular radiance per pixel under the key light (white), added after the SSS pass so it is never blurred
    /// (TAP 2009 §4: diffuse and specular in separate render targets); None: no specular layer (the demo).
    pub(crate) specular: Option<Vec<f32>>,
    /// Linear albedo per pixel from a scan's albedo map ([`crate::runtime::skin::surface_maps`]), replacing the skin
    /// LUT's on skin pixels; None: the LUT's.
    pub(crate) albedo: Option<Vec<[f32; 3]>>,
    /// The rig's hemoglobin at the mesh's uv left to the frame's command encoder
    /// ([`crate::runtime::skin::shade_frame`]); None: `frame.h0` holds the hemoglobin already.
    pub(crate) rig_at_uv: Option<RigAtUvPixels>,
}

/// What the rig at uv ([`crate::runtime::skin::mesh_inputs`]) needs beyond the baked rig: the mesh's texture
/// coordinates per pixel (coverage is the frame's skin mask) and the pose.
pub(crate) struct RigAtUvPixels {
    pub(crate) uv: Vec<[f32; 2]>,
    pub(crate) pose: crate::runtime::skin::mesh_inputs::RigPose,
}

/// Radiance scale of the key light (the diffuse layer's E = KEY_LIGHT_INTENSITY · N·L + ambient).
pub(crate) const KEY_LIGHT_INTENSITY: f32 = 1.6;

/// Direction to the key light (Lambert), view space, unit length.
pub(crate) fn key_light_view() -> [f32; 3] {
    normalise([-0.5, 0.6, 0.62])
}

/// Direction to the back light (transmittance), view space, unit length.
pub(crate) fn back_light_view() -> [f32; 3] {
    normalise([0.3, 0.2, -0.93])
}

fn normalise(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

/// Radiance scale of the back light (the transmitted light is TRANSMITTANCE_INTENSITY · albedo · T(s) · E).
pub(crate) const TRANSMITTANCE_INTENSITY: f32 = 1.5;

/// The demo frame before SSS: geometry and the lit diffuse layer.
pub(crate) struct Lit {
    pub(crate) geo: Geometry,
    /// Skin albedo from the LUT, linear RGBA.
    pub(crate) albedo: Vec<f32>,
    /// Reflected plus transmitted light (albedo · (irradiance + T(s)·E), §5.4; without the albedo under
    /// post-scatter texturing), linear RGBA (alpha = SSS
    /// strength: 1 on skin, 0 elsewhere).
    pub(crate) diffuse: Vec<f32>,
}

/// Skin inputs (albedo from the LUT through the rig, transmittance T(s)·E for the back light) and the lit diffuse
/// layer of `geo`.
pub(crate) fn lit_geometry(gpu: Backend<'_>, geo: Geometry, assets: &DemoAssets) -> Result<Lit, RuntimeError> {
    let (w, h) = (geo.frame.width, geo.frame.height);
    let (luts, rig) = (&assets.luts, &assets.rig);
    let weights = &assets.rig_weights;
    let (key, back) = (assets.lights.key_view, assets.lights.back_view);
    let (albedo, transmitted) = gpu.run(
        |g| SkinInputs::new(&g.device, &g.queue, w, h, luts, rig)?.run(&g.device, &g.queue, &geo.frame, weights, back),
        || Ok(crate::runtime::skin::inputs_cpu::skin_inputs(&geo.frame, luts, rig, weights, back)),
    )?;
    let n = (w * h) as usize;
    let mut albedo = albedo;
    if let Some(map) = &geo.albedo {
        for i in (0..n).filter(|&i| geo.skin[i]) {
            albedo[4 * i..4 * i + 3].copy_from_slice(&map[i]);
        }
    }
    // Diffuse irradiance · albedo (Lambert key light + ambient), alpha = SSS strength (1 on skin, 0 elsewhere).
    let mut diffuse = vec![0.0f32; 4 * n];
    for i in 0..n {
        if !geo.skin[i] {
            continue;
        }
        let nn = geo.frame.normals[i];
        let lambert = (nn[0] * key[0] + nn[1] * key[1] + nn[2] * key[2]).max(0.0);
        let e = KEY_LIGHT_INTENSITY * lambert + 0.1;
        // Thesis §5.4: "we simply store the transmittance and reflectance together. These are then blurred using
        // the screen-space Gaussian convolutions" — the back light's T(s)·E joins the reflected light before the
        // SSS pass, so the shadow map's depth discontinuities are blurred like the rest of the diffuse light.
        for c in 0..3 {
            let light = e + TRANSMITTANCE_INTENSITY * transmitted[4 * i + c];
            diffuse[4 * i + c] = if assets.post_scatter_albedo { light } else { albedo[4 * i + c] * light };
        }
        diffuse[4 * i + 3] = 1.0;
    }
    Ok(Lit { geo, albedo, diffuse })
}

/// The SSS pass of `method` with `assets`' tables (None: no SSS pass).
pub(crate) fn subsurface_of(
    assets: &DemoAssets,
    method: Option<SssMethod>,
) -> Result<Option<chain::Subsurface<'_>>, InvalidInput> {
    let Some(method) = method else { return Ok(None) };
    Ok(Some(match method {
        SssMethod::Separable => chain::Subsurface::Separable { kernel: &assets.kernel, params: &assets.sss },
        SssMethod::Gaussians => chain::Subsurface::Gaussians { blurs: &assets.blurs, params: assets.gaussian_params },
        SssMethod::Importance => chain::Subsurface::Importance {
            samples: assets.importance.as_ref().ok_or_else(|| {
                InvalidInput::new(
                    "sss importance",
                    format!("needs {} in the bake directory", path::IMPORTANCE_KERNEL_DEFAULT),
                )
            })?,
            params: &assets.importance_params,
        },
    }))
}

/// The lit frame `lit` through `method` (None: no SSS), composited over `rgba` and antialiased: each pass
/// submitted and read back on its own (the CPU twin, the procedural demo).
pub(crate) fn shade(
    gpu: Backend<'_>,
    lit: Lit,
    assets: &DemoAssets,
    method: Option<SssMethod>,
    rgba: Vec<u8>,
    aa: Option<&Antialiasing>,
) -> Result<Image<u8>, RuntimeError> {
    let Lit { geo, albedo, diffuse } = lit;
    let (w, h) = (geo.frame.width, geo.frame.height);
    let bloom = assets.bloom.as_ref();
    // Post-scatter texturing: the albedo multiplies the (blurred) irradiance.
    let textured = |mut v: Vec<f32>| {
        if assets.post_scatter_albedo {
            for (i, px) in v.chunks_exact_mut(4).enumerate() {
                for c in 0..3 {
                    px[c] *= albedo[4 * i + c];
                }
            }
        }
        v
    };
    let Some(sss) = subsurface_of(assets, method)? else {
        return composite(gpu, &geo, &textured(diffuse), rgba, bloom, aa);
    };
    let blurred = chain::subsurface(gpu, &diffuse, &geo.depth, (w, h), &sss)?;
    composite(gpu, &geo, &textured(blurred), rgba, bloom, aa)
}

/// Composites the (blurred) diffuse layer (reflected and transmitted light) plus the unblurred specular layer over
/// the background, blooms the HDR frame when `bloom` says so (thesis ch. 4: on the final image, before tone
/// mapping), tone-maps, encodes sRGB and antialiases.
pub(crate) fn composite(
    gpu: Backend<'_>,
    geo: &Geometry,
    blurred: &[f32],
    mut rgba: Vec<u8>,
    bloom: Option<&crate::runtime::skin::bloom::BloomParams>,
    aa: Option<&Antialiasing>,
) -> Result<Image<u8>, RuntimeError> {
    let (w, h) = (geo.frame.width, geo.frame.height);
    let n = (w * h) as usize;
    // The final HDR radiance of the skin.
    let mut hdr = vec![0.0f32; 4 * n];
    for i in 0..n {
        if !geo.skin[i] {
            continue;
        }
        let spec = geo.specular.as_ref().map_or(0.0, |s| s[i]);
        for c in 0..3 {
            hdr[4 * i + c] = blurred[4 * i + c] + spec;
        }
    }
    if let Some(b) = bloom {
        // The background enters as its linear radiance; where bloom adds light to it, it is re-encoded (the
        // background is display-referred: no tone map).
        for i in (0..n).filter(|&i| !geo.skin[i]) {
            for c in 0..3 {
                hdr[4 * i + c] = sampler::srgb_to_linear(rgba[4 * i + c] as f32 / 255.0);
            }
        }
        let out = crate::runtime::chain::bloom_for(gpu, w, h, &hdr, b)?;
        for i in (0..n).filter(|&i| !geo.skin[i]) {
            if out[4 * i..4 * i + 3] != hdr[4 * i..4 * i + 3] {
                for c in 0..3 {
                    rgba[4 * i + c] = sampler::unorm8(sampler::linear_to_srgb(out[4 * i + c].clamp(0.0, 1.0)));
                }
            }
        }
        hdr = out;
    }
    for i in 0..n {
        if !geo.skin[i] {
            continue;
        }
        let v: [f32; 3] = std::array::from_fn(|c| hdr[4 * i + c]);
        // Tone map the luminance (1 − e^−L) and keep the channel ratios, so skin keeps its hue in highlights.
        let l = 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
        let scale = if l > 0.0 { (1.0 - (-l).exp()) / l } else { 0.0 };
        for c in 0..3 {
            rgba[4 * i + c] = sampler::unorm8(sampler::linear_to_srgb((v[c] * scale).min(1.0)));
        }
        rgba[4 * i + 3] = 255;
    }
    let frame = Image::from_vec(w, h, 4, rgba);
    match aa {
        Some(aa) => chain::antialias(gpu, &frame, aa),
        None => Ok(frame),
    }
}
