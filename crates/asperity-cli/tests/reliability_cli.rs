//! Issue 9: no input can hang, abort or slip through, and a study never reports another
//! study's numbers. Each test names the item of the issue it covers; each one failed on
//! the main branch before the fix.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::{files, ok, refused};

fn asperity(args: &[&str], dir: &Path) -> Output {
    asperity_env(args, dir, &[])
}

fn asperity_env(args: &[&str], dir: &Path, env: &[(&str, &str)]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .current_dir(dir)
        .envs(env.iter().copied())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // No command may hang: 60 s is far beyond any run below.
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("asperity {args:?} hung");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().unwrap()
}

/// A `.npy` file (version 1) with this header dict and data.
fn npy(dict: &str, data: &[u8]) -> Vec<u8> {
    let mut header = dict.to_string();
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    bytes.extend(data);
    bytes
}

fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(status.success());
}

/// Items 5, 6: a 128-byte file whose header claims a huge shape, and a header of nested
/// brackets, are refused at once by every reader (no SIGABRT, no hang).
#[test]
fn hostile_npy_headers_are_refused_by_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let huge = npy(
        "{'descr': '<f8', 'fortran_order': False, 'shape': (4000000000000,), }",
        &[],
    );
    assert_eq!(huge.len(), 128);
    std::fs::write(d.join("huge1.npy"), &huge).unwrap();
    let huge3 = npy(
        "{'descr': '<f8', 'fortran_order': False, 'shape': (100000, 100000, 1000), }",
        &[0; 64],
    );
    std::fs::write(d.join("huge3.npy"), &huge3).unwrap();
    let nested = format!(
        "{{'descr': {}'<f8'{}, 'fortran_order': False, 'shape': (1,), }}",
        "[".repeat(24),
        "]".repeat(24)
    );
    std::fs::write(d.join("nested.npy"), npy(&nested, &[0; 8])).unwrap();
    let before = files(d);
    let start = Instant::now();
    for (args, needle) in [
        (
            vec!["mdr", "--line", "huge1.npy", "--out", "o.csv"],
            "needs 32000000000000 bytes",
        ),
        // stats sizes its work from the header first: refused for memory or for length.
        (vec!["stats", "huge1.npy"], "huge1.npy"),
        (
            vec!["bem", "--surface", "huge3.npy", "--pressures", "0.01"],
            "needs",
        ),
        (vec!["stats", "nested.npy"], "plain type string"),
        (
            vec!["mdr", "--line", "nested.npy", "--out", "o.csv"],
            "plain type string",
        ),
        (
            vec!["bem", "--surface", "nested.npy", "--pressures", "0.01"],
            "plain type string",
        ),
    ] {
        refused(&asperity(&args, d), needle);
    }
    // Refused before any work (the 1e9-element arrays would take minutes); room for a
    // busy machine (issue 33 item 16).
    assert!(start.elapsed() < Duration::from_secs(120));
    assert_eq!(files(d), before, "nothing written");
    // mdr's input honours the memory guard: a real 8 MiB line under a 2 MiB cap.
    let line: Vec<u8> = (0..1 << 20)
        .flat_map(|i| (i as f64).to_le_bytes())
        .collect();
    let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (1048576,), }";
    std::fs::write(d.join("line.npy"), npy(dict, &line)).unwrap();
    let out = asperity_env(
        &["mdr", "--line", "line.npy", "--out", "o.csv"],
        d,
        &[("ASPERITY_MEMORY_LIMIT_MIB", "2")],
    );
    refused(&out, "ASPERITY_MEMORY_LIMIT_MIB");
}

