//! **Keyence ZON** files (VK-X, VR series): `KPK0` or `KPK1`, a u32 (little-endian) length
//! and that many bytes of a BMP thumbnail, then a zip archive whose members are named by
//! fixed UUIDs (learnt from SurfaceTopography's `ZON.py`, after the reverse engineering it
//! credits; no real file was at hand, the tests write the layout):
//!
//! * `686613b8-27b5-4a29-8ffc-438c2780873e`: XML whose `XYCalibration/MeterPerPixel` is the
//!   pixel size and `ZCalibration/MeterPerUnit` the height of one count, both in metres;
//! * `4cdb0c75-5706-48cc-a9a1-adf395d609ae`: the heights: `width, height, element size,
//!   row bytes` (i32) and `height` rows of `row bytes` each, holding `width` i32 counts
//!   (rows along y, x fastest; a row may be padded).
//!
//! A height is `count · MeterPerUnit` metres; the sizes are `width · MeterPerPixel` and
//! `height · MeterPerPixel`. In `KPK1` files every member is compressed with Zstandard,
//! which this build does not decode: such a file is refused in those words.

use std::io::Cursor as IoCursor;

use super::bytes::{areal, bad, grid_points, Cursor, Endian};
use super::{Channel, Heights, Reading};
use crate::Result;
use zip::ZipArchive;

const FORMAT: &str = "zon";
const HEIGHTS: &str = "4cdb0c75-5706-48cc-a9a1-adf395d609ae";
const UNITS: &str = "686613b8-27b5-4a29-8ffc-438c2780873e";
/// The largest member read.
const MAX_MEMBER: u64 = 4 << 30;
const MAX_XML: u64 = 16 << 20;

/// Whether the bytes start with a ZON signature.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(b"KPK0") || bytes.starts_with(b"KPK1")
}

/// Parses a whole ZON file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if bytes.starts_with(b"KPK1") {
        return Err(bad(
            FORMAT,
            "a KPK1 file (members compressed with Zstandard) is not supported by this build",
        ));
    }
    if !bytes.starts_with(b"KPK0") {
        return Err(bad(FORMAT, "no KPK0/KPK1 signature"));
    }
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(4)?;
    let thumbnail = c.u32(Endian::Little)? as usize;
    c.skip(thumbnail)?;
    let mut archive = ZipArchive::new(IoCursor::new(&bytes[c.pos()..]))
        .map_err(|e| bad(FORMAT, format!("the archive after the thumbnail: {e}")))?;
    let xml = super::xlsx::member(&mut archive, FORMAT, UNITS, MAX_XML)?;
    let xml = String::from_utf8(xml).map_err(|_| bad(FORMAT, "the unit member is not UTF-8"))?;
    let doc = roxmltree::Document::parse(&xml)
        .map_err(|e| bad(FORMAT, format!("the unit member: {e}")))?;
    let per_pixel = calibration(&doc, "XYCalibration", "MeterPerPixel")?;
    let per_unit = calibration(&doc, "ZCalibration", "MeterPerUnit")?;
    let data = super::xlsx::member(&mut archive, FORMAT, HEIGHTS, MAX_MEMBER)?;
    let map = counts(&data)?.mapv(|v| v * per_unit);
    let (rows, cols) = map.dim();
    Ok(Reading {
        format: FORMAT,
        channels: vec![Channel {
            name: "default".into(),
            heights: Heights::Areal(map),
            size: [Some(cols as f64 * per_pixel), Some(rows as f64 * per_pixel)],
            unit: Some("m".into()),
            is_height: true,
        }],
    })
}

/// A positive finite number at `<section><field>` anywhere in the document.
fn calibration(doc: &roxmltree::Document<'_>, section: &str, field: &str) -> Result<f64> {
    let text = doc
        .descendants()
        .filter(|n| n.has_tag_name(section))
        .flat_map(|n| n.children())
        .find(|n| n.has_tag_name(field))
        .and_then(|n| n.text())
        .ok_or_else(|| bad(FORMAT, format!("no {section}/{field}")))?;
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| bad(FORMAT, format!("{section}/{field} is {text:?}")))
}

