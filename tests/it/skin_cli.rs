//! `rtbake skin-color`: the JSON contract for one point, the table bake into `--out`, and bad input (exit 2, the
//! flag named, nothing written).

use std::path::Path;
use std::process::Output;

use crate::support::rtbake;

fn json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

#[test]
fn point_contract_prints_linear_rgb_and_srgb8() {
    let v = json(&rtbake(&["skin-color", "--melanin", "0", "--hemoglobin", "0", "--json"]));
    let obj = v.as_object().unwrap();
    assert_eq!(obj.keys().collect::<Vec<_>>(), ["linear_rgb", "srgb8"]);
    let lin: Vec<f64> = v["linear_rgb"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    let s8: Vec<i64> = v["srgb8"].as_array().unwrap().iter().map(|x| x.as_i64().unwrap()).collect();
    assert_eq!(lin.len(), 3);
    for (got, want) in s8.iter().zip([221, 216, 203]) {
        assert!((got - want).abs() <= 2, "{s8:?}");
    }
    // A parameter flag changes the answer (Che = 0 makes the flushed corner bluer).
    let a = json(&rtbake(&["skin-color", "--melanin", "0", "--hemoglobin", "0.32", "--json"]));
    let b = json(&rtbake(&[
        "skin-color",
        "--melanin",
        "0",
        "--hemoglobin",
        "0.32",
        "--epidermal-hemoglobin-ratio",
        "0",
        "--json",
    ]));
    assert!(b["linear_rgb"][2].as_f64().unwrap() > 1.5 * a["linear_rgb"][2].as_f64().unwrap());
}

#[test]
fn spectrum_flag_adds_wavelengths_and_reflectance() {
    let v = json(&rtbake(&["skin-color", "--melanin", "0.1", "--hemoglobin", "0.05", "--spectrum", "--json"]));
    let wl = v["wavelength_nm"].as_array().unwrap();
    let r = v["reflectance"].as_array().unwrap();
    assert_eq!((wl.len(), r.len()), (401, 401));
    assert_eq!((wl[0].as_f64(), wl[400].as_f64()), (Some(380.0), Some(780.0)));
    assert!(r.iter().all(|x| (0.0..1.0).contains(&x.as_f64().unwrap())));
    let v5 = json(&rtbake(&[
        "skin-color",
        "--melanin",
        "0.1",
        "--hemoglobin",
        "0.05",
        "--spectrum",
        "--spectral-step-nm",
        "5",
        "--json",
    ]));
    assert_eq!(v5["reflectance"].as_array().unwrap().len(), 81);
}

#[test]
fn params_file_sets_flags_and_command_line_overrides_it() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("p.json");
    std::fs::write(&f, r#"{"melanin": 0.5, "hemoglobin": 0.0, "melanin-blend": 0.7}"#).unwrap();
    let a = json(&rtbake(&["skin-color", "--params", f.to_str().unwrap(), "--json"]));
    let b = json(&rtbake(&["skin-color", "--melanin", "0.5", "--hemoglobin", "0", "--melanin-blend", "0.7", "--json"]));
    assert_eq!(a, b);
    let c = json(&rtbake(&["skin-color", "--params", f.to_str().unwrap(), "--melanin", "0", "--json"]));
    let d = json(&rtbake(&["skin-color", "--melanin", "0", "--hemoglobin", "0", "--json"]));
    assert_eq!(c, d);
}

#[test]
fn out_bakes_the_table_with_the_given_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lut");
    let o = rtbake(&[
        "skin-color",
        "--out",
        out.to_str().unwrap(),
        "--resolution",
        "8x6",
        "--spectral-step-nm",
        "5",
        "--adding",
        "directional",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "skin_color_lut.exr",
        "skin_color_lut_f16.exr",
        "skin_color_lut.ktx2",
        "skin_color_lut_preview_srgb.png",
        "skin_color_lut.json",
        "skin_color_samples.csv",
        "skin_color_spectra.csv",
    ] {
        assert!(out.join(f).is_file(), "{f} missing (--out DIR receives the files, no skin/ subdirectory)");
    }
    let side: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("skin_color_lut.json")).unwrap()).unwrap();
    assert_eq!(side["parameters"]["adding"], "directional");
    assert_eq!(side["parameters"]["spectral_step_nm"], 5);
    assert_eq!((side["width"].as_u64(), side["height"].as_u64()), (Some(8), Some(6)));
    assert!(!out.join("skin").exists());
    let names: Vec<String> =
        std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().all(|n| !n.contains("rtbake-tmp")), "temp files left: {names:?}");
}

