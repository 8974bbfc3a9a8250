//! Surfaces and lines (`asperity surface`, `asperity line`), their statistics and PSD
//! (`asperity stats`): conversions to and from the front-end layer's requests
//! (`asperity_app::surface`, `asperity_app::stats`), the ones the CLI makes.

use std::path::PathBuf;

use asperity::io::{sidecar_path, StagedOutputs};
use asperity::surface::stats::{line_summary, surface_summary};
use asperity::surface::{LineGenerator, SurfaceGenerator};
use asperity::topography;
use asperity_app::stats::analysis::{analyse, Analysis};
use asperity_app::stats::{
    compute, parse_window, PsdConvention, SpectrumHints, Statistics, StatsRequest, StatsSource,
};
use asperity_app::surface::{ensure_usable, grid, sidecar, SurfaceRequest};
use asperity_app::Names;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{heights, Heights};
use crate::errors::{from_error, invalid, refused, request_error};
use crate::interrupt::run_detached;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(generate_surface, m)?)?;
    m.add_function(wrap_pyfunction!(generate_line, m)?)?;
    m.add_function(wrap_pyfunction!(save_heights, m)?)?;
    m.add_function(wrap_pyfunction!(statistics, m)?)?;
    m.add_function(wrap_pyfunction!(analyses, m)?)?;
    m.add_function(wrap_pyfunction!(analysis_names, m)?)?;
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
    n: i128,
    m: Option<i128>,
    hurst: f64,
    rolloff: Option<f64>,
    cutoff: Option<f64>,
    short_cutoff: Option<f64>,
    rms_height: Option<f64>,
    rms_slope: Option<f64>,
    size: f64,
    seed: String,
) -> PyResult<(Bound<'py, numpy::PyArray2<f64>>, String)> {
    let (n, m) = grid(n, m).map_err(refused)?;
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
    n: i128,
    hurst: f64,
    rolloff: Option<f64>,
    cutoff: Option<f64>,
    rms_height: Option<f64>,
    rms_slope: Option<f64>,
    size: f64,
    seed: String,
) -> PyResult<(Bound<'py, PyArray1<f64>>, String)> {
    let (n, _) = grid(n, None).map_err(refused)?;
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
/// The statistics of `asperity stats`, by the front-end layer's one path: heights on square
/// pixels of side `size_x / cols` with the spectrum hints of a generated surface's metadata
/// (JSON), or (`measured`) a measured topography with a size per axis (`size_y` `None`:
/// square pixels), which adds the ISO parameters. Returns the CLI's `--json` fields with
/// the PSD's `q`, `psd` and `modes` as arrays.
#[pyfunction]
#[pyo3(signature = (array, size_x, size_y, measured, metadata, fit_from, fit_to, window, convention))]
#[allow(clippy::too_many_arguments)]
fn statistics<'py>(
    py: Python<'py>,
    array: PyReadonlyArrayDyn<'_, f64>,
    size_x: f64,
    size_y: Option<f64>,
    measured: bool,
    metadata: Option<String>,
    fit_from: Option<f64>,
    fit_to: Option<f64>,
    window: &str,
    convention: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let request = StatsRequest {
        fit_from,
        fit_to,
        window: parse_window(window).map_err(refused)?,
        convention: PsdConvention::parse(convention).map_err(refused)?,
    };
    request.validate().map_err(refused)?;
    let source = stats_source(&array, size_x, size_y, measured, metadata)?;
    // On the calling thread's pool like every computation here (its sums are parallel):
    // rayon's global pool has no threads in a process forked after it started.
    let stats =
        run_detached(py, move |_| compute(&request, source, "heights"))?.map_err(request_error)?;
    statistics_dict(py, &stats)
}

