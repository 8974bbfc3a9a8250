//! `asperity bem` driven as a user would: through the real binary.

use std::path::{Path, PathBuf};

use ndarray::Array2;
use ndarray_npy::{read_npy, write_npy};

mod common;
use common::{ok, png_size, refused, run_asperity as asperity, stderr};

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
    ok(&out);
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

/// `bem` on the surface `s` at p̄ = 0.005, 0.02, 0.08 with the `extra` flags, quietly, into
/// `dir/name`; returns that CSV's path.
fn three_loads(dir: &Path, s: &str, extra: &[&str], name: &str) -> PathBuf {
    let csv = dir.join(name);
    let base = ["bem", "--surface", s, "--out", csv.to_str().unwrap()];
    let base = [&base[..], &["--quiet", "--pressures", "0.005,0.02,0.08"]].concat();
    ok(&asperity(&[&base[..], extra].concat()));
    csv
}

/// `bem` on the surface `s` at p̄ = 0.01 with the `extra` flags is refused (exit 2, one
/// line) with `needle`.
fn refused_at_one_load(s: &str, extra: &[&str], needle: &str) {
    let base = ["bem", "--surface", s, "--pressures", "0.01"];
    refused(&asperity(&[&base[..], extra].concat()), needle);
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
    ok(&out);
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
    ok(&out);
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
    ok(&out);
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
    ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    let mut lines = text.lines();
    assert!(lines.next().unwrap().contains("area_fraction"));
    assert_eq!(lines.count(), 2);
    // The CSV that --out writes, byte for byte (the help promises a CSV either way).
    let csv = dir.path().join("t.csv");
    let written = asperity(&[
        "bem",
        "--surface",
        s.to_str().unwrap(),
        "--indentations",
        "0,0.01",
        "--out",
        csv.to_str().unwrap(),
    ]);
    ok(&written);
    assert_eq!(std::fs::read(&csv).unwrap(), out.stdout);
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
    // A header promising a grid far too large for memory (the data is not there): refused
    // from the header, before anything is read.
    let huge = dir.path().join("huge.npy");
    std::fs::write(&huge, npy_header_only(&[1 << 20, 1 << 20])).unwrap();
    let csv = dir.path().join("out.csv");
    let fields = dir.path().join("fields");
    let s = s.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["--surface", huge.to_str().unwrap(), "--pressures", "0.01"],
            "MiB are available",
        ),
        // Displacement control beyond full contact, refused with the threshold indentation.
        (
            vec!["--surface", s, "--indentations", "0.01,5"],
            "indentation 5.000000e0 is beyond full contact (the gap closes everywhere from an indentation of",
        ),
        // The message names the quantity given: a force, not the mean pressure 5.
        (
            vec!["--surface", s, "--forces", "20", "--size", "2"],
            "force 2.000000e1 is beyond full contact (the gap closes everywhere from a force of",
        ),
        (
            vec!["--surface", s, "--pressures", "0.01", "--max-iter", "0"],
            "--max-iter must be at least 1, got 0",
        ),
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
            "indentation 1.000000e-1 is beyond full contact (the gap closes everywhere from an indentation of",
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
        assert!(!err.contains("mean pressure 5"), "{extra:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{extra:?}: {err}");
        assert!(!csv.exists(), "{extra:?} wrote the CSV");
        assert!(!fields.exists(), "{extra:?} wrote fields");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            4,
            "{extra:?} left files in {}",
            dir.path().display()
        );
    }
    // A missing load flag is a usage error (clap: exit 2).
    let out = asperity(&["bem", "--surface", s]);
    assert_eq!(out.status.code(), Some(2));
}

/// A `.npy` file with a float64 header of `shape` and no data.
fn npy_header_only(shape: &[usize]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let mut dict = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}), }}",
        dims.join(", ")
    );
    while (10 + dict.len() + 1) % 64 != 0 {
        dict.push(' ');
    }
    dict.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((dict.len() as u16).to_le_bytes());
    bytes.extend(dict.as_bytes());
    bytes.extend([0u8; 64]);
    bytes
}

/// Every file under `dir`, recursively (relative paths, sorted).
fn tree(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.push(path.strip_prefix(dir).unwrap().to_path_buf());
            files.extend(
                tree(&path)
                    .into_iter()
                    .map(|p| path.strip_prefix(dir).unwrap().join(p)),
            );
        } else {
            files.push(path.strip_prefix(dir).unwrap().to_path_buf());
        }
    }
    files.sort();
    files
}

#[test]
fn bad_output_paths_and_late_errors_leave_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let before = tree(dir.path());
    let existing_dir = dir.path().join("a_dir");
    std::fs::create_dir(&existing_dir).unwrap();
    let before_with_dir = tree(dir.path());
    let path = |p: &str| dir.path().join(p).to_str().unwrap().to_string();
    let cases: Vec<(Vec<String>, &str)> = vec![
        // --out in a folder that does not exist: refused before solving, so the fields
        // (which would come first) are not written either.
        (
            vec![
                "--pressures".into(),
                "0.01".into(),
                "--out".into(),
                path("nodir/o.csv"),
                "--fields".into(),
                path("f3"),
            ],
            "does not exist",
        ),
        // --out an existing folder, even with --force.
        (
            vec![
                "--pressures".into(),
                "0.01".into(),
                "--out".into(),
                path("a_dir"),
                "--force".into(),
                "--fields".into(),
                path("f3"),
            ],
            "is a folder",
        ),
        // A late error (the third load is beyond full contact) after two loads' fields were
        // written to temporary files, in folders created for them: all removed.
        (
            vec![
                "--pressures".into(),
                "0.01,0.02,1e4".into(),
                "--out".into(),
                path("o.csv"),
                "--fields".into(),
                path("new/nested/f"),
            ],
            "full contact",
        ),
        // The same under displacement control.
        (
            vec![
                "--indentations".into(),
                "0.01,5".into(),
                "--out".into(),
                path("o.csv"),
                "--fields".into(),
                path("f"),
            ],
            "beyond full contact",
        ),
        // --out named as one of the field files.
        (
            vec![
                "--pressures".into(),
                "0.01".into(),
                "--out".into(),
                path("a_dir/gap_0.npy"),
                "--fields".into(),
                path("a_dir"),
            ],
            "is the same file as",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = vec!["bem", "--surface", s];
        args.extend(extra.iter().map(|a| a.as_str()));
        let out = asperity(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(expected), "{extra:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{extra:?}: {err}");
        assert_eq!(tree(dir.path()), before_with_dir, "{extra:?} left files");
    }
    std::fs::remove_dir(&existing_dir).unwrap();
    assert_eq!(tree(dir.path()), before);

    // Forced over existing outputs, a late error keeps the old files as they were.
    let csv = dir.path().join("o.csv");
    let fields = dir.path().join("f");
    let ok = [
        "bem",
        "--surface",
        s,
        "--pressures",
        "0.01,0.02",
        "--out",
        csv.to_str().unwrap(),
        "--fields",
        fields.to_str().unwrap(),
    ];
    assert!(asperity(&ok).status.success());
    let written = tree(dir.path());
    let old_csv = std::fs::read(&csv).unwrap();
    let old_gap = std::fs::read(fields.join("gap_1.npy")).unwrap();
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--pressures",
        "0.03,1e4",
        "--out",
        csv.to_str().unwrap(),
        "--fields",
        fields.to_str().unwrap(),
        "--force",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(tree(dir.path()), written, "temporary files left");
    assert_eq!(std::fs::read(&csv).unwrap(), old_csv);
    assert_eq!(std::fs::read(fields.join("gap_1.npy")).unwrap(), old_gap);
}

