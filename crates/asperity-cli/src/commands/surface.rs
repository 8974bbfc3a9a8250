//! `asperity surface` and `asperity line`: Fourier synthesis of rough surfaces and lines.

use std::path::PathBuf;

use anyhow::Result;
use asperity::io::{sidecar_path, StagedOutputs};
use asperity::surface::stats::{line_summary, surface_summary};
use asperity::surface::{LineGenerator, SurfaceGenerator};
use asperity_app::figure::map::{surface_chart, MapFigure};
use asperity_app::surface::{ensure_usable, grid, sidecar as generated_sidecar, SurfaceRequest};

use crate::request::refused;

/// Spectrum options shared by `surface` and `line`.
#[derive(Debug, Clone, clap::Args)]
pub struct SpectrumArgs {
    /// Hurst exponent H in [-1, 3]: C2D(q) ∝ q^(-2H-2).
    #[arg(long, allow_hyphen_values = true)]
    pub hurst: f64,
    /// Long-wavelength roll-off q0·L/2π: C2D flat below q0 (paper eq. 7).
    #[arg(long, value_name = "Q")]
    pub rolloff: Option<f64>,
    /// Long-wavelength cut-off q0·L/2π: no power below q0 (paper eq. 8).
    #[arg(long, value_name = "Q")]
    pub cutoff: Option<f64>,
    /// Side length L (units of the heights).
    #[arg(long, default_value_t = SurfaceRequest::default().size)]
    pub size: f64,
    /// Random seed (a whole number from 0 to 2^64 − 1); the same seed gives bit-identical
    /// heights whatever the thread count.
    #[arg(long, default_value_t = SurfaceRequest::default().seed)]
    pub seed: String,
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
    pub n: i128,
    /// Grid points along y (rows); defaults to N (square).
    #[arg(long)]
    pub m: Option<i128>,
    #[command(flatten)]
    pub spectrum: SpectrumArgs,
    /// Short-wavelength cut-off q1·L/2π: no power above q1.
    #[arg(long, value_name = "Q")]
    pub short_cutoff: Option<f64>,
    /// Scale to this rms height (default 1 when neither this nor --rms-slope is given).
    #[arg(long)]
    pub rms_height: Option<f64>,
    /// Scale to this rms slope (forward differences).
    #[arg(long)]
    pub rms_slope: Option<f64>,
    /// Also write a grey-scale image (black low, white high), one pixel per point.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Also write the figure of the height map (.png, .svg, or .json for the figure as
    /// data, as asperity.plot.surface draws it): axes in the surface's unit, a scale bar
    /// and a colour bar of the heights.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
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
    pub n: i128,
    #[command(flatten)]
    pub spectrum: SpectrumArgs,
    /// Scale to this rms height (default 1 when neither this nor --rms-slope is given).
    #[arg(long)]
    pub rms_height: Option<f64>,
    /// Scale to this rms slope (forward differences).
    #[arg(long)]
    pub rms_slope: Option<f64>,
}

/// The request of the arguments (`rows`: `--m` of a surface, `None` for a line).
fn request(
    n: usize,
    m: Option<usize>,
    s: &SpectrumArgs,
    short_cutoff: Option<f64>,
    (rms_height, rms_slope): (Option<f64>, Option<f64>),
) -> SurfaceRequest {
    SurfaceRequest {
        n,
        m,
        hurst: s.hurst,
        rolloff: s.rolloff,
        cutoff: s.cutoff,
        short_cutoff,
        rms_height,
        rms_slope,
        size: s.size,
        seed: s.seed.clone(),
    }
}

/// Runs `asperity surface`.
pub fn run_surface(args: &SurfaceArgs) -> Result<()> {
    let s = &args.spectrum;
    let norm = (args.rms_height, args.rms_slope);
    let (n, m) = grid(args.n, args.m)?;
    let (spec, seed) = request(n, m, s, args.short_cutoff, norm)
        .surface()
        .map_err(refused)?;
    let rows = spec.rows();
    let sidecar = sidecar_path(&s.out);
    let mut outputs = vec![s.out.as_path(), sidecar.as_path()];
    outputs.extend(args.png.as_deref());
    outputs.extend(args.plot.as_deref());
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
    if let Some(plot) = &args.plot {
        crate::plot::ImageFormat::from_path(plot, "--plot")?;
    }
    let start = std::time::Instant::now();
    let surface = SurfaceGenerator::new(&spec)?.try_generate(seed)?;
    let elapsed = start.elapsed().as_secs_f64();
    let summary = surface_summary(&surface);
    ensure_usable(&summary, s.size)?;
    staged.write_npy_2d(&s.out, surface.heights())?;
    let record = generated_sidecar("surface", &[rows, n], seed, &spec, &summary);
    staged.write_json(&sidecar, &record)?;
    if let Some(png) = &args.png {
        crate::plot::greyscale_png(&mut staged, png, surface.heights().view())?;
    }
    if let Some(plot) = &args.plot {
        let name = s
            .out
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into());
        let figure = MapFigure {
            name: &name,
            size: (s.size, s.size * rows as f64 / n as f64),
            metres: false,
        };
        let chart = surface_chart(surface.heights().view(), figure);
        crate::plot::stage_charts(&mut staged, plot, &[chart])?;
    }
    staged.commit()?;
    eprintln!(
        "wrote {} ({rows}x{n} in {elapsed:.3} s): rms height {:.6e}, rms slope {:.6e}",
        s.out.display(),
        summary.rms_height,
        summary.rms_slope
    );
    Ok(())
}

/// Runs `asperity line`.
pub fn run_line(args: &LineArgs) -> Result<()> {
    let s = &args.spectrum;
    let norm = (args.rms_height, args.rms_slope);
    let (n, _) = grid(args.n, None)?;
    let (spec, seed) = request(n, None, s, None, norm).line().map_err(refused)?;
    let sidecar = sidecar_path(&s.out);
    let mut staged = StagedOutputs::new([&s.out, &sidecar], s.force)?;
    let line = LineGenerator::new(&spec)?.try_generate(seed)?;
    let summary = line_summary(&line);
    ensure_usable(&summary, s.size)?;
    staged.write_npy_1d(&s.out, line.heights())?;
    let record = generated_sidecar("line", &[n], seed, &spec, &summary);
    staged.write_json(&sidecar, &record)?;
    staged.commit()?;
    eprintln!(
        "wrote {} ({n} points): rms height {:.6e}, rms slope {:.6e}",
        s.out.display(),
        summary.rms_height,
        summary.rms_slope
    );
    Ok(())
}
