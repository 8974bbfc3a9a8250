//! Ensemble studies: many seeded realisations per (method, N, H), their mean force–stiffness
//! curves and the exponent α of `k ∝ F^α` (paper eq. 3, Figs. 1, 2, 5), with checkpoints.
//!
//! A [`StudySpec`] lists grid sizes, Hurst exponents and the number of samples; each
//! `(N, H)` pair is a [`Task`]. Every sample has its own seed, derived from the study seed,
//! N, H and the sample index ([`sample_seed`]), so results do not depend on the order or
//! the thread on which samples run, nor on which other tasks a study contains.
//!
//! # Checkpoints
//! [`StudyDir::open`] writes `DIR/study.json` (the spec), and [`run_any_task`] writes,
//! after every batch of samples, `DIR/checkpoint/<task>.json` with all samples done so far
//! (atomically). Run again with
//! the same spec, it resumes where it stopped and — since samples are deterministic and
//! stored with round-trip precision — gives bit-identical results. A folder holding a
//! different study is refused ([`Error::ForeignCheckpoint`], naming the parameters that
//! differ) unless `discard` is set. The same study over other grids, H values or sample
//! counts is no different study: it is extended, every task it shares with the stored one
//! keeping its checkpoint (a finished BEM task whose sample count changed continues from
//! its kept sample curves; a finished MDR task, whose curves are not kept, is computed
//! again). A folder whose `study.json` names another study but
//! whose checkpoints hold no sample (a study that stopped before its first checkpoint) is
//! free and reused.
//!
//! Every checkpoint is sealed with the full identity of what produced it and a checksum
//! of its content ([`identity`]): one copied from another study, left behind by a study
//! whose `study.json` was deleted, written by an older asperity, edited by hand or damaged
//! is refused with the fields that differ, never merged. Two processes never share a
//! folder: a front end holds [`StudyDir::lock`] while it runs.
//!
//! `study.json` also records the scales of the samples (`normalisation`, see
//! [`samplers::Scales`]), which every checkpoint's identity holds as well.
//!
//! # Samples computed elsewhere
//! A front end that spreads a study's samples over processes (the CLI's MPI build) keeps
//! the folder on one process with [`StudyDir::restore`], [`StudyDir::save_in_progress`]
//! and [`StudyDir::finish`], and computes chosen samples of a task anywhere with
//! [`TaskSamples`]: assembled in index order, they give the serial run's checkpoints and
//! results byte for byte. [`Ledger`] does that bookkeeping: it hands out the samples not
//! yet computed and checkpoints every sample received ([`StudyDir::save_received`]), in
//! index order or not, so that a lost process costs only the samples it was computing.

pub mod compare;
pub mod curve;
pub mod identity;
pub mod ledger;
pub mod samplers;
pub mod sensitivity;
pub mod theory;

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

pub use curve::{
    ensemble_alpha, ensemble_curve, quantile, CurvePoint, EnsemblePoint, FitWindow, SampleCurve,
};
pub use ledger::Ledger;
pub use samplers::{run_any_task, run_any_task_with_loads, Scales, TaskSamples};

use crate::fit::PowerLawFit;
use crate::lock::FolderLock;
use crate::memory::array_bytes;
use crate::spectrum::HURST_RANGE;
use crate::{io, Error, Result};
use identity::{TaskIdentity, Unsealed};

/// Which solver produces the force–stiffness curve of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// 1D method of dimensionality reduction on rough lines (linear springs).
    Mdr,
    /// 3D boundary elements on rough surfaces (free boundaries, frozen-set stiffness).
    Bem,
}

impl Method {
    /// Lower-case name, as in the CLI and CSV.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Mdr => "mdr",
            Method::Bem => "bem",
        }
    }
}

/// Everything that defines a study; validated by [`StudySpec::validate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudySpec {
    /// Solver.
    pub method: Method,
    /// Grid sizes N (points of a line, or points per side of a square surface).
    pub sizes: Vec<usize>,
    /// Hurst exponents.
    pub hursts: Vec<f64>,
    /// Realisations per (N, H).
    pub samples: usize,
    /// Long-wavelength roll-off `q0 L / 2π`, if any.
    pub rolloff: Option<f64>,
    /// Study seed.
    pub seed: u64,
    /// Low-force window of the α fits.
    pub window: FitWindow,
    /// Number of common force levels of the ensemble curves.
    pub levels: usize,
    /// BEM: the contact fraction past which a sample stops loading (its sweep ends with
    /// the first load above it); `None`: all [`samplers::BemSampler::LOADS`] loads, up to
    /// p̄ = 0.2 E*. An α study needs only the low-force end ([`StudySpec::with_alpha_sweep`]);
    /// MDR samples ignore it (their whole curve costs one pass).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sweep_end: Option<f64>,
}

/// An α study's BEM sweep ends past this many times the largest window fraction it may be
/// fitted on: each sample's curve must reach the ensemble's window end, the median over
/// samples of their window ends. Measured on `reproduce fig1 --quick` (64², 128², 9 H,
/// 20 samples each, every sensitivity window): the first load past 4× a window's end
/// carries at least 3.5 times that window's ensemble end force (docs/bem.md).
pub const ALPHA_SWEEP_MARGIN: f64 = 4.0;

impl StudySpec {
    /// The spec with the sweep of an α study: BEM samples stop loading past
    /// [`ALPHA_SWEEP_MARGIN`] times the largest contact fraction any of its α fits can end
    /// at (its own window and those of [`sensitivity::sensitivity_windows`], on each of its
    /// grids), or never where that is not below full contact. The fits are then those of
    /// the whole sweep, bit for bit, as long as every sample's curve reaches the ensemble's
    /// window ends, which [`TaskResult::from_samples`] checks (`samplers::tests`); at a
    /// fraction of the cost: at 128² the loads above 10 % contact are about 40 % of a
    /// sample's time.
    pub fn with_alpha_sweep(mut self) -> Self {
        let largest_end = self
            .sizes
            .iter()
            .flat_map(|&n| {
                let points = n.saturating_mul(n);
                self.fit_windows().map(move |w| w.fraction_range(points).1)
            })
            .fold(0.0, f64::max);
        let end = ALPHA_SWEEP_MARGIN * largest_end;
        self.sweep_end = (self.method == Method::Bem && end < 1.0).then_some(end);
        self
    }

    /// The windows the study's α may be fitted on: its own, and those of the sensitivity
    /// table ([`sensitivity::sensitivity_windows`], refitted from its stored curves).
    fn fit_windows(&self) -> impl Iterator<Item = FitWindow> {
        std::iter::once(self.window).chain(sensitivity::sensitivity_windows())
    }

    /// Checks sizes, Hurst exponents, samples, roll-off and window.
    pub fn validate(&self) -> Result<()> {
        if self.sizes.is_empty() {
            return Err(Error::invalid("n", "no grid size given"));
        }
        let min_n = match self.method {
            Method::Mdr => 16,
            Method::Bem => 8,
        };
        if let Some(&n) = self.sizes.iter().find(|&&n| n < min_n) {
            return Err(Error::invalid(
                "n",
                format!("N = {n} is below the smallest useful size {min_n}"),
            ));
        }
        let mut seen = std::collections::HashSet::with_capacity(self.sizes.len());
        if let Some(n) = self.sizes.iter().find(|&&n| !seen.insert(n)) {
            return Err(Error::invalid("n", format!("N = {n} is given twice")));
        }
        if self.hursts.is_empty() {
            return Err(Error::invalid("hurst", "the range of H is empty"));
        }
        let (lo, hi) = HURST_RANGE;
        if let Some(&h) = self.hursts.iter().find(|h| !(lo..=hi).contains(*h)) {
            return Err(Error::invalid(
                "hurst",
                format!("H = {h} is outside [{lo}, {hi}]"),
            ));
        }
        check_distinct_hursts(&self.hursts)?;
        if self.samples == 0 {
            return Err(Error::invalid("samples", "need at least 1 sample"));
        }
        if let Some(q0) = self.rolloff {
            if !crate::is_positive_finite(q0) {
                return Err(Error::invalid(
                    "rolloff",
                    format!("must be positive, got {q0}"),
                ));
            }
        }
        if !(3..=MAX_LEVELS).contains(&self.levels) {
            return Err(Error::invalid(
                "levels",
                format!("need 3 to {MAX_LEVELS} force levels, got {}", self.levels),
            ));
        }
        self.window.validate()?;
        if let Some(end) = self.sweep_end {
            if !(end > 0.0 && end <= 1.0) {
                return Err(Error::invalid(
                    "sweep_end",
                    format!(
                        "the sweep's end is a contact fraction in (0, 1], got {}",
                        crate::input::short_number(end)
                    ),
                ));
            }
        }
        self.ensure_size()?;
        self.ensure_samplers()
    }