#[test]
fn help_has_examples() {
    let out = asperity(&["bem", "--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Examples:") && text.contains("--nloads") && text.contains("--fields"));
    assert!(text.contains("--out sweep.csv --plot sweep.png"), "{text}");
}

#[test]
fn plot_is_written_as_png_or_svg_beside_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let csv = dir.path().join("c.csv");
    let png = dir.path().join("k.png");
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--nloads",
        "3",
        "--pmin",
        "0.01",
        "--pmax",
        "0.05",
        "--out",
        csv.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
        "--quiet",
    ]);
    ok(&out);
    assert_eq!(read_csv(&csv).1.len(), 3);
    let (w, h) = png_size(&png);
    assert!(w > 0 && h > 0, "{w}x{h}");
    // SVG, with the table on standard output.
    let svg = dir.path().join("k.svg");
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--forces",
        "0.01,0.02",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stdout)
        .trim_start()
        .starts_with("force"));
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    assert_eq!(
        tree(dir.path()),
        [
            "c.csv",
            "c.csv.json",
            "k.png",
            "k.svg",
            "s.npy",
            "s.npy.json"
        ]
        .map(PathBuf::from),
        "no temporary files left"
    );
}

#[test]
fn bad_plots_are_refused_before_solving_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let existing = dir.path().join("old.png");
    std::fs::write(&existing, "precious").unwrap();
    let before = tree(dir.path());
    let path = |p: &str| dir.path().join(p).to_str().unwrap().to_string();
    // Each case would otherwise fail late (the last load is beyond full contact), so the
    // error named proves the check came before any solve.
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec![
                "--pressures".into(),
                "0.01,1e4".into(),
                "--plot".into(),
                path("k.jpg"),
            ],
            "must be .png or .svg",
        ),
        (
            vec![
                "--pressures".into(),
                "0.01,1e4".into(),
                "--plot".into(),
                path("k"),
            ],
            "must be .png or .svg",
        ),
        (
            vec![
                "--pressures".into(),
                "0.01,1e4".into(),
                "--plot".into(),
                path("old.png"),
            ],
            "already exists",
        ),
        // One load is no curve.
        (
            vec![
                "--pressures".into(),
                "1e4".into(),
                "--plot".into(),
                path("k.png"),
            ],
            "at least 2 loads",
        ),
        (
            vec![
                "--nloads".into(),
                "1".into(),
                "--pmin".into(),
                "1e4".into(),
                "--pmax".into(),
                "1e4".into(),
                "--plot".into(),
                path("k.svg"),
            ],
            "at least 2 loads",
        ),
        // The plot named as the table.
        (
            vec![
                "--pressures".into(),
                "0.01,1e4".into(),
                "--plot".into(),
                path("k.png"),
                "--out".into(),
                path("k.png"),
            ],
            "is the same file as",
        ),
    ];
    let (csv, fields) = (path("c.csv"), path("fields"));
    for (extra, expected) in cases {
        let mut args = vec!["bem", "--surface", s];
        args.extend(extra.iter().map(|a| a.as_str()));
        if !extra.contains(&"--out".to_string()) {
            args.extend(["--out", &csv]);
        }
        args.extend(["--fields", &fields]);
        let out = asperity(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(expected), "{extra:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{extra:?}: {err}");
        assert_eq!(tree(dir.path()), before, "{extra:?} left files");
    }
    assert_eq!(std::fs::read_to_string(&existing).unwrap(), "precious");
    // With --force the old plot is replaced (and the other outputs written with it).
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--pressures",
        "0.01,0.02",
        "--out",
        &path("c.csv"),
        "--plot",
        &path("old.png"),
        "--force",
    ]);
    ok(&out);
    assert!(png_size(&existing).0 > 0);
    assert!(dir.path().join("c.csv").exists());
}

#[test]
fn outputs_never_replace_the_surface_or_its_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let sidecar = dir.path().join("s.npy.json");
    let before = tree(dir.path());
    let (surface_bytes, sidecar_bytes) =
        (std::fs::read(&s).unwrap(), std::fs::read(&sidecar).unwrap());
    let dotted = dir.path().join(".").join("s.npy.json");
    for (out, expected) in [
        (sidecar.to_str().unwrap(), "is the sidecar"),
        (dotted.to_str().unwrap(), "is the sidecar"),
        // The CSV over the surface: its record OUT.csv.json would be the sidecar too.
        (s.to_str().unwrap(), "input"),
    ] {
        let out = asperity(&[
            "bem",
            "--surface",
            s.to_str().unwrap(),
            "--pressures",
            "0.01,0.02",
            "--out",
            out,
            "--force",
        ]);
        refused(&out, expected);
        assert_eq!(tree(dir.path()), before);
    }
    assert_eq!(std::fs::read(&s).unwrap(), surface_bytes);
    assert_eq!(std::fs::read(&sidecar).unwrap(), sidecar_bytes);
}

