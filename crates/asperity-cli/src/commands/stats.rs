//! `asperity stats FILE.npy`: statistics of a surface (2D) or line (1D).

use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context, Result};
use asperity::fit::{power_law_fit, PowerLawFit};
use asperity::io::{read_npy, read_npy_shape, StagedOutputs};
use asperity::memory::{array_bytes, ensure_fits};
use asperity::surface::stats::{
    line_psd, line_summary, radial_psd_2d, surface_summary, PsdBin, Summary,
};
use asperity::surface::{Line, Surface};
use ndarray::{Ix1, Ix2};

use super::measured::{
    has_import_sidecar, is_npy, load, parse_size, record as measured_record, MeasuredArgs,
};
use crate::output::{format_number, Table};
use crate::plot::{stage_charts, thin_log, Chart, ImageFormat, Series, Style};
use asperity::topography::stats as topo_stats;
use asperity::topography::Heights;

/// Arguments of `asperity stats`.
#[derive(Debug, clap::Args)]
#[command(
    allow_negative_numbers = true,
    after_help = "Examples:\n  asperity stats s.npy\n  asperity stats s.npy --psd psd.csv --fit-from 6\n  \
    asperity stats s.npy --plot psd.png\n  asperity stats scan.x3p --detrend plane\n  \
    asperity stats profile.csv --detrend mean --json"
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
    /// Also plot the PSD, .png or .svg by the extension: log–log C(q) vs q·L/2π, with the
    /// fitted power law over the fit range (its slope in the legend).
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Print the statistics as JSON.
    #[arg(long)]
    pub json: bool,
    /// Overwrite existing outputs (--psd, --plot).
    #[arg(long)]
    pub force: bool,
}

/// What a sidecar records that shapes the statistics: the side length and the spectrum's
/// limits (as q·L/2π). A missing sidecar gives no hints; one that is corrupt, not a regular
/// file or too large is an error ([`asperity::input::read_sidecar`], the rules of every
/// command).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct SidecarHints {
    size: Option<f64>,
    /// Roll-off (`true`) or cut-off (`false`) wavenumber q0.
    long_wavelength: Option<(bool, f64)>,
    short_cutoff: Option<f64>,
}

fn sidecar_hints(file: &Path) -> Result<SidecarHints> {
    let Some(value) = asperity::input::read_sidecar(file)? else {
        return Ok(SidecarHints::default());
    };
    let spec = &value["spec"];
    let long = &spec["psd"]["long_wavelength"];
    let positive = |v: &serde_json::Value| v.as_f64().filter(|x| x.is_finite() && *x > 0.0);
    Ok(SidecarHints {
        size: positive(&spec["size"]),
        long_wavelength: match (long["kind"].as_str(), positive(&long["q0"])) {
            (Some("roll_off"), Some(q0)) => Some((true, q0)),
            (Some("cut_off"), Some(q0)) => Some((false, q0)),
            _ => None,
        },
        short_cutoff: positive(&spec["psd"]["short_cutoff"]),
    })
}

/// Refuses statistics that overflow float64 (heights near 1e308 square to infinity),
/// naming the file, before anything is written or printed.
fn ensure_finite_statistics(file: &Path, summary: &Summary, bins: &[PsdBin]) -> Result<()> {
    let values = [summary.rms_height, summary.rms_slope]
        .into_iter()
        .chain(summary.rms_curvature)
        .chain(bins.iter().flat_map(|b| [b.q, b.psd]));
    if values.into_iter().any(|v| !v.is_finite()) {
        bail!(
            "{}: its statistics overflow float64 (squares of its heights or slopes exceed \
             1.8e308); rescale the heights",
            file.display()
        );
    }
    Ok(())
}

/// Checks a user-given end of the fit range: a positive, finite q·L/2π.
fn fit_bound(flag: &str, value: Option<f64>) -> Result<Option<f64>> {
    match value {
        Some(v) if !(v.is_finite() && v > 0.0) => {
            bail!("invalid {flag}: must be a positive number of wavelengths per side, got {v}")
        }
        other => Ok(other),
    }
}

