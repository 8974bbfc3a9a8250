//! **Keyence ZON** files (VK-X, VR series): `KPK0` or `KPK1`, a u32 (little-endian) length
//! and that many bytes of a BMP thumbnail, then a zip archive whose members are named by
//! fixed UUIDs (learnt from SurfaceTopography's `ZON.py`, after the reverse engineering it
//! credits; no real file was at hand, the tests write the layout):
//!
//! * `686613b8-27b5-4a29-8ffc-438c2780873e`: XML whose `XYCalibration/MeterPerPixel` is the
//!   pixel size and `ZCalibration/MeterPerUnit` the height of one count, both in metres;
//! * `4cdb0c75-5706-48cc-a9a1-adf395d609ae`: the heights: `width, height, element size,
//!   row bytes` (i32) and `height` rows of `row bytes` each, holding `width` i32 counts
//!   (rows along y, x fastest; a row may be padded);
//! * `9e7ca6dd-0e6a-4d7b-8986-f0a7b773c916` (may be absent): a validity mask in the same
//!   layout with one byte per point; a point whose low two bits are not both zero (out of
//!   range, or excluded by the operator) is undefined, the higher bits (quality notes on
//!   points that keep plausible heights) are ignored, as SurfaceTopography 1.27 does.
//!
//! A height is `count · MeterPerUnit` metres; the sizes are `width · MeterPerPixel` and
//! `height · MeterPerPixel`. In `KPK1` files the bytes of every member are one Zstandard
//! frame (inside the zip member, itself stored or deflated), decoded by `ruzstd`; the
//! decoded size of a grid member is bounded by its own 16-byte header, read first, so a
//! Zstandard bomb is refused after decoding at most what the header justifies.

use std::io::{Cursor as IoCursor, Read};

use super::bytes::{areal, bad, grid_points, height_reading, Endian};
use super::zipped::{self, member};
use super::Reading;
use crate::Result;
use ndarray::Array2;
use zip::ZipArchive;

const FORMAT: &str = "zon";
const HEIGHTS: &str = "4cdb0c75-5706-48cc-a9a1-adf395d609ae";
const UNITS: &str = "686613b8-27b5-4a29-8ffc-438c2780873e";
const VALID: &str = "9e7ca6dd-0e6a-4d7b-8986-f0a7b773c916";
/// The largest member read.
const MAX_MEMBER: u64 = 4 << 30;
const MAX_XML: u64 = 16 << 20;

/// Whether the bytes start with a ZON signature.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(b"KPK0") || bytes.starts_with(b"KPK1")
}

/// A grid member's header and rows: `(width, height, row bytes, rows)`.
type Grid = (usize, usize, usize, Vec<u8>);

/// Parses a whole ZON file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "no KPK0/KPK1 signature"));
    }
    let zstd = bytes.starts_with(b"KPK1");
    let mut c = super::bytes::Cursor::new(FORMAT, bytes);
    c.seek(4)?;
    let thumbnail = c.u32(Endian::Little)? as usize;
    c.skip(thumbnail)?;
    let mut archive = ZipArchive::new(IoCursor::new(&bytes[c.pos()..]))
        .map_err(|e| bad(FORMAT, format!("the archive after the thumbnail: {e}")))?;
    let xml = unpacked(&mut archive, UNITS, zstd, |r| {
        let mut xml = Vec::new();
        r.take(MAX_XML + 1)
            .read_to_end(&mut xml)
            .map_err(|e| bad(FORMAT, format!("{UNITS}: {e}")))?;
        if xml.len() as u64 > MAX_XML {
            return Err(bad(
                FORMAT,
                format!("{UNITS} is larger than {MAX_XML} bytes"),
            ));
        }
        Ok(xml)
    })?;
    let xml = String::from_utf8(xml).map_err(|_| bad(FORMAT, "the unit member is not UTF-8"))?;
    let doc = roxmltree::Document::parse(&xml)
        .map_err(|e| bad(FORMAT, format!("the unit member: {e}")))?;
    let per_pixel = calibration(&doc, "XYCalibration", "MeterPerPixel")?;
    let per_unit = calibration(&doc, "ZCalibration", "MeterPerUnit")?;
    let heights = unpacked(&mut archive, HEIGHTS, zstd, |r| grid(r, HEIGHTS, 4))?;
    let mut map = counts(&heights)?;
    map.mapv_inplace(|v| v * per_unit);
    if zipped::has(&archive, VALID) {
        let mask = unpacked(&mut archive, VALID, zstd, |r| grid(r, VALID, 1))?;
        apply_mask(&mut map, &mask)?;
    }
    let (rows, cols) = map.dim();
    let size = [cols as f64 * per_pixel, rows as f64 * per_pixel];
    Ok(height_reading(FORMAT, "default", map, size, "m"))
}

