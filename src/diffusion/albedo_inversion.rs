//! Artist parameters → physical coefficients: surface albedo and a scattering distance to σa, σs′ of the dipole.
//!
//! H. W. Jensen, J. Buhler, "A Rapid Hierarchical Rendering Technique for Translucent Materials", SIGGRAPH 2002,
//! §4 ("intuitive" parameters): the dipole's total diffuse reflectance (Jensen et al. 2001, eq. 5 with its
//! closed form; [`Dipole::total_reflectance`])
//!
//!   Rd(α′) = (α′/2) (1 + e^(−(4/3) A √(3(1 − α′)))) e^(−√(3(1 − α′)))
//!
//! depends only on the reduced albedo α′ = σs′/σt′ (and on η through A), and rises monotonically from 0 at α′ = 0 to
//! 1 at α′ = 1. Given the surface albedo Rd, α′ is found by bisection on s = √(3(1 − α′)) ∈ [0, √3] (Rd decreases in
//! s) to the last bit. The scattering distance then fixes the scale: either the transport mean free path
//! ℓ = 1/σt′ or the diffuse mean free path ℓd = 1/σtr with σtr = √(3σaσt′) = σt′ √(3(1 − α′)) (Jensen & Buhler's
//! choice). σs′ = α′σt′, σa = (1 − α′)σt′. Burley's shape parameter from the same inputs is
//! [`super::burley::Burley::from_mean_free_path`].

use super::dipole::Dipole;
use super::{boundary_a, FdrForm};
use crate::error::{check_positive, InvalidInput};

/// Which length the artist gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ScatteringDistance {
    /// ℓ = 1/σt′ (mm).
    TransportMeanFreePath,
    /// ℓd = 1/σtr (mm), Jensen & Buhler 2002; infinite without absorption, so an albedo of 1 has no solution.
    DiffuseMeanFreePath,
}

/// The dipole's total diffuse reflectance as a function of the reduced albedo α′ (η and the Fdr form fix A).
pub fn dipole_total_reflectance(albedo_prime: f64, eta: f64, fdr_form: FdrForm) -> f64 {
    let a = boundary_a(eta, fdr_form);
    let s = (3.0 * (1.0 - albedo_prime)).max(0.0).sqrt();
    0.5 * albedo_prime * (1.0 + (-(4.0 / 3.0) * a * s).exp()) * (-s).exp()
}

/// s = √(3(1 − α′)) ∈ [0, √3] whose dipole total diffuse reflectance is `surface_albedo` ∈ [0, 1] (exact at the
/// ends; bisection to adjacent floating-point numbers between them).
fn transport_s(surface_albedo: f64, eta: f64, fdr_form: FdrForm) -> Result<f64, InvalidInput> {
    if !(surface_albedo.is_finite() && (0.0..=1.0).contains(&surface_albedo)) {
        return Err(InvalidInput::new("albedo", format!("must be in 0..=1, got {surface_albedo}")));
    }
    check_positive("eta", eta, "relative index")?;
    let root3 = 3.0f64.sqrt();
    if surface_albedo == 0.0 {
        return Ok(root3);
    }
    if surface_albedo == 1.0 {
        return Ok(0.0);
    }
    let rd = |s: f64| dipole_total_reflectance(1.0 - s * s / 3.0, eta, fdr_form);
    // Rd(s) falls from 1 at s = 0 to 0 at s = √3.
    let (mut lo, mut hi) = (0.0f64, root3);
    for _ in 0..2000 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if rd(mid) > surface_albedo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // The end closer in Rd.
    Ok(if (rd(lo) - surface_albedo).abs() <= (rd(hi) - surface_albedo).abs() { lo } else { hi })
}

/// The reduced albedo α′ ∈ [0, 1] whose dipole total diffuse reflectance is `surface_albedo` ∈ [0, 1].
pub fn reduced_albedo(surface_albedo: f64, eta: f64, fdr_form: FdrForm) -> Result<f64, InvalidInput> {
    let s = transport_s(surface_albedo, eta, fdr_form)?;
    Ok(if surface_albedo == 0.0 { 0.0 } else { (1.0 - s * s / 3.0).clamp(0.0, 1.0) })
}

