//! Sums of Gaussians approximating diffusion profiles (d'Eon, Luebke, Enderton, "Efficient Rendering of Human
//! Skin", EGSR 2007; thesis eq. 2.2 and Table 4.2).
//!
//! G(v, r) = exp(−r²/(2v)) / (2πv)  (unit total ∫ 2πr G dr = 1; v in mm²),  R(r) ≈ Σᵢ wᵢ G(vᵢ, r).

use super::RadialProfile;
use std::f64::consts::PI;

/// Normalised 2-D Gaussian G(v, r), mm⁻² (v in mm², r in mm).
#[inline]
pub fn gaussian_mm2(variance_mm2: f64, r_mm: f64) -> f64 {
    (-r_mm * r_mm / (2.0 * variance_mm2)).exp() / (2.0 * PI * variance_mm2)
}

/// A sum of k Gaussians with variances shared across R, G, B (what shaders want: one blur per variance).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SumOfGaussians {
    /// Ascending variances, mm².
    pub variances_mm2: Vec<f64>,
    /// RGB weight of each Gaussian, same order as `variances_mm2`.
    pub weights: Vec<[f64; 3]>,
}

impl RadialProfile for SumOfGaussians {
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (v, w) in self.variances_mm2.iter().zip(&self.weights) {
            let g = gaussian_mm2(*v, r_mm);
            for c in 0..3 {
                out[c] += w[c] * g;
            }
        }
        out
    }
    fn total_reflectance(&self) -> [f64; 3] {
        let mut out = [0.0; 3];
        for w in &self.weights {
            for c in 0..3 {
                out[c] += w[c];
            }
        }
        out
    }
}

/// d'Eon et al. 2007's 6-Gaussian fit of their three-layer skin (variances mm², weights per channel sum to 1).
pub fn deon6() -> SumOfGaussians {
    SumOfGaussians {
        variances_mm2: vec![0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41],
        weights: vec![
            [0.233, 0.455, 0.649],
            [0.100, 0.336, 0.344],
            [0.118, 0.198, 0.000],
            [0.113, 0.007, 0.007],
            [0.358, 0.004, 0.000],
            [0.078, 0.000, 0.000],
        ],
    }
}

/// d'Eon et al.'s 4-Gaussian skin fit (thesis Table 4.2).
pub fn deon4() -> SumOfGaussians {
    SumOfGaussians {
        variances_mm2: vec![0.0064, 0.0516, 0.2719, 2.0062],
        weights: vec![[0.2405, 0.4474, 0.6157], [0.1158, 0.3661, 0.3439], [0.1836, 0.1864, 0.0], [0.46, 0.0, 0.0402]],
    }
}

/// Profile presets by name: `deon6`, `deon4`.
pub fn preset(name: &str) -> Option<SumOfGaussians> {
    match name.to_ascii_lowercase().as_str() {
        "deon6" => Some(deon6()),
        "deon4" => Some(deon4()),
        _ => None,
    }
}

pub const PRESET_NAMES: [&str; 2] = ["deon6", "deon4"];

/// A sum of Gaussians with its own variances per channel (the general form; shared variances are the special case
/// of three identical lists). Variances in mm², ascending per channel; weights dimensionless (profile units × mm²).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RgbGaussians {
    pub variances_mm2: [Vec<f64>; 3],
    pub weights: [Vec<f64>; 3],
}

impl RgbGaussians {
    /// True when all three channels use the same variances.
    pub fn is_shared(&self) -> bool {
        self.variances_mm2[0] == self.variances_mm2[1] && self.variances_mm2[0] == self.variances_mm2[2]
    }

    /// Number of Gaussians per channel.
    pub fn count(&self) -> usize {
        self.variances_mm2[0].len()
    }

    /// The shared-variance form, if the channels share their variances.
    pub fn to_shared(&self) -> Option<SumOfGaussians> {
        self.is_shared().then(|| SumOfGaussians {
            variances_mm2: self.variances_mm2[0].clone(),
            weights: (0..self.count()).map(|i| [0, 1, 2].map(|c| self.weights[c][i])).collect(),
        })
    }

    /// Sorts every channel by ascending variance (weights follow their variance).
    pub fn sort_ascending(&mut self) {
        for c in 0..3 {
            let mut pairs: Vec<(f64, f64)> =
                self.variances_mm2[c].iter().copied().zip(self.weights[c].iter().copied()).collect();
            pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
            self.variances_mm2[c] = pairs.iter().map(|p| p.0).collect();
            self.weights[c] = pairs.iter().map(|p| p.1).collect();
        }
    }
}

impl From<&SumOfGaussians> for RgbGaussians {
    fn from(s: &SumOfGaussians) -> Self {
        Self {
            variances_mm2: [0, 1, 2].map(|_| s.variances_mm2.clone()),
            weights: [0, 1, 2].map(|c| s.weights.iter().map(|w| w[c]).collect()),
        }
    }
}

impl RadialProfile for RgbGaussians {
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        [0, 1, 2]
            .map(|c| self.variances_mm2[c].iter().zip(&self.weights[c]).map(|(v, w)| w * gaussian_mm2(*v, r_mm)).sum())
    }
    fn total_reflectance(&self) -> [f64; 3] {
        [0, 1, 2].map(|c| self.weights[c].iter().sum())
    }
}
