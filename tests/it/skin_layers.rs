//! Per-wavelength and per-channel coefficients of the physiological two-layer skin against hand computation with
//! the formulas of `specs/skin-color.md` and the rows of Prahl's table.

use rtbake::spectral::colorimetry::Illuminant;
use rtbake::spectral::skin_layers::{two_layer_skin_rgb, RgbReduction, SkinPhysiology};
use std::f64::consts::LN_10;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

/// Blood σa in mm⁻¹ from a Prahl ε (cm⁻¹/M): ln(10) · ε · 150 g/L / 64500 g/mol / 10.
fn blood(eps: f64) -> f64 {
    LN_10 * eps * 150.0 / 64500.0 / 10.0
}

#[test]
fn coefficients_at_501_nm_match_hand_computation() {
    // λ = 501 nm lies between Prahl's rows 500 nm (HbO2 20932.8, Hb 20862) and 502 nm (HbO2 20596.4, Hb 21832.8):
    // linear interpolation halfway.
    let (eps_oxy, eps_deoxy) = ((20932.8 + 20596.4) / 2.0, (20862.0 + 21832.8) / 2.0);
    let l: f64 = 501.0;
    let eumelanin = 6.6e10 * l.powf(-3.33);
    let pheomelanin = 2.9e14 * l.powf(-4.75);
    let baseline = 0.0244 + 8.53 * (-(l - 154.0) / 66.2).exp();
    let sigma_s_epi = 14.74 * l.powf(-0.22) + 2.2e11 * l.powi(-4);
    // βm = 0.61, γ = 0.75, Cm = 0.1, Chd = 0.08, Che = 0.25 · 0.08 = 0.02.
    let melanin = 0.61 * eumelanin + 0.39 * pheomelanin;
    let hb = 0.75 * blood(eps_oxy) + 0.25 * blood(eps_deoxy);
    let epi = 0.1 * melanin + 0.02 * hb + (1.0 - 0.1 - 0.02) * baseline;
    let derm = 0.08 * hb + (1.0 - 0.08) * baseline;

    // The same numbers evaluated independently (Python, double precision).
    assert!(close(blood(eps_oxy), 11.119129865577712, 1e-12));
    assert!(close(blood(eps_deoxy), 11.43121046841421, 1e-12));
    assert!(close(epi, 6.095802049819503, 1e-12));
    assert!(close(derm, 0.9597439853293056, 1e-12));
    assert!(close(sigma_s_epi, 7.2463166361050515, 1e-12));

    let k = SkinPhysiology::default().coefficients_at(l, 0.1, 0.08).unwrap();
    assert!(close(k.epidermis.sigma_a_per_mm, epi, 1e-12), "{} vs {epi}", k.epidermis.sigma_a_per_mm);
    assert!(close(k.dermis.sigma_a_per_mm, derm, 1e-12), "{} vs {derm}", k.dermis.sigma_a_per_mm);
    assert!(close(k.epidermis.sigma_s_prime_per_mm, sigma_s_epi, 1e-12));
    assert!(close(k.dermis.sigma_s_prime_per_mm, 0.5 * sigma_s_epi, 1e-12));
}

#[test]
fn coefficients_at_700_nm_match_hand_computation() {
    // Prahl 700 nm: HbO2 290, Hb 1794.28. Cm = 0.02, Chd = 0.2 → Che = 0.05.
    let l: f64 = 700.0;
    let melanin = 0.61 * 6.6e10 * l.powf(-3.33) + 0.39 * 2.9e14 * l.powf(-4.75);
    let baseline = 0.0244 + 8.53 * (-(700.0 - 154.0) / 66.2f64).exp();
    let hb = 0.75 * blood(290.0) + 0.25 * blood(1794.28);
    let epi = 0.02 * melanin + 0.05 * hb + 0.93 * baseline;
    let derm = 0.2 * hb + 0.8 * baseline;
    assert!(close(epi, 0.3820560836981762, 1e-12));
    assert!(close(derm, 0.09264095879745218, 1e-12));
    let k = SkinPhysiology::default().coefficients_at(l, 0.02, 0.2).unwrap();
    assert!(close(k.epidermis.sigma_a_per_mm, epi, 1e-12));
    assert!(close(k.dermis.sigma_a_per_mm, derm, 1e-12));
    assert!(close(k.epidermis.sigma_s_prime_per_mm, 4.404280371335495, 1e-12));
    assert!(close(k.dermis.sigma_s_prime_per_mm, 2.2021401856677474, 1e-12));
}

