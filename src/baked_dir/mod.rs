//! The bake directory (`baked/` by default): writing assets with their manifest, and verifying them.
//!
//! Invariants:
//! - One writer at a time: a bake holds the directory's advisory lock (`.NAME.rtbake-lock` beside it, see
//!   [`crate::io::file_set`]) exclusively from reading the old manifest to the swap; `verify` holds it shared. A
//!   second bake or verify waits (or fails with `Busy` under `--no-wait`) instead of racing: no lost update.
//! - A bake is all-or-nothing. Every file and the manifest are first written into a hidden staging directory
//!   beside the target (`.NAME.rtbake-stage-PID`), flushed once (`syncfs`), then exchanged with the target in one
//!   `renameat2(RENAME_EXCHANGE)` (Linux; a rolled-forward two-rename fallback elsewhere). The path always names
//!   the old or the new directory. Leftover staging directories are removed only under the exclusive lock, so a
//!   live one is never touched.
//! - Every asset is computed in memory before anything is written (and before locking): a bad parameter writes
//!   nothing.
//! - Files in the target that the manifest does not know (user files) are carried over untouched; rtbake's own
//!   transient names (temp files, probes of older versions) never are.
//! - `verify` re-runs each asset's pure `bake` function from the parameters recorded in the manifest and compares:
//!   byte for byte, or within the tolerance the code (not the manifest) gives; it also checks every sha256 and
//!   reports missing, extra, modified and stale files. Nothing the code can recompute is trusted from the
//!   manifest: unknown, missing or duplicated asset records, duplicated entries, edited metadata or conventions
//!   are `Tampered`. `--pin` compares the manifest's sha256 with one the pipeline keeps. Like a bake, it runs the
//!   assets (and reads and hashes the files) side by side; the report is built in manifest order, so it does not
//!   depend on the thread count. A directory that does not exist, with no bake creating it or killed swapping it,
//!   is refused before its lock is taken.

use crate::bake::BakeError;
use crate::io::file_set::{self, FileSetError};
use crate::io::IoError;
use crate::manifest::ManifestError;
use std::collections::BTreeSet;
use std::fs;
use std::path::Path;

mod bake;
mod verify;

pub use bake::{bake_into, bake_into_with, bake_into_with_progress, recover, BakeSummary};
pub use verify::{check_pin, unverifiable, verify, verify_with, FileReport, FileStatus, VerifyReport};

