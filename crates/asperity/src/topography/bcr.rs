//! Image Metrology SPIP **BCR / BCRF** files (`.bcr`, `.bcrf`).
//!
//! A text header of `key = value` lines, `headersize` characters long (ASCII, or UTF-16LE
//! for the `_unicode` variants, two bytes a character), then `xpixels × ypixels` samples,
//! row by row (our rows are y, as stored): `fileformat = bcrstm` (or `bcrstm_unicode`)
//! holds `i16` samples, times `bit2nm` nanometres; `bcrf` (or `bcrf_unicode`) holds `f32`
//! heights in `zunit` (nanometres where the header names none). `intelmode = 1` is
//! little-endian, `0` big-endian. The physical sizes are `xlength`, `ylength` in `xunit`,
//! `yunit` (nanometres by default). A sample equal to `voidpixels` (f32 files write the
//! largest f32) is undefined. Facts from SPIP's description of the format and
//! SurfaceTopography's `BCRReader`; its reference reading of `bcrf-1.bcrf` reports the
//! lateral unit (nm) as the heights' unit, where the file says `zunit = um`: we keep the
//! file's `µm`, the heights in metres agree.

use super::bytes::{areal, bad, grid_points, samples, Endian, Sample};
use super::{unit_to_metres, Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "bcr";
const ASCII_MAGIC: &[u8] = b"fileformat = bcr";

/// `fileformat = bcr…` in ASCII or UTF-16LE.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(ASCII_MAGIC) || {
        let wide: Vec<u8> = ASCII_MAGIC.iter().flat_map(|&b| [b, 0]).collect();
        bytes.starts_with(&wide)
    }
}

/// The header's `key = value` pairs and its length in bytes.
fn header(bytes: &[u8]) -> Result<(Vec<(String, String)>, usize)> {
    let unicode = bytes.get(1) == Some(&0);
    let width = if unicode { 2 } else { 1 };
    // The header size is among the first lines; read a bounded prefix to find it.
    let decode = |b: &[u8]| -> String {
        if unicode {
            let units: Vec<u16> = b
                .chunks_exact(2)
                .map(|c| u16::from_le_bytes([c[0], c[1]]))
                .collect();
            String::from_utf16_lossy(&units)
        } else {
            b.iter().map(|&c| c as char).collect()
        }
    };
    let pairs = |text: &str| -> Vec<(String, String)> {
        text.lines()
            .filter_map(|l| l.split_once('='))
            .map(|(k, v)| {
                (
                    k.trim().to_ascii_lowercase(),
                    v.trim().trim_end_matches('\0').trim().to_string(),
                )
            })
            .collect()
    };
    let prefix = pairs(&decode(&bytes[..bytes.len().min(512 * width)]));
    let size: usize = prefix
        .iter()
        .find(|(k, _)| k == "headersize")
        .and_then(|(_, v)| v.parse().ok())
        .ok_or_else(|| bad(FORMAT, "no headersize in the header"))?;
    let len = size
        .checked_mul(width)
        .filter(|&l| l <= bytes.len())
        .ok_or_else(|| {
            bad(
                FORMAT,
                format!("headersize {size} runs past the end of the file"),
            )
        })?;
    Ok((pairs(&decode(&bytes[..len])), len))
}

