//! Bounds-checked reading of the binary instrument formats: a cursor over the file's bytes
//! that returns an error (never panics) when a field lies past the end, the decoding of a
//! whole data block whose size is checked against the file before anything is allocated,
//! and the length units the formats write.
//!
//! Every reader of this module's siblings goes through these helpers, so that a header field
//! holding a huge size can only produce [`Error::BadTopography`], never a huge allocation:
//! [`samples`] allocates only after the block it decodes was found inside the file.

use crate::{Error, Result};
use ndarray::Array2;

/// The error of a reader of `format`, with a reason in words.
pub(crate) fn bad(format: &'static str, reason: impl Into<String>) -> Error {
    Error::BadTopography {
        format,
        reason: reason.into(),
    }
}

/// Byte order of a multi-byte field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Endian {
    /// Least significant byte first (Intel).
    Little,
    /// Most significant byte first (Motorola, network order).
    Big,
}

/// A reading position in a file's bytes; every read is checked against the end.
#[derive(Debug, Clone)]
pub(crate) struct Cursor<'a> {
    format: &'static str,
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `bytes`.
    pub(crate) fn new(format: &'static str, bytes: &'a [u8]) -> Self {
        Cursor {
            format,
            bytes,
            pos: 0,
        }
    }

    /// The current offset from the start of the file.
    pub(crate) fn pos(&self) -> usize {
        self.pos
    }

    /// Moves to an absolute offset, which must lie inside the file (or at its end).
    pub(crate) fn seek(&mut self, pos: usize) -> Result<()> {
        if pos > self.bytes.len() {
            return Err(self.past_end(pos, 0));
        }
        self.pos = pos;
        Ok(())
    }

    /// Skips `n` bytes.
    pub(crate) fn skip(&mut self, n: usize) -> Result<()> {
        self.take(n).map(|_| ())
    }

    /// The next `n` bytes.
    pub(crate) fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&end| end <= self.bytes.len())
            .ok_or_else(|| self.past_end(self.pos, n))?;
        let out = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(out)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N]> {
        let mut out = [0u8; N];
        out.copy_from_slice(self.take(N)?);
        Ok(out)
    }

    /// An unsigned byte.
    pub(crate) fn u8(&mut self) -> Result<u8> {
        Ok(self.array::<1>()?[0])
    }

    /// An unsigned 16-bit integer.
    pub(crate) fn u16(&mut self, e: Endian) -> Result<u16> {
        let b = self.array()?;
        Ok(match e {
            Endian::Little => u16::from_le_bytes(b),
            Endian::Big => u16::from_be_bytes(b),
        })
    }

    /// A signed 16-bit integer.
    pub(crate) fn i16(&mut self, e: Endian) -> Result<i16> {
        Ok(self.u16(e)? as i16)
    }

    /// An unsigned 32-bit integer.
    pub(crate) fn u32(&mut self, e: Endian) -> Result<u32> {
        let b = self.array()?;
        Ok(match e {
            Endian::Little => u32::from_le_bytes(b),
            Endian::Big => u32::from_be_bytes(b),
        })
    }

    /// A signed 32-bit integer.
    pub(crate) fn i32(&mut self, e: Endian) -> Result<i32> {
        Ok(self.u32(e)? as i32)
    }

    /// A 32-bit IEEE float.
    pub(crate) fn f32(&mut self, e: Endian) -> Result<f32> {
        Ok(f32::from_bits(self.u32(e)?))
    }

    /// A 64-bit IEEE float.
    pub(crate) fn f64(&mut self, e: Endian) -> Result<f64> {
        let b = self.array()?;
        Ok(match e {
            Endian::Little => f64::from_le_bytes(b),
            Endian::Big => f64::from_be_bytes(b),
        })
    }

    /// A fixed-width text field, ISO-8859-1, cut at the first NUL and trimmed.
    pub(crate) fn text(&mut self, n: usize) -> Result<String> {
        Ok(fixed_text(self.take(n)?))
    }

    fn past_end(&self, pos: usize, n: usize) -> Error {
        bad(
            self.format,
            format!(
                "truncated: {n} bytes wanted at offset {pos}, but the file has {} bytes",
                self.bytes.len()
            ),
        )
    }
}

