//! `asperity bench fft-pair`: the unit of the BEM benchmark's per-iteration cost. Drives the
//! real binary: one line of `key=value` fields with the padded grid and finite positive
//! timings; bad input is one line on stderr and exit status 2.

use std::collections::HashMap;
use std::process::{Command, Output};

fn asperity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .output()
        .unwrap()
}

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
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
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
