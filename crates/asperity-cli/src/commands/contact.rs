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

use std::convert::Infallible;

use anyhow::{bail, Context, Result};
use asperity::bem::sweep::{SweepError, SweepFailure};
use asperity::bem::ContactSolver;
use asperity::io::{sidecar_path, StagedOutputs};
use asperity::surface::Surface;
use asperity_app::bem::{ensure_solver_fits, SolverRequest};
use asperity_app::contact::{self, ContactPlan, ContactRequest, ContactRow, Value};
use serde_json::json;

use super::measured::{load, record, MeasuredArgs};
use crate::output::{format_number, Table};
use asperity_app::figure::contact::{contact_charts, ContactColumns};
use asperity_app::figure::map::{contact_map_chart, MapFigure};

use crate::plot::{stage_charts, Chart, ImageFormat};
use crate::progress::Progress;

/// Arguments of `asperity contact`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:\n  \
    asperity contact scan.x3p --young 210e9 --poisson 0.3 --pressures 1e5,1e6,1e7 --detrend plane\n  \
    asperity contact scan.x3p --modulus 1e9 --pressures 1e4,1e5 --out contact.csv --plot contact.png --map map.png\n  \
    asperity contact afm.txt --channel Height --detrend lines --fill harmonic --modulus 70e9 --pressures 1e6\n  \
    asperity contact scan.x3p --young 210e9 --poisson 0.3 --hardness 2e9 --pressures 1e7,1e8\n  \
    asperity contact scan.x3p --young 210e9,70e9 --poisson 0.3,0.33 --pressures 1e6   # steel on aluminium\n\n\