/// A fixed-width text field: ISO-8859-1, cut at the first NUL, surrounding blanks trimmed.
pub(crate) fn fixed_text(field: &[u8]) -> String {
    let end = field.iter().position(|&b| b == 0).unwrap_or(field.len());
    latin1(&field[..end]).trim().to_string()
}

/// ISO-8859-1 bytes as text (every byte is the code point of the same value).
pub(crate) fn latin1(bytes: &[u8]) -> String {
    bytes.iter().map(|&b| char::from(b)).collect()
}

/// How one sample of a data block is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sample {
    /// Unsigned byte.
    U8,
    /// Signed 16-bit integer.
    I16,
    /// Unsigned 16-bit integer.
    U16,
    /// Signed 32-bit integer.
    I32,
    /// Unsigned 32-bit integer.
    U32,
    /// 32-bit IEEE float.
    F32,
    /// 64-bit IEEE float.
    F64,
}

impl Sample {
    /// Bytes per sample.
    pub(crate) fn size(self) -> usize {
        match self {
            Sample::U8 => 1,
            Sample::I16 | Sample::U16 => 2,
            Sample::I32 | Sample::U32 | Sample::F32 => 4,
            Sample::F64 => 8,
        }
    }

    fn decode(self, b: &[u8], e: Endian) -> f64 {
        let le = e == Endian::Little;
        match self {
            Sample::U8 => f64::from(b[0]),
            Sample::I16 => {
                let a = [b[0], b[1]];
                f64::from(if le {
                    i16::from_le_bytes(a)
                } else {
                    i16::from_be_bytes(a)
                })
            }
            Sample::U16 => {
                let a = [b[0], b[1]];
                f64::from(if le {
                    u16::from_le_bytes(a)
                } else {
                    u16::from_be_bytes(a)
                })
            }
            Sample::I32 => {
                let a = [b[0], b[1], b[2], b[3]];
                f64::from(if le {
                    i32::from_le_bytes(a)
                } else {
                    i32::from_be_bytes(a)
                })
            }
            Sample::U32 => {
                let a = [b[0], b[1], b[2], b[3]];
                f64::from(if le {
                    u32::from_le_bytes(a)
                } else {
                    u32::from_be_bytes(a)
                })
            }
            Sample::F32 => {
                let a = [b[0], b[1], b[2], b[3]];
                f64::from(if le {
                    f32::from_le_bytes(a)
                } else {
                    f32::from_be_bytes(a)
                })
            }
            Sample::F64 => {
                let a = [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
                if le {
                    f64::from_le_bytes(a)
                } else {
                    f64::from_be_bytes(a)
                }
            }
        }
    }
}

/// The number of points of an `nx × ny` grid, refused when a side is zero or the product
/// overflows (a corrupt header); whether the data fit in the file is checked by [`samples`].
pub(crate) fn grid_points(format: &'static str, nx: u64, ny: u64) -> Result<usize> {
    if nx == 0 || ny == 0 {
        return Err(bad(format, format!("empty grid of {nx} × {ny} points")));
    }
    nx.checked_mul(ny)
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| bad(format, format!("grid of {nx} × {ny} points is too large")))
}

/// Decodes `count` samples stored from `offset` on. The block is checked to lie inside the
/// file before the output is allocated, so its size is bounded by the file's length.
pub(crate) fn samples(
    format: &'static str,
    bytes: &[u8],
    offset: usize,
    count: usize,
    sample: Sample,
    endian: Endian,
) -> Result<Vec<f64>> {
    let block = sample_block(format, bytes, offset, count, sample)?;
    Ok(block
        .chunks_exact(sample.size())
        .map(|b| sample.decode(b, endian))
        .collect())
}

