//! Numerical inverse Hankel transform of order zero for radial profiles:
//!
//!   G(r) = (1/2π) ∫₀^∞ F(k) J0(kr) k dk        (Donner & Jensen 2005, §3: a profile and its 2-D Fourier transform)
//!
//! for spectra F that are smooth for k > 0 and decay exponentially, like the layered remainders of
//! [`super::layered`] (DJ05 evaluated this with a zero-padded 2-D FFT; we integrate in k instead).
//!
//! Method: composite Gauss–Legendre panels in k. Panels are geometrically graded towards k = 0 (halving down to half
//! the smallest σtr, where s = sqrt(σtr² + k²) has its branch points ±iσtr) and of equal width w above, up to k_max.
//! The panel width must resolve the oscillation of J0(kr): a 64-point rule is exact for polynomials of degree 127,
//! which represent cos over a phase of 160 rad to ~2e−15 (the Chebyshev coefficient J_128(80)), and a 32-point rule
//! over 60 rad to ~1e−14; radius r uses the first of the dyadic levels w_ℓ = w₀/2^ℓ with w_ℓ r ≤ 160 (64 points
//! on uniform panels and the widest graded one, 32 on the narrower graded panels). w₀ = 16/β for a spectrum
//! decaying like e^(−βk) (at most 32 mm⁻¹).
//!
//! F itself is sampled only once, on 48 Chebyshev nodes of each level-0 panel (F varies by at most e^(−16) across
//! one, and a degree-47 interpolant of any e^(−αk) on a graded panel [a, 2a] is accurate to 2^(−48) of its panel
//! maximum); every level's quadrature nodes lie inside a single level-0 panel (all boundaries are dyadic) and take
//! F from that interpolant. Each level's nodes and weights × k·F(k)/(2π) are computed once, on first use, and
//! shared by all radii. The upper limit k_max is where every channel of k·F(k) has fallen below 1e−16 of its peak
//! (sampled every w₀/8; capped at [`K_MAX_CAP_PER_MM`]). The result is deterministic and independent of the
//! thread count.
//!
//! Accuracy (tests in `tests/diffusion_layered.rs`): single slabs agree with the analytic real-space multipole to
//! ~3e−15 of T(0); ∫2πr G dr reproduces F(0) to ~1e−12 relative.

use super::bessel::j0;
use super::quadrature::{gl32, gl64};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Largest k (mm⁻¹) a spectrum is integrated to; reached only by nearly-singular stacks (decay lengths < 4 µm).
pub const K_MAX_CAP_PER_MM: f64 = 1.0e4;
/// Phase k·r (rad) one 64-point panel may span (a 32-point panel spans at most half of it).
const PHASE_PER_PANEL: f64 = 160.0;
const MAX_LEVELS: usize = 40;
/// Chebyshev nodes per level-0 panel (interpolant of degree 47).
const CHEB: usize = 48;

type Spectrum<const N: usize> = dyn Fn(f64) -> [f64; N] + Send + Sync;

struct Level<const N: usize> {
    k: Vec<f64>,
    /// weight · k · F(k) / (2π)
    wf: Vec<[f64; N]>,
}

/// Level-0 panels with Chebyshev coefficients of F per channel.
struct Master<const N: usize> {
    /// Ascending panel boundaries (panel i is [bounds[i], bounds[i+1]]).
    bounds: Vec<f64>,
    coef: Vec<[[f64; N]; CHEB]>,
}

impl<const N: usize> Master<N> {
    fn eval(&self, k: f64) -> [f64; N] {
        // Panel containing k (boundaries are exact dyadic values; nodes lie strictly inside a panel).
        let i = self.bounds.partition_point(|&b| b <= k).clamp(1, self.bounds.len() - 1) - 1;
        let (a, b) = (self.bounds[i], self.bounds[i + 1]);
        let u = (2.0 * k - a - b) / (b - a);
        let c = &self.coef[i];
        let mut out = [0.0; N];
        for ch in 0..N {
            let (mut b1, mut b2) = (0.0, 0.0);
            for j in (1..CHEB).rev() {
                let b0 = 2.0 * u * b1 - b2 + c[j][ch];
                b2 = b1;
                b1 = b0;
            }
            out[ch] = u * b1 - b2 + c[0][ch];
        }
        out
    }
}

/// A spectrum F(k) (N channels) prepared for inverse transformation at any radius.
pub struct InverseHankel<const N: usize> {
    master: Master<N>,
    w0: f64,
    k_max: f64,
    k_grade_min: f64,
    levels: Vec<OnceLock<Level<N>>>,
}

