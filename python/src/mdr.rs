//! The method of dimensionality reduction (`asperity mdr`): a rough line or an
//! axisymmetric indenter on a foundation of linear, Hertz (15.2) or fractal (15.7) springs.
//!
//! The choice of indenter, spring law and indentations follows
//! `crates/asperity-cli/src/commands/mdr.rs` (`load_indenter`, `spring_law`,
//! `indentation_levels`), reimplemented here with Python's argument names because the
//! CLI's versions read its argument struct; the curve itself is the library's
//! (`Foundation::evaluate`, `LinearCurve::breakpoint`), so the numbers are the CLI's.

use asperity::mdr::{
    log_spaced, Axisymmetric, CurvePoint, Foundation, LinearCurve, RadialProfile, Spring, SpringLaw,
};
use asperity::memory::{array_bytes, ensure_fits};
use asperity::surface::stats::rms_height as rms_of;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::owned_1d;
use crate::errors::{from_error, invalid};
use crate::interrupt::run_detached;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mdr_curve, m)?)?;
    Ok(())
}

/// The indenter on its spring grid (the CLI's `Indenter`).
struct Indenter {
    values: Vec<f64>,
    is_line: bool,
    spacing: f64,
    size: f64,
    description: String,
}

fn need(value: Option<f64>, name: &str, what: &str) -> PyResult<f64> {
    value.ok_or_else(|| invalid(format!("{what} needs {name}")))
}

fn spring_grid(n: Option<usize>, dx: Option<f64>, what: &str) -> PyResult<(usize, f64)> {
    let n = n.ok_or_else(|| invalid(format!("{what} needs n (number of springs)")))?;
    let dx = need(dx, "dx", what)?;
    if !(dx.is_finite() && dx > 0.0) {
        return Err(invalid(format!(
            "invalid dx: the spring spacing Δx must be positive and finite, got {dx}"
        )));
    }
    if n == 0 {
        return Err(invalid("invalid n: need at least one spring"));
    }
    ensure_fits(
        &format!("n = {n} springs (profile and sorted gaps, 16 bytes each)"),
        array_bytes(&[n, 2], std::mem::size_of::<f64>()),
    )
    .map_err(from_error)?;
    Ok((n, dx))
}

/// The options that pick an indenter and its spring law.
struct Options<'a> {
    line: Option<PyReadonlyArray1<'a, f64>>,
    profile: Option<String>,
    radial: Option<PyReadonlyArray1<'a, f64>>,
    radial_step: Option<f64>,
    radius: Option<f64>,
    slope: Option<f64>,
    coefficient: Option<f64>,
    exponent: Option<f64>,
    n: Option<usize>,
    dx: Option<f64>,
    size: Option<f64>,
}

fn load_indenter(o: &Options<'_>) -> PyResult<Indenter> {
    let given = [o.line.is_some(), o.profile.is_some(), o.radial.is_some()];
    if given.iter().filter(|g| **g).count() > 1 {
        return Err(invalid("give one indenter: line, profile or radial"));
    }
    if let Some(line) = &o.line {
        if o.n.is_some() || o.dx.is_some() {
            return Err(invalid(
                "n and dx are for profile and radial indenters (a line's spacing is size / len(line))",
            ));
        }
        let heights = owned_1d(line).to_vec();
        let size = o.size.unwrap_or(1.0);
        if !(size.is_finite() && size > 0.0) {
            return Err(invalid(format!(
                "invalid size: the line length must be positive and finite, got {size}"
            )));
        }
        if heights.is_empty() {
            return Err(invalid("invalid line: it has no points"));
        }
        let spacing = size / heights.len() as f64;
        return Ok(Indenter {
            description: format!("line ({} points, L = {size})", heights.len()),
            values: heights,
            is_line: true,
            spacing,
            size,
        });
    }
    if let Some(radial) = &o.radial {
        let step = need(o.radial_step, "radial_step", "radial")?;
        let samples = owned_1d(radial);
        let profile = RadialProfile::new(samples.as_slice().expect("contiguous"), step)
            .map_err(from_error)?;
        let (n, dx) = spring_grid(o.n, o.dx, "radial")?;
        return Ok(Indenter {
            values: profile.sample(n, dx).map_err(from_error)?,
            is_line: false,
            spacing: dx,
            size: o.size.unwrap_or(n as f64 * dx),
            description: format!(
                "radial profile ({} samples, Δr = {step}), n = {n}, Δx = {dx}",
                samples.len()
            ),
        });
    }
    let Some(kind) = o.profile.as_deref() else {
        return Err(invalid(
            "give an indenter: line=heights, profile='hertz'|'cone'|'punch'|'power' or radial=samples",
        ));
    };
    let shape = match kind {
        "hertz" => Axisymmetric::Sphere {
            radius: need(o.radius, "radius", "profile 'hertz'")?,
        },
        "punch" => Axisymmetric::FlatPunch {
            radius: need(o.radius, "radius", "profile 'punch'")?,
        },
        "cone" => Axisymmetric::Cone {
            slope: need(o.slope, "slope", "profile 'cone'")?,
        },
        "power" => Axisymmetric::PowerLaw {
            coefficient: need(o.coefficient, "coefficient", "profile 'power'")?,
            exponent: need(o.exponent, "exponent", "profile 'power'")?,
        },
        other => {
            return Err(invalid(format!(
                "invalid profile {other:?}: expected hertz, cone, punch or power"
            )))
        }
    };
    shape.validate().map_err(from_error)?;
    let (n, dx) = spring_grid(o.n, o.dx, "profile")?;
    Ok(Indenter {
        values: shape.sample(n, dx).map_err(from_error)?,
        is_line: false,
        spacing: dx,
        size: o.size.unwrap_or(n as f64 * dx),
        description: format!("{shape}, n = {n}, Δx = {dx}"),
    })
}

