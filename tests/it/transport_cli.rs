//! `rtbake transport`: output contracts (CSV in the profile layout, JSON with standard errors, plot), agreement
//! with the library, determinism, and bad input (exit 2 naming the flag or field, nothing written).

use rtbake::diffusion::materials;
use rtbake::transport::{simulate, McSettings, McStack};
use serde_json::Value;

use crate::support::rtbake;

fn ok(args: &[&str]) -> std::process::Output {
    let out = rtbake(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// Equal up to the last bit that serde_json's default float parsing may round differently.
fn same(a: &Value, b: f64) -> bool {
    let a = a.as_f64().unwrap();
    (a - b).abs() <= 1e-14 * b.abs()
}

fn json(args: &[&str]) -> Value {
    serde_json::from_slice(&ok(args).stdout).expect("one JSON object on stdout")
}

const SMALL: [&str; 8] = ["--photons", "2000", "--seed", "7", "--bin-mm", "0.2", "--bins", "20"];

#[test]
fn json_matches_the_library_and_repeats_exactly() {
    let args: Vec<&str> = ["transport", "--material", "skin1", "--json", "-q"].into_iter().chain(SMALL).collect();
    let (a, b) = (json(&args), json(&args));
    assert_eq!(a, b, "same seed, same result");
    let m = materials::find("skin1").unwrap();
    let stack = McStack::semi_infinite(m.sigma_a_per_mm, m.sigma_s_prime_per_mm, 0.0, 1.3).unwrap();
    let lib = simulate(&stack, &McSettings::new(2000, 7, 10, 0.2, 20).unwrap());
    for c in 0..3 {
        assert!(same(&a["total_R"][c]["mean"], lib.channels[c].diffuse_reflectance.mean));
        assert!(same(&a["total_R"][c]["se"], lib.channels[c].diffuse_reflectance.se));
        assert!(same(&a["R"][3][c], lib.channels[c].reflectance_mm2[3].mean));
        assert!(same(&a["R_se"][3][c], lib.channels[c].reflectance_mm2[3].se));
        assert!((a["specular_R"][c].as_f64().unwrap() - (0.3f64 / 2.3).powi(2)).abs() < 1e-15);
    }
    assert_eq!(a["r_mm"].as_array().unwrap().len(), 20);
    assert!(a.get("T").is_none(), "a semi-infinite medium transmits nothing");
    let cmp = &a["diffusion_comparison"]["channels"][0];
    assert!(cmp["total_r_diffusion"].as_f64().unwrap() > 0.0, "{cmp}");
    let other = json(&["transport", "--material", "skin1", "--json", "-q", "--photons", "2000", "--seed", "8"]);
    assert_ne!(a["total_R"], other["total_R"]);
}

#[test]
fn csv_has_the_profile_layout_and_plot_overlays_diffusion() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, plot, out) = (dir.path().join("mc.csv"), dir.path().join("mc.svg"), dir.path().join("mc.json"));
    let args: Vec<&str> = [
        "transport",
        "--material",
        "apple",
        "--thickness-mm",
        "2",
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]
    .into_iter()
    .chain(SMALL)
    .collect();
    ok(&args);
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows[0], "r_mm,R_r,R_g,R_b,T_r,T_g,T_b", "the header of `rtbake profile --csv` for slabs");
    assert_eq!(rows.len(), 21);
    let parsed: Vec<Vec<f64>> = rows[1..].iter().map(|r| r.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    for (i, row) in parsed.iter().enumerate() {
        assert_eq!(row.len(), 7);
        assert!((row[0] - (i as f64 + 0.5) * 0.2).abs() < 1e-12, "bin centre {i}: {}", row[0]);
        assert!(row.iter().all(|v| v.is_finite() && *v >= 0.0));
    }
    // The same header as `rtbake profile --csv` (what the fits' --profile-csv reads).
    let pcsv = dir.path().join("p.csv");
    ok(&[
        "profile",
        "--material",
        "apple",
        "--model",
        "multipole",
        "--thickness-mm",
        "2",
        "--csv",
        pcsv.to_str().unwrap(),
        "-q",
    ]);
    let ptext = std::fs::read_to_string(&pcsv).unwrap();
    assert_eq!(ptext.lines().find(|l| !l.starts_with('#')), Some(rows[0]));
    // The CSV values are the JSON's; the JSON has the standard errors and the slab's transmittance.
    let v: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert!(same(&v["R"][5][1], parsed[5][2]));
    assert!(same(&v["T"][5][2], parsed[5][6]));
    assert!(v["T_se"][5][2].as_f64().unwrap() > 0.0);
    let svg = std::fs::read_to_string(&plot).unwrap();
    for needle in ["Monte Carlo R", "multipole B", "r (mm)", "R(r) (1/mm^2)", "apple (2 mm slab)"] {
        assert!(svg.contains(needle), "plot lacks {needle:?}");
    }
}

