//! Surfaces and lines (`asperity surface`, `asperity line`), their statistics and PSD
//! (`asperity stats`): the same library calls as `crates/asperity-cli/src/commands/
//! surface.rs` and `stats.rs`.

use std::path::PathBuf;

use asperity::fit::power_law_fit;
use asperity::io::{sidecar_path, StagedOutputs};
use asperity::surface::stats::{line_psd, line_summary, radial_psd_2d, surface_summary};
use asperity::surface::{Line, LineGenerator, Surface, SurfaceGenerator};
use asperity_app::surface::{ensure_usable, sidecar, SurfaceRequest};
use numpy::{IntoPyArray, PyArray1, PyArrayDyn, PyReadonlyArray1, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{heights, owned_1d, Heights};
use crate::errors::{from_error, invalid, refused, request_error};
use crate::interrupt::run_detached;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(generate_surface, m)?)?;
    m.add_function(wrap_pyfunction!(generate_line, m)?)?;
    m.add_function(wrap_pyfunction!(save_heights, m)?)?;
    m.add_function(wrap_pyfunction!(summary, m)?)?;
    m.add_function(wrap_pyfunction!(psd, m)?)?;
    m.add_function(wrap_pyfunction!(fit_power_law, m)?)?;
    Ok(())
}

/// The request of Python's keywords (`m`: a surface's rows, `None` for a line).
#[allow(clippy::too_many_arguments)]
fn request(
    n: usize,
    m: Option<usize>,
    hurst: f64,
    (rolloff, cutoff, short_cutoff): (Option<f64>, Option<f64>, Option<f64>),
    (rms_height, rms_slope): (Option<f64>, Option<f64>),
    size: f64,
    seed: String,
) -> SurfaceRequest {
    SurfaceRequest {
        n,
        m,
        hurst,
        rolloff,
        cutoff,
        short_cutoff,
        rms_height,
        rms_slope,
        size,
        seed,
    }
}

/// Generates a surface; returns its heights and the CLI's sidecar (JSON text).
#[pyfunction]
#[pyo3(signature = (n, m, hurst, rolloff, cutoff, short_cutoff, rms_height, rms_slope, size, seed))]
#[allow(clippy::too_many_arguments)]
fn generate_surface<'py>(
    py: Python<'py>,
    n: usize,
    m: Option<usize>,
    hurst: f64,
    rolloff: Option<f64>,
    cutoff: Option<f64>,
    short_cutoff: Option<f64>,
    rms_height: Option<f64>,
    rms_slope: Option<f64>,
    size: f64,
    seed: String,
) -> PyResult<(Bound<'py, numpy::PyArray2<f64>>, String)> {
    let cutoffs = (rolloff, cutoff, short_cutoff);
    let (spec, seed) = request(n, m, hurst, cutoffs, (rms_height, rms_slope), size, seed)
        .surface()
        .map_err(request_error)?;
    let rows = spec.rows();
    // The statistics' sums are parallel: on the calling thread's pool too (see `summary`).
    let (surface, stats) = run_detached(py, |_| {
        let surface = SurfaceGenerator::new(&spec).and_then(|mut g| g.try_generate(seed))?;
        let stats = surface_summary(&surface);
        Ok((surface, stats))
    })?
    .map_err(from_error)?;
    ensure_usable(&stats, size).map_err(refused)?;
    let meta = sidecar("surface", &[rows, n], seed, &spec, &stats).to_string();
    Ok((surface.into_heights().into_pyarray(py), meta))
}

/// Generates a line; returns its heights and the CLI's sidecar (JSON text).
#[pyfunction]
#[pyo3(signature = (n, hurst, rolloff, cutoff, rms_height, rms_slope, size, seed))]
#[allow(clippy::too_many_arguments)]
fn generate_line<'py>(
    py: Python<'py>,
    n: usize,
    hurst: f64,
    rolloff: Option<f64>,
    cutoff: Option<f64>,
    rms_height: Option<f64>,
    rms_slope: Option<f64>,
    size: f64,
    seed: String,
) -> PyResult<(Bound<'py, PyArray1<f64>>, String)> {
    let cutoffs = (rolloff, cutoff, None);
    let (spec, seed) = request(n, None, hurst, cutoffs, (rms_height, rms_slope), size, seed)
        .line()
        .map_err(request_error)?;
    let (line, stats) = run_detached(py, |_| {
        let line = LineGenerator::new(&spec).and_then(|mut g| g.try_generate(seed))?;
        let stats = line_summary(&line);
        Ok((line, stats))
    })?
    .map_err(from_error)?;
    ensure_usable(&stats, size).map_err(refused)?;
    let meta = sidecar("line", &[n], seed, &spec, &stats).to_string();
    Ok((line.into_heights().into_pyarray(py), meta))
}

