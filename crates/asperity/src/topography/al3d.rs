//! Alicona AL3D files (Alicona Imaging, now Bruker Alicona, focus-variation microscopes).
//!
//! Layout (after Gwyddion's `alicona.c` and SurfaceTopography's `AL3D.py`): the 17-byte
//! signature `AliconaImaging\0\r\n`, then tags of 52 bytes each (a 20-byte key, a 30-byte
//! value, both NUL-padded ISO-8859-1 text, and `\r\n`): `Version`, `TagCount`, and
//! `TagCount` further tags. The depth image is `Rows` rows of `Cols` little-endian `f32`
//! heights in metres at the absolute offset `DepthImageOffset`, each row padded to a
//! multiple of 8 bytes. Pixel sizes are `PixelSizeXMeter` and `PixelSizeYMeter`.
//!
//! Undefined points are NaN or the value of `InvalidPixelValue` (written as text, stored as
//! `f32`, so matched within 2.4e-7 relative, two `f32` steps). Rows are stored in order of y;
//! the map is read as it is (SurfaceTopography's `[x, y]` transposed). The texture (colour)
//! planes and the icon are not read.

use super::bytes::{areal, bad, grid_points, height_reading, sample_block, Cursor, Sample};
use super::Reading;
use crate::Result;
use std::collections::HashMap;

const FORMAT: &str = "al3d";
const MAGIC: &[u8] = b"AliconaImaging\x00\r\n";
const KEY: usize = 20;
const VALUE: usize = 30;
/// Relative distance to `InvalidPixelValue` within which a height is undefined.
const INVALID_RELTOL: f64 = 2.4e-7;

/// Whether the bytes start with Alicona's signature.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// Parses a whole AL3D file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(
            FORMAT,
            "the file does not start with the Alicona signature",
        ));
    }
    let mut c = Cursor::new(FORMAT, bytes);
    c.skip(MAGIC.len())?;
    let (key, _) = tag(&mut c)?;
    if key != "Version" {
        return Err(bad(FORMAT, format!("first tag is `{key}`, not `Version`")));
    }
    let (key, value) = tag(&mut c)?;
    let count: usize = match (key.as_str(), value.parse()) {
        ("TagCount", Ok(n)) => n,
        _ => {
            return Err(bad(
                FORMAT,
                format!("second tag is `{key}: {value}`, not a tag count"),
            ))
        }
    };
    let mut tags = HashMap::new();
    for _ in 0..count {
        // Each tag is read from the file, so a huge count ends at the file's end.
        let (key, value) = tag(&mut c)?;
        tags.insert(key, value);
    }
    let number = |key: &str| -> Result<f64> {
        tags.get(key)
            .and_then(|v| v.parse::<f64>().ok())
            .ok_or_else(|| bad(FORMAT, format!("tag `{key}` is missing or not a number")))
    };
    let positive = |key: &str| -> Result<u64> {
        tags.get(key)
            .and_then(|v| v.parse::<u64>().ok())
            .ok_or_else(|| bad(FORMAT, format!("tag `{key}` is missing or not an integer")))
    };
    let (nx, ny) = (positive("Cols")?, positive("Rows")?);
    grid_points(FORMAT, nx, ny)?;
    let offset = usize::try_from(positive("DepthImageOffset")?)
        .map_err(|_| bad(FORMAT, "depth image offset beyond the address space"))?;
    let invalid = number("InvalidPixelValue").unwrap_or(f64::NAN);
    let (dx, dy) = (number("PixelSizeXMeter")?, number("PixelSizeYMeter")?);
    for (key, d) in [("PixelSizeXMeter", dx), ("PixelSizeYMeter", dy)] {
        if !crate::is_positive_finite(d) {
            return Err(bad(FORMAT, format!("{key} is {d}")));
        }
    }
    let map = depth_image(bytes, offset, nx as usize, ny as usize, invalid)?;
    Ok(height_reading(
        FORMAT,
        "Default",
        map,
        [nx as f64 * dx, ny as f64 * dy],
        "m",
    ))
}

