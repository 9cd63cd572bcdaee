//! The bake directory under concurrent runs, kills at every step of the swap, a
//! symlinked `--out` and `--out .`. Concurrency uses two real processes; the interleaving is forced through the
//! `RTBAKE_FAULT_INJECT` hook (`hold@STEP` stops a process at STEP until a line arrives on its stdin), never sleeps.

use crate::support::rtbake;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStderr, Command, Output, Stdio};

const A: &str = "smaa-search";
const B: &str = "mlaa-v2";

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rtbake"))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Starts `rtbake args` with a fault directive, stdin and stderr piped.
fn spawn(args: &[&str], fault: &str) -> (Child, BufReader<ChildStderr>) {
    let mut child = bin()
        .args(args)
        .env("RTBAKE_FAULT_INJECT", fault)
        .stdin(Stdio::piped())
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let err = BufReader::new(child.stderr.take().unwrap());
    (child, err)
}

/// Reads the child's stderr until a line containing `needle` (blocking read; fails at end of stream).
fn wait_for(err: &mut BufReader<ChildStderr>, needle: &str) {
    let mut seen = String::new();
    loop {
        let mut line = String::new();
        assert!(err.read_line(&mut line).unwrap() > 0, "stream ended before {needle:?}; got:\n{seen}");
        if line.contains(needle) {
            return;
        }
        seen.push_str(&line);
    }
}

fn release(child: &mut Child) {
    child.stdin.as_mut().unwrap().write_all(b"go\n").unwrap();
}

fn assets_in(dir: &Path) -> Vec<String> {
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    m["assets"].as_array().unwrap().iter().map(|a| a["name"].as_str().unwrap().to_string()).collect()
}

/// Entries beside `dir` other than `dir` itself and lock files (leftover staging/old directories).
fn leftovers_beside(dir: &Path) -> Vec<String> {
    let name = dir.file_name().unwrap().to_string_lossy().into_owned();
    std::fs::read_dir(dir.parent().unwrap())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(&format!(".{name}.rtbake-")) && !n.ends_with(".rtbake-lock"))
        .collect()
}

fn internal_files_inside(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    fn walk(d: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(d).unwrap().flatten() {
            if e.path().is_dir() {
                walk(&e.path(), out);
            } else if e.file_name().to_string_lossy().contains("rtbake-") {
                out.push(e.path());
            }
        }
    }
    walk(dir, &mut out);
    out
}

