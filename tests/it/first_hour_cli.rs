//! What a new user meets in the first hour: one spelling of a flag works everywhere, a directory output named like a
//! file is refused, `verify DIR` works without `--dir`, a PNG given where an EXR belongs is named as such, the global
//! options are listed apart in every subcommand's help, and errors of hundreds of percent say what they mean.

use crate::support::{crate_dir, rtbake};
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn out_and_output_and_both_profile_spellings_work_everywhere() {
    let t = tempfile::tempdir().unwrap();
    // A directory command given --output, a file command given --out.
    let d = t.path().join("luts");
    let o = rtbake(&["aa", "smaa-search", "--output", s(&d), "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(d.join("SearchTex.dds").is_file() || std::fs::read_dir(&d).unwrap().count() > 0);
    let png = t.path().join("demo.png");
    let o = rtbake(&["run", "demo", "--cpu", "--width", "32", "--height", "18", "--out", s(&png), "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(png.is_file());
    // fit separable spells the preset --profile, the other commands --profile-preset: both work in both.
    for (cmd, flag) in [(&["fit", "separable"][..], "--profile-preset"), (&["fit", "gaussians"][..], "--profile")] {
        let o = rtbake(&[cmd, &[flag, "deon6", "--help"]].concat());
        assert!(o.status.success(), "{cmd:?} {flag}: {}", stderr(&o));
    }
    let o = rtbake(&["fit", "gaussians", "--profile", "deon6", "--count", "2", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_directory_output_named_like_a_file_is_refused() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("t.png");
    for cmd in [&["aa", "smaa-search"][..], &["bake", "smaa-search"]] {
        let o = rtbake(&[cmd, &["--out", s(&out)]].concat());
        assert_eq!(o.status.code(), Some(2), "{cmd:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("--out") && stderr(&o).contains("t.png") && stderr(&o).contains("directory"));
        assert!(!out.exists(), "{cmd:?}: a directory named t.png was created");
    }
}

#[test]
fn verify_takes_the_directory_without_dir_and_png_for_exr_is_named() {
    let t = tempfile::tempdir().unwrap();
    let b = t.path().join("b");
    assert!(rtbake(&["bake", "smaa-search", "-q", "--out", s(&b)]).status.success());
    let o = rtbake(&["verify", s(&b)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("OK") || String::from_utf8_lossy(&o.stdout).contains("OK"), "{}", stderr(&o));
    std::fs::write(b.join("aa/smaa/SearchTex.dds"), b"changed").unwrap();
    assert_eq!(rtbake(&["verify", s(&b)]).status.code(), Some(1), "the positional directory is the one verified");
    let png = crate_dir().join("tests/fixtures/facial/hemoglobin_neutral.png");
    let out = t.path().join("o.exr");
    let o = rtbake(&["run", "sss", "--cpu", "--color", s(&png), "--depth", s(&png), "--output", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--color") && stderr(&o).contains("is a PNG image"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn global_options_have_their_own_heading_in_subcommand_help() {
    let o = rtbake(&["fit", "gaussians", "--help"]);
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    let (own, global) = help.split_once("Global options:").expect("a Global options heading");
    assert!(global.contains("--max-memory") && global.contains("--no-wait"), "{help}");
    assert!(!own.contains("--max-memory") && own.contains("--count"), "{help}");
}

#[test]
fn errors_of_hundreds_of_percent_say_what_they_mean() {
    let deon6 = crate_dir().join("baked/sss/gaussians/deon6.json");
    let o = rtbake(&["evaluate", "--gaussians", s(&deon6), "--against", "skin1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(out.contains("note: errors above 100 % mean the candidate is a different profile"), "{out}");
    assert!(out.contains("--normalize"), "{out}");
    // A fit evaluated back stays below 100 %: no note.
    let o = rtbake(&["evaluate", "--gaussians", s(&deon6), "--against", "deon6"]);
    assert!(!String::from_utf8_lossy(&o.stdout).contains("note:"), "{}", String::from_utf8_lossy(&o.stdout));
}
