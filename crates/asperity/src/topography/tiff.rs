//! A bounds-checked reader of the TIFF container (baseline TIFF 6.0, not BigTIFF) for the
//! instrument formats built on it (JPK): the image file directories (IFDs) with their tags
//! and each page's uncompressed raster.
//!
//! A file starts with `II*\0` (little-endian) or `MM\0*` (big-endian) and the offset of the
//! first IFD; an IFD is a count (u16), entries of 12 bytes (`tag u16 · type u16 · count
//! u32 · value or offset u32`, the value inline when it fits in 4 bytes) and the offset of
//! the next IFD (0 ends the chain). Every offset and count is checked against the file
//! before use; a chain of IFDs that loops or runs past [`MAX_PAGES`] is refused.

use std::collections::HashMap;

use super::bytes::{bad, grid_points, samples, Cursor, Endian, Sample};
use crate::Result;

/// The most pages read from one file.
const MAX_PAGES: usize = 4096;

/// A tag's value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    /// Integers (BYTE, SHORT, LONG and their signed kinds).
    Ints(Vec<i64>),
    /// Reals (RATIONAL, FLOAT, DOUBLE).
    Reals(Vec<f64>),
    /// Text (ASCII), cut at the first NUL.
    Text(String),
    /// A type the readers do not use.
    Other,
}

impl Value {
    /// The first number of an integer or real value.
    pub(crate) fn number(&self) -> Option<f64> {
        match self {
            Value::Ints(v) => v.first().map(|&i| i as f64),
            Value::Reals(v) => v.first().copied(),
            _ => None,
        }
    }

    /// The text of an ASCII value.
    pub(crate) fn text(&self) -> Option<&str> {
        match self {
            Value::Text(t) => Some(t),
            _ => None,
        }
    }
}

/// One page (IFD): its tags, and where each tag's value lies in the file.
#[derive(Debug, Clone)]
pub(crate) struct Page {
    pub tags: HashMap<u16, Value>,
    /// Each tag's value as `(offset, length in bytes)`, checked to lie inside the file.
    pub blocks: HashMap<u16, (usize, usize)>,
}

/// Byte-typed values (BYTE, SBYTE, UNDEFINED) longer than this are not decoded into
/// [`Value::Ints`] (they are data blocks, read through [`Page::blocks`]).
const MAX_DECODED_BYTES: usize = 1 << 16;

/// Whether `bytes` start with a TIFF signature.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(b"II*\0") || bytes.starts_with(b"MM\0*")
}

/// The byte order and every page of a TIFF file.
pub(crate) fn pages(format: &'static str, bytes: &[u8]) -> Result<(Endian, Vec<Page>)> {
    let e = match bytes.get(..4) {
        Some(b"II*\0") => Endian::Little,
        Some(b"MM\0*") => Endian::Big,
        _ => return Err(bad(format, "no TIFF signature")),
    };
    let mut c = Cursor::new(format, bytes);
    c.seek(4)?;
    let mut next = c.u32(e)? as usize;
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    while next != 0 {
        if !seen.insert(next) || out.len() >= MAX_PAGES {
            return Err(bad(
                format,
                "the chain of image directories loops or is too long",
            ));
        }
        let (page, following) = directory(format, bytes, e, next)?;
        next = following;
        out.push(page);
    }
    if out.is_empty() {
        return Err(bad(format, "no image directory"));
    }
    Ok((e, out))
}

/// The image file directory at `offset` (e.g. an EXIF directory a tag points to), and the
/// offset of the next one (0: none).
fn directory(
    format: &'static str,
    bytes: &[u8],
    e: Endian,
    offset: usize,
) -> Result<(Page, usize)> {
    let mut c = Cursor::new(format, bytes);
    c.seek(offset)?;
    let n = c.u16(e)? as usize;
    let mut tags = HashMap::new();
    let mut blocks = HashMap::new();
    for _ in 0..n {
        let (tag, value, block) = entry(&mut c, e)?;
        tags.insert(tag, value);
        blocks.insert(tag, block);
    }
    let next = c.u32(e)? as usize;
    Ok((Page { tags, blocks }, next))
}

/// The image file directory at `offset` alone (a sub-directory such as EXIF's).
pub(crate) fn page_at(
    format: &'static str,
    bytes: &[u8],
    e: Endian,
    offset: usize,
) -> Result<Page> {
    directory(format, bytes, e, offset).map(|(page, _)| page)
}

/// One 12-byte directory entry and where its value lies; the cursor ends after it.
fn entry(c: &mut Cursor, e: Endian) -> Result<(u16, Value, (usize, usize))> {
    let tag = c.u16(e)?;
    let kind = c.u16(e)?;
    let count = c.u32(e)? as usize;
    let size = match kind {
        1 | 2 | 6 | 7 => 1,
        3 | 8 => 2,
        4 | 9 | 11 => 4,
        5 | 10 | 12 => 8,
        _ => 0,
    };
    let field = c.pos();
    c.skip(4)?;
    let after = c.pos();
    let len = count.saturating_mul(size);
    if size == 0 {
        return Ok((tag, Value::Other, (field, 0)));
    }
    let at = if len <= 4 {
        field
    } else {
        let mut o = c.clone();
        o.seek(field)?;
        o.u32(e)? as usize
    };
    c.seek(at)?;
    let value = if size == 1 && count > MAX_DECODED_BYTES {
        let start = c.pos();
        c.skip(count)?;
        c.seek(start)?;
        Value::Other
    } else {
        decode(c, e, kind, count)?
    };
    c.seek(after)?;
    Ok((tag, value, (at, len)))
}

