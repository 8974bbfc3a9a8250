//! What a figure shows ([`asperity_app::figure`]), for `asperity.plot`: the charts the CLI
//! draws with `--plot`, as JSON, which the package draws with matplotlib.

use asperity_app::bem::branches;
use asperity_app::figure::analysis::{analysis_chart, AnalysisFigure};
use asperity_app::figure::contact::{contact_charts, ContactColumns};
use asperity_app::figure::map::{contact_map_chart, surface_chart, MapFigure};
use asperity_app::figure::path::{PathColumns, PathFigure};
use asperity_app::figure::psd::{psd_chart, PsdFigure};
use asperity_app::figure::{self, sweep::SweepColumns, sweep::SweepFigure};
use asperity_app::stats::analysis::Analysis;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sweep_figure, m)?)?;
    m.add_function(wrap_pyfunction!(path_figure, m)?)?;
    m.add_function(wrap_pyfunction!(adhesion_loop_figure, m)?)?;
    m.add_function(wrap_pyfunction!(mdr_figure, m)?)?;
    m.add_function(wrap_pyfunction!(surface_figure, m)?)?;
    m.add_function(wrap_pyfunction!(contact_map_figure, m)?)?;
    m.add_function(wrap_pyfunction!(psd_figure, m)?)?;
    m.add_function(wrap_pyfunction!(contact_figure, m)?)?;
    m.add_function(wrap_pyfunction!(analysis_figure, m)?)?;
    Ok(())
}

/// An MDR curve's figure as `asperity mdr --plot FILE.json` writes it
/// ([`asperity_app::figure::mdr::mdr_charts`]): the columns d, F, k, the indenter's
/// description, the spring law and E*.
#[pyfunction]
#[pyo3(signature = (indentation, force, stiffness, description, law, modulus))]
fn mdr_figure(
    indentation: Vec<f64>,
    force: Vec<f64>,
    stiffness: Vec<f64>,
    description: &str,
    law: &str,
    modulus: f64,
) -> PyResult<String> {
    use asperity_app::figure::mdr::{mdr_charts, MdrColumns, MdrFigure};
    same_length(
        "mdr_figure",
        &[
            ("indentation", indentation.len()),
            ("force", force.len()),
            ("stiffness", stiffness.len()),
        ],
    )?;
    let columns = MdrColumns {
        indentation: &indentation,
        force: &force,
        stiffness: &stiffness,
    };
    let figure = MdrFigure {
        description,
        law,
        modulus,
    };
    Ok(figure::to_json(&mdr_charts(columns, figure)).to_string())
}

/// An adhesive loop's figure as `asperity bem|contact|mdr --work-of-adhesion --plot
/// FILE.json` writes it ([`asperity_app::figure::adhesion::loop_chart`]): per state `(d,
/// F)` and whether it is the retraction's; both pull-offs `((d, F), (d, F))` (force,
/// displacement control); the labels and the forces' unit; a dashed theory curve.
#[pyfunction]
#[pyo3(signature = (indentation, force, retract, pull_off, title, x_label, y_label, force_unit, theory=None))]
#[allow(clippy::too_many_arguments)]
fn adhesion_loop_figure(
    indentation: Vec<f64>,
    force: Vec<f64>,
    retract: Vec<bool>,
    pull_off: Option<((f64, f64), (f64, f64))>,
    title: String,
    x_label: String,
    y_label: String,
    force_unit: String,
    theory: Option<(String, Vec<(f64, f64)>)>,
) -> PyResult<String> {
    use asperity_app::figure::adhesion::{loop_chart, LoopFigure, LoopPoint, LoopPullOffs};
    same_length(
        "adhesion_loop_figure",
        &[
            ("indentation", indentation.len()),
            ("force", force.len()),
            ("retract", retract.len()),
        ],
    )?;
    let points: Vec<LoopPoint> = (0..indentation.len())
        .map(|k| LoopPoint {
            indentation: indentation[k],
            force: force[k],
            retract: retract[k],
        })
        .collect();
    let pull = pull_off.map(|(f, d)| LoopPullOffs {
        force_controlled: f,
        displacement_controlled: d,
    });
    let figure = LoopFigure {
        title,
        x_label,
        y_label,
        force_unit,
        theory,
    };
    Ok(figure::to_json(&[loop_chart(&points, pull, figure)]).to_string())
}

