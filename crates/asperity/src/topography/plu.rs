//! Sensofar PLU files (confocal, interferometric and focus-variation profilers).
//!
//! Layout (after Gwyddion's `sensofar.c` and SurfaceTopography's `PLU.py`; little-endian):
//! a 500-byte header: the acquisition date as text (`Fri Mar 10 16:35:59 2023`, 128 bytes),
//! a `u32` time, a 256-byte comment; the calibration (offset 388: `u32 rows, u32 cols,
//! u32 N_tall, f32 dy_multip, f32 µm per pixel along x, f32 along y, …`); the measurement
//! configuration (offset 428: `u32 type` — 3 is a topography — and four more, then 40
//! bytes of scan settings); at offset 489 the number of layers and at 492 the number of
//! colour images per layer. Each layer is `u32 rows, u32 cols`, `rows × cols` `f32`
//! heights in micrometres (row order = y), `f32 min, max`, then the colour images (3 bytes
//! per point each). A height of 1000001 marks an undefined point.
//!
//! The file has no signature: it is recognised by the date its first bytes must hold and by
//! a layer that fits the file. Layers are channels `layer0`, `layer1`, …; the map is read
//! as it is (SurfaceTopography's `[x, y]` transposed).
//!
//! Not supported: profiles and other measurement types than topography (type 3).

use super::bytes::{areal, bad, fixed_text, grid_points, samples, Cursor, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "plu";
const HEADER: usize = 500;
const UNDEFINED: f64 = 1_000_001.0;
const TOPOGRAPHY: u32 = 3;
const LE: Endian = Endian::Little;
const UM: f64 = 1e-6;
const DAYS: [&str; 7] = ["Mon", "Tue", "Wed", "Thu", "Fri", "Sat", "Sun"];
const MONTHS: [&str; 12] = [
    "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
];

/// Whether the bytes start with a date as Sensofar writes it (`Www Mmm dd hh:mm:ss yyyy`)
/// and are long enough for the header and one layer's size.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    if bytes.len() < HEADER + 8 {
        return false;
    }
    let date = fixed_text(&bytes[..128]);
    let parts: Vec<&str> = date.split_whitespace().collect();
    let digits = |s: &str, n: std::ops::RangeInclusive<usize>| {
        n.contains(&s.len()) && s.bytes().all(|b| b.is_ascii_digit())
    };
    let time_ok = |t: &str| {
        let f: Vec<&str> = t.split(':').collect();
        f.len() == 3 && f.iter().all(|x| digits(x, 2..=2))
    };
    parts.len() == 5
        && DAYS.contains(&parts[0])
        && MONTHS.contains(&parts[1])
        && digits(parts[2], 1..=2)
        && time_ok(parts[3])
        && digits(parts[4], 4..=4)
}

/// Parses a whole PLU file: each layer is a channel.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(
            FORMAT,
            "the file does not start with a Sensofar date header",
        ));
    }
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(388 + 16)?;
    let (um_x, um_y) = (f64::from(c.f32(LE)?), f64::from(c.f32(LE)?));
    for (axis, d) in [("x", um_x), ("y", um_y)] {
        if !crate::is_positive_finite(d) {
            return Err(bad(FORMAT, format!("pixel size along {axis} is {d} µm")));
        }
    }
    c.seek(428)?;
    let kind = c.u32(LE)?;
    if kind != TOPOGRAPHY {
        return Err(bad(
            FORMAT,
            format!("measurement type {kind} is not a topography (3)"),
        ));
    }
    c.seek(489)?;
    let layers = c.u8()?;
    c.seek(492)?;
    let images = usize::from(c.u8()?);
    c.seek(HEADER)?;
    let mut channels = Vec::with_capacity(usize::from(layers));
    for k in 0..layers {
        let rows = c.u32(LE)?;
        let cols = c.u32(LE)?;
        let n = grid_points(FORMAT, rows.into(), cols.into())?;
        let mut values = samples(FORMAT, bytes, c.pos(), n, Sample::F32, LE)?;
        c.skip(n * 4 + 8)?; // the heights, then their min and max
        c.skip(
            n.checked_mul(3 * images)
                .ok_or_else(|| bad(FORMAT, "colour images too large"))?,
        )?;
        for v in &mut values {
            *v = if *v == UNDEFINED { f64::NAN } else { *v * UM };
        }
        let (rows, cols) = (rows as usize, cols as usize);
        channels.push(Channel {
            name: format!("layer{k}"),
            heights: Heights::Areal(areal(FORMAT, rows, cols, values)?),
            size: [Some(cols as f64 * um_x * UM), Some(rows as f64 * um_y * UM)],
            unit: Some("µm".into()),
            is_height: true,
        });
    }
    if channels.is_empty() {
        return Err(bad(FORMAT, "the file holds no layer"));
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_matches, assert_robust, reference, transposed};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        let Some(r) = reference("plu-1.plu") else {
            return;
        };
        // Ours is SurfaceTopography's [x, y] array transposed, nothing flipped.
        assert_matches(&read(&r.bytes).unwrap(), &r, &transposed(&r));
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(r) = reference("plu-1.plu") else {
            return;
        };
        // The layer and its colour image end before the file does (the file carries
        // further data that neither peer reads): cut inside what is read.
        let end = HEADER + 8 + 768 * 576 * 4 + 8 + 3 * 768 * 576;
        assert_robust(
            &r.bytes[..end],
            sniff,
            read,
            HEADER + 8,
            Some(3),
            Duration::from_millis(300),
        );
    }

    #[test]
    fn the_date_is_the_signature() {
        let mut f = vec![0u8; HEADER + 8];
        f[..24].copy_from_slice(b"Fri Mar  3 06:05:59 2023");
        assert!(sniff(&f));
        f[..3].copy_from_slice(b"Fry");
        assert!(!sniff(&f));
    }
}
