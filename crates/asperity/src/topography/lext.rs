//! **Olympus LEXT** confocal microscope files (`.lext`, OLS4000 and later): a TIFF file
//! ([`super::tiff`]) of several pages. The first page's ImageDescription is an XML document
//! whose root is `TiffTagDescData`; its `HeightInfo` gives `HeightDataPerPixelX`, `…Y`
//! (picometres per pixel) and `HeightDataPerPixelZ` (picometres per count), and
//! `HeightDataUnitX/Y/Z` (which must agree). The page whose ImageDescription is `HEIGHT`
//! holds the heights as unsigned counts (rows along y, as stored). The first page's EXIF
//! directory (tag 34665) may hold in its DeviceSettingDescription (tag 41995) XML whose
//! `ImageCommonSettingsInfo` gives `MakerCalibrationValueX/Y/Z`: SurfaceTopography
//! multiplies the pixel sizes and the height per count by them, Gwyddion's `lextfile.c`
//! does not; we follow SurfaceTopography where they are present (factor 1 where absent).
//! A height is `count · HeightDataPerPixelZ · MakerCalibrationValueZ` pm, a side
//! `n · HeightDataPerPixel · MakerCalibrationValue` pm. No real file was at hand: the
//! tests write the layout.

use std::collections::HashMap;

use super::bytes::{bad, height_reading, Endian};
use super::tiff::{self, Page, Value};
use super::Reading;
use crate::Result;

const FORMAT: &str = "lext";
const PM: f64 = 1e-12;
const EXIF_IFD: u16 = 34665;
const DEVICE_SETTING: u16 = 41995;
const DESCRIPTION: u16 = 270;

/// A TIFF file whose first page's description is LEXT's XML.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    tiff::sniff(bytes)
        && tiff::pages(FORMAT, bytes)
            .map(|(_, p)| description(&p[0]).is_some_and(|d| d.contains("<TiffTagDescData")))
            .unwrap_or(false)
}

fn description(page: &Page) -> Option<&str> {
    page.tags.get(&DESCRIPTION).and_then(Value::text)
}

/// The texts of the elements under `section` (anywhere in the XML), by name.
fn fields(xml: &str, section: &str) -> Result<HashMap<String, String>> {
    let doc = roxmltree::Document::parse(xml).map_err(|e| bad(FORMAT, format!("XML: {e}")))?;
    Ok(doc
        .descendants()
        .filter(|n| n.has_tag_name(section))
        .flat_map(|n| n.children())
        .filter(|n| n.is_element())
        .filter_map(|n| {
            Some((
                n.tag_name().name().to_string(),
                n.text()?.trim().to_string(),
            ))
        })
        .collect())
}

fn number(map: &HashMap<String, String>, key: &str) -> Result<f64> {
    let text = map
        .get(key)
        .ok_or_else(|| bad(FORMAT, format!("no {key}")))?;
    text.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| bad(FORMAT, format!("{key} is {text:?}")))
}

/// `MakerCalibrationValueX/Y/Z` from the EXIF directory, each 1 where absent.
fn calibration(bytes: &[u8], e: Endian, first: &Page) -> Result<[f64; 3]> {
    let Some(offset) = first.tags.get(&EXIF_IFD).and_then(Value::number) else {
        return Ok([1.0; 3]);
    };
    let exif = tiff::page_at(FORMAT, bytes, e, offset as usize)?;
    let Some(&(at, len)) = exif.blocks.get(&DEVICE_SETTING) else {
        return Ok([1.0; 3]);
    };
    let raw = &bytes[at..at + len];
    let text = String::from_utf8_lossy(raw.split(|&b| b == 0).next().unwrap_or(&[]));
    if !text.contains("ImageCommonSettingsInfo") {
        return Ok([1.0; 3]);
    }
    let map = fields(&text, "ImageCommonSettingsInfo")?;
    let value = |axis: &str| match map.get(&format!("MakerCalibrationValue{axis}")) {
        None => Ok(1.0),
        Some(_) => number(&map, &format!("MakerCalibrationValue{axis}")),
    };
    Ok([value("X")?, value("Y")?, value("Z")?])
}