#[test]
fn layer_files_of_rtbake_profile_and_skin_are_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("stack.json");
    std::fs::write(
        &p,
        r#"{"eta_above": 1.0, "eta_below": 1.0, "layers": [
  {"thickness_mm": 0.25, "eta": 1.4, "sigma_a": [0.2, 0.5, 1.2], "sigma_s_prime": [5, 6, 7]},
  {"thickness_mm": 3.0, "eta": 1.38, "sigma_a": [0.02, 0.06, 0.12], "sigma_s_prime": [1.5, 2, 2.5]}]}"#,
    )
    .unwrap();
    let v = json(&["transport", "--layers", p.to_str().unwrap(), "--json", "-q", "--photons", "500", "--bins", "10"]);
    let abs = v["absorbed_per_layer"][0].as_array().unwrap();
    assert_eq!(abs.len(), 2);
    for c in 0..3 {
        let total = v["specular_R"][c].as_f64().unwrap()
            + v["total_R"][c]["mean"].as_f64().unwrap()
            + v["total_T"][c]["mean"].as_f64().unwrap()
            + v["absorbed_per_layer"][c].as_array().unwrap().iter().map(|a| a["mean"].as_f64().unwrap()).sum::<f64>();
        assert!((total - 1.0).abs() < 0.05, "energy {total}");
    }
    let s = json(&[
        "transport",
        "--skin-melanin",
        "0.1",
        "--skin-hemoglobin",
        "0.05",
        "--json",
        "-q",
        "--photons",
        "300",
        "--bins",
        "10",
    ]);
    assert_eq!(s["provenance"]["skin"]["melanin_fraction"], 0.1);
    assert_eq!(s["absorbed_per_layer"][0].as_array().unwrap().len(), 2);
}

