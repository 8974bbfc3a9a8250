//! Column text files: `x z` line profiles (stylus instruments; two-column text, Dektak CSV
//! exports with their `Scan Parameters` header and `Lateral um,Raw Micrometer` column
//! names), `z` alone (a profile whose length the caller gives), and `x y z` point lists of
//! a map on a regular grid (missing grid points are undefined).
//!
//! A profile is uniform when every x lies within the printing precision of the file (one
//! unit of the finest last digit printed in the column: rounding each x and both ends
//! moves them by at most that) of the straight line from the first to the last x:
//! then the heights are kept as they are, with spacing `Δx = (x_last − x_0)/(n − 1)` and
//! length `n Δx` (the crate's convention for a line, as SurfaceTopography's for a uniform
//! one). Otherwise the profile is resampled onto `n` uniform points by linear
//! interpolation (SurfaceTopography's reading of a non-uniform profile as piecewise
//! linear), and the resampling is reported as a cleaning step. Facts from
//! SurfaceTopography's `XYZReader` (Dektak header, column units).

use ndarray::{Array1, Array2};

use super::text::{decode, lines, numbers, tokens};
use super::{bad, unit_to_metres, Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "xyz";

/// Header lines skipped at most before the first row of numbers.
const MAX_HEADER_LINES: usize = 400;

/// The columns of a file: values per column, the printing precision per column (one unit
/// of the finest last digit printed: a fixed-precision column like Dektak's `0.2` gives
/// 0.1, a shortest-representation one its finest value's digit), and the units the header
/// names per column.
struct Columns {
    data: Vec<Vec<f64>>,
    ulp: Vec<f64>,
    units: Vec<Option<f64>>,
    unit_names: Vec<Option<String>>,
}

/// One unit of the last printed digit of a number token (`0.2` → 0.1, `1.5e+01` → 1).
fn last_digit_unit(token: &str) -> f64 {
    let (mantissa, exponent) = match token.find(['e', 'E']) {
        Some(i) => (&token[..i], token[i + 1..].parse::<i32>().unwrap_or(0)),
        None => (token, 0),
    };
    let decimals = mantissa
        .split_once('.')
        .map_or(0, |(_, d)| d.len().min(300) as i32);
    10f64.powi(exponent.clamp(-300, 300) - decimals)
}

/// The length unit a column name ends with (`Lateral um` → µm), if any.
fn column_unit(name: &str) -> Option<String> {
    name.split(|c: char| c.is_whitespace() || c == '(' || c == ')' || c == '[' || c == ']')
        .filter(|w| w.len() > 1 || *w == "m")
        .rev()
        .find(|w| unit_to_metres(w).is_some())
        .map(super::canonical_unit)
}

/// Splits the file into its numeric columns (see the module docs).
fn columns(bytes: &[u8]) -> Result<Columns> {
    let text = decode(bytes);
    let mut lines = lines(&text).enumerate().peekable();
    let mut names: Vec<String> = Vec::new();
    if text.trim_start().starts_with("Scan Parameters") {
        // Dektak: skip to `Scan Data`; the next line names the columns.
        lines.find(|(_, l)| l.trim_start().starts_with("Scan Data"));
        let Some((_, header)) = lines.next() else {
            return Err(bad(FORMAT, "Dektak file without data after `Scan Data`"));
        };
        names = header.split(',').map(|s| s.trim().to_string()).collect();
    }
    let mut row = Vec::new();
    let mut skipped = 0;
    while let Some((_, line)) = lines.peek() {
        if numbers(line, &mut row) {
            break;
        }
        skipped += 1;
        if skipped > MAX_HEADER_LINES {
            return Err(bad(FORMAT, "no rows of numbers after the header"));
        }
        lines.next();
    }
    let mut out: Option<Columns> = None;
    for (number_of_line, line) in lines {
        if !numbers(line, &mut row) {
            return Err(bad(
                FORMAT,
                format!("line {}: not a row of numbers", number_of_line + 1),
            ));
        }
        let cols = out.get_or_insert_with(|| Columns {
            data: vec![Vec::new(); row.len().min(4)],
            ulp: vec![f64::INFINITY; row.len().min(4)],
            units: vec![None; row.len().min(4)],
            unit_names: vec![None; row.len().min(4)],
        });
        if row.len() != cols.data.len() || row.len() > 3 {
            return Err(bad(
                FORMAT,
                format!(
                    "line {}: {} values; a column file has the same 1, 2 or 3 on every line",
                    number_of_line + 1,
                    row.len()
                ),
            ));
        }
        for (i, (token, v)) in tokens(line).zip(&row).enumerate() {
            cols.data[i].push(*v);
            cols.ulp[i] = cols.ulp[i].min(last_digit_unit(token));
        }
    }
    let mut cols = out.ok_or_else(|| bad(FORMAT, "no rows of numbers"))?;
    for (i, name) in names.iter().enumerate().take(cols.data.len()) {
        cols.unit_names[i] = column_unit(name);
        cols.units[i] = cols.unit_names[i].as_deref().and_then(unit_to_metres);
    }
    Ok(cols)
}

/// Reads a column file (see the module docs).
#[cfg(test)]
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    read_with_notes(bytes).map(|(r, _)| r)
}

