//! Ensemble studies (`asperity study alpha|curve`) in the CLI's checkpoint folders.
//!
//! [`run_study`] runs the protocol of the front-end layer ([`asperity_app::study`]) that
//! the CLI's `asperity study` runs: the same validation, the same `study.json` and
//! `checkpoint/<task>.json`, the same checkpoint interval, the same tasks in the same
//! order and the same result tables. A study started here resumes from the CLI and the
//! other way round. It writes no `alpha.csv`/`curve.csv` or plots (the tables are
//! returned), and Ctrl-C (or an exception of the progress callback) stops it after the
//! samples in flight; the checkpoints already written stay.

use asperity_app::figure::study::Derived as StudyDerived;
use std::path::PathBuf;

use asperity::lock::FolderLock;
use asperity::stop::Stop;
use asperity::study::{
    SampleCurve, StudyDir, StudySpec, Task, TaskResult, TaskSamples, CHECKPOINT_INTERVAL,
};
use asperity::Error;
use asperity_app::study::distributed::{Action, Coordinator, DistributedError};
use asperity_app::study::progress::{log_line, Eta, StudyProgress};
use asperity_app::study::request::StudyRequest;
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
    m.add_function(wrap_pyfunction!(compare_study, m)?)?;
    m.add_function(wrap_pyfunction!(thread_count, m)?)?;
    m.add_class::<StudyCoordinator>()?;
    m.add_class::<SampleComputer>()?;
    m.add_class::<StudyEta>()?;
    Ok(())
}

/// The ETA of a study's progress in samples (the front-end layer's [`Eta`], the CLI's
/// arithmetic: samples read back from checkpoints do not count towards the rate, each
/// sample weighs its cost), handed to `run_study`'s `eta` callable before the first sample.
#[pyclass(module = "asperity._asperity", name = "StudyEta")]
pub struct StudyEta {
    eta: Eta,
}

#[pymethods]
impl StudyEta {
    /// The samples of the study.
    #[getter]
    fn total(&self) -> u64 {
        self.eta.total()
    }

    /// Seconds left once `done` samples are held after `elapsed` seconds of this run;
    /// None until a sample was computed in this run.
    fn remaining(&self, done: u64, elapsed: f64) -> Option<f64> {
        self.eta.remaining(done, elapsed)
    }

    /// The CLI's line of progress (`name: done/total (E s elapsed, ETA R s)`), or None
    /// while the ETA is unknown.
    fn line(&self, name: &str, done: u64, elapsed: f64) -> Option<String> {
        let total = self.eta.total();
        (self.eta.remaining(done, elapsed))
            .map(|left| log_line(name, done.min(total), total, elapsed, left))
    }
}

/// `hurst` values from the CLI's syntax: values and ranges `A:B:STEP`, comma-separated.
#[pyfunction]
fn hurst_range(text: &str) -> PyResult<Vec<f64>> {
    parse_range(text).map_err(from_error)
}

/// `asperity study compare DIR` by the command's own code
/// ([`asperity_app::study::report::compare_study`]): writes `comparison.csv` and
/// `report.md` into the finished study's folder and returns each row's verdict; its error
/// (an unfinished study, a roll-off study whose sweeps ended, an existing output without
/// `force`) is a `ValueError`, the library's as every function of the package raises it.
#[pyfunction]
fn compare_study(
    py: Python<'_>,
    dir: std::path::PathBuf,
    force: bool,
) -> PyResult<Vec<&'static str>> {
    use asperity_app::study::report::{self, ReportError};
    let rows = py
        .detach(|| report::compare_study(&dir, force))
        .map_err(|error| match error {
            ReportError::Library(error) => from_error(error),
            other => pyo3::exceptions::PyValueError::new_err(other.to_string()),
        })?;
    Ok(rows.iter().map(report::verdict).collect())
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