/// The bytes of a block of `count` samples at `offset`, checked to lie inside the file.
pub(crate) fn sample_block<'a>(
    format: &'static str,
    bytes: &'a [u8],
    offset: usize,
    count: usize,
    sample: Sample,
) -> Result<&'a [u8]> {
    let end = count
        .checked_mul(sample.size())
        .and_then(|len| offset.checked_add(len));
    match end {
        Some(end) if end <= bytes.len() => Ok(&bytes[offset..end]),
        _ => Err(bad(
            format,
            format!(
                "truncated: a data block of {count} samples of {} bytes at offset {offset} does \
                 not fit in the file's {} bytes",
                sample.size(),
                bytes.len()
            ),
        )),
    }
}

/// A row-major `rows × cols` map from values in row order.
pub(crate) fn areal(
    format: &'static str,
    rows: usize,
    cols: usize,
    values: Vec<f64>,
) -> Result<Array2<f64>> {
    Array2::from_shape_vec((rows, cols), values).map_err(|e| {
        bad(
            format,
            format!("data do not form a {rows} × {cols} grid ({e})"),
        )
    })
}

/// An areal channel of `map` (rows along y) with sizes `[x, y]` in metres (`None`: not in
/// the file, asked for) and the file's unit (`None`: the file gives none).
pub(crate) fn areal_channel(
    name: impl Into<String>,
    map: Array2<f64>,
    size: [Option<f64>; 2],
    unit: Option<&str>,
    is_height: bool,
) -> super::Channel {
    super::Channel {
        name: name.into(),
        heights: super::Heights::Areal(map),
        size,
        unit: unit.map(str::to_string),
        is_height,
    }
}

/// A reading of one areal height channel, `name`, of `map` in `unit` with sizes `[x, y]`
/// in metres: what single-image formats (LEXT, ZON, AL3D, …) give.
pub(crate) fn height_reading(
    format: &'static str,
    name: &str,
    map: Array2<f64>,
    size: [f64; 2],
    unit: &str,
) -> super::Reading {
    super::Reading {
        format,
        channels: vec![areal_channel(name, map, size.map(Some), Some(unit), true)],
    }
}

/// A length unit as the formats write it: its canonical spelling and its value in metres.
/// Accepts the SI prefixes from pico to kilo, the micro sign in its Unicode, ISO-8859-1
/// (`µ`), MS-DOS (`æ`) and ASCII (`u`, Nanoscope's `~`) spellings, and the ångström.
pub(crate) fn length_unit(unit: &str) -> Option<(&'static str, f64)> {
    let unit = unit.trim();
    Some(match unit {
        "m" => ("m", 1.0),
        "km" => ("km", 1e3),
        "dm" => ("dm", 1e-1),
        "cm" => ("cm", 1e-2),
        "mm" => ("mm", 1e-3),
        "µm" | "μm" | "um" | "~m" | "æm" | "micron" | "microns" => ("µm", 1e-6),
        "nm" => ("nm", 1e-9),
        "Å" | "A" | "Angstrom" | "angstrom" => ("Å", 1e-10),
        "pm" => ("pm", 1e-12),
        _ => return None,
    })
}

/// The metres per unit of a length unit, or an error naming the field that carried it.
pub(crate) fn metres_per(format: &'static str, what: &str, unit: &str) -> Result<f64> {
    length_unit(unit).map(|(_, f)| f).ok_or_else(|| {
        bad(
            format,
            format!("{what} has unit `{unit}`, which is not a length"),
        )
    })
}

/// Reverses the order of the rows of a map (a flip upside down), in place (rows swapped
/// pairwise) when the map is in standard layout, so a reader never holds it twice.
pub(crate) fn flip_rows(a: &mut Array2<f64>) {
    let cols = a.ncols();
    match a.as_slice_mut() {
        Some(v) if cols > 0 => {
            let rows = v.len() / cols;
            for i in 0..rows / 2 {
                let (top, bottom) = v.split_at_mut((rows - 1 - i) * cols);
                top[i * cols..(i + 1) * cols].swap_with_slice(&mut bottom[..cols]);
            }
        }
        Some(_) => {}
        None => {
            a.invert_axis(ndarray::Axis(0));
            *a = a.as_standard_layout().into_owned();
        }
    }
}