Columns (SI units): mean_pressure_pa, force_n, contact_area_m2, area_fraction, mean_gap_m,\n\
stiffness_n_per_m, patches, indentation_m, iterations, residual; with --hardness then\n\
plastic_area_m2, plastic_fraction (the points at the hardness); with --tangential\n\
stiffness_x_n_per_m, stiffness_y_n_per_m, tangential_ratio; with --resistivity\n\
electrical_conductance_s; with --thermal-conductivity thermal_conductance_w_per_k. The surface is rigid and\n\
pressed into an elastic half-space of effective modulus E* = E/(1 − ν²); free boundaries\n\
(the paper's) unless --boundary periodic. Heights and sizes are read in metres.")]
pub struct ContactArgs {
    /// A measured surface (X3P, SDF, text, ..., or a .npy with an import sidecar).
    pub file: PathBuf,
    /// Effective modulus E* in Pa.
    #[arg(long, allow_negative_numbers = true)]
    pub modulus: Option<f64>,
    /// Young's modulus E in Pa (with --poisson): E* = E/(1 − ν²); two values E₁,E₂ (with
    /// ν₁,ν₂) for two elastic bodies: 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂.
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "E[,E2]"
    )]
    pub young: Vec<f64>,
    /// Poisson's ratio ν, in [0, 0.5] (two values ν₁,ν₂ with two --young values).
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "NU[,NU2]"
    )]
    pub poisson: Vec<f64>,
    /// Mean pressures over the nominal area, Pa, comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "P1,P2,…"
    )]
    pub pressures: Vec<f64>,
    /// Boundary conditions: free (zero-padded) or periodic.
    #[arg(long, default_value_t = SolverRequest::default().boundary)]
    pub boundary: String,
    /// Physical size X (and Y) in metres, where the file has none or to override it.
    #[arg(long, value_name = "X[,Y]")]
    pub size: Option<String>,
    #[command(flatten)]
    pub measured: MeasuredArgs,
    /// Convergence tolerance of the BEM (rms gap violation over the rms height).
    #[arg(long, default_value_t = SolverRequest::default().tolerance, allow_hyphen_values = true)]
    pub tol: f64,
    /// Output table (CSV); printed to stdout when absent. OUT.csv.json records the inputs.
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
    /// Plot (.png or .svg): contact stiffness, contact area and mean gap against force.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Contact map at the largest load (.png, .svg, or .json for the figure as data, as
    /// asperity.plot.contact_map draws it): each 4-connected patch (the patches column's
    /// rule) in a colour of its own, free surface white, axes in metres with a scale bar.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub map: Option<PathBuf>,
    /// Electrical resistivities ρ₁,ρ₂ of the two bodies, Ω·m: adds the column
    /// electrical_conductance_s, C = 2k/(E*(ρ₁+ρ₂)) (Barber's analogy).
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "R1,R2"
    )]
    pub resistivity: Option<Vec<f64>>,
    /// Thermal conductivities κ₁,κ₂ of the two bodies, W/(m·K): adds the column
    /// thermal_conductance_w_per_k, C = (2k/E*)·κ₁κ₂/(κ₁+κ₂) (Barber's analogy).
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "K1,K2"
    )]
    pub thermal_conductivity: Option<Vec<f64>>,
    /// Hardness in Pa: the contact pressure is capped there (elastic–perfectly-plastic
    /// contact, docs/hardness.md; each load on the surface as measured); adds the columns
    /// plastic_area_m2 and plastic_fraction, and the stiffness is that of the elastic set.
    #[arg(long, value_name = "PA", allow_negative_numbers = true)]
    pub hardness: Option<f64>,
    /// Add the tangential (no-slip) stiffness of every load: columns stiffness_x_n_per_m,
    /// stiffness_y_n_per_m (k_x, k_y of the frozen contact set with Cerruti's kernel for
    /// --poisson's ν, docs/tangential.md) and tangential_ratio = (k_x + k_y)/(2k). Needs
    /// --poisson (with --young, or beside --modulus for the kernel alone). About two more
    /// stiffness solves per load. With --hardness, on the elastic set as k: points at the
    /// hardness take no added traction, normal or tangential. --tangential=x (or y) computes
    /// one direction only: its column, tangential_ratio = k_x/k (k_y/k), about one
    /// stiffness solve per load; --tangential alone is --tangential=both.
    #[arg(
        long,
        value_name = "DIR",
        num_args = 0..=1,
        require_equals = true,
        default_missing_value = "both"
    )]
    pub tangential: Option<String>,
    /// Walk the pressures in the given order as one load path (loading, unloading,
    /// reloading: e.g. --pressures 1e7,4e7,1e7,4e7 --hardness 2e8), each step warm from the
    /// last and its plastic displacement kept (the library's load_path, as `asperity bem
    /// --load-path` and Python's Solver.load_path), so the table shows the hysteresis.
    /// Columns branch, force_n, mean_pressure_pa, indentation_m, area_fraction,
    /// plastic_fraction, stiffness_n_per_m, iterations, permanent_max_m; --plot draws the
    /// loop: F and A/A0 against d, k against F, the steps marked by branch.
    #[arg(long)]
    pub load_path: bool,
    /// Work of adhesion Δγ in J/m²: an adhesive run instead of the load sweep — the path of
    /// --indentations (m), then the retraction to pull-off (asperity bem --work-of-adhesion's
    /// solver and rules, docs/adhesion.md): Pohrt & Popov's pixel criterion, or with
    /// --adhesion-range a cohesive law. Columns indentation_m, force_n, mean_pressure_pa,
    /// contact_area_m2, area_fraction, tensile_fraction, rounds, cg_iterations, branch; both
    /// pull-offs (N, m) on stderr and in OUT.csv.json.
    #[arg(long, value_name = "J_PER_M2", allow_negative_numbers = true)]
    pub work_of_adhesion: Option<f64>,
    /// Range of the cohesive law in m (with --work-of-adhesion): h₀ of a Maugis–Dugdale zone
    /// (stress Δγ/h₀) or ρ of an exponential potential (--adhesion-model exponential).
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub adhesion_range: Option<f64>,
    /// The cohesive law of --adhesion-range: maugis-dugdale (the default) or exponential.
    #[arg(long, value_name = "MODEL")]
    pub adhesion_model: Option<String>,
    /// The adhesive run's path of indentations in m, comma separated (negative: pulled back
    /// beyond first touch); the retraction to pull-off follows the last.
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "D1,D2,…"
    )]
    pub indentations: Vec<f64>,
    /// The adhesive retraction's step in m (default: the deepest indentation, plus any
    /// --adhesion-range, / 200).
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub retract_step: Option<f64>,
    /// Overwrite existing outputs.
    #[arg(long)]
    pub force: bool,
    /// No progress output.
    #[arg(long)]
    pub quiet: bool,
    /// Progress inside each solve on stderr: the iteration and the residual every 2 s
    /// (shown anyway on a terminal, unless --quiet).
    #[arg(long)]
    pub progress: bool,
    /// Seconds between two lines of --progress (tests: 0, every iteration).
    #[arg(long, hide = true, value_name = "SECONDS", value_parser = crate::progress::parse_seconds)]
    pub progress_every: Option<f64>,
}

