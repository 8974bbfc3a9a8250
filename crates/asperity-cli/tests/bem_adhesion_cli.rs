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

/// The cells of a CSV: the header, then each row's cells.
fn cells(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text
        .lines()
        .map(|l| l.split(',').map(String::from).collect());
    let header = lines.next().unwrap();
    (header, lines.collect())
}

/// `contact --work-of-adhesion` in SI units is `bem --work-of-adhesion` in model units,
/// scaled: the sphere of the tests above with every length times ℓ = 2⁻¹⁰ m, E* = 2³⁰ Pa,
/// Δγ times E*ℓ (J/m²), a range times ℓ. Powers of two scale every product exactly, so
/// the critical stress and the indentations are the same and the pixel sets of every row;
/// the forces agree to 1e-8 of the largest only: the Love kernel's near field takes
/// logarithms of the pixel's dimensional coordinates (`elastic::love`: `x ln(y + r)` terms
/// whose ln ℓ parts cancel only to rounding), and that rounding moves the CG's iterates,
/// which stop at the solver's tolerance (1e-10 relative residual): measured 8.7e-11
/// relative on the pixel criterion. Both laws tried: the
/// pixel criterion and the exponential potential. The record is in SI units.
#[test]
fn contact_adhesion_in_si_units_is_bems_run_scaled() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (ell, e_star) = (2f64.powi(-10), 2f64.powi(30));
    let model = sphere(d);
    let heights: Array2<f64> = ndarray_npy::read_npy(&model).unwrap();
    write_npy(d.join("si.npy"), &heights.mapv(|h| h * ell)).unwrap();
    let w = work_of_adhesion();
    let path: Vec<f64> = (1..=10).map(|k| 0.015625 * k as f64 / 10.0).collect();
    let list = |scale: f64| -> String {
        let v: Vec<String> = path.iter().map(|x| format!("{:?}", x * scale)).collect();
        v.join(",")
    };
    let range = w.powf(2.0 / 3.0);
    for law in [None, Some(range)] {
        let mut bem_extra: Vec<String> = vec![];
        let mut si_extra: Vec<String> = vec![];
        if let Some(rho) = law {
            bem_extra.extend(["--adhesion-range".into(), format!("{rho:?}")]);
            si_extra.extend(["--adhesion-range".into(), format!("{:?}", rho * ell)]);
            for extra in [&mut bem_extra, &mut si_extra] {
                extra.extend(["--adhesion-model".into(), "exponential".into()]);
            }
        }
        let mut bem = vec![
            "bem",
            "--surface",
            model.to_str().unwrap(),
            "--size",
            "0.32",
        ];
        let (w_model, path_model) = (format!("{w:?}"), list(1.0));
        bem.extend([
            "--work-of-adhesion",
            &w_model,
            "--indentations",
            &path_model,
        ]);
        bem.extend(bem_extra.iter().map(String::as_str));
        bem.extend(["--out", "m.csv", "--force"]);
        ok(&common::asperity(&bem, d));
        let (size, modulus) = (format!("{:?}", 0.32 * ell), format!("{e_star:?}"));
        let (w_si, path_si) = (format!("{:?}", w * e_star * ell), list(ell));
        let mut si = vec!["contact", "si.npy", "--size", &size, "--detrend", "none"];
        si.extend(["--modulus", &modulus, "--work-of-adhesion", &w_si]);
        si.extend(["--indentations", &path_si]);
        si.extend(si_extra.iter().map(String::as_str));
        si.extend(["--out", "s.csv", "--plot", "s.json", "--force"]);
        let out = common::asperity(&si, d);
        ok(&out);
        assert!(stderr(&out).contains(" N at d = "), "{}", stderr(&out));
        // The loop's figure: arrows both ways, the pull-offs named in newtons.
        let figure: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("s.json")).unwrap()).unwrap();
        let series = figure["charts"][0]["series"].as_array().unwrap();
        let styles: Vec<&str> = series
            .iter()
            .map(|s| s["style"].as_str().unwrap())
            .collect();
        assert_eq!(
            styles.iter().filter(|s| **s == "arrows").count(),
            2,
            "{styles:?}"
        );
        assert!(series.iter().any(|s| {
            let label = s["label"].as_str().unwrap();
            label.starts_with("pull-off, force control: F = ") && label.ends_with(" N")
        }));
        let (m_head, m_rows) = cells(&d.join("m.csv"));
        let (s_head, s_rows) = cells(&d.join("s.csv"));
        assert_eq!(
            s_head,
            [
                "indentation_m",
                "force_n",
                "mean_pressure_pa",
                "contact_area_m2",
                "area_fraction",
                "tensile_fraction",
                "rounds",
                "cg_iterations",
                "branch"
            ]
        );
        assert_eq!(m_head[0], "indentation");
        assert_eq!(m_rows.len(), s_rows.len(), "{law:?}");
        let num = |s: &str| s.parse::<f64>().unwrap();
        let largest = m_rows.iter().map(|r| num(&r[1]).abs()).fold(0.0, f64::max);
        let pixel_area = (5e-3 * ell) * (5e-3 * ell);
        for (m, s) in m_rows.iter().zip(&s_rows) {
            assert_eq!(num(&s[0]), num(&m[0]) * ell, "indentation");
            let force = num(&m[1]) * e_star * ell * ell;
            assert!(
                (num(&s[1]) - force).abs() <= 1e-8 * largest * e_star * ell * ell,
                "{law:?}: {} vs {force}",
                s[1]
            );
            let (fraction, points) = (num(&s[4]), 64.0 * 64.0);
            assert_eq!((fraction, &s[5], &s[8]), (num(&m[3]), &m[4], &m[7]));
            assert_eq!(num(&s[3]), (fraction * points).round() * pixel_area);
            assert!(s[6].parse::<usize>().unwrap() >= 1 && s[7].parse::<usize>().unwrap() > 0);
        }
        let record: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("s.csv.json")).unwrap()).unwrap();
        let model: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("m.csv.json")).unwrap()).unwrap();
        let (a, m) = (&record["adhesion"], &model["adhesion"]);
        assert_eq!(record["effective_modulus_pa"].as_f64(), Some(e_star));
        let sigma = m["critical_stress"].as_f64().unwrap() * e_star;
        assert!((a["critical_stress_pa"].as_f64().unwrap() / sigma - 1.0).abs() < 1e-14);
        let f_si = a["pull_off"]["force_controlled"]["force_n"]
            .as_f64()
            .unwrap();
        let f_model = m["pull_off"]["force_controlled"]["force"].as_f64().unwrap();
        assert!(
            (f_si / (f_model * e_star * ell * ell) - 1.0).abs() < 1e-8,
            "{f_si} {f_model}"
        );
    }
}

