//! NetCDF classic files (`.nc`): the container format of contact.engineering.
//!
//! The classic format (`CDF\x01`) and its 64-bit-offset variant (`CDF\x02`), big-endian:
//! the record count, then the lists of dimensions (name, length), global attributes and
//! variables (name, dimension ids, attributes, type, size, data offset: 4 bytes, 8 in the
//! variant). A list is a tag (`0x0A` dimensions, `0x0B` variables, `0x0C` attributes, or
//! zero for an absent list) and a count; names are a length and bytes padded to 4; an
//! attribute is a name, a type, a count and its values padded to 4. Types: 1 byte, 2 char,
//! 3 short, 4 int, 5 float, 6 double. Every numeric variable of one or two dimensions that
//! is not a coordinate variable (one named as its dimension) is a channel, named as the
//! variable; its unit is its `unit` (or `units`) attribute. As contact.engineering writes
//! them, a map `heights(x, y)` is stored x-major (our transpose: our rows are y), and the
//! coordinate variables `x`, `y` carry the physical size in their `length` attribute and
//! `unit`. Variables along the unlimited (record) dimension are not supported. Facts from
//! Unidata's description of the classic format and SurfaceTopography's `NCReader`.
//!
//! Untrusted bytes: every count is checked against the bytes left before a list or value
//! is read, and a variable's data are decoded only after they are found inside the file.

use ndarray::{Array1, Array2};

use super::bytes::{bad, Cursor, Endian};
use super::{unit_to_metres, Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "netcdf";
const BE: Endian = Endian::Big;

/// `CDF\x01` or `CDF\x02`.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.len() >= 4 && &bytes[..3] == b"CDF" && matches!(bytes[3], 1 | 2)
}

/// An attribute's value: text or numbers.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Attr {
    Text(String),
    Numbers(Vec<f64>),
}

/// A variable of the header: its dimensions (ids), attributes, type and data offset.
pub(crate) struct Variable {
    pub(crate) name: String,
    pub(crate) dims: Vec<usize>,
    pub(crate) attrs: Vec<(String, Attr)>,
    pub(crate) kind: u32,
    begin: usize,
}

impl Variable {
    pub(crate) fn text(&self, key: &str) -> Option<&str> {
        self.attrs.iter().find_map(|(k, v)| match v {
            Attr::Text(t) if k == key => Some(t.as_str()),
            _ => None,
        })
    }

    pub(crate) fn number(&self, key: &str) -> Option<f64> {
        self.attrs.iter().find_map(|(k, v)| match v {
            Attr::Numbers(n) if k == key => n.first().copied(),
            _ => None,
        })
    }

    fn unit(&self) -> Option<&str> {
        self.text("unit").or_else(|| self.text("units"))
    }
}

/// Bytes per value of a type, `None` for an unknown type.
fn width(kind: u32) -> Option<usize> {
    match kind {
        1 | 2 => Some(1),
        3 => Some(2),
        4 | 5 => Some(4),
        6 => Some(8),
        _ => None,
    }
}

fn decode(kind: u32, b: &[u8]) -> f64 {
    match kind {
        1 => f64::from(b[0] as i8),
        3 => f64::from(i16::from_be_bytes([b[0], b[1]])),
        4 => f64::from(i32::from_be_bytes([b[0], b[1], b[2], b[3]])),
        5 => f64::from(f32::from_be_bytes([b[0], b[1], b[2], b[3]])),
        _ => f64::from_be_bytes(b.try_into().expect("8 bytes")),
    }
}

/// A count, checked against the bytes left (each element takes at least `min` bytes).
fn count(c: &mut Cursor<'_>, left: usize, min: usize) -> Result<usize> {
    let n = c.u32(BE)? as usize;
    if n.saturating_mul(min) > left {
        return Err(bad(
            FORMAT,
            format!("a count of {n} cannot fit in the file"),
        ));
    }
    Ok(n)
}

fn name(c: &mut Cursor<'_>, len: usize) -> Result<String> {
    let n = count(c, len, 1)?;
    let text = String::from_utf8_lossy(c.take(n)?).into_owned();
    c.skip((4 - n % 4) % 4)?;
    Ok(text)
}

