//! **Mitutoyo SurfTest** profiles exported as Excel workbooks (`.xlsx`).
//!
//! An Office Open XML workbook is a zip archive: `xl/workbook.xml` lists the sheets by name
//! and relationship id, `xl/_rels/workbook.xml.rels` maps an id to the sheet's part,
//! `xl/sharedStrings.xml` holds the texts that cells of type `s` index, and a sheet's
//! `sheetData` holds rows of cells `<c r="E12" t="…"><v>…</v></c>`. A SurfTest export has a
//! sheet `DATA` whose columns E and F hold the positions and heights of the profile (the
//! first position is one step, not zero: the length is the last position), column A the
//! roughness parameters (`Ra 0.018 µm`, whose unit is the heights'), and a sheet
//! `Certificate` whose cell E48 holds the cut-off (`0.08mm`, whose unit is the
//! positions'). Layout facts from SurfaceTopography's reader and the shared mock file.
//!
//! Every member is read through [`member`](super::zipped::member), which refuses a
//! declared size past a cap or past what its compressed bytes can inflate to, and stops
//! reading one byte past the declared size: a zip bomb costs neither memory nor time.

use std::collections::HashMap;
use std::io::Cursor;

use ndarray::Array1;
use zip::ZipArchive;

use super::bytes::{bad, length_unit};
use super::zipped::member;
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "xlsx";
const ZIP_MAGIC: &[u8] = b"PK\x03\x04";
/// The largest XML part read, in bytes.
const MAX_PART: u64 = 256 << 20;

/// A zip archive with an `xl/workbook.xml`.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(ZIP_MAGIC)
        && ZipArchive::new(Cursor::new(bytes))
            .map(|mut z| z.by_name("xl/workbook.xml").is_ok())
            .unwrap_or(false)
}

fn part(archive: &mut ZipArchive<Cursor<&[u8]>>, name: &str) -> Result<String> {
    String::from_utf8(member(archive, FORMAT, name, MAX_PART)?)
        .map_err(|_| bad(FORMAT, format!("{name} is not UTF-8")))
}

fn parse<'a>(text: &'a str, what: &str) -> Result<roxmltree::Document<'a>> {
    roxmltree::Document::parse(text).map_err(|e| bad(FORMAT, format!("{what}: {e}")))
}

/// The part name of the sheet called `sheet`.
fn sheet_part(archive: &mut ZipArchive<Cursor<&[u8]>>, sheet: &str) -> Result<String> {
    let workbook = part(archive, "xl/workbook.xml")?;
    let doc = parse(&workbook, "xl/workbook.xml")?;
    let id = doc
        .descendants()
        .find(|n| n.has_tag_name("sheet") && n.attribute("name") == Some(sheet))
        .and_then(|n| {
            n.attributes()
                .find(|a| a.name() == "id")
                .map(|a| a.value().to_string())
        })
        .ok_or_else(|| {
            bad(
                FORMAT,
                format!("no sheet {sheet:?}: not a Mitutoyo SurfTest export"),
            )
        })?;
    let rels = part(archive, "xl/_rels/workbook.xml.rels")?;
    let doc = parse(&rels, "xl/_rels/workbook.xml.rels")?;
    let target = doc
        .descendants()
        .find(|n| n.has_tag_name("Relationship") && n.attribute("Id") == Some(id.as_str()))
        .and_then(|n| n.attribute("Target"))
        .ok_or_else(|| bad(FORMAT, format!("sheet {sheet:?} has no part")))?;
    Ok(match target.strip_prefix('/') {
        Some(absolute) => absolute.to_string(),
        None => format!("xl/{target}"),
    })
}

/// The shared strings (empty where the workbook has none).
fn shared_strings(archive: &mut ZipArchive<Cursor<&[u8]>>) -> Result<Vec<String>> {
    if archive.by_name("xl/sharedStrings.xml").is_err() {
        return Ok(Vec::new());
    }
    let text = part(archive, "xl/sharedStrings.xml")?;
    let doc = parse(&text, "xl/sharedStrings.xml")?;
    Ok(doc
        .root_element()
        .children()
        .filter(|n| n.has_tag_name("si"))
        .map(|si| {
            si.descendants()
                .filter(|t| t.has_tag_name("t"))
                .filter_map(|t| t.text())
                .collect()
        })
        .collect())
}