/// Runs a bad command with `--out DIR` and checks exit 2, the flag in the message, and an empty DIR.
fn assert_rejected(args: &[&str], flag: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mut full = vec!["skin-color", "--out", out.to_str().unwrap()];
    full.extend_from_slice(args);
    let o = rtbake(&full);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(flag), "{args:?}: message should name {flag}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none(), "{args:?} wrote into --out");
}

#[test]
fn bad_input_exits_2_naming_the_flag_and_writes_nothing() {
    assert_rejected(&["--melanin", "0.6", "--hemoglobin", "0"], "--melanin");
    assert_rejected(&["--melanin", "-0.1", "--hemoglobin", "0"], "--melanin");
    assert_rejected(&["--melanin", "0.1", "--hemoglobin", "0.33"], "--hemoglobin");
    assert_rejected(&["--melanin", "NaN", "--hemoglobin", "0"], "--melanin");
    assert_rejected(&["--melanin", "0.1", "--hemoglobin", "inf"], "--hemoglobin");
    assert_rejected(&["--epidermis-thickness-mm", "-0.25"], "--epidermis-thickness-mm");
    assert_rejected(&["--dermis-thickness-mm", "0"], "--dermis-thickness-mm");
    assert_rejected(&["--epidermis-thickness-mm", "0.1"], "--epidermis-thickness-mm");
    assert_rejected(&["--eta-epidermis", "0"], "--eta-epidermis");
    assert_rejected(&["--eta-dermis", "-1.4"], "--eta-dermis");
    assert_rejected(&["--melanin-blend", "1.5"], "--melanin-blend");
    assert_rejected(&["--oxygenation", "NaN"], "--oxygenation");
    assert_rejected(&["--hemoglobin-g-per-l", "0"], "--hemoglobin-g-per-l");
    assert_rejected(&["--spectral-step-nm", "3"], "--spectral-step-nm");
    assert_rejected(&["--resolution", "0"], "--resolution");
    assert_rejected(&["--resolution", "1"], "--resolution");
    assert_rejected(&["--resolution", "1000000x1000000"], "--resolution");
    assert_rejected(&["--resolution", "99999999999999999999999"], "--resolution");
    assert_rejected(&["--resolution", "256xabc"], "--resolution");
    assert_rejected(&["--adding", "sideways"], "--adding");
    assert_rejected(&["--melanin", "0.1"], "--hemoglobin");
}

#[test]
fn unphysiological_override_is_explicit() {
    let o = rtbake(&["skin-color", "--melanin", "0.8", "--hemoglobin", "0.5", "--json"]);
    assert_eq!(o.status.code(), Some(2));
    let v =
        json(&rtbake(&["skin-color", "--melanin", "0.8", "--hemoglobin", "0.5", "--allow-unphysiological", "--json"]));
    assert!(v["linear_rgb"][0].as_f64().unwrap() > 0.0);
}

#[test]
fn nothing_to_do_is_a_usage_error_and_unwritable_out_is_reported() {
    let o = rtbake(&["skin-color"]);
    assert_eq!(o.status.code(), Some(2));
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("not-a-dir");
    std::fs::write(&file, b"x").unwrap();
    let o = rtbake(&["skin-color", "--out", file.to_str().unwrap(), "--resolution", "4"]);
    assert_ne!(o.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--out"));
    assert_eq!(std::fs::read(Path::new(&file)).unwrap(), b"x");
}
