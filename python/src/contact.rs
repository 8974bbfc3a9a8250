//! `asperity.contact`: the CLI's `asperity contact` (a surface in SI units pressed into an
//! elastic half-space at a list of mean pressures), run by the front-end layer
//! ([`asperity_app::contact`]) as the CLI runs it: the same request, rules and sweep.

use asperity::bem::sweep::{SweepError, SweepFailure};
use asperity::bem::ContactSolver;
use asperity::memory::array_bytes;
use asperity::surface::Surface;
use asperity::topography::patches;
use asperity_app::bem::ensure_solver_fits;
use asperity_app::contact::{self as app, ContactRequest, Value};
use asperity_app::refusal::{positive, Param};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::owned_2d;
use crate::bem::with_context;
use crate::errors::{from_error, from_solve, invalid, refused};
use crate::interrupt::{run_detached, run_detached_with};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(contact, m)?)?;
    m.add_function(wrap_pyfunction!(effective_modulus, m)?)?;
    m.add_function(wrap_pyfunction!(label_patches, m)?)?;
    Ok(())
}

/// E* by the front-end layer's one rule (`asperity contact`'s): the modulus itself, or
/// `E/(1 − ν²)` from Young's modulus and Poisson's ratio.
#[pyfunction]
#[pyo3(signature = (modulus, young, poisson))]
fn effective_modulus(
    modulus: Option<f64>,
    young: Option<Vec<f64>>,
    poisson: Option<Vec<f64>>,
) -> PyResult<f64> {
    let young = young.unwrap_or_default();
    let poisson = poisson.unwrap_or_default();
    app::modulus_of(modulus, &young, &poisson).map_err(refused)
}

/// The 4-connected contact patches of a contact set (`asperity::topography::patches`, the
/// rule of `asperity contact`'s `patches` column): a label per point (0: no contact), each
/// patch's number of points and its area at `pixel_area` a point (positive and finite, by
/// the front-end layer's rule; a keyword of Python's alone: the CLI's column takes the
/// grid's pixel).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn label_patches<'py>(
    py: Python<'py>,
    set: PyReadonlyArray2<'py, bool>,
    pixel_area: f64,
) -> PyResult<(
    Bound<'py, PyArray2<u32>>,
    Bound<'py, PyArray1<u64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    const PIXEL_AREA: Param = Param::new("pixel_area", "pixel_area");
    let area = positive(PIXEL_AREA, pixel_area).map_err(refused)?;
    let (labels, sizes) = patches::label_patches(set.as_array());
    let areas = PyArray1::from_iter(py, sizes.iter().map(|&n| n as u64 as f64 * area));
    let sizes = PyArray1::from_iter(py, sizes.into_iter().map(|n| n as u64));
    Ok((labels.into_pyarray(py), sizes, areas))
}

/// An adhesive run's options: Δγ (J/m²), the range (m), the law, the path (m), the step (m).
type Adhesion = (
    Option<f64>,
    Option<f64>,
    Option<String>,
    Vec<f64>,
    Option<f64>,
);