/// A cell's value: a number or a text.
#[derive(Debug, Clone, PartialEq)]
enum Cell {
    Number(f64),
    Text(String),
}

/// The cells of a sheet by (column letters, row number).
fn cells(text: &str, strings: &[String]) -> Result<HashMap<(String, u32), Cell>> {
    let doc = parse(text, "a sheet")?;
    let mut out = HashMap::new();
    for c in doc.descendants().filter(|n| n.has_tag_name("c")) {
        let Some(reference) = c.attribute("r") else {
            continue;
        };
        let split = reference
            .find(|ch: char| ch.is_ascii_digit())
            .unwrap_or(reference.len());
        let (col, row) = reference.split_at(split);
        let row: u32 = row
            .parse()
            .map_err(|_| bad(FORMAT, format!("cell reference {reference:?}")))?;
        let value = c
            .children()
            .find(|n| n.has_tag_name("v"))
            .and_then(|v| v.text());
        let cell = match (c.attribute("t"), value) {
            (Some("s"), Some(v)) => {
                let i: usize = v
                    .trim()
                    .parse()
                    .map_err(|_| bad(FORMAT, format!("cell {reference}: string index {v:?}")))?;
                let s = strings.get(i).ok_or_else(|| {
                    bad(FORMAT, format!("cell {reference}: no shared string {i}"))
                })?;
                Cell::Text(s.clone())
            }
            (Some("inlineStr"), _) => Cell::Text(
                c.descendants()
                    .filter(|t| t.has_tag_name("t"))
                    .filter_map(|t| t.text())
                    .collect(),
            ),
            (Some("str" | "e"), Some(v)) => Cell::Text(v.to_string()),
            (_, Some(v)) => Cell::Number(
                v.trim()
                    .parse()
                    .map_err(|_| bad(FORMAT, format!("cell {reference}: {v:?} is no number")))?,
            ),
            (_, None) => continue,
        };
        out.insert((col.to_string(), row), cell);
    }
    Ok(out)
}

/// The numbers of a column, in row order.
fn column(sheet: &HashMap<(String, u32), Cell>, col: &str) -> Result<Vec<f64>> {
    let mut rows: Vec<(u32, f64)> = Vec::new();
    for ((c, row), cell) in sheet {
        if c == col {
            match cell {
                Cell::Number(v) => rows.push((*row, *v)),
                Cell::Text(t) => {
                    return Err(bad(
                        FORMAT,
                        format!("cell {col}{row} of DATA holds {t:?}, not a number"),
                    ))
                }
            }
        }
    }
    rows.sort_by_key(|r| r.0);
    Ok(rows.into_iter().map(|r| r.1).collect())
}

/// The unit of a text `number unit` (`0.08mm`, `Ra 0.018 µm`): the last word after the
/// number.
fn unit_after_number(text: &str) -> Option<(&'static str, f64)> {
    let start = text.find(|c: char| c.is_ascii_digit() || c == '.')?;
    let rest = text[start..].trim_start_matches(|c: char| c.is_ascii_digit() || c == '.');
    length_unit(rest.split_whitespace().next()?)
}

