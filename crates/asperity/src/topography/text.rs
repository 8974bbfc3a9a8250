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

/// A text file that starts with a byte-order mark — UTF-8 (`EF BB BF`), UTF-16
/// little-endian (`FF FE`) or big-endian (`FE FF`), as spreadsheet programs write CSV —
/// as UTF-8 without the mark, for the text readers; `None` where there is no mark. UTF-16
/// of an odd length or with an unpaired surrogate is refused in one line.
pub(crate) fn without_bom(bytes: &[u8]) -> Option<Result<Vec<u8>>> {
    let little = match bytes {
        [0xEF, 0xBB, 0xBF, rest @ ..] => return Some(Ok(rest.to_vec())),
        [0xFF, 0xFE, ..] => true,
        [0xFE, 0xFF, ..] => false,
        _ => return None,
    };
    let body = &bytes[2..];
    if !body.len().is_multiple_of(2) {
        return Some(Err(bad(
            FORMAT,
            "UTF-16 text of an odd number of bytes (truncated)",
        )));
    }
    let units = body.chunks_exact(2).map(|p| {
        let pair = [p[0], p[1]];
        if little {
            u16::from_le_bytes(pair)
        } else {
            u16::from_be_bytes(pair)
        }
    });
    let text: std::result::Result<String, _> = char::decode_utf16(units).collect();
    Some(
        text.map(String::into_bytes)
            .map_err(|e| bad(FORMAT, format!("UTF-16 text with {e}"))),
    )
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
        header |= !header_entries(line).is_empty();
    }
    Err(bad(FORMAT, "no line of numbers in the first 400 lines"))
}

/// The header keys this reader knows, with the spellings that mean the same (Gwyddion's
/// German export; the `h=… w=…` grid line of some interferometer exports).
fn known_key(key: &str) -> Option<&'static str> {
    Some(match key {
        "channel" | "kanal" => "channel",
        "width" | "breite" => "width",
        "height" | "höhe" => "height",
        "value units" | "werteinheiten" => "value units",
        "x-length" => "x-length",
        "y-length" => "y-length",
        "x-unit" => "x-unit",
        "y-unit" => "y-unit",
        "z-unit" => "z-unit",
        "h" => "rows",
        "w" => "cols",
        "pixel size" => "pixel size",
        "data unit" => "data unit",
        "height conversion factor (-> m)" => "to metres",
        _ => return None,
    })
}

/// Words in a header key that say it changes the meaning of the numbers: an unknown key
/// holding one is refused rather than ignored.
const MEANINGFUL: &[&str] = &[
    "unit",
    "factor",
    "scale",
    "size",
    "pixel",
    "spacing",
    "offset",
    "resolution",
    "step",
    "range",
    "multiplier",
    "length",
    "width",
    "height",
    "conversion",
    "einheit",
];

/// A header line split into `key: value` / `key = value` pairs, key lower-cased, `#` and
/// spaces trimmed; a line of several `k=v` tokens (`h=650 w=650`) gives several.
fn raw_entries(line: &str) -> Vec<(String, String)> {
    let line = line.trim().trim_start_matches('#').trim();
    if line.len() > MAX_HEADER_LINE {
        return Vec::new();
    }
    let words: Vec<&str> = line.split_whitespace().collect();
    if words.len() > 1 && words.iter().all(|w| w.contains('=')) {
        return words
            .iter()
            .filter_map(|w| w.split_once('='))
            .map(|(k, v)| (k.trim().to_lowercase(), v.trim().to_string()))
            .collect();
    }
    match line.split_once(':').or_else(|| line.split_once('=')) {
        Some((k, v)) => vec![(k.trim().to_lowercase(), v.trim().to_string())],
        None => Vec::new(),
    }
}

/// The known header entries of a line, keys in their one spelling.
fn header_entries(line: &str) -> Vec<(String, String)> {
    raw_entries(line)
        .into_iter()
        .filter_map(|(k, v)| known_key(&k).map(|k| (k.to_string(), v)))
        .collect()
}

