//! Monte Carlo against a diffusion profile: where the diffusion approximation (dipole, Jensen et al. 2001;
//! multipole and layered adding, Donner & Jensen 2005) departs from transport.
//!
//! The Monte Carlo bin value is the annulus mean of R(r), so the diffusion profile is averaged over the same annulus,
//! R̄ᵢ = ∫ 2πr R(r) dr / (π(2i + 1)Δr²) (8-point Gauss–Legendre per bin), before comparing. Reported per channel:
//! the totals (Monte Carlo diffuse Rd ± SE against the profile's ∫2πr R dr) and the relative L2 error of r·R(r)
//! over the bins in a radius window, 100·√(Σ rᵢ²(R̄ᵢ − Rᵢ)²)/√(Σ rᵢ² Rᵢ²) % (the measure the thesis uses for its
//! fits, eq. 2.2, on the Monte Carlo grid).

use super::mc::{Estimate, McResult};
use crate::diffusion::quadrature::gauss_legendre;
use crate::diffusion::RadialProfile;
use serde::Serialize;
use std::f64::consts::PI;

/// One channel's comparison.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChannelComparison {
    /// Monte Carlo total diffuse reflectance and its standard error.
    pub total_r_mc: Estimate,
    /// The profile's ∫2πr R(r) dr.
    pub total_r_diffusion: f64,
    /// (diffusion − Monte Carlo) / Monte Carlo, %.
    pub total_r_difference_percent: f64,
    /// Relative L2 error of r·R(r) over the window, % (`None` when no Monte Carlo photon left in the window).
    pub rr_error_percent: Option<f64>,
    /// Largest |R̄ − R| / SE over the window's bins with a non-zero SE (how many standard errors apart).
    pub max_z: f64,
}

/// The comparison of all channels and the window it used.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    pub r_window_mm: [f64; 2],
    pub channels: [ChannelComparison; 3],
}

/// The profile averaged over every Monte Carlo annulus, per bin and channel, mm⁻².
pub fn bin_averaged(profile: &dyn RadialProfile, bin_mm: f64, bins: usize) -> Vec<[f64; 3]> {
    let (x, w) = gauss_legendre(8);
    let radii: Vec<f64> = (0..bins)
        .flat_map(|i| {
            let (a, b) = (i as f64 * bin_mm, (i + 1) as f64 * bin_mm);
            x.iter().map(move |&t| 0.5 * (a + b) + 0.5 * (b - a) * t).collect::<Vec<_>>()
        })
        .collect();
    let values = profile.reflectance_many(&radii);
    (0..bins)
        .map(|i| {
            let area = PI * (2 * i + 1) as f64 * bin_mm * bin_mm;
            let mut s = [0.0; 3];
            for (k, wk) in w.iter().enumerate() {
                let r = radii[i * w.len() + k];
                for c in 0..3 {
                    s[c] += wk * 0.5 * bin_mm * 2.0 * PI * r * values[i * w.len() + k][c];
                }
            }
            s.map(|v| v / area)
        })
        .collect()
}

/// Compares `mc` with `profile` over bin centres in `r_window_mm` (inclusive). The window recorded in the result is
/// clipped to the tallied range [0, bins·Δr] (so an open window `[a, ∞)` is written as the finite radius it
/// covered, never as a JSON `null`).
pub fn compare(mc: &McResult, profile: &dyn RadialProfile, r_window_mm: [f64; 2]) -> Comparison {
    let s = &mc.settings;
    let diffusion = bin_averaged(profile, s.bin_mm, s.bins);
    let totals = profile.total_reflectance();
    let radii = s.radii_mm();
    let channels = [0, 1, 2].map(|c| {
        let ch = &mc.channels[c];
        let (mut num, mut den, mut max_z) = (0.0f64, 0.0f64, 0.0f64);
        for (i, &r) in radii.iter().enumerate() {
            if r < r_window_mm[0] || r > r_window_mm[1] {
                continue;
            }
            let e = ch.reflectance_mm2[i];
            let d = diffusion[i][c] - e.mean;
            num += r * r * d * d;
            den += r * r * e.mean * e.mean;
            if e.se > 0.0 {
                max_z = max_z.max(d.abs() / e.se);
            }
        }
        let mc_total = ch.diffuse_reflectance;
        ChannelComparison {
            total_r_mc: mc_total,
            total_r_diffusion: totals[c],
            total_r_difference_percent: 100.0 * (totals[c] - mc_total.mean) / mc_total.mean,
            rr_error_percent: (den > 0.0).then(|| 100.0 * (num / den).sqrt()),
            max_z,
        }
    });
    let covered_mm = s.bins as f64 * s.bin_mm;
    Comparison { r_window_mm: [r_window_mm[0].min(covered_mm), r_window_mm[1].min(covered_mm)], channels }
}

