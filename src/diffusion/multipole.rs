//! Multipole diffusion for a slab of finite thickness (Donner & Jensen, "Light Diffusion in Multi-Layered
//! Translucent Materials", SIGGRAPH 2005, "DJ05"; thesis §2).
//!
//! Slab 0 ≤ z ≤ d (z downwards), relative index η0 at the top face and ηd at the bottom face.
//! zb0 = 2A(η0)D, zbd = 2A(ηd)D, l = 1/σt′, L = d + zb0 + zbd; image pairs i = −n..n:
//! zr,i = 2iL + l, zv,i = 2iL − l − 2zb0.
//!
//! Hankel transforms (radial frequency k in mm⁻¹, s = sqrt(σtr² + k²)):
//!   R̂(k) = (α′/2) Σi [ sgn(zr,i) e^(−|zr,i| s) − sgn(zv,i) e^(−|zv,i| s) ]
//!   T̂(k) = (α′/2) Σi [ sgn(d − zr,i) e^(−|d − zr,i| s) − sgn(d − zv,i) e^(−|d − zv,i| s) ]
//! The exact infinite series is geometric in q = e^(−2Ls); it is evaluated here in a form that neither
//! overflows for large s nor cancels for s → 0 (where it tends to Ohm's law T = (l + zb0)/L).

use super::{boundary_a, FdrForm, ReducedCoefficients};
use crate::error::{check_non_negative, check_positive, InvalidInput};

/// How the image series is summed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum Series {
    /// Closed-form infinite series (default).
    #[default]
    Exact,
    /// i = −pairs..=pairs (DJ05 customarily used pairs = 5, i.e. 11 dipoles).
    Truncated { pairs: u32 },
}

/// One channel of a slab.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slab {
    pub sigma_a_per_mm: f64,
    pub sigma_s_prime_per_mm: f64,
    pub thickness_mm: f64,
    /// n_slab / n_above.
    pub eta_top: f64,
    /// n_slab / n_below.
    pub eta_bottom: f64,
    pub fdr_form: FdrForm,
}

impl ReducedCoefficients for Slab {
    fn sigma_a_per_mm(&self) -> f64 {
        self.sigma_a_per_mm
    }
    fn sigma_s_prime_per_mm(&self) -> f64 {
        self.sigma_s_prime_per_mm
    }
}

impl Slab {
    /// Validates the coefficients and the diffusion validity condition d > 1/σt′.
    pub fn new(
        sigma_a_per_mm: f64,
        sigma_s_prime_per_mm: f64,
        thickness_mm: f64,
        eta_top: f64,
        eta_bottom: f64,
        fdr_form: FdrForm,
    ) -> Result<Self, InvalidInput> {
        check_non_negative("sigma_a", sigma_a_per_mm, "mm^-1")?;
        check_positive("sigma_s_prime", sigma_s_prime_per_mm, "mm^-1")?;
        check_positive("thickness_mm", thickness_mm, "mm")?;
        check_positive("eta_top", eta_top, "relative index")?;
        check_positive("eta_bottom", eta_bottom, "relative index")?;
        let l = 1.0 / (sigma_a_per_mm + sigma_s_prime_per_mm);
        if thickness_mm <= l {
            return Err(InvalidInput::new(
                "thickness_mm",
                format!(
                    "must exceed the mean free path 1/sigma_t' = {l:.6} mm (diffusion source must lie inside the slab), got {thickness_mm}"
                ),
            ));
        }
        Ok(Self { sigma_a_per_mm, sigma_s_prime_per_mm, thickness_mm, eta_top, eta_bottom, fdr_form })
    }

    /// The same slab lit from below (face indices swapped): gives R↑, T↑.
    pub fn flipped(&self) -> Self {
        Self { eta_top: self.eta_bottom, eta_bottom: self.eta_top, ..*self }
    }

    /// (l, zb0, zbd, L) in mm.
    pub fn geometry_mm(&self) -> (f64, f64, f64, f64) {
        let st = self.sigma_t_prime();
        let dcoef = 1.0 / (3.0 * st);
        let zb0 = 2.0 * boundary_a(self.eta_top, self.fdr_form) * dcoef;
        let zbd = 2.0 * boundary_a(self.eta_bottom, self.fdr_form) * dcoef;
        let l = 1.0 / st;
        (l, zb0, zbd, self.thickness_mm + zb0 + zbd)
    }

