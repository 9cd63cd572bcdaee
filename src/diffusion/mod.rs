//! Diffusion profiles (thesis ch. 2 and 5.2).
//!
//! Units everywhere: lengths in mm, coefficients in mm⁻¹, radial profiles R(r), T(r) in mm⁻²
//! (fraction of incident power per unit area). These modules know nothing about files or the GPU.
//!
//! Code map:
//! - [`dipole`]: semi-infinite medium (Jensen et al. 2001), closed-form total.
//! - [`multipole`]: slab with different top/bottom boundaries (Donner & Jensen 2005), R(r), T(r) and their Hankel
//!   transforms with the exact infinite image series (default) or i = −N..N.
//! - [`layered`]: [`layered::LayerStack`] (JSON, validated) and [`layered::LayeredProfile`] (adding in frequency
//!   space, symmetric or directional; back to real space by [`hankel`] with [`bessel::j0`]).
//! - [`materials`], [`sum_of_gaussians`]: the Jensen 2001 materials and d'Eon's Gaussian presets.
//! - [`source::ProfileSource`]: the one way commands resolve "material / preset / layer stack" into a
//!   `Box<dyn RadialProfile>` plus provenance; [`table::ProfileTable`]: R, T on a radius grid as CSV / JSON;
//!   `crate::plot::profile`: a table as a two-panel plot (r·R(r) over log r, R(r) log–log) in PNG or SVG.
//! - [`projected`]: per-wavelength profiles projected linearly onto linear-sRGB channels (spectral skins).
//! - [`quadrature`]: Gauss–Legendre rules and ∫2πr R(r) dr on a log grid (used by tests and fitting).

pub mod albedo_inversion;
pub mod bessel;
pub mod burley;
pub mod dipole;
pub mod hankel;
pub mod layered;
pub mod materials;
pub mod multipole;
pub mod projected;
pub mod quadrature;
pub mod source;
pub mod sum_of_gaussians;
pub mod table;
pub mod tabulated;

/// One channel's absorption σa and reduced scattering σs′ (mm⁻¹), and the diffusion-theory quantities built from
/// them, shared by the dipole and the multipole (Jensen et al. 2001, thesis eq. 2.1; Donner & Jensen 2005):
/// σt′ = σa + σs′, α′ = σs′/σt′, σtr = sqrt(3 σa σt′).
pub trait ReducedCoefficients {
    /// σa, mm⁻¹.
    fn sigma_a_per_mm(&self) -> f64;
    /// σs′ = σs (1 − g), mm⁻¹.
    fn sigma_s_prime_per_mm(&self) -> f64;
    /// Reduced extinction coefficient σt′ = σa + σs′, mm⁻¹.
    fn sigma_t_prime(&self) -> f64 {
        self.sigma_a_per_mm() + self.sigma_s_prime_per_mm()
    }
    /// Reduced albedo α′ = σs′/σt′.
    fn albedo_prime(&self) -> f64 {
        self.sigma_s_prime_per_mm() / self.sigma_t_prime()
    }
    /// Effective transport coefficient σtr = sqrt(3 σa σt′), mm⁻¹.
    fn sigma_tr(&self) -> f64 {
        (3.0 * self.sigma_a_per_mm() * self.sigma_t_prime()).sqrt()
    }
}

/// An RGB radial diffusion profile R(r) in mm⁻² (r in mm), with its total ∫₀^∞ 2πr R(r) dr.
///
/// Implemented by the dipole, the multipole, layered stacks and sums of Gaussians, so fitting,
/// separable kernels and transmittance can consume any of them.
pub trait RadialProfile: Sync {
    /// R(r) per channel, mm⁻².
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3];
    /// ∫₀^∞ 2πr R(r) dr per channel (dimensionless).
    fn total_reflectance(&self) -> [f64; 3];
    /// T(r) per channel, mm⁻², for profiles of finite slabs and layer stacks (`None` for semi-infinite media and
    /// Gaussian presets).
    fn transmittance_mm2(&self, _r_mm: f64) -> Option<[f64; 3]> {
        None
    }
    /// ∫₀^∞ 2πr T(r) dr per channel, where the profile has a transmittance.
    fn total_transmittance(&self) -> Option<[f64; 3]> {
        None
    }
    /// The radii (mm) over which the profile is known, where it is not defined everywhere (a tabulated profile:
    /// its first and last rows); comparisons are restricted to it. `None`: all r ≥ 0.
    fn support_mm(&self) -> Option<(f64, f64)> {
        None
    }
    /// Standard error of R(r) per channel, mm⁻², for a profile estimated by Monte Carlo (`None`: exact model).
    fn reflectance_se_mm2(&self, _r_mm: f64) -> Option<[f64; 3]> {
        None
    }
    /// Standard error of the total reflectance per channel, for a Monte Carlo profile (`None`: exact model).
    fn total_reflectance_se(&self) -> Option<[f64; 3]> {
        None
    }
    /// ∫2πr max(0, −R_c) dr per channel where the model clips negative values of an exact linear map to 0 (a
    /// spectral projection, [`projected`]); `None`: nothing is clipped by the model.
    fn clipped_negative_mass(&self) -> Option<[f64; 3]> {
        None
    }
    /// R at many radii (implementations may parallelise; results must not depend on the thread count).
    fn reflectance_many(&self, radii_mm: &[f64]) -> Vec<[f64; 3]> {
        radii_mm.iter().map(|&r| self.reflectance_mm2(r)).collect()
    }
    /// T at many radii, where the profile has a transmittance.
    fn transmittance_many(&self, radii_mm: &[f64]) -> Option<Vec<[f64; 3]>> {
        radii_mm.iter().map(|&r| self.transmittance_mm2(r)).collect()
    }
    /// R and (where defined) T at many radii in one pass.
    fn profile_many(&self, radii_mm: &[f64]) -> (Vec<[f64; 3]>, Option<Vec<[f64; 3]>>) {
        (self.reflectance_many(radii_mm), self.transmittance_many(radii_mm))
    }
}

/// Which polynomial approximates the average diffuse Fresnel reflectance Fdr(η).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FdrForm {
    /// Donner & Jensen 2005: the η ≥ 1 polynomial with full digits plus the η < 1 form for internal interfaces.
    #[default]
    Dj05,
    /// Jensen et al. 2001 as printed (−1.440, 0.710, 0.668, 0.0636), η < 1 form as DJ05.
    Jensen01,
}

/// Average diffuse Fresnel reflectance Fdr(η), η = n_inside / n_outside.
pub fn fdr(eta: f64, form: FdrForm) -> f64 {
    if eta >= 1.0 {
        match form {
            FdrForm::Dj05 => -1.4399 / (eta * eta) + 0.7099 / eta + 0.6681 + 0.0636 * eta,
            FdrForm::Jensen01 => -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta,
        }
    } else {
        -0.4399 + 0.7099 / eta - 0.3319 / (eta * eta) + 0.0636 / (eta * eta * eta)
    }
}

/// Boundary coefficient A = (1 + Fdr)/(1 − Fdr).
pub fn boundary_a(eta: f64, form: FdrForm) -> f64 {
    let f = fdr(eta, form);
    (1.0 + f) / (1.0 - f)
}
