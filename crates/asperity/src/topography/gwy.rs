//! Gwyddion native files (`.gwy`): a serialised tree of objects.
//!
//! The file is `GWYP` followed by one object, a `GwyContainer`. An object is its type name
//! (NUL-terminated), a little-endian `u32` byte size, then that many bytes of components;
//! a component is its name (NUL-terminated), a one-byte type and a value: `b`, `c` one
//! byte, `i` `i32`, `q` `i64`, `d` `f64`, `s` a NUL-terminated string, `o` a nested object;
//! the capital letters are arrays, a `u32` count then the elements (`C`, `I`, `Q`, `D`,
//! `S`, `O`). Each image channel `N` of the container is the component `/N/data`, a
//! `GwyDataField` with `xres`, `yres` (columns, rows), `xreal`, `yreal` (the physical
//! sizes), `si_unit_xy` and `si_unit_z` (`GwySIUnit` objects whose `unitstr` is the unit,
//! in base SI: `m`) and `data` (`D`, `xres × yres` values row by row, the first row at
//! the top: our row 0); its title is the string `/N/data/title`. Masks, presentations,
//! graphs and volume data are passed over. Facts from Gwyddion's documentation of its
//! file format and SurfaceTopography's `GWYReader`.
//!
//! Untrusted bytes: every size is checked against the bytes that remain before anything
//! is taken, arrays are kept as slices of the file until a data field is decoded, and
//! objects may nest at most [`MAX_DEPTH`] deep.

use ndarray::Array2;

use super::bytes::{bad, Cursor, Endian};
use super::{unit_to_metres, Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "gwy";
const MAGIC: &[u8] = b"GWYP";
const LE: Endian = Endian::Little;
/// The deepest nesting of objects accepted (Gwyddion's own files nest 3–4 deep).
const MAX_DEPTH: usize = 32;

/// A file that starts with `GWYP`.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// The values this reader uses; the others are checked for size and passed over.
enum Value<'a> {
    Int(i64),
    Double(f64),
    Text(String),
    Object(Object<'a>),
    /// A `D` array: its bytes, 8 per value.
    Doubles(&'a [u8]),
    Other,
}

/// An object: its type name and components in file order.
struct Object<'a> {
    name: String,
    components: Vec<(String, Value<'a>)>,
}

impl<'a> Object<'a> {
    fn get(&self, name: &str) -> Option<&Value<'a>> {
        self.components
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
    }

    fn int(&self, name: &str) -> Option<i64> {
        match self.get(name) {
            Some(Value::Int(v)) => Some(*v),
            _ => None,
        }
    }

    fn double(&self, name: &str) -> Option<f64> {
        match self.get(name) {
            Some(Value::Double(v)) => Some(*v),
            _ => None,
        }
    }

    /// The `unitstr` of the `GwySIUnit` object `name`, `None` where absent.
    fn unit(&self, name: &str) -> Option<String> {
        match self.get(name) {
            Some(Value::Object(u)) => match u.get("unitstr") {
                Some(Value::Text(s)) => Some(s.clone()),
                _ => None,
            },
            _ => None,
        }
    }
}

/// A NUL-terminated string.
fn cstr(c: &mut Cursor<'_>, rest: &[u8]) -> Result<String> {
    let start = c.pos();
    let len = rest
        .get(start..)
        .and_then(|r| r.iter().position(|&b| b == 0))
        .ok_or_else(|| {
            bad(
                FORMAT,
                format!("a name at offset {start} has no terminating NUL"),
            )
        })?;
    let text = String::from_utf8_lossy(c.take(len)?).into_owned();
    c.skip(1)?;
    Ok(text)
}

/// An object at the cursor (name, size, components), `depth` objects deep.
fn object<'a>(c: &mut Cursor<'a>, all: &'a [u8], depth: usize) -> Result<Object<'a>> {
    if depth > MAX_DEPTH {
        return Err(bad(
            FORMAT,
            format!("objects nested more than {MAX_DEPTH} deep"),
        ));
    }
    let name = cstr(c, all)?;
    let size = c.u32(LE)? as usize;
    let start = c.pos();
    let end = start
        .checked_add(size)
        .filter(|&e| e <= all.len())
        .ok_or_else(|| {
            bad(
                FORMAT,
                format!("object {name} of {size} bytes at offset {start} runs past the end"),
            )
        })?;
    let mut components = Vec::new();
    // The components are read from the file's bytes up to the object's end.
    let mut inner = Cursor::new(FORMAT, &all[..end]);
    inner.seek(start)?;
    while inner.pos() < end {
        components.push(component(&mut inner, &all[..end], depth)?);
    }
    c.seek(end)?;
    Ok(Object { name, components })
}

/// One component: name, type, value.
fn component<'a>(c: &mut Cursor<'a>, all: &'a [u8], depth: usize) -> Result<(String, Value<'a>)> {
    let name = cstr(c, all)?;
    let kind = c.u8()?;
    let value = match kind {
        b'b' | b'c' => {
            c.skip(1)?;
            Value::Other
        }
        b'i' => Value::Int(i64::from(c.i32(LE)?)),
        b'q' => Value::Int(i64::from_le_bytes(c.take(8)?.try_into().expect("8 bytes"))),
        b'd' => Value::Double(c.f64(LE)?),
        b's' => Value::Text(cstr(c, all)?),
        b'o' => Value::Object(object(c, all, depth + 1)?),
        b'C' | b'I' | b'Q' | b'D' => {
            let n = c.u32(LE)? as usize;
            let width = match kind {
                b'C' => 1,
                b'I' => 4,
                _ => 8,
            };
            let len = n
                .checked_mul(width)
                .ok_or_else(|| bad(FORMAT, "array too large"))?;
            let data = c.take(len)?;
            if kind == b'D' {
                Value::Doubles(data)
            } else {
                Value::Other
            }
        }
        b'S' | b'O' => {
            // Each element takes at least one byte: the loop is bounded by the file.
            for _ in 0..c.u32(LE)? {
                if kind == b'S' {
                    cstr(c, all)?;
                } else {
                    object(c, all, depth + 1)?;
                }
            }
            Value::Other
        }
        other => {
            return Err(bad(
                FORMAT,
                format!("component {name} has the unknown type {:?}", other as char),
            ))
        }
    };
    Ok((name, value))
}

