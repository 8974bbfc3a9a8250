//! Plain-text height matrices: one row of the map per line (x along a line, y down the
//! lines), values separated by white space, commas or semicolons; `NaN`, `BAD` or `inf`
//! mark undefined points. A header (lines that are not all numbers, usually starting with
//! `#`) may give, as Gwyddion's ASCII export writes it, `Channel:`, `Width:` (size along
//! x), `Height:` (size along y) with their units, and `Value units:` (the heights' unit);
//! also `x-length =`, `y-length =`, `x-unit =`, `y-unit =`, `z-unit =`. A header after data
//! starts another channel. Without a header the file carries no size and no unit.
//!
//! Facts from Gwyddion's export format and SurfaceTopography's `AscReader` (whose `[x, y]`
//! array is the transpose of ours: a text line is one of our rows).

use ndarray::Array2;

use super::{bad, unit_to_metres, Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "text";

/// Largest header line kept for parsing (longer ones are skipped).
const MAX_HEADER_LINE: usize = 4096;

/// Text if the first 4 KiB hold no NUL and no other control characters than white space.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(4096)];
    !head.is_empty()
        && head
            .iter()
            .all(|&b| b >= 0x20 || matches!(b, b'\t' | b'\n' | b'\r' | 0x0c))
}

/// The text: UTF-8 where it is, else Latin-1 (one byte, one character).
pub(crate) fn decode(bytes: &[u8]) -> std::borrow::Cow<'_, str> {
    match std::str::from_utf8(bytes) {
        Ok(s) => s.into(),
        Err(_) => bytes.iter().map(|&b| b as char).collect::<String>().into(),
    }
}

/// Lines split at `\n`, `\r\n` or a lone `\r` (old Mac files, Dektak exports).
pub(crate) fn lines(text: &str) -> impl Iterator<Item = &str> {
    text.split(['\n', '\r']).filter(|l| !l.trim().is_empty())
}

/// One number, with the spellings of undefined points as NaN.
pub(crate) fn number(token: &str) -> Option<f64> {
    match token.to_ascii_lowercase().as_str() {
        "nan" | "bad" | "inf" | "-inf" | "+inf" | "infinite" => Some(f64::NAN),
        _ => token
            .parse::<f64>()
            .ok()
            .map(|v| if v.is_finite() { v } else { f64::NAN }),
    }
}

/// The tokens of a line: separated by white space, commas or semicolons; empty ones
/// (trailing commas) dropped.
pub(crate) fn tokens(line: &str) -> impl Iterator<Item = &str> {
    line.split(|c: char| c.is_whitespace() || c == ',' || c == ';')
        .filter(|t| !t.is_empty())
}

/// The numbers of a line if every token is one.
pub(crate) fn numbers(line: &str, out: &mut Vec<f64>) -> bool {
    out.clear();
    for t in tokens(line) {
        match number(t) {
            Some(v) => out.push(v),
            None => return false,
        }
    }
    !out.is_empty()
}

/// What a text file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TextKind {
    /// A height matrix (possibly with a header).
    Matrix,
    /// Columns of coordinates: x z (a profile) or x y z (a map as a point list).
    Columns,
}

/// A matrix when a Gwyddion-style header is present or the rows have 4 or more values;
/// columns (z, x z or x y z) when they have 1 to 3 and no matrix header; a Dektak export
/// (`Scan Parameters`) is columns.
pub(crate) fn kind(bytes: &[u8]) -> Result<TextKind> {
    let text = decode(&bytes[..bytes.len().min(1 << 16)]);
    if text.trim_start().starts_with("Scan Parameters") {
        return Ok(TextKind::Columns);
    }
    let mut values = Vec::new();
    let mut header = false;
    for line in lines(&text).take(400) {
        if numbers(line, &mut values) {
            return Ok(if header || values.len() >= 4 {
                TextKind::Matrix
            } else {
                TextKind::Columns
            });
        }
        header |= header_entry(line).is_some();
    }
    Err(bad(FORMAT, "no line of numbers in the first 400 lines"))
}

