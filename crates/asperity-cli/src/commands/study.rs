//! `asperity study`: ensembles over seeds and sweeps over H and N (paper Figs. 1, 2, 5).
//!
//! Studies checkpoint into their output folder after every batch of samples; running the
//! same command again resumes (Ctrl-C loses at most one batch) and gives bit-identical
//! results. A folder that holds a different study is refused unless `--force`. Running a study
//! and writing its tables and plots is shared with `reproduce` ([`crate::studies`]).

use std::path::{Path, PathBuf};

use anyhow::Result;
use asperity::study::{Method, StudySpec, CHECKPOINT_INTERVAL};

use crate::studies::{execute, Kind, RunOptions};
use asperity_app::derived::Derived;
use asperity_app::figure::study as figure;
use asperity_app::range::parse_range;
use asperity_app::study::report::compare_study;
use asperity_app::study::request::StudyRequest;

use crate::request::refused;

/// Options shared by every study.
#[derive(Debug, Clone, clap::Args)]
pub struct CommonArgs {
    /// Solver: mdr (1D method of dimensionality reduction on rough lines) or bem (3D
    /// boundary elements on rough surfaces, free boundaries).
    #[arg(long, value_name = "mdr|bem")]
    pub method: String,
    /// Realisations per (N, H).
    #[arg(long)]
    pub samples: i128,
    /// Long-wavelength roll-off q0·L/2π (paper Fig. 2 uses 6).
    #[arg(long, value_name = "Q")]
    pub rolloff: Option<f64>,
    /// Study seed (every sample's seed derives from it, N, H and the sample index).
    #[arg(long, default_value_t = StudySpec::default().seed.to_string())]
    pub seed: String,
    /// α fit window: fewest points in contact.
    #[arg(long, default_value_t = StudySpec::default().window.min_contacts as i128)]
    pub min_contacts: i128,
    /// α fit window: largest contact fraction.
    #[arg(long, default_value_t = StudySpec::default().window.max_fraction)]
    pub max_fraction: f64,
    /// Common force levels of the ensemble-mean curves.
    #[arg(long, default_value_t = StudySpec::default().levels as i128)]
    pub levels: i128,
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
    /// Save tasks in progress at most every this many seconds (0: after every batch of
    /// samples: 4 per thread, 1 per thread for BEM from 256² on, so that a kill there loses
    /// at most about one sample's time).
    #[arg(long, default_value_t = CHECKPOINT_INTERVAL.as_secs_f64(), value_name = "SECONDS")]
    pub checkpoint_every: f64,
}

/// What `--help` of `study alpha` and `study curve` says about H values and scales (a macro,
/// so that `concat!` can join it into the help texts).
macro_rules! scales_help {
    () => {
        "\
Hurst exponents: comma-separated values and inclusive ranges A:B:STEP, e.g. -1:3:0.25 or
-1:0:0.5,0.8,2:3:1. Each N may be given once, and H values must be at least 1e-6 apart
(checkpoints are named by H to 6 decimals).

Scales (also in DIR/study.json, \"normalisation\"): MDR lines have unit rms height, L = 1,
E* = 1 and linear springs at spacing dx = L/N; BEM surfaces have unit rms slope, L = 1,
E* = 1 and free boundaries. Forces and stiffnesses of the two methods are therefore on
different scales; compare exponents, not values.

The folder also holds the checkpoint: run the same command again to resume (no --force
needed; it rewrites only outputs it wrote that nobody edited since). While a study runs, its
folder is locked: a second process on it is refused, naming the holder's PID."
    };
}

/// Arguments of `asperity study alpha`.
#[derive(Debug, clap::Args)]
#[command(
    allow_negative_numbers = true,
    after_help = concat!("\
Output: DIR/alpha.csv, one row per (N, H): method, n, hurst, alpha, alpha_low, alpha_high,
samples, then alpha_fit_low, alpha_fit_high, alpha_sample_mean, samples_fitted,
alpha_theory; and the plot DIR/alpha.png, DIR/alpha.svg.
  alpha                        alpha fitted on the ensemble-mean curve k(F)
  alpha_fit_low/alpha_fit_high 95 % interval of that fit
  alpha_low/alpha_high         2.5 % and 97.5 % quantiles of the per-sample alpha: the
                               spread over samples, not an interval of the mean

", scales_help!(), "

Examples:
  asperity study alpha --method mdr --n 512,2048 --hurst -1:3:0.25 --samples 100 --out alpha
  asperity study alpha --method bem --n 64 --hurst 0.5 --samples 20 --out alpha-bem")
)]
pub struct AlphaArgs {
    /// Grid sizes N (comma-separated).
    #[arg(long, value_delimiter = ',', required = true)]
    pub n: Vec<i128>,
    /// Hurst exponents: values and inclusive ranges A:B:STEP, comma-separated.
    #[arg(long, allow_hyphen_values = true)]
    pub hurst: String,
    /// BEM: solve every load up to p̄ = 0.2 E* (by default a sample stops loading past
    /// 4 times the largest contact fraction an α window of the study or of `study windows`
    /// ends at; the loads above enter no fit, and the fits are the same).
    #[arg(long)]
    pub full_sweep: bool,
    #[command(flatten)]
    pub common: CommonArgs,
}

