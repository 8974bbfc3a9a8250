//! `asperity surface` and `asperity line`: Fourier synthesis of rough surfaces and lines.

use std::path::PathBuf;

use anyhow::Result;
use asperity::io::{sidecar_path, StagedOutputs};
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::stats::{line_summary, surface_summary};
use asperity::surface::{LineGenerator, LineSpec, Normalisation, SurfaceGenerator, SurfaceSpec};
use serde_json::json;

/// Spectrum options shared by `surface` and `line`.
#[derive(Debug, Clone, clap::Args)]
pub struct SpectrumArgs {
    /// Hurst exponent H in [-1, 3]: C2D(q) ∝ q^(-2H-2).
    #[arg(long, allow_hyphen_values = true)]
    pub hurst: f64,
    /// Long-wavelength roll-off q0·L/2π: C2D flat below q0 (paper eq. 7).
    #[arg(long, value_name = "Q", conflicts_with = "cutoff")]
    pub rolloff: Option<f64>,
    /// Long-wavelength cut-off q0·L/2π: no power below q0 (paper eq. 8).
    #[arg(long, value_name = "Q")]
    pub cutoff: Option<f64>,
    /// Side length L (units of the heights).
    #[arg(long, default_value_t = 1.0)]
    pub size: f64,
    /// Random seed; the same seed gives bit-identical heights whatever the thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output file (.npy, float64); a JSON sidecar FILE.npy.json records every parameter.
    #[arg(long, value_parser = array_path)]
    pub out: PathBuf,
    /// Overwrite existing outputs.
    #[arg(long)]
    pub force: bool,
}

/// `--out`: a path whose name does not promise an image (NumPy data written into
/// `x.png` reads as a broken picture); the image of a surface is `--png`.
fn array_path(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some(e @ ("png" | "svg" | "jpg" | "jpeg" | "tif" | "tiff" | "bmp" | "gif")) => {
            Err(format!(
                "--out writes NumPy data (.npy), not a .{e} image; for the image of a surface \
             give --png FILE.png beside --out FILE.npy"
            ))
        }
        _ => Ok(path),
    }
}

impl SpectrumArgs {
    fn long_wavelength(&self) -> LongWavelength {
        match (self.rolloff, self.cutoff) {
            (Some(q0), _) => LongWavelength::RollOff { q0 },
            (None, Some(q0)) => LongWavelength::CutOff { q0 },
            (None, None) => LongWavelength::None,
        }
    }
}

/// Arguments of `asperity surface`.
#[derive(Debug, clap::Args)]
#[command(
    allow_negative_numbers = true,
    after_help = "Examples:\n  \
    asperity surface --n 512 --hurst 0.8 --rolloff 6 --rms-slope 1 --seed 1 --out s.npy --png s.png\n  \
    asperity surface --n 256 --m 128 --hurst -0.5 --rms-height 1e-3 --out rect.npy"
)]
pub struct SurfaceArgs {
    /// Grid points along x (columns).
    #[arg(long)]
    pub n: usize,
    /// Grid points along y (rows); defaults to N (square).
    #[arg(long)]
    pub m: Option<usize>,
    #[command(flatten)]
    pub spectrum: SpectrumArgs,
    /// Short-wavelength cut-off q1·L/2π: no power above q1.
    #[arg(long, value_name = "Q")]
    pub short_cutoff: Option<f64>,
    /// Scale to this rms height (default 1 when neither this nor --rms-slope is given).
    #[arg(long, conflicts_with = "rms_slope")]
    pub rms_height: Option<f64>,
    /// Scale to this rms slope (forward differences).
    #[arg(long)]
    pub rms_slope: Option<f64>,
    /// Also write a grey-scale image (black low, white high).
    #[arg(long)]
    pub png: Option<PathBuf>,
}

/// Arguments of `asperity line`.
#[derive(Debug, clap::Args)]
#[command(
    allow_negative_numbers = true,
    after_help = "Example:\n  asperity line --n 32768 --hurst 0.5 --seed 3 --out line.npy"
)]
pub struct LineArgs {
    /// Number of points.
    #[arg(long)]
    pub n: usize,
    #[command(flatten)]
    pub spectrum: SpectrumArgs,
    /// Scale to this rms height (default 1 when neither this nor --rms-slope is given).
    #[arg(long, conflicts_with = "rms_slope")]
    pub rms_height: Option<f64>,
    /// Scale to this rms slope (forward differences).
    #[arg(long)]
    pub rms_slope: Option<f64>,
}

