//! Bruker / Veeco / Digital Instruments Nanoscope files (`.spm`, `.001`, …), version 4.3
//! and later, binary data.
//!
//! Layout (the Nanoscope file-format notes, Gwyddion's `nanoscope.c`, SurfaceTopography's
//! `DI.py`): a text header of ISO-8859-1 lines `\*Section` and `\Key: value`, from
//! `\*File list` to `\*File list end`. Each `\*Ciao image list` section (or its older names)
//! is one channel: `Data offset`, `Data length`, `Bytes/pixel` (2 or 4), `Samps/line` (x),
//! `Number of lines` (y), `Scan Size: sx sy unit`, the channel's name in the brackets of
//! `@2:Image Data: S [Height] "Height"`, and its scale `@2:Z scale: V [Sens. Zsens]
//! (0.0050354 V/LSB) 2.910461 V`. From version 9.2 on (`Version: 0x09200000`) the samples
//! are always 32-bit; `Bytes/pixel` then only sets the scale.
//!
//! Scale of a channel (the "hard" and "soft" scales of the notes): a sample `s` (signed,
//! little-endian) is `s · hard / 256^bytes_per_pixel` in the hard value's unit (`V`), times
//! the soft scale `@Sens. Zsens: V 20.83 nm/V` of the scanner or scan list, which turns it
//! into a length. A channel whose soft scale gives a length (`nm/V`) is a height channel,
//! in metres; the others (phase, amplitude error) keep the unit the scales give (`º`, `mV`).
//!
//! Orientation: the lines are stored from the top of the image down; like both peers we
//! reverse them, so our row 0 is the last stored line (SurfaceTopography's `[x, y]` array,
//! which it flips along y, transposed).
//!
//! Not supported: text-data files (`?*File list`), force curves and force volumes,
//! unevenly spaced profile sets, files older than 4.3 (no `@2:Z scale`).

use super::bytes::{areal, bad, flip_rows, grid_points, latin1, length_unit, samples};
use super::bytes::{Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;
use std::collections::HashMap;

const FORMAT: &str = "di";
const FIRST_SECTIONS: [&str; 2] = ["\\*File list", "\\*EC File list"];
const IMAGE_SECTIONS: [&str; 5] = [
    "ciao image list",
    "afm image list",
    "stm image list",
    "ncafm image list",
    "image list",
];
const SCANNER_SECTIONS: [&str; 2] = ["scanner list", "microscope list"];
const SCAN_SECTIONS: [&str; 4] = ["ciao scan list", "afm list", "stm list", "nc afm list"];
/// From this version on, samples are 32-bit whatever `Bytes/pixel` says.
const VERSION_32BIT: u64 = 0x0920_0000;

type Section = HashMap<String, String>;

/// Whether the bytes start with a Nanoscope header's first section.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    FIRST_SECTIONS
        .iter()
        .any(|m| bytes.starts_with(m.as_bytes()))
}

