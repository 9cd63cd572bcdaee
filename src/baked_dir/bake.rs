//! The bake half of the bake directory: every asset computed in memory, then staged beside the target and exchanged
//! with it under the directory's lock (the invariants are in [`super`]); recovery of an interrupted bake.

use super::{io_err, list_files, BakeDirError};
use crate::bake::{Asset, BakedFile};
use crate::io;
use crate::io::file_set::{self, DirLock, LockMode, Wait};
use crate::manifest::{sha256_hex, Manifest, MANIFEST_NAME};
use rayon::prelude::*;
use serde_json::Value;
use std::collections::BTreeSet;
use std::fs;
use std::path::Path;

/// Finishes or discards what a killed bake of `dir` left (see [`file_set::recover`]), waiting for the directory's
/// lock. Returns a description of what was done, if anything.
pub fn recover(dir: &Path) -> Result<Option<String>, BakeDirError> {
    let lock = DirLock::acquire(dir, LockMode::Exclusive, &Wait::Yes(&|_| {}))?;
    Ok(file_set::recover(&lock)?)
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