/// The height map's figure as `asperity surface --plot FILE.json` writes it (heights rows
/// × cols, row 0 at y = 0; sizes along x and y; lengths in metres or the surface's unit).
#[pyfunction]
fn surface_figure(
    heights: PyReadonlyArray2<'_, f64>,
    size_x: f64,
    size_y: f64,
    metres: bool,
    name: &str,
) -> String {
    let figure = map_figure(name, (size_x, size_y), metres);
    figure::to_json(&[surface_chart(heights.as_array(), figure)]).to_string()
}

/// The contact map's figure as `asperity contact --map FILE.json` writes it.
#[pyfunction]
fn contact_map_figure(
    set: PyReadonlyArray2<'_, bool>,
    size_x: f64,
    size_y: f64,
    metres: bool,
    name: &str,
) -> String {
    let figure = map_figure(name, (size_x, size_y), metres);
    figure::to_json(&[contact_map_chart(set.as_array(), figure)]).to_string()
}

/// The map figure of both maps above: its name, sides along x and y, lengths in metres
/// or the surface's unit.
fn map_figure(name: &str, size: (f64, f64), metres: bool) -> MapFigure<'_> {
    MapFigure { name, size, metres }
}

/// The PSD's figure as `asperity stats --plot FILE.json` writes it: bins (q, psd), the
/// side length, 1 or 2 dimensions, the fit range in q·L/2π, the fit (prefactor,
/// exponent) and the Hurst estimate.
#[pyfunction]
#[pyo3(signature = (q, psd, size, ndim, range, fit, hurst, name))]
#[allow(clippy::too_many_arguments)]
fn psd_figure(
    q: Vec<f64>,
    psd: Vec<f64>,
    size: f64,
    ndim: usize,
    range: Option<(f64, f64)>,
    fit: Option<(f64, f64)>,
    hurst: Option<f64>,
    name: &str,
) -> PyResult<String> {
    same_length("psd_figure", &[("q", q.len()), ("psd", psd.len())])?;
    let figure = PsdFigure {
        name,
        q: &q,
        psd: &psd,
        size,
        ndim,
        range,
        fit,
        hurst,
    };
    Ok(figure::to_json(&[psd_chart(figure)]).to_string())
}

/// An analysis' figure as `asperity stats --acf FILE.json` (and the other analysis
/// options) writes it: the analysis' name (`acf`, ...), its two columns, lengths in metres
/// or the heights' own unit.
#[pyfunction]
fn analysis_figure(
    analysis: &str,
    x: Vec<f64>,
    y: Vec<f64>,
    metres: bool,
    name: &str,
) -> PyResult<String> {
    let analysis = Analysis::parse(analysis).map_err(crate::errors::refused)?;
    same_length("analysis_figure", &[("x", x.len()), ("y", y.len())])?;
    let rows: Vec<(f64, f64)> = x.into_iter().zip(y).collect();
    let figure = AnalysisFigure {
        name,
        analysis,
        metres,
    };
    Ok(figure::to_json(&[analysis_chart(&rows, figure)]).to_string())
}

