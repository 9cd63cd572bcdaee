//! Burley's normalized diffusion: an empirical reflectance profile with exact normalisation and a closed-form CDF.
//!
//! P. H. Christensen, B. Burley, "Approximate Reflectance Profiles for Efficient Subsurface Scattering", Pixar
//! Technical Memo 15-04 (2015), eq. 2–3. With surface albedo A and shape parameter d (mm):
//!
//!   R(r) = A · (e^(−r/d) + e^(−r/(3d))) / (8π d r)                                               (mm⁻²)
//!
//! so that ∫₀^∞ R(r) 2πr dr = A exactly. The normalised radial density 2πr R(r) / A has the CDF
//!
//!   F(r) = 1 − (e^(−r/d) + 3 e^(−r/(3d))) / 4,
//!
//! which has no closed-form inverse; [`Burley::sample_radius_mm`] inverts it by Newton's method on x = r/d,
//! safeguarded by bisection on the bracket [0, 3 ln(1/(1 − u))] (F(3 ln(1/(1 − u)) d) ≥ u because
//! e^(−x) ≤ e^(−x/3)), to 1e-14 relative.
//!
//! The paper's shape-parameter fits give d from a mean free path ℓ as d = ℓ / s(A) for three set-ups
//! ([`ShapeFit`]): searchlight illumination with the diffuse mean free path (s = 1.85 − A + 7|A − 0.8|³, §3.2),
//! diffuse surface transmission with the diffuse mean free path (s = 1.9 − A + 3.5(A − 0.8)², §3.3), and
//! searchlight illumination with the volume mean free path ℓ = 1/σt (s = 3.5 + 100(A − 0.33)⁴, §3.4).

use super::RadialProfile;
use crate::error::{check_positive, InvalidInput};
use std::f64::consts::PI;

/// Which of Christensen & Burley's fits s(A) relates the shape parameter to a mean free path: d = ℓ / s(A).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShapeFit {
    /// Perpendicular (searchlight) illumination, ℓ = diffuse mean free path: s = 1.85 − A + 7|A − 0.8|³.
    Searchlight,
    /// Diffuse surface transmission, ℓ = diffuse mean free path: s = 1.9 − A + 3.5(A − 0.8)² (the fit engine
    /// bakers use with a "scattering distance").
    #[default]
    DiffuseTransmission,
    /// Searchlight illumination, ℓ = volume mean free path 1/σt: s = 3.5 + 100(A − 0.33)⁴.
    MeanFreePath,
}

impl ShapeFit {
    /// The scaling factor s(A) of the fit (dimensionless), for A in [0, 1].
    pub fn scale(self, albedo: f64) -> f64 {
        match self {
            Self::Searchlight => 1.85 - albedo + 7.0 * (albedo - 0.8).abs().powi(3),
            Self::DiffuseTransmission => 1.9 - albedo + 3.5 * (albedo - 0.8).powi(2),
            Self::MeanFreePath => 3.5 + 100.0 * (albedo - 0.33).powi(4),
        }
    }

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Searchlight => "searchlight",
            Self::DiffuseTransmission => "diffuse-transmission",
            Self::MeanFreePath => "mean-free-path",
        }
    }
}

/// One channel of Burley's normalized diffusion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Burley {
    /// Surface albedo A = total diffuse reflectance, in [0, 1].
    pub albedo: f64,
    /// Shape parameter d, mm (> 0).
    pub d_mm: f64,
}

impl Burley {
    /// Validates A ∈ [0, 1] and d > 0 (finite).
    pub fn new(albedo: f64, d_mm: f64) -> Result<Self, InvalidInput> {
        check_albedo("albedo", albedo)?;
        check_positive("d_mm", d_mm, "mm")?;
        Ok(Self { albedo, d_mm })
    }

    /// d = ℓ / s(A) from a mean free path ℓ (mm) and one of the paper's fits.
    pub fn from_mean_free_path(albedo: f64, mean_free_path_mm: f64, fit: ShapeFit) -> Result<Self, InvalidInput> {
        check_albedo("albedo", albedo)?;
        check_positive("mean_free_path_mm", mean_free_path_mm, "mm")?;
        Self::new(albedo, mean_free_path_mm / fit.scale(albedo))
    }

    /// R(r), mm⁻² (eq. 2); at r = 0 the profile diverges like 1/r and this returns +∞ for A > 0.
    pub fn reflectance_mm2(&self, r_mm: f64) -> f64 {
        let d = self.d_mm;
        self.albedo * ((-r_mm / d).exp() + (-r_mm / (3.0 * d)).exp()) / (8.0 * PI * d * r_mm)
    }

    /// F(r) = ∫₀^r 2πr′ R(r′) dr′ / A: the fraction of the reflected light within r.
    pub fn cdf(&self, r_mm: f64) -> f64 {
        cdf_x(r_mm.max(0.0) / self.d_mm)
    }

    /// The radial density of the normalised profile, 2πr R(r) / A = (e^(−r/d) + e^(−r/(3d))) / (4d), mm⁻¹.
    pub fn pdf_per_mm(&self, r_mm: f64) -> f64 {
        let d = self.d_mm;
        ((-r_mm / d).exp() + (-r_mm / (3.0 * d)).exp()) / (4.0 * d)
    }