/// Errors of `bake` / `verify` on a directory.
#[derive(Debug, thiserror::Error)]
pub enum BakeDirError {
    #[error("asset {asset}: {source}")]
    Asset { asset: String, source: BakeError },
    #[error(transparent)]
    Io(#[from] IoError),
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    #[error("{path}: {detail}")]
    Unusable { path: String, detail: String },
    #[error(transparent)]
    Dir(#[from] FileSetError),
}

fn io_err(path: &Path, e: std::io::Error) -> BakeDirError {
    BakeDirError::Io(IoError::io(path, e))
}

/// All regular files under `dir`, as `/`-separated relative paths (rtbake's own transient files excluded).
fn list_files(dir: &Path) -> Result<BTreeSet<String>, BakeDirError> {
    let mut out = BTreeSet::new();
    fn walk(base: &Path, d: &Path, out: &mut BTreeSet<String>) -> Result<(), BakeDirError> {
        for e in fs::read_dir(d).map_err(|e| io_err(d, e))?.flatten() {
            let p = e.path();
            let ft = e.file_type().map_err(|e| io_err(&p, e))?;
            if ft.is_dir() {
                walk(base, &p, out)?;
            } else {
                let rel = p.strip_prefix(base).expect("under base");
                let rel = rel.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/");
                if !file_set::is_internal_name(&rel) {
                    out.insert(rel);
                }
            }
        }
        Ok(())
    }
    if dir.exists() {
        walk(dir, dir, &mut out)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::verify::compare;
    use super::*;
    use crate::bake::Asset;
    use crate::bake::BakedFile;
    use crate::bake::{json_file, parse_params, FileMeta};
    use crate::image_buf::Image;
    use crate::io::file_set::Wait;
    use crate::manifest::sha256_hex;
    use crate::manifest::Manifest;
    use crate::manifest::MANIFEST_NAME;
    use crate::manifest::{FileFormat, FileKind};
    use serde_json::Value;

    fn ramp(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
        #[derive(serde::Deserialize)]
        struct P {
            size: u32,
        }
        let p: P = parse_params("ramp", params)?;
        let (w, h) = crate::error::check_size("size", p.size as u64, p.size as u64)?;
        let img = Image::from_vec(w, h, 2, (0..w * h * 2).map(|i| (i % 251) as u8).collect());
        let mut files = crate::bake::unorm8_texture_files("test/ramp", &img, FileKind::Lut, "test ramp")?;
        let f = Image::from_vec(w, h, 1, (0..w * h).map(|i| i as f32 / 7.0).collect());
        files.extend(crate::bake::float_texture_files("test/ramp_f", &f, FileKind::Lut, "test", 1e-6)?);
        files.push(json_file("test/ramp.json", params, FileKind::Json, "params"));
        Ok(files)
    }

    #[test]
    fn verify_refuses_a_missing_directory_before_taking_its_lock() {
        let t = tempfile::tempdir().unwrap();
        let err = verify(&t.path().join("MISSING"), &registry()).unwrap_err();
        assert!(matches!(&err, BakeDirError::Unusable { detail, .. } if detail == "does not exist"), "{err}");
        assert_eq!(fs::read_dir(t.path()).unwrap().count(), 0, "nothing (no .MISSING.rtbake-lock) left in the parent");
    }

    fn registry() -> Vec<Asset> {
        vec![Asset {
            name: "ramp",
            summary: "test",
            default_params: || serde_json::json!({"size": 8}),
            bake: ramp,
            time_estimate: None,
        }]
    }

    /// Entries of `dir` other than lock files.
    fn siblings(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| !n.ends_with(".rtbake-lock"))
            .collect();
        v.sort();
        v
    }

    fn baked(dir: &Path) -> Vec<Asset> {
        let reg = registry();
        bake_into(dir, &[(&reg[0], (reg[0].default_params)())]).unwrap();
        reg
    }

    #[test]
    fn progress_reports_each_asset_then_the_write() {
        let t = tempfile::tempdir().unwrap();
        let reg = registry();
        let seen = std::sync::Mutex::new(Vec::new());
        let jobs = [(&reg[0], serde_json::json!({"size": 4})), (&reg[0], serde_json::json!({"size": 4}))];
        bake_into_with_progress(&t.path().join("b"), &jobs, &|k, name| {
            seen.lock().unwrap().push((k, name.to_string()))
        })
        .unwrap();
        // The assets run side by side, so they report in either order; the write comes after both.
        let mut seen = seen.into_inner().unwrap();
        assert_eq!(seen.pop(), Some((2, "writing".to_string())));
        seen.sort();
        assert_eq!(seen, [(0, "ramp".into()), (1, "ramp".into())]);
    }

    #[test]
    fn bake_then_verify_is_clean_and_rebake_is_byte_identical() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("baked");
        let reg = baked(&dir);
        let report = verify(&dir, &reg).unwrap();
        assert!(report.is_ok(), "{report:?}");
        let before = fs::read(dir.join(MANIFEST_NAME)).unwrap();
        baked(&dir);
        assert_eq!(before, fs::read(dir.join(MANIFEST_NAME)).unwrap());
        // No staging leftovers beside the directory (only its lock file).
        assert_eq!(siblings(t.path()), ["baked"]);
    }

    #[test]
    fn verify_catches_a_single_flipped_byte_in_every_file() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("baked");
        let reg = baked(&dir);
        let m = Manifest::load(&dir).unwrap();
        for e in &m.files {
            let p = dir.join(&e.path);
            let orig = fs::read(&p).unwrap();
            let mut bad = orig.clone();
            let i = bad.len() / 2;
            bad[i] ^= 0x01;
            fs::write(&p, &bad).unwrap();
            let r = verify(&dir, &reg).unwrap();
            let line = r.files.iter().find(|f| f.path == e.path).unwrap();
            assert_eq!(line.status, FileStatus::Modified, "{}", e.path);
            fs::write(&p, &orig).unwrap();
        }
        assert!(verify(&dir, &reg).unwrap().is_ok());
    }