    /// Refuses a study whose size (tasks × samples, and the results it keeps: tasks ×
    /// levels) is beyond what can be run, before anything is created.
    fn ensure_size(&self) -> Result<()> {
        let tasks = self.sizes.len().checked_mul(self.hursts.len());
        let samples = tasks.and_then(|t| t.checked_mul(self.samples));
        match samples {
            Some(total) if total <= MAX_STUDY_SAMPLES => {}
            _ => {
                return Err(Error::invalid(
                    "samples",
                    format!(
                        "{} sizes x {} H values x {} samples is more than the {} samples a \
                         study may hold",
                        self.sizes.len(),
                        self.hursts.len(),
                        self.samples,
                        crate::input::short_number(MAX_STUDY_SAMPLES as f64)
                    ),
                ))
            }
        }
        // The results of every task stay in memory until the tables are written.
        let per_task = array_bytes(&[self.levels], std::mem::size_of::<EnsemblePoint>())
            .zip(array_bytes(&[self.samples], 8))
            .and_then(|(a, b)| a.checked_add(b));
        crate::memory::ensure_fits(
            &format!(
                "the results of a study of {} tasks with {} force levels",
                tasks.unwrap_or(usize::MAX),
                self.levels
            ),
            per_task.and_then(|b| b.checked_mul(tasks? as u64)),
        )
    }

    /// All tasks, sizes outer, H inner.
    pub fn tasks(&self) -> Vec<Task> {
        self.sizes
            .iter()
            .flat_map(|&n| self.hursts.iter().map(move |&hurst| Task { n, hurst }))
            .collect()
    }
}

/// The number of common force levels of the ensemble curves when none is asked for (the
/// CLI's `--levels`, Python's `levels`, the figures and the benchmarks).
pub const DEFAULT_LEVELS: usize = 48;

/// The most force levels of an ensemble curve.
pub const MAX_LEVELS: usize = 100_000;

/// The most samples (over all tasks) a study may hold.
pub const MAX_STUDY_SAMPLES: usize = 1_000_000_000;

/// Refuses H values given twice (`0` and `-0` are one value) or sharing a checkpoint
/// name (6 decimals), in one pass.
fn check_distinct_hursts(hursts: &[f64]) -> Result<()> {
    let mut values = std::collections::HashMap::with_capacity(hursts.len());
    let mut keys = std::collections::HashMap::with_capacity(hursts.len());
    for &h in hursts {
        if values.insert((h + 0.0).to_bits(), h).is_some() {
            return Err(Error::invalid("hurst", format!("H = {h} is given twice")));
        }
        if let Some(earlier) = keys.insert(hurst_key(h), h) {
            return Err(Error::invalid(
                "hurst",
                format!(
                    "H = {earlier} and H = {h} would share one checkpoint (H is kept to 6 \
                     decimals in its name, {}); give values at least 1e-6 apart",
                    hurst_key(h)
                ),
            ));
        }
    }
    Ok(())
}

/// One `(N, H)` ensemble of a study.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Task {
    /// Grid size.
    pub n: usize,
    /// Hurst exponent.
    pub hurst: f64,
}

impl Task {
    /// File-name key, e.g. `mdr_n512_h-0.250000`: H rounded to 6 decimals, so
    /// [`StudySpec::validate`] refuses H values that would share a key.
    pub fn key(&self, method: Method) -> String {
        format!("{}_n{}_h{}", method.name(), self.n, hurst_key(self.hurst))
    }

    /// Same N and the same H bit for bit.
    pub fn same_as(&self, other: &Task) -> bool {
        self.n == other.n && self.hurst.to_bits() == other.hurst.to_bits()
    }
}

/// H as it appears in checkpoint names: signed, 6 decimals.
fn hurst_key(hurst: f64) -> String {
    format!("{hurst:+.6}")
}

/// Relative cost of one sample of `method` at grid size `n`, the weight of a sample in
/// progress estimates: `N² log₂ N` for BEM (FFTs of the N×N grid in every iteration of
/// every load) and `N log₂ N` for MDR (FFT synthesis of the line, then its sort). Only
/// ratios within one method are meaningful.
pub fn sample_cost(method: Method, n: usize) -> f64 {
    let n = n.max(2) as f64;
    match method {
        Method::Bem => n * n * n.log2(),
        Method::Mdr => n * n.log2(),
    }
}

pub(crate) fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// Seed of sample `index` of `(method, N, H)` in a study with seed `study_seed`.
pub fn sample_seed(study_seed: u64, method: Method, task: Task, index: usize) -> u64 {
    let mut x = splitmix64(study_seed ^ method as u64);
    x = splitmix64(x ^ task.n as u64);
    x = splitmix64(x ^ task.hurst.to_bits());
    splitmix64(x ^ index as u64)
}

/// Refuses the samples of a sweep that ended early ([`StudySpec::sweep_end`]) when one
/// of them ends below the ensemble's window end of the study's window or of a sensitivity
/// window: there the fit would average fewer samples than the whole sweep's fit does.
fn check_sweep_reaches_windows(spec: &StudySpec, samples: &[SampleCurve]) -> Result<()> {
    let Some(end) = spec.sweep_end else {
        return Ok(());
    };
    let refs: Vec<&SampleCurve> = samples.iter().collect();
    for window in spec.fit_windows() {
        let Some((_, hi)) = curve::ensemble_window(&refs, &window) else {
            continue;
        };
        let short = samples.iter().enumerate().find_map(|(i, s)| {
            let last = s.points.last()?.force;
            (last < hi).then_some((i, last))
        });
        if let Some((i, last)) = short {
            return Err(Error::invalid(
                "sweep_end",
                format!(
                    "sample {i}, its sweep ended past contact fraction {}, reached force \
                     {last:.6e} only, below the {hi:.6e} at which the ensemble's α window ({}) \
                     ends: this study needs the whole load sweep",
                    crate::input::short_number(end),
                    window.describe()
                ),
            ));
        }
    }
    Ok(())
}

/// Produces the force–stiffness curve of one realisation. A worker holds the plans and
/// buffers of one thread and is reused across its samples.
pub trait Sampler: Sync {
    /// Per-thread state (generators, solvers, scratch).
    type Worker: Send;
    /// A fresh worker.
    fn worker(&self) -> Result<Self::Worker>;
    /// The curve of the realisation with `seed`.
    fn sample(&self, worker: &mut Self::Worker, seed: u64) -> Result<SampleCurve>;
}

/// The result of one task: what follows from its samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskResult {
    /// Method.
    pub method: Method,
    /// The task.
    pub task: Task,
    /// Number of samples.
    pub samples: usize,
    /// Ensemble-mean curve at common force levels.
    pub mean_curve: Vec<EnsemblePoint>,
    /// α fitted on the ensemble-mean curve.
    pub alpha_ensemble: Option<PowerLawFit>,
    /// α of each sample (samples with too few points in the window are skipped).
    pub alpha_samples: Vec<f64>,
}

impl TaskResult {
    /// Builds the ensemble quantities from the samples.
    pub fn from_samples(spec: &StudySpec, task: Task, samples: &[SampleCurve]) -> Result<Self> {
        check_sweep_reaches_windows(spec, samples)?;
        let mean_curve = ensemble_curve(samples, spec.levels)?;
        let alpha_ensemble = ensemble_alpha(samples, &spec.window, spec.levels);
        let alpha_samples = samples
            .iter()
            .filter_map(|s| s.alpha(&spec.window, spec.levels))
            .map(|f| f.exponent)
            .collect();
        Ok(TaskResult {
            method: spec.method,
            task,
            samples: samples.len(),
            mean_curve,
            alpha_ensemble,
            alpha_samples,
        })
    }

    /// 2.5 % and 97.5 % quantiles of the per-sample α.
    pub fn alpha_sample_interval(&self) -> Option<(f64, f64)> {
        Some((
            quantile(&self.alpha_samples, 0.025)?,
            quantile(&self.alpha_samples, 0.975)?,
        ))
    }

    /// Mean of the per-sample α.
    pub fn alpha_sample_mean(&self) -> Option<f64> {
        (!self.alpha_samples.is_empty())
            .then(|| self.alpha_samples.iter().sum::<f64>() / self.alpha_samples.len() as f64)
    }
}

#[derive(Debug, Serialize, Deserialize)]
struct Manifest {
    format: String,
    spec: StudySpec,
    /// Scales of the samples; informative here (each checkpoint's identity holds them
    /// too, and is compared).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    normalisation: Option<Scales>,
}

/// What `checkpoint/<task>.json` holds, sealed with the task's [`TaskIdentity`]: the
/// samples of a task in progress, or the result of a finished one. A finished BEM task
/// keeps its sample curves too (24 loads a sample: tens of kB), so that its α can be
/// refitted with other windows without solving again ([`StudyDir::stored_samples`]); a
/// finished MDR task does not (up to a thousand points a line, 500 lines; recomputing
/// them takes seconds).
#[derive(Debug, Serialize, Deserialize)]
#[serde(tag = "state", rename_all = "snake_case")]
enum Checkpoint {
    InProgress {
        samples: Vec<SampleCurve>,
        /// Samples received beyond the first missing index, by index: a front end that
        /// computes samples out of order ([`StudyDir::save_received`], the MPI build)
        /// keeps them too. Absent (and then not written) in serial runs.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        later: Vec<LaterSample>,
    },
    Done {
        result: TaskResult,
        /// The sample curves (BEM only; absent from checkpoints written before they were kept).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        samples: Vec<SampleCurve>,
    },
}

/// A sample of a task in progress saved beyond the first missing index.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct LaterSample {
    index: usize,
    sample: SampleCurve,
}