/// Member `name` passed to `parse` as a reader of its bytes: the zip member itself
/// (bounded by [`member`]), or in a `KPK1` file the Zstandard frame it holds.
fn unpacked<T>(
    archive: &mut ZipArchive<IoCursor<&[u8]>>,
    name: &str,
    zstd: bool,
    parse: impl FnOnce(&mut dyn Read) -> Result<T>,
) -> Result<T> {
    let data = member(archive, FORMAT, name, MAX_MEMBER)?;
    if zstd {
        parse(&mut zipped::zstd(FORMAT, name, &data)?)
    } else {
        parse(&mut &data[..])
    }
}

/// A grid member: `width, height, element size, row bytes` (i32, little-endian), checked
/// (the element size must be `element`), then exactly `height` rows, read only once the
/// header has said how many bytes they are (so a member's size is justified by its grid).
fn grid(r: &mut dyn Read, name: &str, element: i32) -> Result<Grid> {
    let mut head = [0u8; 16];
    r.read_exact(&mut head)
        .map_err(|_| bad(FORMAT, format!("{name}: truncated header")))?;
    let field = |k: usize| {
        i32::from_le_bytes([
            head[4 * k],
            head[4 * k + 1],
            head[4 * k + 2],
            head[4 * k + 3],
        ])
    };
    let (w, h, size, row_bytes) = (field(0), field(1), field(2), field(3));
    let (wu, hu) = (w.max(0) as usize, h.max(0) as usize);
    grid_points(FORMAT, wu as u64, hu as u64)?;
    let row = usize::try_from(row_bytes).unwrap_or(0);
    if size != element || row < element as usize * wu || row % element as usize != 0 {
        return Err(bad(
            FORMAT,
            format!("{name}: elements of {size} bytes in rows of {row_bytes} bytes for {w} points"),
        ));
    }
    let need = (row as u64)
        .checked_mul(hu as u64)
        .filter(|&b| b <= MAX_MEMBER)
        .ok_or_else(|| bad(FORMAT, format!("{name}: {h} rows of {row_bytes} bytes")))?;
    let mut rows = Vec::new();
    r.take(need)
        .read_to_end(&mut rows)
        .map_err(|e| bad(FORMAT, format!("{name}: {e}")))?;
    if rows.len() as u64 != need {
        return Err(bad(
            FORMAT,
            format!("{name}: truncated: {h} rows of {row_bytes} bytes"),
        ));
    }
    Ok((wu, hu, row, rows))
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

/// The i32 counts of the height grid as a `(height, width)` map.
fn counts(&(w, h, row_bytes, ref rows): &Grid) -> Result<Array2<f64>> {
    let mut values = Vec::with_capacity(w * h);
    for row in rows.chunks_exact(row_bytes) {
        values.extend(
            row[..4 * w]
                .chunks_exact(4)
                .map(|b| f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]]))),
        );
    }
    areal(FORMAT, h, w, values)
}

