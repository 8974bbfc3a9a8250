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

/// What the lines before the numbers say: column names, per-column units, a point count.
#[derive(Default)]
struct Header {
    names: Option<Vec<String>>,
    units: Option<Vec<String>>,
    dektak: bool,
}

/// A line of units, one per column (`µm µm`, `[mm];[mm];[1/0]`): every token a length unit
/// or a bracketed unit, at least one a length unit.
fn units_line(line: &str) -> Option<Vec<String>> {
    let words: Vec<&str> = tokens(line).collect();
    let bracketed = |w: &str| w.starts_with(['[', '(']) && w.ends_with([']', ')']);
    let ok = words
        .iter()
        .all(|w| unit_to_metres(w).is_some() || bracketed(w))
        && words.iter().any(|w| unit_to_metres(w).is_some());
    ok.then(|| words.iter().map(|w| w.to_string()).collect())
}

/// The lines before the first row of numbers, classified; anything else is refused.
fn header(lines: &[(usize, &str)]) -> Result<Header> {
    let mut h = Header::default();
    for &(number, line) in lines {
        let trimmed = line.trim_start();
        if trimmed.starts_with('#') {
            continue;
        }
        if let Some(units) = units_line(line) {
            if h.units.replace(units).is_some() {
                return Err(bad(
                    FORMAT,
                    format!("line {}: a second line of units", number + 1),
                ));
            }
        } else if h.names.is_none() && h.units.is_none() {
            h.names = Some(column_names(line));
        } else {
            return Err(bad(
                FORMAT,
                format!(
                    "line {} `{}`: a header line this reader does not understand; refused rather than guessed",
                    number + 1,
                    super::text::clip(line)
                ),
            ));
        }
    }
    Ok(h)
}

/// The names of a line of column names: split at commas, semicolons or tabs where it has
/// any (a name may hold spaces: `Lateral um`), else at spaces.
fn column_names(line: &str) -> Vec<String> {
    let names: Vec<&str> = if line.contains([',', ';', '\t']) {
        line.split([',', ';', '\t']).collect()
    } else {
        line.split_whitespace().collect()
    };
    names
        .into_iter()
        .map(str::trim)
        .filter(|n| !n.is_empty())
        .map(str::to_string)
        .collect()
}

/// Whether a column name says what the column is: a coordinate (`x`, `Y`, `z1`,
/// `height`, `X_(microns)`), a length unit (`Lateral um`) or the valid-point flag.
fn coordinate_name(name: &str) -> bool {
    let lower = name.to_lowercase();
    let stem: String = lower.chars().take_while(|c| c.is_alphabetic()).collect();
    const WORDS: &[&str] = &[
        "x",
        "y",
        "z",
        "h",
        "height",
        "heights",
        "position",
        "lateral",
        "distance",
        "depth",
        "profile",
        "topography",
        "valid",
    ];
    WORDS.contains(&stem.as_str()) || column_unit(name).is_some()
}

/// Splits the file into its numeric columns (see the module docs).
fn columns(bytes: &[u8]) -> Result<Columns> {
    let text = decode(bytes);
    let all: Vec<(usize, &str)> = lines(&text).enumerate().collect();
    let mut start = 0;
    let mut head = Header::default();
    let mut names: Vec<String> = Vec::new();
    if text.trim_start().starts_with("Scan Parameters") {
        // Dektak: skip to `Scan Data`; the next line names the columns.
        let at = all
            .iter()
            .position(|(_, l)| l.trim_start().starts_with("Scan Data"))
            .ok_or_else(|| bad(FORMAT, "Dektak file without data after `Scan Data`"))?;
        let Some((_, header)) = all.get(at + 1) else {
            return Err(bad(FORMAT, "Dektak file without data after `Scan Data`"));
        };
        names = header.split(',').map(|s| s.trim().to_string()).collect();
        head.dektak = true;
        start = at + 2;
    }
    let mut row = Vec::new();
    let first = all[start..]
        .iter()
        .take(MAX_HEADER_LINES + 1)
        .position(|(_, l)| numbers(l, &mut row))
        .map(|p| p + start)
        .ok_or_else(|| bad(FORMAT, "no rows of numbers after the header"))?;
    if !head.dektak {
        head = header(&all[start..first])?;
        names = head.names.clone().unwrap_or_default();
    }
    let mut cols = numeric_columns(skip_count_line(&all[first..])?)?;
    check_layout(&head, &names, &cols)?;
    assign_units(&mut cols, &head, &names)?;
    if let Some(v) = names.iter().position(|n| n.eq_ignore_ascii_case("valid")) {
        apply_valid_column(&mut cols, v)?;
    }
    Ok(cols)
}

