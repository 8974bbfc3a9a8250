//! Zygo `.datx` (Mx software of Zygo's optical interferometers): an HDF5 file (read by the
//! same Rust decoder as [`super::hdf5`]) whose root dataset `MetaData` is a table of
//! (source, link, destination) strings. From `Root`, the links `Measurement`, `Surface` and
//! `Path` lead to the surface dataset, stored `(rows, columns) = (y, x)` (our order). Its
//! attributes: `Unit` (the heights' unit, e.g. `NanoMeters`), `No Data` (the value of an
//! undefined point; non-finite values are undefined too) and the converters `X Converter`,
//! `Y Converter`, `Z Converter`, each a compound record (category, base unit, unit,
//! parameters): a lateral one is `LateralCat` from `Pixels`, its parameter 1 the pixel
//! spacing in metres; the height one is `HeightCat` in the heights' unit. Strings and
//! parameter arrays may be stored with fixed or variable length (in HDF5's global heap);
//! both are read, from the file's bytes, every field and heap object bounds-checked. Facts
//! from SurfaceTopography's `DATXReader` and Gwyddion's reader; no real `.datx` was at hand,
//! so the tests use files written in this layout by h5py (`tests/data/make_datx.py`), which
//! SurfaceTopography 1.27.1 reads to the same numbers.
//!
//! Refused with one line: a converter of another kind (heights in fringes, a lateral scale
//! not from pixels), a `Unit` that disagrees with the height converter's, a unit that is no
//! length.

use std::collections::HashMap;

use hdf5_reader as h5;
use hdf5_reader::global_heap::GlobalHeapCollection;
use hdf5_reader::{ByteOrder, Datatype, StringSize, VarLenKind};

use super::hdf5::{lib, numeric, read_values};
use super::{bad, Channel, Heights, Reading};
use crate::Result;

pub(crate) const FORMAT: &str = "datx";

/// The most records read from a table or attribute (the metadata of a real file has a few
/// hundred), and the longest string or parameter list taken from the global heap.
const MAX_RECORDS: usize = 100_000;
const MAX_HEAP_OBJECT: usize = 1 << 20;

/// Metres per unit of the unit names the Mx software writes, and their short spelling.
fn unit(name: &str) -> Option<(&'static str, f64)> {
    Some(match name.trim() {
        "Meters" | "m" => ("m", 1.0),
        "MilliMeters" | "mm" => ("mm", 1e-3),
        "MicroMeters" | "um" | "µm" | "μm" => ("µm", 1e-6),
        "NanoMeters" | "nm" => ("nm", 1e-9),
        "Angstroms" | "Å" => ("Å", 1e-10),
        _ => return None,
    })
}

/// One field of a record: text or numbers.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Text(String),
    Numbers(Vec<f64>),
}

/// Whether an open HDF5 file is a `.datx`: it has the root dataset `MetaData`.
pub(crate) fn is_datx(file: &h5::Hdf5File) -> bool {
    file.dataset("MetaData").is_ok()
}

/// Reads the surface of a `.datx` file of `file_len` bytes.
pub(crate) fn read(file: &h5::Hdf5File, file_len: usize) -> Result<Reading> {
    let mut heap = Heap::new(file);
    let path = surface_path(file, &mut heap, file_len)?;
    let ds = file
        .dataset(&path)
        .map_err(|_| bad(FORMAT, format!("the surface dataset {path} is missing")))?;
    if ds.ndim() != 2 || !numeric(ds.dtype()) || ds.shape().contains(&0) {
        return Err(bad(
            FORMAT,
            "the surface is not a two-dimensional numeric map",
        ));
    }
    let [rows, cols] = [ds.shape()[0], ds.shape()[1]];
    let attrs = ds.attributes();
    let attr = |name: &str| attrs.iter().find(|a| a.name == name);
    let (unit_name, to_m) = height_unit(&attr("Unit"), &attr("Z Converter"), &mut heap)?;
    let dx = lateral_spacing(attr("X Converter"), "X Converter", &mut heap)?;
    let dy = lateral_spacing(attr("Y Converter"), "Y Converter", &mut heap)?;
    let no_data = match attr("No Data") {
        None => None,
        Some(a) => match first(records_of(a, &mut heap)?) {
            Some(Value::Numbers(n)) if !n.is_empty() => Some(n[0]),
            _ => return Err(bad(FORMAT, "No Data is not a number")),
        },
    };
    let mut heights = read_values(&ds, file_len)?;
    heights.mapv_inplace(|v| {
        if !v.is_finite() || Some(v) == no_data {
            f64::NAN
        } else {
            v * to_m
        }
    });
    Ok(Reading {
        format: FORMAT,
        channels: vec![Channel {
            name: "Surface".into(),
            heights: Heights::Areal(heights),
            size: [Some(cols as f64 * dx), Some(rows as f64 * dy)],
            unit: Some(unit_name.into()),
            is_height: true,
        }],
    })
}

