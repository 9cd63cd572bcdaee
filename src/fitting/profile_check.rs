//! The one validation of a profile before any consumer uses it (`fit gaussians|burley|separable`, `kernel`,
//! `importance-kernel`, `transmittance`, `evaluate`, `run sss`).
//!
//! Every consumer integrates R(r) over the plane (the total ∫₀^∞ 2πr R(r) dr, the normalisation of the kernels and
//! of `--normalize`) and the least-squares fits integrate its square (the L2 norm ∫₀^∞ r·(r R(r))² dr of thesis
//! eq. 2.2's objective). A profile is usable when, in every channel, R is finite and non-negative on the fits'
//! radial grid ([`super::quadrature::RadialGrid::standard`], 1e−5 … 1e3 mm), its total is finite and positive,
//! and the squared norm is finite: an all-zero channel has nothing to fit or to sample, and values so large that
//! these integrals overflow (R = 1e308 mm⁻²) would turn every fit into NaN.

use super::quadrature::{checked_samples, RadialGrid};
use crate::diffusion::RadialProfile;
use crate::error::InvalidInput;

/// Channel names for messages (R, G, B as the CSV columns name them).
const CHANNELS: [&str; 3] = ["R (red)", "G (green)", "B (blue)"];

/// Checks `profile` for every consumer (see the module docs). Errors carry `param = "profile"`; the caller names the
/// flag and file it came from.
pub fn check_profile(profile: &dyn RadialProfile) -> Result<(), InvalidInput> {
    let grid = RadialGrid::standard();
    let mut samples = profile.reflectance_many(&grid.r_mm);
    checked_samples("profile", &grid.r_mm, &mut samples)?;
    let totals = profile.total_reflectance();
    for c in 0..3 {
        let t = totals[c];
        if !t.is_finite() {
            return Err(InvalidInput::new(
                "profile",
                format!(
                    "channel {}: the total reflectance ∫2πr R(r) dr overflows ({t}); R must stay well below 1e150 mm^-2",
                    CHANNELS[c]
                ),
            ));
        }
        if t <= 0.0 {
            return Err(InvalidInput::new(
                "profile",
                format!(
                    "channel {}: R(r) is 0 at every radius (total reflectance {t}); every channel needs a positive total",
                    CHANNELS[c]
                ),
            ));
        }
        let squares: Vec<f64> = grid.r_mm.iter().zip(&samples).map(|(r, v)| (r * v[c]) * (r * v[c])).collect();
        let norm2 = grid.integrate_r(&squares);
        if !norm2.is_finite() {
            return Err(InvalidInput::new(
                "profile",
                format!(
                    "channel {}: the fits' squared norm ∫ r (r R)^2 dr overflows; R must stay well below 1e150 mm^-2",
                    CHANNELS[c]
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::tabulated::TabulatedProfile;

    fn csv(rows: &str) -> TabulatedProfile {
        TabulatedProfile::from_csv_str(&format!("r_mm,R_r,R_g,R_b\n{rows}"), "t.csv").unwrap()
    }

    #[test]
    fn a_measured_profile_passes() {
        let p = crate::diffusion::sum_of_gaussians::preset("deon6").unwrap();
        check_profile(&p).unwrap();
        check_profile(&csv("0.1,4,2,1\n1,2,1,0.5\n10,0.01,0.01,0.01\n")).unwrap();
    }

    #[test]
    fn an_all_zero_channel_is_refused_naming_it() {
        let e = check_profile(&csv("0.1,4,0,1\n1,2,0,0.5\n")).unwrap_err();
        assert_eq!(e.param, "profile");
        assert!(e.message.contains("G (green)") && e.message.contains("0 at every radius"), "{e}");
        let e = check_profile(&csv("0.1,0,0,0\n1,0,0,0\n")).unwrap_err();
        assert!(e.message.contains("R (red)"), "{e}");
    }

    #[test]
    fn overflowing_values_are_refused_before_a_fit_sees_nan() {
        for v in ["1e308", "1e200"] {
            let e = check_profile(&csv(&format!("0.1,{v},1,1\n1,{v},1,1\n"))).unwrap_err();
            assert!(e.message.contains("R (red)") && e.message.contains("overflows"), "{v}: {e}");
        }
    }
}
