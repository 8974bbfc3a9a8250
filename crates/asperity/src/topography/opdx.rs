//! Bruker Dektak **OPDx** files (`.opdx`, Vision64 software of the Dektak XT stylus
//! profilometers).
//!
//! After the signature `VCA DATA 01 00 00 55`, a sequence of items, each a name (u32
//! length + UTF-8), a type byte and a value; containers (types 0x7D, 0x46, 0x47) hold
//! items up to their own terminator (0x7F) then two bytes, within a length given as a
//! variable-length integer (a byte 1, 2 or 4, then the length in that many bytes). The
//! items are kept by their path (`/1D_Data/Raw/Array`). A profile
//! (`/MetaData/1D_Channels/Height` names its channels) has `NumPoints`, `Extent` (the
//! distance from the first to the last point: the size is `Extent · n / (n − 1)`),
//! `DataScale` (a quantity whose unit converts to the extent's) and `Array` (5 bytes then
//! `n` little-endian f64). A map (`/MetaData/2D_Channels/Height`, the primary channel
//! first) has `Dimension1Points` (y), `Dimension2Points` (x), their extents, `DataScale`
//! and `Matrix` (y rows of x f32, x fastest). Heights are in the x extent's unit. Layout
//! learnt from SurfaceTopography's reader and Gwyddion's `dektakvca.c`; the real file
//! `opdx-3.opdx` is a profile, maps are tested on a file written here in the layout.

use std::collections::HashMap;

use ndarray::Array1;

