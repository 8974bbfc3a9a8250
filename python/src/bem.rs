//! The BEM contact solver (`asperity bem`): one planned [`ContactSolver`] per Python
//! `Solver`, reused across loads (warm starts) as the CLI does.
//!
//! A sweep is the library's [`asperity::bem::sweep::sweep`], the loop `asperity bem` runs
//! too (the full-contact check of every load kind before any solve, then per load: solve,
//! frozen-set stiffness, fields, finite-difference stiffness and the re-solve for the next
//! warm start), so a sweep gives the CLI's numbers bit for bit. The solver polls the stop
//! flag that Ctrl-C sets ([`crate::interrupt`]), so one long solve stops too.

use asperity::bem::sweep::{
    sweep, SweepError, SweepFailure, SweepObserver, SweepParams, SweepRow,
};
use asperity::bem::{ContactSolver, Control, HalfSpace, SolveError, SolverKind, SolverParams};
use asperity::elastic::Boundary;
use asperity::memory::{array_bytes, ensure_fits};
use asperity::surface::Surface;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::arrays::owned_2d;
use crate::errors::{from_error, from_solve, invalid};
use crate::interrupt::{run_detached, run_detached_with, Cancel};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Solver>()?;
    m.add_function(wrap_pyfunction!(check_loads, m)?)?;
    m.add_function(wrap_pyfunction!(log_pressures, m)?)?;
    Ok(())
}

/// The CLI's check of a list of loads (`forces`, `pressures` > 0; `indentations` ≥ 0).
#[pyfunction]
fn check_loads(name: &str, values: Vec<f64>, allow_zero: bool) -> PyResult<()> {
    if values.is_empty() {
        return Err(invalid(format!("{name}: give at least one value")));
    }
    for v in values {
        if !(v.is_finite() && (v > 0.0 || (allow_zero && v == 0.0))) {
            return Err(invalid(format!(
                "{name}: {v} is not allowed (values must be finite and {})",
                if allow_zero { ">= 0" } else { "> 0" }
            )));
        }
    }
    Ok(())
}

/// `nloads` mean pressures log-spaced from `pmin` to `pmax`, as `asperity bem --nloads`.
#[pyfunction]
fn log_pressures(nloads: usize, pmin: f64, pmax: f64) -> PyResult<Vec<f64>> {
    if nloads == 0 {
        return Err(invalid("nloads must be at least 1"));
    }
    check_loads("pmin", vec![pmin], false)?;
    check_loads("pmax", vec![pmax], false)?;
    if pmax < pmin {
        return Err(invalid(format!(
            "pmax ({pmax}) must not be smaller than pmin ({pmin})"
        )));
    }
    ensure_fits(
        &format!("nloads {nloads}: the bookkeeping of {nloads} loads"),
        array_bytes(&[nloads], 1024),
    )
    .map_err(from_error)?;
    Ok((0..nloads)
        .map(|i| {
            let t = if nloads == 1 {
                0.0
            } else {
                i as f64 / (nloads - 1) as f64
            };
            pmin * (pmax / pmin).powf(t)
        })
        .collect())
}

/// The solver choice as the library's [`SolverKind`]: `"bccg"` (the library's default) or
/// `"pk"` (Polonsky–Keer), the CLI's `--solver` names; `"default"` is kept as an alias of
/// the library's default (the name the first release of the package documented).
fn solver_kind(name: &str) -> PyResult<SolverKind> {
    match name {
        "bccg" | "default" => Ok(SolverKind::Bccg),
        "pk" => Ok(SolverKind::PolonskyKeer),
        other => Err(invalid(format!(
            "invalid solver: expected \"bccg\" (the default) or \"pk\" (Polonsky–Keer), got {other:?}"
        ))),
    }
}

/// A load as the library's control: `quantity` is `pressure`, `force` or `indentation`.
fn control(quantity: &str, value: f64) -> PyResult<Control> {
    match quantity {
        "pressure" => Ok(Control::MeanPressure(value)),
        "force" => Ok(Control::Force(value)),
        "indentation" => Ok(Control::Indentation(value)),
        other => Err(invalid(format!(
            "unknown load quantity {other:?} (pressure, force or indentation)"
        ))),
    }
}

/// `error` with `context: ` in front (a `SolveError` keeps its type and attributes).
fn with_context(error: SolveError, context: &str) -> PyErr {
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
    progress: Option<&'a Py<PyAny>>,
    cancel: &'a Cancel,
    total: usize,
}

