//! The method of dimensionality reduction (`asperity mdr`): a rough line or an
//! axisymmetric indenter on a foundation of linear, Hertz (15.2) or fractal (15.7) springs.
//!
//! The choice of indenter, spring law and indentations is the front-end layer's
//! ([`asperity_app::mdr::MdrRequest`]), the one `asperity mdr` runs: the same defaults,
//! rules and words, and the same curve (`Foundation::evaluate`, `LinearCurve::breakpoint`),
//! so the numbers are the CLI's.

use asperity::mdr::{CurvePoint, Spring, SpringLaw};
use asperity_app::mdr::{Branch, Indenter, MdrRequest};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::owned_1d;
use crate::errors::{from_error, refused, request_error};
use crate::interrupt::run_detached;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mdr_curve, m)?)?;
    Ok(())
}

/// The force–indentation–stiffness curve of `asperity mdr` as columns, with a description
/// and the spring law's critical depth.
#[pyfunction]
#[pyo3(signature = (line, profile, radial, radial_step, radius, slope, coefficient, exponent,
    n, dx, size, modulus, spring, hurst, rms_height, asperity_radius, indentations, nloads,
    dmin, dmax, breakpoints, work_of_adhesion))]
#[allow(clippy::too_many_arguments)]
fn mdr_curve<'py>(
    py: Python<'py>,
    line: Option<PyReadonlyArray1<'py, f64>>,
    profile: Option<String>,
    radial: Option<PyReadonlyArray1<'py, f64>>,
    radial_step: Option<f64>,
    radius: Option<f64>,
    slope: Option<f64>,
    coefficient: Option<f64>,
    exponent: Option<f64>,
    n: Option<usize>,
    dx: Option<f64>,
    size: Option<f64>,
    modulus: f64,
    spring: &str,
    hurst: Option<f64>,
    rms_height: Option<f64>,
    asperity_radius: Option<f64>,
    indentations: Option<Vec<f64>>,
    nloads: Option<usize>,
    dmin: Option<f64>,
    dmax: Option<f64>,
    breakpoints: bool,
    work_of_adhesion: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = MdrRequest {
        line: line.is_some(),
        profile,
        radial: radial.is_some(),
        radial_step,
        radius,
        slope,
        coefficient,
        exponent,
        n,
        dx,
        size,
        modulus,
        spring: spring.into(),
        hurst,
        rms_height,
        asperity_radius,
        indentations,
        nloads,
        dmin,
        dmax,
        breakpoints,
        work_of_adhesion,
    };
    request.check().map_err(refused)?;
    let indenter = match (&line, &radial) {
        (Some(line), _) => {
            let heights = owned_1d(line).to_vec();
            Indenter::line(heights, size.unwrap_or(1.0), "").map_err(refused)?
        }
        (None, Some(radial)) => {
            let samples = owned_1d(radial);
            let samples = samples.as_slice().expect("contiguous");
            request.radial(samples, "").map_err(request_error)?
        }
        (None, None) => request.closed_form().map_err(request_error)?,
    };
    if work_of_adhesion.is_some() {
        return adhesive_curve(py, &request, indenter);
    }
    let law = request.spring_law(&indenter).map_err(refused)?;
    let spring = Spring::new(law, indenter.spacing, modulus).map_err(from_error)?;
    let row_bytes = std::mem::size_of::<CurvePoint>();
    let points: Vec<CurvePoint> = run_detached(py, |_| {
        let mut points = Vec::new();
        request
            .compute(&indenter, spring, row_bytes, &mut |p| points.push(p))
            .map(|_| points)
    })?
    .map_err(request_error)?;
    let dict = columns(py, &points)?;
    dict.set_item("description", indenter.description)?;
    dict.set_item("spring", law.name())?;
    dict.set_item("critical_depth", spring.critical_depth())?;
    Ok(dict)
}

/// The four columns of a curve.
fn columns<'py>(py: Python<'py>, points: &[CurvePoint]) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let column = |f: &dyn Fn(&CurvePoint) -> f64| PyArray1::from_iter(py, points.iter().map(f));
    dict.set_item("indentation", column(&|p| p.indentation))?;
    dict.set_item("force", column(&|p| p.force))?;
    dict.set_item("stiffness", column(&|p| p.stiffness))?;
    dict.set_item(
        "contacts",
        PyArray1::from_iter(py, points.iter().map(|p| p.contacts as u64)),
    )?;
    Ok(dict)
}

/// `work_of_adhesion` given: the load path and the retraction to pull-off, as
/// `asperity mdr --work-of-adhesion` computes them.
fn adhesive_curve<'py>(
    py: Python<'py>,
    request: &MdrRequest,
    indenter: Indenter,
) -> PyResult<Bound<'py, PyDict>> {
    let row_bytes = std::mem::size_of::<(CurvePoint, Branch)>();
    let (rows, pull_offs) = run_detached(py, |_| {
        let mut rows = Vec::new();
        request
            .compute_adhesive(&indenter, row_bytes, &mut |p, b| rows.push((p, b)))
            .map(|(_, pull_offs)| (rows, pull_offs))
    })?
    .map_err(request_error)?;
    let points: Vec<CurvePoint> = rows.iter().map(|(p, _)| *p).collect();
    let dict = columns(py, &points)?;
    let branches: Vec<&str> = rows.iter().map(|(_, b)| b.name()).collect();
    dict.set_item("branch", branches)?;
    let pull_off = match pull_offs {
        Some(p) => {
            let point = |q: &CurvePoint| -> PyResult<Bound<'py, PyDict>> {
                let d = PyDict::new(py);
                d.set_item("force", q.force)?;
                d.set_item("indentation", q.indentation)?;
                d.set_item("contacts", q.contacts)?;
                Ok(d)
            };
            let d = PyDict::new(py);
            d.set_item("force_controlled", point(&p.force_controlled)?)?;
            d.set_item(
                "displacement_controlled",
                point(&p.displacement_controlled)?,
            )?;
            Some(d)
        }
        None => None,
    };
    dict.set_item("pull_off", pull_off)?;
    dict.set_item("description", indenter.description)?;
    let spring =
        Spring::new(SpringLaw::Linear, indenter.spacing, request.modulus).map_err(from_error)?;
    dict.set_item("spring", SpringLaw::Linear.name())?;
    dict.set_item("critical_depth", spring.critical_depth())?;
    Ok(dict)
}
