//! `asperity contact FILE --modulus E* --pressures …`: the engineer's question about a
//! measured surface — contact area, mean gap, contact stiffness and number of contact
//! patches against load, in physical units (SI: heights and sizes in metres, moduli and
//! pressures in Pa, forces in N, areas in m², stiffness in N/m).
//!
//! The rough surface (rigid) is pressed into an elastic half-space of effective modulus `E* = E/(1 − ν²)` (BEM,
//! Polonsky–Keer; the contact of two elastic rough bodies maps onto this with the combined
//! roughness and `1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂`). Stiffness by the frozen contact
//! set; mean gap the mean of the gap over the nominal area; patches the 4-connected
//! components of the contact set.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
use asperity::elastic::Boundary;
use asperity::io::{sidecar_path, StagedOutputs};
use asperity::memory::ensure_fits;
use asperity::topography::patches::count_patches;
use ndarray::Array2;
use serde_json::json;

use super::measured::{load, record, MeasuredArgs};
use crate::output::{format_number, Table};
use crate::plot::{greyscale_png, stage_charts, Chart, ImageFormat, Series, Style};

/// Arguments of `asperity contact`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:\n  \
    asperity contact scan.x3p --young 210e9 --poisson 0.3 --pressures 1e5,1e6,1e7 --detrend plane\n  \
    asperity contact scan.x3p --modulus 1e9 --pressures 1e4,1e5 --out contact.csv --plot contact.png --map map.png\n  \
    asperity contact afm.txt --channel Height --detrend lines --fill harmonic --modulus 70e9 --pressures 1e6\n\n\
Columns (SI units): mean_pressure_pa, force_n, contact_area_m2, area_fraction, mean_gap_m,\n\
stiffness_n_per_m, patches, indentation_m, iterations, residual. The surface is rigid and\n\
pressed into an elastic half-space of effective modulus E* = E/(1 − ν²); free boundaries\n\
(the paper's) unless --boundary periodic. Heights and sizes are read in metres.")]
#[command(group(clap::ArgGroup::new("elastic").required(true).args(["modulus", "young"])))]
pub struct ContactArgs {
    /// A measured surface (X3P, SDF, text, ..., or a .npy with an import sidecar).
    pub file: PathBuf,
    /// Effective modulus E* in Pa.
    #[arg(long, allow_negative_numbers = true)]
    pub modulus: Option<f64>,
    /// Young's modulus E in Pa (with --poisson): E* = E/(1 − ν²).
    #[arg(long, requires = "poisson", allow_negative_numbers = true)]
    pub young: Option<f64>,
    /// Poisson's ratio ν, in [0, 0.5).
    #[arg(long, requires = "young", allow_negative_numbers = true)]
    pub poisson: Option<f64>,
    /// Mean pressures over the nominal area, Pa, comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        required = true,
        allow_negative_numbers = true,
        value_name = "P1,P2,…"
    )]
    pub pressures: Vec<f64>,
    /// Boundary conditions: free (zero-padded) or periodic.
    #[arg(long, default_value = "free", value_parser = ["free", "periodic"])]
    pub boundary: String,
    /// Physical size X (and Y) in metres, where the file has none or to override it.
    #[arg(long, value_name = "X[,Y]")]
    pub size: Option<String>,
    #[command(flatten)]
    pub measured: MeasuredArgs,
    /// Convergence tolerance of the BEM (rms gap violation over the rms height).
    #[arg(long, default_value_t = SolverParams::default().tolerance)]
    pub tol: f64,
    /// Output table (CSV); printed to stdout when absent. OUT.csv.json records the inputs.
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
    /// Plot (.png or .svg): contact stiffness, contact area and mean gap against force.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Contact map at the largest load (.png): contact black, free surface white.
    #[arg(long, value_name = "FILE.png")]
    pub map: Option<PathBuf>,
    /// Overwrite existing outputs.
    #[arg(long)]
    pub force: bool,
}

