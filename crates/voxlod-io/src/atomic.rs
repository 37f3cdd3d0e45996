//! Writing files so that they appear whole or not at all, even when the process is stopped.
//!
//! Every writer of this crate goes through a `TempFile` in the target's own directory (so the
//! final step never crosses file systems), and only when everything has been written and flushed
//! is it put in place under the target's name. On any failure — an I/O error, an error of the
//! format code, even a panic — the temporary file is discarded and the target is left as it was.
//!
//! - On Linux the temporary file has no name (`O_TMPFILE`): nothing of it is visible while it is
//!   written, and the kernel frees it when the process ends in any way, `kill -9` included. At
//!   commit it is linked in under the target's name (`linkat` through `/proc/self/fd`); when the
//!   target exists, under a temporary name that is then renamed over the target, so that a reader
//!   sees the old file or the new one, never a mix.
//! - Elsewhere, on file systems without `O_TMPFILE`, or once [`use_named_temporaries`] is
//!   called, it is a named sibling `.NAME.tmp-PID-N`, renamed over the target at commit. These names are kept in a process-wide registry:
//!   [`remove_temporaries_on_signals`] removes them on SIGINT, SIGTERM and SIGHUP. Only a
//!   `kill -9` can leave one behind.
//!
//! Committing holds the registry's lock, so a signal either comes before a commit (nothing
//! appears) or after it; [`crate::OutputSet`] commits several files under one hold. There is no
//! `fsync`: this protects against failed and interrupted runs, not against power loss.
//!
//! Cost: nothing beyond the write itself: the temporary becomes the file by one rename or link,
//! O(1) per file; the registry of pending temporaries is O(files being written).

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

use crate::IoError;

/// Writes `path` through `write`, atomically (see the module documentation). Does not check the
/// path against a command's inputs: commands write through [`crate::OutputSet`].
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), IoError> {
    stage(path, write)?.commit()
}

/// Writes `path`'s temporary file through `write`, leaving the commit to the caller.
pub(crate) fn stage(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<TempFile, IoError> {
    let mut temp = TempFile::create(path)?;
    temp.write_with(write)?;
    Ok(temp)
}

// -------------------------------------------------------------------------------------------
// The registry of what a signal must clean up.

/// Named temporary files and created folders of this process that are not committed yet.
#[derive(Default)]
pub(crate) struct Registry {
    temporaries: Vec<PathBuf>,
    folders: Vec<PathBuf>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    temporaries: Vec::new(),
    folders: Vec::new(),
});

