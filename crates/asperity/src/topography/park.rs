//! **Park Systems** AFM TIFF files (`.tiff`, `.tif`): a one-page TIFF ([`super::tiff`])
//! whose picture is only a preview; the measurement lives in four private tags: `50432`
//! the magic `0x0E031301`, `50433` the version (`0x01000001` or `0x01000002`), `50434` the
//! data block and `50435` a packed little-endian header (no padding between fields).
//!
//! The header's fields used, by byte offset: `0` image type (u32: 0 a 2-D map, 1 a line
//! profile, 2 spectroscopy), `4` the source name (32 UTF-16LE characters, e.g.
//! `Z Height`), `100`, `104` the points along x and y (u32), `140`, `148` the scan sizes
//! along x and y in µm (f64), `220` the data gain, `228` the scale factor (0 means 1),
//! `236` the data offset (f64), `244` the data unit (8 UTF-16LE characters, empty means
//! µm), `272` compression (u32, 0); version 2 adds at `348` the sample type (u32: 0 i16,
//! 1 i32, 2 f32; version 1 holds i16). The header is at least 356 (version 1) or 580
//! (version 2) bytes. A height is `gain · (scale · raw + offset)` in the data unit. The
//! data are stored line by line, the first line at the bottom of the image: rows are
//! flipped (as SurfaceTopography and Gwyddion's `psia.c` do).
//!
//! Layout learnt from SurfaceTopography's `PS.py` and Gwyddion's `psia.c`; checked on
//! SurfaceTopography's `example_ps.tiff` on 2026-11-27 (it read to the peer's reference; the
//! file is not in the shared sets, so the tests write the layout instead).

use super::bytes::{areal, bad, flip_rows, length_unit, samples, Cursor, Endian, Sample};
use super::tiff::{self, Value};
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "park";
const TAG_MAGIC: u16 = 50432;
const TAG_VERSION: u16 = 50433;
const TAG_DATA: u16 = 50434;
const TAG_HEADER: u16 = 50435;
const MAGIC: f64 = 235_082_497.0; // 0x0E031301
const VERSION1: f64 = 16_777_217.0; // 0x01000001
const VERSION2: f64 = 16_777_218.0; // 0x01000002

/// A TIFF file whose first page carries Park Systems' magic tag.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    tiff::sniff(bytes)
        && tiff::pages(FORMAT, bytes)
            .map(|(_, p)| p[0].tags.get(&TAG_MAGIC).and_then(Value::number) == Some(MAGIC))
            .unwrap_or(false)
}

/// The header fields the reader uses.
struct Header {
    image_type: u32,
    name: String,
    nx: u32,
    ny: u32,
    size: [f64; 2],
    gain: f64,
    scale: f64,
    offset: f64,
    unit: String,
    compression: u32,
    sample: Sample,
}

