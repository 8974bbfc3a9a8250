//! `asperity import FILE --out s.npy`: a measured topography (X3P, SDF, text matrix,
//! x y z list, x z profile, or any format the library reads) into a float64 `.npy` with a
//! JSON sidecar recording where it came from and how it was cleaned, or into an X3P file.

use std::path::PathBuf;

use anyhow::{bail, Result};
use asperity::io::{sidecar_path, StagedOutputs};
use asperity::topography::{x3p, Heights};
use serde_json::json;

use super::measured::{load, record, MeasuredArgs};

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

/// Runs `asperity import`.
pub fn run(args: &ImportArgs) -> Result<()> {
    let ext = args
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let x3p_out = match ext.as_deref() {
        Some("npy") => false,
        Some("x3p") => true,
        _ => bail!(
            "--out {}: the file name must end in .npy or .x3p",
            args.out.display()
        ),
    };
    let sidecar = sidecar_path(&args.out);
    let outputs = if x3p_out {
        vec![args.out.clone()]
    } else {
        vec![args.out.clone(), sidecar.clone()]
    };
    let mut staged = StagedOutputs::new(&outputs, args.force)?;
    staged.ensure_not_input(&args.file)?;
    let topography = load(&args.file, &args.measured, args.size.as_deref())?;
    match (&topography.heights, x3p_out) {
        (Heights::Areal(h), true) => {
            let bytes = x3p::to_bytes(h.view(), [topography.sizes[0], topography.sizes[1]])?;
            staged.write_bytes(&args.out, &bytes)?;
        }
        (Heights::Profile(_), true) => bail!(
            "{}: a line profile cannot be written as X3P here (maps only); use --out LINE.npy",
            args.file.display()
        ),
        (Heights::Areal(h), false) => staged.write_npy_2d(&args.out, h)?,
        (Heights::Profile(p), false) => staged.write_npy_1d(&args.out, p)?,
    }
    if !x3p_out {
        let mut value = record(&topography);
        value["kind"] = json!(match topography.heights {
            Heights::Areal(_) => "measured surface",
            Heights::Profile(_) => "measured line",
        });
        value["importer"] = json!(format!("asperity {}", env!("CARGO_PKG_VERSION")));
        staged.write_json(&sidecar, &value)?;
    }
    staged.commit()?;
    let shape: Vec<String> = topography
        .heights
        .shape()
        .iter()
        .map(|d| d.to_string())
        .collect();
    let sizes: Vec<String> = topography.sizes.iter().map(|s| format!("{s:e}")).collect();
    eprintln!(
        "wrote {} ({} {}, channel {:?}, {} grid, sizes {} m{})",
        args.out.display(),
        topography.provenance.format,
        args.file.display(),
        topography.provenance.channel,
        shape.join("x"),
        sizes.join(" x "),
        if topography.provenance.cleaning.is_empty() {
            String::new()
        } else {
            format!("; {}", topography.provenance.cleaning.join("; "))
        }
    );
    Ok(())
}
