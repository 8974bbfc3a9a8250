//! Digital Surf **MountainsMap** documents (`.mnt`).
//!
//! An OLE compound document ([`ole_stream`]) whose stream `ScopedContents` holds, after its
//! own length (u64), a tree of entries `tag (u16) · size (u64) · data`, where the data of a
//! container are entries again. The path to the document's objects is main `0x0001` →
//! contents `0x02BD` → document `0x0002` → objects `0x0001`, whose entries carry one more
//! u64 before each tag. An object is a class `0x0001 {0x0001: u32}`, a body `0x0002` and a
//! GUID. The measured surface is class 9012; its body's entry `0x0001` is an object of
//! class 9062 (the measurement), whose body is `0xFFFF` →
//! `{0xFFFF grid, 0x0001 heights, 0x0002 height axis}`. The grid holds a header (`0xFFFF` →
//! `0xFFFF` → `0x0001`: the surface's name), the x and y axes (`0x0001`, `0x0002`: `0xFFFF`
//! → `{0xFFFF scale, 0x0001 points u32}`) and, optionally, a mask `0x0003` (class 9056,
//! `0x0002 {0x0001 width, 0x0002 height, 0x0005 array}`) whose image has a one-pixel border
//! and marks measured points with 9. A scale is `{0x0001 step f64, 0x0002 unit,
//! 0x0003 display unit, 0x0005 origin f64 in the display unit}`; a text is the byte 0x04
//! then UTF-16LE. An array (class 9049 for heights, 9048 for the mask) is
//! `0x0002 {0x0001 count u32, 0x0002 data}`, the data its size in bytes (u64) and blocks
//! `offset (u64, elements) · elements (u32) · compressed size (u32) · zlib stream`.
//!
//! A height is `count · step + origin`, in the height axis's display unit, rows stored with
//! x fastest. Derived layers (levelled, filtered) are not stored: Mountains recomputes them;
//! only measured surfaces are channels. Layout facts learnt from SurfaceTopography's reader
//! and checked on the two shared files; every size is checked before anything is
//! allocated, and a compressed block may not expand past what its header declares.

use std::io::Read;

use super::bytes::{areal, bad, grid_points, length_unit};
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "mnt";
/// The signature of an OLE compound document.
pub(crate) const OLE_MAGIC: &[u8] = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1";

const CLASS_SURFACE: u32 = 9012;
const CLASS_MEASUREMENT: u32 = 9062;
const CLASS_MASK: u32 = 9056;
const CLASS_MASK_ARRAY: u32 = 9048;
const CLASS_HEIGHTS: u32 = 9049;
/// The mask value of a measured point.
const MEASURED: u8 = 9;
/// The largest expansion of a zlib stream (deflate's limit is about 1032:1).
const MAX_ZLIB_RATIO: usize = 1100;

/// An OLE compound document holding a `ScopedContents` stream.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(OLE_MAGIC) && ole_stream(bytes, "ScopedContents").is_ok()
}

/// The bytes of the stream `name` at the root of an OLE compound document, refused when
/// its declared length exceeds the file's.
pub(crate) fn ole_stream(bytes: &[u8], name: &str) -> Result<Vec<u8>> {
    let ole_err = |e: std::io::Error| bad(FORMAT, format!("not a valid OLE document ({e})"));
    let mut doc = cfb::CompoundFile::open(std::io::Cursor::new(bytes)).map_err(ole_err)?;
    let mut stream = doc
        .open_stream(format!("/{name}"))
        .map_err(|_| bad(FORMAT, format!("the document holds no stream {name:?}")))?;
    let len = stream.len();
    if len > bytes.len() as u64 {
        return Err(bad(
            FORMAT,
            format!(
                "stream {name:?} claims {len} bytes in a file of {}",
                bytes.len()
            ),
        ));
    }
    let mut out = Vec::with_capacity(len as usize);
    stream.read_to_end(&mut out).map_err(ole_err)?;
    Ok(out)
}

/// One entry of the tag-size-data tree.
#[derive(Clone, Copy)]
struct Entry<'a> {
    tag: u16,
    data: &'a [u8],
}