#[test]
fn contact_adhesion_refuses_mixed_requests_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sphere(d);
    let base = ["contact", "sphere.npy", "--size", "0.32", "--modulus", "1"];
    let cases: [(&[&str], &str); 4] = [
        (
            &["--work-of-adhesion", "1e-3", "--pressures", "0.01", "--indentations", "0.01"],
            "--work-of-adhesion takes a path of --indentations (m; solved under displacement control, both pull-offs reported) and does not go with --pressures",
        ),
        (&["--work-of-adhesion", "1e-3"], "--work-of-adhesion needs --indentations"),
        (
            &["--pressures", "0.01", "--adhesion-range", "1e-3"],
            "--adhesion-range needs --work-of-adhesion (J/m²): it belongs to an adhesive run",
        ),
        (
            &["--work-of-adhesion", "0", "--indentations", "0.01"],
            "invalid --work-of-adhesion",
        ),
    ];
    for (extra, needle) in cases {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        refused(&common::asperity(&args, d), needle);
    }
}

/// `mdr --work-of-adhesion --plot FILE.json` draws the loop of the one figure definition:
/// the JKR sphere approached in 30 steps then retracted event by event (a row before and
/// after each release, at one approach): one loading run and one unloading run, so one
/// arrow each, pointing up and down the approach; the pull-off markers are the record's.
#[test]
fn contact_adhesion_loops_have_one_arrow_per_run_in_the_mdr_too() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let path = ["--nloads", "30", "--dmax", "0.09"];
    let outputs = ["--out", "j.csv", "--plot", "j.json"];
    let args = [&common::JKR_SPHERE_MDR[..], &path, &outputs].concat();
    ok(&common::asperity(&args, d));
    let read = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.join(name)).unwrap()).unwrap()
    };
    let figure = read("j.json");
    let series = figure["charts"][0]["series"].as_array().unwrap();
    let named = |label: &str| {
        series
            .iter()
            .find(|s| s["label"].as_str().unwrap().starts_with(label))
            .unwrap_or_else(|| panic!("no series {label}"))
    };
    let points = |s: &serde_json::Value| -> Vec<(f64, f64)> {
        let p = s["points"].as_array().unwrap();
        p.iter()
            .map(|q| (q[0].as_f64().unwrap(), q[1].as_f64().unwrap()))
            .collect()
    };
    let loading = points(named("loading"));
    let unloading = points(named("unloading"));
    assert_eq!(
        (loading.len(), unloading.len()),
        (2, 2),
        "{loading:?} {unloading:?}"
    );
    assert!(loading[1].0 > loading[0].0 && unloading[1].0 < unloading[0].0);
    let pull = &read("j.csv.json")["adhesion"]["pull_off"];
    let marked = points(named("pull-off, force control"));
    let force = pull["force_controlled"]["force"].as_f64().unwrap();
    assert_eq!(marked[0].1, force);
}
