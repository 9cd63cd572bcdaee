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

use crate::diffusion::RadialProfile;

/// The per-channel sum of Gaussians is a profile and lives in [`crate::diffusion::sum_of_gaussians`].
pub use crate::diffusion::sum_of_gaussians::RgbGaussians;
pub use sum_of_gaussians_fit::{
    error_table, fit_sum_of_gaussians, ErrorTableRow, FitSettings, GaussianFit, GaussianFitError,
};

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