/// Parses a whole Nanoscope file: every image section is a channel, in file order.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if bytes.starts_with(b"?*File list") {
        return Err(bad(
            FORMAT,
            "data stored as text are not supported, only binary data",
        ));
    }
    if !sniff(bytes) {
        return Err(bad(FORMAT, "the file does not start with `\\*File list`"));
    }
    let sections = parse_header(bytes)?;
    let merged = |names: &[&str]| -> Section {
        let mut out = Section::new();
        for (_, s) in sections.iter().filter(|(n, _)| names.contains(&n.as_str())) {
            out.extend(s.iter().map(|(k, v)| (k.clone(), v.clone())));
        }
        out
    };
    let file_list = merged(&["file list", "ec file list"]);
    let scanner = merged(&SCANNER_SECTIONS);
    let scan = merged(&SCAN_SECTIONS);
    refuse_unsupported(&sections, &file_list)?;
    let version = file_list
        .get("version")
        .and_then(|v| u64::from_str_radix(v.trim_start_matches("0x"), 16).ok())
        .unwrap_or(0);
    let context = Context {
        bytes,
        version,
        scanner: &scanner,
        scan: &scan,
    };
    let channels = sections
        .iter()
        .filter(|(n, _)| IMAGE_SECTIONS.contains(&n.as_str()))
        .map(|(_, s)| context.channel(s))
        .collect::<Result<Vec<_>>>()?;
    if channels.is_empty() {
        return Err(bad(FORMAT, "the header describes no image"));
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

/// The header's sections in order: lower-case name, lower-case keys → values.
fn parse_header(bytes: &[u8]) -> Result<Vec<(String, Section)>> {
    let mut sections: Vec<(String, Section)> = Vec::new();
    for raw in bytes.split(|&b| b == b'\n') {
        let line = latin1(raw);
        let line = line.trim_matches(|c: char| c.is_whitespace() || c == '\u{1a}');
        if line.eq_ignore_ascii_case("\\*File list end") {
            return Ok(sections);
        }
        if let Some(name) = line.strip_prefix("\\*") {
            sections.push((name.to_lowercase(), Section::new()));
        } else if let Some(entry) = line.strip_prefix('\\') {
            // Keys such as `@2:Z scale` hold colons: the separator is a colon and a blank.
            let (key, value) = entry
                .split_once(": ")
                .unwrap_or((entry.trim_end_matches(':'), ""));
            let Some((_, section)) = sections.last_mut() else {
                return Err(bad(FORMAT, "a header entry precedes the first section"));
            };
            section.insert(key.trim().to_lowercase(), value.trim().to_string());
        } else if !line.is_empty() {
            return Err(bad(
                FORMAT,
                format!("header line `{line}` does not start with `\\`"),
            ));
        }
    }
    Err(bad(FORMAT, "the header has no `\\*File list end` line"))
}

/// Force curves and unevenly spaced profiles have image sections without maps.
fn refuse_unsupported(sections: &[(String, Section)], file_list: &Section) -> Result<()> {
    let mode = sections
        .iter()
        .rev()
        .find_map(|(_, s)| s.get("operating mode"))
        .map(|m| m.as_str());
    let start = file_list.get("start context").map_or("", |s| s.as_str());
    if mode == Some("Force") || start == "FOL" {
        return Err(bad(FORMAT, "force curves are not supported, only images"));
    }
    if start.ends_with("VAR") && mode != Some("Force Volume") {
        return Err(bad(
            FORMAT,
            "unevenly spaced profiles are not supported, only images",
        ));
    }
    Ok(())
}

/// What every image section needs from the rest of the file.
struct Context<'a> {
    bytes: &'a [u8],
    version: u64,
    scanner: &'a Section,
    scan: &'a Section,
}