/// A task in progress saves its samples at most this often (and always when it ends), so
/// that fast tasks (MDR) do not spend their time rewriting checkpoints.
pub const CHECKPOINT_INTERVAL: std::time::Duration = std::time::Duration::from_secs(10);

/// The longest checkpoint interval a caller may ask for, in seconds (about 11 days): longer
/// is no checkpoint at all, and `Duration::from_secs_f64` panics past its range.
pub const MAX_CHECKPOINT_INTERVAL_SECONDS: f64 = 1e6;

const MANIFEST_FORMAT: &str = "asperity-study/1";

/// The largest checkpoint file read (2^34 bytes); the memory guard checks it first.
const CHECKPOINT_MAX_BYTES: u64 = 1 << 34;

/// Where a study keeps its spec and checkpoints.
#[derive(Debug, Clone)]
pub struct StudyDir {
    dir: PathBuf,
    spec: StudySpec,
    interval: std::time::Duration,
    stop: crate::stop::Stop,
}

/// What a folder's `study.json` says, as [`StudyDir::check`] sees it.
enum Stored {
    None,
    Same,
    /// The same study over more N, H or samples: it is extended, each
    /// checkpoint reused where its task's identity matches.
    Extended,
    /// The same study without some of the stored one's (N, H) or with fewer samples:
    /// what the stored study finished would be left out of the results.
    Narrower(String),
    Other(String),
    Corrupt(String),
}

impl StudyDir {
    /// Locks the study folder `dir` (made if missing) against other processes for as long
    /// as the returned lock lives (see [`FolderLock`]); a folder in use is refused at once.
    pub fn lock(dir: &Path) -> Result<FolderLock> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        FolderLock::acquire(dir)
    }

    fn stored_spec(dir: &Path, spec: &StudySpec) -> Result<Stored> {
        let path = dir.join("study.json");
        if std::fs::symlink_metadata(&path).is_err() {
            return Ok(Stored::None);
        }
        let text = crate::input::read_text(&path, crate::input::TEXT_MAX_BYTES)?;
        let manifest = match serde_json::from_str::<Manifest>(&text) {
            Ok(m) if m.format == MANIFEST_FORMAT => m,
            Ok(m) => return Ok(Stored::Corrupt(format!("unknown format {:?}", m.format))),
            Err(e) => return Ok(Stored::Corrupt(crate::input::one_line(&e.to_string()))),
        };
        if &manifest.spec == spec {
            return Ok(Stored::Same);
        }
        // The grids, H values and sample count are not part of a task's identity: a task
        // of the stored study is the same task in this one.
        let extended = StudySpec {
            sizes: spec.sizes.clone(),
            hursts: spec.hursts.clone(),
            samples: spec.samples,
            ..manifest.spec.clone()
        };
        if &extended == spec {
            return Ok(match narrowing(&manifest.spec, spec) {
                Some(left_out) => Stored::Narrower(left_out),
                None => Stored::Extended,
            });
        }
        Ok(Stored::Other(spec_differences(&manifest.spec, spec)))
    }

    /// Checks, without writing, whether `dir` can hold `spec`:
    ///
    /// * `Ok(false)` when it is new or holds the same study (which then resumes; each
    ///   checkpoint is still checked against its task's identity when read), or the same
    ///   study over other grids N, H values or sample count (which is extended: the tasks
    ///   in both keep their checkpoints; a finished BEM task whose sample count changed
    ///   continues from its kept sample curves, a finished MDR task is computed again);
    /// * `Ok(true)` when its checkpoints are to be cleared first: it holds another study
    ///   (or a corrupt `study.json`, or checkpoints without one) and `discard` is set, or
    ///   its `study.json` names another study but no checkpoint holds a sample (that study
    ///   stopped before its first checkpoint: nothing is lost);
    /// * [`Error::NarrowerStudy`] when it holds samples of the same study and `spec` leaves
    ///   out one of its (N, H) or takes fewer samples (its results would shrink: a folder
    ///   only grows), unless `discard`, which then keeps every checkpoint (`Ok(false)`);
    /// * [`Error::ForeignCheckpoint`] when it holds samples of another study, and
    ///   [`Error::Metadata`] when its `study.json` is corrupt and checkpoints hold samples.
    pub fn check(dir: &Path, spec: &StudySpec, discard: bool) -> Result<bool> {
        let stored = Self::stored_spec(dir, spec)?;
        if matches!(stored, Stored::Same | Stored::Extended) {
            return Ok(false);
        }
        if let Stored::Narrower(left_out) = stored {
            // Its checkpoints stay valid (a later run over them reads them back).
            if discard || !Self::holds_samples(dir)? {
                return Ok(false);
            }
            return Err(Error::NarrowerStudy {
                dir: dir.to_path_buf(),
                reason: left_out,
            });
        }
        if !Self::holds_samples(dir)? {
            return Ok(!matches!(stored, Stored::None));
        }
        if discard {
            return Ok(true);
        }
        match stored {
            Stored::None | Stored::Same | Stored::Extended | Stored::Narrower(_) => Ok(false),
            Stored::Other(differences) => Err(Error::ForeignCheckpoint {
                dir: dir.to_path_buf(),
                reason: format!("its study.json has other parameters: {differences}"),
            }),
            Stored::Corrupt(why) => Err(Error::DamagedStudy {
                path: dir.join("study.json"),
                reason: format!("corrupt study file ({why}); restore it"),
            }),
        }
    }

    /// The study to run in `dir` for `spec`: `spec` itself, or, where `dir` holds samples
    /// of the same study with every load solved (no [`StudySpec::sweep_end`]: an α study
    /// made before α sweeps ended early, or with a full sweep), which `spec` would refuse
    /// as another study's, that whole-sweep study, so that the run resumes its checkpoints
    /// (its α are the same, bit for bit, at the cost of the loads past the windows). Never
    /// the other way round: a whole sweep does not take an ended one's samples; and never
    /// when `discard` (the caller discards another study's checkpoints, as in
    /// [`StudyDir::check`]).
    pub fn resumable(dir: &Path, spec: StudySpec, discard: bool) -> StudySpec {
        if discard || spec.sweep_end.is_none() || Self::check(dir, &spec, false).is_ok() {
            return spec;
        }
        let whole = StudySpec {
            sweep_end: None,
            ..spec.clone()
        };
        let resumes = matches!(
            Self::stored_spec(dir, &whole),
            Ok(Stored::Same | Stored::Extended)
        );
        if resumes && Self::holds_samples(dir).unwrap_or(false) {
            whole
        } else {
            spec
        }
    }

    /// Whether any checkpoint in `dir` holds a finished task or a sample. A checkpoint that
    /// cannot be read counts as holding one (nothing is discarded that might matter);
    /// temporary files of unfinished writes do not count.
    fn holds_samples(dir: &Path) -> Result<bool> {
        let folder = dir.join("checkpoint");
        let entries = match std::fs::read_dir(&folder) {
            Ok(entries) => entries,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
            Err(e) => return Err(Error::io(&folder, e)),
        };
        for entry in entries {
            let path = entry.map_err(|e| Error::io(&folder, e))?.path();
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            if name.starts_with('.') || !name.ends_with(".json") {
                continue;
            }
            let value = crate::input::read_text(&path, CHECKPOINT_MAX_BYTES)
                .ok()
                .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok());
            let content = value.as_ref().map(|v| &v["content"]);
            let none = |v: &serde_json::Value| v.as_array().is_none_or(Vec::is_empty);
            let empty = content.is_some_and(|c| {
                c["state"] == "in_progress"
                    && c["samples"].as_array().is_some_and(Vec::is_empty)
                    && none(&c["later"])
            });
            if !empty {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Opens (creating) `dir` for `spec`: a folder with the same spec resumes, a folder with
    /// another study is refused unless `discard`, which deletes its checkpoints (see
    /// [`StudyDir::check`]). Another process must not work in the folder meanwhile: hold
    /// its [`StudyDir::lock`] (as the command-line front end does).
    pub fn open(dir: &Path, spec: &StudySpec, discard: bool) -> Result<Self> {
        if Self::check(dir, spec, discard)? {
            let checkpoints = dir.join("checkpoint");
            match std::fs::remove_dir_all(&checkpoints) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(Error::io(&checkpoints, e))
                }
                _ => {}
            }
        }
        let store = StudyDir {
            dir: dir.to_path_buf(),
            spec: spec.clone(),
            interval: CHECKPOINT_INTERVAL,
            stop: crate::stop::Stop::new(),
        };
        // Every checkpoint already there is verified before the folder is claimed, so that
        // a refused run leaves it exactly as it was.
        for task in spec.tasks() {
            store.load(task)?;
        }
        io::refuse_link(&dir.join("checkpoint"))?;
        std::fs::create_dir_all(dir.join("checkpoint")).map_err(|e| Error::io(dir, e))?;
        let manifest = Manifest {
            format: MANIFEST_FORMAT.into(),
            spec: spec.clone(),
            normalisation: Some(Scales::of(spec.method)),
        };
        io::write_json(&dir.join("study.json"), true, &manifest)?;
        Ok(store)
    }

    /// The study already in `dir`, read without writing anything (to read its
    /// checkpoints, e.g. [`StudyDir::stored_samples`]); an error when `dir` holds no study
    /// or a corrupt `study.json`.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join("study.json");
        let text = crate::input::read_text(&path, crate::input::TEXT_MAX_BYTES)?;
        let manifest = serde_json::from_str::<Manifest>(&text)
            .ok()
            .filter(|m| m.format == MANIFEST_FORMAT)
            .ok_or_else(|| Error::DamagedStudy {
                path: path.clone(),
                reason: "not a study file of this asperity".into(),
            })?;
        Ok(StudyDir {
            dir: dir.to_path_buf(),
            spec: manifest.spec,
            interval: CHECKPOINT_INTERVAL,
            stop: crate::stop::Stop::new(),
        })
    }

    /// Saves tasks in progress at most every `interval` instead of [`CHECKPOINT_INTERVAL`]
    /// (zero: after every batch).
    pub fn with_checkpoint_interval(mut self, interval: std::time::Duration) -> Self {
        self.interval = interval;
        self
    }

    /// Tasks run on this folder ([`run_task`], [`run_any_task_with_loads`]) stop once
    /// `stop` is requested: between samples, and (BEM) within a solver iteration; the
    /// samples finished by then are checkpointed and the task ends with
    /// [`Error::Interrupted`] (or the interrupted sample's error).
    pub fn with_stop(mut self, stop: crate::stop::Stop) -> Self {
        self.stop = stop;
        self
    }

    /// The stop request the tasks run on this folder poll ([`StudyDir::with_stop`]).
    pub fn stop(&self) -> &crate::stop::Stop {
        &self.stop
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Refuses a symbolic link in place of the checkpoint folder or of the checkpoint
    /// `path`: a link planted in the study folder would redirect the study's writes.
    fn refuse_links(&self, path: &Path) -> Result<()> {
        io::refuse_link(&self.dir.join("checkpoint"))?;
        io::refuse_link(path)
    }

    fn checkpoint_path(&self, task: Task) -> PathBuf {
        let key = task.key(self.spec.method);
        self.dir.join("checkpoint").join(format!("{key}.json"))
    }

    /// The checkpoint of `task`, if any: refused unless intact (its checksum) and made by
    /// this task with this study's settings (its identity).
    fn load(&self, task: Task) -> Result<Option<Checkpoint>> {
        let path = self.checkpoint_path(task);
        self.refuse_links(&path)?;
        let length = match std::fs::metadata(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(Error::io(&path, e)),
            Ok(meta) => meta.len(),
        };
        // The text and its parsed samples (about as large again).
        crate::memory::ensure_fits(
            &format!("reading the checkpoint {}", path.display()),
            length.checked_mul(3),
        )?;
        let text = crate::input::read_text(&path, CHECKPOINT_MAX_BYTES)?;
        let wanted = TaskIdentity::of(&self.spec, task);
        let refuse = |what: String| Error::DamagedStudy {
            path: path.clone(),
            reason: format!("{what}; delete it to recompute its task"),
        };
        match identity::unseal::<Checkpoint>(text.as_bytes(), &wanted) {
            Ok(checkpoint) => Ok(Some(checkpoint)),
            Err(Unsealed::Corrupt(why)) => Err(refuse(format!("corrupt checkpoint ({why})"))),
            Err(Unsealed::Checksum) => Err(refuse(
                "the checkpoint does not match its checksum (edited or damaged)".into(),
            )),
            Err(Unsealed::Foreign(differences)) => Err(Error::ForeignCheckpoint {
                dir: self.dir.clone(),
                reason: format!(
                    "{} was made with other settings: {}",
                    path.display(),
                    differences.join(", ")
                ),
            }),
        }
    }

    fn save(&self, task: Task, checkpoint: &Checkpoint) -> Result<()> {
        let path = self.checkpoint_path(task);
        self.refuse_links(&path)?;
        let bytes =
            identity::seal(&TaskIdentity::of(&self.spec, task), checkpoint).map_err(|reason| {
                Error::Metadata {
                    path: path.clone(),
                    reason,
                }
            })?;
        io::write_bytes(&path, true, &bytes)
    }

    /// Saves the first samples of `task`, in progress.
    pub fn save_in_progress(&self, task: Task, samples: &[SampleCurve]) -> Result<()> {
        self.save(
            task,
            &Checkpoint::InProgress {
                samples: samples.to_vec(),
                later: Vec::new(),
            },
        )
    }

    /// Saves the samples of `task` received so far, in progress: `slots[i]` is sample `i`
    /// if received. For front ends that receive samples out of index order (e.g. from
    /// other processes), so that a sample beyond a missing one is kept too.
    pub fn save_received(&self, task: Task, slots: &[Option<SampleCurve>]) -> Result<()> {
        let first = slots.iter().take_while(|s| s.is_some()).count();
        let later = slots
            .iter()
            .enumerate()
            .skip(first)
            .filter_map(|(index, s)| {
                s.as_ref().map(|sample| LaterSample {
                    index,
                    sample: sample.clone(),
                })
            })
            .collect();
        self.save(
            task,
            &Checkpoint::InProgress {
                samples: slots[..first].iter().flatten().cloned().collect(),
                later,
            },
        )
    }
}

