//! `rtbake fit gaussians` and `rtbake transmittance`: JSON contracts, files written, and bad input (exit 2, the
//! flag named, nothing written).

use serde_json::Value;
use std::path::Path;
use std::process::Output;

use crate::support::rtbake;

fn json_of(out: &Output) -> Value {
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("JSON on stdout")
}

fn assert_bad(args: &[&str], flag: &str) {
    let out = rtbake(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(flag), "{args:?}: stderr should name {flag}: {err}");
}

#[test]
fn fit_shared_json_contract() {
    let v = json_of(&rtbake(&["fit", "gaussians", "--material", "skin1", "--count", "4", "--json"]));
    assert_eq!(v["variances"].as_array().unwrap().len(), 4);
    let vars: Vec<f64> = v["variances"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    assert!(vars.windows(2).all(|p| p[0] < p[1]), "ascending: {vars:?}");
    let w = v["weights"].as_array().unwrap();
    assert_eq!(w.len(), 4);
    assert!(w.iter().all(|row| row.as_array().unwrap().len() == 3));
    assert_eq!(v["error_percent"].as_array().unwrap().len(), 3);
    for key in ["blend_weights", "incremental_variances", "std_devs", "lod_thresholds"] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["blend_weights"][0], serde_json::json!([1.0, 1.0, 1.0]));
    let inc0 = v["incremental_variances"][0].as_f64().unwrap();
    assert_eq!(inc0, vars[0]);
    let lod = &v["lod_thresholds"];
    assert_eq!(lod["alpha"], 31.5);
    let two = lod["two_sqrt_v_alpha"][1].as_f64().unwrap();
    assert!((two - 2.0 * vars[1].sqrt() * 31.5).abs() < 1e-12);
    let half = lod["half_sqrt_v_alpha"][1].as_f64().unwrap();
    assert!((half - 0.5 * vars[1].sqrt() * 31.5).abs() < 1e-12);
}

#[test]
fn fit_per_channel_json_contract_and_out_files() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("fit");
    let v = json_of(&rtbake(&[
        "fit",
        "gaussians",
        "--profile-preset",
        "deon6",
        "--count",
        "3",
        "--per-channel",
        "--normalize",
        "--json",
        "--out",
        out_dir.to_str().unwrap(),
    ]));
    let vars = v["variances"].as_array().unwrap();
    assert_eq!(vars.len(), 3);
    assert!(vars.iter().all(|ch| ch.as_array().unwrap().len() == 3));
    assert!(v["weights"].as_array().unwrap().iter().all(|ch| ch.as_array().unwrap().len() == 3));
    let mut names: Vec<String> =
        std::fs::read_dir(&out_dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    let stem = "fit_deon6_k3_per_channel";
    let expect: Vec<String> =
        [".glsl", ".hlsl", ".json", ".wgsl", "_plot.png", "_plot.svg"].iter().map(|s| format!("{stem}{s}")).collect();
    assert_eq!(names, expect);
    let file: Value = serde_json::from_slice(&std::fs::read(out_dir.join(format!("{stem}.json"))).unwrap()).unwrap();
    assert_eq!(file["variances"], v["variances"]);
    assert_eq!(file["source"]["profile_preset"], "deon6");
}

#[test]
fn fit_bad_input_exits_2_naming_the_flag_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o = out.to_str().unwrap();
    assert_bad(&["fit", "gaussians", "--material", "skin1", "--count", "1", "--out", o], "--count");
    assert_bad(&["fit", "gaussians", "--material", "skin1", "--count", "9", "--out", o], "--count");
    assert_bad(&["fit", "gaussians", "--material", "skin1", "--count", "-3", "--out", o], "--count");
    assert_bad(&["fit", "gaussians", "--material", "unobtainium", "--out", o], "--material");
    assert_bad(&["fit", "gaussians", "--profile-preset", "deon7", "--out", o], "--profile-preset");
    assert_bad(&["fit", "gaussians", "--material", "skin1", "--alpha", "0", "--out", o], "--alpha");
    assert_bad(&["fit", "gaussians", "--count", "4", "--out", o], "--material");
    assert!(!Path::new(o).exists(), "nothing may be written on bad input");
}