/// Follows Root → Measurement → Surface → Path through the `MetaData` table.
fn surface_path(file: &h5::Hdf5File, heap: &mut Heap, file_len: usize) -> Result<String> {
    let table = file.dataset("MetaData").map_err(lib)?;
    let Datatype::Compound { size, fields } = table.dtype().clone() else {
        return Err(bad(FORMAT, "MetaData is not a table of records"));
    };
    let n = table
        .shape()
        .iter()
        .try_fold(1u64, |a, &d| a.checked_mul(d));
    match n.and_then(|n| n.checked_mul(u64::from(size))) {
        Some(b) if n.unwrap_or(0) as usize <= MAX_RECORDS && b <= file_len as u64 => {}
        _ => {
            return Err(bad(
                FORMAT,
                "MetaData claims more records than the file holds",
            ))
        }
    }
    let raw = table.read_raw_bytes().map_err(lib)?;
    let mut links: HashMap<(String, String), String> = HashMap::new();
    for element in raw.chunks(size.max(1) as usize) {
        match record(&fields, element, heap)?.as_slice() {
            [Value::Text(s), Value::Text(l), Value::Text(d), ..] => {
                links.insert((s.clone(), l.clone()), d.clone());
            }
            _ => return Err(bad(FORMAT, "MetaData is not a table of three strings")),
        }
    }
    let mut node = "Root".to_string();
    for link in ["Measurement", "Surface", "Path"] {
        node = links
            .get(&(node.clone(), link.to_string()))
            .cloned()
            .ok_or_else(|| bad(FORMAT, format!("MetaData has no link {node} → {link}")))?;
    }
    Ok(node)
}

/// The heights' unit: the `Unit` attribute, equal to the height converter's.
fn height_unit(
    named: &Option<&h5::Attribute>,
    converter_attr: &Option<&h5::Attribute>,
    heap: &mut Heap,
) -> Result<(&'static str, f64)> {
    let named = match named
        .map(|a| records_of(a, heap))
        .transpose()?
        .and_then(first)
    {
        Some(Value::Text(t)) => t,
        Some(_) => return Err(bad(FORMAT, "Unit is not a string")),
        None => return Err(bad(FORMAT, "the surface has no Unit")),
    };
    let ([category, base], _) = converter(*converter_attr, "Z Converter", heap)?;
    if category != "HeightCat" {
        return Err(bad(
            FORMAT,
            format!("a Z converter of category {category:?} (only HeightCat is read)"),
        ));
    }
    let (short, to_m) = unit(&base).ok_or_else(|| {
        bad(
            FORMAT,
            format!("heights in {base:?}, not a length unit (fringes are not read)"),
        )
    })?;
    match unit(&named) {
        Some((s, _)) if s == short => Ok((short, to_m)),
        _ => Err(bad(
            FORMAT,
            format!("two height units: Unit {named:?} and Z Converter {base:?}"),
        )),
    }
}

/// The pixel spacing (metres) of a lateral converter: `LateralCat` from `Pixels`.
fn lateral_spacing(attr: Option<&h5::Attribute>, name: &str, heap: &mut Heap) -> Result<f64> {
    let ([category, base], parameters) = converter(attr, name, heap)?;
    if category != "LateralCat" || base != "Pixels" {
        return Err(bad(
            FORMAT,
            format!("{name} is {category:?} from {base:?} (only LateralCat from Pixels is read)"),
        ));
    }
    match parameters.get(1) {
        Some(&d) if d.is_finite() && d > 0.0 => Ok(d),
        _ => Err(bad(
            FORMAT,
            format!("{name} gives no positive pixel spacing"),
        )),
    }
}

/// A converter attribute: (category, base unit) and its parameters.
fn converter(
    attr: Option<&h5::Attribute>,
    name: &str,
    heap: &mut Heap,
) -> Result<([String; 2], Vec<f64>)> {
    let attr = attr.ok_or_else(|| bad(FORMAT, format!("the surface has no {name}")))?;
    let records = records_of(attr, heap)?;
    match records.first().map(Vec::as_slice) {
        Some([Value::Text(c), Value::Text(b), .., Value::Numbers(p)]) => {
            Ok(([c.clone(), b.clone()], p.clone()))
        }
        _ => Err(bad(
            FORMAT,
            format!("{name} is not a (category, unit, ..., parameters) record"),
        )),
    }
}

/// The first field of the first record.
fn first(records: Vec<Vec<Value>>) -> Option<Value> {
    records.into_iter().next()?.into_iter().next()
}

