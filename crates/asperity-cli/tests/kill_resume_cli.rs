//! Issue 9, "how to prove it": studies and `reproduce` killed at random points (SIGKILL,
//! SIGINT, SIGTERM) resume with the same command, without `--force`, to results that are
//! byte-identical to an uninterrupted run.
//!
//! Kill points are drawn from a fixed seed (splitmix64), as fractions of the measured
//! duration of the uninterrupted run, so every run of the test tries the same points on a
//! given machine. Each test prints how many kills it tried and how many landed before the
//! run ended.
//!
//! Both are in the slow tier (minutes): `cargo test --release -- --ignored`, which `.ci/run`
//! and the README's test command run after the fast tier.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::ok;

fn splitmix64(x: &mut u64) -> u64 {
    *x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *x;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// `count` fractions in (0.05, 0.95), from `seed`.
fn kill_fractions(seed: u64, count: usize) -> Vec<f64> {
    let mut state = seed;
    (0..count)
        .map(|_| 0.05 + 0.9 * (splitmix64(&mut state) >> 11) as f64 / (1u64 << 53) as f64)
        .collect()
}

const SIGNALS: [&str; 3] = ["KILL", "INT", "TERM"];

fn run(args: &[&str], dir: &Path) -> Duration {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    ok(&out);
    start.elapsed()
}

/// Starts `args`, sends `signal` after `delay`; whether it was still running then.
fn kill_after(args: &[&str], dir: &Path, delay: Duration, signal: &str) -> bool {
    let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while start.elapsed() < delay {
        if child.try_wait().unwrap().is_some() {
            return false;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let sent = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .unwrap();
    let status = child.wait().unwrap();
    sent.success() && !status.success()
}

/// Every result file under `dir` (relative path → bytes): all but the lock (it holds a
/// PID), the wall times, and temporary files a SIGKILL can leave (hidden `.tmp` files,
/// which no later run reads).
fn results(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    common::files_under(dir, |name| {
        name == ".asperity.lock" || name == "timings.json" || name.contains(".tmp")
    })
}

/// A small BEM study: for each kill point a fresh folder is killed once and resumed.
#[test]
#[ignore = "slow tier: cargo test --release -- --ignored (.ci/run runs it)"]
fn a_bem_study_killed_anywhere_resumes_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = |out: &str| -> Vec<String> {
        [
            "study",
            "alpha",
            "--method",
            "bem",
            "--n",
            "16",
            "--hurst",
            "0:2:0.5",
            "--samples",
            "12",
            "--checkpoint-every",
            "0",
            "--quiet",
            "--out",
            out,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let refs = |v: &[String]| -> Vec<String> { v.to_vec() };
    let straight = args("straight");
    let straight: Vec<&str> = straight.iter().map(String::as_str).collect();
    let full = run(&straight, d);
    let reference = results(&d.join("straight"));
    let fractions = kill_fractions(9, 12);
    let mut landed = 0;
    for (i, f) in fractions.iter().enumerate() {
        let name = format!("cut{i}");
        let owned = refs(&args(&name));
        let cut: Vec<&str> = owned.iter().map(String::as_str).collect();
        let signal = SIGNALS[i % SIGNALS.len()];
        if kill_after(&cut, d, full.mul_f64(*f), signal) {
            landed += 1;
        }
        run(&cut, d);
        assert_eq!(
            results(&d.join(&name)),
            reference,
            "kill {i} (SIG{signal} at {:.0} % of the run) resumed to other bytes",
            100.0 * f
        );
    }
    eprintln!(
        "bem study: {} kills tried, {landed} landed before the end, 0 failures",
        fractions.len()
    );
}

/// `reproduce fig1 --quick`, killed three times in a row at random points (each resume
/// is itself interrupted), then finished: the same bytes as one uninterrupted run.
#[test]
#[ignore = "slow tier: cargo test --release -- --ignored (.ci/run runs it)"]
fn reproduce_fig1_killed_repeatedly_resumes_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = |out: &'static str| ["reproduce", "fig1", "--quick", "--out", out];
    let full = run(&args("straight"), d);
    let reference = results(&d.join("straight/fig1"));
    let fractions = kill_fractions(15, 3);
    let mut landed = 0;
    for (i, f) in fractions.iter().enumerate() {
        // Each piece runs a fraction of a third of the run, so the kills spread over it.
        let delay = full.mul_f64(f / 3.0);
        if kill_after(&args("cut"), d, delay, SIGNALS[i % SIGNALS.len()]) {
            landed += 1;
        }
    }
    run(&args("cut"), d);
    assert_eq!(results(&d.join("cut/fig1")), reference);
    eprintln!(
        "reproduce fig1 --quick: {} kills tried, {landed} landed before the end, 0 failures",
        fractions.len()
    );
}
