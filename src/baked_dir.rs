//! The bake directory (`baked/` by default): writing assets with their manifest, and verifying them.
//!
//! Invariants:
//! - A bake is all-or-nothing. Every file and the manifest are first written into a hidden staging directory
//!   beside the target (`.NAME.rtbake-stage-PID`), fsynced, then swapped in with two renames. An interrupted bake
//!   leaves either the old directory or the new one (a leftover hidden staging/old directory is recovered or
//!   removed by the next `bake`/`verify`), never a truncated file or a manifest pointing at stale data.
//! - Every asset is computed in memory before anything is written: a bad parameter writes nothing.
//! - Files in the target that the manifest does not know (user files) are carried over untouched.
//! - `verify` re-runs each asset's pure `bake` function from the parameters recorded in the manifest and compares:
//!   byte for byte, or within the file's `verify_tolerance` for float payloads; it also checks every sha256 and
//!   reports missing, extra, modified and stale files.

use crate::bake::{Asset, BakeError, BakedFile};
use crate::io::{self, IoError};
use crate::manifest::{sha256_hex, Entry, Manifest, ManifestError, MANIFEST_NAME};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

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
}

fn io_err(path: &Path, e: std::io::Error) -> BakeDirError {
    BakeDirError::Io(IoError::io(path, e))
}

fn sibling(dir: &Path, tag: &str) -> PathBuf {
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "baked".into());
    dir.with_file_name(format!(".{name}.rtbake-{tag}-{}", std::process::id()))
}

/// Restores `dir` from a leftover `.NAME.rtbake-old-*` if a previous bake died between its two renames, and
/// removes leftover staging directories. Returns a description of what was done, if anything.
pub fn recover(dir: &Path) -> Option<String> {
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = dir.file_name()?.to_string_lossy().into_owned();
    let mut note = None;
    for e in fs::read_dir(parent).ok()?.flatten() {
        let n = e.file_name().to_string_lossy().into_owned();
        if n.starts_with(&format!(".{name}.rtbake-old-")) {
            if !dir.exists() && fs::rename(e.path(), dir).is_ok() {
                note = Some(format!("restored {} from an interrupted bake", dir.display()));
            } else {
                let _ = fs::remove_dir_all(e.path());
            }
        } else if n.starts_with(&format!(".{name}.rtbake-stage-")) {
            let _ = fs::remove_dir_all(e.path());
        }
    }
    note
}

/// All regular files under `dir`, as `/`-separated relative paths (hidden temp files included).
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
                out.insert(rel.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/"));
            }
        }
        Ok(())
    }
    if dir.exists() {
        walk(dir, dir, &mut out)?;
    }
    Ok(out)
}

fn write_synced(path: &Path, bytes: &[u8]) -> Result<(), BakeDirError> {
    use std::io::Write;
    if let Some(p) = path.parent() {
        fs::create_dir_all(p).map_err(|e| io_err(p, e))?;
    }
    let mut f = fs::File::create(path).map_err(|e| io_err(path, e))?;
    f.write_all(bytes).map_err(|e| io_err(path, e))?;
    f.sync_all().map_err(|e| io_err(path, e))
}

/// Summary of a bake.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BakeSummary {
    pub dir: String,
    pub assets: Vec<String>,
    pub files_written: usize,
    pub bytes_written: u64,
    pub files_removed: Vec<String>,
}

/// Computes `jobs` (asset + parameters) and installs them into `dir` with an updated manifest, atomically.
///
/// The manifest records this build's provenance ([`crate::manifest::SOURCE_TREE`]), never the caller's directory.
pub fn bake_into(dir: &Path, jobs: &[(&Asset, Value)]) -> Result<BakeSummary, BakeDirError> {
    bake_into_with_progress(dir, jobs, &|_, _| {})
}