/// Arguments of `asperity study curve`.
#[derive(Debug, clap::Args)]
#[command(
    allow_negative_numbers = true,
    after_help = concat!("\
Output: DIR/curve.csv, one row per (N, H, force level): method, n, hurst, force, stiffness,
stiffness_low, stiffness_high, samples, area_fraction; and the plot DIR/curve.png,
DIR/curve.svg (log-log, band: the interval; dashed: slope 1).
  stiffness                     mean stiffness over samples at that force
  stiffness_low/stiffness_high  95 % confidence interval of that mean (Student t over the
                                samples), unlike alpha_low/alpha_high of study alpha, which
                                are the 2.5-97.5 % spread over samples
  area_fraction                 mean contact fraction at that force
BEM with --poisson NU adds tangential_ratio, tangential_ratio_low, tangential_ratio_high
(mean (k_x + k_y)/(2k) with its 95 % interval) and DIR/tangential.png, .svg (k_t/k_n over
Mindlin's ratio, and C(F) with --resistivity or --thermal-conductivity, which add
electrical_conductance or thermal_conductance with _low and _high; docs/tangential.md).

", scales_help!(), "

Examples:
  asperity study curve --method bem --n 64 --hurst -1,0,1,3 --rolloff 6 --samples 8 --out curves
  asperity study curve --method bem --n 128 --hurst 0,0.8 --rolloff 4 --samples 10 --poisson 0.3 --resistivity 1,1 --out tangential
  asperity study curve --method mdr --n 4096 --hurst -1:3:1 --samples 100 --out mdr-curves")
)]
pub struct CurveArgs {
    /// Grid sizes N (comma-separated), one curve per (N, H).
    #[arg(long, value_delimiter = ',', required = true)]
    pub n: Vec<i128>,
    /// Hurst exponents: values and inclusive ranges A:B:STEP, comma-separated.
    #[arg(long, allow_hyphen_values = true)]
    pub hurst: String,
    /// BEM: Poisson's ratio ν in [0, 0.5] of the tangential (no-slip) stiffness computed at
    /// every load (Cerruti's kernel on the frozen contact set): adds tangential_ratio
    /// (k_x + k_y)/(2k) with its interval, and the figure DIR/tangential.png.
    #[arg(long, value_name = "NU")]
    pub poisson: Option<f64>,
    /// With --poisson: which tangential stiffnesses, x, y or both [default: both]; with one
    /// direction tangential_ratio is k_x/k (k_y/k), at about half the cost (Mindlin's
    /// ratio then bounds neither direction alone).
    #[arg(long, value_name = "DIR")]
    pub tangential: Option<String>,
    /// The two bodies' electrical resistivities ρ₁,ρ₂: adds electrical_conductance
    /// 2k/(E*(ρ₁+ρ₂)) with its interval (Barber's analogy; E* = 1) and its figure.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "RHO1,RHO2",
        allow_hyphen_values = true
    )]
    pub resistivity: Option<Vec<f64>>,
    /// The two bodies' thermal conductivities κ₁,κ₂: adds thermal_conductance
    /// (2k/E*)κ₁κ₂/(κ₁+κ₂) with its interval.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "K1,K2",
        allow_hyphen_values = true
    )]
    pub thermal_conductivity: Option<Vec<f64>>,
    #[command(flatten)]
    pub common: CommonArgs,
}