/// A header entry `key: value` or `key = value`, key lower-cased, `#` and spaces trimmed.
fn header_entry(line: &str) -> Option<(String, String)> {
    let line = line.trim().trim_start_matches('#').trim();
    if line.len() > MAX_HEADER_LINE {
        return None;
    }
    let (key, value) = line.split_once(':').or_else(|| line.split_once('='))?;
    let key = key.trim().to_ascii_lowercase();
    let known = [
        "channel",
        "width",
        "height",
        "value units",
        "x-length",
        "y-length",
        "x-unit",
        "y-unit",
        "z-unit",
    ];
    known
        .contains(&key.as_str())
        .then(|| (key, value.trim().to_string()))
}

/// A length with its unit (`12.34 µm`), in metres; `None` when the unit is unknown.
/// Without a unit the number is returned as it is, marked as such.
fn length(value: &str) -> Option<(f64, bool)> {
    let mut parts = value.split_whitespace();
    let number: f64 = parts.next()?.parse().ok()?;
    match parts.next() {
        Some(unit) => unit_to_metres(unit).map(|f| (number * f, true)),
        None => Some((number, false)),
    }
}

/// One block of the file: its header entries and its rows.
#[derive(Default)]
struct Block {
    header: Vec<(String, String)>,
    values: Vec<f64>,
    rows: usize,
    cols: usize,
}

/// Reads a text height matrix (see the module docs).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    let text = decode(bytes);
    let mut blocks: Vec<Block> = vec![Block::default()];
    let mut row = Vec::new();
    for (number, line) in lines(&text).enumerate() {
        if numbers(line, &mut row) {
            let block = blocks.last_mut().expect("one block");
            if block.rows == 0 {
                block.cols = row.len();
            } else if row.len() != block.cols {
                return Err(bad(
                    FORMAT,
                    format!(
                        "line {}: {} values where the rows before have {}",
                        number + 1,
                        row.len(),
                        block.cols
                    ),
                ));
            }
            block.values.extend_from_slice(&row);
            block.rows += 1;
        } else if let Some(entry) = header_entry(line) {
            if blocks.last().is_some_and(|b| b.rows > 0) {
                blocks.push(Block::default());
            }
            blocks.last_mut().expect("one block").header.push(entry);
        } else if blocks.last().is_some_and(|b| b.rows > 0) {
            return Err(bad(
                FORMAT,
                format!("line {}: not a row of numbers", number + 1),
            ));
        }
    }
    let channels = blocks
        .into_iter()
        .filter(|b| b.rows > 0)
        .enumerate()
        .map(|(i, b)| channel(i, b))
        .collect::<Result<Vec<_>>>()?;
    if channels.is_empty() {
        return Err(bad(FORMAT, "no rows of numbers"));
    }
    Ok(Reading {
        format: "text",
        channels,
    })
}

