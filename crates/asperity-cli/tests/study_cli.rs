//! Drives `asperity study` through the real binary: outputs, resume, bad input.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::{asperity, ok, refused};

const ALPHA: [&str; 12] = [
    "study",
    "alpha",
    "--method",
    "mdr",
    "--n",
    "1024",
    "--hurst",
    "0.5:1:0.5",
    "--samples",
    "12",
    "--quiet",
    "--out",
];

#[test]
fn alpha_study_writes_table_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    ok(&asperity(&[&ALPHA[..], &["a"]].concat(), dir.path()));
    let csv = std::fs::read_to_string(dir.path().join("a/alpha.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(lines
        .next()
        .unwrap()
        .starts_with("method,n,hurst,alpha,alpha_low,alpha_high,samples"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 2);
    assert!(rows[0].starts_with("mdr,1024,0.5,"));
    for ext in ["png", "svg"] {
        assert!(dir.path().join(format!("a/alpha.{ext}")).exists());
    }
    // Running the finished study again resumes (nothing to compute) and rewrites the
    // same outputs; once one is edited, it is refused without --force.
    let csv_path = dir.path().join("a/alpha.csv");
    ok(&asperity(&[&ALPHA[..], &["a"]].concat(), dir.path()));
    assert_eq!(std::fs::read_to_string(&csv_path).unwrap(), csv);
    std::fs::write(&csv_path, format!("{csv}# my note\n")).unwrap();
    refused(
        &asperity(&[&ALPHA[..], &["a"]].concat(), dir.path()),
        "was edited since",
    );
    assert!(std::fs::read_to_string(&csv_path)
        .unwrap()
        .ends_with("# my note\n"));
    ok(&asperity(
        &[&ALPHA[..], &["a", "--force"]].concat(),
        dir.path(),
    ));
    assert_eq!(std::fs::read_to_string(&csv_path).unwrap(), csv);
}

#[test]
fn truncated_checkpoint_resumes_to_identical_results() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&asperity(&[&ALPHA[..], &["s"]].concat(), d));
    let reference = std::fs::read(d.join("s/alpha.csv")).unwrap();
    // Simulate an interruption during the second task: the first task's result is read
    // back from its checkpoint, the second is computed again; outputs were not written.
    let mut checkpoints: Vec<_> = std::fs::read_dir(d.join("s/checkpoint"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    checkpoints.sort();
    let done: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&checkpoints[0]).unwrap()).unwrap();
    assert_eq!(done["content"]["state"], "done");
    std::fs::remove_file(&checkpoints[1]).unwrap();
    for ext in ["csv", "png", "svg"] {
        std::fs::remove_file(d.join(format!("s/alpha.{ext}"))).unwrap();
    }
    ok(&asperity(&[&ALPHA[..], &["s"]].concat(), d));
    assert_eq!(
        std::fs::read(d.join("s/alpha.csv")).unwrap(),
        reference,
        "bit for bit"
    );
}

