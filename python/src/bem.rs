//! The BEM contact solver (`asperity bem`): one planned [`ContactSolver`] per Python
//! `Solver`, reused across loads (warm starts) as the CLI does.
//!
//! A sweep is the library's [`asperity::bem::sweep::sweep`], the loop `asperity bem` runs
//! too (the full-contact check of every load kind before any solve, then per load: solve,
//! frozen-set stiffness, fields, finite-difference stiffness and the re-solve for the next
//! warm start), so a sweep gives the CLI's numbers bit for bit. The solver polls the stop
//! flag that Ctrl-C sets ([`crate::interrupt`]), so one long solve stops too.

use asperity::bem::sweep::{sweep, SweepError, SweepFailure, SweepObserver, SweepParams, SweepRow};
use asperity::bem::{load_path, ContactSolver, Control, Interface, PathPoint, SolveError};
use asperity::elastic::Boundary;
use asperity::memory::array_bytes;
use asperity::surface::Surface;
use asperity_app::bem::params;
use asperity_app::bem::{
    branches, check_capped_loads, check_fd_step, ensure_solver_fits, peak_rss_mib, Loads,
    SolverRequest, TIMING_COLUMNS,
};
use asperity_app::derived::{Derived, Units};
use asperity_app::persson::{bem_mean_gap, SweepPersson, SweepTheory, SWEEP_COLUMNS};
use asperity_app::refusal::count;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::arrays::owned_2d;
use crate::errors::{from_error, from_solve, invalid, refused, request_error};
use crate::interrupt::{run_detached, run_detached_with, Cancel};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Solver>()?;
    m.add_function(wrap_pyfunction!(sweep_loads, m)?)?;
    m.add_function(wrap_pyfunction!(one_load, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_persson, m)?)?;
    Ok(())
}

/// Persson's theory beside a sweep as `(gamma, kappa)`, or None: the front-end layer's
/// rule and defaults ([`SweepPersson::from_options`], `asperity bem --persson`'s).
#[pyfunction]
#[pyo3(signature = (persson, gamma, kappa))]
fn sweep_persson(
    persson: bool,
    gamma: Option<f64>,
    kappa: Option<f64>,
) -> PyResult<Option<(f64, f64)>> {
    let theory = SweepPersson::from_options(persson, gamma, kappa).map_err(refused)?;
    Ok(theory.map(|t| (t.gamma, t.kappa)))
}

/// The load of one solve as `(quantity, value)`: exactly one of the three, by the
/// front-end layer's rule ([`asperity_app::bem::one_load`]); `what` names the method.
#[pyfunction]
#[pyo3(signature = (what, pressure, force, indentation))]
fn one_load(
    what: &str,
    pressure: Option<f64>,
    force: Option<f64>,
    indentation: Option<f64>,
) -> PyResult<(&'static str, f64)> {
    let load = asperity_app::bem::one_load(what, pressure, force, indentation).map_err(refused)?;
    Ok(asperity_app::bem::quantity_of(load))
}

/// The loads of a sweep as `(quantity, values)`: exactly one of the three lists or
/// `nloads` mean pressures log-spaced from `pmin` to `pmax`, checked by the front-end
/// layer's rules (`fields`: every load's fields are kept, for its memory check).
#[pyfunction]
#[pyo3(signature = (forces, pressures, indentations, nloads, pmin, pmax, fields))]
fn sweep_loads(
    forces: Option<Vec<f64>>,
    pressures: Option<Vec<f64>>,
    indentations: Option<Vec<f64>>,
    nloads: Option<i128>,
    pmin: Option<f64>,
    pmax: Option<f64>,
    fields: bool,
) -> PyResult<(&'static str, Vec<f64>)> {
    let nloads = (nloads.map(|n| count(params::NLOADS, n)).transpose()).map_err(refused)?;
    let loads = Loads::from_options(forces, pressures, indentations, nloads, (pmin, pmax))
        .map_err(refused)?;
    let controls = loads.controls(fields).map_err(request_error)?;
    Ok((
        loads.quantity(),
        controls.iter().map(|c| c.value()).collect(),
    ))
}

