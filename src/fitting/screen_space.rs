//! Screen-space subsurface-scattering parameters from a sum of Gaussians (Jimenez, Sundstedt, Gutierrez,
//! "Screen-Space Perceptual Rendering of Human Skin", ACM TAP 6(4), 2009; thesis ch. 4).
//!
//! - Stretch factors (eq. 4.1–4.2): s = α / (d + β·min(|∇d|, γ)), scaled by the diffuse alpha (eq. 4.3–4.4).
//!   Defaults α = 31.5, β = 800, γ = 0.001 (a head 1 unit tall, 20° FOV, 720-pixel viewport).
//! - Depth LOD (eq. 4.5–4.6): a Gaussian of variance v is visible where sqrt(v)·α/d > 0.5 ⇔ d < 2·sqrt(v)·α; the
//!   thesis ships the more aggressive d < 0.5·sqrt(v)·α. Both thresholds are baked, from the full variance vᵢ.
//! - Alpha-blend weights (eq. 4.8): w′ᵢ = wᵢ / Σ_{j≤i} wⱼ per channel (w′₁ = 1), so blending each wider Gaussian
//!   over the running result with factor w′ᵢ yields Σ wᵢGᵢ normalised at every step. A zero running sum gives 0.
//! - Each blur runs on top of the previous one, so it uses the incremental variance vᵢ − vᵢ₋₁ (v₀ = 0; thesis:
//!   2.0062 − 0.2719 = 1.7343) and the shader takes its standard deviation sqrt(vᵢ − vᵢ₋₁).

use super::RgbGaussians;
use crate::error::{check_non_negative, check_positive, InvalidInput};
use crate::io::source::{ShaderInclude, ShaderLang};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// Thesis defaults for eq. 4.1–4.4.
pub const DEFAULT_ALPHA: f64 = 31.5;
pub const DEFAULT_BETA: f64 = 800.0;
pub const DEFAULT_GAMMA: f64 = 0.001;

/// Stretch-factor constants (eq. 4.1–4.4).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StretchParams {
    /// Global SSS level α (`--alpha`).
    pub alpha: f64,
    /// Depth-gradient modulation β (`--beta`).
    pub beta: f64,
    /// Gradient clamp γ (`--gamma`).
    pub gamma: f64,
}

impl Default for StretchParams {
    fn default() -> Self {
        Self { alpha: DEFAULT_ALPHA, beta: DEFAULT_BETA, gamma: DEFAULT_GAMMA }
    }
}

impl StretchParams {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_positive("alpha", self.alpha, "")?;
        check_non_negative("beta", self.beta, "")?;
        check_non_negative("gamma", self.gamma, "")?;
        Ok(())
    }

    /// s = α / (d + β·min(|∇d|, γ))   // eq. 4.1 / 4.2
    pub fn stretch(&self, depth: f64, depth_gradient: f64) -> f64 {
        self.alpha / (depth + self.beta * depth_gradient.abs().min(self.gamma))
    }
}

/// Screen-space parameters of one sum of Gaussians, per channel (identical lists for shared variances).
#[derive(Clone, Debug, PartialEq)]
pub struct ScreenSpaceParams {
    pub shared: bool,
    /// Full variances vᵢ, mm² (ascending).
    pub variances_mm2: [Vec<f64>; 3],
    /// Original weights wᵢ.
    pub weights: [Vec<f64>; 3],
    /// w′ᵢ = wᵢ / Σ_{j≤i} wⱼ (eq. 4.8).
    pub blend_weights: [Vec<f64>; 3],
    /// vᵢ − vᵢ₋₁ (v₀ = 0), mm².
    pub incremental_variances_mm2: [Vec<f64>; 3],
    /// sqrt(vᵢ − vᵢ₋₁), mm: the `width` of the thesis' Listing 4.1.
    pub std_devs_mm: [Vec<f64>; 3],
    pub stretch: StretchParams,
    /// Depth below which Gaussian i is applied, eq. 4.6: 2·sqrt(vᵢ)·α.
    pub lod_depth_eq46: [Vec<f64>; 3],
    /// The thesis' shipped, more aggressive threshold 0.5·sqrt(vᵢ)·α.
    pub lod_depth_shipped: [Vec<f64>; 3],
}

