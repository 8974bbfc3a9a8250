//! `asperity bem`: 3D boundary-element contact of a rough surface (Polonsky–Keer on FFTs)
//! at one or more loads, with the contact stiffness by the frozen contact set.
//!
//! Everything is checked before the first solve (surface and the memory it needs,
//! parameters, every output path). The field files of each load go to temporary files as
//! soon as it is solved (no copies kept in memory); the CSV, the plot and the fields are
//! renamed into place together only after the last load, and any error removes the
//! temporary files, so an error leaves nothing behind.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
use asperity::elastic::Boundary;
use asperity::io::{read_npy_2d, read_npy_shape, sidecar_path, StagedOutputs};
use asperity::memory::{array_bytes, ensure_fits};
use asperity::surface::Surface;

use crate::output::{format_number, Table};
use crate::plot::{stage_charts, Chart, ImageFormat, Series, Style};
use crate::progress::Progress;

/// Arguments of `asperity bem`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:\n  \
    asperity surface --n 256 --hurst 0.8 --rolloff 6 --rms-slope 1 --seed 1 --out s.npy\n  \
    asperity bem --surface s.npy --nloads 20 --pmin 1e-4 --pmax 1e-1 --out curve.csv\n  \
    asperity bem --surface s.npy --pressures 0.01,0.05 --fields fields/ --out loads.csv\n  \
    asperity bem --surface s.npy --boundary periodic --forces 0.02 --tol 1e-10\n  \
    asperity bem --surface s.npy --indentations 0.01,0.02,0.04\n  \
    asperity bem --surface s.npy --nloads 20 --pmin 1e-4 --pmax 1e-1 --out curve.csv --plot curve.png\n\n\
Columns: force, mean_pressure, indentation, area_fraction, stiffness, iterations, residual\n\
(stiffness by the frozen contact set; indentation measured from the highest point; with\n\
--timing also solve_seconds, stiffness_seconds, peak_rss_mib).")]
#[command(group(clap::ArgGroup::new("loads").required(true).args(["forces", "pressures", "indentations", "nloads"])))]
pub struct BemArgs {
    /// Surface heights (.npy, float64, 2D), positive up.
    #[arg(long, value_name = "FILE.npy")]
    pub surface: PathBuf,
    /// Side length L along x; defaults to the surface's sidecar, else 1.
    #[arg(long)]
    pub size: Option<f64>,
    /// Effective modulus E*.
    #[arg(long, default_value_t = 1.0)]
    pub modulus: f64,
    /// Boundary conditions: free (zero-padded, no periodic images; the paper's) or periodic.
    #[arg(long, default_value = "free", value_parser = ["free", "periodic"])]
    pub boundary: String,
    /// Total forces (load control), comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "F1,F2,…"
    )]
    pub forces: Option<Vec<f64>>,
    /// Mean pressures over the nominal area (load control), comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "P1,P2,…"
    )]
    pub pressures: Option<Vec<f64>>,
    /// Indentations from the highest point (displacement control, free boundaries).
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "D1,D2,…"
    )]
    pub indentations: Option<Vec<f64>>,
    /// Number of mean pressures, log-spaced from --pmin to --pmax.
    #[arg(long, value_name = "K", requires_all = ["pmin", "pmax"])]
    pub nloads: Option<usize>,
    /// Smallest mean pressure for --nloads.
    #[arg(
        long,
        value_name = "P",
        allow_negative_numbers = true,
        requires = "nloads"
    )]
    pub pmin: Option<f64>,
    /// Largest mean pressure for --nloads.
    #[arg(
        long,
        value_name = "P",
        allow_negative_numbers = true,
        requires = "nloads"
    )]
    pub pmax: Option<f64>,
    /// Convergence tolerance: rms gap violation on the contact set over the rms height.
    #[arg(long, default_value_t = SolverParams::default().tolerance, allow_negative_numbers = true)]
    pub tol: f64,
    /// Maximum Polonsky–Keer iterations per load.
    #[arg(long, default_value_t = SolverParams::default().max_iterations)]
    pub max_iter: usize,
    /// Output table (CSV); printed to stdout when absent.
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
    /// Also plot the load sweep (needs at least 2 loads), .png or .svg by the extension:
    /// log–log contact stiffness k vs force F (left) and area fraction vs F (right), with
    /// F and k divided by E* (length² and length).
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Write pressure_K.npy and gap_K.npy for every load K (0-based) into DIR.
    #[arg(long, value_name = "DIR")]
    pub fields: Option<PathBuf>,
    /// Add timing columns (solve_seconds, stiffness_seconds, peak_rss_mib), for benchmarks.
    #[arg(long)]
    pub timing: bool,
    /// Skip the frozen-set stiffness (column left empty); for benchmarks of the solve alone.
    #[arg(long, hide = true)]
    pub no_stiffness: bool,
    /// No progress output.
    #[arg(long)]
    pub quiet: bool,
    /// Overwrite existing outputs.
    #[arg(long)]
    pub force: bool,
}