/// Reads a BCR / BCRF file (see the module docs).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "no `fileformat = bcr` at the start"));
    }
    let (entries, offset) = header(bytes)?;
    let get = |key: &str| {
        entries
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    };
    let number = |key: &str| -> Result<f64> {
        get(key)
            .and_then(|v| v.parse::<f64>().ok())
            .ok_or_else(|| bad(FORMAT, format!("`{key}` is missing or not a number")))
    };
    let sample = match get("fileformat").unwrap_or("") {
        "bcrstm" | "bcrstm_unicode" => Sample::I16,
        "bcrf" | "bcrf_unicode" => Sample::F32,
        other => {
            return Err(bad(
                FORMAT,
                format!("fileformat {other:?} is not supported"),
            ))
        }
    };
    let endian = match get("intelmode") {
        Some("0") => Endian::Big,
        _ => Endian::Little,
    };
    let count = |key: &str| -> Result<u64> {
        let v = number(key)?;
        if v.fract() == 0.0 && v >= 1.0 && v <= u32::MAX as f64 {
            Ok(v as u64)
        } else {
            Err(bad(FORMAT, format!("`{key}` = {v} is not a pixel count")))
        }
    };
    let (nx, ny) = (count("xpixels")?, count("ypixels")?);
    let n = grid_points(FORMAT, nx, ny)?;
    let mut values = samples(FORMAT, bytes, offset, n, sample, endian)?;
    let void = get("voidpixels").and_then(|v| v.parse::<f64>().ok());
    let factor = match sample {
        Sample::I16 => number("bit2nm")? * 1e-9,
        _ => metres(get("zunit"), "zunit")?,
    };
    for v in &mut values {
        // Within f32 rounding of the written marker (`3.402823E+38` for the largest f32).
        let undefined = void.is_some_and(|u| (*v - u).abs() <= 1e-6 * u.abs());
        *v = if undefined { f64::NAN } else { *v * factor };
    }
    let size = |key: &str, unit: &str| -> Result<Option<f64>> {
        let s = number(key)? * metres(get(unit), unit)?;
        Ok(crate::is_positive_finite(s).then_some(s))
    };
    let z_unit = match sample {
        Sample::I16 => "nm".to_string(),
        _ => super::canonical_unit(get("zunit").unwrap_or("nm")),
    };
    Ok(Reading {
        format: FORMAT,
        channels: vec![Channel {
            name: "Default".into(),
            heights: Heights::Areal(areal(FORMAT, ny as usize, nx as usize, values)?),
            size: [size("xlength", "xunit")?, size("ylength", "yunit")?],
            unit: Some(z_unit),
            is_height: true,
        }],
    })
}

/// Metres per unit of a header's unit (`nm` where it names none).
fn metres(unit: Option<&str>, key: &str) -> Result<f64> {
    let unit = unit.unwrap_or("nm");
    unit_to_metres(unit)
        .ok_or_else(|| bad(FORMAT, format!("`{key}` = {unit:?} is not a length unit")))
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_robust, check_shared, set_dir, Expect};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        // bcrf-1.bcrf: UTF-16 header of 2048 characters, f32 heights in µm. The peer
        // names the lateral unit (nm) as the heights'; we keep the file's zunit.
        let expect = Expect {
            unit: Some(Some("µm")),
            ..Expect::default()
        };
        check_shared("topographies-2", "bcrf-1.bcrf", expect);
    }

    #[test]
    fn an_ascii_bcrstm_file_in_the_format_layout() {
        let text = "fileformat = bcrstm\nheadersize = NNNN\nxpixels = 3\nypixels = 2\nbit2nm = 0.5\nxlength = 30\nylength = 20\nvoidpixels = 32767\n";
        let text = text.replace("NNNN", &format!("{:04}", text.len()));
        let data: Vec<u8> = [1i16, 2, 3, 4, 32767, -6]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let f = [text.as_bytes(), &data].concat();
        let r = read(&f).unwrap();
        let c = &r.channels[0];
        for (got, want) in c.size.iter().zip([30e-9, 20e-9]) {
            assert!((got.unwrap() - want).abs() < 1e-15 * want, "{got:?}");
        }
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_eq!(h.dim(), (2, 3));
        assert!(h[(1, 1)].is_nan());
        assert!((h[(1, 2)] + 3e-9).abs() < 1e-24); // -6 × 0.5 nm
                                                   // Absurd dimensions: refused before anything is allocated.
        let huge = text.replace("xpixels = 3", "xpixels = 9");
        assert!(read(&[huge.as_bytes(), &data].concat()).is_err());
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-2") else {
            return;
        };
        let bytes = std::fs::read(dir.join("bcrf-1.bcrf")).unwrap();
        assert_robust(
            &bytes,
            sniff,
            read,
            4096,
            Some(8),
            Duration::from_millis(300),
        );
    }
}