/// w′ᵢ = wᵢ / Σ_{j≤i} wⱼ with w′₁ = 1 (eq. 4.8).
pub fn blend_weights(weights: &[f64]) -> Vec<f64> {
    let mut acc = 0.0;
    weights
        .iter()
        .enumerate()
        .map(|(i, &w)| {
            acc += w;
            if i == 0 {
                1.0
            } else if acc > 0.0 {
                w / acc // eq. 4.8
            } else {
                0.0
            }
        })
        .collect()
}

/// vᵢ − vᵢ₋₁ with v₀ = 0 (ascending input).
pub fn incremental_variances(variances_mm2: &[f64]) -> Vec<f64> {
    let mut prev = 0.0;
    variances_mm2
        .iter()
        .map(|&v| {
            let d = v - prev;
            prev = v;
            d
        })
        .collect()
}

impl ScreenSpaceParams {
    /// Derives every screen-space quantity; the sum must be sorted by ascending variance with positive variances.
    pub fn new(sum: &RgbGaussians, stretch: StretchParams) -> Result<Self, InvalidInput> {
        stretch.validate()?;
        for c in 0..3 {
            let v = &sum.variances_mm2[c];
            if v.iter().any(|x| !(x.is_finite() && *x > 0.0)) || v.windows(2).any(|p| p[1] < p[0]) {
                return Err(InvalidInput::new("variances", "must be finite, > 0 and ascending"));
            }
        }
        let per = |f: &dyn Fn(usize) -> Vec<f64>| [f(0), f(1), f(2)];
        let inc = per(&|c| incremental_variances(&sum.variances_mm2[c]));
        Ok(Self {
            shared: sum.is_shared(),
            variances_mm2: sum.variances_mm2.clone(),
            weights: sum.weights.clone(),
            blend_weights: per(&|c| blend_weights(&sum.weights[c])),
            std_devs_mm: [0, 1, 2].map(|c| inc[c].iter().map(|d| d.max(0.0).sqrt()).collect()),
            incremental_variances_mm2: inc,
            stretch,
            lod_depth_eq46: per(&|c| sum.variances_mm2[c].iter().map(|v| 2.0 * v.sqrt() * stretch.alpha).collect()), // eq. 4.6
            lod_depth_shipped: per(&|c| sum.variances_mm2[c].iter().map(|v| 0.5 * v.sqrt() * stretch.alpha).collect()),
        })
    }

    fn count(&self) -> usize {
        self.variances_mm2[0].len()
    }

    /// Per-Gaussian RGB triples of a per-channel quantity.
    fn triples(&self, q: &[Vec<f64>; 3]) -> Vec<[f64; 3]> {
        (0..self.count()).map(|i| [q[0][i], q[1][i], q[2][i]]).collect()
    }

    /// A per-Gaussian quantity in the CLI's JSON shape: shared variances → one array; per channel → [[r…],[g…],[b…]].
    fn variance_like(&self, q: &[Vec<f64>; 3]) -> Value {
        if self.shared {
            json!(q[0])
        } else {
            json!(q)
        }
    }

    /// Weight-like quantities: shared → [[r,g,b] per Gaussian]; per channel → [[r…],[g…],[b…]].
    fn weight_like(&self, q: &[Vec<f64>; 3]) -> Value {
        if self.shared {
            json!(self.triples(q))
        } else {
            json!(q)
        }
    }

