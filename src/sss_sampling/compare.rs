//! Importance-sampled disk vs separable vs sum-of-Gaussians kernels at equal fetch budgets, against the exact
//! convolution of a profile.
//!
//! # The test
//!
//! **Irradiance:** a lit half-plane on a pixel grid of `pixel_mm` mm per pixel (default 125/720 mm: a 125 mm head
//! filling 720 pixels, the separable fit's default): pixel centres xₖ = (k + ½)h, Iₖ = 1 for xₖ > 0, else 0. Every
//! kernel fetches it bilinearly, i.e. sees the continuous ramp I(x) = clamp(x/h + ½, 0, 1) (the GPU's linear
//! filter), and so does the reference.
//!
//! **Reference:** the exact convolution of I with the normalised profile R̂_c = R_c / ∫2πrR_c dr:
//! E_c(x) = ∫₀^∞ 2πr R̂_c(r)·G(x, r) dr with G(x, r) = (1/π)∫₀^π I(x + r cos θ) dθ in closed form:
//! G = r/(πh)·(Φ(u₁) − Φ(u₂)), u₁,₂ = −(x ∓ h/2)/r, Φ(u) = πu (u < −1), u·acos u − √(1 − u²) (|u| ≤ 1), 0 (u > 1).
//! The radial integral is dense Gauss–Legendre: 8 points on [0, 1e−5 mm], then 8 points on each of 128 panels per
//! decade of r over [1e−5, 1e3] mm (tested: doubling the panels changes E by < 1e−7; the kinks of G at r = |x ± h/2| limit the order), normalised by the same
//! quadrature's total.
//!
//! **Equal cost** = the same number of texture fetches per pixel, N:
//! - (a) importance: the N-sample disk kernel of [`super::disk`] (N fetches);
//! - (b) separable: strength/falloff fitted with [`crate::separable::fit`] (default objective, width 0.012,
//!   125 mm per world unit), the runtime's kernel of T taps per pass, T the largest odd number ≤ N/2 (at least 3):
//!   2T ≤ N fetches (18, 38, 78 for N = 20, 40, 80); on the half-plane the vertical pass is the identity;
//! - (c) sum of Gaussians: K = 4 Gaussians with shared variances fitted to the normalised profile
//!   ([`crate::fitting::sum_of_gaussians_fit`]), applied like the screen-space runtime (thesis ch. 4): each
//!   Gaussian blurs the previous result by its incremental standard deviation √(vₖ − vₖ₋₁) as a horizontal and a
//!   vertical pass of T = max(1, ⌊N/(2K)⌋) taps at the Gauss–Hermite nodes (exact for polynomials of degree
//!   2T − 1 in the offset), each pass's result stored per pixel and fetched bilinearly by the next; the output is
//!   Σₖ ŵ_c,k·Bₖ with the weights normalised per channel: 2TK ≤ N fetches (16, 40, 80).
//!
//! **Metric** per channel over the pixels with |xₖ| ≤ the sampled channel's F⁻¹(0.999) + 2 pixels: relative L2
//! ‖a − E‖₂ / ‖E − I‖₂ (the error relative to the blur's own effect on the edge) and the max absolute error
//! max |a − E| (irradiance 1 on the lit side).

// Index loops over channels mirror the equations.
#![allow(clippy::needless_range_loop)]

use super::cdf::RadialCdf;
use super::disk::{ImportanceKernel, SampledProfile};
use crate::diffusion::quadrature::gauss_legendre;
use crate::diffusion::RadialProfile;
use crate::error::InvalidInput;
use crate::fitting::sum_of_gaussians_fit::{fit_sum_of_gaussians, FitSettings, GaussianFitError};
use crate::separable::fit::{self as sep_fit, ObjectiveSpec, SeparableFitError, TargetKernel};
use crate::separable::kernel::{self as sep_kernel, KernelSpec};
use std::f64::consts::PI;

