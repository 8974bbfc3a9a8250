//! `asperity bench fft-pair` (the unit of the BEM benchmark's per-iteration cost) and
//! `asperity bench bem-estimate` and `bench tangential`. Drives the real binary: `key=value` fields with finite
//! values that add up; bad input is one line on stderr and exit status 2.

use std::collections::HashMap;
use std::process::Output;

mod common;
use common::{ok, run_asperity as asperity};

fn fields(output: &Output) -> HashMap<String, String> {
    String::from_utf8_lossy(&output.stdout)
        .split_whitespace()
        .filter_map(|item| item.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

#[test]
fn fft_pair_reports_the_padded_grid_and_positive_timings() {
    for (boundary, grid) in [("free", "24x24"), ("periodic", "12x12")] {
        let out = asperity(&[
            "bench",
            "fft-pair",
            "--n",
            "12",
            "--boundary",
            boundary,
            "--repeat",
            "3",
        ]);
        ok(&out);
        let f = fields(&out);
        assert_eq!(f["kernel"], "FftPair");
        assert_eq!(f["boundary"], boundary);
        assert_eq!(f["grid"], grid);
        for key in [
            "pair_min_s",
            "pair_median_s",
            "apply_min_s",
            "apply_median_s",
        ] {
            let value: f64 = f[key].parse().unwrap();
            assert!(value.is_finite() && value >= 0.0, "{key} = {value}");
        }
        let min: f64 = f["pair_min_s"].parse().unwrap();
        let median: f64 = f["pair_median_s"].parse().unwrap();
        assert!(min <= median);
    }
}

#[test]
fn fft_pair_refuses_bad_input_with_one_line() {
    for args in [
        &["bench", "fft-pair", "--n", "0"][..],
        &["bench", "fft-pair", "--n", "8", "--boundary", "open"][..],
        &["bench", "fft-pair", "--n", "8", "--repeat", "0"][..],
        &["bench", "fft-pair", "--n", "100000000"][..],
    ] {
        let out = asperity(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim().lines().count(), 1, "{args:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}

#[test]
fn bem_estimate_sums_its_sizes_into_the_total() {
    let out = asperity(&[
        "bench",
        "bem-estimate",
        "--sizes",
        "16,24",
        "--samples",
        "3",
        "--hursts",
        "0.5:0.8:0.3",
        "--probes",
        "8,16",
    ]);
    ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<HashMap<String, String>> = stdout
        .lines()
        .map(|line| {
            line.split_whitespace()
                .filter_map(|item| item.split_once('='))
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        })
        .collect();
    assert_eq!(lines.len(), 3, "{stdout}");
    let mut sum = 0.0;
    for (line, n) in lines[..2].iter().zip(["16", "24"]) {
        assert_eq!(line["n"], n);
        assert_eq!(line["hursts"], "2");
        for key in [
            "solve_iterations",
            "cg_iterations",
            "solve_iteration_s",
            "cg_iteration_s",
        ] {
            let value: f64 = line[key].parse().unwrap();
            assert!(value.is_finite() && value > 0.0, "{key} = {value}");
        }
        sum += line["seconds"].parse::<f64>().unwrap();
    }
    let total: f64 = lines[2]["total_seconds"].parse().unwrap();
    assert!((total - sum).abs() <= 2e-3, "{total} vs {sum}");
    // On 16² an α study's sweep would end past full contact: every load, as a curve's.
    assert!(!lines[2].contains_key("sweep_end"), "{stdout}");
}

#[test]
fn bem_estimate_follows_an_alpha_studys_sweep_unless_told_otherwise() {
    let run = |extra: &[&str]| {
        let args = "bench bem-estimate --sizes 64 --samples 2 --hursts 0.5 --probes 32,64";
        let args: Vec<&str> = args.split(' ').chain(extra.iter().copied()).collect();
        let out = asperity(&args);
        ok(&out);
        String::from_utf8_lossy(&out.stdout).to_string()
    };
    let field = |text: &str, key: &str| -> Option<f64> {
        text.split_whitespace()
            .find_map(|item| item.strip_prefix(&format!("{key}=")))
            .map(|v| v.parse().unwrap())
    };
    let (alpha, whole) = (run(&[]), run(&["--full-sweep"]));
    assert_eq!(field(&alpha, "sweep_end"), Some(0.08), "{alpha}");
    assert_eq!(field(&whole, "sweep_end"), None, "{whole}");
    // The loads past 8 % contact are the costly ones.
    let iterations = |t: &str| field(t, "solve_iterations").unwrap();
    assert!(iterations(&alpha) < iterations(&whole), "{alpha}\n{whole}");
}

#[test]
fn bem_estimate_refuses_bad_input_with_one_line() {
    for args in [
        &["bench", "bem-estimate", "--sizes", "4"][..],
        &["bench", "bem-estimate", "--sizes", "16", "--probes", "16,8"][..],
        &["bench", "bem-estimate", "--sizes", "16", "--probes", "16"][..],
        &["bench", "bem-estimate", "--sizes", "16", "--samples", "0"][..],
        &["bench", "bem-estimate", "--sizes", "16", "--hursts", "x"][..],
    ] {
        let out = asperity(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim().lines().count(), 1, "{args:?}: {stderr}");
    }
}

#[test]
fn tangential_times_each_direction_against_the_normal_cg() {
    let out = asperity(&[
        "bench",
        "tangential",
        "--n",
        "48",
        "--repeat",
        "2",
        "--pressures",
        "0.02",
    ]);
    ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    // The normal CG, then x, y, both in f64 and mixed, then the agreement.
    assert_eq!(lines.len(), 8, "{stdout}");
    let field = |line: &str, key: &str| -> String {
        line.split_whitespace()
            .find_map(|item| item.strip_prefix(&format!("{key}=")[..]).map(String::from))
            .unwrap_or_else(|| panic!("{key} in {line}"))
    };
    let solves: Vec<(String, String)> = lines[..7]
        .iter()
        .map(|l| (field(l, "solve"), field(l, "precision")))
        .collect();
    let expected = [
        ("normal", "f64"),
        ("x", "f64"),
        ("y", "f64"),
        ("both", "f64"),
        ("x", "mixed"),
        ("y", "mixed"),
        ("both", "mixed"),
    ];
    for ((solve, precision), (s, p)) in solves.iter().zip(expected) {
        assert_eq!((solve.as_str(), precision.as_str()), (s, p));
    }
    for line in &lines[1..7] {
        // Mindlin's 2(1−ν)/(2−ν) = 0.8235 at ν = 0.3, within the sample's anisotropy.
        let ratio: f64 = field(line, "stiffness_ratio").parse().unwrap();
        assert!((ratio - 0.8235).abs() < 0.02, "{line}");
        let median: f64 = field(line, "cpu_median_s").parse().unwrap();
        assert!(median.is_finite() && median >= 0.0, "{line}");
    }
    let agree: f64 = field(lines[7], "mixed_vs_f64_max_relative")
        .parse()
        .unwrap();
    assert!(agree < 1e-11, "{}", lines[7]);
}

#[test]
fn tangential_refuses_bad_input_with_one_line() {
    for args in [
        &["bench", "tangential", "--n", "16", "--poisson", "0.6"][..],
        &["bench", "tangential", "--n", "16", "--pressures", "-1"][..],
        &["bench", "tangential", "--n", "16", "--repeat", "0"][..],
    ] {
        let out = asperity(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim().lines().count(), 1, "{args:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}
