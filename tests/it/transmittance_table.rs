//! Transmittance table T(s) (thesis eq. 5.12): values, texel convention, shader lookup, encodings.

// Channel-index loops mirror the per-channel equations.
#![allow(clippy::needless_range_loop)]

use rtbake::diffusion::sum_of_gaussians::deon6;
use rtbake::fitting::RgbGaussians;
use rtbake::io::png::{decode, DecodedPng};
use rtbake::transmittance::{table, transmittance, TableSettings, TransmittanceForm};

fn sum() -> RgbGaussians {
    RgbGaussians::from(&deon6())
}

#[test]
fn published_form_starts_at_one_decreases_and_red_reaches_1e4_near_7mm() {
    let s = sum();
    let mut prev = [f64::INFINITY; 3];
    for i in 0..=400 {
        let t = transmittance(&s, i as f64 * 0.02, TransmittanceForm::Published);
        for c in 0..3 {
            assert!(t[c] <= prev[c] && t[c] >= 0.0);
        }
        prev = t;
    }
    // T(0) = Σ w per channel, = 1 for d'Eon's normalised preset.
    let t0 = transmittance(&s, 0.0, TransmittanceForm::Published);
    for c in 0..3 {
        let total: f64 = s.weights[c].iter().sum();
        assert!((t0[c] - total).abs() < 1e-15 && (total - 1.0).abs() < 1e-12);
    }
    let red7 = transmittance(&s, 7.0, TransmittanceForm::Published)[0];
    assert!(red7 > 0.5e-4 && red7 < 2e-4, "{red7}");
    // The physical form decays slower: exp(−s²/(2v)) ≥ exp(−s²/v).
    for i in 1..50 {
        let s_mm = i as f64 * 0.1;
        let p = transmittance(&s, s_mm, TransmittanceForm::Physical);
        let q = transmittance(&s, s_mm, TransmittanceForm::Published);
        for c in 0..3 {
            assert!(p[c] >= q[c]);
        }
    }
}

/// Linear filtering with clamp-to-edge at normalised coordinate u, as a GPU sampler does on a 1-D texture.
fn sample_linear(row: &[[f32; 3]], u: f64) -> [f64; 3] {
    let n = row.len();
    let x = (u * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
    let i = (x.floor() as usize).min(n - 2);
    let f = x - i as f64;
    [0, 1, 2].map(|c| row[i][c] as f64 * (1.0 - f) + row[i + 1][c] as f64 * f)
}

#[test]
fn node_inclusive_texels_and_documented_lookup_formula() {
    let settings = TableSettings { samples: 256, height: 4, s_max_mm: 8.0, form: TransmittanceForm::Published };
    let img = table(&sum(), &settings).unwrap();
    assert_eq!((img.width, img.height, img.channels), (256, 4, 3));
    for y in 1..4 {
        assert_eq!(img.row(y), img.row(0), "rows of the 2-D variant are identical");
    }
    let row: Vec<[f32; 3]> = img.row(0).chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
    for i in [0usize, 1, 100, 255] {
        let s_mm = 8.0 * i as f64 / 255.0;
        let t = transmittance(&sum(), s_mm, TransmittanceForm::Published);
        for c in 0..3 {
            assert_eq!(row[i][c], t[c] as f32);
        }
    }
    // u = s/s_max·(n−1)/n + 0.5/n hits the nodes exactly and interpolates between them.
    let n = 256.0;
    for s_mm in [0.0, 8.0 * 37.0 / 255.0, 8.0, 3.3] {
        let u = s_mm / 8.0 * (n - 1.0) / n + 0.5 / n;
        let got = sample_linear(&row, u);
        let exact = transmittance(&sum(), s_mm, TransmittanceForm::Published);
        for c in 0..3 {
            assert!(
                (got[c] - exact[c]).abs() < 2e-3 * exact[0].max(1e-3),
                "s {s_mm} c {c}: {} vs {}",
                got[c],
                exact[c]
            );
        }
    }
}

#[test]
fn linear16_png_stores_round_65535_t() {
    let settings = TableSettings { samples: 32, height: 1, s_max_mm: 4.0, form: TransmittanceForm::Physical };
    let img = table(&sum(), &settings).unwrap();
    let bytes = rtbake::io::png::encode_linear16(&img).unwrap();
    let DecodedPng::U16(back) = decode(&bytes, "t").unwrap() else { panic!("16-bit expected") };
    for (a, b) in back.data.iter().zip(&img.data) {
        assert_eq!(*a, (b.clamp(0.0, 1.0) * 65535.0).round() as u16);
    }
}

#[test]
fn invalid_settings_are_rejected_with_the_field_name() {
    for (settings, flag) in [
        (TableSettings { samples: 1, ..TableSettings::default() }, "samples"),
        (TableSettings { samples: 20000, ..TableSettings::default() }, "samples"),
        (TableSettings { s_max_mm: 0.0, ..TableSettings::default() }, "s_max_mm"),
        (TableSettings { s_max_mm: f64::NAN, ..TableSettings::default() }, "s_max_mm"),
        (TableSettings { height: 0, ..TableSettings::default() }, "height"),
    ] {
        let err = table(&sum(), &settings).unwrap_err().to_string();
        assert!(err.contains(flag), "{err}");
    }
}
