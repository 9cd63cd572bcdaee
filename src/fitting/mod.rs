//! Fitting diffusion profiles with sums of Gaussians and deriving the real-time parameters from them.
//!
//! - [`sum_of_gaussians_fit`]: d'Eon, Luebke, Enderton, "Efficient Rendering of Human Skin", EGSR 2007 — the
//!   least-squares fit of thesis eq. 2.2, with exact non-negative weights ([`nnls`]) and argmin's Nelder–Mead on
//!   the log-variances, on a fixed radial quadrature ([`quadrature`]).
//! - [`screen_space`]: Jimenez, Sundstedt, Gutierrez, "Screen-Space Perceptual Rendering of Human Skin", ACM TAP
//!   2009 (thesis ch. 4): blend weights (eq. 4.8), incremental variances, depth-LOD thresholds (eq. 4.5–4.6) and the
//!   stretch factors (eq. 4.1–4.4), as JSON and shader includes.
//!
//! Everything here is pure computation over a `&dyn RadialProfile`; nothing touches files.

pub mod nnls;
pub mod quadrature;
pub mod screen_space;
pub mod sum_of_gaussians_fit;

use crate::diffusion::sum_of_gaussians::{gaussian_mm2, SumOfGaussians};
use crate::diffusion::RadialProfile;

pub use sum_of_gaussians_fit::{error_table, fit_sum_of_gaussians, ErrorTableRow, FitError, FitSettings, GaussianFit};

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

/// A profile divided by its per-channel totals (what `FitSettings::normalize` fits; used to plot it).
pub struct NormalizedProfile<'a> {
    pub inner: &'a dyn RadialProfile,
    pub totals: [f64; 3],
}

impl RadialProfile for NormalizedProfile<'_> {
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        let v = self.inner.reflectance_mm2(r_mm);
        [0, 1, 2].map(|c| v[c] / self.totals[c])
    }
    fn total_reflectance(&self) -> [f64; 3] {
        [1.0; 3]
    }
}

/// Plot colours of the R, G, B channels.
pub const CHANNEL_COLORS: [[u8; 3]; 3] = [[200, 30, 30], [20, 140, 40], [30, 60, 210]];

/// r·R(r) (mm⁻¹) on a log r axis per channel, with an optional fitted sum overlaid (dashed). The r range spans the
/// profile's 0.1 %–99.9 % energy quantiles, widened by 3× on both sides; 240 log-spaced points.
pub fn profile_plot(profile: &dyn RadialProfile, fit: Option<&RgbGaussians>, title: &str) -> crate::plot::LinePlot {
    use crate::plot::{LinePlot, Series};
    let grid = quadrature::RadialGrid::standard();
    let samples: Vec<[f64; 3]> = grid.r_mm.iter().map(|&r| profile.reflectance_mm2(r)).collect();
    let targets: Vec<Vec<f64>> = (0..3).map(|c| samples.iter().map(|s| s[c]).collect()).collect();
    let lo = (sum_of_gaussians_fit::quantile_radius(&grid, &targets, 0.001) / 3.0).max(quadrature::R_MIN_MM);
    let hi = (sum_of_gaussians_fit::quantile_radius(&grid, &targets, 0.999) * 3.0).min(quadrature::R_MAX_MM);
    let n = 240;
    let rs: Vec<f64> = (0..n).map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64)).collect();
    let names = ["R", "G", "B"];
    let mut series = Vec::new();
    for c in 0..3 {
        series.push(Series {
            label: format!("profile {}", names[c]),
            color: CHANNEL_COLORS[c],
            dashed: false,
            points: rs.iter().map(|&r| (r, r * profile.reflectance_mm2(r)[c])).collect(),
        });
    }
    if let Some(f) = fit {
        for c in 0..3 {
            series.push(Series {
                label: format!("fit {}", names[c]),
                color: CHANNEL_COLORS[c].map(|v| v / 2),
                dashed: true,
                points: rs.iter().map(|&r| (r, r * f.reflectance_mm2(r)[c])).collect(),
            });
        }
    }
    LinePlot {
        title: title.into(),
        x_label: "r (mm)".into(),
        y_label: "r R(r) (1/mm)".into(),
        log_x: true,
        log_y: false,
        series,
    }
}
