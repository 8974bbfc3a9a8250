//! Drives `asperity persson`: the table agrees with the library on the same surface, κ
//! scales the small-load area as A/A0 → κ p/(E* ḡ) promises, and bad input is refused.

mod common;
use common::{asperity, ok, refused};

use asperity::persson::{Persson, PerssonParams, PERSSON_KAPPA};

fn column(csv: &str, name: &str) -> Vec<f64> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(i).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn persson_table_matches_the_library_and_kappa_scales_the_area() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&asperity(
        &[
            "surface",
            "--n",
            "64",
            "--hurst",
            "0.8",
            "--rolloff",
            "4",
            "--rms-slope",
            "1",
            "--seed",
            "2",
            "--size",
            "2",
            "--out",
            "s.npy",
        ],
        d,
    ));
    ok(&asperity(
        &[
            "persson", "s.npy", "--nloads", "3", "--pmin", "1e-6", "--pmax", "1e-2", "--out",
            "a.csv",
        ],
        d,
    ));
    ok(&asperity(
        &[
            "persson",
            "s.npy",
            "--pressures",
            "1e-6",
            "--kappa",
            "2",
            "--modulus",
            "1",
            "--out",
            "b.csv",
        ],
        d,
    ));
    let a = std::fs::read_to_string(d.join("a.csv")).unwrap();
    let b = std::fs::read_to_string(d.join("b.csv")).unwrap();
    // Small load: the area is linear in κ.
    let ratio = column(&b, "area_fraction")[0] / column(&a, "area_fraction")[0];
    assert!((ratio - 2.0 / PERSSON_KAPPA).abs() < 1e-9, "{ratio}");
    // The same numbers as the library on the surface read back (L = 2 from the sidecar).
    let heights: ndarray::Array2<f64> = ndarray_npy::read_npy(d.join("s.npy")).unwrap();
    let surface = asperity::surface::Surface::new(heights, 2.0).unwrap();
    let theory = Persson::from_surface(&surface, PerssonParams::default()).unwrap();
    for (i, p) in column(&a, "pressure").into_iter().enumerate() {
        let point = theory.predict(p).unwrap();
        assert_eq!(column(&a, "mean_gap")[i], point.mean_gap);
        assert_eq!(column(&a, "contact_stiffness")[i], point.contact_stiffness);
        assert_eq!(
            column(&a, "stiffness_per_area")[i] * 4.0,
            point.contact_stiffness
        ); // A0 = 4
    }
}

#[test]
fn persson_refuses_bad_input_and_keeps_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&asperity(
        &[
            "surface", "--n", "32", "--hurst", "0.5", "--seed", "1", "--out", "s.npy",
        ],
        d,
    ));
    refused(
        &asperity(&["persson", "s.npy", "--pressures", "0"], d),
        "--pressures: 0 is not allowed (values must be finite and > 0)",
    );
    // The load options follow bem's rules and words, from the front-end layer (not clap's).
    refused(
        &asperity(&["persson", "s.npy"], d),
        "give --pressures or --nloads with --pmin and --pmax, not both",
    );
    refused(
        &asperity(
            &[
                "persson",
                "s.npy",
                "--pressures",
                "0.1",
                "--nloads",
                "2",
                "--pmin",
                "1",
                "--pmax",
                "2",
            ],
            d,
        ),
        ", not both",
    );
    refused(
        &asperity(&["persson", "s.npy", "--nloads", "2", "--pmin", "1"], d),
        "--nloads needs --pmin and --pmax",
    );
    refused(
        &asperity(
            &[
                "persson", "s.npy", "--nloads", "2", "--pmin", "2", "--pmax", "1",
            ],
            d,
        ),
        "--pmax (1) must not be smaller than --pmin (2)",
    );
    refused(
        &asperity(
            &["persson", "s.npy", "--pressures", "0.1", "--gamma", "0"],
            d,
        ),
        "gamma",
    );
    refused(
        &asperity(
            &["persson", "s.npy", "--pressures", "0.1", "--modulus", "-1"],
            d,
        ),
        "modulus",
    );
    refused(
        &asperity(&["persson", "missing.npy", "--pressures", "0.1"], d),
        "missing.npy",
    );
    std::fs::write(d.join("o.csv"), "keep").unwrap();
    refused(
        &asperity(
            &["persson", "s.npy", "--pressures", "0.1", "--out", "o.csv"],
            d,
        ),
        "exists",
    );
    assert_eq!(std::fs::read_to_string(d.join("o.csv")).unwrap(), "keep");
}
