//! `asperity bem`: 3D boundary-element contact of a rough surface (the Fourier-preconditioned
//! bound-constrained CG by default, Polonsky–Keer on request, both on FFTs) at one or more loads, with the contact stiffness by the frozen contact set.
//!
//! Everything is checked before the first solve (surface and the memory it needs,
//! parameters, every output path). The field files of each load go to temporary files as
//! soon as it is solved (no copies kept in memory); the CSV, the plot and the fields are
//! renamed into place together only after the last load, and any error removes the
//! temporary files, so an error leaves nothing behind.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use asperity::bem::sweep::{sweep, SweepError, SweepFailure, SweepObserver, SweepRow};
use asperity::bem::ContactSolver;
use asperity::io::{sidecar_path, StagedOutputs};
use asperity::memory::array_bytes;
use asperity::surface::Surface;
use asperity_app::bem::{
    bookkeeping_bytes, ensure_solver_fits, params, peak_rss_mib, BemPlan, BemRequest, Loads,
    SolverRequest, FD_STEP, TIMING_COLUMNS,
};
use asperity_app::derived::{Derived, Units};
use asperity_app::persson::{bem_mean_gap, SweepPersson, SweepTheory, SWEEP_COLUMNS};
use asperity_app::refusal::count;
use serde_json::json;

use super::fields_nc::{
    check_target, fields_folder, netcdf_target, stage_sweep, Grid as NcGrid, Stacks,
};
use super::measured::{open_argument, parse_size, MeasuredArgs};
use crate::output::{format_number, print_stdout, Table};
use asperity_app::argument::{Arrays, Dims, SizeSource};
use asperity_app::figure::sweep::{SweepColumns, SweepFigure};

use crate::plot::{stage_charts, Chart, ImageFormat};
use crate::progress::Progress;
use crate::request::refused;

/// Arguments of `asperity bem`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:\n  \
    asperity surface --n 256 --hurst 0.8 --rolloff 6 --rms-slope 1 --seed 1 --out s.npy\n  \
    asperity bem --surface s.npy --nloads 20 --pmin 1e-4 --pmax 1e-1 --out curve.csv\n  \
    asperity bem --surface s.npy --pressures 0.01,0.05 --fields fields/ --out loads.csv\n  \
    asperity bem --surface s.npy --boundary periodic --forces 0.02 --tol 1e-10\n  \
    asperity bem --surface s.npy --indentations 0.01,0.02,0.04\n  \
    asperity bem --surface s.npy --pressures 0.01,0.05 --solver pk --out reference.csv\n  \
    asperity bem --surface s.npy --pressures 0.01,0.05 --hardness 0.3\n  \
    asperity bem --surface s.npy --nloads 10 --pmin 1e-3 --pmax 1e-1 --poisson 0.3 --resistivity 1,1\n  \
    asperity bem --surface s.npy --nloads 20 --pmin 1e-4 --pmax 1e-1 --out sweep.csv --plot sweep.png\n  \
    asperity bem --surface s.npy --boundary periodic --nloads 10 --pmin 1e-4 --pmax 1e-1 --persson --gamma 0.4\n  \
    asperity bem --surface scan.x3p --detrend plane --modulus 1e9 --pressures 1e5,1e6\n\n\