/// The request of the arguments.
pub(super) fn request(args: &ContactArgs) -> Result<ContactRequest> {
    let (young, young_2) = contact::one_or_two(contact::params::YOUNG, &args.young)?;
    let (poisson, poisson_2) = contact::one_or_two(contact::params::POISSON, &args.poisson)?;
    Ok(ContactRequest {
        modulus: args.modulus,
        young,
        poisson,
        young_2,
        poisson_2,
        pressures: args.pressures.clone(),
        boundary: args.boundary.clone(),
        tolerance: args.tol,
        resistivity: args.resistivity.clone(),
        thermal_conductivity: args.thermal_conductivity.clone(),
        hardness: args.hardness,
        tangential: args.tangential.is_some(),
        directions: args.tangential.clone(),
        work_of_adhesion: args.work_of_adhesion,
        adhesion_range: args.adhesion_range,
        adhesion_model: args.adhesion_model.clone(),
        indentations: args.indentations.clone(),
        retract_step: args.retract_step,
    })
}

/// Step 1: the request (the front-end layer's rules) and the image outputs, checked before
/// any file is read.
pub(super) fn check_args(args: &ContactArgs) -> Result<ContactPlan> {
    let plan = request(args)?.validate()?;
    if let Some(plot) = &args.plot {
        ImageFormat::from_path(plot, "--plot")?;
        if args.pressures.len() < 2 {
            bail!("--plot needs at least 2 pressures (a curve), got 1");
        }
    }
    if let Some(map) = &args.map {
        ImageFormat::from_path(map, "--map")?;
    }
    Ok(plan)
}

/// A sweep's error in the command line's words (the load as `load 3 (…)`).
fn sweep_error(error: SweepError<Infallible>) -> anyhow::Error {
    match error.explain("--fd-stiffness") {
        SweepFailure::Input(source) => source.into(),
        SweepFailure::AtLoad { context, source } => anyhow::Error::new(source).context(context),
        SweepFailure::StepBeyondFullContact(message) => anyhow::anyhow!(message),
        SweepFailure::Stopped(never) => match never {},
    }
}

/// The table of step 3, SI units.
fn table(plan: &ContactPlan, rows: &[ContactRow]) -> Table {
    let mut table = Table::new(&contact::columns(plan));
    for row in rows {
        let cells: Vec<String> = row
            .all_values(&plan.derived)
            .iter()
            .map(|v| match *v {
                Value::Number(x) => format_number(x),
                Value::Count(n) => n.to_string(),
            })
            .collect();
        table.push(&cells);
    }
    table
}

/// A value given once as a number, twice (one per body) as a list, none as null.
fn one_or_both(values: &[f64]) -> serde_json::Value {
    match values {
        [] => serde_json::Value::Null,
        [one] => json!(one),
        both => json!(both),
    }
}

/// The surface's file name, for titles.
pub(super) fn file_name(args: &ContactArgs) -> String {
    args.file
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into())
}

/// The `--plot` panels: stiffness, contact area and mean gap against force, log–log, as
/// `asperity.plot` draws them ([`contact_charts`]).
fn charts(args: &ContactArgs, rows: &[ContactRow], e_star: f64) -> [Chart; 3] {
    let column = |y: fn(&ContactRow) -> f64| -> Vec<f64> { rows.iter().map(y).collect() };
    let (force, stiffness) = (column(|r| r.force), column(|r| r.stiffness));
    let (area, mean_gap) = (column(|r| r.area), column(|r| r.mean_gap));
    let columns = ContactColumns {
        force: &force,
        stiffness: &stiffness,
        area: &area,
        mean_gap: &mean_gap,
    };
    contact_charts(columns, &file_name(args), e_star)
}

