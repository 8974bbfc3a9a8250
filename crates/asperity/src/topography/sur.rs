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

use super::bytes::samples;
use super::bytes::{areal, bad, flip_cols, flip_rows, grid_points, length_unit, metres_per};
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

/// What one object's 512-byte header says.
struct Header {
    endian: Endian,
    objects: usize,
    name: String,
    special: bool,
    sample: Sample,
    zmin: i32,
    nx: usize,
    ny: usize,
    steps: [f32; 3],
    units: [String; 3],
    inversion: u16,
    data: usize,
}

/// The header of the object starting at `start`.
fn header(bytes: &[u8], start: usize) -> Result<Header> {
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
    let (nx, ny, points) = (c.i32(e)?, c.i32(e)?, c.u32(e)?);
    if nx <= 0 || ny <= 0 || i64::from(points) != i64::from(nx) * i64::from(ny) {
        return Err(bad(
            FORMAT,
            format!("grid {nx} × {ny} does not hold {points} points"),
        ));
    }
    let steps = [c.f32(e)?, c.f32(e)?, c.f32(e)?];
    c.seek(start + 180)?;
    let units = [c.text(16)?, c.text(16)?, c.text(16)?];
    c.seek(start + 290)?;
    let inversion = c.u16(e)?;
    c.seek(start + 334)?;
    let (comment, private) = (usize::from(c.u16(e)?), usize::from(c.u16(e)?));
    Ok(Header {
        endian: e,
        objects,
        name,
        special,
        sample,
        zmin,
        nx: nx as usize,
        ny: ny as usize,
        steps,
        units,
        inversion,
        data: start + HEADER + comment + private,
    })
}

/// The object whose header starts at `start`: its channel, where it ends, and how many
/// objects the file says it holds.
fn object(bytes: &[u8], start: usize, first: bool) -> Result<(Channel, usize, usize)> {
    let h = header(bytes, start)?;
    let n = grid_points(FORMAT, h.nx as u64, h.ny as u64)?;
    let mut values = samples(FORMAT, bytes, h.data, n, h.sample, h.endian)?;
    let sign = if (1..=3).contains(&h.inversion) {
        -1.0
    } else {
        1.0
    };
    let scale = sign * f64::from(h.steps[2]) * metres_per(FORMAT, "the height", &h.units[2])?;
    let missing = f64::from(h.zmin) - 2.0;
    for v in &mut values {
        *v = if h.special && *v == missing {
            f64::NAN
        } else {
            *v * scale
        };
    }
    // A profile (one row) has a size along x only; its y step may be anything.
    let mut size = [None, None];
    let axes = if h.ny == 1 { 1 } else { 2 };
    for axis in 0..axes {
        let what = ["the x step", "the y step"][axis];
        let step = f64::from(h.steps[axis]) * metres_per(FORMAT, what, &h.units[axis])?;
        let s = step * [h.nx, h.ny][axis] as f64;
        if !crate::is_positive_finite(s) {
            return Err(bad(FORMAT, format!("{what} gives a size of {s} m")));
        }
        size[axis] = Some(s);
    }
    let heights = if h.ny == 1 {
        let mut line = Array1::from(values);
        if h.inversion == 2 {
            line.invert_axis(ndarray::Axis(0));
            line = line.as_standard_layout().into_owned();
        }
        Heights::Profile(line)
    } else {
        let mut map = areal(FORMAT, h.ny, h.nx, values)?;
        match h.inversion {
            2 => flip_cols(&mut map),
            3 => flip_rows(&mut map),
            _ => {}
        }
        Heights::Areal(map)
    };
    let channel = Channel {
        name: if first || h.name.is_empty() {
            "Default".into()
        } else {
            h.name
        },
        size,
        unit: length_unit(&h.units[2]).map(|(u, _)| u.to_string()),
        heights,
        is_height: true,
    };
    Ok((channel, h.data + n * h.sample.size(), h.objects))
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
    fn a_one_row_object_is_a_profile() {
        let mut f = synthetic(Endian::Little, 2, false);
        f[108..112].copy_from_slice(&4u32.to_le_bytes());
        f[112..116].copy_from_slice(&1u32.to_le_bytes());
        f[124..128].copy_from_slice(&0f32.to_le_bytes()); // no y step
        let reading = read(&f).unwrap();
        let c = &reading.channels[0];
        assert_eq!(c.size, [Some(2e-6), None]);
        let Heights::Profile(p) = &c.heights else {
            panic!("a profile")
        };
        // Inverted and reversed.
        assert_close(p, &[-8e-9, 24e-9, -4e-9, -2e-9]);
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