/// [`bake_into`], calling `progress(k, name)` before computing the k-th job (0-based) and `progress(jobs.len(),
/// "writing")` before the directory is written, so a caller can show per-asset progress.
pub fn bake_into_with_progress(
    dir: &Path,
    jobs: &[(&Asset, Value)],
    progress: &dyn Fn(usize, &str),
) -> Result<BakeSummary, BakeDirError> {
    // 1. Compute everything in memory (pure; a bad parameter writes nothing).
    let mut produced: Vec<(&Asset, &Value, Vec<BakedFile>)> = Vec::new();
    for (k, (asset, params)) in jobs.iter().enumerate() {
        progress(k, asset.name);
        let files = (asset.bake)(params).map_err(|source| BakeDirError::Asset { asset: asset.name.into(), source })?;
        produced.push((asset, params, files));
    }
    progress(jobs.len(), "writing");
    // 2. Existing state.
    recover(dir);
    let old_manifest = if dir.join(MANIFEST_NAME).exists() { Some(Manifest::load(dir)?) } else { None };
    if dir.exists() && old_manifest.is_none() && !list_files(dir)?.is_empty() {
        return Err(BakeDirError::Unusable {
            path: dir.display().to_string(),
            detail:
                "exists, is not empty and has no manifest.json: refusing to bake into a directory rtbake does not own"
                    .into(),
        });
    }
    let mut manifest = old_manifest.clone().unwrap_or_default();
    manifest.stamp_provenance();
    let old_paths: BTreeSet<String> = manifest.files.iter().map(|f| f.path.clone()).collect();
    for (asset, params, files) in &produced {
        manifest.set_asset(asset.name, (*params).clone(), files);
    }
    let new_paths: BTreeSet<String> = manifest.files.iter().map(|f| f.path.clone()).collect();
    let mut seen = BTreeSet::new();
    for f in &manifest.files {
        if !seen.insert(f.path.clone()) {
            return Err(BakeDirError::Unusable { path: f.path.clone(), detail: "produced by two assets".into() });
        }
    }

    // 3. Stage the new directory.
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    fs::create_dir_all(parent).map_err(|e| io_err(parent, e))?;
    let stage = sibling(dir, "stage");
    let _ = fs::remove_dir_all(&stage);
    let result = (|| -> Result<(u64, usize), BakeDirError> {
        fs::create_dir_all(&stage).map_err(|e| io_err(&stage, e))?;
        let mut bytes = 0u64;
        let mut count = 0usize;
        // Carry over files of other assets and user files.
        for rel in list_files(dir)? {
            let rebaked = produced.iter().any(|(a, _, _)| manifest.entry(&rel).is_some_and(|e| e.asset == a.name));
            let dropped = old_paths.contains(&rel) && !new_paths.contains(&rel);
            if rel == MANIFEST_NAME || rebaked || dropped || io::atomic::is_temp_name(&rel) {
                continue;
            }
            let src = dir.join(&rel);
            let dst = stage.join(&rel);
            if let Some(p) = dst.parent() {
                fs::create_dir_all(p).map_err(|e| io_err(p, e))?;
            }
            if fs::hard_link(&src, &dst).is_err() {
                fs::copy(&src, &dst).map_err(|e| io_err(&src, e))?;
            }
        }
        for (_, _, files) in &produced {
            for f in files {
                write_synced(&stage.join(&f.path), &f.bytes)?;
                bytes += f.bytes.len() as u64;
                count += 1;
            }
        }
        write_synced(&stage.join(MANIFEST_NAME), manifest.to_text().as_bytes())?;
        Ok((bytes, count))
    })();
    let (bytes_written, files_written) = match result {
        Ok(v) => v,
        Err(e) => {
            let _ = fs::remove_dir_all(&stage);
            return Err(e);
        }
    };
    // 4. Swap.
    if dir.exists() {
        let old = sibling(dir, "old");
        fs::rename(dir, &old).map_err(|e| {
            let _ = fs::remove_dir_all(&stage);
            io_err(dir, e)
        })?;
        fs::rename(&stage, dir).map_err(|e| {
            let _ = fs::rename(&old, dir);
            io_err(dir, e)
        })?;
        let _ = fs::remove_dir_all(&old);
    } else {
        fs::rename(&stage, dir).map_err(|e| io_err(dir, e))?;
    }
    if let Ok(d) = fs::File::open(parent) {
        let _ = d.sync_all();
    }
    Ok(BakeSummary {
        dir: dir.display().to_string(),
        assets: produced.iter().map(|(a, _, _)| a.name.to_string()).collect(),
        files_written,
        bytes_written,
        files_removed: old_paths.difference(&new_paths).cloned().collect(),
    })
}

/// Status of one file in a verify report.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FileStatus {
    Ok,
    /// Listed in the manifest, absent on disk.
    Missing,
    /// On disk, not listed in the manifest.
    Extra,
    /// Bytes do not match the manifest's sha256 (corrupted or hand-edited).
    Modified,
    /// Matches its sha256, but recomputing the asset from the manifest's parameters gives different content.
    Stale,
    /// The asset's recomputation no longer produces this file, or produces a file the manifest lacks.
    Unlisted,
}

/// One line of a verify report.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FileReport {
    pub path: String,
    pub status: FileStatus,
    pub detail: String,
}

/// Result of `verify`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct VerifyReport {
    pub dir: String,
    pub files: Vec<FileReport>,
    pub problems: usize,
}

impl VerifyReport {
    pub fn is_ok(&self) -> bool {
        self.problems == 0
    }
}

