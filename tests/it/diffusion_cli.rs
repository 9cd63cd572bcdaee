//! `rtbake profile` machine contracts and bad-input handling.

use rtbake::diffusion::materials;
use rtbake::diffusion::multipole::{Series, Slab};
use rtbake::diffusion::{FdrForm, RadialProfile};
use serde_json::Value;
use std::process::Output;

use crate::support::rtbake;

fn json_of(out: &Output) -> Value {
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

fn rgb(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("array");
    assert_eq!(a.len(), 3);
    [0, 1, 2].map(|c| a[c].as_f64().unwrap())
}

fn bad(args: &[&str], needle: &str) {
    let out = rtbake(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: stderr {err}");
    assert!(err.contains(needle), "{args:?}: stderr should name {needle:?}: {err}");
    if args.contains(&"--json") {
        // With --json, stdout holds exactly the error object.
        let v: Value = serde_json::from_slice(&out.stdout).expect("--json error object on stdout");
        assert_eq!(v["exit_code"], 2, "{args:?}: {v}");
        assert!(v["error"].as_str().unwrap().contains(needle), "{args:?}: {v}");
    } else {
        assert!(out.stdout.is_empty(), "{args:?}: nothing on stdout on error");
    }
}

const STACK: &str = r#"{"eta_above": 1.0, "eta_below": 1.0, "layers": [
  {"thickness_mm": 0.25, "eta": 1.4, "sigma_a": [0.2, 0.5, 1.2], "sigma_s_prime": [5, 6, 7]},
  {"thickness_mm": 3.0, "eta": 1.38, "sigma_a": [0.02, 0.06, 0.12], "sigma_s_prime": [1.5, 2, 2.5]}]}"#;

fn write_stack(dir: &tempfile::TempDir, name: &str, text: &str) -> String {
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn material_dipole_json_contract() {
    let v =
        json_of(&rtbake(&["profile", "--material", "skin1", "--model", "dipole", "--radii", "0,0.1,1,10", "--json"]));
    let r: Vec<f64> = v["r_mm"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    assert_eq!(r, vec![0.0, 0.1, 1.0, 10.0]);
    let rows = v["R"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    let dip = materials::find("skin1").unwrap().dipole(FdrForm::Dj05);
    for (i, row) in rows.iter().enumerate() {
        let got = rgb(row);
        let want = dip.reflectance_mm2(r[i]);
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() <= 1e-15 * want[c], "R({})", r[i]);
        }
    }
    // Total diffuse reflectance = Jensen 2001's closed form (skin1 red, η = 1.3).
    let total = rgb(&v["total_R"]);
    let m = materials::find("skin1").unwrap();
    let ap = m.sigma_s_prime_per_mm[0] / (m.sigma_s_prime_per_mm[0] + m.sigma_a_per_mm[0]);
    let f = rtbake::diffusion::fdr(1.3, FdrForm::Dj05);
    let a = (1.0 + f) / (1.0 - f);
    let s = (3.0 * (1.0 - ap)).sqrt();
    let closed = 0.5 * ap * (1.0 + (-(4.0 / 3.0) * a * s).exp()) * (-s).exp();
    assert!((total[0] - closed).abs() < 1e-14, "{} vs {closed}", total[0]);
    assert_eq!(v["model"], "dipole");
    assert_eq!(v["fdr"], "dj05");
    assert_eq!(v["eta"], 1.3);
    assert!(v.get("T").is_none());
}

#[test]
fn fdr_option_is_recorded_and_changes_the_result() {
    let a = json_of(&rtbake(&["profile", "--material", "marble", "--radii", "0.5", "--json"]));
    let b = json_of(&rtbake(&["profile", "--material", "marble", "--radii", "0.5", "--fdr", "jensen01", "--json"]));
    assert_eq!(b["fdr"], "jensen01");
    assert_ne!(a["total_R"], b["total_R"]);
}

#[test]
fn layers_json_contract_with_options() {
    let dir = tempfile::tempdir().unwrap();
    let file = write_stack(&dir, "stack.json", STACK);
    let v = json_of(&rtbake(&["profile", "--layers", &file, "--radii", "0,0.5,2", "--json"]));
    for key in ["r_mm", "R", "T", "total_R", "total_T"] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["T"].as_array().unwrap().len(), 3);
    assert_eq!(v["adding"], "symmetric");
    assert_eq!(v["series"], "exact");
    let (r, t) = (rgb(&v["total_R"]), rgb(&v["total_T"]));
    assert!((0..3).all(|c| r[c] > 0.0 && t[c] > 0.0 && r[c] + t[c] < 1.0));

    let d = json_of(&rtbake(&[
        "profile",
        "--layers",
        &file,
        "--radii",
        "0,0.5,2",
        "--json",
        "--adding",
        "directional",
        "--dipole-pairs",
        "5",
    ]));
    assert_eq!(d["adding"], "directional");
    assert_eq!(d["series"]["truncated_pairs"], 5);
    assert_ne!(d["total_R"], v["total_R"]);
}

