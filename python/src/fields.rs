//! NetCDF field files (`.nc`): what Python's `save("….nc")` writes and `asperity.load`
//! reads, through the library's `asperity::fields` and the front-end layer's descriptions
//! of each quantity (`asperity_app::fields`), the ones `asperity bem --fields FILE.nc`
//! writes.

use std::path::PathBuf;

use asperity::fields::{FieldFile, Values};
use asperity_app::fields::{FieldsBuilder, Placement, Units};
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::errors::{from_error, invalid};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(write_fields, m)?)?;
    m.add_function(wrap_pyfunction!(read_fields, m)?)?;
    Ok(())
}

/// A Python array as the file's values: bool (a flag), int32 (integers) or float64.
fn values(array: &Bound<'_, PyAny>) -> PyResult<Values> {
    if let Ok(a) = array.extract::<PyReadonlyArrayDyn<'_, bool>>() {
        return Ok(Values::Flag(a.as_array().iter().copied().collect()));
    }
    if let Ok(a) = array.extract::<PyReadonlyArrayDyn<'_, i32>>() {
        return Ok(Values::Integer(a.as_array().iter().copied().collect()));
    }
    let a = array.extract::<PyReadonlyArrayDyn<'_, f64>>()?;
    Ok(Values::Real(a.as_array().iter().copied().collect()))
}

fn placement(text: &str) -> PyResult<Placement<'_>> {
    Ok(match text {
        "load" => Placement::Load,
        "map" => Placement::Map,
        "load_map" => Placement::LoadMap,
        other => match other.strip_prefix("along:") {
            Some(dim) => Placement::Along(dim),
            None => return Err(invalid(format!("unknown placement {other}"))),
        },
    })
}

/// Writes a NetCDF field file atomically: `grid` ((rows, cols), (size, size_y)) or None,
/// `units` (metres, pascals known), the `title`, the `record` (JSON text: what produced
/// it) and the variables (name, placement: `load`, `map`, `load_map` or `along:DIM`,
/// array: bool, int32 or float64).
#[pyfunction]
#[pyo3(signature = (path, grid, units, title, record, variables, force))]
#[allow(clippy::too_many_arguments)]
fn write_fields(
    py: Python<'_>,
    path: PathBuf,
    grid: Option<((usize, usize), (f64, f64))>,
    units: (bool, bool),
    title: &str,
    record: &str,
    variables: Vec<(String, String, Bound<'_, PyAny>)>,
    force: bool,
) -> PyResult<()> {
    let record: serde_json::Value =
        serde_json::from_str(record).map_err(|e| invalid(format!("the record: {e}")))?;
    let units = Units {
        metres: units.0,
        pascals: units.1,
    };
    let mut file = FieldsBuilder::new(grid, units, title, &record);
    for (name, place, array) in &variables {
        file.add(name, placement(place)?, values(array)?);
    }
    let file = file.finish();
    py.detach(|| file.write(&path, force)).map_err(from_error)
}

/// Reads a NetCDF field file: (global attributes as (name, text) pairs, the grid
/// (rows, cols, size, size_y, units) or None, the variables as (name, dims, long_name,
/// units, comment, array shaped by the dims)).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn read_fields<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(
    Vec<(String, String)>,
    Option<(usize, usize, f64, f64, Option<String>)>,
    Bound<'py, PyList>,
)> {
    let file = py.detach(|| FieldFile::read(&path)).map_err(from_error)?;
    let lengths = |dims: &[String]| -> Vec<usize> {
        dims.iter()
            .map(|d| match (&file.grid, d.as_str()) {
                (Some(g), "y") => g.rows,
                (Some(g), "x") => g.cols,
                _ => file.dims.iter().find(|e| &e.0 == d).map_or(0, |e| e.1),
            })
            .collect()
    };
    let out = PyList::empty(py);
    for v in &file.variables {
        let shape = lengths(&v.dims);
        let array: Bound<'py, PyAny> = match &v.values {
            Values::Real(x) => x.clone().into_pyarray(py).reshape(shape)?.into_any(),
            Values::Integer(x) => x.clone().into_pyarray(py).reshape(shape)?.into_any(),
            Values::Flag(x) => x.clone().into_pyarray(py).reshape(shape)?.into_any(),
        };
        out.append((
            &v.name,
            v.dims.clone(),
            &v.long_name,
            v.units.clone(),
            v.comment.clone(),
            array,
        ))?;
    }
    let grid = file
        .grid
        .as_ref()
        .map(|g| (g.rows, g.cols, g.size, g.size_y, g.units.clone()));
    Ok((file.attributes.clone(), grid, out))
}
