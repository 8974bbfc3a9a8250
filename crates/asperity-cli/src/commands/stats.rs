//! `asperity stats FILE.npy`: statistics of a surface (2D) or line (1D).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use asperity::io::StagedOutputs;
use asperity::memory::{array_bytes, ensure_fits};
use asperity::topography::Heights;
use asperity_app::stats::analysis::{analyse, Analysis};
use asperity_app::stats::{
    compute, parse_window, PsdConvention, SpectrumHints, Statistics, StatsRequest, StatsSource,
};
use asperity_app::Names;

use super::measured::{open_argument, parse_size, record as measured_record, MeasuredArgs};
use crate::output::{format_number, Table};
use asperity_app::argument::{Arrays, Dims};
use asperity_app::figure::analysis::{analysis_chart, AnalysisFigure};
use asperity_app::figure::psd::{self, PsdFigure};

use crate::plot::{stage_charts, Chart, ImageFormat};

/// Arguments of `asperity stats`.
#[derive(Debug, clap::Args)]
#[command(
    allow_negative_numbers = true,
    after_help = "Examples:\n  asperity stats s.npy\n  asperity stats s.npy --psd psd.csv --fit-from 6\n  \
    asperity stats s.npy --plot psd.png\n  asperity stats scan.x3p --detrend plane --bearing-area bearing.csv\n  \
    asperity stats scan.x3p --acf acf.csv --acf acf.png --scale-dependent-slope slope.svg\n  \
    asperity stats profile.csv --detrend mean --json\n\n\
    Each analysis option (--bearing-area to --curvature-distribution) writes its table as CSV,\n\
    or its figure where the path ends in .png, .svg or .json (the figure as data): log–log\n\
    against the length scale for --acf, --acf-2d, --variable-bandwidth and the\n\
    scale-dependent slope and curvature, linear for the bearing-area curve and the\n\
    distributions, lengths in metres for a measured file. Give an option twice for both."
)]
pub struct StatsArgs {
    /// A surface (2D) or line (1D): `.npy` (float64), or a measured file (X3P, SDF, text,
    /// x y z, profiles, ...), which adds the ISO 25178 / ISO 4287 parameters.
    pub file: PathBuf,
    /// Side length L (.npy: defaults to the sidecar's, else 1); for a measured file its
    /// physical size X[,Y] in metres where the file has none or to override it.
    #[arg(long, value_name = "X[,Y]")]
    pub size: Option<String>,
    #[command(flatten)]
    pub measured: MeasuredArgs,
    /// Write the (radially averaged) PSD as CSV with columns q (the wavenumber, radians
    /// per unit length), psd (C2D(q) in length⁴ for a surface, C1D(q) in length³ for a
    /// line) and q_l_2pi (q·L/2π: wavelengths per side, the unit of --fit-from, --fit-to
    /// and the plot's axis).
    #[arg(long, value_name = "OUT.csv")]
    pub psd: Option<PathBuf>,
    /// Fit the PSD slope from the ring at this q·L/2π [default: 2; the sidecar's roll-off
    /// q0, or the first ring wholly above its cut-off q0 (q0 + 1), if higher].
    #[arg(long, value_name = "Q")]
    pub fit_from: Option<f64>,
    /// Fit the PSD slope up to the ring at this q·L/2π [default: Nyquist; the last ring
    /// wholly below the sidecar's short cut-off q1 (q1 − 1), if lower]. Clamped to Nyquist.
    #[arg(long, value_name = "Q")]
    pub fit_to: Option<f64>,
    /// Window applied to the heights (mean removed) before the PSD's FFT: none (the scan
    /// is one period of a periodic surface) or hann (a non-periodic scan: Hann along a
    /// line, radial Hann on a map, scaled to keep the power; SurfaceTopography's). The
    /// rms values are of the heights as they are.
    #[arg(long, value_name = "NAME", default_value = asperity_app::stats::DEFAULT_WINDOW)]
    pub window: String,
    /// Normalisation of the PSD (--psd, --plot, the fit's prefactor): asperity
    /// (∫ C d^dq = rms²) or surface-topography (∫ C d^dq/(2π)^d = rms²: asperity's times
    /// (2π)² on a map, 2π on a line). The slope and Hurst estimate are the same.
    #[arg(long, value_name = "NAME", default_value = asperity_app::stats::DEFAULT_CONVENTION)]
    pub psd_convention: String,
    /// Write the bearing-area (Abbott–Firestone) curve as CSV with columns material_ratio
    /// (0 to 1 in 101 steps) and height: the height c above which that fraction of the
    /// defined heights lies (ISO 25178-2's material ratio Smr(c), inverted; linear between
    /// order statistics), in the heights' unit (metres for a measured file).
    #[arg(long, value_name = "OUT.csv|FIG")]
    pub bearing_area: Vec<PathBuf>,
    /// Write the height-difference autocorrelation function along x as CSV with columns
    /// distance (r = kΔx) and acf (A(r) = ½⟨(h(x + r) − h(x))²⟩ over every pair of defined
    /// points at that distance in a row, pooled over the rows; SurfaceTopography's ACF of a
    /// non-periodic scan on its grid), in the heights' unit (squared for acf).
    #[arg(long, value_name = "OUT.csv|FIG")]
    pub acf: Vec<PathBuf>,
    /// Write the radially averaged 2-D height-difference ACF of a map as CSV with columns
    /// distance (the mean |r| of the bin's pairs, bins of width min(Δx, Δy)) and acf
    /// (½⟨(h(x + r) − h(x))²⟩ over every pair of defined points, any direction, whose
    /// distance falls in the bin); refused for a profile.
    #[arg(long, value_name = "OUT.csv|FIG")]
    pub acf_2d: Vec<PathBuf>,
    /// Write the variable-bandwidth analysis as CSV with columns bandwidth (the section
    /// size ℓ) and rms_height: the rms height after a least-squares plane is removed in each
    /// rectangle of a checkerboard of 1, 2, 4, … rectangles a side (a profile: a line in
    /// each of 1, 2, 4, … sections), down to 4 grid points a section
    /// (SurfaceTopography's variable_bandwidth_from_area / _from_profile).
    #[arg(long, value_name = "OUT.csv|FIG")]
    pub variable_bandwidth: Vec<PathBuf>,
    /// Write the scale-dependent rms slope along x as CSV with columns distance (r = kΔx,
    /// k ≥ 1) and slope (√(2A(r))/r from the --acf function: the rms of (h(x + r) − h(x))/r;
    /// SurfaceTopography's scale_dependent_slope_from_profile on the scan's grid).
    #[arg(long, value_name = "OUT.csv|FIG")]
    pub scale_dependent_slope: Vec<PathBuf>,
    /// Write the scale-dependent rms curvature along x as CSV with columns distance (the
    /// stencil's length r = 2sΔx, scale factors s log-spaced, 10 a decade) and curvature
    /// (the rms of (h[i+s] − 2h[i] + h[i−s])/(sΔx)² over the rows; SurfaceTopography's
    /// scale_dependent_statistical_property(n=2) of a profile at that distance).
    #[arg(long, value_name = "OUT.csv|FIG")]
    pub scale_dependent_curvature: Vec<PathBuf>,
    /// Write the height distribution as CSV with columns height (bin centre) and density
    /// (count / (n · bin width): it integrates to 1), over ⌊√n⌋ equal bins (10 to 100) from
    /// the lowest to the highest defined height.
    #[arg(long, value_name = "OUT.csv|FIG")]
    pub height_distribution: Vec<PathBuf>,
    /// Write the distribution of the slopes along x, (h[i+1] − h[i])/Δx within each row, as
    /// CSV with columns slope and density (bins as --height-distribution).
    #[arg(long, value_name = "OUT.csv|FIG")]
    pub slope_distribution: Vec<PathBuf>,
    /// Write the distribution of the curvatures along x, (h[i+1] − 2h[i] + h[i−1])/Δx²
    /// within each row, as CSV with columns curvature and density (bins as
    /// --height-distribution).
    #[arg(long, value_name = "OUT.csv|FIG")]
    pub curvature_distribution: Vec<PathBuf>,
    /// Also plot the PSD, .png or .svg by the extension: log–log C(q) vs q·L/2π, with the
    /// fitted power law over the fit range (its slope in the legend).
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Print the statistics as JSON.
    #[arg(long)]
    pub json: bool,
    /// Overwrite existing outputs (--psd, --bearing-area, --acf, --variable-bandwidth,
    /// --acf-2d, --scale-dependent-slope, --scale-dependent-curvature, the distributions,
    /// --plot).
    #[arg(long)]
    pub force: bool,
}

