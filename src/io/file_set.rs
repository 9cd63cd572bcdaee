//! Output directories that concurrent runs and kills cannot corrupt: an advisory lock per directory, a swap that
//! never leaves the path empty, and the one atomic file-set writer every multi-file command uses.
//!
//! Invariants:
//! - Every writer of a directory holds its lock (`.NAME.rtbake-lock` beside the directory, an OS advisory lock
//!   through `std::fs::File::lock`, released by the kernel when the process dies) for the whole stage → install;
//!   readers that must see one consistent state (`verify`) hold it shared. A second writer waits or, with
//!   `Wait::No`, fails with [`FileSetError::Busy`]. The last holder unlinks the lock file while holding it; a
//!   process that waited on an unlinked file re-locks the one the name points to (dev/inode compared), so nothing
//!   stays beside the directory and two processes never hold it at once.
//! - Leftovers (`.NAME.rtbake-stage-PID`, `.rtbake-tmp-`, journals) are removed only while holding the lock
//!   exclusively: their owner held the same lock while it lived, so a leftover seen under the lock is dead.
//!   Nothing is ever left inside a target directory by a probe: the writability probe is a staging directory.
//! - A whole directory is installed with one `renameat2(RENAME_EXCHANGE)` on Linux (the path always names either
//!   the old or the new directory); elsewhere (or where the file system refuses the exchange) with two renames
//!   whose interrupted state is rolled forward to the new directory by the next locked command.
//! - A file set inside a directory shared with other files ([`write_file_set`]) is never visible mixed: the
//!   directory is staged whole beside itself (`.NAME.rtbake-stage-PID`: every other entry hard-linked, the set's
//!   files written new, all made durable together, [`super::atomic::sync_batch`]) and exchanged with the old one in
//!   one `renameat2(RENAME_EXCHANGE)`, so a reader of any file sees the old set or the new one, whatever it reads
//!   in between. Where the directory cannot be staged that way (no exchange on this platform or file system, an
//!   entry that cannot be hard-linked, more than [`MAX_LINKED_ENTRIES`] entries, or the directory is this
//!   process's working directory or holds it) the set is committed by a journal instead: temp files, a journal
//!   listing the renames written atomically, then the renames; a kill after the journal is rolled forward by the
//!   next rtbake command that locks or reads the directory ([`settle`]), a kill before it leaves the old set —
//!   visible mixed only between such a kill and that next command. A set of one file needs neither: its rename is
//!   the commit point, made durable by one fsync of its directory. No output may be one of the command's inputs.
//! - Kill points for tests: `RTBAKE_FAULT_INJECT` holds comma-separated directives checked at each named step:
//!   `kill@STEP` exits at once (status 137, no clean-up, like SIGKILL), `hold@STEP` prints
//!   `rtbake-fault: holding at STEP` on stderr and blocks until a line arrives on stdin, `no-exchange` forces the
//!   two-rename fallback for directories and the journal for file sets. Steps: `locked`, `staged`,
//!   `before-swap`, `after-ready`, `between-renames`, `after-swap`, `journal-written`, `mid-commit`, `probe`.

use super::IoError;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Errors of locking and writing output directories.
#[derive(Debug, thiserror::Error)]
pub enum FileSetError {
    #[error(transparent)]
    Io(#[from] IoError),
    #[error("{dir}: locked by another rtbake process{holder} (without `no_wait`, rtbake waits for it)")]
    Busy { dir: String, holder: String },
    #[error("{output}: refusing to overwrite the input {input} (choose another output path)")]
    OutputIsInput { output: String, input: String },
    #[error("{path}: {detail}")]
    Unusable { path: String, detail: String },
}

fn io_err(path: &Path, e: std::io::Error) -> FileSetError {
    FileSetError::Io(IoError::io(path, e))
}

/// Whether to wait for a lock another process holds. `Yes` calls its function once with a message before blocking.
pub enum Wait<'a> {
    No,
    Yes(&'a dyn Fn(&str)),
}

/// Shared (readers) or exclusive (writers).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LockMode {
    Shared,
    Exclusive,
}

/// Checks the fault-injection directives for `step` (see the module docs). A no-op unless the variable is set.
pub fn fault_point(step: &str) {
    let Ok(spec) = std::env::var("RTBAKE_FAULT_INJECT") else { return };
    for d in spec.split(',').map(str::trim) {
        if d.strip_prefix("kill@") == Some(step) {
            std::process::exit(137);
        }
        if d.strip_prefix("hold@") == Some(step) {
            eprintln!("rtbake-fault: holding at {step}");
            let mut line = String::new();
            let _ = std::io::stdin().read_line(&mut line);
        }
    }
}

fn fault_flag(flag: &str) -> bool {
    std::env::var("RTBAKE_FAULT_INJECT").is_ok_and(|s| s.split(',').any(|d| d.trim() == flag))
}