/// The threshold a refusal states (`... from a mean pressure of X)`).
fn stated_threshold(err: &str) -> f64 {
    let tail = err.rsplit(" of ").next().unwrap();
    tail.trim().trim_end_matches(')').parse().unwrap()
}

#[test]
fn loads_beyond_full_contact_are_refused_before_any_solve() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let csv = dir.path().join("o.csv");
    let csv = csv.to_str().unwrap();
    let before = tree(dir.path());
    // --max-iter 1 fails any solve ("no convergence"): the refusal of the last load, with
    // its index and the threshold in its own quantity, shows that nothing was solved.
    let cases: [(&[&str], &str); 5] = [
        (
            &["--pressures", "0.01,0.02,1e4"],
            "load 2 (mean pressure 10000): mean pressure 1.000000e4 is beyond full contact (the gap closes everywhere from a mean pressure of",
        ),
        (
            &["--forces", "0.02,20", "--size", "2"],
            "load 1 (force 20): force 2.000000e1 is beyond full contact (the gap closes everywhere from a force of",
        ),
        (
            &["--indentations", "0.01,5"],
            "load 1 (indentation 5): indentation 5.000000e0 is beyond full contact (the gap closes everywhere from an indentation of",
        ),
        (
            &["--boundary", "periodic", "--pressures", "0.01,1e4"],
            "load 1 (mean pressure 10000): mean pressure 1.000000e4 is beyond full contact",
        ),
        (
            &["--nloads", "20", "--pmin", "1e-3", "--pmax", "1e4"],
            "load 19 (mean pressure 10000",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = vec!["bem", "--surface", s, "--max-iter", "1", "--out", csv];
        args.extend(extra);
        let out = asperity(&args);
        refused(&out, expected);
        assert_eq!(tree(dir.path()), before, "{extra:?}");
    }
    // Loads below the threshold are solved (here: fail to converge in one iteration).
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--max-iter",
        "1",
        "--pressures",
        "0.01,1",
    ]);
    refused(&out, "load 0 (mean pressure 0.01): no convergence");
    // Just below the threshold, --fd-stiffness's upper step would cross it: refused up
    // front too, naming the flag; without it the load is accepted.
    for boundary in ["free", "periodic"] {
        let out = asperity(&[
            "bem",
            "--surface",
            s,
            "--boundary",
            boundary,
            "--pressures",
            "1e4",
        ]);
        let full = stated_threshold(&stderr(&out));
        let near = format!("{}", full * (1.0 - 1e-4));
        let base = [
            "bem",
            "--surface",
            s,
            "--boundary",
            boundary,
            "--max-iter",
            "1",
        ];
        let out = asperity(&[&base[..], &["--pressures", &near, "--fd-stiffness"]].concat());
        refused(&out, "--fd-stiffness: at load 0");
        assert!(
            stderr(&out).contains("beyond full contact"),
            "{}",
            stderr(&out)
        );
        let out = asperity(&[&base[..], &["--pressures", &near]].concat());
        refused(&out, "no convergence");
    }
}

#[test]
fn fd_stiffness_agrees_with_the_frozen_set_and_changes_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let run = |extra: &[&str], name: &str| {
        let csv = dir.path().join(name);
        let base = [
            "bem",
            "--surface",
            s,
            "--out",
            csv.to_str().unwrap(),
            "--quiet",
        ];
        let out = asperity(&[&base[..], extra].concat());
        ok(&out);
        read_csv(&csv)
    };
    let loads = ["--pressures", "0.005,0.01,0.02,0.04"];
    let (header, rows) = run(
        &[&loads[..], &["--fd-stiffness", "--timing"]].concat(),
        "fd.csv",
    );
    // Appended after the contract's columns, before the timing columns.
    assert_eq!(header[7], "stiffness_fd");
    assert_eq!(header[8], "solve_seconds");
    let (k, fd) = (
        column(&header, "stiffness"),
        column(&header, "stiffness_fd"),
    );
    for row in &rows {
        let relative = row[fd] / row[k] - 1.0;
        assert!(
            relative.abs() < 0.02,
            "frozen set {} vs fd {}",
            row[k],
            row[fd]
        );
    }
    // The frozen-set stiffness and the state of every load are those of a run without it:
    // the first load exactly, the later ones (warm-started from a re-solved state) to the
    // solver's tolerance.
    let (plain_header, plain) = run(&loads, "plain.csv");
    assert_eq!(plain_header.len(), 7);
    assert_eq!(rows[0][..7], plain[0][..7]);
    for (a, b) in rows.iter().zip(&plain) {
        for name in ["force", "indentation", "area_fraction", "stiffness"] {
            let i = column(&plain_header, name);
            assert!(
                (a[i] / b[i] - 1.0).abs() < 1e-5,
                "{name}: {} vs {}",
                a[i],
                b[i]
            );
        }
    }
    // Indentation control; no central difference at d = 0 (an empty cell).
    let csv = dir.path().join("d.csv");
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--indentations",
        "0,0.02",
        "--fd-stiffness",
        "--out",
        csv.to_str().unwrap(),
    ]);
    ok(&out);
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[1].ends_with(','), "{text}");
    let last: Vec<f64> = lines[2].split(',').map(|v| v.parse().unwrap()).collect();
    assert!((last[7] / last[4] - 1.0).abs() < 0.02, "{text}");
    // The help states the step.
    let help = String::from_utf8_lossy(&asperity(&["bem", "--help"]).stdout).into_owned();
    assert!(
        help.contains("--fd-stiffness") && help.contains("1e-3"),
        "{help}"
    );
}