/// The entries of a container's data; `prefixed`: each is preceded by a u64.
fn entries(data: &[u8], prefixed: bool) -> Result<Vec<Entry<'_>>> {
    let mut out = Vec::new();
    let mut pos = 0;
    let head = if prefixed { 18 } else { 10 };
    while pos < data.len() {
        if data.len() - pos < head {
            return Err(bad(FORMAT, "truncated entry header in ScopedContents"));
        }
        let at = pos + head - 10;
        let tag = u16::from_le_bytes([data[at], data[at + 1]]);
        let size = u64::from_le_bytes(data[at + 2..at + 10].try_into().expect("8 bytes"));
        let start = pos + head;
        let end = usize::try_from(size)
            .ok()
            .and_then(|s| start.checked_add(s))
            .filter(|&e| e <= data.len())
            .ok_or_else(|| {
                bad(
                    FORMAT,
                    format!("entry {tag:#06x} of {size} bytes overruns its container"),
                )
            })?;
        out.push(Entry {
            tag,
            data: &data[start..end],
        });
        pos = end;
    }
    Ok(out)
}

/// The data of the first entry tagged `tag` in a container, if any.
fn child(data: &[u8], tag: u16) -> Result<Option<&[u8]>> {
    Ok(entries(data, false)?
        .into_iter()
        .find(|e| e.tag == tag)
        .map(|e| e.data))
}

/// The data at the end of a path of tags, or an error naming the path.
fn path<'a>(data: &'a [u8], tags: &[u16], what: &str) -> Result<&'a [u8]> {
    let mut here = data;
    for &tag in tags {
        here = child(here, tag)?
            .ok_or_else(|| bad(FORMAT, format!("no {what} (entry {tag:#06x} missing)")))?;
    }
    Ok(here)
}

fn u32_of(data: &[u8], what: &str) -> Result<u32> {
    let b: [u8; 4] = data
        .try_into()
        .map_err(|_| bad(FORMAT, format!("{what} is {} bytes, not 4", data.len())))?;
    Ok(u32::from_le_bytes(b))
}

fn f64_of(data: &[u8], what: &str) -> Result<f64> {
    let b: [u8; 8] = data
        .try_into()
        .map_err(|_| bad(FORMAT, format!("{what} is {} bytes, not 8", data.len())))?;
    Ok(f64::from_le_bytes(b))
}

/// A text entry: the marker byte 4, then UTF-16LE, trailing NULs dropped.
fn text_of(data: &[u8]) -> Option<String> {
    let (&marker, rest) = data.split_first()?;
    if marker != 4 || rest.len() % 2 != 0 {
        return None;
    }
    let units: Vec<u16> = rest
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect();
    String::from_utf16(&units)
        .ok()
        .map(|s| s.trim_end_matches('\0').to_string())
}

/// An object's class number and body.
fn object(data: &[u8]) -> Result<(Option<u32>, Option<&[u8]>)> {
    let class = match child(data, 0x0001)? {
        Some(c) => child(c, 0x0001)?
            .map(|n| u32_of(n, "a class number"))
            .transpose()?,
        None => None,
    };
    Ok((class, child(data, 0x0002)?))
}