/// Reads a column file; the notes say what was done beyond reading (a resampling).
pub(crate) fn read_with_notes(bytes: &[u8]) -> Result<(Reading, Vec<String>)> {
    let cols = columns(bytes)?;
    match cols.data.len() {
        1 => Ok((
            profile_reading(Array1::from(cols.data[0].clone()), None, None),
            Vec::new(),
        )),
        2 => {
            let (z, size, notes) = profile(&cols.data[0], &cols.data[1], cols.ulp[0])?;
            let size = size * cols.units[0].unwrap_or(1.0);
            let z = z * cols.units[1].unwrap_or(1.0);
            let unit = cols.unit_names[1]
                .clone()
                .filter(|_| cols.units[0].is_some());
            Ok((profile_reading(z, Some(size), unit), notes))
        }
        _ => {
            let (x, y, z) = (&cols.data[0], &cols.data[1], &cols.data[2]);
            // Printed values that differ at all differ by at least one unit of the digit.
            let constant = |v: &[f64], ulp: f64| v.iter().all(|a| (a - v[0]).abs() < 0.5 * ulp);
            if constant(y, cols.ulp[1]) {
                let (z, size, notes) = profile(x, z, cols.ulp[0])?;
                return Ok((profile_reading(z, Some(size), None), notes));
            }
            if constant(x, cols.ulp[0]) {
                let (z, size, notes) = profile(y, z, cols.ulp[1])?;
                return Ok((profile_reading(z, Some(size), None), notes));
            }
            grid(x, y, z, cols.ulp[0], cols.ulp[1])
        }
    }
}

fn profile_reading(z: Array1<f64>, size: Option<f64>, unit: Option<String>) -> Reading {
    Reading {
        format: "xyz",
        channels: vec![Channel {
            name: "profile".into(),
            heights: Heights::Profile(z),
            size: [size, None],
            unit,
            is_height: true,
        }],
    }
}

/// Heights on a uniform grid along x, the length `n Δx`, and the notes of a resampling.
fn profile(x: &[f64], z: &[f64], ulp: f64) -> Result<(Array1<f64>, f64, Vec<String>)> {
    let n = x.len();
    if n < 2 {
        return Err(bad(FORMAT, "a profile needs at least 2 points"));
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(bad(FORMAT, "an x position is not a finite number"));
    }
    let (x, z): (Vec<f64>, Vec<f64>) = if x[n - 1] < x[0] {
        (
            x.iter().rev().copied().collect(),
            z.iter().rev().copied().collect(),
        )
    } else {
        (x.to_vec(), z.to_vec())
    };
    if let Some(i) = (1..n).find(|&i| x[i] <= x[i - 1]) {
        return Err(bad(
            FORMAT,
            format!(
                "x positions are not strictly monotonic (point {i}: {})",
                x[i]
            ),
        ));
    }
    let range = x[n - 1] - x[0];
    let dx = range / (n - 1) as f64;
    let tol = ulp + 1e-12 * range;
    let uniform = (0..n).all(|i| (x[i] - (x[0] + i as f64 * dx)).abs() <= tol);
    if uniform {
        return Ok((Array1::from(z), n as f64 * dx, Vec::new()));
    }
    // Piecewise-linear interpolation at x_0 + i Δx.
    let mut k = 0;
    let resampled = Array1::from_shape_fn(n, |i| {
        let xi = x[0] + i as f64 * dx;
        while k + 2 < n && x[k + 1] < xi {
            k += 1;
        }
        let t = ((xi - x[k]) / (x[k + 1] - x[k])).clamp(0.0, 1.0);
        z[k] + t * (z[k + 1] - z[k])
    });
    let note = format!(
        "resampled {n} points at non-uniform x onto a uniform grid of spacing {dx:e} by linear interpolation"
    );
    Ok((resampled, n as f64 * dx, vec![note]))
}