/// The data lines without a point count alone on the first line before rows of 2 or 3
/// values (x y lists); the count must be the rows' (or one less, as some writers give).
fn skip_count_line<'a, 'b>(data: &'a [(usize, &'b str)]) -> Result<&'a [(usize, &'b str)]> {
    let [(line, count), (_, next), ..] = data else {
        return Ok(data);
    };
    let mut second = Vec::new();
    let Ok(n) = count.trim().parse::<usize>() else {
        return Ok(data);
    };
    if !(numbers(next, &mut second) && second.len() >= 2) {
        return Ok(data);
    }
    let rows = data.len() - 1;
    if n != rows && n + 1 != rows {
        return Err(bad(
            FORMAT,
            format!(
                "line {}: a count of {n} points where {rows} rows follow",
                line + 1
            ),
        ));
    }
    Ok(&data[1..])
}

/// Refuses what is no list of coordinates: a table whose column names are no coordinates,
/// or too few headerless rows to tell columns from a small matrix.
fn check_layout(head: &Header, names: &[String], cols: &Columns) -> Result<()> {
    if head.dektak {
        return Ok(());
    }
    if let Some(bad_name) = names.iter().find(|n| !coordinate_name(n)) {
        return Err(bad(
            FORMAT,
            format!(
                "column names `{}`: `{bad_name}` is neither a coordinate (x, y, z, height) nor a length; a table is not a topography",
                names.join("`, `")
            ),
        ));
    }
    let rows = cols.data[0].len();
    if head.names.is_none() && head.units.is_none() && rows < 4 && cols.data.len() > 1 {
        return Err(bad(
            FORMAT,
            format!(
                "{rows} rows of {} numbers and no header: too few to tell a height matrix from a list of coordinates; refused rather than guessed (give a matrix a header line such as `# Value units: m`, or the columns a line of names such as `x z`)",
                cols.data.len()
            ),
        ));
    }
    Ok(())
}

/// Each column's unit, from the units line or the column names.
fn assign_units(cols: &mut Columns, head: &Header, names: &[String]) -> Result<()> {
    let mut unit_words: Vec<Option<String>> = match &head.units {
        Some(u) => u.iter().map(|w| Some(w.clone())).collect(),
        None => names.iter().map(|n| column_unit(n)).collect(),
    };
    if head.dektak {
        unit_words.truncate(cols.data.len());
    }
    if !unit_words.is_empty() && unit_words.len() != cols.data.len() {
        return Err(bad(
            FORMAT,
            format!(
                "the header names {} columns, the rows hold {}",
                unit_words.len(),
                cols.data.len()
            ),
        ));
    }
    for (i, w) in unit_words.iter().enumerate() {
        cols.units[i] = w.as_deref().and_then(unit_to_metres);
        cols.unit_names[i] = w
            .as_deref()
            .filter(|w| unit_to_metres(w).is_some())
            .map(super::canonical_unit);
    }
    Ok(())
}