#[test]
fn bad_input_exits_2_naming_the_flag_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("x.csv");
    let bad_stack = dir.path().join("bad.json");
    std::fs::write(&bad_stack, r#"{"layers": [{"thickness_mm": 1, "eta": 0.9, "sigma_a": 1, "sigma_s": 1}]}"#).unwrap();
    let g_stack = dir.path().join("g.json");
    std::fs::write(
        &g_stack,
        r#"{"layers": [{"thickness_mm": 1, "eta": 1.3, "sigma_a": 1, "sigma_s": 1, "g": [0, 1, 0]}]}"#,
    )
    .unwrap();
    let empty = dir.path().join("empty.json");
    std::fs::write(&empty, r#"{"layers": []}"#).unwrap();
    let nan = dir.path().join("nan.json");
    std::fs::write(&nan, r#"{"layers": [{"thickness_mm": 1, "eta": 1.3, "sigma_a": -1, "sigma_s": 1}]}"#).unwrap();
    let (b, g, e, n) =
        (bad_stack.to_str().unwrap(), g_stack.to_str().unwrap(), empty.to_str().unwrap(), nan.to_str().unwrap());
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--material", "skin1", "--photons", "0"], "--photons"),
        (vec!["--material", "skin1", "--photons", "20000000000"], "--photons"),
        (vec!["--material", "skin1", "--bins", "0"], "--bins"),
        (vec!["--material", "skin1", "--bin-mm", "1e-9"], "--bin-mm"),
        (vec!["--material", "skin1", "--batches", "1"], "--batches"),
        (vec!["--material", "skin1", "--g", "1"], "--g"),
        (vec!["--material", "skin1", "--thickness-mm", "-1"], "--thickness-mm"),
        (vec!["--material", "nosuch"], "--material"),
        (vec!["--layers", b], "layers[0].eta"),
        (vec!["--layers", g], "layers[0].g[1]"),
        (vec!["--layers", e], "layers"),
        (vec!["--layers", n], "layers[0].sigma_a[0]"),
        (vec!["--skin-melanin", "0.9", "--skin-hemoglobin", "0.1"], "--skin-melanin"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["transport", "--csv", csv.to_str().unwrap()];
        args.extend(extra);
        let out = rtbake(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?} should name {needle}: {err}");
        assert!(!csv.exists(), "{args:?} wrote its output");
    }
    // With --json the error is one object on stdout.
    let out = rtbake(&["transport", "--material", "skin1", "--photons", "0", "--json"]);
    assert_eq!(out.status.code(), Some(2));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["error"].as_str().unwrap().contains("--photons"), "{v}");
}

/// The committed `transport-report`: every case, g, channel and model; the dipole's totals within a few per cent of
/// Monte Carlo wherever the reduced albedo exceeds 0.99 (diffusion's regime), further off at low albedo; for skins
/// the spectral multipole above the spectral Monte Carlo everywhere, the tissue-like g darkening the transport
/// (σs′ kept), and symmetric and directional adding equal on the one-layer dermis.
#[test]
fn baked_transport_report_shows_where_diffusion_holds() {
    let path = crate::support::baked_dir().join(rtbake::baked_layout::path::TRANSPORT_REPORT_CSV);
    let text = std::fs::read_to_string(&path).unwrap();
    let rows: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
    // 11 materials × 3 channels; (3 baked skins + 4 × 4 grid + 1 dermis) × 2 g × 3 models × 3 channels.
    assert_eq!(rows.len(), 11 * 3 + 20 * 2 * 3 * 3);
    let num = |r: &[&str], i: usize| -> f64 { r[i].parse().unwrap() };
    let (mut high, mut low) = (0, 0);
    let mut mc = std::collections::HashMap::new();
    for r in &rows {
        let (albedo, total, se, diff) = (num(r, 5), num(r, 6), num(r, 7), num(r, 11));
        let rel_se = 100.0 * se / total;
        assert!(total > 0.0 && se > 0.0 && rel_se < 20.0, "{r:?}");
        if r[9] == "dipole" {
            if albedo > 0.99 {
                high += 1;
                assert!(diff.abs() < 2.0 + 3.0 * rel_se, "{r:?}");
            }
            if albedo < 0.8 {
                low += 1;
                assert!(diff > 5.0, "the dipole overestimates total R at low albedo: {r:?}");
            }
        } else {
            mc.insert((r[0], r[3], r[4]), (total, se));
        }
        if r[9] == "spectral-multipole" {
            assert!(diff > rel_se, "the multipole is brighter than transport: {r:?}");
        }
    }
    assert!(high >= 15 && low >= 5, "{high} high-albedo rows, {low} low-albedo rows");
    for (&(case, g, ch), &(t, se)) in &mc {
        if g != "0" {
            let (t0, se0) = mc[&(case, "0", ch)];
            assert!(t < t0 + 3.0 * (se * se + se0 * se0).sqrt(), "{case} {ch}: g = {g} gives {t}, g = 0 {t0}");
        }
    }
    let dermis: Vec<&Vec<&str>> = rows.iter().filter(|r| r[0].starts_with("skin/dermis_only")).collect();
    assert_eq!(dermis.len(), 2 * 3 * 3);
    for r in dermis.iter().filter(|r| r[9] == "multipole-symmetric") {
        let d = dermis.iter().find(|d| d[9] == "multipole-directional" && d[3] == r[3] && d[4] == r[4]).unwrap();
        assert_eq!(r[10], d[10], "one layer: both addings are the slab");
    }
}
