//! `asperity study windows` (Python's `study_windows`): the window sensitivity of a study
//! folder by the front-end layer's one call (`asperity_app::study::windows`).

use std::path::PathBuf;

use asperity_app::study::windows::{window_sensitivity, COLUMNS};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::request_error;
use crate::interrupt::run_detached;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(study_windows, m)?)?;
    m.add_function(wrap_pyfunction!(read_study_file, m)?)?;
    Ok(())
}

/// The rows of `asperity study windows DIR` as columns (the CSV's names, in its order):
/// counts as int64 arrays, the rest float64.
#[pyfunction]
fn study_windows(py: Python<'_>, dir: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let rows = run_detached(py, |_| window_sensitivity(&dir))?.map_err(request_error)?;
    let counts = |f: &dyn Fn(&asperity_app::study::windows::WindowRow) -> usize| {
        ndarray::Array1::from_iter(rows.iter().map(|r| f(r) as i64))
    };
    let values = |f: &dyn Fn(&asperity_app::study::windows::WindowRow) -> f64| {
        ndarray::Array1::from_iter(rows.iter().map(f))
    };
    // In the order of the CSV's columns (`COLUMNS`; test_study_windows.py checks the names
    // against the CLI's header).
    let columns = [
        ("n", counts(&|r| r.n).into_pyarray(py).into_any()),
        ("hurst", values(&|r| r.hurst).into_pyarray(py).into_any()),
        (
            "min_contacts",
            counts(&|r| r.min_contacts).into_pyarray(py).into_any(),
        ),
        (
            "max_fraction",
            values(&|r| r.max_fraction).into_pyarray(py).into_any(),
        ),
        ("alpha", values(&|r| r.alpha).into_pyarray(py).into_any()),
        ("low", values(&|r| r.low).into_pyarray(py).into_any()),
        ("high", values(&|r| r.high).into_pyarray(py).into_any()),
        (
            "samples",
            counts(&|r| r.samples).into_pyarray(py).into_any(),
        ),
    ];
    debug_assert!(columns.iter().map(|c| c.0).eq(COLUMNS));
    let dict = PyDict::new(py);
    for (name, column) in columns {
        dict.set_item(name, column)?;
    }
    Ok(dict)
}

/// A study file read by the front-end layer's reader (`asperity_app::study::file::read`, the
/// one `asperity study file` uses): its keywords for `run_study` (kind, method, sizes,
/// hursts, samples, rolloff, seed, min_contacts, max_fraction, levels, full_sweep, poisson,
/// resistivity, thermal_conductivity); its refusals are the CLI's words.
#[pyfunction]
pub fn read_study_file(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let text = asperity::input::read_text(&path, asperity::input::TEXT_MAX_BYTES)
        .map_err(crate::errors::from_error)?;
    let read = asperity_app::study::file::read(&path, &text).map_err(crate::errors::refused)?;
    let r = read.request;
    let dict = PyDict::new(py);
    let kind = match r.kind {
        asperity_app::study::Kind::Curve => "curve",
        _ => "alpha",
    };
    dict.set_item("kind", kind)?;
    dict.set_item("method", r.method)?;
    dict.set_item("sizes", r.sizes)?;
    dict.set_item("hursts", r.hursts)?;
    dict.set_item("samples", r.samples)?;
    dict.set_item("rolloff", r.rolloff)?;
    dict.set_item("seed", r.seed)?;
    dict.set_item("min_contacts", r.min_contacts)?;
    dict.set_item("max_fraction", r.max_fraction)?;
    dict.set_item("levels", r.levels)?;
    dict.set_item("full_sweep", r.full_sweep)?;
    dict.set_item("poisson", r.poisson)?;
    dict.set_item("tangential", r.tangential)?;
    dict.set_item("resistivity", read.resistivity)?;
    dict.set_item("thermal_conductivity", read.thermal_conductivity)?;
    Ok(dict)
}
