//! Drives the real `asperity` binary: surface, line and stats, including bad input.

use std::path::Path;
use std::process::{Command, Output};

use ndarray::{array, Array2};
use ndarray_npy::{read_npy, write_npy};

mod common;
use common::{asperity, asperity_env, ok, refused, stderr};

/// Exit status 2, a single `error:` line, and nothing new in the folder.
fn assert_refused(out: &Output, dir: &Path, files_before: usize, needle: &str) {
    let err = refused(out, needle);
    assert_eq!(
        std::fs::read_dir(dir).unwrap().count(),
        files_before,
        "no partial file left: {err}"
    );
}

#[test]
fn surface_writes_npy_sidecar_and_png_and_is_reproducible() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = [
        "surface",
        "--n",
        "64",
        "--m",
        "48",
        "--hurst",
        "-0.5",
        "--rms-slope",
        "0.5",
        "--rolloff",
        "4",
        "--size",
        "2",
        "--seed",
        "11",
    ];
    let out = asperity(
        &[&args[..], &["--out", "a.npy", "--png", "a.png"]].concat(),
        d,
    );
    ok(&out);
    let out = asperity(&[&args[..], &["--out", "b.npy"]].concat(), d);
    ok(&out);
    let a: Array2<f64> = read_npy(d.join("a.npy")).unwrap();
    let b: Array2<f64> = read_npy(d.join("b.npy")).unwrap();
    assert_eq!(a.dim(), (48, 64));
    assert!(
        a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
        "same seed, same bits"
    );
    let sidecar: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("a.npy.json")).unwrap()).unwrap();
    assert_eq!(sidecar["kind"], "surface");
    assert_eq!(sidecar["seed"], 11);
    assert_eq!(sidecar["shape"], serde_json::json!([48, 64]));
    let spec = &sidecar["spec"];
    assert_eq!(
        (spec["rows"].as_u64(), spec["cols"].as_u64()),
        (Some(48), Some(64))
    );
    assert_eq!(spec["size"], 2.0);
    assert_eq!(spec["psd"]["hurst"], -0.5);
    assert_eq!(
        spec["psd"]["long_wavelength"],
        serde_json::json!({"kind": "roll_off", "q0": 4.0})
    );
    assert_eq!(spec["psd"]["short_cutoff"], serde_json::Value::Null);
    assert_eq!(
        spec["normalisation"],
        serde_json::json!({"kind": "rms_slope", "value": 0.5})
    );
    let recorded_slope = sidecar["stats"]["rms_slope"].as_f64().unwrap();
    assert!(
        (recorded_slope / 0.5 - 1.0).abs() < 1e-10,
        "{recorded_slope}"
    );
    // The PNG: one pixel per grid point, grey, black at the lowest and white at the
    // highest point.
    let decoder = png::Decoder::new(std::fs::File::open(d.join("a.png")).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert_eq!((info.width, info.height), (64, 48));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let pixels = &pixels[..info.buffer_size()];
    assert!(
        pixels.chunks(3).all(|p| p[0] == p[1] && p[1] == p[2]),
        "grey"
    );
    let grey: Vec<u8> = pixels.chunks(3).map(|p| p[0]).collect();
    assert_eq!(grey.iter().min(), Some(&0), "darkest pixel is black");
    assert_eq!(grey.iter().max(), Some(&255), "lightest pixel is white");
    // ... and at the grid's lowest and highest points.
    let at = |i: usize| grey[i];
    let argmin = a
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))
        .unwrap()
        .0;
    let argmax = a
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.total_cmp(y.1))
        .unwrap()
        .0;
    assert_eq!((at(argmin), at(argmax)), (0, 255));
    let stats = asperity(&["stats", "a.npy", "--json"], d);
    assert!(stats.status.success());
    let v: serde_json::Value = serde_json::from_slice(&stats.stdout).unwrap();
    assert!((v["stats"]["rms_slope"].as_f64().unwrap() / 0.5 - 1.0).abs() < 1e-10);
}