/// The keys of a study file: `(key, type, default, meaning)`, for `--help` and the README.
pub const FILE_KEYS: [(&str, &str, &str, &str); 15] = [
    (
        "kind",
        "\"alpha\" or \"curve\"",
        "required",
        "what to write: alpha.csv or curve.csv, with plots",
    ),
    ("method", "\"mdr\" or \"bem\"", "required", "solver"),
    (
        "n",
        "integer or list of integers",
        "required",
        "grid sizes N",
    ),
    (
        "hurst",
        "number, \"A:B:STEP\" string or list of both",
        "required",
        "Hurst exponents (ranges inclusive)",
    ),
    (
        "samples",
        "integer >= 1",
        "required",
        "realisations per (N, H)",
    ),
    (
        "rolloff",
        "number > 0",
        "none (pure power law)",
        "long-wavelength roll-off q0*L/2pi",
    ),
    ("seed", "integer >= 0", "1", "study seed"),
    (
        "min_contacts",
        "integer >= 1",
        "8",
        "alpha window: fewest points in contact",
    ),
    (
        "max_fraction",
        "number in (0, 1]",
        "0.01",
        "alpha window: largest contact fraction",
    ),
    (
        "levels",
        "integer >= 3",
        "48",
        "common force levels of the ensemble curves",
    ),
    (
        "full_sweep",
        "true or false",
        "false",
        "alpha, BEM: solve every load, not only those up to 4x the windows' end",
    ),
    (
        "poisson",
        "number in [0, 0.5]",
        "none",
        "curve, BEM: Poisson's ratio of the tangential stiffness at every load (tangential_ratio)",
    ),
    (
        "tangential",
        "\"x\", \"y\" or \"both\"",
        "\"both\"",
        "curve, BEM, with poisson: which tangential stiffnesses (one: k_d/k, about half the cost)",
    ),
    (
        "resistivity",
        "list of two numbers > 0",
        "none",
        "curve: the bodies' resistivities: electrical_conductance 2k/(E*(rho1+rho2))",
    ),
    (
        "thermal_conductivity",
        "list of two numbers > 0",
        "none",
        "curve: the bodies' thermal conductivities: thermal_conductance",
    ),
];

/// `--help` of `study file`: the keys (from [`FILE_KEYS`]) and an example.
fn file_help() -> String {
    let mut text = String::from("Keys of a study file (TOML); other keys are refused:\n");
    let width = |i: usize| {
        FILE_KEYS
            .iter()
            .map(|k| [k.0, k.1, k.2][i].len())
            .max()
            .unwrap_or(0)
    };
    let (w0, w1, w2) = (width(0), width(1), width(2));
    text.push_str(&format!(
        "  {:w0$}  {:w1$}  {:w2$}  meaning\n",
        "key", "type", "default"
    ));
    for (key, kind, default, meaning) in FILE_KEYS {
        text.push_str(&format!(
            "  {key:w0$}  {kind:w1$}  {default:w2$}  {meaning}\n"
        ));
    }
    text.push_str(
        "The keys mean what the options of study alpha / study curve mean (see their --help \
         for the outputs and the scales).\n\n\
         Example (docs/sweep.toml):\n",
    );
    for line in SWEEP_EXAMPLE.lines() {
        text.push_str(&format!("  {line}\n"));
    }
    text.push_str("\nRun: asperity study file docs/sweep.toml --out sweep");
    text
}

/// The example study file shipped as `docs/sweep.toml`.
const SWEEP_EXAMPLE: &str = include_str!("../../../../docs/sweep.toml");

