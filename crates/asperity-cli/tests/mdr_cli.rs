//! Integration tests of `asperity mdr` and `asperity reproduce fig15.1|fig15.2`, driving the
//! real binary.

use std::path::Path;

use asperity::reference::{FlatPunch, Hertz, PowerLaw};
use ndarray::Array1;
use ndarray_npy::WriteNpyExt;

mod common;
use common::{asperity, names, ok, png_size, refused, stderr};

/// Rows of a CSV with header `indentation,force,stiffness,contacts`.
fn read_curve(path: &Path) -> Vec<(f64, f64, f64, usize)> {
    let text = std::fs::read_to_string(path).expect("csv written");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("indentation,force,stiffness,contacts"),
        "header"
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[0].parse().unwrap(),
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
                f[3].parse().unwrap(),
            )
        })
        .collect()
}

/// The columns of a CSV of numbers, by header name.
fn read_columns(path: &Path) -> std::collections::HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).expect("csv written");
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(String::from)
        .collect();
    let mut columns: std::collections::HashMap<String, Vec<f64>> =
        header.iter().map(|h| (h.clone(), Vec::new())).collect();
    for line in lines {
        for (name, value) in header.iter().zip(line.split(',')) {
            let column = columns.get_mut(name).expect("known column");
            column.push(value.parse().expect("a number"));
        }
    }
    columns
}

fn write_line(path: &Path, values: Vec<f64>) {
    let file = std::fs::File::create(path).unwrap();
    Array1::from(values).write_npy(file).unwrap();
}

#[test]
fn hertz_profile_reproduces_hertz_force_and_stiffness() {
    let dir = tempfile::tempdir().unwrap();
    let out = asperity(
        &[
            "mdr",
            "--profile",
            "hertz",
            "--radius",
            "1",
            "--n",
            "4001",
            "--dx",
            "1e-3",
            "--modulus",
            "2",
            "--indentations",
            "0.04,0.25,1",
            "--out",
            "h.csv",
        ],
        dir.path(),
    );
    ok(&out);
    let hertz = Hertz {
        radius: 1.0,
        modulus: 2.0,
    };
    let rows = read_curve(&dir.path().join("h.csv"));
    assert_eq!(rows.len(), 3);
    for (d, force, stiffness, contacts) in rows {
        // a = sqrt(R d) ≥ 200 Δx: discretisation ≤ Δx/a = 0.5 %.
        assert!((force / hertz.force(d) - 1.0).abs() < 5e-3, "d = {d}");
        assert!(
            (stiffness / hertz.stiffness(d) - 1.0).abs() < 5e-3,
            "d = {d}"
        );
        assert_eq!(contacts % 2, 1, "symmetric contact about the axis spring");
    }
}

#[test]
fn hertz_spring_law_holds_below_the_resolution() {
    // Δx²/R = 1e-4; at d = 1e-9 one spring touches.
    let dir = tempfile::tempdir().unwrap();
    let run = |spring: &str, name: &str| {
        let out = asperity(
            &[
                "mdr",
                "--profile",
                "hertz",
                "--radius",
                "1",
                "--n",
                "201",
                "--dx",
                "0.01",
                "--spring",
                spring,
                "--indentations",
                "1e-9",
                "--out",
                name,
            ],
            dir.path(),
        );
        ok(&out);
        read_curve(&dir.path().join(name))[0]
    };
    let hertz = Hertz {
        radius: 1.0,
        modulus: 1.0,
    };
    let nonlinear = run("hertz", "nl.csv");
    assert!((nonlinear.1 / hertz.force(1e-9) - 1.0).abs() < 0.02);
    let linear = run("linear", "l.csv");
    assert!(linear.1 / hertz.force(1e-9) > 100.0, "linear springs off");
}