#[test]
fn stale_field_files_of_an_earlier_run_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let fields = dir.path().join("f");
    let f = fields.to_str().unwrap();
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--pressures",
        "0.01,0.02,0.03",
        "--fields",
        f,
    ]);
    ok(&out);
    let before = tree(dir.path());
    let old = std::fs::read(fields.join("gap_2.npy")).unwrap();
    // Two loads would leave pressure_2.npy and gap_2.npy beside the new files: refused,
    // with or without --force, before any solve (--max-iter 1 would fail it).
    for force in [true, false] {
        let mut args = vec![
            "bem",
            "--surface",
            s,
            "--pressures",
            "0.01,0.02",
            "--fields",
            f,
            "--max-iter",
            "1",
        ];
        if force {
            args.push("--force");
        }
        let out = asperity(&args);
        refused(&out, "gap_2.npy");
        assert!(stderr(&out).contains("another folder"), "{}", stderr(&out));
        assert_eq!(tree(dir.path()), before);
    }
    // Any other pressure_*.npy / gap_*.npy counts too; other files do not.
    std::fs::write(dir.path().join("f/notes.txt"), "mine").unwrap();
    std::fs::write(dir.path().join("f/pressure_old.npy"), "old").unwrap();
    let args = [
        "bem",
        "--surface",
        s,
        "--pressures",
        "0.01,0.02,0.03",
        "--fields",
        f,
        "--force",
    ];
    refused(&asperity(&args), "pressure_old.npy");
    std::fs::remove_file(dir.path().join("f/pressure_old.npy")).unwrap();
    // The same loads again replace exactly the files there.
    let out = asperity(&args);
    ok(&out);
    assert_eq!(std::fs::read(fields.join("gap_2.npy")).unwrap(), old);
}

#[test]
fn the_table_records_its_inputs_and_l_is_stated() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let bare = dir.path().join("bare.npy");
    std::fs::copy(s, &bare).unwrap();
    let csv = dir.path().join("o.csv");
    let record = dir.path().join("o.csv.json");
    let run = |surface: &str, extra: &[&str]| {
        let base = [
            "bem",
            "--surface",
            surface,
            "--pressures",
            "0.01,0.02",
            "--force",
        ];
        let out = asperity(&[&base[..], extra].concat());
        ok(&out);
        stderr(&out)
    };
    let out_args = ["--out", csv.to_str().unwrap()];
    let err = run(
        s,
        &[
            &out_args[..],
            &[
                "--size",
                "2",
                "--modulus",
                "3",
                "--boundary",
                "periodic",
                "--tol",
                "1e-9",
            ],
        ]
        .concat(),
    );
    assert!(err.contains("L = 2 (from --size)"), "{err}");
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&record).unwrap()).unwrap();
    assert_eq!(value["surface"], s);
    assert_eq!(value["size"], 2.0);
    assert_eq!(value["size_source"], "--size");
    assert_eq!(value["modulus"], 3.0);
    assert_eq!(value["boundary"], "periodic");
    assert_eq!(value["tolerance"], 1e-9);
    assert_eq!(value["grid"], serde_json::json!([64, 64]));
    assert_eq!(value["loads"]["values"], serde_json::json!([0.01, 0.02]));
    let (header, _) = read_csv(&csv);
    assert_eq!(value["columns"], serde_json::json!(header));
    // L from the sidecar, or the default; stated on stderr (also without --out).
    let err = run(s, &out_args);
    assert!(err.contains("L = 1 (from sidecar)"), "{err}");
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&record).unwrap()).unwrap();
    assert_eq!(value["size_source"], "sidecar");
    assert_eq!(value["boundary"], "free");
    let err = run(bare.to_str().unwrap(), &[]);
    assert!(err.contains("L = 1 (default)"), "{err}");
    assert!(run(s, &[&out_args[..], &["--quiet"]].concat()).is_empty());
    // The record is an output like the others: an existing one is kept without --force,
    // and nothing else is written.
    std::fs::remove_file(&csv).unwrap();
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--pressures",
        "0.01",
        "--out",
        csv.to_str().unwrap(),
    ]);
    refused(&out, "o.csv.json");
    assert!(!csv.exists());
}

#[test]
fn impossible_load_counts_are_refused_without_aborting() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let fields = dir.path().join("f");
    let before = tree(dir.path());
    for (k, expected) in [
        ("18446744073709551615", "exceeds addressable memory"),
        ("1000000000000000", "MiB"),
    ] {
        let out = asperity(&[
            "bem",
            "--surface",
            s,
            "--nloads",
            k,
            "--pmin",
            "1e-3",
            "--pmax",
            "1e-2",
            "--fields",
            fields.to_str().unwrap(),
        ]);
        refused(&out, expected);
        assert!(stderr(&out).contains("--nloads"), "{}", stderr(&out));
        assert_eq!(tree(dir.path()), before);
    }
}

#[test]
fn bad_numbers_name_their_flag() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    for (extra, expected) in [
        (
            &["--modulus", "-1"][..],
            "--modulus must be positive and finite, got -1",
        ),
        (
            &["--size", "-1"][..],
            "--size must be positive and finite, got -1",
        ),
        (
            &["--size", "0"][..],
            "--size must be positive and finite, got 0",
        ),
        (&["--size", "nan"][..], "--size"),
        (
            &["--max-iter", "-1"][..],
            "--max-iter must be at least 1, got -1",
        ),
        (
            &["--nloads", "-1", "--pmin", "1", "--pmax", "2"][..],
            "--nloads must be at least 1, got -1",
        ),
    ] {
        let mut args = vec!["bem", "--surface", s];
        args.extend(extra);
        if !extra.contains(&"--nloads") {
            args.extend(["--pressures", "0.01"]);
        }
        let out = asperity(&args);
        refused(&out, expected);
        assert!(
            !stderr(&out).contains("unexpected argument"),
            "{}",
            stderr(&out)
        );
    }
}

#[test]
fn periodic_indentations_agree_with_load_control() {
    // Periodic displacement control measures d relative to the mean elastic displacement,
    // as load control reports it: the indentations of a load-controlled run, given back
    // with --indentations, reproduce its pressures, areas and stiffnesses.
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let loads = dir.path().join("loads.csv");
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--boundary",
        "periodic",
        "--pressures",
        "0.01,0.05",
        "--out",
        loads.to_str().unwrap(),
    ]);
    ok(&out);
    let (header, by_load) = read_csv(&loads);
    let d = column(&header, "indentation");
    let indentations = by_load
        .iter()
        .map(|row| format!("{:e}", row[d]))
        .collect::<Vec<_>>()
        .join(",");
    let displacements = dir.path().join("displacements.csv");
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--boundary",
        "periodic",
        "--indentations",
        &indentations,
        "--out",
        displacements.to_str().unwrap(),
    ]);
    ok(&out);
    let (header_d, by_indentation) = read_csv(&displacements);
    assert_eq!(header_d, header);
    assert_eq!(by_indentation.len(), 2);
    for (l, i) in by_load.iter().zip(&by_indentation) {
        assert_eq!(i[d], l[d]);
        for name in ["force", "mean_pressure", "stiffness"] {
            let c = column(&header, name);
            assert!(
                (i[c] / l[c] - 1.0).abs() < 1e-6,
                "{name}: {} vs {}",
                i[c],
                l[c]
            );
        }
        let area = column(&header, "area_fraction");
        assert_eq!(i[area], l[area]);
        assert!(i[column(&header, "residual")] < 1e-8);
    }
    // At and beyond full contact, d = max(h) − mean(h), refused in terms of the indentation.
    let heights: Array2<f64> = read_npy(s).unwrap();
    let top = heights.iter().fold(f64::NEG_INFINITY, |m, &h| m.max(h));
    let full = top - heights.mean().unwrap();
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--boundary",
        "periodic",
        "--indentations",
        &format!("{:e}", 1.01 * full),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("is beyond full contact (the gap closes everywhere from an indentation of"),
        "{err}"
    );
}

