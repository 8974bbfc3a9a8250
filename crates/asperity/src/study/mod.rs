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
//! different study is refused ([`Error::ForeignCheckpoint`]) unless `discard` is set; a
//! folder whose `study.json` names another study but whose checkpoints hold no sample (a
//! study that stopped before its first checkpoint) is free and reused. Every checkpoint
//! names its task, and a checkpoint whose task is not the one requested (bit for bit) is
//! refused rather than silently reused.
//!
//! `study.json` also records the scales of the samples (`normalisation`, see
//! [`samplers::Scales`]); it is informative only and not compared on resume, so folders
//! written before it existed resume as before.

pub mod curve;
pub mod samplers;
pub mod theory;

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

pub use curve::{
    ensemble_alpha, ensemble_curve, quantile, CurvePoint, EnsemblePoint, FitWindow, SampleCurve,
};
pub use samplers::{run_any_task, Scales};

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
        for (i, n) in self.sizes.iter().enumerate() {
            if self.sizes[..i].contains(n) {
                return Err(Error::invalid("n", format!("N = {n} is given twice")));
            }
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
        for (i, &h) in self.hursts.iter().enumerate() {
            for &earlier in &self.hursts[..i] {
                if earlier == h {
                    return Err(Error::invalid("hurst", format!("H = {h} is given twice")));
                }
                if hurst_key(earlier) == hurst_key(h) {
                    return Err(Error::invalid(
                        "hurst",
                        format!(
                            "H = {earlier} and H = {h} would share one checkpoint (H is kept \
                             to 6 decimals in its name, {}); give values at least 1e-6 apart",
                            hurst_key(h)
                        ),
                    ));
                }
            }
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
    /// Scales of the samples; informative, not compared on resume (absent in folders
    /// written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    normalisation: Option<Scales>,
}

/// What `checkpoint/<task>.json` holds: the samples of a task in progress, or the result
/// of a finished one (its sample curves are then no longer kept).
#[derive(Debug, Serialize, Deserialize)]
#[serde(tag = "state", rename_all = "snake_case")]
enum Checkpoint {
    InProgress {
        key: String,
        /// The task (absent in checkpoints written before it was recorded).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        task: Option<Task>,
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

    /// The task it holds, where recorded.
    fn task(&self) -> Option<Task> {
        match self {
            Checkpoint::InProgress { task, .. } => *task,
            Checkpoint::Done { result, .. } => Some(result.task),
        }
    }

    /// Whether it holds anything worth keeping: a finished task or at least one sample.
    fn holds_samples(&self) -> bool {
        match self {
            Checkpoint::InProgress { samples, .. } => !samples.is_empty(),
            Checkpoint::Done { .. } => true,
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
    method: Method,
    interval: std::time::Duration,
}

impl StudyDir {
    /// Checks, without writing, whether `dir` can hold `spec`:
    ///
    /// * `Ok(false)` when it is new or holds the same study (which then resumes);
    /// * `Ok(true)` when its checkpoints are to be cleared first: it holds another study
    ///   and `discard` is set, or its `study.json` names another study but no checkpoint
    ///   holds a sample (that study stopped before its first checkpoint: nothing is lost);
    /// * [`Error::ForeignCheckpoint`] when it holds samples of another study.
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
        if same {
            return Ok(false);
        }
        if discard || !Self::holds_samples(dir)? {
            return Ok(true);
        }
        Err(Error::ForeignCheckpoint {
            dir: dir.to_path_buf(),
            reason: "its study.json has other parameters".into(),
        })
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
            let holds = std::fs::read_to_string(&path)
                .ok()
                .and_then(|text| serde_json::from_str::<Checkpoint>(&text).ok())
                .is_none_or(|c| c.holds_samples());
            if holds {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Opens (creating) `dir` for `spec`: a folder with the same spec resumes, a folder with
    /// another study is refused unless `discard`, which deletes its checkpoints (see
    /// [`StudyDir::check`]).
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
        std::fs::create_dir_all(dir.join("checkpoint")).map_err(|e| Error::io(dir, e))?;
        let manifest_path = dir.join("study.json");
        let manifest = Manifest {
            format: MANIFEST_FORMAT.into(),
            spec: spec.clone(),
            normalisation: Some(Scales::of(spec.method)),
        };
        io::write_json(&manifest_path, true, &manifest)?;
        Ok(StudyDir {
            dir: dir.to_path_buf(),
            method: spec.method,
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

    /// The checkpoint of `task`, if any; refused when the file holds another task (its
    /// name or, where recorded, its N and H bit for bit).
    fn load(&self, task: Task) -> Result<Option<Checkpoint>> {
        let key = task.key(self.method);
        let path = self.checkpoint_path(&key);
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
        if let Some(stored) = checkpoint.task().filter(|stored| !stored.same_as(&task)) {
            return Err(Error::ForeignCheckpoint {
                dir: self.dir.clone(),
                reason: format!(
                    "{} holds N = {}, H = {}, not the requested N = {}, H = {}",
                    path.display(),
                    stored.n,
                    stored.hurst,
                    task.n,
                    task.hurst
                ),
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

    /// Saves the first samples of `task`, in progress.
    pub fn save_in_progress(&self, task: Task, samples: &[SampleCurve]) -> Result<()> {
        self.save(&Checkpoint::InProgress {
            key: task.key(self.method),
            task: Some(task),
            samples: samples.to_vec(),
        })
    }
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
    let key = task.key(spec.method);
    let mut samples = match store.load(task)? {
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
            store.save_in_progress(task, &samples)?;
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
        let err = StudyDir::open(dir.path(), &spec(23), false).unwrap_err();
        assert!(matches!(err, Error::ForeignCheckpoint { .. }), "{err}");
        // A file that cannot be read counts as holding samples.
        std::fs::write(dir.path().join("checkpoint/x.json"), "{").unwrap();
        std::fs::remove_file(dir.path().join("checkpoint").join(format!(
            "{}.json",
            Task { n: 64, hurst: 0.5 }.key(Method::Mdr)
        )))
        .unwrap();
        assert!(StudyDir::open(dir.path(), &spec(23), false).is_err());
    }

    #[test]
    fn study_json_written_before_the_normalisation_was_recorded_resumes() {
        let dir = tempfile::tempdir().unwrap();
        let task = Task { n: 64, hurst: 0.5 };
        let store = StudyDir::open(dir.path(), &spec(4), false).unwrap();
        let first = vec![Synthetic.sample(&mut (), 1).unwrap()];
        store.save_in_progress(task, &first).unwrap();
        // The old format: no normalisation, no task in the checkpoint.
        let old = serde_json::json!({"format": MANIFEST_FORMAT, "spec": spec(4)});
        std::fs::write(dir.path().join("study.json"), old.to_string()).unwrap();
        let path = dir
            .path()
            .join("checkpoint")
            .join(format!("{}.json", task.key(Method::Mdr)));
        let mut checkpoint: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
        checkpoint.as_object_mut().unwrap().remove("task");
        std::fs::write(&path, checkpoint.to_string()).unwrap();
        let store = StudyDir::open(dir.path(), &spec(4), false).unwrap();
        let restored = std::sync::Mutex::new(Vec::new());
        run_task(&spec(4), task, &Synthetic, &store, &|done, _| {
            restored.lock().unwrap().push(done)
        })
        .unwrap();
        assert_eq!(
            restored.into_inner().unwrap()[0],
            1,
            "the sample was resumed"
        );
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
        store.save_in_progress(task, &first).unwrap();
        let resumed = run_task(&spec(20), task, &Synthetic, &store, &|_, _| {}).unwrap();
        assert_eq!(resumed, full);
        let a = serde_json::to_string(&resumed).unwrap();
        assert_eq!(a, serde_json::to_string(&full).unwrap(), "bit for bit");
    }
}
