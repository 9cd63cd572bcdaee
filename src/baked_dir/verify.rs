//! The verify half of the bake directory: each asset re-run from the parameters the manifest records and compared
//! with the files (bytes, or the code's tolerance), every sha256 checked, `--pin` (the invariants are in [`super`]).

use super::{io_err, list_files, BakeDirError};
use crate::bake::{Asset, BakeError, BakedFile};
use crate::io;
use crate::io::file_set::{self, DirLock, LockMode, Wait};
use crate::manifest::{sha256_hex, FileFormat, Manifest, SampleType, MANIFEST_NAME};
use rayon::prelude::*;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::Path;

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
    /// The manifest disagrees with what this rtbake knows: an unknown, missing or duplicated asset record, a
    /// duplicated entry, metadata or tolerance that differ from the code, or a manifest that differs from `--pin`.
    Tampered,
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

/// Verifies `dir` against its manifest and against a recomputation of every asset with `registry`, waiting
/// silently for a bake of `dir` to finish.
pub fn verify(dir: &Path, registry: &[Asset]) -> Result<VerifyReport, BakeDirError> {
    verify_with(dir, registry, None, &Wait::Yes(&|_| {}))
}

/// Why `dir` cannot be verified before its lock is taken, if it cannot: it is not a directory, or it does not
/// exist and no bake is creating it or was killed swapping it ([`file_set::absent_without_trace`]).
pub fn unverifiable(dir: &Path) -> Option<&'static str> {
    if dir.exists() && !dir.is_dir() {
        Some("is not a directory")
    } else if file_set::absent_without_trace(dir) {
        Some("does not exist")
    } else {
        None
    }
}

/// [`verify`] with an optional pinned manifest digest (`sha256sum` output or a bare hex digest; see
/// [`check_pin`]) and a choice of waiting for the directory's lock. The directory is read under a shared lock,
/// so no bake can swap it in the middle.
pub fn verify_with(
    dir: &Path,
    registry: &[Asset],
    pin: Option<&str>,
    wait: &Wait,
) -> Result<VerifyReport, BakeDirError> {
    // Before the lock: the lock file lives beside the directory, and verifying a directory that is not there (and
    // that no bake is creating or was killed swapping) must leave nothing behind in its parent.
    if let Some(detail) = unverifiable(dir) {
        return Err(BakeDirError::Unusable { path: dir.display().to_string(), detail: detail.into() });
    }
    let mut lock = DirLock::acquire(dir, LockMode::Shared, wait)?;
    if file_set::swap_interrupted(lock.dir()) {
        // Only a bake killed inside the two-rename fallback swap gets here; finish it first.
        lock = lock.into_exclusive(wait)?;
        file_set::recover(&lock)?;
    }
    let mut report = verify_locked(lock.dir(), registry, pin)?;
    report.dir = dir.display().to_string();
    Ok(report)
}

/// Compares the sha256 of the manifest's bytes with a pin: the first whitespace-separated token of `pin_text`
/// (so `sha256sum baked/manifest.json > baked.pin` makes one).
pub fn check_pin(manifest_bytes: &[u8], pin_text: &str) -> Result<(), String> {
    let want = pin_text.split_whitespace().next().unwrap_or("").to_ascii_lowercase();
    if want.len() != 64 || !want.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(format!("pin is not a sha256 digest (64 hex digits), got {want:?}"));
    }
    let got = sha256_hex(manifest_bytes);
    if got != want {
        return Err(format!("manifest.json sha256 {got} differs from the pinned {want}"));
    }
    Ok(())
}