    /// Transmittance through a thickness s (mm): the profile integrated over the plane at depth s, the light a
    /// point source reaching the other side of a slab of thickness s spreads over it. With ρ² = r² + s²,
    ///
    ///   T(s) = ∫₀^∞ R(√(r² + s²)) 2πr dr = ∫ₛ^∞ R(ρ) 2πρ dρ = A (1 − F(s)) = A (e^(−s/d) + 3e^(−s/(3d))) / 4,
    ///
    /// the form engine bakers use for thin-object transmission with Burley profiles; T(0) = A.
    pub fn plane_transmittance(&self, s_mm: f64) -> f64 {
        let x = s_mm.max(0.0) / self.d_mm;
        self.albedo * 0.25 * ((-x).exp() + 3.0 * (-x / 3.0).exp())
    }

    /// The radius (mm) at which F(r) = u, for u in [0, 1) (importance sampling of the profile).
    pub fn sample_radius_mm(&self, u: f64) -> Result<f64, InvalidInput> {
        if !(0.0..1.0).contains(&u) {
            return Err(InvalidInput::new("u", format!("must be in [0, 1), got {u}")));
        }
        Ok(self.d_mm * inverse_cdf_x(u))
    }
}

fn check_albedo(param: &str, albedo: f64) -> Result<f64, InvalidInput> {
    if albedo.is_finite() && (0.0..=1.0).contains(&albedo) {
        Ok(albedo)
    } else {
        Err(InvalidInput::new(param, format!("must be in 0..=1, got {albedo}")))
    }
}

/// F at x = r/d.
fn cdf_x(x: f64) -> f64 {
    // 1 − (e^(−x) + 3e^(−x/3))/4, written to keep accuracy near x = 0 (where F ≈ x/2).
    -(0.25 * (-x).exp_m1() + 0.75 * (-x / 3.0).exp_m1())
}

/// x = r/d with F(x) = u, u ∈ [0, 1): Newton's method safeguarded by bisection.
fn inverse_cdf_x(u: f64) -> f64 {
    if u == 0.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0f64, 3.0 * (-u).ln_1p().abs());
    // Start from the slower exponential alone, then refine.
    let mut x = 0.5 * (lo + hi);
    for _ in 0..100 {
        let f = cdf_x(x) - u;
        if f > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let slope = ((-x).exp() + (-x / 3.0).exp()) / 4.0;
        let mut next = x - f / slope;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - x).abs() <= 1e-15 * next.max(1e-300) {
            return next;
        }
        x = next;
    }
    x
}

/// Burley's profile per channel (R, G, B), for the profile tools.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbBurley(pub [Burley; 3]);

impl RgbBurley {
    /// From per-channel albedo and mean free path (mm) with one fit.
    pub fn from_mean_free_path(
        albedo: [f64; 3],
        mean_free_path_mm: [f64; 3],
        fit: ShapeFit,
    ) -> Result<Self, InvalidInput> {
        let mut ch = [Burley { albedo: 0.0, d_mm: 1.0 }; 3];
        for c in 0..3 {
            ch[c] = Burley::from_mean_free_path(albedo[c], mean_free_path_mm[c], fit)
                .map_err(|e| InvalidInput::new(format!("{}[{c}]", e.param), e.message))?;
        }
        Ok(Self(ch))
    }
}