/// What `OUT.csv.json` records of the inputs.
pub(super) fn inputs_record(
    args: &ContactArgs,
    plan: &ContactPlan,
    surface: serde_json::Value,
) -> serde_json::Value {
    json!({
        "surface": surface,
        "effective_modulus_pa": plan.half_space.modulus,
        "young_pa": one_or_both(&args.young),
        "poisson": one_or_both(&args.poisson),
        "boundary": plan.half_space.boundary.name(),
        "tolerance": args.tol,
        "pressures_pa": args.pressures,
        "resistivity_ohm_m": args.resistivity,
        "thermal_conductivity_w_per_m_k": args.thermal_conductivity,
        "hardness_pa": args.hardness,
        "tangential": plan.derived.tangential.map(|nu| json!({
            "poisson": nu,
            "directions": plan.derived.directions.name(),
            "method": "frozen contact set, Cerruti kernel (normal-tangential coupling \
                neglected); tangential_ratio = (k_x + k_y)/(2k), or k_x/k (k_y/k) with one \
                direction; with a hardness, on the \
                elastic set (points at the hardness take no added traction)",
        })),
        "conductance": "Barber's analogy from the frozen-set stiffness: electrical \
            2k/(E*(ρ1+ρ2)), thermal (2k/E*)·κ1κ2/(κ1+κ2)",
        "units": "SI: m, Pa, N, m², N/m, S, W/K",
    })
}

/// Runs `asperity contact`: check, read, solve (the library's load sweep), then write
/// every output together.
pub fn run(args: &ContactArgs) -> Result<()> {
    if args.work_of_adhesion.is_some() {
        return super::contact_adhesion::run(args);
    }
    if args.load_path {
        return super::contact_path::run(args);
    }
    let plan = check_args(args)?;
    let boundary = plan.half_space.boundary;
    let e_star = plan.half_space.modulus;
    let record_path = args.out.as_deref().map(sidecar_path);
    let outputs = args
        .out
        .iter()
        .chain(&record_path)
        .chain(&args.plot)
        .chain(&args.map);
    let (mut staged, surface, provenance) = staged_surface(args, outputs)?;
    let (rows, cols) = surface.dim();
    ensure_solver_fits(rows, cols, boundary, Some(0))?;
    let mut solver = ContactSolver::new(&surface, plan.half_space, plan.params)
        .with_context(|| format!("{}", args.file.display()))?;
    let pixel_area = surface.spacing() * surface.spacing_y();
    let sizes = (
        surface.spacing() * cols as f64,
        surface.spacing_y() * rows as f64,
    );
    drop(surface);
    let loads = plan.loads.len();
    let progress = Progress::new("contact", loads as u64, args.quiet || loads < 2);
    let every = crate::progress::solve_progress((args.progress, args.progress_every), args.quiet);
    solver.set_monitor(progress.solve_monitor("contact", every));
    let solved = contact::run(
        &mut solver,
        &plan,
        pixel_area,
        args.map.is_some(),
        &mut || progress.inc(),
    )
    .map_err(sweep_error)?;
    progress.finish();
    let table = table(&plan, &solved.rows);
    match &record_path {
        Some(record_path) => {
            table.stage(&mut staged, args.out.as_deref().expect("with its record"))?;
            let inputs = inputs_record(args, &plan, provenance);
            staged.write_json(record_path, &inputs)?;
        }
        None => print!("{}", String::from_utf8(table.to_csv()?)?),
    }
    if let Some(plot) = &args.plot {
        stage_charts(&mut staged, plot, &charts(args, &solved.rows, e_star))?;
    }
    if let (Some(map), Some(contact)) = (&args.map, &solved.map) {
        let name = file_name(args);
        let figure = MapFigure {
            name: &name,
            size: sizes,
            metres: true,
        };
        stage_charts(
            &mut staged,
            map,
            &[contact_map_chart(contact.view(), figure)],
        )?;
    }
    staged.commit()?;
    Ok(())
}

/// Stages a contact run's outputs (all-or-nothing, none of them the input), then reads the
/// measured surface, naming the file in any error: the first steps of every `contact` mode.
/// Returns the staged outputs, the surface and the file's provenance record.
pub(super) fn staged_surface<'a>(
    args: &ContactArgs,
    outputs: impl IntoIterator<Item = &'a PathBuf>,
) -> Result<(StagedOutputs, Surface, serde_json::Value)> {
    let staged = StagedOutputs::new(outputs, args.force)?;
    staged.ensure_not_input(&args.file)?;
    let topography = load(&args.file, &args.measured, args.size.as_deref())?;
    let surface = topography
        .to_surface()
        .with_context(|| format!("{}", args.file.display()))?;
    Ok((staged, surface, record(&topography)))
}