Columns: force, mean_pressure, indentation, area_fraction, stiffness, iterations, residual\n\
(stiffness by the frozen contact set; indentation from the highest point, or with\n\
periodic boundaries relative to the mean elastic displacement); then plastic_fraction\n\
with --hardness, stiffness_fd with --fd-stiffness, stiffness_x, stiffness_y,\n\
tangential_ratio with --poisson, electrical_conductance with --resistivity,\n\
thermal_conductance with --thermal-conductivity, mean_gap, area_fraction_persson,\n\
mean_gap_persson, stiffness_persson with --persson, and solve_seconds, stiffness_seconds,\n\
peak_rss_mib (tangential_seconds with --poisson) with --timing. With --out, OUT.csv.json records the inputs (surface, L and where it came from,\n\
E*, boundary, tolerance, loads, columns). Loads beyond full contact are refused before\n\
any solve.\n\n\
Memory: a solve holds at most about 240 bytes per grid point with free boundaries, 210\n\
periodic (3.7 GiB at 4096² free); a surface that would not fit in 90 % of the memory\n\
available is refused before its heights are read (ASPERITY_MEMORY_LIMIT_MIB=N caps that\n\
figure at N MiB; docs/performance.md).")]
pub struct BemArgs {
    /// Surface heights, positive up: a .npy (float64, 2D), or a measured file (X3P, SDF,
    /// text matrix, x y z, ...; sizes and units from the file, see --channel, --detrend,
    /// --fill).
    #[arg(long, value_name = "FILE")]
    pub surface: PathBuf,
    /// Side lengths: L along x, and along y after a comma for rectangular pixels (else
    /// square pixels, L·rows/cols along y); default: the surface's sidecar or the measured
    /// file's sizes, else 1 for a .npy (a measured file without sizes is refused).
    #[arg(long, value_name = "X[,Y]", allow_hyphen_values = true)]
    pub size: Option<String>,
    #[command(flatten)]
    pub measured: MeasuredArgs,
    /// Effective modulus E*.
    #[arg(long, default_value_t = SolverRequest::default().modulus, allow_hyphen_values = true)]
    pub modulus: f64,
    /// Boundary conditions: free (zero-padded, no periodic images; the paper's) or periodic.
    #[arg(long, default_value_t = SolverRequest::default().boundary)]
    pub boundary: String,
    /// Total forces (load control), comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        value_name = "F1,F2,…"
    )]
    pub forces: Option<Vec<f64>>,
    /// Mean pressures over the nominal area (load control), comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        value_name = "P1,P2,…"
    )]
    pub pressures: Option<Vec<f64>>,
    /// Indentations (displacement control), comma separated. Free boundaries: from the
    /// highest point of the surface (first contact at 0); periodic: relative to the mean
    /// elastic displacement (zero-mean convention, as load control reports it; full contact
    /// at max(h) − mean(h)).
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        value_name = "D1,D2,…"
    )]
    pub indentations: Option<Vec<f64>>,
    /// Number of mean pressures, log-spaced from --pmin to --pmax.
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub nloads: Option<i128>,
    /// Smallest mean pressure for --nloads.
    #[arg(long, value_name = "P", allow_hyphen_values = true)]
    pub pmin: Option<f64>,
    /// Largest mean pressure for --nloads.
    #[arg(long, value_name = "P", allow_hyphen_values = true)]
    pub pmax: Option<f64>,
    /// Convergence tolerance: rms gap violation on the contact set over the rms height.
    #[arg(long, default_value_t = SolverRequest::default().tolerance, allow_hyphen_values = true)]
    pub tol: f64,
    /// The solver: bccg (default; Fourier-preconditioned bound-constrained conjugate
    /// gradients without restart, tens of iterations) or pk (Polonsky & Keer 1999, the
    /// reference; a few times more iterations, each twice as costly). Both converge to the
    /// same contact to --tol.
    #[arg(long, default_value_t = SolverRequest::default().solver)]
    pub solver: String,
    /// Maximum solver iterations per load.
    #[arg(long, default_value_t = SolverRequest::default().max_iterations as i128, allow_hyphen_values = true)]
    pub max_iter: i128,
    /// Cap the contact pressure at this hardness (in the units of the pressures and
    /// --modulus: E* units by default): elastic–perfectly-plastic contact
    /// (docs/hardness.md), with either solver; adds the column plastic_fraction. Each
    /// load is solved on the surface as given (warm-started; the library's load path keeps
    /// the plastic displacement between loads).
    #[arg(long, value_name = "H", allow_hyphen_values = true)]
    pub hardness: Option<f64>,
    /// Walk the loads in the given order as one load path (loading, unloading,
    /// reloading: e.g. --pressures 0.01,0.04,0.01,0.04 --hardness 0.3), each step warm from
    /// the last and its plastic displacement kept (the library's load_path), so the table
    /// shows the hysteresis. Columns branch, force, mean_pressure, indentation,
    /// area_fraction, plastic_fraction, stiffness, iterations, permanent_max; --fields DIR
    /// writes permanent.npy (the permanent displacement after the last step); --plot
    /// draws the loop: F and A/A0 against d, k against F, the steps marked by branch.
    #[arg(long)]
    pub load_path: bool,
    /// Adhesion (work of adhesion Δγ, in the units of the modulus times a length): Pohrt &
    /// Popov's pixel criterion (docs/adhesion.md) along the path of --indentations
    /// (negative allowed), then retracted to pull-off; both pull-offs on stderr and in
    /// OUT.csv.json. Columns indentation, force, mean_pressure, area_fraction,
    /// tensile_fraction, rounds, cg_iterations, branch (path|retract). Square pixels.
    #[arg(long, value_name = "DG", allow_hyphen_values = true)]
    pub work_of_adhesion: Option<f64>,
    /// A Maugis–Dugdale cohesive zone of this range h₀ instead of the pixel criterion (with
    /// --work-of-adhesion): free pixels within h₀ of the indenter carry the stress Δγ/h₀
    /// (docs/adhesion.md). Refused where one pixel's own stress closes more than h₀.
    #[arg(long, value_name = "H0", allow_hyphen_values = true)]
    pub adhesion_range: Option<f64>,
    /// The cohesive law of --adhesion-range: maugis-dugdale (the default: stress Δγ/h₀
    /// within h₀) or exponential (tension (Δγ/ρ)·exp(−g/ρ) at gap g, ρ the range; Rey,
    /// Anciaux & Molinari 2017, the contact-mechanics challenge's law).
    #[arg(long, value_name = "MODEL")]
    pub adhesion_model: Option<String>,
    /// The retraction's step in indentation (with --work-of-adhesion; default the deepest
    /// indentation, plus any --adhesion-range, / 200).
    #[arg(long, value_name = "STEP", allow_hyphen_values = true)]
    pub retract_step: Option<f64>,
    /// Output table (CSV); printed to stdout when absent. Its inputs go to OUT.csv.json
    /// beside it (surface, L and its source, E*, boundary, tolerance, loads, columns).
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
    /// Also plot the load sweep (needs at least 2 loads), .png or .svg by the extension:
    /// log–log contact stiffness k vs force F (left) and area fraction vs F (right), with
    /// F and k divided by E* (length² and length).
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Write pressure_K.npy and gap_K.npy for every load K (0-based) into DIR. Refused if
    /// DIR holds pressure_*.npy or gap_*.npy files this run would not replace (an earlier
    /// run's; use another folder). A name ending in .nc writes one NetCDF file instead:
    /// pressure(load, y, x), gap(load, y, x), the per-load force, mean_pressure,
    /// indentation and area_fraction, x and y coordinates, CF attributes (units where
    /// known: metres for a measured surface) and the run's record (docs/python.md).
    #[arg(long, value_name = "DIR|FILE.nc")]
    pub fields: Option<PathBuf>,
    /// Add the column stiffness_fd: the finite-difference dF/dd by central differences of
    /// two extra solves at the load × (1 ± 1e-3), after the frozen-set stiffness and the
    /// fields (which are unaffected); the load is then solved again, so the next load
    /// warm-starts from it. About three more (warm-started) solves per load; empty at
    /// indentation 0.
    #[arg(long)]
    pub fd_stiffness: bool,
    /// Poisson's ratio ν in [0, 0.5] of the tangential (no-slip) stiffness: adds the
    /// columns stiffness_x, stiffness_y (k_x, k_y of the frozen contact set with Cerruti's
    /// kernel, docs/tangential.md) and tangential_ratio = (k_x + k_y)/(2k), Mindlin's
    /// 2(1−ν)/(2−ν) for one circular contact. About two more stiffness solves per load.
    /// E* stays --modulus.
    #[arg(long, value_name = "NU", allow_hyphen_values = true)]
    pub poisson: Option<f64>,
    /// With --poisson: which tangential stiffnesses, x, y or both [default: both]. One
    /// direction adds only its column (stiffness_x or stiffness_y), tangential_ratio is
    /// then k_x/k (k_y/k), and costs about one stiffness solve per load instead of two.
    #[arg(long, value_name = "DIR")]
    pub tangential: Option<String>,
    /// Electrical resistivities ρ₁,ρ₂ of the two bodies (units of E*·length/conductance):
    /// adds the column electrical_conductance = 2k/(E*(ρ₁+ρ₂)) (Barber's analogy).
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        value_name = "R1,R2"
    )]
    pub resistivity: Option<Vec<f64>>,
    /// Thermal conductivities κ₁,κ₂ of the two bodies: adds the column
    /// thermal_conductance = (2k/E*)·κ₁κ₂/(κ₁+κ₂) (Barber's analogy).
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        value_name = "K1,K2"
    )]
    pub thermal_conductivity: Option<Vec<f64>>,
    /// Persson's theory beside every load (docs/persson.md): adds the columns mean_gap (the
    /// BEM's mean gap; with periodic boundaries Persson's mean separation ū) and
    /// area_fraction_persson, mean_gap_persson, stiffness_persson (the interfacial K·A0),
    /// computed from the surface's own PSD at each load's mean pressure and E*. Square
    /// pixels. Milliseconds besides the solves.
    #[arg(long)]
    pub persson: bool,
    /// γ of Persson's mean separation (Yang & Persson 2008), in (0, 1] [default: 0.45]
    /// (with --persson).
    #[arg(long, value_name = "G", allow_hyphen_values = true)]
    pub gamma: Option<f64>,
    /// κ of Persson's contact area, A/A0 → κ p/(E* ḡ) at small load [default: √(8/π),
    /// Persson 2001; simulations find about 2] (with --persson).
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub kappa: Option<f64>,
    /// Add timing columns (solve_seconds, stiffness_seconds, peak_rss_mib, and
    /// tangential_seconds with --poisson), for benchmarks.
    #[arg(long)]
    pub timing: bool,
    /// Skip the frozen-set stiffness (column left empty); for benchmarks of the solve alone.
    #[arg(long, hide = true)]
    pub no_stiffness: bool,
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
    /// Overwrite existing outputs.
    #[arg(long)]
    pub force: bool,
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

