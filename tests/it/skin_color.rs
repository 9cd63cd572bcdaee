//! The spectral skin-colour model and its LUT against the expected appearance of `specs/skin-color.md`, physical
//! invariants and determinism.

use rtbake::diffusion::multipole::{Series, Slab};
use rtbake::diffusion::FdrForm;
use rtbake::skin_color::lut::{bake_lut, IndexForm, LutEvaluation, LutLayout};
use rtbake::skin_color::two_layer::{Adding, ThinLayer};
use rtbake::skin_color::SkinColorParams;
use rtbake::spectral::colorimetry::{srgb8, ColorWeights, Illuminant, SpectralGrid};
use rtbake::spectral::skin_layers::SkinPhysiology;

fn rgb(p: &SkinColorParams, cm: f64, chd: f64) -> [f64; 3] {
    p.model().unwrap().evaluate(cm, chd, false).unwrap().linear_rgb
}

fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

fn assert_srgb8_near(got: [u8; 3], want: [u8; 3], tol: i32) {
    for c in 0..3 {
        assert!((got[c] as i32 - want[c] as i32).abs() <= tol, "sRGB8 {got:?}, expected {want:?} ± {tol}");
    }
}

#[test]
fn corners_match_the_published_appearance() {
    let p = SkinColorParams::default();
    let m = p.model().unwrap();
    // Zero concentrations: pale cream ≈ (221, 216, 203). This implementation gives exactly (221, 216, 203).
    let pale = m.evaluate(0.0, 0.0, false).unwrap();
    assert_srgb8_near(pale.srgb8, [221, 216, 203], 2);
    // Cm = 0.5: near-black brown ≈ (52, 43, 36); this implementation: (52, 43, 36).
    let dark = m.evaluate(0.5, 0.0, false).unwrap();
    assert_srgb8_near(dark.srgb8, [52, 43, 36], 2);
    // Along hemoglobin R/G rises from ≈ 1.05 to ≈ 1.9 (here 1.054 → 1.934).
    let flushed = m.evaluate(0.0, 0.32, false).unwrap();
    let rg = |c: [f64; 3]| c[0] / c[1];
    assert!((rg(pale.linear_rgb) - 1.05).abs() < 0.03, "R/G at Chd 0: {}", rg(pale.linear_rgb));
    assert!((rg(flushed.linear_rgb) - 1.9).abs() < 0.08, "R/G at Chd 0.32: {}", rg(flushed.linear_rgb));
    // srgb8 is the sRGB encoding of linear_rgb.
    assert_eq!(pale.srgb8, srgb8(pale.linear_rgb));
}

#[test]
fn lut_brightness_is_monotone_along_both_axes_and_redness_rises_with_hemoglobin() {
    let p = SkinColorParams { width: 24, height: 20, spectral_step_nm: 2, ..SkinColorParams::default() };
    let layout = p.layout().unwrap();
    let img = bake_lut(&p.model().unwrap(), &layout, LutEvaluation::Tabulated).unwrap();
    let px = |i: u32, j: u32| -> [f64; 3] { [0, 1, 2].map(|c| img.get(i, j, c) as f64) };
    for j in 0..layout.height {
        for i in 1..layout.width {
            assert!(luminance(px(i, j)) < luminance(px(i - 1, j)), "melanin axis not darker at ({i}, {j})");
        }
    }
    for i in 0..layout.width {
        for j in 1..layout.height {
            assert!(luminance(px(i, j)) < luminance(px(i, j - 1)), "hemoglobin axis not darker at ({i}, {j})");
        }
    }
    // Redness (R/G) rises with hemoglobin at low melanin, and fades as melanin rises.
    let rg = |c: [f64; 3]| c[0] / c[1];
    for j in 1..layout.height {
        assert!(rg(px(0, j)) > rg(px(0, j - 1)));
    }
    let (h, w) = (layout.height - 1, layout.width - 1);
    assert!(rg(px(w, h)) - rg(px(w, 0)) < 0.25 * (rg(px(0, h)) - rg(px(0, 0))), "redness should fade with melanin");
}

#[test]
fn perfect_white_reflector_maps_to_unit_rgb() {
    let w = ColorWeights::new(SpectralGrid::new(1).unwrap(), Illuminant::D65);
    let white = w.linear_srgb_of(&vec![1.0; w.grid.len()]);
    for c in white {
        assert!((c - 1.0).abs() < 1e-3, "{white:?}");
    }
    assert!((w.xyz_of(&vec![1.0; w.grid.len()])[1] - 1.0).abs() < 1e-12);
}

