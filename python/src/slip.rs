//! Partial slip of an MDR indenter (`asperity mdr --tangential-force`): the cycle of
//! [`asperity_app::slip::SlipRequest`], the one the CLI runs, as columns.

use asperity::mdr::Spring;
use asperity_app::slip::{SlipRequest, DEFAULT_POISSON};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{from_error, refused, request_error};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mdr_slip, m)?)?;
    Ok(())
}

/// The tangential cycle as columns, with the cycle's summary (JSON text); `request`: the
/// keywords of the indenter's `MdrRequest` ([`crate::mdr::request`]).
#[pyfunction]
#[pyo3(signature = (request, line, radial, tangential_force, friction, poisson, cycle_points))]
#[allow(clippy::too_many_arguments)]
fn mdr_slip<'py>(
    py: Python<'py>,
    request: &Bound<'py, PyDict>,
    line: Option<PyReadonlyArray1<'py, f64>>,
    radial: Option<PyReadonlyArray1<'py, f64>>,
    tangential_force: f64,
    friction: Option<f64>,
    poisson: Option<f64>,
    cycle_points: Option<i128>,
) -> PyResult<Bound<'py, PyDict>> {
    let mdr = crate::mdr::request(request, &line, &radial)?;
    let slip = SlipRequest {
        poisson: poisson.unwrap_or(DEFAULT_POISSON),
        friction,
        tangential_force,
        cycle_points,
    };
    mdr.check().map_err(refused)?;
    slip.check(&mdr).map_err(request_error)?;
    let indenter = crate::mdr::indenter(&mdr, &line, &radial)?;
    let law = mdr.spring_law(&indenter).map_err(refused)?;
    let spring = Spring::new(law, indenter.spacing, mdr.modulus).map_err(from_error)?;
    let cycle = slip.run(&mdr, &indenter, spring).map_err(request_error)?;
    let dict = PyDict::new(py);
    let points = &cycle.points;
    let names: Vec<&str> = points.iter().map(|p| p.branch.name()).collect();
    dict.set_item("branch", names)?;
    let column = |f: &dyn Fn(usize) -> f64| PyArray1::from_iter(py, (0..points.len()).map(f));
    dict.set_item(
        "tangential_displacement",
        column(&|i| points[i].displacement),
    )?;
    dict.set_item("tangential_force", column(&|i| points[i].force))?;
    dict.set_item(
        "stick_springs",
        PyArray1::from_iter(py, points.iter().map(|p| p.stick_springs as u64)),
    )?;
    if let Some(radius) = &cycle.stick_radius {
        dict.set_item("stick_radius", PyArray1::from_slice(py, radius))?;
    }
    dict.set_item("summary", cycle.summary().to_string())?;
    dict.set_item("description", indenter.description)?;
    Ok(dict)
}
