//! Exact non-negative least squares in normal-equation (Gram) form:
//!
//! ```text
//! minimise ½ wᵀ G w − bᵀ w   subject to w ≥ 0        (G = AᵀA symmetric positive (semi)definite, b = Aᵀy)
//! ```
//!
//! which is min ‖A w − y‖² up to a constant. [`nnls`] is the active-set algorithm of C. L. Lawson and R. J. Hanson,
//! *Solving Least Squares Problems* (Prentice-Hall, 1974), ch. 23, written against G and b so the fitter never forms
//! A's QR; it terminates at a point satisfying the KKT conditions (w ≥ 0, gradient ≤ tol on the active set, = 0 on the
//! passive set), which for a convex quadratic is the exact optimum. [`nnls_enumerate`] is an independent exact
//! solver for small k (every support set, 2ᵏ − 1 unconstrained solves) used as a test oracle.

// Index loops over the k×k system mirror the algorithm's statement.
#![allow(clippy::needless_range_loop)]

use nalgebra::{DMatrix, DVector};

/// Largest k [`nnls`] accepts (stack buffers).
pub const MAX_K: usize = 16;

/// Cholesky solve of G_PP z = b_P for the index set `p` (row-major k×k `g`); `None` if a pivot is not clearly
/// positive (the new column is numerically dependent on the others).
fn solve_subset(g: &[f64], k: usize, b: &[f64], p: &[usize], z: &mut [f64]) -> Option<()> {
    let n = p.len();
    let mut l = [0.0f64; MAX_K * MAX_K];
    for i in 0..n {
        for j in 0..=i {
            let mut s = g[p[i] * k + p[j]];
            for m in 0..j {
                s -= l[i * MAX_K + m] * l[j * MAX_K + m];
            }
            if i == j {
                let d = g[p[i] * k + p[i]];
                if s.partial_cmp(&(1e-13 * d)) != Some(std::cmp::Ordering::Greater) {
                    return None;
                }
                l[i * MAX_K + i] = s.sqrt();
            } else {
                l[i * MAX_K + j] = s / l[j * MAX_K + j];
            }
        }
    }
    let mut y = [0.0f64; MAX_K];
    for i in 0..n {
        let mut s = b[p[i]];
        for m in 0..i {
            s -= l[i * MAX_K + m] * y[m];
        }
        y[i] = s / l[i * MAX_K + i];
    }
    for i in (0..n).rev() {
        let mut s = y[i];
        for m in i + 1..n {
            s -= l[m * MAX_K + i] * z[m];
        }
        z[i] = s / l[i * MAX_K + i];
    }
    z[..n].iter().all(|v| v.is_finite()).then_some(())
}

/// Value of ½ wᵀ G w − bᵀ w (row-major k×k `g`).
pub fn objective(g: &[f64], b: &[f64], w: &[f64]) -> f64 {
    let k = b.len();
    let mut q = 0.0;
    for i in 0..k {
        let gw: f64 = (0..k).map(|j| g[i * k + j] * w[j]).sum();
        q += w[i] * (0.5 * gw - b[i]);
    }
    q
}

/// Lawson–Hanson active-set NNLS on (G, b), G row-major k×k, k ≤ [`MAX_K`]. Writes w ≥ 0 (exact zeros on the
/// active set). A column numerically dependent on the passive set is never made passive.
pub fn nnls_into(g: &[f64], b: &[f64], w: &mut [f64]) {
    let k = b.len();
    assert!(k <= MAX_K && g.len() == k * k && w.len() == k);
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
    let tol = 1e-14 * scale;
    w.iter_mut().for_each(|x| *x = 0.0);
    let mut passive = [false; MAX_K];
    let mut excluded = [false; MAX_K];
    let mut p = [0usize; MAX_K];
    let mut z = [0.0f64; MAX_K];
    for _ in 0..3 * k + 10 {
        // Most violated KKT condition: largest component of the negative gradient b − G w off the passive set.
        let mut t = usize::MAX;
        let mut best = tol;
        for i in 0..k {
            if passive[i] || excluded[i] {
                continue;
            }
            let gi = b[i] - (0..k).map(|j| g[i * k + j] * w[j]).sum::<f64>();
            if gi > best {
                best = gi;
                t = i;
            }
        }
        if t == usize::MAX {
            break;
        }
        passive[t] = true;
        for _ in 0..3 * k + 10 {
            let mut n = 0;
            for i in 0..k {
                if passive[i] {
                    p[n] = i;
                    n += 1;
                }
            }
            if solve_subset(g, k, b, &p[..n], &mut z).is_none() {
                passive[t] = false;
                excluded[t] = true;
                break;
            }
            if z[..n].iter().all(|&v| v > 0.0) {
                w.iter_mut().for_each(|x| *x = 0.0);
                for m in 0..n {
                    w[p[m]] = z[m];
                }
                excluded = [false; MAX_K];
                break;
            }
            // Step from w towards z until the first passive coordinate reaches zero; drop it.
            let mut alpha = 1.0f64;
            let mut limiting = p[0];
            for m in 0..n {
                if z[m] <= 0.0 {
                    let a = w[p[m]] / (w[p[m]] - z[m]);
                    if a < alpha {
                        alpha = a;
                        limiting = p[m];
                    }
                }
            }
            for m in 0..n {
                w[p[m]] += alpha * (z[m] - w[p[m]]);
                if w[p[m]] <= 0.0 {
                    w[p[m]] = 0.0;
                    passive[p[m]] = false;
                }
            }
            w[limiting] = 0.0;
            passive[limiting] = false;
        }
    }
}