/// A list header: its tag (or zero for an absent list) and element count.
fn list(c: &mut Cursor<'_>, len: usize, tag: u32) -> Result<usize> {
    let t = c.u32(BE)?;
    let n = count(c, len, 4)?;
    if t != tag && !(t == 0 && n == 0) {
        return Err(bad(
            FORMAT,
            format!("expected list tag {tag:#x}, found {t:#x}"),
        ));
    }
    Ok(n)
}

fn attributes(c: &mut Cursor<'_>, len: usize) -> Result<Vec<(String, Attr)>> {
    let n = list(c, len, 0x0C)?;
    let mut out = Vec::new();
    for _ in 0..n {
        let key = name(c, len)?;
        let kind = c.u32(BE)?;
        let w = width(kind).ok_or_else(|| bad(FORMAT, format!("attribute {key}: type {kind}")))?;
        let m = count(c, len, w)?;
        let raw = c.take(m * w)?;
        c.skip((4 - (m * w) % 4) % 4)?;
        let value = if kind == 2 {
            Attr::Text(
                String::from_utf8_lossy(raw)
                    .trim_end_matches('\0')
                    .to_string(),
            )
        } else {
            Attr::Numbers(raw.chunks_exact(w).map(|b| decode(kind, b)).collect())
        };
        out.push((key, value));
    }
    Ok(out)
}

/// The dimensions of a file: name and length.
type Dimensions = Vec<(String, usize)>;

/// A parsed header: the dimensions (name, length), the global attributes and the variables.
pub(crate) struct Header {
    pub(crate) dims: Dimensions,
    pub(crate) attrs: Vec<(String, Attr)>,
    pub(crate) vars: Vec<Variable>,
}

/// The header of a NetCDF classic file (checked against the bytes, see the module docs).
pub(crate) fn header(bytes: &[u8]) -> Result<Header> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "no CDF signature"));
    }
    let len = bytes.len();
    let mut c = Cursor::new(FORMAT, bytes);
    let offset64 = c.take(4)?[3] == 2;
    c.skip(4)?; // the record count
    let mut dims = Vec::new();
    for _ in 0..list(&mut c, len, 0x0A)? {
        let n = name(&mut c, len)?;
        dims.push((n, c.u32(BE)? as usize));
    }
    let attrs = attributes(&mut c, len)?;
    let mut vars = Vec::new();
    for _ in 0..list(&mut c, len, 0x0B)? {
        let var_name = name(&mut c, len)?;
        let ndims = count(&mut c, len, 4)?;
        let ids = (0..ndims)
            .map(|_| c.u32(BE).map(|d| d as usize))
            .collect::<Result<Vec<_>>>()?;
        let attrs = attributes(&mut c, len)?;
        let kind = c.u32(BE)?;
        c.skip(4)?; // vsize, recomputed from the dimensions
        let begin = if offset64 {
            u64::from_be_bytes(c.take(8)?.try_into().expect("8 bytes"))
        } else {
            u64::from(c.u32(BE)?)
        };
        vars.push(Variable {
            name: var_name,
            dims: ids,
            attrs,
            kind,
            begin: usize::try_from(begin).map_err(|_| bad(FORMAT, "offset too large"))?,
        });
    }
    Ok(Header { dims, attrs, vars })
}

/// The shape of a variable (its dimensions' lengths); a record variable is refused.
pub(crate) fn shape(dims: &Dimensions, v: &Variable) -> Result<Vec<usize>> {
    let shape = v
        .dims
        .iter()
        .map(|&d| dims.get(d).map(|d| d.1))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| bad(FORMAT, format!("variable {}: undefined dimension", v.name)))?;
    if shape.contains(&0) {
        return Err(bad(
            FORMAT,
            format!("variable {}: record variables are not supported", v.name),
        ));
    }
    Ok(shape)
}

/// A variable's values as float64 (exact for every type but char), row-major.
pub(crate) fn values(bytes: &[u8], v: &Variable, shape: &[usize]) -> Result<Vec<f64>> {
    let data = block(bytes, v, shape)?;
    let w = width(v.kind).expect("checked by block");
    Ok(data.chunks_exact(w).map(|b| decode(v.kind, b)).collect())
}