#[test]
fn multipole_slab_and_presets() {
    let v = json_of(&rtbake(&[
        "profile",
        "--material",
        "skin2",
        "--model",
        "multipole",
        "--thickness-mm",
        "2",
        "--radii",
        "0,1",
        "--json",
    ]));
    let m = materials::find("skin2").unwrap();
    let s = Slab::new(m.sigma_a_per_mm[1], m.sigma_s_prime_per_mm[1], 2.0, 1.3, 1.3, FdrForm::Dj05).unwrap();
    let (rt, tt) = s.totals(Series::Exact);
    assert!((rgb(&v["total_R"])[1] - rt).abs() < 1e-15);
    assert!((rgb(&v["total_T"])[1] - tt).abs() < 1e-15);
    assert_eq!(v["thickness_mm"], 2.0);

    let p = json_of(&rtbake(&["profile", "--profile-preset", "deon6", "--json"]));
    assert_eq!(p["r_mm"].as_array().unwrap().len(), 200, "default grid");
    let total = rgb(&p["total_R"]);
    assert!((0..3).all(|c| (total[c] - 1.0).abs() < 1e-12), "d'Eon weights sum to 1: {total:?}");
}

#[test]
fn csv_and_out_files_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let file = write_stack(&dir, "stack.json", STACK);
    let csv = dir.path().join("p.csv");
    let out = dir.path().join("p.json");
    let o = rtbake(&[
        "profile",
        "--layers",
        &file,
        "--count",
        "16",
        "--csv",
        csv.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows[0], "r_mm,R_r,R_g,R_b,T_r,T_g,T_b");
    assert_eq!(rows.len(), 17);
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let first: Vec<f64> = rows[1].split(',').map(|x| x.parse().unwrap()).collect();
    // serde_json parses floats to within 1 ulp (no `float_roundtrip` feature).
    let close = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * b.abs();
    assert!(close(first[0], v["r_mm"][0].as_f64().unwrap()));
    assert!(close(first[1], v["R"][0][0].as_f64().unwrap()));
    assert!(close(first[4], v["T"][0][0].as_f64().unwrap()));
}

#[test]
fn bad_input_exits_2_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let stack = |text: &str, name: &str| write_stack(&dir, name, text);
    let thin = stack(&STACK.replace("\"thickness_mm\": 3.0", "\"thickness_mm\": 0.3"), "thin.json");
    bad(&["profile", "--layers", &thin, "--json"], "layers[1].thickness_mm");
    bad(&["profile", "--layers", &thin, "--json"], "1/sigma_t'");
    let neg = stack(&STACK.replace("[0.02, 0.06, 0.12]", "[0.02, -0.06, 0.12]"), "neg.json");
    bad(&["profile", "--layers", &neg], "layers[1].sigma_a[1]");
    let zero = stack(&STACK.replace("[5, 6, 7]", "[5, 0, 7]"), "zero.json");
    bad(&["profile", "--layers", &zero], "layers[0].sigma_s_prime[1]");
    let nan = stack(&STACK.replace("[5, 6, 7]", "[5, NaN, 7]"), "nan.json");
    bad(&["profile", "--layers", &nan], "--layers");
    let eta = stack(&STACK.replace("\"eta\": 1.38", "\"eta\": 0"), "eta.json");
    bad(&["profile", "--layers", &eta], "layers[1].eta");
    let eta_above = stack(&STACK.replace("\"eta_above\": 1.0", "\"eta_above\": -1"), "eta_above.json");
    bad(&["profile", "--layers", &eta_above], "eta_above");
    let empty = stack(r#"{"eta_above": 1.0, "eta_below": 1.0, "layers": []}"#, "empty.json");
    bad(&["profile", "--layers", &empty], "layers");
    let malformed = stack(r#"{"layers": [ {"thickness_mm": 1 "#, "malformed.json");
    bad(&["profile", "--layers", &malformed], "malformed JSON");
    bad(&["profile", "--layers", "/nonexistent/stack.json"], "--layers");
    bad(&["profile", "--material", "skin1", "--radii", "0,1,0.5", "--json"], "--radii");
    bad(&["profile", "--material", "skin1", "--radii", "-1,1", "--json"], "--radii");
    bad(&["profile", "--material", "skin1", "--radii", "0,abc", "--json"], "--radii");
    bad(&["profile", "--material", "skin1", "--radii", "0,1e9", "--json"], "--radii");
    bad(&["profile", "--material", "unobtainium", "--json"], "--material");
    bad(&["profile", "--profile-preset", "deon7", "--json"], "--profile-preset");
    bad(&["profile", "--material", "skin1", "--model", "multipole", "--json"], "--thickness-mm");
    bad(&["profile", "--material", "skin1", "--model", "multipole", "--thickness-mm", "0.5"], "--thickness-mm");
    bad(&["profile", "--material", "skin1", "--dipole-pairs", "5"], "--dipole-pairs");
    bad(&["profile", "--material", "skin1", "--r-min-mm", "0"], "--r-min-mm");
    // Nothing is written on error.
    let csv = dir.path().join("never.csv");
    bad(&["profile", "--layers", &thin, "--csv", csv.to_str().unwrap()], "thickness_mm");
    assert!(!csv.exists());
}
