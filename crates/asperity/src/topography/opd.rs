//! Bruker / Wyko OPD files (Vision software of Wyko white-light interferometers).
//!
//! Layout (after Gwyddion's `opdfile.c` and SurfaceTopography's `OPD.py`; little-endian): a
//! 2-byte prelude, then a directory of 24-byte entries (`name` 16 bytes, `type` i16,
//! `length` i32, `attribute` u16), the first of which is `Directory` itself and gives the
//! directory's length. The blocks' payloads follow the directory, in its order, each
//! `length` bytes long (none where the length is not positive).
//!
//! Arrays (type 3) named `RAW DATA`, `RAW_DATA`, `OPD`, `Raw` or `SAMPLE_DATA` hold heights:
//! `u16 nx, u16 ny, u16 bytes per sample` (1: u8, 2: i16, 4: f32), then the samples with the
//! x index first (`nx` columns of `ny`). Other arrays (`Image`, `Intensity`, `SecArr_0`) are
//! intensities and are not read. Heights are `sample · Wavelength / Mult` nanometres (blocks
//! `Wavelength` f32 and `Mult`, 1 when absent); the size is `nx · Pixel_size` and
//! `ny · Pixel_size · Aspect` millimetres (`Aspect` 1 when absent; no size without
//! `Pixel_size`). Undefined points: a non-finite sample, an i16 of 32766 or more, an f32 of
//! 1e38 or more.
//!
//! Orientation: like both peers we reverse y, so our row `y` is the stored column's sample
//! `ny − 1 − y` (SurfaceTopography's `[x, y]` array transposed).

use super::bytes::{bad, fixed_text, grid_points, samples, Cursor, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;
use ndarray::Array2;
use std::collections::HashMap;

const FORMAT: &str = "opd";
const ENTRY: usize = 24;
const PRELUDE: usize = 2;
const HEIGHT_ARRAYS: [&str; 5] = ["RAW DATA", "RAW_DATA", "OPD", "Raw", "SAMPLE_DATA"];
const LE: Endian = Endian::Little;
const TYPE_ARRAY: i16 = 3;
const TYPE_SHORT: i16 = 6;
const TYPE_FLOAT: i16 = 7;
const TYPE_DOUBLE: i16 = 8;
const TYPE_LONG: i16 = 12;

/// Whether the bytes hold a `Directory` entry after the 2-byte prelude.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.len() >= PRELUDE + 16 && fixed_text(&bytes[PRELUDE..PRELUDE + 16]) == "Directory"
}

/// One directory entry and where its payload starts.
struct Block {
    name: String,
    kind: i16,
    start: usize,
    len: usize,
}

