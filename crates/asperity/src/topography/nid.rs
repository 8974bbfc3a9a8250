//! Nanosurf **NID** files (`.nid`, easyScan 2 / FlexAFM).
//!
//! An INI-style text header (`[Section]` lines and `key=value` lines, CR LF), ended by the
//! two bytes `#!`, then the binary data of every channel, one block after the other in
//! the order of the header's group list. `[DataSet]` lists the groups (`GroupCount`, and
//! `Gr{g}-Ch{c}=DataSet-g:c` for each channel of group `g`, e.g. "Scan forward" and "Scan
//! backward"); each channel's own section gives `Points` (along x) × `Lines` (along y),
//! the lateral ranges `Dim0Range`, `Dim1Range` in `Dim0Unit`, `Dim1Unit`, and the value
//! scale: `SaveBits` (16 or 32), `SaveSign`, `SaveOrder` (`Intel`: little-endian) and
//! `Dim2Min`, `Dim2Range` in `Dim2Unit`. A sample `s` of `b` bits stands for
//! `Dim2Min + Dim2Range · (s − s_min) / 2^b` (`s_min` the smallest sample of its type).
//! Lines are stored from the bottom of the image up; rows are returned top down (`y`
//! counted from the last stored line), as the reference reader does.
//!
//! Channels whose `Dim2Unit` is a length are returned, in heights (metres), named
//! `"{group} ({Dim2Name})"`; channels of other quantities (deflection in N, friction in
//! V) are skipped, as SurfaceTopography 1.27.1 does. Facts from the shared file
//! `nid-1.nid` and its reference reading.

use super::bytes::{areal, bad, flip_rows, grid_points, length_unit, samples, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "nid";

/// The header starts with the `[DataSet]` section.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    let start = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    start.starts_with(b"[DataSet]") && find(bytes, b"\n#!").is_some()
}

fn find(bytes: &[u8], needle: &[u8]) -> Option<usize> {
    bytes.windows(needle.len()).position(|w| w == needle)
}

/// The header's sections: `(name, key=value pairs)` in order.
type Sections = Vec<(String, Vec<(String, String)>)>;

fn sections(text: &str) -> Sections {
    let mut out: Sections = Vec::new();
    for line in text.lines().map(str::trim) {
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            out.push((name.to_string(), Vec::new()));
        } else if let (Some((k, v)), Some(last)) = (line.split_once('='), out.last_mut()) {
            last.1.push((k.trim().to_string(), v.trim().to_string()));
        }
    }
    out
}

/// One channel's layout and scale, from its section.
struct Layout {
    name: String,
    points: u64,
    lines: u64,
    sample: Sample,
    endian: Endian,
    min: f64,
    range: f64,
    unit: String,
    size: [f64; 2],
}

fn layout(group: &str, keys: &[(String, String)]) -> Result<Layout> {
    let get = |key: &str| {
        keys.iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
            .ok_or_else(|| bad(FORMAT, format!("a channel of `{group}` has no `{key}`")))
    };
    let number = |key: &str| -> Result<f64> {
        let v = get(key)?;
        v.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| bad(FORMAT, format!("`{key}` = {v:?} is not a finite number")))
    };
    let count = |key: &str| -> Result<u64> {
        let v = get(key)?;
        v.parse::<u64>()
            .ok()
            .filter(|&n| n >= 1)
            .ok_or_else(|| bad(FORMAT, format!("`{key}` = {v:?} is not a point count")))
    };
    let signed = get("SaveSign")? == "Signed";
    let sample = match (get("SaveBits")?, signed) {
        ("16", true) => Sample::I16,
        ("16", false) => Sample::U16,
        ("32", true) => Sample::I32,
        (bits, _) => {
            return Err(bad(
                FORMAT,
                format!("{bits}-bit samples (signed: {signed}) are not supported"),
            ))
        }
    };
    if get("SaveMode")? != "Binary" {
        return Err(bad(
            FORMAT,
            "only binary data (SaveMode=Binary) are supported",
        ));
    }
    let endian = match get("SaveOrder")? {
        "Intel" => Endian::Little,
        _ => Endian::Big,
    };
    let lateral = |range: &str, unit: &str| -> Result<f64> {
        let factor = length_unit(get(unit)?).map_or(f64::NAN, |(_, f)| f);
        Ok(number(range)? * factor)
    };
    Ok(Layout {
        name: format!("{group} ({})", get("Dim2Name")?),
        points: count("Points")?,
        lines: count("Lines")?,
        sample,
        endian,
        min: number("Dim2Min")?,
        range: number("Dim2Range")?,
        unit: get("Dim2Unit")?.to_string(),
        size: [
            lateral("Dim0Range", "Dim0Unit")?,
            lateral("Dim1Range", "Dim1Unit")?,
        ],
    })
}