/// Reads the profile of a Mitutoyo SurfTest workbook.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !bytes.starts_with(ZIP_MAGIC) {
        return Err(bad(FORMAT, "not a zip archive (no PK signature)"));
    }
    let mut archive = ZipArchive::new(Cursor::new(bytes))
        .map_err(|e| bad(FORMAT, format!("not a readable zip archive ({e})")))?;
    let strings = shared_strings(&mut archive)?;
    let data_part = sheet_part(&mut archive, "DATA")?;
    let data = cells(&part(&mut archive, &data_part)?, &strings)?;
    let certificate_part = sheet_part(&mut archive, "Certificate")?;
    let certificate = cells(&part(&mut archive, &certificate_part)?, &strings)?;
    let x_unit = match certificate.get(&("E".to_string(), 48)) {
        Some(Cell::Text(t)) => unit_after_number(t),
        _ => None,
    }
    .ok_or_else(|| bad(FORMAT, "no cut-off with a length unit in Certificate!E48"))?;
    let z_unit = match data.get(&("A".to_string(), 1)) {
        Some(Cell::Text(t)) => unit_after_number(t)
            .ok_or_else(|| bad(FORMAT, format!("DATA!A1 {t:?} has no length unit")))?,
        _ => x_unit,
    };
    let (x, z) = (column(&data, "E")?, column(&data, "F")?);
    profile(&x, &z, x_unit.1 / z_unit.1, z_unit)
}

