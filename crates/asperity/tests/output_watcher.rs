//! `io::watch_outputs`: the watcher a front end installs is told of every temporary file
//! and new folder of an unfinished output while it exists, runs each commit's renames, and
//! is told when each is finished (renamed into place, or removed). The watcher is
//! process-wide, so it gets a test binary of its own.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use asperity::io::{watch_outputs, OutputWatcher, StagedOutputs};

/// The paths reported unfinished and not yet finished, and how many commits ran.
#[derive(Default)]
struct Recorder {
    pending: Mutex<Vec<PathBuf>>,
    commits: Mutex<usize>,
}

impl OutputWatcher for Recorder {
    fn unfinished(&self, path: &Path) {
        let mut pending = self.pending.lock().unwrap();
        assert!(!pending.iter().any(|p| p == path), "{path:?} twice");
        pending.push(path.to_path_buf());
    }

    fn finished(&self, path: &Path) {
        let mut pending = self.pending.lock().unwrap();
        let i = pending.iter().position(|p| p == path);
        pending.swap_remove(i.unwrap_or_else(|| panic!("{path:?} was not unfinished")));
    }

    fn commit(&self, renames: &mut dyn FnMut()) {
        // Holding this lock through the renames is what a signal handler relies on: the
        // renames must not report back meanwhile (that would deadlock here).
        let _guard = self.pending.lock().unwrap();
        renames();
        *self.commits.lock().unwrap() += 1;
    }
}

fn pending(recorder: &Recorder) -> Vec<PathBuf> {
    let mut paths = recorder.pending.lock().unwrap().clone();
    paths.sort();
    paths
}

#[test]
fn the_watcher_sees_every_unfinished_path_until_it_is_finished() {
    let recorder: &'static Recorder = Box::leak(Box::default());
    assert!(watch_outputs(recorder).is_ok());
    assert!(watch_outputs(recorder).is_err(), "installed twice");
    let dir = tempfile::tempdir().unwrap();
    let (fields, deeper) = (dir.path().join("fields"), dir.path().join("fields/deeper"));
    let (a, b) = (deeper.join("a.npy"), dir.path().join("b.csv"));

    // Folders made and a file written: all three exist and are reported.
    let mut staged = StagedOutputs::in_new_folders([&deeper], [&a, &b], false).unwrap();
    staged.write_bytes(&a, b"half").unwrap();
    let seen = pending(recorder);
    assert_eq!(seen.len(), 3, "{seen:?}");
    assert!(seen.contains(&fields) && seen.contains(&deeper));
    assert!(seen.iter().all(|p| p.exists()));
    let tmp = seen
        .iter()
        .find(|p| p.to_string_lossy().ends_with(".tmp"))
        .unwrap();
    assert_eq!(tmp.parent(), Some(deeper.as_path()));

    // Removing what is reported (what a signal handler does) leaves nothing behind.
    let mut removal = seen.clone();
    removal.sort_by_key(|p| std::cmp::Reverse(p.components().count()));
    for path in &removal {
        let _ = std::fs::remove_file(path).or_else(|_| std::fs::remove_dir(path));
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    std::fs::create_dir_all(&deeper).unwrap(); // back, for the drop below

    // Dropped uncommitted: everything is finished.
    drop(staged);
    assert!(pending(recorder).is_empty());

    // Committed: the renames run inside `commit`, and nothing stays pending.
    let mut staged = StagedOutputs::new([&b], false).unwrap();
    staged.write_bytes(&b, b"done").unwrap();
    assert_eq!(pending(recorder).len(), 1);
    staged.commit().unwrap();
    assert_eq!(*recorder.commits.lock().unwrap(), 1);
    assert!(pending(recorder).is_empty());
    assert_eq!(std::fs::read(&b).unwrap(), b"done");
}
