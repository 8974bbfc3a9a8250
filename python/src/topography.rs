//! Measured topographies through the library's readers (`asperity import` / `stats FILE`):
//! X3P, SDF, text and Gwyddion matrices, x y z lists, profiles, SUR, PLU, OPD, DI, AL3D,
//! MetroPro, FRT, WSxM, TMD and `.npy`, detected by content first, then by extension.

use std::path::PathBuf;

use asperity::topography::{read_file, ChannelChoice, Heights, ReadOptions};
use numpy::IntoPyArray;
use pyo3::prelude::*;

use crate::errors::from_error;
use crate::interrupt::run_detached;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_topography, m)?)?;
    Ok(())
}

/// Reads a measured file with the GIL released: the heights (rows × cols = y × x for a
/// map, or a profile; metres where the file gives a length unit, NaN where undefined), the
/// physical sizes (`[x, y]` or `[x]`) and the provenance as JSON (source, format, channel,
/// channels, units, size source).
#[pyfunction]
#[pyo3(signature = (path, channel, size_x, size_y))]
fn read_topography(
    py: Python<'_>,
    path: PathBuf,
    channel: Option<String>,
    size_x: Option<f64>,
    size_y: Option<f64>,
) -> PyResult<(Py<PyAny>, Vec<f64>, String)> {
    let options = ReadOptions {
        channel: channel.map(|c| c.parse::<ChannelChoice>().unwrap_or_else(|e| match e {})),
        size: size_x.map(|x| [Some(x), size_y]),
        ..ReadOptions::default()
    };
    let topography = run_detached(py, |_| read_file(&path, &options))?.map_err(from_error)?;
    let provenance =
        serde_json::to_string(&topography.provenance).expect("the provenance serialises");
    let heights = match topography.heights {
        Heights::Areal(h) => h.into_pyarray(py).into_any().unbind(),
        Heights::Profile(h) => h.into_pyarray(py).into_any().unbind(),
    };
    Ok((heights, topography.sizes, provenance))
}
