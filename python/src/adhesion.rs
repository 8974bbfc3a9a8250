//! Python's `bem_adhesion()`: the pixel criterion along a path then retracted to pull-off,
//! by the front-end layer's one request (`asperity_app::adhesion`), the one `asperity bem
//! --work-of-adhesion` runs: the same rules, columns and numbers.

use asperity::surface::Surface;
use asperity_app::adhesion::{AdhesionRequest, AdhesionRow, AdhesionRun};
use asperity_app::contact::{ContactRequest, Value};
use asperity_app::contact_adhesion as si;
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::owned_2d;
use crate::errors::{from_error, from_solve, refused};
use crate::interrupt::run_detached;

/// `contact(work_of_adhesion=…)`: the request's adhesive plan (`asperity contact
/// --work-of-adhesion`'s rules), run as the CLI runs it; the CLI's SI columns, both
/// pull-offs (N, m), `σ_c` (Pa), the warning and E*.
pub fn contact_adhesion<'py>(
    py: Python<'py>,
    request: &ContactRequest,
    heights: &PyReadonlyArray2<'_, f64>,
    (size_x, size_y): (f64, Option<f64>),
) -> PyResult<Bound<'py, PyDict>> {
    let plan = request.adhesion_plan().map_err(refused)?;
    let modulus = plan.half_space.modulus;
    let owned = owned_2d(heights);
    let surface = match size_y {
        Some(size_y) => Surface::with_sizes(owned, size_x, size_y),
        None => Surface::new(owned, size_x),
    }
    .map_err(from_error)?;
    let points = surface.dim().0 * surface.dim().1;
    let pixel_area = surface.spacing() * surface.spacing_y();
    let run = run_detached(py, move |_| plan.run(&surface, &mut |_| {}))?.map_err(from_solve)?;
    let dict = PyDict::new(py);
    let rows: Vec<[Value; 8]> = run
        .rows
        .iter()
        .map(|r| si::values(r, pixel_area, points))
        .collect();
    for (k, name) in si::COLUMNS[..8].iter().enumerate() {
        match rows.first().map(|r| r[k]) {
            Some(Value::Count(_)) => {
                let counts = rows.iter().map(|r| match r[k] {
                    Value::Count(n) => n as u64,
                    Value::Number(x) => x as u64,
                });
                dict.set_item(name, PyArray1::from_iter(py, counts))?
            }
            _ => {
                let numbers = rows.iter().map(|r| match r[k] {
                    Value::Number(x) => x,
                    Value::Count(n) => n as f64,
                });
                dict.set_item(name, PyArray1::from_iter(py, numbers))?
            }
        }
    }
    let branches: Vec<&str> = run.rows.iter().map(|r| r.branch.name()).collect();
    dict.set_item("branch", branches)?;
    dict.set_item("pull_off", pull_offs(py, &run)?)?;
    dict.set_item("critical_stress", run.critical_stress)?;
    dict.set_item("warning", run.resolution_warning())?;
    dict.set_item("effective_modulus", modulus)?;
    Ok(dict)
}

/// Both pull-offs of a run (`None`: nothing attached at the end of the path).
fn pull_offs<'py>(py: Python<'py>, run: &AdhesionRun) -> PyResult<Option<Bound<'py, PyDict>>> {
    let Some(p) = run.pull_off else {
        return Ok(None);
    };
    let point =
        |s: &asperity::bem::adhesion::AdhesiveSummary| (s.force, s.indentation, s.attached_points);
    let d = pull_off_dict(
        py,
        "attached_points",
        point(&p.force_controlled),
        point(&p.displacement_controlled),
    )?;
    d.set_item("separated_at", p.separated_at)?;
    Ok(Some(d))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(bem_adhesion, m)?)?;
    Ok(())
}

/// The columns of `asperity bem --work-of-adhesion` for heights `array` of sizes `size_x`
/// and `size_y` (`None`: square pixels), with both pull-offs and `σ_c`.
#[pyfunction]
#[pyo3(signature = (array, size_x, size_y, modulus, boundary, work_of_adhesion, indentations, retract_step, adhesion_range=None, adhesion_model=None))]
#[allow(clippy::too_many_arguments)]
fn bem_adhesion<'py>(
    py: Python<'py>,
    array: PyReadonlyArray2<'_, f64>,
    size_x: f64,
    size_y: Option<f64>,
    modulus: f64,
    boundary: String,
    work_of_adhesion: f64,
    indentations: Vec<f64>,
    retract_step: Option<f64>,
    adhesion_range: Option<f64>,
    adhesion_model: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = AdhesionRequest {
        modulus,
        boundary,
        work_of_adhesion,
        adhesion_range,
        adhesion_model,
        indentations,
        retract_step,
    };
    let plan = request.validate().map_err(refused)?;
    let owned = owned_2d(&array);
    let surface = match size_y {
        Some(size_y) => Surface::with_sizes(owned, size_x, size_y),
        None => Surface::new(owned, size_x),
    }
    .map_err(from_error)?;
    let points = (surface.dim().0 * surface.dim().1) as f64;
    let run = run_detached(py, move |_| plan.run(&surface, &mut |_| {}))?.map_err(from_solve)?;
    let dict = PyDict::new(py);
    let rows = &run.rows;
    let column = |f: &dyn Fn(&AdhesionRow) -> f64| PyArray1::from_iter(py, rows.iter().map(f));
    dict.set_item("indentation", column(&|r| r.summary.indentation))?;
    dict.set_item("force", column(&|r| r.summary.force))?;
    dict.set_item("mean_pressure", column(&|r| r.summary.mean_pressure))?;
    dict.set_item("area_fraction", column(&|r| r.summary.area_fraction))?;
    dict.set_item(
        "tensile_fraction",
        column(&|r| r.summary.tensile_points as f64 / points),
    )?;
    let count = |f: &dyn Fn(&AdhesionRow) -> usize| {
        PyArray1::from_iter(py, rows.iter().map(|r| f(r) as u64))
    };
    dict.set_item("rounds", count(&|r| r.info.rounds))?;
    dict.set_item("cg_iterations", count(&|r| r.info.cg_iterations))?;
    let branches: Vec<&str> = rows.iter().map(|r| r.branch.name()).collect();
    dict.set_item("branch", branches)?;
    dict.set_item("pull_off", pull_offs(py, &run)?)?;
    dict.set_item("critical_stress", run.critical_stress)?;
    dict.set_item("warning", run.resolution_warning())?;
    Ok(dict)
}

/// The pull-offs of an adhesive run as Python returns them (`bem_adhesion`, `mdr` with a
/// work of adhesion): `force_controlled` and `displacement_controlled`, each a dict of
/// `force`, `indentation` and the count of attached points or springs named `count`.
pub fn pull_off_dict<'py>(
    py: Python<'py>,
    count: &str,
    force_controlled: (f64, f64, usize),
    displacement_controlled: (f64, f64, usize),
) -> PyResult<Bound<'py, PyDict>> {
    let point = |(force, indentation, attached): (f64, f64, usize)| -> PyResult<_> {
        let d = PyDict::new(py);
        d.set_item("force", force)?;
        d.set_item("indentation", indentation)?;
        d.set_item(count, attached)?;
        Ok(d)
    };
    let d = PyDict::new(py);
    d.set_item("force_controlled", point(force_controlled)?)?;
    d.set_item("displacement_controlled", point(displacement_controlled)?)?;
    Ok(d)
}