#[test]
fn stats_writes_psd_and_recovers_hurst_of_a_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(asperity(
        &["line", "--n", "8192", "--hurst", "0.7", "--seed", "2", "--out", "l.npy"],
        d
    )
    .status
    .success());
    let out = asperity(&["stats", "l.npy", "--psd", "psd.csv"], d);
    ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    let hurst: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix("hurst_estimate: "))
        .expect("hurst line")
        .trim()
        .parse()
        .unwrap();
    assert!((hurst - 0.7).abs() < 1e-6, "{text}");
    let psd = std::fs::read_to_string(d.join("psd.csv")).unwrap();
    assert!(psd.starts_with("q,psd,q_l_2pi\n"));
    assert_eq!(psd.lines().count(), 1 + 4096);
}

#[test]
fn bad_input_is_refused_with_one_line_and_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = asperity(
        &["surface", "--n", "32", "--hurst", "3.2", "--out", "x.npy"],
        d,
    );
    assert_refused(&out, d, 0, "hurst");
    // NumPy data is never written into a file named as an image.
    for (command, name) in [("surface", "x.png"), ("line", "x.SVG")] {
        let out = asperity(&[command, "--n", "32", "--hurst", "0.5", "--out", name], d);
        assert_refused(&out, d, 0, "NumPy data");
    }
    for hurst in ["-1.01", "-3"] {
        let out = asperity(
            &["surface", "--n", "32", "--hurst", hurst, "--out", "x.npy"],
            d,
        );
        assert_refused(&out, d, 0, "hurst");
        let out = asperity(
            &["line", "--n", "32", "--hurst", hurst, "--out", "x.npy"],
            d,
        );
        assert_refused(&out, d, 0, "hurst");
    }
    let out = asperity(
        &["surface", "--n", "1", "--hurst", "0.5", "--out", "x.npy"],
        d,
    );
    assert_refused(&out, d, 0, "at least 2");
    let out = asperity(&["line", "--n", "1", "--hurst", "0.5", "--out", "x.npy"], d);
    assert_refused(&out, d, 0, "at least 2");
    let out = asperity(
        &[
            "surface", "--n", "200000", "--hurst", "0.5", "--out", "x.npy",
        ],
        d,
    );
    assert_refused(&out, d, 0, "MiB");
    let out = asperity(
        &[
            "surface",
            "--n",
            "16",
            "--hurst",
            "0.5",
            "--rms-height",
            "-1",
            "--out",
            "x.npy",
        ],
        d,
    );
    assert_refused(&out, d, 0, "rms-height");

    write_npy(d.join("nan.npy"), &array![[0.0, 1.0], [f64::NAN, 2.0]]).unwrap();
    // A complex64 array (dtype <c8): not a real dtype.
    let mut complex = b"\x93NUMPY\x01\x00".to_vec();
    let mut dict = "{'descr': '<c8', 'fortran_order': False, 'shape': (2, 2), }".to_string();
    while !(10 + dict.len() + 1).is_multiple_of(64) {
        dict.push(' ');
    }
    dict.push('\n');
    complex.extend((dict.len() as u16).to_le_bytes());
    complex.extend(dict.as_bytes());
    complex.extend([0u8; 32]);
    std::fs::write(d.join("f32.npy"), complex).unwrap();
    write_npy(
        d.join("cube.npy"),
        &ndarray::Array3::<f64>::zeros((2, 2, 2)),
    )
    .unwrap();
    write_npy(d.join("inf.npy"), &array![[0.0, 1.0], [2.0, f64::INFINITY]]).unwrap();
    write_npy(d.join("ninf.npy"), &array![0.0, f64::NEG_INFINITY, 1.0]).unwrap();
    let n = 5;
    assert_refused(&asperity(&["stats", "nan.npy"], d), d, n, "non-finite");
    assert_refused(&asperity(&["stats", "inf.npy"], d), d, n, "inf");
    assert_refused(&asperity(&["stats", "ninf.npy"], d), d, n, "index 1");
    assert_refused(
        &asperity(&["stats", "f32.npy"], d),
        d,
        n,
        "unsupported .npy dtype '<c8'",
    );
    assert_refused(&asperity(&["stats", "cube.npy"], d), d, n, "3 dimensions");
    assert_refused(&asperity(&["stats", "missing.npy"], d), d, n, "missing.npy");

    assert!(asperity(
        &["surface", "--n", "16", "--hurst", "0.5", "--out", "s.npy"],
        d
    )
    .status
    .success());
    let before = std::fs::read(d.join("s.npy")).unwrap();
    let out = asperity(
        &["surface", "--n", "16", "--hurst", "0.9", "--out", "s.npy"],
        d,
    );
    assert_refused(&out, d, n + 2, "already exists");
    assert_eq!(
        std::fs::read(d.join("s.npy")).unwrap(),
        before,
        "existing output untouched"
    );
    let out = asperity(
        &[
            "surface", "--n", "16", "--hurst", "0.9", "--out", "s.npy", "--force",
        ],
        d,
    );
    assert!(out.status.success());
    assert_ne!(std::fs::read(d.join("s.npy")).unwrap(), before);
}