impl RadialProfile for RgbBurley {
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        self.0.map(|b| b.reflectance_mm2(r_mm))
    }

    fn total_reflectance(&self) -> [f64; 3] {
        self.0.map(|b| b.albedo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// T(s) is the plane integral of R: compared with a direct quadrature of ∫ R(√(r² + s²)) 2πr dr.
    #[test]
    fn plane_transmittance_is_the_plane_integral_of_the_profile() {
        let b = Burley::new(0.7, 0.4).unwrap();
        assert_eq!(b.plane_transmittance(0.0), 0.7);
        for s in [0.05, 0.3, 1.0, 4.0] {
            // Substitute r = e^t over t in [ln 1e-9, ln 200] mm, trapezoid with 200k nodes.
            let (t0, t1, n) = ((1e-9f64).ln(), 200f64.ln(), 200_000);
            let h = (t1 - t0) / n as f64;
            let f = |t: f64| {
                let r = t.exp();
                b.reflectance_mm2((r * r + s * s).sqrt()) * 2.0 * PI * r * r
            };
            let sum: f64 = (0..=n).map(|i| f(t0 + i as f64 * h) * if i == 0 || i == n { 0.5 } else { 1.0 }).sum();
            let quad = sum * h;
            let t = b.plane_transmittance(s);
            assert!((quad - t).abs() <= 1e-6 * t, "s = {s}: {quad} vs {t}");
        }
    }

    /// ∫₀^∞ 2πr R(r) dr by Gauss–Legendre on r = d·t/(1 − t) pieces; the integrand 2πr R is finite at 0.
    fn numeric_total(b: &Burley) -> f64 {
        let f =
            |r: f64| if r == 0.0 { b.albedo * 2.0 / (8.0 * b.d_mm) * 2.0 } else { 2.0 * PI * r * b.reflectance_mm2(r) };
        // Composite Simpson in u = r/(r + 3d) ∈ [0, 1): r = 3d u/(1 − u), dr = 3d/(1 − u)² du.
        let n = 20_000;
        let mut s = 0.0;
        for k in 0..=n {
            let u = k as f64 / n as f64;
            if u >= 1.0 {
                continue;
            }
            let r = 3.0 * b.d_mm * u / (1.0 - u);
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            s += w * f(r) * 3.0 * b.d_mm / (1.0 - u).powi(2);
        }
        s / (3.0 * n as f64)
    }

    #[test]
    fn the_profile_integrates_to_the_albedo() {
        for (a, d) in [(0.8, 1.0), (0.3, 0.05), (1.0, 7.5), (0.05, 2.0)] {
            let b = Burley::new(a, d).unwrap();
            let total = numeric_total(&b);
            assert!((total - a).abs() < 1e-9 * a.max(1e-3), "A = {a}, d = {d}: {total}");
        }
    }

    #[test]
    fn cdf_is_the_integral_of_the_pdf_and_its_inverse_round_trips() {
        let b = Burley::new(0.6, 0.7).unwrap();
        // F(r) against a fine trapezoid of the pdf.
        let r_end = 2.0;
        let n = 200_000;
        let h = r_end / n as f64;
        let integral: f64 =
            (0..n).map(|k| 0.5 * h * (b.pdf_per_mm(k as f64 * h) + b.pdf_per_mm((k + 1) as f64 * h))).sum();
        assert!((integral - b.cdf(r_end)).abs() < 1e-10, "{integral} vs {}", b.cdf(r_end));
        assert_eq!(b.cdf(0.0), 0.0);
        assert!((b.cdf(1e6) - 1.0).abs() < 1e-15);
        for k in 0..=1000 {
            let u = k as f64 / 1000.0 * 0.999_999;
            let r = b.sample_radius_mm(u).unwrap();
            let back = b.cdf(r);
            assert!((back - u).abs() <= 1e-14 * u.max(1e-300) + 1e-16, "u = {u}: r = {r}, F(r) = {back}");
        }
        assert!(b.sample_radius_mm(1.0).is_err() && b.sample_radius_mm(-0.1).is_err());
        assert!(b.sample_radius_mm(1e-300).unwrap() > 0.0);
    }

    #[test]
    fn the_papers_shape_fits() {
        // Values of s(A) at a few albedos, from the printed formulas.
        assert!((ShapeFit::Searchlight.scale(0.8) - 1.05).abs() < 1e-15);
        assert!((ShapeFit::Searchlight.scale(0.0) - (1.85 + 7.0 * 0.512)).abs() < 1e-12);
        assert!((ShapeFit::DiffuseTransmission.scale(0.8) - 1.1).abs() < 1e-15);
        assert!((ShapeFit::DiffuseTransmission.scale(1.0) - (0.9 + 3.5 * 0.04)).abs() < 1e-12);
        assert!((ShapeFit::MeanFreePath.scale(0.33) - 3.5).abs() < 1e-15);
        assert!((ShapeFit::MeanFreePath.scale(1.0) - (3.5 + 100.0 * 0.67f64.powi(4))).abs() < 1e-12);
        // d = ℓ / s(A): a longer mean free path widens the profile, every fit positive over [0, 1].
        for fit in [ShapeFit::Searchlight, ShapeFit::DiffuseTransmission, ShapeFit::MeanFreePath] {
            for k in 0..=100 {
                assert!(fit.scale(k as f64 / 100.0) > 0.0, "{fit:?}");
            }
            let b = Burley::from_mean_free_path(0.5, 2.0, fit).unwrap();
            assert!((b.d_mm - 2.0 / fit.scale(0.5)).abs() < 1e-15);
        }
    }

    #[test]
    fn bad_parameters_name_the_field() {
        for (a, d) in [(-0.1, 1.0), (1.1, 1.0), (f64::NAN, 1.0), (0.5, 0.0), (0.5, -1.0), (0.5, f64::INFINITY)] {
            assert!(Burley::new(a, d).is_err(), "A = {a}, d = {d}");
        }
        let e = RgbBurley::from_mean_free_path([0.5, 0.5, 2.0], [1.0; 3], ShapeFit::Searchlight).unwrap_err();
        assert!(e.to_string().contains("albedo[2]") && e.to_string().contains("0..=1"), "{e}");
    }

    #[test]
    fn as_a_radial_profile() {
        let p =
            RgbBurley::from_mean_free_path([0.8, 0.5, 0.2], [3.0, 1.5, 0.8], ShapeFit::DiffuseTransmission).unwrap();
        assert_eq!(p.total_reflectance(), [0.8, 0.5, 0.2]);
        let r = p.reflectance_mm2(0.5);
        for (rc, b) in r.iter().zip(&p.0) {
            assert_eq!(*rc, b.reflectance_mm2(0.5));
            assert!(*rc > 0.0 && rc.is_finite());
        }
    }
}
