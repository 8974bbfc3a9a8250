//! **Keyence** VK laser confocal microscope files: `.vk4` (and the older `.vk3`), and the
//! `.vk6`/`.vk7` containers, which are a short header (`VK6`/`VK7`) followed by a zip
//! archive whose member `Vk4File` is a whole VK4 file.
//!
//! VK3/VK4 layout (little-endian u32 throughout; learnt from Gwyddion's `keyence.c` and
//! SurfaceTopography's `VK.py`): `VK4_` (or `VK3_`), 4 bytes of DLL version, 4 zero bytes;
//! the offset table (VK4: 18 u32, VK3: 17): setting, colour peak, colour light, light
//! 0–2, height 0–2, four thumbnails, assembly, line measurement, line thickness, strings
//! (VK4: one reserved more); then the measurement conditions, whose first u32 is their
//! size (≥ 304) and whose fields 42, 43, 44 are the x and y pixel sizes and the height
//! per count, all in picometres. Each image the table points to (0 = absent) is `width,
//! height, bit depth (8, 16, 32), compression, byte size (= width · height · depth/8),
//! palette min, palette max`, a 768-byte palette and the unsigned samples, rows along y.
//! Height images become channels `Height 0`–`Height 2` (count × height per count), light
//! images non-height channels `Intensity 0`–`2` (count / 2^depth), in Gwyddion's order
//! and names. Both peers give the sizes as `(n − 1)` times the pixel size (Gwyddion:
//! "from comparison with original software"); we follow them. No undefined points.

use std::io::Cursor as IoCursor;

use super::bytes::{areal, areal_channel, bad, grid_points, samples, Cursor, Endian, Sample};
use super::{Channel, Reading};
use crate::Result;
use zip::ZipArchive;

const FORMAT: &str = "vk";
const PM: f64 = 1e-12;
/// The largest `Vk4File` member read from a VK6/VK7 container.
const MAX_MEMBER: u64 = 4 << 30;

/// Whether the bytes start with a VK3/VK4 signature (and the zero file type) or a VK6/VK7
/// container's.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    ((bytes.starts_with(b"VK4_") || bytes.starts_with(b"VK3_"))
        && bytes.get(8..12) == Some(&[0, 0, 0, 0]))
        || bytes.starts_with(b"VK6")
        || bytes.starts_with(b"VK7")
}

