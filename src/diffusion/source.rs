//! Where a diffusion profile comes from: a measured material (dipole or slab), a published sum-of-Gaussians preset,
//! or a user layer stack. One resolution path for every command that consumes profiles (`profile`, `fit`,
//! `kernel`, `transmittance`), so they all accept the same inputs and record the same provenance.

use super::burley::{RgbBurley, ShapeFit};
use super::dipole::Dipole;
use super::layered::{Adding, LayerStack, LayeredProfile};
use super::materials::{self, JENSEN_2001_ETA};
use super::multipole::{Series, Slab, SlabRgb};
use super::projected::{ProjectedPart, ProjectedProfile};
use super::{sum_of_gaussians, FdrForm, RadialProfile};
use crate::error::InvalidInput;
use serde_json::{json, Value};

/// Model used for a measured (Jensen 2001) material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialModel {
    /// Semi-infinite medium (Jensen et al. 2001).
    Dipole,
    /// Slab of the given thickness in air on both sides (Donner & Jensen 2005).
    Multipole { thickness_mm: f64 },
}

/// The transport model that turns a layer stack into a profile.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum TransportModel {
    /// Diffusion: multipole slabs combined by adding (Donner & Jensen 2005), the thesis' model.
    #[default]
    Multipole,
    /// Monte Carlo photon transport (MCML, Wang, Jacques & Zheng 1995; `crate::transport`) with Henyey–Greenstein
    /// anisotropy `g` (σs = σs′/(1 − g), σs′ preserved), `photons` per channel (per wavelength for spectral
    /// skins) and the seed of the counter-based random numbers.
    MonteCarlo { g: f64, photons: u64, seed: u64 },
}

impl TransportModel {
    /// A validated Monte Carlo model: `g` in the open interval (−1, 1) (errors name `g`), `photons` in
    /// 1..=`transport::mc::MAX_PHOTONS` (errors name `photons`).
    pub fn monte_carlo(g: f64, photons: u64, seed: u64) -> Result<Self, InvalidInput> {
        if !(g.is_finite() && g > -1.0 && g < 1.0) {
            return Err(InvalidInput::new("g", format!("must be in the open interval (-1, 1), got {g}")));
        }
        crate::transport::profile::profile_settings(photons, seed)?;
        Ok(Self::MonteCarlo { g, photons, seed })
    }

    /// `{"transport_model": "multipole"}` or `{"transport_model": "monte-carlo", "g", "photons", "seed", ...}`.
    pub fn provenance(&self) -> Value {
        match self {
            Self::Multipole => json!({"transport_model": "multipole"}),
            Self::MonteCarlo { g, photons, seed } => json!({
                "transport_model": "monte-carlo",
                "g": g,
                "photons": photons,
                "seed": seed,
                "mc_bin_mm": crate::transport::profile::PROFILE_BIN_MM,
                "mc_bins": crate::transport::profile::PROFILE_BINS,
                "mc_batches": crate::transport::profile::PROFILE_BATCHES,
                "normalisation": "per unit flux entering the surface (Monte Carlo tallies divided by 1 - Rsp), as the \
                                  diffusion models and the skin-colour LUT",
                "mc_reference": "MCML, Wang, Jacques & Zheng 1995; Henyey-Greenstein phase function, \
                                 sigma_s = sigma_s' / (1 - g); R(r) = annulus means at the bin centres",
            }),
        }
    }

    fn parse(v: &Value) -> Result<Self, InvalidInput> {
        match v.get("transport_model").and_then(Value::as_str) {
            None | Some("multipole") => Ok(Self::Multipole),
            Some("monte-carlo") => {
                let num = |k: &str| {
                    v.get(k).ok_or_else(|| InvalidInput::new(k, "is required for transport_model monte-carlo"))
                };
                let g = num("g")?.as_f64().ok_or_else(|| InvalidInput::new("g", "must be a number"))?;
                let photons =
                    num("photons")?.as_u64().ok_or_else(|| InvalidInput::new("photons", "must be an integer >= 1"))?;
                let seed = num("seed")?.as_u64().ok_or_else(|| InvalidInput::new("seed", "must be an integer >= 0"))?;
                Self::monte_carlo(g, photons, seed)
            }
            Some(other) => {
                Err(InvalidInput::new("transport_model", format!("must be multipole or monte-carlo, got '{other}'")))
            }
        }
    }