/// What `spec`, the same study as `stored` over other N, H or samples, leaves out of
/// it: `None` when it covers every (N, H) of `stored` with at least its samples (it grows
/// the study), else e.g. `N = 4096 (stored 4096, wanted 2048)`.
fn narrowing(stored: &StudySpec, spec: &StudySpec) -> Option<String> {
    let mut left_out = Vec::new();
    let sizes: Vec<usize> = (stored.sizes.iter())
        .filter(|n| !spec.sizes.contains(n))
        .copied()
        .collect();
    if !sizes.is_empty() {
        left_out.push(format!(
            "N = {sizes:?} (stored {:?}, wanted {:?})",
            stored.sizes, spec.sizes
        ));
    }
    let hursts: Vec<f64> = (stored.hursts.iter())
        .filter(|h| !spec.hursts.iter().any(|w| w.to_bits() == h.to_bits()))
        .copied()
        .collect();
    if !hursts.is_empty() {
        left_out.push(format!(
            "H = {hursts:?} (stored {:?}, wanted {:?})",
            stored.hursts, spec.hursts
        ));
    }
    if spec.samples < stored.samples {
        left_out.push(format!(
            "samples (stored {}, wanted {})",
            stored.samples, spec.samples
        ));
    }
    (!left_out.is_empty()).then(|| left_out.join(", "))
}

/// The fields of two specs that differ, as `name: stored X, wanted Y`.
fn spec_differences(stored: &StudySpec, wanted: &StudySpec) -> String {
    let map = |s: &StudySpec| match serde_json::to_value(s) {
        Ok(serde_json::Value::Object(m)) => m,
        _ => serde_json::Map::new(),
    };
    let (a, b) = (map(stored), map(wanted));
    let clip = |v: &serde_json::Value| crate::input::clip(&v.to_string());
    let null = serde_json::Value::Null;
    // A key on one side only (an optional field left out) differs from `null`.
    let only_wanted = b.iter().filter(|(k, _)| !a.contains_key(*k));
    let items: Vec<String> = a
        .iter()
        .map(|(k, v)| (k, v, b.get(k).unwrap_or(&null)))
        .chain(only_wanted.map(|(k, w)| (k, &null, w)))
        .filter(|(_, v, w)| v != w)
        .map(|(k, v, w)| format!("{k}: stored {}, wanted {}", clip(v), clip(w)))
        .collect();
    items.join(", ")
}

/// Progress of a task: `progress(done, total)` with the samples done so far and the
/// task's total. The first call of a task (before any sample is computed) reports the
/// samples read back from its checkpoint — all of them for a finished task — and every
/// later call the samples done after another batch computed in this run, so a caller can
/// tell restored samples from computed ones (e.g. for a rate or an ETA).
pub type ProgressFn<'a> = dyn Fn(usize, usize) + Sync + 'a;

/// Runs (or resumes) one task: samples in parallel batches, one worker per thread kept for
/// the whole task, a checkpoint at most every [`CHECKPOINT_INTERVAL`] (or the store's own
/// interval) and the result saved
/// when the task ends. A finished task is read back, not recomputed.
pub fn run_task<S: Sampler>(
    spec: &StudySpec,
    task: Task,
    sampler: &S,
    store: &StudyDir,
    progress: &ProgressFn,
) -> Result<TaskResult> {
    if &store.spec != spec {
        return Err(Error::invalid(
            "spec",
            "the study folder was opened for another study",
        ));
    }
    let mut samples = match store.restore(task)? {
        Restored::Done(result) => {
            progress(spec.samples, spec.samples);
            return Ok(result);
        }
        Restored::Partial(samples) => samples,
    };
    progress(samples.len(), spec.samples);
    let sampler = &UntilStopped {
        inner: sampler,
        store,
    };
    let mut workers = lane_workers(sampler)?;
    let batch = batch_size(spec.method, task.n, workers.len());
    let mut last_save = std::time::Instant::now();
    while samples.len() < spec.samples {
        if store.stop.is_requested() {
            store.save_in_progress(task, &samples)?;
            return Err(Error::Interrupted {
                dir: store.dir.clone(),
            });
        }
        let indices: Vec<usize> =
            (samples.len()..(samples.len() + batch).min(spec.samples)).collect();
        let computed = sample_on_lanes(spec, task, sampler, &mut workers, &indices);
        let held = samples.len();
        if let Err(error) = take_finished(&mut samples, computed) {
            // The samples finished before the one that failed (or was interrupted) are
            // kept, whenever the last checkpoint was.
            if samples.len() > held {
                store.save_in_progress(task, &samples)?;
            }
            return Err(error);
        }
        if samples.len() < spec.samples && last_save.elapsed() >= store.interval {
            store.save_in_progress(task, &samples)?;
            last_save = std::time::Instant::now();
        }
        progress(samples.len(), spec.samples);
    }
    store.finish(task, samples)
}

