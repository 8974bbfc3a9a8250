//! Ensemble studies (`asperity study alpha|curve`) in the CLI's checkpoint folders.
//!
//! [`run_study`] follows the CLI's `execute` (crates/asperity-cli/src/commands/study.rs):
//! validate the spec, check memory, open the folder (same `study.json`, same
//! `checkpoint/<task>.json`, same checkpoint interval), run every task with the library's
//! `run_task`. A study started here resumes from the CLI and the other way round. Two
//! differences: it writes no `alpha.csv`/`curve.csv` or plots (the results are returned),
//! and its sampler is wrapped by [`Interruptible`], which skips the samples not yet started
//! once Ctrl-C (or an exception of the progress callback) cancelled the run, so that a
//! study stops after the samples in flight; the checkpoints already written stay.

use std::path::PathBuf;
use std::time::Duration;

use asperity::study::samplers::{BemSampler, MdrSampler};
use asperity::study::theory::alpha_theory;
use asperity::study::{
    parse_range, run_task, FitWindow, Method, SampleCurve, Sampler, StudyDir, StudySpec, Task,
    TaskResult, MAX_CHECKPOINT_INTERVAL_SECONDS,
};
use asperity::Error;
use pyo3::prelude::*;
use serde_json::json;

use crate::errors::{from_error, invalid};
use crate::interrupt::{run_detached, Cancel};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run_study, m)?)?;
    m.add_function(wrap_pyfunction!(hurst_range, m)?)?;
    m.add_function(wrap_pyfunction!(default_window, m)?)?;
    Ok(())
}

/// A sampler that skips its samples once the run is cancelled.
struct Interruptible<'a, S> {
    inner: S,
    cancel: &'a Cancel,
}

impl<S: Sampler> Sampler for Interruptible<'_, S> {
    type Worker = S::Worker;

    fn worker(&self) -> asperity::Result<S::Worker> {
        self.inner.worker()
    }

    fn sample(&self, worker: &mut S::Worker, seed: u64) -> asperity::Result<SampleCurve> {
        if self.cancel.is_set() {
            return Err(Error::invalid("study", "interrupted"));
        }
        self.inner.sample(worker, seed)
    }
}

/// `hurst` values from the CLI's syntax: values and ranges `A:B:STEP`, comma-separated.
#[pyfunction]
fn hurst_range(text: &str) -> PyResult<Vec<f64>> {
    parse_range(text).map_err(from_error)
}

/// The default α window `(min_contacts, max_fraction)`.
#[pyfunction]
fn default_window() -> (usize, f64) {
    let w = FitWindow::default();
    (w.min_contacts, w.max_fraction)
}

fn method(name: &str) -> PyResult<Method> {
    match name {
        "mdr" => Ok(Method::Mdr),
        "bem" => Ok(Method::Bem),
        other => Err(invalid(format!(
            "invalid method {other:?}: expected mdr or bem"
        ))),
    }
}

/// Runs (or resumes) a study in `out`; returns the task results as JSON text, each with
/// the CLI's derived columns (`alpha_sample_interval`, `alpha_sample_mean`, `alpha_theory`).
#[pyfunction]
#[pyo3(signature = (method_name, sizes, hursts, samples, rolloff, seed, min_contacts,
    max_fraction, levels, out, force, checkpoint_every, progress))]
#[allow(clippy::too_many_arguments)]
fn run_study(
    py: Python<'_>,
    method_name: &str,
    sizes: Vec<usize>,
    hursts: Vec<f64>,
    samples: usize,
    rolloff: Option<f64>,
    seed: u64,
    min_contacts: usize,
    max_fraction: f64,
    levels: usize,
    out: PathBuf,
    force: bool,
    checkpoint_every: f64,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    if !(0.0..=MAX_CHECKPOINT_INTERVAL_SECONDS).contains(&checkpoint_every) {
        return Err(invalid(format!(
            "checkpoint_every must be between 0 and {MAX_CHECKPOINT_INTERVAL_SECONDS:e} \
             seconds, got {checkpoint_every}"
        )));
    }
    let spec = StudySpec {
        method: method(method_name)?,
        sizes,
        hursts,
        samples,
        rolloff,
        seed,
        window: FitWindow {
            min_contacts,
            max_fraction,
        },
        levels,
    };
    spec.validate().map_err(from_error)?;
    spec.ensure_fits().map_err(from_error)?;
    StudyDir::check(&out, &spec, force).map_err(from_error)?;
    // Held until the study returns: a second process (CLI or Python) on the folder is
    // refused at once, naming this one's PID.
    let _lock = StudyDir::lock(&out).map_err(from_error)?;
    let store = StudyDir::open(&out, &spec, force)
        .map_err(from_error)?
        .with_checkpoint_interval(Duration::from_secs_f64(checkpoint_every));
    let results = run_detached(py, |cancel| {
        run_tasks(&spec, &store, progress.as_ref(), cancel)
    })?
    .map_err(from_error)?;
    let records: Vec<serde_json::Value> = results
        .iter()
        .map(|r| {
            json!({
                "result": r,
                "alpha_sample_interval": r.alpha_sample_interval(),
                "alpha_sample_mean": r.alpha_sample_mean(),
                "alpha_theory": alpha_theory(r.task.hurst, r.task.n),
            })
        })
        .collect();
    Ok(serde_json::Value::from(records).to_string())
}

/// Every task in order, as the CLI's `execute`; progress counts samples over all tasks.
fn run_tasks(
    spec: &StudySpec,
    store: &StudyDir,
    progress: Option<&Py<PyAny>>,
    cancel: &Cancel,
) -> asperity::Result<Vec<TaskResult>> {
    let tasks = spec.tasks();
    let total = tasks.len() * spec.samples;
    let mut results = Vec::with_capacity(tasks.len());
    for (i, &task) in tasks.iter().enumerate() {
        let offset = i * spec.samples;
        let report = |done: usize, _: usize| cancel.call(progress, offset + done, total);
        let result = match spec.method {
            Method::Bem => run_one(
                spec,
                task,
                // Stops inside a sample's solve, not only between samples.
                BemSampler::new(spec, task)?.with_stop(cancel.stop().clone()),
                store,
                &report,
                cancel,
            ),
            Method::Mdr => run_one(
                spec,
                task,
                MdrSampler::new(spec, task)?,
                store,
                &report,
                cancel,
            ),
        };
        let result = result.map_err(|e| match e {
            // The CLI's context: `mdr N = 512 H = 0.5: ...`.
            Error::Solve { context, source } => Error::Solve {
                context: format!(
                    "{} N = {} H = {}: {context}",
                    spec.method.name(),
                    task.n,
                    task.hurst
                ),
                source,
            },
            other => other,
        })?;
        results.push(result);
        if cancel.is_set() {
            break;
        }
    }
    Ok(results)
}

fn run_one<S: Sampler>(
    spec: &StudySpec,
    task: Task,
    sampler: S,
    store: &StudyDir,
    report: &(dyn Fn(usize, usize) + Sync),
    cancel: &Cancel,
) -> asperity::Result<TaskResult> {
    let sampler = Interruptible {
        inner: sampler,
        cancel,
    };
    run_task(spec, task, &sampler, store, report)
}
