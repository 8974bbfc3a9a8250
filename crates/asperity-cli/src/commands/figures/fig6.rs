//! Paper Fig. 6: random self-affine surfaces (grey-scale maps) and rough lines for several
//! Hurst exponents, no roll-off, with the fitted PSD slopes beside the theory C2D ∝ q^(-2H-2)
//! (eq. 1) and C1D ∝ q^(-2H-1) (eq. 29).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use asperity::fit::power_law_fit;
use asperity::spectrum::Psd;
use asperity::surface::stats::{line_psd, radial_psd_2d, surface_summary, PsdBin};
use asperity::surface::{LineGenerator, LineSpec, Normalisation, SurfaceGenerator, SurfaceSpec};
use ndarray::Array2;

use super::super::setting::Setting;
use super::write_report;
use crate::output::Table;
use crate::plot::{greyscale_panel, ordered_color, Chart, ChartFiles, Series, Style};

/// What Fig. 6 draws: the H values, the surface grid and the line length, one seed.
struct Plan {
    hursts: [f64; 6],
    n: usize,
    line_n: usize,
    seed: u64,
    quick: bool,
    setting: Setting,
}

impl Plan {
    fn new(setting: Setting) -> Self {
        let quick = setting.is_quick();
        let n = if quick { 256 } else { 512 };
        Plan {
            hursts: [-0.5, 0.0, 0.5, 1.0, 2.0, 3.0],
            n,
            line_n: 4 * n,
            seed: 6,
            quick,
            setting,
        }
    }
}

/// One H: the statistics row, the surface and the line.
struct Row {
    hurst: f64,
    rms_height: f64,
    rms_slope: f64,
    /// Fitted exponent of the radial 2D PSD (NaN where the fit fails).
    slope_2d: f64,
    /// Fitted exponent of the line's PSD.
    slope_1d: f64,
    surface: Array2<f64>,
    line: Vec<f64>,
}

impl Row {
    fn theory_2d(&self) -> f64 {
        -2.0 * self.hurst - 2.0
    }

    fn theory_1d(&self) -> f64 {
        -2.0 * self.hurst - 1.0
    }
}

/// Fitted PSD exponent over bins with `q L / 2π ≥ 2`.
fn psd_exponent(bins: &[PsdBin], size: f64) -> Option<f64> {
    let (q, c): (Vec<f64>, Vec<f64>) = bins
        .iter()
        .filter(|b| b.q * size / std::f64::consts::TAU >= 2.0 && b.psd > 0.0)
        .map(|b| (b.q, b.psd))
        .unzip();
    power_law_fit(&q, &c).ok().map(|f| f.exponent)
}

fn compute(plan: &Plan, hurst: f64) -> Result<Row> {
    let psd = Psd::power_law(hurst)?;
    let spec = SurfaceSpec::new(plan.n, plan.n, 1.0, psd, Normalisation::RmsHeight(1.0))?;
    let surface = SurfaceGenerator::new(&spec)?.try_generate(plan.seed)?;
    let line_spec = LineSpec::new(plan.line_n, 1.0, psd, Normalisation::RmsHeight(1.0))?;
    let line = LineGenerator::new(&line_spec)?.try_generate(plan.seed)?;
    let summary = surface_summary(&surface);
    Ok(Row {
        hurst,
        rms_height: summary.rms_height,
        rms_slope: summary.rms_slope,
        slope_2d: psd_exponent(&radial_psd_2d(&surface)?, 1.0).unwrap_or(f64::NAN),
        slope_1d: psd_exponent(&line_psd(&line), 1.0).unwrap_or(f64::NAN),
        surface: surface.into_heights(),
        line: line.heights().to_vec(),
    })
}

/// Paper Fig. 6: grey-scale surfaces and their rough lines for several H, no roll-off.
pub fn fig6(dir: &Path, setting: Setting, force: bool) -> Result<()> {
    let plan = Plan::new(setting);
    let rows = plan
        .hursts
        .iter()
        .map(|&hurst| compute(&plan, hurst))
        .collect::<Result<Vec<_>>>()?;
    write_images(dir, &plan, &rows, force)?;
    write_table(dir, &plan, &rows, force)?;
    Ok(write_report(dir, &report(&plan, &rows), force)?)
}