/// The directory a path designates, absolute, with a symlink at its last component followed (so `--out LINK`
/// updates the link's target and keeps the link) and `.`/`..` resolved. The parent is created if missing.
pub fn resolve_target(dir: &Path) -> Result<PathBuf, FileSetError> {
    let unusable = |detail: &str| FileSetError::Unusable { path: dir.display().to_string(), detail: detail.into() };
    if let Ok(md) = fs::symlink_metadata(dir) {
        let real = fs::canonicalize(dir).map_err(|e| io_err(dir, e))?;
        if md.file_type().is_symlink() && !real.is_dir() {
            return Err(unusable("is a symbolic link to something that is not a directory"));
        }
        if real.parent().is_none() {
            return Err(unusable("is a file-system root: rtbake needs a directory it can swap"));
        }
        return Ok(real);
    }
    let name = dir.file_name().ok_or_else(|| unusable("has no directory name"))?;
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    fs::create_dir_all(parent).map_err(|e| io_err(parent, e))?;
    Ok(fs::canonicalize(parent).map_err(|e| io_err(parent, e))?.join(name))
}

fn parent_of(dir: &Path) -> &Path {
    dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

fn dir_name(dir: &Path) -> String {
    dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "out".into())
}

/// A hidden sibling of `dir` owned by this process: `.NAME.rtbake-TAG-PID`.
pub fn sibling(dir: &Path, tag: &str) -> PathBuf {
    dir.with_file_name(format!(".{}.rtbake-{tag}-{}", dir_name(dir), std::process::id()))
}

/// The lock file of `dir` (beside it, so it survives the swap of the directory).
pub fn lock_path(dir: &Path) -> PathBuf {
    dir.with_file_name(format!(".{}.rtbake-lock", dir_name(dir)))
}

/// True when `dir` does not exist and nothing of rtbake's is beside it (no lock file, no staging or swapped-out
/// directory): a command that only reads it may refuse it at once, before creating a lock file in its parent.
/// While a bake creates `dir`, or after one was killed mid-swap, its lock or staging files are there, and the
/// reader must take the lock to wait for it or to finish its swap.
pub fn absent_without_trace(dir: &Path) -> bool {
    if dir.exists() {
        return false;
    }
    let prefix = format!(".{}.rtbake-", dir_name(dir));
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match std::fs::read_dir(parent) {
        Ok(entries) => !entries.flatten().any(|e| e.file_name().to_string_lossy().starts_with(&prefix)),
        Err(_) => true,
    }
}

/// True for names rtbake uses for its own transient files inside a directory (never user files).
pub fn is_internal_name(rel: &str) -> bool {
    let name = rel.rsplit('/').next().unwrap_or(rel);
    name.starts_with('.')
        && (name.contains(".rtbake-tmp-")
            || name.starts_with(".rtbake-write-probe-")
            || name.starts_with(".rtbake-fileset-")
            || name.contains(".rtbake-lock"))
}

/// An advisory lock on one output directory, held until dropped (or the process dies).
#[derive(Debug)]
pub struct DirLock {
    /// The resolved directory (see [`resolve_target`]).
    dir: PathBuf,
    mode: LockMode,
    /// The lock file and its path; None where a read-only parent needs no lock.
    file: Option<(fs::File, PathBuf)>,
}

/// Whether `path` still names the open lock `file` (the last holder unlinks the lock file when it releases it, so
/// a process that opened the old file and then waited holds a lock nobody else will ever take: it must reopen).
#[cfg(unix)]
fn still_names(path: &Path, file: &fs::File) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (fs::metadata(path), file.metadata()) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}
#[cfg(not(unix))]
fn still_names(_path: &Path, _file: &fs::File) -> bool {
    true
}

impl Drop for DirLock {
    /// Releases the lock. The last holder removes the lock file while it still holds it exclusively (a shared
    /// holder first tries to become the only one), so no `.NAME.rtbake-lock` stays beside a directory after the
    /// command, a read-only `verify` included; a process waiting on the removed file notices (`still_names`) and
    /// takes a fresh one.
    fn drop(&mut self) {
        let Some((file, path)) = self.file.take() else { return };
        let sole = self.mode == LockMode::Exclusive || file.try_lock().is_ok();
        if cfg!(unix) && sole && still_names(&path, &file) {
            let _ = fs::remove_file(&path);
        }
        drop(file);
    }
}