/// A sampler that starts no sample once the store's stop is requested (Ctrl-C, or a
/// front end's cancel): the samples in flight end (a BEM sample's solver polls the same
/// flag), those not yet started fail as [`Error::Interrupted`], and [`run_task`] keeps
/// the finished ones before them. Which samples are computed changes, never a number.
struct UntilStopped<'a, S> {
    inner: &'a S,
    store: &'a StudyDir,
}

impl<S: Sampler> Sampler for UntilStopped<'_, S> {
    type Worker = S::Worker;

    fn worker(&self) -> Result<S::Worker> {
        self.inner.worker()
    }

    fn sample(&self, worker: &mut S::Worker, seed: u64) -> Result<SampleCurve> {
        if self.store.stop.is_requested() {
            return Err(Error::Interrupted {
                dir: self.store.dir.clone(),
            });
        }
        self.inner.sample(worker, seed)
    }
}

/// Appends the samples of a batch, in index order, up to the first that failed; returns
/// that one's error.
fn take_finished(samples: &mut Vec<SampleCurve>, batch: Vec<Result<SampleCurve>>) -> Result<()> {
    for sample in batch {
        samples.push(sample?);
    }
    Ok(())
}

/// Samples computed between two chances to checkpoint and report progress: four per
/// lane for cheap samples (fewer pauses), one per lane from BEM on 256² on, where a
/// sample takes seconds to minutes, so that an interrupted task loses at most about one
/// sample's time per lane and the progress bar moves every sample. Samples depend on
/// their seed only, so the batch size never changes a number.
fn batch_size(method: Method, n: usize, lanes: usize) -> usize {
    let per_lane = if sample_cost(method, n) >= sample_cost(Method::Bem, 256) {
        1
    } else {
        4
    };
    per_lane * lanes.max(1)
}

/// One worker of `sampler` per thread of the current rayon pool.
fn lane_workers<S: Sampler>(sampler: &S) -> Result<Vec<S::Worker>> {
    let lanes = rayon::current_num_threads().max(1);
    (0..lanes).map(|_| sampler.worker()).collect()
}

/// The samples `indices` of `task`, in that order, computed in parallel by the workers,
/// one task per worker that takes the next sample not yet taken until none is left
/// (self-scheduling: samples of one task differ in cost by tens of per cent, and with fixed
/// chunks a worker given the costlier samples, or slowed by another process, held the
/// batch up while the other waited). Each sample depends on its seed only
/// ([`sample_seed`]), not on the worker or on what that worker computed before, so the
/// scheduling changes the time, never the numbers.
fn sample_on_lanes<S: Sampler>(
    spec: &StudySpec,
    task: Task,
    sampler: &S,
    workers: &mut [S::Worker],
    indices: &[usize],
) -> Vec<Result<SampleCurve>> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let taken = || next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let done: Vec<Vec<(usize, Result<SampleCurve>)>> = workers
        .par_iter_mut()
        .map(|worker| {
            std::iter::from_fn(|| Some(taken()))
                .take_while(|&slot| slot < indices.len())
                .map(|slot| {
                    let seed = sample_seed(spec.seed, spec.method, task, indices[slot]);
                    (slot, sampler.sample(worker, seed))
                })
                .collect()
        })
        .collect();
    let mut slots: Vec<(usize, Result<SampleCurve>)> = done.into_iter().flatten().collect();
    slots.sort_unstable_by_key(|&(slot, _)| slot);
    slots.into_iter().map(|(_, sample)| sample).collect()
}

/// What a task's checkpoint holds, as [`StudyDir::restore`] reads it.
#[derive(Debug, Clone, PartialEq)]
pub enum Restored {
    /// The task is finished: its result.
    Done(TaskResult),
    /// The task's first samples (none for a task not started), in index order.
    Partial(Vec<SampleCurve>),
}

/// What a task's checkpoint holds, sample by sample, as [`StudyDir::restore_received`]
/// reads it.
#[derive(Debug, Clone, PartialEq)]
pub enum Received {
    /// The task is finished: its result.
    Done(TaskResult),
    /// One slot per sample: those saved so far.
    Partial(Vec<Option<SampleCurve>>),
}

impl StudyDir {
    /// The checkpoint of `task`, read and verified as [`run_task`] reads it: the result of
    /// a finished task, or the samples saved so far (at most the study's sample count).
    /// For front ends that compute a task's samples elsewhere (e.g. on other processes)
    /// and keep its checkpoint with [`StudyDir::save_in_progress`] and
    /// [`StudyDir::finish`].
    pub fn restore(&self, task: Task) -> Result<Restored> {
        self.restore_as(task, self.spec.samples)
    }

    /// How many samples of `task` a run asking for `samples` of them reads back from its
    /// checkpoint instead of computing ([`StudyDir::restore`] with that count): what a
    /// progress bar or a run-time estimate leaves out before the run.
    pub fn samples_held(&self, task: Task, samples: usize) -> Result<usize> {
        Ok(match self.restore_as(task, samples)? {
            Restored::Done(_) => samples,
            Restored::Partial(held) => held.len(),
        })
    }

    /// [`StudyDir::restore`] for a run asking for `count` samples of `task`.
    fn restore_as(&self, task: Task, count: usize) -> Result<Restored> {
        match self.load(task)? {
            Some(Checkpoint::Done { result, .. }) if result.samples == count => {
                Ok(Restored::Done(result))
            }
            // Samples saved beyond a gap are left out: the serial run computes in index
            // order (they are computed again, to the same bits). A finished task that kept
            // its sample curves (BEM) and now has another sample count continues from them:
            // sample i depends only on the seed and i, so the result is that of a fresh run.
            Some(Checkpoint::InProgress { mut samples, .. })
            | Some(Checkpoint::Done { mut samples, .. }) => {
                samples.truncate(count);
                Ok(Restored::Partial(samples))
            }
            None => Ok(Restored::Partial(Vec::new())),
        }
    }

    /// The checkpoint of `task` sample by sample: the result of a finished task, or one
    /// slot per sample of the study holding the samples saved so far, in and out of index
    /// order ([`StudyDir::save_received`]).
    pub fn restore_received(&self, task: Task) -> Result<Received> {
        let count = self.spec.samples;
        let mut slots = vec![None; count];
        match self.load(task)? {
            Some(Checkpoint::Done { result, .. }) if result.samples == count => {
                return Ok(Received::Done(result))
            }
            Some(Checkpoint::InProgress { samples, later }) => {
                for (slot, sample) in slots.iter_mut().zip(samples) {
                    *slot = Some(sample);
                }
                for LaterSample { index, sample } in later {
                    if let Some(slot) = slots.get_mut(index) {
                        *slot = Some(sample);
                    }
                }
            }
            // A finished task kept with another sample count continues from its curves
            // (as in [`StudyDir::restore`]).
            Some(Checkpoint::Done { samples, .. }) => {
                for (slot, sample) in slots.iter_mut().zip(samples) {
                    *slot = Some(sample);
                }
            }
            None => {}
        }
        Ok(Received::Partial(slots))
    }

    /// Ends `task` with all its `samples` (in index order): its result, saved as
    /// [`run_task`] saves it, so that the checkpoint is the same file byte for byte.
    pub fn finish(&self, task: Task, samples: Vec<SampleCurve>) -> Result<TaskResult> {
        if samples.len() != self.spec.samples {
            return Err(Error::invalid(
                "samples",
                format!(
                    "a task ends with its {} samples, got {}",
                    self.spec.samples,
                    samples.len()
                ),
            ));
        }
        let result = TaskResult::from_samples(&self.spec, task, &samples)?;
        let samples = match self.spec.method {
            Method::Bem => samples,
            Method::Mdr => Vec::new(),
        };
        self.save(
            task,
            &Checkpoint::Done {
                result: result.clone(),
                samples,
            },
        )?;
        Ok(result)
    }

    /// The sample curves of `task` stored in its checkpoint, in index order: those of a
    /// finished BEM task, or those saved so far of a task in progress; empty when none
    /// are stored (no checkpoint, a finished MDR task, or a checkpoint written before
    /// finished tasks kept their samples).
    pub fn stored_samples(&self, task: Task) -> Result<Vec<SampleCurve>> {
        Ok(match self.load(task)? {
            Some(Checkpoint::Done { samples, .. })
            | Some(Checkpoint::InProgress { samples, .. }) => samples,
            None => Vec::new(),
        })
    }

    /// The longest time between two checkpoints of a task in progress.
    pub fn checkpoint_interval(&self) -> std::time::Duration {
        self.interval
    }

