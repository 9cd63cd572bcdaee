//! Numerical inverse Hankel transform of order zero for radial profiles:
//!
//!   G(r) = (1/2π) ∫₀^∞ F(k) J0(kr) k dk        (Donner & Jensen 2005, §3: a profile and its 2-D Fourier transform)
//!
//! for spectra F that are smooth for k > 0 and decay exponentially, like the layered remainders of
//! [`super::layered`] (DJ05 evaluated this with a zero-padded 2-D FFT; we integrate in k instead).
//!
//! Method: composite 32-point Gauss–Legendre panels in k. Panels are geometrically graded towards k = 0 (down to a
//! quarter of the smallest σtr, where s = sqrt(σtr² + k²) has its branch points ±iσtr) and of equal width w above.
//! The panel width must resolve the oscillation of J0(kr): a 32-point rule integrates cos exactly to ~1e−19 over a
//! phase of 50 rad, so radius r uses the first of the dyadic levels w_ℓ = w₀/2^ℓ with w_ℓ r ≤ 50. Each level's
//! nodes and the samples k·F(k)·weight/(2π) are computed once, on first use, and shared by all radii. The upper
//! limit k_max is where every channel of k·F(k) has fallen below 1e−16 of its peak (sampled at panel ends; capped at
//! [`K_MAX_CAP_PER_MM`]). The result is deterministic and independent of the thread count.
//!
//! Accuracy (tests in `tests/diffusion_layered.rs`): single slabs agree with the analytic real-space multipole to
//! ~1e−12 of R(0); ∫2πr G dr reproduces F(0) to ~1e−9.

use super::bessel::j0;
use super::quadrature::gl32;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Largest k (mm⁻¹) a spectrum is integrated to; reached only by nearly-singular stacks (decay lengths < 4 µm).
pub const K_MAX_CAP_PER_MM: f64 = 1.0e4;
/// Phase k·r (rad) one 32-point panel may span.
const PHASE_PER_PANEL: f64 = 50.0;
const MAX_LEVELS: usize = 40;

type Spectrum<const N: usize> = dyn Fn(f64) -> [f64; N] + Send + Sync;

struct Level<const N: usize> {
    k: Vec<f64>,
    /// weight · k · F(k) / (2π)
    wf: Vec<[f64; N]>,
}

/// A spectrum F(k) (N channels) prepared for inverse transformation at any radius.
pub struct InverseHankel<const N: usize> {
    f: Box<Spectrum<N>>,
    w0: f64,
    k_max: f64,
    k_grade_min: f64,
    levels: Vec<OnceLock<Level<N>>>,
}

impl<const N: usize> InverseHankel<N> {
    /// `decay_length_mm`: an estimate β of F's decay, F ~ e^(−βk) (sets the base panel width 2/β, at most 4 mm⁻¹);
    /// `sigma_min_per_mm`: the smallest positive σtr entering F (grading towards k = 0; 0 if none).
    pub fn new(f: Box<Spectrum<N>>, decay_length_mm: f64, sigma_min_per_mm: f64) -> Self {
        let beta = if decay_length_mm.is_finite() && decay_length_mm > 0.0 { decay_length_mm } else { 1.0 };
        let w0 = (2.0 / beta).clamp(1e-3, 4.0);
        // k_max: scan panel ends until every channel of k·F(k) is below 1e−16 of its peak, twice in a row.
        let mut peak = [0.0f64; N];
        let mut quiet = 0;
        let mut m = 1usize;
        let k_max = loop {
            let k = m as f64 * w0;
            let v = f(k);
            let mut all_small = true;
            for c in 0..N {
                let a = (v[c] * k).abs();
                peak[c] = peak[c].max(a);
                if a > 1e-16 * peak[c] {
                    all_small = false;
                }
            }
            quiet = if all_small { quiet + 1 } else { 0 };
            if quiet >= 2 || k >= K_MAX_CAP_PER_MM {
                break k;
            }
            m += 1;
        };
        let k_grade_min = if sigma_min_per_mm > 0.0 { 0.25 * sigma_min_per_mm } else { f64::INFINITY };
        Self { f, w0, k_max, k_grade_min, levels: (0..MAX_LEVELS).map(|_| OnceLock::new()).collect() }
    }

    /// Upper integration limit, mm⁻¹.
    pub fn k_max(&self) -> f64 {
        self.k_max
    }

    fn level(&self, l: usize) -> &Level<N> {
        self.levels[l].get_or_init(|| {
            let w = self.w0 / (1u64 << l) as f64;
            // Panels [a, b]: graded [w/2^(m+1), w/2^m] down to k_grade_min (at most 40), then [0, smallest], then
            // uniform panels of width w up to k_max.
            let mut panels: Vec<(f64, f64)> = Vec::new();
            let mut hi = w;
            for _ in 0..40 {
                if hi <= self.k_grade_min {
                    break;
                }
                panels.push((0.5 * hi, hi));
                hi *= 0.5;
            }
            panels.push((0.0, hi));
            panels.reverse();
            let n_uniform = ((self.k_max - w) / w).round().max(0.0) as usize;
            panels.extend((1..=n_uniform).map(|i| (i as f64 * w, (i + 1) as f64 * w)));
            let (x, wt) = gl32();
            let per_panel: Vec<(Vec<f64>, Vec<[f64; N]>)> = panels
                .par_iter()
                .map(|&(a, b)| {
                    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
                    let mut ks = Vec::with_capacity(x.len());
                    let mut wf = Vec::with_capacity(x.len());
                    for (xi, wi) in x.iter().zip(wt) {
                        let k = c + h * xi;
                        let v = (self.f)(k);
                        ks.push(k);
                        wf.push(v.map(|fv| h * wi * k * fv / (2.0 * PI)));
                    }
                    (ks, wf)
                })
                .collect();
            let mut level = Level { k: Vec::new(), wf: Vec::new() };
            for (ks, wf) in per_panel {
                level.k.extend(ks);
                level.wf.extend(wf);
            }
            level
        })
    }

    /// G(r) per channel.
    pub fn eval(&self, r_mm: f64) -> [f64; N] {
        let mut l = 0;
        while l + 1 < MAX_LEVELS && self.w0 / (1u64 << l) as f64 * r_mm > PHASE_PER_PANEL {
            l += 1;
        }
        let level = self.level(l);
        let mut out = [0.0; N];
        for (k, wf) in level.k.iter().zip(&level.wf) {
            let j = j0(k * r_mm);
            for c in 0..N {
                out[c] += wf[c] * j;
            }
        }
        out
    }
}