    /// The JSON keys of the CLI contract (`variances`, `weights`, `blend_weights`, `incremental_variances`,
    /// `std_devs`, `lod_thresholds`) as an object; callers add `error_percent` and provenance.
    pub fn to_json(&self) -> serde_json::Map<String, Value> {
        let file = GaussiansFile {
            shared_variances: self.shared,
            array_layout: if self.shared { ARRAY_LAYOUT_PER_GAUSSIAN } else { ARRAY_LAYOUT_PER_CHANNEL }.into(),
            variances: self.variance_like(&self.variances_mm2),
            weights: self.weight_like(&self.weights),
            blend_weights: self.weight_like(&self.blend_weights),
            incremental_variances: self.variance_like(&self.incremental_variances_mm2),
            std_devs: self.variance_like(&self.std_devs_mm),
            lod_thresholds: LodThresholds {
                alpha: self.stretch.alpha,
                beta: self.stretch.beta,
                gamma: self.stretch.gamma,
                two_sqrt_v_alpha: self.variance_like(&self.lod_depth_eq46),
                half_sqrt_v_alpha: self.variance_like(&self.lod_depth_shipped),
                convention: "apply Gaussian i where linear depth d < threshold_i; two_sqrt_v_alpha is eq. 4.6 \
                             (kernel wider than half a pixel), half_sqrt_v_alpha is the thesis' shipped value"
                    .into(),
            },
            units: json!({"variances": "mm^2", "incremental_variances": "mm^2", "std_devs": "mm", "lod_thresholds": "depth units of alpha"}),
            extra: serde_json::Map::new(),
        };
        match serde_json::to_value(&file).expect("parameter file serialises") {
            Value::Object(m) => m,
            _ => unreachable!("a struct serialises to an object"),
        }
    }

    /// HLSL / GLSL / WGSL include: `SSS_GAUSSIAN_COUNT`, `SSS_ALPHA/BETA/GAMMA` and per-Gaussian arrays. Shared
    /// variances are scalar arrays; per-channel variances are float3 arrays (x = R, y = G, z = B).
    pub fn shader_include(&self, lang: ShaderLang, from: &str) -> String {
        let mut inc = ShaderInclude::new(lang, from)
            .comment("Screen-space SSS sum of Gaussians (Jimenez et al. 2009; thesis eq. 4.1-4.8).")
            .comment("Variances in mm^2, std devs in mm. Blur i runs on top of blur i-1 with SSS_STD_DEVS[i];")
            .comment("blend it over the running result with factor SSS_BLEND_WEIGHTS[i] (eq. 4.8, first = 1).")
            .comment("Skip Gaussian i where linear depth >= SSS_LOD_DEPTH_*[i] (eq. 4.6 / thesis' 0.5 sqrt(v) alpha).")
            .int_const("SSS_GAUSSIAN_COUNT", self.count() as i64)
            .float_const("SSS_ALPHA", self.stretch.alpha)
            .float_const("SSS_BETA", self.stretch.beta)
            .float_const("SSS_GAMMA", self.stretch.gamma);
        inc = inc
            .vec_array("SSS_WEIGHTS", &self.triples(&self.weights))
            .vec_array("SSS_BLEND_WEIGHTS", &self.triples(&self.blend_weights));
        let arrays: [(&str, &[Vec<f64>; 3]); 5] = [
            ("SSS_VARIANCES", &self.variances_mm2),
            ("SSS_INCREMENTAL_VARIANCES", &self.incremental_variances_mm2),
            ("SSS_STD_DEVS", &self.std_devs_mm),
            ("SSS_LOD_DEPTH_EQ46", &self.lod_depth_eq46),
            ("SSS_LOD_DEPTH_SHIPPED", &self.lod_depth_shipped),
        ];
        for (name, q) in arrays {
            inc = if self.shared { inc.float_array(name, &q[0]) } else { inc.vec_array(name, &self.triples(q)) };
        }
        inc.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_incremental_variance_example() {
        let inc = incremental_variances(&[0.0064, 0.0516, 0.2719, 2.0062]);
        assert!((inc[3] - 1.7343).abs() < 1e-12);
        assert_eq!(inc[0], 0.0064);
    }

    #[test]
    fn blending_reproduces_the_weighted_sum() {
        // Blending c = c_src·w′ + c_dst·(1 − w′) over Gaussians i = 1..n yields Σ wᵢ xᵢ / Σ wᵢ.
        let w = [0.2, 0.0, 0.5, 0.3, 0.1];
        let x = [1.0, 7.0, 2.0, 3.0, 5.0];
        let bw = blend_weights(&w);
        let mut c = 0.0;
        for i in 0..w.len() {
            c = x[i] * bw[i] + c * (1.0 - bw[i]);
        }
        let expect: f64 = w.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>() / w.iter().sum::<f64>();
        assert!((c - expect).abs() < 1e-12);
    }
}

/// `array_layout` of a shared-variance file.
pub const ARRAY_LAYOUT_PER_GAUSSIAN: &str = "per Gaussian: variances[i] (one per Gaussian, shared by R, G, B); \
weights[i], blend_weights[i] = [r, g, b] of Gaussian i";
/// `array_layout` of a per-channel file.
pub const ARRAY_LAYOUT_PER_CHANNEL: &str = "per channel: variances[c][i], weights[c][i], blend_weights[c][i] for \
channel c (0 = R, 1 = G, 2 = B) and Gaussian i";

/// The keys of a sum-of-Gaussians / screen-space parameter file (`sss/gaussians/*.json`, `rtbake fit gaussians
/// --json`) that the runtime reads. Shapes depend on `shared_variances` (shared: `variances` is one array and the
/// weight-like keys are `[r, g, b]` per Gaussian; per channel: `[[r…], [g…], [b…]]`), so they stay JSON values
/// here and are checked by the reader.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GaussiansFile {
    pub shared_variances: bool,
    /// How the arrays are indexed, spelled out for readers of the file ([`ARRAY_LAYOUT_PER_GAUSSIAN`] or
    /// [`ARRAY_LAYOUT_PER_CHANNEL`]); absent in files written before it existed.
    #[serde(default)]
    pub array_layout: String,
    pub variances: Value,
    pub weights: Value,
    pub blend_weights: Value,
    pub incremental_variances: Value,
    pub std_devs: Value,
    pub lod_thresholds: LodThresholds,
    pub units: Value,
    /// Provenance, error figures and the like added by the command that wrote the file.
    #[serde(flatten)]
    pub extra: serde_json::Map<String, Value>,
}

