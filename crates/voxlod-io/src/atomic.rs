//! Writing files so that they appear whole or not at all.
//!
//! Every writer of this crate goes through here. The bytes go to a temporary file in the target's
//! own directory (`.name.tmp-PID-N`, so the final rename never crosses file systems), and only
//! when everything has been written and flushed is it renamed over the target. On any failure —
//! an I/O error, an error of the format code, even a panic — the temporary file is removed and
//! the target is left as it was. There is no `fsync`: this protects against failed and
//! interrupted writes, not against power loss.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::IoError;

/// Writes `path` through `write`, atomically (see the module documentation).
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), IoError> {
    let mut temp = TempFile::create(path)?;
    temp.write_with(write)?;
    temp.commit()
}

/// A temporary sibling of a target file, removed on drop unless committed.
///
/// Several files that belong together (a NRRD header and its data file) are written as several
/// `TempFile`s, all filled before any is committed.
pub(crate) struct TempFile {
    target: PathBuf,
    temp: PathBuf,
    writer: Option<BufWriter<File>>,
}

static COUNTER: AtomicU64 = AtomicU64::new(0);

impl TempFile {
    /// Creates the temporary file next to `target`.
    pub(crate) fn create(target: &Path) -> Result<TempFile, IoError> {
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
        loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let mut temp_name = std::ffi::OsString::from(".");
            temp_name.push(name);
            temp_name.push(format!(".tmp-{}-{n}", std::process::id()));
            let temp = dir.join(temp_name);
            match OpenOptions::new().write(true).create_new(true).open(&temp) {
                Ok(file) => {
                    return Ok(TempFile {
                        target: target.to_path_buf(),
                        temp,
                        writer: Some(BufWriter::with_capacity(1 << 20, file)),
                    })
                }
                // A stale file of an earlier crash with the same name: take the next number.
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(IoError::access(target, "cannot write", &e)),
            }
        }
    }

    /// Runs `write` on the temporary file and flushes it.
    pub(crate) fn write_with(
        &mut self,
        write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
    ) -> Result<(), IoError> {
        let writer = self
            .writer
            .as_mut()
            .expect("write_with is called once, before commit");
        write(writer)
            .and_then(|()| writer.flush())
            .map_err(|e| IoError::access(&self.target, "cannot write", &e))
    }

    /// Renames the temporary file over the target.
    pub(crate) fn commit(mut self) -> Result<(), IoError> {
        // Close the file before renaming it (required on some platforms).
        drop(self.writer.take());
        std::fs::rename(&self.temp, &self.target)
            .map_err(|e| IoError::access(&self.target, "cannot rename the finished file", &e))?;
        // Nothing left to clean up.
        self.temp = PathBuf::new();
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        drop(self.writer.take());
        if !self.temp.as_os_str().is_empty() {
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

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
}