/// The keywords of a study (`study_alpha`, `study_curve`) as `_run_study` hands them over,
/// a dict with these keys: the [`StudyRequest`] both front ends make.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct StudyKeywords {
    /// `alpha` or `curve`.
    kind: String,
    method: String,
    sizes: Vec<i128>,
    hursts: Vec<f64>,
    samples: i128,
    rolloff: Option<f64>,
    seed: Option<String>,
    min_contacts: Option<i128>,
    max_fraction: Option<f64>,
    levels: Option<i128>,
    full_sweep: bool,
    poisson: Option<f64>,
    /// `x`, `y` or `both` (none: both), with `poisson`.
    tangential: Option<String>,
}

impl From<StudyKeywords> for StudyRequest {
    fn from(k: StudyKeywords) -> Self {
        StudyRequest {
            kind: match k.kind.as_str() {
                "curve" => Kind::Curve,
                _ => Kind::Alpha,
            },
            method: k.method,
            sizes: k.sizes,
            hursts: k.hursts,
            samples: k.samples,
            rolloff: k.rolloff,
            seed: k.seed,
            min_contacts: k.min_contacts,
            max_fraction: k.max_fraction,
            levels: k.levels,
            full_sweep: k.full_sweep,
            poisson: k.poisson,
            tangential: k.tangential,
        }
    }
}

/// Runs (or resumes) a study in `out`; returns the task results and the result tables
/// (`alpha.csv`'s and `curve.csv`'s) as JSON text ([`records`]).
#[pyfunction]
#[pyo3(signature = (request, out, force, checkpoint_every, progress, resistivity=None,
    thermal_conductivity=None, eta=None))]
#[allow(clippy::too_many_arguments)]
fn run_study(
    py: Python<'_>,
    request: StudyKeywords,
    out: PathBuf,
    force: bool,
    checkpoint_every: Option<f64>,
    progress: Option<Py<PyAny>>,
    resistivity: Option<Vec<f64>>,
    thermal_conductivity: Option<Vec<f64>>,
    eta: Option<Py<PyAny>>,
) -> PyResult<String> {
    let request = StudyRequest::from(request);
    let derived = derived(&request, &resistivity, &thermal_conductivity)?;
    let spec = request.spec().map_err(refused)?;
    let interval = checkpoint_interval(checkpoint_every)?;
    let spec = resumable(py, spec, &out, force)?;
    study::validate(&spec).map_err(request_error)?;
    // The flag that Ctrl-C raises: the samples poll it.
    let stop = Stop::new();
    let (_lock, store) = open_folder(&spec, out, force, interval, stop.clone())?;
    let plan = StudyProgress::of(&store).map_err(from_error)?;
    if let Some(eta) = &eta {
        let handed = Py::new(
            py,
            StudyEta {
                eta: plan.sample_eta(),
            },
        )?;
        eta.call1(py, (handed,))?;
    }
    let results = run_detached_with(py, &stop, |cancel| {
        run_tasks(&store, &plan, progress.as_ref(), cancel)
    })?
    .map_err(|failure| from_error(failure.into_error()))?;
    Ok(records(&spec, store.path(), &results, derived))
}

/// The tangential and conductance columns and figures of a curve study
/// ([`asperity_app::derived::Derived`]: the CLI's `--poisson`, `--resistivity`,
/// `--thermal-conductivity`, refused in the same words; the request's `poisson` and
/// `tangential`).
fn derived(
    request: &StudyRequest,
    resistivity: &Option<Vec<f64>>,
    thermal_conductivity: &Option<Vec<f64>>,
) -> PyResult<StudyDerived> {
    let derived = asperity_app::derived::Derived::validate(
        request.poisson,
        request.tangential.as_deref(),
        resistivity,
        thermal_conductivity,
    )
    .map_err(crate::errors::refused)?;
    Ok(derived.into())
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
fn records(
    spec: &StudySpec,
    dir: &std::path::Path,
    results: &[TaskResult],
    derived: StudyDerived,
) -> String {
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
        "curve": rows::curve_table_with(results, &derived.transport),
        "comparisons": comparisons,
        "comparison_error": error,
        "figures": figures(results, derived),
    })
    .to_string()
}

