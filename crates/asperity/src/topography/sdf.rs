//! ISO 25178-71 surface data files (SDF), ASCII (`aISO-1.0`) and binary (`bISO-1.0`).
//!
//! Structure (ISO 25178-71; facts checked against SurfaceTopography's `SDFReader`): a
//! header of `NumPoints` (points per profile, along x), `NumProfiles` (along y),
//! `Xscale`, `Yscale` (spacings in metres), `Zscale` (metres per stored unit),
//! `Compression` (0: none) and `DataType` (5: int16, 6: int32, 7: float64). The ASCII form
//! writes `key = value` lines, a line `*`, the values (white-space separated, `BAD` for an
//! undefined point), and `*`; the binary form an 81-byte little-endian header
//! (`8s 10s 12s 12s u16 u16 f64×4 u8×3`) followed by the values, profile after profile.
//! Undefined points: `BAD` / NaN, and the smallest integer of the integer types. Profiles
//! are our rows (y), points our columns (x).

use ndarray::Array2;

use super::{bad, Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "sdf";
const ASCII_MAGIC: &[u8] = b"aISO-1.0";
const BINARY_MAGIC: &[u8] = b"bISO-1.0";
const BINARY_HEADER: usize = 81;

/// `aISO-1.0` or `bISO-1.0` at the start.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(ASCII_MAGIC) || bytes.starts_with(BINARY_MAGIC)
}

/// The header fields the data needs.
#[derive(Debug, Clone, Copy)]
struct Header {
    points: usize,
    profiles: usize,
    scale: [f64; 3],
    data_type: u8,
}

impl Header {
    /// Checks the values before any allocation: sizes, scales, data type, and that the
    /// data can be in `available` bytes (`bytes_per_value` each at least).
    fn validate(
        &self,
        compression: i64,
        available: usize,
        bytes_per_value: usize,
    ) -> Result<usize> {
        if compression != 0 {
            return Err(bad(
                FORMAT,
                format!("compression {compression} is not supported (only 0)"),
            ));
        }
        if !matches!(self.data_type, 5..=7) {
            return Err(bad(
                FORMAT,
                format!(
                    "DataType {} is not supported (5: int16, 6: int32, 7: float64)",
                    self.data_type
                ),
            ));
        }
        if self.points < 2 || self.profiles < 2 {
            return Err(bad(
                FORMAT,
                format!(
                    "a map needs at least 2 x 2 points, the header gives {} x {}",
                    self.points, self.profiles
                ),
            ));
        }
        if let Some(s) = self.scale.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(bad(FORMAT, format!("scale {s} is not positive and finite")));
        }
        let count = self
            .points
            .checked_mul(self.profiles)
            .filter(|c| {
                c.checked_mul(bytes_per_value)
                    .is_some_and(|b| b <= available)
            })
            .ok_or_else(|| {
                bad(
                    FORMAT,
                    format!(
                        "truncated: {} x {} values do not fit in the {available} bytes of data",
                        self.points, self.profiles
                    ),
                )
            })?;
        Ok(count)
    }

    fn channel(&self, values: Vec<f64>) -> Result<Channel> {
        let heights = Array2::from_shape_vec((self.profiles, self.points), values)
            .map_err(|e| bad(FORMAT, e.to_string()))?;
        Ok(Channel {
            name: "heights".into(),
            heights: Heights::Areal(heights),
            size: [
                Some(self.scale[0] * self.points as f64),
                Some(self.scale[1] * self.profiles as f64),
            ],
            unit: Some("m".into()),
            is_height: true,
        })
    }
}

/// Reads an SDF file (see the module docs).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    let channel = if bytes.starts_with(ASCII_MAGIC) {
        read_ascii(bytes)?
    } else if bytes.starts_with(BINARY_MAGIC) {
        read_binary(bytes)?
    } else {
        return Err(bad(FORMAT, "no aISO-1.0 or bISO-1.0 magic at the start"));
    };
    Ok(Reading {
        format: FORMAT,
        channels: vec![channel],
    })
}

fn read_ascii(bytes: &[u8]) -> Result<Channel> {
    let text = super::text::decode(bytes);
    let mut sections = text[ASCII_MAGIC.len()..].split('*');
    let header_text = sections.next().unwrap_or_default();
    let data = sections
        .next()
        .ok_or_else(|| bad(FORMAT, "truncated: no `*` line after the header"))?;
    let field = |name: &str| -> Result<&str> {
        header_text
            .lines()
            .filter_map(|l| l.split_once('='))
            .find(|(k, _)| k.trim() == name)
            .map(|(_, v)| v.trim())
            .ok_or_else(|| bad(FORMAT, format!("header field {name} is missing")))
    };
    let int = |name: &str| -> Result<i64> {
        field(name)?
            .parse()
            .map_err(|_| bad(FORMAT, format!("header field {name} is not a whole number")))
    };
    let float = |name: &str| -> Result<f64> {
        field(name)?
            .parse()
            .map_err(|_| bad(FORMAT, format!("header field {name} is not a number")))
    };
    let size = |name: &str| -> Result<usize> {
        usize::try_from(int(name)?).map_err(|_| bad(FORMAT, format!("{name} is negative")))
    };
    let header = Header {
        points: size("NumPoints")?,
        profiles: size("NumProfiles")?,
        scale: [float("Xscale")?, float("Yscale")?, float("Zscale")?],
        data_type: u8::try_from(int("DataType")?).unwrap_or(0),
    };
    let compression = field("Compression")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    // A value takes at least 2 characters (a digit and a separator).
    let count = header.validate(compression, data.len() + 1, 2)?;
    let mut values = Vec::with_capacity(count);
    for token in data.split_whitespace() {
        if values.len() == count {
            return Err(bad(
                FORMAT,
                format!("more than the {count} values the header gives"),
            ));
        }
        let v = match token {
            "BAD" | "bad" => f64::NAN,
            t => super::text::number(t)
                .ok_or_else(|| bad(FORMAT, format!("{t:?} is not a number")))?,
        };
        values.push(v * header.scale[2]);
    }
    if values.len() != count {
        return Err(bad(
            FORMAT,
            format!(
                "truncated: {} values where the header gives {count}",
                values.len()
            ),
        ));
    }
    header.channel(values)
}