#[test]
fn line_breakpoints_and_log_spaced_loads() {
    let dir = tempfile::tempdir().unwrap();
    let out = asperity(
        &[
            "line", "--n", "1024", "--hurst", "0.5", "--size", "2", "--seed", "3", "--out", "l.npy",
        ],
        dir.path(),
    );
    ok(&out);
    let out = asperity(
        &["mdr", "--line", "l.npy", "--breakpoints", "--out", "b.csv"],
        dir.path(),
    );
    ok(&out);
    let rows = read_curve(&dir.path().join("b.csv"));
    assert_eq!(rows.len(), 1024);
    assert_eq!((rows[0].0, rows[0].1, rows[0].3), (0.0, 0.0, 1));
    // Size 2 from the sidecar: E*Δx = 2/1024.
    for (j, row) in rows.iter().enumerate() {
        assert_eq!(row.3, j + 1);
        assert!((row.2 / ((j + 1) as f64 * 2.0 / 1024.0) - 1.0).abs() < 1e-12);
    }
    assert!(rows
        .windows(2)
        .all(|w| w[1].0 >= w[0].0 && w[1].1 >= w[0].1));
    // At d = 0 --indentations counts springs compressed at d: none (the breakpoint row
    // above counts the spring just touching). Documented in --help for --breakpoints.
    let out = asperity(
        &[
            "mdr",
            "--line",
            "l.npy",
            "--indentations",
            "0",
            "--out",
            "z.csv",
        ],
        dir.path(),
    );
    ok(&out);
    assert_eq!(
        read_curve(&dir.path().join("z.csv")),
        vec![(0.0, 0.0, 0.0, 0)]
    );
    let out = asperity(
        &["mdr", "--line", "l.npy", "--nloads", "12", "--out", "n.csv"],
        dir.path(),
    );
    ok(&out);
    let loads = read_curve(&dir.path().join("n.csv"));
    assert_eq!(loads.len(), 12);
    assert!(loads
        .windows(2)
        .all(|w| w[1].0 > w[0].0 && w[1].1 >= w[0].1));
    // The last level is full contact: every spring touches but the lowest.
    assert!(loads[11].3 >= 1023);
    // The same curve through the fractal law converges to it once many springs touch.
    let out = asperity(
        &[
            "mdr", "--line", "l.npy", "--spring", "fractal", "--hurst", "0.5", "--nloads", "12",
            "--out", "f.csv",
        ],
        dir.path(),
    );
    ok(&out);
    let fractal = read_curve(&dir.path().join("f.csv"));
    assert!((fractal[11].1 / loads[11].1 - 1.0).abs() < 0.05);
}

#[test]
fn out_records_the_inputs_beside_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let line = [
        "line", "--n", "256", "--hurst", "0.5", "--size", "2", "--seed", "3",
    ];
    ok(&asperity(&[&line[..], &["--out", "l.npy"]].concat(), d));
    let run = [
        "mdr",
        "--line",
        "l.npy",
        "--spring",
        "fractal",
        "--hurst",
        "0.5",
        "--nloads",
        "7",
        "--modulus",
        "3",
        "--out",
        "c.csv",
    ];
    ok(&asperity(&run, d));
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("c.csv.json")).unwrap()).unwrap();
    assert_eq!(record["command"], "asperity mdr");
    assert_eq!(record["indenter"]["kind"], "line");
    assert_eq!(record["indenter"]["size_source"], "sidecar");
    assert_eq!(record["springs"], 256);
    assert_eq!(record["size"], 2.0);
    assert_eq!(record["modulus"], 3.0);
    assert_eq!(record["spring_law"]["kind"], "fractal");
    assert_eq!(record["spring_law"]["hurst"], 0.5);
    // The indentations recorded are those of the table, bit for bit.
    let recorded: Vec<f64> = record["indentations"]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let table: Vec<f64> = read_curve(&d.join("c.csv")).iter().map(|r| r.0).collect();
    assert_eq!(recorded, table);
    // Like every single command's outputs, the record is not overwritten without --force.
    std::fs::remove_file(d.join("c.csv")).unwrap();
    refused(&asperity(&run, d), "c.csv.json");
    assert!(!d.join("c.csv").exists());
    ok(&asperity(&[&run[..], &["--force"]].concat(), d));
}

