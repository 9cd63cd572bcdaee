//! Multi-file outputs outside `bake` are one set (locked, all or nothing, a kill rolled
//! forward by the next command that locks or reads the directory), and an output equal to an input is refused.
//! Kill points come from the `RTBAKE_FAULT_INJECT` hook, not from timing.

use crate::support::rtbake;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("tests/fixtures/facial/hemoglobin_{name}.png"))
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `maps hemoglobin` over the fixtures with the given neutral map, into `out`, with a fault directive.
fn hemoglobin(neutral: &str, out: &Path, fault: &str) -> Output {
    let anger = format!("anger={}", s(&fixture("anger")));
    Command::new(env!("CARGO_BIN_EXE_rtbake"))
        .args(["maps", "hemoglobin", "--neutral", s(&fixture(neutral)), "--target", &anger])
        .args(["--radius", "4", "--rig-size", "16", "--out", s(out), "-q"])
        .env("RTBAKE_FAULT_INJECT", fault)
        .output()
        .unwrap()
}

/// Names and sha256 of the files in `dir`.
fn files_of(dir: &Path) -> Vec<(String, String)> {
    let mut v: Vec<(String, String)> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| {
            let sha = rtbake::manifest::sha256_hex(&std::fs::read(e.path()).unwrap());
            (e.file_name().to_string_lossy().into_owned(), sha)
        })
        .collect();
    v.sort();
    v
}

#[test]
fn a_killed_rig_write_is_never_seen_mixed() {
    let t = tempfile::tempdir().unwrap();
    // The two rigs a pipeline alternates between, written cleanly for reference.
    let (old_ref, new_ref) = (t.path().join("old"), t.path().join("new"));
    assert!(hemoglobin("neutral", &old_ref, "").status.success());
    assert!(hemoglobin("joy", &new_ref, "").status.success());
    assert_ne!(files_of(&old_ref), files_of(&new_ref));
    // The directory exchanged whole (Linux), and the journal where it cannot be (`no-exchange`).
    for (step, committed, fault) in [
        ("locked", false, ""),
        ("staged", false, ""),
        ("before-swap", false, ""),
        ("after-swap", true, ""),
        ("staged", false, ",no-exchange"),
        ("journal-written", true, ",no-exchange"),
        ("mid-commit", true, ",no-exchange"),
    ] {
        let rig = t.path().join(format!("rig-{step}{}", fault.replace(',', "-")));
        assert!(hemoglobin("neutral", &rig, "").status.success());
        let o = hemoglobin("joy", &rig, &format!("kill@{step}{fault}"));
        assert_eq!(o.status.code(), Some(137), "{step}: {}", stderr(&o));
        if fault.is_empty() {
            // Exchanged whole: what any reader sees right after the kill, before any rtbake command runs, is one
            // complete set, old or new.
            let want = if committed { &new_ref } else { &old_ref };
            assert_eq!(files_of(&rig), files_of(want), "{step}: visible mixed or incomplete right after the kill");
        }
        // rig-eval reads the rig: it first completes a committed set, so it never evaluates a mix.
        let h = t.path().join(format!("h-{step}.exr"));
        let o =
            rtbake(&["maps", "rig-eval", "--rig", s(&rig.join("rig.json")), "--weights", "neutral=1", "--out", s(&h)]);
        assert!(o.status.success(), "{step}: {}", stderr(&o));
        let want = if committed { &new_ref } else { &old_ref };
        if committed {
            assert_eq!(files_of(&rig), files_of(want), "{step}: the rig is not the complete new set");
        } else {
            // Before the commit point only orphan temp files may remain; the next writer removes them.
            let visible: Vec<_> = files_of(&rig).into_iter().filter(|(n, _)| !n.contains(".rtbake-tmp-")).collect();
            assert_eq!(visible, files_of(want), "{step}: the old rig was touched");
            assert!(hemoglobin("neutral", &rig, "").status.success());
            assert_eq!(files_of(&rig), files_of(&old_ref), "{step}: temp files left after the next write");
        }
    }
}