/// Panels (a, b, uses the 64-point rule) of one level: graded [w/2^(m+1), w/2^m] down to `k_grade_min` (at most
/// 40), [0, smallest], then uniform panels of width w up to `k_max` rounded up to a multiple of w. The uniform panels
/// and the top graded one use 64 points, the narrower graded ones 32.
fn panels(w: f64, k_grade_min: f64, k_max: f64) -> Vec<(f64, f64, bool)> {
    let mut out: Vec<(f64, f64, bool)> = Vec::new();
    let mut hi = w;
    for m in 0..40 {
        if hi <= k_grade_min {
            break;
        }
        out.push((0.5 * hi, hi, m == 0));
        hi *= 0.5;
    }
    out.push((0.0, hi, out.is_empty()));
    out.reverse();
    let n_uniform = (k_max / w).ceil().max(1.0) as usize - 1;
    out.extend((1..=n_uniform).map(|i| (i as f64 * w, (i + 1) as f64 * w, true)));
    out
}

impl<const N: usize> InverseHankel<N> {
    /// `decay_length_mm`: an estimate β of F's decay, F ~ e^(−βk) (sets the base panel width 8/β, at most
    /// 16 mm⁻¹); `sigma_min_per_mm`: the smallest positive σtr entering F (grading towards k = 0; 0 if none).
    pub fn new(f: Box<Spectrum<N>>, decay_length_mm: f64, sigma_min_per_mm: f64) -> Self {
        let beta = if decay_length_mm.is_finite() && decay_length_mm > 0.0 { decay_length_mm } else { 1.0 };
        let w0 = (16.0 / beta).clamp(1e-3, 32.0);
        // k_max: scan in steps of w0/8 until every channel of k·F(k) is below 1e−16 of its peak, twice in a row.
        let mut peak = [0.0f64; N];
        let mut quiet = 0;
        let mut m = 1usize;
        let k_max = loop {
            let k = m as f64 * w0 / 8.0;
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
        let k_grade_min = if sigma_min_per_mm > 0.0 { 0.5 * sigma_min_per_mm } else { f64::INFINITY };
        let master_panels = panels(w0, k_grade_min, k_max);
        let coef: Vec<[[f64; N]; CHEB]> = master_panels
            .par_iter()
            .map(|&(a, b, _)| {
                let samples: Vec<[f64; N]> = (0..CHEB)
                    .map(|i| {
                        let t = (PI * (i as f64 + 0.5) / CHEB as f64).cos();
                        f(0.5 * (a + b) + 0.5 * (b - a) * t)
                    })
                    .collect();
                let mut c = [[0.0; N]; CHEB];
                for (j, cj) in c.iter_mut().enumerate() {
                    for (i, fi) in samples.iter().enumerate() {
                        // cos(π j (i + ½)/n), angle reduced exactly in integers.
                        let m = (j * (2 * i + 1)) % (4 * CHEB);
                        let w = (PI * m as f64 / (2 * CHEB) as f64).cos();
                        for ch in 0..N {
                            cj[ch] += fi[ch] * w;
                        }
                    }
                    for v in cj.iter_mut() {
                        *v *= 2.0 / CHEB as f64;
                    }
                }
                for v in c[0].iter_mut() {
                    *v *= 0.5;
                }
                c
            })
            .collect();
        let mut bounds: Vec<f64> = master_panels.iter().map(|p| p.0).collect();
        bounds.push(master_panels.last().map_or(w0, |p| p.1));
        Self {
            master: Master { bounds, coef },
            w0,
            k_max,
            k_grade_min,
            levels: (0..MAX_LEVELS).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Upper integration limit, mm⁻¹.
    pub fn k_max(&self) -> f64 {
        self.k_max
    }

    /// The interpolated spectrum F(k) (k ≤ k_max).
    pub fn spectrum(&self, k_per_mm: f64) -> [f64; N] {
        self.master.eval(k_per_mm)
    }

    fn level(&self, l: usize) -> &Level<N> {
        self.levels[l].get_or_init(|| {
            let w = self.w0 / (1u64 << l) as f64;
            let mut level = Level { k: Vec::new(), wf: Vec::new() };
            for (a, b, wide) in panels(w, self.k_grade_min, self.k_max) {
                let (x, wt) = if wide { gl64() } else { gl32() };
                let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
                for (xi, wi) in x.iter().zip(wt) {
                    let k = c + h * xi;
                    let v = self.master.eval(k);
                    level.k.push(k);
                    level.wf.push(v.map(|fv| h * wi * k * fv / (2.0 * PI)));
                }
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
