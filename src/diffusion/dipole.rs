//! Dipole diffusion for a semi-infinite medium.
//!
//! H. W. Jensen, S. R. Marschner, M. Levoy, P. Hanrahan, "A Practical Model for Subsurface Light Transport",
//! SIGGRAPH 2001; thesis eq. 2.1. With σt′ = σa + σs′, α′ = σs′/σt′, σtr = sqrt(3 σa σt′), D = 1/(3σt′),
//! zr = 1/σt′, zb = 2AD, zv = zr + 2zb, dr = sqrt(r² + zr²), dv = sqrt(r² + zv²):
//!
//! R(r) = α′/(4π) · [ zr (1 + σtr dr) e^(−σtr dr)/dr³ + zv (1 + σtr dv) e^(−σtr dv)/dv³ ]      (mm⁻²)
//!
//! Total diffuse reflectance (closed form): Rd = (α′/2)(1 + e^(−(4/3) A sqrt(3(1 − α′)))) e^(−sqrt(3(1 − α′))).

use super::{boundary_a, FdrForm, ReducedCoefficients};
use crate::error::{check_non_negative, check_positive, InvalidInput};
use std::f64::consts::PI;

/// One channel of a semi-infinite medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dipole {
    pub sigma_a_per_mm: f64,
    pub sigma_s_prime_per_mm: f64,
    /// Relative index η = n_inside / n_outside.
    pub eta: f64,
    pub fdr_form: FdrForm,
}

impl ReducedCoefficients for Dipole {
    fn sigma_a_per_mm(&self) -> f64 {
        self.sigma_a_per_mm
    }
    fn sigma_s_prime_per_mm(&self) -> f64 {
        self.sigma_s_prime_per_mm
    }
}

impl Dipole {
    /// Validates the coefficients (σa ≥ 0, σs′ > 0, η > 0, all finite).
    pub fn new(
        sigma_a_per_mm: f64,
        sigma_s_prime_per_mm: f64,
        eta: f64,
        fdr_form: FdrForm,
    ) -> Result<Self, InvalidInput> {
        check_non_negative("sigma_a", sigma_a_per_mm, "mm^-1")?;
        check_positive("sigma_s_prime", sigma_s_prime_per_mm, "mm^-1")?;
        check_positive("eta", eta, "relative index")?;
        Ok(Self { sigma_a_per_mm, sigma_s_prime_per_mm, eta, fdr_form })
    }

    /// Depths of the real and virtual sources (zr, zv), mm.
    pub fn source_depths_mm(&self) -> (f64, f64) {
        let st = self.sigma_t_prime();
        let d = 1.0 / (3.0 * st);
        let a = boundary_a(self.eta, self.fdr_form);
        let zr = 1.0 / st;
        let zb = 2.0 * a * d;
        (zr, zr + 2.0 * zb)
    }

    /// R(r) in mm⁻² (Jensen 2001 eq. 4 / thesis eq. 2.1).
    pub fn reflectance_mm2(&self, r_mm: f64) -> f64 {
        let (zr, zv) = self.source_depths_mm();
        let str_ = self.sigma_tr();
        let dr = (r_mm * r_mm + zr * zr).sqrt();
        let dv = (r_mm * r_mm + zv * zv).sqrt();
        let term = |z: f64, dist: f64| z * (1.0 + str_ * dist) * (-str_ * dist).exp() / (dist * dist * dist);
        self.albedo_prime() / (4.0 * PI) * (term(zr, dr) + term(zv, dv))
    }

    /// Closed-form total diffuse reflectance Rd = ∫₀^∞ 2πr R(r) dr.
    pub fn total_reflectance(&self) -> f64 {
        let ap = self.albedo_prime();
        let a = boundary_a(self.eta, self.fdr_form);
        let s = (3.0 * (1.0 - ap)).sqrt();
        0.5 * ap * (1.0 + (-(4.0 / 3.0) * a * s).exp()) * (-s).exp()
    }
}

/// Three channels of a dipole material (e.g. a Jensen 2001 preset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DipoleRgb(pub [Dipole; 3]);

impl super::RadialProfile for DipoleRgb {
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        [0, 1, 2].map(|c| self.0[c].reflectance_mm2(r_mm))
    }
    fn total_reflectance(&self) -> [f64; 3] {
        [0, 1, 2].map(|c| self.0[c].total_reflectance())
    }
}