/// One 52-byte tag: key and value, the `\r\n` checked.
fn tag(c: &mut Cursor) -> Result<(String, String)> {
    let key = c.text(KEY)?;
    let value = c.text(VALUE)?;
    if c.take(2)? != b"\r\n" {
        return Err(bad(FORMAT, format!("tag `{key}` does not end with CR LF")));
    }
    Ok((key, value))
}

/// The `ny` rows of `nx` heights, rows padded to 8 bytes; undefined points become NaN.
fn depth_image(
    bytes: &[u8],
    offset: usize,
    nx: usize,
    ny: usize,
    invalid: f64,
) -> Result<ndarray::Array2<f64>> {
    let too_large = || bad(FORMAT, "depth image too large");
    let stride = nx.checked_mul(4).ok_or_else(too_large)?.div_ceil(8) * 2;
    let count = stride.checked_mul(ny).ok_or_else(too_large)?;
    let block = sample_block(FORMAT, bytes, offset, count, Sample::F32)?;
    let mut values = Vec::with_capacity(nx * ny);
    for row in block.chunks_exact(stride * 4) {
        for b in row[..nx * 4].chunks_exact(4) {
            let v = f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
            let marked = (v - invalid).abs() <= INVALID_RELTOL * invalid.abs();
            values.push(if v.is_nan() || marked { f64::NAN } else { v });
        }
    }
    areal(FORMAT, ny, nx, values)
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_matches, assert_robust, reference, transposed};
    use super::super::Heights;
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        let Some(r) = reference("al3d-1.al3d") else {
            return;
        };
        // Ours is SurfaceTopography's [x, y] array transposed, nothing flipped.
        assert_matches(&read(&r.bytes).unwrap(), &r, &transposed(&r));
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(r) = reference("al3d-1.al3d") else {
            return;
        };
        // The file ends with the texture planes, which are not read: cut only inside the
        // header and the depth image.
        let reading = read(&r.bytes).unwrap();
        let end = 1261 + 200 * 296 * 4;
        assert!(!reading.channels.is_empty());
        let depth = &r.bytes[..end];
        assert_robust(
            depth,
            sniff,
            read,
            1261,
            Some(4),
            Duration::from_millis(300),
        );
    }

    #[test]
    fn the_invalid_marker_and_the_row_padding() {
        // A 3 × 2 image: rows of 12 bytes padded to 16; one point carries the marker.
        let mut f = MAGIC.to_vec();
        let mut put = |k: &str, v: &str| {
            let mut field = [0u8; 52];
            field[..k.len()].copy_from_slice(k.as_bytes());
            field[20..20 + v.len()].copy_from_slice(v.as_bytes());
            field[50..].copy_from_slice(b"\r\n");
            f.extend_from_slice(&field);
        };
        put("Version", "1");
        put("TagCount", "6");
        put("Cols", "3");
        put("Rows", "2");
        put("PixelSizeXMeter", "1e-06");
        put("PixelSizeYMeter", "2e-06");
        put("InvalidPixelValue", "3.0000000028082e+15");
        let offset = 17 + 8 * 52;
        put("DepthImageOffset", &offset.to_string());
        let rows = [[1.0f32, 2.0, 3e15], [4.0, f32::NAN, 6.0]];
        for row in rows {
            row.iter()
                .for_each(|v| f.extend_from_slice(&v.to_le_bytes()));
            f.extend_from_slice(&[0xee; 4]);
        }
        let reading = read(&f).unwrap();
        let c = &reading.channels[0];
        assert_eq!(c.size, [Some(3e-6), Some(4e-6)]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        let nan: Vec<bool> = h.iter().map(|v| v.is_nan()).collect();
        assert_eq!(nan, [false, false, true, false, true, false]);
        assert_eq!((h[[0, 1]], h[[1, 0]], h[[1, 2]]), (2.0, 4.0, 6.0));
    }
}