#[test]
#[ignore = "slow tier: cargo test --release -- --ignored (.ci/run runs it)"]
fn killed_study_resumes_to_the_uninterrupted_result() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = |out: &'static str| {
        vec![
            "study",
            "curve",
            "--method",
            "mdr",
            "--n",
            "32768",
            "--hurst",
            "-1,0,0.5,1,2,3",
            "--samples",
            "300",
            "--quiet",
            "--checkpoint-every",
            "0",
            "--out",
            out,
        ]
    };
    let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args("killed"))
        .current_dir(d)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let checkpoints = d.join("killed/checkpoint");
    while start.elapsed() < Duration::from_secs(60) {
        // Stop as soon as a task has saved samples while still in progress.
        let partial = std::fs::read_dir(&checkpoints)
            .into_iter()
            .flatten()
            .any(|e| {
                let text = std::fs::read_to_string(e.unwrap().path()).unwrap_or_default();
                text.contains("\"in_progress\"")
            });
        if partial {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL: no chance to clean up
    child.wait().unwrap();
    assert!(
        !d.join("killed/curve.csv").exists(),
        "killed before the end (study too small for this machine?)"
    );
    ok(&asperity(&args("killed"), d));
    ok(&asperity(&args("straight"), d));
    assert_eq!(
        std::fs::read(d.join("killed/curve.csv")).unwrap(),
        std::fs::read(d.join("straight/curve.csv")).unwrap()
    );
}

#[test]
#[ignore = "slow tier: cargo test --release -- --ignored (.ci/run runs it)"]
fn terminated_study_removes_its_temporary_files_and_resumes() {
    // SIGTERM (like Ctrl-C) runs the handler: unfinished outputs' temporary files go, the
    // exit status is 130, and the checkpoints written so far let the study resume.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = [
        "study",
        "curve",
        "--method",
        "mdr",
        "--n",
        "32768",
        "--hurst",
        "0,0.5,1,2",
        "--samples",
        "300",
        "--quiet",
        "--checkpoint-every",
        "0",
        "--out",
        "termed",
    ];
    let child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .current_dir(d)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let checkpoints = d.join("termed/checkpoint");
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(60)
        && std::fs::read_dir(&checkpoints).map_or(true, |mut e| e.next().is_none())
    {
        std::thread::sleep(Duration::from_millis(5));
    }
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !d.join("termed/curve.csv").exists(),
        "terminated before the end (study too small for this machine?)"
    );
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    let mut stack = vec![d.join("termed")];
    while let Some(folder) = stack.pop() {
        for entry in std::fs::read_dir(folder).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy();
            assert!(!name.contains(".tmp"), "left {}", path.display());
            if path.is_dir() {
                stack.push(path);
            }
        }
    }
    ok(&asperity(&args, d));
    assert!(d.join("termed/curve.csv").exists());
}

#[test]
fn bad_studies_are_refused_and_lose_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = ["study", "alpha", "--method", "mdr", "--n", "256", "--quiet"];
    refused(
        &asperity(
            &[
                &base[..],
                &["--hurst", "1:0:0.1", "--samples", "3", "--out", "x"],
            ]
            .concat(),
            d,
        ),
        "empty range",
    );
    refused(
        &asperity(
            &[
                &base[..],
                &["--hurst", "0.5", "--samples", "0", "--out", "x"],
            ]
            .concat(),
            d,
        ),
        "samples",
    );
    refused(
        &asperity(
            &[
                &base[..],
                &["--hurst", "3.5", "--samples", "2", "--out", "x"],
            ]
            .concat(),
            d,
        ),
        "outside",
    );
    assert!(!d.join("x").exists(), "nothing written for invalid studies");
    ok(&asperity(
        &[
            &base[..],
            &["--hurst", "0.5", "--samples", "3", "--out", "y"],
        ]
        .concat(),
        d,
    ));
    let before = std::fs::read(d.join("y/study.json")).unwrap();
    std::fs::remove_file(d.join("y/alpha.csv")).unwrap();
    refused(
        &asperity(
            &[
                &base[..],
                &[
                    "--hurst",
                    "0.5",
                    "--samples",
                    "3",
                    "--seed",
                    "9",
                    "--out",
                    "y",
                ],
            ]
            .concat(),
            d,
        ),
        "another study",
    );
    assert_eq!(
        std::fs::read(d.join("y/study.json")).unwrap(),
        before,
        "the other study's checkpoint is kept"
    );
    ok(&asperity(
        &[
            &base[..],
            &[
                "--hurst",
                "0.5",
                "--samples",
                "3",
                "--seed",
                "9",
                "--out",
                "y",
                "--force",
            ],
        ]
        .concat(),
        d,
    ));
}

