//! Contact fields as NetCDF-3 files (`.nc`), the format of climate and ocean data that
//! xarray, scipy, ParaView, Panoply, MATLAB and contact.engineering read.
//!
//! A [`FieldFile`] is a set of named arrays on the surface's grid and on other dimensions
//! (the loads of a sweep, the patches of a contact map) with CF-style attributes
//! (`long_name`, `units` where the unit is known, a `comment` where it is the user's), and
//! global text attributes that carry what produced it. Layout: the map dimensions are `y`
//! (rows) and `x` (columns), C order, as the library's arrays; the coordinate variables
//! `x` and `y` hold each pixel's position `i·Δx` (from 0, `Δx = size / cols`) and carry the
//! side in a `length` attribute, so asperity's topography reader (and contact.engineering)
//! read a 2D field back with its physical size. Written by the pure-Rust `netcdf3` crate
//! (no libnetcdf), in the classic format (`CDF\x01`), or the 64-bit-offset one (`CDF\x02`)
//! above 1 GiB of data; read back by the bounded parser of [`crate::topography`]'s NetCDF
//! reader, so there is one NetCDF reader in the crate.
//!
//! Round trips are exact: float64 values are stored as NetCDF doubles, integers as 32-bit
//! ints, flags (a contact set) as bytes 0/1. Maps must be finite; a variable without a map
//! dimension (a column of a sweep) may hold NaN for "not computed", stored as the
//! NetCDF default fill value (`_FillValue` = 9.969209968386869e36) and read back as NaN.
//! Writes are atomic (one file or none, [`crate::io::write_bytes`]).
//!
//! ```
//! use asperity::fields::{FieldFile, Grid, Values, Variable};
//!
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("fields.nc");
//! let file = FieldFile {
//!     grid: Some(Grid { rows: 2, cols: 3, size: 3e-6, size_y: 2e-6, units: Some("m".into()) }),
//!     dims: vec![],
//!     variables: vec![Variable {
//!         name: "pressure".into(),
//!         dims: vec!["y".into(), "x".into()],
//!         long_name: "contact pressure".into(),
//!         units: Some("Pa".into()),
//!         comment: None,
//!         values: Values::Real(vec![0.0, 1e6, 2e6, 0.0, 0.0, 5e5]),
//!     }],
//!     attributes: vec![("source".into(), "an example".into())],
//! };
//! file.write(&path, false).unwrap();
//! assert_eq!(FieldFile::read(&path).unwrap(), file);
//! ```

use std::cell::RefCell;
use std::io::{Cursor, Seek, SeekFrom, Write};
use std::path::Path;
use std::rc::Rc;

use crate::topography::netcdf::{self, Attr};
use crate::{Error, Result};

/// The value that stands for NaN (not computed) in a variable without a map dimension:
/// NetCDF's default fill value for doubles.
pub const FILL: f64 = netcdf3::NC_FILL_F64;

/// The global attribute the writer adds (first) and the reader takes away.
const CONVENTIONS: (&str, &str) = ("Conventions", "CF-1.8");

/// Above this many bytes of data the 64-bit-offset variant is written.
const CLASSIC_LIMIT: usize = 1 << 30;

/// The values of a variable, row-major over its dimensions.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Float64 (NetCDF `double`).
    Real(Vec<f64>),
    /// 32-bit integers (NetCDF `int`), e.g. patch labels.
    Integer(Vec<i32>),
    /// True/false (NetCDF `byte` 1/0, with CF `flag_values`), e.g. a contact set.
    Flag(Vec<bool>),
}

impl Values {
    /// How many values.
    #[allow(clippy::len_without_is_empty)]
    pub fn len(&self) -> usize {
        match self {
            Values::Real(v) => v.len(),
            Values::Integer(v) => v.len(),
            Values::Flag(v) => v.len(),
        }
    }
}

/// A named array with its dimensions and CF attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Its name (NetCDF rules: a letter or `_`, then letters, digits, `_.@+-`).
    pub name: String,
    /// Its dimensions, slowest first: `["y", "x"]` for a map, `["load", "y", "x"]` for a
    /// map per load, any dimension of [`FieldFile::dims`].
    pub dims: Vec<String>,
    /// CF `long_name`: what it is, in words.
    pub long_name: String,
    /// CF `units` (UDUNITS: `m`, `Pa`, `N`, `N/m`, `1`), where the unit is known.
    pub units: Option<String>,
    /// CF `comment`: e.g. the unit where it is the user's (`in the units of the heights`).
    pub comment: Option<String>,
    /// The values, as many as the product of the dimensions' lengths.
    pub values: Values,
}

