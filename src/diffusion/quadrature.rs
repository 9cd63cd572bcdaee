//! Gauss–Legendre quadrature (nodes and weights computed here by Newton iteration on the Legendre recurrence;
//! Golub & Welsch-free textbook construction, e.g. Press et al., *Numerical Recipes*, 3rd ed., §4.6).
//!
//! Used by the inverse Hankel transform of layered profiles and by the tests that integrate ∫2πr R(r) dr.

use std::f64::consts::PI;
use std::sync::OnceLock;

/// Nodes and weights of the n-point Gauss–Legendre rule on [−1, 1] (nodes ascending).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1, "Gauss-Legendre rule needs at least one node");
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        // Initial guess (Tricomi), then Newton on P_n.
        let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (p, d) = legendre_and_derivative(n, z);
            dp = d;
            let dz = p / d;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre_and_derivative(n, z);
        if d != 0.0 {
            dp = d;
        }
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        x[i] = -z;
        x[n - 1 - i] = z;
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    (x, w)
}

/// (P_n(z), P_n′(z)) by the three-term recurrence.
fn legendre_and_derivative(n: usize, z: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, z);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (z * p1 - p0) / (z * z - 1.0);
    (p1, d)
}

/// The 32-point rule, computed once.
pub fn gl32() -> &'static (Vec<f64>, Vec<f64>) {
    static R: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    R.get_or_init(|| gauss_legendre(32))
}

/// The 64-point rule, computed once.
pub fn gl64() -> &'static (Vec<f64>, Vec<f64>) {
    static R: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    R.get_or_init(|| gauss_legendre(64))
}

/// ∫_a^b f with composite `rule` on `panels` equal panels.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize, rule: &(Vec<f64>, Vec<f64>)) -> f64 {
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let c = a + (p as f64 + 0.5) * h;
        let mut s = 0.0;
        for (x, w) in rule.0.iter().zip(&rule.1) {
            s += w * f(c + 0.5 * h * x);
        }
        sum += 0.5 * h * s;
    }
    sum
}

/// ∫₀^∞ 2πr R(r) dr of a radial profile with the substitution r = e^u on [r_min, r_max] (plus the disc
/// [0, r_min] by a small panel rule); `R` may return several channels.
pub fn radial_total<const N: usize>(f: impl Fn(f64) -> [f64; N], r_min: f64, r_max: f64, panels: usize) -> [f64; N] {
    let rule = gl32();
    let mut out = [0.0; N];
    let (ua, ub) = (r_min.ln(), r_max.ln());
    let h = (ub - ua) / panels as f64;
    for p in 0..panels {
        let c = ua + (p as f64 + 0.5) * h;
        for (x, w) in rule.0.iter().zip(&rule.1) {
            let r = (c + 0.5 * h * x).exp();
            let v = f(r);
            for ch in 0..N {
                out[ch] += 0.5 * h * w * 2.0 * PI * r * r * v[ch];
            }
        }
    }
    for (x, w) in rule.0.iter().zip(&rule.1) {
        let r = 0.5 * r_min * (1.0 + x);
        let v = f(r);
        for ch in 0..N {
            out[ch] += 0.5 * r_min * w * 2.0 * PI * r * v[ch];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_integrate_polynomials_exactly() {
        for n in [1, 2, 5, 16, 32, 64] {
            let (x, w) = gauss_legendre(n);
            assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-14, "n={n}");
            // ∫_{-1}^{1} x^(2n-2) = 2/(2n-1)
            let deg = 2 * n - 2;
            let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
            assert!((s - 2.0 / (deg as f64 + 1.0)).abs() < 1e-14, "n={n} s={s}");
        }
    }
}