/// `n` UTF-16LE characters at the cursor, cut at the first NUL and trimmed.
fn utf16(c: &mut Cursor, n: usize) -> Result<String> {
    let raw = c.take(2 * n)?;
    let units: Vec<u16> = raw
        .chunks_exact(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .take_while(|&u| u != 0)
        .collect();
    Ok(String::from_utf16_lossy(&units).trim().to_string())
}

fn header(block: &[u8], version2: bool) -> Result<Header> {
    let need = if version2 { 580 } else { 356 };
    if block.len() < need {
        return Err(bad(
            FORMAT,
            format!("the header holds {} of {need} bytes", block.len()),
        ));
    }
    let le = Endian::Little;
    let mut c = Cursor::new(FORMAT, block);
    let image_type = c.u32(le)?;
    let name = utf16(&mut c, 32)?;
    c.seek(100)?;
    let (nx, ny) = (c.u32(le)?, c.u32(le)?);
    c.seek(140)?;
    let size = [c.f64(le)?, c.f64(le)?];
    c.seek(220)?;
    let (gain, scale, offset) = (c.f64(le)?, c.f64(le)?, c.f64(le)?);
    let unit = utf16(&mut c, 8)?;
    c.seek(272)?;
    let compression = c.u32(le)?;
    let kind = if version2 {
        c.seek(348)?;
        c.u32(le)?
    } else {
        0
    };
    let sample = match kind {
        0 => Sample::I16,
        1 => Sample::I32,
        2 => Sample::F32,
        k => return Err(bad(FORMAT, format!("unknown sample type {k}"))),
    };
    Ok(Header {
        image_type,
        name,
        nx,
        ny,
        size,
        gain,
        scale: if scale == 0.0 { 1.0 } else { scale },
        offset,
        unit: if unit.is_empty() { "um".into() } else { unit },
        compression,
        sample,
    })
}

/// Parses a whole Park Systems TIFF file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    let (_, pages) = tiff::pages(FORMAT, bytes)?;
    let page = &pages[0];
    if page.tags.get(&TAG_MAGIC).and_then(Value::number) != Some(MAGIC) {
        return Err(bad(FORMAT, "a TIFF file without Park Systems' magic tag"));
    }
    if pages.len() != 1 {
        return Err(bad(FORMAT, "a Park Systems TIFF holds one page"));
    }
    let version = page.tags.get(&TAG_VERSION).and_then(Value::number);
    let version2 = match version {
        Some(VERSION1) => false,
        Some(VERSION2) => true,
        _ => return Err(bad(FORMAT, "only versions 1 and 2 are supported")),
    };
    let block = |tag| {
        let &(at, len) = page
            .blocks
            .get(&tag)
            .ok_or_else(|| bad(FORMAT, format!("no tag {tag}")))?;
        bytes
            .get(at..at.saturating_add(len))
            .ok_or_else(|| bad(FORMAT, format!("tag {tag} lies past the end of the file")))
    };
    tiff::check_strips(FORMAT, bytes, page)?;
    let h = header(block(TAG_HEADER)?, version2)?;
    check(&h)?;
    let (unit, metres) = length_unit(&h.unit)
        .ok_or_else(|| bad(FORMAT, format!("data unit `{}` is not a length", h.unit)))?;
    let n = super::bytes::grid_points(FORMAT, h.nx.into(), h.ny.into())?;
    let mut values = samples(FORMAT, block(TAG_DATA)?, 0, n, h.sample, Endian::Little)?;
    let factor = h.gain * metres;
    values
        .iter_mut()
        .for_each(|v| *v = factor * (h.scale * *v + h.offset));
    let mut map = areal(FORMAT, h.ny as usize, h.nx as usize, values)?;
    flip_rows(&mut map);
    Ok(Reading {
        format: FORMAT,
        channels: vec![Channel {
            name: h.name,
            heights: Heights::Areal(map),
            size: [Some(h.size[0] * 1e-6), Some(h.size[1] * 1e-6)],
            unit: Some(unit.into()),
            is_height: true,
        }],
    })
}