/// Item 8: a FIFO as input, study file or sidecar, and a sidecar that is /dev/zero, are
/// refused at once (each used to hang or read gigabytes).
#[test]
fn special_files_are_refused_everywhere_input_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    mkfifo(&d.join("fifo.npy"));
    mkfifo(&d.join("fifo.toml"));
    ok(&asperity(
        &["surface", "--n", "16", "--hurst", "0.5", "--out", "s.npy"],
        d,
    ));
    ok(&asperity(
        &["line", "--n", "64", "--hurst", "0.5", "--out", "l.npy"],
        d,
    ));
    for (args, needle) in [
        (vec!["stats", "fifo.npy"], "not a regular file"),
        (
            vec!["bem", "--surface", "fifo.npy", "--pressures", "0.01"],
            "not a regular file",
        ),
        (
            vec!["mdr", "--line", "fifo.npy", "--out", "o.csv"],
            "not a regular file",
        ),
        (
            vec!["study", "file", "fifo.toml", "--out", "st"],
            "not a regular file",
        ),
    ] {
        refused(&asperity(&args, d), needle);
    }
    // Sidecars: a FIFO, then /dev/zero behind a link.
    std::fs::remove_file(d.join("s.npy.json")).unwrap();
    mkfifo(&d.join("s.npy.json"));
    std::fs::remove_file(d.join("l.npy.json")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", d.join("l.npy.json")).unwrap();
    refused(&asperity(&["stats", "s.npy"], d), "not a regular file");
    refused(
        &asperity(&["bem", "--surface", "s.npy", "--pressures", "0.01"], d),
        "s.npy.json",
    );
    refused(
        &asperity(&["mdr", "--line", "l.npy", "--out", "o.csv"], d),
        "not a regular file",
    );
    assert!(!d.join("st").exists() && !d.join("o.csv").exists());
}

/// Item 16: one sidecar reader with one set of rules; a corrupt sidecar is an error, not
/// L = 1, and stats refuses the sizes bem and mdr refuse.
#[test]
fn sidecars_follow_one_set_of_rules() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&asperity(
        &["surface", "--n", "16", "--hurst", "0.5", "--out", "s.npy"],
        d,
    ));
    ok(&asperity(
        &["line", "--n", "64", "--hurst", "0.5", "--out", "l.npy"],
        d,
    ));
    let cases = [
        ("{\"spec\": {\"size\": 2", "corrupt sidecar"),
        ("{\"spec\": {\"size\": -1}}", "spec.size = -1"),
        ("{\"spec\": {\"size\": 0}}", "spec.size = 0"),
    ];
    for (text, needle) in cases {
        std::fs::write(d.join("s.npy.json"), text).unwrap();
        std::fs::write(d.join("l.npy.json"), text).unwrap();
        refused(&asperity(&["stats", "s.npy"], d), needle);
        refused(&asperity(&["stats", "l.npy"], d), needle);
        let bem = ["bem", "--surface", "s.npy", "--pressures", "0.01"];
        refused(&asperity(&bem, d), needle);
        refused(
            &asperity(&["mdr", "--line", "l.npy", "--out", "o.csv"], d),
            needle,
        );
    }
    // A sidecar without a size is no hint (L = 1), as is no sidecar at all.
    std::fs::write(d.join("s.npy.json"), "{\"spec\": {}}").unwrap();
    let out = asperity(&["stats", "s.npy"], d);
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stdout).contains("size 1)"));
}

const STUDY: [&str; 14] = [
    "study",
    "alpha",
    "--method",
    "bem",
    "--n",
    "16",
    "--hurst",
    "0.5,1",
    "--samples",
    "3",
    "--quiet",
    "--checkpoint-every",
    "0",
    "--out",
];

fn study(extra: &[&str], out: &str, dir: &Path) -> Output {
    asperity(&[&STUDY[..], &[out], extra].concat(), dir)
}

fn checkpoint(dir: &Path, name: &str) -> PathBuf {
    dir.join(name).join("checkpoint/bem_n16_h+0.500000.json")
}

