//! Ensemble studies (`asperity study alpha|curve`) in the CLI's checkpoint folders.
//!
//! [`run_study`] runs the protocol of the front-end layer ([`asperity_app::study`]) that
//! the CLI's `asperity study` runs: the same validation, the same `study.json` and
//! `checkpoint/<task>.json`, the same checkpoint interval, the same tasks in the same
//! order and the same result tables. A study started here resumes from the CLI and the
//! other way round. It writes no `alpha.csv`/`curve.csv` or plots (the tables are
//! returned), and Ctrl-C (or an exception of the progress callback) stops it after the
//! samples in flight; the checkpoints already written stay.

use std::path::PathBuf;

use asperity::lock::FolderLock;
use asperity::stop::Stop;
use asperity::study::{
    Ledger, Method, SampleCurve, StudyDir, StudySpec, Task, TaskResult, TaskSamples,
    CHECKPOINT_INTERVAL,
};
use asperity::Error;
use asperity_app::study::progress::StudyProgress;
use asperity_app::study::{self, rows, Kind, TaskFailure};
use asperity_app::Names;
use pyo3::prelude::*;
use serde_json::json;

use crate::errors::{from_error, invalid, refused, request_error};
use crate::interrupt::{run_detached, run_detached_with, Cancel};
use asperity_app::range::parse_range;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run_study, m)?)?;
    m.add_function(wrap_pyfunction!(hurst_range, m)?)?;
    m.add_function(wrap_pyfunction!(comparison_columns, m)?)?;
    m.add_function(wrap_pyfunction!(thread_count, m)?)?;
    m.add_class::<StudyLedger>()?;
    m.add_class::<SampleComputer>()?;
    Ok(())
}

/// `hurst` values from the CLI's syntax: values and ranges `A:B:STEP`, comma-separated.
#[pyfunction]
fn hurst_range(text: &str) -> PyResult<Vec<f64>> {
    parse_range(text).map_err(from_error)
}

/// The columns of `comparison.csv`, `(name, type)` with type `text`, `count` or `number`
/// ([`rows::COMPARISON_COLUMNS`]): the names and types of `StudyResult.comparison()`.
#[pyfunction]
fn comparison_columns() -> Vec<(&'static str, String)> {
    rows::COMPARISON_COLUMNS
        .iter()
        .map(|(name, kind)| {
            let kind = serde_json::to_value(kind).expect("column types serialise");
            (*name, kind.as_str().unwrap_or_default().to_string())
        })
        .collect()
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

/// Runs (or resumes) a study in `out`; returns the task results and the result tables
/// (`alpha.csv`'s and `curve.csv`'s) as JSON text ([`records`]).
#[pyfunction]
#[pyo3(signature = (method_name, sizes, hursts, samples, rolloff, seed, min_contacts,
    max_fraction, levels, alpha_sweep, out, force, checkpoint_every, progress))]
#[allow(clippy::too_many_arguments)]
fn run_study(
    py: Python<'_>,
    method_name: &str,
    sizes: Vec<usize>,
    hursts: Vec<f64>,
    samples: usize,
    rolloff: Option<f64>,
    seed: Option<u64>,
    min_contacts: Option<usize>,
    max_fraction: Option<f64>,
    levels: Option<usize>,
    alpha_sweep: bool,
    out: PathBuf,
    force: bool,
    checkpoint_every: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let spec = make_spec(
        method_name,
        (sizes, hursts, samples),
        rolloff,
        seed,
        (min_contacts, max_fraction, levels),
        alpha_sweep,
    )?;
    let interval = checkpoint_interval(checkpoint_every)?;
    let spec = resumable(py, spec, &out, force)?;
    study::validate(&spec).map_err(request_error)?;
    // The flag that Ctrl-C raises: the samples poll it.
    let stop = Stop::new();
    let (_lock, store) = open_folder(&spec, out, force, interval, stop.clone())?;
    let plan = StudyProgress::of(&store).map_err(from_error)?;
    let results = run_detached_with(py, &stop, |cancel| {
        run_tasks(&store, &plan, progress.as_ref(), cancel)
    })?
    .map_err(|failure| from_error(failure.into_error()))?;
    Ok(records(&spec, store.path(), &results))
}