/// The `--plot` chart ([`asperity_app::figure::psd::psd_chart`]): the PSD against q·L/2π,
/// log–log, with the fitted power law drawn over the fit range.
fn psd_chart(file: &Path, stats: &Statistics) -> Chart {
    let name = file_name(file);
    let q: Vec<f64> = stats.bins.iter().map(|b| b.q).collect();
    let psd: Vec<f64> = stats.bins.iter().map(|b| b.psd).collect();
    psd::psd_chart(PsdFigure {
        name: &name,
        q: &q,
        psd: &psd,
        size: stats.size,
        ndim: stats.dims.len(),
        range: stats.plan.range,
        fit: stats.fit.map(|f| (f.prefactor, f.exponent)),
        hurst: stats.hurst,
    })
}

/// The file through the front-end layer's one call: a measured file (or an imported
/// `.npy`) with its record, else a plain `.npy` (1D or 2D), its side length from --size, the
/// sidecar, else 1, with what the sidecar says of its spectrum.
fn open_source(
    args: &StatsArgs,
    size: Option<[Option<f64>; 2]>,
) -> Result<(StatsSource, Option<serde_json::Value>)> {
    // The array, its centred copy, the half spectrum and the FFT's work buffer: about 4×
    // the file; the PSD's ring sums up to 12 bytes a point more (their parallel blocks hold
    // at most about as many entries as the half spectrum): checked from the header before
    // the data are read.
    let fits = |shape: &[usize]| {
        ensure_fits(
            &format!(
                "computing the statistics of {} (shape {shape:?})",
                args.file.display()
            ),
            array_bytes(shape, 4 * 8 + 12),
        )
    };
    let input = open_argument(
        &args.file,
        &args.measured,
        size,
        Arrays::Plain(Dims::Either, &fits),
    )?;
    let t = input.topography;
    if input.measured {
        // A measured file's sidecar (if any) is its import record, not a generator's spec.
        let record = measured_record(&t);
        let source = StatsSource::Measured {
            heights: t.heights,
            sizes: t.sizes,
        };
        return Ok((source, Some(record)));
    }
    let heights = match t.heights {
        Heights::Areal(h) => h.into_dyn(),
        Heights::Profile(h) => h.into_dyn(),
    };
    let hints =
        (input.sidecar.as_ref()).map_or_else(SpectrumHints::default, SpectrumHints::from_sidecar);
    let source = StatsSource::Grid {
        heights,
        size: t.sizes[0],
        hints,
    };
    Ok((source, None))
}

