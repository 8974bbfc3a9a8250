//! `asperity surface` / `line` inputs that only make sense on some grids or scales:
//! refused with one line, exit 2, nothing written.

mod common;
use common::{asperity, ok};

#[test]
fn grid_and_scale_limits_are_refused_with_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: [(&[&str], &str); 6] = [
        // q0 at or beyond the Nyquist wavenumber (8 for 16 points per side).
        (
            &["surface", "--n", "16", "--hurst", "0.5", "--rolloff", "8"],
            "Nyquist",
        ),
        (
            &["surface", "--n", "16", "--hurst", "0.5", "--cutoff", "100"],
            "Nyquist",
        ),
        (
            &["line", "--n", "16", "--hurst", "0.5", "--rolloff", "100"],
            "Nyquist",
        ),
        (
            &[
                "surface",
                "--n",
                "16",
                "--hurst",
                "0.5",
                "--short-cutoff",
                "0.5",
            ],
            "short-cutoff",
        ),
        // Heights whose squares would overflow.
        (
            &[
                "surface",
                "--n",
                "16",
                "--hurst",
                "0.5",
                "--rms-height",
                "1e160",
            ],
            "rms-height",
        ),
        // --png takes PNG only.
        (
            &["surface", "--n", "16", "--hurst", "0.5", "--png", "s.jpg"],
            "--png",
        ),
    ];
    for (args, needle) in cases {
        let mut args = args.to_vec();
        args.extend(["--out", "s.npy"]);
        let out = asperity(&args, d);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert_eq!(std::fs::read_dir(d).unwrap().count(), 0, "{args:?} wrote");
    }
    // Just below Nyquist is fine.
    let out = asperity(
        &[
            "surface",
            "--n",
            "16",
            "--hurst",
            "0.5",
            "--rolloff",
            "7",
            "--out",
            "s.npy",
        ],
        d,
    );
    ok(&out);
}
