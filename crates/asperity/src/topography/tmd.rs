//! TrueMap TMD files (TrueGage TrueMap surface metrology software).
//!
//! Layout (little-endian; as described by Gwyddion's `rmitmd.c` and read by
//! SurfaceTopography's `TMD.py`): the 32-byte signature `Binary TrueMap Data File v2.0\r\n\0`,
//! a NUL-terminated comment (ISO-8859-1, 24 bytes in the files seen, variable in principle),
//! then `u32 nx, u32 ny, f32 length_x, f32 length_y, f32 offset_x, f32 offset_y` and `ny`
//! rows of `nx` `f32` heights. Lengths and heights are in millimetres. The file has no
//! marker of undefined points. Rows are stored in order of y, so the map is read as it is
//! (`(row, col) = (y, x)`, SurfaceTopography's `[x, y]` transposed).

use super::bytes::{areal, bad, grid_points, samples, Cursor, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "tmd";
const MAGIC: &[u8] = b"Binary TrueMap Data File v2.0";
/// The signature field's fixed width.
const MAGIC_FIELD: usize = 32;
/// Longest comment accepted while looking for its terminating NUL.
const MAX_COMMENT: usize = 4096;
const MM: f64 = 1e-3;

/// Whether the bytes start with TrueMap's signature.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// Parses a whole TMD file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(
            FORMAT,
            "the file does not start with the TrueMap signature",
        ));
    }
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(MAGIC_FIELD)?;
    let window = &bytes[MAGIC_FIELD..bytes.len().min(MAGIC_FIELD + MAX_COMMENT)];
    let comment_len = window
        .iter()
        .position(|&b| b == 0)
        .ok_or_else(|| bad(FORMAT, "the comment has no terminating NUL"))?;
    c.skip(comment_len + 1)?;
    let nx = c.u32(Endian::Little)?;
    let ny = c.u32(Endian::Little)?;
    let length_x = f64::from(c.f32(Endian::Little)?);
    let length_y = f64::from(c.f32(Endian::Little)?);
    c.skip(8)?; // offsets of the map's origin, not needed for the heights
    let n = grid_points(FORMAT, nx.into(), ny.into())?;
    for (axis, l) in [("x", length_x), ("y", length_y)] {
        if !crate::is_positive_finite(l) {
            return Err(bad(FORMAT, format!("length along {axis} is {l}")));
        }
    }
    let mut values = samples(FORMAT, bytes, c.pos(), n, Sample::F32, Endian::Little)?;
    values.iter_mut().for_each(|v| *v *= MM);
    let map = areal(FORMAT, ny as usize, nx as usize, values)?;
    Ok(Reading {
        format: FORMAT,
        channels: vec![Channel {
            name: "Default".into(),
            heights: Heights::Areal(map),
            size: [Some(length_x * MM), Some(length_y * MM)],
            unit: Some("mm".into()),
            is_height: true,
        }],
    })
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_matches, assert_robust, reference, transposed};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        let Some(r) = reference("tmd-1.tmd") else {
            return;
        };
        // Ours is SurfaceTopography's [x, y] array transposed, nothing flipped.
        assert_matches(&read(&r.bytes).unwrap(), &r, &transposed(&r));
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(r) = reference("tmd-1.tmd") else {
            return;
        };
        assert_robust(
            &r.bytes,
            sniff,
            read,
            80,
            Some(4),
            Duration::from_millis(300),
        );
    }

    #[test]
    fn a_longer_comment_moves_the_header() {
        // A synthetic file with a 40-byte comment and a 2 × 1 map.
        let mut f = b"Binary TrueMap Data File v2.0\r\n\0".to_vec();
        f.extend_from_slice(&[b'c'; 39]);
        f.push(0);
        for v in [2u32, 1] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        for v in [4.0f32, 2.0, 0.0, 0.0, 0.5, -0.25] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        let reading = read(&f).unwrap();
        let c = &reading.channels[0];
        assert_eq!(c.size, [Some(4e-3), Some(2e-3)]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_eq!(h.as_slice().unwrap(), &[0.5e-3, -0.25e-3]);
    }
}
