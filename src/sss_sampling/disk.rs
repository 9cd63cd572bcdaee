//! An importance-sampled disk kernel of a radial profile (the sampling Unity HDRP's diffusion profiles use;
//! Golubev, "Efficient Screen-Space Subsurface Scattering Using Burley's Normalized Diffusion in Real-Time",
//! SIGGRAPH 2018 course "Advances in Real-Time Rendering").
//!
//! N samples (1..=[`MAX_SAMPLES`]; HDRP's quality presets use [`UNITY_SAMPLE_PRESETS`] = 20, 40, 80):
//!
//! - radius rᵢ = F⁻¹(uᵢ) at the stratified quantiles uᵢ = (i + 0.5)/N of the sampled channel's radial CDF
//!   F(r) = ∫₀^r 2πr′R(r′)dr′ / ∫₀^∞ 2πr′R(r′)dr′;
//! - angle θᵢ = i·π(3 − √5) (the golden angle: a Fibonacci spiral), so (xᵢ, yᵢ) = rᵢ(cos θᵢ, sin θᵢ) mm;
//! - area density pdf(rᵢ) = F′(rᵢ)/(2πrᵢ) = R_s(rᵢ)/A_s (mm⁻²; s the sampled channel, A_s its total);
//! - weight w_c,i = R_c(rᵢ)/pdf(rᵢ)/N, the reciprocal-pdf (Monte Carlo) estimator of ∫R_c dA = A_c; its sum is
//!   kept as [`ImportanceKernel::estimated_totals`], and the weights used for blurring are normalised,
//!   ŵ_c,i = w_c,i / Σᵢ w_c,i, so each channel sums to 1 (energy-preserving blur: the total reflectance belongs
//!   in the albedo, as for the separable and sum-of-Gaussians passes).
//!
//! **Which channel is sampled:** the one with the largest mean radius ∫ r·2πrR dr / A (HDRP samples the widest
//! channel so no channel's tail is missed; narrower channels get large weights near the centre instead). Burley's
//! mean radius is 2.5·d (closed form); other profiles take it from the tabulated CDF.
//!
//! **How F is inverted:** Burley's closed form ([`crate::diffusion::burley::Burley::sample_radius_mm`], Newton on
//! F(r) = 1 − (e^(−r/d) + 3e^(−r/3d))/4 to 1e−14); any other profile through the tabulated CDF of
//! [`super::cdf`] (monotone Hermite on a 256-per-decade log grid, tested against the Burley closed form).
//!
//! **Cut-off:** [`ImportanceKernel::cutoff_mm`] = F⁻¹([`CUTOFF_QUANTILE`] = 0.999) of the sampled channel, the
//! radius within which 99.9 % of its reflected light lands (a screen-space filter radius).

// Index loops over channels mirror the equations.
#![allow(clippy::needless_range_loop)]

use super::cdf::RadialCdf;
use crate::diffusion::burley::RgbBurley;
use crate::diffusion::RadialProfile;
use crate::error::InvalidInput;
use std::f64::consts::PI;

/// Largest sample budget.
pub const MAX_SAMPLES: usize = 1024;
/// Unity HDRP's diffusion-profile sample budgets (low, medium, high quality).
pub const UNITY_SAMPLE_PRESETS: [usize; 3] = [20, 40, 80];
/// The quantile of the sampled channel's CDF that defines the far cut-off radius.
pub const CUTOFF_QUANTILE: f64 = 0.999;
/// The golden angle π(3 − √5), radians.
pub fn golden_angle_rad() -> f64 {
    PI * (3.0 - 5f64.sqrt())
}

/// A profile as the sampler sees it: Burley with its closed-form CDF, or any profile through a tabulated CDF.
#[derive(Clone, Copy)]
pub enum SampledProfile<'a> {
    Burley(&'a RgbBurley),
    Tabulated(&'a dyn RadialProfile),
}

/// How the radii were drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inversion {
    /// Burley's closed-form CDF, inverted by Newton's method.
    BurleyClosedForm,
    /// The tabulated CDF of [`super::cdf`].
    TabulatedCdf,
}

