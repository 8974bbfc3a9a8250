//! `io::abandon_unfinished_outputs`, what a signal handler calls before exiting: it removes
//! the temporary files and new folders of outputs not yet committed, and leaves committed
//! outputs alone. It keeps the process-wide list locked afterwards, so it gets a test
//! binary of its own.

use asperity::io::{abandon_unfinished_outputs, StagedOutputs};

fn listing(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = walk(dir)
        .into_iter()
        .map(|p| p.strip_prefix(dir).unwrap().display().to_string())
        .collect();
    names.sort();
    names
}

fn walk(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(walk(&path));
        }
        out.push(path);
    }
    out
}

#[test]
fn unfinished_outputs_are_removed_and_finished_ones_kept() {
    let dir = tempfile::tempdir().unwrap();
    let done = dir.path().join("done.csv");
    let mut finished = StagedOutputs::new([&done], false).unwrap();
    finished.write_bytes(&done, b"kept").unwrap();
    finished.commit().unwrap();

    let fields = dir.path().join("fields/deeper");
    let (a, b) = (fields.join("a.npy"), dir.path().join("b.csv"));
    let mut pending = StagedOutputs::in_new_folders([&fields], [&a, &b], false).unwrap();
    pending.write_bytes(&a, b"half").unwrap();
    assert!(listing(dir.path()).iter().any(|n| n.ends_with(".tmp")));

    // A signal arrives: the handler removes what is unfinished and exits; the staged
    // outputs are never dropped (the process ends), so nothing else cleans up.
    abandon_unfinished_outputs();
    std::mem::forget(pending);
    assert_eq!(listing(dir.path()), ["done.csv"]);
    assert_eq!(std::fs::read(&done).unwrap(), b"kept");
}