/// What the statistics and the analyses are computed from, by the rules of
/// [`statistics`]: heights on square pixels with a generated surface's spectrum hints, or a
/// measured topography with a size per axis.
fn stats_source(
    array: &PyReadonlyArrayDyn<'_, f64>,
    size_x: f64,
    size_y: Option<f64>,
    measured: bool,
    metadata: Option<String>,
) -> PyResult<StatsSource> {
    Ok(match (heights(array, "heights")?, measured) {
        (Heights::Line(h), true) => StatsSource::Measured {
            heights: topography::Heights::Profile(h),
            sizes: vec![size_x],
        },
        (Heights::Surface(h), true) => {
            let square = size_x * h.nrows() as f64 / h.ncols() as f64;
            StatsSource::Measured {
                heights: topography::Heights::Areal(h),
                sizes: vec![size_x, size_y.unwrap_or(square)],
            }
        }
        (h, false) => {
            let metadata: Option<serde_json::Value> =
                metadata.and_then(|text| serde_json::from_str(&text).ok());
            StatsSource::Grid {
                heights: match h {
                    Heights::Line(h) => h.into_dyn(),
                    Heights::Surface(h) => h.into_dyn(),
                },
                size: size_x,
                hints: metadata
                    .map_or_else(SpectrumHints::default, |v| SpectrumHints::from_sidecar(&v)),
            }
        }
    })
}

/// The tables of `asperity stats`'s analyses (`--acf`, `--bearing-area`, ...), by the
/// front-end layer's one call ([`analyse`]) on the source [`statistics`] takes: `names` are
/// Python's names of the analyses (`acf`, `acf_2d`, ...); returns, for each, its two
/// columns as `(name, array)`.
#[pyfunction]
#[pyo3(signature = (array, size_x, size_y, measured, metadata, names))]
fn analyses<'py>(
    py: Python<'py>,
    array: PyReadonlyArrayDyn<'_, f64>,
    size_x: f64,
    size_y: Option<f64>,
    measured: bool,
    metadata: Option<String>,
    names: Vec<String>,
) -> PyResult<Vec<[Column<'py>; 2]>> {
    let wanted = (names.iter().map(|n| Analysis::parse(n)))
        .collect::<Result<Vec<_>, _>>()
        .map_err(refused)?;
    let source = stats_source(&array, size_x, size_y, measured, metadata)?;
    let tables = run_detached(py, |_| analyse(&source, &wanted))?.map_err(request_error)?;
    Ok((wanted.iter().zip(tables))
        .map(|(analysis, rows)| {
            let [first, second] = analysis.columns();
            let (a, b): (Vec<f64>, Vec<f64>) = rows.into_iter().unzip();
            [(first, a.into_pyarray(py)), (second, b.into_pyarray(py))]
        })
        .collect())
}

/// One column of an analysis: its name and values.
type Column<'py> = (&'static str, Bound<'py, PyArray1<f64>>);

/// The names of the analyses, in the order of `asperity stats --help`.
#[pyfunction]
fn analysis_names() -> Vec<&'static str> {
    Analysis::ALL.iter().map(|a| a.param().keyword).collect()
}

fn statistics_dict<'py>(py: Python<'py>, stats: &Statistics) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let s = &stats.summary;
    dict.set_item("rms_height", s.rms_height)?;
    dict.set_item("rms_slope", s.rms_slope)?;
    dict.set_item("rms_curvature", s.rms_curvature)?;
    let (f, plan) = (stats.fit, &stats.plan);
    dict.set_item("psd_slope", f.map(|f| f.exponent))?;
    dict.set_item("psd_slope_low", f.map(|f| f.low))?;
    dict.set_item("psd_slope_high", f.map(|f| f.high))?;
    dict.set_item("fit_points", f.map(|f| f.points))?;
    dict.set_item("fit_prefactor", f.map(|f| f.prefactor))?;
    dict.set_item("fit_stderr", f.map(|f| f.stderr))?;
    dict.set_item("fit_from", plan.range.map(|r| r.0))?;
    dict.set_item("fit_to", plan.range.map(|r| r.1))?;
    let note = plan.note.as_ref().map(|n| n.words(Names::Keywords));
    dict.set_item("fit_note", note)?;
    dict.set_item("hurst_estimate", stats.hurst)?;
    dict.set_item("iso", stats.iso.as_ref().map(|v| v.to_string()))?;
    dict.set_item("size", stats.size)?;
    let column = |f: &dyn Fn(&asperity::surface::stats::PsdBin) -> f64| {
        ndarray::Array1::from_iter(stats.bins.iter().map(f))
    };
    let modes = ndarray::Array1::from_iter(stats.bins.iter().map(|b| b.modes as u64));
    dict.set_item("q", column(&|b| b.q).into_pyarray(py))?;
    dict.set_item("psd", column(&|b| b.psd).into_pyarray(py))?;
    dict.set_item("modes", modes.into_pyarray(py))?;
    Ok(dict)
}