/// Verifies `dir` against its manifest and against a recomputation of every asset with `registry`.
pub fn verify(dir: &Path, registry: &[Asset]) -> Result<VerifyReport, BakeDirError> {
    let manifest = Manifest::load(dir)?;
    let on_disk = list_files(dir)?;
    let mut reports: BTreeMap<String, FileReport> = BTreeMap::new();
    let mut set = |path: &str, status: FileStatus, detail: String| {
        let e = reports.entry(path.to_string()).or_insert(FileReport {
            path: path.into(),
            status: FileStatus::Ok,
            detail: String::new(),
        });
        if e.status == FileStatus::Ok {
            e.status = status;
            e.detail = detail;
        }
    };
    let mut bytes_of: BTreeMap<String, Vec<u8>> = BTreeMap::new();
    for entry in &manifest.files {
        let p = dir.join(&entry.path);
        match fs::read(&p) {
            Err(_) => set(&entry.path, FileStatus::Missing, "listed in manifest.json, not on disk".into()),
            Ok(b) => {
                let sha = sha256_hex(&b);
                if sha != entry.sha256 || b.len() as u64 != entry.size_bytes {
                    set(
                        &entry.path,
                        FileStatus::Modified,
                        format!(
                            "sha256 {sha} ({} bytes), manifest says {} ({} bytes)",
                            b.len(),
                            entry.sha256,
                            entry.size_bytes
                        ),
                    );
                } else {
                    set(&entry.path, FileStatus::Ok, String::new());
                }
                bytes_of.insert(entry.path.clone(), b);
            }
        }
    }
    for rel in &on_disk {
        if rel != MANIFEST_NAME && manifest.entry(rel).is_none() {
            set(rel, FileStatus::Extra, "on disk, not listed in manifest.json".into());
        }
    }
    // Recompute every asset from the recorded parameters.
    for record in &manifest.assets {
        let Some(asset) = registry.iter().find(|a| a.name == record.name) else {
            for e in manifest.files.iter().filter(|e| e.asset == record.name) {
                set(&e.path, FileStatus::Stale, format!("asset {:?} is unknown to this rtbake", record.name));
            }
            continue;
        };
        let files = match (asset.bake)(&record.params) {
            Ok(f) => f,
            Err(err) => {
                for e in manifest.files.iter().filter(|e| e.asset == record.name) {
                    set(&e.path, FileStatus::Stale, format!("recomputing asset {} failed: {err}", record.name));
                }
                continue;
            }
        };
        let produced: BTreeSet<&str> = files.iter().map(|f| f.path.as_str()).collect();
        for e in manifest.files.iter().filter(|e| e.asset == record.name) {
            if !produced.contains(e.path.as_str()) {
                set(&e.path, FileStatus::Unlisted, format!("asset {} no longer produces this file", record.name));
            }
        }
        for f in &files {
            match manifest.entry(&f.path) {
                None => {
                    set(&f.path, FileStatus::Unlisted, format!("asset {} produces it, manifest lacks it", record.name))
                }
                Some(entry) => {
                    if let Some(disk) = bytes_of.get(&f.path) {
                        if let Err(why) = compare(entry, disk, &f.bytes) {
                            set(&f.path, FileStatus::Stale, why);
                        }
                    }
                }
            }
        }
    }
    let files: Vec<FileReport> = reports.into_values().collect();
    let problems = files.iter().filter(|f| f.status != FileStatus::Ok).count();
    Ok(VerifyReport { dir: dir.display().to_string(), files, problems })
}

/// Compares the file on disk with its recomputation: identical bytes, or floats within tolerance.
fn compare(entry: &Entry, disk: &[u8], fresh: &[u8]) -> Result<(), String> {
    if disk == fresh {
        return Ok(());
    }
    let Some(tol) = entry.meta.verify_tolerance else {
        let first = disk.iter().zip(fresh).position(|(a, b)| a != b).unwrap_or(disk.len().min(fresh.len()));
        return Err(format!(
            "differs from recomputation (byte-exact format): first difference at byte {first}, sizes {} vs {}",
            disk.len(),
            fresh.len()
        ));
    };
    let a = decode_samples(entry, disk).map_err(|e| format!("cannot decode file on disk: {e}"))?;
    let b = decode_samples(entry, fresh).map_err(|e| format!("cannot decode recomputation: {e}"))?;
    if a.len() != b.len() {
        return Err(format!("sample count {} vs recomputed {}", a.len(), b.len()));
    }
    let mut worst = 0.0f64;
    for (x, y) in a.iter().zip(&b) {
        let d = if x.is_nan() && y.is_nan() { 0.0 } else { (x - y).abs() };
        if d.is_nan() || d > worst {
            worst = if d.is_nan() { f64::INFINITY } else { d };
        }
    }
    if worst > tol {
        return Err(format!("max |difference| {worst:e} exceeds tolerance {tol:e}"));
    }
    Ok(())
}

