//! Physical invariants of the dipole and multipole models (`specs/diffusion.md`): closed-form totals against
//! numerical ∫2πr R dr, R + T = 1 and Ohm's law without absorption, thick slab → dipole, truncation pitfall.

use rtbake::diffusion::dipole::Dipole;
use rtbake::diffusion::materials::{self, JENSEN_2001};
use rtbake::diffusion::multipole::{Series, Slab};
use rtbake::diffusion::quadrature::radial_total;
use rtbake::diffusion::{fdr, FdrForm, RadialProfile, ReducedCoefficients};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

#[test]
fn dipole_closed_form_total_equals_numerical_integral_for_every_material() {
    for form in [FdrForm::Dj05, FdrForm::Jensen01] {
        for m in &JENSEN_2001 {
            let p = m.dipole(form);
            let sigma_min = p.0.iter().map(|d| d.sigma_tr()).fold(f64::INFINITY, f64::min);
            let r_max = 50.0 / sigma_min + 10.0;
            let numeric = radial_total(|r| p.reflectance_mm2(r), 1e-7, r_max, 300);
            let closed = p.total_reflectance();
            for c in 0..3 {
                assert!(
                    rel(numeric[c], closed[c]) < 1e-9,
                    "{} {form:?} ch{c}: {} vs {}",
                    m.name,
                    numeric[c],
                    closed[c]
                );
            }
        }
    }
}

#[test]
fn fdr_forms_are_continuous_at_eta_one_and_jensen01_is_the_rounded_polynomial() {
    assert!((fdr(1.0, FdrForm::Dj05) - fdr(1.0 - 1e-12, FdrForm::Dj05)).abs() < 1e-10);
    // Jensen 2001 printed −1.440/η² + 0.710/η + 0.668 + 0.0636η.
    let eta: f64 = 1.3;
    let j01 = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    assert_eq!(fdr(eta, FdrForm::Jensen01), j01);
    assert!((fdr(eta, FdrForm::Dj05) - j01).abs() > 1e-5);
    // Published rounded value for skin (η = 1.3): Fdr ≈ 0.44.
    assert!((fdr(eta, FdrForm::Dj05) - 0.44).abs() < 0.01);
}

#[test]
fn dipole_rejects_bad_coefficients_naming_the_field() {
    assert_eq!(Dipole::new(f64::NAN, 1.0, 1.3, FdrForm::Dj05).unwrap_err().param, "sigma_a");
    assert_eq!(Dipole::new(0.1, 0.0, 1.3, FdrForm::Dj05).unwrap_err().param, "sigma_s_prime");
    assert_eq!(Dipole::new(0.1, 1.0, -1.0, FdrForm::Dj05).unwrap_err().param, "eta");
}

fn slab(sigma_a: f64, sigma_s: f64, d: f64, eta0: f64, etad: f64) -> Slab {
    Slab::new(sigma_a, sigma_s, d, eta0, etad, FdrForm::Dj05).unwrap()
}

/// Slabs covering absorbing/non-absorbing, thin/thick, matched/mismatched faces.
fn slabs() -> Vec<Slab> {
    vec![
        slab(0.05, 1.5, 1.0, 1.4, 1.4),
        slab(0.05, 1.5, 1.0, 1.4, 1.0 / 1.2),
        slab(0.5, 3.0, 0.4, 1.3, 1.0),
        slab(0.002, 2.0, 2.0, 1.0, 1.5),
        slab(0.0, 1.5, 1.0, 1.4, 1.4),
        slab(0.0, 2.0, 0.8, 1.3, 1.0 / 1.1),
    ]
}

