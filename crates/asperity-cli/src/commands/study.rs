//! `asperity study`: ensembles over seeds and sweeps over H and N (paper Figs. 1, 2, 5).
//!
//! Studies checkpoint into their output folder after every batch of samples; running the
//! same command again resumes (Ctrl-C loses at most one batch) and gives bit-identical
//! results. A folder that holds a different study is refused unless `--force`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::{Context, Result};
use asperity::study::theory::{alpha_pohrt_popov, alpha_white_noise, ALPHA_HERTZ};
use asperity::study::{
    parse_range, run_any_task, sample_cost, FitWindow, Method, StudyDir, StudySpec, TaskResult,
    CHECKPOINT_INTERVAL,
};
use serde::Deserialize;

use crate::output::{format_number, Table};
use crate::plot::{ordered_color, Chart, Series, Style};
use crate::progress::Progress;

/// `--method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MethodArg {
    /// 1D method of dimensionality reduction on rough lines.
    Mdr,
    /// 3D boundary elements on rough surfaces (free boundaries).
    Bem,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Mdr => Method::Mdr,
            MethodArg::Bem => Method::Bem,
        }
    }
}

/// Options shared by every study.
#[derive(Debug, Clone, clap::Args)]
pub struct CommonArgs {
    /// Solver.
    #[arg(long, value_enum)]
    pub method: MethodArg,
    /// Realisations per (N, H).
    #[arg(long)]
    pub samples: usize,
    /// Long-wavelength roll-off q0·L/2π (paper Fig. 2 uses 6).
    #[arg(long, value_name = "Q")]
    pub rolloff: Option<f64>,
    /// Study seed (every sample's seed derives from it, N, H and the sample index).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// α fit window: fewest points in contact.
    #[arg(long, default_value_t = FitWindow::default().min_contacts)]
    pub min_contacts: usize,
    /// α fit window: largest contact fraction.
    #[arg(long, default_value_t = FitWindow::default().max_fraction)]
    pub max_fraction: f64,
    /// Common force levels of the ensemble-mean curves.
    #[arg(long, default_value_t = 48)]
    pub levels: usize,
    #[command(flatten)]
    pub run: RunArgs,
}

/// Where and how a study runs (not part of what it computes).
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// Output folder (also holds the checkpoint).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite outputs and discard another study's checkpoint in the folder.
    #[arg(long)]
    pub force: bool,
    /// No progress output.
    #[arg(long)]
    pub quiet: bool,
    /// Save tasks in progress at most every this many seconds (0: after every batch).
    #[arg(long, default_value_t = CHECKPOINT_INTERVAL.as_secs_f64(), value_name = "SECONDS")]
    pub checkpoint_every: f64,
}

/// Arguments of `asperity study alpha`.
#[derive(Debug, clap::Args)]
#[command(
    allow_negative_numbers = true,
    after_help = "Examples:\n  \
    asperity study alpha --method mdr --n 512,2048 --hurst -1:3:0.25 --samples 100 --out alpha\n  \
    asperity study alpha --method bem --n 64 --hurst 0.5 --samples 20 --out alpha-bem"
)]
pub struct AlphaArgs {
    /// Grid sizes N (comma-separated).
    #[arg(long, value_delimiter = ',', required = true)]
    pub n: Vec<usize>,
    /// Hurst exponents: values and inclusive ranges A:B:STEP, comma-separated.
    #[arg(long, allow_hyphen_values = true)]
    pub hurst: String,
    #[command(flatten)]
    pub common: CommonArgs,
}

/// Arguments of `asperity study curve`.
#[derive(Debug, clap::Args)]
#[command(
    allow_negative_numbers = true,
    after_help = "Examples:\n  \
    asperity study curve --method bem --n 64 --hurst -1,0,1,3 --rolloff 6 --samples 8 --out curves\n  \
    asperity study curve --method mdr --n 4096 --hurst -1:3:1 --samples 100 --out mdr-curves"
)]
pub struct CurveArgs {
    /// Grid size N.
    #[arg(long)]
    pub n: usize,
    /// Hurst exponents: values and inclusive ranges A:B:STEP, comma-separated.
    #[arg(long, allow_hyphen_values = true)]
    pub hurst: String,
    #[command(flatten)]
    pub common: CommonArgs,
}

