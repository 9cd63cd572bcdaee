//! Multi-file outputs seen by a reader that is not rtbake (an engine loading the directory): never a mix of two
//! runs, whatever instant a kill hits; what a killed writer leaves beside the directory is removed by the next
//! command that locks it, `verify` included; a listed file replaced by a symbolic link fails `verify`. Kill points
//! come from `RTBAKE_FAULT_INJECT`.

use crate::support::rtbake;
use std::path::Path;
use std::process::{Command, Output};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// (name, bytes) of every entry in `dir`, recursively, sorted.
fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if e.file_type().unwrap().is_dir() {
            v.extend(tree(&e.path()).into_iter().map(|(n, b)| (format!("{name}/{n}"), b)));
        } else {
            v.push((name, std::fs::read(e.path()).unwrap()));
        }
    }
    v.sort();
    v
}

/// Entries rtbake left beside `dir` (staging directories, journals), the lock file excepted.
fn leftovers_beside(dir: &Path) -> Vec<String> {
    let prefix = format!(".{}.rtbake-", dir.file_name().unwrap().to_string_lossy());
    std::fs::read_dir(dir.parent().unwrap())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(&prefix) && !n.ends_with("rtbake-lock"))
        .collect()
}

fn aa_four_formats(out: &Path, fault: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rtbake"))
        .args(["aa", "mlaa-v1.4", "--format", "bin,dds,ktx2,png", "-q", "--out", s(out)])
        .env("RTBAKE_FAULT_INJECT", fault)
        .output()
        .unwrap()
}

#[test]
fn a_kill_anywhere_in_a_four_format_write_leaves_the_old_or_the_new_set() {
    let t = tempfile::tempdir().unwrap();
    let fresh = t.path().join("fresh");
    assert!(aa_four_formats(&fresh, "").status.success(), "reference write");
    let new_set = tree(&fresh);
    // bin, dds (DX10) and its legacy-header copy, ktx2, png; Bevy's `.meta` beside the four textures.
    assert_eq!(new_set.len(), 9, "{:?}", new_set.iter().map(|f| &f.0).collect::<Vec<_>>());
    for (step, committed) in [("locked", false), ("staged", false), ("before-swap", false), ("after-swap", true)] {
        let d = t.path().join(format!("D-{step}"));
        std::fs::create_dir_all(d.join("engine")).unwrap();
        // An earlier run's set (other bytes under the same names) beside the user's own files.
        for (name, _) in &new_set {
            std::fs::write(d.join(name), format!("old {name}")).unwrap();
        }
        std::fs::write(d.join("notes.txt"), b"mine").unwrap();
        std::fs::write(d.join("engine/config.ini"), b"kept").unwrap();
        let old = tree(&d);
        let o = aa_four_formats(&d, &format!("kill@{step}"));
        assert_eq!(o.status.code(), Some(137), "{step}: {}", stderr(&o));
        let seen = tree(&d);
        let mut want = if committed { new_set.clone() } else { Vec::new() };
        if committed {
            want.push(("engine/config.ini".into(), b"kept".to_vec()));
            want.push(("notes.txt".into(), b"mine".to_vec()));
            want.sort();
        } else {
            want = old.clone();
        }
        assert_eq!(seen, want, "{step}: the directory is not exactly the old or the new state");
        // The next command that locks the directory removes what the killed writer left beside it.
        assert!(aa_four_formats(&d, "").status.success());
        assert_eq!(leftovers_beside(&d), Vec::<String>::new(), "{step}");
        assert_eq!(std::fs::read(d.join("notes.txt")).unwrap(), b"mine", "{step}: a user file was lost");
    }
}

#[test]
fn verify_removes_a_killed_bakes_staging_directory() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("b");
    let o = Command::new(env!("CARGO_BIN_EXE_rtbake"))
        .args(["bake", "smaa-search", "-q", "--out", s(&d)])
        .env("RTBAKE_FAULT_INJECT", "kill@before-swap")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(137), "{}", stderr(&o));
    assert_eq!(leftovers_beside(&d).len(), 1, "the killed bake's stage: {:?}", leftovers_beside(&d));
    assert!(rtbake(&["bake", "smaa-search", "-q", "--out", s(&d)]).status.success());
    // A stage whose process is gone (pid far above any live one), as a kill during a bake leaves it.
    let stale = t.path().join(".b.rtbake-stage-4000000");
    std::fs::create_dir(&stale).unwrap();
    std::fs::write(stale.join("big.bin"), vec![0u8; 1024]).unwrap();
    let o = rtbake(&["verify", "--dir", s(&d), "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stale.exists(), "verify left the dead process's staging directory");
}

#[test]
fn a_listed_file_replaced_by_a_symlink_fails_verify_with_and_without_pin() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("b");
    assert!(rtbake(&["bake", "smaa-search", "-q", "--out", s(&d)]).status.success());
    let file = d.join("aa/smaa/SearchTex.dds");
    let outside = t.path().join("identical.dds");
    std::fs::copy(&file, &outside).unwrap();
    std::fs::remove_file(&file).unwrap();
    std::os::unix::fs::symlink(&outside, &file).unwrap();
    let pin = t.path().join("pin");
    let digest = rtbake::manifest::sha256_hex(&std::fs::read(d.join("manifest.json")).unwrap());
    std::fs::write(&pin, format!("{digest}  manifest.json\n")).unwrap();
    for extra in [&[][..], &["--pin", s(&pin)][..]] {
        let o = rtbake(&[&["verify", "--dir", s(&d)][..], extra].concat());
        assert_eq!(o.status.code(), Some(1), "{extra:?}: {}", stderr(&o));
        let out = format!("{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
        assert!(
            out.contains("aa/smaa/SearchTex.dds is a symbolic link to") && out.contains("identical.dds"),
            "{extra:?}: {out}"
        );
    }
}

#[test]
fn transport_csv_json_and_plot_in_one_directory_are_one_set() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("mc");
    std::fs::create_dir(&d).unwrap();
    let run = |seed: &str, fault: &str| {
        Command::new(env!("CARGO_BIN_EXE_rtbake"))
            .args(["transport", "--material", "skin1", "--photons", "2000", "--seed", seed, "-q"])
            .args(["--csv", s(&d.join("r.csv")), "--out", s(&d.join("r.json")), "--plot", s(&d.join("r.svg"))])
            .env("RTBAKE_FAULT_INJECT", fault)
            .output()
            .unwrap()
    };
    assert!(run("1", "").status.success());
    let first = tree(&d);
    assert_eq!(first.len(), 3);
    let o = run("2", "kill@before-swap");
    assert_eq!(o.status.code(), Some(137), "{}", stderr(&o));
    assert_eq!(tree(&d), first, "a kill before the swap left the first run's trio");
    let o = run("2", "kill@after-swap");
    assert_eq!(o.status.code(), Some(137), "{}", stderr(&o));
    let second = tree(&d);
    assert!(second.iter().zip(&first).all(|(a, b)| a.0 == b.0 && a.1 != b.1), "all three files are the new run's");
}