impl Context<'_> {
    /// One image section read into a channel.
    fn channel(&self, s: &Section) -> Result<Channel> {
        let int = |key: &str| -> Result<u64> {
            s.get(key)
                .and_then(|v| v.parse::<u64>().ok())
                .ok_or_else(|| bad(FORMAT, format!("`{key}` is missing or not an integer")))
        };
        let (mut nx, mut ny) = (int("samps/line")?, int("number of lines")?);
        let offset = int("data offset")?;
        let length = int("data length")?;
        let bpp = s.get("bytes/pixel").map_or(Ok(2), |_| int("bytes/pixel"))?;
        if bpp != 2 && bpp != 4 {
            return Err(bad(
                FORMAT,
                format!("{bpp} bytes per pixel (2 or 4 are known)"),
            ));
        }
        let points = grid_points(FORMAT, nx, ny)? as u64;
        let elsize = if self.version >= VERSION_32BIT && length >= points.saturating_mul(4) {
            4
        } else {
            bpp
        };
        let [mut sx, mut sy, xy_metres] = self.scan_size(s)?;
        // Some files give a wrong grid in the image section; the scan list's is then right.
        if let (Some(gx), Some(gy)) = (self.global("samps/line"), self.global("lines")) {
            let global = gx.saturating_mul(gy).saturating_mul(elsize);
            let own = points.saturating_mul(elsize);
            if own != length && (global == length || (own > length && length >= global)) {
                if !self.scan.contains_key("slow axis size") {
                    sx *= gx as f64 / nx as f64;
                    sy *= gy as f64 / ny as f64;
                }
                (nx, ny) = (gx, gy);
            } else if self.scan.contains_key("slow axis size") && nonsquare(s) && ny < gy {
                sy *= ny as f64 / gy as f64; // stopped early: the slow size is the full scan's
            }
        }
        let n = grid_points(FORMAT, nx, ny)?;
        if (n as u64).saturating_mul(elsize) > length {
            return Err(bad(
                FORMAT,
                format!("{nx} × {ny} samples do not fit in {length} bytes"),
            ));
        }
        let sample = if elsize == 2 {
            Sample::I16
        } else {
            Sample::I32
        };
        let offset = usize::try_from(offset).map_err(|_| bad(FORMAT, "offset too large"))?;
        let mut values = samples(FORMAT, self.bytes, offset, n, sample, Endian::Little)?;
        let (name, scale) = self.scale(s, bpp)?;
        values.iter_mut().for_each(|v| *v *= scale.factor);
        let mut map = areal(FORMAT, ny as usize, nx as usize, values)?;
        flip_rows(&mut map);
        Ok(Channel {
            name,
            heights: Heights::Areal(map),
            size: [Some(sx * xy_metres), Some(sy * xy_metres)],
            unit: scale.unit,
            is_height: scale.is_height,
        })
    }

    fn global(&self, key: &str) -> Option<u64> {
        self.scan.get(key).and_then(|v| v.parse().ok())
    }

    /// `[sx, sy, metres per unit]`: `Scan Size: 500 500 nm` (or `500 nm` for a square), the
    /// slow axis from `Slow Axis Size` of the scan list where newer files give it.
    fn scan_size(&self, s: &Section) -> Result<[f64; 3]> {
        let text = s
            .get("scan size")
            .ok_or_else(|| bad(FORMAT, "`Scan Size` is missing"))?;
        let (sx, sy, unit) = size_with_unit(text)?;
        let metres = length_unit(&unit)
            .map(|(_, f)| f)
            .ok_or_else(|| bad(FORMAT, format!("scan size unit `{unit}` is not a length")))?;
        let slow = self.scan.get("slow axis size").map(|v| size_with_unit(v));
        Ok(match slow {
            Some(Ok((slow, _, slow_unit))) => match length_unit(&slow_unit) {
                Some((_, f)) => [sx, slow * f / metres, metres],
                None => [sx, sy, metres],
            },
            _ => [sx, sy, metres],
        })
    }

    /// The channel's name and the factor from a sample to its value.
    fn scale(&self, s: &Section, bpp: u64) -> Result<(String, Scale)> {
        let name = ["@2:image data", "@3:image data", "@4:image data"]
            .iter()
            .find_map(|k| s.get(*k))
            .map(|v| {
                let v = Value::parse(v);
                v.soft
                    .unwrap_or_else(|| v.hard.trim_matches('"').to_string())
            })
            .or_else(|| s.get("image data").cloned())
            .unwrap_or_else(|| "Unknown".into());
        let z = s
            .get("@4:z scale")
            .or_else(|| s.get("@2:z scale"))
            .ok_or_else(|| bad(FORMAT, "no `@2:Z scale` entry (files before version 4.3)"))?;
        let z = Value::parse(z);
        let (hard, hard_unit) = number_and_unit(&z.hard)?;
        let per_lsb = hard / 256f64.powi(bpp as i32);
        let soft = z.soft.as_ref().and_then(|q| {
            let key = format!("@{}", q.to_lowercase());
            self.scanner.get(&key).or_else(|| self.scan.get(&key))
        });
        let Some(soft) = soft
            .map(|v| number_and_unit(&Value::parse(v).hard))
            .transpose()?
        else {
            return Ok((name, Scale::raw(per_lsb, hard_unit)));
        };
        let (soft, soft_unit) = soft;
        let Some((unit, per)) = soft_unit.split_once('/') else {
            return Ok((name, Scale::raw(per_lsb, hard_unit)));
        };
        let Some(ratio) = prefix_ratio(&hard_unit, per) else {
            return Err(bad(FORMAT, format!("hard unit `{hard_unit}` and soft unit `{soft_unit}` of channel `{name}` do not match")));
        };
        let factor = per_lsb * ratio * soft;
        Ok((
            name,
            match length_unit(unit) {
                Some((u, metres)) => Scale {
                    factor: factor * metres,
                    unit: Some(u.into()),
                    is_height: true,
                },
                None => Scale::raw(factor, unit.to_string()),
            },
        ))
    }
}