/// The surface's grid: dimensions `y` (rows) and `x` (columns) and their coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Points along y.
    pub rows: usize,
    /// Points along x.
    pub cols: usize,
    /// Side along x.
    pub size: f64,
    /// Side along y.
    pub size_y: f64,
    /// The unit of the sides and coordinates (`m`), `None` where it is the user's.
    pub units: Option<String>,
}

/// A NetCDF field file: see the module docs.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FieldFile {
    /// The map's grid, if any variable lies on it.
    pub grid: Option<Grid>,
    /// Other dimensions (name, length ≥ 1), e.g. `("load", 8)`.
    pub dims: Vec<(String, usize)>,
    /// The variables, in the order written.
    pub variables: Vec<Variable>,
    /// Global text attributes (name, value), in order: what produced the file.
    pub attributes: Vec<(String, String)>,
}

fn invalid(reason: impl Into<String>) -> Error {
    Error::InvalidParameter {
        name: "NetCDF field file",
        reason: reason.into(),
    }
}

fn bad(reason: impl Into<String>) -> Error {
    crate::topography::bytes::bad("netcdf", reason)
}

/// `true` for a path that names a NetCDF file (`.nc`, any case).
pub fn is_netcdf_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("nc"))
}

impl FieldFile {
    /// Every dimension: `y`, `x` (with a grid), then [`FieldFile::dims`].
    fn all_dims(&self) -> Vec<(String, usize)> {
        let grid = self
            .grid
            .iter()
            .flat_map(|g| [("y".to_string(), g.rows), ("x".to_string(), g.cols)]);
        grid.chain(self.dims.iter().cloned()).collect()
    }

    /// Checks names, lengths, sizes and values before anything is written.
    fn check(&self) -> Result<()> {
        if let Some(g) = &self.grid {
            if g.rows == 0 || g.cols == 0 {
                return Err(invalid("the grid has no point"));
            }
            if !crate::is_positive_finite(g.size) || !crate::is_positive_finite(g.size_y) {
                return Err(invalid(format!(
                    "the sides must be positive and finite, got {} × {}",
                    crate::input::short_number(g.size),
                    crate::input::short_number(g.size_y)
                )));
            }
        }
        let dims = self.all_dims();
        for (name, len) in &self.dims {
            if *len == 0 {
                return Err(invalid(format!("dimension {name} has length 0")));
            }
        }
        let mut vars: Vec<&str> = self.grid.iter().flat_map(|_| ["x", "y"]).collect();
        vars.extend(self.variables.iter().map(|v| v.name.as_str()));
        for names in [dims.iter().map(|d| d.0.as_str()).collect(), vars] {
            for (k, name) in names.iter().enumerate() {
                if !netcdf3::is_valid_name(name) {
                    return Err(invalid(format!("{name:?} is not a valid NetCDF name")));
                }
                if names[..k].contains(name) {
                    return Err(invalid(format!("{name} is named twice")));
                }
            }
        }
        for (key, _) in &self.attributes {
            if !netcdf3::is_valid_name(key) || key == CONVENTIONS.0 {
                return Err(invalid(format!(
                    "global attribute {key:?} cannot be written"
                )));
            }
        }
        self.variables
            .iter()
            .try_for_each(|v| check_variable(v, &dims))
    }

