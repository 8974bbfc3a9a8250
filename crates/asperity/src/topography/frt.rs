//! FRT MicroProf files (optical profilometers of FRT, Fries Research & Technology).
//!
//! Layout (after Gwyddion's `microprof.c` and SurfaceTopography's `FRT.py`; little-endian):
//! `FRTM_GLIDERV` and the version `1.00` or `1.01`, a `u16` count of blocks, then the
//! blocks: `u16 tag`, the payload's size (`u32` in 1.00, `u64` in 1.01), the payload. The
//! blocks used:
//! * `0x0066`: `u32 nx, u32 ny, u32 bits` (16: unsigned, 32: signed samples);
//! * `0x0067`: `f64` sizes along x and y in metres;
//! * `0x006C`: `u32` range, `f64` metres per count;
//! * `0x000B`: the topography, `ny` rows of `nx` samples;
//! * `0x007D`, in files without `0x000B`: four `u16` buffer ids, then images, each
//!   `u32 type, nx, ny, bits` and its samples; the height-like types (topography 0x4,
//!   thickness 0x80, sample thickness 0x800, AFM 0x1000) are channels.
//!
//! A sample of 1 marks an undefined point. Orientation: the first stored row is the bottom
//! line; like both peers we reverse the rows (SurfaceTopography's `[x, y]` array,
//! flipped along y, transposed). Other blocks (settings, drift data, ...) are skipped.

use super::bytes::{areal, bad, flip_rows, grid_points, samples, Cursor, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;
use ndarray::Array2;

const FORMAT: &str = "frt";
const MAGIC: &[u8] = b"FRTM_GLIDERV";
const LE: Endian = Endian::Little;
const TOPOGRAPHY: u16 = 0x000B;
const GRID: u16 = 0x0066;
const SIZES: u16 = 0x0067;
const SCALE: u16 = 0x006C;
const MULTI: u16 = 0x007D;
const HEIGHT_TYPES: u32 = 0x0004 | 0x0080 | 0x0800 | 0x1000;

/// Whether the bytes start with FRT's signature.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// A block's payload.
struct Block<'a> {
    tag: u16,
    data: &'a [u8],
}

/// Parses a whole FRT file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "the file does not start with `FRTM_GLIDERV`"));
    }
    let blocks = blocks(bytes)?;
    let find = |tag: u16| blocks.iter().find(|b| b.tag == tag).map(|b| b.data);
    let need = |tag: u16, what: &str| {
        find(tag).ok_or_else(|| bad(FORMAT, format!("no block {tag:#06x} ({what})")))
    };
    let mut c = Cursor::new(FORMAT, need(SIZES, "sizes")?);
    let size = [c.f64(LE)?, c.f64(LE)?];
    let mut c = Cursor::new(FORMAT, need(SCALE, "height scale")?);
    c.skip(4)?;
    let scale = c.f64(LE)?;
    if !(scale.is_finite() && scale != 0.0) {
        return Err(bad(
            FORMAT,
            format!("height scale {scale} is not a usable number"),
        ));
    }
    let size = size.map(|s| Some(s).filter(|s| s.is_finite() && *s > 0.0));
    let channel = |name: String, heights: Array2<f64>| Channel {
        name,
        heights: Heights::Areal(heights),
        size,
        unit: Some("m".into()),
        is_height: true,
    };
    let channels = if let Some(data) = find(TOPOGRAPHY) {
        let mut g = Cursor::new(FORMAT, need(GRID, "grid")?);
        let (nx, ny, bits) = (g.u32(LE)?, g.u32(LE)?, g.u32(LE)?);
        vec![channel(
            "default".into(),
            raster(data, nx, ny, bits, scale)?,
        )]
    } else {
        images(need(MULTI, "topography")?, scale)?
            .into_iter()
            .map(|(name, map)| channel(name, map))
            .collect()
    };
    if channels.is_empty() {
        return Err(bad(FORMAT, "the file holds no height image"));
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

/// The tag list, each payload checked to lie inside the file.
fn blocks(bytes: &[u8]) -> Result<Vec<Block<'_>>> {
    let mut c = Cursor::new(FORMAT, bytes);
    c.skip(MAGIC.len())?;
    let wide = match c.take(4)? {
        b"1.00" => false,
        b"1.01" => true,
        v => {
            return Err(bad(
                FORMAT,
                format!(
                    "version `{}` (1.00 and 1.01 known)",
                    super::bytes::latin1(v)
                ),
            ))
        }
    };
    let count = c.u16(LE)?;
    let mut out = Vec::with_capacity(usize::from(count));
    for _ in 0..count {
        let tag = c.u16(LE)?;
        let len = if wide {
            let (lo, hi) = (c.u32(LE)?, c.u32(LE)?);
            u64::from(lo) | u64::from(hi) << 32
        } else {
            u64::from(c.u32(LE)?)
        };
        let len = usize::try_from(len).map_err(|_| bad(FORMAT, "block larger than memory"))?;
        out.push(Block {
            tag,
            data: c.take(len)?,
        });
    }
    Ok(out)
}

