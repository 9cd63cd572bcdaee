//! The transport model of layered and skin profiles on the command line: `--model mc` (Monte Carlo, `--g`,
//! `--photons`, `--seed`) on every profile consumer, the spectral skin projection, and their bad input.

use crate::support::rtbake;
use std::process::Output;

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("JSON on stdout")
}

fn assert_usage(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "expected exit 2: {err}");
    for n in needles {
        assert!(err.contains(n), "stderr lacks '{n}': {err}");
    }
}

const STACK: &str = r#"{"eta_above": 1.0, "eta_below": 1.0, "layers": [
 {"thickness_mm": 0.25, "eta": 1.4, "sigma_a": [0.2, 0.5, 1.2], "sigma_s_prime": [5.0, 6.0, 7.0]},
 {"thickness_mm": 3.0, "eta": 1.4, "sigma_a": [0.1, 0.3, 0.6], "sigma_s_prime": [2.0, 2.5, 3.0]}]}"#;

/// `--model mc` on a layer stack: the provenance names the model, the tissue-like default g, photons, seed and the
/// standard errors; the same seed gives the same bytes, another seed other numbers; the Monte Carlo total (per
/// entering flux) lies within 5 standard errors of a run of the library's transport with the same stack, and below
/// the multipole
/// (diffusion over-estimates these low-albedo layers).
#[test]
fn monte_carlo_profile_records_its_model_and_errors() {
    let t = tempfile::tempdir().unwrap();
    let file = t.path().join("stack.json");
    std::fs::write(&file, STACK).unwrap();
    let f = file.to_str().unwrap();
    let args = ["profile", "--layers", f, "--model", "mc", "--photons", "3000", "--json"];
    let v = json(&rtbake(&args));
    assert_eq!(v["transport_model"], "monte-carlo");
    assert_eq!(v["g"], 0.8);
    assert_eq!(v["photons"], 3000);
    assert_eq!(v["seed"], 1);
    let se: Vec<f64> = serde_json::from_value(v["total_R_se"].clone()).unwrap();
    let total: Vec<f64> = serde_json::from_value(v["total_R"].clone()).unwrap();
    assert!(se.iter().zip(&total).all(|(s, t)| *s > 0.0 && *s < 0.1 * t), "{se:?} {total:?}");
    assert_eq!(json(&rtbake(&args)), v, "same seed, same bytes");
    let other =
        json(&rtbake(&["profile", "--layers", f, "--model", "mc", "--photons", "3000", "--seed", "2", "--json"]));
    assert_ne!(other["total_R"], v["total_R"]);
    let multipole = json(&rtbake(&["profile", "--layers", f, "--json"]));
    assert_eq!(multipole["transport_model"], "multipole");
    let stack = rtbake::diffusion::layered::LayerStack::from_json_str(STACK).unwrap();
    let mc = rtbake::transport::McStack::from_layer_stack(&stack, 0.8).unwrap();
    let reference =
        rtbake::transport::simulate(&mc, &rtbake::transport::McSettings::new(20_000, 9, 10, 0.1, 10).unwrap());
    for c in 0..3 {
        // The profile counts the light that enters (÷ (1 − Rsp)), as the diffusion models do.
        let k = 1.0 / (1.0 - reference.channels[c].specular_reflectance);
        let r = reference.channels[c].diffuse_reflectance;
        let combined = ((k * r.se).powi(2) + se[c] * se[c]).sqrt();
        assert!((total[c] - k * r.mean).abs() <= 5.0 * combined, "channel {c}: {} vs {r:?}", total[c]);
        assert!(multipole["total_R"][c].as_f64().unwrap() > total[c], "channel {c}");
    }
}

