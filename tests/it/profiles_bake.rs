//! The `diffusion-profiles` bake asset: what it writes, that its tables are `rtbake profile`'s, that the totals are
//! the closed-form dipole totals, and that its bytes do not depend on the thread count.

use rtbake::bake::{registry, BakedFile};
use rtbake::diffusion::materials::JENSEN_2001;
use serde_json::Value;
use std::process::Command;

fn bake(params: &Value) -> Vec<BakedFile> {
    let asset = registry().into_iter().find(|a| a.name == "diffusion-profiles").expect("asset registered");
    (asset.bake)(params).expect("bakes")
}

fn default_params() -> Value {
    (registry().into_iter().find(|a| a.name == "diffusion-profiles").unwrap().default_params)()
}

fn file<'a>(files: &'a [BakedFile], path: &str) -> &'a BakedFile {
    files.iter().find(|f| f.path == path).unwrap_or_else(|| panic!("{path} not baked"))
}

fn text(files: &[BakedFile], path: &str) -> String {
    String::from_utf8(file(files, path).bytes.clone()).unwrap()
}

/// Closed-form total diffuse reflectance of a semi-infinite medium (Jensen et al. 2001):
/// Rd = (α′/2)(1 + e^(−(4/3) A sqrt(3(1 − α′)))) e^(−sqrt(3(1 − α′))), A = (1 + Fdr)/(1 − Fdr), Fdr by the
/// Donner & Jensen 2005 polynomial at η = 1.3. Written out here independently of the library.
fn closed_form_rd(sigma_a: f64, sigma_s_prime: f64) -> f64 {
    let eta: f64 = 1.3;
    let fdr = -1.4399 / (eta * eta) + 0.7099 / eta + 0.6681 + 0.0636 * eta;
    let a = (1.0 + fdr) / (1.0 - fdr);
    let albedo = sigma_s_prime / (sigma_a + sigma_s_prime);
    let s = (3.0 * (1.0 - albedo)).sqrt();
    0.5 * albedo * (1.0 + (-(4.0 / 3.0) * a * s).exp()) * (-s).exp()
}

/// The `total_R` / `total_T` triple of a table's JSON sidecar (the CSV holds the header and rows only).
fn json_totals(json: &[u8], key: &str) -> Option<[f64; 3]> {
    let v: Value = serde_json::from_slice(json).unwrap();
    let t = v[key].as_array()?;
    Some([t[0].as_f64()?, t[1].as_f64()?, t[2].as_f64()?])
}

#[test]
fn writes_tables_and_plots_for_every_default_profile() {
    let files = bake(&default_params());
    let mut stems: Vec<String> = JENSEN_2001.iter().map(|m| format!("dipole/{}", m.name)).collect();
    stems.extend(["presets/deon6", "presets/deon4", "layered/skin3_example"].map(String::from));
    stems.extend(["0.02_chd0.05", "0.1_chd0.1", "0.3_chd0.05"].map(|s| format!("skin/two_layer_cm{s}")));
    for stem in &stems {
        for ext in ["csv", "json", "svg"] {
            let f = file(&files, &format!("profiles/{stem}.{ext}"));
            assert!(!f.bytes.is_empty());
        }
        // Every table records its model options.
        let json: Value = serde_json::from_slice(&file(&files, &format!("profiles/{stem}.json")).bytes).unwrap();
        assert!(json["model"].is_string(), "{stem}");
        assert_eq!(json["r_mm"].as_array().unwrap().len(), 200);
        let csv = text(&files, &format!("profiles/{stem}.csv"));
        let svg = text(&files, &format!("profiles/{stem}.svg"));
        assert!(svg.contains("<desc>rtbake profile: {") && svg.matches("<polyline").count() >= 6, "{stem}");
        // Header row first, no comment lines (pandas/numpy/spreadsheet defaults); provenance in the JSON.
        assert!(csv.lines().next().is_some_and(|l| l.starts_with("r_mm,R_r,R_g,R_b")), "{stem}");
        assert!(!csv.contains('#'), "{stem}: a comment line in the CSV");
    }
    let pngs: Vec<&str> = files.iter().filter(|f| f.path.ends_with(".png")).map(|f| f.path.as_str()).collect();
    assert_eq!(pngs.len(), 4, "{pngs:?}");
    assert_eq!(files.len(), 3 * stems.len() + 4 + 1);
    assert!(files.iter().all(|f| f.path.starts_with("profiles/")));

    // Layer stacks carry T and T̂(0); the skin records its chromophores; the 3-layer example its layers.
    let skin: Value =
        serde_json::from_slice(&file(&files, "profiles/skin/two_layer_cm0.3_chd0.05.json").bytes).unwrap();
    assert_eq!(skin["skin"]["melanin_fraction"], 0.3);
    assert!(skin["T"].is_array() && skin["total_T"].is_array());
    let three: Value = serde_json::from_slice(&file(&files, "profiles/layered/skin3_example.json").bytes).unwrap();
    assert_eq!(three["layers"]["layers"].as_array().unwrap().len(), 3);
    let t = json_totals(&file(&files, "profiles/layered/skin3_example.json").bytes, "total_T").unwrap();
    assert!(t[0] > 1e-6 && t[0] > t[1] && t[1] > t[2], "red transmits most through the thin stack: {t:?}");
}