fn write_images(dir: &Path, plan: &Plan, rows: &[Row], force: bool) -> Result<()> {
    let views: Vec<(String, ndarray::ArrayView2<f64>)> = rows
        .iter()
        .enumerate()
        .map(|(i, r)| {
            // The last caption also names the setting: the figure says how it was made.
            let mark = if i + 1 == rows.len() {
                format!(" ({} setting)", plan.setting.name())
            } else {
                String::new()
            };
            (format!("H = {}{mark}", r.hurst), r.surface.view())
        })
        .collect();
    greyscale_panel(
        &dir.join("fig6_surfaces.png"),
        &dir.join("fig6_surfaces.svg"),
        &views,
        220,
        force,
    )?;
    // Lines stacked with an offset of 5 rms heights, as in the figure.
    let dx = 1.0 / plan.line_n as f64;
    let last = (rows.len() - 1) as f64;
    let series = rows
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let offset = -5.0 * i as f64;
            let points = r
                .line
                .iter()
                .enumerate()
                .map(|(j, h)| (j as f64 * dx, h + offset))
                .collect();
            // Named at their right end: a legend would cover the stacked lines.
            Series::new("", points, Style::Line)
                .color(ordered_color(0.85 * i as f64 / last))
                .tag(format!("H = {}", r.hurst))
        })
        .collect();
    Chart {
        title: format!(
            "Fig. 6: rough lines (C1D = π q C2D), offset for clarity ({} setting)",
            plan.setting.name()
        ),
        x_label: "x / L".into(),
        y_label: "h / h_rms (offset)".into(),
        log_x: false,
        log_y: false,
        series,
    }
    .save(
        &dir.join("fig6_lines.png"),
        &dir.join("fig6_lines.svg"),
        force,
    )
}

fn write_table(dir: &Path, plan: &Plan, rows: &[Row], force: bool) -> Result<()> {
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
    for r in rows {
        table.push_numbers(&[
            r.hurst,
            plan.n as f64,
            r.rms_height,
            r.rms_slope,
            r.slope_2d,
            r.theory_2d(),
            r.slope_1d,
            r.theory_1d(),
        ]);
    }
    table.write(&dir.join("fig6.csv"), force)
}

fn report(plan: &Plan, rows: &[Row]) -> String {
    let mut rows_md = String::new();
    for r in rows {
        let _ = writeln!(
            rows_md,
            "| {} | {:.3} | {:.3} | {:.3} | {:.3} |",
            r.hurst,
            r.slope_2d,
            r.theory_2d(),
            r.slope_1d,
            r.theory_1d()
        );
    }
    let (n, line_n, seed) = (plan.n, plan.line_n, plan.seed);
    format!(
        "# Fig. 6: random self-affine surfaces and lines\n\n\
         Surfaces {n}x{n} and lines of {line_n} points, seed {seed}, no roll-off or cut-off,\n\
         random phases, normalised to unit rms height{}.\n\n\
         - `fig6_surfaces.png/.svg`: grey-scale height maps (black low, white high), as the paper's upper row.\n\
         - `fig6_lines.png/.svg`: the corresponding rough lines, as the paper's lower row.\n\
         - `fig6.csv`: statistics; the fitted PSD slopes (q L/2π ≥ 2) beside the theory\n  \
           C2D ∝ q^(-2H-2) (eq. 1) and C1D ∝ q^(-2H-1) (eq. 29).\n\n\
         | H | 2D slope (ours) | 2D theory | 1D slope (ours) | 1D theory |\n|---|---|---|---|---|\n{rows_md}\n\
         The paper shows the images only; there are no numbers to compare beyond the spectra.\n",
        if plan.quick {
            " (--quick: 256² instead of 512²)"
        } else {
            ""
        }
    )
}
