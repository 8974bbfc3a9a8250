//! Python's `persson()`: Persson's theory from a surface's own PSD by the front-end layer's
//! one path (`asperity_app::persson`), the one `asperity persson` runs: the same request,
//! rules, columns and numbers.

use asperity::persson::PerssonParams;
use asperity::surface::Surface;
use asperity_app::persson::{self, compute, params, PerssonRequest, COLUMNS};
use asperity_app::refusal::count;
use numpy::{IntoPyArray, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::owned_2d;
use crate::errors::{from_error, refused, request_error};
use crate::interrupt::run_detached;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(persson_table, m)?)?;
    Ok(())
}

/// The table of `asperity persson` for heights `array` (rows × cols) of sizes `size_x` and
/// `size_y` (`None`: square pixels): one array per column, with the surface's rms height,
/// spectral rms gradient and `u0`. The pressures are `pressures`, or `nloads` log-spaced
/// from `pmin` to `pmax`.
#[pyfunction]
#[pyo3(signature = (array, size_x, size_y, modulus, gamma, kappa, pressures, nloads, pmin, pmax))]
#[allow(clippy::too_many_arguments)]
fn persson_table<'py>(
    py: Python<'py>,
    array: PyReadonlyArray2<'_, f64>,
    size_x: f64,
    size_y: Option<f64>,
    modulus: f64,
    gamma: f64,
    kappa: f64,
    pressures: Option<Vec<f64>>,
    nloads: Option<i128>,
    pmin: Option<f64>,
    pmax: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let nloads = (nloads.map(|n| count(params::NLOADS, n)).transpose()).map_err(refused)?;
    let pressures = persson::pressures(pressures, nloads, pmin, pmax).map_err(request_error)?;
    let request = PerssonRequest {
        params: PerssonParams {
            modulus,
            gamma,
            kappa,
        },
        pressures,
    };
    request.validate().map_err(request_error)?;
    let owned = owned_2d(&array);
    let surface = match size_y {
        Some(size_y) => Surface::with_sizes(owned, size_x, size_y),
        None => Surface::new(owned, size_x),
    }
    .map_err(from_error)?;
    let table = run_detached(py, move |_| compute(&surface, &request))?.map_err(request_error)?;
    let dict = PyDict::new(py);
    for (k, name) in COLUMNS.iter().enumerate() {
        let column = ndarray::Array1::from_iter(table.rows.iter().map(|row| row[k]));
        dict.set_item(*name, column.into_pyarray(py))?;
    }
    dict.set_item("rms_height", table.rms_height)?;
    dict.set_item("rms_gradient", table.rms_gradient)?;
    dict.set_item("u0", table.u0)?;
    Ok(dict)
}