/// The channels' layouts in the order their data are stored (group by group).
fn layouts(sections: &Sections) -> Result<Vec<Layout>> {
    let section = |name: &str| sections.iter().find(|(n, _)| n == name).map(|(_, k)| k);
    let index = section("DataSet").ok_or_else(|| bad(FORMAT, "no [DataSet] section"))?;
    let value = |key: &str| {
        index
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    };
    let groups: usize = value("GroupCount")
        .and_then(|v| v.parse().ok())
        .filter(|&g| g <= 64)
        .ok_or_else(|| bad(FORMAT, "[DataSet] has no valid GroupCount"))?;
    let mut out = Vec::new();
    for g in 0..groups {
        let group = value(&format!("Gr{g}-Name")).unwrap_or("Group").to_string();
        let prefix = format!("Gr{g}-Ch");
        for (key, target) in index.iter().filter(|(k, _)| k.starts_with(&prefix)) {
            let keys = section(target)
                .ok_or_else(|| bad(FORMAT, format!("{key} names [{target}], which is missing")))?;
            out.push(layout(&group, keys)?);
        }
    }
    if out.is_empty() {
        return Err(bad(FORMAT, "the header lists no channel"));
    }
    Ok(out)
}

/// Reads a NID file (see the module docs).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "no [DataSet] header ended by #!"));
    }
    let end = find(bytes, b"\n#!").expect("sniffed") + 1;
    let text: String = bytes[..end].iter().map(|&b| b as char).collect();
    let mut offset = end + 2;
    let mut channels = Vec::new();
    for l in layouts(&sections(&text))? {
        let n = grid_points(FORMAT, l.points, l.lines)?;
        let block = n
            .checked_mul(l.sample.size())
            .ok_or_else(|| bad(FORMAT, format!("{} is too large", l.name)))?;
        let Some((_, metres)) = length_unit(&l.unit) else {
            // Not a height: skipped, but its block still lies in the file.
            offset = offset
                .checked_add(block)
                .filter(|&o| o <= bytes.len())
                .ok_or_else(|| {
                    bad(
                        FORMAT,
                        format!("truncated: the data of {} end past the file", l.name),
                    )
                })?;
            continue;
        };
        let raw = samples(FORMAT, bytes, offset, n, l.sample, l.endian)?;
        offset += block;
        let lowest = match l.sample {
            Sample::I16 => f64::from(i16::MIN),
            Sample::I32 => f64::from(i32::MIN),
            _ => 0.0,
        };
        let steps = 2f64.powi(8 * l.sample.size() as i32);
        let values = raw
            .into_iter()
            .map(|s| (l.min + l.range * (s - lowest) / steps) * metres)
            .collect();
        let mut heights = areal(FORMAT, l.lines as usize, l.points as usize, values)?;
        flip_rows(&mut heights);
        let size = l.size.map(|s| crate::is_positive_finite(s).then_some(s));
        channels.push(Channel {
            name: l.name,
            heights: Heights::Areal(heights),
            size,
            unit: length_unit(&l.unit).map(|(u, _)| u.to_string()),
            is_height: true,
        });
    }
    if channels.is_empty() {
        return Err(bad(FORMAT, "no channel holds heights (a length unit)"));
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
        // nid-1.nid: 2 groups × 4 channels of 256², i32; the 4 in metres are read.
        check_shared("topographies-2", "nid-1.nid", Default::default());
    }

    #[test]
    fn a_small_file_in_the_format_layout() {
        let header = "[DataSet]\r\nVersion=2\r\nGroupCount=1\r\nGr0-Name=Scan forward\r\n\
            Gr0-Ch0=DataSet-0:0\r\nGr0-Ch1=DataSet-0:1\r\n\r\n";
        let channel = |name: &str, unit: &str| {
            format!(
                "[DataSet-0:{name}]\r\nPoints=3\r\nLines=2\r\nDim0Range=3e-6\r\nDim0Unit=m\r\n\
                 Dim1Range=2e-6\r\nDim1Unit=m\r\nDim2Name=Z\r\nDim2Unit={unit}\r\n\
                 Dim2Range=4e-6\r\nDim2Min=-2e-6\r\nSaveMode=Binary\r\nSaveBits=16\r\n\
                 SaveSign=Signed\r\nSaveOrder=Intel\r\n\r\n"
            )
        };
        let text = format!("{header}{}{}", channel("0", "V"), channel("1", "m"));
        let volts = [0i16; 6];
        let metres = [i16::MIN, 0, 16384, -16384, 1, 2];
        let data: Vec<u8> = volts
            .iter()
            .chain(&metres)
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let f = [text.as_bytes(), b"#!", &data].concat();
        let r = read(&f).unwrap();
        assert_eq!(r.channels.len(), 1, "the channel in volts is skipped");
        let c = &r.channels[0];
        assert_eq!(c.name, "Scan forward (Z)");
        assert_eq!(c.size, [Some(3e-6), Some(2e-6)]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        // Stored bottom line first: the first stored line is the last row.
        assert_eq!(h.dim(), (2, 3));
        let close = |got: f64, want: f64| assert!((got - want).abs() < 1e-20, "{got} vs {want}");
        close(h[(1, 0)], -2e-6); // i16::MIN → Dim2Min
        close(h[(1, 1)], 0.0); // 0 → the middle of the range
        close(h[(1, 2)], 1e-6); // 16384 → three quarters
        close(h[(0, 0)], -1e-6); // the second stored line is the first row
                                 // A header that promises more data than the file holds is refused.
        let short = [text.as_bytes(), b"#!", &data[..10]].concat();
        assert!(read(&short).is_err());
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-2") else {
            return;
        };
        let bytes = std::fs::read(dir.join("nid-1.nid")).unwrap();
        assert_robust(
            &bytes,
            sniff,
            read,
            30_748,
            Some(9),
            Duration::from_millis(300),
        );
    }
}