/// Parses a whole LEXT file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    let (e, pages) = tiff::pages(FORMAT, bytes)?;
    let xml = description(&pages[0])
        .filter(|d| d.contains("<TiffTagDescData"))
        .ok_or_else(|| bad(FORMAT, "the first page's description is not LEXT's XML"))?;
    let info = fields(xml, "HeightInfo")?;
    let units: Vec<Option<&String>> = ["X", "Y", "Z"]
        .iter()
        .map(|a| info.get(&format!("HeightDataUnit{a}")))
        .collect();
    if units.iter().any(|u| *u != units[2]) {
        return Err(bad(FORMAT, "the x, y and height units differ"));
    }
    let [cx, cy, cz] = calibration(bytes, e, &pages[0])?;
    let dx = number(&info, "HeightDataPerPixelX")? * cx * PM;
    let dy = number(&info, "HeightDataPerPixelY")? * cy * PM;
    let dz = number(&info, "HeightDataPerPixelZ")? * cz * PM;
    let page = pages
        .iter()
        .find(|p| description(p).is_some_and(|d| d.trim().eq_ignore_ascii_case("HEIGHT")))
        .ok_or_else(|| bad(FORMAT, "no page described as HEIGHT"))?;
    for p in &pages {
        tiff::check_strips(FORMAT, bytes, p)?;
    }
    let (rows, cols, values) = tiff::raster(FORMAT, bytes, e, page)?;
    let map = super::bytes::areal(
        FORMAT,
        rows,
        cols,
        values.into_iter().map(|v| v * dz).collect(),
    )?;
    Ok(height_reading(
        FORMAT,
        "Height",
        map,
        [cols as f64 * dx, rows as f64 * dy],
        "pm",
    ))
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_close, assert_robust};
    use super::super::Heights;
    use super::*;
    use std::time::Duration;

    /// A LEXT file in the format's own layout: page 0 a 1 × 1 byte image with the XML
    /// description and an EXIF directory (calibration 1.5 along x, 2 along z); page 1 the
    /// `HEIGHT` raster of u32 counts (3 × 2).
    fn write(counts: &[u32], exif: bool) -> Vec<u8> {
        let xml = "<?xml version=\"1.0\"?><TiffTagDescData version=\"1\"><HeightInfo>\
            <HeightDataPerPixelX>250000</HeightDataPerPixelX><HeightDataPerPixelY>500000</HeightDataPerPixelY>\
            <HeightDataPerPixelZ>10</HeightDataPerPixelZ><HeightDataUnitX>1</HeightDataUnitX>\
            <HeightDataUnitY>1</HeightDataUnitY><HeightDataUnitZ>1</HeightDataUnitZ></HeightInfo></TiffTagDescData>\0";
        let setting = "<?xml version=\"1.0\"?><ExifTagDescData><ImageCommonSettingsInfo>\
            <MakerCalibrationValueX>1.5</MakerCalibrationValueX><MakerCalibrationValueY>1</MakerCalibrationValueY>\
            <MakerCalibrationValueZ>2</MakerCalibrationValueZ></ImageCommonSettingsInfo></ExifTagDescData>";
        let mut blob: Vec<u8> = Vec::new(); // the blocks after the directories
        let base = 1024u32;
        let mut at = |b: &[u8]| {
            let o = base + blob.len() as u32;
            blob.extend_from_slice(b);
            o
        };
        let xml_at = at(xml.as_bytes());
        let set_at = at(setting.as_bytes());
        let pixel_at = at(&[7]);
        let name_at = at(b"HEIGHT\0");
        let height: Vec<u8> = counts.iter().flat_map(|c| c.to_le_bytes()).collect();
        let height_at = at(&height);
        let mut f = b"II*\0".to_vec();
        f.extend_from_slice(&8u32.to_le_bytes());
        let dir = |f: &mut Vec<u8>, entries: &[(u16, u16, u32, u32)], next: u32| {
            f.extend_from_slice(&(entries.len() as u16).to_le_bytes());
            for &(tag, kind, count, value) in entries {
                for b in [
                    &tag.to_le_bytes()[..],
                    &kind.to_le_bytes(),
                    &count.to_le_bytes(),
                    &value.to_le_bytes(),
                ] {
                    f.extend_from_slice(b);
                }
            }
            f.extend_from_slice(&next.to_le_bytes());
        };
        let mut first = vec![
            (256, 4, 1, 1),
            (257, 4, 1, 1),
            (DESCRIPTION, 2, xml.len() as u32, xml_at),
            (273, 4, 1, pixel_at),
            (279, 4, 1, 1),
        ];
        if exif {
            first.push((EXIF_IFD, 4, 1, 512));
        }
        dir(&mut f, &first, 256);
        f.resize(256, 0);
        dir(
            &mut f,
            &[
                (256, 4, 1, 3),
                (257, 4, 1, 2),
                (258, 3, 1, 32),
                (DESCRIPTION, 2, 7, name_at),
                (273, 4, 1, height_at),
                (279, 4, 1, height.len() as u32),
            ],
            0,
        );
        f.resize(512, 0);
        dir(
            &mut f,
            &[(DEVICE_SETTING, 7, setting.len() as u32, set_at)],
            0,
        );
        f.resize(base as usize, 0);
        f.extend_from_slice(&blob);
        f
    }

    #[test]
    fn a_written_file_reads_back_with_and_without_calibration() {
        let counts = [0, 1, 2, 3, 4, 4_000_000_000];
        for (exif, cal) in [(true, [1.5, 1.0, 2.0]), (false, [1.0; 3])] {
            let f = write(&counts, exif);
            assert!(sniff(&f));
            let r = read(&f).unwrap();
            let c = &r.channels[0];
            assert_close(
                c.size.iter().flatten(),
                &[3.0 * 0.25e-6 * cal[0], 2.0 * 0.5e-6 * cal[1]],
            );
            let Heights::Areal(h) = &c.heights else {
                panic!()
            };
            assert_eq!(h.dim(), (2, 3));
            let want: Vec<f64> = counts
                .iter()
                .map(|&k| k as f64 * 10.0 * cal[2] * 1e-12)
                .collect();
            assert_close(h.iter(), &want);
        }
    }

    #[test]
    fn a_truncated_or_corrupt_file_is_refused() {
        let f = write(&[0, 1, 2, 3, 4, 5], true);
        assert_robust(
            &f,
            sniff,
            read,
            f.len() - 1,
            Some(4),
            Duration::from_millis(300),
        );
    }
}