/// A study's spec from `run_study`'s arguments (`alpha_sweep`: an α study's load sweep,
/// [`Kind::spec`]), not yet validated: `(sizes, hursts, samples)` as given, and the seed,
/// the α window and the levels as given or, where `None`, [`StudySpec::default`]'s — the
/// defaults of `asperity study`, which live there only.
fn make_spec(
    method_name: &str,
    (sizes, hursts, samples): (Vec<usize>, Vec<f64>, usize),
    rolloff: Option<f64>,
    seed: Option<u64>,
    (min_contacts, max_fraction, levels): (Option<usize>, Option<f64>, Option<usize>),
    alpha_sweep: bool,
) -> PyResult<StudySpec> {
    let defaults = StudySpec::default();
    let mut window = defaults.window;
    window.min_contacts = min_contacts.unwrap_or(window.min_contacts);
    window.max_fraction = max_fraction.unwrap_or(window.max_fraction);
    let spec = StudySpec {
        method: method(method_name)?,
        sizes,
        hursts,
        samples,
        rolloff,
        seed: seed.unwrap_or(defaults.seed),
        window,
        levels: levels.unwrap_or(defaults.levels),
        ..defaults
    };
    Ok(Kind::Alpha.spec(spec, !alpha_sweep))
}

/// The checkpoint interval: `checkpoint_every` seconds by the front-end layer's rule, or
/// where `None` the CLI's default ([`CHECKPOINT_INTERVAL`]).
fn checkpoint_interval(checkpoint_every: Option<f64>) -> PyResult<std::time::Duration> {
    match checkpoint_every {
        Some(seconds) => study::checkpoint_interval(seconds).map_err(refused),
        None => Ok(CHECKPOINT_INTERVAL),
    }
}

/// The study to run in `out` ([`study::resumable`]): `spec`, or the whole-sweep study
/// whose samples the folder holds, said by a `UserWarning`; `spec` when `force`.
fn resumable(
    py: Python<'_>,
    spec: StudySpec,
    out: &std::path::Path,
    force: bool,
) -> PyResult<StudySpec> {
    let (run, note) = study::resumable(spec, out, force);
    if let Some(note) = note {
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        let message = std::ffi::CString::new(note.words(Names::Keywords))
            .map_err(|e| invalid(e.to_string()))?;
        PyErr::warn(py, category.as_any(), &message, 1)?;
    }
    Ok(run)
}

/// Checks, locks and opens the study folder `out` as the CLI does.
fn open_folder(
    spec: &StudySpec,
    out: PathBuf,
    force: bool,
    interval: std::time::Duration,
    stop: Stop,
) -> PyResult<(FolderLock, StudyDir)> {
    study::check(spec, &out, force).map_err(from_error)?;
    // Held until the study returns: a second process (CLI or Python) on the folder is
    // refused at once, naming this one's PID.
    study::open(spec, &out, force, interval, stop).map_err(from_error)
}

/// The task results as JSON text: `tasks` (each as its checkpoint stores it), `alpha`
/// and `curve` (the tables of `alpha.csv` and `curve.csv`, [`asperity_app::study::rows`]:
/// `columns` as `(name, type)` and `rows` of cells) and `comparisons`: per task, its row
/// of the comparison with the paper and the verdict (`asperity study compare`,
/// [`study::comparison`]: α beside eq. (6)/(24), or a roll-off study's steepest slope
/// beside "≈ 1" with the bootstrap interval over the sample curves in `dir`), or
/// `comparison_error` where the study cannot be compared (the words).
fn records(spec: &StudySpec, dir: &std::path::Path, results: &[TaskResult]) -> String {
    let (comparisons, error) = match study::comparison(spec, dir, results) {
        Ok(rows) => {
            let rows = rows.into_iter().map(|row| {
                row.map_or(
                    serde_json::Value::Null,
                    |(row, verdict)| json!({"row": row, "verdict": verdict}),
                )
            });
            (rows.collect(), None)
        }
        Err(e) => (Vec::new(), Some(e.to_string())),
    };
    json!({
        "tasks": results,
        "alpha": rows::alpha_table(results),
        "curve": rows::curve_table(results),
        "comparisons": comparisons,
        "comparison_error": error,
        "figures": figures(results),
    })
    .to_string()
}

