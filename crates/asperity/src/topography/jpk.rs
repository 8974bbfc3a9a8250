//! **JPK** (Bruker) AFM image scans (`.jpk`): a TIFF file ([`super::tiff`]) whose first
//! page is a thumbnail carrying the scan's global tags (`0x8042` GridULength and `0x8043`
//! GridVLength in metres) and whose further pages are one channel each: `0x8052` its name,
//! `0x8051` whether it is the retrace (then `retrace` is added to the name, inside its
//! parentheses if it ends with one), `0x8081` the name of its default slot. Slots are
//! blocks of tags of stride `0x30` from `0x8090`: `+0x00` the slot's name, `+0x12` its unit,
//! `+0x13` its scaling type, `+0x14` multiplier and `+0x15` offset: a value is
//! `raw · multiplier + offset` in the unit. The channels whose default slot is in a length
//! unit are read; the raster's first line is the bottom of the image unless `0x8045`
//! GridReflect is set, and rows are returned top down. Layout learnt from
//! SurfaceTopography's reader and Gwyddion's `jpkscan.c`; checked on the shared
//! `afmreader-sample_0.jpk`.
//!
//! **QI maps** (Quantitative Imaging): a `.jpk-qi-image` is such a TIFF (Gwyddion's
//! `jpkscan.c` and AFMReader read it as a `.jpk` image), detected by content like one; a
//! `.jpk-qi-data` file is a zip archive holding that image as `data-image.jpk-qi-image`
//! beside the force curves (`index/<n>/segments/...`, not read), read here through
//! [`zipped::member`](super::zipped::member). SurfaceTopography 1.27.1 reads neither; no
//! real QI file was at hand: the tests put the real `afmreader-sample_0.jpk` and a written
//! scan into that layout.

use std::collections::HashMap;

use super::bytes::{areal, bad, flip_rows, length_unit};
use super::tiff::{self, Page, Value};
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "jpk";
/// The QI image inside a `.jpk-qi-data` archive.
const QI_IMAGE: &str = "data-image.jpk-qi-image";
/// The largest QI image read from an archive.
const MAX_QI_IMAGE: u64 = 4 << 30;
const FIRST_SLOT: u16 = 0x8090;
const SLOT_STRIDE: u16 = 0x30;

/// A TIFF file whose first page carries JPK's grid size tags.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    tiff::sniff(bytes)
        && tiff::pages(FORMAT, bytes)
            .map(|(_, p)| p[0].tags.contains_key(&0x8042) && p[0].tags.contains_key(&0x8050))
            .unwrap_or(false)
}

fn text(tags: &HashMap<u16, Value>, tag: u16) -> Option<&str> {
    tags.get(&tag).and_then(Value::text)
}

/// The default slot's unit, multiplier and offset of a channel page.
fn slot(page: &Page) -> Result<Option<(&'static str, f64, f64, f64)>> {
    let Some(default) = text(&page.tags, 0x8081) else {
        return Ok(None);
    };
    let slots = page
        .tags
        .get(&0x8080)
        .and_then(Value::number)
        .unwrap_or(0.0)
        .clamp(0.0, 64.0) as u16;
    let base = (0..slots)
        .map(|k| FIRST_SLOT + k * SLOT_STRIDE)
        .find(|&b| text(&page.tags, b) == Some(default));
    let Some(base) = base else {
        return Err(bad(FORMAT, format!("no slot named {default:?}")));
    };
    let Some(unit) = text(&page.tags, base + 0x12).and_then(length_unit) else {
        return Ok(None);
    };
    if text(&page.tags, base + 0x13) != Some("LinearScaling") {
        return Err(bad(FORMAT, "a length channel without linear scaling"));
    }
    let number = |t| page.tags.get(&t).and_then(Value::number);
    let multiply = number(base + 0x14).ok_or_else(|| bad(FORMAT, "a slot without multiplier"))?;
    let offset = number(base + 0x15).unwrap_or(0.0);
    Ok(Some((unit.0, unit.1, multiply, offset)))
}

/// The channel's name: its fancy name, with `retrace` for a retrace channel.
fn channel_name(page: &Page, fancy: &str) -> String {
    let retrace = page
        .tags
        .get(&0x8051)
        .and_then(Value::number)
        .unwrap_or(0.0)
        != 0.0;
    match (retrace, fancy.strip_suffix(')')) {
        (false, _) => fancy.to_string(),
        (true, Some(open)) => format!("{open}, retrace)"),
        (true, None) => format!("{fancy} (retrace)"),
    }
}