/// Every element of an attribute as a record of fields (a compound's fields in order; a
/// plain string or number is a record of one field).
fn records_of(a: &h5::Attribute, heap: &mut Heap) -> Result<Vec<Vec<Value>>> {
    // Variable-length strings the decoder already took from the global heap.
    if let Some(strings) = &a.decoded_strings {
        return Ok(strings
            .iter()
            .map(|s| vec![Value::Text(s.trim().to_string())])
            .collect());
    }
    let n = a.num_elements().map_err(lib)?;
    let size = element_size(&a.datatype, heap.offset_size);
    if n as usize > MAX_RECORDS || size == 0 {
        return Err(bad(FORMAT, format!("{} holds {n} records", a.name)));
    }
    let need = n as usize * size;
    let raw = a
        .raw_data
        .get(..need)
        .ok_or_else(|| bad(FORMAT, format!("{} is shorter than its records", a.name)))?;
    raw.chunks(size)
        .map(|element| match &a.datatype {
            Datatype::Compound { fields, .. } => record(fields, element, heap),
            other => Ok(vec![value(other, element, heap)?]),
        })
        .collect()
}

/// A compound element's fields, each from its bytes.
fn record(fields: &[h5::CompoundField], element: &[u8], heap: &mut Heap) -> Result<Vec<Value>> {
    fields
        .iter()
        .map(|f| {
            let at = f.byte_offset as usize;
            let width = element_size(&f.datatype, heap.offset_size);
            let bytes = at
                .checked_add(width)
                .and_then(|end| element.get(at..end))
                .filter(|_| width > 0)
                .ok_or_else(|| bad(FORMAT, format!("field {} lies outside its record", f.name)))?;
            value(&f.datatype, bytes, heap)
        })
        .collect()
}

/// The stored width of one element of `t` (0 for a type not read here).
fn element_size(t: &Datatype, offset_size: u8) -> usize {
    match t {
        Datatype::FixedPoint { size, .. } | Datatype::FloatingPoint { size, .. } => *size as usize,
        Datatype::String {
            size: StringSize::Fixed(n),
            ..
        } => *n as usize,
        Datatype::String {
            size: StringSize::Variable,
            ..
        }
        | Datatype::VarLen { .. } => 8 + offset_size as usize,
        Datatype::Compound { size, .. } => *size as usize,
        Datatype::Array { base, dims } => {
            let n = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d));
            n.and_then(|n| n.checked_mul(element_size(base, offset_size) as u64))
                .filter(|&b| b <= MAX_HEAP_OBJECT as u64)
                .unwrap_or(0) as usize
        }
        _ => 0,
    }
}

/// One field from its stored bytes.
fn value(t: &Datatype, b: &[u8], heap: &mut Heap) -> Result<Value> {
    Ok(match t {
        Datatype::String {
            size: StringSize::Fixed(_),
            ..
        } => Value::Text(text(b)),
        Datatype::String {
            size: StringSize::Variable,
            ..
        } => Value::Text(text(&heap.object(b)?)),
        Datatype::VarLen {
            kind: VarLenKind::String,
            ..
        } => Value::Text(text(&heap.object(b)?)),
        Datatype::VarLen { base, .. } => {
            let data = heap.object(b)?;
            let w = element_size(base, heap.offset_size);
            if w == 0 {
                return Err(bad(FORMAT, "a variable-length array of a type not read"));
            }
            Value::Numbers(
                data.chunks_exact(w)
                    .filter_map(|e| number(base, e))
                    .collect(),
            )
        }
        Datatype::Array { base, .. } => {
            let w = element_size(base, heap.offset_size).max(1);
            Value::Numbers(b.chunks_exact(w).filter_map(|e| number(base, e)).collect())
        }
        other => Value::Numbers(number(other, b).into_iter().collect()),
    })
}

/// Text up to the first NUL, trimmed.
fn text(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).trim().to_string()
}

/// An integer or float of its stored byte order, as f64.
fn number(t: &Datatype, b: &[u8]) -> Option<f64> {
    let (size, order) = match t {
        Datatype::FixedPoint {
            size, byte_order, ..
        }
        | Datatype::FloatingPoint {
            size, byte_order, ..
        } => (*size as usize, byte_order),
        _ => return None,
    };
    if !matches!(size, 1 | 2 | 4 | 8) {
        return None;
    }
    let mut le = [0u8; 8];
    let b = b.get(..size)?;
    le[..size].copy_from_slice(b);
    if *order == ByteOrder::BigEndian {
        le[..size].reverse();
    }
    let bits = u64::from_le_bytes(le);
    Some(match t {
        Datatype::FloatingPoint { size: 8, .. } => f64::from_bits(bits),
        Datatype::FloatingPoint { size: 4, .. } => f64::from(f32::from_bits(bits as u32)),
        Datatype::FixedPoint { signed: true, .. } => {
            let shift = 64 - 8 * size as u32;
            (((bits << shift) as i64) >> shift) as f64
        }
        Datatype::FixedPoint { signed: false, .. } => bits as f64,
        _ => return None,
    })
}