fn normalisation(rms_height: Option<f64>, rms_slope: Option<f64>) -> Normalisation {
    match (rms_height, rms_slope) {
        (_, Some(s)) => Normalisation::RmsSlope(s),
        (Some(h), None) => Normalisation::RmsHeight(h),
        (None, None) => Normalisation::default(),
    }
}

/// Refuses a generated profile that float64 cannot represent: heights that underflow to
/// zero (a tiny --rms-height) or slopes that overflow (a tiny --size), naming the inputs.
fn ensure_usable(rms_height: f64, rms_slope: f64, s: &SpectrumArgs) -> Result<()> {
    let short = asperity::input::short_number;
    if !(rms_height.is_finite() && rms_height > 0.0) {
        anyhow::bail!(
            "the generated heights are not representable (rms height {}): --rms-height or \
             --rms-slope with --size {} is beyond the range of float64",
            short(rms_height),
            short(s.size)
        );
    }
    if !(rms_slope.is_finite() && rms_slope > 0.0) {
        anyhow::bail!(
            "the generated slopes are not representable (rms slope {}): --size {} is too \
             small for float64 slopes",
            short(rms_slope),
            short(s.size)
        );
    }
    Ok(())
}

/// Runs `asperity surface`.
pub fn run_surface(args: &SurfaceArgs) -> Result<()> {
    let s = &args.spectrum;
    let psd = Psd::new(s.hurst, s.long_wavelength(), args.short_cutoff)?;
    let rows = args.m.unwrap_or(args.n);
    let spec = SurfaceSpec::new(
        rows,
        args.n,
        s.size,
        psd,
        normalisation(args.rms_height, args.rms_slope),
    )?;
    let sidecar = sidecar_path(&s.out);
    let mut outputs = vec![s.out.as_path(), sidecar.as_path()];
    outputs.extend(args.png.as_deref());
    // All outputs are checked now and written all-or-nothing after the work.
    let mut staged = StagedOutputs::new(&outputs, s.force)?;
    if let Some(png) = &args.png {
        let is_png = png
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !is_png {
            anyhow::bail!("--png {}: the file name must end in .png", png.display());
        }
    }
    let start = std::time::Instant::now();
    let surface = SurfaceGenerator::new(&spec)?.try_generate(s.seed)?;
    let elapsed = start.elapsed().as_secs_f64();
    let summary = surface_summary(&surface);
    ensure_usable(summary.rms_height, summary.rms_slope, s)?;
    staged.write_npy_2d(&s.out, surface.heights())?;
    staged.write_json(
        &sidecar,
        &json!({
            "kind": "surface",
            "generator": format!("asperity {}", env!("CARGO_PKG_VERSION")),
            "shape": [rows, args.n],
            "seed": s.seed,
            "spec": spec,
            "stats": summary,
        }),
    )?;
    if let Some(png) = &args.png {
        crate::plot::greyscale_png(&mut staged, png, surface.heights().view())?;
    }
    staged.commit()?;
    eprintln!(
        "wrote {} ({rows}x{} in {elapsed:.3} s): rms height {:.6e}, rms slope {:.6e}",
        s.out.display(),
        args.n,
        summary.rms_height,
        summary.rms_slope
    );
    Ok(())
}

/// Runs `asperity line`.
pub fn run_line(args: &LineArgs) -> Result<()> {
    let s = &args.spectrum;
    let psd = Psd::new(s.hurst, s.long_wavelength(), None)?;
    let spec = LineSpec::new(
        args.n,
        s.size,
        psd,
        normalisation(args.rms_height, args.rms_slope),
    )?;
    let sidecar = sidecar_path(&s.out);
    let mut staged = StagedOutputs::new([&s.out, &sidecar], s.force)?;
    let line = LineGenerator::new(&spec)?.try_generate(s.seed)?;
    let summary = line_summary(&line);
    ensure_usable(summary.rms_height, summary.rms_slope, s)?;
    staged.write_npy_1d(&s.out, line.heights())?;
    staged.write_json(
        &sidecar,
        &json!({
            "kind": "line",
            "generator": format!("asperity {}", env!("CARGO_PKG_VERSION")),
            "shape": [args.n],
            "seed": s.seed,
            "spec": spec,
            "stats": summary,
        }),
    )?;
    staged.commit()?;
    eprintln!(
        "wrote {} ({} points): rms height {:.6e}, rms slope {:.6e}",
        s.out.display(),
        args.n,
        summary.rms_height,
        summary.rms_slope
    );
    Ok(())
}