#[test]
fn both_solvers_give_the_same_contact_and_the_record_names_the_solver() {
    // --solver pk (the reference) and the default bccg to 1e-11: the same contact area and
    // stiffness, indentations to 1e-9 relative; pk takes more iterations. A bad name is
    // refused with exit 2.
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let mut tables = Vec::new();
    for solver in ["pk", "bccg", ""] {
        let csv = dir.path().join(format!("run_{solver}.csv"));
        let mut args = vec![
            "bem",
            "--surface",
            s.to_str().unwrap(),
            "--pressures",
            "0.01,0.03",
            "--tol",
            "1e-11",
            "--out",
            csv.to_str().unwrap(),
        ];
        if !solver.is_empty() {
            args.extend(["--solver", solver]);
        }
        let out = asperity(&args);
        ok(&out);
        let record = csv.with_extension("csv.json");
        let value: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(record).unwrap()).unwrap();
        let expected = if solver.is_empty() { "bccg" } else { solver };
        assert_eq!(value["solver"], expected);
        tables.push(read_csv(&csv));
    }
    let (header, pk) = &tables[0];
    let (_, bccg) = &tables[1];
    assert_eq!(tables[1], tables[2], "bccg is the default");
    let [area, d, k, it] = ["area_fraction", "indentation", "stiffness", "iterations"]
        .map(|name| column(header, name));
    for (a, b) in pk.iter().zip(bccg) {
        assert_eq!(a[area], b[area]);
        assert!((a[d] / b[d] - 1.0).abs() < 1e-9, "{} vs {}", a[d], b[d]);
        assert!((a[k] / b[k] - 1.0).abs() < 1e-6, "{} vs {}", a[k], b[k]);
        assert!(b[it] < a[it], "bccg {} vs pk {} iterations", b[it], a[it]);
    }
    let out = asperity(&[
        "bem",
        "--surface",
        s.to_str().unwrap(),
        "--pressures",
        "0.01",
        "--solver",
        "cg",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--solver"), "{}", stderr(&out));
}

/// `--size X,Y`: Y equal to the square-pixel default (L·rows/cols) gives the very numbers
/// of `--size X`; another Y (rectangular pixels) changes them and is recorded.
#[test]
fn size_takes_both_sides() {
    let dir = tempfile::tempdir().unwrap();
    let square: Array2<f64> = read_npy(surface(dir.path())).unwrap();
    // 64 rows × 32 columns: with L = 1 along x, square pixels make the y side 2.
    let tall = square.slice(ndarray::s![.., ..32]).to_owned();
    let s = dir.path().join("tall.npy");
    write_npy(&s, &tall).unwrap();
    let run = |size: &str, name: &str| {
        let out = dir.path().join(name);
        let o = asperity(&[
            "bem",
            "--surface",
            s.to_str().unwrap(),
            "--size",
            size,
            "--pressures",
            "0.01,0.03",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let record: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join(format!("{name}.json"))).unwrap(),
        )
        .unwrap();
        (
            std::fs::read(&out).unwrap(),
            record["size_y"].as_f64().unwrap(),
        )
    };
    let (default_y, y1) = run("1", "a.csv");
    let (explicit_y, y2) = run("1,2", "b.csv");
    let (other_y, y3) = run("1,1", "c.csv");
    assert_eq!((y1, y2, y3), (2.0, 2.0, 1.0));
    assert_eq!(default_y, explicit_y);
    assert_ne!(default_y, other_y);
}

#[test]
fn hardness_caps_the_pressure_and_adds_the_plastic_fraction() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let run = |extra: &[&str]| {
        let mut args = vec!["bem", "--surface", s.to_str().unwrap(), "--quiet"];
        args.extend_from_slice(extra);
        asperity(&args)
    };
    // The default BCCG and Polonsky–Keer: the same plastic fractions (the same sets).
    let mut fractions = Vec::new();
    for (name, solver) in [("bccg", &[][..]), ("pk", &["--solver", "pk"][..])] {
        let csv = dir.path().join(format!("h_{name}.csv"));
        let fields = dir.path().join(format!("hf_{name}"));
        let mut args = vec!["--pressures", "0.01,0.03", "--hardness", "0.3"];
        args.extend_from_slice(solver);
        args.extend_from_slice(&["--out", csv.to_str().unwrap()]);
        args.extend_from_slice(&["--fields", fields.to_str().unwrap()]);
        ok(&run(&args));
        let (header, rows) = read_csv(&csv);
        let plastic = column(&header, "plastic_fraction");
        let area = column(&header, "area_fraction");
        for (k, row) in rows.iter().enumerate() {
            let p: Array2<f64> = read_npy(fields.join(format!("pressure_{k}.npy"))).unwrap();
            let n = p.len() as f64;
            assert!(p.iter().all(|&v| (0.0..=0.3).contains(&v)));
            let at_cap = p.iter().filter(|&&v| v == 0.3).count() as f64;
            assert!(at_cap > 0.0);
            assert_eq!(row[plastic], at_cap / n);
            assert!(row[plastic] < row[area]);
        }
        fractions.push(rows.iter().map(|r| r[plastic]).collect::<Vec<_>>());
    }
    assert_eq!(fractions[0], fractions[1]);
    // Refused before any work, one line each: a bad hardness, a load the cap cannot
    // carry.
    for (extra, needle) in [
        (&["--pressures", "0.01", "--hardness", "0"][..], "hardness"),
        (
            &["--pressures", "0.01", "--hardness", "nan"][..],
            "hardness",
        ),
        (
            &["--pressures", "0.3", "--hardness", "0.3"][..],
            "at or above the hardness",
        ),
        (
            &["--pressures", "0.01", "--solver", "pk", "--hardness", "-1"][..],
            "hardness",
        ),
    ] {
        refused(&run(extra), needle);
    }
}