/// [`nnls_into`] returning a new vector.
pub fn nnls(g: &[f64], b: &[f64]) -> Vec<f64> {
    let mut w = vec![0.0; b.len()];
    nnls_into(g, b, &mut w);
    w
}

/// Exact NNLS by enumerating every support set (k ≤ 16): the optimum is the feasible unconstrained sub-solution
/// of least objective. Exponential in k; for tests and small problems only.
pub fn nnls_enumerate(g: &[f64], b: &[f64]) -> Vec<f64> {
    let k = b.len();
    assert!(k <= 16, "nnls_enumerate is for small k");
    let gm = DMatrix::from_row_slice(k, k, g);
    let mut best = vec![0.0; k];
    let mut best_f = 0.0;
    for mask in 1u32..(1u32 << k) {
        let p: Vec<usize> = (0..k).filter(|i| mask & (1 << i) != 0).collect();
        let gs = DMatrix::from_fn(p.len(), p.len(), |i, j| gm[(p[i], p[j])]);
        let bs = DVector::from_fn(p.len(), |i, _| b[p[i]]);
        let Some(zp) = gs.lu().solve(&bs) else { continue };
        if zp.iter().any(|&z| z < 0.0) {
            continue;
        }
        let mut w = vec![0.0; k];
        for (idx, &i) in p.iter().enumerate() {
            w[i] = zp[idx];
        }
        let f = objective(g, b, &w);
        if f < best_f {
            best_f = f;
            best = w;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(state: &mut u64) -> f64 {
        *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn matches_enumeration_on_random_problems() {
        let mut s = 12345u64;
        for trial in 0..300 {
            let k = 2 + trial % 7;
            let m = k + 3;
            let a = DMatrix::from_fn(m, k, |_, _| lcg(&mut s) - 0.3);
            let y = DVector::from_fn(m, |_, _| lcg(&mut s) * 2.0 - 0.7);
            let g: Vec<f64> = (a.transpose() * &a).transpose().iter().copied().collect();
            let b: Vec<f64> = (a.transpose() * &y).iter().copied().collect();
            let w1 = nnls(&g, &b);
            let w2 = nnls_enumerate(&g, &b);
            assert!(w1.iter().all(|&v| v >= 0.0));
            let (f1, f2) = (objective(&g, &b, &w1), objective(&g, &b, &w2));
            assert!((f1 - f2).abs() <= 1e-12 * (1.0 + f2.abs()), "trial {trial}: {f1} vs {f2}");
            for (x, y) in w1.iter().zip(&w2) {
                assert!((x - y).abs() < 1e-9, "trial {trial}: {w1:?} vs {w2:?}");
            }
        }
    }

    #[test]
    fn recovers_exact_nonnegative_solution_with_zeros() {
        // y = A w_true with some zero weights: NNLS must return w_true exactly (to rounding).
        let mut s = 7u64;
        let a = DMatrix::from_fn(12, 5, |_, _| lcg(&mut s));
        let w_true = DVector::from_vec(vec![0.5, 0.0, 1.25, 0.0, 0.1]);
        let y = &a * &w_true;
        let g: Vec<f64> = (a.transpose() * &a).transpose().iter().copied().collect();
        let b: Vec<f64> = (a.transpose() * &y).iter().copied().collect();
        let w = nnls(&g, &b);
        for (x, t) in w.iter().zip(w_true.iter()) {
            assert!((x - t).abs() < 1e-10, "{w:?}");
        }
    }
}