#[test]
fn a_failing_output_leaves_no_other_output_behind() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = ["surface", "--n", "16", "--hurst", "0.5", "--out", "a.npy"];
    // The image cannot be written (its folder is missing): nor are the array and sidecar.
    let out = asperity(&[&base[..], &["--png", "missing/a.png"]].concat(), d);
    assert_refused(&out, d, 0, "does not exist");
    let absolute = d.join("nowhere").join("a.png");
    let out = asperity(
        &[&base[..], &["--png", absolute.to_str().unwrap()]].concat(),
        d,
    );
    assert_refused(&out, d, 0, "does not exist");
    // The image would overwrite the array or its sidecar (also with --force).
    for twin in ["a.npy", "./a.npy", "a.npy.json"] {
        let out = asperity(&[&base[..], &["--png", twin]].concat(), d);
        assert_refused(&out, d, 0, "same file");
        let out = asperity(&[&base[..], &["--png", twin, "--force"]].concat(), d);
        assert_refused(&out, d, 0, "same file");
    }
    // An output that is a folder.
    std::fs::create_dir(d.join("folder.png")).unwrap();
    let out = asperity(
        &[&base[..], &["--png", "folder.png", "--force"]].concat(),
        d,
    );
    assert_refused(&out, d, 1, "is a folder");
    let out = asperity(
        &["line", "--n", "16", "--hurst", "0.5", "--out", "no/l.npy"],
        d,
    );
    assert_refused(&out, d, 1, "does not exist");
    // stats --psd: into a missing folder, or over its own input.
    assert!(asperity(&base, d).status.success());
    let out = asperity(&["stats", "a.npy", "--psd", "no/psd.csv"], d);
    assert_refused(&out, d, 3, "does not exist");
    let before = std::fs::read(d.join("a.npy")).unwrap();
    let out = asperity(&["stats", "a.npy", "--psd", "a.npy", "--force"], d);
    assert_refused(&out, d, 3, "input");
    assert_eq!(std::fs::read(d.join("a.npy")).unwrap(), before);
    // ... or over the input's sidecar (its size and generating parameters).
    let sidecar = std::fs::read(d.join("a.npy.json")).unwrap();
    for psd in ["a.npy.json", "./a.npy.json"] {
        let out = asperity(&["stats", "a.npy", "--psd", psd, "--force"], d);
        assert_refused(&out, d, 3, "is the sidecar a.npy.json of the input a.npy");
    }
    assert_eq!(std::fs::read(d.join("a.npy.json")).unwrap(), sidecar);
}

