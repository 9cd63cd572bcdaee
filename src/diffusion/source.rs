//! Where a diffusion profile comes from: a measured material (dipole or slab), a published sum-of-Gaussians preset,
//! or a user layer stack. One resolution path for every command that consumes profiles (`profile`, `fit`,
//! `kernel`, `transmittance`), so they all accept the same inputs and record the same provenance.

use super::burley::{RgbBurley, ShapeFit};
use super::dipole::Dipole;
use super::layered::{Adding, LayerStack, LayeredProfile};
use super::materials::{self, JENSEN_2001_ETA};
use super::multipole::{Series, Slab, SlabRgb};
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

/// A resolvable profile description.
#[derive(Clone, Debug, PartialEq)]
pub enum ProfileSource {
    /// One of [`materials::JENSEN_2001`] by name (η = 1.3).
    Material { name: String, model: MaterialModel, fdr: FdrForm, series: Series },
    /// A sum-of-Gaussians preset by name (`deon6`, `deon4`).
    Preset(String),
    /// A user layer stack.
    Layers { stack: LayerStack, adding: Adding, series: Series, fdr: FdrForm },
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
                })
            }
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
                let m = materials::find(name).ok_or_else(|| {
                    InvalidInput::new(
                        "material",
                        format!("'{name}' is not a known material; expected one of {}", materials::names().join(", ")),
                    )
                })?;
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
                sum_of_gaussians::preset(name).map(|p| Box::new(p) as Box<dyn RadialProfile + Send>).ok_or_else(|| {
                    InvalidInput::new(
                        "profile_preset",
                        format!(
                            "'{name}' is not a known profile preset; expected one of {}",
                            sum_of_gaussians::PRESET_NAMES.join(", ")
                        ),
                    )
                })
            }
            ProfileSource::Layers { stack, adding, series, fdr } => {
                Ok(Box::new(LayeredProfile::new(stack, *adding, *series, *fdr)?))
            }
            ProfileSource::Burley { albedo, mean_free_path_mm, fit } => {
                Ok(Box::new(RgbBurley::from_mean_free_path(*albedo, *mean_free_path_mm, *fit)?))
            }
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
            ProfileSource::Layers { stack, adding, series, fdr } => json!({
                "model": "layered",
                "adding": adding.name(),
                "series": series_json(*series),
                "fdr": fdr_name(*fdr),
                "layers": stack.to_json(),
                "units": "r in mm, R and T in mm^-2",
            }),
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
            ProfileSource::Layers { stack, adding: Adding::Directional, series: Series::Exact, fdr: FdrForm::Dj05 },
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
    }
}