/// Arguments of `asperity study file`.
#[derive(Debug, clap::Args)]
#[command(after_help = file_help())]
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
    /// α of a finished or running BEM study refitted with other windows (start 4, 8, 16
    /// contacts; end 0.5, 1, 2 % contact), each with a bootstrap 95 % interval → CSV on
    /// stdout.
    #[command(
        after_help = "Reads the sample curves that the study's checkpoints keep (finished BEM \
tasks, and tasks in progress); writes nothing into the folder.\nColumns: n, hurst, \
min_contacts, max_fraction, alpha (ensemble-mean fit), low, high (2.5 and 97.5 % of 400 \
bootstrap resamples of the samples), samples.\n\nExample:\n  asperity study windows \
docs/results/medium/fig2/bem > windows.csv"
    )]
    Windows(WindowsArgs),
    /// A finished study beside the paper → DIR/comparison.csv and DIR/report.md, with a
    /// verdict per row (with roll-off: the steepest log–log slope against the paper's
    /// "≈ 1", with a bootstrap interval; without: α against eqs. (6) and (24)).
    #[command(after_help = "Example:\n  asperity study compare docs/results/fig2_1024 --force")]
    Compare(CompareArgs),
}

/// Arguments of `asperity study compare`.
#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// The study folder (holding study.json and checkpoint/).
    pub dir: PathBuf,
    /// Overwrite an existing comparison.csv and report.md.
    #[arg(long)]
    pub force: bool,
}

/// Arguments of `asperity study windows`.
#[derive(Debug, clap::Args)]
pub struct WindowsArgs {
    /// The study folder (holding study.json and checkpoint/).
    pub dir: PathBuf,
}

/// `asperity study windows`: the window sensitivity as CSV on stdout.
fn windows(args: &WindowsArgs) -> Result<()> {
    let rows = asperity_app::study::windows::window_sensitivity(&args.dir)
        .map_err(crate::request::refused)?;
    let table = asperity_app::study::windows::csv(&rows)?;
    use std::io::Write as _;
    std::io::stdout().write_all(&table)?;
    Ok(())
}

/// Arguments of `asperity study`.
#[derive(Debug, clap::Args)]
pub struct StudyArgs {
    /// Which study.
    #[command(subcommand)]
    pub command: StudyCommand,
}

/// Reads a study file's text by the front-end layer's reader
/// ([`asperity_app::study::file::read`]): the kind, the spec (not yet validated) and a curve
/// study's tangential and conductance columns; its refusals in the keys' words.
fn parse_study_file(path: &Path, text: &str) -> Result<(Kind, StudySpec, figure::Derived)> {
    let read = asperity_app::study::file::read(path, text)
        .map_err(|r| anyhow::anyhow!("{}", r.words(asperity_app::Names::Keywords)))?;
    Ok((read.request.kind, read.spec, read.derived))
}

/// The request of the options shared by every study, with the sizes and H values of the
/// kind's own flags.
fn request(kind: Kind, common: &CommonArgs, sizes: &[i128], hurst: &str) -> Result<StudyRequest> {
    Ok(StudyRequest {
        kind,
        method: common.method.clone(),
        sizes: sizes.to_vec(),
        hursts: parse_range(hurst)?,
        samples: common.samples,
        rolloff: common.rolloff,
        seed: Some(common.seed.clone()),
        min_contacts: Some(common.min_contacts),
        max_fraction: Some(common.max_fraction),
        levels: Some(common.levels),
        full_sweep: false,
        poisson: None,
        tangential: None,
    })
}

impl RunOptions {
    fn from_args(run: &RunArgs) -> Result<Self> {
        let checkpoint_every = asperity_app::study::checkpoint_interval(run.checkpoint_every)?;
        Ok(RunOptions {
            force: run.force,
            quiet: run.quiet,
            checkpoint_every,
            setting: None,
            derived: Default::default(),
        })
    }
}