/// Decodes a file's samples as f64 for tolerant comparison.
fn decode_samples(entry: &Entry, bytes: &[u8]) -> Result<Vec<f64>, String> {
    let path = entry.path.as_str();
    match entry.meta.format.as_str() {
        "exr" => io::exr::decode(bytes, path)
            .map(|(img, _)| img.data.iter().map(|&v| v as f64).collect())
            .map_err(|e| e.to_string()),
        "ktx2" => {
            let (_, _, _, data, _) = io::ktx2::decode(bytes, path).map_err(|e| e.to_string())?;
            Ok(payload_samples(&data, &entry.meta.sample_type))
        }
        "dds" => {
            let (_, _, _, data) = io::dds::decode(bytes, path).map_err(|e| e.to_string())?;
            Ok(payload_samples(&data, &entry.meta.sample_type))
        }
        "raw" => Ok(payload_samples(bytes, &entry.meta.sample_type)),
        "png" => match io::png::decode(bytes, path).map_err(|e| e.to_string())? {
            io::png::DecodedPng::U8(i) => Ok(i.data.iter().map(|&v| v as f64).collect()),
            io::png::DecodedPng::U16(i) => Ok(i.data.iter().map(|&v| v as f64).collect()),
        },
        _ => Ok(numbers_in_text(bytes)),
    }
}

fn payload_samples(data: &[u8], sample_type: &str) -> Vec<f64> {
    match sample_type {
        "f16" => data.chunks_exact(2).map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f64()).collect(),
        "f32" => data.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64).collect(),
        "u16" => data.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]]) as f64).collect(),
        _ => data.iter().map(|&v| v as f64).collect(),
    }
}

/// Every number in a text file, in order (for tolerant comparison of JSON, CSV and shader includes).
fn numbers_in_text(bytes: &[u8]) -> Vec<f64> {
    let text = String::from_utf8_lossy(bytes);
    let mut out = Vec::new();
    let mut tok = String::new();
    let flush = |tok: &mut String, out: &mut Vec<f64>| {
        if let Ok(v) = tok.parse::<f64>() {
            out.push(v);
        }
        tok.clear();
    };
    for ch in text.chars() {
        if ch.is_ascii_digit() || ch == '.' || ch == '-' || ch == '+' || ch == 'e' || ch == 'E' {
            tok.push(ch);
        } else {
            flush(&mut tok, &mut out);
        }
    }
    flush(&mut tok, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::{json_file, parse_params, FileMeta};
    use crate::image_buf::Image;

    fn ramp(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
        #[derive(serde::Deserialize)]
        struct P {
            size: u32,
        }
        let p: P = parse_params("ramp", params)?;
        let (w, h) = crate::error::check_size("size", p.size as u64, p.size as u64)?;
        let img = Image::from_vec(w, h, 2, (0..w * h * 2).map(|i| (i % 251) as u8).collect());
        let mut files = crate::bake::unorm8_texture_files("test/ramp", &img, "lut", "test ramp")?;
        let f = Image::from_vec(w, h, 1, (0..w * h).map(|i| i as f32 / 7.0).collect());
        files.extend(crate::bake::float_texture_files("test/ramp_f", &f, "lut", "test", 1e-6)?);
        files.push(json_file("test/ramp.json", params, "json", "params"));
        Ok(files)
    }

    fn registry() -> Vec<Asset> {
        vec![Asset { name: "ramp", summary: "test", default_params: || serde_json::json!({"size": 8}), bake: ramp }]
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
        assert_eq!(*seen.lock().unwrap(), [(0, "ramp".into()), (1, "ramp".into()), (2, "writing".to_string())]);
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
        // No staging leftovers beside the directory.
        assert_eq!(fs::read_dir(t.path()).unwrap().count(), 1);
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
        assert!(recover(&dir).is_some());
        assert!(verify(&dir, &registry()).unwrap().is_ok());
        assert_eq!(fs::read_dir(t.path()).unwrap().count(), 1);
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
        let meta = FileMeta::text("json", "json", "");
        let mut entry = Entry { path: "x.json".into(), asset: "a".into(), meta, size_bytes: 0, sha256: String::new() };
        assert!(compare(&entry, b"[1.0, 2.0]", b"[1.0, 2.0000001]").is_err());
        entry.meta.verify_tolerance = Some(1e-6);
        assert!(compare(&entry, b"[1.0, 2.0]", b"[1.0, 2.0000001]").is_ok());
        assert!(compare(&entry, b"[1.0, 2.0]", b"[1.0, 2.01]").is_err());
    }
}