/// Item 1: a checkpoint copied into another study's folder (without its study.json), or
/// left where study.json was deleted, is refused naming what differs; a hand-edited one
/// is refused by its checksum; nothing is merged, and the exit status is 2.
#[test]
fn a_study_never_reports_another_studys_samples() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&study(&[], "a", d));
    let reference = std::fs::read(d.join("a/alpha.csv")).unwrap();
    for (extra, field) in [
        (&["--seed", "2"][..], "seed: stored 1, wanted 2"),
        (&["--rolloff", "2"][..], "rolloff: stored null, wanted 2"),
        (&["--levels", "20"][..], "levels: stored 48, wanted 20"),
        (
            &["--max-fraction", "0.5"][..],
            "window.max_fraction: stored",
        ),
    ] {
        let _ = std::fs::remove_dir_all(d.join("b"));
        std::fs::create_dir_all(d.join("b/checkpoint")).unwrap();
        std::fs::copy(checkpoint(d, "a"), checkpoint(d, "b")).unwrap();
        refused(&study(extra, "b", d), field);
        assert!(!d.join("b/alpha.csv").exists());
    }
    // study.json deleted, then the same folder rerun with another seed.
    std::fs::remove_file(d.join("a/study.json")).unwrap();
    refused(&study(&["--seed", "5"], "a", d), "seed: stored 1, wanted 5");
    // A hand edit that keeps the JSON valid.
    let text = std::fs::read_to_string(checkpoint(d, "a")).unwrap();
    let edited = text.replacen("\"stiffness\":", "\"stiffness\":1", 1);
    assert_ne!(edited, text);
    std::fs::write(checkpoint(d, "a"), &edited).unwrap();
    refused(&study(&[], "a", d), "does not match its checksum");
    std::fs::write(checkpoint(d, "a"), &text).unwrap();
    ok(&study(&[], "a", d));
    assert_eq!(std::fs::read(d.join("a/alpha.csv")).unwrap(), reference);
}

/// Item 2: outputs are committed together with their record; a folder left with only
/// some outputs (as the old order could leave it) still resumes with the same command.
#[test]
fn a_study_resumes_without_force_whatever_outputs_it_left() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&study(&[], "a", d));
    let csv = std::fs::read(d.join("a/alpha.csv")).unwrap();
    let svg = std::fs::read(d.join("a/alpha.svg")).unwrap();
    assert!(d.join("a/.asperity-outputs.json").exists());
    std::fs::remove_file(d.join("a/alpha.png")).unwrap();
    std::fs::remove_file(d.join("a/alpha.svg")).unwrap();
    ok(&study(&[], "a", d));
    assert_eq!(std::fs::read(d.join("a/alpha.csv")).unwrap(), csv);
    assert_eq!(std::fs::read(d.join("a/alpha.svg")).unwrap(), svg);
    // An output someone else put there is refused, naming it.
    std::fs::remove_dir_all(d.join("a")).unwrap();
    std::fs::create_dir(d.join("a")).unwrap();
    std::fs::write(d.join("a/alpha.svg"), "mine").unwrap();
    refused(&study(&[], "a", d), "alpha.svg");
    assert_eq!(std::fs::read(d.join("a/alpha.svg")).unwrap(), b"mine");
}

/// Item 4: a second process on a study folder is refused at once with the holder's PID;
/// once the holder is killed, the folder is free (no stale lock).
#[test]
fn a_study_folder_is_locked_while_a_run_works_in_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let long = [
        "study",
        "alpha",
        "--method",
        "bem",
        "--n",
        "64",
        "--hurst",
        "-1:3:0.5",
        "--samples",
        "50",
        "--quiet",
        "--out",
        "busy",
    ];
    let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(long)
        .current_dir(d)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !d.join("busy/study.json").exists() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(10));
    }
    for extra in [&[][..], &["--force", "--seed", "9"][..]] {
        let t = Instant::now();
        let out = asperity(&[&long[..], extra].concat(), d);
        refused(&out, &format!("PID {}", child.id()));
        // At once, not after the holder's long study; room for a busy machine.
        assert!(t.elapsed() < Duration::from_secs(60), "refused at once");
    }
    child.kill().unwrap(); // SIGKILL: no handler runs
    child.wait().unwrap();
    let out = asperity(
        &[
            "study",
            "alpha",
            "--method",
            "bem",
            "--n",
            "16",
            "--hurst",
            "0.5",
            "--samples",
            "1",
            "--quiet",
            "--out",
            "busy",
            "--force",
        ],
        d,
    );
    ok(&out);
}