fn check(h: &Header) -> Result<()> {
    if h.image_type == 1 {
        return Err(bad(FORMAT, "line profiles are not supported"));
    }
    if h.image_type > 2 {
        return Err(bad(FORMAT, format!("unknown image type {}", h.image_type)));
    }
    if h.compression != 0 {
        return Err(bad(FORMAT, "compressed data are not supported"));
    }
    for (axis, s) in ["x", "y"].iter().zip(h.size) {
        if !crate::is_positive_finite(s) {
            return Err(bad(FORMAT, format!("scan size along {axis} is {s}")));
        }
    }
    if ![h.gain, h.scale, h.offset].iter().all(|v| v.is_finite()) {
        return Err(bad(FORMAT, "a non-finite data gain, scale or offset"));
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::testkit::{assert_close, assert_robust};
    use super::*;
    use std::time::Duration;

    /// A Park Systems TIFF in the format's own layout: one little-endian page whose
    /// picture is a 1 × 1 byte, the magic, version, data and header tags.
    pub(crate) fn write(version: u32, sample: u32, nx: u32, ny: u32, data: &[u8]) -> Vec<u8> {
        let mut header = vec![0u8; if version == 2 { 580 } else { 356 }];
        let put = |h: &mut Vec<u8>, at: usize, b: &[u8]| h[at..at + b.len()].copy_from_slice(b);
        for (i, u) in "Z Height".encode_utf16().enumerate() {
            put(&mut header, 4 + 2 * i, &u.to_le_bytes());
        }
        put(&mut header, 100, &nx.to_le_bytes());
        put(&mut header, 104, &ny.to_le_bytes());
        put(&mut header, 140, &2.0f64.to_le_bytes());
        put(&mut header, 148, &1.0f64.to_le_bytes());
        put(&mut header, 220, &(-2.0f64).to_le_bytes());
        put(&mut header, 228, &0.5f64.to_le_bytes());
        put(&mut header, 236, &1.0f64.to_le_bytes());
        for (i, u) in "nm".encode_utf16().enumerate() {
            put(&mut header, 244 + 2 * i, &u.to_le_bytes());
        }
        if version == 2 {
            put(&mut header, 348, &sample.to_le_bytes());
        }
        let version = if version == 2 {
            0x0100_0002u32
        } else {
            0x0100_0001
        };
        // Entries: (tag, type, count, value or offset); blocks follow the directory.
        let entries = 8u32;
        let dir = 8u32;
        let after = dir + 2 + 12 * entries + 4;
        let data_at = after;
        let header_at = data_at + data.len() as u32;
        let pixel_at = header_at + header.len() as u32;
        let mut f = b"II*\0".to_vec();
        f.extend_from_slice(&dir.to_le_bytes());
        f.extend_from_slice(&(entries as u16).to_le_bytes());
        let mut entry = |tag: u16, kind: u16, count: u32, value: u32| {
            f.extend_from_slice(&tag.to_le_bytes());
            f.extend_from_slice(&kind.to_le_bytes());
            f.extend_from_slice(&count.to_le_bytes());
            f.extend_from_slice(&value.to_le_bytes());
        };
        entry(256, 4, 1, 1);
        entry(257, 4, 1, 1);
        entry(273, 4, 1, pixel_at);
        entry(279, 4, 1, 1);
        entry(TAG_MAGIC, 4, 1, 0x0E03_1301);
        entry(TAG_VERSION, 4, 1, version);
        entry(TAG_DATA, 1, data.len() as u32, data_at);
        entry(TAG_HEADER, 7, header.len() as u32, header_at);
        f.extend_from_slice(&0u32.to_le_bytes());
        f.extend_from_slice(data);
        f.extend_from_slice(&header);
        f.push(0);
        f
    }

    #[test]
    fn a_written_file_reads_back_in_each_sample_type() {
        // Heights gain · (scale · raw + offset) nm = -2 · (0.5 · raw + 1) nm, rows flipped.
        let raw = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let want: Vec<f64> = [4.0, 5.0, 6.0, 1.0, 2.0, 3.0]
            .iter()
            .map(|r| -2.0 * (0.5 * r + 1.0) * 1e-9)
            .collect();
        let as_i16: Vec<u8> = raw.iter().flat_map(|&r| (r as i16).to_le_bytes()).collect();
        let as_i32: Vec<u8> = raw.iter().flat_map(|&r| (r as i32).to_le_bytes()).collect();
        let as_f32: Vec<u8> = raw.iter().flat_map(|&r| (r as f32).to_le_bytes()).collect();
        for (version, sample, data) in [
            (1, 0, &as_i16),
            (2, 0, &as_i16),
            (2, 1, &as_i32),
            (2, 2, &as_f32),
        ] {
            let file = write(version, sample, 3, 2, data);
            assert!(sniff(&file));
            let reading = read(&file).unwrap();
            let c = &reading.channels[0];
            assert_eq!(c.name, "Z Height");
            assert_eq!(c.unit.as_deref(), Some("nm"));
            assert_eq!(c.size, [Some(2e-6), Some(1e-6)]);
            let Heights::Areal(h) = &c.heights else {
                panic!()
            };
            assert_eq!(h.dim(), (2, 3));
            assert_close(h.iter(), &want);
        }
    }

    #[test]
    fn a_truncated_or_corrupt_written_file_is_refused() {
        let data: Vec<u8> = (0..6i16).flat_map(|r| r.to_le_bytes()).collect();
        let file = write(2, 0, 3, 2, &data);
        assert_robust(
            &file,
            sniff,
            read,
            file.len() - 1,
            Some(4),
            Duration::from_millis(300),
        );
        // A grid larger than the data block is refused, not read past the block.
        let big = write(2, 0, 4, 2, &data);
        let err = read(&big).unwrap_err().to_string();
        assert!(err.contains("truncated"), "{err}");
    }
}