/// Writes heights as `.npy` with the sidecar `FILE.npy.json` (JSON text `metadata`),
/// both or neither, as the CLI does.
#[pyfunction]
#[pyo3(signature = (path, array, metadata, force))]
fn save_heights(
    path: PathBuf,
    array: PyReadonlyArrayDyn<'_, f64>,
    metadata: &str,
    force: bool,
) -> PyResult<()> {
    let record: serde_json::Value =
        serde_json::from_str(metadata).map_err(|e| invalid(format!("metadata: {e}")))?;
    let sidecar = sidecar_path(&path);
    let mut staged = StagedOutputs::new([&path, &sidecar], force).map_err(from_error)?;
    match heights(&array, "heights")? {
        Heights::Line(h) => staged.write_npy_1d(&path, &h),
        Heights::Surface(h) => staged.write_npy_2d(&path, &h),
    }
    .map_err(from_error)?;
    staged.write_json(&sidecar, &record).map_err(from_error)?;
    staged.commit().map_err(from_error)
}

/// A line or a surface of the given heights and side length.
enum Profile {
    Line(Line),
    Surface(Surface),
}

fn profile(array: &PyReadonlyArrayDyn<'_, f64>, size: f64) -> PyResult<Profile> {
    match heights(array, "heights")? {
        Heights::Line(h) => Line::new(h, size).map(Profile::Line),
        Heights::Surface(h) => Surface::new(h, size).map(Profile::Surface),
    }
    .map_err(from_error)
}

/// rms height, slope and curvature (`asperity stats`).
#[pyfunction]
fn summary<'py>(
    py: Python<'py>,
    array: PyReadonlyArrayDyn<'_, f64>,
    size: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let profile = profile(&array, size)?;
    // On the calling thread's pool like every computation here (its sums are parallel):
    // rayon's global pool has no threads in a process forked after it started.
    let s = run_detached(py, move |_| match profile {
        Profile::Line(line) => line_summary(&line),
        Profile::Surface(surface) => surface_summary(&surface),
    })?;
    let dict = PyDict::new(py);
    dict.set_item("rms_height", s.rms_height)?;
    dict.set_item("rms_slope", s.rms_slope)?;
    dict.set_item("rms_curvature", s.rms_curvature)?;
    Ok(dict)
}

/// The PSD (radially averaged for a surface): wavenumbers q, PSD values and the number of
/// Fourier modes of each bin.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn psd<'py>(
    py: Python<'py>,
    array: PyReadonlyArrayDyn<'_, f64>,
    size: f64,
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<u64>>,
)> {
    let profile = profile(&array, size)?;
    let bins = run_detached(py, move |_| match profile {
        Profile::Line(line) => Ok(line_psd(&line)),
        Profile::Surface(surface) => radial_psd_2d(&surface),
    })?
    .map_err(from_error)?;
    let column = |f: &dyn Fn(&asperity::surface::stats::PsdBin) -> f64| {
        ndarray::Array1::from_iter(bins.iter().map(f)).into_dyn()
    };
    let modes = ndarray::Array1::from_iter(bins.iter().map(|b| b.modes as u64)).into_dyn();
    Ok((
        column(&|b| b.q).into_pyarray(py),
        column(&|b| b.psd).into_pyarray(py),
        modes.into_pyarray(py),
    ))
}

/// Least-squares power law `y = A x^p` on log–log axes, with the 95 % interval of `p`.
#[pyfunction]
fn fit_power_law<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (x, y) = (owned_1d(&x), owned_1d(&y));
    let fit = power_law_fit(
        x.as_slice().expect("contiguous"),
        y.as_slice().expect("contiguous"),
    )
    .map_err(from_error)?;
    let dict = PyDict::new(py);
    dict.set_item("exponent", fit.exponent)?;
    dict.set_item("prefactor", fit.prefactor)?;
    dict.set_item("stderr", fit.stderr)?;
    dict.set_item("low", fit.low)?;
    dict.set_item("high", fit.high)?;
    dict.set_item("points", fit.points)?;
    Ok(dict)
}