#[test]
fn sampled_radial_profile_is_transformed() {
    // f = r²/2R sampled on r = 0, 1e-3, …, 1: its MDR transform is x²/R, so the foundation
    // reproduces Hertz like the closed-form sphere (a ≥ 200 Δx: within 0.5 %).
    let dir = tempfile::tempdir().unwrap();
    let radius = 0.5;
    write_line(
        &dir.path().join("tip.npy"),
        (0..=1000)
            .map(|k| (k as f64 * 1e-3).powi(2) / (2.0 * radius))
            .collect(),
    );
    let out = asperity(
        &[
            "mdr",
            "--radial",
            "tip.npy",
            "--radial-step",
            "1e-3",
            "--n",
            "1601",
            "--dx",
            "1e-3",
            "--indentations",
            "0.05,0.2",
            "--out",
            "r.csv",
        ],
        dir.path(),
    );
    ok(&out);
    let hertz = Hertz {
        radius,
        modulus: 1.0,
    };
    for (d, force, stiffness, _) in read_curve(&dir.path().join("r.csv")) {
        assert!((force / hertz.force(d) - 1.0).abs() < 5e-3, "d = {d}");
        assert!(
            (stiffness / hertz.stiffness(d) - 1.0).abs() < 5e-3,
            "d = {d}"
        );
    }
    // Springs beyond the sampled radius are refused.
    let out = asperity(
        &[
            "mdr",
            "--radial",
            "tip.npy",
            "--radial-step",
            "1e-3",
            "--n",
            "3001",
            "--dx",
            "1e-3",
        ],
        dir.path(),
    );
    refused(&out, "beyond the radial profile");
}

#[test]
fn fractal_law_needs_a_valid_hurst_exponent() {
    let dir = tempfile::tempdir().unwrap();
    write_line(
        &dir.path().join("l.npy"),
        (0..64).map(|i| (i as f64).sin()).collect(),
    );
    for hurst in ["0", "-0.5", "2.5"] {
        let out = asperity(
            &[
                "mdr", "--line", "l.npy", "--spring", "fractal", "--hurst", hurst,
            ],
            dir.path(),
        );
        refused(&out, "hurst");
    }
    let out = asperity(
        &["mdr", "--line", "l.npy", "--spring", "fractal"],
        dir.path(),
    );
    refused(&out, "--hurst");
}

#[test]
fn non_positive_spacing_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    for dx in ["0", "-0.01"] {
        let out = asperity(
            &[
                "mdr",
                "--profile",
                "hertz",
                "--radius",
                "1",
                "--n",
                "11",
                "--dx",
                dx,
            ],
            dir.path(),
        );
        refused(&out, "dx");
    }
    // A line that exists, so that the size (not a missing file) is what is refused.
    write_line(
        &dir.path().join("l.npy"),
        (0..64).map(|i| (i as f64).sin()).collect(),
    );
    for size in ["0", "-1"] {
        let out = asperity(&["mdr", "--line", "l.npy", "--size", size], dir.path());
        refused(&out, "size");
    }
}

#[test]
fn negative_indentation_range_is_refused_by_the_range_check() {
    // Without allow_negative_numbers clap would read "-1" as an unknown flag.
    let dir = tempfile::tempdir().unwrap();
    let base = [
        "mdr",
        "--profile",
        "hertz",
        "--radius",
        "1",
        "--n",
        "11",
        "--dx",
        "0.1",
    ];
    for (flag, needle) in [("--dmin", "--dmin"), ("--dmax", "--dmax")] {
        let mut args = base.to_vec();
        args.extend([flag, "-1"]);
        let out = asperity(&args, dir.path());
        refused(&out, needle);
        assert!(
            stderr(&out).contains("-1") && !stderr(&out).contains("unexpected argument"),
            "{}",
            stderr(&out)
        );
    }
}

#[test]
fn missing_required_arguments_are_named() {
    // The front-end layer names what is missing (the same words as Python's).
    let dir = tempfile::tempdir().unwrap();
    let out = asperity(
        &["mdr", "--radial", "tip.npy", "--n", "5", "--dx", "1e-3"],
        dir.path(),
    );
    refused(&out, "--radial needs --radial-step");
    // `bem` without any load flag names the load options it needs (the front-end layer's
    // words, the same as Python's).
    let out = asperity(&["bem", "--surface", "s.npy"], dir.path());
    refused(
        &out,
        "give one of --forces, --pressures, --indentations or --nloads with --pmin and --pmax",
    );
}

#[test]
fn nan_in_the_profile_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    write_line(&dir.path().join("nan.npy"), vec![0.0, 1.0, f64::NAN, 0.5]);
    let out = asperity(&["mdr", "--line", "nan.npy", "--out", "x.csv"], dir.path());
    refused(&out, "non-finite");
    assert!(!dir.path().join("x.csv").exists(), "nothing written");
    let out = asperity(
        &[
            "mdr",
            "--radial",
            "nan.npy",
            "--radial-step",
            "0.1",
            "--n",
            "3",
            "--dx",
            "0.1",
        ],
        dir.path(),
    );
    refused(&out, "non-finite");
}