/// Sets to NaN the points whose mask byte has either of its low two bits set; the mask's
/// grid must be the heights'.
fn apply_mask(map: &mut Array2<f64>, &(w, h, row_bytes, ref rows): &Grid) -> Result<()> {
    if (h, w) != map.dim() {
        return Err(bad(
            FORMAT,
            format!(
                "the validity mask is {w} × {h}, the heights {} × {}",
                map.ncols(),
                map.nrows()
            ),
        ));
    }
    for (row, mask) in map.rows_mut().into_iter().zip(rows.chunks_exact(row_bytes)) {
        for (z, m) in row.into_iter().zip(mask) {
            if m & 0x03 != 0 {
                *z = f64::NAN;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_close, assert_robust, assert_zip_sizes_robust};
    use super::super::Heights;
    use super::*;
    use std::io::Write;
    use std::time::Duration;

    const UNIT_XML: &[u8] =
        b"<?xml version=\"1.0\"?><UnitInfo><XYCalibration><MeterPerPixel>2.5e-7\
        </MeterPerPixel></XYCalibration><ZCalibration><MeterPerUnit>1e-9</MeterPerUnit>\
        </ZCalibration></UnitInfo>";

    /// A grid member: the 16-byte header and rows of `w` values padded by 4 bytes.
    fn grid_member(w: usize, element: usize, values: &[u8]) -> Vec<u8> {
        let h = values.len() / (w * element);
        let row = w * element + 4;
        let mut data = Vec::new();
        for v in [w, h, element, row] {
            data.extend_from_slice(&(v as i32).to_le_bytes());
        }
        for r in values.chunks(w * element) {
            data.extend_from_slice(r);
            data.extend_from_slice(&[0xAB; 4]); // padding
        }
        data
    }

    /// A ZON file in the format's own layout: the signature, a 6-byte stand-in thumbnail,
    /// and a zip of `members` (name, bytes), each deflated and, under `KPK1`, first
    /// compressed into one Zstandard frame (ruzstd's encoder).
    fn container(magic: &[u8], members: &[(&str, Vec<u8>)]) -> Vec<u8> {
        let mut zip = zip::ZipWriter::new(IoCursor::new(Vec::new()));
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        for (name, data) in members {
            zip.start_file(*name, options).unwrap();
            let data = if magic == b"KPK1" {
                let level = ruzstd::encoding::CompressionLevel::Fastest;
                ruzstd::encoding::compress_to_vec(&data[..], level)
            } else {
                data.clone()
            };
            zip.write_all(&data).unwrap();
        }
        let archive = zip.finish().unwrap().into_inner();
        let mut f = magic.to_vec();
        f.extend_from_slice(&6u32.to_le_bytes());
        f.extend_from_slice(b"BM\0\0\0\0");
        f.extend_from_slice(&archive);
        f
    }

    /// A 3 × 2 map of `counts` with the unit XML and, where given, a validity mask.
    fn write(magic: &[u8], counts: &[i32], mask: Option<&[u8]>) -> Vec<u8> {
        let bytes: Vec<u8> = counts.iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut members = vec![
            (UNITS, UNIT_XML.to_vec()),
            (HEIGHTS, grid_member(3, 4, &bytes)),
        ];
        if let Some(m) = mask {
            members.push((VALID, grid_member(3, 1, m)));
        }
        container(magic, &members)
    }

    fn heights(r: &Reading) -> &Array2<f64> {
        let Heights::Areal(h) = &r.channels[0].heights else {
            panic!()
        };
        h
    }

    #[test]
    fn a_written_file_reads_back() {
        for magic in [b"KPK0", b"KPK1"] {
            let f = write(magic, &[1, -2, 3, 4, 5, 600], None);
            assert!(sniff(&f));
            let r = read(&f).unwrap();
            assert_close(r.channels[0].size.iter().flatten(), &[7.5e-7, 5e-7]);
            assert_eq!(heights(&r).dim(), (2, 3));
            assert_close(heights(&r).iter(), &[1e-9, -2e-9, 3e-9, 4e-9, 5e-9, 600e-9]);
        }
    }

    #[test]
    fn the_validity_mask_undefines_points_by_its_low_two_bits() {
        // 0x01 out of range and 0x02 excluded: undefined; 0x40 and 0x80 (quality notes) and
        // 0x00: kept.
        let mask = [0x00, 0x01, 0x02, 0x40, 0x80 | 0x01, 0x80];
        for magic in [b"KPK0", b"KPK1"] {
            let r = read(&write(magic, &[1, 2, 3, 4, 5, 6], Some(&mask))).unwrap();
            let nan = f64::NAN;
            assert_close(heights(&r).iter(), &[1e-9, nan, nan, 4e-9, nan, 6e-9]);
        }
        // A mask of another grid is refused.
        let f = container(
            b"KPK0",
            &[
                (UNITS, UNIT_XML.to_vec()),
                (HEIGHTS, grid_member(3, 4, &[0; 24])),
                (VALID, grid_member(2, 1, &[0; 6])),
            ],
        );
        let err = read(&f).unwrap_err().to_string();
        assert!(err.contains("validity mask is 2 × 3"), "{err}");
    }

    #[test]
    fn a_member_compressed_by_the_zstd_program_reads() {
        // The height member compressed by the reference `zstd` tool (an encoder other than
        // the one the other tests use): tests/data/make_zon_zstd.py.
        let frame = include_bytes!("../../tests/data/zon-heights-64x48.zst");
        let mut zip = zip::ZipWriter::new(IoCursor::new(Vec::new()));
        let options = zip::write::SimpleFileOptions::default();
        let level = ruzstd::encoding::CompressionLevel::Fastest;
        zip.start_file(UNITS, options).unwrap();
        zip.write_all(&ruzstd::encoding::compress_to_vec(UNIT_XML, level))
            .unwrap();
        zip.start_file(HEIGHTS, options).unwrap();
        zip.write_all(frame).unwrap();
        let mut file = b"KPK1\0\0\0\0".to_vec();
        file.extend_from_slice(&zip.finish().unwrap().into_inner());
        let r = read(&file).unwrap();
        let h = heights(&r);
        assert_eq!(h.dim(), (48, 64));
        for ((y, x), v) in h.indexed_iter() {
            let want = ((37 * x + 3 * y * y) % 1000) as f64 - 500.0;
            assert!(
                (v - want * 1e-9).abs() <= 1e-12 * want.abs() * 1e-9,
                "({y}, {x}): {v}"
            );
        }
    }

    #[test]
    fn a_zstd_bomb_is_refused_after_what_the_grid_header_justifies() {
        // A 3 × 2 header followed by 64 MiB of zeros in one Zstandard frame of a few KiB:
        // the rows are read to the header's 24 bytes + padding, the rest is never decoded.
        let mut data = grid_member(3, 4, &[0; 24]);
        data.resize(64 << 20, 0);
        let f = container(b"KPK1", &[(UNITS, UNIT_XML.to_vec()), (HEIGHTS, data)]);
        assert!(f.len() < 64 << 10, "{} bytes", f.len());
        let start = std::time::Instant::now();
        assert!(read(&f).is_ok());
        assert!(start.elapsed() < Duration::from_secs(1));
        // A header claiming 30000 × 30000 points (3.6 GB) over a short stream: refused as truncated
        // (the rows buffer grows with the data that arrive, not with the claim).
        let mut data = grid_member(3, 4, &[0; 24]);
        data[0..4].copy_from_slice(&30_000i32.to_le_bytes());
        data[4..8].copy_from_slice(&30_000i32.to_le_bytes());
        data[12..16].copy_from_slice(&120_000i32.to_le_bytes());
        let f = container(b"KPK1", &[(UNITS, UNIT_XML.to_vec()), (HEIGHTS, data)]);
        let err = read(&f).unwrap_err().to_string();
        assert!(
            err.contains("truncated") && err.lines().count() == 1,
            "{err}"
        );
    }

    #[test]
    fn truncations_corruptions_and_zip_sizes_are_refused() {
        for magic in [b"KPK0", b"KPK1"] {
            let f = write(magic, &[1, -2, 3, 4, 5, 600], Some(&[0, 1, 2, 0, 0, 0]));
            assert_robust(
                &f,
                sniff,
                read,
                f.len() - 1,
                Some(4),
                Duration::from_millis(300),
            );
            assert_zip_sizes_robust(&f, read, Duration::from_millis(200));
        }
    }
}