/// The registry, locked. A panic elsewhere does not stop the clean-up.
pub(crate) fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Registry {
    fn forget_temporary(&mut self, path: &Path) {
        self.temporaries.retain(|p| p != path);
    }

    /// Registers a folder that a set of outputs created, to be removed (if still empty) when the
    /// set is abandoned or the process is stopped.
    pub(crate) fn add_folder(&mut self, dir: PathBuf) {
        self.folders.push(dir);
    }

    /// Forgets a folder: its set was committed, or the folder was removed.
    pub(crate) fn forget_folder(&mut self, dir: &Path) {
        self.folders.retain(|p| p != dir);
    }

    /// Removes every registered temporary file, then every registered folder that is empty
    /// (the most recently created first).
    fn remove_all(&mut self) {
        for temp in self.temporaries.drain(..) {
            let _ = std::fs::remove_file(temp);
        }
        for dir in self.folders.drain(..).rev() {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

/// Removes this process's temporary files and the empty folders its unfinished outputs created,
/// and keeps the registry locked for good, so that no writer can create a new temporary
/// afterwards. For a process about to end (see [`remove_temporaries_on_signals`]).
pub fn remove_temporaries_for_exit() {
    let mut registry = registry();
    registry.remove_all();
    std::mem::forget(registry);
}

/// On SIGINT, SIGTERM and SIGHUP: removes this process's temporary files (see
/// [`remove_temporaries_for_exit`]), prints `message` and the signal on standard error, and
/// ends the process with status 128 + the signal's number (130, 143, 129).
///
/// Call it first thing in `main`, before any other thread starts: it blocks these signals in
/// the calling thread, which every later thread inherits, and waits for them in a thread of its
/// own (so the clean-up runs as ordinary code, not in a signal handler). Unix only; elsewhere it
/// does nothing.
pub fn remove_temporaries_on_signals(message: &'static str) {
    #[cfg(unix)]
    signals::wait_in_a_thread(message);
    #[cfg(not(unix))]
    let _ = message;
}

#[cfg(unix)]
mod signals {
    const SIGNALS: [(libc::c_int, &str); 3] = [
        (libc::SIGINT, "SIGINT"),
        (libc::SIGTERM, "SIGTERM"),
        (libc::SIGHUP, "SIGHUP"),
    ];

    pub(super) fn wait_in_a_thread(message: &'static str) {
        // SAFETY: sigset_t is plain data that sigemptyset initialises; pthread_sigmask only
        // changes this thread's mask.
        let set = unsafe {
            let mut set: libc::sigset_t = std::mem::zeroed();
            libc::sigemptyset(&mut set);
            for (signal, _) in SIGNALS {
                libc::sigaddset(&mut set, signal);
            }
            libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut());
            set
        };
        let waiter = std::thread::Builder::new()
            .name("voxlod-signals".into())
            .spawn(move || loop {
                let mut signal: libc::c_int = 0;
                // SAFETY: `set` is an initialised signal set and `signal` a valid out pointer.
                if unsafe { libc::sigwait(&set, &mut signal) } == 0 {
                    stop(message, signal);
                }
            });
        if waiter.is_err() {
            // No thread to wait: let the signals act as before rather than be ignored.
            // SAFETY: as above.
            unsafe { libc::pthread_sigmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut()) };
        }
    }

    fn stop(message: &str, signal: libc::c_int) -> ! {
        super::remove_temporaries_for_exit();
        let name = SIGNALS
            .iter()
            .find(|(s, _)| *s == signal)
            .map_or("a signal", |(_, name)| name);
        let line = format!("{message} ({name})\n");
        // A raw write: another thread may hold the lock of std's stderr.
        // SAFETY: the pointer and length describe `line`'s bytes.
        unsafe {
            libc::write(2, line.as_ptr().cast(), line.len());
            libc::_exit(128 + signal)
        }
    }
}

// -------------------------------------------------------------------------------------------
// Temporary files.

/// A temporary file for a target file, discarded on drop unless committed.
///
/// Several files that belong together (a NRRD header and its data file, the levels of a
/// pyramid) are written as several `TempFile`s, all filled before any is committed.
pub(crate) struct TempFile {
    target: PathBuf,
    /// `None` once committed, or after a failed write.
    file: Option<File>,
    /// The temporary's name; `None` for an unnamed file, and once committed or removed.
    name: Option<PathBuf>,
}

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// `dir/.NAME.tmp-PID-N`, with a number not used before in this process.
fn temporary_name(dir: &Path, name: &std::ffi::OsStr) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(".tmp-{}-{n}", std::process::id()));
    dir.join(temp_name)
}

/// The folder of `target` (`.` for a bare file name) and its file name.
fn split(target: &Path) -> Result<(PathBuf, &std::ffi::OsStr), IoError> {
    let name = target.file_name().ok_or_else(|| {
        IoError::new(
            target,
            crate::IoErrorKind::Access,
            "cannot write: the path does not name a file",
        )
    })?;
    let dir = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((dir, name))
}

impl TempFile {
    /// Creates the temporary file for `target`: unnamed where the system allows, else named.
    pub(crate) fn create(target: &Path) -> Result<TempFile, IoError> {
        let (dir, name) = split(target)?;
        let (file, name) = match unnamed::create(&dir) {
            Some(file) => (file, None),
            None => {
                let (file, temp) = create_named(target, &dir, name)?;
                (file, Some(temp))
            }
        };
        Ok(TempFile {
            target: target.to_path_buf(),
            file: Some(file),
            name,
        })
    }

    /// Whether the temporary has a name in the file system (false for an unnamed file).
    #[cfg(test)]
    pub(crate) fn is_named(&self) -> bool {
        self.name.is_some()
    }

    pub(crate) fn target(&self) -> &Path {
        &self.target
    }

    /// Runs `write` on the temporary file, buffered, and flushes it. The buffer goes when done,
    /// so that a set of many staged files holds only their descriptors.
    pub(crate) fn write_with(
        &mut self,
        write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
    ) -> Result<(), IoError> {
        let file = self
            .file
            .take()
            .expect("write_with is called before commit");
        let mut writer = BufWriter::with_capacity(1 << 20, file);
        let file = write(&mut writer)
            .and_then(|()| writer.flush())
            .and_then(|()| writer.into_inner().map_err(|e| e.into_error()))
            .map_err(|e| IoError::access(&self.target, "cannot write", &e))?;
        self.file = Some(file);
        Ok(())
    }

    /// Puts the file in place under the target's name.
    pub(crate) fn commit(self) -> Result<(), IoError> {
        let mut registry = registry();
        self.commit_locked(&mut registry)
    }