/// The channel of positions `x` (times `to_z` in the heights' unit) and heights `z`.
fn profile(x: &[f64], z: &[f64], to_z: f64, unit: (&'static str, f64)) -> Result<Reading> {
    if x.len() != z.len() || x.len() < 2 {
        return Err(bad(
            FORMAT,
            format!("{} positions and {} heights in DATA", x.len(), z.len()),
        ));
    }
    let x: Vec<f64> = x.iter().map(|v| v * to_z).collect();
    let step = x[1] - x[0];
    let uniform = x
        .windows(2)
        .all(|w| ((w[1] - w[0]) - step).abs() <= 1e-8 + 1e-5 * step.abs());
    if !uniform || step.is_nan() || step <= 0.0 {
        return Err(bad(
            FORMAT,
            "the positions are not uniformly spaced and increasing (export a CSV profile instead)",
        ));
    }
    let length = x.iter().copied().fold(f64::MIN, f64::max);
    Ok(Reading {
        format: "mitutoyo",
        channels: vec![Channel {
            name: "Default".into(),
            heights: Heights::Profile(Array1::from_iter(z.iter().map(|v| v * unit.1))),
            size: [Some(length * unit.1), None],
            unit: Some(unit.0.to_string()),
            is_height: true,
        }],
    })
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{
        assert_close, assert_robust, assert_zip_sizes_robust, check_shared, set_dir,
    };
    use super::*;
    use std::io::Write;
    use std::time::Duration;

    #[test]
    fn reads_the_mock_export_to_the_reference() {
        // 960 points at 0.5 µm (positions in mm, heights in µm).
        check_shared("topographies-3", "mitutoyo_mock.xlsx", Default::default());
    }

    /// A workbook whose sheets hold `data` and `certificate` as sheet XML.
    fn workbook(data: &str, certificate: &str) -> Vec<u8> {
        let mut z = zip::ZipWriter::new(Cursor::new(Vec::new()));
        let options = zip::write::SimpleFileOptions::default();
        let parts = [
            (
                "xl/workbook.xml",
                r#"<workbook xmlns:r="r"><sheets><sheet name="Certificate" r:id="rId1"/><sheet name="DATA" r:id="rId2"/></sheets></workbook>"#.to_string(),
            ),
            (
                "xl/_rels/workbook.xml.rels",
                r#"<Relationships><Relationship Id="rId1" Target="worksheets/sheet1.xml"/><Relationship Id="rId2" Target="worksheets/sheet2.xml"/></Relationships>"#.to_string(),
            ),
            ("xl/sharedStrings.xml", "<sst><si><t>0.8 mm</t></si><si><t>Ra 1.5 nm</t></si></sst>".to_string()),
            ("xl/worksheets/sheet1.xml", certificate.to_string()),
            ("xl/worksheets/sheet2.xml", data.to_string()),
        ];
        for (name, text) in parts {
            z.start_file(name, options).unwrap();
            z.write_all(text.as_bytes()).unwrap();
        }
        z.finish().unwrap().into_inner()
    }

    fn data_sheet() -> String {
        let rows: String = (1..=4)
            .map(|i| {
                let a = if i == 1 {
                    r#"<c r="A1" t="s"><v>1</v></c>"#
                } else {
                    ""
                };
                format!(
                    r#"<row r="{i}">{a}<c r="E{i}"><v>{}</v></c><c r="F{i}"><v>{}</v></c></row>"#,
                    f64::from(i) * 0.002,
                    f64::from(i) - 2.0
                )
            })
            .collect();
        format!("<worksheet><sheetData>{rows}</sheetData></worksheet>")
    }

    const CERTIFICATE: &str = r#"<worksheet><sheetData><row r="48"><c r="E48" t="s"><v>0</v></c></row></sheetData></worksheet>"#;

    #[test]
    fn a_small_workbook_in_the_export_layout() {
        let r = read(&workbook(&data_sheet(), CERTIFICATE)).unwrap();
        let c = &r.channels[0];
        assert_eq!(c.unit.as_deref(), Some("nm"));
        // Positions 2, 4, 6, 8 µm: the length is the last, 8 µm; heights in nm.
        assert_close(&[c.size[0].unwrap()], &[8e-6]);
        let Heights::Profile(h) = &c.heights else {
            panic!()
        };
        assert_close(h.iter(), &[-1e-9, 0.0, 1e-9, 2e-9]);
        // Non-uniform positions are refused, not read as uniform.
        let skewed = data_sheet().replace("<v>0.006</v>", "<v>0.0065</v>");
        assert!(read(&workbook(&skewed, CERTIFICATE)).is_err());
    }

    /// Rewrites the uncompressed size of every member in the local and central headers.
    fn declare_size(zip: &mut [u8], size: u32) {
        for i in 0..zip.len().saturating_sub(30) {
            if zip[i..].starts_with(b"PK\x03\x04") {
                zip[i + 22..i + 26].copy_from_slice(&size.to_le_bytes());
            }
            if zip[i..].starts_with(b"PK\x01\x02") {
                zip[i + 24..i + 28].copy_from_slice(&size.to_le_bytes());
            }
        }
    }

    #[test]
    fn zip_bombs_are_refused_without_allocating() {
        // A member declaring 4 GB from a few hundred compressed bytes.
        let mut declared = workbook(&data_sheet(), CERTIFICATE);
        declare_size(&mut declared, u32::MAX - 1);
        let err = read(&declared).unwrap_err().to_string();
        assert!(err.contains("declares"), "{err}");
        // A member declaring less than it inflates to: reading stops one byte past the
        // declared size.
        let big = format!(
            "<worksheet><sheetData>{}</sheetData></worksheet>",
            "<row r=\"9\"></row>".repeat(200_000)
        );
        let mut under = workbook(&big, CERTIFICATE);
        declare_size(&mut under, 1000);
        let err = read(&under).unwrap_err().to_string();
        assert!(err.lines().count() == 1, "{err}");
        // And the bounded read itself: a member of 3.2 MB of zeros declared as such is
        // read, with a cap below its size it is refused.
        let mut z = zip::ZipWriter::new(Cursor::new(Vec::new()));
        z.start_file("zeros", zip::write::SimpleFileOptions::default())
            .unwrap();
        z.write_all(&vec![0u8; 3_200_000]).unwrap();
        let bytes = z.finish().unwrap().into_inner();
        let mut archive = ZipArchive::new(Cursor::new(&bytes[..])).unwrap();
        assert_eq!(
            member(&mut archive, FORMAT, "zeros", 4 << 20)
                .unwrap()
                .len(),
            3_200_000
        );
        assert!(member(&mut archive, FORMAT, "zeros", 1 << 20).is_err());
        // Every member declaring 4 GiB, and sizes altered at random.
        let book = workbook(&data_sheet(), CERTIFICATE);
        assert_zip_sizes_robust(&book, read, Duration::from_millis(300));
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-3") else {
            return;
        };
        let bytes = std::fs::read(dir.join("mitutoyo_mock.xlsx")).unwrap();
        let n = bytes.len() - 1;
        assert_robust(&bytes, sniff, read, n, Some(4), Duration::from_millis(400));
    }
}