/// `ny` rows of `nx` samples from the start of `data`, in metres, rows reversed.
fn raster(data: &[u8], nx: u32, ny: u32, bits: u32, scale: f64) -> Result<Array2<f64>> {
    let sample = match bits {
        16 => Sample::U16,
        32 => Sample::I32,
        _ => {
            return Err(bad(
                FORMAT,
                format!("{bits} bits per sample (16 or 32 known)"),
            ))
        }
    };
    let n = grid_points(FORMAT, nx.into(), ny.into())?;
    let mut values = samples(FORMAT, data, 0, n, sample, LE)?;
    for v in &mut values {
        *v = if *v == 1.0 { f64::NAN } else { *v * scale };
    }
    let mut map = areal(FORMAT, ny as usize, nx as usize, values)?;
    flip_rows(&mut map);
    Ok(map)
}

/// The height-like images of the multi-image block, named as SurfaceTopography names them
/// (`Topography (top sensor) 1`).
fn images(data: &[u8], scale: f64) -> Result<Vec<(String, Array2<f64>)>> {
    let mut c = Cursor::new(FORMAT, data);
    c.skip(8)?;
    let mut out = Vec::new();
    while c.pos() < data.len() {
        // Each image consumes its 16-byte header at least, so the loop ends.
        let (kind, nx, ny, bits) = (c.u32(LE)?, c.u32(LE)?, c.u32(LE)?, c.u32(LE)?);
        let n = grid_points(FORMAT, nx.into(), ny.into())?;
        let len = n
            .checked_mul(bits as usize / 8)
            .ok_or_else(|| bad(FORMAT, "image too large"))?;
        let block = c.take(len)?;
        if kind & HEIGHT_TYPES == 0 {
            continue;
        }
        let name = match kind & 0xFFDF {
            0x4 => "Topography",
            0x80 => "Thickness",
            0x800 => "Sample thickness",
            0x1000 => "AFM",
            _ => "Unknown",
        };
        let sensor = if kind & 0x1000_0000 != 0 {
            "bottom"
        } else {
            "top"
        };
        let counter = ((kind & 0x0F00_0000) >> 24) + 1;
        let name = format!("{name} ({sensor} sensor) {counter}");
        out.push((name, raster(block, nx, ny, bits, scale)?));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::testkit::transposed;
    use super::super::testkit::{assert_close, assert_matches, assert_robust, reference};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        let Some(r) = reference("frt-2.frt") else {
            return;
        };
        // Both readers reverse the stored rows; ours is then SurfaceTopography's [x, y]
        // array transposed.
        assert_matches(&read(&r.bytes).unwrap(), &r, &transposed(&r));
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(r) = reference("frt-2.frt") else {
            return;
        };
        assert_robust(
            &r.bytes,
            sniff,
            read,
            140,
            Some(4),
            Duration::from_millis(300),
        );
    }

    #[test]
    fn the_multi_image_block_of_a_wide_file() {
        let mut f = b"FRTM_GLIDERV1.01".to_vec();
        f.extend_from_slice(&3u16.to_le_bytes());
        let mut block = |tag: u16, payload: &[u8]| {
            f.extend_from_slice(&tag.to_le_bytes());
            f.extend_from_slice(&(payload.len() as u64).to_le_bytes());
            f.extend_from_slice(payload);
        };
        let sizes: Vec<u8> = [2e-3f64, 1e-3]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        block(SIZES, &sizes);
        let mut scale = 5u32.to_le_bytes().to_vec();
        scale.extend_from_slice(&1e-9f64.to_le_bytes());
        block(SCALE, &scale);
        let mut multi = vec![0u8; 8];
        // An intensity image (type 0x2), skipped, then a topography of 2 × 2.
        for (kind, vals) in [(0x2u32, [7u16, 7, 7, 7]), (0x0100_0004, [3, 1, 5, 6])] {
            for v in [kind, 2, 2, 16] {
                multi.extend_from_slice(&v.to_le_bytes());
            }
            vals.iter()
                .for_each(|v| multi.extend_from_slice(&v.to_le_bytes()));
        }
        block(MULTI, &multi);
        let reading = read(&f).unwrap();
        assert_eq!(reading.channels.len(), 1);
        let c = &reading.channels[0];
        assert_eq!(c.name, "Topography (top sensor) 2");
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        // Rows reversed; 1 marks an undefined point.
        assert_close(h, &[5e-9, 6e-9, 3e-9, f64::NAN]);
    }
}