#[test]
fn existing_output_is_kept_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("c.csv");
    std::fs::write(&target, "keep me").unwrap();
    let args = [
        "mdr",
        "--profile",
        "cone",
        "--slope",
        "0.2",
        "--n",
        "101",
        "--dx",
        "0.01",
        "--nloads",
        "5",
        "--out",
        "c.csv",
    ];
    let out = asperity(&args, dir.path());
    refused(&out, "already exists");
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep me");
    let mut forced = args.to_vec();
    forced.push("--force");
    let out = asperity(&forced, dir.path());
    ok(&out);
    assert_eq!(read_curve(&target).len(), 5);
    // The table and its record of inputs, no temporary files.
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        2,
        "no temporary files left"
    );
}

#[test]
fn help_has_examples() {
    let dir = tempfile::tempdir().unwrap();
    let out = asperity(&["mdr", "--help"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        text.contains("Examples:") && text.contains("--breakpoints"),
        "{text}"
    );
    assert!(text.contains("--plot curve.svg"), "{text}");
    // The two meanings of `contacts` are stated: just after a breakpoint vs at d.
    assert!(
        text.contains("just after the breakpoint") && text.contains("compressed at d"),
        "{text}"
    );
}

#[test]
fn reproduce_book_figures() {
    let dir = tempfile::tempdir().unwrap();
    for (figure, files) in [
        (
            "fig15.1",
            &["fig15_1.csv", "fig15_1.png", "fig15_1.svg", "report.md"][..],
        ),
        (
            "fig15.2",
            &["fig15_2.csv", "fig15_2.png", "fig15_2.svg", "report.md"][..],
        ),
    ] {
        let out = asperity(
            &["reproduce", figure, "--quick", "--out", "figs"],
            dir.path(),
        );
        assert!(out.status.success(), "{figure}: {}", stderr(&out));
        for file in files {
            let path = dir.path().join("figs").join(figure).join(file);
            assert!(path.exists(), "{} missing", path.display());
        }
        let report =
            std::fs::read_to_string(dir.path().join("figs").join(figure).join("report.md"))
                .unwrap();
        assert!(report.contains(if figure == "fig15.1" {
            "4/3 E* R^½"
        } else {
            "(15.3)"
        }));
        // The same command again rewrites its own folder; another setting is refused.
        let again = asperity(
            &["reproduce", figure, "--quick", "--out", "figs"],
            dir.path(),
        );
        assert_eq!(again.status.code(), Some(0), "{}", stderr(&again));
        let other = asperity(&["reproduce", figure, "--out", "figs"], dir.path());
        refused(&other, "not made by");
    }
    // Fig. 15.1 (sphere R = 1, Δx = 0.01, E* = 1; critical depth u0 = Δx²/R = 1e-4).
    let fig1 = read_columns(&dir.path().join("figs/fig15.1/fig15_1.csv"));
    let u0 = 1e-4;
    let (d, lin, nl, hertz) = (
        &fig1["indentation"],
        &fig1["force_linear"],
        &fig1["force_nonlinear"],
        &fig1["force_hertz"],
    );
    let mut below = 0;
    for i in 0..d.len() {
        if d[i] <= 0.1 * u0 {
            // One spring on its Hertz branch carries exactly 4/3 E* R^½ d^(3/2) (measured
            // to 1e-15); 2 % is the bound for (15.2) far below the resolution.
            assert!((nl[i] / hertz[i] - 1.0).abs() < 0.02, "d = {}", d[i]);
            below += 1;
        }
        if d[i] <= 3e-3 * u0 {
            // A linear spring gives E*Δx d: Hertz × 3Δx/(4 sqrt(R d)) ≥ 13.7 for
            // d ≤ 3e-3 u0 (23.7 at the first row, 1e-3 u0).
            assert!(
                lin[i] / hertz[i] > 10.0,
                "linear springs far off at d = {}",
                d[i]
            );
        }
        if d[i] >= 100.0 * u0 {
            // Many springs (a ≥ 10 Δx): both laws follow Hertz (measured ≤ 0.4 %).
            assert!((nl[i] / hertz[i] - 1.0).abs() < 0.02, "d = {}", d[i]);
            assert!((lin[i] / hertz[i] - 1.0).abs() < 0.02, "d = {}", d[i]);
        }
    }
    assert!(below >= 20, "rows far below u0: {below}");

    // Fig. 15.2 (--quick: 50 lines of N = 2049, H = 1, h = L = E* = 1). Critical depth
    // (15.6): u0 = (H+1)²/(1.9412 H)·((H+1)/1.9412·Δx/L)^H·h ≈ 1.04e-3.
    let fig2 = read_columns(&dir.path().join("figs/fig15.2/fig15_2.csv"));
    let (d, lin, nl, asymptote) = (
        &fig2["indentation"],
        &fig2["force_linear"],
        &fig2["force_nonlinear"],
        &fig2["force_asymptote"],
    );
    let u0 = 4.0 / 1.9412 * (2.0 / 1.9412 / 2049.0);
    let small: Vec<usize> = (0..d.len()).filter(|&i| d[i] <= 0.1 * u0).collect();
    assert!(small.len() >= 10, "small-indentation rows: {}", small.len());
    for &i in &small {
        // Below u0 each line's touching spring follows (15.3) itself (measured ratio
        // 1.0000); within 1 % is the book's claim that (15.7) keeps the asymptote.
        assert!(
            (nl[i] / asymptote[i] - 1.0).abs() < 0.01,
            "(15.7) vs (15.3) at d = {}: {}",
            d[i],
            nl[i] / asymptote[i]
        );
    }
    // The bend of the linear-spring curve: over the first 10 rows (d = 1e-6 … 1.1e-5 h,
    // one spring per line) F ∝ d, slope 1 (measured 1.000 to 1.002); (15.3) has slope 2,
    // so ±0.05 separates the two clearly while allowing a second spring in a few lines.
    let slope = |f: &[f64], a: usize, b: usize| (f[b] / f[a]).ln() / (d[b] / d[a]).ln();
    let linear_slope = slope(lin, 0, 9);
    assert!(
        (linear_slope - 1.0).abs() < 0.05,
        "linear slope {linear_slope}"
    );
    let nonlinear_slope = slope(nl, 0, 9);
    assert!(
        (nonlinear_slope - 2.0).abs() < 0.05,
        "(15.7) slope {nonlinear_slope}"
    );
    // And the linear springs are far above the asymptote there (≥ 100× at d ≤ 1.1e-5 h).
    assert!((0..10).all(|i| lin[i] / asymptote[i] > 100.0));
}

#[test]
fn alpha_theory_column_uses_eq_24_at_h_zero() {
    // The paper derives eq. (24) for H = 0 ("valid not only for H = 0, but also for smaller
    // values"), so the theory column at H = 0 is (1 + log2 N)/(3 + log2 N), not 1/(1+0).
    let dir = tempfile::tempdir().unwrap();
    let out = asperity(
        &[
            "study",
            "alpha",
            "--method",
            "mdr",
            "--n",
            "1024",
            "--hurst",
            "-0.5:0.5:0.5",
            "--samples",
            "4",
            "--quiet",
            "--out",
            "a",
        ],
        dir.path(),
    );
    ok(&out);
    let csv = std::fs::read_to_string(dir.path().join("a/alpha.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (hurst, theory) = (col("hurst"), col("alpha_theory"));
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[hurst].parse().unwrap(), f[theory].parse().unwrap())
        })
        .collect();
    let eq24 = 11.0 / 13.0; // log2 1024 = 10
    let expected = [(-0.5, eq24), (0.0, eq24), (0.5, 1.0 / 1.5)];
    assert_eq!(rows.len(), expected.len(), "{csv}");
    for ((h, t), (eh, et)) in rows.iter().zip(expected) {
        assert_eq!(*h, eh);
        assert!((t - et).abs() < 1e-6, "H = {h}: theory {t}, expected {et}");
    }
}

