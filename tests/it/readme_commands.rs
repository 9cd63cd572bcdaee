//! Every command of the README runs as written: the lines of the README's ```sh blocks are run
//! in order with `sh -c` in a scratch directory (the first of them bakes `baked/` there), with this build's
//! `rtbake` first on the PATH. Only files a fresh clone has, or an earlier command wrote, may be named.

use crate::support::crate_dir;
use std::path::Path;
use std::process::Command;

/// The lines of the ```sh blocks, in order.
fn sh_lines(readme: &str) -> Vec<String> {
    let mut in_sh = false;
    let mut lines = Vec::new();
    for line in readme.lines() {
        let t = line.trim();
        if t.starts_with("```") {
            in_sh = !in_sh && t == "```sh";
            continue;
        }
        if in_sh && !t.is_empty() && !t.starts_with('#') {
            lines.push(t.to_string());
        }
    }
    lines
}

#[test]
fn every_readme_command_runs_as_written() {
    let readme = std::fs::read_to_string(crate_dir().join("README.md")).unwrap();
    let lines = sh_lines(&readme);
    assert!(lines.len() >= 35, "expected the README's examples, found {} lines: {lines:?}", lines.len());
    assert!(lines[0].starts_with("rtbake bake"), "the first example must bake: {:?}", lines[0]);
    // Any `rtbake …` shown outside a ```sh block would escape this test.
    for (i, l) in readme.lines().enumerate() {
        let cmd =
            l.trim_start().strip_prefix("rtbake ").filter(|_| l.starts_with("    rtbake ") || l.starts_with("rtbake "));
        if cmd.is_some_and(|rest| rest.starts_with(|c: char| c.is_ascii_lowercase() || c == '-')) {
            assert!(lines.iter().any(|x| x == l.trim()), "README line {}: {l:?} is not in a ```sh block", i + 1);
        }
    }
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_rtbake")).parent().unwrap().to_path_buf();
    let path = format!("{}:{}", bin_dir.display(), std::env::var("PATH").unwrap_or_default());
    let t = tempfile::tempdir().unwrap();
    for line in &lines {
        let o = Command::new("sh").arg("-c").arg(line).current_dir(t.path()).env("PATH", &path).output().unwrap();
        assert!(
            o.status.success(),
            "README command failed ({}):\n  {line}\nstdout: {}\nstderr: {}",
            o.status,
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    // What the examples promise to write.
    let d = t.path();
    for f in [
        "baked/manifest.json",
        "out/aa-bake/aa/smaa/AreaTex.dds",
        "out/small-lut/skin/skin_color_lut.exr",
        "out/mlaa/AreaMap257_v1.4.bin",
        "out/smaa/AreaTex.ktx2",
        "out/profile.csv",
        "out/fit",
        "out/t",
        "out/k",
        "out/lut/skin_color_lut.exr",
        "out/rig/rig.json",
        "out/h.exr",
        "out/maps/neutral.png",
        "out/rig2/rig.json",
        "out/wrinkles",
        "out/demo.png",
        "out/aliased.png",
        "out/sss-in/irradiance.exr",
        "out/sss-in/depth.exr",
        "out/smaa.png",
        "out/mlaa.png",
        "out/sss.exr",
    ] {
        assert!(d.join(f).exists(), "{f} was not written by the README's commands");
    }
    assert!(!d.join("out/mlaa/AreaMap257_v1.4.h").exists(), "a 3 MiB table got its C source by default");
    assert!(!d.join("out/lut/skin").exists(), "skin-color --out DIR must write into DIR");
}