/// A load as the library's control: `quantity` is `pressure`, `force` or `indentation`
/// (the front-end layer's names, [`asperity_app::bem::load_of`]).
fn control(quantity: &str, value: f64) -> PyResult<Control> {
    asperity_app::bem::load_of(quantity, value).map_err(refused)
}

/// `error` with `context: ` in front (a `SolveError` keeps its type and attributes).
pub(crate) fn with_context(error: SolveError, context: &str) -> PyErr {
    let err = from_solve(error);
    Python::attach(|py| {
        let value = err.value(py);
        let message = value.str().map(|s| s.to_string()).unwrap_or_default();
        let _ = value.setattr("args", (format!("{context}: {message}"),));
    });
    err
}

/// Why a sweep stopped: the cancel flag (Ctrl-C or an exception of the progress
/// callback, raised by `run_detached` instead of this).
struct Cancelled;

/// A sweep's error as a Python exception, with the load as the library's
/// [`SweepError::explain`] names it.
fn sweep_error(error: SweepError<Cancelled>) -> PyErr {
    match error.explain("fd_stiffness") {
        SweepFailure::Input(source) => from_solve(source),
        SweepFailure::AtLoad { context, source } => with_context(source, &context),
        SweepFailure::StepBeyondFullContact(message) => invalid(message),
        SweepFailure::Stopped(Cancelled) => {
            pyo3::exceptions::PyKeyboardInterrupt::new_err("interrupted")
        }
    }
}

/// A sweep's Python side: the fields of every load (when asked for) and the progress
/// callback, which may cancel the sweep between loads.
struct PyObserver<'a> {
    fields: bool,
    pressures: Vec<ndarray::Array2<f64>>,
    gaps: Vec<ndarray::Array2<f64>>,
    mean_gaps: Option<Vec<f64>>,
    progress: Option<&'a Py<PyAny>>,
    cancel: &'a Cancel,
    total: usize,
    /// The peak resident memory after each load (`timing`).
    peak_rss: Option<Vec<f64>>,
}

impl SweepObserver for PyObserver<'_> {
    type Error = Cancelled;

    fn solved(&mut self, _load: usize, solver: &ContactSolver) -> Result<(), Cancelled> {
        if self.fields {
            self.pressures.push(solver.pressure().to_owned());
            self.gaps.push(solver.gap().to_owned());
        }
        if let Some(gaps) = &mut self.mean_gaps {
            gaps.push(bem_mean_gap(solver));
        }
        Ok(())
    }

    fn finished(&mut self, load: usize, _row: &SweepRow) -> Result<(), Cancelled> {
        if let Some(peaks) = &mut self.peak_rss {
            peaks.push(peak_rss_mib().unwrap_or(f64::NAN));
        }
        self.cancel.call(self.progress, load + 1, self.total);
        if self.cancel.is_set() {
            return Err(Cancelled);
        }
        Ok(())
    }
}

/// A reusable BEM contact solver (the compiled core of `asperity.Solver`).
#[pyclass(module = "asperity._asperity")]
pub struct Solver {
    solver: ContactSolver,
    modulus: f64,
    boundary: Boundary,
    size: f64,
}

