//! How a study runs: the [`Sampler`] of a method, one task run (or resumed) in parallel
//! batches on lanes of workers with checkpoints ([`run_task`]), and its [`TaskResult`].

use super::*;

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
pub(super) struct UntilStopped<'a, S> {
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
pub(super) fn take_finished(
    samples: &mut Vec<SampleCurve>,
    batch: Vec<Result<SampleCurve>>,
) -> Result<()> {
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
pub(super) fn batch_size(method: Method, n: usize, lanes: usize) -> usize {
    let per_lane = if sample_cost(method, n) >= sample_cost(Method::Bem, 256) {
        1
    } else {
        4
    };
    per_lane * lanes.max(1)
}

/// One worker of `sampler` per thread of the current rayon pool.
pub(super) fn lane_workers<S: Sampler>(sampler: &S) -> Result<Vec<S::Worker>> {
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
pub(super) fn sample_on_lanes<S: Sampler>(
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
