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

pub mod burley_fit;
pub mod evaluate;
pub mod nnls;
pub mod profile_check;
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
