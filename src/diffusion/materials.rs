//! Measured scattering coefficients of Jensen et al. 2001 (Table in "A Practical Model for Subsurface Light
//! Transport", SIGGRAPH 2001, Table 2). σs′ and σa in **mm⁻¹** for R, G, B; η = 1.3.

use super::dipole::{Dipole, DipoleRgb};
use super::FdrForm;

/// Relative index of refraction used with every Jensen 2001 material.
pub const JENSEN_2001_ETA: f64 = 1.3;

/// One measured material: reduced scattering and absorption, mm⁻¹, per RGB channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub name: &'static str,
    pub sigma_s_prime_per_mm: [f64; 3],
    pub sigma_a_per_mm: [f64; 3],
}

/// The 11 materials of Jensen et al. 2001 (mm⁻¹).
pub const JENSEN_2001: [Material; 11] = [
    Material { name: "apple", sigma_s_prime_per_mm: [2.29, 2.39, 1.97], sigma_a_per_mm: [0.0030, 0.0034, 0.046] },
    Material { name: "chicken1", sigma_s_prime_per_mm: [0.15, 0.21, 0.38], sigma_a_per_mm: [0.015, 0.077, 0.19] },
    Material { name: "chicken2", sigma_s_prime_per_mm: [0.19, 0.25, 0.32], sigma_a_per_mm: [0.018, 0.088, 0.20] },
    Material { name: "cream", sigma_s_prime_per_mm: [7.38, 5.47, 3.15], sigma_a_per_mm: [0.0002, 0.0028, 0.0163] },
    Material { name: "ketchup", sigma_s_prime_per_mm: [0.18, 0.07, 0.03], sigma_a_per_mm: [0.061, 0.97, 1.45] },
    Material { name: "marble", sigma_s_prime_per_mm: [2.19, 2.62, 3.00], sigma_a_per_mm: [0.0021, 0.0041, 0.0071] },
    Material { name: "potato", sigma_s_prime_per_mm: [0.68, 0.70, 0.55], sigma_a_per_mm: [0.0024, 0.0090, 0.12] },
    Material { name: "skimmilk", sigma_s_prime_per_mm: [0.70, 1.22, 1.90], sigma_a_per_mm: [0.0014, 0.0025, 0.0142] },
    Material { name: "skin1", sigma_s_prime_per_mm: [0.74, 0.88, 1.01], sigma_a_per_mm: [0.032, 0.17, 0.48] },
    Material { name: "skin2", sigma_s_prime_per_mm: [1.09, 1.59, 1.79], sigma_a_per_mm: [0.013, 0.070, 0.145] },
    Material { name: "wholemilk", sigma_s_prime_per_mm: [2.55, 3.21, 3.77], sigma_a_per_mm: [0.0011, 0.0024, 0.014] },
];

/// Looks a material up by name, case-insensitively.
pub fn find(name: &str) -> Option<&'static Material> {
    JENSEN_2001.iter().find(|m| m.name.eq_ignore_ascii_case(name))
}

/// Names accepted by [`find`], for error messages.
pub fn names() -> Vec<&'static str> {
    JENSEN_2001.iter().map(|m| m.name).collect()
}

impl Material {
    /// The material as a semi-infinite dipole with η = 1.3.
    pub fn dipole(&self, fdr_form: FdrForm) -> DipoleRgb {
        DipoleRgb([0, 1, 2].map(|c| Dipole {
            sigma_a_per_mm: self.sigma_a_per_mm[c],
            sigma_s_prime_per_mm: self.sigma_s_prime_per_mm[c],
            eta: JENSEN_2001_ETA,
            fdr_form,
        }))
    }
}
