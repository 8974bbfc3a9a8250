//! `asperity bem --work-of-adhesion` through the real binary: the pixel criterion's loop
//! and pull-offs on a sphere, and its refusals.

use std::path::{Path, PathBuf};
use std::process::Output;

use ndarray::Array2;
use ndarray_npy::write_npy;

mod common;
use common::{ok, refused, run_asperity as asperity, stderr};

/// A sphere R = 1 on 64² pixels of 5e-3 (L = 0.32), peak at pixel (32, 32).
fn sphere(dir: &Path) -> PathBuf {
    let (n, dx) = (64, 5e-3);
    let heights = Array2::from_shape_fn((n, n), |(i, j)| {
        let (y, x) = ((i as f64 - 32.0) * dx, (j as f64 - 32.0) * dx);
        -(x * x + y * y) / 2.0
    });
    let path = dir.join("sphere.npy");
    write_npy(&path, &heights).unwrap();
    path
}

/// w for JKR's force-controlled pull-off radius a_c = 0.1 (20 pixels) on the sphere:
/// w = 8 a_c³ E*/(9π R) with R = E* = 1.
fn work_of_adhesion() -> f64 {
    8.0 * 0.1f64.powi(3) / (9.0 * std::f64::consts::PI)
}

/// `bem --work-of-adhesion` on the sphere along 10 indentations up to 0.015625, with the
/// `extra` flags, into `csv`.
fn adhesive_run(dir: &Path, csv: &Path, extra: &[&str]) -> Output {
    let s = sphere(dir);
    let path: Vec<String> = (1..=10)
        .map(|k| format!("{}", 0.015625 * k as f64 / 10.0))
        .collect();
    let (w, path) = (work_of_adhesion().to_string(), path.join(","));
    let mut args = vec!["bem", "--surface", s.to_str().unwrap(), "--size", "0.32"];
    args.extend(["--work-of-adhesion", &w]);
    args.extend_from_slice(extra);
    args.extend(["--indentations", &path, "--out", csv.to_str().unwrap()]);
    asperity(&args)
}

#[test]
fn a_sphere_gives_the_loop_and_jkrs_pull_off_to_the_criterions_accuracy() {
    // w chosen so that JKR's force-controlled pull-off radius is a_c = 0.1 = 20 pixels: the
    // criterion's first-order error there is +6.9 % (library tests), checked here to 8 %.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("loop.csv");
    let w = work_of_adhesion();
    let out = adhesive_run(dir.path(), &csv, &[]);
    ok(&out);
    assert!(
        stderr(&out).contains("pull-off: force control F = "),
        "{}",
        stderr(&out)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "indentation,force,mean_pressure,area_fraction,tensile_fraction,rounds,cg_iterations,branch"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.iter().filter(|r| r[7] == "path").count(), 10);
    assert!(rows.iter().skip(10).all(|r| r[7] == "retract"));
    let least = rows
        .iter()
        .map(|r| r[1].parse::<f64>().unwrap())
        .fold(0.0, f64::min);
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("loop.csv.json")).unwrap())
            .unwrap();
    let pull = &record["adhesion"]["pull_off"];
    let force = pull["force_controlled"]["force"].as_f64().unwrap();
    assert!(force <= least, "{force} {least}");
    let jkr = -1.5 * std::f64::consts::PI * w;
    assert!((force / jkr - 1.0).abs() < 0.08, "{force} vs {jkr}");
    let displaced = pull["displacement_controlled"]["force"].as_f64().unwrap();
    assert!(displaced < 0.0 && displaced > force);
}

#[test]
fn a_cohesive_zone_gives_maugis_pull_off() {
    // The sphere of the test above at Maugis parameter λ = 1 (range h₀ = wλ₁, λ₁ the λ of a
    // unit stress): the library measures +1.78 % against Maugis's −1.6007πwR at 20 pixels
    // (with a finer retraction step); checked to 3 %, and the record names the model.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("md.csv");
    let w = work_of_adhesion();
    let unit_lambda = 2.0 * (1.0 / (std::f64::consts::PI * w * (4.0f64 / 3.0).powi(2))).cbrt();
    let range = (w * unit_lambda).to_string();
    let out = adhesive_run(dir.path(), &csv, &["--adhesion-range", &range]);
    ok(&out);
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("md.csv.json")).unwrap())
            .unwrap();
    let adhesion = &record["adhesion"];
    assert_eq!(adhesion["model"], "Maugis–Dugdale cohesive zone");
    assert!(adhesion["zone_resolution"].as_f64().unwrap() > 10.0);
    let force = adhesion["pull_off"]["force_controlled"]["force"]
        .as_f64()
        .unwrap();
    let maugis = -1.6007 * std::f64::consts::PI * w;
    assert!((force / maugis - 1.0).abs() < 0.03, "{force} vs {maugis}");
}

