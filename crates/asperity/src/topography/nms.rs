//! **NanoFocus** µsurf confocal microscope files (`.nms`).
//!
//! Layout (little-endian, fixed offsets; learnt from SurfaceTopography's `NMS.py`, the only
//! public description, and checked on 2026-11-27 on its example files, which are not in the
//! shared sets: the tests write the layout instead): `16`, `24` the lowest and
//! highest height in µm (f64); `32` the format tag `OM_MS_2.0`; `52` the image's title
//! (`Confocal Height Image`); `1352` the offset of the height block (u32, 3468 in every
//! file seen), `1356` the bytes per height (u32, 2); `1368`, `1372` the points along x and
//! y (u32); `1376`, `1384` the steps along x and y (f64, no unit stored). From the header's
//! end, `ny` rows of `nx` u16 counts (rows = y, as stored), then an 8-bit intensity image
//! of the same grid (not read). A height is `zmin + count · (zmax − zmin) / 65534` µm
//! (SurfaceTopography's scale).
//!
//! The steps carry no unit: SurfaceTopography takes them as millimetres, which gives its
//! example files (512 points of step 312.5) a side of 160 m; read as nanometres they give
//! 160 µm, a plausible confocal field, but the file does not say so. The reader therefore
//! gives no size, and `--size` is asked for (never invented).

use super::bytes::{areal, bad, grid_points, samples, Cursor, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "nms";
const TAG_AT: usize = 32;
const TAG: &[u8] = b"OM_MS_";
const HEADER: usize = 3468;
/// The largest side accepted (SurfaceTopography's bound).
const MAX_SIDE: u32 = 100_000;

/// Whether the bytes carry NanoFocus' format tag and header size.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.get(TAG_AT..TAG_AT + TAG.len()) == Some(TAG)
        && bytes
            .get(1352..1356)
            .is_some_and(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize == HEADER)
}

/// Parses a whole NMS file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    let le = Endian::Little;
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(16)?;
    let (zmin, zmax) = (c.f64(le)?, c.f64(le)?);
    if bytes.get(TAG_AT..TAG_AT + TAG.len()) != Some(TAG) {
        return Err(bad(FORMAT, "no `OM_MS_` format tag at byte 32"));
    }
    c.seek(1352)?;
    let (offset, width) = (c.u32(le)? as usize, c.u32(le)?);
    if offset != HEADER || width != 2 {
        return Err(bad(
            FORMAT,
            format!("a data block at {offset} of {width}-byte samples (only 3468 and 2 known)"),
        ));
    }
    c.seek(1368)?;
    let (nx, ny) = (c.u32(le)?, c.u32(le)?);
    let (dx, dy) = (c.f64(le)?, c.f64(le)?);
    if nx > MAX_SIDE || ny > MAX_SIDE {
        return Err(bad(FORMAT, format!("a grid of {nx} × {ny} points")));
    }
    if !(crate::is_positive_finite(dx) && crate::is_positive_finite(dy)) {
        return Err(bad(FORMAT, format!("steps {dx} × {dy}")));
    }
    if !(zmin.is_finite() && zmax.is_finite() && zmax >= zmin) {
        return Err(bad(FORMAT, format!("height range {zmin} to {zmax} µm")));
    }
    let n = grid_points(FORMAT, nx.into(), ny.into())?;
    // The intensity image follows the heights: the file must hold both.
    let need = n.saturating_mul(3).saturating_add(HEADER);
    if bytes.len() < need {
        return Err(bad(
            FORMAT,
            format!("truncated: {} of {need} bytes", bytes.len()),
        ));
    }
    let step = (zmax - zmin) / 65534.0;
    let mut values = samples(FORMAT, bytes, HEADER, n, Sample::U16, le)?;
    values
        .iter_mut()
        .for_each(|v| *v = (zmin + *v * step) * 1e-6);
    Ok(Reading {
        format: FORMAT,
        channels: vec![Channel {
            name: "Default".into(),
            heights: Heights::Areal(areal(FORMAT, ny as usize, nx as usize, values)?),
            size: [None, None],
            unit: Some("µm".into()),
            is_height: true,
        }],
    })
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_close, assert_robust};
    use super::*;
    use std::time::Duration;

    /// An NMS file in the format's own layout: the header fields at their offsets, `nx × ny`
    /// u16 counts and as many intensity bytes.
    fn write(nx: u32, ny: u32, zmin: f64, zmax: f64, counts: &[u16]) -> Vec<u8> {
        let mut f = vec![0u8; HEADER];
        let mut put = |at: usize, b: &[u8]| f[at..at + b.len()].copy_from_slice(b);
        for (i, v) in [2u32, 1, 0, 65535].iter().enumerate() {
            put(4 * i, &v.to_le_bytes());
        }
        put(16, &zmin.to_le_bytes());
        put(24, &zmax.to_le_bytes());
        put(32, b"OM_MS_2.0");
        put(52, b"Confocal Height Image");
        put(1352, &(HEADER as u32).to_le_bytes());
        put(1356, &2u32.to_le_bytes());
        put(1368, &nx.to_le_bytes());
        put(1372, &ny.to_le_bytes());
        put(1376, &312.5f64.to_le_bytes());
        put(1384, &312.5f64.to_le_bytes());
        f.extend(counts.iter().flat_map(|c| c.to_le_bytes()));
        f.extend(counts.iter().map(|&c| (c >> 8) as u8));
        f
    }

    #[test]
    fn a_written_file_reads_back() {
        let f = write(3, 2, 1.0, 3.0, &[0, 32767, 65534, 1, 2, 3]);
        assert!(sniff(&f));
        let r = read(&f).unwrap();
        let c = &r.channels[0];
        assert_eq!(c.size, [None, None], "the steps have no unit: no size");
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_eq!(h.dim(), (2, 3));
        let z = |k: f64| (1.0 + k * 2.0 / 65534.0) * 1e-6;
        assert_close(
            h.iter(),
            &[z(0.0), z(32767.0), z(65534.0), z(1.0), z(2.0), z(3.0)],
        );
    }

    #[test]
    fn a_truncated_or_corrupt_written_file_is_refused() {
        let f = write(3, 2, 1.0, 3.0, &[0, 32767, 65534, 1, 2, 3]);
        assert_robust(&f, sniff, read, 1400, None, Duration::from_millis(300));
        for cut in [HEADER, HEADER + 12, f.len() - 1] {
            assert!(read(&f[..cut]).is_err(), "cut at {cut}");
        }
    }
}