#[test]
fn flat_punch_profile_has_stiffness_two_modulus_radius() {
    let dir = tempfile::tempdir().unwrap();
    let run = |radius: &str, name: &str| {
        let out = asperity(
            &[
                "mdr",
                "--profile",
                "punch",
                "--radius",
                radius,
                "--n",
                "401",
                "--dx",
                "1e-3",
                "--modulus",
                "0.8",
                "--indentations",
                "1e-6,0.01,0.3",
                "--out",
                name,
            ],
            dir.path(),
        );
        ok(&out);
        read_curve(&dir.path().join(name))
    };
    for (radius, springs) in [(0.1, 201), (0.0375, 75), (0.0505, 101)] {
        let punch = FlatPunch {
            radius,
            modulus: 0.8,
        };
        let rows = run(&radius.to_string(), &format!("p{radius}.csv"));
        assert_eq!(rows.len(), 3);
        for (d, force, stiffness, contacts) in rows {
            // 2m+1 springs of E*Δx for a = mΔx (edge springs included): k = 2E*(a + Δx/2),
            // off by Δx/(2a) ≤ Δx/a; exact for a = (m+½)Δx.
            assert_eq!(contacts, springs, "a = {radius}");
            let tolerance = 1e-3 / radius;
            assert!(
                (stiffness / punch.stiffness() - 1.0).abs() <= tolerance,
                "a = {radius}: k = {stiffness} vs {}",
                punch.stiffness()
            );
            assert!((force / punch.force(d) - 1.0).abs() <= tolerance, "d = {d}");
        }
    }
    // Without --dmax or --indentations a punch has no range of indentations.
    let out = asperity(
        &[
            "mdr",
            "--profile",
            "punch",
            "--radius",
            "0.1",
            "--n",
            "401",
            "--dx",
            "1e-3",
        ],
        dir.path(),
    );
    refused(&out, "--indentations");
}

