//! Measured topographies through the front-end layer's one call for any surface argument
//! (`asperity_app::argument::open`, the one every CLI command uses): X3P, SDF,
//! text and Gwyddion matrices, x y z lists, profiles, SUR, PLU, OPD, DI, AL3D, MetroPro,
//! FRT, WSxM, TMD and `.npy`, detected by content first, then by extension; levelled and
//! filled as asked, with the CLI's warnings.

use std::path::PathBuf;

use asperity::io::StagedOutputs;
use asperity::topography::{Fill, Heights, Provenance, Topography};
use asperity_app::argument::{open, Arrays, Input};
use asperity_app::import::Import;
use asperity_app::measured::{MeasuredRequest, WarningKind};
use asperity_app::{Names, RequestError};
use numpy::{IntoPyArray, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::arrays;
use crate::errors::{from_error, invalid, request_error};
use crate::interrupt::run_detached;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_topography, m)?)?;
    m.add_function(wrap_pyfunction!(import_topography, m)?)?;
    m.add_function(wrap_pyfunction!(save_topography, m)?)?;
    m.add_function(wrap_pyfunction!(save_files, m)?)?;
    m.add_function(wrap_pyfunction!(saved_sidecar, m)?)?;
    m.add_function(wrap_pyfunction!(sizes, m)?)?;
    Ok(())
}

/// `size=` of a surface or line argument as `(x, y)` (`y` None: square pixels), by the rule
/// of the CLI's `--size` ([`asperity_app::argument::sizes`]).
#[pyfunction]
fn sizes(values: Vec<f64>) -> PyResult<(Option<f64>, Option<f64>)> {
    let [x, y] = asperity_app::argument::sizes(&values).map_err(crate::errors::refused)?;
    Ok((x, y))
}

/// The sidecar of a file `asperity.load` loads back, as JSON text, or None: by the rules of
/// every input ([`asperity_app::argument::saved_sidecar`]: the file and its sidecar regular
/// files, the sidecar bounded and valid JSON; a FIFO is refused, not waited on).
#[pyfunction]
fn saved_sidecar(path: PathBuf) -> PyResult<Option<String>> {
    let value = asperity_app::argument::saved_sidecar(&path).map_err(from_error)?;
    Ok(value.map(|v| v.to_string()))
}