/// The study's figures as the CLI draws them ([`asperity_app::figure::study`]): `alpha`
/// (α(H) with the theory curves, or α(N) for one H), `curve` (the ensemble k(F)) and
/// `area` (the ensemble A/A₀(F)), each as `asperity-figure/1` JSON, and `tangential`
/// (`k_t/k_n` and `C(F)`, [`asperity_app::figure::study::derived_charts`]) where the study
/// has them.
fn figures(results: &[TaskResult], derived: StudyDerived) -> serde_json::Value {
    use asperity_app::figure::{study as charts, to_json};
    let extra = charts::derived_charts(results, derived);
    json!({
        "alpha": to_json(&[charts::alpha_chart(results, &charts::title(Kind::Alpha, None))]),
        "curve": to_json(&[charts::curve_chart(results, &charts::title(Kind::Curve, None))]),
        "area": to_json(&[charts::area_chart(results, "Contact fraction vs force (ensemble mean)")]),
        "tangential": (!extra.is_empty()).then(|| to_json(&extra)),
    })
}

/// The threads of this process's rayon pool: the samples it computes at once.
#[pyfunction]
fn thread_count() -> usize {
    rayon::current_num_threads().max(1)
}

/// Rank 0's side of a study spread over the ranks of an MPI job (`asperity/_mpi.py`): the
/// front-end layer's coordinator ([`Coordinator`]: who computes what, the samples taken in
/// and checkpointed by the library's ledger, a failure ending the study once nothing is in
/// flight), which the CLI's MPI build drives too. Python carries its actions out as
/// messages: `("assign", rank, task, indices, spec)` (`spec`: the study's spec as JSON for
/// a rank that has not met it, else None), `("stop", rank)` and `("end",)`. The folder is
/// opened by [`StudyCoordinator::begin`] and its lock held until
/// [`StudyCoordinator::close`].
#[pyclass(module = "asperity._asperity")]
pub struct StudyCoordinator {
    machine: Coordinator,
    /// The study begun: its spec and folder.
    study: Option<(StudySpec, StudyDir)>,
    /// Its tangential and conductance columns ([`derived`]).
    derived: StudyDerived,
    lock: Option<FolderLock>,
}