/// `--poisson`, `--resistivity`, `--thermal-conductivity`: the tangential stiffness and the
/// conductances of every load as columns after the contract's, before the timing ones; the
/// contract's columns are those of a run without them, cell for cell (the tangential CGs
/// do not move the solver); `tangential_ratio` is `(k_x + k_y)/(2k)` near Mindlin's
/// `2(1−ν)/(2−ν)`; the conductances are `k` times Barber's factors; bad values are refused
/// with one line and exit 2.
#[test]
fn tangential_and_conductance_columns_follow_the_frozen_set() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let run = |extra: &[&str], name: &str| {
        let csv = three_loads(dir.path(), s, extra, name);
        (std::fs::read_to_string(&csv).unwrap(), read_csv(&csv))
    };
    let derived = [
        "--poisson",
        "0.3",
        "--resistivity",
        "2,3",
        "--thermal-conductivity",
        "4,12",
        "--timing",
    ];
    let (text, (header, rows)) = run(&derived, "derived.csv");
    let names = [
        "stiffness_x",
        "stiffness_y",
        "tangential_ratio",
        "electrical_conductance",
        "thermal_conductance",
        "solve_seconds",
    ];
    assert_eq!(header[7..13], names);
    assert_eq!(header.last().unwrap(), "tangential_seconds");
    let (plain_text, _) = run(&[], "plain.csv");
    for (a, b) in text.lines().skip(1).zip(plain_text.lines().skip(1)) {
        let cells: Vec<&str> = a.split(',').collect();
        assert_eq!(cells[..7].join(","), b, "the contract's cells");
    }
    let at = |row: &[f64], name: &str| row[column(&header, name)];
    let mindlin = 2.0 * 0.7 / 1.7;
    for row in &rows {
        let (k, kx, ky) = (
            at(row, "stiffness"),
            at(row, "stiffness_x"),
            at(row, "stiffness_y"),
        );
        assert_eq!(at(row, "tangential_ratio"), (kx + ky) / (2.0 * k));
        // A 64² rough surface: within 1 % of Mindlin's ratio (0.8235), as docs/tangential.md
        // measures at 512² and 1024².
        assert!((at(row, "tangential_ratio") / mindlin - 1.0).abs() < 0.01);
        // Barber: C = 2k/(E*(ρ₁+ρ₂)) and (2k/E*)·κ₁κ₂/(κ₁+κ₂), E* = 1.
        assert!((at(row, "electrical_conductance") / (2.0 * k / 5.0) - 1.0).abs() < 1e-15);
        assert!((at(row, "thermal_conductance") / (2.0 * k * 3.0) - 1.0).abs() < 1e-15);
        assert!(at(row, "tangential_seconds") >= 0.0);
    }
    let record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("derived.csv.json")).unwrap())
            .unwrap();
    assert_eq!(record["tangential"]["poisson"], 0.3);
    assert_eq!(record["resistivity"], serde_json::json!([2.0, 3.0]));
    let bad = |extra: &[&str], needle: &str| refused_at_one_load(s, extra, needle);
    bad(
        &["--poisson", "0.7"],
        "--poisson must be in [0, 0.5] (Poisson's ratio), got 0.7",
    );
    bad(&["--poisson", "nan"], "--poisson must be in [0, 0.5]");
    bad(
        &["--resistivity", "1"],
        "invalid --resistivity: give two values",
    );
    bad(
        &["--thermal-conductivity", "1,-1"],
        "each body's thermal conductivity must be positive and finite, got -1",
    );
    let adhesive = [
        "bem",
        "--surface",
        s,
        "--indentations",
        "0.01",
        "--work-of-adhesion",
        "0.1",
        "--poisson",
        "0.3",
    ];
    refused(&asperity(&adhesive), "does not go with --poisson");
}

/// `--tangential x|y|both`: one direction adds only its column, and `tangential_ratio` is
/// its `k_d/k`; `x` is the `both` run's `k_x` cell for cell (the same start and CG), `y`
/// its `k_y` to the CG's tolerance (another start); the contract's columns are unchanged;
/// a bad direction, or one without `--poisson`, is refused with one line and exit 2.
#[test]
fn one_tangential_direction_is_the_both_runs_column() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let run = |extra: &[&str], name: &str| {
        read_csv(&three_loads(
            dir.path(),
            s,
            &[&["--poisson", "0.3"], extra].concat(),
            name,
        ))
    };
    let (both_header, both) = run(&[], "both.csv");
    let (explicit_header, explicit) = run(&["--tangential", "both"], "explicit.csv");
    assert_eq!((&explicit_header, &explicit), (&both_header, &both));
    for (direction, name) in [("x", "stiffness_x"), ("y", "stiffness_y")] {
        let (header, rows) = run(&["--tangential", direction], &format!("{direction}.csv"));
        assert_eq!(header[7..9], [name, "tangential_ratio"]);
        assert_eq!(header.len(), 9, "{header:?}");
        for (row, whole) in rows.iter().zip(&both) {
            assert_eq!(row[..7], whole[..7], "the contract's cells");
            let (k, kd) = (row[4], row[7]);
            let whole_kd = whole[column(&both_header, name)];
            if direction == "x" {
                assert_eq!(kd, whole_kd);
            } else {
                // Stopping energy error 1e-12 relative.
                assert!((kd / whole_kd - 1.0).abs() < 1e-11, "{kd} {whole_kd}");
            }
            assert_eq!(row[8], kd / k);
        }
    }
    let record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("x.csv.json")).unwrap()).unwrap();
    assert_eq!(record["tangential"]["directions"], "x");
    let bad = |extra: &[&str], needle: &str| refused_at_one_load(s, extra, needle);
    bad(
        &["--poisson", "0.3", "--tangential", "z"],
        "--tangential must be x, y or both, got \"z\"",
    );
    bad(
        &["--tangential", "x"],
        "--tangential needs --poisson ν (of Cerruti's kernel)",
    );
}