impl DirLock {
    /// The resolved directory this lock guards.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    pub fn mode(&self) -> LockMode {
        self.mode
    }

    /// Locks `dir` (resolved first). A shared lock on a directory whose parent is read-only is granted without a
    /// lock file: nobody can write there anyway.
    pub fn acquire(dir: &Path, mode: LockMode, wait: &Wait) -> Result<Self, FileSetError> {
        let resolved = resolve_target(dir)?;
        let path = lock_path(&resolved);
        loop {
            let Some(file) = Self::lock_file(&resolved, &path, mode, wait)? else {
                return Ok(Self { dir: resolved, mode, file: None });
            };
            if !still_names(&path, &file) {
                // The holder we waited for removed this file on release: lock the one that names the directory now.
                continue;
            }
            if mode == LockMode::Exclusive {
                // Who holds it, for the message of a waiting process (best effort).
                let _ = file.set_len(0);
                let _ = (&file).write_all(std::process::id().to_string().as_bytes());
            }
            // Staging directories of killed writers (they held this lock while they lived): removed by whoever
            // locks the directory next, readers (`verify`) included.
            remove_stale_stages(&resolved);
            fault_point("locked");
            return Ok(Self { dir: resolved, mode, file: Some((file, path)) });
        }
    }

    /// Opens (creating) and locks the lock file at `path`, waiting per `wait`; None for a shared lock whose parent
    /// is read-only.
    fn lock_file(resolved: &Path, path: &Path, mode: LockMode, wait: &Wait) -> Result<Option<fs::File>, FileSetError> {
        let file = match fs::OpenOptions::new().read(true).write(true).create(true).truncate(false).open(path) {
            Ok(f) => f,
            Err(e)
                if mode == LockMode::Shared
                    && matches!(
                        e.kind(),
                        std::io::ErrorKind::PermissionDenied | std::io::ErrorKind::ReadOnlyFilesystem
                    ) =>
            {
                return Ok(None);
            }
            Err(e) => return Err(io_err(path, e)),
        };
        let attempt = |f: &fs::File| match mode {
            LockMode::Shared => f.try_lock_shared(),
            LockMode::Exclusive => f.try_lock(),
        };
        match attempt(&file) {
            Ok(()) => {}
            Err(fs::TryLockError::Error(e)) => return Err(io_err(path, e)),
            Err(fs::TryLockError::WouldBlock) => {
                let holder = match fs::read_to_string(path) {
                    Ok(s) if !s.trim().is_empty() => format!(" (pid {})", s.trim()),
                    _ => String::new(),
                };
                match wait {
                    Wait::No => return Err(FileSetError::Busy { dir: resolved.display().to_string(), holder }),
                    Wait::Yes(say) => {
                        say(&format!(
                            "waiting for the lock on {} held by another rtbake process{holder} ({})",
                            resolved.display(),
                            path.display()
                        ));
                        let r = match mode {
                            LockMode::Shared => file.lock_shared(),
                            LockMode::Exclusive => file.lock(),
                        };
                        r.map_err(|e| io_err(path, e))?;
                    }
                }
            }
        }
        Ok(Some(file))
    }

    /// Upgrades a shared lock to exclusive (releases, then waits for exclusive).
    pub fn into_exclusive(self, wait: &Wait) -> Result<Self, FileSetError> {
        if self.mode == LockMode::Exclusive {
            return Ok(self);
        }
        let dir = self.dir.clone();
        drop(self);
        Self::acquire(&dir, LockMode::Exclusive, wait)
    }
}

/// Whether this process may create files in the existing directory `dir`, checked without creating anything
/// (`access(W_OK | X_OK)` on Unix, which also reports a read-only file system), so a kill leaves no probe behind.
pub fn check_dir_writable(dir: &Path) -> std::io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
        // SAFETY: a valid NUL-terminated path; access does not retain it.
        if unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) } != 0 {
            return Err(std::io::Error::last_os_error());
        }
        Ok(())
    }
    #[cfg(not(unix))]
    {
        if fs::metadata(dir)?.permissions().readonly() {
            return Err(std::io::Error::from(std::io::ErrorKind::PermissionDenied));
        }
        Ok(())
    }
}

/// Before any work: the directory that will hold `dir` exists (created) and accepts a new entry. The probe is an
/// empty staging directory beside `dir`; a probe left by a kill is a stale staging directory that the next locked
/// command removes — never a file inside `dir`.
pub fn probe_writable(dir: &Path) -> Result<(), FileSetError> {
    let resolved = resolve_target(dir)?;
    let probe = sibling(&resolved, "stage");
    let parent = parent_of(&resolved);
    if probe.exists() {
        return Ok(());
    }
    fs::create_dir(&probe).map_err(|e| io_err(parent, e))?;
    fault_point("probe");
    match fs::remove_dir(&probe) {
        // The probe is made without the lock: a concurrent writer's recovery, which owns every staging name under
        // its lock, may already have removed it. Creating it was the proof of writability.
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        other => other.map_err(|e| io_err(&probe, e)),
    }
}

/// Whether a killed writer left `dir` inside a fallback swap (missing, or a finished "ready" directory beside it):
/// a reader must then take the exclusive lock and [`recover`] before reading.
pub fn swap_interrupted(dir: &Path) -> bool {
    if !dir.exists() {
        return true;
    }
    let prefix = format!(".{}.rtbake-ready-", dir_name(dir));
    fs::read_dir(parent_of(dir))
        .map(|rd| rd.flatten().any(|e| e.file_name().to_string_lossy().starts_with(&prefix)))
        .unwrap_or(false)
}