/// Reads every channel of a JPK scan in a length unit.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    let (e, pages) = tiff::pages(FORMAT, bytes)?;
    let global = &pages[0].tags;
    let size = |t: u16| {
        global
            .get(&t)
            .and_then(Value::number)
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| {
                bad(
                    FORMAT,
                    format!("no scan size (tag {t:#x}) on the first page"),
                )
            })
    };
    let (u, v) = (size(0x8042)?, size(0x8043)?);
    let mut channels = Vec::new();
    for page in &pages {
        tiff::check_strips(FORMAT, bytes, page)?;
    }
    for page in &pages[1..] {
        let Some(fancy) = text(&page.tags, 0x8052) else {
            continue;
        };
        let Some((unit, per_unit, multiply, offset)) = slot(page)? else {
            continue;
        };
        let (rows, cols, raw) = tiff::raster(FORMAT, bytes, e, page)?;
        let heights = raw
            .into_iter()
            .map(|r| (r + offset / multiply) * multiply * per_unit)
            .collect();
        let mut h = areal(FORMAT, rows, cols, heights)?;
        if page
            .tags
            .get(&0x8045)
            .and_then(Value::number)
            .unwrap_or(0.0)
            == 0.0
        {
            flip_rows(&mut h);
        }
        channels.push(Channel {
            name: channel_name(page, fancy),
            heights: Heights::Areal(h),
            size: [Some(u), Some(v)],
            unit: Some(unit.to_string()),
            is_height: true,
        });
    }
    if channels.is_empty() {
        return Err(bad(FORMAT, "no channel in a length unit"));
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

/// A zip archive holding a QI image (`.jpk-qi-data`).
pub(crate) fn sniff_qi_data(bytes: &[u8]) -> bool {
    bytes.starts_with(b"PK\x03\x04")
        && zip::ZipArchive::new(std::io::Cursor::new(bytes))
            .map(|z| super::zipped::has(&z, QI_IMAGE))
            .unwrap_or(false)
}

/// Reads the QI image of a `.jpk-qi-data` archive as a JPK image scan.
pub(crate) fn read_qi_data(bytes: &[u8]) -> Result<Reading> {
    if !bytes.starts_with(b"PK\x03\x04") {
        return Err(bad(FORMAT, "a QI data file that is not a zip archive"));
    }
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(bytes))
        .map_err(|e| bad(FORMAT, format!("not a readable QI data archive ({e})")))?;
    let image = super::zipped::member(&mut archive, FORMAT, QI_IMAGE, MAX_QI_IMAGE)?;
    if !sniff(&image) {
        return Err(bad(
            FORMAT,
            format!("{QI_IMAGE} is not a JPK image (TIFF with the grid tags)"),
        ));
    }
    read(&image)
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_robust, assert_zip_sizes_robust, check_shared, set_dir};
    use super::*;
    use std::io::Write;
    use std::time::Duration;

    /// A `.jpk-qi-data` archive in the layout: a force-curve member and the QI image.
    fn qi_data(image: &[u8]) -> Vec<u8> {
        let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let deflated = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        zip.start_file("header.properties", deflated).unwrap();
        zip.write_all(b"type=quantitative-imaging-map\n").unwrap();
        zip.start_file("index/0/segments/0/channels/vDeflection.dat", deflated)
            .unwrap();
        zip.write_all(&[0, 0, 0, 1]).unwrap();
        zip.start_file(QI_IMAGE, deflated).unwrap();
        zip.write_all(image).unwrap();
        zip.finish().unwrap().into_inner()
    }

    #[test]
    fn a_qi_image_and_qi_data_read_as_the_image_scan() {
        let Some(dir) = set_dir("topographies-3") else {
            return;
        };
        let bytes = std::fs::read(dir.join("afmreader-sample_0.jpk")).unwrap();
        let direct = read(&bytes).unwrap();
        // A .jpk-qi-image is detected by content, its extension also names this reader.
        let path = std::path::Path::new("scan.jpk-qi-image");
        let (image, _) = super::super::detect_and_read(path, &bytes).unwrap();
        assert_eq!(image, direct);
        let data = qi_data(&bytes);
        assert!(sniff_qi_data(&data) && !sniff(&data));
        let path = std::path::Path::new("scan.jpk-qi-data");
        let (wrapped, _) = super::super::detect_and_read(path, &data).unwrap();
        assert_eq!(wrapped, direct);
        // An archive without the image, or whose image is no JPK scan: one line.
        let err = read_qi_data(&qi_data(b"II*\0 not a scan"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("not a JPK image") && err.lines().count() == 1,
            "{err}"
        );
    }

    #[test]
    fn reads_the_real_scan_to_the_reference() {
        // 6 channels of 256² i32 in metres (trace and retrace), a thumbnail page first.
        check_shared(
            "topographies-3",
            "afmreader-sample_0.jpk",
            Default::default(),
        );
    }

    /// A tag of the synthetic file.
    enum T {
        Long(u32),
        Double(f64),
        Ascii(&'static str),
    }

    /// A little-endian TIFF of `pages` (tags; `273` is filled with the page's raster
    /// offset) and their rasters.
    type PageSpec = (Vec<(u16, T)>, Vec<u8>);

    fn tiff_file(pages: Vec<PageSpec>) -> Vec<u8> {
        let ifd_len = |n: usize| 2 + 12 * (n + 1) + 4;
        let ifds: usize = pages.iter().map(|(t, _)| ifd_len(t.len())).sum();
        let mut data = Vec::new();
        let mut raster_at = Vec::new();
        for (_, r) in &pages {
            raster_at.push(8 + ifds + data.len());
            data.extend_from_slice(r);
        }
        let mut out = b"II*\0".to_vec();
        out.extend(8u32.to_le_bytes());
        let mut at = 8;
        for (k, (tags, raster)) in pages.iter().enumerate() {
            let n = tags.len() + 1;
            at += ifd_len(tags.len());
            out.extend((n as u16).to_le_bytes());
            let mut entry = |tag: u16, kind: u16, count: usize, bytes: Vec<u8>| {
                out.extend(tag.to_le_bytes());
                out.extend(kind.to_le_bytes());
                out.extend((count as u32).to_le_bytes());
                if bytes.len() <= 4 {
                    let mut field = bytes.clone();
                    field.resize(4, 0);
                    out.extend(field);
                } else {
                    out.extend(((8 + ifds + data.len()) as u32).to_le_bytes());
                    data.extend(bytes);
                }
            };
            entry(273, 4, 1, (raster_at[k] as u32).to_le_bytes().to_vec());
            for (tag, value) in tags {
                match value {
                    T::Long(v) => entry(*tag, 4, 1, v.to_le_bytes().to_vec()),
                    T::Double(v) => entry(*tag, 12, 1, v.to_le_bytes().to_vec()),
                    T::Ascii(s) => {
                        let b = [s.as_bytes(), b"\0"].concat();
                        entry(*tag, 2, b.len(), b)
                    }
                }
            }
            let next = if k + 1 < pages.len() { at } else { 0 };
            out.extend((next as u32).to_le_bytes());
            let _ = raster;
        }
        [out, data].concat()
    }

    #[test]
    fn a_small_scan_in_the_format_layout() {
        let thumbnail = vec![
            (256, T::Long(1)),
            (257, T::Long(1)),
            (258, T::Long(8)),
            (279, T::Long(1)),
            (0x8042, T::Double(3e-6)),
            (0x8043, T::Double(2e-6)),
            (0x8050, T::Ascii("thumbnail")),
        ];
        let raw: Vec<u8> = (0..6i32).flat_map(|v| v.to_le_bytes()).collect();
        let height = vec![
            (256, T::Long(3)),
            (257, T::Long(2)),
            (258, T::Long(32)),
            (279, T::Long(24)),
            (339, T::Long(2)),
            (0x8051, T::Long(1)),
            (0x8052, T::Ascii("Height (measured)")),
            (0x8080, T::Long(1)),
            (0x8081, T::Ascii("nominal")),
            (0x8090, T::Ascii("nominal")),
            (0x80A2, T::Ascii("nm")),
            (0x80A3, T::Ascii("LinearScaling")),
            (0x80A4, T::Double(2.0)),
            (0x80A5, T::Double(1.0)),
        ];
        let file = tiff_file(vec![(thumbnail, vec![7]), (height, raw)]);
        assert!(sniff(&file));
        // The same scan as a QI data archive: the same reading, and the archive's zip
        // sizes fuzzed.
        let data = qi_data(&file);
        assert_eq!(read_qi_data(&data).unwrap(), read(&file).unwrap());
        assert_robust(
            &data,
            sniff_qi_data,
            read_qi_data,
            data.len() - 1,
            Some(4),
            Duration::from_millis(300),
        );
        assert_zip_sizes_robust(&data, read_qi_data, Duration::from_millis(300));
        let r = read(&file).unwrap();
        let c = &r.channels[0];
        assert_eq!(c.name, "Height (measured, retrace)");
        assert_eq!(c.unit.as_deref(), Some("nm"));
        assert_eq!(c.size, [Some(3e-6), Some(2e-6)]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        // 2 raw + 1 nm; the first stored line is the bottom row.
        let want = [7e-9, 9e-9, 11e-9, 1e-9, 3e-9, 5e-9];
        super::super::testkit::assert_close(h.iter(), &want);
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-3") else {
            return;
        };
        let bytes = std::fs::read(dir.join("afmreader-sample_0.jpk")).unwrap();
        assert_robust(
            &bytes,
            sniff,
            read,
            16_384,
            Some(4),
            Duration::from_millis(400),
        );
    }
}
