//! Bessel function of the first kind J0(x) to ~1e−15 absolute accuracy, for the inverse Hankel transform
//! R(r) = (1/2π) ∫₀^∞ R̂(k) J0(kr) k dk (Donner & Jensen 2005, eq. 9).
//!
//! * |x| < 25: piecewise Chebyshev interpolants (degree 15 on unit panels), whose samples are computed once, at
//!   first use, from Bessel's integral J0(x) = (1/π) ∫₀^π cos(x sin θ) dθ (DLMF 10.9.1) by the trapezoid rule; the
//!   integrand is periodic and entire, so with 96 nodes the rule is exact to rounding for x < 25 (its error is
//!   2·J_192(x), DLMF 3.5(i)).
//! * |x| ≥ 25: Hankel's asymptotic expansion (DLMF 10.17.3), J0(x) = sqrt(2/(πx)) (P cos ω − Q sin ω),
//!   ω = x − π/4, with at most 9 terms of each series (the truncation error is below 1e−16 for x ≥ 25), and a
//!   sine/cosine with Cody–Waite reduction and Taylor polynomials (absolute error ~1e−16 for x < 1e7).

use std::f64::consts::PI;
use std::sync::OnceLock;

const SPLIT: f64 = 25.0;
const DEGREE: usize = 16; // coefficients per panel (polynomial degree 15; the next would be < 1e−21)
const PANELS: usize = 25; // unit panels covering [0, 25)
const ASYM_TERMS: usize = 9;

struct Tables {
    cheb: Vec<[f64; DEGREE]>,
    /// (−1)^⌊k/2⌋ a_k, with a_k(0) of DLMF 10.17.1: a_k = Π_{j=1..k} (−(2j−1)²) / (k! 8^k), as they enter P, Q.
    asym_signed: [f64; 2 * ASYM_TERMS],
}

/// J0 by Bessel's integral (trapezoid rule, exact to rounding for |x| < ~60). Slow; used to build the tables
/// and by tests.
pub fn j0_integral(x: f64) -> f64 {
    const N: usize = 96;
    // (1/π)∫₀^π cos(x sin θ) dθ = (1/N) Σ_{j=0}^{N−1} cos(x sin(π(j + ½)/N)) (midpoint rule, periodic integrand);
    // the integrand is symmetric about θ = π/2, so half the nodes suffice. Neumaier-compensated sum.
    let (mut s, mut comp) = (0.0f64, 0.0f64);
    for j in 0..N / 2 {
        let th = PI * (j as f64 + 0.5) / N as f64;
        let v = (x * th.sin()).cos();
        let t = s + v;
        comp += if s.abs() >= v.abs() { (s - t) + v } else { (v - t) + s };
        s = t;
    }
    (s + comp) / (N / 2) as f64
}

fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| {
        let n = DEGREE;
        let cheb = (0..PANELS)
            .map(|p| {
                let f: Vec<f64> = (0..n)
                    .map(|k| {
                        let t = (PI * (k as f64 + 0.5) / n as f64).cos();
                        j0_integral(p as f64 + 0.5 + 0.5 * t)
                    })
                    .collect();
                let mut c = [0.0; DEGREE];
                for (j, cj) in c.iter_mut().enumerate() {
                    let mut s = 0.0;
                    for (k, fk) in f.iter().enumerate() {
                        // cos(π j (k + ½)/n) with the angle reduced exactly in integers (mod 2π).
                        let m = (j * (2 * k + 1)) % (4 * n);
                        s += fk * (PI * m as f64 / (2 * n) as f64).cos();
                    }
                    *cj = 2.0 * s / n as f64;
                }
                c[0] *= 0.5;
                c
            })
            .collect();
        let mut asym = [0.0; 2 * ASYM_TERMS];
        let mut a = 1.0;
        asym[0] = 1.0;
        for (k, ak) in asym.iter_mut().enumerate().skip(1) {
            let kf = k as f64;
            a *= -(2.0 * kf - 1.0) * (2.0 * kf - 1.0) / (8.0 * kf);
            *ak = a;
        }
        let mut asym_signed = asym;
        for (k, v) in asym_signed.iter_mut().enumerate() {
            if (k / 2) % 2 == 1 {
                *v = -*v;
            }
        }
        Tables { cheb, asym_signed }
    })
}

/// Bessel function of the first kind of order zero.
pub fn j0(x: f64) -> f64 {
    let x = x.abs();
    let t = tables();
    if x < SPLIT {
        let p = (x as usize).min(PANELS - 1);
        let u = 2.0 * (x - p as f64) - 1.0;
        // Clenshaw recurrence.
        let c = &t.cheb[p];
        let (mut b1, mut b2) = (0.0, 0.0);
        for &cj in c.iter().skip(1).rev() {
            let b0 = 2.0 * u * b1 - b2 + cj;
            b2 = b1;
            b1 = b0;
        }
        u * b1 - b2 + c[0]
    } else if x.is_finite() {
        // P = Σ (−1)^k a_2k / x^2k, Q = Σ (−1)^k a_(2k+1) / x^(2k+1)   (DLMF 10.17.3), truncated where the
        // next term is below 1e−17: a_0..a_17 for x ≥ 25, ..a_13 for x ≥ 40, ..a_9 for x ≥ 80, ..a_7 for x ≥ 200.
        let pairs = if x >= 200.0 {
            4
        } else if x >= 80.0 {
            5
        } else if x >= 40.0 {
            7
        } else {
            9
        };
        let inv = 1.0 / x;
        let y = inv * inv;
        let (mut p, mut q) = (0.0, 0.0);
        for k in (0..pairs).rev() {
            // Signs (−1)^k are folded into the table.
            p = p * y + t.asym_signed[2 * k];
            q = q * y + t.asym_signed[2 * k + 1];
        }
        let q = q * inv;
        let (s, c) = sin_cos(x);
        // cos(x − π/4) = (cos x + sin x)/√2, sin(x − π/4) = (sin x − cos x)/√2; sqrt(2/(πx))/√2 = sqrt(1/(πx)).
        (std::f64::consts::FRAC_1_PI * inv).sqrt() * (p * (c + s) - q * (s - c))
    } else {
        0.0
    }
}