/// Issue 33 items 13 and 15: a solve that cannot converge ends early, in one line that says
/// why, instead of running to its iteration limit (here a million: hours at 64²). A
/// tolerance below the rounding floor stands for every stagnating solve; both solvers.
#[test]
fn a_solve_that_stops_improving_is_given_up_early_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    for solver in ["bccg", "pk"] {
        let out = asperity(&[
            "bem",
            "--surface",
            s.to_str().unwrap(),
            "--solver",
            solver,
            "--pressures",
            "0.01",
            "--tol",
            "1e-300",
            "--max-iter",
            "1000000",
        ]);
        let err = refused(
            &out,
            "load 0 (mean pressure 0.01): no convergence: the residual",
        );
        assert!(
            err.contains("stopped decreasing (not halved in the last 1000 of")
                && err.contains("near the rounding floor, ask for a larger tolerance")
                && !err.contains("NaN"),
            "{solver}: {err}"
        );
    }
}

/// `--persson`: the BEM's mean gap and Persson's three columns after the contract's; the
/// contract's cells are those of a run without it; the theory's cells are `asperity
/// persson`'s for the same surface, pressures, E*, γ and κ (to the rounding of the profile
/// `max(h) − h` the sweep takes its PSD from); with periodic boundaries the mean gap is
/// `mean(max(h) − h) − indentation` (zero-mean displacement); bad values are refused before
/// any solve.
#[test]
fn persson_columns_beside_the_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let s = s.to_str().unwrap();
    let pressures = "0.005,0.02,0.08";
    let run = |extra: &[&str], name: &str| {
        let csv = dir.path().join(name);
        let base = ["bem", "--surface", s, "--out", csv.to_str().unwrap()];
        let common = [
            "--quiet",
            "--pressures",
            pressures,
            "--boundary",
            "periodic",
        ];
        let common = [&common[..], &["--modulus", "2"]].concat();
        ok(&asperity(&[&base[..], &common, extra].concat()));
        (std::fs::read_to_string(&csv).unwrap(), read_csv(&csv))
    };
    let options = ["--persson", "--gamma", "0.4", "--kappa", "2"];
    let (text, (header, rows)) = run(&options, "persson.csv");
    let names = [
        "mean_gap",
        "area_fraction_persson",
        "mean_gap_persson",
        "stiffness_persson",
    ];
    assert_eq!(header[7..], names);
    let (plain_text, _) = run(&[], "plain.csv");
    for (a, b) in text.lines().skip(1).zip(plain_text.lines().skip(1)) {
        let cells: Vec<&str> = a.split(',').collect();
        assert_eq!(cells[..7].join(","), b, "the contract's cells");
    }
    let theory = dir.path().join("theory.csv");
    ok(&asperity(&[
        "persson",
        s,
        "--pressures",
        pressures,
        "--modulus",
        "2",
        "--gamma",
        "0.4",
        "--kappa",
        "2",
        "--out",
        theory.to_str().unwrap(),
    ]));
    let (theory_header, theory_rows) = read_csv(&theory);
    let heights: Array2<f64> = read_npy(s).unwrap();
    let top = heights.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let mean_profile = heights.mapv(|h| top - h).mean().unwrap();
    let at = |row: &[f64], name: &str| row[column(&header, name)];
    for (row, expected) in rows.iter().zip(&theory_rows) {
        let want = |name: &str| expected[column(&theory_header, name)];
        for (ours, theirs) in [
            ("area_fraction_persson", "area_fraction"),
            ("mean_gap_persson", "mean_gap"),
            ("stiffness_persson", "contact_stiffness"),
        ] {
            let (a, b) = (at(row, ours), want(theirs));
            assert!((a / b - 1.0).abs() < 1e-12, "{ours}: {a} vs {b}");
        }
        let gap = mean_profile - at(row, "indentation");
        assert!((at(row, "mean_gap") - gap).abs() < 1e-9 * mean_profile);
    }
    let record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("persson.csv.json")).unwrap())
            .unwrap();
    assert_eq!(record["persson"]["gamma"], 0.4);
    assert_eq!(record["persson"]["kappa"], 2.0);
    assert!(record["persson"]["u0"].as_f64().unwrap() > 0.0);
    let bad = |extra: &[&str], needle: &str| refused_at_one_load(s, extra, needle);
    bad(
        &["--persson", "--gamma", "1.5"],
        "γ must lie in (0, 1], got 1.5",
    );
    bad(
        &["--persson", "--kappa", "-1"],
        "κ must be positive and finite",
    );
    bad(&["--gamma", "0.4"], "--gamma goes with --persson");
    let adhesive = ["--indentations", "0.01", "--work-of-adhesion", "0.1"];
    let base = ["bem", "--surface", s, "--persson"];
    refused(
        &asperity(&[&base[..], &adhesive].concat()),
        "--persson goes with a load sweep",
    );
}

/// Issue 33, item 13: a single long solve printed nothing until it ended. `--progress`
/// reports the iteration and the residual inside each solve (every 2 s; the hidden
/// `--progress-every 0` of this test: every iteration, so that nothing here depends on the
/// machine's speed); without it, off a terminal, the solve stays silent.
#[test]
fn progress_inside_a_solve_reports_iterations_and_residuals() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    for solver in ["bccg", "pk"] {
        let run = |extra: &[&str]| {
            let args = [
                &["bem", "--surface", s.to_str().unwrap(), "--solver", solver][..],
                &["--pressures", "0.01,0.02"][..],
                extra,
            ]
            .concat();
            let out = asperity(&args);
            ok(&out);
            let table = String::from_utf8(out.stdout.clone()).unwrap();
            (table, stderr(&out))
        };
        let (quiet_table, silent) = run(&[]);
        assert!(!silent.contains("iteration"), "{solver}: {silent}");
        let (table, err) = run(&["--progress-every", "0"]);
        assert_eq!(table, quiet_table, "{solver}: the same results");
        let iterations: Vec<usize> = table
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(5).unwrap().parse().unwrap())
            .collect();
        for (load, &solved) in iterations.iter().enumerate() {
            let prefix = format!("bem: load {}/2: iteration ", load + 1);
            let lines: Vec<(usize, f64)> = err
                .lines()
                .filter_map(|l| l.strip_prefix(&prefix))
                .map(|l| {
                    let (iteration, rest) = l.split_once(", residual ").unwrap();
                    let residual = rest.split_once(' ').unwrap().0;
                    (iteration.parse().unwrap(), residual.parse().unwrap())
                })
                .collect();
            assert!(
                !lines.is_empty() && lines.len() <= solved + 1,
                "{solver}: {err}"
            );
            assert!(lines.windows(2).all(|w| w[0].0 < w[1].0), "{solver}: {err}");
            assert!(lines
                .iter()
                .all(|&(i, r)| i < solved && r.is_finite() && r >= 1e-8));
        }
        let out = asperity(&[
            "bem",
            "--surface",
            s.to_str().unwrap(),
            "--pressures",
            "0.01",
            "--progress-every",
            "-1",
        ]);
        refused(&out, "-1");
    }
}