/// E* from the arguments, checked.
fn effective_modulus(args: &ContactArgs) -> Result<f64> {
    let e_star = match (args.modulus, args.young, args.poisson) {
        (Some(m), None, None) => m,
        (None, Some(e), Some(nu)) => {
            if !(nu.is_finite() && (0.0..0.5).contains(&nu)) {
                bail!("invalid --poisson {nu}: Poisson's ratio must be in [0, 0.5)");
            }
            if !(e.is_finite() && e > 0.0) {
                bail!("invalid --young {e}: must be positive and finite (Pa)");
            }
            e / (1.0 - nu * nu)
        }
        _ => bail!("give either --modulus E* or --young E with --poisson ν"),
    };
    if !(e_star.is_finite() && e_star > 0.0) {
        bail!("invalid --modulus {e_star}: must be positive and finite (Pa)");
    }
    Ok(e_star)
}

/// One load's results, SI units.
struct Row {
    pressure: f64,
    force: f64,
    area: f64,
    fraction: f64,
    mean_gap: f64,
    stiffness: f64,
    patches: usize,
    indentation: f64,
    iterations: usize,
    residual: f64,
}

/// Step 1: the loads, the tolerance and the image outputs, checked before any file is read.
fn check_args(args: &ContactArgs) -> Result<()> {
    if args.pressures.is_empty() {
        bail!("--pressures: give at least one value");
    }
    if let Some(p) = args
        .pressures
        .iter()
        .find(|p| !(p.is_finite() && **p > 0.0))
    {
        bail!("--pressures: {p} is not allowed (mean pressures must be finite and > 0, Pa)");
    }
    if !(args.tol.is_finite() && args.tol > 0.0) {
        bail!("--tol must be positive and finite, got {}", args.tol);
    }
    if let Some(plot) = &args.plot {
        ImageFormat::from_path(plot, "--plot")?;
        if args.pressures.len() < 2 {
            bail!("--plot needs at least 2 pressures (a curve), got 1");
        }
    }
    if let Some(map) = &args.map {
        if !map
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            bail!("--map {}: the file name must end in .png", map.display());
        }
    }
    Ok(())
}

/// The solves of step 2: one row per load, and the contact map of the last load (when
/// `--map` asks for it: 0 in contact, 1 free).
struct Solved {
    rows: Vec<Row>,
    map: Option<Array2<f64>>,
}

/// Step 2: every mean pressure solved in turn (each warm-starts from the previous), with
/// the contact map of the last.
fn solve(args: &ContactArgs, solver: &mut ContactSolver, pixel_area: f64) -> Result<Solved> {
    let mut rows = Vec::with_capacity(args.pressures.len());
    let mut map = None;
    for (k, &p) in args.pressures.iter().enumerate() {
        let (summary, info) = solver
            .solve(Control::MeanPressure(p))
            .with_context(|| format!("load {k} (mean pressure {p} Pa)"))?;
        let contact = solver.pressure().mapv(|v| v > 0.0);
        let patches = count_patches(contact.view());
        let mean_gap = solver.gap().mean().unwrap_or(f64::NAN);
        if k + 1 == args.pressures.len() && args.map.is_some() {
            map = Some(contact.mapv(|c| if c { 0.0 } else { 1.0 }));
        }
        let (stiffness, _) = solver
            .frozen_set_stiffness()
            .with_context(|| format!("stiffness at load {k} (mean pressure {p} Pa)"))?;
        rows.push(Row {
            pressure: summary.mean_pressure,
            force: summary.force,
            area: summary.contact_points as f64 * pixel_area,
            fraction: summary.area_fraction,
            mean_gap,
            stiffness,
            patches,
            indentation: summary.indentation,
            iterations: info.iterations,
            residual: info.residual,
        });
    }
    Ok(Solved { rows, map })
}