// Taylor coefficients (−1)ⁿ/(2n + 1)! and (−1)ⁿ/(2n)!, n = 1.., of sin and cos on |θ| ≤ π/4 (the first omitted
// terms are below 10⁻¹⁶): the one copy lives in the photon-lane crate (its azimuth uses them too); `sin_cos` here
// evaluates them.
use rtbake_lanes::{COS_TAYLOR, SIN_TAYLOR};

/// (sin x, cos x) for 0 ≤ x < ~1e7: x = n·π/2 + y with π/2 split in three parts (the first two with 30
/// significant bits, so n·part is exact), then Taylor polynomials on |y| ≤ π/4 (next terms < 5e−17).
#[inline]
fn sin_cos(x: f64) -> (f64, f64) {
    if x >= 1.0e7 {
        return x.sin_cos();
    }
    const P1: f64 = 1.570_796_325_802_803;
    const P2: f64 = 9.920_935_791_635_221e-10;
    const P3: f64 = 5.170_182_981_794_105e-19;
    // Nearest quadrant by truncation (x ≥ 0; avoids a libm round call on baseline x86-64).
    let ni = (x * std::f64::consts::FRAC_2_PI + 0.5) as i64;
    let n = ni as f64;
    let y = ((x - n * P1) - n * P2) - n * P3;
    let z = y * y;
    // sin y = y Σ (−1)^k z^k/(2k+1)!, cos y = Σ (−1)^k z^k/(2k)!
    let (s, c) = (&SIN_TAYLOR, &COS_TAYLOR);
    let sn =
        y * (1.0 + z * (s[0] + z * (s[1] + z * (s[2] + z * (s[3] + z * (s[4] + z * (s[5] + z * (s[6] + z * s[7]))))))));
    let cs = 1.0
        + z * (c[0]
            + z * (c[1] + z * (c[2] + z * (c[3] + z * (c[4] + z * (c[5] + z * (c[6] + z * (c[7] + z * c[8]))))))));
    match ni & 3 {
        0 => (sn, cs),
        1 => (cs, -sn),
        2 => (-sn, -cs),
        _ => (-cs, sn),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference values from mpmath (30 digits), rounded to 20.
    #[allow(clippy::excessive_precision)]
    const REF: [(f64, f64); 19] = [
        (39.99, 0.008_627_041_957_705_529_8),
        (40.0, 0.007_366_890_584_237_289_6),
        (79.99, -0.070_299_276_949_752_633),
        (80.0, -0.069_742_165_512_210_023),
        (199.99, -0.015_979_717_959_609_418),
        (200.0, -0.015_437_439_930_565_092),
        (5000.25, -0.004_186_660_992_767_011),
        (0.0, 1.0),
        (0.5, 0.938_469_807_240_812_904_23),
        (1.0, 0.765_197_686_557_966_551_45),
        (5.0, -0.177_596_771_314_338_304_35),
        (10.0, -0.245_935_764_451_348_335_2),
        (17.5, -0.103_110_398_228_685_922_17),
        (24.9, 0.083_245_968_353_015_490_053),
        (25.1, 0.108_275_671_499_949_451_98),
        (30.0, -0.086_367_983_581_040_211_336),
        (60.0, -0.091_471_804_089_061_869_531),
        (123.4, -0.071_525_536_719_260_154_445),
        (1000.5, 0.019_486_559_987_130_137_373),
    ];

    #[test]
    fn j0_matches_reference_values() {
        for (x, v) in REF {
            assert!((j0(x) - v).abs() < 2e-15, "J0({x}) = {} vs {v}", j0(x));
            assert_eq!(j0(-x), j0(x));
        }
        // First zero j_{0,1} = 2.404825557695773 (DLMF Table 10.21.1).
        assert!(j0(2.404_825_557_695_773).abs() < 1e-15);
    }

    #[test]
    fn sin_cos_matches_std() {
        for i in 0..20000 {
            let x = i as f64 * 0.7316 + (i as f64).powi(2) * 1e-3;
            let (s, c) = sin_cos(x);
            assert!(
                (s - x.sin()).abs() < 4e-16 * (1.0 + x * 1e-9) && (c - x.cos()).abs() < 4e-16 * (1.0 + x * 1e-9),
                "x={x}"
            );
        }
    }

    #[test]
    fn j0_is_continuous_across_the_split_and_matches_the_integral() {
        for x in [SPLIT - 1e-9, SPLIT, SPLIT + 1e-9] {
            assert!((j0(x) - j0_integral(x)).abs() < 2e-15, "x={x}");
        }
        for i in 0..400 {
            let x = i as f64 * 0.1234;
            assert!((j0(x) - j0_integral(x)).abs() < 2e-15, "x={x}");
        }
    }
}
