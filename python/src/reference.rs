//! `asperity.reference`: the library's closed-form reference solutions
//! (`asperity::reference`), evaluated elementwise over numpy arrays by the same functions the
//! library's tests and the CLI's reports use.

use asperity::reference::{
    CattaneoMindlin, Cone, Dmt, FlatPunch, Hertz, Jkr, JohnsonSinusoid, Kendall, MaugisDugdale,
    PowerLaw, PullOff, Westergaard,
};
use asperity_app::refusal::{self, Names, Param};
use numpy::{IntoPyArray, PyArrayDyn, PyReadonlyArrayDyn};
use pyo3::prelude::*;

use crate::errors::{from_error, invalid};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(reference, m)?)?;
    Ok(())
}

/// A method of a model: its value at `x` (the array argument) given the scalars before it.
type Method = Box<dyn Fn(f64) -> f64>;

/// `N` parameters, each positive and finite by the front-end layer's rule
/// (`asperity_app::refusal::positive`, the CLI's), the model named in the error.
fn positive<const N: usize>(
    model: &str,
    names: [&'static str; N],
    params: &[f64],
) -> PyResult<[f64; N]> {
    if params.len() != N {
        return Err(invalid(format!(
            "{model}: expected {N} parameters ({}), got {}",
            names.join(", "),
            params.len()
        )));
    }
    for (&name, &value) in names.iter().zip(params) {
        refusal::positive(Param::new(name, name), value)
            .map_err(|r| invalid(format!("{model}: {}", r.words(Names::Keywords))))?;
    }
    Ok(std::array::from_fn(|i| params[i]))
}

/// `scalars[i]`, or an error naming the method.
fn scalar(method: &str, scalars: &[f64], i: usize) -> PyResult<f64> {
    scalars
        .get(i)
        .copied()
        .ok_or_else(|| invalid(format!("{method}: expected {} scalar arguments", i + 1)))
}

fn unknown(model: &str, method: &str) -> PyErr {
    invalid(format!("{model} has no method {method:?}"))
}

/// Axisymmetric indenters without adhesion.
fn indenter(model: &str, params: &[f64], method: &str, scalars: &[f64]) -> PyResult<Method> {
    Ok(match model {
        "hertz" => {
            let [radius, modulus] = positive(model, ["radius", "modulus"], params)?;
            let h = Hertz { radius, modulus };
            match method {
                "force" => Box::new(move |d| h.force(d)),
                "contact_radius" => Box::new(move |d| h.contact_radius(d)),
                "indentation" => Box::new(move |f| h.indentation(f)),
                "stiffness" => Box::new(move |d| h.stiffness(d)),
                "pressure" => {
                    let d = scalar(method, scalars, 0)?;
                    Box::new(move |r| h.pressure(d, r))
                }
                _ => return Err(unknown(model, method)),
            }
        }
        "flat_punch" => {
            let [radius, modulus] = positive(model, ["radius", "modulus"], params)?;
            let p = FlatPunch { radius, modulus };
            match method {
                "force" => Box::new(move |d| p.force(d)),
                "stiffness" => Box::new(move |_| p.stiffness()),
                _ => return Err(unknown(model, method)),
            }
        }
        "cone" => {
            let [slope, modulus] = positive(model, ["slope", "modulus"], params)?;
            let c = Cone { slope, modulus };
            match method {
                "force" => Box::new(move |d| c.force(d)),
                "contact_radius" => Box::new(move |d| c.contact_radius(d)),
                "stiffness" => Box::new(move |d| c.stiffness(d)),
                _ => return Err(unknown(model, method)),
            }
        }
        "power_law" => {
            let names = ["coefficient", "exponent", "modulus"];
            let [coefficient, exponent, modulus] = positive(model, names, params)?;
            let p = PowerLaw {
                coefficient,
                exponent,
                modulus,
            };
            match method {
                "force" => Box::new(move |d| p.force(d)),
                "contact_radius" => Box::new(move |d| p.contact_radius(d)),
                "stiffness" => Box::new(move |d| p.stiffness(d)),
                _ => return Err(unknown(model, method)),
            }
        }
        _ => return other(model, params, method, scalars),
    })
}

/// Westergaard's wavy contact and Cattaneo–Mindlin's partial slip.
fn other(model: &str, params: &[f64], method: &str, scalars: &[f64]) -> PyResult<Method> {
    Ok(match model {
        "westergaard" => {
            let names = ["wavelength", "amplitude", "modulus"];
            let [wavelength, amplitude, modulus] = positive(model, names, params)?;
            let w = Westergaard {
                wavelength,
                amplitude,
                modulus,
            };
            match method {
                "full_contact_pressure" => Box::new(move |_| w.full_contact_pressure()),
                "contact_half_width" => Box::new(move |p| w.contact_half_width(p)),
                "contact_fraction" => Box::new(move |p| w.contact_fraction(p)),
                "indentation" => Box::new(move |p| w.indentation(p)),
                "pressure" => {
                    let p = scalar(method, scalars, 0)?;
                    Box::new(move |x| w.pressure(p, x))
                }
                _ => return Err(unknown(model, method)),
            }
        }
        "cattaneo_mindlin" => {
            let names = ["radius", "modulus", "ratio", "friction"];
            let [radius, modulus, ratio, friction] = positive(model, names, params)?;
            let c = CattaneoMindlin {
                radius,
                modulus,
                ratio,
                friction,
            };
            let d = scalar(method, scalars, 0)?;
            match method {
                "stick_radius" => Box::new(move |q| c.stick_radius(d, q)),
                "displacement" => Box::new(move |q| c.displacement(d, q)),
                "unloading_displacement" => {
                    let top = scalar(method, scalars, 1)?;
                    Box::new(move |q| c.unloading_displacement(d, top, q))
                }
                "no_slip_stiffness" => Box::new(move |_| c.no_slip_stiffness(d)),
                "dissipation" => Box::new(move |q| c.dissipation(d, q)),
                _ => return Err(unknown(model, method)),
            }
        }
        _ => return adhesive(model, params, method),
    })
}

/// The pull-off's control by its name.
fn control(name: &str) -> PyResult<PullOff> {
    match name {
        "force" => Ok(PullOff::ForceControlled),
        "displacement" => Ok(PullOff::DisplacementControlled),
        other => Err(invalid(format!(
            "control must be 'force' or 'displacement', got {other:?}"
        ))),
    }
}

/// Maugis–Dugdale's sphere, dimensionless (`maugis_dugdale`: its curve against Ā and its
/// pull-off), and the units of a given sphere (`maugis_scales`).
fn maugis(model: &str, params: &[f64], method: &str) -> PyResult<Method> {
    Ok(match model {
        "maugis_dugdale" => {
            let [lambda] = positive(model, ["maugis_parameter"], params)?;
            let md = MaugisDugdale::new(lambda).map_err(from_error)?;
            let pull_off = |rest: &str| control(rest).map(|c| md.pull_off(c));
            match method {
                "force" => Box::new(move |a| md.at_radius(a).force),
                "approach" => Box::new(move |a| md.at_radius(a).approach),
                "zone_ratio" => Box::new(move |a| md.at_radius(a).zone_ratio),
                _ if method.starts_with("pull_off_force_") => {
                    let point = pull_off(&method[15..])?;
                    Box::new(move |_| point.force)
                }
                _ if method.starts_with("pull_off_radius_") => {
                    let point = pull_off(&method[16..])?;
                    Box::new(move |_| point.radius)
                }
                _ if method.starts_with("pull_off_approach_") => {
                    let point = pull_off(&method[18..])?;
                    Box::new(move |_| point.approach)
                }
                _ => return Err(unknown(model, method)),
            }
        }
        "maugis_scales" => {
            let names = ["radius", "modulus", "work_of_adhesion", "stress"];
            let [r, e, w, stress] = positive(model, names, params)?;
            let scales = MaugisDugdale::scales(r, e, w, stress);
            let value = match method {
                "radius" => scales.radius,
                "force" => scales.force,
                "approach" => scales.approach,
                "lambda" => scales.lambda,
                _ => return Err(unknown(model, method)),
            };
            Box::new(move |_| value)
        }
        "johnson_sinusoid" => return johnson(model, params, method),
        _ => return Err(invalid(format!("unknown reference solution {model:?}"))),
    })
}

/// Johnson's adhesive sinusoid (`asperity::reference::JohnsonSinusoid`): its curve against
/// the contact half-width, the ends of its stable branch and its pull-offs (NaN where no
/// partial contact is stable), and the two thresholds of α.
fn johnson(model: &str, params: &[f64], method: &str) -> PyResult<Method> {
    let names = ["wavelength", "amplitude", "modulus", "work_of_adhesion"];
    let [l, amp, e, w] = positive(model, names, params)?;
    let j = JohnsonSinusoid::new(l, amp, e, w).map_err(from_error)?;
    let constant = |v: f64| -> Method { Box::new(move |_| v) };
    let branch = j.stable_branch();
    Ok(match method {
        "mean_pressure" => Box::new(move |a| j.mean_pressure(a)),
        "approach" => Box::new(move |a| j.approach(a)),
        "full_contact_pressure" => constant(j.full_contact_pressure()),
        "alpha" => constant(j.alpha()),
        "alpha_stable" => constant(JohnsonSinusoid::ALPHA_STABLE),
        "alpha_snap" => constant(JohnsonSinusoid::ALPHA_SNAP),
        "stable_branch_least" => constant(branch.map_or(f64::NAN, |b| b.0)),
        "stable_branch_greatest" => constant(branch.map_or(f64::NAN, |b| b.1)),
        _ if method.starts_with("pull_off_half_width_") => {
            let point = j.pull_off(control(&method[20..])?);
            constant(point.map_or(f64::NAN, |p| p.0))
        }
        _ if method.starts_with("pull_off_pressure_") => {
            let point = j.pull_off(control(&method[18..])?);
            constant(point.map_or(f64::NAN, |p| p.1))
        }
        _ => return Err(unknown(model, method)),
    })
}

/// JKR, DMT and Kendall's punch (the library refuses non-positive parameters).
fn adhesive(model: &str, params: &[f64], method: &str) -> PyResult<Method> {
    let names = ["radius", "modulus", "work_of_adhesion"];
    Ok(match model {
        "jkr" => {
            let [r, e, w] = positive(model, names, params)?;
            let j = Jkr::new(r, e, w).map_err(from_error)?;
            match method {
                "approach" => Box::new(move |a| j.approach(a)),
                "force" => Box::new(move |a| j.force(a)),
                "contact_radius_at_force" => {
                    Box::new(move |f| j.contact_radius_at_force(f).unwrap_or(f64::NAN))
                }
                "zero_force_radius" => Box::new(move |_| j.zero_force_radius()),
                "pull_off_force_force" | "pull_off_force_displacement" => {
                    let c = control(&method[15..])?;
                    Box::new(move |_| j.pull_off_force(c))
                }
                "pull_off_radius_force" | "pull_off_radius_displacement" => {
                    let c = control(&method[16..])?;
                    Box::new(move |_| j.pull_off_radius(c))
                }
                _ => return Err(unknown(model, method)),
            }
        }
        "dmt" => {
            let [r, e, w] = positive(model, names, params)?;
            let d = Dmt::new(r, e, w).map_err(from_error)?;
            match method {
                "approach" => Box::new(move |a| d.approach(a)),
                "force" => Box::new(move |a| d.force(a)),
                "pull_off_force" => Box::new(move |_| d.pull_off_force()),
                _ => return Err(unknown(model, method)),
            }
        }
        "kendall" => {
            let [r, e, w] = positive(model, names, params)?;
            let k = Kendall::new(r, e, w).map_err(from_error)?;
            match method {
                "force" => Box::new(move |d| k.force(d)),
                "pull_off_approach" => Box::new(move |_| k.pull_off_approach()),
                "pull_off_force" => Box::new(move |_| k.pull_off_force()),
                _ => return Err(unknown(model, method)),
            }
        }
        _ => return maugis(model, params, method),
    })
}

/// `model(params).method(*scalars, x)` elementwise over the array `x`.
#[pyfunction]
#[pyo3(signature = (model, params, method, scalars, x))]
fn reference<'py>(
    py: Python<'py>,
    model: &str,
    params: Vec<f64>,
    method: &str,
    scalars: Vec<f64>,
    x: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Some(bad) = scalars.iter().find(|v| !v.is_finite()) {
        return Err(invalid(format!(
            "{method}: arguments must be finite, got {}",
            asperity_app::refusal::number(*bad)
        )));
    }
    let f = indenter(model, &params, method, &scalars)?;
    Ok(x.as_array().mapv(f).into_pyarray(py))
}
