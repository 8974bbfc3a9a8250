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
pub fn fig6(dir: &Path, setting: Setting, force: bool) -> Result<()> {
    let quick = setting.is_quick();
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
        let slope_2d = psd_exponent(&radial_psd_2d(&surface)?, 1.0).unwrap_or(f64::NAN);
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
    Ok(())
}

use asperity::study::theory::{alpha_theory, alpha_white_noise};
use asperity::study::{parse_range, FitWindow, Method, StudySpec, TaskResult};

use super::setting::Setting;
use super::study::{execute, write_alpha, write_curves, Kind, RunOptions};

fn study_spec(
    method: Method,
    sizes: Vec<usize>,
    hursts: Vec<f64>,
    samples: usize,
    rolloff: Option<f64>,
) -> StudySpec {
    StudySpec {
        method,
        sizes,
        hursts,
        samples,
        rolloff,
        seed: 2013,
        window: FitWindow::default(),
        levels: 48,
    }
}

/// `-1 … 3 (17 values)`.
fn describe_hursts(hursts: &[f64]) -> String {
    match hursts {
        [] => "none".into(),
        [one] => format!("{one}"),
        [first, .., last] => format!("{first} … {last} ({} values)", hursts.len()),
    }
}

/// States a figure's BEM studies before they start: grids, samples and, for the settings
/// that take hours, the estimated run time measured on this machine
/// ([`super::bench::estimate_bem_seconds`]; probes at 32² and 64², a few seconds).
fn announce(figure: &str, setting: Setting, studies: &[(&StudySpec, Option<f64>)]) -> Result<()> {
    if setting == Setting::Quick {
        // Minutes: the report states the setting; stderr stays for errors.
        return Ok(());
    }
    for (spec, rolloff) in studies {
        eprintln!(
            "{figure} ({} setting): BEM on N = {:?}, {} samples per (N, H), H = {}",
            setting.name(),
            spec.sizes,
            spec.samples,
            describe_hursts(&spec.hursts)
        );
        if matches!(setting, Setting::Medium | Setting::Paper) {
            let study = super::bench::BemStudy {
                sizes: &spec.sizes,
                samples: spec.samples,
                hursts: &spec.hursts,
                rolloff: *rolloff,
            };
            let estimate = super::bench::estimate_bem_seconds(&study, (32, 64))?;
            eprintln!(
                "{figure}: estimated BEM time on this machine {:.1} h ({} lanes; checkpointed: \
                 an interrupted run resumes with the same command)",
                estimate.seconds / 3600.0,
                estimate.lanes
            );
        }
    }
    Ok(())
}

/// Runs one study of a figure in `dir/<name>/` (its own checkpoint, lock and record of
/// outputs) and returns results; `discard` is the user's --force.
fn figure_study(
    dir: &Path,
    name: &str,
    spec: &StudySpec,
    kind: Kind,
    force: bool,
) -> Result<Vec<TaskResult>> {
    let sub = dir.join(name);
    let options = RunOptions {
        force,
        quiet: false,
        checkpoint_every: asperity::study::CHECKPOINT_INTERVAL,
    };
    execute(spec, &sub, options, kind)
}

fn alpha_rows_md(results: &[TaskResult]) -> String {
    let mut md = String::from("| method | N | H | α (ensemble fit) | 95 % of samples | theory |\n|---|---|---|---|---|---|\n");
    for r in results {
        let (lo, hi) = r.alpha_sample_interval().unwrap_or((f64::NAN, f64::NAN));
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.3} | {:.3} – {:.3} | {:.3} |",
            r.method.name(),
            r.task.n,
            r.task.hurst,
            r.alpha_ensemble.map_or(f64::NAN, |f| f.exponent),
            lo,
            hi,
            alpha_theory(r.task.hurst, r.task.n)
        );
    }
    md
}