#[test]
fn power_law_profile_matches_its_closed_form() {
    // f = c r³: g = κ(3) c |x|³ with κ(3) = 3π/4; F = 2E* n/(n+1) d a, k = 2E*a.
    let dir = tempfile::tempdir().unwrap();
    let out = asperity(
        &[
            "mdr",
            "--profile",
            "power",
            "--coefficient",
            "0.5",
            "--exponent",
            "3",
            "--n",
            "4001",
            "--dx",
            "1e-3",
            "--modulus",
            "1.5",
            "--indentations",
            "0.15,0.5,1.1",
            "--out",
            "p.csv",
        ],
        dir.path(),
    );
    ok(&out);
    let power = PowerLaw {
        coefficient: 0.5,
        exponent: 3.0,
        modulus: 1.5,
    };
    assert!((power.stretch() - 0.75 * std::f64::consts::PI).abs() < 1e-12);
    let rows = read_curve(&dir.path().join("p.csv"));
    assert_eq!(rows.len(), 3);
    for (d, force, stiffness, _) in rows {
        // a ≥ 0.5 = 500 Δx: the discrete contact edge costs at most Δx/a = 0.2 %.
        let a = power.contact_radius(d);
        assert!((0.5..2.0).contains(&a), "a = {a} inside the springs");
        assert!((force / power.force(d) - 1.0).abs() < 1e-3 / a, "d = {d}");
        assert!(
            (stiffness / power.stiffness(d) - 1.0).abs() < 1e-3 / a,
            "d = {d}: k = {stiffness} vs {}",
            power.stiffness(d)
        );
    }
}

#[test]
fn sizes_that_cannot_fit_in_memory_are_refused() {
    // 1e15 springs need 16 PB; usize::MAX overflows the byte count. Both are refused with
    // one line before anything is allocated (they used to abort with status 134).
    let dir = tempfile::tempdir().unwrap();
    for n in ["1000000000000000", &usize::MAX.to_string()] {
        let out = asperity(
            &[
                "mdr",
                "--profile",
                "hertz",
                "--radius",
                "1",
                "--n",
                n,
                "--dx",
                "1e-3",
            ],
            dir.path(),
        );
        // "needs about … MiB" or, where the byte count overflows, "exceeds addressable memory".
        refused(&out, if n.len() > 16 { "memory" } else { "MiB" });
        refused(&out, "--n");
    }
    let out = asperity(
        &[
            "mdr",
            "--profile",
            "hertz",
            "--radius",
            "1",
            "--n",
            "11",
            "--dx",
            "0.1",
            "--nloads",
            "1000000000000000",
        ],
        dir.path(),
    );
    refused(&out, "--nloads");
    refused(&out, "MiB");
}