#[test]
fn stack_reflectance_at_one_wavelength_is_the_adding_formula_over_the_multipole_totals() {
    // Rebuild R(λ) at 550 nm for (Cm, Chd) = (0.05, 0.1) by hand from the layer coefficients and Slab::totals.
    let p = SkinColorParams { spectral_step_nm: 10, ..SkinColorParams::default() };
    let m = p.model().unwrap();
    let s = m.evaluate(0.05, 0.1, false).unwrap();
    let i = m.wavelengths_nm().iter().position(|&l| l == 550.0).unwrap();
    let k = SkinPhysiology::default().coefficients_at(550.0, 0.05, 0.1).unwrap();
    let epi =
        Slab::new(k.epidermis.sigma_a_per_mm, k.epidermis.sigma_s_prime_per_mm, 0.25, 1.4, 1.0, FdrForm::Dj05).unwrap();
    let derm =
        Slab::new(k.dermis.sigma_a_per_mm, k.dermis.sigma_s_prime_per_mm, 20.0, 1.0, 1.0, FdrForm::Dj05).unwrap();
    let (r1, t1) = epi.totals(Series::Exact);
    let (r2, _) = derm.totals(Series::Exact);
    let expect = r1 + t1 * t1 * r2 / (1.0 - r1 * r2);
    assert!((s.reflectance[i] - expect).abs() < 1e-14, "{} vs {expect}", s.reflectance[i]);

    // Directional adding uses the epidermis lit from below.
    let pd = SkinColorParams { adding: Adding::Directional, ..p.clone() };
    let sd = pd.model().unwrap().evaluate(0.05, 0.1, false).unwrap();
    let (r1u, t1u) = epi.flipped().totals(Series::Exact);
    let expect_d = r1 + t1 * r2 * t1u / (1.0 - r1u * r2);
    assert!((sd.reflectance[i] - expect_d).abs() < 1e-14);
    // `specs/diffusion.md`: the two variants differ by up to ~20 % for skin. Here the directional form is darker,
    // most at the pale corner (−16 % in luminance), and identical where the epidermis is opaque (Cm = 0.5).
    let (m_sym, m_dir) = (p.model().unwrap(), pd.model().unwrap());
    let rel = |cm: f64, chd: f64| {
        let (a, b) = (m_sym.evaluate(cm, chd, false).unwrap(), m_dir.evaluate(cm, chd, false).unwrap());
        (luminance(b.linear_rgb) - luminance(a.linear_rgb)) / luminance(a.linear_rgb)
    };
    assert!((-0.2..-0.1).contains(&rel(0.0, 0.0)), "pale corner: {}", rel(0.0, 0.0));
    assert!(rel(0.5, 0.0).abs() < 1e-3, "dark corner: {}", rel(0.5, 0.0));
}

#[test]
fn tabulated_lut_matches_direct_evaluation() {
    // Covers the full Table 7.1 box (corners included) at 1 nm; the literal form covers the wider [0, 1]² box.
    for form in [IndexForm::NormalizedCbrt, IndexForm::LiteralCbrt] {
        for adding in [Adding::Symmetric, Adding::Directional] {
            let p = SkinColorParams { width: 9, height: 7, index_form: form, adding, ..SkinColorParams::default() };
            let m = p.model().unwrap();
            let layout = p.layout().unwrap();
            let a = bake_lut(&m, &layout, LutEvaluation::Tabulated).unwrap();
            let b = bake_lut(&m, &layout, LutEvaluation::Direct).unwrap();
            let max = a.data.iter().zip(&b.data).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
            assert!(max < 1e-7, "{form:?} {adding:?}: tabulated vs direct differ by {max}");
        }
    }
}

#[test]
fn lut_texels_equal_point_evaluation_at_their_nodes() {
    let p = SkinColorParams { width: 5, height: 4, lut_evaluation: LutEvaluation::Direct, ..Default::default() };
    let m = p.model().unwrap();
    let layout = p.layout().unwrap();
    let img = bake_lut(&m, &layout, LutEvaluation::Direct).unwrap();
    for (i, j) in [(0, 0), (4, 0), (0, 3), (2, 1), (4, 3)] {
        let (cm, chd) = (layout.melanin_at_column(i), layout.hemoglobin_at_row(j));
        let s = m.evaluate(cm, chd, false).unwrap();
        for c in 0..3 {
            assert!((img.get(i, j, c) as f64 - s.linear_rgb[c as usize]).abs() < 1e-6);
        }
    }
    // Row 0 is Chd = 0, the last column is Cm = 0.5, the last row Chd = 0.32.
    assert_eq!(layout.hemoglobin_at_row(0), 0.0);
    assert_eq!(layout.melanin_at_column(4), 0.5);
    assert!((layout.hemoglobin_at_row(3) - 0.32).abs() < 1e-15);
}