#[test]
fn memory_guard_refuses_before_writing_anything() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let limit = [("ASPERITY_MEMORY_LIMIT_MIB", "1")];
    let args = [
        "surface", "--n", "2048", "--hurst", "0.5", "--out", "big.npy", "--png", "big.png",
    ];
    let out = asperity_env(&args, d, &limit);
    assert_refused(&out, d, 0, "memory");
    let err = stderr(&out);
    assert!(
        err.contains("128 MiB") && err.contains("ASPERITY_MEMORY_LIMIT_MIB"),
        "{err}"
    );
    let out = asperity_env(
        &["line", "--n", "1048576", "--hurst", "0.5", "--out", "l.npy"],
        d,
        &limit,
    );
    assert_refused(&out, d, 0, "memory");
    // A malformed limit is an error, not ignored.
    let out = asperity_env(&args, d, &[("ASPERITY_MEMORY_LIMIT_MIB", "lots")]);
    assert_refused(&out, d, 0, "ASPERITY_MEMORY_LIMIT_MIB");
    // stats checks the need from the header, before reading: about 4x the file for the
    // heights and the spectrum, and since the ring sums are counted (issue 33 item 14)
    // their blocks too, 6 MiB for this 1 MiB file.
    write_npy(d.join("s.npy"), &Array2::<f64>::zeros((256, 512))).unwrap();
    let out = asperity_env(&["stats", "s.npy", "--psd", "psd.csv"], d, &limit);
    assert_refused(&out, d, 1, "memory");
    assert!(stderr(&out).contains("6 MiB"), "{}", stderr(&out));
    // A generous limit changes nothing.
    let out = asperity_env(
        &["surface", "--n", "64", "--hurst", "0.5", "--out", "ok.npy"],
        d,
        &[("ASPERITY_MEMORY_LIMIT_MIB", "100000")],
    );
    ok(&out);
}

#[test]
fn memory_guard_sees_the_address_space_limit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let exe = env!("CARGO_BIN_EXE_asperity");
    // `ulimit -v` (RLIMIT_AS, in KiB): 400 MiB cannot hold a 4096² surface (512 MiB).
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 409600 && exec '{exe}' surface --n 4096 --hurst 0.5 --out big.npy"
        ))
        .current_dir(d)
        .output()
        .expect("run sh");
    assert_refused(&out, d, 0, "RLIMIT_AS");
}

#[test]
fn huge_grids_exceed_addressable_memory() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = asperity(
        &[
            "surface",
            "--n",
            "4294967296",
            "--m",
            "4294967296",
            "--hurst",
            "0.5",
            "--out",
            "x.npy",
        ],
        d,
    );
    assert_refused(&out, d, 0, "exceeds addressable memory");
    assert!(!stderr(&out).contains("18446744073709551615"));
}

/// `asperity stats --json` of `file` with extra arguments, parsed.
fn stats_json(d: &Path, file: &str, extra: &[&str]) -> serde_json::Value {
    let out = asperity(&[&["stats", file, "--json"], extra].concat(), d);
    ok(&out);
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn stats_fit_range_follows_the_sidecar_spectrum() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let generate = |extra: &[&str], out: &str| {
        let base = ["surface", "--n", "512", "--hurst", "0.8", "--seed", "4"];
        let o = asperity(&[&base[..], extra, &["--out", out]].concat(), d);
        ok(&o);
    };
    let slope_ok = |v: &serde_json::Value| {
        let slope = v["psd_slope"].as_f64().unwrap();
        assert!((slope + 3.6).abs() < 0.05, "slope {slope}: {v}");
    };
    // A short cut-off caps the default fit at the last full ring below it (was -27.98).
    generate(&["--short-cutoff", "64"], "short.npy");
    let v = stats_json(d, "short.npy", &[]);
    assert_eq!(v["fit_from"], 2.0);
    assert_eq!(v["fit_to"], 63.0);
    slope_ok(&v);
    // A cut-off: the ring at q0 is half empty, so the default fit starts at q0 + 1.
    generate(&["--cutoff", "6"], "cut.npy");
    let v = stats_json(d, "cut.npy", &[]);
    assert_eq!(v["fit_from"], 7.0);
    assert_eq!(v["fit_to"], 256.0, "Nyquist, as a number");
    slope_ok(&v);
    // A roll-off: from the knee q0 (as before).
    generate(&["--rolloff", "6", "--short-cutoff", "100.7"], "roll.npy");
    let v = stats_json(d, "roll.npy", &[]);
    assert_eq!(v["fit_from"], 6.0);
    assert_eq!(v["fit_to"], 100.0);
    slope_ok(&v);
    // No sidecar: 2 to Nyquist; user bounds are used as given.
    std::fs::copy(d.join("cut.npy"), d.join("bare.npy")).unwrap();
    let v = stats_json(d, "bare.npy", &[]);
    assert_eq!(
        (v["fit_from"].as_f64(), v["fit_to"].as_f64()),
        (Some(2.0), Some(256.0))
    );
    let v = stats_json(d, "short.npy", &["--fit-from", "4", "--fit-to", "40"]);
    assert_eq!(
        (v["fit_from"].as_f64(), v["fit_to"].as_f64()),
        (Some(4.0), Some(40.0))
    );
    slope_ok(&v);
}