/// Every command that takes the layered profile flags accepts `--model mc` (fits, kernel, importance kernel,
/// transmittance), and records the Monte Carlo model where it writes provenance.
#[test]
fn every_profile_consumer_runs_with_monte_carlo() {
    let t = tempfile::tempdir().unwrap();
    let file = t.path().join("stack.json");
    std::fs::write(&file, STACK).unwrap();
    let f = file.to_str().unwrap();
    let mc = ["--layers", f, "--model", "mc", "--photons", "2000", "--g", "0.5"];
    let with = |cmd: &[&str]| -> Vec<String> { cmd.iter().chain(mc.iter()).map(|s| s.to_string()).collect() };
    // (`fit separable --json` prints the fitted kernel only, no provenance.)
    for (cmd, records) in [
        (vec!["fit", "gaussians", "--json"], true),
        (vec!["fit", "separable", "--json"], false),
        (vec!["fit", "burley", "--json"], true),
        (vec!["transmittance", "--s", "0.5,1", "--json"], true),
        (vec!["importance-kernel", "--samples", "16", "--json"], true),
    ] {
        let args = with(&cmd);
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = rtbake(&refs);
        assert!(o.status.success(), "{cmd:?}: {}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(!records || text.contains("monte-carlo"), "{cmd:?} records the model: {text}");
    }
    let out = t.path().join("k");
    let o = rtbake(&[
        "kernel",
        "--samples",
        "11",
        "--out",
        out.to_str().unwrap(),
        "--name",
        "mc",
        "--quiet",
        mc[0],
        mc[1],
        mc[2],
        mc[3],
        mc[4],
        mc[5],
        mc[6],
        mc[7],
    ]);
    assert!(o.status.success(), "kernel: {}", String::from_utf8_lossy(&o.stderr));
}

/// `--skin-melanin/--skin-hemoglobin` give the spectral profile by default (its provenance says so and names the
/// projection); `--skin-projection band-averaged` keeps the old reduction and says so; the spectral Monte Carlo
/// runs per wavelength group.
#[test]
fn skins_are_spectral_by_default_and_band_averaged_by_name() {
    let skin = ["profile", "--skin-melanin", "0.1", "--skin-hemoglobin", "0.1", "--count", "20"];
    let with = |extra: &[&str]| -> serde_json::Value {
        let args: Vec<&str> = skin.iter().chain(extra).chain(["--json"].iter()).copied().collect();
        json(&rtbake(&args))
    };
    let v = with(&[]);
    assert_eq!(v["model"], "spectral-layered");
    assert_eq!(v["skin"]["projection"]["kind"], "spectral");
    assert_eq!(v["rgb"]["illuminant"], "d65");
    assert!(v["clipped_negative_mass"]["per_channel"][2].as_f64().unwrap() > 0.0);
    let b = with(&["--skin-projection", "band-averaged"]);
    assert_eq!(b["model"], "layered");
    assert_eq!(b["skin"]["projection"]["kind"], "band-averaged");
    let m = with(&["--model", "mc", "--photons", "300"]);
    assert_eq!(m["model"], "spectral-layered");
    assert_eq!(m["transport_model"], "monte-carlo");
    assert_eq!(m["wavelengths_nm"]["count"], 41);
}

/// Bad input is refused before any work with exit 2, naming the flag and the range; nothing is written.
#[test]
fn bad_model_input_is_refused_naming_the_flag() {
    let t = tempfile::tempdir().unwrap();
    let file = t.path().join("stack.json");
    std::fs::write(&file, STACK).unwrap();
    let f = file.to_str().unwrap();
    let out = t.path().join("p.csv");
    let o = out.to_str().unwrap();
    let base = ["profile", "--layers", f, "--csv", o];
    let run = |extra: &[&str]| rtbake(&base.iter().chain(extra).copied().collect::<Vec<_>>());
    assert_usage(&run(&["--model", "mc", "--g", "1"]), &["--g", "(-1, 1)"]);
    assert_usage(&run(&["--model", "mc", "--g", "-1.5"]), &["--g", "(-1, 1)"]);
    assert_usage(&run(&["--model", "mc", "--photons", "0"]), &["--photons", "1..="]);
    assert_usage(&run(&["--g", "0.5"]), &["--model mc"]);
    assert_usage(&rtbake(&["fit", "gaussians", "--layers", f, "--model", "mc", "--g", "1.0"]), &["--g"]);
    // A thick, nearly white slab, or g -> 1 with sigma_s' kept, would trace for hours: refused by the estimate.
    let white = t.path().join("white.json");
    std::fs::write(
        &white,
        r#"{"layers": [{"thickness_mm": 100.0, "eta": 1.4, "sigma_a": [1e-6, 1e-6, 1e-6], "sigma_s_prime": [10, 10, 10]}]}"#,
    )
    .unwrap();
    let w = white.to_str().unwrap();
    let slow = rtbake(&["profile", "--layers", w, "--model", "mc", "--photons", "1000000", "--csv", o]);
    assert_usage(&slow, &["--max-seconds", "--photons"]);
    assert_usage(&run(&["--model", "mc", "--g", "0.99999", "--max-seconds", "60"]), &["--max-seconds", "--g 0.99999"]);
    let forward = rtbake(&["transport", "--material", "skin1", "--thickness-mm", "5", "--g", "0.99999", "--out", o]);
    assert_usage(&forward, &["--max-seconds"]);
    assert_usage(&rtbake(&["transport", "--layers", w, "--photons", "1000000", "--out", o]), &["--max-seconds"]);
    assert!(!out.exists(), "nothing written");
}

/// `transport --csv X --out X` is refused (the second write would replace the first); the JSON's comparison
/// window is finite numbers (the tallied range), never null.
#[test]
fn transport_outputs_must_differ_and_window_is_finite() {
    let t = tempfile::tempdir().unwrap();
    let same = t.path().join("same.txt");
    let s = same.to_str().unwrap();
    let o = rtbake(&["transport", "--material", "skin1", "--photons", "200", "--csv", s, "--out", s]);
    assert_usage(&o, &["--csv", "--out", "same file"]);
    assert!(!same.exists());
    let v = json(&rtbake(&["transport", "--material", "skin1", "--photons", "200", "--bins", "40", "--json"]));
    let w = &v["diffusion_comparison"]["r_window_mm"];
    assert_eq!(w[0].as_f64(), Some(0.0));
    assert_eq!(w[1].as_f64(), Some(40.0 * 0.05));
}

/// `evaluate --against` takes the model flags for the targets that have a transport model (skin:CM,CHD and
/// layer-stack files): the target's provenance records the Monte Carlo and its standard errors; a named material
/// or preset with `--model mc`, g outside (−1, 1) and zero photons are refused with exit 2 naming the flag.
#[test]
fn evaluate_against_takes_the_model_flags() {
    let t = tempfile::tempdir().unwrap();
    let file = t.path().join("stack.json");
    std::fs::write(&file, STACK).unwrap();
    let f = file.to_str().unwrap();
    let base = ["--json", "evaluate", "--burley-albedo", "0.8,0.5,0.3", "--burley-d-mm", "1,0.5,0.25", "--against"];
    let run = |extra: &[&str]| rtbake(&base.iter().chain(extra).copied().collect::<Vec<_>>());
    for target in [f, "skin:0.1,0.1"] {
        let o = run(&[target, "--model", "mc", "--photons", "200", "--g", "0.5"]);
        assert!(o.status.success(), "{target}: {}", String::from_utf8_lossy(&o.stderr));
        let v = json(&o);
        assert_eq!(v["target"]["transport_model"], "monte-carlo", "{v}");
        assert_eq!(v["target"]["g"], 0.5);
        assert!(v["target"]["total_R_se"].as_array().unwrap().iter().all(|x| x.as_f64().unwrap() > 0.0), "{v}");
    }
    assert_usage(&run(&["skin1", "--model", "mc"]), &["--model mc", "skin1"]);
    assert_usage(&run(&["deon6", "--model", "mc"]), &["--model mc", "deon6"]);
    assert_usage(&run(&["skin:0.1,0.1", "--model", "mc", "--g", "-1"]), &["--g", "(-1, 1)"]);
    assert_usage(&run(&[f, "--model", "mc", "--photons", "0"]), &["--photons", "1..="]);
    assert_usage(&run(&[f, "--g", "0.5"]), &["--model mc"]);
}

/// Every profile consumer refuses a Henyey–Greenstein g outside (−1, 1) and a photon count of 0 with exit 2 naming
/// the flag and the range, before any work (nothing written where it writes files).
#[test]
fn every_profile_consumer_refuses_bad_model_flags() {
    let t = tempfile::tempdir().unwrap();
    let file = t.path().join("stack.json");
    std::fs::write(&file, STACK).unwrap();
    let f = file.to_str().unwrap();
    let out = t.path().join("k");
    let o = out.to_str().unwrap();
    let consumers: [Vec<&str>; 9] = [
        vec!["profile", "--layers", f, "--json"],
        vec!["fit", "gaussians", "--layers", f, "--json"],
        vec!["fit", "separable", "--layers", f, "--json"],
        vec!["fit", "burley", "--layers", f, "--json"],
        vec!["transmittance", "--layers", f, "--s", "0.5,1", "--json"],
        vec!["importance-kernel", "--layers", f, "--samples", "16", "--json"],
        vec!["kernel", "--layers", f, "--samples", "11", "--out", o, "--name", "bad"],
        vec!["evaluate", "--burley-albedo", "0.8,0.5,0.3", "--burley-d-mm", "1,0.5,0.25", "--against", f],
        vec!["profile", "--skin-melanin", "0.1", "--skin-hemoglobin", "0.1", "--json"],
    ];
    for cmd in &consumers {
        for (bad, needles) in [
            (["--g", "1.5"], ["--g", "(-1, 1)"]),
            (["--g", "-1"], ["--g", "(-1, 1)"]),
            (["--photons", "0"], ["--photons", "1..="]),
        ] {
            let args: Vec<&str> = cmd.iter().copied().chain(["--model", "mc"]).chain(bad).collect();
            assert_usage(&rtbake(&args), &needles);
        }
    }
    assert!(!out.exists(), "nothing written");
}