/// A block as a channel: heights scaled by `Value units`, sizes from `Width`/`Height`.
fn channel(index: usize, block: Block) -> Result<Channel> {
    let get = |key: &str| {
        block
            .header
            .iter()
            .rev()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    };
    if block.rows < 2 || block.cols < 2 {
        return Err(bad(
            FORMAT,
            format!(
                "a height matrix needs at least 2 rows and 2 columns, found {} x {}",
                block.rows, block.cols
            ),
        ));
    }
    let z_unit = get("value units").or(get("z-unit")).map(str::trim);
    let z_factor = z_unit.and_then(unit_to_metres);
    // Sizes: `Width: 12.34 µm`, or `x-length = 12.34` with `x-unit = µm`; a size without
    // a known unit is taken in the heights' unit when that is a length, else ignored.
    let size = |value: Option<&str>, unit: Option<&str>| -> Option<f64> {
        let (v, with_unit) = length(value?)?;
        if with_unit {
            return Some(v);
        }
        match unit.and_then(unit_to_metres).or(z_factor) {
            Some(f) => Some(v * f),
            None => Some(v),
        }
    };
    let sx = size(get("width").or(get("x-length")), get("x-unit"));
    let sy = size(get("height").or(get("y-length")), get("y-unit"));
    let mut heights = Array2::from_shape_vec((block.rows, block.cols), block.values)
        .map_err(|e| bad(FORMAT, e.to_string()))?;
    if let Some(f) = z_factor {
        heights.mapv_inplace(|v| v * f);
    }
    Ok(Channel {
        name: get("channel")
            .map(str::to_string)
            .unwrap_or_else(|| format!("channel {index}")),
        heights: Heights::Areal(heights),
        size: [sx, sy],
        unit: z_unit.map(super::canonical_unit),
        is_height: z_unit.is_none() || z_factor.is_some(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::test_files::{assert_close, folder, fuzz, record, reference};

    /// Our `(row, col) = (y, x)` heights against the reference `[x, y]`: transposed.
    fn check_against_reference(name: &str) {
        let Some(dir) = folder() else { return };
        let bytes = std::fs::read(dir.join(name)).unwrap();
        assert_eq!(kind(&bytes).unwrap(), TextKind::Matrix, "{name}");
        let reading = read(&bytes).unwrap();
        let record = record(&dir, name);
        let channel = &reading.channels[0];
        assert_eq!(channel.name, record["default_channel"].as_str().unwrap());
        let Heights::Areal(h) = &channel.heights else {
            panic!("{name}: a map")
        };
        let reference = reference(&dir, name);
        assert_eq!(reference.shape(), &[h.ncols(), h.nrows()], "{name}: [x, y]");
        for ((x, y), v) in reference
            .into_dimensionality::<ndarray::Ix2>()
            .unwrap()
            .indexed_iter()
        {
            assert_close(h[(y, x)], *v, 1e-12, name);
        }
        for (axis, size) in channel.size.iter().enumerate() {
            let want = record["physical_sizes_m"][axis].as_f64().unwrap();
            assert_close(size.unwrap(), want, 1e-12, name);
        }
    }

    #[test]
    fn gwyddion_export_matches_the_reference() {
        check_against_reference("gwyddion-export-english.txt");
    }

    #[test]
    fn matrix_with_header_matches_the_reference() {
        check_against_reference("matrix-3.txt");
        check_against_reference("txt_example.txt");
    }

    #[test]
    fn headerless_matrix_has_no_size_nor_unit() {
        let r = read(b"1 2 3 4\n5 NaN 7 8\r\n9 10 11 12").unwrap();
        let c = &r.channels[0];
        assert_eq!(c.size, [None, None]);
        assert_eq!(c.unit, None);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_eq!(h.dim(), (3, 4));
        assert!(h[(1, 1)].is_nan());
        assert_eq!(h[(2, 3)], 12.0);
    }

    #[test]
    fn two_channels_and_ragged_rows() {
        let text = "# Channel: A\n# Width: 2 nm\n# Height: 1 nm\n# Value units: nm\n1 2\n3 4\n\
                    # Channel: Phase\n# Value units: deg\n5 6\n7 8\n";
        let r = read(text.as_bytes()).unwrap();
        assert_eq!(r.channels.len(), 2);
        assert_eq!(r.channels[0].size, [Some(2e-9), Some(1e-9)]);
        assert!(r.channels[0].is_height && !r.channels[1].is_height);
        assert!(read(b"1 2 3\n4 5\n").is_err());
        assert!(read(b"# Width: 1 m\n").is_err());
    }

    #[test]
    fn fuzzed_text_never_panics() {
        let Some(dir) = folder() else { return };
        for name in ["gwyddion-export-english.txt", "txt_example.txt"] {
            let bytes = std::fs::read(dir.join(name)).unwrap();
            fuzz(&bytes, read);
        }
    }
}