/// Paper Fig. 1: α(H) from MDR (N = 2^9, 2^11, 2^15) and BEM (N = 2^7 … 2^10).
pub fn fig1(dir: &Path, setting: Setting, force: bool, discard: bool) -> Result<()> {
    let hursts = parse_range("-1:3:0.25")?;
    // MDR is cheap (the paper's 25 500 lines take seconds): every setting keeps it.
    let (mdr_sizes, mdr_samples) = setting.fig1_mdr();
    let mdr = study_spec(Method::Mdr, mdr_sizes, hursts, mdr_samples, None);
    let plan = setting.fig1_bem()?;
    let bem = study_spec(Method::Bem, plan.sizes, plan.hursts, plan.samples, None);
    announce("fig1", setting, &[(&bem, None)])?;
    let mdr_results = figure_study(dir, "mdr", &mdr, Kind::Alpha, discard)?;
    let bem_results = figure_study(dir, "bem", &bem, Kind::Alpha, discard)?;
    let all: Vec<TaskResult> = mdr_results.iter().chain(&bem_results).cloned().collect();
    write_alpha(dir, &all, force)?;
    let report = format!(
        "# Fig. 1: exponent α of k ∝ F^α versus H\n\n{}\n\n\
         - MDR: N = {:?}, {} samples per (N, H), H = {}.\n\
         - BEM: free boundaries, N = {:?}, {} samples per (N, H), H = {}.\n\
         - α window: {}; α is fitted on the ensemble-mean k(F) (column `alpha`), and per sample\n  \
           (`alpha_low`, `alpha_high`: 2.5 % and 97.5 % of the per-sample values).\n\n\
         Files: `alpha.csv`, `alpha.png`, `alpha.svg` (both methods with the theory curves);\n\
         `mdr/` and `bem/` hold each method's table, plot and checkpoint.\n\n\
         ## The paper's values beside ours\n\
         The paper: α = 1/3 for H > 2 (Hertz), α = 1/(1+H) for 0 < H < 2 (eq. 6), and for H ≤ 0 an\n\
         N-dependent α ≈ 0.9 given by eq. (24), α = (1 + log2 N)/(3 + log2 N), derived for H = 0 and\n\
         \"valid not only for H = 0, but also for smaller values\". Column *theory* is that value\n\
         for each row (eq. 24 at H = 0, not 1/(1+0) = 1).\n\n{}\n",
        setting.describe(),
        mdr.sizes,
        mdr.samples,
        describe_hursts(&mdr.hursts),
        bem.sizes,
        bem.samples,
        describe_hursts(&bem.hursts),
        mdr.window.describe(),
        alpha_rows_md(&all)
    );
    super::report::write(dir, super::report::Results::Fig1(&all), &report, force)
}

/// Paper Fig. 2: k(F) for nominally flat surfaces with roll-off q0 L/2π = 6 (BEM).
pub fn fig2(dir: &Path, setting: Setting, force: bool, discard: bool) -> Result<()> {
    let plan = setting.fig2()?;
    let (n, samples) = (plan.sizes[0], plan.samples);
    let spec = study_spec(Method::Bem, plan.sizes, plan.hursts, samples, Some(6.0));
    announce("fig2", setting, &[(&spec, Some(6.0))])?;
    let results = figure_study(dir, "bem", &spec, Kind::Curve, discard)?;
    write_curves(dir, &results, force, "fig2")?;
    let mut md = String::from(
        "| H | low-force α (window) | steepest slope over a decade of F (paper: ≈ 1) | contact fraction there |\n\
         |---|---|---|---|\n",
    );
    for r in &results {
        let (steepest, fractions) = match super::report::steepest_slope(r, &spec.window) {
            Some((slope, first, last)) => {
                (format!("{slope:.3}"), format!("{first:.2e} – {last:.2e}"))
            }
            None => ("—".into(), "— (the curve spans less than a decade)".into()),
        };
        let low = r
            .alpha_ensemble
            .map_or("—".to_string(), |a| format!("{:.3}", a.exponent));
        let _ = writeln!(
            md,
            "| {} | {low} | {steepest} | {fractions} |",
            r.task.hurst
        );
    }
    let report = format!(
        "# Fig. 2: contact stiffness vs force with roll-off q0 L/2π = 6\n\n{}\n\n\
         BEM, free boundaries, N = {n}, {samples} samples per H, surfaces normalised to unit rms\n\
         slope. Files: `fig2.csv`, `fig2.png`, `fig2.svg`; `bem/` holds the study and checkpoint.\n\n\
         ## The paper's values beside ours\n\
         The paper (1024², 60 samples): at low force the curves follow k ∝ F^α with α ≥ 1/3;\n\
         at higher force all collapse onto an almost linear relation (slope ≈ 1).\n\n\
         Ours: the *steepest slope* is the largest log–log slope of the ensemble-mean curve\n\
         over any stretch of one decade in force, from {min_contacts} pixels in contact on, and the\n\
         contact fractions where that stretch lies, around 0.1–1 % contact: beyond a few\n\
         per cent the elastic interaction of the contact spots drives k towards the stiffness\n\
         of the whole square, 2E*L/√π ≈ 1.13 E*L, and the curves bend over. Eq. (24) says why\n\
         the slope should approach 1 only on fine grids (a roll-off surface is H = −1 below\n\
         q0; the more modes, the closer to linear, paper Fig. 5). Development runs of\n\
         `asperity study curve --method bem --rolloff 6` (3–6 samples each, so ±0.05) gave\n\
         for H = −1: 0.73 at N = 128 and 256, 0.87 at N = 512; the full setting (1024²)\n\
         measures how close to 1 the paper's grid comes.\n\n{md}\n",
        setting.describe(),
        min_contacts = spec.window.min_contacts,
    );
    super::report::write(
        dir,
        super::report::Results::Fig2(&results, spec.window),
        &report,
        force,
    )
}