/// What `read_topography` hands to Python: the heights, the sizes, the provenance (JSON)
/// and the warnings as `(category, words)`.
type Read = (Py<PyAny>, Vec<f64>, String, Vec<(&'static str, String)>);

/// Reads and cleans a measured file with the GIL released: the heights (rows × cols = y × x
/// for a map, or a profile; metres where the file gives a length unit, NaN where undefined
/// and no filling was named), the physical sizes (`[x, y]` or `[x]`), the provenance as
/// JSON (source, format, channel, channels, units, size source, cleaning) and the warnings
/// (`unlevelled` or `unit`, with their words).
#[pyfunction]
#[pyo3(signature = (path, channel, size_x, size_y, detrend, fill))]
fn read_topography(
    py: Python<'_>,
    path: PathBuf,
    channel: Option<String>,
    size_x: Option<f64>,
    size_y: Option<f64>,
    detrend: Option<String>,
    fill: Option<String>,
) -> PyResult<Read> {
    let request = MeasuredRequest {
        channel,
        size: size_x.map(|x| [Some(x), size_y]),
        detrend,
        fill,
    };
    let opened = run_detached(py, |_| {
        open(&path, &request, Arrays::Measured, Some(Fill::Keep))
    })?
    .map_err(request_error)?;
    Ok(to_python(py, opened))
}

/// `asperity import`: reads and cleans a measured file as [`read_topography`] (undefined
/// points refused unless a filling is named, as the CLI) and writes it into `out` by the
/// front-end layer's writer ([`Import`]: `.npy` with the import sidecar, or `.x3p`), the
/// outputs checked before the file is read and written all or nothing; returns what
/// `read_topography` returns.
#[pyfunction]
#[pyo3(signature = (path, out, channel, size_x, size_y, detrend, fill, force))]
#[allow(clippy::too_many_arguments)]
fn import_topography(
    py: Python<'_>,
    path: PathBuf,
    out: PathBuf,
    channel: Option<String>,
    size_x: Option<f64>,
    size_y: Option<f64>,
    detrend: Option<String>,
    fill: Option<String>,
    force: bool,
) -> PyResult<Read> {
    let request = MeasuredRequest {
        channel,
        size: size_x.map(|x| [Some(x), size_y]),
        detrend,
        fill,
    };
    let opened = run_detached(py, |_| {
        let import = Import::stage(&path, &out, force)?;
        let opened = open(&path, &request, Arrays::Measured, None)?;
        import.write(&path, &opened.topography)?;
        Ok::<_, RequestError>(opened)
    })?
    .map_err(request_error)?;
    Ok(to_python(py, opened))
}

/// The heights, sizes, provenance (JSON) and warnings of an opened file.
fn to_python(py: Python<'_>, opened: Input) -> Read {
    let warnings = opened
        .warnings
        .iter()
        .map(|w| {
            let category = match w.kind {
                WarningKind::Unlevelled => "unlevelled",
                WarningKind::NoUnit => "unit",
            };
            (category, w.words.words(Names::Keywords))
        })
        .collect();
    let topography = opened.topography;
    let provenance =
        serde_json::to_string(&topography.provenance).expect("the provenance serialises");
    let heights = match topography.heights {
        Heights::Areal(h) => h.into_pyarray(py).into_any().unbind(),
        Heights::Profile(h) => h.into_pyarray(py).into_any().unbind(),
    };
    (heights, topography.sizes, provenance, warnings)
}

/// Writes a topography as `asperity import` does (the front-end layer's one writer,
/// `asperity_app::import`):
/// `path` `.npy` with its sidecar, or `.x3p` for a map. `provenance` is the JSON of
/// `read_topography`'s record.
#[pyfunction]
#[pyo3(signature = (path, array, sizes, provenance, force))]
fn save_topography(
    py: Python<'_>,
    path: PathBuf,
    array: PyReadonlyArrayDyn<'_, f64>,
    sizes: Vec<f64>,
    provenance: &str,
    force: bool,
) -> PyResult<()> {
    let provenance: Provenance =
        serde_json::from_str(provenance).map_err(|e| invalid(format!("provenance: {e}")))?;
    let heights = match arrays::heights(&array, "heights")? {
        arrays::Heights::Line(h) => Heights::Profile(h),
        arrays::Heights::Surface(h) => Heights::Areal(h),
    };
    let needed = heights.shape().len();
    if sizes.len() != needed || !sizes.iter().all(|s| s.is_finite() && *s > 0.0) {
        return Err(invalid(format!(
            "sizes: expected {needed} positive finite sizes, got {sizes:?}"
        )));
    }
    let topography = Topography {
        heights,
        sizes,
        provenance,
    };
    let input = topography.provenance.source.clone();
    let import = Import::stage(&input, &path, force).map_err(request_error)?;
    run_detached(py, |_| import.write(&input, &topography))?.map_err(request_error)
}

/// Writes files all-or-nothing as the CLI writes its outputs (`asperity::io::StagedOutputs`):
/// each `(path, bytes)` to a synced temporary file beside it, then all renamed into place;
/// an existing file is refused unless `force`.
#[pyfunction]
#[pyo3(signature = (files, force))]
fn save_files(files: Vec<(PathBuf, Bound<'_, PyBytes>)>, force: bool) -> PyResult<()> {
    if files.is_empty() {
        return Err(invalid("nothing to write"));
    }
    let mut staged = StagedOutputs::new(files.iter().map(|(p, _)| p), force).map_err(from_error)?;
    for (path, bytes) in &files {
        staged
            .write_bytes(path, bytes.as_bytes())
            .map_err(from_error)?;
    }
    staged.commit().map_err(from_error)
}
