//! Zygo MetroPro DAT files (binary, written by the MetroPro software of Zygo
//! interferometers).
//!
//! Layout (Zygo's MetroPro reference guide, section "Data file format", as read by
//! Gwyddion's `metropro.c` and SurfaceTopography's `MetroPro.py`): big-endian; a header
//! whose signature is `88 1B 03 6F`, `…70` or `…71` (header formats 1, 2 and 3) and whose
//! size (offset 6) is 834 bytes for formats 1 and 2 and 4096 for format 3; then
//! `ac_n_buckets` intensity frames of `ac_width × ac_height` `u16`, then the phase map of
//! `cn_width × cn_height` `i32` (offsets 52–58 and 68–70), rows in order of y.
//!
//! Heights (metres): `phase · intf_scale_factor · obliquity_factor · wavelength / R`, with
//! `R` = 4096, 32768 or 131072 for `phase_res` (offset 218) 0, 1, 2, negated where `sign`
//! (offset 232) is set; the factors are `f32` at offsets 164, 176 and 168 (wavelength in
//! metres). A phase of 2147483640 or more marks an undefined point. The lateral size is
//! `lateral_res` (offset 184, metres per pixel) times the pixel counts; a file without it
//! (0) has no size. The map is read as it is (SurfaceTopography's `[x, y]` transposed).
//! The intensity frames are not read.

use super::bytes::{areal, bad, grid_points, samples, Cursor, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "metropro";
const MAGICS: [[u8; 4]; 3] = [
    [0x88, 0x1b, 0x03, 0x6f],
    [0x88, 0x1b, 0x03, 0x70],
    [0x88, 0x1b, 0x03, 0x71],
];
/// Phases at or above this mark undefined points.
const INVALID_PHASE: f64 = 2_147_483_640.0;
const BE: Endian = Endian::Big;

/// Whether the bytes start with one of MetroPro's three signatures.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    MAGICS.iter().any(|m| bytes.starts_with(m))
}

/// Parses a whole MetroPro DAT file (its phase map; the intensity frames are skipped).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(
            FORMAT,
            "the file does not start with a MetroPro signature",
        ));
    }
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(6)?;
    let header_size = c.u32(BE)? as usize;
    let expected = if bytes[3] == 0x71 { 4096 } else { 834 };
    if header_size != expected {
        return Err(bad(
            FORMAT,
            format!("header size {header_size}, expected {expected}"),
        ));
    }
    c.seek(52)?;
    let (ac_w, ac_h, buckets) = (c.u16(BE)?, c.u16(BE)?, c.u16(BE)?);
    c.seek(68)?;
    let (cn_w, cn_h) = (c.u16(BE)?, c.u16(BE)?);
    c.seek(164)?;
    let scale_factor = f64::from(c.f32(BE)?);
    let wavelength = f64::from(c.f32(BE)?);
    c.seek(176)?;
    let obliquity = f64::from(c.f32(BE)?);
    c.seek(184)?;
    let lateral_res = f64::from(c.f32(BE)?);
    c.seek(218)?;
    let resolution = match c.i16(BE)? {
        0 => 4096.0,
        1 => 32768.0,
        2 => 131072.0,
        other => {
            return Err(bad(
                FORMAT,
                format!("phase resolution code {other} (0, 1, 2 known)"),
            ))
        }
    };
    c.seek(232)?;
    let sign = if c.i16(BE)? != 0 { -1.0 } else { 1.0 };
    c.seek(header_size)?;
    let intensity = 2 * usize::from(buckets) * usize::from(ac_w) * usize::from(ac_h);
    c.skip(intensity)?;
    let n = grid_points(FORMAT, cn_w.into(), cn_h.into())?;
    let factor = sign * scale_factor * obliquity * wavelength / resolution;
    if !(factor.is_finite() && factor != 0.0) {
        return Err(bad(
            FORMAT,
            format!("height scale {factor} is not a usable number"),
        ));
    }
    let mut values = samples(FORMAT, bytes, c.pos(), n, Sample::I32, BE)?;
    for v in &mut values {
        *v = if *v >= INVALID_PHASE {
            f64::NAN
        } else {
            *v * factor
        };
    }
    let map = areal(FORMAT, cn_h.into(), cn_w.into(), values)?;
    let size = |pixels: u16| (lateral_res > 0.0).then(|| lateral_res * f64::from(pixels));
    Ok(Reading {
        format: FORMAT,
        channels: vec![Channel {
            name: "Default".into(),
            heights: Heights::Areal(map),
            size: [size(cn_w), size(cn_h)],
            unit: Some("m".into()),
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
        let Some(r) = reference("metropro-1.dat") else {
            return;
        };
        // Ours is SurfaceTopography's [x, y] array transposed, nothing flipped.
        assert_matches(&read(&r.bytes).unwrap(), &r, &transposed(&r));
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(r) = reference("metropro-1.dat") else {
            return;
        };
        assert_robust(
            &r.bytes,
            sniff,
            read,
            834,
            Some(4),
            Duration::from_millis(300),
        );
    }

    #[test]
    fn phase_scale_sign_and_invalid_marker() {
        let mut f = vec![0u8; 834];
        f[..4].copy_from_slice(&MAGICS[0]);
        f[6..10].copy_from_slice(&834u32.to_be_bytes());
        f[68..70].copy_from_slice(&2u16.to_be_bytes());
        f[70..72].copy_from_slice(&1u16.to_be_bytes());
        for (at, v) in [(164, 0.5f32), (168, 632.8e-9), (176, 1.0), (184, 1e-6)] {
            f[at..at + 4].copy_from_slice(&v.to_be_bytes());
        }
        f[218..220].copy_from_slice(&1i16.to_be_bytes());
        f[232..234].copy_from_slice(&1i16.to_be_bytes());
        f.extend_from_slice(&32768i32.to_be_bytes());
        f.extend_from_slice(&2147483647i32.to_be_bytes());
        let reading = read(&f).unwrap();
        let c = &reading.channels[0];
        let px = f64::from(1e-6f32);
        assert_eq!(c.size, [Some(2.0 * px), Some(px)]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        // One full phase range is half a wavelength (scale factor 0.5), negated by `sign`.
        let want = -0.5 * f64::from(632.8e-9f32);
        assert!((h[[0, 0]] - want).abs() < 1e-15 * want.abs());
        assert!(h[[0, 1]].is_nan());
    }
}