/// Reads a Gwyddion native file (see the module docs).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "no GWYP signature"));
    }
    let mut c = Cursor::new(FORMAT, bytes);
    c.skip(MAGIC.len())?;
    let root = object(&mut c, bytes, 0)?;
    if root.name != "GwyContainer" {
        return Err(bad(
            FORMAT,
            format!("the top object is a {}, not a GwyContainer", root.name),
        ));
    }
    let mut fields: Vec<(u64, &Object)> = root
        .components
        .iter()
        .filter_map(|(name, v)| {
            let index = name
                .strip_prefix('/')?
                .strip_suffix("/data")?
                .parse()
                .ok()?;
            match v {
                Value::Object(o) if o.name == "GwyDataField" => Some((index, o)),
                _ => None,
            }
        })
        .collect();
    fields.sort_by_key(|(i, _)| *i);
    let channels = fields
        .iter()
        .map(|(i, field)| {
            let title = match root.get(&format!("/{i}/data/title")) {
                Some(Value::Text(t)) => t.clone(),
                _ => format!("/{i}/data"),
            };
            channel(title, field)
        })
        .collect::<Result<Vec<_>>>()?;
    if channels.is_empty() {
        return Err(bad(FORMAT, "the file holds no image channel (/N/data)"));
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

/// A `GwyDataField` as a channel.
fn channel(name: String, field: &Object) -> Result<Channel> {
    let missing = |what: &str| bad(FORMAT, format!("channel {name}: no {what}"));
    let xres = field.int("xres").ok_or_else(|| missing("xres"))?;
    let yres = field.int("yres").ok_or_else(|| missing("yres"))?;
    let Some(Value::Doubles(data)) = field.get("data") else {
        return Err(missing("data"));
    };
    let count = usize::try_from(xres)
        .ok()
        .zip(usize::try_from(yres).ok())
        .filter(|&(x, y)| x > 0 && y > 0)
        .and_then(|(x, y)| x.checked_mul(y))
        .filter(|&n| n.checked_mul(8) == Some(data.len()))
        .ok_or_else(|| {
            bad(
                FORMAT,
                format!(
                    "channel {name}: {xres} × {yres} points do not match its {} data values",
                    data.len() / 8
                ),
            )
        })?;
    let values: Vec<f64> = data
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect();
    debug_assert_eq!(values.len(), count);
    let mut heights = Array2::from_shape_vec((yres as usize, xres as usize), values)
        .map_err(|e| bad(FORMAT, e.to_string()))?;
    let xy = field.unit("si_unit_xy").as_deref().and_then(unit_to_metres);
    let size = |key: &str| {
        let v = field.double(key)?;
        let metres = v * xy?;
        crate::is_positive_finite(metres).then_some(metres)
    };
    let z_unit = field.unit("si_unit_z");
    let z = z_unit.as_deref().and_then(unit_to_metres);
    if let Some(f) = z {
        heights.mapv_inplace(|v| v * f);
    }
    Ok(Channel {
        name,
        heights: Heights::Areal(heights),
        size: [size("xreal"), size("yreal")],
        unit: z_unit.map(|u| super::canonical_unit(&u)),
        is_height: z.is_some(),
    })
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_robust, check_shared, set_dir, Expect};
    use super::*;
    use std::time::Duration;

    /// A file in the format's own layout: one `xres × yres` field in metres.
    fn gwy(xres: i32, yres: i32, values: &[f64], title: &str) -> Vec<u8> {
        fn obj(name: &str, body: &[u8]) -> Vec<u8> {
            let mut o = name.as_bytes().to_vec();
            o.push(0);
            o.extend_from_slice(&(body.len() as u32).to_le_bytes());
            o.extend_from_slice(body);
            o
        }
        fn comp(name: &str, kind: u8, value: &[u8]) -> Vec<u8> {
            let mut c = name.as_bytes().to_vec();
            c.push(0);
            c.push(kind);
            c.extend_from_slice(value);
            c
        }
        let unit = obj("GwySIUnit", &comp("unitstr", b's', b"m\0"));
        let mut field = Vec::new();
        field.extend(comp("xres", b'i', &xres.to_le_bytes()));
        field.extend(comp("yres", b'i', &yres.to_le_bytes()));
        field.extend(comp("xreal", b'd', &2e-6f64.to_le_bytes()));
        field.extend(comp("yreal", b'd', &1e-6f64.to_le_bytes()));
        field.extend(comp("si_unit_xy", b'o', &unit));
        field.extend(comp("si_unit_z", b'o', &unit));
        let mut data = (values.len() as u32).to_le_bytes().to_vec();
        values
            .iter()
            .for_each(|v| data.extend_from_slice(&v.to_le_bytes()));
        field.extend(comp("data", b'D', &data));
        let mut body = comp("/0/data", b'o', &obj("GwyDataField", &field));
        let mut t = title.as_bytes().to_vec();
        t.push(0);
        body.extend(comp("/0/data/title", b's', &t));
        let mut file = MAGIC.to_vec();
        file.extend(obj("GwyContainer", &body));
        file
    }

    #[test]
    fn reads_the_real_file_to_the_reference() {
        // TopoStats' file_square.gwy: one 256 × 256 channel in metres.
        check_shared(
            "topographies-3",
            "topostats-file_square.gwy",
            Expect::default(),
        );
    }

    #[test]
    fn a_file_in_the_format_layout() {
        let values = [1e-9, 2e-9, 3e-9, 4e-9, 5e-9, 6e-9];
        let r = read(&gwy(3, 2, &values, "Height")).unwrap();
        let c = &r.channels[0];
        assert_eq!(c.name, "Height");
        assert_eq!(c.size, [Some(2e-6), Some(1e-6)]);
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        assert_eq!(h.dim(), (2, 3));
        assert_eq!(h[(1, 0)], 4e-9); // rows of xres values
                                     // Absurd dimensions: refused, nothing allocated from them.
        for (x, y) in [(i32::MAX, i32::MAX), (3, 3), (-3, -2), (0, 6)] {
            let err = read(&gwy(x, y, &values, "H")).unwrap_err().to_string();
            assert!(err.contains("do not match"), "{err}");
        }
    }

    #[test]
    fn nesting_beyond_the_limit_is_refused() {
        // 100 objects each holding the next: an error, not a deep recursion.
        let mut inner = Vec::new();
        for _ in 0..100 {
            let mut o = b"GwyContainer\0".to_vec();
            let mut body = b"x\0o".to_vec();
            body.extend_from_slice(&inner);
            o.extend_from_slice(&(body.len() as u32).to_le_bytes());
            o.extend(body);
            inner = o;
        }
        let mut file = MAGIC.to_vec();
        file.extend(inner);
        let err = read(&file).unwrap_err().to_string();
        assert!(err.contains("nested"), "{err}");
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-3") else {
            return;
        };
        let bytes = std::fs::read(dir.join("topostats-file_square.gwy")).unwrap();
        assert_robust(
            &bytes,
            sniff,
            read,
            8192,
            Some(4),
            Duration::from_millis(300),
        );
        let small = gwy(3, 2, &[1.0; 6], "H");
        assert_robust(
            &small,
            sniff,
            read,
            small.len() - 1,
            Some(4),
            Duration::from_millis(300),
        );
    }
}
