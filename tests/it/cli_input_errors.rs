//! Non-finite results are errors naming their input (nothing written), negative
//! numbers after a space reach the range check that names the flag, and `--asset-params` type errors name the
//! field.

use crate::support::rtbake;
use std::process::Output;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn huge_layer_coefficients_are_an_error_naming_the_file_not_nan_output() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("p.json");
    let csv = t.path().join("p.csv");
    for (field, layer) in [
        ("sigma_a", r#"{"thickness_mm": 1.0, "eta": 1.4, "sigma_a": [1e300, 0.1, 0.1], "sigma_s_prime": [1, 1, 1]}"#),
        (
            "thickness_mm",
            r#"{"thickness_mm": 1e300, "eta": 1.4, "sigma_a": [0.1, 0.1, 0.1], "sigma_s_prime": [1, 1, 1]}"#,
        ),
    ] {
        let layers = t.path().join(format!("{field}.json"));
        std::fs::write(&layers, format!(r#"{{"eta_above": 1.0, "eta_below": 1.0, "layers": [{layer}]}}"#)).unwrap();
        let o = rtbake(&[
            "profile",
            "--layers",
            layers.to_str().unwrap(),
            "--count",
            "8",
            "--out",
            out.to_str().unwrap(),
            "--csv",
            csv.to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{field}: {err}");
        assert!(
            err.contains("--layers") && err.contains(layers.to_str().unwrap()) && err.contains("not finite"),
            "{err}"
        );
        assert!(!out.exists() && !csv.exists(), "{field}: a non-finite table was written");
    }
}

#[test]
fn negative_numbers_after_a_space_reach_the_flags_range_check() {
    let t = tempfile::tempdir().unwrap();
    for (args, flag) in [
        (vec!["profile", "--material", "skin1", "--model", "multipole", "--thickness-mm", "-1"], "--thickness-mm"),
        (vec!["kernel", "--samples", "-3"], "--samples"),
        (vec!["transmittance", "--s-max", "-2", "--s", "1"], "--s-max"),
    ] {
        let o = rtbake(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
        assert!(err.contains(flag), "{args:?} should name {flag}: {err}");
    }
    // A u32 flag: clap's own message names the flag and the range.
    let out = t.path().join("s");
    let o = rtbake(&["maps", "synthetic", "--seed", "-1", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--seed") && stderr(&o).contains("0..="), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn asset_params_type_errors_name_the_field() {
    let t = tempfile::tempdir().unwrap();
    let params = t.path().join("p.json");
    let out = t.path().join("b");
    for (json, field) in [
        (r#"{"transmittance": {"table": {"samples": "many"}}}"#, "table.samples"),
        (r#"{"mlaa-v2": {"max_distances": [15.5]}}"#, "max_distances[0]"),
        (r#"{"hemoglobin-rig-example": {"seed": -4}}"#, "seed"),
    ] {
        std::fs::write(&params, json).unwrap();
        let asset = json.split('"').nth(1).unwrap();
        let o = rtbake(&["bake", asset, "--out", out.to_str().unwrap(), "--asset-params", params.to_str().unwrap()]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{json}: {err}");
        assert!(err.contains(&format!("parameter {field}:")), "{json}: should name {field}: {err}");
        assert!(!out.exists());
    }
}

#[test]
fn sizes_beyond_the_memory_budget_are_refused_before_allocating_with_estimate_and_limit() {
    let t = tempfile::tempdir().unwrap();
    let png = t.path().join("d.png");
    let table = t.path().join("tr");
    for (args, flags) in [
        (
            vec!["run", "demo", "--cpu", "--width", "4096", "--height", "4096", "--max-memory", "1G", "--output"],
            "--width 4096 --height 4096",
        ),
        (
            vec!["transmittance", "--samples", "16384", "--height", "16384", "--max-memory", "4G", "--out"],
            "--samples 16384 --height 16384",
        ),
    ] {
        let mut args = args.clone();
        let out = if args[0] == "run" { &png } else { &table };
        args.push(out.to_str().unwrap());
        let o = rtbake(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(flags) && err.contains("GiB") && err.contains("--max-memory"), "{err}");
        assert!(!out.exists());
    }
    // Within the budget it runs.
    let o =
        rtbake(&["transmittance", "--samples", "64", "--max-memory", "64M", "--out", table.to_str().unwrap(), "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = rtbake(&["transmittance", "--samples", "64", "--max-memory", "lots", "--out", table.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--max-memory"), "{}", stderr(&o));
}