/// Runs `asperity study`.
pub fn run(args: &StudyArgs) -> Result<()> {
    let (kind, spec, out, options) = match &args.command {
        StudyCommand::Alpha(a) => {
            let request = StudyRequest {
                full_sweep: a.full_sweep,
                ..request(Kind::Alpha, &a.common, &a.n, &a.hurst)?
            };
            let spec = request.spec().map_err(|r| refused(r.into()))?;
            (
                Kind::Alpha,
                spec,
                &a.common.run.out,
                RunOptions::from_args(&a.common.run)?,
            )
        }
        StudyCommand::Curve(c) => {
            let request = StudyRequest {
                poisson: c.poisson,
                tangential: c.tangential.clone(),
                ..request(Kind::Curve, &c.common, &c.n, &c.hurst)?
            };
            let spec = request.spec().map_err(|r| refused(r.into()))?;
            let derived = Derived::validate(
                c.poisson,
                c.tangential.as_deref(),
                &c.resistivity,
                &c.thermal_conductivity,
            )
            .map_err(|r| refused(r.into()))?;
            let options = RunOptions {
                derived: derived.into(),
                ..RunOptions::from_args(&c.common.run)?
            };
            (Kind::Curve, spec, &c.common.run.out, options)
        }
        StudyCommand::Windows(w) => return windows(w),
        StudyCommand::Compare(c) => {
            return compare_study(&c.dir, c.force)
                .map(drop)
                .map_err(crate::request::report_error)
        }
        StudyCommand::File(f) => {
            let text = asperity::input::read_text(&f.file, asperity::input::TEXT_MAX_BYTES)?;
            let (kind, spec, derived) = parse_study_file(&f.file, &text)?;
            let options = RunOptions {
                derived,
                ..RunOptions::from_args(&f.run)?
            };
            (kind, spec, &f.run.out, options)
        }
    };
    let spec = crate::studies::resumable(spec, out, options.force, options.quiet);
    if spec.method == Method::Bem && !options.quiet {
        announce_bem(&spec, out)?;
    }
    execute(&spec, out, options, kind)?;
    Ok(())
}

/// The smallest grid whose BEM study gets an up-front time estimate (probes of a few
/// seconds; smaller studies take about that long in all).
const ESTIMATE_FROM_N: usize = 256;