    /// The study this folder was opened for.
    pub fn spec(&self) -> &StudySpec {
        &self.spec
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A study of one task (N = `n`, H = 0.5, 3 samples) in a new folder, opened.
    fn three_sample_study(method: Method, n: usize) -> (StudySpec, tempfile::TempDir, StudyDir) {
        let spec = StudySpec {
            method,
            sizes: vec![n],
            hursts: vec![0.5],
            samples: 3,
            rolloff: None,
            seed: 3,
            window: FitWindow::default(),
            levels: 16,
            sweep_end: None,
        };
        let dir = tempfile::tempdir().unwrap();
        let store = StudyDir::open(dir.path(), &spec, false).unwrap();
        (spec, dir, store)
    }

    #[test]
    fn samples_held_are_what_a_run_of_that_size_reads_back() {
        // A finished task of 3 samples: a run of 3 reads back all 3; a run of 2 or 5
        // continues from the kept curves (BEM: 2 and 3 of them) or, without kept curves
        // (MDR), recomputes everything.
        for (method, n, other) in [(Method::Bem, 16, [2, 3]), (Method::Mdr, 512, [0, 0])] {
            let (spec, _dir, store) = three_sample_study(method, n);
            let task = spec.tasks()[0];
            assert_eq!(store.samples_held(task, 3).unwrap(), 0);
            run_any_task(&spec, task, &store, &|_, _| {}).unwrap();
            let held: Vec<usize> = [3, 2, 5]
                .iter()
                .map(|&wanted| store.samples_held(task, wanted).unwrap())
                .collect();
            assert_eq!(held, [3, other[0], other[1]], "{method:?}");
        }
    }

    #[test]
    fn finished_bem_tasks_keep_their_sample_curves_and_mdr_tasks_do_not() {
        for (method, n, kept) in [(Method::Bem, 16, true), (Method::Mdr, 512, false)] {
            let (spec, dir, store) = three_sample_study(method, n);
            let task = spec.tasks()[0];
            let result = run_any_task(&spec, task, &store, &|_, _| {}).unwrap();
            let stored = StudyDir::read(dir.path())
                .unwrap()
                .stored_samples(task)
                .unwrap();
            if kept {
                // The stored curves give the finished result again, bit for bit.
                assert_eq!(stored.len(), 3);
                assert_eq!(
                    TaskResult::from_samples(&spec, task, &stored).unwrap(),
                    result
                );
            } else {
                assert!(stored.is_empty());
            }
        }
        assert!(StudyDir::read(tempfile::tempdir().unwrap().path()).is_err());
    }

    #[test]
    fn a_finished_bem_task_grows_from_its_kept_curves_to_a_fresh_runs_result() {
        let spec = |samples| StudySpec {
            method: Method::Bem,
            sizes: vec![16],
            hursts: vec![0.5],
            samples,
            rolloff: None,
            seed: 5,
            window: FitWindow::default(),
            levels: 16,
            sweep_end: None,
        };
        let (small, grown) = (spec(3), spec(5));
        let task = small.tasks()[0];
        let dir = tempfile::tempdir().unwrap();
        let store = StudyDir::open(dir.path(), &small, false).unwrap();
        run_any_task(&small, task, &store, &|_, _| {}).unwrap();
        drop(store);
        let kept = StudyDir::read(dir.path())
            .unwrap()
            .stored_samples(task)
            .unwrap();
        let store = StudyDir::open(dir.path(), &grown, false).unwrap();
        match store.restore(task).unwrap() {
            Restored::Partial(samples) => assert_eq!(samples, kept, "the 3 kept curves"),
            Restored::Done(_) => panic!("a task of 3 samples is not done at 5"),
        }
        let grown_result = run_any_task(&grown, task, &store, &|_, _| {}).unwrap();
        let fresh_dir = tempfile::tempdir().unwrap();
        let fresh = StudyDir::open(fresh_dir.path(), &grown, false).unwrap();
        assert_eq!(
            run_any_task(&grown, task, &fresh, &|_, _| {}).unwrap(),
            grown_result
        );
        // Shrinking would leave samples out of the results: refused unless discarding
        // (force), which keeps the checkpoint and takes its first samples: again a fresh
        // run's result.
        let err = StudyDir::open(dir.path(), &small, false).unwrap_err();
        assert!(matches!(err, Error::NarrowerStudy { .. }), "{err}");
        let store = StudyDir::open(dir.path(), &small, true).unwrap();
        let shrunk = run_any_task(&small, task, &store, &|_, _| {}).unwrap();
        let fresh_dir = tempfile::tempdir().unwrap();
        let fresh = StudyDir::open(fresh_dir.path(), &small, false).unwrap();
        assert_eq!(
            run_any_task(&small, task, &fresh, &|_, _| {}).unwrap(),
            shrunk
        );
    }

    #[test]
    fn seeds_differ_by_task_and_index_only() {
        let t = Task { n: 512, hurst: 0.5 };
        let a = sample_seed(1, Method::Mdr, t, 0);
        assert_eq!(a, sample_seed(1, Method::Mdr, t, 0));
        assert_ne!(a, sample_seed(1, Method::Mdr, t, 1));
        assert_ne!(a, sample_seed(2, Method::Mdr, t, 0));
        assert_ne!(a, sample_seed(1, Method::Bem, t, 0));
        assert_ne!(
            a,
            sample_seed(1, Method::Mdr, Task { n: 512, hurst: 0.6 }, 0)
        );
    }

    fn spec(samples: usize) -> StudySpec {
        StudySpec {
            method: Method::Mdr,
            sizes: vec![64],
            hursts: vec![0.5],
            samples,
            rolloff: None,
            seed: 3,
            window: FitWindow {
                min_contacts: 1,
                max_fraction: 1.0,
            },
            levels: 10,
            sweep_end: None,
        }
    }

    #[test]
    fn validation_rejects_bad_studies() {
        assert!(spec(0).validate().is_err());
        let mut s = spec(3);
        s.hursts.clear();
        assert!(s.validate().is_err());
        s.hursts = vec![4.0];
        assert!(s.validate().is_err());
        s.hursts = vec![0.5];
        s.sizes = vec![2];
        assert!(s.validate().is_err());
        s.sizes = vec![64];
        for end in [0.0, -0.1, 1.5, f64::NAN, f64::INFINITY] {
            s.sweep_end = Some(end);
            let err = s.validate().unwrap_err().to_string();
            assert!(err.contains("sweep_end"), "{end}: {err}");
        }
        s.sweep_end = Some(1.0);
        s.validate().unwrap();
    }

    #[test]
    fn an_alpha_sweep_ends_past_every_window_it_may_be_fitted_on() {
        let mut s = spec(3);
        s.method = Method::Bem;
        s.window = FitWindow::default();
        s.sizes = vec![128, 64];
        // 4 × the sensitivity table's 2 % (above the default window's 1 %).
        assert_eq!(s.clone().with_alpha_sweep().sweep_end, Some(0.08));
        s.window.max_fraction = 0.05;
        assert_eq!(s.clone().with_alpha_sweep().sweep_end, Some(0.2));
        // On a 16² grid, 16 contacts are 6.25 % and the window spans 4× that: 25 %, so
        // the sweep would end past full contact, and solves every load.
        s.window.max_fraction = 0.01;
        s.sizes = vec![64, 16];
        assert_eq!(s.clone().with_alpha_sweep().sweep_end, None);
        s.sizes = vec![32];
        let end = s.clone().with_alpha_sweep().sweep_end.unwrap();
        assert!((end - 4.0 * 4.0 * 16.0 / 1024.0).abs() < 1e-15, "{end}");
        // MDR curves cost one pass whatever their length: no sweep to end.
        s.method = Method::Mdr;
        assert_eq!(s.with_alpha_sweep().sweep_end, None);
    }

    #[test]
    fn repeated_or_colliding_values_are_refused() {
        let message = |s: &StudySpec| s.validate().unwrap_err().to_string();
        let mut s = spec(3);
        s.sizes = vec![64, 128, 64];
        assert!(
            message(&s).contains("N = 64 is given twice"),
            "{}",
            message(&s)
        );
        s.sizes = vec![64];
        s.hursts = vec![0.5, 1.0, 0.5];
        assert!(
            message(&s).contains("H = 0.5 is given twice"),
            "{}",
            message(&s)
        );
        s.hursts = vec![0.0, -0.0];
        assert!(s.validate().is_err(), "0 and -0 are one H");
        // Distinct values that round to the same checkpoint name: both named.
        s.hursts = vec![0.5000001, 0.5000002];
        let m = message(&s);
        assert!(m.contains("0.5000001") && m.contains("0.5000002"), "{m}");
        s.hursts = vec![0.500001, 0.500002];
        s.validate().unwrap();
        assert_ne!(s.tasks()[0].key(Method::Mdr), s.tasks()[1].key(Method::Mdr));
    }

    #[test]
    fn a_checkpoint_of_another_task_under_the_same_name_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let spec = spec(5);
        let store = StudyDir::open(dir.path(), &spec, false).unwrap();
        let stored = Task {
            n: 64,
            hurst: 0.5000001,
        };
        let asked = Task {
            n: 64,
            hurst: 0.5000002,
        };
        assert_eq!(stored.key(Method::Mdr), asked.key(Method::Mdr));
        // In progress.
        let first = vec![Synthetic.sample(&mut (), 1).unwrap()];
        store.save_in_progress(stored, &first).unwrap();
        let err = run_task(&spec, asked, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
        assert!(err.to_string().contains("0.5000001"), "{err}");
        // Finished.
        run_task(&spec, stored, &Synthetic, &store, &|_, _| {}).unwrap();
        let err = run_task(&spec, asked, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
        // The stored task itself is read back.
        run_task(&spec, stored, &Synthetic, &store, &|_, _| {}).unwrap();
    }

    /// An ended sweep resumes the whole sweep whose samples the folder holds (the same
    /// study otherwise, or that study extended); never another study's, never a folder
    /// without samples, and never the other way round.
    #[test]
    fn an_ended_sweep_resumes_the_whole_sweep_a_folder_holds() {
        let dir = tempfile::tempdir().unwrap();
        let whole = spec(4);
        let ended = StudySpec {
            sweep_end: Some(0.08),
            ..spec(4)
        };
        // study.json alone: the folder is free, the ended sweep runs as asked.
        let store = StudyDir::open(dir.path(), &whole, false).unwrap();
        assert_eq!(StudyDir::resumable(dir.path(), ended.clone(), false), ended);
        let one = vec![Synthetic.sample(&mut (), 1).unwrap()];
        store
            .save_in_progress(Task { n: 64, hurst: 0.5 }, &one)
            .unwrap();
        assert_eq!(StudyDir::resumable(dir.path(), ended.clone(), false), whole);
        assert_eq!(StudyDir::resumable(dir.path(), ended.clone(), true), ended);
        // The same with more samples (the study extended) ...
        let more = StudySpec {
            samples: 9,
            ..ended.clone()
        };
        let resumed = StudyDir::resumable(dir.path(), more.clone(), false);
        assert_eq!((resumed.sweep_end, resumed.samples), (None, 9));
        StudyDir::open(dir.path(), &resumed, false).unwrap();
        // ... but not with another seed, nor a whole sweep in an ended one's folder.
        let other = StudySpec { seed: 9, ..more };
        assert_eq!(StudyDir::resumable(dir.path(), other.clone(), false), other);
        let ended_dir = tempfile::tempdir().unwrap();
        let store = StudyDir::open(ended_dir.path(), &ended, false).unwrap();
        store
            .save_in_progress(Task { n: 64, hurst: 0.5 }, &one)
            .unwrap();
        assert_eq!(
            StudyDir::resumable(ended_dir.path(), whole.clone(), false),
            whole
        );
        assert!(StudyDir::open(ended_dir.path(), &whole, false).is_err());
    }

    #[test]
    fn a_folder_without_samples_is_free_for_another_study() {
        let dir = tempfile::tempdir().unwrap();
        // study.json written, then stopped before any checkpoint.
        StudyDir::open(dir.path(), &spec(20), false).unwrap();
        let store = StudyDir::open(dir.path(), &spec(21), false).unwrap();
        // An in-progress checkpoint without samples keeps nothing either.
        store
            .save_in_progress(Task { n: 64, hurst: 0.5 }, &[])
            .unwrap();
        let store = StudyDir::open(dir.path(), &spec(22), false).unwrap();
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("study.json")).unwrap()).unwrap();
        assert_eq!(manifest["spec"]["samples"], 22);
        assert_eq!(manifest["normalisation"]["rms_height"], 1.0);
        // One sample makes it another study's again.
        let one = vec![Synthetic.sample(&mut (), 1).unwrap()];
        store
            .save_in_progress(Task { n: 64, hurst: 0.5 }, &one)
            .unwrap();
        // (Another seed: more samples alone would extend the study.)
        let other = StudySpec {
            seed: 7,
            ..spec(23)
        };
        let err = StudyDir::open(dir.path(), &other, false).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
        // A file that cannot be read counts as holding samples.
        std::fs::write(dir.path().join("checkpoint/x.json"), "{").unwrap();
        std::fs::remove_file(dir.path().join("checkpoint").join(format!(
            "{}.json",
            Task { n: 64, hurst: 0.5 }.key(Method::Mdr)
        )))
        .unwrap();
        assert!(StudyDir::open(dir.path(), &other, false).is_err());
    }

