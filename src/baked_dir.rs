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

use crate::bake::{Asset, BakeError, BakedFile};
use crate::io::file_set::{self, DirLock, FileSetError, LockMode, Wait};
use crate::io::{self, IoError};
use crate::manifest::{sha256_hex, Manifest, ManifestError, MANIFEST_NAME};
use rayon::prelude::*;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::Path;

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

/// Finishes or discards what a killed bake of `dir` left (see [`file_set::recover`]), waiting for the directory's
/// lock. Returns a description of what was done, if anything.
pub fn recover(dir: &Path) -> Result<Option<String>, BakeDirError> {
    let lock = DirLock::acquire(dir, LockMode::Exclusive, &Wait::Yes(&|_| {}))?;
    Ok(file_set::recover(&lock)?)
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

/// Writes a file of the stage; the stage is made durable as a whole afterwards ([`io::atomic::sync_batch`]).
fn write_unsynced(path: &Path, bytes: &[u8]) -> Result<(), BakeDirError> {
    if let Some(p) = path.parent() {
        fs::create_dir_all(p).map_err(|e| io_err(p, e))?;
    }
    fs::write(path, bytes).map_err(|e| io_err(path, e))
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

/// Computes `jobs` (asset + parameters) and installs them into `dir` with an updated manifest, atomically,
/// waiting silently for the directory's lock.
///
/// The manifest records this build's provenance ([`crate::manifest::SOURCE_TREE`]), never the caller's directory.
pub fn bake_into(dir: &Path, jobs: &[(&Asset, Value)]) -> Result<BakeSummary, BakeDirError> {
    bake_into_with(dir, jobs, &|_, _| {}, &Wait::Yes(&|_| {}))
}

/// [`bake_into`], calling `progress(k, name)` before computing the k-th job (0-based) and `progress(jobs.len(),
/// "writing")` before the directory is written, so a caller can show per-asset progress.
pub fn bake_into_with_progress(
    dir: &Path,
    jobs: &[(&Asset, Value)],
    progress: &(dyn Fn(usize, &str) + Sync),
) -> Result<BakeSummary, BakeDirError> {
    bake_into_with(dir, jobs, progress, &Wait::Yes(&|_| {}))
}

/// [`bake_into_with_progress`] with a choice of waiting for the lock another process holds on `dir`.
pub fn bake_into_with(
    dir: &Path,
    jobs: &[(&Asset, Value)],
    progress: &(dyn Fn(usize, &str) + Sync),
    wait: &Wait,
) -> Result<BakeSummary, BakeDirError> {
    // 1. Compute everything in memory (pure; a bad parameter writes nothing). No lock is needed for this. The assets
    //    run side by side (each is a pure function of its parameters, so the bytes do not depend on the order or the
    //    thread count); results are kept in job order and the first failing job in that order is the error reported.
    //    Each asset's files are hashed for the manifest as soon as it is done, beside the other assets.
    type Produced = (Vec<BakedFile>, Vec<String>);
    let results: Vec<Result<Produced, BakeDirError>> = jobs
        .par_iter()
        .enumerate()
        .map(|(k, (asset, params))| {
            progress(k, asset.name);
            let files = asset.run(params).map_err(|source| BakeDirError::Asset { asset: asset.name.into(), source })?;
            let digests = files.par_iter().map(|f| sha256_hex(&f.bytes)).collect();
            Ok((files, digests))
        })
        .collect();
    let mut produced: Vec<(&Asset, &Value, Vec<BakedFile>)> = Vec::with_capacity(jobs.len());
    let mut digests: Vec<Vec<String>> = Vec::with_capacity(jobs.len());
    for ((asset, params), result) in jobs.iter().zip(results) {
        let (files, d) = result?;
        produced.push((asset, params, files));
        digests.push(d);
    }
    progress(jobs.len(), "writing");
    // 2. From here to the swap, the directory is ours: the existing state read below cannot change under us.
    let lock = DirLock::acquire(dir, LockMode::Exclusive, wait)?;
    let real = lock.dir().to_path_buf();
    file_set::recover(&lock)?;
    let old_manifest = if real.join(MANIFEST_NAME).exists() { Some(Manifest::load(&real)?) } else { None };
    if real.exists() && old_manifest.is_none() && !list_files(&real)?.is_empty() {
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
    for ((asset, params, files), digests) in produced.iter().zip(&digests) {
        manifest.set_asset_with_digests(asset.name, (*params).clone(), files, digests);
    }
    let new_paths: BTreeSet<String> = manifest.files.iter().map(|f| f.path.clone()).collect();
    let mut seen = BTreeSet::new();
    for f in &manifest.files {
        if !seen.insert(f.path.clone()) {
            return Err(BakeDirError::Unusable { path: f.path.clone(), detail: "produced by two assets".into() });
        }
    }

    // 3. Stage the new directory beside the target (a stale stage of ours was removed by the recovery).
    let stage = file_set::sibling(&real, "stage");
    let _ = fs::remove_dir_all(&stage);
    let result = (|| -> Result<(u64, usize), BakeDirError> {
        fs::create_dir_all(&stage).map_err(|e| io_err(&stage, e))?;
        let mut bytes = 0u64;
        let mut count = 0usize;
        // Carry over files of other assets and user files.
        for rel in list_files(&real)? {
            let rebaked = produced.iter().any(|(a, _, _)| manifest.entry(&rel).is_some_and(|e| e.asset == a.name));
            let dropped = old_paths.contains(&rel) && !new_paths.contains(&rel);
            if rel == MANIFEST_NAME || rebaked || dropped {
                continue;
            }
            let src = real.join(&rel);
            let dst = stage.join(&rel);
            if let Some(p) = dst.parent() {
                fs::create_dir_all(p).map_err(|e| io_err(p, e))?;
            }
            if fs::hard_link(&src, &dst).is_err() {
                fs::copy(&src, &dst).map_err(|e| io_err(&src, e))?;
            }
        }
        // The new files are independent: written side by side (the page-cache copies and file creations scale
        // with the threads; the flush below is one).
        let new_files: Vec<&BakedFile> = produced.iter().flat_map(|(_, _, files)| files).collect();
        let mut written: Vec<std::path::PathBuf> = new_files.iter().map(|f| stage.join(&f.path)).collect();
        new_files.par_iter().zip(&written).try_for_each(|(f, path)| write_unsynced(path, &f.bytes))?;
        for f in &new_files {
            bytes += f.bytes.len() as u64;
            count += 1;
        }
        written.push(stage.join(MANIFEST_NAME));
        write_unsynced(&stage.join(MANIFEST_NAME), manifest.to_text().as_bytes())?;
        // One flush for every file and directory of the stage (not one fsync per file) before the swap.
        io::atomic::sync_batch(&stage, &written)?;
        Ok((bytes, count))
    })();
    let (bytes_written, files_written) = match result {
        Ok(v) => v,
        Err(e) => {
            let _ = fs::remove_dir_all(&stage);
            return Err(e);
        }
    };
    file_set::fault_point("staged");
    // 4. Swap: the path names the old or the new directory at every instant.
    file_set::install_dir(&lock, &stage)?;
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
fn compare(meta: &crate::manifest::FileMeta, path: &str, disk: &[u8], fresh: &[u8]) -> Result<(), String> {
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
    match meta.format.as_str() {
        "exr" => io::exr::decode(bytes, path)
            .map(|(img, _)| img.data.iter().map(|&v| v as f64).collect())
            .map_err(|e| e.to_string()),
        "ktx2" => {
            let (_, _, _, data, _) = io::ktx2::decode(bytes, path).map_err(|e| e.to_string())?;
            Ok(payload_samples(&data, &meta.sample_type))
        }
        "dds" => {
            let (_, _, _, data) = io::dds::decode(bytes, path).map_err(|e| e.to_string())?;
            Ok(payload_samples(&data, &meta.sample_type))
        }
        "raw" => Ok(payload_samples(bytes, &meta.sample_type)),
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

    #[test]
    fn verify_refuses_a_missing_directory_before_taking_its_lock() {
        let t = tempfile::tempdir().unwrap();
        let err = verify(&t.path().join("MISSING"), &registry()).unwrap_err();
        assert!(matches!(&err, BakeDirError::Unusable { detail, .. } if detail == "does not exist"), "{err}");
        assert_eq!(fs::read_dir(t.path()).unwrap().count(), 0, "nothing (no .MISSING.rtbake-lock) left in the parent");
    }

    fn registry() -> Vec<Asset> {
        vec![Asset { name: "ramp", summary: "test", default_params: || serde_json::json!({"size": 8}), bake: ramp }]
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
        let meta = FileMeta::text("json", "json", "");
        let mut meta = meta;
        assert!(compare(&meta, "x.json", b"[1.0, 2.0]", b"[1.0, 2.0000001]").is_err());
        meta.verify_tolerance = Some(1e-6);
        assert!(compare(&meta, "x.json", b"[1.0, 2.0]", b"[1.0, 2.0000001]").is_ok());
        assert!(compare(&meta, "x.json", b"[1.0, 2.0]", b"[1.0, 2.01]").is_err());
    }

    type Edit = Box<dyn Fn(&mut Value)>;

    /// Issue 15 finding 4: a file tampered together with its sha256 must fail whatever else the manifest says.
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
