//! `rtbake bake` / `verify` / `assets` from the command line: exit codes, messages, atomicity.

use std::path::Path;
use std::process::{Command, Output};

/// A small, fast asset used to exercise the machinery.
const SMALL: &str = "smaa-search";

use crate::support::rtbake;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    fn walk(base: &Path, d: &Path, out: &mut Vec<(String, Vec<u8>)>) {
        for e in std::fs::read_dir(d).unwrap().flatten() {
            if e.path().is_dir() {
                walk(base, &e.path(), out);
            } else {
                out.push((
                    e.path().strip_prefix(base).unwrap().display().to_string(),
                    std::fs::read(e.path()).unwrap(),
                ));
            }
        }
    }
    if dir.exists() {
        walk(dir, dir, &mut out);
    }
    out.sort();
    out
}

#[test]
fn version_and_help() {
    let o = rtbake(&["--version"]);
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains(env!("CARGO_PKG_VERSION")));
    let o = rtbake(&["bake", "--help"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("[default: baked]"));
}

#[test]
fn unknown_asset_is_refused_and_nothing_is_written() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("b");
    let o = rtbake(&["bake", "no-such-asset", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("unknown asset \"no-such-asset\""), "{}", stderr(&o));
    assert!(stderr(&o).contains(SMALL), "the message lists the known assets");
    assert!(!out.exists());
}