/// A negative count, a bad seed or an unknown method: refused by the front-end layer's rules
/// (asperity_app::study::request) in one line that names the flag, before any folder is
/// made (clap said "invalid digit found in string" before; Python words them alike,
/// python/tests/test_rules.py).
#[test]
fn negative_counts_and_unknown_methods_are_refused_by_the_study_request() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: [(&[&str], &str); 7] = [
        (&["--n", "64,-32"], "--n must be at least 1, got -32"),
        (&["--samples", "-1"], "--samples must be at least 1, got -1"),
        (&["--levels", "-3"], "--levels must be at least 1, got -3"),
        (
            &["--min-contacts", "-1"],
            "--min-contacts must be at least 1, got -1",
        ),
        (
            &["--seed", "-1"],
            "--seed must be a whole number from 0 to 18446744073709551615, got -1",
        ),
        (
            &["--method", "fem"],
            "--method must be mdr or bem, got \"fem\"",
        ),
        (
            &["--samples", "99999999999999999999"],
            "--samples is too large, got ",
        ),
    ];
    for (change, words) in cases {
        let mut args = vec![
            "study",
            "alpha",
            "--method",
            "mdr",
            "--n",
            "32",
            "--samples",
        ];
        args.extend(["2", "--hurst", "0.5", "--out", "x"]);
        for pair in change.chunks(2) {
            let at = args.iter().position(|a| *a == pair[0]).map(|i| i + 1);
            match at {
                Some(i) => args[i] = pair[1],
                None => args.extend(pair),
            }
        }
        let message = refused(&asperity(&args, d), words);
        assert!(
            message.lines().count() == 1 && message.contains(words),
            "{message}"
        );
        assert!(!d.join("x").exists(), "{change:?}: nothing written");
    }
}

#[test]
fn toml_study_file_runs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("s.toml"),
        "kind = \"curve\"\nmethod = \"bem\"\nn = [32]\nhurst = [0.5, 2.0]\nsamples = 2\nrolloff = 4\n",
    )
    .unwrap();
    ok(&asperity(
        &["study", "file", "s.toml", "--out", "t", "--quiet"],
        d,
    ));
    let csv = std::fs::read_to_string(d.join("t/curve.csv")).unwrap();
    assert!(csv.starts_with("method,n,hurst,force,stiffness,stiffness_low,stiffness_high,samples"));
    assert!(csv.lines().skip(1).all(|l| l.starts_with("bem,32,")));
    std::fs::write(
        d.join("bad.toml"),
        "kind = \"alpha\"\nmethod = \"mdr\"\nn = [64]\nhurst = \"0.5\"\nsampels = 3\n",
    )
    .unwrap();
    refused(
        &asperity(&["study", "file", "bad.toml", "--out", "u"], d),
        "bad.toml",
    );
}

#[test]
fn a_study_refused_for_memory_creates_nothing_and_the_folder_stays_free() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = |n: &'static str| {
        vec![
            "study",
            "alpha",
            "--method",
            "bem",
            "--n",
            n,
            "--hurst",
            "0.5",
            "--samples",
            "2",
            "--quiet",
            "--out",
            "D",
        ]
    };
    let out = asperity(&args("100000"), d);
    refused(&out, "100000x100000");
    assert!(String::from_utf8_lossy(&out.stderr).contains("MiB"));
    assert!(!d.join("D").exists(), "nothing created");
    // The largest N counts, wherever it is in the list.
    refused(&asperity(&args("32,100000"), d), "memory");
    assert!(!d.join("D").exists(), "nothing created");
    ok(&asperity(&args("32"), d));
    assert!(d.join("D/alpha.csv").exists());
}

#[test]
fn a_folder_whose_study_saved_no_sample_is_free() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = ["study", "alpha", "--method", "mdr", "--n", "256", "--quiet"];
    ok(&asperity(
        &[
            &base[..],
            &["--hurst", "0.5", "--samples", "3", "--out", "y"],
        ]
        .concat(),
        d,
    ));
    // As if that study had stopped before its first checkpoint (and before its outputs).
    std::fs::remove_dir_all(d.join("y/checkpoint")).unwrap();
    std::fs::create_dir(d.join("y/checkpoint")).unwrap();
    for ext in ["csv", "png", "svg"] {
        std::fs::remove_file(d.join(format!("y/alpha.{ext}"))).unwrap();
    }
    ok(&asperity(
        &[&base[..], &["--hurst", "1", "--samples", "4", "--out", "y"]].concat(),
        d,
    ));
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("y/study.json")).unwrap()).unwrap();
    assert_eq!(manifest["spec"]["samples"], 4);
    assert_eq!(manifest["normalisation"]["rms_height"], 1.0);
    assert!(d.join("y/alpha.csv").exists());
}