fn decode(c: &mut Cursor, e: Endian, kind: u16, count: usize) -> Result<Value> {
    // The block is checked to lie in the file before anything is allocated.
    let size = match kind {
        1 | 2 | 6 | 7 => 1,
        3 | 8 => 2,
        4 | 9 | 11 => 4,
        _ => 8,
    };
    let start = c.pos();
    c.skip(count.saturating_mul(size))?;
    c.seek(start)?;
    Ok(match kind {
        2 => Value::Text(super::bytes::fixed_text(c.take(count)?)),
        1 | 7 => Value::Ints(c.take(count)?.iter().map(|&b| i64::from(b)).collect()),
        6 => Value::Ints(c.take(count)?.iter().map(|&b| i64::from(b as i8)).collect()),
        3 => Value::Ints(
            (0..count)
                .map(|_| c.u16(e).map(i64::from))
                .collect::<Result<_>>()?,
        ),
        8 => Value::Ints(
            (0..count)
                .map(|_| c.i16(e).map(i64::from))
                .collect::<Result<_>>()?,
        ),
        4 => Value::Ints(
            (0..count)
                .map(|_| c.u32(e).map(i64::from))
                .collect::<Result<_>>()?,
        ),
        9 => Value::Ints(
            (0..count)
                .map(|_| c.i32(e).map(i64::from))
                .collect::<Result<_>>()?,
        ),
        11 => Value::Reals(
            (0..count)
                .map(|_| c.f32(e).map(f64::from))
                .collect::<Result<_>>()?,
        ),
        12 => Value::Reals((0..count).map(|_| c.f64(e)).collect::<Result<_>>()?),
        5 | 10 => Value::Reals(
            (0..count)
                .map(|_| {
                    let (n, d) = if kind == 5 {
                        (f64::from(c.u32(e)?), f64::from(c.u32(e)?))
                    } else {
                        (f64::from(c.i32(e)?), f64::from(c.i32(e)?))
                    };
                    Ok(n / d)
                })
                .collect::<Result<_>>()?,
        ),
        _ => Value::Other,
    })
}

fn ints<'p>(format: &'static str, page: &'p Page, tag: u16, what: &str) -> Result<&'p [i64]> {
    match page.tags.get(&tag) {
        Some(Value::Ints(v)) if !v.is_empty() => Ok(v),
        _ => Err(bad(format, format!("a page has no {what} (tag {tag})"))),
    }
}

/// Checks that every strip of a page lies inside the file (a cut file is refused even
/// where the cut falls in a page no reader uses).
pub(crate) fn check_strips(format: &'static str, bytes: &[u8], page: &Page) -> Result<()> {
    let (Some(Value::Ints(offsets)), Some(Value::Ints(counts))) =
        (page.tags.get(&273), page.tags.get(&279))
    else {
        return Ok(());
    };
    for (&o, &l) in offsets.iter().zip(counts) {
        if o < 0 || l < 0 || o.saturating_add(l) as u64 > bytes.len() as u64 {
            return Err(bad(format, "a strip lies past the end of the file"));
        }
    }
    Ok(())
}

/// A page's uncompressed single-channel raster as `(rows, cols, row-major values)`.
pub(crate) fn raster(
    format: &'static str,
    bytes: &[u8],
    e: Endian,
    page: &Page,
) -> Result<(usize, usize, Vec<f64>)> {
    let one = |tag, what| ints(format, page, tag, what).map(|v| v[0]);
    let (w, h) = (one(256, "image width")?, one(257, "image length")?);
    let bits = one(258, "bits per sample")?;
    let kind = page.tags.get(&339).and_then(Value::number).unwrap_or(1.0) as i64;
    if page.tags.get(&259).and_then(Value::number).unwrap_or(1.0) != 1.0 {
        return Err(bad(format, "compressed TIFF rasters are not supported"));
    }
    if page.tags.get(&277).and_then(Value::number).unwrap_or(1.0) != 1.0 {
        return Err(bad(format, "a raster of several samples per pixel"));
    }
    let sample = match (kind, bits) {
        (1, 8) => Sample::U8,
        (1, 16) => Sample::U16,
        (1, 32) => Sample::U32,
        (2, 16) => Sample::I16,
        (2, 32) => Sample::I32,
        (3, 32) => Sample::F32,
        (3, 64) => Sample::F64,
        _ => {
            return Err(bad(
                format,
                format!("samples of {bits} bits, format {kind}"),
            ))
        }
    };
    let n = grid_points(format, w.max(0) as u64, h.max(0) as u64)?;
    let offsets = ints(format, page, 273, "strip offsets")?;
    let counts = ints(format, page, 279, "strip byte counts")?;
    if offsets.len() != counts.len() {
        return Err(bad(
            format,
            "strip offsets and byte counts differ in number",
        ));
    }
    let need = n
        .checked_mul(sample.size())
        .filter(|&b| b <= bytes.len())
        .ok_or_else(|| {
            bad(
                format,
                format!("a {w} × {h} raster does not fit in the file"),
            )
        })?;
    let mut raw = Vec::with_capacity(need);
    for (&o, &l) in offsets.iter().zip(counts) {
        let take = (l.max(0) as usize).min(need - raw.len());
        let start = usize::try_from(o).map_err(|_| bad(format, "a negative strip offset"))?;
        let strip = start
            .checked_add(take)
            .and_then(|end| bytes.get(start..end))
            .ok_or_else(|| bad(format, "a strip lies past the end of the file"))?;
        raw.extend_from_slice(strip);
    }
    if raw.len() != need {
        return Err(bad(
            format,
            format!("the strips hold {} of {need} bytes", raw.len()),
        ));
    }
    Ok((
        h as usize,
        w as usize,
        samples(format, &raw, 0, n, sample, e)?,
    ))
}
