//! Ctrl-C, SIGTERM and SIGHUP: the process exits with the conventional status 130 after
//! removing the temporary files (and the folders made for them) of every output not yet
//! renamed into place, so an interrupt never leaves a half-written output or a stray
//! `.tmp` file. Finished outputs and study checkpoints stay; a study resumes from them.
//!
//! While a study computes its samples ([`graceful`]), the first interrupt only asks it to
//! stop ([`stop`], the study folder's stop request): the study checkpoints the samples it
//! finished and the front end then exits with 130 ([`exit_interrupted`]); a second
//! interrupt exits at once.
//!
//! The library keeps no process-wide state: it reports each unfinished path to the
//! [`asperity::io::OutputWatcher`] installed here, and this module owns the list.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{LazyLock, Mutex, MutexGuard};

use asperity::io::OutputWatcher;
use asperity::stop::Stop;

/// The stop request of the study running in this process.
static STOP: LazyLock<Stop> = LazyLock::new(Stop::new);

/// Whether a study that checkpoints on [`STOP`] is computing now.
static GRACEFUL: AtomicBool = AtomicBool::new(false);

/// The stop request a study polls (hand it to `StudyDir::with_stop`).
pub fn stop() -> Stop {
    STOP.clone()
}

/// Whether an interrupt asked the study to stop.
pub fn stop_requested() -> bool {
    STOP.is_requested()
}

/// While the returned guard lives, the first interrupt requests [`stop`] instead of
/// exiting: the study checkpoints what it finished, then calls [`exit_interrupted`].
pub fn graceful() -> Graceful {
    GRACEFUL.store(true, Ordering::SeqCst);
    Graceful
}

/// See [`graceful`]; interrupts exit at once again once dropped.
pub struct Graceful;

impl Drop for Graceful {
    fn drop(&mut self) {
        GRACEFUL.store(false, Ordering::SeqCst);
    }
}

/// Removes the unfinished outputs and exits with 130.
pub fn exit_interrupted() -> ! {
    std::mem::forget(UNFINISHED.remove_all());
    eprintln!("interrupted: unfinished outputs removed (a study resumes when run again)");
    std::process::exit(130);
}

/// The temporary files and folders of unfinished outputs, in the order they were made.
struct Unfinished(Mutex<Vec<PathBuf>>);

static UNFINISHED: Unfinished = Unfinished(Mutex::new(Vec::new()));

impl Unfinished {
    fn lock(&self) -> MutexGuard<'_, Vec<PathBuf>> {
        // A panic while holding the lock leaves the list valid: keep using it.
        self.0
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Removes every listed path, newest first (so a file goes before its folder, and a
    /// folder only if empty), and returns the list still locked: a handler that exits
    /// right after keeps it so, and a commit on another thread then never renames.
    fn remove_all(&self) -> MutexGuard<'_, Vec<PathBuf>> {
        let mut list = self.lock();
        for path in list.drain(..).rev() {
            if path.is_dir() {
                let _ = std::fs::remove_dir(&path); // only if empty
            } else {
                let _ = std::fs::remove_file(&path);
            }
        }
        list
    }
}

impl OutputWatcher for Unfinished {
    fn unfinished(&self, path: &Path) {
        self.lock().push(path.to_path_buf());
    }

    fn finished(&self, path: &Path) {
        let mut list = self.lock();
        if let Some(i) = list.iter().rposition(|p| p == path) {
            list.remove(i);
        }
    }

    fn commit(&self, renames: &mut dyn FnMut()) {
        // Held through the renames: an interrupting signal waits until all are done.
        let _list = self.lock();
        renames();
    }
}

/// Installs the watcher and the signal handler; a warning (not an error) where the
/// platform refuses the handler.
pub fn install() {
    let _ = asperity::io::watch_outputs(&UNFINISHED);
    let handler = ctrlc::set_handler(|| {
        if GRACEFUL.load(Ordering::SeqCst) && !STOP.is_requested() {
            STOP.request();
            eprintln!(
                "interrupted: checkpointing the finished samples (interrupt again to quit at once)"
            );
            return;
        }
        exit_interrupted();
    });
    if let Err(err) = handler {
        eprintln!(
            "warning: no interrupt handler ({err}); an interrupted run may leave hidden .tmp files"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unfinished_paths_are_removed_and_finished_ones_kept() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let list = Unfinished(Mutex::new(Vec::new()));
        // A committed output, and an unfinished one in two new folders.
        std::fs::write(d.join("done.csv"), b"kept").unwrap();
        let (fields, deeper) = (d.join("fields"), d.join("fields/deeper"));
        for folder in [&fields, &deeper] {
            std::fs::create_dir(folder).unwrap();
            list.unfinished(folder);
        }
        let tmp = deeper.join(".a.npy.1.0.tmp");
        std::fs::write(&tmp, b"half").unwrap();
        list.unfinished(&tmp);
        // A finished temporary file (renamed into place) is not removed.
        let renamed = d.join(".b.csv.1.0.tmp");
        list.unfinished(&renamed);
        list.finished(&renamed);
        std::fs::write(&renamed, b"someone else's").unwrap();
        let left = list.remove_all();
        assert!(left.is_empty());
        drop(left);
        let mut names: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, [".b.csv.1.0.tmp", "done.csv"]);
        assert_eq!(std::fs::read(d.join("done.csv")).unwrap(), b"kept");
    }
}
