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
//! different study is refused ([`Error::ForeignCheckpoint`]) unless `discard` is set.

pub mod curve;
pub mod samplers;
pub mod theory;

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

pub use curve::{
    ensemble_alpha, ensemble_curve, quantile, CurvePoint, EnsemblePoint, FitWindow, SampleCurve,
};
pub use samplers::run_any_task;

use crate::fit::PowerLawFit;
use crate::spectrum::HURST_RANGE;
use crate::{io, Error, Result};

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
}

impl StudySpec {
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
        if self.samples == 0 {
            return Err(Error::invalid("samples", "need at least 1 sample"));
        }
        if let Some(q0) = self.rolloff {
            if !(q0.is_finite() && q0 > 0.0) {
                return Err(Error::invalid(
                    "rolloff",
                    format!("must be positive, got {q0}"),
                ));
            }
        }
        if self.levels < 3 {
            return Err(Error::invalid("levels", "need at least 3 force levels"));
        }
        self.window.validate()
    }

    /// All tasks, sizes outer, H inner.
    pub fn tasks(&self) -> Vec<Task> {
        self.sizes
            .iter()
            .flat_map(|&n| self.hursts.iter().map(move |&hurst| Task { n, hurst }))
            .collect()
    }
}

/// Parses Hurst exponents: comma-separated items, each a value or an inclusive range
/// `A:B:STEP` (e.g. `-1:0:0.5,0.8,2:3:1`).
pub fn parse_range(text: &str) -> Result<Vec<f64>> {
    let mut values = Vec::new();
    for item in text.split(',') {
        values.extend(parse_range_item(item)?);
    }
    Ok(values)
}

fn parse_range_item(text: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = text.split(':').collect();
    let num = |s: &str| {
        s.trim()
            .parse::<f64>()
            .map_err(|_| Error::invalid("hurst", format!("'{s}' is not a number in '{text}'")))
    };
    match parts.as_slice() {
        [single] => Ok(vec![num(single)?]),
        [a, b, step] => {
            let (a, b, step) = (num(a)?, num(b)?, num(step)?);
            if step.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || b < a {
                return Err(Error::invalid(
                    "hurst",
                    format!("empty range '{text}' (need A <= B and STEP > 0)"),
                ));
            }
            let count = ((b - a) / step + 1e-9).floor() as usize + 1;
            // Round to 1e-12 so that 0.1-steps print and key cleanly.
            Ok((0..count)
                .map(|i| ((a + step * i as f64) * 1e12).round() / 1e12)
                .collect())
        }
        _ => Err(Error::invalid(
            "hurst",
            format!("'{text}' is neither a value nor A:B:STEP"),
        )),
    }
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
    /// File-name key, e.g. `mdr_n512_h-0.2500`.
    pub fn key(&self, method: Method) -> String {
        format!("{}_n{}_h{:+.6}", method.name(), self.n, self.hurst)
    }
}