/// Items 3 and 17: reproduce rewrites its own unchanged outputs, never one a user edited
/// (without --force), and report.md holds no wall time: every result file of a rerun is
/// byte-identical.
#[test]
fn reproduce_keeps_edited_files_and_reruns_identically() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&asperity(&["reproduce", "fig15.1", "--out", "R"], d));
    let folder = d.join("R/fig15.1");
    let snapshot = |skip: &[&str]| -> Vec<(PathBuf, Vec<u8>)> {
        files(&folder)
            .into_iter()
            .filter(|p| !skip.iter().any(|s| p.ends_with(s)))
            .map(|p| (p.clone(), std::fs::read(&p).unwrap()))
            .collect()
    };
    let first = snapshot(&["timings.json", ".asperity.lock"]);
    assert!(first.iter().any(|(p, _)| p.ends_with("report.md")));
    ok(&asperity(&["reproduce", "fig15.1", "--out", "R"], d));
    assert_eq!(snapshot(&["timings.json", ".asperity.lock"]), first);
    let report = folder.join("report.md");
    std::fs::write(&report, "my notes").unwrap();
    let err = refused(
        &asperity(&["reproduce", "fig15.1", "--out", "R"], d),
        "report.md",
    );
    assert!(err.contains("--force"), "{err}");
    assert_eq!(std::fs::read_to_string(&report).unwrap(), "my notes");
    ok(&asperity(
        &["reproduce", "fig15.1", "--out", "R", "--force"],
        d,
    ));
    assert_eq!(snapshot(&["timings.json", ".asperity.lock"]), first);
}

/// Item 14: a reproduce refused for memory leaves no folder and no reproduce.json.
#[test]
fn a_reproduce_refused_for_memory_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = asperity_env(
        &["reproduce", "fig1", "--quick", "--out", "R"],
        d,
        &[("ASPERITY_MEMORY_LIMIT_MIB", "1")],
    );
    refused(&out, "MiB");
    assert!(!d.join("R/fig1").exists());
}

/// Items 7, 12, 13, 14: sizes, ranges and tolerances refused up front, one line each,
/// before any folder is made; negative values parse as `-0.5` does.
#[test]
fn parameters_are_refused_up_front_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = [
        "study",
        "alpha",
        "--method",
        "mdr",
        "--n",
        "64",
        "--samples",
        "1",
        "--quiet",
    ];
    for (extra, needle) in [
        (&["--hurst", "-1:3:1e-9"][..], "gives 4e9 values"),
        (&["--hurst", "0:nan:0.1"][..], "not a finite number"),
        (
            &["--hurst", "0.5", "--levels", "1000000000000"][..],
            "force levels",
        ),
        (
            &["--hurst", "0.5", "--checkpoint-every", "1e300"][..],
            "--checkpoint-every",
        ),
        (&["--hurst", "0.5", "--rolloff", "32"][..], "Nyquist"),
        (
            &["--hurst", "0.5", "--max-fraction", "2"][..],
            "max_fraction = 2",
        ),
    ] {
        refused(
            &asperity(&[&base[..], extra, &["--out", "x"]].concat(), d),
            needle,
        );
        assert!(!d.join("x").exists(), "{extra:?} made the folder");
    }
    // Negative values in scientific notation and -inf reach the value checks.
    ok(&asperity(
        &[
            "surface", "--n", "16", "--hurst", "-1e-300", "--out", "n.npy",
        ],
        d,
    ));
    refused(
        &asperity(
            &["surface", "--n", "16", "--hurst", "-inf", "--out", "i.npy"],
            d,
        ),
        "H = -inf is outside",
    );
    ok(&asperity(
        &["surface", "--n", "16", "--hurst", "0.5", "--out", "s.npy"],
        d,
    ));
    let err = refused(
        &asperity(
            &[
                "bem",
                "--surface",
                "s.npy",
                "--pressures",
                "0.01",
                "--tol",
                "2",
            ],
            d,
        ),
        "--tol must be positive and at most 1e-2",
    );
    assert!(err.contains("got 2"), "{err}");
}