/// Parses a whole VK3, VK4, VK6 or VK7 file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if bytes.starts_with(b"VK6") || bytes.starts_with(b"VK7") {
        return read_container(bytes);
    }
    let table_len = if bytes.starts_with(b"VK4_") {
        18
    } else if bytes.starts_with(b"VK3_") {
        17
    } else {
        return Err(bad(FORMAT, "no VK3, VK4, VK6 or VK7 signature"));
    };
    if bytes.get(8..12) != Some(&[0, 0, 0, 0]) {
        return Err(bad(
            FORMAT,
            "the file type is not 0 (assembled files are not supported)",
        ));
    }
    let le = Endian::Little;
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(12)?;
    let table: Vec<u32> = (0..table_len).map(|_| c.u32(le)).collect::<Result<_>>()?;
    let conditions = c.pos();
    let size = c.u32(le)? as usize;
    if size < 304 || conditions.saturating_add(size) > bytes.len() {
        return Err(bad(
            FORMAT,
            format!("measurement conditions of {size} bytes"),
        ));
    }
    c.seek(conditions + 4 * 42)?;
    let (dx, dy, dz) = (c.u32(le)?, c.u32(le)?, c.u32(le)?);
    let mut channels = Vec::new();
    for (k, &offset) in table[3..6].iter().enumerate() {
        if let Some((mut map, depth)) = image(bytes, offset)? {
            map.mapv_inplace(|v| v / f64::powi(2.0, depth as i32));
            channels.push(channel(format!("Intensity {k}"), map, [dx, dy], None));
        }
    }
    for (k, &offset) in table[6..9].iter().enumerate() {
        if let Some((mut map, _)) = image(bytes, offset)? {
            map.mapv_inplace(|v| v * f64::from(dz) * PM);
            channels.push(channel(format!("Height {k}"), map, [dx, dy], Some("pm")));
        }
    }
    if !channels.iter().any(|c| c.is_height) {
        return Err(bad(FORMAT, "the file holds no height image"));
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

fn channel(name: String, map: ndarray::Array2<f64>, step: [u32; 2], unit: Option<&str>) -> Channel {
    let (rows, cols) = map.dim();
    // (n − 1) · step, as both peers; a zero step gives no size (asked for).
    let side = |n: usize, s: u32| (s > 0 && n > 1).then(|| (n - 1) as f64 * f64::from(s) * PM);
    let size = [side(cols, step[0]), side(rows, step[1])];
    areal_channel(name, map, size, unit, unit.is_some())
}

/// The image at `offset` (0: none) as counts, with its bit depth.
fn image(bytes: &[u8], offset: u32) -> Result<Option<(ndarray::Array2<f64>, u32)>> {
    if offset == 0 {
        return Ok(None);
    }
    let le = Endian::Little;
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(offset as usize)?;
    let (w, h, depth) = (c.u32(le)?, c.u32(le)?, c.u32(le)?);
    let (compression, byte_size) = (c.u32(le)?, c.u32(le)?);
    c.skip(8 + 768)?;
    let sample = match depth {
        8 => Sample::U8,
        16 => Sample::U16,
        32 => Sample::U32,
        d => return Err(bad(FORMAT, format!("an image of {d} bits per sample"))),
    };
    if compression != 0 {
        return Err(bad(FORMAT, "compressed images are not supported"));
    }
    let n = grid_points(FORMAT, w.into(), h.into())?;
    if n as u64 * u64::from(depth / 8) != u64::from(byte_size) {
        return Err(bad(
            FORMAT,
            format!("an image of {w} × {h} × {depth} bits declares {byte_size} bytes"),
        ));
    }
    let values = samples(FORMAT, bytes, c.pos(), n, sample, le)?;
    Ok(Some((
        areal(FORMAT, h as usize, w as usize, values)?,
        depth,
    )))
}

/// A VK6/VK7 container: the VK4 file inside its zip archive.
fn read_container(bytes: &[u8]) -> Result<Reading> {
    // The archive follows a header of its own; reading from the first local file header
    // makes the archive's offsets relative to it whatever the header's length.
    let start = bytes
        .windows(4)
        .position(|w| w == b"PK\x03\x04")
        .ok_or_else(|| bad(FORMAT, "a VK6/VK7 file without its zip archive"))?;
    let mut archive = ZipArchive::new(IoCursor::new(&bytes[start..]))
        .map_err(|e| bad(FORMAT, format!("the VK6/VK7 archive: {e}")))?;
    let inner = inner_vk4(&mut archive)?;
    read(&inner)
}

/// The bytes before the first image: signature, version, file type and the offset table.
const VK4_HEAD: u64 = 12 + 4 * 18;
/// An image's header: width, height, depth, compression, byte size, palette range, and
/// the 768-byte palette before the samples.
const IMAGE_HEAD: u64 = 7 * 4 + 768;

/// The container's `Vk4File`, its VK4 header checked as it is inflated, before anything
/// the size of the member is allocated: the signature, and every image's dimensions,
/// which must fit (`offset + header + width · height · depth/8`) in the bytes the member
/// declares, themselves within what the container's compressed bytes can inflate to.
fn inner_vk4(archive: &mut ZipArchive<IoCursor<&[u8]>>) -> Result<Vec<u8>> {
    use std::io::Read;
    const NAME: &str = "Vk4File";
    let file = archive
        .by_name(NAME)
        .map_err(|e| bad(FORMAT, format!("{NAME}: {e}")))?;
    let declared = super::zipped::declared_size(&file, FORMAT, NAME, MAX_MEMBER)?;
    let mut reader = file.take(declared + 1);
    let mut data = Vec::new();
    let mut upto = |data: &mut Vec<u8>, end: u64| -> Result<()> {
        let want = end.min(declared).saturating_sub(data.len() as u64);
        (&mut reader)
            .take(want)
            .read_to_end(data)
            .map_err(|e| bad(FORMAT, format!("{NAME}: {e}")))?;
        match data.len() as u64 >= end {
            true => Ok(()),
            false => Err(bad(
                FORMAT,
                format!(
                    "{NAME} ends at byte {} of the {declared} it declares",
                    data.len()
                ),
            )),
        }
    };
    upto(&mut data, 4)?;
    if !data.starts_with(b"VK4_") {
        return Err(bad(FORMAT, "the archive's Vk4File is not a VK4 file"));
    }
    upto(&mut data, VK4_HEAD)?;
    let at = |data: &[u8], k: usize| u32::from_le_bytes(data[k..k + 4].try_into().expect("4"));
    // The light and height images (table entries 3–8), in the order of their offsets.
    let mut images: Vec<u64> = (3..9)
        .map(|k| u64::from(at(&data, 12 + 4 * k)))
        .filter(|&o| o != 0)
        .collect();
    images.sort_unstable();
    for offset in images {
        if offset + IMAGE_HEAD > declared {
            return Err(bad(
                FORMAT,
                format!("an image at byte {offset}, past the {declared} bytes of {NAME}"),
            ));
        }
        upto(&mut data, offset + IMAGE_HEAD)?;
        let o = offset as usize;
        let (w, h, depth) = (at(&data, o), at(&data, o + 4), at(&data, o + 8));
        let need = u64::from(w) * u64::from(h) * u64::from(depth / 8);
        if offset + IMAGE_HEAD + need > declared {
            return Err(bad(
                FORMAT,
                format!(
                    "an image of {w} × {h} × {depth} bits at byte {offset} does not fit in \
                     the {declared} bytes of {NAME}"
                ),
            ));
        }
    }
    crate::memory::ensure_fits(&format!("reading {NAME} of a vk file"), Some(declared))?;
    data.reserve_exact((declared as usize).saturating_sub(data.len()));
    upto(&mut data, declared)?;
    // One byte past the declared size means the member inflates to more than it says.
    if reader
        .read(&mut [0u8; 1])
        .map_err(|e| bad(FORMAT, format!("{NAME}: {e}")))?
        != 0
    {
        return Err(bad(
            FORMAT,
            format!("{NAME} inflates to more than its {declared} bytes"),
        ));
    }
    Ok(data)
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_close, assert_robust, assert_zip_sizes_robust};
    use super::super::Heights;
    use super::*;
    use std::io::Write;
    use std::time::Duration;

    /// A VK4 file in the format's own layout: header, offset table, 304 bytes of
    /// measurement conditions, then a 16-bit light image and a 32-bit height image.
    fn write_vk4(w: u32, h: u32, light: &[u16], height: &[u32]) -> Vec<u8> {
        let mut f = b"VK4_\x01\x00\x00\x00\0\0\0\0".to_vec();
        let conditions = 12 + 72;
        let light_at = conditions + 304;
        let height_at = light_at + 796 + 2 * light.len();
        let mut table = [0u32; 18];
        table[3] = light_at as u32;
        table[6] = height_at as u32;
        f.extend(table.iter().flat_map(|v| v.to_le_bytes()));
        let mut conds = vec![0u32; 76];
        conds[0] = 304;
        (conds[42], conds[43], conds[44]) = (250_000, 500_000, 10_000); // pm
        f.extend(conds.iter().flat_map(|v| v.to_le_bytes()));
        let image_header = |f: &mut Vec<u8>, depth: u32| {
            let n = w * h;
            for v in [w, h, depth, 0, n * depth / 8, 0, 0] {
                f.extend_from_slice(&v.to_le_bytes());
            }
            f.extend_from_slice(&[0u8; 768]);
        };
        image_header(&mut f, 16);
        f.extend(light.iter().flat_map(|v| v.to_le_bytes()));
        image_header(&mut f, 32);
        f.extend(height.iter().flat_map(|v| v.to_le_bytes()));
        f
    }

    /// A VK6/VK7 container: a short header and a zip archive holding `Vk4File`.
    fn write_container(magic: &[u8], vk4: &[u8]) -> Vec<u8> {
        let mut zip = zip::ZipWriter::new(IoCursor::new(Vec::new()));
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        zip.start_file("Vk4File", options).unwrap();
        zip.write_all(vk4).unwrap();
        let archive = zip.finish().unwrap().into_inner();
        let mut f = magic.to_vec();
        f.extend_from_slice(&[0u8; 21]);
        f.extend_from_slice(&archive);
        f
    }

    fn sample() -> Vec<u8> {
        write_vk4(
            3,
            2,
            &[0, 1, 2, 3, 4, 65535],
            &[0, 1, 2, 3, 4, 4_000_000_000],
        )
    }

    fn check(reading: &Reading) {
        let names: Vec<&str> = reading.channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["Intensity 0", "Height 0"]);
        let c = &reading.channels[1];
        assert!(c.is_height && !reading.channels[0].is_height);
        assert_eq!(c.unit.as_deref(), Some("pm"));
        // (n − 1) · step: 2 · 0.25 µm along x, 1 · 0.5 µm along y.
        assert_close(c.size.iter().flatten(), &[0.5e-6, 0.5e-6]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_eq!(h.dim(), (2, 3));
        let want: Vec<f64> = [0.0, 1.0, 2.0, 3.0, 4.0, 4e9]
            .iter()
            .map(|k| k * 1e-8)
            .collect();
        assert_close(h.iter(), &want);
    }

    #[test]
    fn a_written_vk4_reads_back() {
        let f = sample();
        assert!(sniff(&f));
        check(&read(&f).unwrap());
    }

    #[test]
    fn a_written_vk6_and_vk7_read_back() {
        for magic in [&b"VK6"[..], b"VK7"] {
            let f = write_container(magic, &sample());
            assert!(sniff(&f));
            check(&read(&f).unwrap());
        }
    }

    #[test]
    fn a_truncated_or_corrupt_file_is_refused() {
        let f = sample();
        assert_robust(
            &f,
            sniff,
            read,
            f.len() - 1,
            Some(4),
            Duration::from_millis(300),
        );
        let c = write_container(b"VK6", &f);
        assert_robust(
            &c,
            sniff,
            read,
            c.len() - 1,
            Some(3),
            Duration::from_millis(300),
        );
        for magic in [&b"VK6"[..], b"VK7"] {
            let c = write_container(magic, &f);
            assert_zip_sizes_robust(&c, read, Duration::from_millis(200));
        }
    }
}