/// Arguments of `asperity study file`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Example study file (study.toml):\n  \
    kind = \"alpha\"          # or \"curve\"\n  \
    method = \"mdr\"\n  \
    n = [512, 2048, 32768]\n  \
    hurst = \"-1:3:0.25\"     # or a list [0.5, 0.8]\n  \
    samples = 500\n  \
    seed = 1                # optional; also rolloff, min_contacts, max_fraction, levels\n\n\
    Run: asperity study file study.toml --out sweep")]
pub struct FileArgs {
    /// A TOML study file.
    pub file: PathBuf,
    #[command(flatten)]
    pub run: RunArgs,
}

/// The study kinds.
#[derive(Debug, clap::Subcommand)]
pub enum StudyCommand {
    /// α of k ∝ F^α over a sweep of N and H → DIR/alpha.csv, alpha.png, alpha.svg.
    Alpha(AlphaArgs),
    /// Ensemble-mean k(F) curves for several H → DIR/curve.csv, curve.png, curve.svg.
    Curve(CurveArgs),
    /// Run a study described by a TOML file (for larger sweeps).
    File(FileArgs),
}

/// Arguments of `asperity study`.
#[derive(Debug, clap::Args)]
pub struct StudyArgs {
    /// Which study.
    #[command(subcommand)]
    pub command: StudyCommand,
}