#[test]
fn stats_refuses_nonsense_fit_ranges() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(asperity(
        &[
            "surface",
            "--n",
            "64",
            "--hurst",
            "0.5",
            "--short-cutoff",
            "10",
            "--out",
            "s.npy"
        ],
        d
    )
    .status
    .success());
    for (args, needle) in [
        (&["--fit-from", "nan"][..], "--fit-from"),
        (&["--fit-to", "inf"][..], "--fit-to"),
        (&["--fit-from", "-3"][..], "--fit-from"),
        (&["--fit-to", "0"][..], "--fit-to"),
        (&["--fit-from", "50", "--fit-to", "10"][..], "below"),
        (&["--fit-from", "5", "--fit-to", "5"][..], "below"),
        // Above the sidecar's short cut-off (default upper end 9): the flag given is named.
        (
            &["--fit-from", "20"][..],
            "invalid --fit-from 20: the PSD fit range would be empty",
        ),
        // Beyond Nyquist (32), with --fit-to clamped to it.
        (
            &["--fit-from", "40", "--fit-to", "1000"][..],
            "invalid --fit-from 40",
        ),
        // Below the default lower end 2.
        (
            &["--fit-to", "1.5"][..],
            "invalid --fit-to 1.5: the PSD fit range would be empty",
        ),
    ] {
        let out = asperity(&[&["stats", "s.npy"], args].concat(), d);
        assert_refused(&out, d, 2, needle);
    }
}

#[test]
fn an_existing_sidecar_or_png_alone_is_not_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = ["surface", "--n", "16", "--hurst", "0.5", "--out", "a.npy"];
    // Only the sidecar exists (the array was deleted): refused, the sidecar kept.
    std::fs::write(d.join("a.npy.json"), b"{\"mine\": true}").unwrap();
    let out = asperity(&base, d);
    assert_refused(&out, d, 1, "a.npy.json: output already exists");
    assert_eq!(
        std::fs::read(d.join("a.npy.json")).unwrap(),
        b"{\"mine\": true}"
    );
    let out = asperity(
        &["line", "--n", "16", "--hurst", "0.5", "--out", "a.npy"],
        d,
    );
    assert_refused(&out, d, 1, "a.npy.json: output already exists");
    std::fs::remove_file(d.join("a.npy.json")).unwrap();
    // Only the PNG exists.
    std::fs::write(d.join("a.png"), b"not mine to overwrite").unwrap();
    let out = asperity(&[&base[..], &["--png", "a.png"]].concat(), d);
    assert_refused(&out, d, 1, "a.png: output already exists");
    assert_eq!(
        std::fs::read(d.join("a.png")).unwrap(),
        b"not mine to overwrite"
    );
    // With --force all three are written.
    let out = asperity(&[&base[..], &["--png", "a.png", "--force"]].concat(), d);
    ok(&out);
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 3);
    assert_ne!(
        std::fs::read(d.join("a.png")).unwrap(),
        b"not mine to overwrite"
    );
}

