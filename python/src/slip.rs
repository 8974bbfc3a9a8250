//! Partial slip of an MDR indenter (`asperity mdr --tangential-force`): the cycle of
//! [`asperity_app::slip::SlipRequest`], the one the CLI runs, as columns.

use asperity::mdr::Spring;
use asperity_app::mdr::{Indenter, MdrRequest};
use asperity_app::slip::SlipRequest;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::owned_1d;
use crate::errors::{from_error, refused, request_error};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mdr_slip, m)?)?;
    Ok(())
}

/// The tangential cycle as columns, with the cycle's summary (JSON text); `request` is the
/// indenter's [`MdrRequest`] as JSON.
#[pyfunction]
#[pyo3(signature = (request, line, radial, tangential_force, friction, poisson, cycle_points))]
fn mdr_slip<'py>(
    py: Python<'py>,
    request: &str,
    line: Option<PyReadonlyArray1<'py, f64>>,
    radial: Option<PyReadonlyArray1<'py, f64>>,
    tangential_force: f64,
    friction: Option<f64>,
    poisson: f64,
    cycle_points: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut mdr: MdrRequest = serde_json::from_str(request)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(format!("mdr request: {e}")))?;
    mdr.line = line.is_some();
    mdr.radial = radial.is_some();
    let slip = SlipRequest {
        poisson,
        friction,
        tangential_force,
        cycle_points,
    };
    mdr.check().map_err(refused)?;
    slip.check(&mdr).map_err(request_error)?;
    let indenter = match (&line, &radial) {
        (Some(line), _) => {
            let heights = owned_1d(line).to_vec();
            Indenter::line(heights, mdr.size.unwrap_or(1.0), "").map_err(refused)?
        }
        (None, Some(radial)) => {
            let samples = owned_1d(radial);
            let samples = samples.as_slice().expect("contiguous");
            mdr.radial(samples, "").map_err(request_error)?
        }
        (None, None) => mdr.closed_form().map_err(request_error)?,
    };
    let law = mdr.spring_law(&indenter).map_err(refused)?;
    let spring = Spring::new(law, indenter.spacing, mdr.modulus).map_err(from_error)?;
    let cycle = slip.run(&mdr, &indenter, spring).map_err(request_error)?;
    let dict = PyDict::new(py);
    let points = &cycle.points;
    let names: Vec<&str> = points.iter().map(|p| p.branch.name()).collect();
    dict.set_item("branch", names)?;
    let column = |f: &dyn Fn(usize) -> f64| PyArray1::from_iter(py, (0..points.len()).map(f));
    dict.set_item("tangential_displacement", column(&|i| points[i].displacement))?;
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
