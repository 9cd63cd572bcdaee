//! Where a diffusion profile comes from: a measured material (dipole or slab), a published sum-of-Gaussians preset,
//! or a user layer stack. One resolution path for every command that consumes profiles (`profile`, `fit`,
//! `kernel`, `transmittance`), so they all accept the same inputs and record the same provenance.

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

impl ProfileSource {
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
        }
    }
}