/// The i32 counts of the height member as a `(height, width)` map.
fn counts(data: &[u8]) -> Result<ndarray::Array2<f64>> {
    let le = Endian::Little;
    let mut c = Cursor::new(FORMAT, data);
    let (w, h, element, row_bytes) = (c.i32(le)?, c.i32(le)?, c.i32(le)?, c.i32(le)?);
    let (w, h) = (w.max(0) as usize, h.max(0) as usize);
    let n = grid_points(FORMAT, w as u64, h as u64)?;
    let row_bytes = usize::try_from(row_bytes).unwrap_or(0);
    if element != 4 || row_bytes < 4 * w {
        return Err(bad(
            FORMAT,
            format!("elements of {element} bytes in rows of {row_bytes} bytes for {w} points"),
        ));
    }
    let need = row_bytes
        .checked_mul(h)
        .and_then(|b| b.checked_add(16))
        .filter(|&b| b <= data.len())
        .ok_or_else(|| bad(FORMAT, format!("truncated: {h} rows of {row_bytes} bytes")))?;
    let mut values = Vec::with_capacity(n);
    for row in data[16..need].chunks_exact(row_bytes) {
        values.extend(
            row[..4 * w]
                .chunks_exact(4)
                .map(|b| f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]]))),
        );
    }
    areal(FORMAT, h, w, values)
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_close, assert_robust};
    use super::*;
    use std::io::Write;
    use std::time::Duration;

    /// A ZON file in the format's own layout: `KPK0`, a 6-byte stand-in thumbnail, and a
    /// zip with the unit XML and a 3 × 2 height member whose rows are padded to 16 bytes.
    fn write(magic: &[u8], counts: &[i32]) -> Vec<u8> {
        let mut zip = zip::ZipWriter::new(IoCursor::new(Vec::new()));
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        zip.start_file(UNITS, options).unwrap();
        zip.write_all(
            b"<?xml version=\"1.0\"?><UnitInfo><XYCalibration><MeterPerPixel>2.5e-7</MeterPerPixel>\
              </XYCalibration><ZCalibration><MeterPerUnit>1e-9</MeterPerUnit></ZCalibration></UnitInfo>",
        )
        .unwrap();
        zip.start_file(HEIGHTS, options).unwrap();
        let mut data = Vec::new();
        for v in [3i32, 2, 4, 16] {
            data.extend_from_slice(&v.to_le_bytes());
        }
        for row in counts.chunks(3) {
            data.extend(row.iter().flat_map(|v| v.to_le_bytes()));
            data.extend_from_slice(&[0xAB; 4]); // padding
        }
        zip.write_all(&data).unwrap();
        let archive = zip.finish().unwrap().into_inner();
        let mut f = magic.to_vec();
        f.extend_from_slice(&6u32.to_le_bytes());
        f.extend_from_slice(b"BM\0\0\0\0");
        f.extend_from_slice(&archive);
        f
    }

    #[test]
    fn a_written_file_reads_back() {
        let f = write(b"KPK0", &[1, -2, 3, 4, 5, 600]);
        assert!(sniff(&f));
        let r = read(&f).unwrap();
        let c = &r.channels[0];
        assert_close(c.size.iter().flatten(), &[7.5e-7, 5e-7]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_eq!(h.dim(), (2, 3));
        assert_close(h.iter(), &[1e-9, -2e-9, 3e-9, 4e-9, 5e-9, 600e-9]);
    }

    #[test]
    fn zstd_members_and_truncations_are_refused() {
        let err = read(&write(b"KPK1", &[0; 6])).unwrap_err().to_string();
        assert!(err.contains("Zstandard"), "{err}");
        let f = write(b"KPK0", &[1, -2, 3, 4, 5, 600]);
        assert_robust(
            &f,
            sniff,
            read,
            f.len() - 1,
            Some(4),
            Duration::from_millis(300),
        );
    }
}