impl Inversion {
    pub fn name(self) -> &'static str {
        match self {
            Self::BurleyClosedForm => "burley-closed-form",
            Self::TabulatedCdf => "tabulated-cdf",
        }
    }
}

/// One sample of the disk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskSample {
    /// Radius, mm.
    pub r_mm: f64,
    /// Angle, radians (golden-angle spiral; not reduced modulo 2π).
    pub theta_rad: f64,
    /// Area density of the sampled channel at r, mm⁻².
    pub pdf_per_mm2: f64,
    /// Normalised weight per channel (each channel sums to 1 over the samples).
    pub weight: [f64; 3],
    /// Un-normalised weight R_c(r)/pdf(r)/N per channel.
    pub weight_unnormalised: [f64; 3],
}

impl DiskSample {
    /// Offset (x, y) in mm.
    pub fn offset_mm(&self) -> [f64; 2] {
        [self.r_mm * self.theta_rad.cos(), self.r_mm * self.theta_rad.sin()]
    }
}

/// An importance-sampled disk kernel.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportanceKernel {
    pub samples: Vec<DiskSample>,
    /// The channel whose CDF was sampled (0 = R, 1 = G, 2 = B).
    pub sampled_channel: usize,
    /// Mean radius of each channel's normalised radial density, mm (the sampled channel has the largest).
    pub mean_radius_mm: [f64; 3],
    pub inversion: Inversion,
    /// Σᵢ w_c,i (un-normalised): the estimate of the total reflectance A_c.
    pub estimated_totals: [f64; 3],
    /// The totals the sampler normalised by: Burley's A_c, or the tabulated ∫₀^1000mm 2πrR dr.
    pub profile_totals: [f64; 3],
    /// F⁻¹(0.999) of the sampled channel, mm.
    pub cutoff_mm: f64,
}

/// Validates the sample budget (`samples`, 1..=1024).
pub fn check_samples(n: usize) -> Result<usize, InvalidInput> {
    crate::error::check_range("samples", n, 1, MAX_SAMPLES, "samples")
}

impl ImportanceKernel {
    /// Samples `profile` with `n` samples (see the module docs).
    pub fn new(profile: SampledProfile<'_>, n: usize) -> Result<Self, InvalidInput> {
        check_samples(n)?;
        match profile {
            SampledProfile::Burley(b) => Self::burley(b, n),
            SampledProfile::Tabulated(p) => Self::tabulated(p, n),
        }
    }

    fn burley(b: &RgbBurley, n: usize) -> Result<Self, InvalidInput> {
        let totals = b.total_reflectance();
        for (c, a) in totals.iter().enumerate() {
            if a.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(InvalidInput::new(
                    format!("albedo[{c}]"),
                    "must be > 0 for an importance kernel (a channel with no reflectance has nothing to sample)",
                ));
            }
        }
        let mean = b.0.map(|x| 2.5 * x.d_mm);
        let s = widest(&mean);
        let bs = b.0[s];
        let mut samples = Vec::with_capacity(n);
        for i in 0..n {
            let r = bs.sample_radius_mm(quantile(i, n))?;
            let pdf = bs.pdf_per_mm(r) / (2.0 * PI * r);
            let rc = b.reflectance_mm2(r);
            samples.push(sample(i, n, r, pdf, rc));
        }
        let cutoff_mm = bs.sample_radius_mm(CUTOFF_QUANTILE)?;
        finish(samples, s, mean, Inversion::BurleyClosedForm, totals, cutoff_mm)
    }

    fn tabulated(p: &dyn RadialProfile, n: usize) -> Result<Self, InvalidInput> {
        let cdf = RadialCdf::tabulate(p)?;
        let mean = [0, 1, 2].map(|c| cdf.channels[c].mean_radius_mm);
        let totals = [0, 1, 2].map(|c| cdf.channels[c].total);
        let s = widest(&mean);
        let radii: Vec<f64> = (0..n).map(|i| cdf.inverse(s, quantile(i, n))).collect();
        let values = p.reflectance_many(&radii);
        let mut samples = Vec::with_capacity(n);
        for (i, (r, rc)) in radii.iter().zip(&values).enumerate() {
            let rc = rc.map(|x| x.max(0.0));
            if rc.iter().any(|x| !x.is_finite()) {
                return Err(InvalidInput::new("profile", format!("R({r} mm) is not finite")));
            }
            let pdf = rc[s] / totals[s];
            if pdf.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(InvalidInput::new(
                    "profile",
                    format!("has zero density at the sampled radius {r} mm of channel {s}"),
                ));
            }
            samples.push(sample(i, n, *r, pdf, rc));
        }
        let cutoff_mm = cdf.inverse(s, CUTOFF_QUANTILE);
        finish(samples, s, mean, Inversion::TabulatedCdf, totals, cutoff_mm)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Never true (N ≥ 1); for clippy's `len_without_is_empty`.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The kernel's response to a function of position: Σᵢ ŵ_c,i·f_c(xᵢ, yᵢ) (mm offsets from the pixel).
    pub fn apply(&self, f: impl Fn([f64; 2]) -> [f64; 3]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for s in &self.samples {
            let v = f(s.offset_mm());
            for c in 0..3 {
                out[c] += s.weight[c] * v[c];
            }
        }
        out
    }
}

