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

/// Relative size (to the channel's largest |R|) below which a negative sample is the numerical floor of a profile's
/// transform (the layered multipole's inverse Hankel transform returns values of order −1e−19 mm⁻² far from the
/// source) and reads as 0.
pub const NEGATIVE_FLOOR: f64 = 1e-12;

/// Checks profile samples `values[j]` at `r_mm[j]` for a fit or a comparison: every value finite, negatives only
/// within [`NEGATIVE_FLOOR`] of the channel's peak (set to 0); `name` names the profile in the error.
pub fn checked_samples(name: &str, r_mm: &[f64], values: &mut [[f64; 3]]) -> Result<(), crate::error::InvalidInput> {
    for c in 0..3 {
        let peak = values.iter().map(|v| v[c].abs()).filter(|v| v.is_finite()).fold(0.0, f64::max);
        for (k, v) in values.iter_mut().enumerate() {
            if !v[c].is_finite() || v[c] < -NEGATIVE_FLOOR * peak {
                return Err(crate::error::InvalidInput::new(
                    name,
                    format!("R at r = {} mm (channel {c}) is {}; expected finite and >= 0", r_mm[k], v[c]),
                ));
            }
            v[c] = v[c].max(0.0);
        }
    }
    Ok(())
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

    #[test]
    fn samples_at_the_transform_floor_read_as_zero_and_real_negatives_are_refused() {
        let r = [0.1, 1.0, 10.0];
        let mut v = [[1.0, 2.0, 3.0], [0.5, 1.0, 1.0], [-6e-20, 0.0, 1e-3]];
        checked_samples("profile", &r, &mut v).unwrap();
        assert_eq!(v[2], [0.0, 0.0, 1e-3]);
        let mut bad = [[1.0, 2.0, 3.0], [0.5, -1e-6, 1.0], [0.0, 0.0, 0.0]];
        let e = checked_samples("profile", &r, &mut bad).unwrap_err();
        assert!(e.message.contains("r = 1 mm (channel 1)"), "{e}");
        let mut nan = [[f64::NAN, 1.0, 1.0]];
        assert!(checked_samples("profile", &r[..1], &mut nan).is_err());
    }
}