/// σa and σs′ (mm⁻¹) of the dipole whose surface albedo is `surface_albedo` and whose scattering distance of kind
/// `kind` is `distance_mm`.
pub fn dipole_coefficients(
    surface_albedo: f64,
    distance_mm: f64,
    kind: ScatteringDistance,
    eta: f64,
    fdr_form: FdrForm,
) -> Result<Dipole, InvalidInput> {
    check_positive("distance_mm", distance_mm, "mm")?;
    let s = transport_s(surface_albedo, eta, fdr_form)?;
    if surface_albedo == 0.0 {
        return Err(InvalidInput::new(
            "albedo",
            "0 means no scattering (reduced albedo 0); the dipole needs sigma_s' > 0: give an albedo above 0",
        ));
    }
    let sigma_t_prime = match kind {
        ScatteringDistance::TransportMeanFreePath => 1.0 / distance_mm,
        ScatteringDistance::DiffuseMeanFreePath => {
            if s <= 0.0 {
                return Err(InvalidInput::new(
                    "albedo",
                    format!(
                        "{surface_albedo} means no absorption (reduced albedo 1), where the diffuse mean free path \
                         1/sigma_tr is infinite: give an albedo below 1 or a transport mean free path"
                    ),
                ));
            }
            // σtr = σt′ · s
            1.0 / (distance_mm * s)
        }
    };
    // σa = (1 − α′)σt′ = (s²/3)σt′, computed from s so that albedos near 1 keep their small absorption.
    let sigma_a = s * s / 3.0 * sigma_t_prime;
    Dipole::new(sigma_a, (1.0 - s * s / 3.0) * sigma_t_prime, eta, fdr_form)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::ReducedCoefficients;

    fn albedos() -> Vec<f64> {
        let mut v = vec![0.0, 1e-9, 1e-6, 1e-3, 0.999, 0.999_999, 1.0 - 1e-12, 1.0];
        v.extend((1..100).map(|k| k as f64 / 100.0));
        v
    }

    #[test]
    fn forward_and_inverse_round_trip_over_the_whole_albedo_range() {
        for eta in [1.0, 1.3, 1.4] {
            for fdr in [FdrForm::Dj05, FdrForm::Jensen01] {
                for a in albedos() {
                    for (kind, ell) in [
                        (ScatteringDistance::TransportMeanFreePath, 0.7),
                        (ScatteringDistance::DiffuseMeanFreePath, 2.5),
                    ] {
                        if a == 0.0 || (a == 1.0 && kind == ScatteringDistance::DiffuseMeanFreePath) {
                            continue;
                        }
                        let d = dipole_coefficients(a, ell, kind, eta, fdr).unwrap();
                        let back = d.total_reflectance();
                        assert!((back - a).abs() <= 1e-6 * a + 1e-15, "eta {eta}, A {a}, {kind:?}: Rd = {back}");
                        let length = match kind {
                            ScatteringDistance::TransportMeanFreePath => 1.0 / d.sigma_t_prime(),
                            ScatteringDistance::DiffuseMeanFreePath => 1.0 / d.sigma_tr(),
                        };
                        assert!((length - ell).abs() <= 1e-12 * ell, "A {a}, {kind:?}: {length}");
                    }
                }
            }
        }
        // The round trip the other way: from coefficients to albedo and back.
        let d = Dipole::new(0.032, 0.74, 1.3, FdrForm::Dj05).unwrap();
        let ap = reduced_albedo(d.total_reflectance(), 1.3, FdrForm::Dj05).unwrap();
        assert!((ap - d.albedo_prime()).abs() < 1e-12, "{ap} vs {}", d.albedo_prime());
    }

    #[test]
    fn the_ends_of_the_range() {
        assert_eq!(reduced_albedo(0.0, 1.3, FdrForm::Dj05).unwrap(), 0.0);
        assert_eq!(reduced_albedo(1.0, 1.3, FdrForm::Dj05).unwrap(), 1.0);
        let white =
            dipole_coefficients(1.0, 1.0, ScatteringDistance::TransportMeanFreePath, 1.3, FdrForm::Dj05).unwrap();
        assert_eq!(white.sigma_a_per_mm, 0.0);
    }

    #[test]
    fn no_solution_is_a_clear_error() {
        let e = dipole_coefficients(1.0, 1.0, ScatteringDistance::DiffuseMeanFreePath, 1.3, FdrForm::Dj05).unwrap_err();
        assert_eq!(e.param, "albedo");
        assert!(e.message.contains("infinite"), "{e}");
        let e =
            dipole_coefficients(0.0, 1.0, ScatteringDistance::TransportMeanFreePath, 1.3, FdrForm::Dj05).unwrap_err();
        assert!(e.param == "albedo" && e.message.contains("no scattering"), "{e}");
        for a in [-0.01, 1.01, f64::NAN, f64::INFINITY] {
            assert_eq!(reduced_albedo(a, 1.3, FdrForm::Dj05).unwrap_err().param, "albedo", "{a}");
        }
        let e = dipole_coefficients(0.5, 0.0, ScatteringDistance::TransportMeanFreePath, 1.3, FdrForm::Dj05);
        assert_eq!(e.unwrap_err().param, "distance_mm");
    }
}
