//! Atomic file writes: write to a temporary file in the destination directory, fsync, rename.
//!
//! A crash or an error at any point leaves either the old file or the new one, never a truncated file.

use super::IoError;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Name of the temporary sibling used while writing `path`.
fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.rtbake-tmp-{}", std::process::id()))
}

/// Pieces a large staged file is written in ([`write_with_early_writeback`]).
const WRITEBACK_PIECE_BYTES: usize = 8 << 20;

/// Writes `bytes` to `f`; a file larger than one [`WRITEBACK_PIECE_BYTES`] piece is written piece by piece, and on
/// Linux each written piece is handed to the disk at once (`sync_file_range(SYNC_FILE_RANGE_WRITE)`, which starts
/// the writeback without waiting for it), so the file system's block allocation and the device transfer of the
/// earlier pieces overlap the copying of the later ones and the final fsync waits only for the tail. Durability is
/// still the caller's fsync: this only moves work earlier.
fn write_with_early_writeback(f: &mut fs::File, bytes: &[u8]) -> std::io::Result<()> {
    if bytes.len() <= WRITEBACK_PIECE_BYTES {
        return f.write_all(bytes);
    }
    let mut offset = 0usize;
    for piece in bytes.chunks(WRITEBACK_PIECE_BYTES) {
        f.write_all(piece)?;
        #[cfg(target_os = "linux")]
        {
            use std::os::fd::AsRawFd;
            // SAFETY: a valid open descriptor; the call reads no memory of ours. Best effort: a file system
            // that does not support it (EINVAL, ENOSYS, …) is synced by the caller's fsync as before.
            let _ = unsafe {
                libc::sync_file_range(
                    f.as_raw_fd(),
                    offset as libc::off64_t,
                    piece.len() as libc::off64_t,
                    libc::SYNC_FILE_RANGE_WRITE,
                )
            };
        }
        offset += piece.len();
    }
    Ok(())
}

/// Writes `bytes` to a temporary sibling of `path` and fsyncs it; returns the temp path (not yet renamed).
pub fn stage(path: &Path, bytes: &[u8]) -> Result<PathBuf, IoError> {
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        write_with_early_writeback(&mut f, bytes)?;
        f.sync_all()
    })();
    match result {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = fs::remove_file(&tmp);
            Err(IoError::io(path, e))
        }
    }
}

/// Writes `bytes` to a temporary sibling of `path` without syncing it (the caller makes a whole batch durable
/// with one [`sync_batch`] before any rename); returns the temp path.
pub fn stage_unsynced(path: &Path, bytes: &[u8]) -> Result<PathBuf, IoError> {
    let tmp = temp_path(path);
    match fs::File::create(&tmp).and_then(|mut f| write_with_early_writeback(&mut f, bytes)) {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = fs::remove_file(&tmp);
            Err(IoError::io(path, e))
        }
    }
}

/// Batches of at most this many files are made durable file by file: `syncfs` also flushes whatever else is dirty on
/// the file system (other processes' writes), so it pays only where it replaces many fsyncs (a bake's ~400 files).
pub const SYNCFS_MIN_FILES: usize = 16;

/// Makes a batch of files written below `root` durable: an fsync per file for small batches
/// ([`SYNCFS_MIN_FILES`]); for large ones on Linux one flush instead of one fsync per file, `syncfs(2)` of `root`'s
/// file system (data and metadata of every file written, in one journal commit; it reports write-back errors since
/// Linux 5.8); elsewhere, or if `syncfs` fails, an fsync per file.
pub fn sync_batch(root: &Path, files: &[PathBuf]) -> Result<(), IoError> {
    #[cfg(target_os = "linux")]
    if files.len() > SYNCFS_MIN_FILES {
        use std::os::fd::AsRawFd;
        if let Ok(d) = fs::File::open(root) {
            // SAFETY: `d` is an open file descriptor for the duration of the call; syncfs only reads it.
            if unsafe { libc::syncfs(d.as_raw_fd()) } == 0 {
                return Ok(());
            }
        }
    }
    for f in files {
        fs::File::open(f).and_then(|f| f.sync_all()).map_err(|e| IoError::io(f, e))?;
    }
    Ok(())
}

/// Renames a staged temp file over `path`.
pub fn commit(tmp: &Path, path: &Path) -> Result<(), IoError> {
    fs::rename(tmp, path).map_err(|e| {
        let _ = fs::remove_file(tmp);
        IoError::io(path, e)
    })
}

/// Writes `bytes` to `path` atomically (temp file + fsync + rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    let tmp = stage(path, bytes)?;
    commit(&tmp, path)?;
    if let Some(dir) = path.parent() {
        // Persist the rename itself; best effort (not every filesystem supports fsync on directories).
        if let Ok(d) = fs::File::open(if dir.as_os_str().is_empty() { Path::new(".") } else { dir }) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

/// Removes leftover temp files of this module in `dir` (e.g. after a killed bake). Returns how many.
pub fn clean_stale_temps(dir: &Path) -> usize {
    let mut n = 0;
    if let Ok(rd) = fs::read_dir(dir) {
        for e in rd.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') && name.contains(".rtbake-tmp-") && fs::remove_file(e.path()).is_ok() {
                n += 1;
            }
        }
    }
    n
}

/// True if `name` is one of our temp files.
pub fn is_temp_name(name: &str) -> bool {
    name.starts_with('.') && name.contains(".rtbake-tmp-")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn write_then_overwrite_leaves_no_temp() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.bin");
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"second");
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().flatten().map(|e| e.file_name()).collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn a_file_written_in_pieces_is_whole() {
        // Two full pieces and a 1-byte tail, every byte distinct from its neighbours' position mod 251.
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("big.bin");
        let bytes: Vec<u8> = (0..2 * WRITEBACK_PIECE_BYTES + 1).map(|i| (i % 251) as u8).collect();
        write_atomic(&p, &bytes).unwrap();
        assert!(fs::read(&p).unwrap() == bytes, "the staged pieces reassemble the bytes in order");
    }

    #[test]
    fn failed_write_keeps_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing-dir").join("a.bin");
        assert!(write_atomic(&p, b"x").is_err());
        assert!(!p.exists());
    }
}