#[test]
fn unwritable_output_directory_is_refused() {
    let t = tempfile::tempdir().unwrap();
    let file = t.path().join("plain-file");
    std::fs::write(&file, b"x").unwrap();
    let out = file.join("sub");
    let o = rtbake(&["bake", SMALL, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--out"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
}

#[test]
fn bake_verify_and_catch_a_flipped_byte_in_any_file() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("b");
    let o = rtbake(&["bake", SMALL, "--out", out.to_str().unwrap(), "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = rtbake(&["verify", "--dir", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let files = snapshot(&out);
    assert!(files.len() > 4);
    for (rel, bytes) in &files {
        let p = out.join(rel);
        let mut bad = bytes.clone();
        let i = bad.len() / 3;
        bad[i] ^= 0x20;
        std::fs::write(&p, &bad).unwrap();
        let o = rtbake(&["verify", "--dir", out.to_str().unwrap()]);
        assert_ne!(o.status.code(), Some(0), "a flipped byte in {rel} went unnoticed");
        if rel != "manifest.json" {
            assert!(stderr(&o).contains(rel.as_str()), "report names {rel}: {}", stderr(&o));
        } else {
            assert!(stderr(&o).contains("manifest"), "{}", stderr(&o));
        }
        std::fs::write(&p, bytes).unwrap();
    }
    assert!(rtbake(&["verify", "--dir", out.to_str().unwrap()]).status.success());
    // A stray file is reported as extra.
    std::fs::write(out.join("stray.bin"), b"?").unwrap();
    let o = rtbake(&["verify", "--dir", out.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(1));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(report["files"].as_array().unwrap().iter().any(|f| f["path"] == "stray.bin" && f["status"] == "extra"));
}

#[test]
fn bad_asset_parameters_touch_nothing() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("b");
    assert!(rtbake(&["bake", SMALL, "--out", out.to_str().unwrap(), "-q"]).status.success());
    let before = snapshot(&out);
    let params = t.path().join("p.json");
    std::fs::write(&params, format!("{{\"{SMALL}\": {{\"no_such_field\": 1}}}}")).unwrap();
    let o = rtbake(&["bake", SMALL, "--out", out.to_str().unwrap(), "--asset-params", params.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(before, snapshot(&out));
    std::fs::write(&params, "{ not json").unwrap();
    let o = rtbake(&["bake", SMALL, "--out", out.to_str().unwrap(), "--asset-params", params.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("malformed JSON"), "{}", stderr(&o));
    assert_eq!(before, snapshot(&out));
}

#[test]
fn asset_params_over_the_time_budget_are_refused_before_any_work() {
    // Monte Carlo skins at 10^8 photons per wavelength: hours by the photon kernel's estimate. The bake is refused
    // before anything is written (the existing bake stays as it was, a new directory is not created), naming the
    // asset, the estimate and the budget; under a raised budget the estimate is no longer the refusal.
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("b");
    assert!(rtbake(&["bake", SMALL, "--out", out.to_str().unwrap(), "-q"]).status.success());
    let before = snapshot(&out);
    let params = t.path().join("p.json");
    let skin_mc = |photons: u64| {
        serde_json::json!({"diffusion-profiles": {"skin_model": {"model": "mc", "photons": photons}}}).to_string()
    };
    std::fs::write(&params, skin_mc(100_000_000)).unwrap();
    for dir in [&out, &t.path().join("new")] {
        let o = rtbake(&[
            "bake",
            "diffusion-profiles",
            "--out",
            dir.to_str().unwrap(),
            "--asset-params",
            params.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains("diffusion-profiles ~") && e.contains("time budget of 600 s") && e.contains("--max-seconds"),
            "{e}"
        );
    }
    assert_eq!(before, snapshot(&out));
    assert!(!t.path().join("new").exists());
    // The default transport report is estimated, and within the default budget; a smaller budget refuses it.
    let o = rtbake(&["bake", "transport-report", "--out", out.to_str().unwrap(), "--max-seconds", "1"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("transport-report ~"), "{}", stderr(&o));
    // A bad parameter the estimate reads is named as the bake names it.
    std::fs::write(&params, r#"{"diffusion-profiles": {"skin_model": {"model": "mc", "g": 1.5}}}"#).unwrap();
    let o = rtbake(&[
        "bake",
        "diffusion-profiles",
        "--out",
        out.to_str().unwrap(),
        "--asset-params",
        params.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("skin_model.g must be in the open interval (-1, 1)"), "{}", stderr(&o));
    assert_eq!(before, snapshot(&out));
}

#[test]
fn params_file_sets_flags_and_explicit_flags_override_it() {
    let t = tempfile::tempdir().unwrap();
    let params = t.path().join("p.json");
    let from_file = t.path().join("from-file");
    let explicit = t.path().join("explicit");
    std::fs::write(&params, serde_json::json!({"out": from_file.to_str().unwrap()}).to_string()).unwrap();
    assert!(rtbake(&["bake", SMALL, "--params", params.to_str().unwrap(), "-q"]).status.success());
    assert!(from_file.join("manifest.json").exists());
    let o = rtbake(&["bake", SMALL, "--params", params.to_str().unwrap(), "--out", explicit.to_str().unwrap(), "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(explicit.join("manifest.json").exists());
}

#[test]
fn killed_bake_leaves_old_or_new_directory_never_a_mix() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("b");
    assert!(rtbake(&["bake", SMALL, "--out", out.to_str().unwrap(), "-q"]).status.success());
    for delay_ms in [5u64, 20, 60, 150, 400] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_rtbake"))
            .args(["bake", "--out", out.to_str().unwrap(), "-q"])
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        // Whatever moment it died at, the directory (after recovery of an interrupted swap) verifies.
        let o = rtbake(&["verify", "--dir", out.to_str().unwrap()]);
        assert!(o.status.success(), "after kill at {delay_ms} ms: {}", stderr(&o));
        for e in std::fs::read_dir(&out).unwrap().flatten() {
            assert!(!e.file_name().to_string_lossy().contains("rtbake-"), "temp file left inside baked dir");
        }
    }
}

#[test]
fn verify_refuses_a_missing_directory_and_leaves_nothing_behind() {
    let t = tempfile::tempdir().unwrap();
    let missing = t.path().join("MISSING");
    let o = rtbake(&["verify", "--dir", missing.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains(missing.to_str().unwrap()) && stderr(&o).contains("does not exist"), "{}", stderr(&o));
    // No lock file (`.MISSING.rtbake-lock`), stage or directory appears in the parent.
    let left: Vec<_> = std::fs::read_dir(t.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    // A file where the directory should be: refused the same way, the file untouched.
    let file = t.path().join("f");
    std::fs::write(&file, b"x").unwrap();
    let o = rtbake(&["verify", "--dir", file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("is not a directory"), "{}", stderr(&o));
    let left: Vec<_> = std::fs::read_dir(t.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left, vec![std::ffi::OsString::from("f")]);
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
}