    /// Builds the profile of one layer stack (channels as the stack's).
    pub fn build_stack(
        &self,
        stack: &LayerStack,
        adding: Adding,
        series: Series,
        fdr: FdrForm,
        seed_offset: u64,
    ) -> Result<Box<dyn RadialProfile + Send>, InvalidInput> {
        match *self {
            Self::Multipole => Ok(Box::new(LayeredProfile::new(stack, adding, series, fdr)?)),
            Self::MonteCarlo { g, photons, seed } => {
                let mc = crate::transport::McStack::from_layer_stack(stack, g)?;
                let settings = crate::transport::profile::profile_settings(photons, seed.wrapping_add(seed_offset))?;
                Ok(Box::new(crate::transport::profile::McProfile::simulate(&mc, &settings)))
            }
        }
    }

    /// Upper estimate of the wall time of [`Self::build_stack`] tabulated at `radii` radii, seconds.
    pub fn time_estimate_seconds(&self, stack: &LayerStack, series: Series, radii: usize, threads: usize) -> f64 {
        match *self {
            Self::Multipole => {
                super::layered::profile_time_estimate_seconds(stack.layers().len(), radii, series, threads)
            }
            Self::MonteCarlo { g, photons, seed } => {
                match (
                    crate::transport::McStack::from_layer_stack(stack, g),
                    crate::transport::profile::profile_settings(photons, seed),
                ) {
                    (Ok(mc), Ok(settings)) => settings.time_estimate_for_stack(&mc, threads),
                    _ => 0.0,
                }
            }
        }
    }
}

/// How far the spectral multipole of the physiological skins is from Monte Carlo transport (the three baked skins
/// at 20 000 photons per wavelength; the two-layer skins of the baked `transport-report`, a 4 × 4 melanin ×
/// hemoglobin grid and the baked skins; README, "Skins: spectral profiles and Monte Carlo"); recorded in the
/// provenance of every spectral multipole profile.
pub const SKIN_MULTIPOLE_ERROR: &str = "total R above Monte Carlo transport (same sigma_s'): +18 to +43 % at g = 0, \
    +30 to +199 % at g = 0.8 for the baked skins; +14 to +50 % at g = 0 and +21 to +216 % at g = 0.8 over the \
    transport-report's two-layer skins (Cm 0.01-0.45, Chd 0.01-0.3; darker skins worst); --model mc gives the transport \
    solution";

/// A spectral material as per-wavelength layer stacks, three wavelengths per stack (channel k of stack j is
/// wavelength `wavelengths_nm[j][k]`), projected onto linear sRGB with `weights[j][k][c]`
/// ([`super::projected`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralStacks {
    pub wavelengths_nm: Vec<[f64; 3]>,
    pub stacks: Vec<LayerStack>,
    pub weights: Vec<[[f64; 3]; 3]>,
    /// What the projection is, recorded in the provenance (illuminant, observer, matrix, normalisation).
    pub projection: Value,
}

/// A resolvable profile description.
#[derive(Clone, Debug, PartialEq)]
pub enum ProfileSource {
    /// One of [`materials::JENSEN_2001`] by name (η = 1.3).
    Material { name: String, model: MaterialModel, fdr: FdrForm, series: Series },
    /// A sum-of-Gaussians preset by name (`deon6`, `deon4`).
    Preset(String),
    /// A user layer stack.
    Layers { stack: LayerStack, adding: Adding, series: Series, fdr: FdrForm, transport: TransportModel },
    /// A spectral material (physiological skin): per-wavelength stacks projected onto RGB.
    Spectral { stacks: Box<SpectralStacks>, adding: Adding, series: Series, fdr: FdrForm, transport: TransportModel },
    /// Burley's normalized diffusion from per-channel surface albedo and mean free path (mm) with one shape fit.
    Burley { albedo: [f64; 3], mean_free_path_mm: [f64; 3], fit: ShapeFit },
}