#[test]
fn stats_plots_the_psd_with_its_fit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let surface = [
        "surface",
        "--n",
        "64",
        "--hurst",
        "0.8",
        "--rolloff",
        "4",
        "--seed",
        "1",
        "--out",
        "s.npy",
    ];
    assert!(asperity(&surface, d).status.success());
    let line = ["line", "--n", "1024", "--hurst", "0.5", "--out", "l.npy"];
    assert!(asperity(&line, d).status.success());
    let out = asperity(
        &["stats", "s.npy", "--psd", "psd.csv", "--plot", "s.png"],
        d,
    );
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stdout).contains("psd_slope: "));
    let decoder = png::Decoder::new(std::fs::File::open(d.join("s.png")).unwrap());
    let reader = decoder.read_info().unwrap();
    assert!(reader.info().width > 0 && reader.info().height > 0);
    assert!(d.join("psd.csv").exists());
    let out = asperity(&["stats", "l.npy", "--json", "--plot", "l.svg"], d);
    ok(&out);
    let value: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let slope = value["psd_slope"].as_f64().unwrap();
    let svg = std::fs::read_to_string(d.join("l.svg")).unwrap();
    assert!(svg.contains("<svg"));
    // The legend gives the fitted slope.
    assert!(
        svg.contains(&format!("slope {slope:.3}")),
        "slope {slope:.3}"
    );
    // s.npy, l.npy, their sidecars, psd.csv, s.png, l.svg: no temporary files.
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 7);
}

#[test]
fn stats_refuses_bad_plots_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let heights = Array2::from_shape_fn((16, 16), |(i, j)| ((i * 7 + j * 3) % 5) as f64);
    write_npy(d.join("s.npy"), &heights).unwrap();
    std::fs::write(d.join("old.png"), b"keep me").unwrap();
    for (plot, needle) in [
        ("psd.jpg", "must be .png or .svg"),
        ("psd", "must be .png or .svg"),
        ("s.npy", "must be .png or .svg"),
        ("old.png", "old.png: output already exists"),
    ] {
        let out = asperity(&["stats", "s.npy", "--psd", "psd.csv", "--plot", plot], d);
        assert_refused(&out, d, 2, needle);
        // Checked before the input is read: a missing input is not what is reported.
        let out = asperity(&["stats", "missing.npy", "--plot", plot], d);
        assert_refused(&out, d, 2, needle);
    }
    assert_eq!(std::fs::read(d.join("old.png")).unwrap(), b"keep me");
    let out = asperity(
        &[
            "stats", "s.npy", "--plot", "old.png", "--psd", "psd.csv", "--force",
        ],
        d,
    );
    ok(&out);
    assert_ne!(std::fs::read(d.join("old.png")).unwrap(), b"keep me");
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 3);
    // A flat surface has no power to show on log axes: one line, nothing written.
    write_npy(d.join("flat.npy"), &Array2::<f64>::ones((16, 16))).unwrap();
    let out = asperity(
        &[
            "stats", "flat.npy", "--psd", "flat.csv", "--plot", "flat.png",
        ],
        d,
    );
    assert_refused(&out, d, 4, "nothing to show");
}

#[test]
fn stats_help_has_a_plot_example() {
    let dir = tempfile::tempdir().unwrap();
    let out = asperity(&["stats", "--help"], dir.path());
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("asperity stats s.npy --plot psd.png"),
        "{text}"
    );
}