    /// (R̂(k), T̂(k)) for radial frequency k (mm⁻¹). At k = 0 these are the total reflectance and transmittance.
    pub fn hankel_rt(&self, k_per_mm: f64, series: Series) -> (f64, f64) {
        let s = (self.sigma_tr().powi(2) + k_per_mm * k_per_mm).sqrt();
        match series {
            Series::Exact => self.hankel_exact(s),
            Series::Truncated { pairs } => self.hankel_truncated(s, pairs as i64),
        }
    }

    /// Hankel transforms of the image pairs beyond `pairs` (|i| > pairs) of the infinite series, so that
    /// `hankel_rt(k, Exact) = hankel_rt(k, Truncated { pairs }) + hankel_tail(k, pairs)`. With q = e^(−2Ls), J = pairs:
    /// R̂tail = −α′ [sinh(as) + sinh(bs)] q^(J+1)/(1 − q), T̂tail = α′ [sinh(av s) − sinh(ar s)] q^(J+1)/(1 − q)
    /// (a = l, b = l + 2zb0, ar = d − l, av = d + l + 2zb0), evaluated without overflow.
    pub fn hankel_tail(&self, k_per_mm: f64, pairs: u32) -> (f64, f64) {
        let s = (self.sigma_tr().powi(2) + k_per_mm * k_per_mm).sqrt();
        let (l, zb0, _, big_l) = self.geometry_mm();
        let d = self.thickness_mm;
        let (a, b, ar, av) = (l, l + 2.0 * zb0, d - l, d + l + 2.0 * zb0);
        let h = 0.5 * self.albedo_prime();
        let one_minus_q = -(-2.0 * big_l * s).exp_m1();
        if one_minus_q == 0.0 {
            // s = 0: 2 sinh(xs) q^(J+1)/(1 − q) → x/L.
            return (-h * (a + b) / big_l, h * (av - ar) / big_l);
        }
        let z = 2.0 * (pairs as f64 + 1.0) * big_l;
        // 2 sinh(xs) q^(J+1) = e^(−(z − x)s) − e^(−(z + x)s), 0 ≤ x < z.
        let e2 = |x: f64| (-(z - x) * s).exp() - (-(z + x) * s).exp();
        ((-h * (e2(a) + e2(b))) / one_minus_q, h * (e2(av) - e2(ar)) / one_minus_q)
    }

    /// Total diffuse reflectance and transmittance (R̂(0), T̂(0)).
    pub fn totals(&self, series: Series) -> (f64, f64) {
        self.hankel_rt(0.0, series)
    }

    /// R̂(0) of the exact series alone: the bits of `totals(Series::Exact).0` without the transmittance's terms
    /// (the skin-colour table needs only the dermis' reflectance, at every row and wavelength).
    pub fn total_reflectance_exact(&self) -> f64 {
        let s = (self.sigma_tr().powi(2) + 0.0 * 0.0).sqrt();
        self.hankel_exact_parts(s, false).0
    }

    fn hankel_truncated(&self, s: f64, n: i64) -> (f64, f64) {
        let (l, zb0, _, big_l) = self.geometry_mm();
        let d = self.thickness_mm;
        let e = |z: f64| z.signum() * (-z.abs() * s).exp();
        let (mut r, mut t) = (0.0, 0.0);
        for i in -n..=n {
            let zr = 2.0 * i as f64 * big_l + l;
            let zv = 2.0 * i as f64 * big_l - l - 2.0 * zb0;
            r += e(zr) - e(zv);
            t += e(d - zr) - e(d - zv);
        }
        let h = 0.5 * self.albedo_prime();
        (h * r, h * t)
    }

    fn hankel_exact(&self, s: f64) -> (f64, f64) {
        self.hankel_exact_parts(s, true)
    }