/// Reverses the order of the columns of a map (a left-right mirror), in place when the
/// map is in standard layout.
pub(crate) fn flip_cols(a: &mut Array2<f64>) {
    let cols = a.ncols();
    match a.as_slice_mut() {
        Some(v) if cols > 0 => v.chunks_exact_mut(cols).for_each(|row| row.reverse()),
        Some(_) => {}
        None => {
            a.invert_axis(ndarray::Axis(1));
            *a = a.as_standard_layout().into_owned();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flips_in_place_match_the_reversed_views() {
        // Odd and even row counts, a single row and column, and a map not in standard
        // layout (a transposed view), against ndarray's reversed views copied.
        for (rows, cols) in [(5, 3), (4, 6), (1, 4), (3, 1)] {
            let a = Array2::from_shape_fn((rows, cols), |(i, j)| (i * 10 + j) as f64);
            for m in [a.clone(), a.t().to_owned(), a.t().into_owned()] {
                let mut r = m.clone();
                flip_rows(&mut r);
                assert_eq!(r, m.slice(ndarray::s![..;-1, ..]));
                let mut c = m.clone();
                flip_cols(&mut c);
                assert_eq!(c, m.slice(ndarray::s![.., ..;-1]));
            }
        }
    }

    #[test]
    fn cursor_reads_both_byte_orders_and_stops_at_the_end() {
        let bytes = [0x01, 0x02, 0x03, 0x04, 0x05];
        let mut c = Cursor::new("test", &bytes);
        assert_eq!(c.u16(Endian::Little).unwrap(), 0x0201);
        assert_eq!(c.u16(Endian::Big).unwrap(), 0x0304);
        assert!(c.u16(Endian::Little).is_err());
        assert_eq!(c.pos(), 4);
        assert!(c.seek(6).is_err());
        c.seek(1).unwrap();
        assert_eq!(c.u32(Endian::Big).unwrap(), 0x02030405);
        assert!(c.take(usize::MAX).is_err());
    }

    #[test]
    fn samples_refuse_a_block_past_the_end_before_allocating() {
        let bytes = 1.5f32.to_le_bytes();
        let v = samples("test", &bytes, 0, 1, Sample::F32, Endian::Little).unwrap();
        assert_eq!(v, vec![1.5]);
        assert!(samples("test", &bytes, 1, 1, Sample::F32, Endian::Little).is_err());
        // A count whose byte size overflows is an error, not an allocation.
        assert!(samples("test", &bytes, 0, usize::MAX / 2, Sample::F64, Endian::Big).is_err());
        assert!(grid_points("test", u64::MAX, 3).is_err());
        assert!(grid_points("test", 0, 3).is_err());
    }

    #[test]
    fn samples_decode_every_type_in_both_orders() {
        let cases: [(Sample, Vec<u8>, f64); 6] = [
            (Sample::U8, vec![200], 200.0),
            (Sample::I16, (-3i16).to_be_bytes().to_vec(), -3.0),
            (Sample::U16, 65000u16.to_be_bytes().to_vec(), 65000.0),
            (Sample::I32, (-70000i32).to_be_bytes().to_vec(), -70000.0),
            (Sample::F32, 0.25f32.to_be_bytes().to_vec(), 0.25),
            (Sample::F64, (-1e-300f64).to_be_bytes().to_vec(), -1e-300),
        ];
        for (s, be, want) in cases {
            let le: Vec<u8> = be.iter().rev().copied().collect();
            assert_eq!(samples("t", &be, 0, 1, s, Endian::Big).unwrap(), vec![want]);
            assert_eq!(
                samples("t", &le, 0, 1, s, Endian::Little).unwrap(),
                vec![want]
            );
        }
    }

    #[test]
    fn length_units_in_their_spellings() {
        assert_eq!(length_unit("~m"), Some(("µm", 1e-6)));
        assert_eq!(length_unit("\u{e6}m"), Some(("µm", 1e-6)));
        assert_eq!(length_unit(" nm "), Some(("nm", 1e-9)));
        assert_eq!(length_unit("V"), None);
        assert!(metres_per("t", "height", "V").is_err());
    }
}