    /// The file's bytes (see the module docs).
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        self.check()?;
        let set = self.data_set().map_err(|e| invalid(e.to_string()))?;
        let data: usize = self.variables.iter().map(|v| v.values.len() * 8).sum();
        let version = if data < CLASSIC_LIMIT {
            netcdf3::Version::Classic
        } else {
            netcdf3::Version::Offset64Bit
        };
        let buffer = SharedBuffer::default();
        let mut writer =
            netcdf3::FileWriter::open_seek_write("fields.nc", Box::new(buffer.clone()))
                .map_err(|e| invalid(format!("{e:?}")))?;
        writer
            .set_def(&set, version, 0)
            .map_err(|e| invalid(format!("{e:?}")))?;
        self.write_data(&mut writer)
            .map_err(|e| invalid(format!("{e:?}")))?;
        writer.close().map_err(|e| invalid(format!("{e:?}")))?;
        Ok(buffer.take())
    }

    /// The header: dimensions, coordinate variables, variables and their attributes.
    fn data_set(&self) -> std::result::Result<netcdf3::DataSet, netcdf3::InvalidDataSet> {
        let mut set = netcdf3::DataSet::new();
        for (name, len) in self.all_dims() {
            set.add_fixed_dim(&name, len)?;
        }
        set.add_global_attr_string(CONVENTIONS.0, CONVENTIONS.1)?;
        for (key, value) in &self.attributes {
            set.add_global_attr_string(key, value)?;
        }
        if let Some(g) = &self.grid {
            for (axis, size) in [("x", g.size), ("y", g.size_y)] {
                set.add_var_f64(axis, &[axis])?;
                set.add_var_attr_string(axis, "long_name", format!("position along {axis}"))?;
                set.add_var_attr_string(
                    axis,
                    "standard_name",
                    format!("projection_{axis}_coordinate"),
                )?;
                set.add_var_attr_string(axis, "axis", axis.to_uppercase())?;
                if let Some(u) = &g.units {
                    set.add_var_attr_string(axis, "units", u)?;
                }
                set.add_var_attr_f64(axis, "length", vec![size])?;
            }
        }
        for v in &self.variables {
            let dims: Vec<&str> = v.dims.iter().map(String::as_str).collect();
            match &v.values {
                Values::Real(_) => set.add_var_f64(&v.name, &dims)?,
                Values::Integer(_) => set.add_var_i32(&v.name, &dims)?,
                Values::Flag(_) => set.add_var_i8(&v.name, &dims)?,
            }
            set.add_var_attr_string(&v.name, "long_name", &v.long_name)?;
            if let Some(u) = &v.units {
                set.add_var_attr_string(&v.name, "units", u)?;
            }
            if let Some(c) = &v.comment {
                set.add_var_attr_string(&v.name, "comment", c)?;
            }
            match &v.values {
                Values::Real(x) if x.iter().any(|x| x.is_nan()) => {
                    set.add_var_attr_f64(&v.name, "_FillValue", vec![FILL])?
                }
                Values::Flag(_) => {
                    set.add_var_attr_i8(&v.name, "flag_values", vec![0, 1])?;
                    set.add_var_attr_string(&v.name, "flag_meanings", "false true")?;
                }
                _ => {}
            }
        }
        Ok(set)
    }

    fn write_data(
        &self,
        writer: &mut netcdf3::FileWriter<'_>,
    ) -> std::result::Result<(), netcdf3::WriteError> {
        if let Some(g) = &self.grid {
            for (axis, n, size) in [("x", g.cols, g.size), ("y", g.rows, g.size_y)] {
                let step = size / n as f64;
                let positions: Vec<f64> = (0..n).map(|i| i as f64 * step).collect();
                writer.write_var_f64(axis, &positions)?;
            }
        }
        for v in &self.variables {
            match &v.values {
                Values::Real(x) => {
                    let filled: Vec<f64> = x
                        .iter()
                        .map(|&x| if x.is_nan() { FILL } else { x })
                        .collect();
                    writer.write_var_f64(&v.name, &filled)?
                }
                Values::Integer(x) => writer.write_var_i32(&v.name, x)?,
                Values::Flag(x) => {
                    let bytes: Vec<i8> = x.iter().map(|&b| i8::from(b)).collect();
                    writer.write_var_i8(&v.name, &bytes)?
                }
            }
        }
        Ok(())
    }

    /// Writes the file atomically (refusing an existing one unless `force`).
    pub fn write(&self, path: &Path, force: bool) -> Result<()> {
        let bytes = self.to_bytes()?;
        crate::io::write_bytes(path, force, &bytes)
    }

    /// Reads a file written by [`FieldFile::write`] (or any NetCDF classic file laid out
    /// so: see the module docs), refusing anything else in one line.
    pub fn read(path: &Path) -> Result<Self> {
        let (file, len) = crate::input::open_regular(path)?;
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(&mut std::io::Read::take(file, len), &mut bytes)
            .map_err(|e| Error::io(path, e))?;
        Self::from_bytes(&bytes).map_err(|e| Error::BadInput {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
    }

    /// Parses the bytes of a field file (see [`FieldFile::read`]).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let header = netcdf::header(bytes)?;
        let mut attributes = Vec::new();
        for (key, value) in &header.attrs {
            match value {
                Attr::Text(t) if key == CONVENTIONS.0 => {
                    if t != CONVENTIONS.1 {
                        return Err(bad(format!(
                            "Conventions {t:?}, not {:?}: not a field file",
                            CONVENTIONS.1
                        )));
                    }
                }
                Attr::Text(t) => attributes.push((key.clone(), t.clone())),
                Attr::Numbers(_) => return Err(bad(format!("global attribute {key} is not text"))),
            }
        }
        if !header.attrs.iter().any(|(k, _)| k == CONVENTIONS.0) {
            return Err(bad("no Conventions attribute: not a field file"));
        }
        let grid = read_grid(&header)?;
        let dims = header
            .dims
            .iter()
            .filter(|(n, _)| grid.is_none() || (n != "x" && n != "y"))
            .cloned()
            .collect();
        let mut variables = Vec::new();
        for v in &header.vars {
            if grid.is_some() && (v.name == "x" || v.name == "y") {
                continue;
            }
            variables.push(read_variable(bytes, &header, v)?);
        }
        Ok(FieldFile {
            grid,
            dims,
            variables,
            attributes,
        })
    }
}