    /// [`TempFile::commit`] for a caller that holds the registry's lock (to commit several
    /// files under one hold).
    pub(crate) fn commit_locked(mut self, registry: &mut Registry) -> Result<(), IoError> {
        // Taken first: `drop` must find nothing to unregister, since the caller holds the lock.
        let name = self.name.take();
        let file = self
            .file
            .take()
            .expect("a TempFile is committed once, after writing");
        let placed = match &name {
            Some(temp) => {
                // Close the file before renaming it (required on some platforms).
                drop(file);
                std::fs::rename(temp, &self.target)
            }
            None => unnamed::link(&file, &self.target),
        };
        if let Some(temp) = &name {
            if placed.is_err() {
                let _ = std::fs::remove_file(temp);
            }
            registry.forget_temporary(temp);
        }
        placed
            .map_err(|e| IoError::access(&self.target, "cannot put the finished file in place", &e))
    }
}

/// Creates `dir/.NAME.tmp-PID-N` and registers it, under the registry's lock so that a signal
/// cannot come between the two.
fn create_named(
    target: &Path,
    dir: &Path,
    name: &std::ffi::OsStr,
) -> Result<(File, PathBuf), IoError> {
    let mut registry = registry();
    loop {
        let temp = temporary_name(dir, name);
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(file) => {
                registry.temporaries.push(temp.clone());
                return Ok((file, temp));
            }
            // A stale file of an earlier crash with the same name: take the next number.
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(IoError::access(target, "cannot write", &e)),
        }
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        drop(self.file.take());
        if let Some(temp) = self.name.take() {
            let mut registry = registry();
            let _ = std::fs::remove_file(&temp);
            registry.forget_temporary(&temp);
        }
    }
}

static NAMED_TEMPORARIES: AtomicBool = AtomicBool::new(false);

/// Makes every temporary file this process creates from now on a named one, as on systems
/// without unnamed temporary files (see the module documentation): a write in progress shows in
/// its folder as `.NAME.tmp-PID-N`, a failed write and [`remove_temporaries_on_signals`]
/// remove it, and only a `kill -9` leaves it behind. Unnamed temporaries, where the system has
/// them, are the default; this cannot be undone within the process.
pub fn use_named_temporaries() {
    NAMED_TEMPORARIES.store(true, Ordering::Relaxed);
}

/// Whether [`use_named_temporaries`] was called.
fn named_temporaries_asked() -> bool {
    NAMED_TEMPORARIES.load(Ordering::Relaxed)
}

/// Unnamed temporary files: Linux's `O_TMPFILE`, linked in through `/proc/self/fd`.
#[cfg(target_os = "linux")]
mod unnamed {
    use std::ffi::CString;
    use std::fs::{File, OpenOptions};
    use std::io;
    use std::os::unix::ffi::OsStrExt;
    use std::os::unix::fs::OpenOptionsExt;
    use std::os::unix::io::AsRawFd;
    use std::path::Path;

    /// An unnamed file in `dir`, or `None` where that is not possible (no `/proc`, a file
    /// system without `O_TMPFILE`, named temporaries asked for), for the caller to fall back
    /// to a named one, which also reports any real error such as a missing folder.
    pub(super) fn create(dir: &Path) -> Option<File> {
        static PROC: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
        let proc = *PROC.get_or_init(|| Path::new("/proc/self/fd").is_dir());
        if !proc || super::named_temporaries_asked() {
            return None;
        }
        OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_TMPFILE)
            .mode(0o666)
            .open(dir)
            .ok()
    }

    /// Gives `file` the name `to`; fails if `to` exists.
    fn link_as(file: &File, to: &Path) -> io::Result<()> {
        let from = CString::new(format!("/proc/self/fd/{}", file.as_raw_fd()))?;
        let to = CString::new(to.as_os_str().as_bytes())?;
        // SAFETY: both are valid NUL-terminated paths that outlive the call.
        let linked = unsafe {
            libc::linkat(
                libc::AT_FDCWD,
                from.as_ptr(),
                libc::AT_FDCWD,
                to.as_ptr(),
                libc::AT_SYMLINK_FOLLOW,
            )
        };
        if linked == 0 {
            Ok(())
        } else {
            Err(io::Error::last_os_error())
        }
    }

    /// Links `file` in as `target`: directly when `target` does not exist, else under a
    /// temporary name renamed over it (an atomic replacement). The caller holds the registry's
    /// lock, so no signal clean-up runs while the temporary name exists.
    pub(super) fn link(file: &File, target: &Path) -> io::Result<()> {
        match link_as(file, target) {
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
            done => return done,
        }
        let (dir, name) = super::split(target).map_err(|e| io::Error::other(e.message))?;
        let temp = loop {
            let temp = super::temporary_name(&dir, name);
            match link_as(file, &temp) {
                Ok(()) => break temp,
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        };
        std::fs::rename(&temp, target).inspect_err(|_| {
            let _ = std::fs::remove_file(&temp);
        })
    }
}

