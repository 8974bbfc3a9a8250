//! `asperity import FILE --out s.npy`: a measured topography (X3P, SDF, text matrix,
//! x y z list, x z profile, or any format the library reads) into a float64 `.npy` with a
//! JSON sidecar recording where it came from and how it was cleaned, or into an X3P file.

use std::path::PathBuf;

use anyhow::Result;
use asperity_app::import::Import;

use super::measured::{load, MeasuredArgs};
use crate::request::refused;

/// Arguments of `asperity import`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:\n  \
    asperity import scan.x3p --out s.npy --detrend plane\n  \
    asperity import afm.txt --out s.npy --channel ZSensor --detrend lines --fill harmonic\n  \
    asperity import matrix.txt --size 10e-6,5e-6 --out s.npy --detrend none\n  \
    asperity import profile.csv --out line.npy --detrend mean\n  \
    asperity import scan.sdf --out s.x3p --detrend plane\n\n\
Heights and sizes are written in metres (where the file gives a unit). The sidecar\n\
OUT.npy.json records source, format, channel, units, sizes per axis and every cleaning\n\
step; asperity's other commands read the sizes from it.")]
pub struct ImportArgs {
    /// A measured topography file; the format is found from its content (then extension).
    pub file: PathBuf,
    /// Output: .npy (with OUT.npy.json beside it) or .x3p (maps only).
    #[arg(long, value_name = "OUT.npy|OUT.x3p")]
    pub out: PathBuf,
    /// Physical size X (and Y) in metres, where the file has none or to override it;
    /// X alone: square pixels.
    #[arg(long, value_name = "X[,Y]")]
    pub size: Option<String>,
    #[command(flatten)]
    pub measured: MeasuredArgs,
    /// Overwrite existing outputs.
    #[arg(long)]
    pub force: bool,
}

/// Runs `asperity import`: the outputs staged, the file opened, the outputs written, by
/// the front-end layer ([`asperity_app::import`]).
pub fn run(args: &ImportArgs) -> Result<()> {
    let import = Import::stage(&args.file, &args.out, args.force).map_err(refused)?;
    let topography = load(&args.file, &args.measured, args.size.as_deref())?;
    import.write(&args.file, &topography).map_err(refused)?;
    eprintln!(
        "{}",
        asperity_app::import::summary(&args.out, &args.file, &topography)
    );
    Ok(())
}