/// Prints the ISO parameters, if any, one per line with their units.
fn print_iso(iso: &Option<serde_json::Value>) {
    let Some(serde_json::Value::Object(map)) = iso else {
        return;
    };
    let order = [
        "sq", "sa", "sz", "ssk", "sku", "sdq", "sdr", "rq", "ra", "rz", "rsk", "rku", "rdq",
    ];
    for name in order {
        let Some(value) = map.get(name) else { continue };
        let v = value.as_f64().unwrap_or(f64::NAN);
        let (label, unit) = match name {
            "sdr" => ("Sdr".to_string(), format!(" ({:.4} %)", 100.0 * v)),
            "sdq" | "rdq" | "ssk" | "sku" | "rsk" | "rku" => (capitalised(name), String::new()),
            _ => (capitalised(name), " m".to_string()),
        };
        println!("{label}: {}{unit}", format_number(v));
    }
}

fn capitalised(name: &str) -> String {
    let mut c = name.chars();
    c.next()
        .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
        .unwrap_or_default()
}

/// Runs `asperity stats`: the arguments and outputs are checked, the file read, the
/// statistics computed and the PSD fitted by the front-end layer, the outputs written
/// together, then the statistics printed.
pub fn run(args: &StatsArgs) -> Result<()> {
    let size = args.size.as_deref().map(parse_size).transpose()?;
    let named = |r: asperity_app::Refusal| anyhow::anyhow!(r.words(Names::Flags));
    let request = StatsRequest {
        fit_from: args.fit_from,
        fit_to: args.fit_to,
        window: parse_window(&args.window).map_err(named)?,
        convention: PsdConvention::parse(&args.psd_convention).map_err(named)?,
    };
    request.validate()?;
    // The outputs are checked before the (possibly large) input is read.
    if let Some(plot) = &args.plot {
        ImageFormat::from_path(plot, "--plot")?;
    }
    let requested = analyses(args);
    let outputs = (args.psd.iter().chain(&args.plot)).chain(requested.iter().map(|(p, _)| *p));
    let figures: Vec<bool> = requested.iter().map(|(p, _)| is_figure(p)).collect();
    let mut staged = StagedOutputs::new(outputs, args.force)?;
    staged.ensure_not_input(&args.file)?;
    let (source, record) = open_source(args, size)?;
    // Each analysis once, however many outputs it has.
    let mut wanted: Vec<Analysis> = Vec::new();
    for &(_, analysis) in &requested {
        if !wanted.contains(&analysis) {
            wanted.push(analysis);
        }
    }
    let tables = analyse(&source, &wanted).map_err(crate::request::refused)?;
    let stats = compute(&request, source, &args.file.display().to_string())
        .map_err(crate::request::refused)?;
    stage_outputs(args, &mut staged, &stats)?;
    let name = file_name(&args.file);
    for ((path, analysis), figure) in requested.iter().zip(figures) {
        let at = wanted.iter().position(|a| a == analysis);
        let rows = &tables[at.expect("every analysis asked for is computed")];
        if figure {
            let figure = AnalysisFigure {
                name: &name,
                analysis: *analysis,
                metres: record.is_some(),
            };
            stage_charts(&mut staged, path, &[analysis_chart(rows, figure)])
                .with_context(|| format!("writing {}", path.display()))?;
        } else {
            stage_pairs(&mut staged, path, analysis.columns(), rows)?;
        }
    }
    staged.commit()?;
    if args.json {
        print_json(args, &stats, record)
    } else {
        print_text(args, &stats, record.as_ref());
        Ok(())
    }
}