/// An axis scale: the step and its unit's metres, the display unit and the origin there.
struct Scale {
    /// The grid spacing (or height per count) in `per_unit` metres.
    step: f64,
    /// Metres per unit of the step.
    per_unit: f64,
    /// The display unit's canonical spelling and metres per display unit.
    display: (&'static str, f64),
    /// The origin in the display unit.
    origin: f64,
}

impl Scale {
    /// The step in units of `to` metres (a unit conversion as the reference does it).
    fn step_in(&self, to: f64) -> f64 {
        self.step * (self.per_unit / to)
    }
}

fn scale(data: &[u8], what: &str) -> Result<Scale> {
    let step = f64_of(path(data, &[0x0001], what)?, "a step")?;
    let unit = text_of(path(data, &[0x0002], what)?)
        .ok_or_else(|| bad(FORMAT, format!("the unit of the {what} is no text")))?;
    let shown = child(data, 0x0003)?
        .and_then(text_of)
        .unwrap_or_else(|| unit.clone());
    let not_length = |u: &str| bad(FORMAT, format!("the {what} has unit {u:?}, not a length"));
    let (_, per_unit) = length_unit(&unit).ok_or_else(|| not_length(&unit))?;
    let display = length_unit(&shown).ok_or_else(|| not_length(&shown))?;
    let origin = match child(data, 0x0005)? {
        Some(o) => f64_of(o, "an origin")?,
        None => 0.0,
    };
    if !step.is_finite() || step == 0.0 || !origin.is_finite() {
        return Err(bad(
            FORMAT,
            format!("the {what} has step {step} and origin {origin}"),
        ));
    }
    Ok(Scale {
        step,
        per_unit,
        display,
        origin,
    })
}

/// A lateral axis: its number of points and its scale.
fn lateral(grid: &[u8], tag: u16, what: &str) -> Result<(u32, Scale)> {
    let axis = path(grid, &[tag, 0xFFFF], what)?;
    let n = u32_of(path(axis, &[0x0001], what)?, "a number of points")?;
    Ok((n, scale(path(axis, &[0xFFFF], what)?, what)?))
}

/// An array object of class `class`: `count` elements from its zlib blocks.
fn array(data: &[u8], class: u32, count: usize, what: &str) -> Result<(Vec<u8>, usize)> {
    let (found, _) = object(data)?;
    if found != Some(class) {
        return Err(bad(
            FORMAT,
            format!("the {what} is of class {found:?}, not {class}"),
        ));
    }
    let body = path(data, &[0x0002], what)?;
    let n = u32_of(path(body, &[0x0001], what)?, "a count")? as usize;
    if n != count {
        return Err(bad(
            FORMAT,
            format!("the {what} holds {n} values for a grid of {count}"),
        ));
    }
    decode_blocks(path(body, &[0x0002], what)?, count, what)
}

/// The decompressed bytes of a block array and the size of one element.
fn decode_blocks(data: &[u8], count: usize, what: &str) -> Result<(Vec<u8>, usize)> {
    let short = || bad(FORMAT, format!("the {what} is truncated"));
    let total = u64::from_le_bytes(data.get(..8).ok_or_else(short)?.try_into().expect("8"));
    let element = (total % count as u64 == 0).then(|| total / count as u64);
    let element = match element {
        Some(e @ (1 | 2 | 4)) => e as usize,
        _ => {
            return Err(bad(
                FORMAT,
                format!("the {what} has {total} bytes for {count} values"),
            ))
        }
    };
    let total = count * element;
    if total / MAX_ZLIB_RATIO > data.len() {
        return Err(bad(
            FORMAT,
            format!(
                "the {what} claims {total} bytes from {} compressed",
                data.len()
            ),
        ));
    }
    let mut out = vec![0u8; total];
    let (mut pos, mut filled) = (8, 0);
    while pos < data.len() {
        let head = data.get(pos..pos + 16).ok_or_else(short)?;
        let offset = u64::from_le_bytes(head[..8].try_into().expect("8"));
        let n = u32::from_le_bytes(head[8..12].try_into().expect("4")) as u64;
        let packed = u32::from_le_bytes(head[12..].try_into().expect("4")) as usize;
        pos += 16;
        let stream = data
            .get(pos..pos.saturating_add(packed))
            .ok_or_else(short)?;
        pos += packed;
        let start = offset.saturating_mul(element as u64);
        let len = n.saturating_mul(element as u64);
        let end = start.saturating_add(len);
        if end > total as u64 {
            return Err(bad(
                FORMAT,
                format!("a block of the {what} lies past its end"),
            ));
        }
        let target = &mut out[start as usize..end as usize];
        inflate_exact(stream, target)
            .map_err(|r| bad(FORMAT, format!("a block of the {what}: {r}")))?;
        filled += len as usize;
    }
    if filled != total {
        return Err(bad(
            FORMAT,
            format!("the {what} has {filled} of {total} bytes"),
        ));
    }
    Ok((out, element))
}

/// Inflates a zlib stream into exactly `target`, refusing a stream that gives more or less.
fn inflate_exact(stream: &[u8], target: &mut [u8]) -> std::result::Result<(), String> {
    let mut z = flate2::read::ZlibDecoder::new(stream);
    z.read_exact(target)
        .map_err(|e| format!("does not inflate to {} bytes ({e})", target.len()))?;
    let mut extra = [0u8; 1];
    match z.read(&mut extra) {
        Ok(0) => Ok(()),
        Ok(_) => Err(format!("inflates to more than {} bytes", target.len())),
        Err(e) => Err(e.to_string()),
    }
}

/// The measured surface of a class-9012 body as a channel (`None` for a non-length one).
fn surface(body: &[u8]) -> Result<Option<Channel>> {
    let Some(inner) = child(body, 0x0001)? else {
        return Ok(None);
    };
    let (class, Some(m)) = object(inner)? else {
        return Ok(None);
    };
    if class != Some(CLASS_MEASUREMENT) {
        return Ok(None);
    }
    let m = path(m, &[0xFFFF], "measurement")?;
    let grid = path(m, &[0xFFFF], "grid")?;
    let (nx, sx) = lateral(grid, 0x0001, "x axis")?;
    let (ny, sy) = lateral(grid, 0x0002, "y axis")?;
    let z_axis = path(m, &[0x0002], "height axis")?;
    let sz = scale(path(z_axis, &[0xFFFF], "height axis")?, "height axis")?;
    let count = grid_points(FORMAT, nx.into(), ny.into())?;
    let (raw, element) = array(
        path(m, &[0x0001], "heights")?,
        CLASS_HEIGHTS,
        count,
        "heights",
    )?;
    let per_display = sz.display.1;
    let step = sz.step_in(per_display);
    let mut heights: Vec<f64> = match element {
        2 => raw
            .chunks_exact(2)
            .map(|c| f64::from(i16::from_le_bytes([c[0], c[1]])))
            .collect(),
        4 => raw
            .chunks_exact(4)
            .map(|c| f64::from(i32::from_le_bytes([c[0], c[1], c[2], c[3]])))
            .collect(),
        e => {
            return Err(bad(
                FORMAT,
                format!("heights of {e} bytes are not supported"),
            ))
        }
    };
    for h in &mut heights {
        *h = (*h * step + sz.origin) * per_display;
    }
    if let Some(mask) = child(grid, 0x0003)? {
        apply_mask(mask, nx as usize, ny as usize, &mut heights)?;
    }
    let name = child(grid, 0xFFFF)?
        .map(|h| path(h, &[0xFFFF, 0x0001], "name"))
        .transpose()
        .ok()
        .flatten()
        .and_then(text_of)
        .filter(|n| !n.is_empty());
    let title = child(body, 0xFFFF)?
        .and_then(|h| child(h, 0x0004).ok().flatten())
        .and_then(text_of);
    Ok(Some(Channel {
        name: name.or(title).unwrap_or_else(|| "Default".into()),
        heights: Heights::Areal(areal(FORMAT, ny as usize, nx as usize, heights)?),
        size: [
            Some(f64::from(nx) * sx.step_in(per_display) * per_display),
            Some(f64::from(ny) * sy.step_in(per_display) * per_display),
        ],
        unit: Some(sz.display.0.to_string()),
        is_height: true,
    }))
}

/// Marks the points the mask image (with its one-pixel border) does not mark measured.
fn apply_mask(mask: &[u8], nx: usize, ny: usize, heights: &mut [f64]) -> Result<()> {
    let (class, _) = object(mask)?;
    if class != Some(CLASS_MASK) {
        return Ok(());
    }
    let body = path(mask, &[0x0002], "mask")?;
    let w = u32_of(path(body, &[0x0001], "mask")?, "a mask width")? as usize;
    let h = u32_of(path(body, &[0x0002], "mask")?, "a mask height")? as usize;
    if (w, h) != (nx, ny) {
        return Err(bad(
            FORMAT,
            format!("a mask of {w} × {h} for a grid of {nx} × {ny}"),
        ));
    }
    let image_len = (nx + 2) * (ny + 2);
    let (image, element) = array(
        path(body, &[0x0005], "mask")?,
        CLASS_MASK_ARRAY,
        image_len,
        "mask",
    )?;
    if element != 1 {
        return Err(bad(FORMAT, format!("a mask of {element}-byte values")));
    }
    for row in 0..ny {
        for col in 0..nx {
            if image[(row + 1) * (nx + 2) + col + 1] != MEASURED {
                heights[row * nx + col] = f64::NAN;
            }
        }
    }
    Ok(())
}

/// Reads every measured surface of a MountainsMap document.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !bytes.starts_with(OLE_MAGIC) {
        return Err(bad(FORMAT, "not an OLE compound document"));
    }
    read_contents(&ole_stream(bytes, "ScopedContents")?)
}