    /// Fails (and requests `stop`) on the sample whose seed is `failing`.
    struct FailsAt {
        failing: u64,
        stop: crate::stop::Stop,
    }

    impl Sampler for FailsAt {
        type Worker = ();
        fn worker(&self) -> Result<()> {
            Ok(())
        }
        fn sample(&self, worker: &mut (), seed: u64) -> Result<SampleCurve> {
            if seed == self.failing {
                self.stop.request();
                return Err(Error::invalid("sample", "interrupted"));
            }
            Synthetic.sample(worker, seed)
        }
    }

    /// Item 8 of issue 33: a task stopped early (Ctrl-C) or by a failed sample keeps the
    /// samples it finished, though no checkpoint interval has passed.
    #[test]
    fn an_interrupted_task_checkpoints_the_samples_it_finished() {
        let task = Task { n: 64, hurst: 0.5 };
        let dir = tempfile::tempdir().unwrap();
        let stop = crate::stop::Stop::new();
        let store = StudyDir::open(dir.path(), &spec(20), false)
            .unwrap()
            .with_stop(stop.clone());
        let failing = FailsAt {
            failing: sample_seed(3, Method::Mdr, task, 6),
            stop: stop.clone(),
        };
        assert!(run_task(&spec(20), task, &failing, &store, &|_, _| {}).is_err());
        let Restored::Partial(held) = store.restore(task).unwrap() else {
            panic!("not finished")
        };
        assert_eq!(held.len(), 6, "samples 0 to 5 kept");
        // Resumed with the stop still requested: nothing computed, nothing lost.
        let err = run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(matches!(err, Error::Interrupted { .. }), "{err}");
        assert_eq!(store.samples_held(task, 20).unwrap(), 6);
        stop.clear();
        let resumed = run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap();
        let fresh = {
            let other = tempfile::tempdir().unwrap();
            let store = StudyDir::open(other.path(), &spec(20), false).unwrap();
            run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap()
        };
        assert_eq!(resumed, fresh);
    }

    #[cfg(unix)]
    #[test]
    fn links_in_place_of_checkpoints_are_refused_and_their_targets_untouched() {
        let task = Task { n: 64, hurst: 0.5 };
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim.json");
        std::fs::write(&victim, "precious").unwrap();
        let store = StudyDir::open(dir.path(), &spec(4), false).unwrap();
        std::os::unix::fs::symlink(&victim, checkpoint_file(dir.path(), task)).unwrap();
        let sample = Synthetic.sample(&mut (), 1).unwrap();
        let err = store.save_in_progress(task, &[sample]).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert!(StudyDir::open(dir.path(), &spec(4), false).is_err());
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
        // A link in place of the checkpoint folder.
        let elsewhere = tempfile::tempdir().unwrap();
        let linked = tempfile::tempdir().unwrap();
        std::os::unix::fs::symlink(elsewhere.path(), linked.path().join("checkpoint")).unwrap();
        let err = StudyDir::open(linked.path(), &spec(4), false).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert_eq!(std::fs::read_dir(elsewhere.path()).unwrap().count(), 0);
    }

    fn checkpoint_file(dir: &Path, task: Task) -> PathBuf {
        dir.join("checkpoint")
            .join(format!("{}.json", task.key(Method::Mdr)))
    }