#[test]
fn stats_psd_columns_state_their_units() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (make, file) in [
        (
            &[
                "surface", "--n", "48", "--m", "32", "--hurst", "0.6", "--size", "3",
            ][..],
            "s.npy",
        ),
        (
            &["line", "--n", "256", "--hurst", "0.6", "--size", "3"][..],
            "l.npy",
        ),
    ] {
        let out = asperity(&[make, &["--out", file]].concat(), d);
        ok(&out);
        let csv = format!("{file}.csv");
        let out = asperity(&["stats", file, "--psd", &csv], d);
        ok(&out);
        let text = std::fs::read_to_string(d.join(&csv)).unwrap();
        let mut lines = text.lines();
        // The contract's q,psd first; q_l_2pi appended.
        assert_eq!(lines.next(), Some("q,psd,q_l_2pi"));
        let mut rows = 0;
        for line in lines {
            let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
            let want = v[0] * 3.0 / std::f64::consts::TAU;
            assert!((v[2] / want - 1.0).abs() < 1e-14, "{line}");
            rows += 1;
        }
        assert!(rows > 10);
    }
    let help = asperity(&["stats", "--help"], d);
    let help = String::from_utf8_lossy(&help.stdout);
    for unit in [
        "radians per unit length",
        "wavelengths per side",
        "q_l_2pi",
        "length⁴",
    ] {
        assert!(help.contains(unit), "{unit}: {help}");
    }
}

#[test]
fn stats_fit_range_is_clamped_and_an_empty_default_is_no_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let make = |extra: &[&str], out: &str| {
        let base = ["surface", "--n", "128", "--hurst", "0.8", "--seed", "5"];
        let o = asperity(&[&base[..], extra, &["--out", out]].concat(), d);
        ok(&o);
    };
    make(&["--rolloff", "6"], "s.npy");
    // --fit-to beyond Nyquist (64) is clamped, and said so.
    let v = stats_json(d, "s.npy", &["--fit-to", "1000"]);
    assert_eq!(v["fit_to"], 64.0);
    assert!(v["fit_note"].as_str().unwrap().contains("clamped"), "{v}");
    assert!(v["psd_slope"].as_f64().is_some());
    let out = asperity(&["stats", "s.npy", "--fit-to", "1000"], d);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("64 (Nyquist; --fit-to 1000 clamped to it)"),
        "{text}"
    );
    assert!(!text.contains("1000 (Nyquist)"), "{text}");
    // Within range: no note.
    assert!(stats_json(d, "s.npy", &["--fit-to", "40"])["fit_note"].is_null());
    // Defaults that leave no range: the statistics, psd_slope n/a and the cause; exit 0.
    // `surface` refuses a roll-off beyond Nyquist; a sidecar from elsewhere may claim one.
    make(&["--rolloff", "6"], "high.npy");
    let sidecar = d.join("high.npy.json");
    let text = std::fs::read_to_string(&sidecar).unwrap();
    assert!(text.contains("\"q0\": 6.0"), "{text}");
    std::fs::write(&sidecar, text.replace("\"q0\": 6.0", "\"q0\": 100.0")).unwrap();
    make(&[], "tiny.npy");
    let tiny = Array2::from_shape_fn((2, 2), |(i, j)| (i * 2 + j) as f64 * 0.3);
    write_npy(d.join("tiny.npy"), &tiny).unwrap();
    std::fs::remove_file(d.join("tiny.npy.json")).unwrap();
    for (file, cause) in [
        (
            "high.npy",
            "from 100 (the sidecar's roll-off q0 = 100) to 64 (Nyquist)",
        ),
        ("tiny.npy", "from 2 (the default lower end) to 1 (Nyquist)"),
    ] {
        let out = asperity(&["stats", file], d);
        assert!(out.status.success(), "{file}: {}", stderr(&out));
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            text.contains("rms_height: ") && text.contains("rms_slope: "),
            "{text}"
        );
        let line = text.lines().find(|l| l.starts_with("psd_slope")).unwrap();
        assert!(
            line.starts_with("psd_slope: n/a (") && line.contains(cause),
            "{line}"
        );
        let v = stats_json(d, file, &[]);
        assert!(v["psd_slope"].is_null() && v["fit_from"].is_null(), "{v}");
        assert!(v["fit_note"].as_str().unwrap().contains(cause), "{v}");
        // Outputs are still written (the PSD, its plot without a fit).
        let out = asperity(&["stats", file, "--psd", &format!("{file}.csv")], d);
        ok(&out);
    }
    // A given --fit-from beyond Nyquist is an error naming it.
    let out = asperity(&["stats", "s.npy", "--fit-from", "100"], d);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("invalid --fit-from 100"),
        "{}",
        stderr(&out)
    );
}