#[test]
fn hurst_values_sharing_a_checkpoint_name_or_repeated_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |command: &str, n: &str, hurst: &str| {
        asperity(
            &[
                "study",
                command,
                "--method",
                "mdr",
                "--n",
                n,
                "--hurst",
                hurst,
                "--samples",
                "2",
                "--quiet",
                "--out",
                "c",
            ],
            d,
        )
    };
    let out = run("curve", "512", "0.5000001,0.5000002");
    refused(&out, "0.5000001");
    assert!(String::from_utf8_lossy(&out.stderr).contains("0.5000002"));
    refused(
        &run("alpha", "512", "0.5,0:1:0.5"),
        "H = 0.5 is given twice",
    );
    refused(
        &run("alpha", "512,256,512", "0.5"),
        "N = 512 is given twice",
    );
    assert!(!d.join("c").exists());
}

#[test]
fn curve_accepts_hurst_ranges() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&asperity(
        &[
            "study",
            "curve",
            "--method",
            "mdr",
            "--n",
            "256",
            "--hurst",
            "-1:3:1",
            "--samples",
            "3",
            "--quiet",
            "--out",
            "r",
        ],
        d,
    ));
    let csv = std::fs::read_to_string(d.join("r/curve.csv")).unwrap();
    let mut hursts: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap())
        .collect();
    hursts.dedup();
    assert_eq!(hursts, ["-1.0", "0.0", "1.0", "2.0", "3.0"]);
    for ext in ["png", "svg"] {
        assert!(d.join(format!("r/curve.{ext}")).exists());
    }
}

#[test]
fn help_explains_intervals_and_scales() {
    let dir = tempfile::tempdir().unwrap();
    for command in ["alpha", "curve"] {
        let out = asperity(&["study", command, "--help"], dir.path());
        ok(&out);
        let help = String::from_utf8_lossy(&out.stdout);
        for needle in [
            "unit rms height",
            "unit rms slope",
            "free boundaries",
            "A:B:STEP",
        ] {
            assert!(help.contains(needle), "{command}: no '{needle}' in {help}");
        }
    }
    let out = asperity(&["study", "curve", "--help"], dir.path());
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(
        help.contains("95 % confidence interval of that mean"),
        "{help}"
    );
    let out = asperity(&["study", "file", "--help"], dir.path());
    let help = String::from_utf8_lossy(&out.stdout);
    for key in [
        "kind",
        "method",
        "rolloff",
        "min_contacts",
        "max_fraction",
        "levels",
    ] {
        assert!(help.contains(key), "{key}");
    }
}

#[test]
fn the_example_study_file_runs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/sweep.toml");
    ok(&asperity(
        &[
            "study",
            "file",
            example.to_str().unwrap(),
            "--out",
            "sweep",
            "--quiet",
        ],
        d,
    ));
    let csv = std::fs::read_to_string(d.join("sweep/alpha.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 2 * 17, "2 sizes x 17 H");
    // Single values for n and hurst; errors name line, column and key.
    std::fs::write(
        d.join("one.toml"),
        "kind = \"curve\"\nmethod = \"mdr\"\nn = 256\nhurst = 0.5\nsamples = 2\n",
    )
    .unwrap();
    ok(&asperity(
        &["study", "file", "one.toml", "--out", "one", "--quiet"],
        d,
    ));
    std::fs::write(
        d.join("bad.toml"),
        "kind = \"curve\"\nmethod = \"mdr\"\nn = 256\nhurst = \"x\"\nsamples = 2\n",
    )
    .unwrap();
    refused(
        &asperity(&["study", "file", "bad.toml", "--out", "bad"], d),
        "bad.toml, line 4, column 9 (key `hurst`)",
    );
}

#[test]
fn curve_study_takes_a_list_of_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "study",
        "curve",
        "--method",
        "mdr",
        "--n",
        "64,128",
        "--hurst",
        "0.5",
        "--samples",
        "2",
        "--quiet",
        "--out",
        "c",
    ];
    ok(&asperity(&args, dir.path()));
    let csv = std::fs::read_to_string(dir.path().join("c/curve.csv")).unwrap();
    for n in ["64", "128"] {
        let prefix = format!("mdr,{n},0.5,");
        assert!(csv.lines().any(|l| l.starts_with(&prefix)), "{n}: {csv}");
    }
}