#[test]
fn transmittance_json_contract() {
    let v = json_of(&rtbake(&["transmittance", "--profile-preset", "deon6", "--s", "0,0.5,1,2", "--json"]));
    assert_eq!(v["s_mm"], serde_json::json!([0.0, 0.5, 1.0, 2.0]));
    let t = v["T"].as_array().unwrap();
    assert_eq!(t.len(), 4);
    for t0 in t[0].as_array().unwrap() {
        assert!((t0.as_f64().unwrap() - 1.0).abs() < 1e-12);
    }
    // Published form: red at 1 mm = Σ w exp(−1/v) of d'Eon's six Gaussians.
    let v6: [f64; 6] = [0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41];
    let wr: [f64; 6] = [0.233, 0.100, 0.118, 0.113, 0.358, 0.078];
    let expect: f64 = v6.iter().zip(&wr).map(|(v, w)| w * (-1.0 / v).exp()).sum();
    assert!((t[2][0].as_f64().unwrap() - expect).abs() < 1e-12);
    assert_eq!(v["form"], "published");
    // --physical uses exp(−s²/(2v)).
    let p = json_of(&rtbake(&["transmittance", "--profile-preset", "deon6", "--s", "1", "--physical", "--json"]));
    let expect: f64 = v6.iter().zip(&wr).map(|(v, w)| w * (-1.0 / (2.0 * v)).exp()).sum();
    assert!((p["T"][0][0].as_f64().unwrap() - expect).abs() < 1e-12);
    assert_eq!(p["form"], "physical");
    // Unsorted distances are accepted and answered in input order.
    let u = json_of(&rtbake(&["transmittance", "--s", "2,0", "--json"]));
    assert_eq!(u["T"][0], v["T"][3]);
    assert_eq!(u["T"][1], v["T"][0]);
}

#[test]
fn transmittance_out_writes_table_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t");
    let o = out.to_str().unwrap();
    let v = json_of(&rtbake(&["transmittance", "--out", o, "--samples", "64", "--s-max", "4", "--json"]));
    let mut names: Vec<String> =
        std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    // The linear KTX2 and PNG carry Bevy's `.meta`; the sRGB preview does not.
    let expect: Vec<String> = [
        ".exr",
        ".json",
        ".ktx2",
        ".ktx2.meta",
        "_f16.exr",
        "_linear16.png",
        "_linear16.png.meta",
        "_preview_srgb.png",
    ]
    .iter()
    .map(|s| format!("deon6_published{s}"))
    .collect();
    assert_eq!(names, expect);
    assert!(v["convention"].as_str().unwrap().contains("s = s_max*i/(n-1)"));
    let (img, _) = rtbake::io::exr::decode(&std::fs::read(out.join("deon6_published.exr")).unwrap(), "t").unwrap();
    assert_eq!((img.width, img.height, img.channels), (64, 1, 3));
}

#[test]
fn transmittance_bad_input_exits_2_naming_the_flag_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o = out.to_str().unwrap();
    assert_bad(&["transmittance", "--s", "0,nan", "--out", o], "--s");
    assert_bad(&["transmittance", "--s", "-1", "--out", o], "--s");
    assert_bad(&["transmittance", "--s", "1,x", "--out", o], "--s");
    assert_bad(&["transmittance", "--s", "inf", "--out", o], "--s");
    assert_bad(&["transmittance", "--out", o, "--samples", "0"], "--samples");
    assert_bad(&["transmittance", "--out", o, "--samples", "1"], "--samples");
    assert_bad(&["transmittance", "--out", o, "--samples", "1000000"], "--samples");
    assert_bad(&["transmittance", "--out", o, "--s-max", "0"], "--s-max");
    assert_bad(&["transmittance", "--out", o, "--s-max", "-2"], "--s-max");
    assert_bad(&["transmittance", "--out", o, "--s-max", "nan"], "--s-max");
    assert_bad(&["transmittance", "--out", o, "--height", "0"], "--height");
    assert_bad(&["transmittance", "--profile-preset", "nope", "--out", o], "--profile-preset");
    assert_bad(&["transmittance", "--material", "skin1", "--count", "9", "--out", o], "--count");
    assert!(!Path::new(o).exists(), "nothing may be written on bad input");
}

#[test]
fn error_table_cli_prints_33_entries() {
    let v = json_of(&rtbake(&["fit", "gaussians", "--error-table", "--json"]));
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 11);
    assert!(rows.iter().all(|r| r["error_percent"].as_array().unwrap().len() == 3));
    let cream = rows.iter().find(|r| r["material"] == "cream").unwrap();
    assert!((cream["error_percent"][0].as_f64().unwrap() - 1.50).abs() < 0.02);
}
