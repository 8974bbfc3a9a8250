//! WSxM files (`.stp`, `.top`, `.tom`; Nanotec Electrónica's WSxM SPM software).
//!
//! Layout (after Gwyddion's `wsxmfile.c` and SurfaceTopography's `WSXM.py`): a text header of
//! ISO-8859-1 lines, `WSxM file copyright …`, `SxM Image file`, `Image header size: N`, then
//! `[Section]` lines and `key: value` lines up to `[Header end]`; the data follow that line:
//! `rows × columns` little-endian samples of the `Image Data Type` (`short`/`integer`: i16,
//! the default when the entry is missing; `float`: f32; `double`: f64).
//!
//! Scale: `General Info / Z Amplitude` (e.g. `13.7 nm`) is the span of the image. Floating
//! data are stored in that unit already (as both peers read them); integer data are scaled so
//! that their span is the amplitude (Gwyddion's rule, with the span of the data themselves;
//! SurfaceTopography takes the span from the header's rounded `Maximum`/`Minimum` instead).
//! Lateral sizes are `Control / X Amplitude` and `Y Amplitude` (the latter defaults to the
//! former). A Z unit that is not a length (a current, `a.u.`) gives a non-height channel.
//!
//! Orientation: the image is stored rotated by 180°; like both peers we rotate it back, so
//! our map is the stored `rows × columns` block with both axes reversed.

use super::bytes::{areal, bad, grid_points, latin1, length_unit, samples};
use super::bytes::{metres_per, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;
use std::collections::HashMap;

const FORMAT: &str = "wsxm";
const MAGIC: &[u8] = b"WSxM file copyright";
const KIND: &str = "SxM Image file";
const HEADER_END: &[u8] = b"[Header end]";

/// Whether the bytes start with WSxM's two signature lines.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    let mut lines = bytes.split(|&b| b == b'\n');
    lines.next().is_some_and(|l| l.starts_with(MAGIC))
        && lines.next().is_some_and(|l| latin1(l).trim() == KIND)
}

/// `(section, key)` → value of the text header.
type Header = HashMap<(String, String), String>;

/// Parses a whole WSxM image file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(
            FORMAT,
            "the file does not start with the WSxM signature lines",
        ));
    }
    let end = find(bytes, HEADER_END)
        .ok_or_else(|| bad(FORMAT, "the header has no `[Header end]` line"))?;
    let header = parse_header(&bytes[..end])?;
    let mut data_start = end + HEADER_END.len();
    if bytes[data_start..].starts_with(b"\r\n") {
        data_start += 2;
    } else if bytes[data_start..].starts_with(b"\n") {
        data_start += 1;
    }
    let cols = count(&header, "Number of columns")?;
    let rows = count(&header, "Number of rows")?;
    let sample = match get(&header, "General Info", "Image Data Type") {
        None | Some("short") | Some("integer") => Sample::I16,
        Some("float") => Sample::F32,
        Some("double") => Sample::F64,
        Some(other) => return Err(bad(FORMAT, format!("unknown image data type `{other}`"))),
    };
    let n = grid_points(FORMAT, cols, rows)?;
    let mut values = samples(FORMAT, bytes, data_start, n, sample, Endian::Little)?;
    let (amplitude, z_unit) = amount(&header, "General Info", "Z Amplitude")?;
    let z = length_unit(&z_unit);
    let per_unit = z.map_or(1.0, |(_, f)| f);
    let span = if matches!(sample, Sample::I16) {
        let (lo, hi) = values
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
        if hi > lo {
            amplitude / (hi - lo)
        } else {
            0.0
        }
    } else {
        1.0
    };
    values.iter_mut().for_each(|v| *v *= span * per_unit);
    values.reverse(); // the 180° rotation: both axes reversed
    let map = areal(FORMAT, rows as usize, cols as usize, values)?;
    let size_x = lateral(&header, "X Amplitude")?;
    let size_y = match get(&header, "Control", "Y Amplitude") {
        Some(_) => lateral(&header, "Y Amplitude")?,
        None => size_x,
    };
    Ok(Reading {
        format: FORMAT,
        channels: vec![Channel {
            name: "Default".into(),
            heights: Heights::Areal(map),
            size: [Some(size_x), Some(size_y)],
            unit: Some(z.map_or(z_unit.clone(), |(u, _)| u.to_string())),
            is_height: z.is_some(),
        }],
    })
}