#[test]
fn a_finished_study_grows_by_another_n_or_h_reusing_its_checkpoints() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let study = |n: &str, hurst: &str| {
        let args = [
            "study",
            "alpha",
            "--method",
            "mdr",
            "--n",
            n,
            "--hurst",
            hurst,
            "--samples",
            "4",
            "--quiet",
            "--out",
            "g",
        ];
        asperity(&args, d)
    };
    ok(&study("256", "0.5"));
    let checkpoint = d.join("g/checkpoint/mdr_n256_h+0.500000.json");
    let before = std::fs::read(&checkpoint).unwrap();
    let modified = || std::fs::metadata(&checkpoint).unwrap().modified().unwrap();
    let stamp = modified();
    ok(&study("256,512", "0.5,1"));
    assert_eq!(
        modified(),
        stamp,
        "the finished task is read back, not rewritten"
    );
    assert_eq!(std::fs::read(&checkpoint).unwrap(), before);
    let csv = std::fs::read_to_string(d.join("g/alpha.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "header and 4 tasks: {csv}");
}

/// Item 7 of issue 33: a run into a finished study's folder that would leave out one of
/// its (N, H) or take fewer samples is refused (its results would be replaced by fewer),
/// every output untouched; --force runs it and keeps the left-out task's checkpoint.
#[test]
fn a_narrower_run_into_a_finished_study_is_refused_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let study = |n: &str, samples: &str, extra: &[&str]| {
        let args = [
            &[
                "study",
                "alpha",
                "--method",
                "mdr",
                "--n",
                n,
                "--hurst",
                "0.5",
                "--samples",
                samples,
                "--quiet",
                "--out",
                "g",
            ][..],
            extra,
        ]
        .concat();
        asperity(&args, d)
    };
    ok(&study("256,512", "4", &[]));
    let outputs = ["alpha.csv", "alpha.png", "alpha.svg", "study.json"];
    let read = || outputs.map(|f| std::fs::read(d.join("g").join(f)).unwrap());
    let before = read();
    refused(&study("256", "4", &[]), "N = [512]");
    refused(&study("256,512", "3", &[]), "samples (stored 4, wanted 3)");
    assert_eq!(read(), before, "nothing replaced");
    // Growing is allowed: every stored task is in the run.
    ok(&study("256,512,1024", "4", &[]));
    let csv = std::fs::read_to_string(d.join("g/alpha.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");
    ok(&study("256", "4", &["--force"]));
    assert!(d.join("g/checkpoint/mdr_n512_h+0.500000.json").exists());
}

/// Item 8 of issue 33: Ctrl-C before the first checkpoint interval keeps the samples
/// finished so far (the study stops, checkpoints them, exits with 130) and the rerun
/// resumes from them.
#[test]
fn ctrl_c_checkpoints_the_finished_samples() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "study",
        "alpha",
        "--method",
        "mdr",
        "--n",
        "65536",
        "--hurst",
        "0.5",
        "--samples",
        "100000",
        "--checkpoint-every",
        "100000",
        "--quiet",
        "--out",
        "g",
    ];
    let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .current_dir(dir.path())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let checkpoint = dir.path().join("g/checkpoint/mdr_n65536_h+0.500000.json");
    let start = Instant::now();
    // Samples take milliseconds: a few seconds after the folder is open, many are done.
    while !dir.path().join("g/study.json").exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_secs(3));
    assert!(child.try_wait().unwrap().is_none(), "still running");
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&checkpoint).expect("a checkpoint was written");
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    let held = value["content"]["samples"].as_array().map_or(0, Vec::len);
    assert!(held > 0, "no sample kept: {text:.200}");
}