type PyAction = (&'static str, usize, usize, Vec<usize>, Option<String>);

#[pymethods]
impl StudyCoordinator {
    /// A job of `size` ranks, rank 0 computing `lanes` samples at once.
    #[new]
    fn new(size: usize, lanes: usize) -> Self {
        StudyCoordinator {
            machine: Coordinator::new(size, lanes),
            study: None,
            derived: StudyDerived::default(),
            lock: None,
        }
    }

    /// Opens the study as `run_study` does (same arguments but the progress callback) and
    /// begins it: the first actions.
    #[pyo3(signature = (request, out, force, checkpoint_every, resistivity=None,
        thermal_conductivity=None))]
    #[allow(clippy::too_many_arguments)]
    fn begin(
        &mut self,
        py: Python<'_>,
        request: StudyKeywords,
        out: PathBuf,
        force: bool,
        checkpoint_every: Option<f64>,
        resistivity: Option<Vec<f64>>,
        thermal_conductivity: Option<Vec<f64>>,
    ) -> PyResult<Vec<PyAction>> {
        let request = StudyRequest::from(request);
        let derived = derived(&request, &resistivity, &thermal_conductivity)?;
        let spec = request.spec().map_err(refused)?;
        let interval = checkpoint_interval(checkpoint_every)?;
        let spec = resumable(py, spec, &out, force)?;
        study::validate(&spec).map_err(request_error)?;
        let (lock, store) = open_folder(&spec, out, force, interval, Stop::new())?;
        let actions = self
            .machine
            .begin(store.clone())
            .map_err(distributed_error)?;
        self.study = Some((spec, store));
        self.derived = derived;
        self.lock = Some(lock);
        Ok(self.actions(actions))
    }

    /// Rank `rank` is ready and computes `lanes` samples at once.
    fn on_ready(&mut self, rank: usize, lanes: usize) -> Vec<PyAction> {
        let actions = self.machine.on_ready(rank, lanes);
        self.actions(actions)
    }

    /// Rank `rank` computed its last assignment: the curves as JSON (from
    /// `SampleComputer.compute`); garbled ones fail the assignment.
    fn on_done(&mut self, rank: usize, curves: &str) -> Vec<PyAction> {
        let actions = match serde_json::from_str::<Vec<SampleCurve>>(curves) {
            Ok(curves) => self.machine.on_done(rank, curves),
            Err(e) => (self.machine).on_failed(rank, &format!("garbled sample curves: {e}")),
        };
        self.actions(actions)
    }

    /// Rank `rank`'s last assignment failed with `reason`.
    fn on_failed(&mut self, rank: usize, reason: &str) -> Vec<PyAction> {
        let actions = self.machine.on_failed(rank, reason);
        self.actions(actions)
    }

    /// This process failed on its own (`reason`): the study ends once nothing is in flight.
    fn halt(&mut self, reason: &str) -> Vec<PyAction> {
        let actions = self.machine.halt(reason);
        self.actions(actions)
    }

    /// Checkpoints the samples received, when due.
    fn save_due(&mut self) -> Vec<PyAction> {
        let actions = self.machine.save_due();
        self.actions(actions)
    }

    /// `(samples received, samples of the study)`.
    fn progress(&self) -> (u64, u64) {
        self.machine.progress()
    }

    /// The ranks computing samples.
    fn busy(&self) -> Vec<usize> {
        self.machine.busy()
    }

    /// The results of the study that ended, as `run_study` returns them, or its failure.
    fn finish(&mut self) -> PyResult<String> {
        let results = self.machine.finish().map_err(distributed_error)?;
        let (spec, store) = self
            .study
            .take()
            .ok_or_else(|| invalid("no study was begun"))?;
        Ok(records(&spec, store.path(), &results, self.derived))
    }

    /// Ends the job: the actions telling the ready ranks to stop (the others are told by
    /// `on_ready`).
    fn stop(&mut self) -> PyResult<Vec<PyAction>> {
        let actions = self.machine.stop().map_err(distributed_error)?;
        Ok(self.actions(actions))
    }

    /// Whether every other rank was told to stop.
    fn stopped(&self) -> bool {
        self.machine.stopped()
    }

    /// Releases the folder's lock.
    fn close(&mut self) {
        self.lock = None;
    }
}

impl StudyCoordinator {
    /// The actions as Python tuples (the struct docs).
    fn actions(&self, actions: Vec<Action>) -> Vec<PyAction> {
        let spec = || {
            let (spec, _) = self.study.as_ref().expect("assignments within a study");
            serde_json::to_string(spec).expect("specs serialise")
        };
        let spec_json = std::cell::OnceCell::new();
        (actions.into_iter())
            .map(|action| match action {
                Action::Assign {
                    rank,
                    task,
                    indices,
                    spec: first,
                } => {
                    let json = first.then(|| spec_json.get_or_init(spec).clone());
                    ("assign", rank, task, indices, json)
                }
                Action::Stop { rank } => ("stop", rank, 0, Vec::new(), None),
                Action::End => ("end", 0, 0, Vec::new(), None),
            })
            .collect()
    }
}

/// A distributed study's failure as Python raises it: the library's errors as everywhere
/// (a task's named with it), a rank's failure or a protocol error as `RuntimeError`.
fn distributed_error(error: DistributedError) -> PyErr {
    match error {
        DistributedError::Task(failure) => from_error(failure.into_error()),
        DistributedError::Store(error) => from_error(error),
        other => pyo3::exceptions::PyRuntimeError::new_err(other.to_string()),
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
    /// For the study of `spec_json` (sent with a rank's first assignment, `StudyCoordinator`).
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