/// Why a header line before the data cannot be passed over: an unknown key that may
/// change the numbers' meaning, or a line of words that is no comment (`#`), such as the
/// column names of a table. `None`: a comment or known entries.
fn unknown_header(line: &str) -> Option<String> {
    let entries = raw_entries(line);
    if let Some((key, _)) = entries
        .iter()
        .find(|(k, _)| known_key(k).is_none() && MEANINGFUL.iter().any(|w| k.contains(w)))
    {
        return Some(format!(
            "header entry `{key}` is not one this reader knows, and it may change the heights or sizes"
        ));
    }
    if entries.is_empty() && !line.trim_start().starts_with('#') {
        return Some("neither a header entry (`key: value`), a `#` comment nor a row of numbers (column names of a table?)".into());
    }
    None
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

/// A line shortened for an error message (at most 60 characters).
pub(crate) fn clip(line: &str) -> String {
    let line = line.trim();
    match line.char_indices().nth(60) {
        Some((i, _)) => format!("{}…", &line[..i]),
        None => line.to_string(),
    }
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
        } else if let Some(why) = unknown_header(line) {
            return Err(bad(
                FORMAT,
                format!(
                    "line {} `{}`: {why}; refused rather than guessed",
                    number + 1,
                    clip(line)
                ),
            ));
        } else if !header_entries(line).is_empty() {
            if blocks.last().is_some_and(|b| b.rows > 0) {
                blocks.push(Block::default());
            }
            blocks
                .last_mut()
                .expect("one block")
                .header
                .extend(header_entries(line));
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
    check_grid(&block, get("rows"), get("cols"))?;
    let (z_unit, z_factor) = z_scale(
        get("to metres"),
        get("value units").or(get("z-unit")).or(get("data unit")),
    )?;
    // Sizes: `Width: 12.34 µm`, or `x-length = 12.34` with `x-unit = µm`; a size without
    // a known unit is taken in the heights' unit when that is a length, else ignored;
    // `pixel size = 0.37 µm` gives both (square pixels).
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
    let pixel = match get("pixel size") {
        Some(p) => Some(pixel_size(p)?),
        None => None,
    };
    let sx = size(get("width").or(get("x-length")), get("x-unit"))
        .or(pixel.map(|p| p * block.cols as f64));
    let sy = size(get("height").or(get("y-length")), get("y-unit"))
        .or(pixel.map(|p| p * block.rows as f64));
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
        unit: z_unit.as_deref().map(super::canonical_unit),
        is_height: z_unit.is_none() || z_factor.is_some(),
    })
}

/// The heights' unit and factor to metres: a `height conversion factor (-> m)` (the raw
/// numbers times it are metres, whatever their own unit), else the unit the header names.
fn z_scale(to_metres: Option<&str>, unit: Option<&str>) -> Result<(Option<String>, Option<f64>)> {
    if let Some(text) = to_metres {
        let f: f64 = text.trim().parse().map_err(|_| {
            bad(
                FORMAT,
                format!("height conversion factor {text:?} is not a number"),
            )
        })?;
        if !crate::is_positive_finite(f) {
            return Err(bad(
                FORMAT,
                format!("height conversion factor {f} is not positive and finite"),
            ));
        }
        return Ok((Some("m".into()), Some(f)));
    }
    let unit = unit.map(|u| u.trim().to_string());
    let factor = unit.as_deref().and_then(unit_to_metres);
    Ok((unit, factor))
}

/// `pixel size = 3.7e-7 m`: a length with a known unit, in metres.
fn pixel_size(value: &str) -> Result<f64> {
    match length(value) {
        Some((v, true)) if crate::is_positive_finite(v) => Ok(v),
        _ => Err(bad(
            FORMAT,
            format!("pixel size {value:?} is not a positive length with a known unit"),
        )),
    }
}