use super::bytes::{areal, bad, grid_points, length_unit, samples, Cursor, Endian, Sample};
use super::{Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "opdx";
const MAGIC: &[u8] = b"VCA DATA\x01\x00\x00\x55";
/// Containers nest no deeper than this (a corrupt file could otherwise recurse without end).
const MAX_DEPTH: usize = 32;

/// The `VCA DATA` signature.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// An item's value, as far as the reader needs it.
#[derive(Debug, Clone)]
enum Value {
    Number(f64),
    Text(String),
    /// A quantity or unit: value and unit symbol.
    Quantity(f64, String),
    List(Vec<String>),
    /// f64 samples: offset of the block and its length in bytes.
    Doubles(usize, usize),
    /// f32 matrix: offset, length in bytes, x and y points.
    Matrix(usize, usize, u32, u32),
    Other,
}

type Manifest = HashMap<String, Value>;

fn name(c: &mut Cursor) -> Result<String> {
    let n = c.u32(Endian::Little)? as usize;
    Ok(String::from_utf8_lossy(c.take(n)?).into_owned())
}

fn varlen(c: &mut Cursor) -> Result<usize> {
    Ok(match c.u8()? {
        1 => c.u8()? as usize,
        2 => c.u16(Endian::Little)? as usize,
        4 => c.u32(Endian::Little)? as usize,
        n => return Err(bad(FORMAT, format!("a length of {n} bytes"))),
    })
}

/// A unit record: name, symbol, value and 12 more bytes.
fn unit_data(c: &mut Cursor) -> Result<Value> {
    name(c)?;
    let symbol = name(c)?;
    let value = c.f64(Endian::Little)?;
    c.skip(12)?;
    Ok(Value::Quantity(value, symbol))
}

/// Reads the value of `len` bytes at the cursor with a reader, checking it used them all.
fn sized(c: &mut Cursor, f: impl FnOnce(&mut Cursor) -> Result<Value>) -> Result<Value> {
    let len = varlen(c)?;
    let end = c
        .pos()
        .checked_add(len)
        .ok_or_else(|| bad(FORMAT, "a length overflows"))?;
    let v = f(c)?;
    if c.pos() > end {
        return Err(bad(FORMAT, "an item overruns its length"));
    }
    c.seek(end)?;
    Ok(v)
}

/// A block of `len` bytes to skip over, returned as (offset, length).
fn block(c: &mut Cursor, len: usize) -> Result<(usize, usize)> {
    let at = c.pos();
    c.skip(len)?;
    Ok((at, len))
}

fn matrix(c: &mut Cursor, named: bool) -> Result<Value> {
    name(c)?;
    if named {
        c.u32(Endian::Little)?;
        name(c)?;
    }
    let len = varlen(c)?;
    let y = c.u32(Endian::Little)?;
    let x = c.u32(Endian::Little)?;
    let len = len
        .checked_sub(8)
        .ok_or_else(|| bad(FORMAT, "a matrix shorter than its sizes"))?;
    let (at, len) = block(c, len)?;
    Ok(Value::Matrix(at, len, x, y))
}

/// The value of a (non-container) item of type `t` at `path`.
fn value(c: &mut Cursor, t: u8, path: &str) -> Result<Value> {
    let le = Endian::Little;
    Ok(match t {
        0x00 => matrix(c, true)?,
        0x45 => matrix(c, false)?,
        0x01 => Value::Number(f64::from(c.u8()?)),
        0x04 => Value::Number(f64::from(c.i16(le)?)),
        0x05 => Value::Number(f64::from(c.u16(le)?)),
        0x06 => Value::Number(f64::from(c.i32(le)?)),
        0x07 => Value::Number(f64::from(c.u32(le)?)),
        0x0A | 0x0B => {
            let b: [u8; 8] = c.take(8)?.try_into().expect("8 bytes");
            Value::Number(if t == 0x0A {
                i64::from_le_bytes(b) as f64
            } else {
                u64::from_le_bytes(b) as f64
            })
        }
        0x0C => Value::Number(f64::from(c.f32(le)?)),
        0x0D => Value::Number(c.f64(le)?),
        0x0E => {
            name(c)?;
            let n = varlen(c)?;
            c.skip(n)?;
            Value::Other
        }
        0x12 => {
            let n = varlen(c)?;
            Value::Text(String::from_utf8_lossy(c.take(n)?).into_owned())
        }
        0x13 => sized(c, |c| {
            let v = c.f64(le)?;
            name(c)?;
            Ok(Value::Quantity(v, name(c)?))
        })?,
        0x15 => {
            c.skip(9)?;
            Value::Other
        }
        0x18 => sized(c, unit_data)?,
        0x40 => {
            name(c)?;
            let n = varlen(c)?;
            let (at, len) = block(c, n)?;
            Value::Doubles(at, len)
        }
        0x7C => positions(c, path)?,
        t => return Err(bad(FORMAT, format!("unknown item type {t:#04x} at {path}"))),
    })
}

/// A string list: its names up to its length.
fn string_list(c: &mut Cursor) -> Result<Value> {
    name(c)?;
    let len = varlen(c)?;
    let end = c
        .pos()
        .checked_add(len)
        .ok_or_else(|| bad(FORMAT, "a length overflows"))?;
    let mut list = Vec::new();
    while c.pos() < end {
        list.push(name(c)?);
    }
    if c.pos() != end {
        return Err(bad(FORMAT, "a string list overruns its length"));
    }
    Ok(Value::List(list))
}

/// Position data (skipped: the grids are uniform).
fn positions(c: &mut Cursor, path: &str) -> Result<Value> {
    if !path.starts_with("/1D_Data") && !path.starts_with("/2D_Data") {
        return Err(bad(
            FORMAT,
            format!("position data outside the data at {path}"),
        ));
    }
    name(c)?;
    let n = varlen(c)?;
    c.skip(n)?;
    Ok(Value::Other)
}

/// Reads one item into the manifest; `false` at a terminator.
fn item(c: &mut Cursor, manifest: &mut Manifest, prefix: &str, depth: usize) -> Result<bool> {
    let path = format!("{prefix}/{}", name(c)?);
    let t = c.u8()?;
    match t {
        0x7F => Ok(false),
        0x7D | 0x46 | 0x47 => {
            if depth >= MAX_DEPTH {
                return Err(bad(
                    FORMAT,
                    format!("containers nested deeper than {MAX_DEPTH}"),
                ));
            }
            let len = varlen(c)?;
            let end = c
                .pos()
                .checked_add(len)
                .ok_or_else(|| bad(FORMAT, "a length overflows"))?;
            while item(c, manifest, &path, depth + 1)? {}
            c.skip(2)?;
            if c.pos() != end {
                return Err(bad(
                    FORMAT,
                    format!("container {path} does not end at its length"),
                ));
            }
            Ok(true)
        }
        0x42 => {
            let v = string_list(c)?;
            manifest.insert(path, v);
            Ok(true)
        }
        t => {
            let v = value(c, t, &path)?;
            manifest.insert(path, v);
            Ok(true)
        }
    }
}

fn get<'m>(m: &'m Manifest, key: &str) -> Result<&'m Value> {
    m.get(key).ok_or_else(|| bad(FORMAT, format!("no {key}")))
}

fn number(m: &Manifest, key: &str) -> Result<f64> {
    match get(m, key)? {
        Value::Number(v) => Ok(*v),
        _ => Err(bad(FORMAT, format!("{key} is not a number"))),
    }
}