/// The request's rules, then the sweep (or with `adhesion` the adhesive run); returns the
/// CLI's columns (and the contact set of the last load with `map`); with `load_path`, the
/// rules alone (None: `_api._contact_path` walks the path on `Solver.load_path`).
#[pyfunction]
#[pyo3(signature = (heights, size_x, size_y, pressures, modulus, young, poisson, boundary, tolerance, map, resistivity=None, thermal_conductivity=None, hardness=None, tangential=false, directions=None, progress=None, adhesion=None, load_path=false))]
#[allow(clippy::too_many_arguments)]
fn contact<'py>(
    py: Python<'py>,
    heights: PyReadonlyArray2<'_, f64>,
    size_x: f64,
    size_y: Option<f64>,
    pressures: Vec<f64>,
    modulus: Option<f64>,
    young: Option<Vec<f64>>,
    poisson: Option<Vec<f64>>,
    boundary: &str,
    tolerance: f64,
    map: bool,
    resistivity: Option<Vec<f64>>,
    thermal_conductivity: Option<Vec<f64>>,
    hardness: Option<f64>,
    tangential: bool,
    directions: Option<String>,
    progress: Option<Py<PyAny>>,
    adhesion: Option<Adhesion>,
    load_path: bool,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let (young, young_2) =
        app::one_or_two(app::params::YOUNG, young.as_deref().unwrap_or(&[])).map_err(refused)?;
    let (poisson, poisson_2) =
        app::one_or_two(app::params::POISSON, poisson.as_deref().unwrap_or(&[]))
            .map_err(refused)?;
    let request = ContactRequest {
        modulus,
        young,
        poisson,
        young_2,
        poisson_2,
        pressures,
        boundary: boundary.into(),
        tolerance,
        resistivity,
        thermal_conductivity,
        hardness,
        tangential,
        directions,
        ..ContactRequest::default()
    };
    let request = match adhesion {
        Some((w, range, model, path, step)) => ContactRequest {
            work_of_adhesion: w,
            adhesion_range: range,
            adhesion_model: model,
            indentations: path,
            retract_step: step,
            ..request
        },
        None => request,
    };
    request
        .refuse_run_options(load_path, map)
        .map_err(refused)?;
    if request.is_adhesive() {
        return crate::adhesion::contact_adhesion(py, &request, &heights, (size_x, size_y))
            .map(Some);
    }
    if load_path {
        // The rules alone: the path itself runs on `Solver.load_path` (`_api._contact_path`).
        return request.validate().map(|_| None).map_err(refused);
    }
    let plan = request.validate().map_err(refused)?;
    let (rows, cols) = heights.as_array().dim();
    ensure_solver_fits(
        rows,
        cols,
        plan.half_space.boundary,
        array_bytes(&[rows, cols], 8),
    )
    .map_err(from_error)?;
    let owned = owned_2d(&heights);
    let surface = match size_y {
        Some(size_y) => Surface::with_sizes(owned, size_x, size_y),
        None => Surface::new(owned, size_x),
    }
    .map_err(from_error)?;
    let pixel_area = surface.spacing() * surface.spacing_y();
    // Set-up is parallel work too: on the calling thread's pool, never rayon's global one
    // (a process forked after it started has it without threads: issue 33, item 9).
    let mut solver = run_detached(py, |_| {
        ContactSolver::new(&surface, plan.half_space, plan.params)
    })?
    .map_err(from_solve)?;
    drop(surface);
    let stop = solver.stop().clone();
    let total = plan.loads.len();
    // `progress(done, total)` before the first load and after each (`asperity contact
    // --progress`); an exception it raises stops the sweep.
    let run = run_detached_with(py, &stop, |cancel| {
        cancel.call(progress.as_ref(), 0, total);
        let mut done = 0;
        let mut on_load = || {
            done += 1;
            cancel.call(progress.as_ref(), done, total);
        };
        app::run(&mut solver, &plan, pixel_area, map, &mut on_load)
    })?
    .map_err(|e: SweepError<_>| match e.explain("fd_stiffness") {
        SweepFailure::Input(source) => from_solve(source),
        SweepFailure::AtLoad { context, source } => with_context(source, &context),
        SweepFailure::StepBeyondFullContact(message) => invalid(message),
        SweepFailure::Stopped(never) => match never {},
    })?;
    let dict = PyDict::new(py);
    for (k, name) in app::columns(&plan).iter().enumerate() {
        let column: Vec<Value> = run
            .rows
            .iter()
            .map(|row| row.all_values(&plan.derived)[k])
            .collect();
        if column.iter().all(|v| matches!(v, Value::Count(_))) {
            let counts = column.iter().map(|v| match *v {
                Value::Count(n) => n as u64,
                Value::Number(_) => unreachable!("a column of counts"),
            });
            dict.set_item(name, PyArray1::from_iter(py, counts))?;
        } else {
            let numbers = column.iter().map(|v| match *v {
                Value::Number(x) => x,
                Value::Count(n) => n as f64,
            });
            dict.set_item(name, PyArray1::from_iter(py, numbers))?;
        }
    }
    if let Some(map) = run.map {
        dict.set_item("map", map.into_pyarray(py))?;
    }
    dict.set_item("effective_modulus", plan.half_space.modulus)?;
    Ok(Some(dict))
}