#[test]
fn plot_is_written_for_lines_and_profiles() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let line: Vec<f64> = (0..256)
        .map(|i| (i as f64 * 0.37).sin() + 0.01 * i as f64)
        .collect();
    write_line(&d.join("line.npy"), line);
    let runs: [&[&str]; 4] = [
        &[
            "--line", "line.npy", "--nloads", "20", "--out", "a.csv", "--plot", "a.png",
        ],
        &["--line", "line.npy", "--breakpoints", "--plot", "b.svg"],
        &[
            "--profile",
            "hertz",
            "--radius",
            "1",
            "--n",
            "201",
            "--dx",
            "0.01",
            "--spring",
            "hertz",
            "--indentations",
            "1e-6,1e-4,1e-3",
            "--plot",
            "c.PNG",
        ],
        &[
            "--profile",
            "cone",
            "--slope",
            "0.2",
            "--n",
            "101",
            "--dx",
            "0.01",
            "--spring",
            "fractal",
            "--hurst",
            "0.7",
            "--rms-height",
            "0.01",
            "--nloads",
            "5",
            "--plot",
            "d.svg",
        ],
    ];
    for extra in runs {
        let out = asperity(&[&["mdr"], extra].concat(), d);
        assert!(out.status.success(), "{extra:?}: {}", stderr(&out));
    }
    assert_eq!(read_curve(&d.join("a.csv")).len(), 20);
    for png in ["a.png", "c.PNG"] {
        let (w, h) = png_size(&d.join(png));
        assert!(w > 0 && h > 0, "{png}: {w}x{h}");
    }
    for svg in ["b.svg", "d.svg"] {
        assert!(std::fs::read_to_string(d.join(svg))
            .unwrap()
            .contains("<svg"));
    }
    assert_eq!(
        names(d),
        [
            "a.csv",
            "a.csv.json",
            "a.png",
            "b.svg",
            "c.PNG",
            "d.svg",
            "line.npy"
        ],
        "no temporary files left"
    );
}

#[test]
fn bad_plots_are_refused_before_any_work_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("old.svg"), "keep me").unwrap();
    // Without --radius the profile fails after the outputs are checked: the errors below
    // prove the plot was refused first.
    let base = [
        "mdr",
        "--profile",
        "hertz",
        "--n",
        "101",
        "--dx",
        "0.01",
        "--out",
        "c.csv",
    ];
    let cases: [(&[&str], &str); 5] = [
        (
            &["--nloads", "5", "--plot", "k.pdf"],
            "must be .png or .svg",
        ),
        (&["--nloads", "5", "--plot", "k"], "must be .png or .svg"),
        (&["--nloads", "5", "--plot", "old.svg"], "already exists"),
        (
            &["--indentations", "0.1", "--plot", "k.png"],
            "at least 2 indentations",
        ),
        (
            &["--nloads", "1", "--plot", "k.png"],
            "at least 2 indentations",
        ),
    ];
    for (extra, needle) in cases {
        let out = asperity(&[&base[..], extra].concat(), d);
        refused(&out, needle);
        assert_eq!(names(d), ["old.svg"], "{extra:?} wrote files");
    }
    assert_eq!(
        std::fs::read_to_string(d.join("old.svg")).unwrap(),
        "keep me"
    );
    // The missing radius itself, once the plot is acceptable.
    let out = asperity(
        &[&base[..], &["--nloads", "5", "--plot", "k.png"]].concat(),
        d,
    );
    refused(&out, "--radius");
    assert_eq!(names(d), ["old.svg"]);
    // With --force the old plot is replaced, together with the table.
    let out = asperity(
        &[
            &base[..],
            &[
                "--radius", "1", "--nloads", "5", "--plot", "old.svg", "--force",
            ],
        ]
        .concat(),
        d,
    );
    ok(&out);
    assert!(std::fs::read_to_string(d.join("old.svg"))
        .unwrap()
        .contains("<svg"));
    assert_eq!(names(d), ["c.csv", "c.csv.json", "old.svg"]);
}