#[test]
fn index_mapping_round_trips_and_follows_eq_7_7() {
    let l = LutLayout::new(256, 128, IndexForm::NormalizedCbrt).unwrap();
    for i in [0u32, 1, 17, 128, 255] {
        let cm = l.melanin_at_column(i);
        let (u, _) = l.texcoord(cm, 0.0);
        assert!((u * 256.0 - 0.5 - i as f64).abs() < 1e-9, "column {i}: texcoord {u}");
    }
    for j in [0u32, 5, 64, 127] {
        let (_, v) = l.texcoord(0.0, l.hemoglobin_at_row(j));
        assert!((v * 128.0 - 0.5 - j as f64).abs() < 1e-9);
    }
    // Eq. 7.7 normalised: u = cbrt(Cm / 0.5). Half the columns cover Cm < 0.5/8 = 0.0625.
    assert!((l.uv(0.0625, 0.04).0 - 0.5).abs() < 1e-12);
    assert!((l.uv(0.0625, 0.04).1 - 0.5).abs() < 1e-12);
    let lit = LutLayout::new(64, 64, IndexForm::LiteralCbrt).unwrap();
    assert!((lit.uv(0.125, 0.008).0 - 0.5).abs() < 1e-12 && (lit.uv(0.125, 0.008).1 - 0.2).abs() < 1e-12);
    assert!(LutLayout::new(1, 64, IndexForm::NormalizedCbrt).is_err());
    assert!(LutLayout::new(64, 1_000_000, IndexForm::NormalizedCbrt).is_err());
}

#[test]
fn lut_bytes_do_not_depend_on_the_thread_count() {
    let p = SkinColorParams { width: 33, height: 29, ..SkinColorParams::default() };
    let bake = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| rtbake::bake::skin::skin_color_lut_files(&p).unwrap())
    };
    let one = bake(1);
    for threads in [2, 5] {
        let many = bake(threads);
        assert_eq!(one.len(), many.len());
        for (a, b) in one.iter().zip(&many) {
            assert_eq!(a.path, b.path);
            assert!(a.bytes == b.bytes, "{} differs between 1 and {threads} threads", a.path);
        }
    }
}

/// The default 256² table at 1 nm (the vectorised tabulated path) against the committed bake of `baked/skin/`
/// (baked before the loop was vectorised, with the Lagrange form of the interpolation): within the asset's verify
/// tolerance `LUT_TOLERANCE` = 1e-6, and the same bits on 1 and 2 threads.
#[test]
fn default_lut_matches_the_committed_bake_within_the_verify_tolerance_on_any_thread_count() {
    let dir = crate::support::baked_dir();
    let manifest = rtbake::manifest::Manifest::load(&dir).unwrap();
    let record = manifest.assets.iter().find(|a| a.name == "skin-color-lut").expect("skin-color-lut is baked");
    let p: SkinColorParams = serde_json::from_value(record.params.clone()).unwrap();
    assert_eq!(p, SkinColorParams::default(), "the committed bake uses the default parameters");
    let bytes = std::fs::read(dir.join("skin/skin_color_lut.exr")).unwrap();
    let (baked, _) = rtbake::io::exr::decode(&bytes, "skin/skin_color_lut.exr").unwrap();
    let (model, layout) = (p.model().unwrap(), p.layout().unwrap());
    let bake = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| bake_lut(&model, &layout, LutEvaluation::Tabulated).unwrap())
    };
    let (one, two) = (bake(1), bake(2));
    assert!(
        one.data.iter().zip(&two.data).all(|(a, b)| a.to_bits() == b.to_bits()),
        "1 and 2 threads give different tables"
    );
    assert_eq!((baked.width, baked.height, baked.channels), (one.width, one.height, one.channels));
    let max = one.data.iter().zip(&baked.data).map(|(a, b)| (*a as f64 - *b as f64).abs()).fold(0.0f64, f64::max);
    eprintln!("max |new - baked| = {max:e} (linear RGB)");
    assert!(max <= rtbake::bake::skin::LUT_TOLERANCE, "max |new - baked| = {max:e}");
}