/// The file's global heap collections, parsed once each, for variable-length fields.
struct Heap<'a> {
    file: &'a h5::Hdf5File,
    offset_size: u8,
    length_size: u8,
    collections: HashMap<u64, GlobalHeapCollection>,
}

impl<'a> Heap<'a> {
    fn new(file: &'a h5::Hdf5File) -> Self {
        let sb = file.superblock();
        Heap {
            file,
            offset_size: sb.offset_size,
            length_size: sb.length_size,
            collections: HashMap::new(),
        }
    }

    /// The object a variable-length field names: `length u32 · collection address ·
    /// index u32`; an empty field (address undefined or index 0) is empty.
    fn object(&mut self, field: &[u8]) -> Result<Vec<u8>> {
        let w = self.offset_size as usize;
        let corrupt = || bad(FORMAT, "a corrupt variable-length field");
        let le = |b: &[u8]| b.iter().rev().fold(0u64, |a, &x| (a << 8) | u64::from(x));
        let len = le(field.get(..4).ok_or_else(corrupt)?) as usize;
        let address = le(field.get(4..4 + w).ok_or_else(corrupt)?);
        let index = le(field.get(4 + w..8 + w).ok_or_else(corrupt)?);
        if index == 0 || address == u64::MAX >> (64 - 8 * w as u32) {
            return Ok(Vec::new());
        }
        if !self.collections.contains_key(&address) {
            if self.collections.len() >= MAX_RECORDS {
                return Err(bad(FORMAT, "too many global heap collections"));
            }
            let parsed = GlobalHeapCollection::parse_at_storage(
                self.file.storage(),
                address,
                self.offset_size,
                self.length_size,
            )
            .map_err(lib)?;
            self.collections.insert(address, parsed);
        }
        let object = u16::try_from(index)
            .ok()
            .and_then(|i| self.collections[&address].get_object(i))
            .ok_or_else(|| bad(FORMAT, format!("global heap object {index} is missing")))?;
        // The field's length counts elements; the object holds their bytes.
        let data = &object.data;
        if data.len() > MAX_HEAP_OBJECT || len > data.len() {
            return Err(corrupt());
        }
        Ok(data.clone())
    }
}

#[cfg(test)]
mod tests {
    use crate::topography::testkit::{assert_close, assert_robust};
    use crate::topography::{hdf5, Heights};
    use std::time::Duration;

    fn file(name: &str) -> Vec<u8> {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
        std::fs::read(format!("{dir}{name}")).unwrap()
    }

    /// z[r, c] = 10 r + c − 7.5 in the file's unit; (1, 2) is `No Data`, (2, 3) NaN.
    fn expected(to_m: f64) -> Vec<f64> {
        let mut z: Vec<f64> = (0..4)
            .flat_map(|r| (0..5).map(move |c| (10 * r + c) as f64 - 7.5))
            .map(|v| v * to_m)
            .collect();
        z[5 + 2] = f64::NAN;
        z[2 * 5 + 3] = f64::NAN;
        z
    }

    #[test]
    fn both_string_layouts_read_like_the_peer() {
        // SurfaceTopography 1.27.1 reads both files as 1.25 × 2 (µm) with these heights
        // (its [x, y] array is our transpose) and the same two undefined points.
        for (name, unit, to_m) in [
            ("datx-vlen.datx", "nm", 1e-9),
            ("datx-fixed.datx", "µm", 1e-6),
        ] {
            let reading = hdf5::read(&file(name)).unwrap();
            assert_eq!(reading.format, "datx");
            let c = &reading.channels[0];
            assert_eq!(reading.channels.len(), 1);
            assert_eq!(
                (c.name.as_str(), c.unit.as_deref()),
                ("Surface", Some(unit))
            );
            let Heights::Areal(h) = &c.heights else {
                panic!("a map")
            };
            assert_eq!(h.dim(), (4, 5), "{name}: (rows, cols) = (y, x)");
            assert_close(h.iter(), &expected(to_m));
            let [x, y] = [c.size[0].unwrap(), c.size[1].unwrap()];
            assert!(
                (x - 1.25e-6).abs() < 1e-18 && (y - 2e-6).abs() < 1e-18,
                "{x} {y}"
            );
        }
    }

    #[test]
    fn a_corrupt_datx_is_refused_without_a_panic() {
        for name in ["datx-vlen.datx", "datx-fixed.datx"] {
            let bytes = file(name);
            // Flips anywhere but the last byte (a cut at the full length is no cut).
            let (header, budget) = (bytes.len() - 1, Duration::from_millis(1500));
            assert_robust(&bytes, hdf5::sniff, hdf5::read, header, Some(8), budget);
        }
    }
}