/// The verification itself, on a directory the caller has locked (or knows to be quiet).
fn verify_locked(dir: &Path, registry: &[Asset], pin: Option<&str>) -> Result<VerifyReport, BakeDirError> {
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
    // Nothing in the manifest that the code can recompute is trusted: the manifest's own header first.
    if let Some(pin) = pin {
        let bytes = fs::read(dir.join(MANIFEST_NAME)).map_err(|e| io_err(&dir.join(MANIFEST_NAME), e))?;
        if let Err(why) = check_pin(&bytes, pin) {
            set(MANIFEST_NAME, FileStatus::Tampered, why);
        }
    }
    if manifest.conventions != crate::manifest::conventions() {
        set(MANIFEST_NAME, FileStatus::Tampered, "conventions differ from this rtbake's".into());
    }
    let mut seen_assets = BTreeSet::new();
    for record in &manifest.assets {
        if !seen_assets.insert(record.name.as_str()) {
            set(MANIFEST_NAME, FileStatus::Tampered, format!("asset {:?} is recorded twice", record.name));
        }
        if !registry.iter().any(|a| a.name == record.name) {
            set(MANIFEST_NAME, FileStatus::Tampered, format!("asset {:?} is unknown to this rtbake", record.name));
        }
    }
    let mut seen_paths = BTreeSet::new();
    for entry in &manifest.files {
        if !seen_paths.insert(entry.path.as_str()) {
            set(&entry.path, FileStatus::Tampered, "listed twice in manifest.json".into());
        }
        if !registry.iter().any(|a| a.name == entry.asset) {
            set(&entry.path, FileStatus::Tampered, format!("asset {:?} is unknown to this rtbake", entry.asset));
        } else if !seen_assets.contains(entry.asset.as_str()) {
            set(
                &entry.path,
                FileStatus::Tampered,
                format!(
                    "asset {:?} has no record (parameters) in manifest.json, so it cannot be recomputed",
                    entry.asset
                ),
            );
        }
    }
    // Files are read and hashed side by side; their statuses are set in manifest order below.
    let read: Vec<Option<(Vec<u8>, String)>> = manifest
        .files
        .par_iter()
        .map(|entry| {
            fs::read(dir.join(&entry.path)).ok().map(|b| {
                let sha = sha256_hex(&b);
                (b, sha)
            })
        })
        .collect();
    let mut bytes_of: BTreeMap<String, Vec<u8>> = BTreeMap::new();
    for (entry, read) in manifest.files.iter().zip(read) {
        match read {
            None => set(&entry.path, FileStatus::Missing, "listed in manifest.json, not on disk".into()),
            Some((b, sha)) => {
                if let Some(link) = crate::io::file_set::symlink_on_path(dir, &entry.path) {
                    set(&entry.path, FileStatus::Tampered, format!("{link}; a baked file must be a regular file"));
                }
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
    // Recompute every asset from the recorded parameters; metadata and tolerances come from the recomputation.
    // The assets are pure and run side by side (as in a bake); their results are compared in manifest order.
    let mut recomputed = BTreeSet::new();
    let jobs: Vec<(&crate::manifest::AssetRecord, &Asset)> = manifest
        .assets
        .iter()
        .filter_map(|record| registry.iter().find(|a| a.name == record.name).map(|asset| (record, asset)))
        .filter(|(record, _)| recomputed.insert(record.name.as_str()))
        .collect();
    let results: Vec<Result<Vec<BakedFile>, BakeError>> =
        jobs.par_iter().map(|(record, asset)| asset.run(&record.params)).collect();
    for ((record, _), result) in jobs.iter().zip(results) {
        let files = match result {
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
                Some(entry) if entry.asset != record.name => set(
                    &f.path,
                    FileStatus::Tampered,
                    format!("manifest attributes it to asset {:?}, the code to {}", entry.asset, record.name),
                ),
                Some(entry) => {
                    // Content first (a changed parameter shows as stale content), then the metadata the code gives.
                    let content = bytes_of.get(&f.path).map(|disk| compare(&f.meta, &f.path, disk, &f.bytes));
                    if let Some(Err(why)) = content {
                        set(&f.path, FileStatus::Stale, why);
                    } else if let Some(why) = meta_difference(&entry.meta, &f.meta) {
                        set(&f.path, FileStatus::Tampered, why);
                    }
                }
            }
        }
    }
    let files: Vec<FileReport> = reports.into_values().collect();
    let problems = files.iter().filter(|f| f.status != FileStatus::Ok).count();
    Ok(VerifyReport { dir: dir.display().to_string(), files, problems })
}

/// The first metadata field where the manifest differs from what the code produces, described.
fn meta_difference(recorded: &crate::manifest::FileMeta, code: &crate::manifest::FileMeta) -> Option<String> {
    // The manifest went through JSON text; so does the code's metadata before comparing (float parsing).
    let code: crate::manifest::FileMeta =
        serde_json::from_str(&serde_json::to_string(code).ok()?).unwrap_or_else(|_| code.clone());
    let code = &code;
    if recorded == code {
        return None;
    }
    let (a, b) = (serde_json::to_value(recorded).ok()?, serde_json::to_value(code).ok()?);
    let (Value::Object(a), Value::Object(b)) = (&a, &b) else { return Some("metadata differs from the code".into()) };
    let keys: BTreeSet<&String> = a.keys().chain(b.keys()).collect();
    for k in keys {
        let (x, y) = (a.get(k).unwrap_or(&Value::Null), b.get(k).unwrap_or(&Value::Null));
        if x != y {
            return Some(format!("metadata field {k}: manifest says {x}, the code produces {y}"));
        }
    }
    Some("metadata differs from the code".into())
}

/// Compares the file on disk with its recomputation: identical bytes, or floats within tolerance.
pub(super) fn compare(meta: &crate::manifest::FileMeta, path: &str, disk: &[u8], fresh: &[u8]) -> Result<(), String> {
    if disk == fresh {
        return Ok(());
    }
    let Some(tol) = meta.verify_tolerance else {
        let first = disk.iter().zip(fresh).position(|(a, b)| a != b).unwrap_or(disk.len().min(fresh.len()));
        return Err(format!(
            "differs from recomputation (byte-exact format): first difference at byte {first}, sizes {} vs {}",
            disk.len(),
            fresh.len()
        ));
    };
    let a = decode_samples(meta, path, disk).map_err(|e| format!("cannot decode file on disk: {e}"))?;
    let b = decode_samples(meta, path, fresh).map_err(|e| format!("cannot decode recomputation: {e}"))?;
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
fn decode_samples(meta: &crate::manifest::FileMeta, path: &str, bytes: &[u8]) -> Result<Vec<f64>, String> {
    match meta.format {
        FileFormat::Exr => io::exr::decode(bytes, path)
            .map(|(img, _)| img.data.iter().map(|&v| v as f64).collect())
            .map_err(|e| e.to_string()),
        FileFormat::Ktx2 => {
            let (_, _, _, data, _) = io::ktx2::decode(bytes, path).map_err(|e| e.to_string())?;
            Ok(payload_samples(&data, meta.sample_type))
        }
        FileFormat::Dds => {
            let (_, _, _, data) = io::dds::decode(bytes, path).map_err(|e| e.to_string())?;
            Ok(payload_samples(&data, meta.sample_type))
        }
        FileFormat::Raw => Ok(payload_samples(bytes, meta.sample_type)),
        FileFormat::Png => match io::png::decode(bytes, path).map_err(|e| e.to_string())? {
            io::png::DecodedPng::U8(i) => Ok(i.data.iter().map(|&v| v as f64).collect()),
            io::png::DecodedPng::U16(i) => Ok(i.data.iter().map(|&v| v as f64).collect()),
        },
        _ => Ok(numbers_in_text(bytes)),
    }
}

fn payload_samples(data: &[u8], sample_type: SampleType) -> Vec<f64> {
    match sample_type {
        SampleType::F16 => data.chunks_exact(2).map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f64()).collect(),
        SampleType::F32 => data.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64).collect(),
        SampleType::U16 => data.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]]) as f64).collect(),
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