/// Parses a whole OPD file: each height array is a channel.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(
            FORMAT,
            "the file does not start with a `Directory` block",
        ));
    }
    let blocks = directory(bytes)?;
    let mut numbers = HashMap::new();
    for b in blocks.iter().filter(|b| b.kind != TYPE_ARRAY) {
        if let Some(v) = scalar(bytes, b)? {
            numbers.insert(b.name.as_str(), v);
        }
    }
    let wavelength = *numbers
        .get("Wavelength")
        .ok_or_else(|| bad(FORMAT, "no `Wavelength` block: the height scale is unknown"))?;
    let mult = numbers.get("Mult").copied().unwrap_or(1.0);
    let aspect = numbers.get("Aspect").copied().unwrap_or(1.0);
    let factor = wavelength / mult * 1e-9;
    if !(factor.is_finite() && factor != 0.0) {
        return Err(bad(
            FORMAT,
            format!("height scale {factor} is not a usable number"),
        ));
    }
    let pixel = numbers
        .get("Pixel_size")
        .copied()
        .filter(|p| p.is_finite() && *p > 0.0);
    let channels = blocks
        .iter()
        .filter(|b| b.kind == TYPE_ARRAY && HEIGHT_ARRAYS.contains(&b.name.as_str()))
        .map(|b| {
            let map = raster(bytes, b, factor)?;
            let (ny, nx) = map.dim();
            Ok(Channel {
                name: b.name.clone(),
                heights: Heights::Areal(map),
                size: [
                    pixel.map(|p| nx as f64 * p * 1e-3),
                    pixel.map(|p| ny as f64 * p * aspect * 1e-3),
                ],
                unit: Some("mm".into()),
                is_height: true,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    if channels.is_empty() {
        return Err(bad(FORMAT, "the file holds no height array"));
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

/// The directory's entries (after `Directory` itself), with the payloads' places, each
/// checked to lie inside the file.
fn directory(bytes: &[u8]) -> Result<Vec<Block>> {
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(PRELUDE + 18)?;
    let len = c.i32(LE)?;
    let len = usize::try_from(len)
        .ok()
        .filter(|l| l % ENTRY == 0 && *l >= ENTRY)
        .ok_or_else(|| {
            bad(
                FORMAT,
                format!("directory length {len} is not a multiple of 24"),
            )
        })?;
    let mut payload = PRELUDE
        .checked_add(len)
        .filter(|&p| p <= bytes.len())
        .ok_or_else(|| bad(FORMAT, "the directory runs past the end of the file"))?;
    c.seek(PRELUDE + ENTRY)?;
    let mut blocks = Vec::with_capacity(len / ENTRY);
    for _ in 1..len / ENTRY {
        let name = c.text(16)?;
        let kind = c.i16(LE)?;
        let size = usize::try_from(c.i32(LE)?).unwrap_or(0);
        c.skip(2)?;
        if payload
            .checked_add(size)
            .is_none_or(|end| end > bytes.len())
        {
            return Err(bad(
                FORMAT,
                format!("block `{name}` runs past the end of the file"),
            ));
        }
        blocks.push(Block {
            name,
            kind,
            start: payload,
            len: size,
        });
        payload += size;
    }
    Ok(blocks)
}

/// The number a scalar block holds; the value's size follows the block's length, since some
/// files declare a type that does not match it (as Gwyddion notes).
fn scalar(bytes: &[u8], b: &Block) -> Result<Option<f64>> {
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(b.start)?;
    Ok(match (b.kind, b.len) {
        (TYPE_SHORT | TYPE_FLOAT, 2) => Some(f64::from(c.i16(LE)?)),
        (TYPE_SHORT, 4) | (TYPE_LONG, 4..) => Some(f64::from(c.i32(LE)?)),
        (TYPE_FLOAT, 4..) => Some(f64::from(c.f32(LE)?)),
        (TYPE_DOUBLE, 8..) => Some(c.f64(LE)?),
        _ => None,
    })
}

/// A height array in metres, rows in order of y reversed.
fn raster(bytes: &[u8], b: &Block, factor: f64) -> Result<Array2<f64>> {
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(b.start)?;
    let (nx, ny, size) = (c.u16(LE)?, c.u16(LE)?, c.u16(LE)?);
    let (sample, limit) = match size {
        1 => (Sample::U8, f64::INFINITY),
        2 => (Sample::I16, 32766.0),
        4 => (Sample::F32, 1e38),
        _ => {
            return Err(bad(
                FORMAT,
                format!("array `{}` has {size}-byte samples", b.name),
            ))
        }
    };
    let n = grid_points(FORMAT, nx.into(), ny.into())?;
    if 6 + n * sample.size() > b.len {
        return Err(bad(
            FORMAT,
            format!("array `{}` is longer than its block", b.name),
        ));
    }
    let mut values = samples(FORMAT, bytes, c.pos(), n, sample, LE)?;
    for v in &mut values {
        *v = if v.is_finite() && *v < limit {
            *v * factor
        } else {
            f64::NAN
        };
    }
    let (nx, ny) = (usize::from(nx), usize::from(ny));
    // Stored [x][y]; ours is (row, col) = (y, x) with y reversed: the transpose, its rows
    // reversed, both in place (the map is never held twice).
    let stored =
        Array2::from_shape_vec((nx, ny), values).map_err(|e| bad(FORMAT, e.to_string()))?;
    let mut map = super::hdf5::into_transposed(stored);
    super::bytes::flip_rows(&mut map);
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_matches, assert_robust, reference, transposed};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        let Some(r) = reference("opd-1.opd") else {
            return;
        };
        // Both readers reverse y; ours is then SurfaceTopography's [x, y] array transposed.
        assert_matches(&read(&r.bytes).unwrap(), &r, &transposed(&r));
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(r) = reference("opd-1.opd") else {
            return;
        };
        assert_robust(
            &r.bytes,
            sniff,
            read,
            24002,
            Some(6),
            Duration::from_millis(300),
        );
    }

    #[test]
    fn a_small_file_with_i16_samples_mult_and_aspect() {
        let entry = |name: &str, kind: i16, len: i32| {
            let mut e = [0u8; 24];
            e[..name.len()].copy_from_slice(name.as_bytes());
            e[16..18].copy_from_slice(&kind.to_le_bytes());
            e[18..22].copy_from_slice(&len.to_le_bytes());
            e
        };
        let mut f = vec![0u8; 2];
        f.extend_from_slice(&entry("Directory", 1, 6 * 24));
        f.extend_from_slice(&entry("Wavelength", 7, 4));
        f.extend_from_slice(&entry("Mult", 6, 2));
        f.extend_from_slice(&entry("Aspect", 7, 4));
        f.extend_from_slice(&entry("Pixel_size", 7, 4));
        f.extend_from_slice(&entry("RAW_DATA", 3, 6 + 8));
        f.extend_from_slice(&600f32.to_le_bytes());
        f.extend_from_slice(&2i16.to_le_bytes());
        f.extend_from_slice(&2f32.to_le_bytes());
        f.extend_from_slice(&0.001f32.to_le_bytes());
        for v in [2u16, 2, 2] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        // x = 0: y = 0, 1; x = 1: y = 0, 1.
        for v in [10i16, 20, 30, 32767] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        let reading = read(&f).unwrap();
        let c = &reading.channels[0];
        let px = f64::from(0.001f32) * 1e-3;
        assert_eq!(c.size, [Some(2.0 * px), Some(2.0 * px * 2.0)]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        // 300 nm per count; row 0 is the last stored y.
        assert!((h[[0, 0]] - 20.0 * 300e-9).abs() < 1e-20);
        assert!(h[[0, 1]].is_nan());
        assert!((h[[1, 0]] - 10.0 * 300e-9).abs() < 1e-20);
        assert!((h[[1, 1]] - 30.0 * 300e-9).abs() < 1e-20);
    }
}