    #[test]
    fn checkpoints_of_older_versions_are_refused_not_merged() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let store = StudyDir::open(dir.path(), &spec(4), false).unwrap();
        // The format before identities: key, task and samples, no checksum.
        let old = serde_json::json!({
            "state": "in_progress",
            "key": task.key(Method::Mdr),
            "task": task,
            "samples": [Synthetic.sample(&mut (), 1).unwrap()],
        });
        std::fs::write(checkpoint_file(dir.path(), task), old.to_string()).unwrap();
        let err = run_task(&spec(4), task, &Synthetic, &store, &|_, _| {}).unwrap_err();
        let text = err.to_string();
        assert!(
            matches!(err, Error::DamagedStudy { .. }) && text.contains("older asperity"),
            "{text}"
        );
        // Discarding (force) clears it.
        let mut other = spec(4);
        other.seed = 9;
        StudyDir::open(dir.path(), &other, true).unwrap();
        assert!(!checkpoint_file(dir.path(), task).exists());
    }

    /// Item 1 of issue 9: a checkpoint copied from another study, or left by a study whose
    /// study.json was deleted, is refused naming every field that differs; an edited or
    /// damaged one is refused by its checksum.
    #[test]
    fn checkpoints_carry_their_identity_and_checksum() {
        let task = Task { n: 64, hurst: 0.5 };
        let first = tempfile::tempdir().unwrap();
        let store = StudyDir::open(first.path(), &spec(6), false).unwrap();
        store
            .save_in_progress(task, &[Synthetic.sample(&mut (), 1).unwrap()])
            .unwrap();
        let saved = std::fs::read(checkpoint_file(first.path(), task)).unwrap();
        type Change = Box<dyn Fn(&mut StudySpec)>;
        let variants: Vec<(&str, Change)> = vec![
            ("seed", Box::new(|s| s.seed = 4)),
            ("rolloff", Box::new(|s| s.rolloff = Some(6.0))),
            ("levels", Box::new(|s| s.levels = 11)),
            (
                "window.min_contacts",
                Box::new(|s| s.window.min_contacts = 2),
            ),
            ("sweep_end", Box::new(|s| s.sweep_end = Some(0.08))),
        ];
        for (field, change) in variants {
            let mut other = spec(6);
            change(&mut other);
            let dir = tempfile::tempdir().unwrap();
            let store = StudyDir::open(dir.path(), &other, false).unwrap();
            // No study.json from the first study: only the copied checkpoint.
            std::fs::write(checkpoint_file(dir.path(), task), &saved).unwrap();
            let err = run_task(&other, task, &Synthetic, &store, &|_, _| {}).unwrap_err();
            assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
            let text = err.to_string();
            assert!(
                text.contains(&format!("{field}: stored")),
                "{field}: {text}"
            );
            assert!(!text.contains('\n'));
            // Refused, not merged: the copied file is left as it was.
            assert_eq!(
                std::fs::read(checkpoint_file(dir.path(), task)).unwrap(),
                saved
            );
        }
        // A hand edit that keeps valid JSON: a changed stiffness.
        let text = String::from_utf8(saved.clone()).unwrap();
        let at = text.find("\"stiffness\":").unwrap() + 12;
        let mut edited = text.clone();
        edited.insert(at, '9');
        std::fs::write(checkpoint_file(first.path(), task), edited).unwrap();
        let err = run_task(&spec(6), task, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(err.to_string().contains("checksum"), "{err}");
        // Truncated: corrupt.
        std::fs::write(
            checkpoint_file(first.path(), task),
            &saved[..saved.len() / 2],
        )
        .unwrap();
        let err = run_task(&spec(6), task, &Synthetic, &store, &|_, _| {}).unwrap_err();
        assert!(err.to_string().contains("corrupt checkpoint"), "{err}");
        // Intact: resumed.
        std::fs::write(checkpoint_file(first.path(), task), &saved).unwrap();
        run_task(&spec(6), task, &Synthetic, &store, &|_, _| {}).unwrap();
    }

    #[test]
    fn a_corrupt_study_json_is_named_as_such() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let store = StudyDir::open(dir.path(), &spec(4), false).unwrap();
        store
            .save_in_progress(task, &[Synthetic.sample(&mut (), 1).unwrap()])
            .unwrap();
        std::fs::write(dir.path().join("study.json"), "{\"format\": \"asp").unwrap();
        let err = StudyDir::check(dir.path(), &spec(4), false)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("corrupt study file") && !err.contains("other parameters"),
            "{err}"
        );
        // Another study's parameters are named.
        let mut other = spec(4);
        other.seed = 77;
        StudyDir::open(dir.path(), &spec(4), true).unwrap();
        store
            .save_in_progress(task, &[Synthetic.sample(&mut (), 1).unwrap()])
            .unwrap();
        let err = StudyDir::check(dir.path(), &other, false)
            .unwrap_err()
            .to_string();
        assert!(err.contains("seed: stored 3, wanted 77"), "{err}");
    }

    #[test]
    fn sizes_and_ranges_are_bounded_up_front() {
        // Item 7: 1e12 levels, an absurd sample count (ranges: the CLI's `range`).
        let mut s = spec(3);
        s.levels = 1_000_000_000_000;
        let err = s.validate().unwrap_err().to_string();
        assert!(err.contains("force levels"), "{err}");
        s.levels = 10;
        s.samples = usize::MAX / 2;
        s.hursts = vec![0.1, 0.2, 0.3];
        let err = s.validate().unwrap_err().to_string();
        assert!(err.contains("samples a study may hold"), "{err}");
    }

    #[test]
    fn duplicate_h_checking_is_linear() {
        // Item 9: 40 001 values (the quadratic check took minutes at this size).
        // H = -1, -0.9999, ..., 3 (rounded as the CLI's ranges are, so that 0.5 is exact).
        let hursts: Vec<f64> = (0..=40_000)
            .map(|i| ((-1.0 + i as f64 * 1e-4) * 1e12).round() / 1e12)
            .collect();
        assert_eq!(hursts.len(), 40_001);
        let mut s = spec(1);
        s.hursts = hursts;
        let start = std::time::Instant::now();
        s.validate().unwrap();
        assert!(
            start.elapsed() < std::time::Duration::from_secs(2),
            "{:?}",
            start.elapsed()
        );
        s.hursts.push(0.5);
        assert!(s
            .validate()
            .unwrap_err()
            .to_string()
            .contains("given twice"));
    }

    #[test]
    fn sample_costs_grow_with_n() {
        assert!(sample_cost(Method::Bem, 128) / sample_cost(Method::Bem, 64) > 4.0);
        let mdr = sample_cost(Method::Mdr, 1 << 15) / sample_cost(Method::Mdr, 1 << 9);
        assert!((mdr - 64.0 * 15.0 / 9.0).abs() < 1e-9);
    }

    /// A sampler whose curve is a deterministic function of the seed.
    struct Synthetic;
    impl Sampler for Synthetic {
        type Worker = ();
        fn worker(&self) -> Result<()> {
            Ok(())
        }
        fn sample(&self, _: &mut (), seed: u64) -> Result<SampleCurve> {
            let c = 1.0 + (seed % 1000) as f64 / 1000.0;
            let points = (1..50)
                .map(|j| {
                    let force = j as f64 * c;
                    CurvePoint {
                        fraction: j as f64 / 64.0,
                        force,
                        stiffness: force.sqrt(),
                    }
                })
                .collect();
            Ok(SampleCurve {
                points_total: 64,
                points,
                piecewise_constant: false,
            })
        }
    }

    #[test]
    fn costly_samples_checkpoint_after_one_per_lane() {
        assert_eq!(batch_size(Method::Mdr, 1 << 15, 2), 8);
        assert_eq!(batch_size(Method::Bem, 128, 2), 8);
        assert_eq!(batch_size(Method::Bem, 256, 2), 2);
        assert_eq!(batch_size(Method::Bem, 1024, 16), 16);
    }

    #[test]
    fn a_study_grows_by_grids_h_values_and_samples_reusing_its_checkpoints() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let run = |spec: &StudySpec| -> Vec<TaskResult> {
            let store = StudyDir::open(dir.path(), spec, false).unwrap();
            spec.tasks()
                .into_iter()
                .map(|t| run_task(spec, t, &Synthetic, &store, &|_, _| {}).unwrap())
                .collect()
        };
        let first = run(&spec(6));
        let path = dir
            .path()
            .join("checkpoint")
            .join(format!("{}.json", task.key(Method::Mdr)));
        let modified = || std::fs::metadata(&path).unwrap().modified().unwrap();
        let before = modified();
        // Another N and another H: the finished task is read back, not recomputed.
        let wider = StudySpec {
            sizes: vec![64, 128],
            hursts: vec![0.5, 1.0],
            ..spec(6)
        };
        let grown = run(&wider);
        assert_eq!(grown.len(), 4);
        assert_eq!(grown[0], first[0], "the stored task, bit for bit");
        assert_eq!(modified(), before, "its checkpoint untouched");
        // More samples: that task again, now with 9, equal to a fresh study of 9.
        let more = StudySpec {
            samples: 9,
            ..wider.clone()
        };
        let extended = run(&more);
        let fresh = {
            let other = tempfile::tempdir().unwrap();
            let store = StudyDir::open(other.path(), &more, false).unwrap();
            run_task(&more, task, &Synthetic, &store, &|_, _| {}).unwrap()
        };
        assert_eq!(extended[0], fresh);
        // Anything else still makes another study.
        let rolled = StudySpec {
            rolloff: Some(2.0),
            ..more
        };
        let err = StudyDir::open(dir.path(), &rolled, false).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
    }

    #[test]
    fn foreign_checkpoint_is_refused_and_resume_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let full = {
            let store = StudyDir::open(dir.path(), &spec(20), false).unwrap();
            run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap()
        };
        // A different study in the same folder is refused and nothing is lost.
        let other_seed = StudySpec {
            seed: 4,
            ..spec(20)
        };
        let err = StudyDir::open(dir.path(), &other_seed, false).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
        assert!(
            err.to_string().contains("seed: stored 3, wanted 4"),
            "{err}"
        );
        // A field the stored spec leaves out (an optional one) is named too.
        let ended = StudySpec {
            sweep_end: Some(0.5),
            ..spec(20)
        };
        let err = StudyDir::open(dir.path(), &ended, false).unwrap_err();
        assert!(
            err.to_string()
                .contains("sweep_end: stored null, wanted 0.5"),
            "{err}"
        );
        assert!(dir
            .path()
            .join("checkpoint")
            .join(format!("{}.json", task.key(Method::Mdr)))
            .exists());
        // Interrupted run: keep only the first 7 samples in the checkpoint, then resume.
        let other = tempfile::tempdir().unwrap();
        let store = StudyDir::open(other.path(), &spec(20), false).unwrap();
        let first: Vec<SampleCurve> = (0..7)
            .map(|i| {
                let seed = sample_seed(3, Method::Mdr, task, i);
                Synthetic.sample(&mut (), seed).unwrap()
            })
            .collect();
        store.save_in_progress(task, &first).unwrap();
        let resumed = run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap();
        assert_eq!(resumed, full);
        let a = serde_json::to_string(&resumed).unwrap();
        assert_eq!(a, serde_json::to_string(&full).unwrap(), "bit for bit");
    }
}