/// The PSD fit range, and what the output says about it.
#[derive(Debug, Clone, PartialEq)]
struct FitPlan {
    /// Rings `from ..= to` (as q·L/2π); `None` when the default range is empty.
    range: Option<(f64, f64)>,
    /// A clamped --fit-to, or why there is no range.
    note: Option<String>,
    /// Where the ends come from, e.g. `the sidecar's roll-off q0 = 6 to Nyquist`.
    origin: String,
}

/// The PSD slope is fitted over the rings (bins) `κ = from ..= to`, `κ = round(q·L/2π)`.
/// By default: from 2, or from the roll-off q0 (the knee, as the paper fits), or from the
/// first ring wholly above a cut-off q0 (q0 + 1 for a whole q0: the ring at q0 is half
/// empty); up to the last ring wholly below a short cut-off q1 (q1 − 1), else Nyquist
/// (`nyquist`, the last ring). A --fit-to beyond Nyquist is clamped to it. A range left
/// empty by the defaults (a sidecar's roll-off at or above Nyquist, a tiny grid) gives no
/// fit and a note; one made empty by a given --fit-from or --fit-to is an error naming it.
fn fit_range(args: &StatsArgs, hints: &SidecarHints, nyquist: f64) -> Result<FitPlan> {
    let user_from = fit_bound("--fit-from", args.fit_from)?;
    let user_to = fit_bound("--fit-to", args.fit_to)?;
    let (default_from, from_why) = match hints.long_wavelength {
        Some((true, q0)) if q0 > 2.0 => (q0, format!("the sidecar's roll-off q0 = {q0}")),
        Some((false, q0)) if (q0 + 0.5).ceil() > 2.0 => (
            (q0 + 0.5).ceil(),
            format!("the first ring wholly above the sidecar's cut-off q0 = {q0}"),
        ),
        _ => (2.0, "the default lower end".to_string()),
    };
    let (default_to, to_why) = match hints.short_cutoff {
        Some(q1) if (q1 - 0.5).floor() < nyquist => (
            (q1 - 0.5).floor(),
            format!("the last ring wholly below the sidecar's short cut-off q1 = {q1}"),
        ),
        _ => (nyquist, "Nyquist".to_string()),
    };
    let mut note = None;
    let (to, to_given, to_why) = match user_to {
        Some(t) if t > nyquist => {
            note = Some(format!(
                "--fit-to {t} is beyond Nyquist ({nyquist}): clamped to it"
            ));
            (
                nyquist,
                false,
                format!("Nyquist; --fit-to {t} clamped to it"),
            )
        }
        Some(t) => (t, true, "--fit-to".to_string()),
        None => (default_to, false, to_why),
    };
    let from = user_from.unwrap_or(default_from);
    let from_why = if user_from.is_some() {
        "--fit-from".to_string()
    } else {
        from_why
    };
    let origin = format!("from {from_why} to {to_why}");
    if from <= to {
        return Ok(FitPlan {
            range: Some((from, to)),
            note,
            origin,
        });
    }
    match (user_from, to_given) {
        (Some(f), _) => bail!(
            "invalid --fit-from {f}: the PSD fit range would be empty, its upper end is {to} ({to_why}); give a smaller --fit-from"
        ),
        (None, true) => bail!(
            "invalid --fit-to {to}: the PSD fit range would be empty, its lower end is {from} ({from_why}); give a larger --fit-to or a smaller --fit-from"
        ),
        (None, false) => Ok(FitPlan {
            range: None,
            note: Some(format!(
                "no PSD fit: the default range is empty, from {from} ({from_why}) to {to} ({to_why}); set --fit-from and --fit-to"
            )),
            origin,
        }),
    }
}