/// The steepest log–log slope over one decade of force of `curve.csv`'s mean curve for
/// one H, from 8 contacts on: a least-squares fit of ln k on ln F over every run of rows
/// spanning at least a decade, written here independently of the library.
fn steepest_slope_of_curve_csv(csv: &str, hurst: &str, points_total: f64) -> f64 {
    let rows: Vec<(f64, f64)> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|f| f[2] == hurst && f[8].parse::<f64>().unwrap() >= 8.0 / points_total)
        .map(|f| (f[3].parse().unwrap(), f[4].parse().unwrap()))
        .collect();
    let mut best = f64::NEG_INFINITY;
    for first in 0..rows.len() {
        let Some(last) = (first + 2..rows.len()).find(|&j| rows[j].0 >= 10.0 * rows[first].0)
        else {
            break;
        };
        let pts: Vec<(f64, f64)> = rows[first..=last]
            .iter()
            .map(|&(f, k)| (f.ln(), k.ln()))
            .collect();
        let m = pts.len() as f64;
        let (mx, my) = pts
            .iter()
            .fold((0.0, 0.0), |(a, b), p| (a + p.0 / m, b + p.1 / m));
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        best = best.max(sxy / sxx);
    }
    best
}

#[test]
fn compare_writes_slopes_with_intervals_and_verdicts_and_refuses_unfinished_studies() {
    let dir = tempfile::tempdir().unwrap();
    ok(&asperity(
        &[
            "study",
            "curve",
            "--method",
            "bem",
            "--n",
            "16",
            "--hurst",
            "0,2",
            "--rolloff",
            "4",
            "--samples",
            "3",
            "--seed",
            "1",
            "--quiet",
            "--out",
            "s",
        ],
        dir.path(),
    ));
    ok(&asperity(&["study", "compare", "s"], dir.path()));
    let s = dir.path().join("s");
    let curve = std::fs::read_to_string(s.join("curve.csv")).unwrap();
    let csv = std::fs::read_to_string(s.join("comparison.csv")).unwrap();
    let report = std::fs::read_to_string(s.join("report.md")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 2, "{csv}");
    for (row, hurst) in rows.iter().zip(["0.0", "2.0"]) {
        assert_eq!((row[0], row[3], row[7]), ("bem", "steepest_slope", "1.0"));
        let num = |i: usize| row[i].parse::<f64>().unwrap();
        let expected = steepest_slope_of_curve_csv(&curve, hurst, 256.0);
        assert!((num(4) - expected).abs() < 1e-9, "{} vs {expected}", num(4));
        // A bootstrap interval over 3 samples: not empty, and around the slope.
        assert!(num(5) < num(6) && num(5) <= num(4) + 0.05 && num(6) >= num(4) - 0.05);
        let line = format!("| bem | 16 | {} | steepest_slope | {:.3} |", num(2), num(4));
        assert!(report.contains(&line), "{line} not in:\n{report}");
    }
    assert!(report.contains("asperity study compare"), "{report}");
    refused(&asperity(&["study", "compare", "s"], dir.path()), "exists");
    // One more sample asked for: the tasks are no longer finished.
    let spec = std::fs::read_to_string(s.join("study.json")).unwrap();
    std::fs::write(
        s.join("study.json"),
        spec.replace("\"samples\": 3", "\"samples\": 4"),
    )
    .unwrap();
    refused(
        &asperity(&["study", "compare", "s", "--force"], dir.path()),
        "not finished",
    );
}

#[test]
fn a_bem_study_reports_progress_per_solved_load() {
    // 2 H × 3 samples × 24 loads: the log (stderr is no terminal here) counts loads.
    let dir = tempfile::tempdir().unwrap();
    let args: Vec<&str> = "study alpha --method bem --n 16 --hurst 0.5,1 --samples 3 --out p"
        .split(' ')
        .collect();
    let out = asperity(&args, dir.path());
    ok(&out);
    let err = common::stderr(&out);
    assert!(err.contains("bem study (loads): 144/144 ("), "{err}");
}