#[pymethods]
impl Solver {
    #[new]
    #[pyo3(signature = (heights, size_x, size_y, modulus, boundary, tolerance, max_iterations, solver, hardness=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        heights: PyReadonlyArray2<'_, f64>,
        size_x: f64,
        size_y: Option<f64>,
        modulus: f64,
        boundary: &str,
        tolerance: f64,
        max_iterations: i128,
        solver: &str,
        hardness: Option<f64>,
    ) -> PyResult<Self> {
        let request = SolverRequest {
            modulus,
            boundary: boundary.into(),
            solver: solver.into(),
            tolerance,
            max_iterations: count(params::MAX_ITER, max_iterations).map_err(refused)?,
            hardness,
        };
        let plan = request.validate().map_err(refused)?;
        let half_space = plan.half_space;
        let given: Vec<f64> = std::iter::once(size_x).chain(size_y).collect();
        asperity_app::argument::sizes(&given).map_err(refused)?;
        let (rows, cols) = heights.as_array().dim();
        ensure_solver_fits(
            rows,
            cols,
            half_space.boundary,
            array_bytes(&[rows, cols], 8),
        )
        .map_err(from_error)?;
        // A grid below 2×2 is refused by the library's rule (`Surface::new`), as the CLI's
        // surfaces are.
        let owned = owned_2d(&heights);
        let surface = match size_y {
            Some(size_y) => Surface::with_sizes(owned, size_x, size_y),
            None => Surface::new(owned, size_x),
        }
        .map_err(from_error)?;
        let solver = run_detached(py, |_| plan.solver(&surface))?.map_err(from_solve)?;
        Ok(Solver {
            solver,
            modulus,
            boundary: half_space.boundary,
            size: size_x,
        })
    }

    /// `(rows, cols)`.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        self.solver.dim()
    }

    /// Nominal area `rows · cols · Δ²`.
    #[getter]
    fn nominal_area(&self) -> f64 {
        self.solver.nominal_area()
    }

    #[getter]
    fn modulus(&self) -> f64 {
        self.modulus
    }

    #[getter]
    fn boundary(&self) -> &'static str {
        self.boundary.name()
    }

    #[getter]
    fn size(&self) -> f64 {
        self.size
    }

    #[getter]
    fn tolerance(&self) -> f64 {
        self.solver.params().tolerance
    }

    #[getter]
    fn max_iterations(&self) -> usize {
        self.solver.params().max_iterations
    }

    /// `"bccg"` or `"pk"`.
    #[getter]
    fn solver(&self) -> &'static str {
        self.solver.params().solver.name()
    }

    /// The hardness that caps the pressure, or `None` (the hard wall).
    #[getter]
    fn hardness(&self) -> Option<f64> {
        match self.solver.interface() {
            Interface::Hardness { h } => Some(h),
            _ => None,
        }
    }

    /// The permanent displacement kept by load paths so far (zeros before any).
    fn permanent_displacement<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.solver.permanent_displacement().into_pyarray(py)
    }

    /// Forgets the last solution (the next solve starts cold).
    fn reset(&mut self) {
        self.solver.reset();
    }

    /// `(mean_pressure, indentation)` of full contact (see the library's
    /// `full_contact_threshold`; on free boundaries it forgets the warm start).
    fn full_contact_threshold(&mut self, py: Python<'_>) -> PyResult<(f64, Option<f64>)> {
        let (stop, solver) = (self.solver.stop().clone(), &mut self.solver);
        let t = run_detached_with(py, &stop, |_| solver.full_contact_threshold())?
            .map_err(from_solve)?;
        Ok((t.mean_pressure, t.indentation))
    }

    /// One solve; returns the scalars and, with `fields`, pressure, gap, displacement.
    #[pyo3(signature = (quantity, value, fields))]
    fn solve<'py>(
        &mut self,
        py: Python<'py>,
        quantity: &str,
        value: f64,
        fields: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let control = control(quantity, value)?;
        self.check_capped(&[control])?;
        let (stop, solver) = (self.solver.stop().clone(), &mut self.solver);
        // No up-front full-contact check here (the CLI's is for sweeps): the library's
        // solve refuses such a load itself, with the same threshold, and a single solve
        // then costs exactly what the library's does.
        let (summary, info, state) = run_detached_with(py, &stop, |_| {
            let (summary, info) = solver.solve(control)?;
            let state = if fields { solver.state() } else { None };
            let plastic = match solver.interface() {
                Interface::HardWall => None,
                _ => solver.plastic_displacement().filter(|_| fields),
            };
            Ok::<_, SolveError>((summary, info, state.map(|s| (s, plastic))))
        })?
        .map_err(from_solve)?;
        let dict = PyDict::new(py);
        dict.set_item("force", summary.force)?;
        dict.set_item("mean_pressure", summary.mean_pressure)?;
        dict.set_item("indentation", summary.indentation)?;
        dict.set_item("area_fraction", summary.area_fraction)?;
        dict.set_item("contact_points", summary.contact_points)?;
        dict.set_item("plastic_fraction", summary.plastic_fraction)?;
        dict.set_item("plastic_points", summary.plastic_points)?;
        dict.set_item("iterations", info.iterations)?;
        dict.set_item("residual", info.residual)?;
        if let Some((state, plastic)) = state {
            dict.set_item("pressure", state.pressure.into_pyarray(py))?;
            dict.set_item("gap", state.gap.into_pyarray(py))?;
            dict.set_item("displacement", state.displacement.into_pyarray(py))?;
            if let Some(w) = plastic {
                dict.set_item("plastic_displacement", w.into_pyarray(py))?;
            }
        }
        Ok(dict)
    }

    /// The library's load path ([`load_path`]): the loads in order (loading, unloading,
    /// reloading), each warm from the last, the plastic displacement of each kept (the
    /// solver's surface stays deformed afterwards). Returns the columns and the permanent
    /// displacement after the last step.
    fn load_path<'py>(
        &mut self,
        py: Python<'py>,
        quantity: &str,
        values: Vec<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let loads = values
            .iter()
            .map(|&v| control(quantity, v))
            .collect::<PyResult<Vec<_>>>()?;
        self.check_capped(&loads)?;
        let (stop, solver) = (self.solver.stop().clone(), &mut self.solver);
        let (points, permanent) = run_detached_with(py, &stop, |_| {
            let points = load_path(solver, &loads)?;
            Ok::<_, SolveError>((points, solver.permanent_displacement()))
        })?
        .map_err(from_solve)?;
        path_dict(py, (&values, &points), permanent)
    }

    /// Frozen-set stiffness of the last solve: `(k, iterations, residual)`.
    fn stiffness(&mut self, py: Python<'_>) -> PyResult<(f64, usize, f64)> {
        let (stop, solver) = (self.solver.stop().clone(), &mut self.solver);
        let (k, info) =
            run_detached_with(py, &stop, |_| solver.frozen_set_stiffness())?.map_err(from_solve)?;
        Ok((k, info.iterations, info.residual))
    }

    /// Finite-difference `dF/dd` around a load (leaves the solver at the upper step).
    fn fd_stiffness(
        &mut self,
        py: Python<'_>,
        quantity: &str,
        value: f64,
        step: f64,
    ) -> PyResult<f64> {
        let control = control(quantity, value)?;
        let (stop, solver) = (self.solver.stop().clone(), &mut self.solver);
        run_detached_with(py, &stop, |_| {
            solver.finite_difference_stiffness(control, step)
        })?
        .map_err(from_solve)
    }

    /// A load sweep as `asperity bem` runs it (module docs); returns the columns. The
    /// tangential stiffness (`poisson`) and the conductances (`resistivity`,
    /// `thermal_conductivity`, two bodies each) by the front-end layer's one definition;
    /// `persson` = `(gamma, kappa)`: the BEM's mean gap and Persson's columns
    /// (`asperity bem --persson`).
    /// `timing`: also the columns of `asperity bem --timing` ([`TIMING_COLUMNS`], then
    /// `tangential_seconds` with the tangential stiffness).
    #[pyo3(signature = (quantity, values, stiffness, fd_step, fields, progress, poisson=None, resistivity=None, thermal_conductivity=None, persson=None, tangential=None, timing=false))]
    #[allow(clippy::too_many_arguments)]
    fn sweep<'py>(
        &mut self,
        py: Python<'py>,
        quantity: &str,
        values: Vec<f64>,
        stiffness: bool,
        fd_step: Option<f64>,
        fields: bool,
        progress: Option<Py<PyAny>>,
        poisson: Option<f64>,
        resistivity: Option<Vec<f64>>,
        thermal_conductivity: Option<Vec<f64>>,
        persson: Option<(f64, f64)>,
        tangential: Option<String>,
        timing: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let loads = values
            .iter()
            .map(|&v| control(quantity, v))
            .collect::<PyResult<Vec<_>>>()?;
        if let Some(step) = fd_step {
            check_fd_step(step).map_err(refused)?;
        }
        let derived = Derived::validate(
            poisson,
            tangential.as_deref(),
            &resistivity,
            &thermal_conductivity,
        )
        .map_err(refused)?;
        self.check_capped(&loads)?;
        let theory = persson
            .map(|(gamma, kappa)| SweepTheory::new(&self.solver, SweepPersson { gamma, kappa }))
            .transpose()
            .map_err(request_error)?;
        let (stop, solver) = (self.solver.stop().clone(), &mut self.solver);
        let params = SweepParams {
            stiffness,
            fd_step,
            tangential: derived.tangential,
            directions: derived.directions,
        };
        let rows = run_detached_with(py, &stop, |cancel| {
            let mut observer = PyObserver {
                fields,
                pressures: Vec::new(),
                gaps: Vec::new(),
                mean_gaps: theory.as_ref().map(|_| Vec::new()),
                progress: progress.as_ref(),
                cancel,
                total: loads.len(),
                peak_rss: timing.then(Vec::new),
            };
            cancel.call(observer.progress, 0, loads.len());
            let rows = sweep(solver, &loads, params, &mut observer);
            let mean_gaps = observer.mean_gaps.unwrap_or_default();
            let peaks = observer.peak_rss.unwrap_or_default();
            rows.map(|rows| (rows, (observer.pressures, observer.gaps), (mean_gaps, peaks)))
        })?
        .map_err(sweep_error)?;
        let (rows, observer, (mean_gaps, peaks)) = rows;
        let plastic = self.hardness().is_some();
        let dict = columns_dict(py, &rows, (params, plastic), observer)?;
        for (k, name) in derived.columns(Units::Model).into_iter().enumerate() {
            let column = rows.iter().map(|r| {
                let values = derived.values(&derived.row(r, self.modulus));
                values[k].unwrap_or(f64::NAN)
            });
            dict.set_item(name, PyArray1::from_iter(py, column))?;
        }
        if let Some(theory) = &theory {
            persson_columns(py, &dict, theory, &rows, &mean_gaps)?;
        }
        if timing {
            timing_columns(py, &dict, &rows, &peaks, derived.tangential.is_some())?;
        }
        Ok(dict)
    }
}

