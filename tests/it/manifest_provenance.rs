//! The manifest records rtbake's own provenance: the crate version and the git tree id of the
//! `src/` it was compiled from, captured at build time — not the directory the user bakes in — and re-baking the
//! same tree leaves `manifest.json` byte-identical.

use crate::support::{crate_dir, rtbake};
use std::path::Path;
use std::process::Command;

fn bake_in(cwd: &Path, out: &Path) -> Vec<u8> {
    let o = Command::new(env!("CARGO_BIN_EXE_rtbake"))
        .current_dir(cwd)
        .args(["bake", "smaa-search", "--quiet", "--out"])
        .arg(out)
        .output()
        .expect("run rtbake");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read(out.join("manifest.json")).unwrap()
}

fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let o = Command::new("git").current_dir(dir).args(args).output().ok()?;
    o.status.success().then(|| String::from_utf8_lossy(&o.stdout).trim().to_string())
}

#[test]
fn manifest_records_rtbake_source_not_the_working_directory() {
    let t = tempfile::tempdir().unwrap();
    // A foreign git repository with a commit, as a user's own project would be.
    let foreign = t.path().join("project");
    std::fs::create_dir_all(&foreign).unwrap();
    let have_git = git(&foreign, &["init", "-q"]).is_some()
        && git(&foreign, &["-c", "user.name=x", "-c", "user.email=x@x", "commit", "-q", "--allow-empty", "-m", "x"])
            .is_some();
    let in_foreign = bake_in(&foreign, &t.path().join("a"));
    let elsewhere = t.path().join("plain");
    std::fs::create_dir_all(&elsewhere).unwrap();
    let in_plain = bake_in(&elsewhere, &t.path().join("b"));
    assert_eq!(in_foreign, in_plain, "the manifest depends on the directory rtbake runs in");

    let m: serde_json::Value = serde_json::from_slice(&in_plain).unwrap();
    assert_eq!(m["tool_version"], env!("CARGO_PKG_VERSION"));
    let tree = m["source_tree"].as_str().unwrap();
    assert_eq!(tree, rtbake::manifest::SOURCE_TREE);
    assert!(tree.len() == 40 && tree.bytes().all(|b| b.is_ascii_hexdigit()), "source_tree {tree:?}");
    assert!(m.get("git_revision").is_none());
    if have_git {
        let foreign_head = git(&foreign, &["rev-parse", "HEAD"]).unwrap();
        assert!(!String::from_utf8_lossy(&in_foreign).contains(&foreign_head[..12]));
    }
}

/// The build script's tree id is git's: stage the crate's current `src/` into a scratch index and ask git.
#[test]
fn source_tree_is_git_tree_id_of_src() {
    let dir = crate_dir();
    if git(&dir, &["rev-parse", "--git-dir"]).is_none() {
        // A source tarball has no git to compare with; the id is still computed from the files.
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED: source_tree vs `git write-tree` — {} is not a git checkout",
            dir.display()
        );
        return;
    }
    let t = tempfile::tempdir().unwrap();
    let index = t.path().join("index");
    let run = |args: &[&str]| {
        let o = Command::new("git").current_dir(&dir).env("GIT_INDEX_FILE", &index).args(args).output().unwrap();
        assert!(o.status.success(), "git {args:?}: {}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).trim().to_string()
    };
    run(&["read-tree", "--empty"]);
    run(&["add", "--force", "src", "Cargo.lock"]);
    assert_eq!(run(&["write-tree", "--prefix=src/"]), rtbake::manifest::SOURCE_TREE);
    let lock = run(&["ls-files", "-s", "Cargo.lock"]);
    assert_eq!(lock.split_whitespace().nth(1), Some(rtbake::manifest::CARGO_LOCK));
}

#[test]
fn rebake_keeps_the_manifest_byte_identical() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("baked");
    let first = bake_in(t.path(), &out);
    let again = bake_in(t.path(), &out);
    assert_eq!(first, again);
    let v = rtbake(&["verify", "--quiet", "--dir", out.to_str().unwrap()]);
    assert!(v.status.success(), "{}", String::from_utf8_lossy(&v.stderr));
}