/// A quantity's value and its unit as (canonical spelling, metres per unit).
fn quantity(m: &Manifest, key: &str) -> Result<(f64, (&'static str, f64))> {
    match get(m, key)? {
        Value::Quantity(v, unit) if v.is_finite() => {
            let u = length_unit(unit)
                .ok_or_else(|| bad(FORMAT, format!("{key} is in {unit:?}, not a length")))?;
            Ok((*v, u))
        }
        _ => Err(bad(FORMAT, format!("{key} is not a finite quantity"))),
    }
}

/// A count of points from the manifest (positive, whole).
fn points(m: &Manifest, key: &str) -> Result<u64> {
    let n = number(m, key)?;
    if !(n >= 1.0 && n.fract() == 0.0 && n < 1e15) {
        return Err(bad(FORMAT, format!("{key} is {n}")));
    }
    Ok(n as u64)
}

/// The size spanned by `n` points whose first and last are `extent` apart.
fn size_from_extent(extent: f64, n: u64) -> f64 {
    if n > 1 {
        extent * n as f64 / (n - 1) as f64
    } else {
        extent
    }
}

fn channel_name(m: &Manifest, prefix: &str, fallback: &str) -> String {
    match m.get(&format!("{prefix}/DataKind")) {
        Some(Value::Text(t)) => t.clone(),
        _ => fallback.to_string(),
    }
}

fn profile(bytes: &[u8], m: &Manifest, channel: &str) -> Result<Channel> {
    let prefix = format!("/1D_Data/{channel}");
    let n = points(m, &format!("{prefix}/NumPoints"))?;
    let (extent, unit) = quantity(m, &format!("{prefix}/Extent"))?;
    let (scale, height_unit) = quantity(m, &format!("{prefix}/DataScale"))?;
    let factor = scale * (height_unit.1 / unit.1);
    let Value::Doubles(at, len) = *get(m, &format!("{prefix}/Array"))? else {
        return Err(bad(FORMAT, format!("{prefix}/Array is not an array")));
    };
    let count = usize::try_from(n).map_err(|_| bad(FORMAT, "too many points"))?;
    if count.checked_mul(8).and_then(|b| b.checked_add(5)) != Some(len) {
        return Err(bad(FORMAT, format!("{len} bytes of data for {n} points")));
    }
    let raw = samples(FORMAT, bytes, at + 5, count, Sample::F64, Endian::Little)?;
    let heights: Array1<f64> = raw.into_iter().map(|v| v * factor * unit.1).collect();
    Ok(Channel {
        name: channel_name(m, &prefix, channel),
        heights: Heights::Profile(heights),
        size: [Some(size_from_extent(extent, n) * unit.1), None],
        unit: Some(unit.0.to_string()),
        is_height: true,
    })
}

fn map(bytes: &[u8], m: &Manifest, channel: &str) -> Result<Channel> {
    let prefix = format!("/2D_Data/{channel}");
    let ny = points(m, &format!("{prefix}/Dimension1Points"))?;
    let nx = points(m, &format!("{prefix}/Dimension2Points"))?;
    let (ey, uy) = quantity(m, &format!("{prefix}/Dimension1Extent"))?;
    let (ex, ux) = quantity(m, &format!("{prefix}/Dimension2Extent"))?;
    let (scale, hu) = quantity(m, &format!("{prefix}/DataScale"))?;
    let factor = scale * (hu.1 / ux.1);
    let Value::Matrix(at, len, x, y) = *get(m, &format!("{prefix}/Matrix"))? else {
        return Err(bad(FORMAT, format!("{prefix}/Matrix is not a matrix")));
    };
    if (u64::from(x), u64::from(y)) != (nx, ny) {
        return Err(bad(
            FORMAT,
            format!("a {x} × {y} matrix for {nx} × {ny} points"),
        ));
    }
    let count = grid_points(FORMAT, nx, ny)?;
    if count.checked_mul(4) != Some(len) {
        return Err(bad(
            FORMAT,
            format!("{len} bytes of data for {count} points"),
        ));
    }
    let raw = samples(FORMAT, bytes, at, count, Sample::F32, Endian::Little)?;
    let heights = raw.into_iter().map(|v| v * factor * ux.1).collect();
    let size_y = size_from_extent(ey, ny) * (uy.1 / ux.1);
    Ok(Channel {
        name: channel_name(m, &prefix, channel),
        heights: Heights::Areal(areal(FORMAT, ny as usize, nx as usize, heights)?),
        size: [Some(size_from_extent(ex, nx) * ux.1), Some(size_y * ux.1)],
        unit: Some(ux.0.to_string()),
        is_height: true,
    })
}

/// The names of a string list in the manifest (empty if absent).
fn list(m: &Manifest, key: &str) -> Vec<String> {
    match m.get(key) {
        Some(Value::List(l)) => l.clone(),
        _ => Vec::new(),
    }
}

/// Reads the height channels of an OPDx file: profiles or maps, as its `DataKind` says
/// (else as its data are).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "no VCA DATA signature"));
    }
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(MAGIC.len())?;
    let mut m = Manifest::new();
    while item(&mut c, &mut m, "", 0)? {}
    // The last terminator is followed by two bytes, as every container's is.
    c.skip(2)?;
    let kind = match m.get("/MetaData/DataKind") {
        Some(Value::Text(t)) => t.as_str(),
        _ => "",
    };
    let has = |p: &str| m.keys().any(|k| k.starts_with(p));
    let areal = kind == "Surface Height" || (kind != "Surface Profile" && has("/2D_Data/"));
    let channels = if areal {
        let mut names = list(&m, "/MetaData/2D_Channels/Height");
        if let Some(Value::Text(primary)) = m.get("/MetaData/PrimaryData2D") {
            names.retain(|n| n != primary);
            names.insert(0, primary.clone());
        }
        names
            .iter()
            .filter(|n| m.contains_key(&format!("/2D_Data/{n}/Matrix")))
            .map(|n| map(bytes, &m, n))
            .collect::<Result<Vec<_>>>()?
    } else {
        list(&m, "/MetaData/1D_Channels/Height")
            .iter()
            .map(|n| profile(bytes, &m, n))
            .collect::<Result<Vec<_>>>()?
    };
    if channels.is_empty() {
        return Err(bad(FORMAT, format!("no height data (data kind {kind:?})")));
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_close, assert_robust, check_shared, set_dir};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_profile_to_the_reference() {
        // 3001 f64 samples, extent and data scale in µm.
        check_shared("topographies-2", "opdx-3.opdx", Default::default());
    }

    fn named(s: &str) -> Vec<u8> {
        [&(s.len() as u32).to_le_bytes()[..], s.as_bytes()].concat()
    }

    fn item(name: &str, t: u8, body: &[u8]) -> Vec<u8> {
        [named(name), vec![t], body.to_vec()].concat()
    }

    fn sized(body: &[u8]) -> Vec<u8> {
        [&[2u8][..], &(body.len() as u16).to_le_bytes(), body].concat()
    }

    fn container(name: &str, items: &[Vec<u8>]) -> Vec<u8> {
        let inner = [items.concat(), item("", 0x7F, &[]), vec![0xFF, 0xFF]].concat();
        item(name, 0x7D, &sized(&inner))
    }

    fn unit(name: &str, value: f64, symbol: &str) -> Vec<u8> {
        let body = [
            named("u"),
            named(symbol),
            value.to_le_bytes().to_vec(),
            vec![0; 12],
        ]
        .concat();
        item(name, 0x18, &sized(&body))
    }

    /// A map of 3 × 2 f32 values, extents 4 µm (x, 3 points) and 1 mm (y, 2 points), data
    /// scale 2 nm.
    fn map_file() -> Vec<u8> {
        let values: Vec<u8> = [1.0f32, 2.0, 3.0, -1.0, -2.0, 0.5]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let matrix_body = [
            named("Matrix<float>"),
            sized(&[&2u32.to_le_bytes()[..], &3u32.to_le_bytes(), &values].concat()),
        ]
        .concat();
        let channels = [named("StringList"), sized(&named("Height"))].concat();
        let data = container(
            "Height",
            &[
                item("DataKind", 0x12, &[&[1u8, 6][..], b"Height"].concat()),
                item("Dimension1Points", 0x07, &2u32.to_le_bytes()),
                item("Dimension2Points", 0x07, &3u32.to_le_bytes()),
                unit("Dimension1Extent", 1.0, "mm"),
                unit("Dimension2Extent", 4.0, "µm"),
                unit("DataScale", 2.0, "nm"),
                item("Matrix", 0x45, &matrix_body),
            ],
        );
        let meta = container(
            "MetaData",
            &[
                item(
                    "DataKind",
                    0x12,
                    &[&[1u8, 14][..], b"Surface Height"].concat(),
                ),
                container("2D_Channels", &[item("Height", 0x42, &channels)]),
            ],
        );
        let body = [
            meta,
            container("2D_Data", &[data]),
            item("", 0x7F, &[0xFF, 0xFF]),
        ]
        .concat();
        [MAGIC, &body].concat()
    }

    #[test]
    fn a_small_map_in_the_format_layout() {
        let r = read(&map_file()).unwrap();
        let c = &r.channels[0];
        assert_eq!(c.name, "Height");
        assert_eq!(c.unit.as_deref(), Some("µm"));
        // Extents span first to last point: 4 µm · 3/2 and 1 mm · 2/1.
        let size = [c.size[0].unwrap(), c.size[1].unwrap()];
        assert_close(&size, &[6e-6, 2e-3]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_eq!(h.dim(), (2, 3));
        assert_close(h.iter(), &[2e-9, 4e-9, 6e-9, -2e-9, -4e-9, 1e-9]);
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-2") else {
            return;
        };
        let bytes = std::fs::read(dir.join("opdx-3.opdx")).unwrap();
        let n = bytes.len() - 1;
        assert_robust(&bytes, sniff, read, n, Some(12), Duration::from_millis(300));
        let map = map_file();
        let n = map.len() - 1;
        assert_robust(&map, sniff, read, n, Some(12), Duration::from_millis(200));
    }
}