#[test]
fn rgb_at_representative_wavelengths_is_the_spectral_value() {
    // Wavelength reduction at 700 / 501 / 700 nm: each channel is exactly the hand-computed spectral coefficient.
    let p = SkinPhysiology::default();
    let rgb =
        two_layer_skin_rgb(&p, 0.1, 0.08, false, &RgbReduction::Wavelengths { nm: [700.0, 501.0, 700.0] }).unwrap();
    assert!(close(rgb.epidermis.sigma_a_per_mm[1], 6.095802049819503, 1e-12));
    assert!(close(rgb.dermis.sigma_a_per_mm[1], 0.9597439853293056, 1e-12));
    assert!(close(rgb.epidermis.sigma_s_prime_per_mm[1], 7.2463166361050515, 1e-12));
    assert_eq!(rgb.epidermis.sigma_a_per_mm[0], rgb.epidermis.sigma_a_per_mm[2]);
    assert_eq!(rgb.epidermis.thickness_mm, 0.25);
    assert_eq!(rgb.dermis.thickness_mm, 20.0);
    assert_eq!((rgb.epidermis.eta, rgb.dermis.eta, rgb.eta_below_dermis), (1.4, 1.4, 1.4));
}

#[test]
fn sensitivity_weighted_rgb_is_a_mean_of_the_spectrum() {
    // Each channel is a convex combination of the spectral values, so it lies within their range over the channel's
    // support; red sees less melanin and blood than green, green less than blue; σs′ falls with wavelength.
    let p = SkinPhysiology::default();
    let rgb = two_layer_skin_rgb(&p, 0.05, 0.05, false, &RgbReduction::default()).unwrap();
    let spectral: Vec<_> = (380..=780).map(|l| p.coefficients_at(l as f64, 0.05, 0.05).unwrap()).collect();
    let lo = spectral.iter().map(|k| k.epidermis.sigma_a_per_mm).fold(f64::INFINITY, f64::min);
    let hi = spectral.iter().map(|k| k.epidermis.sigma_a_per_mm).fold(0.0, f64::max);
    for c in 0..3 {
        assert!(lo <= rgb.epidermis.sigma_a_per_mm[c] && rgb.epidermis.sigma_a_per_mm[c] <= hi);
    }
    let (a, s) = (rgb.epidermis.sigma_a_per_mm, rgb.epidermis.sigma_s_prime_per_mm);
    assert!(a[0] < a[1] && a[1] < a[2], "{a:?}");
    assert!(s[0] < s[1] && s[1] < s[2], "{s:?}");
    assert!(rgb.dermis.sigma_a_per_mm[0] < rgb.dermis.sigma_a_per_mm[1], "{:?}", rgb.dermis.sigma_a_per_mm);
    for (d, e) in rgb.dermis.sigma_s_prime_per_mm.iter().zip(s) {
        assert!(close(*d, 0.5 * e, 1e-12));
    }

    // With no melanin and no blood the epidermis is pure baseline: its RGB σa is the weighted mean of the baseline
    // formula, computed here with the same weights.
    let w = RgbReduction::SensitivityWeighted { illuminant: Illuminant::D65 }.weights().unwrap();
    let base = |l: f64| 0.0244 + 8.53 * (-(l - 154.0) / 66.2).exp();
    let rgb0 = two_layer_skin_rgb(&p, 0.0, 0.0, false, &RgbReduction::default()).unwrap();
    for c in 0..3 {
        let sum_w: f64 = w.iter().map(|x| x.1[c]).sum();
        assert!((sum_w - 1.0).abs() < 1e-12);
        assert!(w.iter().all(|x| x.1[c] >= 0.0));
        let expect: f64 = w.iter().map(|(l, wc)| wc[c] * base(*l)).sum();
        assert!(close(rgb0.epidermis.sigma_a_per_mm[c], expect, 1e-12));
        assert!(close(rgb0.dermis.sigma_a_per_mm[c], expect, 1e-12));
    }
}

#[test]
fn out_of_range_inputs_are_rejected_by_name() {
    let p = SkinPhysiology::default();
    let e = two_layer_skin_rgb(&p, 0.6, 0.0, false, &RgbReduction::default()).unwrap_err();
    assert_eq!(e.param, "melanin_fraction");
    let e = two_layer_skin_rgb(&p, 0.1, f64::NAN, false, &RgbReduction::default()).unwrap_err();
    assert_eq!(e.param, "hemoglobin_fraction");
    assert!(two_layer_skin_rgb(&p, 0.6, 0.5, true, &RgbReduction::default()).is_ok());
    let bad = SkinPhysiology { epidermis_thickness_mm: -0.1, ..SkinPhysiology::default() };
    assert_eq!(bad.validate().unwrap_err().param, "epidermis_thickness_mm");
    let bad = SkinPhysiology { eta_dermis: 0.0, ..SkinPhysiology::default() };
    assert_eq!(bad.validate().unwrap_err().param, "eta_dermis");
    let e = two_layer_skin_rgb(&p, 0.1, 0.1, false, &RgbReduction::Wavelengths { nm: [1200.0, 500.0, 400.0] });
    assert_eq!(e.unwrap_err().param, "wavelengths_nm[0]");
}