/// The factor from a sample to a channel's value.
struct Scale {
    factor: f64,
    unit: Option<String>,
    is_height: bool,
}

impl Scale {
    fn raw(factor: f64, unit: String) -> Self {
        let unit = Some(unit).filter(|u| !u.is_empty());
        Scale {
            factor,
            unit,
            is_height: false,
        }
    }
}

/// A `@` header value: `V [soft scale name] (hard scale per LSB) hard value unit`.
struct Value {
    soft: Option<String>,
    hard: String,
}

impl Value {
    fn parse(text: &str) -> Value {
        let mut rest = text.trim().get(1..).unwrap_or("").trim(); // the type letter
        let mut soft = None;
        if let Some(inner) = rest.strip_prefix('[') {
            if let Some((name, after)) = inner.split_once(']') {
                soft = Some(name.trim().to_string()).filter(|n| !n.is_empty());
                rest = after.trim();
            }
        }
        if rest.starts_with('(') {
            // The unit may itself hold parentheses, e.g. log(Arb): match them.
            let mut depth = 0i32;
            for (i, ch) in rest.char_indices() {
                depth += match ch {
                    '(' => 1,
                    ')' => -1,
                    _ => 0,
                };
                if depth == 0 {
                    rest = rest[i + 1..].trim();
                    break;
                }
            }
        }
        Value {
            soft,
            hard: rest.to_string(),
        }
    }
}

/// `2.910461 V` → (2.910461, `V`).
fn number_and_unit(text: &str) -> Result<(f64, String)> {
    let text = text.trim();
    let (number, unit) = text.split_once(char::is_whitespace).unwrap_or((text, ""));
    let x: f64 = number
        .parse()
        .map_err(|_| bad(FORMAT, format!("`{text}` is not a number with a unit")))?;
    Ok((x, unit.trim().to_string()))
}

/// `500 500 nm` → (500, 500, `nm`); `500 nm` → (500, 500, `nm`).
fn size_with_unit(text: &str) -> Result<(f64, f64, String)> {
    let (sx, rest) = number_and_unit(text)?;
    match number_and_unit(&rest) {
        Ok((sy, unit)) => Ok((sx, sy, unit)),
        Err(_) => Ok((sx, sx, rest)),
    }
}

/// How many `to` one `from` is, for units that differ only by an SI prefix (`mV` → `V`).
fn prefix_ratio(from: &str, to: &str) -> Option<f64> {
    if from == to {
        return Some(1.0);
    }
    let split = |u: &str| -> (f64, String) {
        let mut chars = u.chars();
        let p = match chars.next() {
            Some('p') => 1e-12,
            Some('n') => 1e-9,
            Some('u' | 'µ' | 'μ' | '~') => 1e-6,
            Some('m') => 1e-3,
            Some('k') => 1e3,
            _ => return (1.0, u.to_string()),
        };
        let base: String = chars.collect();
        if base.is_empty() {
            (1.0, u.to_string())
        } else {
            (p, base)
        }
    };
    let ((pf, bf), (pt, bt)) = (split(from), split(to));
    (bf == bt).then(|| pf / pt)
}