#[test]
fn an_alpha_study_ends_its_bem_sweeps_past_the_windows_and_fits_as_the_whole_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args: Vec<&str> = "study alpha --method bem --n 64 --hurst -1,1 --samples 4 --out"
        .split(' ')
        .collect();
    let ended = asperity(&[&args[..], &["a"]].concat(), d);
    ok(&ended);
    // Progress still counts every load of every sample.
    let err = common::stderr(&ended);
    assert!(err.contains("bem study (loads): 192/192 ("), "{err}");
    ok(&asperity(
        &[&args[..], &["f", "--full-sweep", "--quiet"]].concat(),
        d,
    ));
    let read = |p: &str| std::fs::read_to_string(d.join(p)).unwrap();
    assert_eq!(read("a/alpha.csv"), read("f/alpha.csv"));
    // 4 × the 2 % of the window table: in the spec, so in every checkpoint's identity.
    assert!(read("a/study.json").contains("\"sweep_end\": 0.08"));
    assert!(!read("f/study.json").contains("sweep_end"));
    // The whole sweep is another study: refused in the folder, which is left as it was.
    let before = read("a/alpha.csv");
    refused(
        &asperity(&[&args[..], &["a", "--full-sweep"]].concat(), d),
        "sweep_end",
    );
    assert_eq!(read("a/alpha.csv"), before);
    // The other way round, a folder holding the whole sweep's samples (as every α study's
    // did before the sweeps ended) is resumed as that study, more samples computed too.
    let whole_spec = read("f/study.json");
    let grown: Vec<&str> = [&args[..8], &["--samples", "5", "--out", "f"]].concat();
    let resumed = asperity(&grown, d);
    ok(&resumed);
    assert!(
        common::stderr(&resumed).contains("resuming its study, which solves every load"),
        "{}",
        common::stderr(&resumed)
    );
    assert_eq!(
        read("f/study.json"),
        whole_spec.replace("\"samples\": 4", "\"samples\": 5")
    );
    ok(&asperity(
        &[&args[..8], &["--samples", "5", "--out", "g", "--quiet"]].concat(),
        d,
    ));
    assert_eq!(read("f/alpha.csv"), read("g/alpha.csv"));
    // With a roll-off, `study compare` reads the steepest slope of whole mean curves: an
    // ended sweep is refused there (its folder left as it was), a full one compared.
    let rolled: Vec<&str> = "study alpha --method bem --n 32 --hurst 1 --samples 2 --rolloff 4 \
                             --quiet --out"
        .split_whitespace()
        .collect();
    ok(&asperity(&[&rolled[..], &["r"]].concat(), d));
    refused(
        &asperity(&["study", "compare", "r"], d),
        "stopped loading past 25 % contact",
    );
    assert!(!d.join("r/comparison.csv").exists());
    ok(&asperity(
        &[&rolled[..], &["rf", "--full-sweep"]].concat(),
        d,
    ));
    ok(&asperity(&["study", "compare", "rf"], d));
    // --force discards it instead, for the ended sweep.
    ok(&asperity(
        &[&args[..], &["f", "--force", "--quiet"]].concat(),
        d,
    ));
    assert!(read("f/study.json").contains("\"sweep_end\": 0.08"));
    // A curve study solves every load: the key is refused there.
    std::fs::write(
        d.join("c.toml"),
        "kind = \"curve\"\nmethod = \"bem\"\nn = 32\nhurst = 0.5\nsamples = 2\nfull_sweep = true\n",
    )
    .unwrap();
    refused(
        &asperity(&["study", "file", "c.toml", "--out", "c"], d),
        "full_sweep applies to alpha studies only",
    );
    assert!(!d.join("c").exists());
}