impl GaussiansFile {
    /// The sum of Gaussians the file describes (`rtbake evaluate --gaussians`): shared → `variances` [v…] and
    /// `weights` `[[r,g,b] per Gaussian]`; per channel → both `[[r…],[g…],[b…]]`. Checks shapes, finiteness, v > 0 and
    /// w ≥ 0, naming the field.
    pub fn sum(&self) -> Result<RgbGaussians, InvalidInput> {
        fn parse<T: serde::de::DeserializeOwned>(v: &Value, key: &str, shape: &str) -> Result<T, InvalidInput> {
            serde_json::from_value(v.clone()).map_err(|e| InvalidInput::new(key, format!("must be {shape}: {e}")))
        }
        let sum = if self.shared_variances {
            let v: Vec<f64> = parse(&self.variances, "variances", "an array of numbers (shared_variances)")?;
            let w: Vec<[f64; 3]> = parse(&self.weights, "weights", "an array of [r, g, b] (shared_variances)")?;
            if v.len() != w.len() {
                return Err(InvalidInput::new("weights", format!("has {} entries for {} variances", w.len(), v.len())));
            }
            RgbGaussians::from(&crate::diffusion::sum_of_gaussians::SumOfGaussians { variances_mm2: v, weights: w })
        } else {
            let v: [Vec<f64>; 3] = parse(&self.variances, "variances", "[[r…], [g…], [b…]] (per channel)")?;
            let w: [Vec<f64>; 3] = parse(&self.weights, "weights", "[[r…], [g…], [b…]] (per channel)")?;
            if (0..3).any(|c| v[c].len() != w[c].len()) {
                return Err(InvalidInput::new("weights", "needs one weight per variance in every channel"));
            }
            RgbGaussians { variances_mm2: v, weights: w }
        };
        for c in 0..3 {
            if sum.variances_mm2[c].is_empty() {
                return Err(InvalidInput::new("variances", "must hold at least one Gaussian"));
            }
            if sum.variances_mm2[c].iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(InvalidInput::new("variances", "must be finite and > 0 (mm^2)"));
            }
            if sum.weights[c].iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
                return Err(InvalidInput::new("weights", "must be finite and >= 0"));
            }
        }
        Ok(sum)
    }
}

/// α, β, γ of the screen-space pass (eq. 4.5–4.6) and the per-Gaussian depth thresholds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LodThresholds {
    pub alpha: f64,
    pub beta: f64,
    pub gamma: f64,
    pub two_sqrt_v_alpha: Value,
    pub half_sqrt_v_alpha: Value,
    pub convention: String,
}