    /// (R̂, T̂) at `s`; T̂ = 0 unless `transmittance`.
    #[inline(always)]
    fn hankel_exact_parts(&self, s: f64, transmittance: bool) -> (f64, f64) {
        let (l, zb0, _, big_l) = self.geometry_mm();
        let d = self.thickness_mm;
        let a = l;
        let b = l + 2.0 * zb0;
        let ar = d - l;
        let av = d + l + 2.0 * zb0;
        // g·(e^(−xs) − e^(xs)) with g = q/(1 − q), q = e^(−2Ls), for 0 ≤ x ≤ 2L. The x-independent e^(2Ls) − 1
        // (or q) is formed once for the four terms (the same values as forming it per term).
        let two_ls = 2.0 * big_l * s;
        let shared = if two_ls == 0.0 {
            0.0
        } else if two_ls < 50.0 {
            two_ls.exp_m1()
        } else {
            (-two_ls).exp()
        };
        let g_diff = |x: f64| -> f64 {
            if two_ls == 0.0 {
                -x / big_l
            } else if two_ls < 50.0 {
                -2.0 * (x * s).sinh() / shared
            } else {
                ((-(2.0 * big_l + x) * s).exp() - (-(2.0 * big_l - x) * s).exp()) / (1.0 - shared)
            }
        };
        // e^(−xs)(1 + g) − e^(xs) g
        let term = |x: f64| (-x * s).exp() + g_diff(x);
        let h = 0.5 * self.albedo_prime();
        let r = term(a) + term(b);
        if !transmittance {
            return (h * r, 0.0);
        }
        let t = ar.signum() * (-ar.abs() * s).exp() + g_diff(ar) - term(av);
        (h * r, h * t)
    }
}

/// Most image pairs [`Series::Exact`] sums explicitly while they decay geometrically (σtr·L ≥ 40/4096 ≈ 0.01).
pub const EXACT_MAX_PAIRS: u32 = 2048;
/// Pairs summed explicitly before the Euler–Maclaurin tail when the decay is (nearly) algebraic.
pub const EXACT_EM_PAIRS: u32 = 256;

/// One image source, ×4π/α′: f(z) = z (1 + σρ) e^(−σρ)/ρ³ with ρ = sqrt(r² + z²) (odd in z).
#[inline]
fn image(z: f64, r2: f64, sigma: f64) -> f64 {
    let rho = (r2 + z * z).sqrt();
    z * (1.0 + sigma * rho) * (-sigma * rho).exp() / (rho * rho * rho)
}

/// e^(−σρ)/ρ = ∫_z^∞ f(z′) dz′ (for z > 0).
#[inline]
fn image_tail_integral(z: f64, r2: f64, sigma: f64) -> f64 {
    let rho = (r2 + z * z).sqrt();
    (-sigma * rho).exp() / rho
}

/// ∂f/∂z = e^(−σρ)/ρ³ · [(1 + σρ) − z²(3 + 3σρ + σ²ρ²)/ρ²].
#[inline]
fn image_dz(z: f64, r2: f64, sigma: f64) -> f64 {
    let rho2 = r2 + z * z;
    let rho = rho2.sqrt();
    let sr = sigma * rho;
    (-sr).exp() / (rho2 * rho) * ((1.0 + sr) - z * z * (3.0 + 3.0 * sr + sr * sr) / rho2)
}