fn rgb(v: &Value, key: &str) -> Result<[f64; 3], InvalidInput> {
    let a = v.get(key).and_then(Value::as_array).filter(|a| a.len() == 3);
    let vals: Option<Vec<f64>> = a.and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>());
    match vals {
        Some(x) => Ok([x[0], x[1], x[2]]),
        None => Err(InvalidInput::new(key, "is required for model burley: three numbers [R, G, B]")),
    }
}

fn series_json(series: Series) -> Value {
    match series {
        Series::Exact => json!("exact"),
        Series::Truncated { pairs } => json!({"truncated_pairs": pairs}),
    }
}

fn fdr_name(fdr: FdrForm) -> &'static str {
    match fdr {
        FdrForm::Dj05 => "dj05",
        FdrForm::Jensen01 => "jensen01",
    }
}

fn parse_fdr(v: &Value) -> Result<FdrForm, InvalidInput> {
    match v.get("fdr").and_then(Value::as_str).unwrap_or("dj05") {
        "dj05" => Ok(FdrForm::Dj05),
        "jensen01" => Ok(FdrForm::Jensen01),
        other => Err(InvalidInput::new("fdr", format!("must be dj05 or jensen01, got '{other}'"))),
    }
}

fn parse_series(v: &Value) -> Result<Series, InvalidInput> {
    match v.get("series") {
        None => Ok(Series::Exact),
        Some(Value::String(s)) if s == "exact" => Ok(Series::Exact),
        Some(obj) => match obj.get("truncated_pairs").and_then(Value::as_u64) {
            Some(p) if p <= 10_000 => Ok(Series::Truncated { pairs: p as u32 }),
            _ => Err(InvalidInput::new(
                "series",
                format!("must be \"exact\" or {{\"truncated_pairs\": N}} with N in 0..=10000, got {obj}"),
            )),
        },
    }
}

impl ProfileSource {
    /// Rebuilds a source from its [`provenance`](Self::provenance) JSON (so bake parameters round-trip):
    /// `{"model": "dipole" | "multipole" | "sum-of-gaussians" | "layered", ...}` with the keys `provenance` writes.
    pub fn from_json(v: &Value) -> Result<Self, InvalidInput> {
        let model = v
            .get("model")
            .and_then(Value::as_str)
            .ok_or_else(|| InvalidInput::new("model", "must be one of dipole, multipole, sum-of-gaussians, layered"))?;
        let string = |key: &str| -> Result<String, InvalidInput> {
            v.get(key)
                .and_then(Value::as_str)
                .map(str::to_string)
                .ok_or_else(|| InvalidInput::new(key, format!("is required (a string) for model {model}")))
        };
        match model {
            "dipole" => Ok(ProfileSource::Material {
                name: string("material")?,
                model: MaterialModel::Dipole,
                fdr: parse_fdr(v)?,
                series: Series::Exact,
            }),
            "multipole" => Ok(ProfileSource::Material {
                name: string("material")?,
                model: MaterialModel::Multipole {
                    thickness_mm: v
                        .get("thickness_mm")
                        .and_then(Value::as_f64)
                        .ok_or_else(|| InvalidInput::new("thickness_mm", "is required (mm) for model multipole"))?,
                },
                fdr: parse_fdr(v)?,
                series: parse_series(v)?,
            }),
            "sum-of-gaussians" => Ok(ProfileSource::Preset(string("profile_preset")?)),
            "burley" => Ok(ProfileSource::Burley {
                albedo: rgb(v, "albedo")?,
                mean_free_path_mm: rgb(v, "mean_free_path_mm")?,
                fit: serde_json::from_value(v.get("shape_fit").cloned().unwrap_or(json!("diffuse-transmission")))
                    .map_err(|e| InvalidInput::new("shape_fit", e.to_string()))?,
            }),
            "layered" => {
                let layers =
                    v.get("layers").ok_or_else(|| InvalidInput::new("layers", "is required for model layered"))?;
                let adding = match v.get("adding").and_then(Value::as_str) {
                    None => Adding::default(),
                    Some(a) => Adding::parse("adding", a)?,
                };
                Ok(ProfileSource::Layers {
                    stack: LayerStack::from_json_str(&layers.to_string())?,
                    adding,
                    series: parse_series(v)?,
                    fdr: parse_fdr(v)?,
                    transport: TransportModel::parse(v)?,
                })
            }
            "spectral-layered" => Err(InvalidInput::new(
                "model",
                "spectral-layered profiles are rebuilt from their skin parameters (skin.melanin_fraction, \
                 skin.hemoglobin_fraction) through spectral::skin_layers::physiological_skin_source, not from JSON",
            )),
            other => Err(InvalidInput::new(
                "model",
                format!("must be one of dipole, multipole, sum-of-gaussians, layered, burley, got '{other}'"),
            )),
        }
    }