/// The header's grid (`h=… w=…`), where given, must be the matrix's.
fn check_grid(block: &Block, rows: Option<&str>, cols: Option<&str>) -> Result<()> {
    for (what, given, found) in [("h", rows, block.rows), ("w", cols, block.cols)] {
        let Some(given) = given else { continue };
        if given.trim().parse::<usize>().ok() != Some(found) {
            return Err(bad(
                FORMAT,
                format!(
                    "the header says {what}={given} but the matrix has {} rows of {} values",
                    block.rows, block.cols
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod bom_tests {
    //! Text files with a byte-order mark (UTF-8, UTF-16 LE and BE) read like the same text
    //! without one: the shared real text files re-encoded here (no other file is written).
    use super::without_bom;
    use crate::topography::{detect_and_read, testkit::set_dir};

    fn utf16(text: &str, little: bool) -> Vec<u8> {
        let mut out = if little {
            vec![0xFF, 0xFE]
        } else {
            vec![0xFE, 0xFF]
        };
        for u in text.encode_utf16() {
            out.extend(if little {
                u.to_le_bytes()
            } else {
                u.to_be_bytes()
            });
        }
        out
    }

    #[test]
    fn text_with_a_byte_order_mark_reads_like_without() {
        let files = [
            ("topographies", "dektak-1.csv"),
            ("topographies", "gwyddion-export-english.txt"),
            ("topographies-2", "gwyddion-export-german.txt"),
            ("topographies-2", "hfm-1.hfm"),
            ("topographies-3", "csv-1.csv"),
        ];
        for (set, name) in files {
            let Some(dir) = set_dir(set) else { return };
            let path = dir.join(name);
            let bytes = std::fs::read(&path).unwrap();
            // As the readers decode it (dektak-1.csv is Latin-1: its µ is one byte).
            let text = super::decode(&bytes).into_owned();
            let (plain, _) = detect_and_read(&path, &bytes).unwrap();
            let mut utf8 = vec![0xEF, 0xBB, 0xBF];
            utf8.extend_from_slice(&bytes);
            for marked in [utf8, utf16(&text, true), utf16(&text, false)] {
                let (read, _) =
                    detect_and_read(&path, &marked).unwrap_or_else(|e| panic!("{name}: {e}"));
                assert_eq!(read.format, plain.format, "{name}");
                assert_eq!(read.channels, plain.channels, "{name}");
            }
        }
    }

    #[test]
    fn corrupt_utf16_is_refused_in_one_line() {
        let text = "x y\n1 2\n2 3\n3 5\n4 7\n";
        let mut bytes = utf16(text, true);
        for cut in 3..bytes.len() {
            if let Some(Err(e)) = without_bom(&bytes[..cut]) {
                assert!(!e.to_string().contains('\n'), "{e}");
            }
        }
        // An unpaired high surrogate.
        bytes.extend([0x00, 0xD8, 0x41, 0x00]);
        let err = without_bom(&bytes).unwrap().unwrap_err().to_string();
        assert!(err.contains("UTF-16"), "{err}");
        assert!(without_bom(b"x y\n1 2\n").is_none());
    }
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
    fn pixel_size_and_height_conversion_factor_headers_match_the_reference() {
        // `h=… w=…`, `pixel size=… m`, `data unit=rad`, `height conversion factor (-> m)=…`:
        // the heights are the numbers times the factor, in metres; the sizes pixel × count.
        use crate::topography::testkit::{check_shared, Expect};
        for name in ["matrix-2.txt", "matrix-4.txt"] {
            let expect = Expect {
                channel_names: false, // the peer's `Default`, our `channel 0`
                ..Expect::default()
            };
            check_shared("topographies-2", name, expect);
        }
        let text =
            "h=2 w=3\npixel size=2 um\ndata unit=rad\nheight conversion factor (-> m)=1e-8\n\
                    1 2 3\n4 5 6\n";
        let c = &read(text.as_bytes()).unwrap().channels[0];
        assert_eq!(c.size, [Some(6e-6), Some(4e-6)]);
        assert_eq!(c.unit.as_deref(), Some("m"));
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_close(h[(1, 2)], 6e-8, 1e-15, "6 × 1e-8");
        // The header's grid must be the matrix's.
        let err = read(text.replace("w=3", "w=4").as_bytes()).unwrap_err();
        assert!(err.to_string().contains("w=4"), "{err}");
    }

    #[test]
    fn german_gwyddion_export_matches_the_reference() {
        use crate::topography::testkit::{check_shared, Expect};
        check_shared(
            "topographies-2",
            "gwyddion-export-german.txt",
            Expect::default(),
        );
    }

    #[test]
    fn a_header_the_reader_does_not_know_is_refused_not_ignored() {
        for text in [
            "z scale factor = 1e-9\n1 2 3 4\n5 6 7 8\n",
            "# Pixel spacing: 3 nm\n1 2 3 4\n5 6 7 8\n",
            "a,b,c,d\n1,2,3,4\n5,6,7,8\n",
        ] {
            let err = read(text.as_bytes()).unwrap_err().to_string();
            assert!(err.contains("line 1") && err.contains("refused"), "{err}");
            assert_eq!(err.lines().count(), 1);
        }
        // A comment without a key, or a key that cannot change the numbers, is passed over.
        assert!(read(b"# made by hand\n# Date: 2024-01-01\n1 2 3 4\n5 6 7 8\n").is_ok());
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