/// Real-space sums. The i-th and (−i)-th image pairs are grouped (f is odd) into
/// P(j) = Σ_m c_m f(2jL + o_m), j ≥ 1, with four (c_m, o_m); i = 0 is the plain dipole.
///
/// [`Series::Exact`] sums j = 1, 2, … until the bound 4(1 + σz)e^(−σz)/z² (z = 2jL − max|o|) on every
/// remaining term, summed as a geometric series, is below 1e−17 of the magnitude of the sum so far; that takes
/// about 20/(σtr L) pairs. When σtr L < 40/(2·[`EXACT_MAX_PAIRS`]) — σa → 0 — the terms decay only algebraically
/// (P(j) ~ j^−3 at σa = 0: stopping after N pairs would leave an error ~N^−2 of the series, and the totals of any
/// truncated sum stay at α′ instead of reaching R + T = 1). Then [`EXACT_EM_PAIRS`] pairs are summed and the rest
/// Σ_{j>J} P(j) is added by the Euler–Maclaurin midpoint formula ∫_{J+½}^∞ P(t) dt + P′(J + ½)/24, where
/// ∫ f dz = −e^(−σρ)/ρ is analytic. P varies in j on the scale min(ρ/(2L), 1/(2Lσ)) ≥ J, so the first neglected
/// term, −7 P‴/5760, is ~1e−14 of R(0) (tests: long truncated sums at σa = 1e−7 and mpmath at σa = 0 agree
/// to ~1e−14 of R(0); ∫2πr R dr = R̂(0) at σa = 0). Relative accuracy is lost only where R(r) itself is below
/// ~1e−14 R(0) (σa = 0, r ≫ L: the image sum cancels to e^(−πr/L)).
fn image_series(r_mm: f64, sigma: f64, big_l: f64, dipole: f64, terms: [(f64, f64); 4], series: Series) -> f64 {
    let r2 = r_mm * r_mm;
    let pair = |j: f64| -> f64 { terms.iter().map(|&(c, o)| c * image(2.0 * j * big_l + o, r2, sigma)).sum() };
    let mut sum = dipole;
    match series {
        Series::Truncated { pairs } => {
            for j in 1..=pairs {
                sum += pair(j as f64);
            }
        }
        Series::Exact => {
            let o_max = terms.iter().map(|t| t.1.abs()).fold(0.0, f64::max);
            let two_l_sigma = 2.0 * big_l * sigma;
            let geometric = two_l_sigma * EXACT_MAX_PAIRS as f64 >= 40.0;
            let ratio = -(-two_l_sigma).exp_m1(); // 1 − e^(−2Lσ)
            let mut scale = dipole.abs();
            let mut j = 1u32;
            loop {
                let p = pair(j as f64);
                sum += p;
                scale += p.abs();
                if geometric {
                    let z = 2.0 * (j + 1) as f64 * big_l - o_max;
                    let bound = 4.0 * (1.0 + sigma * z) * (-sigma * z).exp() / (z * z);
                    if bound < 1e-17 * scale * ratio || j >= EXACT_MAX_PAIRS {
                        break;
                    }
                } else if j >= EXACT_EM_PAIRS {
                    // Euler–Maclaurin (midpoint) tail Σ_{j>J} P(j) ≈ ∫_{J+½}^∞ P dt + P′(J+½)/24.
                    let t0 = j as f64 + 0.5;
                    let mut tail = 0.0;
                    for &(c, o) in &terms {
                        let z0 = 2.0 * t0 * big_l + o;
                        tail += c
                            * (image_tail_integral(z0, r2, sigma) / (2.0 * big_l)
                                + 2.0 * big_l * image_dz(z0, r2, sigma) / 24.0);
                    }
                    sum += tail;
                    break;
                }
                j += 1;
            }
        }
    }
    sum
}

impl Slab {
    /// Diffuse reflectance R(r) of the lit (top) face, mm⁻² (DJ05 eq. 12).
    pub fn reflectance_mm2(&self, r_mm: f64, series: Series) -> f64 {
        let (l, zb0, _, big_l) = self.geometry_mm();
        let sigma = self.sigma_tr();
        let r2 = r_mm * r_mm;
        let (a, b) = (l, l + 2.0 * zb0);
        // i = 0: zr = l, zv = −l − 2zb0 → f(a) − f(−b) = f(a) + f(b).
        let dipole = image(a, r2, sigma) + image(b, r2, sigma);
        // j ≥ 1 with −j: f(2jL + a) − f(2jL − b) − f(2jL − a) + f(2jL + b).
        let terms = [(1.0, a), (1.0, b), (-1.0, -a), (-1.0, -b)];
        self.albedo_prime() / (4.0 * std::f64::consts::PI) * image_series(r_mm, sigma, big_l, dipole, terms, series)
    }

    /// Diffuse transmittance T(r) through the bottom face, mm⁻² (DJ05 eq. 13).
    pub fn transmittance_mm2(&self, r_mm: f64, series: Series) -> f64 {
        let (l, zb0, _, big_l) = self.geometry_mm();
        let sigma = self.sigma_tr();
        let r2 = r_mm * r_mm;
        let d = self.thickness_mm;
        let (ar, av) = (d - l, d + l + 2.0 * zb0);
        // i = 0: f(d − zr) − f(d − zv) = f(ar) − f(av).
        let dipole = image(ar, r2, sigma) - image(av, r2, sigma);
        // j ≥ 1 with −j: f(2jL + ar) − f(2jL + av) − f(2jL − ar) + f(2jL − av).
        let terms = [(1.0, ar), (-1.0, av), (-1.0, -ar), (1.0, -av)];
        self.albedo_prime() / (4.0 * std::f64::consts::PI) * image_series(r_mm, sigma, big_l, dipole, terms, series)
    }
}

