//! `asperity bem` driven as a user would: through the real binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use ndarray::Array2;
use ndarray_npy::{read_npy, write_npy};

fn asperity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A 64² rough surface made by `asperity surface`.
fn surface(dir: &Path) -> PathBuf {
    let path = dir.join("s.npy");
    let out = asperity(&[
        "surface",
        "--n",
        "64",
        "--hurst",
        "0.8",
        "--rolloff",
        "4",
        "--rms-slope",
        "0.5",
        "--seed",
        "3",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    path
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap()
}

#[test]
fn pressures_with_fields_write_the_documented_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let csv = dir.path().join("out.csv");
    let fields = dir.path().join("fields");
    let out = asperity(&[
        "bem",
        "--surface",
        s.to_str().unwrap(),
        "--pressures",
        "0.01,0.03",
        "--out",
        csv.to_str().unwrap(),
        "--fields",
        fields.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (header, rows) = read_csv(&csv);
    assert_eq!(
        header,
        [
            "force",
            "mean_pressure",
            "indentation",
            "area_fraction",
            "stiffness",
            "iterations",
            "residual"
        ]
    );
    assert_eq!(rows.len(), 2);
    for (k, row) in rows.iter().enumerate() {
        let pressure: Array2<f64> = read_npy(fields.join(format!("pressure_{k}.npy"))).unwrap();
        let gap: Array2<f64> = read_npy(fields.join(format!("gap_{k}.npy"))).unwrap();
        assert_eq!(pressure.dim(), (64, 64));
        assert_eq!(gap.dim(), (64, 64));
        // The fields agree with the table: mean pressure, contact fraction, complementarity.
        let mean = pressure.mean().unwrap();
        assert!((mean / row[column(&header, "mean_pressure")] - 1.0).abs() < 1e-12);
        let in_contact = pressure.iter().filter(|&&p| p > 0.0).count() as f64 / 4096.0;
        assert_eq!(in_contact, row[column(&header, "area_fraction")]);
        assert!(pressure
            .iter()
            .zip(&gap)
            .all(|(&p, &g)| p >= 0.0 && g >= 0.0 && p * g == 0.0));
        assert!(row[column(&header, "residual")] < 1e-8);
        assert!(row[column(&header, "stiffness")] > 0.0);
    }
    // Size 1 (from the sidecar): force = mean pressure.
    assert_eq!(rows[0][0], rows[0][1]);
    assert!(rows[1][column(&header, "stiffness")] > rows[0][column(&header, "stiffness")]);
}

#[test]
fn nloads_are_log_spaced_and_monotonic_and_forces_agree_with_pressures() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let csv = dir.path().join("curve.csv");
    let out = asperity(&[
        "bem",
        "--surface",
        s.to_str().unwrap(),
        "--nloads",
        "3",
        "--pmin",
        "1e-3",
        "--pmax",
        "1e-1",
        "--size",
        "2",
        "--out",
        csv.to_str().unwrap(),
        "--timing",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (header, rows) = read_csv(&csv);
    assert!(header.contains(&"solve_seconds".to_string()));
    let p: Vec<f64> = rows.iter().map(|r| r[1]).collect();
    for (got, want) in p.iter().zip([1e-3, 1e-2, 1e-1]) {
        assert!((got / want - 1.0).abs() < 1e-12);
    }
    for w in rows.windows(2) {
        assert!(w[1][2] > w[0][2], "indentation grows");
        assert!(w[1][3] > w[0][3], "area grows");
        assert!(w[1][4] > w[0][4], "stiffness grows");
    }
    // L = 2: force = 4 p; the same state by --forces.
    assert!((rows[1][0] / (4.0 * rows[1][1]) - 1.0).abs() < 1e-12);
    let csv2 = dir.path().join("forces.csv");
    let force = format!("{}", rows[1][0]);
    let out = asperity(&[
        "bem",
        "--surface",
        s.to_str().unwrap(),
        "--forces",
        &force,
        "--size",
        "2",
        "--out",
        csv2.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (_, again) = read_csv(&csv2);
    assert!((again[0][2] / rows[1][2] - 1.0).abs() < 1e-6);
}

#[test]
fn stdout_table_without_out_and_indentation_control() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let out = asperity(&[
        "bem",
        "--surface",
        s.to_str().unwrap(),
        "--indentations",
        "0,0.01",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    let mut lines = text.lines();
    assert!(lines.next().unwrap().contains("area_fraction"));
    assert_eq!(lines.count(), 2);
}

#[test]
fn existing_outputs_are_kept_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let csv = dir.path().join("out.csv");
    std::fs::write(&csv, "precious").unwrap();
    let args = [
        "bem",
        "--surface",
        s.to_str().unwrap(),
        "--pressures",
        "0.01",
        "--out",
        csv.to_str().unwrap(),
    ];
    let out = asperity(&args);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--force"), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "precious");
    let mut forced = args.to_vec();
    forced.push("--force");
    assert!(asperity(&forced).status.success());
    assert!(std::fs::read_to_string(&csv).unwrap().starts_with("force,"));
}

#[test]
fn bad_input_is_one_line_exit_2_and_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let mut nan: Array2<f64> = read_npy(&s).unwrap();
    nan[[5, 7]] = f64::NAN;
    let nan_path = dir.path().join("nan.npy");
    write_npy(&nan_path, &nan).unwrap();
    let csv = dir.path().join("out.csv");
    let fields = dir.path().join("fields");
    let s = s.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "--surface",
                nan_path.to_str().unwrap(),
                "--pressures",
                "0.01",
            ],
            "non-finite",
        ),
        (vec!["--surface", s, "--pressures", "0.01,-0.02"], "-0.02"),
        (
            vec!["--surface", s, "--pressures", "0.01", "--tol", "0"],
            "--tol",
        ),
        (
            vec!["--surface", s, "--pressures", "0.01", "--tol=-1e-6"],
            "--tol",
        ),
        (
            vec!["--surface", s, "--pressures", "0.01,1e4"],
            "full contact",
        ),
        (
            vec![
                "--surface",
                s,
                "--boundary",
                "periodic",
                "--pressures",
                "1e4",
            ],
            "full contact",
        ),
        (
            vec![
                "--surface",
                s,
                "--boundary",
                "periodic",
                "--indentations",
                "0.1",
            ],
            "free",
        ),
        (
            vec![
                "--surface",
                s,
                "--nloads",
                "3",
                "--pmin",
                "0.1",
                "--pmax",
                "0.01",
            ],
            "--pmax",
        ),
        (
            vec!["--surface", s, "--pressures", "0.01", "--max-iter", "2"],
            "no convergence",
        ),
        (
            vec!["--surface", "missing.npy", "--pressures", "0.01"],
            "missing.npy",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = vec!["bem"];
        args.extend(&extra);
        args.extend([
            "--out",
            csv.to_str().unwrap(),
            "--fields",
            fields.to_str().unwrap(),
        ]);
        let out = asperity(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(expected), "{extra:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{extra:?}: {err}");
        assert!(!csv.exists(), "{extra:?} wrote the CSV");
        assert!(!fields.exists(), "{extra:?} wrote fields");
    }
    // A missing load flag is a usage error (clap: exit 2).
    let out = asperity(&["bem", "--surface", s]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn help_has_examples() {
    let out = asperity(&["bem", "--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Examples:") && text.contains("--nloads") && text.contains("--fields"));
}