/// The stratified quantile (i + 0.5)/N.
pub fn quantile(i: usize, n: usize) -> f64 {
    (i as f64 + 0.5) / n as f64
}

fn widest(mean: &[f64; 3]) -> usize {
    // The first channel of the largest mean radius (ties: the lowest index, deterministic).
    let mut s = 0;
    for c in 1..3 {
        if mean[c] > mean[s] {
            s = c;
        }
    }
    s
}

fn sample(i: usize, n: usize, r: f64, pdf: f64, rc: [f64; 3]) -> DiskSample {
    let w = rc.map(|x| x / pdf / n as f64);
    DiskSample {
        r_mm: r,
        theta_rad: i as f64 * golden_angle_rad(),
        pdf_per_mm2: pdf,
        weight: w,
        weight_unnormalised: w,
    }
}

fn finish(
    mut samples: Vec<DiskSample>,
    sampled_channel: usize,
    mean_radius_mm: [f64; 3],
    inversion: Inversion,
    profile_totals: [f64; 3],
    cutoff_mm: f64,
) -> Result<ImportanceKernel, InvalidInput> {
    let mut est = [0.0; 3];
    for s in &samples {
        for c in 0..3 {
            est[c] += s.weight_unnormalised[c];
        }
    }
    for (c, e) in est.iter().enumerate() {
        if !(e.is_finite() && *e > 0.0) {
            return Err(InvalidInput::new(
                "profile",
                format!("channel {c}: the samples see no reflectance (sum of weights {e}); the channel is too narrow for this budget"),
            ));
        }
    }
    for s in &mut samples {
        for c in 0..3 {
            s.weight[c] = s.weight_unnormalised[c] / est[c];
        }
    }
    Ok(ImportanceKernel {
        samples,
        sampled_channel,
        mean_radius_mm,
        inversion,
        estimated_totals: est,
        profile_totals,
        cutoff_mm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::burley::{Burley, ShapeFit};
    use crate::diffusion::sum_of_gaussians::deon6;

    fn skin_burley() -> RgbBurley {
        RgbBurley::from_mean_free_path([0.8, 0.5, 0.3], [1.0, 0.5, 0.25], ShapeFit::DiffuseTransmission).unwrap()
    }

    #[test]
    fn importance_weights_sum_to_one_and_stratify_the_cdf() {
        let b = skin_burley();
        for n in [1, 20, 40, 80, 1024] {
            for k in [
                ImportanceKernel::new(SampledProfile::Burley(&b), n).unwrap(),
                ImportanceKernel::new(SampledProfile::Tabulated(&b), n).unwrap(),
            ] {
                assert_eq!(k.len(), n);
                assert_eq!(k.sampled_channel, 0, "red has the largest d");
                for c in 0..3 {
                    let s: f64 = k.samples.iter().map(|x| x.weight[c]).sum();
                    assert!((s - 1.0).abs() < 1e-12, "{s}");
                }
                let bs = b.0[0];
                for (i, s) in k.samples.iter().enumerate() {
                    let f = bs.cdf(s.r_mm);
                    let tol = if k.inversion == Inversion::BurleyClosedForm { 1e-9 } else { 1e-8 };
                    assert!((f - quantile(i, n)).abs() < tol, "{:?} i = {i}: F = {f}", k.inversion);
                    assert!((s.theta_rad - i as f64 * golden_angle_rad()).abs() < 1e-12);
                    // The sampled channel's un-normalised weight is A_s/N exactly.
                    assert!((s.weight_unnormalised[0] - 0.8 / n as f64).abs() < 1e-6 / n as f64);
                }
            }
        }
    }

    #[test]
    fn importance_tabulated_cdf_matches_the_burley_closed_form() {
        let b = Burley::new(0.6, 0.7).unwrap();
        let p = RgbBurley([b; 3]);
        let cdf = RadialCdf::tabulate(&p).unwrap();
        for k in 0..=400 {
            let r = 10f64.powf(-4.0 + 6.0 * k as f64 / 400.0);
            let (want, got) = (b.cdf(r), cdf.cdf(0, r));
            assert!((want - got).abs() < 1e-9, "r = {r}: {got} vs {want}");
        }
        for k in 1..1000 {
            let u = k as f64 / 1000.0;
            let (want, got) = (b.sample_radius_mm(u).unwrap(), cdf.inverse(0, u));
            assert!((want - got).abs() < 1e-6 * want, "u = {u}: {got} vs {want}");
            assert!((cdf.cdf(0, got) - u).abs() < 1e-12);
        }
        assert!((cdf.channels[0].total - 0.6).abs() < 1e-9);
        assert!((cdf.channels[0].mean_radius_mm - 2.5 * 0.7).abs() < 1e-6);
    }

    #[test]
    fn importance_unnormalised_sum_converges_to_the_albedo() {
        // For the channels not sampled, Σ w → A with an error that shrinks with N.
        let b = skin_burley();
        let mut last = [f64::INFINITY; 2];
        for n in [20, 80, 320, 1024] {
            let k = ImportanceKernel::new(SampledProfile::Burley(&b), n).unwrap();
            for (j, c) in [1usize, 2].iter().enumerate() {
                let e = (k.estimated_totals[*c] - b.0[*c].albedo).abs() / b.0[*c].albedo;
                assert!(e < last[j], "N = {n}, channel {c}: {e} not below {}", last[j]);
                last[j] = e;
            }
            assert!((k.estimated_totals[0] - 0.8).abs() < 1e-12);
        }
        assert!(last[0] < 0.01 && last[1] < 0.02, "{last:?}");
    }

    #[test]
    fn importance_is_deterministic_and_picks_the_widest_channel() {
        let g = deon6();
        let a = ImportanceKernel::new(SampledProfile::Tabulated(&g), 40).unwrap();
        let b = ImportanceKernel::new(SampledProfile::Tabulated(&g), 40).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.sampled_channel, 0, "{:?}", a.mean_radius_mm);
        assert!(a.cutoff_mm > a.samples.last().unwrap().r_mm);
        assert!((a.profile_totals[0] - 1.0).abs() < 2e-3);
    }

    struct Nan;
    impl RadialProfile for Nan {
        fn reflectance_mm2(&self, r: f64) -> [f64; 3] {
            [1.0, if r > 1.0 { f64::NAN } else { 1.0 }, 1.0]
        }
        fn total_reflectance(&self) -> [f64; 3] {
            [1.0; 3]
        }
    }

    #[test]
    fn importance_bad_input_names_the_field() {
        let b = skin_burley();
        for n in [0, 1025] {
            let e = ImportanceKernel::new(SampledProfile::Burley(&b), n).unwrap_err();
            assert_eq!(e.param, "samples");
            assert!(e.message.contains("1..=1024"), "{e}");
        }
        let e = ImportanceKernel::new(SampledProfile::Tabulated(&Nan), 20).unwrap_err();
        assert_eq!(e.param, "profile");
        assert!(e.message.contains("not finite"), "{e}");
        let zero =
            RgbBurley([Burley::new(0.5, 1.0).unwrap(), Burley::new(0.0, 1.0).unwrap(), Burley::new(0.5, 1.0).unwrap()]);
        assert_eq!(ImportanceKernel::new(SampledProfile::Burley(&zero), 20).unwrap_err().param, "albedo[1]");
    }
}