/// Whether an image section says its aspect ratio is not 1:1.
fn nonsquare(s: &Section) -> bool {
    let ratio = s
        .get("aspect ratio")
        .and_then(|a| a.split(':').next()?.trim().parse::<f64>().ok());
    matches!(ratio, Some(r) if r > 0.0 && r != 1.0)
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_matches, assert_robust, reference, transposed};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        let Some(r) = reference("di-1.di") else {
            return;
        };
        let reading = read(&r.bytes).unwrap();
        // Both readers reverse the stored lines; ours is then SurfaceTopography's [x, y]
        // array transposed.
        assert_matches(&reading, &r, &transposed(&r));
        let heights: Vec<bool> = reading.channels.iter().map(|c| c.is_height).collect();
        assert_eq!(heights, [true, true, false, false]);
        // The phase channel in degrees: 360° over the 16-bit range.
        assert_eq!(reading.channels[2].unit.as_deref(), Some("\u{ba}"));
    }

    #[test]
    fn the_height_scale_is_hard_times_soft() {
        let Some(r) = reference("di-1.di") else {
            return;
        };
        let reading = read(&r.bytes).unwrap();
        // Sample 1 of the first channel: 2.910461 V / 65536 × 20.82646 nm/V.
        let raw = samples(FORMAT, &r.bytes, 40960, 1, Sample::I16, Endian::Little).unwrap()[0];
        let Heights::Areal(h) = &reading.channels[0].heights else {
            panic!()
        };
        let want = raw * 2.910461 / 65536.0 * 20.82646e-9;
        assert!((h[[511, 0]] - want).abs() <= 1e-15 * want.abs());
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(r) = reference("di-1.di") else {
            return;
        };
        assert_robust(
            &r.bytes,
            sniff,
            read,
            40960,
            Some(4),
            Duration::from_millis(400),
        );
    }

    #[test]
    fn a_version_9_2_file_has_32_bit_samples() {
        let header = |offset: usize| {
            format!(
                "\\*File list\r\n\\Version: 0x09200000\r\n\\*Scanner list\r\n\
                 \\@Sens. Zsens: V 10 nm/V\r\n\\*Ciao scan list\r\n\\Samps/line: 2\r\n\
                 \\Lines: 1\r\n\\*Ciao image list\r\n\\Data offset: {offset:05}\r\n\
                 \\Data length: 8\r\n\\Bytes/pixel: 4\r\n\\Samps/line: 2\r\n\
                 \\Number of lines: 1\r\n\\Scan Size: 4 2 ~m\r\n\
                 \\@2:Image Data: S [ZSensor] \"Height Sensor\"\r\n\
                 \\@2:Z scale: V [Sens. Zsens] (0.0001 V/LSB) 4294967.296 V\r\n\
                 \\*File list end\r\n"
            )
        };
        let offset = header(0).len();
        let mut f = header(offset).into_bytes();
        for v in [100i32, -300] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        let reading = read(&f).unwrap();
        let c = &reading.channels[0];
        assert_eq!((c.name.as_str(), c.is_height), ("ZSensor", true));
        assert_eq!(c.size, [Some(4e-6), Some(2e-6)]);
        // 4294967.296 V / 256^4 = 1 mV per count, times 10 nm/V.
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        super::super::testkit::assert_close(h, &[1e-9, -3e-9]);
    }

    #[test]
    fn header_values_and_units() {
        let v = Value::parse("V [Sens. Zsens] (0.005035400 V/LSB) 2.910461 V");
        assert_eq!(
            (v.soft.as_deref(), v.hard.as_str()),
            (Some("Sens. Zsens"), "2.910461 V")
        );
        let v = Value::parse("V (0.0003662 log(Arb)/LSB) 1.5 log(Arb)");
        assert_eq!((v.soft, v.hard.as_str()), (None, "1.5 log(Arb)"));
        assert_eq!(prefix_ratio("mV", "V"), Some(1e-3));
        assert_eq!(prefix_ratio("V", "nm"), None);
        assert_eq!(size_with_unit("10 ~m").unwrap(), (10.0, 10.0, "~m".into()));
    }
}
