//! Helpers shared by the CLI integration tests: run the real binary, check a run succeeded
//! or was refused the way the CLI promises (exit status 2, one line on stderr), and read
//! back what it wrote.
//!
//! Every test file is its own crate and compiles this module whole, using only part of it.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `asperity args` in the test's working directory (stdin closed, output captured).
pub fn run_asperity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Runs `asperity args` in `dir`.
pub fn asperity(args: &[&str], dir: &Path) -> Output {
    asperity_env(args, dir, &[])
}

/// Runs `asperity args` in `dir` with extra environment variables.
pub fn asperity_env(args: &[&str], dir: &Path, env: &[(&str, &str)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

/// The run's stderr as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Asserts the run succeeded, showing its stderr when not.
pub fn ok(out: &Output) {
    assert!(out.status.success(), "{}", stderr(out));
}

/// Asserts the run was refused as the CLI promises: exit status 2 and one line on stderr,
/// in words (no NUL byte, no `Debug` struct text), that contains `needle`. Returns that
/// stderr.
pub fn refused(out: &Output, needle: &str) -> String {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(needle), "expected '{needle}' in: {err}");
    assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
    assert!(!err.contains('\0') && !err.contains(" { "), "{err:?}");
    err
}

/// Width and height of a PNG file.
pub fn png_size(path: &Path) -> (u32, u32) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let reader = decoder.read_info().unwrap();
    (reader.info().width, reader.info().height)
}

/// The names of the entries of `dir`, sorted.
pub fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The paths of the entries of `dir`, sorted.
pub fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    out.sort();
    out
}

/// Every file under `dir` (recursively) with its bytes, by its path relative to `dir`,
/// except the files whose name `skip` accepts (bookkeeping that a resumed run may write
/// differently: stamps, timings, locks, temporary files).
pub fn files_under(dir: &Path, skip: impl Fn(&str) -> bool) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                stack.push(path);
            } else if !skip(&name) {
                let key = path
                    .strip_prefix(dir)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned();
                out.insert(key, std::fs::read(&path).unwrap());
            }
        }
    }
    out
}

/// `mdr` on the adhesive JKR sphere of the CLI tests: R = 1, E* = 1, Δγ = 1e-3 on 1001
/// springs Δx = 1e-3 apart (the force-controlled pull-off radius is 152 Δx, the
/// displacement-controlled one 73 Δx); the path and outputs follow.
pub const JKR_SPHERE_MDR: [&str; 11] = [
    "mdr",
    "--profile",
    "hertz",
    "--radius",
    "1",
    "--n",
    "1001",
    "--dx",
    "1e-3",
    "--work-of-adhesion",
    "1e-3",
];
