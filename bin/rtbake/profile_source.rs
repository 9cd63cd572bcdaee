//! Profile inputs shared by `fit gaussians` and `fit separable` beyond the named materials and presets:
//! a user layer stack (`--layers FILE`) or the physiological two-layer skin (`--skin-melanin`, `--skin-hemoglobin`).

use crate::cli::{usage, usage_msg};
use rtbake::diffusion::layered::{Adding, LayerStack};
use rtbake::diffusion::multipole::Series;
use rtbake::diffusion::source::ProfileSource;
use rtbake::diffusion::{FdrForm, RadialProfile};
use rtbake::spectral::skin_layers::{two_layer_skin_rgb, RgbReduction, SkinPhysiology};
use serde_json::{json, Value};
use std::path::PathBuf;

/// A resolved target: the profile, its provenance JSON and a file stem.
pub type ResolvedProfile = (Box<dyn RadialProfile>, Value, String);

/// Layered-profile flags (flattened into the fit commands).
#[derive(clap::Args, Debug, Default)]
pub struct LayeredArgs {
    /// Target: a layer-stack JSON, top layer first (mm, mm^-1): {"eta_above": 1.0, "eta_below": 1.0, "layers":
    /// [{"thickness_mm": .., "eta": .., "sigma_a": [r,g,b], "sigma_s_prime": [r,g,b]}, ...]}
    #[arg(long, value_name = "FILE")]
    pub layers: Option<PathBuf>,
    /// Target: physiological two-layer skin (Donner & Jensen 2006; epidermis 0.25 mm over dermis 20 mm, eta 1.4)
    /// with this melanin volume fraction Cm in 0..=0.5; coefficients are D65 / sRGB-sensitivity-weighted spectral
    /// averages per channel (see `rtbake::spectral::skin_layers`)
    #[arg(long, value_name = "CM", requires = "skin_hemoglobin")]
    pub skin_melanin: Option<f64>,
    /// Dermal hemoglobin volume fraction Chd in 0..=0.32 for --skin-melanin
    #[arg(long, value_name = "CHD", requires = "skin_melanin")]
    pub skin_hemoglobin: Option<f64>,
    /// Layer adding for --layers / --skin-*: symmetric (DJ05 as printed, default) or directional (Kubelka)
    #[arg(long, value_name = "MODE", default_value = "symmetric")]
    pub adding: String,
    /// Truncate the multipole image series to i = -N..N (default: exact infinite series)
    #[arg(long, value_name = "N")]
    pub dipole_pairs: Option<u32>,
}

impl LayeredArgs {
    pub fn is_set(&self) -> bool {
        self.layers.is_some() || self.skin_melanin.is_some()
    }

    /// Resolves the layered source, if one was given: (profile, provenance, file stem).
    pub fn resolve(&self) -> anyhow::Result<Option<ResolvedProfile>> {
        if !self.is_set() {
            return Ok(None);
        }
        if self.layers.is_some() && self.skin_melanin.is_some() {
            return Err(usage_msg("--layers and --skin-melanin/--skin-hemoglobin are exclusive"));
        }
        let adding = Adding::parse("--adding", &self.adding).map_err(usage)?;
        if let Some(n) = self.dipole_pairs {
            if n > 10_000 {
                return Err(usage_msg(format!("--dipole-pairs must be in 0..=10000, got {n}")));
            }
        }
        let series = self.dipole_pairs.map(|pairs| Series::Truncated { pairs }).unwrap_or_default();
        let (stack, extra, stem) = if let Some(path) = &self.layers {
            let text = std::fs::read_to_string(path)
                .map_err(|e| usage(anyhow::anyhow!("--layers {}: cannot read: {e}", path.display())))?;
            let stack = LayerStack::from_json_str(&text)
                .map_err(|e| usage(anyhow::anyhow!("--layers {}: {e}", path.display())))?;
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "layers".into());
            (stack, json!({"file": path.display().to_string()}), stem)
        } else {
            let cm = self.skin_melanin.expect("checked");
            let chd = self.skin_hemoglobin.expect("required by clap");
            let skin = two_layer_skin_rgb(&SkinPhysiology::default(), cm, chd, false, &RgbReduction::default())
                .map_err(|e| usage(anyhow::anyhow!("--skin-melanin/--skin-hemoglobin: {e}")))?;
            let stack = skin.layer_stack().map_err(|e| usage(anyhow::anyhow!("physiological skin: {e}")))?;
            let extra = json!({
                "physiological_skin": {"melanin": cm, "hemoglobin": chd, "physiology": "skin-color.md defaults",
                                       "rgb_reduction": "D65 x linear-sRGB sensitivity weighted spectral mean"}
            });
            (stack, extra, format!("skin_cm{cm}_chd{chd}"))
        };
        let src = ProfileSource::Layers { stack, adding, series, fdr: FdrForm::Dj05 };
        let profile = src.build().map_err(usage)?;
        let mut provenance = src.provenance();
        if let (Value::Object(p), Value::Object(e)) = (&mut provenance, extra) {
            p.extend(e);
        }
        Ok(Some((profile, provenance, stem)))
    }
}
