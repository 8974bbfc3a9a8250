//! `asperity persson`: Persson's theory for a surface, from its own radially averaged PSD
//! (the library's `persson` module, docs/persson.md): relative contact area, mean
//! interfacial separation and contact stiffness against the mean pressure.
//!
//! A command of its own rather than an option of `stats` or `bem`: it needs its own inputs
//! (E*, pressures, γ, κ) and writes a load table, which `stats` does not; and it runs in
//! milliseconds without a solver, which `bem` would make wait for its checks and solves.

use std::path::PathBuf;

use anyhow::{Context, Result};
use asperity::persson::PerssonParams;
use asperity::surface::Surface;
use asperity_app::persson::{compute, params, pressures, PerssonRequest, COLUMNS};
use asperity_app::refusal::count;

use super::measured::{open_argument, parse_size, MeasuredArgs};
use crate::output::Table;
use crate::request::refused;
use asperity_app::argument::{Arrays, Dims};

/// Arguments of `asperity persson`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:\n  \
    asperity surface --n 256 --hurst 0.8 --rolloff 6 --rms-slope 1 --seed 1 --out s.npy\n  \
    asperity persson s.npy --nloads 20 --pmin 1e-4 --pmax 1e-1 --out persson.csv\n  \
    asperity persson s.npy --pressures 0.001,0.01 --kappa 2 --gamma 0.4\n  \
    asperity persson scan.x3p --detrend plane --modulus 1e9 --pressures 1e5,1e6\n\n\
Columns: pressure (mean pressure, in the unit of --modulus), area_fraction (A/A0),\n\
mean_gap (in the length unit of the surface: metres for a measured file),\n\
stiffness_per_area (K = -dp/dū, pressure per length), contact_stiffness (K·A0, force per\n\
length, comparable with `asperity bem`'s stiffness). Equations: Persson 2001 (area),\n\
Persson 2007 with Yang & Persson 2008's S = γ + (1-γ)P² (separation); see docs/persson.md.")]
pub struct PerssonArgs {
    /// Surface heights, positive up: a .npy (float64, 2D; L from its sidecar, else 1) or a
    /// measured file (X3P, SDF, text matrix, x y z, ...; sizes and units from the file).
    pub surface: PathBuf,
    /// Side lengths X[,Y] (overrides the sidecar's or the file's).
    #[arg(long, value_name = "X[,Y]")]
    pub size: Option<String>,
    #[command(flatten)]
    pub measured: MeasuredArgs,
    /// Effective modulus E*.
    #[arg(long, default_value_t = PerssonParams::default().modulus, allow_hyphen_values = true)]
    pub modulus: f64,
    /// Mean pressures, comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        value_name = "P1,P2,…"
    )]
    pub pressures: Option<Vec<f64>>,
    /// Number of mean pressures, log-spaced from --pmin to --pmax.
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub nloads: Option<i128>,
    /// Smallest mean pressure for --nloads.
    #[arg(long, value_name = "P", allow_hyphen_values = true)]
    pub pmin: Option<f64>,
    /// Largest mean pressure for --nloads.
    #[arg(long, value_name = "P", allow_hyphen_values = true)]
    pub pmax: Option<f64>,
    /// Yang & Persson's elastic-energy factor γ, in (0, 1] (1: no correction).
    #[arg(long, default_value_t = PerssonParams::default().gamma, allow_hyphen_values = true)]
    pub gamma: f64,
    /// Small-load area coefficient κ in A/A0 → κ p/(E* ḡ) [default: √(8/π), Persson 2001;
    /// simulations find about 2].
    #[arg(long, default_value_t = PerssonParams::default().kappa, allow_hyphen_values = true)]
    pub kappa: f64,
    /// Output table (CSV); printed to stdout when absent.
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
    /// Overwrite an existing output.
    #[arg(long)]
    pub force: bool,
}

/// Runs `asperity persson`: the request, the surface, the front-end layer's table.
pub fn run(args: &PerssonArgs) -> Result<()> {
    let request = PerssonRequest {
        params: PerssonParams {
            modulus: args.modulus,
            gamma: args.gamma,
            kappa: args.kappa,
        },
        pressures: pressures(
            args.pressures.clone(),
            args.nloads.map(|n| count(params::NLOADS, n)).transpose()?,
            args.pmin,
            args.pmax,
        )
        .map_err(refused)?,
    };
    request.validate().map_err(refused)?;
    let surface = read_surface(args)?;
    let table = compute(&surface, &request)
        .map_err(refused)
        .with_context(|| format!("{}", args.surface.display()))?;
    let mut csv = Table::new(&COLUMNS);
    for row in &table.rows {
        csv.push_numbers(row);
    }
    match &args.out {
        Some(path) => csv.write(path, args.force)?,
        None => print!("{}", String::from_utf8(csv.to_csv()?)?),
    }
    let (rows, cols) = surface.dim();
    eprintln!(
        "{}: {rows}x{cols}, rms height {:.4e}, rms gradient (spectral) {:.4e}, u0 {:.4e} (γ = {}, κ = {})",
        args.surface.display(),
        table.rms_height,
        table.rms_gradient,
        table.u0,
        args.gamma,
        args.kappa
    );
    Ok(())
}

/// The surface: a measured file (or an imported .npy) through the topography reader, else
/// a .npy with its side length from --size, its sidecar or 1 (the front-end layer's one
/// call).
fn read_surface(args: &PerssonArgs) -> Result<Surface> {
    let size = args.size.as_deref().map(parse_size).transpose()?;
    let no_check = |_: &[usize]| Ok(());
    let input = open_argument(
        &args.surface,
        &args.measured,
        size,
        Arrays::Plain(Dims::Map, &no_check),
    )?;
    input
        .topography
        .to_surface()
        .with_context(|| format!("{}", args.surface.display()))
}