/// Whether an analysis' output is its figure (`.png`, `.svg`, `.json`) rather than CSV.
fn is_figure(path: &Path) -> bool {
    let ext = path.extension().and_then(|e| e.to_str());
    ext.is_some_and(|e| ["png", "svg", "json"].contains(&e.to_ascii_lowercase().as_str()))
}

/// The file's name for the figures' titles (its path when it has none).
fn file_name(file: &Path) -> String {
    file.file_name().map_or_else(
        || file.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}

/// The analyses asked for, each with its outputs (an option given twice: both), in the
/// order of the options.
fn analyses(args: &StatsArgs) -> Vec<(&PathBuf, Analysis)> {
    let paths = [
        (&args.bearing_area, Analysis::BearingArea),
        (&args.acf, Analysis::Acf),
        (&args.acf_2d, Analysis::Acf2d),
        (&args.variable_bandwidth, Analysis::VariableBandwidth),
        (&args.scale_dependent_slope, Analysis::ScaleDependentSlope),
        (
            &args.scale_dependent_curvature,
            Analysis::ScaleDependentCurvature,
        ),
        (&args.height_distribution, Analysis::HeightDistribution),
        (&args.slope_distribution, Analysis::SlopeDistribution),
        (
            &args.curvature_distribution,
            Analysis::CurvatureDistribution,
        ),
    ];
    (paths.into_iter())
        .flat_map(|(paths, analysis)| paths.iter().map(move |p| (p, analysis)))
        .collect()
}

/// Stages a two-column table.
fn stage_pairs(
    staged: &mut StagedOutputs,
    path: &Path,
    header: [&str; 2],
    rows: &[(f64, f64)],
) -> Result<()> {
    let mut table = Table::new(&header);
    for &(a, b) in rows {
        table.push_numbers(&[a, b]);
    }
    table
        .stage(staged, path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Stages the --psd table and the --plot chart (committed together by the caller).
fn stage_outputs(args: &StatsArgs, staged: &mut StagedOutputs, stats: &Statistics) -> Result<()> {
    let (bins, size) = (&stats.bins, stats.size);
    if let Some(path) = &args.psd {
        let mut table = Table::new(&["q", "psd", "q_l_2pi"]);
        for b in bins {
            table.push_numbers(&[b.q, b.psd, b.q * size / std::f64::consts::TAU]);
        }
        table
            .stage(staged, path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.plot {
        let chart = psd_chart(&args.file, stats);
        stage_charts(staged, path, &[chart])
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// `--json`: everything in one JSON object.
fn print_json(
    args: &StatsArgs,
    stats: &Statistics,
    record: Option<serde_json::Value>,
) -> Result<()> {
    let (f, plan) = (stats.fit, &stats.plan);
    let value = serde_json::json!({
        "file": args.file, "shape": stats.dims, "size": stats.size, "stats": stats.summary,
        "psd_slope": f.map(|f| f.exponent), "psd_slope_low": f.map(|f| f.low),
        "psd_slope_high": f.map(|f| f.high), "fit_from": plan.range.map(|r| r.0),
        "fit_to": plan.range.map(|r| r.1),
        "fit_note": plan.note.as_ref().map(|n| n.words(Names::Flags)),
        "hurst_estimate": stats.hurst, "iso": stats.iso, "measured": record,
    });
    println!("{}", serde_json::to_string_pretty(&value)?);
    Ok(())
}

/// The statistics as `name: value` lines.
fn print_text(args: &StatsArgs, stats: &Statistics, record: Option<&serde_json::Value>) {
    print_file_line(&args.file, stats, record);
    let (summary, plan, nyquist) = (&stats.summary, &stats.plan, stats.nyquist);
    println!("rms_height: {}", format_number(summary.rms_height));
    println!("rms_slope: {}", format_number(summary.rms_slope));
    match summary.rms_curvature {
        Some(c) => println!("rms_curvature: {}", format_number(c)),
        None => println!("rms_curvature: n/a (grid too small)"),
    }
    print_iso(&stats.iso);
    let note = plan.note.as_ref().map(|n| n.words(Names::Flags));
    match (stats.fit, plan.range) {
        (Some(f), Some((from, to))) => {
            let end = match &note {
                Some(_) => format!(
                    "{to} (Nyquist; --fit-to {} clamped to it)",
                    args.fit_to.unwrap_or(to)
                ),
                None if to >= nyquist => format!("{to} (Nyquist)"),
                None => to.to_string(),
            };
            println!(
                "psd_slope: {:.4} (95% interval {:.4} .. {:.4}; fit over q·L/2π in [{from}, {end}], {} bins)",
                f.exponent, f.low, f.high, f.points
            );
            println!("hurst_estimate: {:.4}", stats.hurst.unwrap_or(f64::NAN));
        }
        (_, None) => println!(
            "psd_slope: n/a ({})",
            note.as_deref().unwrap_or("no PSD fit range")
        ),
        (None, Some((from, to))) => println!(
            "psd_slope: n/a (fewer than 2 bins with power in the fit range [{from}, {to}], {})",
            plan.origin.words(Names::Flags)
        ),
    }
}

/// The `file:` line: shape and size, or a measured file's format, channel and cleaning.
fn print_file_line(file: &Path, stats: &Statistics, record: Option<&serde_json::Value>) {
    let shape: Vec<String> = stats.dims.iter().map(|d| d.to_string()).collect();
    match record {
        Some(r) => println!(
            "file: {} ({}, {}, channel {}, sizes {} m; cleaning: {})",
            file.display(),
            r["format"].as_str().unwrap_or("?"),
            shape.join(" x "),
            r["channel"],
            r["sizes"],
            match r["cleaning"].as_array() {
                Some(c) if !c.is_empty() => c
                    .iter()
                    .filter_map(|v| v.as_str())
                    .collect::<Vec<_>>()
                    .join("; "),
                _ => "none".to_string(),
            }
        ),
        None => println!(
            "file: {} ({}, size {})",
            file.display(),
            shape.join(" x "),
            stats.size
        ),
    }
}