    /// Builds the profile. Errors name the parameter: `material`, `thickness_mm`, `profile_preset`, or the
    /// layer-stack field (`layers[1].thickness_mm`, …).
    pub fn build(&self) -> Result<Box<dyn RadialProfile + Send>, InvalidInput> {
        match self {
            ProfileSource::Material { name, model, fdr, series } => {
                let m = jensen_material("material", name)?;
                match model {
                    MaterialModel::Dipole => {
                        for c in 0..3 {
                            Dipole::new(m.sigma_a_per_mm[c], m.sigma_s_prime_per_mm[c], JENSEN_2001_ETA, *fdr)?;
                        }
                        Ok(Box::new(m.dipole(*fdr)))
                    }
                    MaterialModel::Multipole { thickness_mm } => {
                        let mut ch = Vec::with_capacity(3);
                        for c in 0..3 {
                            ch.push(Slab::new(
                                m.sigma_a_per_mm[c],
                                m.sigma_s_prime_per_mm[c],
                                *thickness_mm,
                                JENSEN_2001_ETA,
                                JENSEN_2001_ETA,
                                *fdr,
                            )?);
                        }
                        Ok(Box::new(SlabRgb { channels: [ch[0], ch[1], ch[2]], series: *series }))
                    }
                }
            }
            ProfileSource::Preset(name) => {
                gaussian_preset("profile_preset", name).map(|p| Box::new(p) as Box<dyn RadialProfile + Send>)
            }
            ProfileSource::Layers { stack, adding, series, fdr, transport } => {
                transport.build_stack(stack, *adding, *series, *fdr, 0)
            }
            ProfileSource::Spectral { stacks, adding, series, fdr, transport } => {
                use rayon::prelude::*;
                let build =
                    |(j, s): (usize, &LayerStack)| transport.build_stack(s, *adding, *series, *fdr, (j as u64) << 32);
                // Multipole groups are cheap and independent: built side by side; Monte Carlo runs are parallel
                // inside, so they go one after the other. Either way the parts keep the wavelength order.
                let profiles: Vec<Box<dyn RadialProfile + Send>> = match transport {
                    TransportModel::Multipole => {
                        stacks.stacks.par_iter().enumerate().map(build).collect::<Result<_, _>>()?
                    }
                    TransportModel::MonteCarlo { .. } => {
                        stacks.stacks.iter().enumerate().map(build).collect::<Result<_, _>>()?
                    }
                };
                let parts = profiles
                    .into_iter()
                    .zip(&stacks.weights)
                    .map(|(profile, w)| ProjectedPart { profile, weights: *w })
                    .collect();
                Ok(Box::new(ProjectedProfile::new(parts, true)))
            }
            ProfileSource::Burley { albedo, mean_free_path_mm, fit } => {
                Ok(Box::new(RgbBurley::from_mean_free_path(*albedo, *mean_free_path_mm, *fit)?))
            }
        }
    }

    /// Upper estimate of the wall time of [`Self::build`] plus tabulating `radii` radii on `threads` threads, seconds
    /// (layer stacks and spectral stacks; 0 for the closed-form models).
    pub fn time_estimate_seconds(&self, radii: usize, threads: usize) -> f64 {
        match self {
            ProfileSource::Layers { stack, series, transport, .. } => {
                transport.time_estimate_seconds(stack, *series, radii, threads)
            }
            ProfileSource::Spectral { stacks, series, transport, .. } => {
                stacks.stacks.iter().map(|s| transport.time_estimate_seconds(s, *series, radii, threads)).sum()
            }
            _ => 0.0,
        }
    }