#[cfg(not(target_os = "linux"))]
mod unnamed {
    use std::fs::File;
    use std::path::Path;

    pub(super) fn create(_dir: &Path) -> Option<File> {
        None
    }

    pub(super) fn link(_file: &File, _target: &Path) -> std::io::Result<()> {
        unreachable!("there are no unnamed temporaries on this platform")
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The names in a folder, sorted.
    pub(crate) use voxlod_testkit::files::entries;

    #[test]
    fn success_leaves_only_the_target() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomically(&path, |w| w.write_all(b"hello")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"hello");
        assert_eq!(entries(dir.path()), ["out.txt"]);
    }

    #[test]
    fn failure_keeps_the_old_file_and_removes_the_temp() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        std::fs::write(&path, b"old").unwrap();
        let err = write_atomically(&path, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("the format code failed"))
        })
        .unwrap_err();
        assert_eq!(err.kind, crate::IoErrorKind::Access);
        assert!(err.to_string().contains("out.txt"), "{err}");
        assert!(err.to_string().contains("the format code failed"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(entries(dir.path()), ["out.txt"]);
    }

    #[test]
    fn a_panic_removes_the_temp() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.bin");
        let result = std::panic::catch_unwind(|| {
            let _ = write_atomically(&path, |_| panic!("boom"));
        });
        assert!(result.is_err());
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn missing_directory_is_an_access_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no/such/dir/x.ply");
        let err = write_atomically(&path, |w| w.write_all(b"x")).unwrap_err();
        assert_eq!(err.kind, crate::IoErrorKind::Access);
        assert!(err.to_string().contains("x.ply"), "{err}");
        assert!(entries(dir.path()).is_empty());
    }

    /// On Linux the file being written has no name: a `kill -9` at this point leaves nothing.
    /// The commit replaces an existing target with the whole new content.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_file_being_written_is_invisible_until_committed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.raw");
        std::fs::write(&path, b"old").unwrap();
        let mut temp = TempFile::create(&path).unwrap();
        if temp.is_named() {
            // ext4, XFS, Btrfs and tmpfs have it; some overlay and network file systems do not.
            let temp_dir = std::env::temp_dir();
            voxlod_testkit::skips::skip(format!(
                "the file system of {} has no O_TMPFILE",
                temp_dir.display()
            ));
            return;
        }
        temp.write_with(|w| w.write_all(&[7u8; 100_000])).unwrap();
        assert_eq!(entries(dir.path()), ["big.raw"]);
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        temp.commit().unwrap();
        assert_eq!(entries(dir.path()), ["big.raw"]);
        assert_eq!(std::fs::read(&path).unwrap(), vec![7u8; 100_000]);
        // A new name is linked in directly.
        let fresh = dir.path().join("fresh.raw");
        let temp = stage(&fresh, |w| w.write_all(b"new")).unwrap();
        temp.commit().unwrap();
        assert_eq!(std::fs::read(&fresh).unwrap(), b"new");
        assert_eq!(entries(dir.path()), ["big.raw", "fresh.raw"]);
    }

    /// Named temporaries (the fallback) are registered until committed or dropped, and the
    /// exit clean-up removes those still registered.
    #[test]
    fn named_temporaries_are_registered_for_the_clean_up() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("n.txt");
        let (dir_path, name) = split(&path).unwrap();
        let (file, temp) = create_named(&path, &dir_path, name).unwrap();
        let file_name = temp.file_name().unwrap().to_string_lossy().into_owned();
        assert!(file_name.starts_with(".n.txt.tmp-"), "{file_name}");
        assert!(registry().temporaries.contains(&temp));
        let staged = TempFile {
            target: path.clone(),
            file: Some(file),
            name: Some(temp.clone()),
        };
        assert!(staged.is_named());
        assert_eq!(entries(dir.path()), [file_name]);
        drop(staged);
        assert!(entries(dir.path()).is_empty());
        assert!(!registry().temporaries.contains(&temp));

        // What a signal does: every registered name goes, and only those.
        let (_file, temp) = create_named(&path, &dir_path, name).unwrap();
        std::fs::write(dir.path().join("kept.txt"), b"x").unwrap();
        let mut local = Registry {
            temporaries: vec![temp.clone()],
            folders: Vec::new(),
        };
        registry().forget_temporary(&temp);
        local.remove_all();
        assert_eq!(entries(dir.path()), ["kept.txt"]);
    }
}
