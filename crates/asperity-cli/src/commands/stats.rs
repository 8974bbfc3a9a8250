//! `asperity stats FILE.npy`: statistics of a surface (2D) or line (1D).

use std::path::PathBuf;

use anyhow::{Context, Result};
use asperity::fit::power_law_fit;
use asperity::io::{read_npy, sidecar_path, StagedOutputs};
use asperity::surface::stats::{
    line_psd, line_summary, radial_psd_2d, surface_summary, PsdBin, Summary,
};
use asperity::surface::{Line, Surface};
use ndarray::{Ix1, Ix2};

use crate::output::{format_number, Table};

/// Arguments of `asperity stats`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Examples:\n  asperity stats s.npy\n  asperity stats s.npy --psd psd.csv --fit-from 6"
)]
pub struct StatsArgs {
    /// A surface (2D) or line (1D) `.npy` file, float64.
    pub file: PathBuf,
    /// Side length L; defaults to the sidecar's, else 1.
    #[arg(long)]
    pub size: Option<f64>,
    /// Write the (radially averaged) PSD as CSV with columns q,psd.
    #[arg(long, value_name = "OUT.csv")]
    pub psd: Option<PathBuf>,
    /// Fit the PSD slope from this q·L/2π (default 2, or the sidecar's roll-off/cut-off if higher).
    #[arg(long, value_name = "Q")]
    pub fit_from: Option<f64>,
    /// Fit the PSD slope up to this q·L/2π (default: Nyquist).
    #[arg(long, value_name = "Q")]
    pub fit_to: Option<f64>,
    /// Print the statistics as JSON.
    #[arg(long)]
    pub json: bool,
    /// Overwrite an existing PSD file.
    #[arg(long)]
    pub force: bool,
}

/// Size and the long-wavelength limit recorded in a sidecar, if there is one.
fn sidecar_hints(file: &std::path::Path) -> (Option<f64>, Option<f64>) {
    let Ok(text) = std::fs::read_to_string(sidecar_path(file)) else {
        return (None, None);
    };
    let Ok(value) = serde_json::from_str::<serde_json::Value>(&text) else {
        return (None, None);
    };
    let spec = &value["spec"];
    (
        spec["size"].as_f64(),
        spec["psd"]["long_wavelength"]["q0"].as_f64(),
    )
}

/// Runs `asperity stats`.
pub fn run(args: &StatsArgs) -> Result<()> {
    // The PSD output is checked before the (possibly large) input is read.
    let mut staged = match &args.psd {
        Some(psd) => {
            let staged = StagedOutputs::new([psd], args.force)?;
            staged.ensure_not_input(&args.file)?;
            Some(staged)
        }
        None => None,
    };
    let (sidecar_size, sidecar_q0) = sidecar_hints(&args.file);
    let size = args.size.or(sidecar_size).unwrap_or(1.0);
    let array = read_npy(&args.file)?;
    let (summary, bins, dims, psd_offset): (Summary, Vec<PsdBin>, Vec<usize>, f64) =
        match array.ndim() {
            1 => {
                let line = Line::new(array.into_dimensionality::<Ix1>()?, size)?;
                (line_summary(&line), line_psd(&line), vec![line.len()], 1.0)
            }
            2 => {
                let surface = Surface::new(array.into_dimensionality::<Ix2>()?, size)?;
                let (r, c) = surface.dim();
                (
                    surface_summary(&surface),
                    radial_psd_2d(&surface),
                    vec![r, c],
                    2.0,
                )
            }
            d => anyhow::bail!(
                "{}: expected a 1D line or 2D surface, found {d} dimensions",
                args.file.display()
            ),
        };
    let kappa = |q: f64| q * size / std::f64::consts::TAU;
    let from = args
        .fit_from
        .unwrap_or_else(|| sidecar_q0.unwrap_or(0.0).max(2.0));
    let to = args.fit_to.unwrap_or(f64::INFINITY);
    let (q, c): (Vec<f64>, Vec<f64>) = bins
        .iter()
        .filter(|b| (from..=to).contains(&kappa(b.q)) && b.psd > 0.0)
        .map(|b| (b.q, b.psd))
        .unzip();
    let fit = power_law_fit(&q, &c).ok();
    if let (Some(path), Some(mut staged)) = (&args.psd, staged.take()) {
        let mut table = Table::new(&["q", "psd"]);
        for b in &bins {
            table.push_numbers(&[b.q, b.psd]);
        }
        table
            .stage(&mut staged, path)
            .and_then(|()| Ok(staged.commit()?))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    // C2D ∝ q^(-2H-2), C1D ∝ q^(-2H-1): H = -(slope + offset)/2.
    let hurst = fit.map(|f| -(f.exponent + psd_offset) / 2.0);
    if args.json {
        let value = serde_json::json!({
            "file": args.file, "shape": dims, "size": size, "stats": summary,
            "psd_slope": fit.map(|f| f.exponent), "psd_slope_low": fit.map(|f| f.low),
            "psd_slope_high": fit.map(|f| f.high), "fit_from": from, "fit_to": to, "hurst_estimate": hurst,
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    let shape: Vec<String> = dims.iter().map(|d| d.to_string()).collect();
    println!(
        "file: {} ({}, size {size})",
        args.file.display(),
        shape.join(" x ")
    );
    println!("rms_height: {}", format_number(summary.rms_height));
    println!("rms_slope: {}", format_number(summary.rms_slope));
    match summary.rms_curvature {
        Some(c) => println!("rms_curvature: {}", format_number(c)),
        None => println!("rms_curvature: n/a (grid too small)"),
    }
    match fit {
        Some(f) => {
            println!(
                "psd_slope: {:.4} (95% interval {:.4} .. {:.4}; fit over q·L/2π in [{from}, {}], {} bins)",
                f.exponent,
                f.low,
                f.high,
                if to.is_finite() { to.to_string() } else { "Nyquist".into() },
                f.points
            );
            println!("hurst_estimate: {:.4}", hurst.unwrap_or(f64::NAN));
        }
        None => println!("psd_slope: n/a (fewer than 2 bins with power in the fit range)"),
    }
    Ok(())
}