/// The first occurrence of `needle` in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// The `[Section]` and `key: value` lines after the three signature lines.
fn parse_header(text: &[u8]) -> Result<Header> {
    let mut header = Header::new();
    let mut section: Option<String> = None;
    for raw in text.split(|&b| b == b'\n').skip(3) {
        let line = latin1(raw);
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        if line.starts_with('[') && line.ends_with(']') {
            section = Some(line[1..line.len() - 1].to_string());
        } else if let (Some(s), Some((k, v))) = (&section, line.split_once(':')) {
            header.insert((s.clone(), k.trim().to_string()), v.trim().to_string());
        } else {
            return Err(bad(
                FORMAT,
                format!("header line `{line}` is outside a section or has no `:`"),
            ));
        }
    }
    Ok(header)
}

fn get<'a>(h: &'a Header, section: &str, key: &str) -> Option<&'a str> {
    h.get(&(section.to_string(), key.to_string()))
        .map(String::as_str)
}

/// A positive count of the `General Info` section.
fn count(h: &Header, key: &str) -> Result<u64> {
    get(h, "General Info", key)
        .and_then(|v| v.parse::<u64>().ok())
        .filter(|&n| n > 0)
        .ok_or_else(|| {
            bad(
                FORMAT,
                format!("`{key}` is missing or not a positive integer"),
            )
        })
}

/// A positive `number unit` entry.
fn amount(h: &Header, section: &str, key: &str) -> Result<(f64, String)> {
    let v = get(h, section, key).ok_or_else(|| bad(FORMAT, format!("`{key}` is missing")))?;
    let (number, unit) = v.split_once(' ').unwrap_or((v, ""));
    match number.trim().parse::<f64>() {
        Ok(x) if crate::is_positive_finite(x) => Ok((x, unit.trim().to_string())),
        _ => Err(bad(
            FORMAT,
            format!("`{key}` is `{v}`, not a positive amount"),
        )),
    }
}

/// A lateral size of the `Control` section, in metres.
fn lateral(h: &Header, key: &str) -> Result<f64> {
    let (x, unit) = amount(h, "Control", key)?;
    Ok(x * metres_per(FORMAT, key, &unit)?)
}

#[cfg(test)]
mod tests {
    use super::super::bytes::flip_cols;
    use super::super::bytes::flip_rows;
    use super::super::testkit::{assert_matches, assert_robust, reference, transposed};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        let Some(r) = reference("stp-1.stp") else {
            return;
        };
        // Both readers rotate the stored image by 180°; ours is then SurfaceTopography's
        // [x, y] array transposed.
        let reading = read(&r.bytes).unwrap();
        assert_matches(&reading, &r, &transposed(&r));
        // And the stored block itself, double data in nm, is the reference rotated back.
        let mut stored = transposed(&r);
        flip_rows(&mut stored);
        flip_cols(&mut stored);
        let raw = samples(
            FORMAT,
            &r.bytes,
            4607,
            256 * 256,
            Sample::F64,
            Endian::Little,
        );
        for (a, b) in raw.unwrap().iter().zip(stored.iter()) {
            assert!((a * 1e-9 - b).abs() <= 1e-12 * 1.3e-8);
        }
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(r) = reference("stp-1.stp") else {
            return;
        };
        assert_robust(
            &r.bytes,
            sniff,
            read,
            4607,
            Some(4),
            Duration::from_millis(300),
        );
    }

    #[test]
    fn integer_data_span_the_z_amplitude() {
        let mut f =
            b"WSxM file copyright UAM\r\nSxM Image file\r\nImage header size: 0\r\n".to_vec();
        f.extend_from_slice(
            b"[Control]\r\n    X Amplitude: 2 \xb5m\r\n[General Info]\r\n    Number of columns: 2\r\n\
              Number of rows: 1\r\n    Image Data Type: short\r\n    Z Amplitude: 8 nm\r\n\
              [Header end]\r\n",
        );
        for v in [-100i16, 300] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        let reading = read(&f).unwrap();
        let c = &reading.channels[0];
        assert_eq!(c.size, [Some(2e-6), Some(2e-6)]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        // Span 400 counts = 8 nm, and the row is stored right to left.
        let want = [300.0 * 2e-11, -100.0 * 2e-11];
        for (g, w) in h.iter().zip(want) {
            assert!((g - w).abs() < 1e-15 * 6e-9, "{g} vs {w}");
        }
    }
}