/// Before a BEM study on grids from [`ESTIMATE_FROM_N`] on, its run time on this machine
/// ([`crate::estimate::estimate_study`]) for the samples not yet checkpointed in
/// `out`.
fn announce_bem(spec: &StudySpec, out: &Path) -> Result<()> {
    if spec.sizes.iter().all(|&n| n < ESTIMATE_FROM_N) {
        return Ok(());
    }
    let (estimate, stored) = crate::estimate::estimate_study(spec, out)?;
    eprintln!(
        "bem study: N = {:?}, {} H, {} samples each{}{}: estimated {} on this machine ({} lanes; \
         checkpointed: an interrupted run resumes with the same command)",
        spec.sizes,
        spec.hursts.len(),
        spec.samples,
        crate::studies::describe_sweep(spec),
        match stored {
            0 => String::new(),
            s => format!(" ({s} already checkpointed, not counted)"),
        },
        crate::estimate::human_duration(estimate.seconds),
        estimate.lanes
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use asperity::study::FitWindow;

    #[test]
    fn study_files_take_single_values_and_lists() {
        let parse = |text: &str| parse_study_file(Path::new("s.toml"), text);
        let base = "kind = \"curve\"\nmethod = \"mdr\"\nsamples = 3\n";
        let (kind, spec, _) = parse(&format!("{base}n = 512\nhurst = 0.5\n")).unwrap();
        assert_eq!(kind, Kind::Curve);
        assert_eq!((spec.sizes, spec.hursts), (vec![512], vec![0.5]));
        let (_, spec, _) = parse(&format!("{base}n = [512, 1024]\nhurst = 1\n")).unwrap();
        assert_eq!((spec.sizes, spec.hursts), (vec![512, 1024], vec![1.0]));
        let (_, spec, _) = parse(&format!("{base}n = 64\nhurst = \"-1:0:0.5\"\n")).unwrap();
        assert_eq!(spec.hursts, vec![-1.0, -0.5, 0.0]);
        let (_, spec, _) =
            parse(&format!("{base}n = 64\nhurst = [\"-1:0:0.5\", 2, 2.5]\n")).unwrap();
        assert_eq!(spec.hursts, vec![-1.0, -0.5, 0.0, 2.0, 2.5]);
        assert_eq!(spec.seed, 1);
        assert_eq!(spec.levels, 48);
        assert_eq!(spec.window, FitWindow::default());
    }

    #[test]
    fn study_files_take_the_tangential_and_conductance_keys() {
        let parse = |text: &str| parse_study_file(Path::new("s.toml"), text);
        let base = "kind = \"curve\"\nmethod = \"bem\"\nn = 32\nhurst = 0.5\nsamples = 2\n";
        let (kind, spec, derived) = parse(&format!(
            "{base}poisson = 0.3\nresistivity = [1, 3]\nthermal_conductivity = [2.0, 2.0]\n"
        ))
        .unwrap();
        assert_eq!(
            (kind, spec.poisson, derived.poisson),
            (Kind::Curve, Some(0.3), Some(0.3))
        );
        spec.validate().unwrap();
        // Barber's analogy with these bodies: 2k/(E*(1+3)) and (2k/E*)·2·2/(2+2).
        assert_eq!(derived.transport.electrical(1.0, 1.0), Some(0.5));
        assert_eq!(derived.transport.thermal(1.0, 1.0), Some(2.0));
        let (_, plain, none) = parse(base).unwrap();
        assert_eq!((plain.poisson, none.poisson), (None, None));
        assert_eq!(none.transport.electrical(1.0, 1.0), None);
        // Refused in the keys' words, naming the file.
        let refused = |extra: &str| parse(&format!("{base}{extra}")).unwrap_err().to_string();
        assert_eq!(
            refused("poisson = 0.7\n"),
            "s.toml: poisson must be in [0, 0.5] (Poisson's ratio), got 0.7"
        );
        assert!(refused("resistivity = [1]\n").starts_with("s.toml: invalid resistivity: give two"));
        let err = refused("thermal_conductivity = [1, -2]\n");
        assert!(
            err.contains("thermal_conductivity") && err.contains("positive"),
            "{err}"
        );
        let mdr = base.replace("bem", "mdr");
        let err = parse(&format!("{mdr}poisson = 0.3\n"))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("s.toml: poisson applies to BEM studies only"),
            "{err}"
        );
        let alpha = base.replace("curve", "alpha");
        let err = parse(&format!("{alpha}resistivity = [1, 1]\n"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("apply to curve studies only"), "{err}");
        assert!(refused("poisson = \"0.3\"\n").contains("(key `poisson`)"));
    }

    #[test]
    fn study_file_errors_name_the_line_column_and_key() {
        let parse = |text: &str| {
            parse_study_file(Path::new("s.toml"), text)
                .unwrap_err()
                .to_string()
        };
        let err =
            parse("kind = \"alpha\"\nmethod = \"mdr\"\nn = \"512\"\nhurst = 0.5\nsamples = 3\n");
        assert!(
            err.starts_with("s.toml, line 3, column 5 (key `n`): "),
            "{err}"
        );
        assert!(err.contains("grid size"), "{err}");
        assert!(!err.contains('\n'), "{err}");
        let err = parse("kind = \"alpha\"\nmethod = \"mdr\"\nn = 64\nhurst = true\nsamples = 3\n");
        assert!(err.contains("line 4") && err.contains("`hurst`"), "{err}");
        let err =
            parse("kind = \"alpha\"\nmethod = \"mdr\"\nn = 64\nhurst = \"1:0:1\"\nsamples = 3\n");
        assert!(
            err.contains("line 4") && err.contains("empty range"),
            "{err}"
        );
        let err = parse("kind = \"alpha\"\nmethod = \"mdr\"\nn = 64\nhurst = 0.5\nsampels = 3\n");
        assert!(err.contains("line 5") && err.contains("sampels"), "{err}");
        let err = parse("kind = \"alpha\"\nmethod = \"mdr\"\nn = 64\nhurst = 0.5\n");
        assert_eq!(err, "s.toml: missing field `samples`");
        let err = parse("kind = \"alpha\"\nmethod = \"mdr\"\nn = [64\n");
        assert!(err.contains("line 3") || err.contains("line 4"), "{err}");
    }

    /// Inputs tried by the property test below.
    const FUZZ_CASES: u32 = 1000;

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: FUZZ_CASES, failure_persistence: None, ..Default::default() })]

        /// The example study file with bytes changed, cut or inserted: parsed or refused in
        /// one line; a spec it accepts either validates or is refused by validation, in one
        /// line too (never a panic, an abort or a huge allocation).
        #[test]
        fn mutated_study_files_never_panic(
            at in 0usize..10_000,
            byte in proptest::prelude::any::<u8>(),
            mode in 0u8..4,
            number in proptest::prelude::prop::sample::select(vec!["1e300", "-1", "nan", "1e-9", "18446744073709551616", "\"-1:3:1e-12\"", "[]"]),
        ) {
            let mut bytes = SWEEP_EXAMPLE.as_bytes().to_vec();
            let i = at % bytes.len();
            match mode {
                0 => bytes[i] = byte,
                1 => bytes.truncate(i),
                2 => bytes.insert(i, byte),
                _ => bytes.extend(format!("\nlevels = {number}\n").as_bytes()),
            }
            let text = String::from_utf8_lossy(&bytes);
            match parse_study_file(Path::new("s.toml"), &text) {
                Ok((_, spec, _)) => {
                    if let Err(e) = spec.validate() {
                        proptest::prop_assert!(!e.to_string().contains('\n'));
                    }
                }
                Err(e) => proptest::prop_assert!(!e.to_string().contains('\n'), "{}", e),
            }
        }
    }

    /// The defaults that `--help` of `study file` and the README list are the library's
    /// (`StudySpec::default`, where every front end takes them from), not a copy that
    /// could drift.
    #[test]
    fn the_file_keys_defaults_are_the_librarys() {
        let spec = StudySpec::default();
        let default = |key: &str| FILE_KEYS.iter().find(|k| k.0 == key).unwrap().2;
        assert_eq!(default("seed"), spec.seed.to_string());
        assert_eq!(
            default("min_contacts"),
            spec.window.min_contacts.to_string()
        );
        assert_eq!(
            default("max_fraction"),
            spec.window.max_fraction.to_string()
        );
        assert_eq!(default("levels"), spec.levels.to_string());
        let alpha = StudyRequest::default();
        assert_eq!(default("full_sweep"), alpha.full_sweep.to_string());
    }

    #[test]
    fn the_example_file_parses_and_help_and_readme_list_every_key() {
        let (kind, spec, _) =
            parse_study_file(Path::new("docs/sweep.toml"), SWEEP_EXAMPLE).unwrap();
        assert_eq!(kind, Kind::Alpha);
        spec.validate().unwrap();
        let help = file_help();
        let readme = include_str!("../../../../README.md");
        for (key, kind, default, _) in FILE_KEYS {
            let row = help
                .lines()
                .find(|l| l.trim_start().starts_with(&format!("{key} ")))
                .unwrap_or_else(|| panic!("{key} missing from --help"));
            assert!(row.contains(kind) && row.contains(default), "{row}");
            let row = readme
                .lines()
                .find(|l| l.starts_with(&format!("| `{key}` |")))
                .unwrap_or_else(|| panic!("{key} missing from README's table"));
            assert!(row.contains(default), "README: {row}");
        }
        // Every key the parser knows is in the table: an unknown key's error lists them.
        let err = parse_study_file(Path::new("s.toml"), "nokey = 1\n")
            .unwrap_err()
            .to_string();
        let listed = err.split("expected one of").nth(1).unwrap_or_default();
        let known: Vec<&str> = listed.split('`').skip(1).step_by(2).collect();
        assert_eq!(known.len(), FILE_KEYS.len(), "{err}");
        for key in known {
            assert!(FILE_KEYS.iter().any(|k| k.0 == key), "{key} not documented");
        }
    }
}