#[test]
fn concurrent_bakes_of_different_assets_serialise_and_keep_both() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("d");
    // First bake stops after staging, holding the lock.
    let (mut first, mut first_err) = spawn(&["bake", A, "--out", s(&d)], "hold@staged");
    wait_for(&mut first_err, "holding at staged");
    // A second bake and a verify fail fast with --no-wait (exit 3, naming the directory) ...
    let o = rtbake(&["bake", B, "--out", s(&d), "--no-wait"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(stderr(&o).contains("locked by another rtbake process"), "{}", stderr(&o));
    // ... and the live staging directory of the first survives them (finding 2).
    let o = rtbake(&["verify", "--dir", s(&d), "--no-wait"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert_eq!(leftovers_beside(&d), [format!(".d.rtbake-stage-{}", first.id())]);
    // Without --no-wait the second bake says it waits, then waits.
    let (mut second, mut second_err) = spawn(&["bake", B, "--out", s(&d)], "");
    wait_for(&mut second_err, "waiting for the lock");
    release(&mut first);
    assert!(first.wait().unwrap().success());
    assert!(second.wait().unwrap().success());
    // No lost update: both assets are in the manifest and everything verifies.
    assert_eq!(assets_in(&d), [B, A]);
    let o = rtbake(&["verify", "--dir", s(&d)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(leftovers_beside(&d).is_empty(), "{:?}", leftovers_beside(&d));
}

#[test]
fn verify_waits_for_a_running_bake_and_sees_the_finished_directory() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("d");
    assert!(rtbake(&["bake", A, "--out", s(&d), "-q"]).status.success());
    let (mut bake, mut bake_err) = spawn(&["bake", B, "--out", s(&d)], "hold@before-swap");
    wait_for(&mut bake_err, "holding at before-swap");
    let (mut verify, mut verify_err) = spawn(&["verify", "--dir", s(&d)], "");
    wait_for(&mut verify_err, "waiting for the lock");
    release(&mut bake);
    assert!(bake.wait().unwrap().success());
    let status = verify.wait().unwrap();
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut verify_err, &mut rest).unwrap();
    assert!(status.success(), "{rest}");
    assert_eq!(assets_in(&d), [B, A]);
}

/// Kills a bake of {A, B} over a directory holding {A} at `step`; the directory must then hold either {A} (killed
/// before the commit point) or {A, B}, verify, and keep no rtbake file inside.
fn kill_at(step: &str, exchange: bool, committed: bool) {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("d");
    assert!(rtbake(&["bake", A, "--out", s(&d), "-q"]).status.success());
    let fault = if exchange { format!("kill@{step}") } else { format!("kill@{step},no-exchange") };
    let o = bin().args(["bake", A, B, "--out", s(&d), "-q"]).env("RTBAKE_FAULT_INJECT", &fault).output().unwrap();
    assert_eq!(o.status.code(), Some(137), "{fault}: did not stop at the kill point: {}", stderr(&o));
    if exchange {
        assert!(d.join("manifest.json").is_file(), "{fault}: the bake directory vanished");
    }
    // The next command (here verify) finishes or discards what the killed one left.
    let o = rtbake(&["verify", "--dir", s(&d)]);
    assert!(o.status.success(), "{fault}: {}", stderr(&o));
    let want: &[&str] = if committed { &[B, A] } else { &[A] };
    assert_eq!(assets_in(&d), want, "{fault}");
    assert!(internal_files_inside(&d).is_empty(), "{fault}: {:?}", internal_files_inside(&d));
    // A bake (exclusive lock) removes whatever leftover the shared-lock verify left beside the directory.
    assert!(rtbake(&["bake", A, "--out", s(&d), "-q"]).status.success());
    assert!(leftovers_beside(&d).is_empty(), "{fault}: {:?}", leftovers_beside(&d));
}

#[test]
fn a_kill_at_any_step_of_the_exchange_swap_leaves_old_or_new() {
    for (step, committed) in [("probe", false), ("locked", false), ("staged", false), ("before-swap", false)] {
        kill_at(step, true, committed);
    }
    kill_at("after-swap", true, true);
}

#[test]
fn a_kill_at_any_step_of_the_fallback_swap_is_rolled_forward() {
    for (step, committed) in [("before-swap", false), ("after-ready", true), ("between-renames", true)] {
        kill_at(step, false, committed);
    }
    kill_at("after-swap", false, true);
}

#[test]
fn a_probe_left_by_an_older_rtbake_is_not_carried_over() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("d");
    assert!(rtbake(&["bake", A, "--out", s(&d), "-q"]).status.success());
    std::fs::write(d.join(".rtbake-write-probe-12345"), b"").unwrap();
    assert!(rtbake(&["bake", A, "--out", s(&d), "-q"]).status.success());
    assert!(internal_files_inside(&d).is_empty(), "{:?}", internal_files_inside(&d));
    assert!(rtbake(&["verify", "--dir", s(&d)]).status.success());
}

/// Found by `scripts/trial_reliability.sh` (1 of 24 concurrent rounds): a bake's writability probe, made before
/// it takes the lock, was removed by a concurrent bake's recovery, and the first bake then failed "not writable".
#[test]
fn a_probe_removed_by_a_concurrent_recovery_does_not_fail_the_bake() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("d");
    let (mut first, mut err) = spawn(&["bake", A, "--out", s(&d)], "hold@probe");
    wait_for(&mut err, "holding at probe");
    // The second bake takes the lock, treats the probe as a stale staging directory and removes it.
    assert!(rtbake(&["bake", B, "--out", s(&d), "-q"]).status.success());
    release(&mut first);
    let o = first.wait_with_output().unwrap();
    assert!(o.status.success(), "first bake failed after its probe was removed: {}", stderr(&o));
    let mut assets = assets_in(&d);
    assets.sort();
    let mut want = vec![A.to_string(), B.to_string()];
    want.sort();
    assert_eq!(assets, want);
    assert!(rtbake(&["verify", "--dir", s(&d)]).status.success());
}

#[cfg(unix)]
#[test]
fn bake_through_a_symlink_updates_its_target_and_keeps_the_link() {
    let t = tempfile::tempdir().unwrap();
    let target = t.path().join("real");
    let link = t.path().join("link");
    assert!(rtbake(&["bake", A, "--out", s(&target), "-q"]).status.success());
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let o = rtbake(&["bake", B, "--out", s(&link), "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link was replaced");
    assert_eq!(assets_in(&target), [B, A]);
    assert!(rtbake(&["verify", "--dir", s(&link)]).status.success());
}

#[test]
fn bake_into_the_current_directory() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("here");
    std::fs::create_dir(&d).unwrap();
    let o = bin().args(["bake", A, "--out", ".", "-q"]).current_dir(&d).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let o = bin().args(["verify", "--dir", "."]).current_dir(&d).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn verify_pin_rejects_a_consistently_edited_manifest() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("d");
    assert!(rtbake(&["bake", A, "--out", s(&d), "-q"]).status.success());
    let pin = t.path().join("d.pin");
    let digest = rtbake::manifest::sha256_hex(&std::fs::read(d.join("manifest.json")).unwrap());
    std::fs::write(&pin, format!("{digest}  d/manifest.json\n")).unwrap();
    assert!(rtbake(&["verify", "--dir", s(&d), "--pin", s(&pin)]).status.success());
    // A whole new bake is self-consistent, but not what the pipeline pinned.
    assert!(rtbake(&["bake", B, "--out", s(&d), "-q"]).status.success());
    let o = rtbake(&["verify", "--dir", s(&d), "--pin", s(&pin)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("TAMPERED") && stderr(&o).contains("pinned"), "{}", stderr(&o));
}

/// Nothing of rtbake's stays beside a directory after a command: the lock file is removed by its last holder, after
/// a bake, a read-only `verify` and a file set written into a user's directory alike.
#[test]
fn no_lock_file_stays_beside_a_directory_after_a_command() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("baked");
    let o = rtbake(&["bake", A, "--out", s(&d)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = rtbake(&["verify", "--dir", s(&d)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sets = t.path().join("tables");
    let o = rtbake(&["aa", "smaa-search", "--format", "bin", "--out", s(&sets)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut left: Vec<String> =
        std::fs::read_dir(t.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    left.sort();
    assert_eq!(left, ["baked", "tables"]);
}