/// Three channels of a slab with the series choice: a [`RadialProfile`](super::RadialProfile) with transmittance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabRgb {
    pub channels: [Slab; 3],
    pub series: Series,
}

impl super::RadialProfile for SlabRgb {
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        [0, 1, 2].map(|c| self.channels[c].reflectance_mm2(r_mm, self.series))
    }
    fn total_reflectance(&self) -> [f64; 3] {
        [0, 1, 2].map(|c| self.channels[c].totals(self.series).0)
    }
    fn transmittance_mm2(&self, r_mm: f64) -> Option<[f64; 3]> {
        Some([0, 1, 2].map(|c| self.channels[c].transmittance_mm2(r_mm, self.series)))
    }
    fn total_transmittance(&self) -> Option<[f64; 3]> {
        Some([0, 1, 2].map(|c| self.channels[c].totals(self.series).1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skinlike(d: f64, sigma_a: f64) -> Slab {
        Slab::new(sigma_a, 1.5, d, 1.4, 1.4, FdrForm::Dj05).unwrap()
    }

    #[test]
    fn reflectance_alone_has_the_bits_of_the_totals() {
        // Thin and thick slabs: 2Ls below 50 (expm1 branch) and above it (q branch), and σa = 0.
        for (d, sigma_a) in [(1.0, 0.01), (1.0, 30.0), (20.0, 0.02), (20.0, 2.0), (1.0, 0.0)] {
            let slab = skinlike(d, sigma_a);
            assert_eq!(slab.total_reflectance_exact().to_bits(), slab.totals(Series::Exact).0.to_bits(), "d {d}");
        }
    }

    #[test]
    fn exact_series_matches_long_truncated_sum() {
        let slab = skinlike(0.8, 0.02);
        for k in [0.0, 0.3, 2.0, 40.0] {
            let (re, te) = slab.hankel_rt(k, Series::Exact);
            let (rt, tt) = slab.hankel_rt(k, Series::Truncated { pairs: 4000 });
            assert!((re - rt).abs() < 1e-9 * rt.abs().max(1e-12), "k={k} R {re} vs {rt}");
            assert!((te - tt).abs() < 1e-9 * tt.abs().max(1e-12), "k={k} T {te} vs {tt}");
        }
    }

    #[test]
    fn non_absorbing_slab_obeys_ohms_law() {
        let slab = skinlike(2.0, 0.0);
        let (r, t) = slab.totals(Series::Exact);
        let (l, zb0, _, big_l) = slab.geometry_mm();
        assert!((r + t - 1.0).abs() < 1e-12, "R+T = {}", r + t);
        assert!((t - (l + zb0) / big_l).abs() < 1e-12);
    }

    #[test]
    fn tail_completes_truncated_sums() {
        for slab in
            [skinlike(0.8, 0.02), skinlike(2.0, 0.0), Slab::new(0.3, 2.0, 0.9, 1.3, 0.9, FdrForm::Dj05).unwrap()]
        {
            for k in [0.0, 0.3, 2.0, 10.0] {
                for pairs in [0, 1, 3] {
                    let (re, te) = slab.hankel_rt(k, Series::Exact);
                    let (rt, tt) = slab.hankel_rt(k, Series::Truncated { pairs });
                    let (ra, ta) = slab.hankel_tail(k, pairs);
                    assert!((rt + ra - re).abs() < 1e-14, "k={k} J={pairs}: R {} vs {re}", rt + ra);
                    assert!((tt + ta - te).abs() < 1e-14, "k={k} J={pairs}: T {} vs {te}", tt + ta);
                }
            }
        }
    }

    #[test]
    fn rejects_slab_thinner_than_mean_free_path() {
        let err = Slab::new(0.1, 0.9, 0.5, 1.4, 1.4, FdrForm::Dj05).unwrap_err();
        assert_eq!(err.param, "thickness_mm");
    }
}