/// The study's figures as the CLI draws them ([`asperity_app::figure::study`]): `alpha`
/// (α(H) with the theory curves, or α(N) for one H), `curve` (the ensemble k(F)) and
/// `area` (the ensemble A/A₀(F)), each as `asperity-figure/1` JSON.
fn figures(results: &[TaskResult]) -> serde_json::Value {
    use asperity_app::figure::{study as charts, to_json};
    json!({
        "alpha": to_json(&[charts::alpha_chart(results, &charts::title(Kind::Alpha, None))]),
        "curve": to_json(&[charts::curve_chart(results, &charts::title(Kind::Curve, None))]),
        "area": to_json(&[charts::area_chart(results, "Contact fraction vs force (ensemble mean)")]),
    })
}

/// The threads of this process's rayon pool: the samples it computes at once.
#[pyfunction]
fn thread_count() -> usize {
    rayon::current_num_threads().max(1)
}

/// Rank 0's side of a study spread over the ranks of an MPI job (`asperity/_mpi.py`): the
/// folder checked, locked and opened as `run_study` does, and the library's
/// [`Ledger`], which hands out samples, checkpoints those received and ends each task as
/// the serial run does. The lock is held until [`StudyLedger::close`].
#[pyclass(module = "asperity._asperity")]
pub struct StudyLedger {
    spec: StudySpec,
    store: StudyDir,
    ledger: Option<Ledger>,
    lock: Option<FolderLock>,
}

#[pymethods]
impl StudyLedger {
    /// Opens the study as `run_study` (same arguments but the progress callback).
    #[new]
    #[pyo3(signature = (method_name, sizes, hursts, samples, rolloff, seed, min_contacts,
        max_fraction, levels, alpha_sweep, out, force, checkpoint_every))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        method_name: &str,
        sizes: Vec<usize>,
        hursts: Vec<f64>,
        samples: usize,
        rolloff: Option<f64>,
        seed: Option<u64>,
        min_contacts: Option<usize>,
        max_fraction: Option<f64>,
        levels: Option<usize>,
        alpha_sweep: bool,
        out: PathBuf,
        force: bool,
        checkpoint_every: Option<f64>,
    ) -> PyResult<Self> {
        let spec = make_spec(
            method_name,
            (sizes, hursts, samples),
            rolloff,
            seed,
            (min_contacts, max_fraction, levels),
            alpha_sweep,
        )?;
        let interval = checkpoint_interval(checkpoint_every)?;
        let spec = resumable(py, spec, &out, force)?;
        study::validate(&spec).map_err(request_error)?;
        let (lock, store) = open_folder(&spec, out, force, interval, Stop::new())?;
        let ledger = Ledger::restore(&store).map_err(from_error)?;
        Ok(StudyLedger {
            spec,
            store,
            ledger: Some(ledger),
            lock: Some(lock),
        })
    }

    /// The study's spec as JSON, for the other ranks' `SampleComputer`.
    fn spec_json(&self) -> String {
        serde_json::to_string(&self.spec).expect("specs serialise")
    }

    /// Up to `lanes` samples to compute next, `(task number, indices)`, or None.
    fn next_work(&mut self, lanes: usize) -> PyResult<Option<(usize, Vec<usize>)>> {
        Ok(self.ledger()?.next_work(lanes))
    }

    /// Takes in the curves (JSON, from `SampleComputer.compute`) of samples `indices` of
    /// task `t`.
    fn receive(&mut self, t: usize, indices: Vec<usize>, curves: &str) -> PyResult<()> {
        let curves: Vec<SampleCurve> = serde_json::from_str(curves)
            .map_err(|e| invalid(format!("garbled sample curves: {e}")))?;
        let store = self.store.clone();
        let ledger = self.ledger()?;
        let task = ledger.task(t);
        ledger
            .receive(&store, t, &indices, curves)
            .map_err(|e| from_error(with_task(store.spec(), task, e)))
    }

    /// Checkpoints the samples received, when due; the number of files written.
    fn save_due(&mut self) -> PyResult<usize> {
        let store = self.store.clone();
        self.ledger()?.save_due(&store).map_err(from_error)
    }

    /// `(samples received, samples of the study)`.
    fn progress(&mut self) -> PyResult<(u64, u64)> {
        let ledger = self.ledger()?;
        Ok((ledger.done(), ledger.total()))
    }

    /// Whether every task is finished.
    fn finished(&mut self) -> PyResult<bool> {
        Ok(self.ledger()?.finished())
    }

    /// The results, as `run_study` returns them; the study must be finished.
    fn results(&mut self) -> PyResult<String> {
        let ledger = self
            .ledger
            .take()
            .ok_or_else(|| invalid("the study is closed"))?;
        if !ledger.finished() {
            return Err(invalid("the study is not finished"));
        }
        Ok(records(&self.spec, self.store.path(), &ledger.results()))
    }

    /// Releases the folder's lock.
    fn close(&mut self) {
        self.ledger = None;
        self.lock = None;
    }
}