/// Under an exclusive lock: finishes or discards whatever a killed writer of `lock.dir()` left. Returns a
/// description of what was done, if anything.
pub fn recover(lock: &DirLock) -> Result<Option<String>, FileSetError> {
    assert_eq!(lock.mode, LockMode::Exclusive, "recovery needs the exclusive lock");
    let dir = lock.dir();
    let parent = parent_of(dir);
    let prefix = format!(".{}.rtbake-", dir_name(dir));
    let mut note = Vec::new();
    let mut ready = Vec::new();
    let mut old = Vec::new();
    let mut stale = Vec::new();
    if let Ok(rd) = fs::read_dir(parent) {
        for e in rd.flatten() {
            let n = e.file_name().to_string_lossy().into_owned();
            let Some(rest) = n.strip_prefix(&prefix) else { continue };
            if rest.starts_with("ready-") {
                ready.push(e.path());
            } else if rest.starts_with("old-") {
                old.push(e.path());
            } else if rest.starts_with("stage-") {
                stale.push(e.path());
            }
        }
    }
    // A writer killed inside the fallback swap: once its new directory was complete and renamed to "ready" it had
    // committed, so roll forward; otherwise the old directory stays or comes back.
    if let Some(r) = ready.pop() {
        if dir.exists() {
            let aside = sibling(dir, "old");
            fs::rename(dir, &aside).map_err(|e| io_err(dir, e))?;
            old.push(aside);
        }
        fs::rename(&r, dir).map_err(|e| io_err(dir, e))?;
        note.push(format!("installed the finished result of an interrupted run into {}", dir.display()));
    } else if !dir.exists() {
        if let Some(o) = old.pop() {
            fs::rename(&o, dir).map_err(|e| io_err(dir, e))?;
            note.push(format!("restored {} from an interrupted run", dir.display()));
        }
    }
    for p in ready.iter().chain(&old).chain(&stale) {
        let _ = if p.is_dir() { fs::remove_dir_all(p) } else { fs::remove_file(p) };
    }
    if dir.is_dir() {
        if let Some(n) = settle_locked(dir)? {
            note.push(n);
        }
    }
    Ok(if note.is_empty() { None } else { Some(note.join("; ")) })
}

