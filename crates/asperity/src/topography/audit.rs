//! The audit of every real file of the three shared sets against SurfaceTopography 1.27.1's
//! reference: each file is read as `read_file` reads it (content first, then extension),
//! its default channel compared with the reference field by field, without any per-file
//! allowance. A file either matches in every field or is listed in [`DIFFERENCES`] with
//! the fields that differ on purpose (the reader's own test checks what it reads there
//! instead). Run with `--nocapture` to print the table of `docs/topographies.md`.

use super::{detect_and_read, testkit::set_dir, Heights, Reading};
use ndarray::ArrayD;

/// Files whose reading differs on purpose from the reference, the fields that differ, and
/// why (a field not named must match).
const DIFFERENCES: &[(&str, &[&str], &str)] = &[
    (
        "sdf-1.sdf",
        &["unit"],
        "SDF's scales are metres by ISO 25178-71, our unit `m`; the peer names its display unit µm",
    ),
    (
        "dektak-1.csv",
        &["size"],
        "x printed to 0.1 µm: uniform within printing precision; length nΔx, not x_last − x_0",
    ),
    (
        "xy-1.txt",
        &["heights", "size"],
        "non-uniform x: resampled onto n uniform points (recorded as a cleaning step)",
    ),
    (
        "xy-2.txt",
        &["heights", "size", "unit"],
        "its units line `µm µm` is applied (the peer ignores it); non-uniform x resampled",
    ),
    (
        "csv-1.csv",
        &["size"],
        "non-uniform x; only x has a unit, so the numbers stay raw; length nΔx",
    ),
    (
        "bcrf-1.bcrf",
        &["unit"],
        "the file's zunit µm (the peer reports the lateral unit nm); heights in metres agree",
    ),
    (
        "multiple_data_sets.h5",
        &["size"],
        "no size in the file: the peer was given one unit per pixel, we ask for --size",
    ),
];

/// Channel names are ours where the file names none (the peer says `Default`/`default`).
const OUR_CHANNEL_NAMES: &[&str] = &[
    "x3p-2.x3p",
    "st-written-1.x3p",
    "st-written-2.x3p",
    "openfmc-ISO5436-sample4_bin.x3p",
    "gwyddion-export-english.txt",
    "gwyddion-export-german.txt",
    "matrix-2.txt",
    "matrix-3.txt",
    "matrix-4.txt",
    "txt_example.txt",
    "dektak-1.csv",
    "xy-1.txt",
    "xy-2.txt",
    "csv-1.csv",
    "hfm-1.hfm",
    "sdf-1.sdf",
    "nc-1.nc",
];

/// The fields of one file's reading that differ from the reference, and the largest
/// relative height difference over the points both define.
fn compare(
    reading: &Reading,
    meta: &serde_json::Value,
    want: &ArrayD<f64>,
) -> (Vec<&'static str>, f64) {
    let mut differ = Vec::new();
    let c = reading
        .channels
        .iter()
        .find(|c| c.is_height)
        .expect("a height channel");
    let got: Vec<f64> = match &c.heights {
        Heights::Areal(h) if want.shape() == [h.ncols(), h.nrows()] => {
            h.t().iter().copied().collect()
        }
        Heights::Profile(h) if want.shape() == [h.len()] => h.to_vec(),
        _ => Vec::new(),
    };
    let mut worst = 0.0f64;
    if got.is_empty() {
        differ.push("grid");
    } else {
        let mut nan_differ = false;
        for (g, w) in got.iter().zip(want.iter()) {
            match (g.is_nan(), w.is_nan()) {
                (false, false) => worst = worst.max((g - w).abs() / w.abs().max(f64::MIN_POSITIVE)),
                (a, b) => nan_differ |= a != b,
            }
        }
        if nan_differ {
            differ.push("undefined");
        }
        if worst > 1e-12 {
            differ.push("heights");
        }
    }
    let sizes = &meta["physical_sizes_m"];
    let size_ok = (0..2).all(|axis| match (c.size[axis], sizes[axis].as_f64()) {
        (Some(g), Some(w)) => (g - w).abs() <= 1e-12 * w.abs(),
        (g, w) => g.is_none() && w.is_none(),
    });
    if !size_ok {
        differ.push("size");
    }
    if c.unit.as_deref() != meta["unit"].as_str() {
        differ.push("unit");
    }
    (differ, worst)
}

#[test]
fn every_shared_file_matches_the_reference_or_differs_as_named() {
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    for set in ["topographies", "topographies-2", "topographies-3"] {
        let Some(dir) = set_dir(set) else { return };
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .filter(|n| !n.contains(".reference") && n != "README.md")
            .collect();
        names.sort();
        for name in names {
            let path = dir.join(&name);
            let json = std::fs::read_to_string(dir.join(format!("{name}.reference.json"))).unwrap();
            let meta: serde_json::Value = serde_json::from_str(&json).unwrap();
            let want: ArrayD<f64> =
                ndarray_npy::read_npy(dir.join(format!("{name}.reference.npy"))).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            let peer_format = meta["format"].as_str().unwrap_or("?");
            let reading = match detect_and_read(&path, &bytes) {
                Ok((r, _)) => r,
                Err(e) => {
                    rows.push(format!(
                        "| {set}/{name} | {peer_format} | — | no: {e} | — | — |"
                    ));
                    failures.push(format!("{name}: not read: {e}"));
                    continue;
                }
            };
            let (mut differ, worst) = compare(&reading, &meta, &want);
            let names_ours: Vec<&str> = reading.channels.iter().map(|c| c.name.as_str()).collect();
            let names_peer: Vec<&str> = meta["channels"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_str().unwrap())
                .collect();
            if names_ours != names_peer && !OUR_CHANNEL_NAMES.contains(&name.as_str()) {
                differ.push("channels");
            }
            let named = DIFFERENCES.iter().find(|(n, _, _)| *n == name);
            let allowed: &[&str] = named.map_or(&[], |(_, fields, _)| fields);
            let unexpected: Vec<&str> = differ
                .iter()
                .copied()
                .filter(|f| !allowed.contains(f))
                .collect();
            if !unexpected.is_empty() {
                failures.push(format!(
                    "{name}: {unexpected:?} differ (largest height difference {worst:.1e})"
                ));
            }
            let verdict = match named {
                Some((_, fields, why)) => {
                    format!("differs on purpose ({}): {why}", fields.join(", "))
                }
                None if unexpected.is_empty() => format!("yes (heights ≤ {worst:.1e} rel.)"),
                None => format!("**no**: {unexpected:?}"),
            };
            rows.push(format!(
                "| {set}/{name} | {peer_format} | {} | yes | {verdict} | {} |",
                reading.format,
                want.shape()
                    .iter()
                    .map(|n| n.to_string())
                    .collect::<Vec<_>>()
                    .join(" × "),
            ));
        }
    }
    eprintln!("| file | peer format | our format | reads | matches | grid [x, y] |");
    eprintln!("|---|---|---|---|---|---|");
    for row in &rows {
        eprintln!("{row}");
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