#[test]
fn spectral_step_and_dermis_bottom_sensitivities_are_as_documented() {
    let base = SkinColorParams::default();
    let coarse = SkinColorParams { spectral_step_nm: 5, ..base.clone() };
    let air_below = SkinColorParams { eta_below_dermis: 1.0, ..base.clone() };
    for (cm, chd) in [(0.0, 0.0), (0.05, 0.05), (0.5, 0.32), (0.01, 0.32)] {
        let a = rgb(&base, cm, chd);
        let b = rgb(&coarse, cm, chd);
        let c = rgb(&air_below, cm, chd);
        for ch in 0..3 {
            // 5 nm instead of 1 nm: ≤ 0.25 % (spec).
            assert!(((b[ch] - a[ch]) / a[ch]).abs() <= 2.5e-3, "5 nm step at ({cm}, {chd}): {a:?} vs {b:?}");
            // The 20 mm dermis is effectively semi-infinite: an air gap below changes < 1e-4.
            assert!((c[ch] - a[ch]).abs() < 1e-4, "bottom face at ({cm}, {chd}): {a:?} vs {c:?}");
        }
    }
    // Che = 0 instead of 0.25·Chd changes blue strongly at high hemoglobin (spec: up to 150 %).
    let no_che = SkinColorParams { epidermal_hemoglobin_ratio: 0.0, ..base.clone() };
    let (a, b) = (rgb(&base, 0.0, 0.32), rgb(&no_che, 0.0, 0.32));
    assert!(b[2] / a[2] > 1.5, "blue without Che: {} vs {}", b[2], a[2]);
    // Equal-energy illuminant: a different white, up to ~20 %.
    let e = SkinColorParams { illuminant: Illuminant::EqualEnergy, ..base.clone() };
    let (a, b) = (rgb(&base, 0.0, 0.0), rgb(&e, 0.0, 0.0));
    let max_rel = (0..3).map(|c| ((b[c] - a[c]) / a[c]).abs()).fold(0.0, f64::max);
    assert!(max_rel > 0.02 && max_rel < 0.3, "equal-energy changes the pale corner by {max_rel}");
}

#[test]
fn thin_epidermis_is_rejected_or_clamped_on_request() {
    // 0.2 mm is thinner than 1/σt′ above ~630 nm without melanin.
    let p = SkinColorParams { epidermis_thickness_mm: 0.2, width: 4, height: 4, ..SkinColorParams::default() };
    let m = p.model().unwrap();
    let err = bake_lut(&m, &p.layout().unwrap(), LutEvaluation::Tabulated).unwrap_err();
    let msg = err.to_string();
    assert!(msg.starts_with("epidermis_thickness_mm must exceed"), "{msg}");
    assert!(msg.contains("780 nm"), "the worst wavelength is the red end: {msg}");
    let clamp = SkinColorParams { thin_layer: ThinLayer::ClampTransmittance, ..p };
    let img = bake_lut(&clamp.model().unwrap(), &clamp.layout().unwrap(), LutEvaluation::Tabulated).unwrap();
    assert!(img.data.iter().all(|v| v.is_finite() && *v >= 0.0));
    // The published 0.25 mm is valid everywhere (l = 0.2484 mm at 780 nm without melanin).
    let ok = SkinColorParams { width: 4, height: 4, ..SkinColorParams::default() };
    assert!(bake_lut(&ok.model().unwrap(), &ok.layout().unwrap(), LutEvaluation::Tabulated).is_ok());
}

#[test]
fn default_asset_round_trips_its_parameters_and_decodes() {
    let asset = rtbake::bake::registry().into_iter().find(|a| a.name == "skin-color-lut").expect("registered");
    let params = (asset.default_params)();
    let parsed: SkinColorParams = serde_json::from_value(params.clone()).unwrap();
    assert_eq!(parsed, SkinColorParams::default());
    assert_eq!(serde_json::to_value(&parsed).unwrap(), params);
    // A typo in the parameters is an error, not a silent default.
    let mut typo = params.clone();
    typo["melanin_blnd"] = serde_json::json!(0.7);
    assert!((asset.bake)(&typo).is_err());
    // Small bake through the registry: EXR decodes to the samples the CSV states at the nodes it shares.
    let mut small = params;
    small["width"] = serde_json::json!(3);
    small["height"] = serde_json::json!(2);
    let files = (asset.bake)(&small).unwrap();
    let exr = files.iter().find(|f| f.path == "skin/skin_color_lut.exr").unwrap();
    let (img, _) = rtbake::io::exr::decode(&exr.bytes, &exr.path).unwrap();
    assert_eq!((img.width, img.height, img.channels), (3, 2, 3));
    let csv = std::str::from_utf8(&files.iter().find(|f| f.path == "skin/skin_color_samples.csv").unwrap().bytes)
        .unwrap()
        .to_string();
    let corner: Vec<&str> = csv.lines().find(|l| l.starts_with("0.5,0.32,")).unwrap().split(',').collect();
    for c in 0..3 {
        let v: f64 = corner[4 + c].parse().unwrap();
        assert!((img.get(2, 1, c as u32) as f64 - v).abs() < 1e-6);
    }
    let sidecar: serde_json::Value =
        serde_json::from_slice(&files.iter().find(|f| f.path == "skin/skin_color_lut.json").unwrap().bytes).unwrap();
    assert_eq!(sidecar["parameters"]["width"], 3);
    assert_eq!(sidecar["index"]["hemoglobin_max"], 0.32);
    let png = files.iter().find(|f| f.path == "skin/skin_color_lut_preview_srgb.png").unwrap();
    assert_eq!(png.meta.color_space.as_str(), "srgb");
    assert!(files.iter().filter(|f| f.meta.kind.as_str() == "lut").all(|f| f.meta.color_space.as_str() == "linear"));
}