    /// The transport model of a layer or spectral stack (`None` for the closed-form models).
    pub fn transport(&self) -> Option<TransportModel> {
        match self {
            ProfileSource::Layers { transport, .. } | ProfileSource::Spectral { transport, .. } => Some(*transport),
            _ => None,
        }
    }

    /// The model options, as JSON keys to record next to every output.
    pub fn provenance(&self) -> Value {
        match self {
            ProfileSource::Material { name, model, fdr, series } => {
                let mut v = json!({
                    "material": name.to_ascii_lowercase(),
                    "fdr": fdr_name(*fdr),
                    "eta": JENSEN_2001_ETA,
                    "units": "r in mm, R and T in mm^-2",
                });
                match model {
                    MaterialModel::Dipole => {
                        v["model"] = json!("dipole");
                    }
                    MaterialModel::Multipole { thickness_mm } => {
                        v["model"] = json!("multipole");
                        v["thickness_mm"] = json!(thickness_mm);
                        v["series"] = series_json(*series);
                    }
                }
                v
            }
            ProfileSource::Preset(name) => json!({
                "model": "sum-of-gaussians",
                "profile_preset": name.to_ascii_lowercase(),
                "units": "r in mm, R in mm^-2",
            }),
            ProfileSource::Layers { stack, adding, series, fdr, transport } => {
                let mut v = json!({
                    "model": "layered",
                    "adding": adding.name(),
                    "series": series_json(*series),
                    "fdr": fdr_name(*fdr),
                    "layers": stack.to_json(),
                    "rgb": "per-channel coefficients as given (band-averaged where they come from spectra)",
                    "units": "r in mm, R and T in mm^-2",
                });
                merge(&mut v, transport.provenance());
                v
            }
            ProfileSource::Spectral { stacks, adding, series, fdr, transport } => {
                // The last group repeats its last wavelength (at weight 0) to fill three channels.
                let mut all: Vec<f64> = stacks.wavelengths_nm.iter().flatten().copied().collect();
                all.dedup();
                let mut v = json!({
                    "model": "spectral-layered",
                    "adding": adding.name(),
                    "series": series_json(*series),
                    "fdr": fdr_name(*fdr),
                    "wavelengths_nm": {
                        "first": all.iter().copied().fold(f64::INFINITY, f64::min),
                        "last": all.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                        "count": all.len(),
                    },
                    "rgb": stacks.projection,
                    "units": "r in mm, R and T in mm^-2",
                });
                if *transport == TransportModel::Multipole {
                    v["expected_error"] = json!(SKIN_MULTIPOLE_ERROR);
                }
                merge(&mut v, transport.provenance());
                v
            }
            ProfileSource::Burley { albedo, mean_free_path_mm, fit } => json!({
                "model": "burley",
                "albedo": albedo,
                "mean_free_path_mm": mean_free_path_mm,
                "shape_fit": fit.name(),
                "reference": "Christensen & Burley 2015, normalized diffusion",
                "units": "r in mm, R in mm^-2",
            }),
        }
    }
}

/// The one lookup of a Jensen 2001 material by name (Jensen et al., SIGGRAPH 2001, Table 2); `param` names the
/// field or flag that gave it, and a refusal lists the known names.
pub fn jensen_material(param: &str, name: &str) -> Result<&'static materials::Material, InvalidInput> {
    materials::find(name).ok_or_else(|| {
        InvalidInput::new(
            param,
            format!("'{name}' is not a known material; expected one of {}", materials::names().join(", ")),
        )
    })
}