/// `study curve --poisson --resistivity`: the tangential ratio at every force level, with
/// its interval, at least Mindlin's `2(1−ν)/(2−ν)` (an exact bound on any contact set,
/// docs/tangential.md) and within 1 % of it; the electrical conductance and its interval
/// are the stiffness's times `2/(E*(ρ₁+ρ₂))` (E* = 1); the normal columns are those of the
/// study without them; the figures of k_t/k_n and C(F) are written beside `curve.png`.
/// Bad values, or `--poisson` with MDR, are refused with one line, creating nothing.
#[test]
fn curve_study_adds_the_tangential_ratio_and_the_conductance() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = [
        "study",
        "curve",
        "--method",
        "bem",
        "--n",
        "32",
        "--hurst",
        "0.5",
        "--rolloff",
        "4",
        "--samples",
        "3",
        "--levels",
        "5",
        "--quiet",
        "--out",
    ];
    let with = |extra: &[&str]| asperity(&[&base[..], extra].concat(), d);
    ok(&with(&["t", "--poisson", "0.3", "--resistivity", "1,3"]));
    ok(&with(&["plain"]));
    let read = |folder: &str| {
        let csv = std::fs::read_to_string(d.join(folder).join("curve.csv")).unwrap();
        let mut lines = csv.lines();
        let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        let rows: Vec<Vec<String>> = lines
            .map(|l| l.split(',').map(String::from).collect())
            .collect();
        (header, rows)
    };
    let (header, rows) = read("t");
    let (plain_header, plain_rows) = read("plain");
    assert_eq!(
        header[plain_header.len()..],
        [
            "tangential_ratio",
            "tangential_ratio_low",
            "tangential_ratio_high",
            "electrical_conductance",
            "electrical_conductance_low",
            "electrical_conductance_high"
        ]
    );
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mindlin = 2.0 * 0.7 / 1.7;
    assert_eq!(rows.len(), 5);
    for (row, plain) in rows.iter().zip(&plain_rows) {
        assert_eq!(row[..plain.len()], plain[..]);
        let at = |name: &str| row[col(name)].parse::<f64>().unwrap();
        let ratio = at("tangential_ratio");
        assert!(
            ratio >= mindlin * (1.0 - 1e-9) && ratio < mindlin * 1.01,
            "{ratio}"
        );
        assert!(at("tangential_ratio_low") <= ratio && ratio <= at("tangential_ratio_high"));
        for (c, k) in [("", ""), ("_low", "_low"), ("_high", "_high")] {
            let conductance = at(&format!("electrical_conductance{c}"));
            let stiffness = at(&format!("stiffness{k}"));
            assert!((conductance / (stiffness * 2.0 / 4.0) - 1.0).abs() < 1e-15);
        }
    }
    assert!(d.join("t/tangential.png").is_file() && d.join("t/tangential.svg").is_file());
    assert!(!d.join("plain/tangential.png").exists());
    for (extra, needle) in [
        (vec!["--poisson", "0.7"], "--poisson must be in [0, 0.5]"),
        (vec!["--resistivity", "1"], "give two values"),
        (
            vec!["--thermal-conductivity", "1,-2"],
            "positive and finite",
        ),
    ] {
        let out = with(&[&["bad"], &extra[..]].concat());
        refused(&out, needle);
        assert!(!d.join("bad").exists());
    }
    let mdr = [
        "study",
        "curve",
        "--method",
        "mdr",
        "--n",
        "64",
        "--hurst",
        "0.5",
        "--samples",
        "2",
        "--quiet",
        "--poisson",
        "0.3",
        "--out",
        "mdr",
    ];
    // In the CLI's words (issue 37: it said the library's "invalid poisson: ...").
    refused(
        &asperity(&mdr, d),
        "error: --poisson applies to BEM studies only (--method bem): an MDR line has no \
         tangential kernel",
    );
    assert!(!d.join("mdr").exists());
}

/// Issue 33: `--out FILE/x` with FILE a regular file said "FILE/x/checkpoint: Not a
/// directory (os error 20)"; now one line in asperity's words naming FILE, exit 2, and
/// FILE untouched (both study commands, the folder itself a file too).
#[test]
fn an_output_folder_under_a_file_is_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("FILE"), "kept").unwrap();
    for command in ["alpha", "curve"] {
        for out in ["FILE/x", "FILE/x/y"] {
            let mut args = ALPHA.to_vec();
            args[1] = command;
            args.push(out);
            let err = refused(&asperity(&args, dir.path()), "FILE is a file, not a folder");
            assert!(err.contains(&format!("{out}: cannot be a folder")), "{err}");
            assert!(!err.contains("os error"), "{err}");
        }
        let mut args = ALPHA.to_vec();
        args[1] = command;
        args.push("FILE");
        let err = refused(
            &asperity(&args, dir.path()),
            "FILE: exists and is not a folder",
        );
        assert!(!err.contains("os error"), "{err}");
    }
    assert_eq!(
        std::fs::read_to_string(dir.path().join("FILE")).unwrap(),
        "kept"
    );
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1, "{names:?}");
}