/// The bits of a field file's float64 variable.
fn nc_real(file: &asperity::fields::FieldFile, name: &str) -> Vec<f64> {
    let v = file.variables.iter().find(|v| v.name == name).unwrap();
    match &v.values {
        asperity::fields::Values::Real(x) => x.clone(),
        other => panic!("{name}: {other:?}"),
    }
}

#[test]
fn fields_to_a_netcdf_file_hold_the_npy_fields_bit_for_bit() {
    use asperity::fields::FieldFile;
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let (nc, folder, csv) = (
        dir.path().join("fields.nc"),
        dir.path().join("fields"),
        dir.path().join("out.csv"),
    );
    for (fields, out) in [(&nc, Some(&csv)), (&folder, None)] {
        let mut args = vec![
            "bem",
            "--surface",
            s.to_str().unwrap(),
            "--pressures",
            "0.01,0.03",
        ];
        args.extend(["--fields", fields.to_str().unwrap(), "--quiet"]);
        if let Some(out) = out {
            args.extend(["--out", out.to_str().unwrap()]);
        }
        ok(&asperity(&args));
    }
    let file = FieldFile::read(&nc).unwrap();
    let grid = file.grid.as_ref().unwrap();
    assert_eq!(
        (grid.rows, grid.cols, grid.size, grid.size_y),
        (64, 64, 1.0, 1.0)
    );
    assert_eq!(grid.units, None); // a generated surface: the heights' unit is the user's
    assert_eq!(file.dims, vec![("load".to_string(), 2)]);
    let (pressure, gap) = (nc_real(&file, "pressure"), nc_real(&file, "gap"));
    for k in 0..2 {
        let p: Array2<f64> = read_npy(folder.join(format!("pressure_{k}.npy"))).unwrap();
        let g: Array2<f64> = read_npy(folder.join(format!("gap_{k}.npy"))).unwrap();
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&pressure[k * 4096..(k + 1) * 4096]),
            bits(p.as_slice().unwrap())
        );
        assert_eq!(
            bits(&gap[k * 4096..(k + 1) * 4096]),
            bits(g.as_slice().unwrap())
        );
    }
    // The per-load columns are the table's; the record is OUT.csv.json's.
    let (header, rows) = read_csv(&csv);
    for name in ["force", "mean_pressure", "indentation", "area_fraction"] {
        let table: Vec<f64> = rows.iter().map(|r| r[column(&header, name)]).collect();
        assert_eq!(nc_real(&file, name), table, "{name}");
    }
    let record: serde_json::Value = serde_json::from_str(
        &file
            .attributes
            .iter()
            .find(|a| a.0 == "asperity_record")
            .unwrap()
            .1,
    )
    .unwrap();
    let sidecar: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out.csv.json")).unwrap())
            .unwrap();
    assert_eq!(record, sidecar);
    let p = file
        .variables
        .iter()
        .find(|v| v.name == "pressure")
        .unwrap();
    assert_eq!(p.dims, ["load", "y", "x"]);
    assert_eq!(p.units, None);
    assert_eq!(p.comment.as_deref(), Some("in the units of the modulus E*"));
}

#[test]
fn a_netcdf_fields_file_is_refused_where_it_cannot_be_written() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let run = |fields: &Path, extra: &[&str]| {
        let mut args = vec![
            "bem",
            "--surface",
            s.to_str().unwrap(),
            "--pressures",
            "0.01",
        ];
        args.extend(["--fields", fields.to_str().unwrap(), "--quiet"]);
        args.extend(extra);
        asperity(&args)
    };
    // A folder named *.nc; a .nc in a missing folder; an existing file without --force.
    let folder = dir.path().join("taken.nc");
    std::fs::create_dir(&folder).unwrap();
    refused(&run(&folder, &[]), "is a folder");
    let missing = dir.path().join("no/such/f.nc");
    refused(&run(&missing, &[]), "no/such");
    assert!(!dir.path().join("no").exists());
    let existing = dir.path().join("f.nc");
    std::fs::write(&existing, b"mine").unwrap();
    refused(&run(&existing, &[]), "already exists");
    assert_eq!(std::fs::read(&existing).unwrap(), b"mine");
    ok(&run(&existing, &["--force"]));
    assert!(asperity::fields::FieldFile::read(&existing).is_ok());
}

#[test]
fn a_load_path_writes_its_permanent_displacement_to_a_netcdf_file() {
    let dir = tempfile::tempdir().unwrap();
    let s = surface(dir.path());
    let (nc, folder) = (dir.path().join("path.nc"), dir.path().join("path"));
    for fields in [&nc, &folder] {
        ok(&asperity(&[
            "bem",
            "--surface",
            s.to_str().unwrap(),
            "--pressures",
            "0.01,0.04,0.01",
            "--hardness",
            "0.3",
            "--load-path",
            "--boundary",
            "periodic",
            "--quiet",
            "--fields",
            fields.to_str().unwrap(),
        ]));
    }
    let file = asperity::fields::FieldFile::read(&nc).unwrap();
    let permanent: Array2<f64> = read_npy(folder.join("permanent.npy")).unwrap();
    assert_eq!(
        nc_real(&file, "permanent_displacement"),
        permanent.as_slice().unwrap()
    );
    assert!(permanent.iter().any(|&w| w > 0.0));
    assert_eq!(nc_real(&file, "permanent_max").len(), 3);
}
