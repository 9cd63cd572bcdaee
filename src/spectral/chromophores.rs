//! Spectral absorption of the skin chromophores (λ in nm, coefficients in mm⁻¹).
//!
//! Donner & Jensen, "A Spectral BSSRDF for Shading Human Skin", EGSR 2006, and Donner, Weyrich, d'Eon,
//! Ramamoorthi & Rusinkiewicz, "A Layered, Heterogeneous Reflectance Model for Acquiring and Rendering Human Skin",
//! SIGGRAPH Asia 2008; as used for the skin-colour table of the thesis (Jimenez 2012, §7.6, Table 7.1).
//! The forms here are the **mm⁻¹** ones (the cm⁻¹ forms printed elsewhere are 6.6e11, 2.9e15 and
//! 0.244 + 85.3·exp(…)):
//!
//! | chromophore | σa(λ) [mm⁻¹] |
//! | --- | --- |
//! | eumelanin | 6.6e10 · λ^−3.33 |
//! | pheomelanin | 2.9e14 · λ^−4.75 |
//! | baseline (melanin- and blood-free tissue) | 0.0244 + 8.53 · exp(−(λ − 154)/66.2) |
//! | whole blood, oxy / deoxy | ln(10) · ε(λ) · c / M / 10, ε from Prahl (cm⁻¹/M), c = 150 g/L, M = 64500 g/mol |
//!
//! Reduced scattering (same papers): σs′,epi = 14.74 · λ^−0.22 + 2.2e11 · λ^−4 (mm⁻¹), σs′,derm = 0.5 · σs′,epi.
//!
//! Prahl's table has a 2 nm step; values at other wavelengths are interpolated linearly between its rows.

use super::data::{hemoglobin_extinction, HEMOGLOBIN_FIRST_NM, HEMOGLOBIN_STEP_NM};

/// Hemoglobin concentration of whole blood used by Donner & Jensen 2006, g/L.
pub const DEFAULT_HEMOGLOBIN_G_PER_L: f64 = 150.0;
/// Molar mass of hemoglobin, g/mol.
pub const DEFAULT_HEMOGLOBIN_MOLAR_MASS_G_PER_MOL: f64 = 64500.0;

/// Eumelanin absorption σa,em(λ) = 6.6e10 · λ^−3.33, mm⁻¹.
pub fn eumelanin_sigma_a_per_mm(lambda_nm: f64) -> f64 {
    6.6e10 * lambda_nm.powf(-3.33)
}

/// Pheomelanin absorption σa,pm(λ) = 2.9e14 · λ^−4.75, mm⁻¹.
pub fn pheomelanin_sigma_a_per_mm(lambda_nm: f64) -> f64 {
    2.9e14 * lambda_nm.powf(-4.75)
}

/// Baseline (chromophore-free tissue) absorption σa,base(λ) = 0.0244 + 8.53 · exp(−(λ − 154)/66.2), mm⁻¹.
pub fn baseline_sigma_a_per_mm(lambda_nm: f64) -> f64 {
    0.0244 + 8.53 * (-(lambda_nm - 154.0) / 66.2).exp()
}

/// Epidermal reduced scattering σs′,epi(λ) = 14.74 · λ^−0.22 + 2.2e11 · λ^−4, mm⁻¹.
pub fn epidermis_sigma_s_prime_per_mm(lambda_nm: f64) -> f64 {
    14.74 * lambda_nm.powf(-0.22) + 2.2e11 * lambda_nm.powi(-4)
}

/// Dermal reduced scattering σs′,derm(λ) = 0.5 · σs′,epi(λ), mm⁻¹.
pub fn dermis_sigma_s_prime_per_mm(lambda_nm: f64) -> f64 {
    0.5 * epidermis_sigma_s_prime_per_mm(lambda_nm)
}

/// Prahl's molar extinction `[ε_HbO2, ε_Hb]` (cm⁻¹/M, decadic) at `lambda_nm`, linearly interpolated between the
/// 2 nm rows. Returns `None` outside the table (250–1000 nm).
pub fn hemoglobin_extinction_per_cm_per_molar(lambda_nm: f64) -> Option<[f64; 2]> {
    let first = HEMOGLOBIN_FIRST_NM as f64;
    let step = HEMOGLOBIN_STEP_NM as f64;
    let last = first + step * (hemoglobin_extinction().len() - 1) as f64;
    if !(first..=last).contains(&lambda_nm) {
        return None;
    }
    let x = (lambda_nm - first) / step;
    let i = (x.floor() as usize).min(hemoglobin_extinction().len() - 2);
    let f = x - i as f64;
    let (a, b) = (hemoglobin_extinction()[i], hemoglobin_extinction()[i + 1]);
    Some([a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])])
}

