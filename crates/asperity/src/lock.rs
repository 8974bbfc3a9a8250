//! An advisory lock on an output folder, so that two processes never work in one study or
//! `reproduce` folder at once.
//!
//! [`FolderLock::acquire`] takes an exclusive `flock(2)` on `DIR/.asperity.lock` without
//! waiting and writes the holder's PID into the file. The kernel releases a `flock` when
//! the last descriptor of the open file closes, which includes the death of the process by
//! any signal, so a killed run never leaves a stale lock: the file may stay, but it is
//! free. A second process is refused at once with [`Error::FolderInUse`], naming the PID
//! that the holder recorded. Two locks on one folder conflict within one process too.
//! Where `flock` does not exist (not Unix) the lock is a no-op.

use std::fs::File;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// The lock file's name inside a locked folder.
pub const LOCK_FILE: &str = ".asperity.lock";

/// A held lock; released when dropped (or when the process ends).
#[derive(Debug)]
pub struct FolderLock {
    _file: File,
    dir: PathBuf,
}

impl FolderLock {
    /// Locks the existing folder `dir`, or fails at once with [`Error::FolderInUse`].
    pub fn acquire(dir: &Path) -> Result<FolderLock> {
        let path = dir.join(LOCK_FILE);
        crate::io::refuse_link(&path)?;
        let mut options = std::fs::OpenOptions::new();
        options.read(true).write(true).create(true).truncate(false);
        crate::io::no_follow(&mut options);
        let mut file = options.open(&path).map_err(|e| link_or_io(&path, e))?;
        if !try_lock(&file).map_err(|e| Error::io(&path, e))? {
            return Err(Error::FolderInUse {
                dir: dir.to_path_buf(),
                holder: holder(&mut file),
            });
        }
        // Best effort: the PID only serves the message of a refused second process.
        let _ = file.set_len(0);
        let _ = file.rewind();
        let _ = write!(file, "{}", std::process::id());
        Ok(FolderLock {
            _file: file,
            dir: dir.to_path_buf(),
        })
    }

    /// The locked folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

/// A link planted between the check and the open makes `O_NOFOLLOW` fail with `ELOOP`:
/// the same refusal as [`crate::io::refuse_link`].
fn link_or_io(path: &Path, e: std::io::Error) -> Error {
    #[cfg(unix)]
    if e.raw_os_error() == Some(libc::ELOOP) {
        return crate::io::refuse_link(path)
            .err()
            .unwrap_or(Error::io(path, e));
    }
    Error::io(path, e)
}

/// `PID 1234`, as recorded by the holder (at most 32 bytes are read).
fn holder(file: &mut File) -> String {
    let mut text = String::new();
    let _ = file.rewind();
    let _ = file.take(32).read_to_string(&mut text);
    match text.trim().parse::<u32>() {
        Ok(pid) => format!("PID {pid}"),
        Err(_) => "PID not yet recorded".into(),
    }
}

#[cfg(unix)]
fn try_lock(file: &File) -> std::io::Result<bool> {
    use std::os::unix::io::AsRawFd;
    // SAFETY: flock on a descriptor this File owns; no memory is passed.
    let rc = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if rc == 0 {
        return Ok(true);
    }
    let err = std::io::Error::last_os_error();
    if err.raw_os_error() == Some(libc::EWOULDBLOCK) {
        Ok(false)
    } else {
        Err(err)
    }
}

#[cfg(not(unix))]
fn try_lock(_: &File) -> std::io::Result<bool> {
    Ok(true)
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_with_the_pid_and_freed_on_drop() {
        let dir = tempfile::tempdir().unwrap();
        let first = FolderLock::acquire(dir.path()).unwrap();
        let err = FolderLock::acquire(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains(&format!("PID {}", std::process::id())),
            "{err}"
        );
        assert!(!err.contains('\n'), "{err}");
        drop(first);
        FolderLock::acquire(dir.path()).unwrap();
    }

    #[test]
    fn a_link_in_place_of_the_lock_file_is_refused_and_its_target_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim.txt");
        std::fs::write(&victim, "precious").unwrap();
        std::os::unix::fs::symlink(&victim, dir.path().join(LOCK_FILE)).unwrap();
        let err = FolderLock::acquire(dir.path()).unwrap_err().to_string();
        assert!(err.contains("symbolic link"), "{err}");
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
        // A dangling link is refused too (it would create the file it names).
        let dangling = tempfile::tempdir().unwrap();
        let target = dangling.path().join("created");
        std::os::unix::fs::symlink(&target, dangling.path().join(LOCK_FILE)).unwrap();
        assert!(FolderLock::acquire(dangling.path()).is_err());
        assert!(!target.exists());
    }
}
