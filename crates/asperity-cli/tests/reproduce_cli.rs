//! `asperity reproduce` on folders that already hold something: the same command resumes
//! (an interrupted run finishes with the numbers of an uninterrupted one), anything else is
//! refused before any work.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::{asperity, ok};

#[test]
fn the_same_command_runs_again_and_foreign_folders_are_refused_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&asperity(&["reproduce", "fig15.1", "--out", "R"], d));
    let first = std::fs::read(d.join("R/fig15.1/fig15_1.csv")).unwrap();
    // Run again: no --force needed, same numbers.
    ok(&asperity(&["reproduce", "fig15.1", "--out", "R"], d));
    assert_eq!(
        std::fs::read(d.join("R/fig15.1/fig15_1.csv")).unwrap(),
        first
    );

    // A folder holding someone else's file: refused before the first figure starts.
    std::fs::create_dir_all(d.join("R/fig6")).unwrap();
    std::fs::write(d.join("R/fig6/report.md"), "mine").unwrap();
    let out = asperity(&["reproduce", "all", "--quick", "--out", "R"], d);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("R/fig6") && err.contains("--force"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert_eq!(
        std::fs::read_to_string(d.join("R/fig6/report.md")).unwrap(),
        "mine"
    );
    for later in ["fig1", "fig2", "fig5", "fig15.2"] {
        assert!(!d.join("R").join(later).exists(), "{later} was started");
    }
    // The same figure with another setting is someone else too.
    let out = asperity(&["reproduce", "fig15.1", "--quick", "--out", "R"], d);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
#[ignore = "slow tier: cargo test --release -- --ignored (.ci/run runs it)"]
fn an_interrupted_figure_resumes_to_the_uninterrupted_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = |out: &'static str| ["reproduce", "fig5", "--quick", "--out", out];
    let child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args("cut"))
        .current_dir(d)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let checkpoints = d.join("cut/fig5/mdr/checkpoint");
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(60)
        && std::fs::read_dir(&checkpoints).map_or(true, |mut e| e.next().is_none())
    {
        std::thread::sleep(Duration::from_millis(5));
    }
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    assert!(
        !d.join("cut/fig5/fig5.csv").exists(),
        "interrupted after the end (figure too small for this machine?)"
    );
    assert_eq!(out.status.code(), Some(130));
    ok(&asperity(&args("cut"), d));
    ok(&asperity(&args("straight"), d));
    assert_eq!(
        std::fs::read(d.join("cut/fig5/fig5.csv")).unwrap(),
        std::fs::read(d.join("straight/fig5/fig5.csv")).unwrap()
    );
}

#[test]
fn no_command_shows_the_commands() {
    let dir = tempfile::tempdir().unwrap();
    for args in [&[][..], &["study"][..]] {
        let out = asperity(args, dir.path());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("Usage:") && err.contains("Commands:"), "{err}");
    }
}