impl StudyLedger {
    fn ledger(&mut self) -> PyResult<&mut Ledger> {
        self.ledger
            .as_mut()
            .ok_or_else(|| invalid("the study is closed"))
    }
}

/// A rank's side of a study spread over an MPI job: computes chosen samples of its tasks
/// with the library's [`TaskSamples`] (the same curves, bit for bit, as the serial run's),
/// keeping the workers of the last task.
#[pyclass(module = "asperity._asperity")]
pub struct SampleComputer {
    spec: StudySpec,
    tasks: Vec<Task>,
    current: Option<(usize, TaskSamples)>,
}

#[pymethods]
impl SampleComputer {
    /// For the study of `spec_json` (`StudyLedger.spec_json`).
    #[new]
    fn new(spec_json: &str) -> PyResult<Self> {
        let spec: StudySpec = serde_json::from_str(spec_json)
            .map_err(|e| invalid(format!("garbled study spec: {e}")))?;
        spec.validate().map_err(from_error)?;
        Ok(SampleComputer {
            tasks: spec.tasks(),
            spec,
            current: None,
        })
    }

    /// The curves of samples `indices` of task number `t`, as JSON.
    fn compute(&mut self, py: Python<'_>, t: usize, indices: Vec<usize>) -> PyResult<String> {
        let task = *self
            .tasks
            .get(t)
            .ok_or_else(|| invalid(format!("no task number {t}")))?;
        if self.current.as_ref().is_none_or(|(c, _)| *c != t) {
            self.current = None;
            let samples = TaskSamples::new(&self.spec, task).map_err(from_error)?;
            self.current = Some((t, samples));
        }
        let (_, samples) = self.current.as_mut().expect("set above");
        let curves = run_detached(py, |_| samples.compute(&indices))?;
        let curves = curves.map_err(|e| from_error(with_task(&self.spec, task, e)))?;
        Ok(serde_json::to_string(&curves).expect("curves serialise"))
    }
}

/// Every task in order ([`study::run_tasks`]); progress counts the samples held over all
/// tasks, as the CLI's bar does ([`StudyProgress`]).
fn run_tasks(
    store: &StudyDir,
    plan: &StudyProgress,
    progress: Option<&Py<PyAny>>,
    cancel: &Cancel,
) -> Result<Vec<TaskResult>, TaskFailure> {
    let report =
        |task: usize, done: usize| cancel.call(progress, plan.held(task, done), plan.total());
    study::run_tasks(store, &report, None)
}

/// A solver error with the CLI's context: `mdr N = 512 H = 0.5: ...`.
fn with_task(spec: &StudySpec, task: Task, source: Error) -> Error {
    let method = spec.method;
    TaskFailure {
        method,
        task,
        source,
    }
    .into_error()
}
