//! Issue 33, item 10: file names that are not UTF-8, and a standard output that cannot be
//! written (a closed pipe, a full device), end in one line (or quietly for a closed pipe),
//! never in a panic.

use std::ffi::OsStr;
use std::os::unix::ffi::OsStrExt;
use std::path::Path;
use std::process::{Command, Output, Stdio};

mod common;
use common::ok;

fn run(args: &[&OsStr], dir: &Path, stdout: Stdio) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .current_dir(dir)
        .stdout(stdout)
        .stderr(Stdio::piped())
        .output()
        .unwrap()
}

fn surface(dir: &Path) {
    let args = [
        "surface", "--n", "32", "--hurst", "0.8", "--size", "1", "--out", "s.npy",
    ];
    ok(&common::asperity(&args, dir));
}

#[test]
fn names_that_are_not_utf8_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    surface(dir.path());
    let bad = OsStr::from_bytes(b"x\xff.npy");
    std::fs::copy(dir.path().join("s.npy"), dir.path().join(bad)).unwrap();
    let o = |s: &'static str| OsStr::new(s);
    let cases: Vec<Vec<&OsStr>> = vec![
        vec![o("stats"), bad],
        vec![o("stats"), o("s.npy"), o("--psd"), bad],
        vec![
            o("bem"),
            o("--surface"),
            o("s.npy"),
            o("--pressures"),
            o("0.01"),
            o("--out"),
            bad,
        ],
        vec![o("bem"), o("--surface"), bad, o("--pressures"), o("0.01")],
        vec![o("mdr"), o("--line"), bad],
        vec![o("import"), bad, o("--out"), o("o.npy")],
        vec![
            o("contact"),
            bad,
            o("--pressures"),
            o("1e4"),
            o("--modulus"),
            o("1e9"),
        ],
        vec![o("reproduce"), o("fig1"), o("--quick"), o("--out"), bad],
    ];
    for args in cases {
        let out = run(&args, dir.path(), Stdio::null());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains("not UTF-8"), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    }
    assert!(!dir.path().join("x\u{fffd}").exists());
}

#[test]
fn a_closed_pipe_ends_quietly_and_a_full_device_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    surface(dir.path());
    let args = [OsStr::new("stats"), OsStr::new("s.npy")];
    // A pipe whose reading end is closed before anything is written: every write fails
    // with EPIPE.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = run(&args, dir.path(), Stdio::from(writer));
    assert_eq!(
        out.status.code(),
        Some(141),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let out = run(&args, dir.path(), Stdio::from(full));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.starts_with("error: writing to standard output"),
        "{stderr}"
    );
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
}