#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let ca = std::ffi::CString::new(a.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
    let cb = std::ffi::CString::new(b.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
    // SAFETY: two valid NUL-terminated paths; renameat2 does not retain them.
    let r = unsafe { libc::renameat2(libc::AT_FDCWD, ca.as_ptr(), libc::AT_FDCWD, cb.as_ptr(), libc::RENAME_EXCHANGE) };
    if r == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

#[cfg(not(target_os = "linux"))]
fn exchange(_a: &Path, _b: &Path) -> std::io::Result<()> {
    Err(std::io::Error::from(std::io::ErrorKind::Unsupported))
}

/// The kernel or file system cannot exchange (old kernel, NFS, …): use the fallback swap.
fn exchange_unsupported(e: &std::io::Error) -> bool {
    #[cfg(target_os = "linux")]
    if matches!(e.raw_os_error(), Some(libc::EINVAL) | Some(libc::ENOSYS) | Some(libc::EOPNOTSUPP)) {
        return true;
    }
    e.kind() == std::io::ErrorKind::Unsupported
}

fn sync_dir(dir: &Path) {
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
}

/// Under an exclusive lock: replaces `lock.dir()` by the complete, fsynced directory `stage` (a sibling of it).
/// The path names the old or the new directory at every instant where the platform can exchange two directories;
/// elsewhere the interrupted fallback is rolled forward by [`recover`].
pub fn install_dir(lock: &DirLock, stage: &Path) -> Result<(), FileSetError> {
    assert_eq!(lock.mode, LockMode::Exclusive, "installing needs the exclusive lock");
    let dir = lock.dir();
    let parent = parent_of(dir);
    fault_point("before-swap");
    if !dir.exists() {
        fs::rename(stage, dir).map_err(|e| io_err(dir, e))?;
        sync_dir(parent);
        fault_point("after-swap");
        return Ok(());
    }
    if !fault_flag("no-exchange") {
        match exchange(stage, dir) {
            Ok(()) => {
                sync_dir(parent);
                fault_point("after-swap");
                // `stage` now holds the old directory.
                let _ = fs::remove_dir_all(stage);
                return Ok(());
            }
            Err(e) if exchange_unsupported(&e) => {}
            Err(e) => {
                let _ = fs::remove_dir_all(stage);
                return Err(io_err(dir, e));
            }
        }
    }
    let ready = sibling(dir, "ready");
    let old = sibling(dir, "old");
    fs::rename(stage, &ready).map_err(|e| io_err(&ready, e))?;
    fault_point("after-ready");
    fs::rename(dir, &old).map_err(|e| io_err(dir, e))?;
    fault_point("between-renames");
    fs::rename(&ready, dir).map_err(|e| io_err(dir, e))?;
    sync_dir(parent);
    fault_point("after-swap");
    let _ = fs::remove_dir_all(&old);
    Ok(())
}

// ---------------------------------------------------------------------------------------------------------------
// File sets inside a shared directory.

const JOURNAL_PREFIX: &str = ".rtbake-fileset-";

#[derive(serde::Serialize, serde::Deserialize)]
struct Journal {
    /// (temp path, final path), both relative to the directory.
    renames: Vec<(String, String)>,
}

/// Rolls forward every committed journal in `dir` and removes orphan temp files beside it (needs the lock).
fn settle_locked(dir: &Path) -> Result<Option<String>, FileSetError> {
    let mut done = 0usize;
    let mut journals = Vec::new();
    let mut orphans = Vec::new();
    if let Ok(rd) = fs::read_dir(dir) {
        for e in rd.flatten() {
            let n = e.file_name().to_string_lossy().into_owned();
            if n.starts_with(JOURNAL_PREFIX) && n.ends_with(".json") {
                journals.push(e.path());
            } else if super::atomic::is_temp_name(&n) || n.starts_with(".rtbake-write-probe-") {
                // Includes a journal's own temp (never committed) and the probes older versions could leave.
                orphans.push(e.path());
            }
        }
    }
    // Committed sets first (their temps are not orphans), then whatever temp file is left.
    for j in journals {
        let text = fs::read_to_string(&j).map_err(|e| io_err(&j, e))?;
        let journal: Journal = serde_json::from_str(&text).map_err(|e| FileSetError::Unusable {
            path: j.display().to_string(),
            detail: format!("unreadable file-set journal: {e}"),
        })?;
        for (tmp, dst) in &journal.renames {
            let (tmp, dst) = (dir.join(tmp), dir.join(dst));
            if tmp.exists() {
                fs::rename(&tmp, &dst).map_err(|e| io_err(&dst, e))?;
            }
            if let Some(p) = dst.parent() {
                sync_dir(p);
            }
        }
        fs::remove_file(&j).map_err(|e| io_err(&j, e))?;
        done += 1;
    }
    for o in orphans {
        let _ = fs::remove_file(o);
    }
    Ok((done > 0).then(|| format!("completed {done} interrupted file-set write(s) in {}", dir.display())))
}

/// For readers of a directory written by [`write_file_set`]: if a killed writer left a committed set half
/// renamed, completes it (under the lock) so the reader sees the whole new set, never a mix.
pub fn settle(dir: &Path, wait: &Wait) -> Result<Option<String>, FileSetError> {
    let pending =
        fs::read_dir(dir).map(|rd| rd.flatten().any(|e| e.file_name().to_string_lossy().starts_with(JOURNAL_PREFIX)));
    if !pending.unwrap_or(false) {
        return Ok(None);
    }
    let lock = DirLock::acquire(dir, LockMode::Exclusive, wait)?;
    settle_locked(lock.dir())
}

/// Directories with more entries than this are not staged whole (hard-linking them would cost more than the set):
/// their file sets are committed by the journal.
pub const MAX_LINKED_ENTRIES: usize = 10_000;

/// Holding the lock of `dir` (shared or exclusive): removes the staging directories killed writers left beside it
/// (`.NAME.rtbake-stage-PID` whose process is gone; a writer stages only while it holds this lock exclusively, so
/// no live writer's stage can be seen here). A stage of a live process — the lock-free writability probe of
/// [`probe_writable`] — is kept.
fn remove_stale_stages(dir: &Path) {
    let prefix = format!(".{}.rtbake-stage-", dir_name(dir));
    let Ok(rd) = fs::read_dir(parent_of(dir)) else { return };
    for e in rd.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = name.strip_prefix(&prefix).and_then(|p| p.parse::<u32>().ok()) else { continue };
        if pid != std::process::id() && !process_alive(pid) {
            let _ = fs::remove_dir_all(e.path());
        }
    }
}

/// Whether a process with this id exists (Unix: `kill(pid, 0)`; elsewhere assumed alive).
pub fn process_alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else { return false };
        // SAFETY: signal 0 performs only the existence and permission check.
        let r = unsafe { libc::kill(pid, 0) };
        r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// Recreates the tree under `from` in `to` with hard links (directories made, files linked, symbolic links copied),