/// Refuses a `--fields` folder that holds `pressure_*.npy` or `gap_*.npy` files this run
/// would not write (`count` loads): left beside the new ones, they would pass for its own.
fn ensure_no_stale_fields(dir: &Path, count: usize) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(()); // a missing folder is made; anything else is reported when staging
    };
    let ours = |name: &str| {
        let index = name
            .strip_prefix("pressure_")
            .or_else(|| name.strip_prefix("gap_"))
            .and_then(|rest| rest.strip_suffix(".npy"));
        index.and_then(|k| k.parse::<usize>().ok()).map(|k| {
            // Only the canonical spelling of an index below `count` is written.
            k < count && name.ends_with(&format!("_{k}.npy"))
        })
    };
    let mut stale: Vec<String> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|name| {
            let pattern = (name.starts_with("pressure_") || name.starts_with("gap_"))
                && name.ends_with(".npy");
            pattern && ours(name) != Some(true)
        })
        .collect();
    stale.sort();
    if let Some(first) = stale.first() {
        let more = match stale.len() {
            1 => String::new(),
            n => format!(" and {} more", n - 1),
        };
        bail!(
            "--fields {}: holds {first}{more} from an earlier run, which this run ({count} load{}) would not replace; use another folder (or remove the old field files)",
            dir.display(),
            if count == 1 { "" } else { "s" }
        );
    }
    Ok(())
}