/// Item 11: no command writes a non-finite number or a degenerate surface.
#[test]
fn non_finite_results_are_refused_naming_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&asperity(
        &["line", "--n", "1024", "--hurst", "0.5", "--out", "l.npy"],
        d,
    ));
    let fractal = [
        "mdr", "--line", "l.npy", "--spring", "fractal", "--hurst", "1e-300", "--out", "m.csv",
    ];
    refused(&asperity(&fractal, d), "not a finite number");
    assert!(!d.join("m.csv").exists());
    refused(
        &asperity(
            &[
                "surface", "--n", "16", "--hurst", "0.5", "--size", "1e-308", "--out", "a.npy",
            ],
            d,
        ),
        "--size 1e-308",
    );
    refused(
        &asperity(
            &[
                "surface",
                "--n",
                "16",
                "--hurst",
                "0.5",
                "--rms-height",
                "1e-320",
                "--out",
                "b.npy",
            ],
            d,
        ),
        "--rms-height",
    );
    assert!(!d.join("a.npy").exists() && !d.join("b.npy").exists());
    let data: Vec<u8> = (0..64)
        .flat_map(|i| (if i % 2 == 0 { 1e308f64 } else { -1e308 }).to_le_bytes())
        .collect();
    let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (8, 8), }";
    std::fs::write(d.join("big.npy"), npy(dict, &data)).unwrap();
    refused(
        &asperity(&["stats", "big.npy"], d),
        // Heights of any size have finite rms statistics now (issue 33, item 5); the PSD,
        // in height², is what leaves the range of f64.
        "big.npy: invalid heights: their PSD (height² × length²) is beyond the range",
    );
}

/// Item 14: output names of 240–255 bytes work (the temporary name is shortened), longer
/// ones are refused before any work.
#[test]
fn long_output_names_work_or_are_refused_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let name = format!("{}.npy", "a".repeat(246)); // its sidecar: 255 bytes
    ok(&asperity(
        &["surface", "--n", "16", "--hurst", "0.5", "--out", &name],
        d,
    ));
    assert_eq!(files(d).len(), 2, "array and sidecar, no temporary file");
    let long = format!("{}.npy", "b".repeat(250));
    refused(
        &asperity(
            &["surface", "--n", "16", "--hurst", "0.5", "--out", &long],
            d,
        ),
        "at most 255",
    );
    assert_eq!(files(d).len(), 2);
}

/// Issue 33, item 11: under an address-space limit (`ulimit -v`) a run either works or is
/// refused with one line (status 2) — never a panic (rayon's pool unable to start its
/// threads: status 101) or an abort (an allocation the guard let through failing in a
/// thread's own malloc arena: SIGABRT). 36 runs: 6 limits × 1, 2 and 8 threads × 2 commands
/// (surface generation, a BEM sweep with stiffness); before the fix 8 of them failed.
#[test]
fn an_address_space_limit_gives_a_result_or_a_refusal_never_a_crash() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let exe = env!("CARGO_BIN_EXE_asperity");
    let prepare = std::process::Command::new(exe)
        .args([
            "surface",
            "--n",
            "256",
            "--hurst",
            "0.8",
            "--rms-slope",
            "1",
        ])
        .args(["--seed", "1", "--out", "s.npy"])
        .current_dir(d)
        .output()
        .unwrap();
    assert!(prepare.status.success());
    let commands = [
        "surface --n 512 --hurst 0.8 --out u.npy --force",
        "bem --surface s.npy --pressures 0.01,0.05",
    ];
    let (mut worked, mut refused) = (0, 0);
    for kib in [20_000, 40_000, 80_000, 120_000, 160_000, 320_000] {
        for threads in ["1", "2", "8"] {
            for command in commands {
                let out = std::process::Command::new("sh")
                    .arg("-c")
                    .arg(format!("ulimit -v {kib} && exec '{exe}' {command}"))
                    .env("RAYON_NUM_THREADS", threads)
                    .current_dir(d)
                    .output()
                    .expect("run sh");
                let err = String::from_utf8_lossy(&out.stderr);
                match out.status.code() {
                    Some(0) => worked += 1,
                    Some(2) => {
                        assert_eq!(err.trim_end().lines().count(), 1, "{kib} KiB: {err}");
                        refused += 1;
                    }
                    code => panic!("{command} at {kib} KiB, {threads} threads: {code:?}: {err}"),
                }
            }
        }
    }
    assert!(
        worked > 0 && refused > 0,
        "{worked} worked, {refused} refused"
    );
}