/// leaving out the relative paths in `skip`. `false` when an entry cannot be reproduced that way (a special file,
/// a hard link refused) or there are more than [`MAX_LINKED_ENTRIES`] entries.
fn link_tree(from: &Path, to: &Path, rel: &str, skip: &[&str], count: &mut usize) -> std::io::Result<bool> {
    for e in fs::read_dir(from)? {
        let e = e?;
        let name = e.file_name().to_string_lossy().into_owned();
        let child_rel = if rel.is_empty() { name.clone() } else { format!("{rel}/{name}") };
        *count += 1;
        if *count > MAX_LINKED_ENTRIES {
            return Ok(false);
        }
        let (src, dst) = (e.path(), to.join(&name));
        let ft = e.file_type()?;
        if ft.is_dir() {
            fs::create_dir(&dst)?;
            fs::set_permissions(&dst, fs::metadata(&src)?.permissions())?;
            if !link_tree(&src, &dst, &child_rel, skip, count)? {
                return Ok(false);
            }
        } else if skip.contains(&child_rel.as_str()) || super::atomic::is_temp_name(&name) {
            continue;
        } else if ft.is_symlink() {
            #[cfg(unix)]
            std::os::unix::fs::symlink(fs::read_link(&src)?, &dst)?;
            #[cfg(not(unix))]
            return Ok(false);
        } else if ft.is_file() {
            if fs::hard_link(&src, &dst).is_err() {
                return Ok(false);
            }
        } else {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Writes the set by staging the whole directory beside it and exchanging the two (see the module docs). `Ok(false)`:
/// not possible here, nothing changed, the caller commits by the journal.
fn swap_whole_directory(lock: &DirLock, files: &[(&str, &[u8])]) -> Result<bool, FileSetError> {
    let root = lock.dir();
    if fault_flag("no-exchange") || cfg!(not(target_os = "linux")) {
        return Ok(false);
    }
    // Exchanging the working directory (or a directory above it) would leave this process, and a shell started
    // there, in the swapped-out copy.
    if std::env::current_dir().ok().and_then(|d| fs::canonicalize(d).ok()).is_some_and(|cwd| cwd.starts_with(root)) {
        return Ok(false);
    }
    let stage = sibling(root, "stage");
    let _ = fs::remove_dir_all(&stage);
    fs::create_dir(&stage).map_err(|e| io_err(&stage, e))?;
    let give_up = |stage: &Path| {
        let _ = fs::remove_dir_all(stage);
        Ok(false)
    };
    let skip: Vec<&str> = files.iter().map(|(rel, _)| *rel).collect();
    let mut count = 0;
    match link_tree(root, &stage, "", &skip, &mut count) {
        Ok(true) => {}
        Ok(false) | Err(_) => return give_up(&stage),
    }
    let written = (|| -> Result<Vec<PathBuf>, FileSetError> {
        let mut paths = Vec::with_capacity(files.len());
        for (rel, bytes) in files {
            let dst = stage.join(rel);
            if let Some(p) = dst.parent() {
                fs::create_dir_all(p).map_err(|e| io_err(p, e))?;
            }
            if dst.is_dir() {
                return Err(FileSetError::Unusable {
                    path: root.join(rel).display().to_string(),
                    detail: "is a directory; cannot write a file there".into(),
                });
            }
            fs::write(&dst, bytes).map_err(|e| io_err(&root.join(rel), e))?;
            paths.push(dst);
        }
        super::atomic::sync_batch(&stage, &paths)?;
        Ok(paths)
    })();
    let paths = match written {
        Ok(p) => p,
        Err(e) => {
            let _ = fs::remove_dir_all(&stage);
            return Err(e);
        }
    };
    let mut dirs: Vec<PathBuf> = paths.iter().filter_map(|p| p.parent().map(Path::to_path_buf)).collect();
    dirs.push(stage.clone());
    dirs.sort();
    dirs.dedup();
    dirs.iter().for_each(|d| sync_dir(d));
    if let Ok(md) = fs::metadata(root) {
        let _ = fs::set_permissions(&stage, md.permissions());
    }
    fault_point("staged");
    fault_point("before-swap");
    match exchange(&stage, root) {
        Ok(()) => {
            sync_dir(parent_of(root));
            fault_point("after-swap");
            // `stage` now holds the old directory: its links and the old versions of the set's files.
            let _ = fs::remove_dir_all(&stage);
            Ok(true)
        }
        Err(e) if exchange_unsupported(&e) => give_up(&stage),
        Err(e) => {
            let _ = fs::remove_dir_all(&stage);
            Err(io_err(root, e))
        }
    }
}

/// For a file `rel` (`/`-separated) listed in `dir`: the target of the first symbolic link on its path inside
/// `dir` (the file itself or a directory above it), if any. A listed file must be a regular file inside the
/// directory: a link to an identical file elsewhere would let that other file change what the directory holds.
pub fn symlink_on_path(dir: &Path, rel: &str) -> Option<String> {
    let mut p = dir.to_path_buf();
    for part in rel.split('/') {
        p.push(part);
        if fs::symlink_metadata(&p).ok()?.file_type().is_symlink() {
            let target = fs::read_link(&p).map(|t| t.display().to_string()).unwrap_or_else(|_| "?".into());
            return Some(format!("{} is a symbolic link to {target}", p.strip_prefix(dir).unwrap_or(&p).display()));
        }
    }
    None
}

/// Same file: equal canonical paths, or (Unix) the same device and inode.
fn same_file(a: &Path, b: &Path) -> bool {
    match (fs::canonicalize(a), fs::canonicalize(b)) {
        (Ok(x), Ok(y)) if x == y => return true,
        _ => {}
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (fs::metadata(a), fs::metadata(b)) {
            return x.dev() == y.dev() && x.ino() == y.ino();
        }
    }
    false
}

/// Refuses an output path that is one of `inputs` (same file, however spelled).
pub fn check_outputs_not_inputs(outputs: &[PathBuf], inputs: &[&Path]) -> Result<(), FileSetError> {
    for o in outputs {
        for i in inputs {
            if same_file(o, i) {
                return Err(FileSetError::OutputIsInput {
                    output: o.display().to_string(),
                    input: i.display().to_string(),
                });
            }
        }
    }
    Ok(())
}

/// Writes `files` (paths relative to `dir`, `/`-separated) into `dir` as one set: all or nothing, under the
/// directory's exclusive lock, refusing any output that is one of `inputs`. Creates `dir` if missing. Returns the
/// written paths.
pub fn write_file_set(
    dir: &Path,
    files: &[(&str, &[u8])],
    inputs: &[&Path],
    wait: &Wait,
) -> Result<Vec<PathBuf>, FileSetError> {
    for (rel, _) in files {
        let p = Path::new(rel);
        if rel.is_empty() || p.is_absolute() || p.components().any(|c| !matches!(c, std::path::Component::Normal(_))) {
            return Err(FileSetError::Unusable { path: rel.to_string(), detail: "not a plain relative path".into() });
        }
    }
    let outputs: Vec<PathBuf> = files.iter().map(|(rel, _)| dir.join(rel)).collect();
    for (k, (rel, _)) in files.iter().enumerate() {
        if files[..k].iter().any(|(r, _)| r == rel) {
            return Err(FileSetError::Unusable {
                path: dir.join(rel).display().to_string(),
                detail: "is given for two outputs of one command; give each output its own file".into(),
            });
        }
    }
    check_outputs_not_inputs(&outputs, inputs)?;
    fs::create_dir_all(dir).map_err(|e| io_err(dir, e))?;
    let lock = DirLock::acquire(dir, LockMode::Exclusive, wait)?;
    let root = lock.dir().to_path_buf();
    settle_locked(&root)?;
    if files.len() > 1 && swap_whole_directory(&lock, files)? {
        return Ok(outputs);
    }
    // Stage.
    let mut renames: Vec<(String, String)> = Vec::new();
    let staged = (|| -> Result<(), FileSetError> {
        for (rel, bytes) in files {
            let dst = root.join(rel);
            if let Some(p) = dst.parent() {
                fs::create_dir_all(p).map_err(|e| io_err(p, e))?;
            }
            if dst.is_dir() {
                return Err(FileSetError::Unusable {
                    path: dst.display().to_string(),
                    detail: "is a directory; cannot write a file there".into(),
                });
            }
            let tmp = super::atomic::stage_unsynced(&dst, bytes)?;
            let tmp_rel = tmp.strip_prefix(&root).expect("temp beside its file").to_string_lossy().into_owned();
            renames.push((tmp_rel, rel.to_string()));
        }
        // One flush for the whole set before the journal makes it the committed state.
        let temps: Vec<PathBuf> = renames.iter().map(|(tmp, _)| root.join(tmp)).collect();
        super::atomic::sync_batch(&root, &temps)?;
        Ok(())
    })();
    if let Err(e) = staged {
        for (tmp, _) in &renames {
            let _ = fs::remove_file(root.join(tmp));
        }
        return Err(e);
    }
    fault_point("staged");
    if let [(tmp, rel)] = renames.as_slice() {
        // One file: its rename is the commit point on its own (the path names the old or the new file at every
        // instant), so it needs no journal; one fsync of its directory makes the rename durable.
        let dst = root.join(rel);
        if let Err(e) = fs::rename(root.join(tmp), &dst) {
            let _ = fs::remove_file(root.join(tmp));
            return Err(io_err(&dst, e));
        }
        sync_dir(parent_of(&dst));
        return Ok(outputs);
    }
    // Commit point: the journal, written atomically.
    let journal = root.join(format!("{JOURNAL_PREFIX}{}.json", std::process::id()));
    let text = serde_json::to_string(&Journal { renames: renames.clone() }).expect("journal serialises");
    super::atomic::write_atomic(&journal, text.as_bytes())?;
    fault_point("journal-written");
    for (k, (tmp, dst)) in renames.iter().enumerate() {
        let dst = root.join(dst);
        fs::rename(root.join(tmp), &dst).map_err(|e| io_err(&dst, e))?;
        if k == 0 {
            fault_point("mid-commit");
        }
    }
    let mut dirs: Vec<PathBuf> = outputs.iter().filter_map(|p| p.parent().map(Path::to_path_buf)).collect();
    dirs.dedup();
    for d in dirs {
        sync_dir(&d);
    }
    fs::remove_file(&journal).map_err(|e| io_err(&journal, e))?;
    sync_dir(&root);
    Ok(outputs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_exclusive_lock_is_busy_without_wait() {
        let t = tempfile::tempdir().unwrap();
        let d = t.path().join("d");
        let a = DirLock::acquire(&d, LockMode::Exclusive, &Wait::No).unwrap();
        // A second open file description conflicts even within one process.
        let err = DirLock::acquire(&d, LockMode::Shared, &Wait::No).unwrap_err();
        assert!(matches!(err, FileSetError::Busy { .. }), "{err}");
        drop(a);
        let s1 = DirLock::acquire(&d, LockMode::Shared, &Wait::No).unwrap();
        let _s2 = DirLock::acquire(&d, LockMode::Shared, &Wait::No).unwrap();
        assert!(matches!(DirLock::acquire(&d, LockMode::Exclusive, &Wait::No), Err(FileSetError::Busy { .. })));
        drop(s1);
    }

    #[test]
    fn the_last_holder_removes_the_lock_file_and_a_waiter_relocks_a_fresh_one() {
        let t = tempfile::tempdir().unwrap();
        let d = t.path().join("d");
        let lock = lock_path(&d);
        // Readers: the last one out removes the file, the first one out leaves it to the other.
        let r1 = DirLock::acquire(&d, LockMode::Shared, &Wait::No).unwrap();
        let r2 = DirLock::acquire(&d, LockMode::Shared, &Wait::No).unwrap();
        drop(r1);
        assert!(lock.exists(), "removed while another reader held it");
        drop(r2);
        assert!(!lock.exists(), "the last reader left {}", lock.display());
        // A writer waited on the file its predecessor then removed: it must lock the file that names the
        // directory now, so a third process cannot hold the directory at the same time.
        let first = DirLock::acquire(&d, LockMode::Exclusive, &Wait::No).unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        let d2 = d.clone();
        let waiter = std::thread::spawn(move || {
            let say = |_: &str| tx.send(()).unwrap();
            let l = DirLock::acquire(&d2, LockMode::Exclusive, &Wait::Yes(&say)).unwrap();
            let busy = DirLock::acquire(&d2, LockMode::Exclusive, &Wait::No);
            assert!(matches!(busy, Err(FileSetError::Busy { .. })), "two exclusive holders");
            drop(l);
        });
        rx.recv().unwrap(); // the waiter opened the old file and is blocked on it
        drop(first);
        waiter.join().unwrap();
        assert!(!lock.exists(), "the waiter left {}", lock.display());
    }

    #[test]
    fn install_exchanges_and_leaves_nothing() {
        let t = tempfile::tempdir().unwrap();
        let d = t.path().join("d");
        fs::create_dir(&d).unwrap();
        fs::write(d.join("a"), b"old").unwrap();
        let lock = DirLock::acquire(&d, LockMode::Exclusive, &Wait::No).unwrap();
        let stage = sibling(lock.dir(), "stage");
        fs::create_dir(&stage).unwrap();
        fs::write(stage.join("a"), b"new").unwrap();
        install_dir(&lock, &stage).unwrap();
        assert_eq!(fs::read(d.join("a")).unwrap(), b"new");
        let names: Vec<String> =
            fs::read_dir(t.path()).unwrap().flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect();
        assert_eq!(names.len(), 2, "{names:?}"); // d and its lock file
    }

    #[test]
    fn file_set_refuses_an_input_as_output_and_writes_nothing() {
        let t = tempfile::tempdir().unwrap();
        let input = t.path().join("rig.json");
        fs::write(&input, b"in").unwrap();
        let spelled = t.path().join(".").join("rig.json");
        let err = write_file_set(t.path(), &[("x.bin", b"1"), ("rig.json", b"2")], &[&spelled], &Wait::No).unwrap_err();
        assert!(matches!(err, FileSetError::OutputIsInput { .. }), "{err}");
        assert_eq!(fs::read(&input).unwrap(), b"in");
        assert!(!t.path().join("x.bin").exists());
    }

    #[test]
    fn committed_journal_is_rolled_forward_and_orphans_removed() {
        let t = tempfile::tempdir().unwrap();
        let d = t.path().join("d");
        write_file_set(&d, &[("a", b"1"), ("sub/b", b"1")], &[], &Wait::No).unwrap();
        // Simulate a kill after the journal and the first rename.
        fs::write(d.join("sub/.b.rtbake-tmp-999"), b"2").unwrap();
        fs::write(d.join("a"), b"2").unwrap();
        let j = Journal {
            renames: vec![("a.tmp-gone".into(), "a".into()), ("sub/.b.rtbake-tmp-999".into(), "sub/b".into())],
        };
        fs::write(d.join(".rtbake-fileset-999.json"), serde_json::to_string(&j).unwrap()).unwrap();
        fs::write(d.join(".c.rtbake-tmp-998"), b"orphan").unwrap();
        assert!(settle(&d, &Wait::No).unwrap().is_some());
        assert_eq!(fs::read(d.join("sub/b")).unwrap(), b"2");
        let mut names: Vec<String> =
            fs::read_dir(&d).unwrap().flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        assert_eq!(names, ["a", "sub"]);
    }
}
