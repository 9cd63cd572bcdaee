//! Evaluating given profile parameters against a target profile (`rtbake evaluate`).
//!
//! A candidate radial profile (a sum of Gaussians, Burley's normalized diffusion, any [`RadialProfile`]) is compared
//! with a target on the fixed radial grid of the fits ([`RadialGrid::standard`], 1e-5..1e3 mm, 16 nodes per decade)
//! with the metrics the fits report:
//!
//! - **relative L2 of r·R(r)** (the curve the papers plot), √(∫ (r (R_cand − R_target))² dr / ∫ (r R_target)² dr),
//!   percent — the metric of [`super::burley_fit`];
//! - **max**: max_r |r ΔR(r)| / max_r |r R_target(r)|, percent (the largest deviation of the plotted curve, relative
//!   to its peak);
//! - **eq. 2.2 RMS**: √(∫ r (R_cand − R_target)² dr / ∫ r R_target² dr), percent — the error
//!   [`super::fit_sum_of_gaussians`] reports (d'Eon et al.'s weighting), so a sum of Gaussians evaluated against the
//!   profile it was fitted to reproduces `rtbake fit gaussians`' `error_percent`;
//! - **totals**: ∫ 2πr R dr of both and their difference (candidate − target), the colour a renderer would shift.
//!
//! Where either profile is known only over a range ([`RadialProfile::support_mm`]: a tabulated `--profile-csv`),
//! the errors are measured over the grid nodes inside it (the CSV's extrapolation is no measurement); the totals are
//! each profile's own.
//!
//! With `normalize`, both profiles are divided by their own totals first (shape only; the separable kernel and a
//! normalised fit conserve energy and take colour from the albedo). The separable kernel is not radial; its errors
//! are [`crate::separable::fit::kernel_errors`] on the fit's 2-D grid.

use super::quadrature::{checked_samples, RadialGrid};
use crate::diffusion::RadialProfile;
use crate::error::InvalidInput;

/// Errors of a candidate profile against a target, per channel.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ProfileErrors {
    /// Relative L2 of r·R(r), percent.
    pub relative_l2_percent: [f64; 3],
    /// max |r ΔR| / max |r R_target|, percent.
    pub max_percent: [f64; 3],
    /// √(∫ r ΔR² dr / ∫ r R_target² dr), percent (thesis eq. 2.2's weighting: the Gaussian fit's error).
    pub eq_2_2_rms_percent: [f64; 3],
    /// The radii compared, mm (first and last grid node used).
    pub compared_range_mm: [f64; 2],
    /// ∫ 2πr R dr of the candidate (1 with `normalize`).
    pub candidate_totals: [f64; 3],
    /// ∫ 2πr R dr of the target (1 with `normalize`).
    pub target_totals: [f64; 3],
    /// candidate − target totals.
    pub total_difference: [f64; 3],
    /// Whether both were normalised to unit totals first.
    pub normalized: bool,
}

impl ProfileErrors {
    /// The largest relative L2 over the channels (what `--max-error` gates on).
    pub fn worst_relative_l2_percent(&self) -> f64 {
        self.relative_l2_percent.iter().copied().fold(0.0, f64::max)
    }
}