/// The table of step 3, SI units.
fn table(rows: &[Row]) -> Table {
    let mut table = Table::new(&[
        "mean_pressure_pa",
        "force_n",
        "contact_area_m2",
        "area_fraction",
        "mean_gap_m",
        "stiffness_n_per_m",
        "patches",
        "indentation_m",
        "iterations",
        "residual",
    ]);
    let n = |v: f64| format_number(v);
    for r in rows {
        table.push(&[
            n(r.pressure),
            n(r.force),
            n(r.area),
            n(r.fraction),
            n(r.mean_gap),
            n(r.stiffness),
            r.patches.to_string(),
            n(r.indentation),
            r.iterations.to_string(),
            n(r.residual),
        ]);
    }
    table
}

/// The `--plot` panels: stiffness, contact area and mean gap against force, log–log.
fn charts(args: &ContactArgs, rows: &[Row], e_star: f64) -> [Chart; 3] {
    let name = args
        .file
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into());
    let points = |y: &dyn Fn(&Row) -> f64| -> Vec<(f64, f64)> {
        rows.iter().map(|r| (r.force, y(r))).collect()
    };
    let chart = |title: String, y_label: &str, y: &dyn Fn(&Row) -> f64| Chart {
        title,
        x_label: "normal force F  [N]".into(),
        y_label: y_label.into(),
        log_x: true,
        log_y: true,
        series: vec![Series::new("", points(y), Style::LinePoints)],
    };
    [
        chart(
            format!("{name}: contact stiffness (E* = {e_star:.3e} Pa)"),
            "stiffness k  [N/m]",
            &|r| r.stiffness,
        ),
        chart(
            format!("{name}: true contact area"),
            "contact area A  [m²]",
            &|r| r.area,
        ),
        chart(format!("{name}: mean gap"), "mean gap  [m]", &|r| {
            r.mean_gap
        }),
    ]
}

/// Runs `asperity contact`: check, read, solve, then write every output together.
pub fn run(args: &ContactArgs) -> Result<()> {
    let e_star = effective_modulus(args)?;
    let boundary: Boundary = args.boundary.parse()?;
    check_args(args)?;
    let record_path = args.out.as_deref().map(sidecar_path);
    let outputs = args
        .out
        .iter()
        .chain(&record_path)
        .chain(&args.plot)
        .chain(&args.map);
    let mut staged = StagedOutputs::new(outputs, args.force)?;
    staged.ensure_not_input(&args.file)?;
    let topography = load(&args.file, &args.measured, args.size.as_deref())?;
    let surface = topography
        .to_surface()
        .with_context(|| format!("{}", args.file.display()))?;
    let (rows, cols) = surface.dim();
    ensure_fits(
        &format!("asperity contact on a {rows}x{cols} surface"),
        ContactSolver::memory_bytes(rows, cols, boundary),
    )?;
    let params = SolverParams {
        tolerance: args.tol,
        ..SolverParams::default()
    };
    let half_space = HalfSpace {
        modulus: e_star,
        boundary,
    };
    let mut solver = ContactSolver::new(&surface, half_space, params)
        .with_context(|| format!("{}", args.file.display()))?;
    let pixel_area = surface.spacing() * surface.spacing_y();
    drop(surface);
    let solved = solve(args, &mut solver, pixel_area)?;
    let table = table(&solved.rows);
    match &record_path {
        Some(record_path) => {
            table.stage(&mut staged, args.out.as_deref().expect("with its record"))?;
            let inputs = json!({
                "surface": record(&topography),
                "effective_modulus_pa": e_star,
                "young_pa": args.young,
                "poisson": args.poisson,
                "boundary": boundary.name(),
                "tolerance": args.tol,
                "pressures_pa": args.pressures,
                "units": "SI: m, Pa, N, m², N/m",
            });
            staged.write_json(record_path, &inputs)?;
        }
        None => print!("{}", String::from_utf8(table.to_csv()?)?),
    }
    if let Some(plot) = &args.plot {
        stage_charts(&mut staged, plot, &charts(args, &solved.rows, e_star))?;
    }
    if let (Some(map), Some(values)) = (&args.map, &solved.map) {
        greyscale_png(&mut staged, map, values.view())?;
    }
    staged.commit()?;
    Ok(())
}