    #[test]
    fn verify_reports_missing_extra_and_stale() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("baked");
        let reg = baked(&dir);
        fs::remove_file(dir.join("test/ramp.dds")).unwrap();
        fs::write(dir.join("test/stray.txt"), b"x").unwrap();
        // Hand-edit the parameters so the recomputation differs but checksums still match.
        let mut m = Manifest::load(&dir).unwrap();
        m.assets[0].params = serde_json::json!({"size": 9});
        fs::write(dir.join(MANIFEST_NAME), m.to_text()).unwrap();
        let r = verify(&dir, &reg).unwrap();
        let status = |p: &str| r.files.iter().find(|f| f.path == p).map(|f| f.status.clone());
        assert_eq!(status("test/ramp.dds"), Some(FileStatus::Missing));
        assert_eq!(status("test/stray.txt"), Some(FileStatus::Extra));
        assert_eq!(status("test/ramp.bin"), Some(FileStatus::Stale));
        assert!(!r.is_ok());
    }

    #[test]
    fn verify_report_is_the_same_for_any_thread_count() {
        // Two assets (so they run side by side), one file missing, one modified, one stale recomputation.
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("baked");
        let mut reg = registry();
        reg.push(Asset {
            name: "ramp2",
            summary: "test",
            default_params: || serde_json::json!({"size": 5}),
            time_estimate: None,
            bake: |v| {
                let files = ramp(v)?;
                Ok(files
                    .into_iter()
                    .map(|mut f| {
                        f.path = f.path.replace("test/", "test2/");
                        f
                    })
                    .collect())
            },
        });
        bake_into(&dir, &[(&reg[0], (reg[0].default_params)()), (&reg[1], (reg[1].default_params)())]).unwrap();
        fs::remove_file(dir.join("test/ramp.dds")).unwrap();
        let p = dir.join("test2/ramp.bin");
        let mut b = fs::read(&p).unwrap();
        b[3] ^= 0x10;
        fs::write(&p, b).unwrap();
        let mut m = Manifest::load(&dir).unwrap();
        m.assets[0].params = serde_json::json!({"size": 9});
        fs::write(dir.join(MANIFEST_NAME), m.to_text()).unwrap();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| verify(&dir, &reg).unwrap())
        };
        let one = run(1);
        assert!(one.problems >= 3, "{one:?}");
        for threads in [2, 3] {
            assert_eq!(run(threads), one, "{threads} threads");
        }
    }

    #[test]
    fn corrupted_manifest_is_an_error() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("baked");
        let reg = baked(&dir);
        let text = fs::read_to_string(dir.join(MANIFEST_NAME)).unwrap();
        fs::write(dir.join(MANIFEST_NAME), &text[..text.len() / 2]).unwrap();
        assert!(matches!(verify(&dir, &reg), Err(BakeDirError::Manifest(_))));
    }

    #[test]
    fn bad_parameters_write_nothing() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("baked");
        let reg = baked(&dir);
        let before = list_files(&dir).unwrap();
        let manifest_before = fs::read(dir.join(MANIFEST_NAME)).unwrap();
        let err = bake_into(&dir, &[(&reg[0], serde_json::json!({"size": 1_000_000}))]).unwrap_err();
        assert!(err.to_string().contains("size"), "{err}");
        assert_eq!(before, list_files(&dir).unwrap());
        assert_eq!(manifest_before, fs::read(dir.join(MANIFEST_NAME)).unwrap());
    }

    #[test]
    fn interrupted_swap_is_recovered() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("baked");
        baked(&dir);
        // Simulate a crash between the two renames: the old directory moved aside, the new one never arrived.
        let old = t.path().join(".baked.rtbake-old-999");
        fs::rename(&dir, &old).unwrap();
        fs::create_dir_all(t.path().join(".baked.rtbake-stage-999/test")).unwrap();
        fs::write(t.path().join(".baked.rtbake-stage-999/test/ramp.bin"), b"trunc").unwrap();
        assert!(recover(&dir).unwrap().is_some());
        assert!(verify(&dir, &registry()).unwrap().is_ok());
        assert_eq!(siblings(t.path()), ["baked"]);
    }

    #[test]
    fn refuses_foreign_non_empty_directory() {
        let t = tempfile::tempdir().unwrap();
        fs::write(t.path().join("notes.txt"), b"mine").unwrap();
        let reg = registry();
        let err = bake_into(t.path(), &[(&reg[0], (reg[0].default_params)())]).unwrap_err();
        assert!(matches!(err, BakeDirError::Unusable { .. }));
        assert_eq!(fs::read(t.path().join("notes.txt")).unwrap(), b"mine");
    }

    #[test]
    fn float_files_compare_within_tolerance() {
        let meta = FileMeta::text(FileKind::Json, FileFormat::Json, "");
        let mut meta = meta;
        assert!(compare(&meta, "x.json", b"[1.0, 2.0]", b"[1.0, 2.0000001]").is_err());
        meta.verify_tolerance = Some(1e-6);
        assert!(compare(&meta, "x.json", b"[1.0, 2.0]", b"[1.0, 2.0000001]").is_ok());
        assert!(compare(&meta, "x.json", b"[1.0, 2.0]", b"[1.0, 2.01]").is_err());
    }

    type Edit = Box<dyn Fn(&mut Value)>;

    /// A file tampered together with its sha256 must fail whatever else the manifest says.
    #[test]
    fn manifest_cannot_switch_verification_off() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("baked");
        let reg = baked(&dir);
        let pristine = fs::read_to_string(dir.join(MANIFEST_NAME)).unwrap();
        let target = "test/ramp_f.ktx2";
        let orig = fs::read(dir.join(target)).unwrap();
        // Tamper the float file (within 1e9, far beyond the code's tolerance) and record its new sha256.
        let mut bad = orig.clone();
        let n = bad.len();
        bad[n - 2..].copy_from_slice(&half::f16::from_f32(60000.0).to_le_bytes());
        let tampered = |edit: &dyn Fn(&mut Value)| {
            let mut m: Value = serde_json::from_str(&pristine).unwrap();
            for f in m["files"].as_array_mut().unwrap() {
                if f["path"] == target {
                    f["sha256"] = sha256_hex(&bad).into();
                }
            }
            edit(&mut m);
            fs::write(dir.join(target), &bad).unwrap();
            fs::write(dir.join(MANIFEST_NAME), serde_json::to_string_pretty(&m).unwrap()).unwrap();
            let r = verify(&dir, &reg).unwrap();
            fs::write(dir.join(target), &orig).unwrap();
            fs::write(dir.join(MANIFEST_NAME), &pristine).unwrap();
            r
        };
        let file_edit = |key: &'static str, v: Value| {
            move |m: &mut Value| {
                for f in m["files"].as_array_mut().unwrap() {
                    if f["path"] == target {
                        f[key] = v.clone();
                    }
                }
            }
        };
        let cases: Vec<(&str, Edit)> = vec![
            ("sha256 only", Box::new(|_: &mut Value| {})),
            ("asset record removed", Box::new(|m: &mut Value| m["assets"] = serde_json::json!([]))),
            ("asset record renamed", Box::new(|m: &mut Value| m["assets"][0]["name"] = "other".into())),
            (
                "asset of the entries renamed",
                Box::new(|m: &mut Value| {
                    for f in m["files"].as_array_mut().unwrap() {
                        f["asset"] = "other".into();
                    }
                }),
            ),
            ("tolerance raised", Box::new(file_edit("verify_tolerance", 1e9.into()))),
        ];
        for (what, edit) in &cases {
            let r = tampered(edit.as_ref());
            assert!(!r.is_ok(), "{what}: verify passed");
            assert!(r.files.iter().any(|f| f.path == target && f.status != FileStatus::Ok), "{what}: {r:?}");
        }
        // Metadata edits alone (file untouched): each is reported.
        let meta_cases: Vec<(&str, Edit)> = vec![
            ("color_space", Box::new(file_edit("color_space", "srgb".into()))),
            ("width", Box::new(file_edit("width", 9.into()))),
            ("pixel_format", Box::new(file_edit("pixel_format", "R32_SFLOAT".into()))),
            (
                "duplicate entry",
                Box::new(|m: &mut Value| {
                    let files = m["files"].as_array_mut().unwrap();
                    let first = files[0].clone();
                    files.push(first);
                }),
            ),
            (
                "duplicate asset",
                Box::new(|m: &mut Value| {
                    let a = m["assets"].as_array_mut().unwrap();
                    let first = a[0].clone();
                    a.push(first);
                }),
            ),
            ("conventions", Box::new(|m: &mut Value| m["conventions"]["row_order"] = "bottom first".into())),
        ];
        for (what, edit) in &meta_cases {
            let mut m: Value = serde_json::from_str(&pristine).unwrap();
            edit(&mut m);
            fs::write(dir.join(MANIFEST_NAME), serde_json::to_string_pretty(&m).unwrap()).unwrap();
            let r = verify(&dir, &reg).unwrap();
            fs::write(dir.join(MANIFEST_NAME), &pristine).unwrap();
            assert!(r.files.iter().any(|f| f.status == FileStatus::Tampered), "{what}: {r:?}");
        }
        assert!(verify(&dir, &reg).unwrap().is_ok());
    }

    #[test]
    fn pin_detects_any_manifest_edit() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("baked");
        let reg = baked(&dir);
        let text = fs::read(dir.join(MANIFEST_NAME)).unwrap();
        let pin = format!("{}  manifest.json\n", sha256_hex(&text));
        assert!(verify_with(&dir, &reg, Some(&pin), &Wait::No).unwrap().is_ok());
        // A consistent edit: different parameters, re-baked, so files, sha256 and recomputation all agree.
        bake_into(&dir, &[(&reg[0], serde_json::json!({"size": 9}))]).unwrap();
        assert!(verify(&dir, &reg).unwrap().is_ok());
        let r = verify_with(&dir, &reg, Some(&pin), &Wait::No).unwrap();
        let line = r.files.iter().find(|f| f.path == MANIFEST_NAME).unwrap();
        assert_eq!(line.status, FileStatus::Tampered, "{r:?}");
        assert!(check_pin(b"x", "not-a-digest").unwrap_err().contains("64 hex"));
    }
}