#[test]
fn adhesive_sphere_loop_lets_go_at_the_jkr_pull_offs() {
    // common::JKR_SPHERE_MDR: the pull-off radii are 152 Δx and 73 Δx (library tests:
    // 4e-5 and 4.5e-3 at this Δx).
    let dir = tempfile::tempdir().unwrap();
    let path = ["--indentations", "0.02,0.09,0.05"];
    let outputs = ["--out", "jkr.csv", "--plot", "jkr.svg"];
    let out = asperity(
        &[&common::JKR_SPHERE_MDR[..], &path, &outputs].concat(),
        dir.path(),
    );
    ok(&out);
    let text = std::fs::read_to_string(dir.path().join("jkr.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("indentation,force,stiffness,contacts,branch")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows[0][4], "approach");
    assert_eq!(rows[1][4], "approach");
    assert_eq!(rows.last().unwrap()[3], "0");
    let least = rows
        .iter()
        .map(|r| r[1].parse::<f64>().unwrap())
        .fold(f64::INFINITY, f64::min);
    let expected = -1.5 * std::f64::consts::PI * 1e-3;
    assert!((least / expected - 1.0).abs() < 1e-3, "{least}");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("jkr.csv.json")).unwrap())
            .unwrap();
    let pull = &record["adhesion"]["pull_off"];
    let force = pull["force_controlled"]["force"].as_f64().unwrap();
    assert!((force / least - 1.0).abs() < 1e-6, "{force} vs {least}");
    let displacement = pull["displacement_controlled"]["force"].as_f64().unwrap();
    let expected = -5.0 / 6.0 * std::f64::consts::PI * 1e-3;
    assert!(
        (displacement / expected - 1.0).abs() < 1e-2,
        "{displacement}"
    );
    assert!(stderr(&out).contains("pull-off: force control F = "));
    assert!(dir.path().join("jkr.svg").exists());
    // Refusals: one line, before any output.
    for (w, words) in [
        ("0", "invalid --work-of-adhesion: the work of adhesion Δγ must be positive and finite, got 0"),
        ("nan", "invalid --work-of-adhesion: the work of adhesion Δγ must be positive and finite, got NaN"),
    ] {
        let out = asperity(
            &["mdr", "--profile", "hertz", "--radius", "1", "--n", "11", "--dx", "0.1",
              "--work-of-adhesion", w, "--out", "no.csv"],
            dir.path(),
        );
        refused(&out, words);
        assert!(!dir.path().join("no.csv").exists());
    }
}

#[test]
fn tangential_force_gives_the_cattaneo_mindlin_cycle() {
    // Sphere R = 1 at d = 1 (a = 1, F = 4/3), a/Δx = 1000, μ = 0.5, ν = 0.3, Q* = μF/2.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cycle.csv");
    let o = asperity(
        &[
            "mdr",
            "--profile",
            "hertz",
            "--radius",
            "1",
            "--n",
            "2401",
            "--dx",
            "1e-3",
            "--indentations",
            "1",
            "--tangential-force",
            "0.3333333333333333",
            "--friction",
            "0.5",
            "--cycle-points",
            "5",
            "--out",
            out.to_str().unwrap(),
        ],
        dir.path(),
    );
    ok(&o);
    let text = std::fs::read_to_string(&out).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 15);
    let top = &rows[4];
    assert_eq!(top[0], "loading");
    let exact = asperity::reference::CattaneoMindlin {
        radius: 1.0,
        modulus: 1.0,
        ratio: asperity::mdr::mindlin_ratio(0.3).unwrap(),
        friction: 0.5,
    };
    let u: f64 = top[1].parse().unwrap();
    let u_exact = exact.displacement(1.0, 1.0 / 3.0);
    assert!((u / u_exact - 1.0).abs() < 1e-3, "u {u} vs {u_exact}");
    let c: f64 = top[4].parse().unwrap();
    assert!((c - 0.5f64.cbrt()).abs() < 1e-3, "c/a {c}");
    // The unloading branch ends at (−u*, −Q*); the record holds the cycle's summary.
    let end = &rows[9];
    assert_eq!(end[0], "unloading");
    assert!((end[1].parse::<f64>().unwrap() + u).abs() < 1e-12);
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("cycle.csv.json")).unwrap())
            .unwrap();
    let k = record["cycle"]["no_slip_stiffness"].as_f64().unwrap();
    assert!(
        (k / exact.no_slip_stiffness(1.0) - 1.0).abs() < 1e-3,
        "k_t {k}"
    );
    // Beyond μF: refused, nothing written.
    let o = asperity(
        &[
            "mdr",
            "--profile",
            "hertz",
            "--radius",
            "1",
            "--n",
            "2401",
            "--dx",
            "1e-3",
            "--indentations",
            "1",
            "--tangential-force",
            "0.7",
            "--friction",
            "0.5",
            "--out",
            dir.path().join("x.csv").to_str().unwrap(),
        ],
        dir.path(),
    );
    refused(&o, "|Q| <= μF");
    assert!(!dir.path().join("x.csv").exists());
}