#[test]
fn skin1_table_is_what_rtbake_profile_prints() {
    let files = bake(&default_params());
    let baked: Value = serde_json::from_slice(&file(&files, "profiles/dipole/skin1.json").bytes).unwrap();
    let out =
        Command::new(env!("CARGO_BIN_EXE_rtbake")).args(["profile", "--material", "skin1", "--json"]).output().unwrap();
    assert!(out.status.success());
    let cli: Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["r_mm", "R", "total_R", "model", "material", "fdr", "eta"] {
        assert_eq!(baked[key], cli[key], "{key}");
    }
    // The layered skin too (the CLI's --skin-* flags build the same stack).
    let baked: Value =
        serde_json::from_slice(&file(&files, "profiles/skin/two_layer_cm0.1_chd0.1.json").bytes).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_rtbake"))
        .args(["profile", "--skin-melanin", "0.1", "--skin-hemoglobin", "0.1", "--json"])
        .output()
        .unwrap();
    let cli: Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["r_mm", "R", "T", "total_R", "total_T", "layers", "adding"] {
        assert_eq!(baked[key], cli[key], "{key}");
    }
}

#[test]
fn json_totals_are_the_closed_form_dipole_totals_and_the_tables_integrate_to_them() {
    let files = bake(&default_params());
    let summary = text(&files, "profiles/totals.csv");
    for m in JENSEN_2001 {
        let csv = text(&files, &format!("profiles/dipole/{}.csv", m.name));
        let json = &file(&files, &format!("profiles/dipole/{}.json", m.name)).bytes;
        let totals = json_totals(json, "total_R").expect("total_R in the JSON");
        assert!(json_totals(json, "total_T").is_none(), "a semi-infinite medium has no T");
        // ∫ 2πr R(r) dr by the trapezoid rule in ln r over the tabulated [0.001, 100] mm.
        let rows: Vec<Vec<f64>> = csv
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("r_mm"))
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect();
        for c in 0..3 {
            let expected = closed_form_rd(m.sigma_a_per_mm[c], m.sigma_s_prime_per_mm[c]);
            assert!((totals[c] - expected).abs() <= 1e-14 * expected, "{} ch {c}: {} vs {expected}", m.name, totals[c]);
            let integral: f64 = rows
                .windows(2)
                .map(|w| {
                    let f = |row: &[f64]| 2.0 * std::f64::consts::PI * row[0] * row[0] * row[1 + c];
                    0.5 * (f(&w[0]) + f(&w[1])) * (w[1][0] / w[0][0]).ln()
                })
                .sum();
            assert!((integral / expected - 1.0).abs() < 2e-3, "{} ch {c}: table integrates to {integral}", m.name);
        }
        let row = summary.lines().find(|l| l.starts_with(&format!("dipole/{},", m.name))).unwrap();
        let v: Vec<f64> = row.split(',').skip(1).take(3).map(|x| x.parse().unwrap()).collect();
        // serde_json's default float parsing may land one ulp away from Rust's `parse`.
        for c in 0..3 {
            assert!((v[c] - totals[c]).abs() <= 4.0 * f64::EPSILON * totals[c], "{}: {v:?} vs {totals:?}", m.name);
        }
    }
}

#[test]
fn params_round_trip_and_bytes_do_not_depend_on_threads() {
    let params = default_params();
    let again: Value = serde_json::from_str(&serde_json::to_string(&params).unwrap()).unwrap();
    let many = bake(&again);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| bake(&params));
    assert_eq!(many.len(), one.len());
    for (a, b) in many.iter().zip(&one) {
        assert_eq!(a.path, b.path);
        assert!(a.bytes == b.bytes, "{} differs with 1 thread", a.path);
    }
}
