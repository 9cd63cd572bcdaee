//! Published numbers the sum-of-Gaussians fitter must reproduce (specs/sss-fitting.md §1; thesis eq. 2.2, Table 4.2;
//! d'Eon, Luebke, Enderton, EGSR 2007).

// Channel-index loops mirror the per-channel equations.
#![allow(clippy::needless_range_loop)]

use rtbake::diffusion::sum_of_gaussians::{deon4, deon6};
use rtbake::fitting::screen_space::blend_weights;
use rtbake::fitting::{error_table, fit_sum_of_gaussians, FitSettings, RgbGaussians};

fn assert_recovers(truth: &RgbGaussians, fit: &RgbGaussians) {
    for c in 0..3 {
        for (v, t) in fit.variances_mm2[c].iter().zip(&truth.variances_mm2[c]) {
            assert!(((v - t) / t).abs() < 1e-6, "channel {c}: variance {v} vs {t}");
        }
        for (w, t) in fit.weights[c].iter().zip(&truth.weights[c]) {
            if *t == 0.0 {
                assert!(w.abs() < 1e-9, "channel {c}: weight {w} should be 0");
            } else {
                assert!(((w - t) / t).abs() < 1e-6, "channel {c}: weight {w} vs {t}");
            }
        }
    }
}

#[test]
fn shared_six_gaussian_fit_recovers_deon6() {
    // The starts are derived from the profile's energy quantiles (a generic geometric spread), not from the answer.
    let truth = RgbGaussians::from(&deon6());
    let settings = FitSettings { count: 6, shared_variances: true, normalize: false, starts: 8 };
    let fit = fit_sum_of_gaussians(&deon6(), &settings).unwrap();
    assert_recovers(&truth, &fit.sum);
    assert!(fit.error_percent.iter().all(|e| *e < 1e-6), "{:?}", fit.error_percent);
}

#[test]
fn shared_four_gaussian_fit_recovers_deon4_with_normalisation() {
    let truth = deon4();
    let totals: Vec<f64> = (0..3).map(|c| truth.weights.iter().map(|w| w[c]).sum()).collect();
    let settings = FitSettings { count: 4, shared_variances: true, normalize: true, starts: 8 };
    let fit = fit_sum_of_gaussians(&truth, &settings).unwrap();
    // Normalised: weights are the preset's divided by each channel's total.
    let mut expect = RgbGaussians::from(&truth);
    for c in 0..3 {
        expect.weights[c].iter_mut().for_each(|w| *w /= totals[c]);
    }
    assert_recovers(&expect, &fit.sum);
}

#[test]
fn per_channel_fit_recovers_per_channel_variances() {
    let truth = RgbGaussians {
        variances_mm2: [vec![0.02, 0.9], vec![0.05, 3.0], vec![0.01, 0.2]],
        weights: [vec![0.3, 0.5], vec![0.6, 0.1], vec![0.2, 0.05]],
    };
    let settings = FitSettings { count: 2, shared_variances: false, normalize: false, starts: 4 };
    let fit = fit_sum_of_gaussians(&truth, &settings).unwrap();
    assert_recovers(&truth, &fit.sum);
}

#[test]
fn jensen_error_table_spans_deon_range() {
    let rows = error_table().unwrap();
    assert_eq!(rows.len(), 11);
    let get = |name: &str, c: usize| rows.iter().find(|r| r.material == name).unwrap().error_percent[c];
    let cream_r = get("cream", 0);
    let chicken2_b = get("chicken2", 2);
    // d'Eon et al. 2007: "errors between 1.52 and 0.0793 percent"; within 0.02 percentage points of both ends,
    // and of the spec's values for this metric (≈ 1.50 %, ≈ 0.0794 %).
    assert!((cream_r - 1.52).abs() <= 0.02 && (cream_r - 1.50).abs() <= 0.02, "cream red {cream_r}");
    assert!((chicken2_b - 0.0793).abs() <= 0.02 && (chicken2_b - 0.0794).abs() <= 0.001, "chicken2 blue {chicken2_b}");
    for r in &rows {
        for c in 0..3 {
            let e = r.error_percent[c];
            if r.material == "ketchup" && c > 0 {
                // The near-black Ketchup G, B fit even better (≈ 0.03 %), below d'Eon's range.
                assert!(e < chicken2_b && e > 0.0, "ketchup {c}: {e}");
            } else {
                assert!(e <= cream_r && e >= chicken2_b, "{} {c}: {e} outside [{chicken2_b}, {cream_r}]", r.material);
            }
        }
    }
}

/// Thesis Table 4.2, w′ columns (rows by ascending variance; R, G, B).
const TABLE_4_2_DEON4: [[f64; 3]; 4] =
    [[1.0, 1.0, 1.0], [0.3251, 0.45, 0.3583], [0.34, 0.1864, 0.0], [0.46, 0.0, 0.0402]];
const TABLE_4_2_DEON6: [[f64; 3]; 6] = [
    [1.0, 1.0, 1.0],
    [0.3, 0.424, 0.346],
    [0.261, 0.2, 0.0],
    [0.2, 0.007, 0.007],
    [0.388, 0.004, 0.0],
    [0.078, 0.0, 0.0],
];

/// Digits after the decimal point of a printed value (the table prints 3–4 digits, trailing zeros dropped).
fn printed_unit(v: f64, max_digits: i32) -> f64 {
    let mut d = 0;
    while d < max_digits && ((v * 10f64.powi(d)).round() - v * 10f64.powi(d)).abs() > 1e-9 {
        d += 1;
    }
    10f64.powi(-d.max(1))
}

fn check_table(sum: &rtbake::diffusion::sum_of_gaussians::SumOfGaussians, table: &[[f64; 3]], digits: i32) {
    let rgb = RgbGaussians::from(sum);
    for c in 0..3 {
        let bw = blend_weights(&rgb.weights[c]);
        for (i, row) in table.iter().enumerate() {
            // The printed values are rounded or truncated to their last digit (e.g. 0.336/0.791 = 0.42478 is
            // printed 0.424), so agreement is within one unit of the last printed digit.
            let unit = printed_unit(row[c], digits).min(10f64.powi(-(digits - 1)));
            assert!((bw[i] - row[c]).abs() < unit, "row {i} channel {c}: {} vs printed {}", bw[i], row[c]);
        }
    }
}

#[test]
fn screen_space_blend_weights_reproduce_thesis_table_4_2() {
    check_table(&deon4(), &TABLE_4_2_DEON4, 4);
    check_table(&deon6(), &TABLE_4_2_DEON6, 3);
}