#[test]
fn multipole_totals_equal_numerical_integrals_of_real_space_profiles() {
    for s in slabs() {
        let (rt, tt) = s.totals(Series::Exact);
        let (_, _, _, big_l) = s.geometry_mm();
        let r_max = 60.0 * big_l + if s.sigma_tr() > 0.0 { 40.0 / s.sigma_tr() } else { 0.0 };
        let num = radial_total(
            |r| [s.reflectance_mm2(r, Series::Exact), s.transmittance_mm2(r, Series::Exact)],
            1e-7,
            r_max,
            300,
        );
        assert!(rel(num[0], rt) < 1e-9, "{s:?}: ∫R = {} vs R̂(0) = {rt}", num[0]);
        assert!(rel(num[1], tt) < 1e-9, "{s:?}: ∫T = {} vs T̂(0) = {tt}", num[1]);
    }
}

#[test]
fn exact_real_space_series_matches_long_truncated_sums() {
    // σa = 1e−7: the image terms decay so slowly (σtr L ~ 2e−3) that the Euler–Maclaurin tail is used after 256
    // pairs, while 40000 explicit pairs have converged (e^(−2·40000·σtr·L) ≪ 1e−16). σa = 1e−4 and 0.05: summed
    // explicitly until the geometric bound.
    for s in [
        slab(1e-7, 1.5, 1.0, 1.4, 1.4),
        slab(1e-7, 2.0, 0.8, 1.3, 1.0 / 1.1),
        slab(1e-4, 1.5, 1.0, 1.4, 1.4),
        slab(0.05, 1.5, 1.0, 1.4, 1.0),
    ] {
        for r in [0.0, 0.01, 0.3, 1.0, 4.0, 20.0] {
            let long = Series::Truncated { pairs: 40000 };
            let (re, rl) = (s.reflectance_mm2(r, Series::Exact), s.reflectance_mm2(r, long));
            let (te, tl) = (s.transmittance_mm2(r, Series::Exact), s.transmittance_mm2(r, long));
            let scale_r = s.reflectance_mm2(0.0, long);
            let scale_t = s.transmittance_mm2(0.0, long);
            assert!((re - rl).abs() < 1e-13 * scale_r, "R({r}) {re} vs {rl}");
            assert!((te - tl).abs() < 1e-13 * scale_t, "T({r}) {te} vs {tl}");
        }
    }
}

#[test]
fn non_absorbing_slabs_conserve_energy_and_obey_ohms_law() {
    for (eta0, etad) in [(1.4, 1.4), (1.3, 1.0 / 1.1), (1.0, 1.5)] {
        let s = slab(0.0, 1.5, 1.2, eta0, etad);
        let (r, t) = s.totals(Series::Exact);
        let (l, zb0, _, big_l) = s.geometry_mm();
        assert!((r + t - 1.0).abs() < 1e-13, "R + T = {}", r + t);
        assert!(rel(t, (l + zb0) / big_l) < 1e-13, "Ohm's law: T = {t}, (l + zb0)/L = {}", (l + zb0) / big_l);
        // σa → 0 approaches the same limit continuously.
        let (r9, t9) = slab(1e-10, 1.5, 1.2, eta0, etad).totals(Series::Exact);
        assert!((r9 + t9 - 1.0).abs() < 1e-8 && (t9 - t).abs() < 1e-8, "σa = 1e−10: R + T = {}", r9 + t9);
    }
    // Any truncated sum misses this: each image pair integrates to zero, so R̂(0) + T̂(0) stays at α′ + …
    let s = slab(0.0, 1.5, 1.2, 1.4, 1.4);
    let (r5, t5) = s.totals(Series::Truncated { pairs: 5 });
    let (re, te) = s.totals(Series::Exact);
    assert!((r5 - re).abs() > 0.05 && (t5 - te).abs() > 0.05, "truncated: R {r5} T {t5}; exact R {re} T {te}");
}

