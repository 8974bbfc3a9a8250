//! Figures of the paper that need only surfaces and lines (Fig. 6), and the shared
//! report writer of `asperity reproduce`.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use asperity::fit::power_law_fit;
use asperity::spectrum::Psd;
use asperity::surface::stats::{line_psd, radial_psd_2d, surface_summary};
use asperity::surface::{LineGenerator, LineSpec, Normalisation, SurfaceGenerator, SurfaceSpec};

use crate::output::{format_number, Table};
use crate::plot::{greyscale_panel, ordered_color, Chart, Series, Style};

/// Writes `report.md` atomically.
pub fn write_report(dir: &Path, text: &str, force: bool) -> Result<()> {
    asperity::io::write_bytes(&dir.join("report.md"), force, text.as_bytes())?;
    Ok(())
}

/// Fitted PSD exponent over bins with `q L / 2π ≥ 2`.
fn psd_exponent(bins: &[asperity::surface::stats::PsdBin], size: f64) -> Option<f64> {
    let (q, c): (Vec<f64>, Vec<f64>) = bins
        .iter()
        .filter(|b| b.q * size / std::f64::consts::TAU >= 2.0 && b.psd > 0.0)
        .map(|b| (b.q, b.psd))
        .unzip();
    power_law_fit(&q, &c).ok().map(|f| f.exponent)
}

/// Paper Fig. 6: grey-scale surfaces and their rough lines for several H, no roll-off.
pub fn fig6(dir: &Path, quick: bool, force: bool) -> Result<()> {
    let hursts = [-0.5, 0.0, 0.5, 1.0, 2.0, 3.0];
    let n = if quick { 256 } else { 512 };
    let line_n = 4 * n;
    let seed = 6;
    let mut maps = Vec::new();
    let mut line_series = Vec::new();
    let mut table = Table::new(&[
        "hurst",
        "n",
        "rms_height",
        "rms_slope",
        "psd_slope_2d",
        "psd_slope_2d_theory",
        "psd_slope_1d",
        "psd_slope_1d_theory",
    ]);
    let mut rows_md = String::new();
    for (i, &hurst) in hursts.iter().enumerate() {
        let psd = Psd::power_law(hurst)?;
        let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsHeight(1.0))?;
        let surface = SurfaceGenerator::new(&spec)?.try_generate(seed)?;
        let line_spec = LineSpec::new(line_n, 1.0, psd, Normalisation::RmsHeight(1.0))?;
        let line = LineGenerator::new(&line_spec)?.try_generate(seed)?;
        let summary = surface_summary(&surface);
        let slope_2d = psd_exponent(&radial_psd_2d(&surface), 1.0).unwrap_or(f64::NAN);
        let slope_1d = psd_exponent(&line_psd(&line), 1.0).unwrap_or(f64::NAN);
        table.push_numbers(&[
            hurst,
            n as f64,
            summary.rms_height,
            summary.rms_slope,
            slope_2d,
            -2.0 * hurst - 2.0,
            slope_1d,
            -2.0 * hurst - 1.0,
        ]);
        let _ = writeln!(
            rows_md,
            "| {hurst} | {:.3} | {:.3} | {:.3} | {:.3} |",
            slope_2d,
            -2.0 * hurst - 2.0,
            slope_1d,
            -2.0 * hurst - 1.0
        );
        maps.push((format!("H = {hurst}"), surface.into_heights()));
        // Lines stacked with an offset of 5 rms heights, as in the figure.
        let dx = 1.0 / line_n as f64;
        let offset = -5.0 * i as f64;
        let points = line
            .heights()
            .iter()
            .enumerate()
            .map(|(j, h)| (j as f64 * dx, h + offset))
            .collect();
        line_series.push(
            Series::new(format!("H = {hurst}"), points, Style::Line)
                .color(ordered_color(i as f64 / (hursts.len() - 1) as f64)),
        );
    }
    let views: Vec<(String, ndarray::ArrayView2<f64>)> =
        maps.iter().map(|(t, m)| (t.clone(), m.view())).collect();
    greyscale_panel(
        &dir.join("fig6_surfaces.png"),
        &dir.join("fig6_surfaces.svg"),
        &views,
        220,
        force,
    )?;
    Chart {
        title: "Fig. 6: rough lines (C1D = π q C2D), offset for clarity".into(),
        x_label: "x / L".into(),
        y_label: "h / h_rms (offset)".into(),
        log_x: false,
        log_y: false,
        series: line_series,
    }
    .save(
        &dir.join("fig6_lines.png"),
        &dir.join("fig6_lines.svg"),
        force,
    )?;
    table.write(&dir.join("fig6.csv"), force)?;
    let report = format!(
        "# Fig. 6: random self-affine surfaces and lines\n\n\
         Surfaces {n}x{n} and lines of {line_n} points, seed {seed}, no roll-off or cut-off,\n\
         random phases, normalised to unit rms height{}.\n\n\
         - `fig6_surfaces.png/.svg`: grey-scale height maps (black low, white high), as the paper's upper row.\n\
         - `fig6_lines.png/.svg`: the corresponding rough lines, as the paper's lower row.\n\
         - `fig6.csv`: statistics; the fitted PSD slopes (q L/2π ≥ 2) beside the theory\n  \
           C2D ∝ q^(-2H-2) (eq. 1) and C1D ∝ q^(-2H-1) (eq. 29).\n\n\
         | H | 2D slope (ours) | 2D theory | 1D slope (ours) | 1D theory |\n|---|---|---|---|---|\n{rows_md}\n\
         The paper shows the images only; there are no numbers to compare beyond the spectra.\n",
        if quick { " (--quick: 256² instead of 512²)" } else { "" }
    );
    write_report(dir, &report, force)?;
    let _ = format_number;
    Ok(())
}