fn splitmix64(mut x: u64) -> u64 {
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
    pub fn from_samples(spec: &StudySpec, task: Task, samples: Vec<SampleCurve>) -> Result<Self> {
        let mean_curve = ensemble_curve(&samples, spec.levels)?;
        let alpha_ensemble = ensemble_alpha(&samples, &spec.window, spec.levels);
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
}

/// What `checkpoint/<task>.json` holds: the samples of a task in progress, or the result
/// of a finished one (its sample curves are then no longer kept).
#[derive(Debug, Serialize, Deserialize)]
#[serde(tag = "state", rename_all = "snake_case")]
enum Checkpoint {
    InProgress {
        key: String,
        samples: Vec<SampleCurve>,
    },
    Done {
        key: String,
        result: TaskResult,
    },
}

impl Checkpoint {
    fn key(&self) -> &str {
        match self {
            Checkpoint::InProgress { key, .. } | Checkpoint::Done { key, .. } => key,
        }
    }
}

/// A task in progress saves its samples at most this often (and always when it ends), so
/// that fast tasks (MDR) do not spend their time rewriting checkpoints.
pub const CHECKPOINT_INTERVAL: std::time::Duration = std::time::Duration::from_secs(10);

const MANIFEST_FORMAT: &str = "asperity-study/1";

/// Where a study keeps its spec and checkpoints.
#[derive(Debug, Clone)]
pub struct StudyDir {
    dir: PathBuf,
    interval: std::time::Duration,
}

impl StudyDir {
    /// Checks, without writing, whether `dir` can hold `spec`: `Ok(false)` when it is new
    /// or holds the same study, `Ok(true)` when it holds another study and `discard` is
    /// set, [`Error::ForeignCheckpoint`] otherwise.
    pub fn check(dir: &Path, spec: &StudySpec, discard: bool) -> Result<bool> {
        let manifest_path = dir.join("study.json");
        if !manifest_path.exists() {
            return Ok(false);
        }
        let text =
            std::fs::read_to_string(&manifest_path).map_err(|e| Error::io(&manifest_path, e))?;
        let same = serde_json::from_str::<Manifest>(&text)
            .map(|m| m.format == MANIFEST_FORMAT && &m.spec == spec)
            .unwrap_or(false);
        match (same, discard) {
            (true, _) => Ok(false),
            (false, true) => Ok(true),
            (false, false) => Err(Error::ForeignCheckpoint {
                dir: dir.to_path_buf(),
                reason: "its study.json has other parameters".into(),
            }),
        }
    }

    /// Opens (creating) `dir` for `spec`: a folder with the same spec resumes, a folder with
    /// another study is refused unless `discard`, which deletes its checkpoints.
    pub fn open(dir: &Path, spec: &StudySpec, discard: bool) -> Result<Self> {
        if Self::check(dir, spec, discard)? {
            let checkpoints = dir.join("checkpoint");
            std::fs::remove_dir_all(&checkpoints).map_err(|e| Error::io(&checkpoints, e))?;
        }
        std::fs::create_dir_all(dir.join("checkpoint")).map_err(|e| Error::io(dir, e))?;
        let manifest_path = dir.join("study.json");
        let manifest = Manifest {
            format: MANIFEST_FORMAT.into(),
            spec: spec.clone(),
        };
        io::write_json(&manifest_path, true, &manifest)?;
        Ok(StudyDir {
            dir: dir.to_path_buf(),
            interval: CHECKPOINT_INTERVAL,
        })
    }

    /// Saves tasks in progress at most every `interval` instead of [`CHECKPOINT_INTERVAL`]
    /// (zero: after every batch).
    pub fn with_checkpoint_interval(mut self, interval: std::time::Duration) -> Self {
        self.interval = interval;
        self
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    fn checkpoint_path(&self, key: &str) -> PathBuf {
        self.dir.join("checkpoint").join(format!("{key}.json"))
    }

    fn load(&self, key: &str) -> Result<Option<Checkpoint>> {
        let path = self.checkpoint_path(key);
        if !path.exists() {
            return Ok(None);
        }
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        let checkpoint: Checkpoint = serde_json::from_str(&text).map_err(|e| Error::Metadata {
            path: path.clone(),
            reason: format!("unreadable checkpoint: {e}"),
        })?;
        if checkpoint.key() != key {
            return Err(Error::ForeignCheckpoint {
                dir: self.dir.clone(),
                reason: format!("{} is not {key}", path.display()),
            });
        }
        Ok(Some(checkpoint))
    }

    fn save(&self, checkpoint: &Checkpoint) -> Result<()> {
        let path = self.checkpoint_path(checkpoint.key());
        let text = serde_json::to_vec(checkpoint).map_err(|e| Error::Metadata {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        io::write_bytes(&path, true, &text)
    }

    /// Saves the first samples of a task in progress.
    pub fn save_in_progress(&self, key: &str, samples: &[SampleCurve]) -> Result<()> {
        self.save(&Checkpoint::InProgress {
            key: key.to_string(),
            samples: samples.to_vec(),
        })
    }
}

/// Progress of a study: samples done so far (including resumed ones) and the total.
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
    let key = task.key(spec.method);
    let mut samples = match store.load(&key)? {
        Some(Checkpoint::Done { result, .. }) if result.samples == spec.samples => {
            progress(spec.samples, spec.samples);
            return Ok(result);
        }
        Some(Checkpoint::InProgress { samples, .. }) => samples,
        _ => Vec::new(),
    };
    samples.truncate(spec.samples);
    progress(samples.len(), spec.samples);
    let lanes = rayon::current_num_threads().max(1);
    let mut workers = (0..lanes)
        .map(|_| sampler.worker())
        .collect::<Result<Vec<_>>>()?;
    let batch = 4 * lanes;
    let mut last_save = std::time::Instant::now();
    while samples.len() < spec.samples {
        let indices: Vec<usize> =
            (samples.len()..(samples.len() + batch).min(spec.samples)).collect();
        let per_lane = indices.len().div_ceil(lanes);
        let done: Vec<Vec<Result<SampleCurve>>> = workers
            .par_iter_mut()
            .zip(indices.par_chunks(per_lane))
            .map(|(worker, chunk)| {
                chunk
                    .iter()
                    .map(|&index| {
                        sampler.sample(worker, sample_seed(spec.seed, spec.method, task, index))
                    })
                    .collect()
            })
            .collect();
        for curve in done.into_iter().flatten() {
            samples.push(curve?);
        }
        if samples.len() < spec.samples && last_save.elapsed() >= store.interval {
            store.save_in_progress(&key, &samples)?;
            last_save = std::time::Instant::now();
        }
        progress(samples.len(), spec.samples);
    }
    let result = TaskResult::from_samples(spec, task, samples)?;
    store.save(&Checkpoint::Done {
        key,
        result: result.clone(),
    })?;
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_inclusive_and_validated() {
        assert_eq!(
            parse_range("-1:3:0.5").unwrap(),
            vec![-1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]
        );
        assert_eq!(parse_range("0.1:0.3:0.1").unwrap(), vec![0.1, 0.2, 0.3]);
        assert_eq!(parse_range("0.8").unwrap(), vec![0.8]);
        assert_eq!(parse_range("-0.5,0.5:1:0.5").unwrap(), vec![-0.5, 0.5, 1.0]);
        assert!(parse_range("").is_err());
        assert!(parse_range("1:0:0.1").is_err(), "empty range");
        assert!(parse_range("0:1:0").is_err());
        assert!(parse_range("a:b").is_err());
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
    fn foreign_checkpoint_is_refused_and_resume_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let full = {
            let store = StudyDir::open(dir.path(), &spec(20), false).unwrap();
            run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap()
        };
        // A different study in the same folder is refused and nothing is lost.
        let err = StudyDir::open(dir.path(), &spec(21), false).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
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
        store
            .save_in_progress(&task.key(Method::Mdr), &first)
            .unwrap();
        let resumed = run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap();
        assert_eq!(resumed, full);
        let a = serde_json::to_string(&resumed).unwrap();
        assert_eq!(a, serde_json::to_string(&full).unwrap(), "bit for bit");
    }
}