/// `surface --plot`: the height map's figure (one definition with Python's
/// `asperity.plot.surface`): as data, the cells are the heights written, over the
/// surface's sizes, with a scale bar; as PNG and SVG, drawn; any other extension refused
/// before anything is written.
#[test]
fn surface_plot_is_the_height_map_with_its_scale_bar() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = [
        "surface", "--n", "40", "--m", "24", "--hurst", "0.7", "--size", "2", "--seed", "3",
    ];
    ok(&asperity(
        &[&base[..], &["--out", "s.npy", "--plot", "s.json"]].concat(),
        d,
    ));
    let heights: Array2<f64> = read_npy(d.join("s.npy")).unwrap();
    let figure: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("s.json")).unwrap()).unwrap();
    assert_eq!(figure["format"], "asperity-figure/1");
    let image = &figure["charts"][0]["series"][0]["image"];
    assert_eq!(
        (image["rows"].as_u64(), image["cols"].as_u64()),
        (Some(24), Some(40))
    );
    assert_eq!(image["extent"], serde_json::json!([2.0, 1.2]));
    let cells: Vec<f64> = image["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(cells, heights.iter().copied().collect::<Vec<f64>>());
    assert_eq!(image["scale_bar"]["label"], "0.2");
    for plot in ["p.png", "p.svg"] {
        let out = asperity(
            &[&base[..], &["--out", "t.npy", "--plot", plot, "--force"]].concat(),
            d,
        );
        ok(&out);
        assert!(std::fs::metadata(d.join(plot)).unwrap().len() > 1000);
    }
    let before = std::fs::read_dir(d).unwrap().count();
    let out = asperity(
        &[&base[..], &["--out", "u.npy", "--plot", "u.jpg"]].concat(),
        d,
    );
    assert_refused(&out, d, before, "--plot u.jpg");
}

/// A negative grid size of `surface`, `line` and `mdr --profile`, and a negative number of
/// points of a tangential cycle: refused in the front-end layer's words (the same as
/// Python's, python/tests/test_rules.py; clap said "invalid digit found in string" before),
/// nothing written.
#[test]
fn negative_counts_are_refused_in_the_front_end_layers_words() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let hertz = ["mdr", "--profile", "hertz", "--radius", "1", "--dx", "0.01"];
    let slip = [
        "--n",
        "401",
        "--indentations",
        "1",
        "--tangential-force",
        "0.1",
    ];
    let cases: [(Vec<&str>, &str); 5] = [
        (
            vec!["surface", "--n", "-16", "--hurst", "0.5", "--out", "x.npy"],
            "--n must be at least 1, got -16",
        ),
        (
            vec![
                "surface", "--n", "16", "--m", "-3", "--hurst", "0.5", "--out", "x.npy",
            ],
            "--m must be at least 1, got -3",
        ),
        (
            vec!["line", "--n", "-8", "--hurst", "0.5", "--out", "x.npy"],
            "--n must be at least 1, got -8",
        ),
        (
            [&hertz[..], &["--n", "-11", "--out", "x.csv"]].concat(),
            "--n must be at least 1, got -11",
        ),
        (
            [
                &hertz[..],
                &slip,
                &["--friction", "0.5", "--cycle-points", "-3"],
            ]
            .concat(),
            "invalid --cycle-points: a branch needs at least 2 points, got -3",
        ),
    ];
    for (args, words) in cases {
        let out = asperity(&args, d);
        assert_eq!(stderr(&out).trim(), format!("error: {words}"), "{args:?}");
        assert_refused(&out, d, 0, words);
    }
}