/// What `asperity bem` does during the library's sweep: writes each load's fields to
/// their staged files as soon as it is solved, counts progress and, with `--timing`, notes
/// the peak memory after each load.
struct CliObserver<'a> {
    staged: &'a mut StagedOutputs,
    fields: Option<&'a [(PathBuf, PathBuf)]>,
    netcdf: Option<&'a mut Stacks>,
    progress: Progress,
    peak_rss: Option<Vec<f64>>,
    mean_gaps: Option<Vec<f64>>,
}

impl SweepObserver for CliObserver<'_> {
    type Error = anyhow::Error;

    fn solved(&mut self, load: usize, solver: &ContactSolver) -> Result<()> {
        if let Some((p_path, g_path)) = self.fields.map(|f| &f[load]) {
            self.staged.write_npy_2d(p_path, &solver.pressure())?;
            self.staged.write_npy_2d(g_path, &solver.gap())?;
        }
        if let Some(stacks) = &mut self.netcdf {
            stacks.push(solver);
        }
        if let Some(gaps) = &mut self.mean_gaps {
            gaps.push(bem_mean_gap(solver));
        }
        Ok(())
    }

    fn finished(&mut self, _load: usize, _row: &SweepRow) -> Result<()> {
        if let Some(peaks) = &mut self.peak_rss {
            peaks.push(peak_rss_mib().unwrap_or(f64::NAN));
        }
        self.progress.inc();
        Ok(())
    }
}

/// A sweep's error in the command line's words (its flags, the load as `load 3 (…)`), as
/// the library's [`SweepError::explain`] puts it.
fn sweep_error(error: SweepError<anyhow::Error>) -> anyhow::Error {
    match error.explain("--fd-stiffness") {
        SweepFailure::Input(source) => source.into(),
        SweepFailure::AtLoad { context, source } => anyhow::Error::new(source).context(context),
        SweepFailure::StepBeyondFullContact(message) => anyhow::anyhow!(message),
        SweepFailure::Stopped(e) => e,
    }
}

/// As the stderr line states where L came from: `from --size`, `from sidecar`, `default`.
fn size_phrase(source: SizeSource) -> &'static str {
    match source {
        SizeSource::Flag => "from --size",
        SizeSource::Sidecar => "from sidecar",
        SizeSource::File => "from the measured file",
        SizeSource::Default => "default",
    }
}

/// The columns written: the fixed ones, then `stiffness_fd` with `--fd-stiffness` and the
/// timing columns with `--timing`.
#[derive(Debug, Clone, Copy)]
struct Columns {
    fd: bool,
    timing: bool,
    plastic: bool,
    derived: Derived,
    modulus: f64,
    persson: bool,
}

impl Columns {
    fn header(self) -> Vec<&'static str> {
        let mut header = vec![
            "force",
            "mean_pressure",
            "indentation",
            "area_fraction",
            "stiffness",
            "iterations",
            "residual",
        ];
        if self.plastic {
            header.push("plastic_fraction");
        }
        if self.fd {
            header.push("stiffness_fd");
        }
        header.extend(self.derived.columns(Units::Model));
        if self.persson {
            header.extend(SWEEP_COLUMNS);
        }
        if self.timing {
            header.extend(TIMING_COLUMNS);
            if self.derived.tangential.is_some() {
                header.push("tangential_seconds");
            }
        }
        header
    }

    /// One row's CSV cells: numbers in their shortest round-trip form, the iterations as an
    /// integer, an empty cell where a value was not computed.
    fn cells(self, row: &Row) -> Vec<String> {
        let number = |v: Option<f64>| v.map_or_else(String::new, format_number);
        let r = &row.sweep;
        let mut cells = vec![
            format_number(r.summary.force),
            format_number(r.summary.mean_pressure),
            format_number(r.summary.indentation),
            format_number(r.summary.area_fraction),
            number(r.stiffness),
            r.info.iterations.to_string(),
            format_number(r.info.residual),
        ];
        if self.plastic {
            cells.push(format_number(r.summary.plastic_fraction));
        }
        if self.fd {
            cells.push(number(r.stiffness_fd));
        }
        let derived = self.derived.row(r, self.modulus);
        cells.extend(self.derived.values(&derived).into_iter().map(number));
        if self.persson {
            cells.extend(row.persson.iter().map(|&v| number(v)));
        }
        if self.timing {
            cells.extend([
                format_number(r.solve_seconds),
                format_number(r.stiffness_seconds),
                format_number(row.peak_rss_mib),
            ]);
            if self.derived.tangential.is_some() {
                cells.push(format_number(r.tangential_seconds));
            }
        }
        cells
    }
}