/// Whole-blood absorption σa = ln(10) · ε · c / M / 10 in mm⁻¹ for a molar extinction ε in cm⁻¹/M, a hemoglobin
/// concentration c in g/L and a molar mass M in g/mol (the /10 converts cm⁻¹ to mm⁻¹).
pub fn blood_sigma_a_per_mm(
    extinction_per_cm_per_molar: f64,
    hemoglobin_g_per_l: f64,
    molar_mass_g_per_mol: f64,
) -> f64 {
    std::f64::consts::LN_10 * extinction_per_cm_per_molar * hemoglobin_g_per_l / molar_mass_g_per_mol / 10.0
}

/// All chromophore spectra at one wavelength (mm⁻¹); the per-wavelength constants of the two-layer model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChromophoreSpectra {
    pub lambda_nm: f64,
    pub eumelanin: f64,
    pub pheomelanin: f64,
    pub baseline: f64,
    pub oxy_blood: f64,
    pub deoxy_blood: f64,
    pub sigma_s_prime_epidermis: f64,
    pub sigma_s_prime_dermis: f64,
}

impl ChromophoreSpectra {
    /// Evaluates every chromophore at `lambda_nm` (250–1000 nm, the range of Prahl's table; `None` outside).
    pub fn at(lambda_nm: f64, hemoglobin_g_per_l: f64, molar_mass_g_per_mol: f64) -> Option<Self> {
        let [e_oxy, e_deoxy] = hemoglobin_extinction_per_cm_per_molar(lambda_nm)?;
        Some(Self {
            lambda_nm,
            eumelanin: eumelanin_sigma_a_per_mm(lambda_nm),
            pheomelanin: pheomelanin_sigma_a_per_mm(lambda_nm),
            baseline: baseline_sigma_a_per_mm(lambda_nm),
            oxy_blood: blood_sigma_a_per_mm(e_oxy, hemoglobin_g_per_l, molar_mass_g_per_mol),
            deoxy_blood: blood_sigma_a_per_mm(e_deoxy, hemoglobin_g_per_l, molar_mass_g_per_mol),
            sigma_s_prime_epidermis: epidermis_sigma_s_prime_per_mm(lambda_nm),
            sigma_s_prime_dermis: dermis_sigma_s_prime_per_mm(lambda_nm),
        })
    }

    /// Melanin mix βm·σa,em + (1 − βm)·σa,pm, mm⁻¹.
    pub fn melanin(&self, beta_m: f64) -> f64 {
        beta_m * self.eumelanin + (1.0 - beta_m) * self.pheomelanin
    }

    /// Blood at oxygenation γ: γ·σa,oxy + (1 − γ)·σa,deoxy, mm⁻¹.
    pub fn blood(&self, gamma: f64) -> f64 {
        gamma * self.oxy_blood + (1.0 - gamma) * self.deoxy_blood
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_hits_table_rows_and_midpoints() {
        // 500 nm is row (500 − 250)/2 = 125; 501 nm is halfway to row 126.
        let r = hemoglobin_extinction()[125];
        let s = hemoglobin_extinction()[126];
        assert_eq!(hemoglobin_extinction_per_cm_per_molar(500.0).unwrap(), r);
        let mid = hemoglobin_extinction_per_cm_per_molar(501.0).unwrap();
        assert!((mid[0] - 0.5 * (r[0] + s[0])).abs() < 1e-9);
        assert!((mid[1] - 0.5 * (r[1] + s[1])).abs() < 1e-9);
        assert_eq!(hemoglobin_extinction_per_cm_per_molar(1000.0).unwrap(), hemoglobin_extinction()[375]);
        assert!(hemoglobin_extinction_per_cm_per_molar(249.0).is_none());
        assert!(hemoglobin_extinction_per_cm_per_molar(1001.0).is_none());
    }

    #[test]
    fn mm_forms_are_tenth_of_cm_forms() {
        // The cm⁻¹ forms 6.6e11, 2.9e15 and 0.244 + 85.3·exp(…) are exactly 10× the mm⁻¹ ones.
        for l in [400.0, 550.0, 700.0] {
            assert!((eumelanin_sigma_a_per_mm(l) * 10.0 - 6.6e11 * f64::powf(l, -3.33)).abs() < 1e-9);
            assert!((pheomelanin_sigma_a_per_mm(l) * 10.0 - 2.9e15 * f64::powf(l, -4.75)).abs() < 1e-9);
            let cm = 0.244 + 85.3 * (-(l - 154.0) / 66.2).exp();
            assert!((baseline_sigma_a_per_mm(l) * 10.0 - cm).abs() < 1e-12);
        }
    }
}