impl Solver {
    /// Refuses, before any solve, the loads the solver's hardness cannot carry: the rule
    /// and words of `asperity bem --hardness` ([`check_capped_loads`]), forces over this
    /// surface's nominal area.
    fn check_capped(&self, loads: &[Control]) -> PyResult<()> {
        let area = Some(self.solver.nominal_area());
        check_capped_loads(self.solver.interface(), loads, area, "").map_err(refused)
    }
}

/// A load path's columns ([`PathPoint`]s; the front-end layer's `PATH_COLUMNS`, with
/// `branch` a list of names, plus `contact_points` and `plastic_points`) and the permanent
/// displacement after its last step, as numpy arrays.
fn path_dict<'py>(
    py: Python<'py>,
    (values, points): (&[f64], &[PathPoint]),
    permanent: ndarray::Array2<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let names: Vec<&str> = branches(values).into_iter().map(|b| b.name()).collect();
    dict.set_item("branch", names)?;
    let column = |f: &dyn Fn(&PathPoint) -> f64| PyArray1::from_iter(py, points.iter().map(f));
    let count = |f: &dyn Fn(&PathPoint) -> usize| {
        PyArray1::from_iter(py, points.iter().map(|p| f(p) as u64))
    };
    dict.set_item("force", column(&|p| p.summary.force))?;
    dict.set_item("mean_pressure", column(&|p| p.summary.mean_pressure))?;
    dict.set_item("indentation", column(&|p| p.summary.indentation))?;
    dict.set_item("area_fraction", column(&|p| p.summary.area_fraction))?;
    dict.set_item("plastic_fraction", column(&|p| p.summary.plastic_fraction))?;
    dict.set_item("stiffness", column(&|p| p.stiffness))?;
    dict.set_item("iterations", count(&|p| p.iterations))?;
    dict.set_item("permanent_max", column(&|p| p.permanent_max))?;
    dict.set_item("contact_points", count(&|p| p.summary.contact_points))?;
    dict.set_item("plastic_points", count(&|p| p.summary.plastic_points))?;
    dict.set_item("permanent_displacement", permanent.into_pyarray(py))?;
    Ok(dict)
}