/// Compares `candidate` with `target` (module docs); both must be finite and non-negative on the grid, with
/// positive totals when `normalize` is set.
pub fn compare_profiles(
    candidate: &dyn RadialProfile,
    target: &dyn RadialProfile,
    normalize: bool,
) -> Result<ProfileErrors, InvalidInput> {
    let mut grid = RadialGrid::standard();
    let (mut lo, mut hi) = (0.0f64, f64::INFINITY);
    for (a, b) in [candidate.support_mm(), target.support_mm()].into_iter().flatten() {
        (lo, hi) = (lo.max(a), hi.min(b));
    }
    // Keep the nodes inside the support (a small relative slack keeps a node that equals a CSV row).
    let keep: Vec<bool> = grid.r_mm.iter().map(|&r| r >= lo * (1.0 - 1e-12) && r <= hi * (1.0 + 1e-12)).collect();
    if keep.iter().filter(|&&k| k).count() < 2 {
        return Err(InvalidInput::new(
            "target",
            format!("the profiles overlap on [{lo}, {hi}] mm, fewer than 2 nodes of the comparison grid"),
        ));
    }
    grid.r_mm = grid.r_mm.iter().zip(&keep).filter(|(_, &k)| k).map(|(r, _)| *r).collect();
    grid.weights = grid.weights.iter().zip(&keep).filter(|(_, &k)| k).map(|(w, _)| *w).collect();
    let mut cand = candidate.reflectance_many(&grid.r_mm);
    let mut targ = target.reflectance_many(&grid.r_mm);
    checked_samples("candidate", &grid.r_mm, &mut cand)?;
    checked_samples("target", &grid.r_mm, &mut targ)?;
    let (mut ct, mut tt) = (candidate.total_reflectance(), target.total_reflectance());
    let mut scale = ([1.0; 3], [1.0; 3]);
    if normalize {
        for c in 0..3 {
            for (name, t) in [("candidate", ct[c]), ("target", tt[c])] {
                if !(t.is_finite() && t > 0.0) {
                    return Err(InvalidInput::new(
                        name,
                        format!("total reflectance (channel {c}) is {t}; `normalize` needs it finite and > 0"),
                    ));
                }
            }
            scale.0[c] = 1.0 / ct[c];
            scale.1[c] = 1.0 / tt[c];
        }
        (ct, tt) = ([1.0; 3], [1.0; 3]);
    }
    let mut out = ProfileErrors {
        relative_l2_percent: [0.0; 3],
        max_percent: [0.0; 3],
        eq_2_2_rms_percent: [0.0; 3],
        compared_range_mm: [grid.r_mm[0], *grid.r_mm.last().expect("checked")],
        candidate_totals: ct,
        target_totals: tt,
        total_difference: [0, 1, 2].map(|c| ct[c] - tt[c]),
        normalized: normalize,
    };
    for c in 0..3 {
        // ∫ (r f)² dr = ∫ r·(r f²) dr: the grid integrates r·g.
        let rr =
            |f: &dyn Fn(usize) -> f64| -> Vec<f64> { (0..grid.len()).map(|j| grid.r_mm[j] * f(j).powi(2)).collect() };
        let diff = |j: usize| cand[j][c] * scale.0[c] - targ[j][c] * scale.1[c];
        let norm = grid.integrate_r(&rr(&|j| targ[j][c] * scale.1[c]));
        if norm.is_nan() || norm <= 0.0 {
            return Err(InvalidInput::new("target", format!("channel {c} is zero on the grid; nothing to compare")));
        }
        out.relative_l2_percent[c] = 100.0 * (grid.integrate_r(&rr(&diff)) / norm).sqrt();
        let sq = |f: &dyn Fn(usize) -> f64| -> Vec<f64> { (0..grid.len()).map(|j| f(j).powi(2)).collect() };
        let norm_2_2 = grid.integrate_r(&sq(&|j| targ[j][c] * scale.1[c]));
        out.eq_2_2_rms_percent[c] = 100.0 * (grid.integrate_r(&sq(&diff)) / norm_2_2).sqrt();
        let peak = (0..grid.len()).map(|j| grid.r_mm[j] * targ[j][c] * scale.1[c]).fold(0.0, f64::max);
        let worst = (0..grid.len()).map(|j| (grid.r_mm[j] * diff(j)).abs()).fold(0.0, f64::max);
        out.max_percent[c] = 100.0 * worst / peak;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::burley::{Burley, RgbBurley};
    use crate::diffusion::sum_of_gaussians::deon6;

    #[test]
    fn a_profile_against_itself_has_no_error_and_a_scaled_one_has_its_scale() {
        let p = deon6();
        let e = compare_profiles(&p, &p, false).unwrap();
        assert_eq!(e.relative_l2_percent, [0.0; 3]);
        assert_eq!(e.total_difference, [0.0; 3]);
        let b =
            RgbBurley([Burley::new(0.5, 1.0).unwrap(), Burley::new(0.4, 0.5).unwrap(), Burley::new(0.2, 0.2).unwrap()]);
        let b2 = RgbBurley(b.0.map(|x| Burley::new(x.albedo * 1.1, x.d_mm).unwrap()));
        let e = compare_profiles(&b2, &b, false).unwrap();
        for c in 0..3 {
            assert!((e.relative_l2_percent[c] - 10.0).abs() < 1e-9, "{e:?}");
            assert!((e.max_percent[c] - 10.0).abs() < 1e-9, "{e:?}");
            assert!((e.total_difference[c] - 0.1 * b.0[c].albedo).abs() < 1e-12);
        }
        // Normalised: the scale disappears.
        let e = compare_profiles(&b2, &b, true).unwrap();
        assert!(e.worst_relative_l2_percent() < 1e-12 && e.total_difference == [0.0; 3], "{e:?}");
    }

    #[test]
    fn a_different_shape_is_measured() {
        let wide = RgbBurley([Burley::new(0.5, 1.0).unwrap(); 3]);
        let narrow = RgbBurley([Burley::new(0.5, 0.5).unwrap(); 3]);
        let e = compare_profiles(&wide, &narrow, false).unwrap();
        assert!(e.relative_l2_percent[0] > 30.0 && e.max_percent[0] > 10.0, "{e:?}");
        assert_eq!(e.total_difference, [0.0; 3]);
    }
}