/// The one lookup of a sum-of-Gaussians preset by name (case-insensitive; d'Eon et al. 2007); `param` names the
/// field or flag that gave it, and a refusal lists the known names.
pub fn gaussian_preset(param: &str, name: &str) -> Result<sum_of_gaussians::SumOfGaussians, InvalidInput> {
    sum_of_gaussians::preset(name).ok_or_else(|| {
        InvalidInput::new(
            param,
            format!(
                "'{name}' is not a known profile preset; expected one of {}",
                sum_of_gaussians::PRESET_NAMES.join(", ")
            ),
        )
    })
}

/// Adds what only a built profile knows to its provenance: `total_R_se` (Monte Carlo standard errors of the
/// totals) and `clipped_negative_mass` (∫2πr max(0, −R_c) dr a spectral projection set to 0, with why).
pub fn add_built_provenance(provenance: &mut Value, profile: &dyn RadialProfile) {
    if let Some(se) = profile.total_reflectance_se() {
        provenance["total_R_se"] = json!(se);
    }
    if let Some(m) = profile.clipped_negative_mass() {
        provenance["clipped_negative_mass"] = json!({
            "per_channel": m,
            "reason": "the exact linear-sRGB projection turns negative where only deep red light is left (outside \
                       the sRGB gamut); R(r) and T(r) hold 0 there, so their integral exceeds total_R by this mass",
        });
    }
}

fn merge(dst: &mut Value, src: Value) {
    if let (Value::Object(d), Value::Object(s)) = (dst, src) {
        d.extend(s);
    }
}

/// A provenance object with the publication it comes from added as `"reference"`.
pub fn with_reference(mut provenance: Value, reference: &str) -> Value {
    if let Value::Object(m) = &mut provenance {
        m.insert("reference".into(), json!(reference));
    }
    provenance
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::layered::Layer;

    #[test]
    fn provenance_round_trips_and_builds() {
        let stack = LayerStack::new(
            1.0,
            1.0,
            vec![
                Layer { thickness_mm: 0.25, eta: 1.4, sigma_a: [0.2, 0.5, 1.2], sigma_s_prime: [5.0, 6.0, 7.0] },
                Layer { thickness_mm: 5.0, eta: 1.4, sigma_a: [0.01, 0.05, 0.1], sigma_s_prime: [1.5, 2.0, 2.5] },
            ],
        )
        .unwrap();
        let sources = [
            ProfileSource::Material {
                name: "skin1".into(),
                model: MaterialModel::Dipole,
                fdr: FdrForm::Jensen01,
                series: Series::Exact,
            },
            ProfileSource::Material {
                name: "marble".into(),
                model: MaterialModel::Multipole { thickness_mm: 3.0 },
                fdr: FdrForm::Dj05,
                series: Series::Truncated { pairs: 5 },
            },
            ProfileSource::Preset("deon6".into()),
            ProfileSource::Layers {
                stack: stack.clone(),
                adding: Adding::Directional,
                series: Series::Exact,
                fdr: FdrForm::Dj05,
                transport: TransportModel::Multipole,
            },
            ProfileSource::Layers {
                stack,
                adding: Adding::Symmetric,
                series: Series::Exact,
                fdr: FdrForm::Dj05,
                transport: TransportModel::monte_carlo(0.8, 300, 7).unwrap(),
            },
        ];
        for src in sources {
            let back = ProfileSource::from_json(&src.provenance()).unwrap();
            assert_eq!(back, src);
            let (a, b) = (src.build().unwrap(), back.build().unwrap());
            assert_eq!(a.total_reflectance(), b.total_reflectance());
            assert_eq!(a.reflectance_mm2(0.7), b.reflectance_mm2(0.7));
        }
        let e = ProfileSource::from_json(&json!({"model": "dipole", "material": "unobtainium"})).unwrap().build();
        assert_eq!(e.err().unwrap().param, "material");
        assert_eq!(ProfileSource::from_json(&json!({"model": "plasma"})).unwrap_err().param, "model");
        assert_eq!(TransportModel::monte_carlo(1.0, 10, 1).unwrap_err().param, "g");
        assert_eq!(TransportModel::monte_carlo(-1.0, 10, 1).unwrap_err().param, "g");
        assert_eq!(TransportModel::monte_carlo(0.5, 0, 1).unwrap_err().param, "photons");
    }
}