/// The two panels of a load sweep (k(F), A/A₀(F)) as `asperity bem --plot FILE.json`
/// writes them: columns of equal length (NaN where not computed).
#[pyfunction]
#[pyo3(signature = (force, stiffness, stiffness_fd, area_fraction, name, modulus, physical, boundary))]
#[allow(clippy::too_many_arguments)]
fn sweep_figure(
    force: Vec<f64>,
    stiffness: Vec<f64>,
    stiffness_fd: Option<Vec<f64>>,
    area_fraction: Vec<f64>,
    name: &str,
    modulus: f64,
    physical: bool,
    boundary: &str,
) -> PyResult<String> {
    let mut lengths = vec![
        ("force", force.len()),
        ("stiffness", stiffness.len()),
        ("area_fraction", area_fraction.len()),
    ];
    lengths.extend(stiffness_fd.as_ref().map(|fd| ("stiffness_fd", fd.len())));
    same_length("sweep_figure", &lengths)?;
    let columns = SweepColumns {
        force: &force,
        stiffness: &stiffness,
        stiffness_fd: stiffness_fd.as_deref(),
        area_fraction: &area_fraction,
    };
    let figure = SweepFigure {
        name,
        modulus,
        physical,
        boundary,
    };
    let charts = figure::sweep::sweep_charts(columns, figure);
    Ok(figure::to_json(&charts).to_string())
}

/// The three panels of a load path (F(d), A/A₀(d), k(F), steps marked by branch) as
/// `asperity bem --load-path --plot FILE.json` writes them; `values`: the path's loads or
/// indentations in order (their branches), the columns one value per step.
#[pyfunction]
#[pyo3(signature = (values, indentation, force, area_fraction, stiffness, name, boundary, hardness))]
#[allow(clippy::too_many_arguments)]
fn path_figure(
    values: Vec<f64>,
    indentation: Vec<f64>,
    force: Vec<f64>,
    area_fraction: Vec<f64>,
    stiffness: Vec<f64>,
    name: &str,
    boundary: &str,
    hardness: Option<f64>,
) -> PyResult<String> {
    same_length(
        "path_figure",
        &[
            ("values", values.len()),
            ("indentation", indentation.len()),
            ("force", force.len()),
            ("area_fraction", area_fraction.len()),
            ("stiffness", stiffness.len()),
        ],
    )?;
    let branch = branches(&values);
    let columns = PathColumns {
        branch: &branch,
        indentation: &indentation,
        force: &force,
        area_fraction: &area_fraction,
        stiffness: &stiffness,
    };
    let figure = PathFigure {
        name,
        boundary,
        hardness,
    };
    let charts = figure::path::path_charts(columns, figure);
    Ok(figure::to_json(&charts).to_string())
}

/// The three panels of an SI contact sweep (k(F), A(F), mean gap against F; N, N/m, m², m)
/// as `asperity contact --plot FILE.json` writes them; `modulus`: E* in Pa.
#[pyfunction]
fn contact_figure(
    force: Vec<f64>,
    stiffness: Vec<f64>,
    area: Vec<f64>,
    mean_gap: Vec<f64>,
    modulus: f64,
    name: &str,
) -> PyResult<String> {
    same_length(
        "contact_figure",
        &[
            ("force", force.len()),
            ("stiffness", stiffness.len()),
            ("area", area.len()),
            ("mean_gap", mean_gap.len()),
        ],
    )?;
    let columns = ContactColumns {
        force: &force,
        stiffness: &stiffness,
        area: &area,
        mean_gap: &mean_gap,
    };
    Ok(figure::to_json(&contact_charts(columns, name, modulus)).to_string())
}

/// The one check of every figure above whose columns go side by side: `columns` as `(name,
/// length)`, each as long as the first, else a `ValueError` naming `what` (the function),
/// the first column that differs and both lengths.
fn same_length(what: &str, columns: &[(&str, usize)]) -> PyResult<()> {
    let Some(((first, expected), rest)) = columns.split_first() else {
        return Ok(());
    };
    match rest.iter().find(|(_, length)| length != expected) {
        Some((name, length)) => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "{what}: the column {name} has {length} values, {first} has {expected}"
        ))),
        None => Ok(()),
    }
}