/// Paper Fig. 5: α versus N for H < 0 against eq. (24).
pub fn fig5(dir: &Path, setting: Setting, force: bool, discard: bool) -> Result<()> {
    let (mdr_sizes, mdr_samples) = setting.fig5_mdr();
    let mdr = study_spec(Method::Mdr, mdr_sizes, vec![-0.5], mdr_samples, None);
    let plan = setting.fig5_bem();
    let bem = study_spec(Method::Bem, plan.sizes, plan.hursts, plan.samples, None);
    announce("fig5", setting, &[(&bem, None)])?;
    let mdr_results = figure_study(dir, "mdr", &mdr, Kind::Alpha, discard)?;
    let bem_results = figure_study(dir, "bem", &bem, Kind::Alpha, discard)?;
    let mut table = Table::new(&[
        "method",
        "n_interpretation",
        "n",
        "log2_n",
        "alpha",
        "alpha_eq24",
    ]);
    let mut md = String::from(
        "| method | N as | N | log2 N | α (ours) | eq. (24) |\n|---|---|---|---|---|---|\n",
    );
    let mut rows: Vec<(String, String, f64, f64)> = Vec::new();
    for r in &mdr_results {
        rows.push((
            "mdr".into(),
            "modes".into(),
            r.task.n as f64,
            r.alpha_ensemble.map_or(f64::NAN, |a| a.exponent),
        ));
    }
    for r in &bem_results {
        let a = r.alpha_ensemble.map_or(f64::NAN, |a| a.exponent);
        rows.push(("bem".into(), "lines".into(), r.task.n as f64, a));
        rows.push((
            "bem".into(),
            "points".into(),
            (r.task.n * r.task.n) as f64,
            a,
        ));
    }
    for (method, how, n, a) in &rows {
        table.push(&[
            method.clone(),
            how.clone(),
            format_number(*n),
            format_number(n.log2()),
            format_number(*a),
            format_number(alpha_white_noise(*n)),
        ]);
        let _ = writeln!(
            md,
            "| {method} | {how} | {n} | {:.0} | {a:.3} | {:.3} |",
            n.log2(),
            alpha_white_noise(*n)
        );
    }
    table.write(&dir.join("fig5.csv"), force)?;
    let theory: Vec<(f64, f64)> = (4..=21)
        .map(|m| (m as f64, alpha_white_noise(2f64.powi(m))))
        .collect();
    let pick = |how: &str| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.1 == how)
            .map(|r| (r.2.log2(), r.3))
            .collect()
    };
    Chart {
        title: "Fig. 5: α vs grid size for H = -0.5".into(),
        x_label: "log2 N".into(),
        y_label: "α".into(),
        log_x: false,
        log_y: false,
        series: vec![
            Series::new("eq. (24)", theory, Style::Line).color(plotters::style::RED),
            Series::new("MDR (N = modes)", pick("modes"), Style::Points)
                .color(plotters::style::BLACK),
            Series::new("BEM (N = lines per side)", pick("lines"), Style::Points)
                .color(plotters::style::GREEN),
            Series::new("BEM (N = grid points)", pick("points"), Style::Points)
                .color(plotters::style::MAGENTA),
        ],
    }
    .save(&dir.join("fig5.png"), &dir.join("fig5.svg"), force)?;
    let report = format!(
        "# Fig. 5: α versus N for H < 0\n\n{}\n\n\
         H = -0.5. MDR: N = {:?}, {} samples each. BEM: free boundaries, N = {:?}, {} samples each,\n\
         each shown twice: N as lines per side and N² as grid points (as the paper does).\n\
         α window: {}.\n\n\
         ## The paper's values beside ours\n\
         The paper: MDR follows eq. (24), α = (1 + log2 N)/(3 + log2 N), closely; BEM follows a\n\
         similar dependence.\n\n{md}\n",
        setting.describe(),
        mdr.sizes,
        mdr.samples,
        bem.sizes,
        bem.samples,
        mdr.window.describe()
    );
    let results = super::report::Results::Fig5(&mdr_results, &bem_results);
    super::report::write(dir, results, &report, force)
}