impl SweepObserver for PyObserver<'_> {
    type Error = Cancelled;

    fn solved(&mut self, _load: usize, solver: &ContactSolver) -> Result<(), Cancelled> {
        if self.fields {
            self.pressures.push(solver.pressure().to_owned());
            self.gaps.push(solver.gap().to_owned());
        }
        Ok(())
    }

    fn finished(&mut self, load: usize, _row: &SweepRow) -> Result<(), Cancelled> {
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
    #[pyo3(signature = (heights, size_x, size_y, modulus, boundary, tolerance, max_iterations, solver))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        heights: PyReadonlyArray2<'_, f64>,
        size_x: f64,
        size_y: Option<f64>,
        modulus: f64,
        boundary: &str,
        tolerance: f64,
        max_iterations: usize,
        solver: &str,
    ) -> PyResult<Self> {
        let solver = solver_kind(solver)?;
        let boundary: Boundary = boundary.parse().map_err(from_error)?;
        if !(modulus.is_finite() && modulus > 0.0) {
            return Err(invalid(format!(
                "modulus must be positive and finite, got {modulus}"
            )));
        }
        for (name, size) in [("size", Some(size_x)), ("size_y", size_y)] {
            if let Some(size) = size.filter(|s| !(s.is_finite() && *s > 0.0)) {
                return Err(invalid(format!(
                    "{name} must be positive and finite, got {size}"
                )));
            }
        }
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(invalid(format!(
                "tolerance must be positive and finite, got {tolerance}"
            )));
        }
        let params = SolverParams {
            solver,
            tolerance,
            max_iterations,
            ..SolverParams::default()
        };
        params.validate().map_err(from_error)?;
        let (rows, cols) = heights.as_array().dim();
        let bytes = ContactSolver::memory_bytes(rows, cols, boundary)
            .zip(array_bytes(&[rows, cols], 8))
            .and_then(|(solver, heights)| solver.checked_add(heights));
        ensure_fits(
            &format!(
                "a BEM solver on a {rows}x{cols} surface ({} boundaries)",
                boundary.name()
            ),
            bytes,
        )
        .map_err(from_error)?;
        if rows < 2 || cols < 2 {
            return Err(invalid(format!(
                "invalid grid: a surface needs at least 2x2 points, got ({rows}, {cols})"
            )));
        }
        let owned = owned_2d(&heights);
        let surface = match size_y {
            Some(size_y) => Surface::with_sizes(owned, size_x, size_y),
            None => Surface::new(owned, size_x),
        }
        .map_err(from_error)?;
        let half_space = HalfSpace { modulus, boundary };
        let solver = run_detached(py, |_| ContactSolver::new(&surface, half_space, params))?
            .map_err(from_solve)?;
        Ok(Solver {
            solver,
            modulus,
            boundary,
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
        let (stop, solver) = (self.solver.stop().clone(), &mut self.solver);
        // No up-front full-contact check here (the CLI's is for sweeps): the library's
        // solve refuses such a load itself, with the same threshold, and a single solve
        // then costs exactly what the library's does.
        let (summary, info, state) = run_detached_with(py, &stop, |_| {
            let (summary, info) = solver.solve(control)?;
            let state = if fields { solver.state() } else { None };
            Ok::<_, SolveError>((summary, info, state))
        })?
        .map_err(from_solve)?;
        let dict = PyDict::new(py);
        dict.set_item("force", summary.force)?;
        dict.set_item("mean_pressure", summary.mean_pressure)?;
        dict.set_item("indentation", summary.indentation)?;
        dict.set_item("area_fraction", summary.area_fraction)?;
        dict.set_item("contact_points", summary.contact_points)?;
        dict.set_item("iterations", info.iterations)?;
        dict.set_item("residual", info.residual)?;
        if let Some(state) = state {
            dict.set_item("pressure", state.pressure.into_pyarray(py))?;
            dict.set_item("gap", state.gap.into_pyarray(py))?;
            dict.set_item("displacement", state.displacement.into_pyarray(py))?;
        }
        Ok(dict)
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

    /// A load sweep as `asperity bem` runs it (module docs); returns the columns.
    #[pyo3(signature = (quantity, values, stiffness, fd_step, fields, progress))]
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
    ) -> PyResult<Bound<'py, PyDict>> {
        let loads = values
            .iter()
            .map(|&v| control(quantity, v))
            .collect::<PyResult<Vec<_>>>()?;
        let (stop, solver) = (self.solver.stop().clone(), &mut self.solver);
        let params = SweepParams { stiffness, fd_step };
        let (rows, observer) = run_detached_with(py, &stop, |cancel| {
            let mut observer = PyObserver {
                fields,
                pressures: Vec::new(),
                gaps: Vec::new(),
                progress: progress.as_ref(),
                cancel,
                total: loads.len(),
            };
            cancel.call(observer.progress, 0, loads.len());
            let rows = sweep(solver, &loads, params, &mut observer);
            rows.map(|rows| (rows, (observer.pressures, observer.gaps)))
        })?
        .map_err(sweep_error)?;
        columns_dict(py, &rows, params, observer)
    }
}

/// The sweep's columns (as the CLI's CSV, plus `contact_points`) as numpy arrays.
fn columns_dict<'py>(
    py: Python<'py>,
    rows: &[SweepRow],
    params: SweepParams,
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
