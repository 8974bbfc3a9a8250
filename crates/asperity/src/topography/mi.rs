//! Molecular Imaging / Agilent **PicoView MI** image files (`.mi`).
//!
//! A text header of lines `key value`, the key in the first 14 columns (`fileType
//! Image`, `xPixels`, `yPixels`, `xLength`, `yLength` in metres, …), with one block per
//! buffer (`bufferLabel`, `bufferRange`, `bufferUnit`, … ) in the order the data are
//! stored, ended by the line `data BINARY_32` (i32 samples) or `data BINARY` (i16), then
//! every buffer's `xPixels × yPixels` little-endian samples. A sample `s` of `b` bits
//! stands for `s · bufferRange / 2^(b−1)` in `bufferUnit`. Lines are stored from the bottom
//! of the image up; rows are returned top down, as the reference reader does. Every buffer
//! is a channel named by its label; those in a length unit are heights (metres). ASCII
//! data and spectroscopy files are refused. Facts from the shared file `mi-1.mi` and its
//! reference reading.

use super::bytes::{areal, bad, flip_rows, grid_points, length_unit, samples, Endian, Sample};
use super::{canonical_unit, Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "mi";
const MAGIC: &[u8] = b"fileType      ";

/// `fileType` in the first line.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// One header line split into its key (the first 14 columns) and value.
fn entry(line: &str) -> (&str, &str) {
    let cut = line.char_indices().nth(14).map_or(line.len(), |(i, _)| i);
    (line[..cut].trim(), line[cut..].trim())
}

/// A buffer of the header: label, range and unit.
struct Buffer {
    label: String,
    range: Option<f64>,
    unit: Option<String>,
}

/// The header's global keys, its buffers, the sample type and where the data start.
struct Header {
    keys: Vec<(String, String)>,
    buffers: Vec<Buffer>,
    sample: Sample,
    data: usize,
}

fn header(bytes: &[u8]) -> Result<Header> {
    let (mut keys, mut buffers) = (Vec::new(), Vec::<Buffer>::new());
    let mut pos = 0;
    while pos < bytes.len() {
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |e| pos + e);
        let line: String = bytes[pos..end].iter().map(|&b| b as char).collect();
        pos = (end + 1).min(bytes.len());
        let (key, value) = entry(line.trim_end_matches('\r'));
        match key {
            "data" => {
                let sample = match value {
                    "BINARY_32" => Sample::I32,
                    "BINARY" => Sample::I16,
                    other => return Err(bad(FORMAT, format!("data {other:?} is not supported"))),
                };
                return Ok(Header {
                    keys,
                    buffers,
                    sample,
                    data: pos,
                });
            }
            "bufferLabel" => buffers.push(Buffer {
                label: value.to_string(),
                range: None,
                unit: None,
            }),
            "bufferRange" | "bufferUnit" => {
                let buffer = buffers
                    .last_mut()
                    .ok_or_else(|| bad(FORMAT, format!("{key} before any bufferLabel")))?;
                if key == "bufferRange" {
                    buffer.range = value.parse().ok().filter(|r: &f64| r.is_finite());
                } else {
                    buffer.unit = Some(value.to_string());
                }
            }
            _ => keys.push((key.to_string(), value.to_string())),
        }
    }
    Err(bad(FORMAT, "no `data` line ends the header"))
}

/// Reads an MI image file (see the module docs).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "no `fileType` at the start"));
    }
    let h = header(bytes)?;
    let get = |key: &str| {
        h.keys
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    };
    if get("fileType") != Some("Image") {
        return Err(bad(
            FORMAT,
            "only image files (fileType Image) are supported",
        ));
    }
    let count = |key: &str| -> Result<u64> {
        get(key)
            .and_then(|v| v.parse::<u64>().ok())
            .filter(|&n| n >= 1)
            .ok_or_else(|| bad(FORMAT, format!("`{key}` is missing or not a pixel count")))
    };
    let length = |key: &str| -> Option<f64> {
        get(key)
            .and_then(|v| v.parse::<f64>().ok())
            .filter(|&l| crate::is_positive_finite(l))
    };
    let (nx, ny) = (count("xPixels")?, count("yPixels")?);
    let n = grid_points(FORMAT, nx, ny)?;
    if h.buffers.is_empty() {
        return Err(bad(FORMAT, "the header lists no buffer"));
    }
    let full_scale = 2f64.powi(8 * h.sample.size() as i32 - 1);
    let mut offset = h.data;
    let mut channels = Vec::with_capacity(h.buffers.len());
    for b in &h.buffers {
        let range = b.range.ok_or_else(|| {
            bad(
                FORMAT,
                format!("buffer {:?} has no valid bufferRange", b.label),
            )
        })?;
        let unit = b.unit.as_deref().unwrap_or("");
        let metres = length_unit(unit).map(|(_, f)| f);
        let factor = range / full_scale * metres.unwrap_or(1.0);
        let mut values = samples(FORMAT, bytes, offset, n, h.sample, Endian::Little)?;
        offset += n * h.sample.size();
        values.iter_mut().for_each(|v| *v *= factor);
        let mut heights = areal(FORMAT, ny as usize, nx as usize, values)?;
        flip_rows(&mut heights);
        channels.push(Channel {
            name: b.label.clone(),
            heights: Heights::Areal(heights),
            size: [length("xLength"), length("yLength")],
            unit: (!unit.is_empty()).then(|| canonical_unit(unit)),
            is_height: metres.is_some(),
        });
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_robust, check_shared, set_dir};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        // mi-1.mi: 4 buffers of 256² i32 (topography in µm, three in volts).
        check_shared("topographies-2", "mi-1.mi", Default::default());
    }

    fn line(key: &str, value: &str) -> String {
        format!("{key:<14}{value}\r\n")
    }

    #[test]
    fn a_small_file_in_the_format_layout() {
        let mut text = line("fileType", "Image");
        for (k, v) in [
            ("xPixels", "3"),
            ("yPixels", "2"),
            ("xLength", "3e-6"),
            ("yLength", "2e-6"),
        ] {
            text += &line(k, v);
        }
        for (label, unit) in [("Topography", "nm"), ("Deflection", "V")] {
            text += &line("bufferLabel", label);
            text += &line("bufferRange", "4");
            text += &line("bufferUnit", unit);
        }
        text += &line("data", "BINARY");
        let stored = [i16::MIN, 0, 16384, -8192, 1, 2, 0, 0, 0, 0, 0, 0];
        let data: Vec<u8> = stored.iter().flat_map(|v| v.to_le_bytes()).collect();
        let r = read(&[text.as_bytes(), &data].concat()).unwrap();
        let names: Vec<&str> = r.channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["Topography", "Deflection"]);
        assert!(r.channels[0].is_height && !r.channels[1].is_height);
        assert_eq!(r.channels[0].unit.as_deref(), Some("nm"));
        let Heights::Areal(h) = &r.channels[0].heights else {
            panic!()
        };
        assert_eq!(h.dim(), (2, 3));
        // Stored bottom line first; s · 4 nm / 2^15.
        assert_eq!(h[(1, 0)], -4e-9);
        assert_eq!(h[(1, 2)], 2e-9);
        assert_eq!(h[(0, 0)], -1e-9);
        // One sample short: refused.
        let short = [text.as_bytes(), &data[..data.len() - 1]].concat();
        assert!(read(&short).is_err());
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-2") else {
            return;
        };
        let bytes = std::fs::read(dir.join("mi-1.mi")).unwrap();
        assert_robust(
            &bytes,
            sniff,
            read,
            5_073,
            Some(14),
            Duration::from_millis(300),
        );
    }
}
