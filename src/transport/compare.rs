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