/// What a study writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// α table and plot.
    Alpha,
    /// Mean curves table and plot.
    Curve,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum HurstSpec {
    Range(String),
    List(Vec<f64>),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyFile {
    kind: Kind,
    method: MethodArg,
    n: Vec<usize>,
    hurst: HurstSpec,
    samples: usize,
    rolloff: Option<f64>,
    seed: Option<u64>,
    min_contacts: Option<usize>,
    max_fraction: Option<f64>,
    levels: Option<usize>,
}

fn spec_from(common: &CommonArgs, sizes: Vec<usize>, hursts: Vec<f64>) -> StudySpec {
    StudySpec {
        method: common.method.into(),
        sizes,
        hursts,
        samples: common.samples,
        rolloff: common.rolloff,
        seed: common.seed,
        window: FitWindow {
            min_contacts: common.min_contacts,
            max_fraction: common.max_fraction,
        },
        levels: common.levels,
    }
}

/// How a study runs (not part of what it computes).
#[derive(Debug, Clone, Copy)]
pub struct RunOptions {
    /// Overwrite outputs, discard another study's checkpoint.
    pub force: bool,
    /// No progress output.
    pub quiet: bool,
    /// Longest time between checkpoints of a task in progress.
    pub checkpoint_every: Duration,
}

impl RunOptions {
    fn from_args(run: &RunArgs) -> Result<Self> {
        anyhow::ensure!(
            run.checkpoint_every.is_finite() && run.checkpoint_every >= 0.0,
            "--checkpoint-every must be a number of seconds >= 0, got {}",
            run.checkpoint_every
        );
        Ok(RunOptions {
            force: run.force,
            quiet: run.quiet,
            checkpoint_every: Duration::from_secs_f64(run.checkpoint_every),
        })
    }
}

/// Runs `asperity study`.
pub fn run(args: &StudyArgs) -> Result<()> {
    let (kind, spec, out, options) = match &args.command {
        StudyCommand::Alpha(a) => {
            let spec = spec_from(&a.common, a.n.clone(), parse_range(&a.hurst)?);
            (
                Kind::Alpha,
                spec,
                &a.common.run.out,
                RunOptions::from_args(&a.common.run)?,
            )
        }
        StudyCommand::Curve(c) => {
            let spec = spec_from(&c.common, vec![c.n], parse_range(&c.hurst)?);
            (
                Kind::Curve,
                spec,
                &c.common.run.out,
                RunOptions::from_args(&c.common.run)?,
            )
        }
        StudyCommand::File(f) => {
            let text = std::fs::read_to_string(&f.file)
                .with_context(|| format!("reading {}", f.file.display()))?;
            let file: StudyFile = toml::from_str(&text)
                .map_err(|e| anyhow::anyhow!("{}: {}", f.file.display(), e.message()))?;
            let window = FitWindow::default();
            let spec = StudySpec {
                method: file.method.into(),
                sizes: file.n,
                hursts: match file.hurst {
                    HurstSpec::Range(r) => parse_range(&r)?,
                    HurstSpec::List(l) => l,
                },
                samples: file.samples,
                rolloff: file.rolloff,
                seed: file.seed.unwrap_or(1),
                window: FitWindow {
                    min_contacts: file.min_contacts.unwrap_or(window.min_contacts),
                    max_fraction: file.max_fraction.unwrap_or(window.max_fraction),
                },
                levels: file.levels.unwrap_or(48),
            };
            (file.kind, spec, &f.run.out, RunOptions::from_args(&f.run)?)
        }
    };
    let results = execute(&spec, out, options, &outputs(kind, out))?;
    match kind {
        Kind::Alpha => write_alpha(out, &results, options.force),
        Kind::Curve => write_curves(out, &results, options.force, "curve"),
    }
}

/// The files a study of `kind` writes into `dir`.
pub fn outputs(kind: Kind, dir: &Path) -> Vec<PathBuf> {
    let stem = match kind {
        Kind::Alpha => "alpha",
        Kind::Curve => "curve",
    };
    ["csv", "png", "svg"]
        .iter()
        .map(|ext| dir.join(format!("{stem}.{ext}")))
        .collect()
}

/// Validates (the spec, then whether its largest task fits in memory), checks outputs,
/// opens (or resumes) the study folder and runs every task with a progress bar. Nothing
/// is created before every check has passed. Returns the task results in task order.
///
/// The progress bar counts samples; its ETA weighs each sample by
/// [`sample_cost`] and leaves out samples read back from checkpoints (see
/// [`crate::progress`]).
pub fn execute(
    spec: &StudySpec,
    dir: &Path,
    options: RunOptions,
    outputs: &[PathBuf],
) -> Result<Vec<TaskResult>> {
    let RunOptions {
        force,
        quiet,
        checkpoint_every,
    } = options;
    spec.validate()?;
    spec.ensure_fits()?;
    StudyDir::check(dir, spec, force)?;
    for path in outputs {
        asperity::io::ensure_new_output(path, force)?;
    }
    let store = StudyDir::open(dir, spec, force)?.with_checkpoint_interval(checkpoint_every);
    let tasks = spec.tasks();
    let segments: Vec<(u64, f64)> = tasks
        .iter()
        .map(|t| (spec.samples as u64, sample_cost(spec.method, t.n)))
        .collect();
    let progress = Progress::weighted(&format!("{} study", spec.method.name()), &segments, quiet);
    let mut results = Vec::with_capacity(tasks.len());
    for (i, task) in tasks.iter().enumerate() {
        let offset = (i * spec.samples) as u64;
        // The first report of a task is what its checkpoint held (run_task's contract).
        let first = AtomicBool::new(true);
        let result = run_any_task(spec, *task, &store, &|done, _| {
            if first.swap(false, Ordering::Relaxed) {
                progress.restore(offset + done as u64)
            } else {
                progress.set(offset + done as u64)
            }
        })
        .with_context(|| format!("{} N = {} H = {}", spec.method.name(), task.n, task.hurst))?;
        results.push(result);
    }
    progress.finish();
    Ok(results)
}

fn opt(v: Option<f64>) -> String {
    v.map(format_number).unwrap_or_default()
}

/// `alpha.csv` (contract columns first, then extras) and the α(H) plot with theory curves.
pub fn write_alpha(dir: &Path, results: &[TaskResult], force: bool) -> Result<()> {
    let mut table = Table::new(&[
        "method",
        "n",
        "hurst",
        "alpha",
        "alpha_low",
        "alpha_high",
        "samples",
        "alpha_fit_low",
        "alpha_fit_high",
        "alpha_sample_mean",
        "samples_fitted",
        "alpha_theory",
    ]);
    for r in results {
        let (lo, hi) = r.alpha_sample_interval().unzip();
        table.push(&[
            r.method.name().to_string(),
            r.task.n.to_string(),
            format_number(r.task.hurst),
            opt(r.alpha_ensemble.map(|f| f.exponent)),
            opt(lo),
            opt(hi),
            r.samples.to_string(),
            opt(r.alpha_ensemble.map(|f| f.low)),
            opt(r.alpha_ensemble.map(|f| f.high)),
            opt(r.alpha_sample_mean()),
            r.alpha_samples.len().to_string(),
            format_number(asperity::study::theory::alpha_theory(
                r.task.hurst,
                r.task.n,
            )),
        ]);
    }
    table.write(&dir.join("alpha.csv"), force)?;
    alpha_chart(results, "α of k ∝ F^α vs H").save(
        &dir.join("alpha.png"),
        &dir.join("alpha.svg"),
        force,
    )
}

/// The α(H) chart: one series per (method, N) and the theory curves (6), 1/3 and (24).
pub fn alpha_chart(results: &[TaskResult], title: &str) -> Chart {
    let mut series = Vec::new();
    let mut sizes: Vec<(Method, usize)> = results.iter().map(|r| (r.method, r.task.n)).collect();
    sizes.dedup();
    for (k, &(method, n)) in sizes.iter().enumerate() {
        let points = results
            .iter()
            .filter(|r| r.method == method && r.task.n == n)
            .filter_map(|r| r.alpha_ensemble.map(|f| (r.task.hurst, f.exponent)))
            .collect();
        let t = if sizes.len() > 1 {
            k as f64 / (sizes.len() - 1) as f64
        } else {
            0.5
        };
        series.push(
            Series::new(
                format!("{} N = {n}", method.name()),
                points,
                Style::LinePoints,
            )
            .color(ordered_color(t * 0.85)),
        );
    }
    // (6) on (0, 2]: H = 0 itself belongs to (24), drawn below on [-1, 0].
    let pp: Vec<(f64, f64)> = (1..=40)
        .map(|i| 0.05 * i as f64)
        .map(|h| (h, alpha_pohrt_popov(h)))
        .collect();
    series.push(Series::new("1/(1+H) (6)", pp, Style::Dashed).color(plotters::style::BLACK));
    series.push(
        Series::new(
            "1/3 (Hertz)",
            vec![(2.0, ALPHA_HERTZ), (3.0, ALPHA_HERTZ)],
            Style::Dashed,
        )
        .color(plotters::style::RED),
    );
    for (k, &(_, n)) in sizes.iter().enumerate() {
        let a = alpha_white_noise(n as f64);
        let label = if k == 0 {
            "(1+log2 N)/(3+log2 N) (24)"
        } else {
            ""
        };
        series.push(
            Series::new(label, vec![(-1.0, a), (0.0, a)], Style::Dashed)
                .color(plotters::style::BLUE),
        );
    }
    Chart {
        title: title.into(),
        x_label: "Hurst exponent H".into(),
        y_label: "α".into(),
        log_x: false,
        log_y: false,
        series,
    }
}

/// `<stem>.csv` with the ensemble-mean curves and a log–log plot of k(F).
pub fn write_curves(dir: &Path, results: &[TaskResult], force: bool, stem: &str) -> Result<()> {
    let mut table = Table::new(&[
        "method",
        "n",
        "hurst",
        "force",
        "stiffness",
        "stiffness_low",
        "stiffness_high",
        "samples",
        "area_fraction",
    ]);
    for r in results {
        for p in &r.mean_curve {
            table.push(&[
                r.method.name().to_string(),
                r.task.n.to_string(),
                format_number(r.task.hurst),
                format_number(p.force),
                format_number(p.stiffness),
                format_number(p.stiffness_low),
                format_number(p.stiffness_high),
                p.samples.to_string(),
                format_number(p.fraction),
            ]);
        }
    }
    table.write(&dir.join(format!("{stem}.csv")), force)?;
    curve_chart(results, "Contact stiffness vs force (ensemble mean)").save(
        &dir.join(format!("{stem}.png")),
        &dir.join(format!("{stem}.svg")),
        force,
    )
}

/// Log–log k(F), one series per task, coloured by H.
pub fn curve_chart(results: &[TaskResult], title: &str) -> Chart {
    let (hmin, hmax) = results
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
            (a.min(r.task.hurst), b.max(r.task.hurst))
        });
    let series = results
        .iter()
        .map(|r| {
            let t = if hmax > hmin {
                (r.task.hurst - hmin) / (hmax - hmin)
            } else {
                0.5
            };
            let points = r
                .mean_curve
                .iter()
                .map(|p| (p.force, p.stiffness))
                .collect();
            Series::new(
                format!("{} N = {} H = {}", r.method.name(), r.task.n, r.task.hurst),
                points,
                Style::Line,
            )
            .color(ordered_color(t * 0.9))
        })
        .collect();
    Chart {
        title: title.into(),
        x_label: "normal force F (E* = 1, unit rms)".into(),
        y_label: "contact stiffness k".into(),
        log_x: true,
        log_y: true,
        series,
    }
}