/// The loads requested, as solver controls.
fn controls(args: &BemArgs) -> Result<Vec<Control>> {
    let check = |name: &str, values: &[f64], allow_zero: bool| -> Result<()> {
        if values.is_empty() {
            bail!("--{name}: give at least one value");
        }
        for &v in values {
            let ok = v.is_finite() && (v > 0.0 || (allow_zero && v == 0.0));
            if !ok {
                bail!(
                    "--{name}: {v} is not allowed (values must be finite and {})",
                    if allow_zero { ">= 0" } else { "> 0" }
                );
            }
        }
        Ok(())
    };
    if let Some(forces) = &args.forces {
        check("forces", forces, false)?;
        return Ok(forces.iter().map(|&f| Control::Force(f)).collect());
    }
    if let Some(pressures) = &args.pressures {
        check("pressures", pressures, false)?;
        return Ok(pressures
            .iter()
            .map(|&p| Control::MeanPressure(p))
            .collect());
    }
    if let Some(indentations) = &args.indentations {
        check("indentations", indentations, true)?;
        return Ok(indentations
            .iter()
            .map(|&d| Control::Indentation(d))
            .collect());
    }
    let (Some(k), Some(pmin), Some(pmax)) = (args.nloads, args.pmin, args.pmax) else {
        bail!(
            "give one of --forces, --pressures, --indentations or --nloads with --pmin and --pmax"
        );
    };
    if k == 0 {
        bail!("--nloads must be at least 1");
    }
    check("pmin", &[pmin], false)?;
    check("pmax", &[pmax], false)?;
    if pmax < pmin {
        bail!("--pmax ({pmax}) must not be smaller than --pmin ({pmin})");
    }
    Ok((0..k)
        .map(|i| {
            let t = if k == 1 {
                0.0
            } else {
                i as f64 / (k - 1) as f64
            };
            Control::MeanPressure(pmin * (pmax / pmin).powf(t))
        })
        .collect())
}

/// Side length from the surface's JSON sidecar, if there is one.
fn sidecar_size(file: &Path) -> Option<f64> {
    let text = std::fs::read_to_string(sidecar_path(file)).ok()?;
    let value: serde_json::Value = serde_json::from_str(&text).ok()?;
    value["spec"]["size"].as_f64()
}

/// Peak resident memory of this process (MiB), from /proc/self/status (Linux).
fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn field_paths(dir: &Path, count: usize) -> Vec<(PathBuf, PathBuf)> {
    (0..count)
        .map(|k| {
            (
                dir.join(format!("pressure_{k}.npy")),
                dir.join(format!("gap_{k}.npy")),
            )
        })
        .collect()
}

struct Row {
    values: Vec<f64>,
    stiffness: Option<f64>,
}