/// The diffusion model rtbake has for `stack` (σs′ = σs(1 − g) per channel, DJ05 Fdr, exact image series):
/// a single semi-infinite layer is the dipole (η = n_layer/n_above; Jensen et al. 2001), finite stacks are the
/// multipole / layered adding (Donner & Jensen 2005). Returns the profile and its name, or why there is none
/// (a semi-infinite layer under others; a layer thinner than 1/σt′, where the multipole is not defined).
pub fn diffusion_counterpart(
    stack: &super::McStack,
) -> Result<(Box<dyn RadialProfile + Send>, &'static str), crate::error::InvalidInput> {
    use crate::diffusion::dipole::{Dipole, DipoleRgb};
    use crate::diffusion::layered::{Adding, Layer, LayerStack, LayeredProfile};
    use crate::diffusion::multipole::Series;
    use crate::diffusion::FdrForm;
    let layers = stack.layers();
    let reduced = |l: &super::McLayer| [0, 1, 2].map(|c| l.sigma_s_per_mm[c] * (1.0 - l.g[c]));
    if layers.len() == 1 && layers[0].thickness_mm.is_infinite() {
        let l = &layers[0];
        let sp = reduced(l);
        let mut d = Vec::with_capacity(3);
        for (c, &s) in sp.iter().enumerate() {
            d.push(Dipole::new(l.sigma_a_per_mm[c], s, l.eta / stack.eta_above(), FdrForm::Dj05)?);
        }
        return Ok((Box::new(DipoleRgb([d[0], d[1], d[2]])), "dipole"));
    }
    if layers.iter().any(|l| l.thickness_mm.is_infinite()) {
        return Err(crate::error::InvalidInput::new(
            "layers",
            "a semi-infinite layer under other layers has no diffusion counterpart in rtbake",
        ));
    }
    let ls = LayerStack::new(
        stack.eta_above(),
        stack.eta_below(),
        layers
            .iter()
            .map(|l| Layer {
                thickness_mm: l.thickness_mm,
                eta: l.eta,
                sigma_a: l.sigma_a_per_mm,
                sigma_s_prime: reduced(l),
            })
            .collect(),
    )?;
    let name = if layers.len() == 1 { "multipole" } else { "layered multipole" };
    Ok((Box::new(LayeredProfile::new(&ls, Adding::Symmetric, Series::Exact, FdrForm::Dj05)?), name))
}

/// A reference profile on Monte Carlo bins: the annulus means of R(r) and their standard errors at the bin centres
/// (i + ½)Δr, and the totals with their standard errors. Built from any [`RadialProfile`] that carries standard
/// errors (a [`super::profile::McProfile`], or a spectral projection of several, whose per-bin values are then the
/// projected annulus means because the projection is linear).
#[derive(Clone, Debug, PartialEq)]
pub struct BinnedReference {
    pub bin_mm: f64,
    pub r_mm2: Vec<[f64; 3]>,
    pub r_se_mm2: Vec<[f64; 3]>,
    pub total_r: [Estimate; 3],
}

/// How far a model is from a [`BinnedReference`] in one channel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ModelDifference {
    /// The model's ∫2πr R(r) dr.
    pub total_r: f64,
    /// (model − reference) / reference, %.
    pub total_r_difference_percent: f64,
    /// Relative L2 error of r·R(r) over the window, % (`None` where the reference has no light in the window).
    pub rr_error_percent: Option<f64>,
}

impl BinnedReference {
    /// Evaluates `reference` at the centres of `bins` bins of `bin_mm`.
    ///
    /// # Panics
    /// When `reference` has no standard errors (it is not a Monte Carlo result).
    pub fn from_profile(reference: &dyn RadialProfile, bin_mm: f64, bins: usize) -> Self {
        let centres: Vec<f64> = (0..bins).map(|i| (i as f64 + 0.5) * bin_mm).collect();
        let se = |r: f64| reference.reflectance_se_mm2(r).expect("a Monte Carlo reference has standard errors");
        let total_se = reference.total_reflectance_se().expect("a Monte Carlo reference has standard errors");
        let total = reference.total_reflectance();
        Self {
            bin_mm,
            r_mm2: reference.reflectance_many(&centres),
            r_se_mm2: centres.iter().map(|&r| se(r)).collect(),
            total_r: [0, 1, 2].map(|c| Estimate { mean: total[c], se: total_se[c] }),
        }
    }

