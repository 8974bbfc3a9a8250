//! Digital Surf SUR files (MountainsMap's native format, written by many instruments).
//!
//! Layout (after Gwyddion's `surffile.c` and SurfaceTopography's `SUR.py`): one or more
//! objects, each a 512-byte header followed by a comment, a private zone and the data. The
//! header (little-endian; big-endian where its `format` field is 257, the Macintosh
//! variant) starts with `DIGITAL SURF`; the fields used are the number of objects (offset
//! 14), the object's type (18), whether non-measured points occur (86), bits per point
//! (98, 16 or 32, signed), `zmin` (100), `nx`, `ny`, the number of points (108–119), the
//! steps `dx`, `dy` and the height scale `dz` (120–131, `f32`), their units (180, 196, 212,
//! 16 bytes each), the inversion flag (290), the comment and private sizes (334, 336).
//!
//! Heights are `sample · dz` in the unit at 212 (`mm`, `µm`, … incl. MS-DOS `æm`); where the
//! header says non-measured points occur, a sample of `zmin − 2` marks one. The Z offset
//! (offset 474) is not added (as SurfaceTopography; Gwyddion adds it): it moves the mean
//! plane only. Inversion 1 negates the heights, 2 also mirrors left-right, 3 upside down.
//! Rows are stored in order of y, so the map is read as it is (SurfaceTopography's `[x, y]`
//! transposed). An object with one row is a profile. Objects are channels, in file order;
//! the first is named `Default`, the others by their object name.
//!
//! Not supported: compressed data (a point size other than 16 or 32 bits).

