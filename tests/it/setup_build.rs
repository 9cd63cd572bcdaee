//! The README's two set-up commands share one build: `cargo run --locked` (the main job) and `cargo test --locked`
//! must compile every dependency with the same features and profile, or the second command rebuilds wgpu and ~40
//! crates (a dev-dependency that turns on a feature of a shared crate — tempfile's bitflags `std`, ron's bitflags
//! `serde` and serde `alloc` — is enough). Checked on cargo's unit graphs (`--unit-graph`, read through
//! `RUSTC_BOOTSTRAP=1` as cargo's own tooling does), which list every unit without compiling anything.

use std::collections::BTreeSet;
use std::process::Command;

/// (package, features, mode, opt-level) of every non-rtbake unit of a cargo command's unit graph.
fn units(args: &[&str], target: &std::path::Path) -> BTreeSet<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let o = Command::new(cargo)
        .args(args)
        .args(["--locked", "--offline", "--unit-graph", "-Z", "unstable-options"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("RUSTC_BOOTSTRAP", "1")
        .env("CARGO_TARGET_DIR", target)
        .output()
        .expect("run cargo");
    assert!(o.status.success(), "cargo {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    let g: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    g["units"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|u| !u["pkg_id"].as_str().unwrap().contains("rtbake"))
        .map(|u| format!("{} {} {} {}", u["pkg_id"], u["features"], u["mode"], u["profile"]["opt_level"]))
        .collect()
}

#[test]
fn cargo_run_and_cargo_test_build_the_dependencies_once() {
    let t = tempfile::tempdir().unwrap();
    let run = units(&["build", "--bin", "rtbake"], t.path());
    let test = units(&["test", "--no-run"], t.path());
    let rebuilt: Vec<&String> = run.difference(&test).collect();
    assert!(run.len() > 200, "{} units", run.len());
    assert!(rebuilt.is_empty(), "cargo test would rebuild {} dependency units: {rebuilt:#?}", rebuilt.len());
}