    fn window(&self, r_window_mm: [f64; 2]) -> impl Iterator<Item = (usize, f64)> + '_ {
        (0..self.r_mm2.len())
            .map(|i| (i, (i as f64 + 0.5) * self.bin_mm))
            .filter(move |&(_, r)| r >= r_window_mm[0] && r <= r_window_mm[1])
    }

    /// The reference's own noise in the r·R(r) measure: 100·√(Σ rᵢ² SEᵢ²)/√(Σ rᵢ² Rᵢ²) % over the window — the
    /// floor below which a model's r·R(r) error cannot be told from the Monte Carlo noise.
    pub fn rr_noise_percent(&self, r_window_mm: [f64; 2]) -> [Option<f64>; 3] {
        [0, 1, 2].map(|c| {
            let (mut num, mut den) = (0.0f64, 0.0f64);
            for (i, r) in self.window(r_window_mm) {
                num += r * r * self.r_se_mm2[i][c] * self.r_se_mm2[i][c];
                den += r * r * self.r_mm2[i][c] * self.r_mm2[i][c];
            }
            (den > 0.0).then(|| 100.0 * (num / den).sqrt())
        })
    }

    /// `model` against the reference: totals, and the relative L2 error of r·R(r) over the window with the model
    /// averaged over each annulus ([`bin_averaged`]).
    pub fn compare(&self, model: &dyn RadialProfile, r_window_mm: [f64; 2]) -> [ModelDifference; 3] {
        let avg = bin_averaged(model, self.bin_mm, self.r_mm2.len());
        self.compare_binned(&avg, model.total_reflectance(), r_window_mm)
    }

    /// [`Self::compare`] for a model already averaged over the reference's annuli (`avg`, one row per bin, as
    /// [`bin_averaged`] gives it) with its totals — so one evaluation of the model serves several references.
    pub fn compare_binned(&self, avg: &[[f64; 3]], totals: [f64; 3], r_window_mm: [f64; 2]) -> [ModelDifference; 3] {
        assert_eq!(avg.len(), self.r_mm2.len(), "one model value per reference bin");
        [0, 1, 2].map(|c| {
            let (mut num, mut den) = (0.0f64, 0.0f64);
            for (i, r) in self.window(r_window_mm) {
                let d = avg[i][c] - self.r_mm2[i][c];
                num += r * r * d * d;
                den += r * r * self.r_mm2[i][c] * self.r_mm2[i][c];
            }
            let reference = self.total_r[c].mean;
            ModelDifference {
                total_r: totals[c],
                total_r_difference_percent: 100.0 * (totals[c] - reference) / reference,
                rr_error_percent: (den > 0.0).then(|| 100.0 * (num / den).sqrt()),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::dipole::{Dipole, DipoleRgb};
    use crate::diffusion::FdrForm;
    use crate::transport::profile::McProfile;
    use crate::transport::{McSettings, McStack};

    /// A Monte Carlo reference compared with itself (as a profile) differs by nothing; a model that is the
    /// reference scaled by k differs by (k − 1) in total and in r·R(r); the noise floor is positive and shrinks
    /// with more photons.
    #[test]
    fn binned_reference_measures_scaled_models_exactly() {
        let stack = McStack::semi_infinite([0.05, 0.2, 0.5], [1.0, 1.2, 1.5], 0.0, 1.3).unwrap();
        let run = |n| {
            let s = McSettings::new(n, 7, 4, 0.1, 40).unwrap();
            BinnedReference::from_profile(&McProfile::simulate(&stack, &s), s.bin_mm, s.bins)
        };
        let reference = run(4000);
        let totals = reference.total_r.map(|e| e.mean);
        let same = reference.compare_binned(&reference.r_mm2, totals, [0.0, f64::INFINITY]);
        let scaled: Vec<[f64; 3]> = reference.r_mm2.iter().map(|v| v.map(|x| 1.25 * x)).collect();
        let k = reference.compare_binned(&scaled, totals.map(|t| 1.25 * t), [0.0, f64::INFINITY]);
        for c in 0..3 {
            assert_eq!(same[c].total_r_difference_percent, 0.0);
            assert_eq!(same[c].rr_error_percent, Some(0.0));
            assert!((k[c].total_r_difference_percent - 25.0).abs() < 1e-9);
            assert!((k[c].rr_error_percent.unwrap() - 25.0).abs() < 1e-9);
        }
        let (few, many) = (reference.rr_noise_percent([0.0, 4.0]), run(40_000).rr_noise_percent([0.0, 4.0]));
        for c in 0..3 {
            assert!(few[c].unwrap() > 0.0 && many[c].unwrap() < 0.6 * few[c].unwrap(), "{few:?} {many:?}");
        }
        // A window beyond every bin has no light: no r·R(r) error.
        assert_eq!(reference.compare_binned(&scaled, totals, [50.0, 60.0])[0].rr_error_percent, None);
        // `compare` evaluates a profile on the annuli; the dipole is within tens of per cent of this transport.
        let dip = DipoleRgb(
            [0, 1, 2].map(|c| Dipole::new([0.05, 0.2, 0.5][c], [1.0, 1.2, 1.5][c], 1.3, FdrForm::Dj05).unwrap()),
        );
        let d = reference.compare(&dip, [0.0, f64::INFINITY]);
        assert!(d.iter().all(|x| x.total_r_difference_percent.abs() < 60.0), "{d:?}");
    }
}