use super::bytes::{areal, bad, flip_cols, flip_rows, grid_points, metres_per, samples};
use super::bytes::{Cursor, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;
use ndarray::Array1;

const FORMAT: &str = "sur";
const MAGIC: &[u8] = b"DIGITAL SURF";
const HEADER: usize = 512;
/// `format` field of the Macintosh (big-endian) variant.
const MAC: u16 = 257;

/// Whether the bytes start with Digital Surf's signature.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// Parses a whole SUR file: each object is a channel.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "the file does not start with `DIGITAL SURF`"));
    }
    let mut channels = Vec::new();
    let mut start = 0;
    loop {
        // Each object consumes at least its 512-byte header, so the loop ends.
        let (channel, end, objects) = object(bytes, start, channels.is_empty())?;
        channels.push(channel);
        start = end;
        if channels.len() >= objects {
            break;
        }
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

/// The object whose header starts at `start`: its channel, where it ends, and how many
/// objects the file says it holds.
fn object(bytes: &[u8], start: usize, first: bool) -> Result<(Channel, usize, usize)> {
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(start)?;
    if c.take(12)? != MAGIC {
        return Err(bad(
            FORMAT,
            format!("object at offset {start} lacks the signature"),
        ));
    }
    let e = if c.u16(Endian::Little)? == MAC {
        Endian::Big
    } else {
        Endian::Little
    };
    let objects = usize::from(c.u16(e)?.max(1));
    c.seek(start + 20)?;
    let name = c.text(30)?;
    c.seek(start + 86)?;
    let special = c.u16(e)? == 1;
    c.seek(start + 98)?;
    let sample = match c.u16(e)? {
        16 => Sample::I16,
        32 => Sample::I32,
        bits => {
            return Err(bad(
                FORMAT,
                format!("{bits} bits per point (compressed or unknown)"),
            ))
        }
    };
    let zmin = c.i32(e)?;
    c.skip(4)?;
    let (nx, ny) = (c.i32(e)?, c.i32(e)?);
    let points = c.u32(e)?;
    let (dx, dy, dz) = (c.f32(e)?, c.f32(e)?, c.f32(e)?);
    c.seek(start + 180)?;
    let units = [c.text(16)?, c.text(16)?, c.text(16)?];
    c.seek(start + 290)?;
    let inversion = c.u16(e)?;
    c.seek(start + 334)?;
    let (comment, private) = (usize::from(c.u16(e)?), usize::from(c.u16(e)?));
    if nx <= 0 || ny <= 0 || i64::from(points) != i64::from(nx) * i64::from(ny) {
        return Err(bad(
            FORMAT,
            format!("grid {nx} × {ny} does not hold {points} points"),
        ));
    }
    let n = grid_points(FORMAT, nx as u64, ny as u64)?;
    let data = start + HEADER + comment + private;
    let mut values = samples(FORMAT, bytes, data, n, sample, e)?;
    let z_unit = metres_per(FORMAT, "the height", &units[2])?;
    let sign = if (1..=3).contains(&inversion) {
        -1.0
    } else {
        1.0
    };
    let scale = sign * f64::from(dz) * z_unit;
    let missing = f64::from(zmin) - 2.0;
    for v in &mut values {
        *v = if special && *v == missing {
            f64::NAN
        } else {
            *v * scale
        };
    }
    let size_x = f64::from(dx) * metres_per(FORMAT, "the x step", &units[0])? * nx as f64;
    let size_y = f64::from(dy) * metres_per(FORMAT, "the y step", &units[1])? * ny as f64;
    for (axis, s) in [("x", size_x), ("y", size_y)] {
        if !(s.is_finite() && s > 0.0) {
            return Err(bad(FORMAT, format!("size along {axis} is {s}")));
        }
    }
    let heights = if ny == 1 {
        let mut line = Array1::from(values);
        if inversion == 2 {
            line.invert_axis(ndarray::Axis(0));
            line = line.as_standard_layout().into_owned();
        }
        Heights::Profile(line)
    } else {
        let mut map = areal(FORMAT, ny as usize, nx as usize, values)?;
        match inversion {
            2 => flip_cols(&mut map),
            3 => flip_rows(&mut map),
            _ => {}
        }
        Heights::Areal(map)
    };
    let channel = Channel {
        name: if first || name.is_empty() {
            "Default".into()
        } else {
            name
        },
        size: [Some(size_x), (ny > 1).then_some(size_y)],
        unit: super::bytes::length_unit(&units[2]).map(|(u, _)| u.to_string()),
        heights,
        is_height: true,
    };
    Ok((channel, data + n * sample.size(), objects))
}

#[cfg(test)]
mod tests {
    use super::super::testkit::transposed;
    use super::super::testkit::{assert_close, assert_matches, assert_robust, reference};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        let Some(r) = reference("sur-2.sur") else {
            return;
        };
        // Ours is SurfaceTopography's [x, y] array transposed (this file is not inverted).
        assert_matches(&read(&r.bytes).unwrap(), &r, &transposed(&r));
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(r) = reference("sur-2.sur") else {
            return;
        };
        assert_robust(
            &r.bytes,
            sniff,
            read,
            HEADER,
            Some(4),
            Duration::from_millis(300),
        );
    }

    /// A one-object file: 2 × 2 points of 16 bits, in either byte order.
    fn synthetic(e: Endian, inversion: u16, special: bool) -> Vec<u8> {
        let mut f = vec![0u8; HEADER];
        let put = |f: &mut Vec<u8>, at: usize, b: &[u8]| f[at..at + b.len()].copy_from_slice(b);
        let u16b = |v: u16| {
            if e == Endian::Big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        let u32b = |v: u32| {
            if e == Endian::Big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        put(&mut f, 0, MAGIC);
        put(&mut f, 12, &u16b(if e == Endian::Big { MAC } else { 0 }));
        put(&mut f, 14, &u16b(1));
        put(&mut f, 86, &u16b(u16::from(special)));
        put(&mut f, 98, &u16b(16));
        put(&mut f, 100, &u32b((-10i32) as u32));
        for (at, v) in [(108, 2u32), (112, 2), (116, 4)] {
            put(&mut f, at, &u32b(v));
        }
        for (at, v) in [(120, 0.5f32), (124, 0.25), (128, 2.0)] {
            put(&mut f, at, &u32b(v.to_bits()));
        }
        for at in [180, 196] {
            put(&mut f, at, b"\xe6m");
        }
        put(&mut f, 212, b"nm");
        put(&mut f, 290, &u16b(inversion));
        for v in [1i16, 2, -12, 4] {
            f.extend_from_slice(&u16b(v as u16));
        }
        f
    }

    #[test]
    fn byte_orders_inversion_and_non_measured_points() {
        for e in [Endian::Little, Endian::Big] {
            let reading = read(&synthetic(e, 0, true)).unwrap();
            let c = &reading.channels[0];
            assert_eq!(c.size, [Some(1e-6), Some(0.5e-6)]);
            let Heights::Areal(h) = &c.heights else {
                panic!()
            };
            // zmin − 2 = −12 marks the third point.
            assert_close(h, &[2e-9, 4e-9, f64::NAN, 8e-9]);
        }
        let reading = read(&synthetic(Endian::Little, 2, false)).unwrap();
        let Heights::Areal(h) = &reading.channels[0].heights else {
            panic!()
        };
        // Inverted and mirrored left-right; without the flag, −12 is a height.
        assert_close(h, &[-4e-9, -2e-9, -8e-9, 24e-9]);
    }
}