#[test]
fn an_exponential_potential_is_between_dmt_and_jkr() {
    // The sphere of the tests above at Tabor's μ = 1 (ρ = (Rw²/E*²)^{1/3}, resolution 14):
    // the library measures −1.664πwR on a grid that holds gaps to 15ρ; this 64² grid holds
    // them to about 3ρ only and cuts up to e⁻³ of the tail's pull (DMT's share), so only the
    // band between JKR's −1.5πwR and DMT's −2πwR less that is checked. The record names the
    // model.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("exp.csv");
    let w = work_of_adhesion();
    let range = w.powf(2.0 / 3.0).to_string();
    let model = [
        "--adhesion-range",
        &range,
        "--adhesion-model",
        "exponential",
    ];
    let out = adhesive_run(dir.path(), &csv, &model);
    ok(&out);
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("exp.csv.json")).unwrap())
            .unwrap();
    let adhesion = &record["adhesion"];
    assert_eq!(adhesion["model"], "exponential potential");
    let force = adhesion["pull_off"]["force_controlled"]["force"]
        .as_f64()
        .unwrap();
    let expected = -1.664 * std::f64::consts::PI * w;
    assert!(
        (force / expected - 1.0).abs() < 0.03,
        "{force} vs {expected}"
    );
}

#[test]
fn meaningless_adhesive_requests_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let s = sphere(dir.path());
    let s = s.to_str().unwrap();
    let csv = dir.path().join("x.csv");
    let out_flag = csv.to_str().unwrap();
    let cases: [(&[&str], &str); 12] = [
        (
            &["--work-of-adhesion", "-1e-3", "--indentations", "0.01"],
            "invalid --work-of-adhesion",
        ),
        (
            &["--work-of-adhesion", "inf", "--indentations", "0.01"],
            "invalid --work-of-adhesion",
        ),
        (
            &["--work-of-adhesion", "1e-3", "--pressures", "0.01"],
            "does not go with --pressures",
        ),
        (
            &["--work-of-adhesion", "1e-3", "--indentations", "0,-0.01"],
            "never press the surface",
        ),
        (
            &[
                "--work-of-adhesion",
                "1e-3",
                "--indentations",
                "0.01",
                "--retract-step",
                "0",
            ],
            "--retract-step must be positive",
        ),
        (
            &["--retract-step", "1e-3", "--indentations", "0.01"],
            "goes with --work-of-adhesion",
        ),
        (
            &["--adhesion-range", "1e-3", "--indentations", "0.01"],
            "--adhesion-range goes with --work-of-adhesion",
        ),
        (
            &[
                "--work-of-adhesion",
                "1e-3",
                "--adhesion-range",
                "-1",
                "--indentations",
                "0.01",
            ],
            "invalid --adhesion-range",
        ),
        (
            // One pixel's Dugdale stress (1e-3/1e-9) would close far more than the range.
            &[
                "--work-of-adhesion",
                "1e-3",
                "--adhesion-range",
                "1e-9",
                "--indentations",
                "0.01",
            ],
            "spans no pixel",
        ),
        (
            &["--adhesion-model", "exponential", "--indentations", "0.01"],
            "--adhesion-model goes with --work-of-adhesion",
        ),
        (
            &[
                "--work-of-adhesion",
                "1e-3",
                "--adhesion-model",
                "exponential",
                "--indentations",
                "0.01",
            ],
            "--adhesion-model needs --adhesion-range",
        ),
        (
            &[
                "--work-of-adhesion",
                "1e-3",
                "--adhesion-range",
                "1e-3",
                "--adhesion-model",
                "lennard-jones",
                "--indentations",
                "0.01",
            ],
            "invalid --adhesion-model",
        ),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["bem", "--surface", s, "--out", out_flag];
        args.extend_from_slice(extra);
        refused(&asperity(&args), needle);
        assert!(!csv.exists());
    }
    // Rectangular pixels: the criterion's σ_c is for square ones.
    let out = asperity(&[
        "bem",
        "--surface",
        s,
        "--size",
        "0.32,0.16",
        "--work-of-adhesion",
        "1e-3",
        "--indentations",
        "0.01",
        "--out",
        out_flag,
    ]);
    refused(&out, "square pixels");
    assert!(!csv.exists());
}