/// Reads a NetCDF classic file (see the module docs).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    let Header { dims, vars, .. } = header(bytes)?;
    let mut channels = Vec::new();
    for v in &vars {
        let shape = shape(&dims, v)?;
        // Every variable's data must lie in the file, channel or not.
        let data = block(bytes, v, &shape)?;
        let is_coordinate = v.dims.len() == 1 && dims[v.dims[0]].0 == v.name;
        if is_coordinate || v.kind == 2 || !(1..=2).contains(&v.dims.len()) {
            continue;
        }
        let coords: Vec<Option<&Variable>> = v
            .dims
            .iter()
            .map(|&d| {
                vars.iter()
                    .find(|c| c.name == dims[d].0 && c.dims.len() == 1 && c.dims[0] == d)
            })
            .collect();
        let names: Vec<&str> = v.dims.iter().map(|&d| dims[d].0.as_str()).collect();
        channels.push(channel(v, data, &shape, &coords, &names)?);
    }
    if channels.is_empty() {
        return Err(bad(FORMAT, "no numeric variable of one or two dimensions"));
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

/// Physical length of a dimension: its coordinate variable's `length` in its `unit`.
fn length(coord: Option<&Variable>) -> Option<f64> {
    let c = coord?;
    let l = c.number("length")? * unit_to_metres(c.unit()?)?;
    crate::is_positive_finite(l).then_some(l)
}

/// The bytes of a variable's data, checked to lie inside the file.
fn block<'a>(bytes: &'a [u8], v: &Variable, shape: &[usize]) -> Result<&'a [u8]> {
    let w = width(v.kind)
        .ok_or_else(|| bad(FORMAT, format!("variable {}: type {}", v.name, v.kind)))?;
    shape
        .iter()
        .try_fold(w, |a, &b| a.checked_mul(b))
        .and_then(|len| v.begin.checked_add(len).map(|end| (v.begin, end)))
        .filter(|&(_, end)| end <= bytes.len())
        .map(|(s, e)| &bytes[s..e])
        .ok_or_else(|| {
            bad(
                FORMAT,
                format!("variable {}: its data do not fit in the file", v.name),
            )
        })
}

fn channel(
    v: &Variable,
    block: &[u8],
    shape: &[usize],
    coords: &[Option<&Variable>],
    dim_names: &[&str],
) -> Result<Channel> {
    let w = width(v.kind).expect("checked by block");
    let values: Vec<f64> = block.chunks_exact(w).map(|b| decode(v.kind, b)).collect();
    let unit = v.unit().map(str::to_string);
    let factor = unit.as_deref().and_then(unit_to_metres);
    let scale = factor.unwrap_or(1.0);
    let (heights, size) = if shape.len() == 1 {
        let h = Array1::from(values) * scale;
        (Heights::Profile(h), [length(coords[0]), None])
    } else {
        let a = Array2::from_shape_vec((shape[0], shape[1]), values)
            .map_err(|e| bad(FORMAT, e.to_string()))?
            * scale;
        // `heights(x, y)` is x-major: our rows are y, the transpose.
        if dim_names[0] == "x" {
            // In place (tile by tile): the map is never held twice.
            let t = super::hdf5::into_transposed(a);
            (Heights::Areal(t), [length(coords[0]), length(coords[1])])
        } else {
            (Heights::Areal(a), [length(coords[1]), length(coords[0])])
        }
    };
    Ok(Channel {
        name: v.name.clone(),
        heights,
        size,
        unit: unit.map(|u| super::canonical_unit(&u)),
        is_height: factor.is_some(),
    })
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_robust, check_shared, set_dir, Expect};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        // nc-1.nc (contact.engineering's container): heights(x, y) 5 × 10 in nm, sizes in
        // the `length` attributes of x and y. The peer calls the channel `Default`.
        let expect = Expect {
            channel_names: false,
            ..Expect::default()
        };
        check_shared("topographies-3", "nc-1.nc", expect);
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-3") else {
            return;
        };
        let bytes = std::fs::read(dir.join("nc-1.nc")).unwrap();
        assert_robust(
            &bytes,
            sniff,
            read,
            0x1a4,
            Some(3),
            Duration::from_millis(300),
        );
        // An absurd count: refused before anything is allocated.
        let mut huge = bytes.clone();
        huge[8..12].copy_from_slice(&0x0A_u32.to_be_bytes());
        huge[12..16].copy_from_slice(&u32::MAX.to_be_bytes());
        assert!(read(&huge).is_err());
    }
}