/// The BEM's mean gap and Persson's columns ([`SWEEP_COLUMNS`]; NaN where the CLI leaves
/// the cell empty: a mean pressure of 0).
fn persson_columns(
    py: Python<'_>,
    dict: &Bound<'_, PyDict>,
    theory: &SweepTheory,
    rows: &[SweepRow],
    mean_gaps: &[f64],
) -> PyResult<()> {
    let mut columns = vec![mean_gaps.to_vec(), Vec::new(), Vec::new(), Vec::new()];
    for row in rows {
        let predicted = theory
            .row(row.summary.mean_pressure)
            .map_err(request_error)?;
        for (column, value) in columns[1..].iter_mut().zip(predicted) {
            column.push(value.unwrap_or(f64::NAN));
        }
    }
    for (name, column) in SWEEP_COLUMNS.into_iter().zip(columns) {
        dict.set_item(name, PyArray1::from_vec(py, column))?;
    }
    Ok(())
}

/// `asperity bem --timing`'s columns, in its order: each load's solve and stiffness
/// seconds, the peak resident memory after it (MiB, NaN where the system does not say),
/// then `tangential_seconds` with the tangential stiffness.
fn timing_columns(
    py: Python<'_>,
    dict: &Bound<'_, PyDict>,
    rows: &[SweepRow],
    peaks: &[f64],
    tangential: bool,
) -> PyResult<()> {
    let column = |f: &dyn Fn(&SweepRow) -> f64| PyArray1::from_iter(py, rows.iter().map(f));
    let [solve, stiffness, peak] = TIMING_COLUMNS;
    dict.set_item(solve, column(&|r| r.solve_seconds))?;
    dict.set_item(stiffness, column(&|r| r.stiffness_seconds))?;
    dict.set_item(peak, PyArray1::from_slice(py, peaks))?;
    if tangential {
        dict.set_item("tangential_seconds", column(&|r| r.tangential_seconds))?;
    }
    Ok(())
}