/// The measured surfaces of a `ScopedContents` stream.
fn read_contents(contents: &[u8]) -> Result<Reading> {
    let tree = contents
        .get(8..)
        .ok_or_else(|| bad(FORMAT, "ScopedContents is too short"))?;
    let objects = path(tree, &[0x0001, 0x02BD, 0x0002, 0x0001], "document objects")?;
    let mut channels = Vec::new();
    for e in entries(objects, true)?
        .into_iter()
        .filter(|e| e.tag == 0x0001)
    {
        if let (Some(CLASS_SURFACE), Some(body)) = object(e.data)? {
            channels.extend(surface(body)?);
        }
    }
    if channels.is_empty() {
        return Err(bad(FORMAT, "the document holds no measured surface"));
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
    fn reads_the_real_files_to_the_reference() {
        // mnt-1: 960 × 600 i32 counts, no mask; mnt-2: 1280 × 960 with a mask of 45405
        // non-measured points.
        check_shared("topographies-2", "mnt-1.mnt", Default::default());
        check_shared("topographies-2", "mnt-2.mnt", Default::default());
    }

    fn tlv(tag: u16, data: &[u8]) -> Vec<u8> {
        [
            &tag.to_le_bytes()[..],
            &(data.len() as u64).to_le_bytes(),
            data,
        ]
        .concat()
    }

    fn text(s: &str) -> Vec<u8> {
        let mut out = vec![4u8];
        out.extend(s.encode_utf16().flat_map(|u| u.to_le_bytes()));
        out
    }

    fn class(n: u32) -> Vec<u8> {
        tlv(0x0001, &tlv(0x0001, &n.to_le_bytes()))
    }

    /// An array object of `class` whose bytes are split into two zlib blocks, stored in
    /// reverse order (blocks carry their offset).
    fn block_array(class_number: u32, count: u32, bytes: &[u8], element: usize) -> Vec<u8> {
        use std::io::Write;
        let half = bytes.len() / element / 2 * element;
        let mut data = (bytes.len() as u64).to_le_bytes().to_vec();
        for (offset, part) in [(half, &bytes[half..]), (0, &bytes[..half])] {
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            z.write_all(part).unwrap();
            let packed = z.finish().unwrap();
            data.extend(((offset / element) as u64).to_le_bytes());
            data.extend(((part.len() / element) as u32).to_le_bytes());
            data.extend((packed.len() as u32).to_le_bytes());
            data.extend(packed);
        }
        let body = [tlv(0x0001, &count.to_le_bytes()), tlv(0x0002, &data)].concat();
        [class(class_number), tlv(0x0002, &body)].concat()
    }

    fn scale(step: f64, unit: &str, shown: &str, origin: f64) -> Vec<u8> {
        [
            tlv(0x0001, &step.to_le_bytes()),
            tlv(0x0002, &text(unit)),
            tlv(0x0003, &text(shown)),
            tlv(0x0005, &origin.to_le_bytes()),
        ]
        .concat()
    }

    fn axis(n: u32, step_mm: f64) -> Vec<u8> {
        let inner = [
            tlv(0xFFFF, &scale(step_mm, "mm", "µm", 0.0)),
            tlv(0x0001, &n.to_le_bytes()),
        ]
        .concat();
        tlv(0xFFFF, &inner)
    }

    /// A document with one surface of 3 × 2 i16 counts, 0.5 nm per count, origin 1 µm,
    /// spacing 2 µm × 3 µm, the point (row 1, col 2) not measured.
    fn document() -> Vec<u8> {
        let counts: Vec<u8> = [0i16, 2, -4, 6, 8, 10]
            .iter()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        let mut image = vec![22u8; 5 * 4];
        for (r, c) in [(0, 0), (0, 1), (0, 2), (1, 0), (1, 1)] {
            image[(r + 1) * 5 + c + 1] = MEASURED;
        }
        let mask_body = [
            tlv(0x0001, &3u32.to_le_bytes()),
            tlv(0x0002, &2u32.to_le_bytes()),
            tlv(0x0005, &block_array(CLASS_MASK_ARRAY, 20, &image, 1)),
        ]
        .concat();
        let mask = [class(CLASS_MASK), tlv(0x0002, &mask_body)].concat();
        let name = tlv(0xFFFF, &tlv(0xFFFF, &tlv(0x0001, &text("scan 7\0"))));
        let grid = [
            name,
            tlv(0x0001, &axis(3, 2e-3)),
            tlv(0x0002, &axis(2, 3e-3)),
            tlv(0x0003, &mask),
        ]
        .concat();
        let z = tlv(0xFFFF, &scale(0.5, "nm", "µm", 1.0));
        let measurement = [
            tlv(0xFFFF, &grid),
            tlv(0x0001, &block_array(CLASS_HEIGHTS, 6, &counts, 2)),
            tlv(0x0002, &z),
        ]
        .concat();
        let inner = [
            class(CLASS_MEASUREMENT),
            tlv(0x0002, &tlv(0xFFFF, &measurement)),
        ]
        .concat();
        let surface = [class(CLASS_SURFACE), tlv(0x0002, &tlv(0x0001, &inner))].concat();
        let object = [&0u64.to_le_bytes()[..], &tlv(0x0001, &surface)].concat();
        let tree = tlv(0x0001, &tlv(0x02BD, &tlv(0x0002, &tlv(0x0001, &object))));
        [&(tree.len() as u64).to_le_bytes()[..], &tree].concat()
    }

    #[test]
    fn a_small_document_in_the_format_layout() {
        use std::io::Write;
        let contents = document();
        let mut ole = cfb::CompoundFile::create(std::io::Cursor::new(Vec::new())).unwrap();
        ole.create_stream("/ScopedContents")
            .unwrap()
            .write_all(&contents)
            .unwrap();
        let file = ole.into_inner().into_inner();
        assert!(sniff(&file));
        let r = read(&file).unwrap();
        let c = &r.channels[0];
        assert_eq!(c.name, "scan 7");
        assert_eq!(c.unit.as_deref(), Some("µm"));
        let size = [c.size[0].unwrap(), c.size[1].unwrap()];
        super::super::testkit::assert_close(&size, &[6e-6, 6e-6]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_eq!(h.dim(), (2, 3));
        // count · 0.5 nm + 1 µm, x fastest; (1, 2) not measured.
        let want = [1e-6, 1.001e-6, 0.998e-6, 1.003e-6, 1.004e-6, f64::NAN];
        super::super::testkit::assert_close(h.iter(), &want);
        // A declared size the blocks do not fill is refused.
        let mut short = contents.clone();
        short.truncate(contents.len() - 1);
        assert!(read_contents(&short).is_err());
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-2") else {
            return;
        };
        let bytes = std::fs::read(dir.join("mnt-1.mnt")).unwrap();
        assert_robust(
            &bytes,
            sniff,
            read,
            4096,
            Some(8),
            Duration::from_millis(300),
        );
        // The tree inside the document: cuts and flips of its first 64 KiB.
        let contents = ole_stream(&bytes, "ScopedContents").unwrap();
        assert_robust(
            &contents,
            |_| true,
            read_contents,
            65_536,
            None,
            Duration::from_millis(400),
        );
    }
}