/// Drops the `valid` column (1 = measured, 0 = not), marking its zeros undefined in the
/// heights (the last remaining column).
fn apply_valid_column(cols: &mut Columns, v: usize) -> Result<()> {
    if cols.data.len() < 3 || v != cols.data.len() - 1 {
        return Err(bad(
            FORMAT,
            "a `valid` column must follow the x and height columns",
        ));
    }
    let flags = cols.data.remove(v);
    cols.ulp.remove(v);
    cols.units.remove(v);
    cols.unit_names.remove(v);
    let z = cols.data.last_mut().expect("two columns left");
    for (i, (f, z)) in flags.iter().zip(z.iter_mut()).enumerate() {
        if *f == 0.0 {
            *z = f64::NAN;
        } else if *f != 1.0 {
            return Err(bad(
                FORMAT,
                format!("row {}: valid flag {f} is neither 0 nor 1", i + 1),
            ));
        }
    }
    Ok(())
}

/// The numbers of the data lines as columns (the same 1, 2 or 3 on every line).
fn numeric_columns(data_lines: &[(usize, &str)]) -> Result<Columns> {
    let mut row = Vec::new();
    let mut out: Option<Columns> = None;
    for &(number_of_line, line) in data_lines {
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
    out.ok_or_else(|| bad(FORMAT, "no rows of numbers"))
}

/// Reads a column file (see the module docs).
#[cfg(test)]
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    read_with_notes(bytes).map(|(r, _)| r)
}