/// One load's results: the library's row, the peak memory after it (`--timing`), and with
/// `--persson` the BEM's mean gap and Persson's three columns.
struct Row {
    sweep: SweepRow,
    peak_rss_mib: f64,
    persson: Vec<Option<f64>>,
}

/// The `--plot` panels ([`asperity_app::figure::sweep`]): k vs F and area fraction vs F,
/// in N and N/m as the CSV holds them when the surface came from a measured file (lengths
/// in metres, E* in Pa: `physical`), else divided by E*.
fn sweep_charts(
    rows: &[Row],
    fd: bool,
    (modulus, physical): (f64, bool),
    surface: &Path,
    boundary: &str,
) -> [Chart; 2] {
    let name = surface.file_name().map_or_else(
        || surface.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    let column =
        |y: &dyn Fn(&SweepRow) -> f64| -> Vec<f64> { rows.iter().map(|r| y(&r.sweep)).collect() };
    let force = column(&|r| r.summary.force);
    let stiffness = column(&|r| r.stiffness.unwrap_or(f64::NAN));
    let stiffness_fd = column(&|r| r.stiffness_fd.unwrap_or(f64::NAN));
    let area_fraction = column(&|r| r.summary.area_fraction);
    let columns = SweepColumns {
        force: &force,
        stiffness: &stiffness,
        stiffness_fd: fd.then_some(&stiffness_fd[..]),
        area_fraction: &area_fraction,
    };
    let figure = SweepFigure {
        name: &name,
        modulus,
        physical,
        boundary,
    };
    asperity_app::figure::sweep::sweep_charts(columns, figure)
}

/// The checked arguments: everything a solve needs besides the surface.
struct Plan {
    request: BemRequest,
    bem: BemPlan,
    size: [Option<f64>; 2],
    columns: Columns,
    persson: Option<SweepPersson>,
}

/// The request of the arguments: the loads, the solver and what each load computes.
pub(super) fn request(args: &BemArgs) -> Result<BemRequest> {
    let loads = Loads::from_options(
        args.forces.clone(),
        args.pressures.clone(),
        args.indentations.clone(),
        args.nloads.map(|n| count(params::NLOADS, n)).transpose()?,
        (args.pmin, args.pmax),
    )?;
    Ok(BemRequest {
        solver: SolverRequest {
            modulus: args.modulus,
            boundary: args.boundary.clone(),
            solver: args.solver.clone(),
            tolerance: args.tol,
            max_iterations: count(params::MAX_ITER, args.max_iter)?,
            hardness: args.hardness,
        },
        loads,
        stiffness: !args.no_stiffness,
        fd_step: args.fd_stiffness.then_some(FD_STEP),
        fields: args.fields.is_some(),
        poisson: args.poisson,
        tangential: args.tangential.clone(),
        resistivity: args.resistivity.clone(),
        thermal_conductivity: args.thermal_conductivity.clone(),
    })
}

/// Step 1a: every argument that can be checked without touching a file: the request (the
/// front-end layer's rules), the size, the plot.
fn plan(args: &BemArgs) -> Result<Plan> {
    let request = request(args)?;
    let bem = request.validate()?;
    let size = match &args.size {
        Some(text) => parse_size(text)?,
        None => [None, None],
    };
    if let Some(plot) = &args.plot {
        ImageFormat::from_path(plot, "--plot")?;
        if bem.loads.len() < 2 {
            bail!("--plot needs at least 2 loads (a curve), got 1");
        }
        if args.no_stiffness {
            bail!("--plot draws the stiffness: drop --no-stiffness");
        }
    }
    let columns = Columns {
        fd: args.fd_stiffness,
        timing: args.timing,
        plastic: bem.hardness().is_some(),
        derived: bem.derived,
        modulus: bem.half_space.modulus,
        persson: args.persson,
    };
    let persson = SweepPersson::from_options(args.persson, args.gamma, args.kappa)
        .map_err(|r| refused(r.into()))?;
    if let Some(options) = persson {
        options.params(bem.half_space.modulus).map_err(refused)?;
    }
    Ok(Plan {
        request,
        bem,
        size,
        columns,
        persson,
    })
}

/// The declared outputs: staged, with the field paths of every load (`--fields`).
pub(super) struct Outputs {
    pub(super) staged: StagedOutputs,
    fields: Option<Vec<(PathBuf, PathBuf)>>,
    /// `--fields FILE.nc`: the fields of every load, written at the end.
    netcdf: Option<Stacks>,
}

/// Step 1b: the outputs, checked before any work. Each folder exists (`--fields DIR` and its
/// missing parents are made here, and removed again on any error), no output is named twice
/// or exists without `--force`, none is the surface or its sidecar, and `--fields DIR` holds
/// no field files of another run. They are written to temporary files as each load is solved
/// and renamed into place together at the end.
pub(super) fn stage_outputs(args: &BemArgs, loads: usize) -> Result<Outputs> {
    let netcdf = netcdf_target(args.fields.as_ref());
    let folder = fields_folder(args.fields.as_ref());
    if let Some(path) = netcdf {
        check_target(path)?;
    }
    if let Some(dir) = folder {
        ensure_no_stale_fields(dir, loads)?;
    }
    let fields = folder.map(|dir| field_paths(dir, loads));
    let record_path = args.out.as_deref().map(sidecar_path);
    let output_paths = args
        .out
        .iter()
        .chain(&record_path)
        .chain(&args.plot)
        .map(PathBuf::as_path)
        .chain(netcdf)
        .chain(fields.iter().flatten().flat_map(|(p, g)| [p.as_path(), g]));
    let staged = StagedOutputs::in_new_folders(folder, output_paths, args.force)?;
    staged.ensure_not_input(&args.surface)?;
    let netcdf = netcdf.map(Stacks::new);
    Ok(Outputs {
        staged,
        fields,
        netcdf,
    })
}

/// Step 1c: the surface, with where its side length came from. A `.npy`'s memory is checked
/// from its header before its data is read (the solver plus the per-load bookkeeping: the
/// heights are freed before the first solve, `run`); a measured file is read, bounded, by
/// the topography reader and checked after.
fn read_surface(args: &BemArgs, plan: &Plan, outputs: &Outputs) -> Result<(Surface, SizeSource)> {
    let loads = plan.bem.loads.len();
    let fields = (outputs.fields.is_some(), outputs.netcdf.is_some());
    read_surface_with(
        args,
        (plan.size, plan.bem.half_space.boundary),
        (loads, fields),
        true,
    )
}

/// The surface of a run without a load sweep (`--work-of-adhesion`), with where its side
/// length came from as the record names it.
pub(super) fn read_surface_for(
    args: &BemArgs,
    boundary: asperity::elastic::Boundary,
) -> Result<(Surface, &'static str)> {
    let size = match &args.size {
        Some(text) => parse_size(text)?,
        None => [None, None],
    };
    let (surface, source) = read_surface_with(args, (size, boundary), (0, (false, false)), false)?;
    Ok((surface, source.name()))
}

/// [`read_surface`] for `size` (`--size`) and `boundary`, with the bookkeeping of `loads`
/// loads (and their fields: written as solved, or kept for one `.nc` file) in the memory
/// check, and the heights unless `heights_freed` (the caller frees them before solving).
fn read_surface_with(
    args: &BemArgs,
    (size, boundary): ([Option<f64>; 2], asperity::elastic::Boundary),
    (loads, (fields, kept)): (usize, (bool, bool)),
    heights_freed: bool,
) -> Result<(Surface, SizeSource)> {
    let fits = |shape: &[usize]| match *shape {
        [rows, cols] => {
            // A .nc file: pressure and gap of every load, a filled copy and the bytes.
            let kept = if kept { [loads, rows, cols, 6] } else { [0; 4] };
            // The heights, unless freed before the first solve (`run`): while they live
            // (read, solver built) the solver holds less than its estimate by more than
            // they take (8 bytes per point, and a reader's copy while it converts them):
            // the stiffness CG's 56 bytes per point come with the first stiffness.
            let heights = array_bytes(&[rows, cols], if heights_freed { 0 } else { 8 });
            let extra = heights
                .zip(bookkeeping_bytes(loads, fields || kept[0] > 0))
                .and_then(|(heights, loads)| heights.checked_add(loads))
                .zip(array_bytes(&kept, 8))
                .and_then(|(extra, kept)| extra.checked_add(kept));
            ensure_solver_fits(rows, cols, boundary, extra)
        }
        _ => Ok(()),
    };
    let size = (size != [None, None]).then_some(size);
    let input = open_argument(
        &args.surface,
        &args.measured,
        size,
        Arrays::Plain(Dims::Map, &fits),
    )?;
    let surface = input.topography.to_surface().with_context(|| {
        match (input.size_source, &input.topography.sizes[..]) {
            (SizeSource::Sidecar, [size, ..]) => format!(
                "{} (L = {size} from its sidecar {})",
                args.surface.display(),
                sidecar_path(&args.surface).display()
            ),
            _ => format!("{}", args.surface.display()),
        }
    })?;
    if input.measured {
        let (rows, cols) = surface.dim();
        ensure_solver_fits(rows, cols, boundary, Some(0))?;
    }
    Ok((surface, input.size_source))
}

/// The surface as the record and the stderr line state it.
struct SurfaceInfo {
    grid: (usize, usize),
    size: f64,
    size_y: f64,
    square_pixels: bool,
    source: SizeSource,
}

impl SurfaceInfo {
    fn sizes_shown(&self) -> String {
        if self.square_pixels {
            format!("{}", self.size)
        } else {
            format!("{} × {}", self.size, self.size_y)
        }
    }
}

/// Step 2: every load solved (warm starts in the given order) after the full-contact check
/// of every load: the library's sweep, the fields staged as each load is solved.
fn solve(
    args: &BemArgs,
    plan: &Plan,
    (solver, theory): (&mut ContactSolver, Option<&SweepTheory>),
    outputs: &mut Outputs,
) -> Result<Vec<Row>> {
    let loads = &plan.bem.loads;
    let mut observer = CliObserver {
        staged: &mut outputs.staged,
        fields: outputs.fields.as_deref(),
        netcdf: outputs.netcdf.as_mut(),
        progress: Progress::new("bem", loads.len() as u64, args.quiet || loads.len() < 2),
        peak_rss: args.timing.then(Vec::new),
        mean_gaps: theory.map(|_| Vec::new()),
    };
    let every = crate::progress::solve_progress((args.progress, args.progress_every), args.quiet);
    solver.set_monitor(observer.progress.solve_monitor("bem", every));
    let solved = sweep(solver, loads, plan.bem.sweep, &mut observer).map_err(sweep_error)?;
    observer.progress.finish();
    let peak_rss = observer.peak_rss.take().unwrap_or_default();
    let mean_gaps = observer.mean_gaps.take().unwrap_or_default();
    let mut rows = Vec::with_capacity(solved.len());
    for (k, sweep) in solved.into_iter().enumerate() {
        let persson = match theory {
            Some(theory) => {
                let predicted = theory.row(sweep.summary.mean_pressure).map_err(refused)?;
                std::iter::once(mean_gaps.get(k).copied())
                    .chain(predicted)
                    .collect()
            }
            None => Vec::new(),
        };
        rows.push(Row {
            sweep,
            peak_rss_mib: peak_rss.get(k).copied().unwrap_or(f64::NAN),
            persson,
        });
    }
    Ok(rows)
}

/// The inputs of a run, for OUT.csv.json (`hardness` only where the pressure is capped,
/// `persson` only with `--persson`).
fn record(
    args: &BemArgs,
    plan: &Plan,
    surface: &SurfaceInfo,
    theory: Option<&SweepTheory>,
) -> serde_json::Value {
    let mut record = inputs(args, plan, surface);
    if let (Some(h), Some(fields)) = (plan.bem.hardness(), record.as_object_mut()) {
        fields.insert("hardness".into(), json!(h));
    }
    if let (Some(t), Some(fields)) = (theory, record.as_object_mut()) {
        fields.insert("persson".into(), persson_record(t));
    }
    record
}

/// Persson's theory beside the sweep, for OUT.csv.json.
fn persson_record(theory: &SweepTheory) -> serde_json::Value {
    let theory = theory.theory();
    json!({
        "gamma": theory.params().gamma,
        "kappa": theory.params().kappa,
        "rms_gradient": theory.rms_gradient(),
        "rms_height": theory.rms_height(),
        "u0": theory.u0(),
        "source": "the surface's radially averaged PSD (docs/persson.md)",
    })
}

/// The inputs of every run, for OUT.csv.json.
fn inputs(args: &BemArgs, plan: &Plan, surface: &SurfaceInfo) -> serde_json::Value {
    json!({
        "command": "asperity bem",
        "version": env!("CARGO_PKG_VERSION"),
        "surface": args.surface,
        "grid": [surface.grid.0, surface.grid.1],
        "size": surface.size,
        "size_y": surface.size_y,
        "size_source": surface.source.name(),
        "modulus": args.modulus,
        "boundary": plan.bem.half_space.boundary.name(),
        "solver": plan.bem.params.solver.name(),
        "tolerance": args.tol,
        "max_iterations": args.max_iter,
        "loads": plan.request.loads.record(),
        "stiffness": if args.no_stiffness { None } else { Some("frozen contact set") },
        "fd_relative_step": args.fd_stiffness.then_some(FD_STEP),
        "tangential": plan.bem.derived.tangential.map(|nu| json!({
            "poisson": nu,
            "directions": plan.bem.derived.directions.name(),
            "method": "frozen contact set, Cerruti kernel (normal-tangential coupling neglected)",
        })),
        "resistivity": args.resistivity,
        "thermal_conductivity": args.thermal_conductivity,
        "fields": args.fields,
        "columns": plan.columns.header(),
    })
}

/// Step 3: the table (to OUT.csv with its record, else to standard output after the
/// commit) and the plot, renamed into place with the fields.
fn write(
    args: &BemArgs,
    (plan, theory): (&Plan, Option<&SweepTheory>),
    surface: &SurfaceInfo,
    rows: &[Row],
    outputs: Outputs,
) -> Result<()> {
    let Outputs {
        mut staged, netcdf, ..
    } = outputs;
    if let Some(stacks) = netcdf {
        let path = stacks.path.clone();
        let record = record(args, plan, surface, theory);
        stage_netcdf(&mut staged, stacks, surface, rows, &record)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let mut table = Table::new(&plan.columns.header());
    for row in rows {
        table.push(&plan.columns.cells(row));
    }
    if let Some(out) = &args.out {
        table
            .stage(&mut staged, out)
            .with_context(|| format!("writing {}", out.display()))?;
        let record_path = sidecar_path(out);
        staged
            .write_json(&record_path, &record(args, plan, surface, theory))
            .with_context(|| format!("writing {}", record_path.display()))?;
    }
    if let Some(plot) = &args.plot {
        let physical = matches!(surface.source, SizeSource::File);
        let boundary = plan.bem.half_space.boundary.name();
        let charts = sweep_charts(
            rows,
            plan.columns.fd,
            (args.modulus, physical),
            &args.surface,
            boundary,
        );
        stage_charts(&mut staged, plot, &charts)
            .with_context(|| format!("writing {}", plot.display()))?;
    }
    staged.commit()?;
    if !args.quiet {
        eprintln!(
            "L = {} ({})",
            surface.sizes_shown(),
            size_phrase(surface.source)
        );
    }
    match &args.out {
        Some(out) if !args.quiet => eprintln!(
            "wrote {} and {} ({} loads)",
            out.display(),
            sidecar_path(out).display(),
            rows.len()
        ),
        Some(_) => {}
        None => print_stdout(&table.to_csv()?)?,
    }
    Ok(())
}

/// Stages `--fields FILE.nc`: every load's fields with the table's first columns and the
/// run's record.
fn stage_netcdf(
    staged: &mut StagedOutputs,
    stacks: Stacks,
    surface: &SurfaceInfo,
    rows: &[Row],
    record: &serde_json::Value,
) -> Result<()> {
    let column = |f: fn(&asperity::bem::ContactSummary) -> f64| -> Vec<f64> {
        rows.iter().map(|r| f(&r.sweep.summary)).collect()
    };
    let columns = [
        ("force", column(|s| s.force)),
        ("mean_pressure", column(|s| s.mean_pressure)),
        ("indentation", column(|s| s.indentation)),
        ("area_fraction", column(|s| s.area_fraction)),
    ];
    let grid = NcGrid {
        dim: surface.grid,
        sizes: (surface.size, surface.size_y),
        metres: matches!(surface.source, SizeSource::File),
    };
    stage_sweep(staged, stacks, &grid, &columns, record)
}

/// Runs `asperity bem`: plan (every check before the first solve), solve, write.
pub fn run(args: &BemArgs) -> Result<()> {
    if args.persson && (args.work_of_adhesion.is_some() || args.load_path) {
        let other = match args.load_path {
            true => "--load-path",
            false => "--work-of-adhesion",
        };
        bail!("--persson goes with a load sweep, not with {other}");
    }
    if let Some(w) = args.work_of_adhesion {
        return super::bem_adhesion::run(args, w);
    }
    if args.retract_step.is_some() {
        bail!("--retract-step goes with --work-of-adhesion");
    }
    if args.adhesion_range.is_some() {
        bail!("--adhesion-range goes with --work-of-adhesion");
    }
    if args.adhesion_model.is_some() {
        bail!("--adhesion-model goes with --work-of-adhesion");
    }
    if args.load_path {
        return super::bem_path::run(args);
    }
    let plan = plan(args)?;
    let mut outputs = stage_outputs(args, plan.bem.loads.len())?;
    let (surface, source) = read_surface(args, &plan, &outputs)?;
    let info = SurfaceInfo {
        grid: surface.dim(),
        size: surface.size(),
        size_y: surface.size_y(),
        square_pixels: surface.has_square_pixels(),
        source,
    };
    let mut solver = plan.bem.solver(&surface)?;
    // The solver keeps its own copy of the profile: free the heights (peak memory).
    drop(surface);
    plan.bem.check_forces(solver.nominal_area())?;
    let theory = plan
        .persson
        .map(|options| SweepTheory::new(&solver, options))
        .transpose()
        .map_err(refused)?;
    let rows = solve(args, &plan, (&mut solver, theory.as_ref()), &mut outputs)?;
    write(args, (&plan, theory.as_ref()), &info, &rows, outputs)
}