fn spring_law(
    spring: &str,
    o: &Options<'_>,
    indenter: &Indenter,
    hurst: Option<f64>,
    rms_height: Option<f64>,
    asperity_radius: Option<f64>,
) -> PyResult<SpringLaw> {
    Ok(match spring {
        "linear" => SpringLaw::Linear,
        "hertz" => {
            let radius = match (asperity_radius, o.profile.as_deref()) {
                (Some(r), _) => r,
                (None, Some("hertz")) => need(o.radius, "radius", "profile 'hertz'")?,
                _ => return Err(invalid("the hertz spring law (15.2) needs asperity_radius")),
            };
            SpringLaw::Hertz { radius }
        }
        "fractal" => {
            let hurst =
                hurst.ok_or_else(|| invalid("the fractal spring law (15.7) needs hurst"))?;
            let rms = match (rms_height, indenter.is_line) {
                (Some(h), _) => h,
                (None, true) => rms_of(indenter.values.iter().copied()),
                (None, false) => {
                    return Err(invalid(
                        "the fractal spring law (15.7) on a profile needs rms_height",
                    ))
                }
            };
            SpringLaw::Fractal {
                hurst,
                rms_height: rms,
                size: indenter.size,
            }
        }
        other => {
            return Err(invalid(format!(
                "invalid spring {other:?}: expected linear, hertz or fractal"
            )))
        }
    })
}

fn indentation_levels(
    indentations: Option<Vec<f64>>,
    nloads: Option<usize>,
    dmin: Option<f64>,
    dmax: Option<f64>,
    foundation: &Foundation,
) -> PyResult<Vec<f64>> {
    if let Some(list) = indentations {
        if let Some(bad) = list.iter().find(|d| !d.is_finite() || **d < 0.0) {
            return Err(invalid(format!(
                "invalid indentations: each must be finite and >= 0, got {bad}"
            )));
        }
        return Ok(list);
    }
    let count = nloads.unwrap_or(50);
    ensure_fits(
        &format!("nloads = {count}"),
        array_bytes(&[count], std::mem::size_of::<CurvePoint>()),
    )
    .map_err(from_error)?;
    let dmax = match dmax {
        Some(d) => d,
        None => {
            let full = foundation.full_contact_indentation();
            if full <= 0.0 {
                return Err(invalid(
                    "every spring touches at once (a flat punch?): give dmax or indentations",
                ));
            }
            full
        }
    };
    let dmin = dmin.unwrap_or(dmax * 1e-6);
    log_spaced(dmin, dmax, count).map_err(|e| invalid(format!("dmin/dmax/nloads: {e}")))
}

/// The force–indentation–stiffness curve of `asperity mdr` as columns, with a description
/// and the spring law's critical depth.
#[pyfunction]
#[pyo3(signature = (line, profile, radial, radial_step, radius, slope, coefficient, exponent,
    n, dx, size, modulus, spring, hurst, rms_height, asperity_radius, indentations, nloads,
    dmin, dmax, breakpoints))]
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
) -> PyResult<Bound<'py, PyDict>> {
    if breakpoints && (indentations.is_some() || nloads.is_some()) {
        return Err(invalid(
            "breakpoints gives the exact curve: drop indentations and nloads",
        ));
    }
    if indentations.is_some() && nloads.is_some() {
        return Err(invalid("give at most one of indentations and nloads"));
    }
    let o = Options {
        line,
        profile,
        radial,
        radial_step,
        radius,
        slope,
        coefficient,
        exponent,
        n,
        dx,
        size,
    };
    let indenter = load_indenter(&o)?;
    let law = spring_law(spring, &o, &indenter, hurst, rms_height, asperity_radius)?;
    let spring = Spring::new(law, indenter.spacing, modulus).map_err(from_error)?;
    let points: Vec<CurvePoint> = if breakpoints {
        if !(spring.is_linear() && indenter.is_line) {
            return Err(invalid(
                "breakpoints needs a line with linear springs (the exact piecewise-linear curve)",
            ));
        }
        let values = &indenter.values;
        run_detached(py, |_| {
            LinearCurve::from_heights(values, spring.spacing(), modulus)
                .map(|curve| (1..=curve.len()).map(|j| curve.breakpoint(j)).collect())
        })?
        .map_err(from_error)?
    } else {
        let foundation = if indenter.is_line {
            Foundation::from_heights(&indenter.values, spring)
        } else {
            Foundation::from_profile(&indenter.values, spring)
        }
        .map_err(from_error)?;
        let levels = indentation_levels(indentations, nloads, dmin, dmax, &foundation)?;
        run_detached(py, |_| {
            levels.iter().map(|&d| foundation.evaluate(d)).collect()
        })?
    };
    let dict = PyDict::new(py);
    let column = |f: &dyn Fn(&CurvePoint) -> f64| PyArray1::from_iter(py, points.iter().map(f));
    dict.set_item("indentation", column(&|p| p.indentation))?;
    dict.set_item("force", column(&|p| p.force))?;
    dict.set_item("stiffness", column(&|p| p.stiffness))?;
    dict.set_item(
        "contacts",
        PyArray1::from_iter(py, points.iter().map(|p| p.contacts as u64)),
    )?;
    dict.set_item("description", indenter.description)?;
    dict.set_item("spring", law.name())?;
    dict.set_item("critical_depth", spring.critical_depth())?;
    Ok(dict)
}