/// The `--plot` panels: k/E* vs F/E* and area fraction vs F/E*, log–log.
fn sweep_charts(rows: &[Row], modulus: f64, surface: &Path, boundary: &str) -> [Chart; 2] {
    let name = surface.file_name().map_or_else(
        || surface.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    let force = |row: &Row| row.values[0] / modulus;
    let points = |y: &dyn Fn(&Row) -> f64| rows.iter().map(|r| (force(r), y(r))).collect();
    let x_label = "normal force F / E*  [length²]".to_string();
    let stiffness = Chart {
        title: format!("{name}: contact stiffness (E* = {modulus}, {boundary} boundaries)"),
        x_label: x_label.clone(),
        y_label: "contact stiffness k / E*  [length]".into(),
        log_x: true,
        log_y: true,
        series: vec![Series::new(
            "frozen contact set",
            points(&|r| r.stiffness.unwrap_or(f64::NAN) / modulus),
            Style::LinePoints,
        )],
    };
    let area = Chart {
        title: format!("{name}: true contact area"),
        x_label,
        y_label: "area fraction A / A0".into(),
        log_x: true,
        log_y: true,
        series: vec![Series::new("", points(&|r| r.values[3]), Style::LinePoints)],
    };
    [stiffness, area]
}

/// Runs `asperity bem`.
pub fn run(args: &BemArgs) -> Result<()> {
    // 1. Everything that can be checked before solving.
    let boundary: Boundary = args.boundary.parse()?;
    let loads = controls(args)?;
    if boundary == Boundary::Periodic && loads.iter().any(|c| matches!(c, Control::Indentation(_)))
    {
        bail!("--indentations needs --boundary free: a periodic half-space fixes displacements only up to their mean (use --pressures or --forces)");
    }
    if !(args.modulus.is_finite() && args.modulus > 0.0) {
        bail!(
            "--modulus must be positive and finite, got {}",
            args.modulus
        );
    }
    if !(args.tol.is_finite() && args.tol > 0.0) {
        bail!("--tol must be positive and finite, got {}", args.tol);
    }
    let params = SolverParams {
        tolerance: args.tol,
        max_iterations: args.max_iter,
        ..SolverParams::default()
    };
    params
        .validate()
        .with_context(|| format!("--max-iter {}", args.max_iter))?;
    if let Some(plot) = &args.plot {
        ImageFormat::from_path(plot, "--plot")?;
        if loads.len() < 2 {
            bail!("--plot needs at least 2 loads (a curve), got 1");
        }
        if args.no_stiffness {
            bail!("--plot draws the stiffness: drop --no-stiffness");
        }
    }
    // Outputs, checked before any work: each folder exists (--fields DIR and its missing
    // parents are made here, and removed again on any error), no output is named twice or
    // exists without --force. They are written to temporary files as each load is solved
    // and renamed into place together at the end.
    let fields = args
        .fields
        .as_ref()
        .map(|dir| field_paths(dir, loads.len()));
    let output_paths = args
        .out
        .iter()
        .chain(&args.plot)
        .chain(fields.iter().flatten().flat_map(|(p, g)| [p, g]));
    let mut staged = StagedOutputs::in_new_folders(&args.fields, output_paths, args.force)?;
    staged.ensure_not_input(&args.surface)?;
    // Memory, from the file's header before its data is read: the solver plus the heights,
    // alive while the solver is built (the fields go to files as they are solved).
    let shape = read_npy_shape(&args.surface)?;
    if let [rows, cols] = shape[..] {
        let bytes = ContactSolver::memory_bytes(rows, cols, boundary)
            .zip(array_bytes(&[rows, cols], 8))
            .and_then(|(solver, heights)| solver.checked_add(heights));
        ensure_fits(
            &format!(
                "asperity bem on a {rows}x{cols} surface ({} boundaries)",
                boundary.name()
            ),
            bytes,
        )?;
    }
    let size = args
        .size
        .or_else(|| sidecar_size(&args.surface))
        .unwrap_or(1.0);
    let heights = read_npy_2d(&args.surface)?;
    let surface =
        Surface::new(heights, size).with_context(|| format!("{}", args.surface.display()))?;
    let half_space = HalfSpace {
        modulus: args.modulus,
        boundary,
    };
    let mut solver = ContactSolver::new(&surface, half_space, params)?;
    // The solver keeps its own copy of the profile: free the heights (peak memory).
    drop(surface);

    // 2. Solve every load (warm starts in the given order).
    let progress = Progress::new("bem", loads.len() as u64, args.quiet || loads.len() < 2);
    let mut rows = Vec::with_capacity(loads.len());
    for (k, &control) in loads.iter().enumerate() {
        let describe = || match control {
            Control::Force(f) => format!("load {k} (force {f})"),
            Control::MeanPressure(p) => format!("load {k} (mean pressure {p})"),
            Control::Indentation(d) => format!("load {k} (indentation {d})"),
        };
        let start = Instant::now();
        let (summary, info) = solver.solve(control).with_context(describe)?;
        let solve_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let stiffness = if args.no_stiffness {
            None
        } else {
            Some(
                solver
                    .frozen_set_stiffness()
                    .with_context(|| format!("stiffness at {}", describe()))?
                    .0,
            )
        };
        let stiffness_seconds = start.elapsed().as_secs_f64();
        let mut values = vec![
            summary.force,
            summary.mean_pressure,
            summary.indentation,
            summary.area_fraction,
            stiffness.unwrap_or(f64::NAN),
            info.iterations as f64,
            info.residual,
        ];
        if args.timing {
            values.extend([
                solve_seconds,
                stiffness_seconds,
                peak_rss_mib().unwrap_or(f64::NAN),
            ]);
        }
        if let Some((p_path, g_path)) = fields.as_ref().map(|f| &f[k]) {
            staged.write_npy_2d(p_path, &solver.pressure())?;
            staged.write_npy_2d(g_path, &solver.gap())?;
        }
        rows.push(Row { values, stiffness });
        progress.inc();
    }
    progress.finish();

    // 3. Write.
    let mut header = vec![
        "force",
        "mean_pressure",
        "indentation",
        "area_fraction",
        "stiffness",
        "iterations",
        "residual",
    ];
    if args.timing {
        header.extend(["solve_seconds", "stiffness_seconds", "peak_rss_mib"]);
    }
    let format_row = |row: &Row| -> Vec<String> {
        row.values
            .iter()
            .enumerate()
            .map(|(i, v)| match i {
                4 if row.stiffness.is_none() => String::new(),
                5 => format!("{}", *v as u64),
                _ => format_number(*v),
            })
            .collect()
    };
    if let Some(out) = &args.out {
        let mut table = Table::new(&header);
        for row in &rows {
            table.push(&format_row(row));
        }
        table
            .stage(&mut staged, out)
            .with_context(|| format!("writing {}", out.display()))?;
    }
    if let Some(plot) = &args.plot {
        let charts = sweep_charts(&rows, args.modulus, &args.surface, boundary.name());
        stage_charts(&mut staged, plot, &charts)
            .with_context(|| format!("writing {}", plot.display()))?;
    }
    staged.commit()?;
    match &args.out {
        Some(out) => {
            if !args.quiet {
                eprintln!("wrote {} ({} loads)", out.display(), rows.len());
            }
        }
        None => {
            let cells: Vec<Vec<String>> = rows
                .iter()
                .map(|row| {
                    row.values
                        .iter()
                        .enumerate()
                        .map(|(i, v)| match i {
                            4 if row.stiffness.is_none() => "-".to_string(),
                            5 => format!("{}", *v as u64),
                            _ => format!("{v:.6e}"),
                        })
                        .collect()
                })
                .collect();
            let widths: Vec<usize> = header
                .iter()
                .enumerate()
                .map(|(i, h)| {
                    cells
                        .iter()
                        .map(|r| r[i].len())
                        .chain([h.len()])
                        .max()
                        .unwrap_or(0)
                })
                .collect();
            let line = |fields: Vec<&str>| {
                fields
                    .iter()
                    .zip(&widths)
                    .map(|(f, w)| format!("{f:>w$}"))
                    .collect::<Vec<_>>()
                    .join("  ")
            };
            println!("{}", line(header.clone()));
            for row in &cells {
                println!("{}", line(row.iter().map(|s| s.as_str()).collect()));
            }
        }
    }
    Ok(())
}