/// The distinct values of `v` (within `tol`), if they are uniformly spaced: first value,
/// spacing, count.
fn axis(v: &[f64], tol: f64, name: &str) -> Result<(f64, f64, usize)> {
    let mut sorted: Vec<f64> = v.to_vec();
    if sorted.iter().any(|a| !a.is_finite()) {
        return Err(bad(
            FORMAT,
            format!("a {name} position is not a finite number"),
        ));
    }
    sorted.sort_by(f64::total_cmp);
    let mut distinct = vec![sorted[0]];
    for &a in &sorted[1..] {
        if a - distinct[distinct.len() - 1] >= 0.5 * tol {
            distinct.push(a);
        }
    }
    let m = distinct.len();
    if m == 1 {
        return Ok((distinct[0], 0.0, 1));
    }
    let step = (distinct[m - 1] - distinct[0]) / (m - 1) as f64;
    let uniform = distinct
        .iter()
        .enumerate()
        .all(|(i, a)| (a - (distinct[0] + i as f64 * step)).abs() <= tol + 1e-9 * step);
    if !uniform {
        return Err(bad(
            FORMAT,
            format!("the {name} positions of the x y z list are not on a uniform grid"),
        ));
    }
    Ok((distinct[0], step, m))
}

/// An x y z list on a regular grid as a map: rows along y, columns along x.
fn grid(x: &[f64], y: &[f64], z: &[f64], ulp_x: f64, ulp_y: f64) -> Result<(Reading, Vec<String>)> {
    let n = z.len();
    let (x0, dx, nx) = axis(x, ulp_x, "x")?;
    let (y0, dy, ny) = axis(y, ulp_y, "y")?;
    let cells = nx.checked_mul(ny).filter(|&c| c <= 2 * n).ok_or_else(|| {
        bad(
            FORMAT,
            format!(
                "{nx} x {ny} grid positions for {n} points: not a grid (more than half missing)"
            ),
        )
    })?;
    if nx < 2 || ny < 2 {
        return Err(bad(FORMAT, "a map needs at least 2 x 2 points"));
    }
    let mut heights = Array2::from_elem((ny, nx), f64::NAN);
    let mut seen = vec![false; cells];
    for k in 0..n {
        let col = ((x[k] - x0) / dx).round() as usize;
        let row = ((y[k] - y0) / dy).round() as usize;
        if row >= ny || col >= nx {
            return Err(bad(FORMAT, format!("point {} is off the grid", k + 1)));
        }
        let cell = row * nx + col;
        if std::mem::replace(&mut seen[cell], true) {
            return Err(bad(
                FORMAT,
                format!("point {} repeats grid position ({}, {})", k + 1, x[k], y[k]),
            ));
        }
        heights[(row, col)] = z[k];
    }
    let reading = Reading {
        format: "xyz",
        channels: vec![Channel {
            name: "heights".into(),
            heights: Heights::Areal(heights),
            size: [Some(nx as f64 * dx), Some(ny as f64 * dy)],
            unit: None,
            is_height: true,
        }],
    };
    Ok((reading, Vec::new()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::test_files::{assert_close, folder, fuzz, record, reference};

    #[test]
    fn dektak_matches_the_reference() {
        let Some(dir) = folder() else { return };
        let name = "dektak-1.csv";
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let (reading, notes) = read_with_notes(&bytes).unwrap();
        // Positions are printed to 0.1 µm at a 0.156 µm step: uniform within printing
        // precision, so the heights are kept as read.
        assert!(notes.is_empty(), "{notes:?}");
        let c = &reading.channels[0];
        assert_eq!(c.unit.as_deref(), Some("µm"));
        let Heights::Profile(h) = &c.heights else {
            panic!()
        };
        let reference = reference(&dir, name);
        assert_eq!(reference.shape(), &[h.len()]);
        for (a, b) in h.iter().zip(reference.iter()) {
            assert_close(*a, *b, 1e-12, name);
        }
        // SurfaceTopography's tolerance (1e-6 absolute) calls it non-uniform and reports
        // the x range, x_last − x_0; ours is n Δx = range · n/(n − 1) (one more spacing).
        let range = record(&dir, name)["physical_sizes_m"][0].as_f64().unwrap();
        let n = h.len() as f64;
        assert_close(c.size[0].unwrap(), range * n / (n - 1.0), 1e-12, name);
    }

    #[test]
    fn nonuniform_profile_is_resampled_and_says_so() {
        let Some(dir) = folder() else { return };
        let name = "xy-1.txt";
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let (reading, notes) = read_with_notes(&bytes).unwrap();
        assert_eq!(notes.len(), 1, "{notes:?}");
        let c = &reading.channels[0];
        assert_eq!(c.unit, None); // the file gives none: raw numbers
        let Heights::Profile(h) = &c.heights else {
            panic!()
        };
        // The reference holds the file's z at its non-uniform x; ours is their linear
        // interpolation at x_0 + iΔx: equal at both ends, and every interior value lies
        // between the two reference values that bracket it.
        let reference = reference(&dir, name);
        let z: Vec<f64> = reference.iter().copied().collect();
        let cols = columns(&bytes).unwrap();
        assert_eq!(cols.data[1], z, "the file's z are the reference heights");
        let x = &cols.data[0];
        let n = z.len();
        assert_eq!(h.len(), n);
        assert_close(h[0], z[0], 1e-15, name);
        assert_close(h[n - 1], z[n - 1], 1e-12, name);
        let dx = (x[n - 1] - x[0]) / (n - 1) as f64;
        for i in 0..n {
            let xi = x[0] + i as f64 * dx;
            let k = x.partition_point(|&v| v <= xi).clamp(1, n - 1);
            let t = (xi - x[k - 1]) / (x[k] - x[k - 1]);
            let want = z[k - 1] + t * (z[k] - z[k - 1]);
            assert_close(h[i], want, 1e-12, name);
        }
        let range = record(&dir, name)["physical_sizes_file_unit"][0]
            .as_f64()
            .unwrap();
        assert_close(
            c.size[0].unwrap(),
            range * n as f64 / (n - 1) as f64,
            1e-12,
            name,
        );
    }

    #[test]
    fn xyz_grid_with_a_missing_point() {
        let mut text = String::new();
        for row in 0..3 {
            for col in 0..4 {
                if (row, col) != (1, 2) {
                    text += &format!(
                        "{} {} {}\n",
                        col as f64 * 0.5,
                        row as f64 * 0.25,
                        row * 10 + col
                    );
                }
            }
        }
        let (r, _) = read_with_notes(text.as_bytes()).unwrap();
        let Heights::Areal(h) = &r.channels[0].heights else {
            panic!()
        };
        assert_eq!(h.dim(), (3, 4));
        assert!(h[(1, 2)].is_nan());
        assert_eq!(h[(2, 3)], 23.0);
        assert_eq!(r.channels[0].size, [Some(2.0), Some(0.75)]);
        assert!(read(b"0 0 1\n0 0 2\n1 1 3\n1 0 4\n0 1 5\n").is_err()); // repeated point
        assert!(read(b"0 0 1\n1 0 2\n5 1 3\n").is_err()); // not a grid
    }

    #[test]
    fn uniform_two_column_profile() {
        let (r, notes) = read_with_notes(b"0 1\n0.5 2\n1.0 3\n1.5 nan\n").unwrap();
        assert!(notes.is_empty());
        assert_eq!(r.channels[0].size[0], Some(2.0));
        assert!(read(b"0 1\n2 2\n1 3\n").is_err()); // not monotonic
    }

    #[test]
    fn fuzzed_columns_never_panic() {
        let Some(dir) = folder() else { return };
        let bytes = std::fs::read(dir.join("xy-1.txt")).unwrap();
        fuzz(&bytes, read);
        let bytes = std::fs::read(dir.join("dektak-1.csv")).unwrap();
        fuzz(&bytes[..6000.min(bytes.len())], read);
    }
}