/// The `--plot` chart: the PSD against q·L/2π, log–log, with the fitted power law drawn
/// over the fit range `[from, to]` (in q·L/2π).
fn psd_chart(
    file: &Path,
    bins: &[PsdBin],
    size: f64,
    ndim: usize,
    (from, to): (f64, f64),
    fit: Option<PowerLawFit>,
    hurst: Option<f64>,
) -> Chart {
    let wavelengths = |q: f64| q * size / std::f64::consts::TAU;
    let name = file.file_name().map_or_else(
        || file.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    let (kind, psd_name, unit) = if ndim == 1 {
        ("line", "C1D(q)", "length³")
    } else {
        ("surface", "C2D(q)", "length⁴")
    };
    // Every ring of a surface; a line's many noisy bins as points, thinned to what a
    // figure shows.
    let points = thin_log(bins.iter().map(|b| (wavelengths(b.q), b.psd)), 5000);
    let style = if points.len() <= 300 {
        Style::LinePoints
    } else {
        Style::Points
    };
    let mut series = vec![Series::new("PSD", points, style)];
    if let Some(f) = fit {
        // The fit is C = A q^p in physical q; drawn from the first to the last bin fitted.
        let fitted: Vec<f64> = bins
            .iter()
            .filter(|b| b.psd > 0.0)
            .map(|b| wavelengths(b.q))
            .filter(|k| (from..=to).contains(&k.round()))
            .collect();
        let ends = [fitted.first(), fitted.last()];
        let line = ends
            .into_iter()
            .flatten()
            .map(|&k| {
                let q = k * std::f64::consts::TAU / size;
                (k, f.prefactor * q.powf(f.exponent))
            })
            .collect();
        let label = match hurst {
            Some(h) => format!("fit: slope {:.3} (H ≈ {h:.3})", f.exponent),
            None => format!("fit: slope {:.3}", f.exponent),
        };
        series.push(Series::new(label, line, Style::Dashed).color(plotters::style::BLACK));
    }
    Chart {
        title: format!("{name}: power spectrum of the {kind} (L = {size})"),
        x_label: "wavenumber q·L/2π".into(),
        y_label: format!("PSD {psd_name}  [{unit}]"),
        log_x: true,
        log_y: true,
        series,
    }
}

/// What the statistics are computed from: the summary, PSD bins, shape, PSD slope offset (1 for a line, 2 for a surface), side length along x,
/// the ISO parameters (measured files) and the measured file's record.
struct Inputs {
    summary: Summary,
    bins: Vec<PsdBin>,
    dims: Vec<usize>,
    psd_offset: f64,
    size: f64,
    iso: Option<serde_json::Value>,
    record: Option<serde_json::Value>,
}

impl Inputs {
    /// The PSD ring `κ = round(q·L/2π)` of wavenumber `q`.
    fn ring(&self, q: f64) -> f64 {
        (q * self.size / std::f64::consts::TAU).round()
    }
}

/// A `.npy` array, its side length from --size, the sidecar, else 1.
fn npy_inputs(args: &StatsArgs, hints: &SidecarHints, size_x: Option<f64>) -> Result<Inputs> {
    // The array, its centred copy, the half spectrum and the FFT's work buffer: about 4×
    // the file; the PSD's ring sums up to 12 bytes a point more (their parallel blocks hold
    // at most about as many entries as the half spectrum): checked from the header before
    // the data are read.
    let shape = read_npy_shape(&args.file)?;
    ensure_fits(
        &format!(
            "computing the statistics of {} (shape {shape:?})",
            args.file.display()
        ),
        array_bytes(&shape, 4 * 8 + 12),
    )?;
    let size = size_x.or(hints.size).unwrap_or(1.0);
    let array = read_npy(&args.file)?;
    let (summary, bins, dims, psd_offset) = match array.ndim() {
        1 => {
            let line = Line::new(array.into_dimensionality::<Ix1>()?, size)?;
            (line_summary(&line), line_psd(&line), vec![line.len()], 1.0)
        }
        2 => {
            let surface = Surface::new(array.into_dimensionality::<Ix2>()?, size)?;
            let (r, c) = surface.dim();
            (
                surface_summary(&surface),
                radial_psd_2d(&surface).with_context(|| args.file.display().to_string())?,
                vec![r, c],
                2.0,
            )
        }
        d => bail!(
            "{}: expected a 1D line or 2D surface, found {d} dimensions",
            args.file.display()
        ),
    };
    Ok(Inputs {
        summary,
        bins,
        dims,
        psd_offset,
        size,
        iso: None,
        record: None,
    })
}

/// A measured file (or an imported `.npy`): read, cleaned as asked, with the ISO
/// parameters; the PSD in physical units (metres), rectangular pixels included.
fn measured_inputs(args: &StatsArgs) -> Result<Inputs> {
    let t = load(&args.file, &args.measured, args.size.as_deref())?;
    let record = Some(measured_record(&t));
    let dims = t.heights.shape();
    match &t.heights {
        Heights::Profile(_) => {
            let line = t.to_line()?;
            let iso = topo_stats::profile(line.heights().view(), line.spacing())?;
            Ok(Inputs {
                summary: line_summary(&line),
                bins: line_psd(&line),
                dims,
                psd_offset: 1.0,
                size: line.size(),
                iso: Some(serde_json::to_value(iso)?),
                record,
            })
        }
        Heights::Areal(_) => {
            let surface = t.to_surface()?;
            let iso = topo_stats::areal(
                surface.heights().view(),
                surface.spacing(),
                surface.spacing_y(),
            )?;
            let (summary, bins) = if surface.has_square_pixels() {
                (surface_summary(&surface), radial_psd_2d(&surface)?)
            } else {
                let summary = Summary {
                    rms_height: iso.sq,
                    rms_slope: topo_stats::rms_slope_forward(
                        surface.heights().view(),
                        surface.spacing(),
                        surface.spacing_y(),
                    ),
                    rms_curvature: None,
                };
                let bins = topo_stats::radial_psd(
                    surface.heights().view(),
                    surface.size(),
                    surface.size_y(),
                )?;
                (summary, bins)
            };
            Ok(Inputs {
                summary,
                bins,
                dims,
                psd_offset: 2.0,
                size: surface.size(),
                iso: Some(serde_json::to_value(iso)?),
                record,
            })
        }
    }
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

/// Runs `asperity stats`: the arguments and outputs are checked, the file read, the PSD
/// fitted, the outputs written together, then the statistics printed.
pub fn run(args: &StatsArgs) -> Result<()> {
    let size_x = match &args.size {
        Some(text) => parse_size(text)?[0],
        None => None,
    };
    check_fit_bounds(args)?;
    // The outputs are checked before the (possibly large) input is read.
    if let Some(plot) = &args.plot {
        ImageFormat::from_path(plot, "--plot")?;
    }
    let mut staged = StagedOutputs::new(args.psd.iter().chain(&args.plot), args.force)?;
    staged.ensure_not_input(&args.file)?;
    let measured = !is_npy(&args.file) || has_import_sidecar(&args.file);
    // A measured file's sidecar (if any) is its import record, not a generator's spec.
    let (hints, inputs) = if measured {
        (SidecarHints::default(), measured_inputs(args)?)
    } else {
        let hints = sidecar_hints(&args.file)?;
        let inputs = npy_inputs(args, &hints, size_x)?;
        (hints, inputs)
    };
    ensure_finite_statistics(&args.file, &inputs.summary, &inputs.bins)?;
    let nyquist = inputs.bins.last().map_or(0.0, |b| inputs.ring(b.q));
    let plan = fit_range(args, &hints, nyquist)?;
    let fit = psd_fit(&inputs, &plan);
    stage_outputs(args, &mut staged, &inputs, &plan, fit)?;
    staged.commit()?;
    if args.json {
        print_json(args, &inputs, &plan, fit)
    } else {
        print_text(args, &inputs, &plan, fit, nyquist);
        Ok(())
    }
}

/// Refuses a --fit-from or --fit-to that is no positive number, or a range they leave
/// empty.
fn check_fit_bounds(args: &StatsArgs) -> Result<()> {
    fit_bound("--fit-from", args.fit_from)?;
    fit_bound("--fit-to", args.fit_to)?;
    if let (Some(from), Some(to)) = (args.fit_from, args.fit_to) {
        ensure!(
            from < to,
            "invalid PSD fit range: --fit-from {from} must be below --fit-to {to}"
        );
    }
    Ok(())
}

/// The PSD's power-law fit over the plan's rings and the Hurst exponent it gives.
#[derive(Debug, Clone, Copy)]
struct PsdFit {
    fit: Option<PowerLawFit>,
    hurst: Option<f64>,
}

fn psd_fit(inputs: &Inputs, plan: &FitPlan) -> PsdFit {
    let fit = plan.range.and_then(|(from, to)| {
        let (q, c): (Vec<f64>, Vec<f64>) = inputs
            .bins
            .iter()
            .filter(|b| (from..=to).contains(&inputs.ring(b.q)) && b.psd > 0.0)
            .map(|b| (b.q, b.psd))
            .unzip();
        power_law_fit(&q, &c).ok()
    });
    // C2D ∝ q^(-2H-2), C1D ∝ q^(-2H-1): H = -(slope + offset)/2.
    let hurst = fit.map(|f| -(f.exponent + inputs.psd_offset) / 2.0);
    PsdFit { fit, hurst }
}

/// Stages the --psd table and the --plot chart (committed together by the caller).
fn stage_outputs(
    args: &StatsArgs,
    staged: &mut StagedOutputs,
    inputs: &Inputs,
    plan: &FitPlan,
    fit: PsdFit,
) -> Result<()> {
    let (bins, size) = (&inputs.bins, inputs.size);
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
        let range = plan.range.unwrap_or((0.0, 0.0));
        let dims = inputs.dims.len();
        let chart = psd_chart(&args.file, bins, size, dims, range, fit.fit, fit.hurst);
        stage_charts(staged, path, &[chart])
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// `--json`: everything in one JSON object.
fn print_json(args: &StatsArgs, inputs: &Inputs, plan: &FitPlan, fit: PsdFit) -> Result<()> {
    let (f, hurst) = (fit.fit, fit.hurst);
    let value = serde_json::json!({
        "file": args.file, "shape": inputs.dims, "size": inputs.size, "stats": inputs.summary,
        "psd_slope": f.map(|f| f.exponent), "psd_slope_low": f.map(|f| f.low),
        "psd_slope_high": f.map(|f| f.high), "fit_from": plan.range.map(|r| r.0),
        "fit_to": plan.range.map(|r| r.1), "fit_note": plan.note, "hurst_estimate": hurst,
        "iso": inputs.iso, "measured": inputs.record,
    });
    println!("{}", serde_json::to_string_pretty(&value)?);
    Ok(())
}

/// The statistics as `name: value` lines.
fn print_text(args: &StatsArgs, inputs: &Inputs, plan: &FitPlan, fit: PsdFit, nyquist: f64) {
    print_file_line(&args.file, inputs);
    let summary = &inputs.summary;
    println!("rms_height: {}", format_number(summary.rms_height));
    println!("rms_slope: {}", format_number(summary.rms_slope));
    match summary.rms_curvature {
        Some(c) => println!("rms_curvature: {}", format_number(c)),
        None => println!("rms_curvature: n/a (grid too small or rectangular pixels)"),
    }
    print_iso(&inputs.iso);
    match (fit.fit, plan.range) {
        (Some(f), Some((from, to))) => {
            let end = match &plan.note {
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
            println!("hurst_estimate: {:.4}", fit.hurst.unwrap_or(f64::NAN));
        }
        (_, None) => println!(
            "psd_slope: n/a ({})",
            plan.note.as_deref().unwrap_or("no PSD fit range")
        ),
        (None, Some((from, to))) => println!(
            "psd_slope: n/a (fewer than 2 bins with power in the fit range [{from}, {to}], {})",
            plan.origin
        ),
    }
}

/// The `file:` line: shape and size, or a measured file's format, channel and cleaning.
fn print_file_line(file: &Path, inputs: &Inputs) {
    let shape: Vec<String> = inputs.dims.iter().map(|d| d.to_string()).collect();
    match &inputs.record {
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
            inputs.size
        ),
    }
}