#[test]
fn thick_slab_converges_to_the_dipole() {
    for m in ["skin1", "skin2", "ketchup", "potato"] {
        let mat = materials::find(m).unwrap();
        for c in 0..3 {
            let (sa, ss) = (mat.sigma_a_per_mm[c], mat.sigma_s_prime_per_mm[c]);
            let dip = Dipole::new(sa, ss, 1.3, FdrForm::Dj05).unwrap();
            let thick = slab(sa, ss, 50.0, 1.3, 1.3);
            let (rt, _) = thick.totals(Series::Exact);
            // The bottom face's images sit ≥ 2d deep: the difference is ~e^(−2σtr d).
            let tol = 1e-13_f64.max(10.0 * (-2.0 * thick.sigma_tr() * 50.0).exp());
            let rel_total = rel(rt, dip.total_reflectance());
            assert!(rel_total < tol, "{m} ch{c}: slab {rt} vs dipole {}", dip.total_reflectance());
            for r in [0.0, 0.1, 1.0, 5.0] {
                let (a, b) = (thick.reflectance_mm2(r, Series::Exact), dip.reflectance_mm2(r));
                assert!(rel(a, b) < tol * 10.0, "{m} ch{c} r={r}: {a} vs {b}");
            }
        }
    }
    // The skin-like case of the spec: relative difference ~1e−12 at d = 50 mm.
    let dip = Dipole::new(0.1, 1.5, 1.4, FdrForm::Dj05).unwrap();
    let (rt, _) = slab(0.1, 1.5, 50.0, 1.4, 1.4).totals(Series::Exact);
    assert!(rel(rt, dip.total_reflectance()) < 1e-12);
}

#[test]
fn truncated_sum_of_11_dipoles_is_wrong_by_more_than_one_percent_for_thin_weakly_absorbing_slabs() {
    // The customary i = −5..5 (DJ05, pbrt-v2-skin) for a 1.5 mm slab with little absorption: R and T are each
    // off by several percent (their errors cancel in R + T).
    let s = slab(0.001, 1.0, 1.5, 1.3, 1.3);
    let (re, te) = s.totals(Series::Exact);
    let (r5, t5) = s.totals(Series::Truncated { pairs: 5 });
    assert!(rel(r5, re) > 0.01 && rel(t5, te) > 0.01, "R {r5} vs {re}, T {t5} vs {te}");
    // The real-space profile is off as well, most at large r.
    let (a, b) = (s.reflectance_mm2(5.0, Series::Truncated { pairs: 5 }), s.reflectance_mm2(5.0, Series::Exact));
    assert!(rel(a, b) > 0.01, "R(5 mm): truncated {a} vs exact {b}");
}

#[test]
fn slab_validity_condition_names_the_field() {
    let e = Slab::new(0.1, 0.9, 0.5, 1.4, 1.4, FdrForm::Dj05).unwrap_err();
    assert_eq!(e.param, "thickness_mm");
    assert!(e.message.contains("1/sigma_t'"), "{}", e.message);
    assert!(Slab::new(0.1, 0.9, 1.0001, 1.4, 1.4, FdrForm::Dj05).is_ok());
}

#[test]
fn non_absorbing_slab_profile_matches_high_precision_image_sum() {
    // σa = 0, σs′ = 1.5 mm⁻¹, d = 1 mm, η = 1.4 both faces: R(r) from the full image series summed with mpmath
    // (30 digits, `nsum` with its convergence acceleration).
    let s = slab(0.0, 1.5, 1.0, 1.4, 1.4);
    #[allow(clippy::excessive_precision)]
    let reference = [
        (0.0, 0.180_423_308_549_500_39),
        (0.5, 0.092_963_009_391_612_49),
        (2.0, 0.006_158_331_103_981_464_5),
        (10.0, 3.478_213_981_221_919_5e-6),
        (50.0, 1.471_501_545_938_828_5e-20),
    ];
    for (r, v) in reference {
        let got = s.reflectance_mm2(r, Series::Exact);
        assert!((got - v).abs() < 1e-14 * reference[0].1, "R({r}) = {got}, mpmath {v}");
    }
}