/// Errors of the comparison.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    #[error("{0}")]
    Invalid(#[from] InvalidInput),
    #[error("separable fit: {0}")]
    Separable(#[from] SeparableFitError),
    #[error("sum-of-Gaussians fit: {0}")]
    Gaussians(#[from] GaussianFitError),
}

/// Number of Gaussians of competitor (c).
pub const GAUSSIANS: usize = 4;

/// Dense-quadrature panels per decade of the reference.
const REFERENCE_PANELS_PER_DECADE: usize = 128;

/// One method's errors at one budget.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodErrors {
    /// `importance`, `separable` or `gaussians`.
    pub method: &'static str,
    /// Texture fetches per pixel.
    pub fetches: usize,
    /// ‖a − E‖₂ / ‖E − I‖₂ per channel.
    pub rel_l2: [f64; 3],
    /// max |a − E| per channel.
    pub max_abs: [f64; 3],
}

/// The edge test of one profile: reference and fitted competitors (independent of N).
pub struct EdgeTest {
    pub pixel_mm: f64,
    /// Pixel centres of the evaluated row, mm.
    x_mm: Vec<f64>,
    /// Index range of the pixels the metric uses.
    eval: std::ops::Range<usize>,
    /// E_c at the pixel centres.
    exact: [Vec<f64>; 3],
    /// Separable fit (strength, falloff) and its mm per kernel unit.
    separable: (crate::separable::SeparableParams, f64),
    /// Shared variances (mm², ascending) and normalised weights of the Gaussian fit.
    gaussians: (Vec<f64>, Vec<[f64; 3]>),
}

fn ramp(x: f64, h: f64) -> f64 {
    (x / h + 0.5).clamp(0.0, 1.0)
}

fn phi(u: f64) -> f64 {
    if u < -1.0 {
        PI * u
    } else if u > 1.0 {
        0.0
    } else {
        u * u.acos() - (1.0 - u * u).sqrt()
    }
}

/// (1/π)∫₀^π ramp(x + r cos θ) dθ.
fn ring_average(x: f64, r: f64, h: f64) -> f64 {
    if r == 0.0 {
        return ramp(x, h);
    }
    let u1 = -(x - 0.5 * h) / r;
    let u2 = -(x + 0.5 * h) / r;
    (r / (PI * h) * (phi(u1) - phi(u2))).clamp(0.0, 1.0)
}

/// Nodes and weights (summing to 1) of the T-point Gauss–Hermite rule for the standard normal density
/// (Golub–Welsch: eigen-decomposition of the Jacobi matrix of the probabilists' Hermite polynomials).
pub fn gauss_hermite_normal(t: usize) -> (Vec<f64>, Vec<f64>) {
    let mut j = nalgebra::DMatrix::<f64>::zeros(t, t);
    for k in 1..t {
        let b = (k as f64).sqrt();
        j[(k, k - 1)] = b;
        j[(k - 1, k)] = b;
    }
    let eig = nalgebra::SymmetricEigen::new(j);
    let mut pairs: Vec<(f64, f64)> =
        (0..t).map(|k| (eig.eigenvalues[k], eig.eigenvectors[(0, k)] * eig.eigenvectors[(0, k)])).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let s: f64 = pairs.iter().map(|p| p.1).sum();
    (pairs.iter().map(|p| p.0).collect(), pairs.iter().map(|p| p.1 / s).collect())
}

/// Linear interpolation of per-pixel values at x (mm), clamp to edge (the GPU's bilinear fetch along a row).
fn fetch(values: &[f64], x0_mm: f64, h: f64, x: f64) -> f64 {
    let t = (x - x0_mm) / h;
    let n = values.len();
    if t <= 0.0 {
        return values[0];
    }
    if t >= (n - 1) as f64 {
        return values[n - 1];
    }
    let i = t.floor() as usize;
    let f = t - i as f64;
    values[i] + (values[i + 1] - values[i]) * f
}

/// The separable runtime's taps per pass for a budget of N fetches.
pub fn separable_taps(n: usize) -> usize {
    let t = (n / 2).max(3);
    if t.is_multiple_of(2) {
        t - 1
    } else {
        t
    }
}

/// Gauss–Hermite taps per pass of each Gaussian for a budget of N fetches.
pub fn gaussian_taps(n: usize) -> usize {
    (n / (2 * GAUSSIANS)).max(1)
}

impl EdgeTest {
    /// Builds the reference and fits both competitors to `profile` (seconds: two fits).
    pub fn new(profile: &dyn RadialProfile, pixel_mm: f64) -> Result<Self, CompareError> {
        crate::error::check_positive("pixel_mm", pixel_mm, "mm")?;
        let cdf = RadialCdf::tabulate(profile)?;
        let mean = [0, 1, 2].map(|c| cdf.channels[c].mean_radius_mm);
        let s = (0..3).fold(0, |s, c| if mean[c] > mean[s] { c } else { s });
        let extent = cdf.inverse(s, 0.999) + 2.0 * pixel_mm;
        let h = pixel_mm;
        // Stored row: twice the extent plus a margin for the intermediate blurs' fetches.
        let k = (2.0 * extent / h).ceil() as i64 + 4;
        let x_mm: Vec<f64> = (-k..k).map(|i| (i as f64 + 0.5) * h).collect();
        let first = x_mm.partition_point(|x| *x < -extent);
        let last = x_mm.partition_point(|x| *x <= extent);
        let exact = reference(profile, &x_mm, h, REFERENCE_PANELS_PER_DECADE)?;

        let spec = ObjectiveSpec { pixel_mm, ..ObjectiveSpec::default() };
        let target = TargetKernel::from_profile(profile, &spec, "importance comparison")?;
        let fit = sep_fit::fit(&target)?;
        let settings = FitSettings { count: GAUSSIANS, shared_variances: true, normalize: true, starts: 8 };
        let g = fit_sum_of_gaussians(profile, &settings)?;
        let vars = g.sum.variances_mm2[0].clone();
        let mut weights: Vec<[f64; 3]> = (0..vars.len()).map(|i| [0, 1, 2].map(|c| g.sum.weights[c][i])).collect();
        for c in 0..3 {
            let t: f64 = weights.iter().map(|w| w[c]).sum();
            weights.iter_mut().for_each(|w| w[c] /= t);
        }
        Ok(Self {
            pixel_mm,
            x_mm,
            eval: first..last,
            exact,
            separable: (fit.params, spec.mm_per_kernel_unit()),
            gaussians: (vars, weights),
        })
    }

    fn errors(&self, method: &'static str, fetches: usize, a: &[Vec<f64>; 3]) -> MethodErrors {
        let mut rel_l2 = [0.0; 3];
        let mut max_abs = [0.0f64; 3];
        for c in 0..3 {
            let (mut num, mut den) = (0.0, 0.0);
            for k in self.eval.clone() {
                let e = self.exact[c][k];
                let d = a[c][k] - e;
                num += d * d;
                let i = if self.x_mm[k] > 0.0 { 1.0 } else { 0.0 };
                den += (e - i) * (e - i);
                max_abs[c] = max_abs[c].max(d.abs());
            }
            rel_l2[c] = (num / den).sqrt();
        }
        MethodErrors { method, fetches, rel_l2, max_abs }
    }

    /// The importance kernel's errors.
    pub fn importance(&self, kernel: &ImportanceKernel) -> MethodErrors {
        let h = self.pixel_mm;
        let a = [0, 1, 2].map(|c| {
            self.x_mm
                .iter()
                .map(|x| kernel.samples.iter().map(|s| s.weight[c] * ramp(x + s.offset_mm()[0], h)).sum())
                .collect()
        });
        self.errors("importance", kernel.len(), &a)
    }

    /// The fitted separable kernel's errors with the taps of budget `n`.
    pub fn separable(&self, n: usize) -> Result<MethodErrors, CompareError> {
        let taps = separable_taps(n);
        let k = sep_kernel::generate(&KernelSpec::new(taps, self.separable.0))?;
        let (h, mm) = (self.pixel_mm, self.separable.1);
        let a = [0, 1, 2]
            .map(|c| self.x_mm.iter().map(|x| k.taps.iter().map(|t| t[c] * ramp(x + t[3] * mm, h)).sum()).collect());
        Ok(self.errors("separable", 2 * taps, &a))
    }

    /// The fitted sum of Gaussians' errors with the taps of budget `n`.
    pub fn gaussians(&self, n: usize) -> MethodErrors {
        let t = gaussian_taps(n);
        let (z, w) = gauss_hermite_normal(t);
        let h = self.pixel_mm;
        let x0 = self.x_mm[0];
        let (vars, weights) = &self.gaussians;
        let mut prev: Vec<f64> = self.x_mm.iter().map(|x| ramp(*x, h)).collect();
        let mut out = [0, 1, 2].map(|_| vec![0.0; self.x_mm.len()]);
        let mut v_prev = 0.0;
        for (v, wk) in vars.iter().zip(weights) {
            let sigma = (v - v_prev).max(0.0).sqrt();
            v_prev = *v;
            let next: Vec<f64> = if sigma == 0.0 {
                prev.clone()
            } else {
                self.x_mm
                    .iter()
                    .map(|x| z.iter().zip(&w).map(|(zi, wi)| wi * fetch(&prev, x0, h, x + sigma * zi)).sum())
                    .collect()
            };
            for c in 0..3 {
                for (o, b) in out[c].iter_mut().zip(&next) {
                    *o += wk[c] * b;
                }
            }
            prev = next;
        }
        self.errors("gaussians", 2 * t * vars.len(), &out)
    }

    /// All three methods at budget `n` for `profile` (the profile the test was built from).
    pub fn compare(&self, profile: SampledProfile<'_>, n: usize) -> Result<[MethodErrors; 3], CompareError> {
        let k = ImportanceKernel::new(profile, n)?;
        Ok([self.importance(&k), self.separable(n)?, self.gaussians(n)])
    }
}

/// E_c(x) at the pixel centres (module docs), with `panels` Gauss–Legendre panels per decade.
fn reference(profile: &dyn RadialProfile, x_mm: &[f64], h: f64, panels: usize) -> Result<[Vec<f64>; 3], InvalidInput> {
    let (gx, gw) = gauss_legendre(8);
    let (r0, r1) = (super::cdf::R_MIN_MM, super::cdf::R_MAX_MM);
    let mut nodes = Vec::new();
    let mut dr = Vec::new();
    for (x, w) in gx.iter().zip(&gw) {
        nodes.push(0.5 * r0 * (1.0 + x));
        dr.push(0.5 * r0 * w);
    }
    let m = (r1 / r0).log10().round() as usize * panels;
    let du = (r1 / r0).ln() / m as f64;
    for j in 0..m {
        for (x, w) in gx.iter().zip(&gw) {
            let r = (r0.ln() + du * (j as f64 + 0.5 * (1.0 + x))).exp();
            nodes.push(r);
            dr.push(0.5 * du * w * r);
        }
    }
    let values = profile.reflectance_many(&nodes);
    let mut out = [Vec::new(), Vec::new(), Vec::new()];
    for c in 0..3 {
        let p: Vec<f64> =
            nodes.iter().zip(&values).zip(&dr).map(|((r, v), d)| 2.0 * PI * r * v[c].max(0.0) * d).collect();
        if p.iter().any(|x| !x.is_finite()) {
            return Err(InvalidInput::new("profile", "R(r) is not finite"));
        }
        let total: f64 = p.iter().sum();
        // Skip nodes that carry no mass (far tails) for speed.
        let live: Vec<(f64, f64)> =
            nodes.iter().zip(&p).filter(|(_, w)| **w > 1e-18 * total).map(|(r, w)| (*r, *w / total)).collect();
        out[c] = x_mm.iter().map(|x| live.iter().map(|(r, w)| w * ring_average(*x, *r, h)).sum()).collect();
    }
    Ok(out)
}

/// A markdown table of comparison rows: (profile label, N, the three methods' errors).
pub fn markdown_table(rows: &[(String, usize, [MethodErrors; 3])]) -> String {
    let mut s = String::from(
        "| profile | N | method | fetches | rel. L2 R | rel. L2 G | rel. L2 B | max abs R | max abs G | max abs B |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for (label, n, methods) in rows {
        for m in methods {
            s.push_str(&format!(
                "| {label} | {n} | {} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} |\n",
                m.method, m.fetches, m.rel_l2[0], m.rel_l2[1], m.rel_l2[2], m.max_abs[0], m.max_abs[1], m.max_abs[2]
            ));
        }
    }
    s
}

/// The comparison of three profiles (skin1 dipole, d'Eon 6-Gaussian skin, a Burley skin) at
/// N = 20, 40, 80 with the default pixel (125/720 mm): the rows of [`markdown_table`].
pub fn default_comparison() -> Result<Vec<(String, usize, [MethodErrors; 3])>, CompareError> {
    use crate::diffusion::burley::{RgbBurley, ShapeFit};
    let skin1 = crate::diffusion::materials::find("skin1").expect("built-in").dipole(crate::diffusion::FdrForm::Dj05);
    let deon6 = crate::diffusion::sum_of_gaussians::deon6();
    let burley = RgbBurley::from_mean_free_path(BURLEY_SKIN_ALBEDO, BURLEY_SKIN_MFP_MM, ShapeFit::DiffuseTransmission)?;
    let pixel_mm = ObjectiveSpec::default().pixel_mm;
    let profiles: [(&str, SampledProfile<'_>, &dyn RadialProfile); 3] = [
        ("skin1 (Jensen dipole)", SampledProfile::Tabulated(&skin1), &skin1),
        ("deon6 (d'Eon 6 Gaussians)", SampledProfile::Tabulated(&deon6), &deon6),
        ("Burley skin", SampledProfile::Burley(&burley), &burley),
    ];
    let mut rows = Vec::new();
    for (label, sampled, dynp) in profiles {
        let test = EdgeTest::new(dynp, pixel_mm)?;
        for n in super::disk::UNITY_SAMPLE_PRESETS {
            rows.push((label.to_string(), n, test.compare(sampled, n)?));
        }
    }
    Ok(rows)
}

/// The Burley skin of the comparison and the default bake: surface albedo per channel.
pub const BURLEY_SKIN_ALBEDO: [f64; 3] = [0.8, 0.5, 0.3];
/// The Burley skin's diffuse mean free path per channel, mm (diffuse-transmission fit).
pub const BURLEY_SKIN_MFP_MM: [f64; 3] = [1.0, 0.5, 0.25];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::burley::{Burley, RgbBurley};

    #[test]
    fn importance_gauss_hermite_integrates_polynomials() {
        for t in 1..=10 {
            let (z, w) = gauss_hermite_normal(t);
            // E[z^2k] of the standard normal = (2k − 1)!!
            for k in 0..t {
                let m: f64 = z.iter().zip(&w).map(|(z, w)| w * z.powi(2 * k as i32)).sum();
                let want: f64 = (1..=k).map(|j| (2 * j - 1) as f64).product();
                assert!((m - want).abs() < 1e-9 * want, "t = {t}, k = {k}: {m} vs {want}");
            }
        }
    }

    #[test]
    fn importance_reference_quadrature_is_converged() {
        let b = RgbBurley([
            Burley::new(0.8, 0.3).unwrap(),
            Burley::new(0.5, 0.1).unwrap(),
            Burley::new(0.3, 0.05).unwrap(),
        ]);
        let h = 0.1;
        let x: Vec<f64> = (-30..30).map(|i| (i as f64 + 0.5) * h).collect();
        let a = reference(&b, &x, h, 128).unwrap();
        let b2 = reference(&b, &x, h, 256).unwrap();
        for c in 0..3 {
            for k in 0..x.len() {
                assert!((a[c][k] - b2[c][k]).abs() < 1e-7, "{c} {k}: {} vs {}", a[c][k], b2[c][k]);
                // Symmetry of the edge response: E(x) + E(−x) = 1.
                assert!((a[c][k] + a[c][x.len() - 1 - k] - 1.0).abs() < 1e-9);
            }
        }
    }
    #[test]
    fn importance_comparison_table() {
        // The ordering measured (table in the module's report): for every profile the importance kernel's error
        // (worst channel) falls with N, and at N = 80 it beats the separable kernel and the sum of Gaussians at
        // their equal fetch budgets; at N = 20 it already beats the separable kernel.
        let rows = default_comparison().unwrap();
        eprintln!("{}", markdown_table(&rows));
        let worst = |m: &MethodErrors| m.rel_l2.iter().fold(0.0f64, |a, b| a.max(*b));
        for chunk in rows.chunks(3) {
            let label = &chunk[0].0;
            let imp: Vec<f64> = chunk.iter().map(|r| worst(&r.2[0])).collect();
            assert!(imp[0] > imp[1] && imp[1] > imp[2], "{label}: importance error must fall with N: {imp:?}");
            let (n20, n80) = (&chunk[0].2, &chunk[2].2);
            assert!(worst(&n20[0]) < worst(&n20[1]), "{label}: N = 20 importance vs separable");
            assert!(worst(&n80[0]) < worst(&n80[1]), "{label}: N = 80 importance vs separable");
            assert!(worst(&n80[0]) < worst(&n80[2]), "{label}: N = 80 importance vs gaussians");
            for m in n80 {
                assert!(m.fetches <= 80, "{label}: {} uses {} fetches", m.method, m.fetches);
            }
        }
    }
}