/// A variable's dimensions exist, its values fill them, and its numbers are allowed.
fn check_variable(v: &Variable, dims: &[(String, usize)]) -> Result<()> {
    let mut count = 1usize;
    for d in &v.dims {
        let len = dims
            .iter()
            .find(|(n, _)| n == d)
            .map(|(_, len)| *len)
            .ok_or_else(|| invalid(format!("{}: no dimension {d}", v.name)))?;
        count = count.saturating_mul(len);
    }
    if v.dims.is_empty() || count != v.values.len() {
        return Err(invalid(format!(
            "{}: {} values for dimensions {:?} ({count})",
            v.name,
            v.values.len(),
            v.dims
        )));
    }
    let Values::Real(x) = &v.values else {
        return Ok(());
    };
    let on_map = v.dims.iter().any(|d| d == "x" || d == "y");
    let has_nan = x.iter().any(|x| x.is_nan());
    if let Some(index) = x
        .iter()
        .position(|&x| x.is_infinite() || (on_map && x.is_nan()) || (has_nan && x == FILL))
    {
        return Err(Error::NonFinite {
            what: format!("field {}", v.name),
            index,
            value: x[index],
        });
    }
    Ok(())
}

/// The grid, from the dimensions `y`, `x` and their coordinate variables' `length`.
fn read_grid(header: &netcdf::Header) -> Result<Option<Grid>> {
    let dim = |name: &str| header.dims.iter().find(|d| d.0 == name).map(|d| d.1);
    let (Some(rows), Some(cols)) = (dim("y"), dim("x")) else {
        return Ok(None);
    };
    let coord = |name: &str| {
        header
            .vars
            .iter()
            .find(|v| v.name == name && v.dims.len() == 1)
            .ok_or_else(|| bad(format!("no coordinate variable {name}")))
    };
    let (x, y) = (coord("x")?, coord("y")?);
    let length = |v: &netcdf::Variable| {
        v.number("length")
            .filter(|l| crate::is_positive_finite(*l))
            .ok_or_else(|| bad(format!("coordinate {} has no positive length", v.name)))
    };
    Ok(Some(Grid {
        rows,
        cols,
        size: length(x)?,
        size_y: length(y)?,
        units: x.text("units").map(str::to_string),
    }))
}

fn read_variable(bytes: &[u8], header: &netcdf::Header, v: &netcdf::Variable) -> Result<Variable> {
    let shape = netcdf::shape(&header.dims, v)?;
    let raw = netcdf::values(bytes, v, &shape)?;
    let values = match v.kind {
        6 => {
            let fill = v.number("_FillValue");
            Values::Real(
                raw.into_iter()
                    .map(|x| if Some(x) == fill { f64::NAN } else { x })
                    .collect(),
            )
        }
        4 => Values::Integer(raw.into_iter().map(|x| x as i32).collect()),
        1 => {
            if let Some(x) = raw.iter().find(|&&x| x != 0.0 && x != 1.0) {
                return Err(bad(format!("flag {} holds {x}, not 0 or 1", v.name)));
            }
            Values::Flag(raw.into_iter().map(|x| x == 1.0).collect())
        }
        kind => {
            return Err(bad(format!(
                "variable {}: type {kind} is not written here",
                v.name
            )))
        }
    };
    let dims = v.dims.iter().map(|&d| header.dims[d].0.clone()).collect();
    Ok(Variable {
        name: v.name.clone(),
        dims,
        long_name: v.text("long_name").unwrap_or_default().to_string(),
        units: v.text("units").map(str::to_string),
        comment: v.text("comment").map(str::to_string),
        values,
    })
}

/// An in-memory file the `netcdf3` writer seeks in, shared so the bytes can be taken
/// after the writer is closed.
#[derive(Clone, Default)]
struct SharedBuffer(Rc<RefCell<Cursor<Vec<u8>>>>);

impl SharedBuffer {
    fn take(&self) -> Vec<u8> {
        std::mem::take(self.0.borrow_mut().get_mut())
    }
}

impl Write for SharedBuffer {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Seek for SharedBuffer {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.0.borrow_mut().seek(pos)
    }
}

#[cfg(test)]
mod tests;