#[test]
fn an_output_that_is_an_input_is_refused() {
    let t = tempfile::tempdir().unwrap();
    let rig = t.path().join("r");
    assert!(hemoglobin("neutral", &rig, "").status.success());
    let before = files_of(&rig);
    // Same file, spelled two ways.
    let json = rig.join("rig.json");
    let dotted = rig.join(".").join("h0.exr");
    for out in [json.clone(), dotted] {
        let o = rtbake(&["maps", "rig-eval", "--rig", s(&json), "--weights", "neutral=1", "--out", s(&out)]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let err = stderr(&o);
        let name = out.file_name().unwrap().to_str().unwrap();
        assert!(err.contains("refusing to overwrite the input") && err.contains(name), "{err}");
        assert_eq!(files_of(&rig), before);
    }
    // A rig written over its own input map.
    let n = t.path().join("n");
    std::fs::create_dir(&n).unwrap();
    let neutral = n.join("rig.json");
    std::fs::copy(fixture("neutral"), &neutral).unwrap();
    let anger = format!("anger={}", s(&fixture("anger")));
    let o = rtbake(&[
        "maps",
        "hemoglobin",
        "--neutral",
        s(&neutral),
        "--target",
        &anger,
        "--radius",
        "4",
        "--rig-size",
        "16",
        "--out",
        s(&n),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read(&neutral).unwrap(), std::fs::read(fixture("neutral")).unwrap());
}

#[test]
fn a_second_writer_of_an_output_directory_waits_or_fails_fast() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("aa");
    let mut first = Command::new(env!("CARGO_BIN_EXE_rtbake"))
        .args(["aa", "smaa-search", "--out", s(&d), "-q"])
        .env("RTBAKE_FAULT_INJECT", "hold@staged")
        .stdin(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(first.stderr.take().unwrap());
    let mut line = String::new();
    while !line.contains("holding at staged") {
        line.clear();
        assert!(err.read_line(&mut line).unwrap() > 0, "first writer ended early");
    }
    let o = rtbake(&["aa", "mlaa-v2", "--out", s(&d), "--no-wait"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    first.stdin.as_mut().unwrap().write_all(b"\n").unwrap();
    assert!(first.wait().unwrap().success());
    assert!(rtbake(&["aa", "mlaa-v2", "--out", s(&d), "--no-wait", "-q"]).status.success());
    let names: Vec<String> = files_of(&d).into_iter().map(|(n, _)| n).collect();
    assert!(names.iter().all(|n| !n.contains("rtbake-")), "{names:?}");
    assert!(
        names.iter().any(|n| n.starts_with("SearchTex")) && names.iter().any(|n| n.starts_with("AreaTex_MLAAv2")),
        "{names:?}"
    );
}

#[test]
fn single_file_outputs_equal_to_an_input_are_refused_too() {
    let t = tempfile::tempdir().unwrap();
    let layers = t.path().join("l.json");
    let text = r#"{"eta_above": 1.0, "eta_below": 1.0, "layers": [{"thickness_mm": 1.0, "eta": 1.4, "sigma_a": [0.1, 0.1, 0.1], "sigma_s_prime": [1, 1, 1]}]}"#;
    std::fs::write(&layers, text).unwrap();
    for flag in ["--out", "--csv"] {
        let o = rtbake(&["profile", "--layers", s(&layers), "--count", "4", flag, s(&layers)]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(flag) && stderr(&o).contains("refusing to overwrite the input"), "{}", stderr(&o));
        assert_eq!(std::fs::read_to_string(&layers).unwrap(), text);
    }
    let png = t.path().join("in.png");
    std::fs::copy(fixture("neutral"), &png).unwrap();
    let before = std::fs::read(&png).unwrap();
    let o = rtbake(&["run", "smaa", "--cpu", "--input", s(&png), "--output", s(&t.path().join(".").join("in.png"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--output") && stderr(&o).contains("refusing to overwrite the input"));
    assert_eq!(std::fs::read(&png).unwrap(), before);
}
