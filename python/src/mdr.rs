//! The method of dimensionality reduction (`asperity mdr`): a rough line or an
//! axisymmetric indenter on a foundation of linear, Hertz (15.2) or fractal (15.7) springs.
//!
//! The choice of indenter, spring law and indentations is the front-end layer's
//! ([`asperity_app::mdr::MdrRequest`]), the one `asperity mdr` runs: the same defaults,
//! rules and words, and the same curve (`Foundation::evaluate`, `LinearCurve::breakpoint`),
//! so the numbers are the CLI's.

use asperity::mdr::{CurvePoint, Spring, SpringLaw};
use asperity_app::mdr::{params, Branch, Indenter, MdrRequest};
use asperity_app::refusal::count;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::adhesion::pull_off_dict;
use crate::arrays::owned_1d;
use crate::errors::{from_error, refused, request_error};
use crate::interrupt::run_detached;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mdr_curve, m)?)?;
    Ok(())
}

/// The force–indentation–stiffness curve of `asperity mdr` as columns, with a description
/// and the spring law's critical depth; `request`: the keywords of the [`MdrRequest`]
/// ([`request`]).
#[pyfunction]
#[pyo3(signature = (request, line, radial))]
fn mdr_curve<'py>(
    py: Python<'py>,
    request: &Bound<'py, PyDict>,
    line: Option<PyReadonlyArray1<'py, f64>>,
    radial: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = self::request(request, &line, &radial)?;
    request.check().map_err(refused)?;
    let indenter = indenter(&request, &line, &radial)?;
    let modulus = request.modulus;
    if request.work_of_adhesion.is_some() {
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
    dict.set_item("modulus", modulus)?;
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

/// The [`MdrRequest`] of `mdr` and `mdr_slip` from Python's `_mdr_request`: the keywords
/// given, by name (those left out take the request's defaults, the CLI's), with `line` and
/// `radial` set by the arrays given.
pub fn request<'py>(
    keywords: &Bound<'py, PyDict>,
    line: &Option<PyReadonlyArray1<'py, f64>>,
    radial: &Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<MdrRequest> {
    fn item<'py, T: FromPyObjectOwned<'py>>(
        keywords: &Bound<'py, PyDict>,
        name: &str,
    ) -> PyResult<Option<T>> {
        match keywords.get_item(name)? {
            Some(value) if !value.is_none() => value.extract::<T>().map(Some).map_err(Into::into),
            _ => Ok(None),
        }
    }
    let defaults = MdrRequest::default();
    Ok(MdrRequest {
        line: line.is_some(),
        profile: item(keywords, "profile")?,
        radial: radial.is_some(),
        radial_step: item(keywords, "radial_step")?,
        radius: item(keywords, "radius")?,
        slope: item(keywords, "slope")?,
        coefficient: item(keywords, "coefficient")?,
        exponent: item(keywords, "exponent")?,
        n: (item::<i128>(keywords, "n")?)
            .map(|n| count(params::N, n))
            .transpose()
            .map_err(refused)?,
        dx: item(keywords, "dx")?,
        size: item(keywords, "size")?,
        modulus: item(keywords, "modulus")?.unwrap_or(defaults.modulus),
        spring: item(keywords, "spring")?.unwrap_or(defaults.spring),
        hurst: item(keywords, "hurst")?,
        rms_height: item(keywords, "rms_height")?,
        asperity_radius: item(keywords, "asperity_radius")?,
        indentations: item(keywords, "indentations")?,
        nloads: (item::<i128>(keywords, "nloads")?)
            .map(|n| count(params::NLOADS, n))
            .transpose()
            .map_err(refused)?,
        dmin: item(keywords, "dmin")?,
        dmax: item(keywords, "dmax")?,
        breakpoints: item(keywords, "breakpoints")?.unwrap_or(defaults.breakpoints),
        work_of_adhesion: item(keywords, "work_of_adhesion")?,
    })
}

/// The indenter of a checked `request`: the line's heights, the radial samples mapped by
/// the MDR transform, or the closed-form profile.
pub fn indenter(
    request: &MdrRequest,
    line: &Option<PyReadonlyArray1<'_, f64>>,
    radial: &Option<PyReadonlyArray1<'_, f64>>,
) -> PyResult<Indenter> {
    match (line, radial) {
        (Some(line), _) => {
            let heights = owned_1d(line).to_vec();
            Indenter::line(heights, request.size.unwrap_or(1.0), "").map_err(refused)
        }
        (None, Some(radial)) => {
            let samples = owned_1d(radial);
            let samples = samples.as_slice().expect("contiguous");
            request.radial(samples, "").map_err(request_error)
        }
        (None, None) => request.closed_form().map_err(request_error),
    }
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
    let point = |q: &CurvePoint| (q.force, q.indentation, q.contacts);
    let pull_off = pull_offs
        .map(|p| {
            let (force, displacement) = (&p.force_controlled, &p.displacement_controlled);
            pull_off_dict(py, "contacts", point(force), point(displacement))
        })
        .transpose()?;
    dict.set_item("pull_off", pull_off)?;
    dict.set_item("description", indenter.description)?;
    let spring =
        Spring::new(SpringLaw::Linear, indenter.spacing, request.modulus).map_err(from_error)?;
    dict.set_item("spring", SpringLaw::Linear.name())?;
    dict.set_item("critical_depth", spring.critical_depth())?;
    dict.set_item("modulus", request.modulus)?;
    Ok(dict)
}