/// The sweep's columns (as the CLI's CSV, plus `contact_points`) as numpy arrays.
fn columns_dict<'py>(
    py: Python<'py>,
    rows: &[SweepRow],
    (params, plastic): (SweepParams, bool),
    (pressures, gaps): (Vec<ndarray::Array2<f64>>, Vec<ndarray::Array2<f64>>),
) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let column = |f: &dyn Fn(&SweepRow) -> f64| PyArray1::from_iter(py, rows.iter().map(f));
    let count =
        |f: &dyn Fn(&SweepRow) -> usize| PyArray1::from_iter(py, rows.iter().map(|r| f(r) as u64));
    dict.set_item("force", column(&|r| r.summary.force))?;
    dict.set_item("mean_pressure", column(&|r| r.summary.mean_pressure))?;
    dict.set_item("indentation", column(&|r| r.summary.indentation))?;
    dict.set_item("area_fraction", column(&|r| r.summary.area_fraction))?;
    if params.stiffness {
        dict.set_item("stiffness", column(&|r| r.stiffness.unwrap_or(f64::NAN)))?;
    }
    dict.set_item("iterations", count(&|r| r.info.iterations))?;
    dict.set_item("residual", column(&|r| r.info.residual))?;
    if plastic {
        dict.set_item("plastic_fraction", column(&|r| r.summary.plastic_fraction))?;
    }
    if params.fd_step.is_some() {
        // NaN at indentation 0 (no central difference there), as the CLI's empty cell.
        dict.set_item(
            "stiffness_fd",
            column(&|r| r.stiffness_fd.unwrap_or(f64::NAN)),
        )?;
    }
    dict.set_item("contact_points", count(&|r| r.summary.contact_points))?;
    if !pressures.is_empty() || !gaps.is_empty() {
        let list = |arrays: Vec<ndarray::Array2<f64>>| -> PyResult<Bound<'_, PyList>> {
            let items: Vec<Bound<'_, PyArray2<f64>>> =
                arrays.into_iter().map(|a| a.into_pyarray(py)).collect();
            PyList::new(py, items)
        };
        dict.set_item("pressure", list(pressures)?)?;
        dict.set_item("gap", list(gaps)?)?;
    }
    Ok(dict)
}