/// Reads a column file; the notes say what was done beyond reading (a resampling).
pub(crate) fn read_with_notes(bytes: &[u8]) -> Result<(Reading, Vec<String>)> {
    let cols = columns(bytes)?;
    // The file's units apply only when every coordinate has one (the positions' and the
    // heights'); otherwise all numbers are kept raw and the unit is `None`.
    let n = cols.data.len();
    let all_units: Option<Vec<f64>> = if n > 1 {
        cols.units.iter().copied().collect()
    } else {
        None
    };
    let (xf, zf, unit) = match &all_units {
        Some(f) => (f[0], f[n - 1], cols.unit_names[n - 1].clone()),
        None => (1.0, 1.0, None),
    };
    match n {
        1 => Ok((
            profile_reading(Array1::from(cols.data[0].clone()), None, None),
            Vec::new(),
        )),
        2 => {
            let (z, size, notes) = profile(&cols.data[0], &cols.data[1], cols.ulp[0])?;
            Ok((profile_reading(z * zf, Some(size * xf), unit), notes))
        }
        _ => {
            if all_units.as_ref().is_some_and(|f| f[0] != f[1]) {
                return Err(bad(FORMAT, "x and y are given in different units"));
            }
            let (x, y, z) = (&cols.data[0], &cols.data[1], &cols.data[2]);
            // Printed values that differ at all differ by at least one unit of the digit.
            let constant = |v: &[f64], ulp: f64| v.iter().all(|a| (a - v[0]).abs() < 0.5 * ulp);
            let (mut reading, notes) = if constant(y, cols.ulp[1]) {
                let (z, size, notes) = profile(x, z, cols.ulp[0])?;
                (profile_reading(z, Some(size), None), notes)
            } else if constant(x, cols.ulp[0]) {
                let (z, size, notes) = profile(y, z, cols.ulp[1])?;
                (profile_reading(z, Some(size), None), notes)
            } else {
                grid(x, y, z, cols.ulp[0], cols.ulp[1])?
            };
            let c = &mut reading.channels[0];
            c.size = c.size.map(|s| s.map(|s| s * xf));
            match &mut c.heights {
                Heights::Areal(h) => h.mapv_inplace(|v| v * zf),
                Heights::Profile(h) => h.mapv_inplace(|v| v * zf),
            }
            c.unit = unit;
            Ok((reading, notes))
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
            format!("the {name} positions of the x y z list are not on a uniform grid (a 3-column height matrix needs a header line such as `# Value units: m`)"),
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
    fn semicolon_profile_with_units_and_a_valid_column_matches_the_reference() {
        // `X;Y;valid` then `[mm];[mm];[1/0]`: x and heights in mm, the flag column dropped.
        use crate::topography::testkit::{check_shared, Expect};
        let expect = Expect {
            channel_names: false, // the peer's `default`, our `profile`
            ..Expect::default()
        };
        check_shared("topographies-2", "hfm-1.hfm", expect);
        let text = "X;Y;valid\n[mm];[mm];[1/0]\n0;1;1\n1;2;0\n2;3;1\n3;4;1\n";
        let c = &read(text.as_bytes()).unwrap().channels[0];
        let Heights::Profile(h) = &c.heights else {
            panic!("a profile")
        };
        assert_eq!(h.len(), 4);
        assert!(h[1].is_nan());
        assert_close(h[3], 4e-3, 1e-15, "mm");
        assert_eq!(c.unit.as_deref(), Some("mm"));
        assert_close(c.size[0].unwrap(), 4e-3, 1e-15, "4 × 1 mm");
        // A flag that is neither 0 nor 1, or no unit line and names only: as it says.
        assert!(read(b"X;Y;valid\n0;1;1\n1;2;2\n2;3;1\n3;4;1\n").is_err());
    }

    #[test]
    fn units_line_and_count_line() {
        // xy-2.txt: `µm µm`, then `23`, then 24 rows `x, z` at non-uniform x. The peer
        // ignores the units line (raw numbers); we take the file at its word: metres.
        let Some(dir) = crate::topography::testkit::set_dir("topographies-2") else {
            return;
        };
        let name = "xy-2.txt";
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let (reading, notes) = read_with_notes(&bytes).unwrap();
        assert_eq!(notes.len(), 1, "non-uniform x is resampled: {notes:?}");
        let c = &reading.channels[0];
        assert_eq!(c.unit.as_deref(), Some("µm"));
        let Heights::Profile(h) = &c.heights else {
            panic!()
        };
        let z: Vec<f64> = reference(&dir, name).iter().copied().collect();
        assert_eq!(h.len(), z.len());
        let n = z.len();
        assert_close(h[0], z[0] * 1e-6, 1e-12, name);
        assert_close(h[n - 1], z[n - 1] * 1e-6, 1e-12, name);
        let range = record(&dir, name)["physical_sizes_file_unit"][0]
            .as_f64()
            .unwrap();
        assert_close(
            c.size[0].unwrap(),
            range * 1e-6 * n as f64 / (n - 1) as f64,
            1e-12,
            name,
        );
        // A count that matches neither the rows nor the rows less one is refused.
        assert!(read(b"um um\n7\n0, 1\n1, 2\n2, 3\n3, 4\n").is_err());
    }

    #[test]
    fn csv_profile_with_a_unit_in_its_header() {
        // csv-1.csv: `X_(microns),y1`, 8 rows; x is uniform within its printing
        // precision (0.0386 steps, one of 0.0387), so the heights are the file's. The
        // heights have no unit: all numbers stay raw (unit None), as the peer reads them;
        // our length is n Δx where the peer reports the x range.
        use crate::topography::testkit::{check_shared, Expect};
        let range: f64 = 0.3089 - 0.0386;
        let expect = Expect {
            channel_names: false,
            unit: Some(None),
            size: Some([Some(range * 8.0 / 7.0), None]),
            ..Expect::default()
        };
        check_shared("topographies-3", "csv-1.csv", expect);
    }

    #[test]
    fn a_table_of_named_columns_is_refused() {
        let err = read(b"q,psd,q_l_2pi\n1,2,3\n2,3,4\n3,4,5\n4,5,6\n").unwrap_err();
        assert!(
            err.to_string().contains("a table is not a topography"),
            "{err}"
        );
        // Too few rows to tell columns from a matrix, without a header: refused.
        for text in ["1 2 3\n4 5 6\n", "1 2\n3 4\n", "0 1\n1 2\n2 3\n"] {
            let err = read(text.as_bytes()).unwrap_err().to_string();
            assert!(err.contains("refused rather than guessed"), "{err}");
        }
        // The same with names is a profile.
        assert!(read(b"x z\n0 1\n1 2\n").is_ok());
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
