//! The fixed radial quadrature behind every fit integral.
//!
//! The fit objective (thesis eq. 2.2) and its error metric are integrals of the form ∫₀^∞ r·f(r) dr with f smooth
//! in r and decaying at least exponentially (Gaussians, dipole/multipole tails). Substituting r = eᵘ gives
//! ∫ r²·f(eᵘ) du, an integrand that decays exponentially at both ends of the u axis; the trapezoid rule in u then
//! converges geometrically (the classic result for analytic, rapidly decaying integrands on the real line). The grid:
//!
//! - nodes rⱼ = 10^(−5 + j/16) mm, j = 0..=128 (1e−5 mm … 1e3 mm, 16 nodes per decade, 129 nodes);
//! - weights qⱼ = h·rⱼ² with h = ln(10)/16, halved at the last node; the first node gets h/(1 − e^(−2h))·r₀², which
//!   is its own weight h plus the trapezoid rule's infinite left tail h·Σ_{m≥1} r₀² e^(−2mh) for f constant near
//!   r = 0 (the rule is continued to r → 0 rather than cut off; the remaining error is O(r₀⁴ f″)).
//!
//! Checked in tests: ∫ r G(v₁) G(v₂) dr = 1/(4π²(v₁+v₂)) to 1e−12 relative for v in 1e−4..1e4 mm², and the dipole's
//! 2π∫ r R dr equals its closed-form total. The grid is fixed (not profile-adaptive) so a fit is a deterministic
//! function of the profile; variances are restricted to [`V_MIN_MM2`, `V_MAX_MM2`], well inside the grid.

/// First node, mm.
pub const R_MIN_MM: f64 = 1e-5;
/// Last node, mm.
pub const R_MAX_MM: f64 = 1e3;
/// Nodes per decade of r.
pub const NODES_PER_DECADE: usize = 16;
/// Smallest variance a fit may use, mm² (standard deviation 0.01 mm = 1000 r_min).
pub const V_MIN_MM2: f64 = 1e-4;
/// Largest variance a fit may use, mm² (standard deviation 100 mm = r_max / 10).
pub const V_MAX_MM2: f64 = 1e4;

/// Nodes and weights of the quadrature ∫₀^∞ r·f(r) dr ≈ Σ qⱼ f(rⱼ).
#[derive(Clone, Debug)]
pub struct RadialGrid {
    pub r_mm: Vec<f64>,
    /// Weights qⱼ (mm²), already including the factor r of the integrand.
    pub weights: Vec<f64>,
}

impl RadialGrid {
    /// The fixed grid documented at module level.
    pub fn standard() -> Self {
        let decades = (R_MAX_MM / R_MIN_MM).log10().round() as usize;
        let n = decades * NODES_PER_DECADE + 1;
        let h = std::f64::consts::LN_10 / NODES_PER_DECADE as f64;
        let r_mm: Vec<f64> =
            (0..n).map(|j| 10f64.powf(R_MIN_MM.log10() + j as f64 / NODES_PER_DECADE as f64)).collect();
        let weights = r_mm
            .iter()
            .enumerate()
            .map(|(j, r)| {
                let w = if j == 0 {
                    h / (1.0 - (-2.0 * h).exp())
                } else if j == n - 1 {
                    0.5 * h
                } else {
                    h
                };
                w * r * r
            })
            .collect();
        Self { r_mm, weights }
    }

    pub fn len(&self) -> usize {
        self.r_mm.len()
    }

    pub fn is_empty(&self) -> bool {
        self.r_mm.is_empty()
    }

    /// ∫₀^∞ r·f(r) dr for samples fⱼ = f(rⱼ).
    pub fn integrate_r(&self, samples: &[f64]) -> f64 {
        self.weights.iter().zip(samples).map(|(q, f)| q * f).sum()
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::diffusion::sum_of_gaussians::gaussian_mm2;
    use std::f64::consts::PI;

    #[test]
    fn gaussian_products_integrate_exactly() {
        let g = RadialGrid::standard();
        assert_eq!(g.len(), 129);
        for &v1 in &[1e-4, 1e-3, 0.0064, 0.3, 7.41, 1e4] {
            for &v2 in &[1e-4, 0.05, 2.0, 1e4] {
                let f: Vec<f64> = g.r_mm.iter().map(|&r| gaussian_mm2(v1, r) * gaussian_mm2(v2, r)).collect();
                let exact = 1.0 / (4.0 * PI * PI * (v1 + v2));
                let rel = (g.integrate_r(&f) - exact).abs() / exact;
                assert!(rel < 1e-12, "v1 {v1} v2 {v2}: rel {rel:e}");
            }
        }
    }

    #[test]
    fn dipole_total_matches_closed_form() {
        use crate::diffusion::{materials::JENSEN_2001, RadialProfile};
        let g = RadialGrid::standard();
        for m in &JENSEN_2001 {
            let d = m.dipole(crate::diffusion::FdrForm::Dj05);
            let exact = d.total_reflectance();
            for c in 0..3 {
                let f: Vec<f64> = g.r_mm.iter().map(|&r| d.reflectance_mm2(r)[c]).collect();
                let total = 2.0 * PI * g.integrate_r(&f);
                assert!(((total - exact[c]) / exact[c]).abs() < 1e-11, "{} {c}: {total} vs {}", m.name, exact[c]);
            }
        }
    }
}
