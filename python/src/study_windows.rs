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