fn read_binary(bytes: &[u8]) -> Result<Channel> {
    if bytes.len() < BINARY_HEADER {
        return Err(bad(
            FORMAT,
            format!(
                "truncated: {} bytes, the binary header alone has 81",
                bytes.len()
            ),
        ));
    }
    let u16_at = |o: usize| u16::from_le_bytes([bytes[o], bytes[o + 1]]) as usize;
    let f64_at = |o: usize| f64::from_le_bytes(bytes[o..o + 8].try_into().expect("8 bytes"));
    let header = Header {
        points: u16_at(42),
        profiles: u16_at(44),
        scale: [f64_at(46), f64_at(54), f64_at(62)],
        data_type: bytes[79],
    };
    let compression = bytes[78] as i64;
    let width = match header.data_type {
        5 => 2,
        6 => 4,
        _ => 8,
    };
    let data = &bytes[BINARY_HEADER..];
    let count = header.validate(compression, data.len(), width)?;
    let z = header.scale[2];
    let values = data[..count * width]
        .chunks_exact(width)
        .map(|c| match header.data_type {
            5 => match i16::from_le_bytes([c[0], c[1]]) {
                i16::MIN => f64::NAN,
                v => v as f64 * z,
            },
            6 => match i32::from_le_bytes(c.try_into().expect("4 bytes")) {
                i32::MIN => f64::NAN,
                v => v as f64 * z,
            },
            _ => f64::from_le_bytes(c.try_into().expect("8 bytes")) * z,
        })
        .map(|v| if v.is_finite() { v } else { f64::NAN })
        .collect();
    header.channel(values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::test_files::{assert_close, folder, fuzz, record, reference};

    #[test]
    fn ascii_sdf_matches_the_reference() {
        let Some(dir) = folder() else { return };
        let name = "sdf-1.sdf";
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let reading = read(&bytes).unwrap();
        let c = &reading.channels[0];
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        // Reference [x, y] = our (row y, col x) transposed.
        let reference = reference(&dir, name)
            .into_dimensionality::<ndarray::Ix2>()
            .unwrap();
        assert_eq!(reference.dim(), (h.ncols(), h.nrows()));
        for ((x, y), v) in reference.indexed_iter() {
            assert_close(h[(y, x)], *v, 1e-12, name);
        }
        let record = record(&dir, name);
        for axis in 0..2 {
            let want = record["physical_sizes_m"][axis].as_f64().unwrap();
            assert_close(c.size[axis].unwrap(), want, 1e-12, name);
        }
    }

    /// A binary SDF built from the structure: header, then int16 values with one BAD.
    #[test]
    fn binary_sdf_with_an_undefined_point() {
        let mut bytes = b"bISO-1.0".to_vec();
        bytes.extend_from_slice(&[b' '; 34]); // ManufacID, CreateDate, ModDate
        bytes.extend_from_slice(&3u16.to_le_bytes());
        bytes.extend_from_slice(&2u16.to_le_bytes());
        for s in [1e-6, 2e-6, 1e-9, 1e-9] {
            bytes.extend_from_slice(&f64::to_le_bytes(s));
        }
        bytes.extend_from_slice(&[0, 5, 0]);
        assert_eq!(bytes.len(), BINARY_HEADER);
        for v in [1i16, 2, 3, 4, i16::MIN, -6] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let r = read(&bytes).unwrap();
        let Heights::Areal(h) = &r.channels[0].heights else {
            panic!()
        };
        assert_eq!(h.dim(), (2, 3));
        assert_close(h[(0, 2)], 3e-9, 1e-15, "int16 × Zscale");
        assert!(h[(1, 1)].is_nan());
        assert_close(h[(1, 2)], -6e-9, 1e-15, "int16 × Zscale");
        assert_eq!(r.channels[0].size, [Some(3e-6), Some(4e-6)]);
        assert!(read(&bytes[..bytes.len() - 1]).is_err());
        fuzz(&bytes, read);
    }

    #[test]
    fn fuzzed_sdf_never_panics() {
        let Some(dir) = folder() else { return };
        let bytes = std::fs::read(dir.join("sdf-1.sdf")).unwrap();
        fuzz(&bytes, read);
        assert!(read(b"aISO-1.0\nNumPoints = 99999999\nNumProfiles = 99999999\n*\n1\n*").is_err());
    }
}
