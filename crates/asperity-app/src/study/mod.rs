//! Studies (`asperity study alpha|curve`, Python's `study_alpha`/`study_curve`): the
//! protocol both front ends run, once.
//!
//! A front end turns its arguments into a [`request::StudyRequest`], the request into a
//! [`StudySpec`] ([`request::StudyRequest::spec`]) and then, in this order:
//! 1. [`Kind::spec`]: the load sweep of the study's kind (an α study's BEM samples stop
//!    loading past the fit windows unless a full sweep is asked for);
//! 2. [`checkpoint_interval`]: the checkpoint interval's rule;
//! 3. [`resumable`]: the study a folder can resume (its note said to the user);
//! 4. [`validate`]: the spec's rules, the fit window against the grid, memory;
//! 5. [`check`] the folder (another study's checkpoints are refused unless forced), then
//!    [`open`] it (locked against other processes, opened or resumed);
//! 6. [`run_tasks`]: every task in order, each resumed from its checkpoint;
//! 7. [`rows::alpha_table`] or [`rows::curve_table`]: the result columns, defined once.
//!
//! The CLI writes the table as CSV with its plots; Python returns it as numpy columns.

pub mod distributed;
pub mod file;
pub mod progress;
pub mod report;
pub mod request;
pub mod rows;
pub mod windows;

use std::path::Path;
use std::time::Duration;

use asperity::lock::FolderLock;
use asperity::stop::Stop;
use asperity::study::compare;
use asperity::study::samplers::OnLoad;
use asperity::study::{
    run_any_task_with_loads, Method, StudyDir, StudySpec, Task, TaskResult,
    MAX_CHECKPOINT_INTERVAL_SECONDS,
};
use serde::Deserialize;

use crate::refusal::{Param, Refusal, RequestError};

/// What a study computes for its results.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// α per task: `alpha.csv` ([`rows::alpha_table`]).
    Alpha,
    /// Ensemble-mean curves: `curve.csv` ([`rows::curve_table`]).
    Curve,
}

impl Kind {
    /// The name of its table (`alpha`, `curve`), the stem of the CLI's outputs.
    pub fn stem(self) -> &'static str {
        match self {
            Kind::Alpha => "alpha",
            Kind::Curve => "curve",
        }
    }

    /// `spec` with the load sweep of this kind: an α study's BEM samples stop loading past
    /// the fits' windows ([`StudySpec::with_alpha_sweep`]; the same α) unless
    /// `full_sweep`; a curve study solves every load.
    pub fn spec(self, spec: StudySpec, full_sweep: bool) -> StudySpec {
        match self {
            Kind::Alpha if !full_sweep => spec.with_alpha_sweep(),
            _ => spec,
        }
    }

    /// Its result table; a curve study's with the conductance columns of `transport`
    /// ([`rows::curve_table_with`]).
    pub fn table(
        self,
        results: &[TaskResult],
        transport: &asperity::bem::conductance::Transport,
    ) -> rows::Table {
        match self {
            Kind::Alpha => rows::alpha_table(results),
            Kind::Curve => rows::curve_table_with(results, transport),
        }
    }
}

/// The longest time between checkpoints of a task in progress.
pub const CHECKPOINT_EVERY: Param = Param::new("--checkpoint-every", "checkpoint_every");
/// An α study that solves every load.
pub const FULL_SWEEP: Param = Param::new("--full-sweep", "full_sweep=True");
/// Discard another study's checkpoints.
pub const FORCE: Param = Param::new("--force", "force=True");

/// The checkpoint interval of `seconds`: from 0 (after every batch of samples) to
/// [`MAX_CHECKPOINT_INTERVAL_SECONDS`] (about 11 days).
pub fn checkpoint_interval(seconds: f64) -> Result<Duration, Refusal> {
    let max = MAX_CHECKPOINT_INTERVAL_SECONDS;
    if !(0.0..=max).contains(&seconds) {
        return Err(Refusal::of(CHECKPOINT_EVERY).text(format!(
            " must be between 0 and {max:e} seconds, got {}",
            asperity::input::short_number(seconds)
        )));
    }
    Ok(Duration::from_secs_f64(seconds))
}

/// The study to run in `dir` ([`StudyDir::resumable`]): `spec`, or the whole-sweep study
/// whose samples the folder holds, with a note for the user; always `spec` when
/// `discard`.
pub fn resumable(spec: StudySpec, dir: &Path, discard: bool) -> (StudySpec, Option<Refusal>) {
    let run = StudyDir::resumable(dir, spec.clone(), discard);
    if run == spec {
        return (run, None);
    }
    let note = Refusal::saying(format!(
        "{}: resuming its study, which solves every load (as alpha studies did before \
         they stopped loading past their fit windows, or with ",
        dir.display()
    ))
    .param(FULL_SWEEP)
    .text("): the same alpha, its checkpoints kept; ")
    .param(FORCE)
    .text(" discards them");
    (run, Some(note))
}

/// Refuses a study that cannot run: Poisson's ratio of an MDR study
/// ([`check_tangential`]), the library's rules on the spec ([`StudySpec::validate`]), a fit window no load reaches ([`check_min_contacts`]), and
/// results that would not fit in memory ([`StudySpec::ensure_fits`]).
pub fn validate(spec: &StudySpec) -> Result<(), RequestError> {
    let library = |e| RequestError::Invalid(Box::new(e));
    check_tangential(spec)?;
    spec.validate().map_err(library)?;
    check_min_contacts(spec)?;
    spec.ensure_fits().map_err(library)
}

/// Refuses a folder that holds another study's checkpoints, or results this study would
/// leave out, unless `force` ([`StudyDir::check`]). Creates nothing.
pub fn check(spec: &StudySpec, dir: &Path, force: bool) -> asperity::Result<()> {
    StudyDir::check(dir, spec, force).map(drop)
}

/// Locks the folder `dir` against other processes (CLI or Python; the lock is held until
/// it is dropped) and opens (or resumes) the study there, checkpointing a task in progress
/// at most every `interval` and stopping when `stop` is requested.
pub fn open(
    spec: &StudySpec,
    dir: &Path,
    force: bool,
    interval: Duration,
    stop: Stop,
) -> asperity::Result<(FolderLock, StudyDir)> {
    let lock = StudyDir::lock(dir)?;
    let store = StudyDir::open(dir, spec, force)?
        .with_checkpoint_interval(interval)
        .with_stop(stop);
    Ok((lock, store))
}

/// A task that failed, named as both front ends say it: `mdr N = 512 H = 0.5`.
#[derive(Debug, thiserror::Error)]
#[error("{} N = {} H = {}", .method.name(), .task.n, .task.hurst)]
pub struct TaskFailure {
    /// The study's method.
    pub method: Method,
    /// The task.
    pub task: Task,
    /// What failed.
    #[source]
    pub source: asperity::Error,
}

impl TaskFailure {
    /// The library's error, a solver's failure named with the task
    /// (`mdr N = 512 H = 0.5: …`), for a front end that maps the library's errors.
    pub fn into_error(self) -> asperity::Error {
        match self.source {
            asperity::Error::Solve { context, source } => asperity::Error::Solve {
                context: format!(
                    "{} N = {} H = {}: {context}",
                    self.method.name(),
                    self.task.n,
                    self.task.hurst
                ),
                source,
            },
            other => other,
        }
    }
}

/// Runs (or resumes) every task of the study in `store`, in task order: a finished task
/// is read back, the others computed from where their checkpoints stopped
/// ([`run_any_task_with_loads`]). `progress(task, done)` reports the samples of task
/// number `task` done so far (first those read back, then after each batch); `on_load`,
/// if any, is called after every load a BEM sample solves here. Once the store's stop is
/// requested no sample starts and the task in progress checkpoints what it finished.
pub fn run_tasks(
    store: &StudyDir,
    progress: &(dyn Fn(usize, usize) + Sync),
    on_load: Option<OnLoad>,
) -> Result<Vec<TaskResult>, TaskFailure> {
    let spec = store.spec();
    let tasks = spec.tasks();
    let mut results = Vec::with_capacity(tasks.len());
    for (i, &task) in tasks.iter().enumerate() {
        let report = |done: usize, _: usize| progress(i, done);
        let result = run_any_task_with_loads(spec, task, store, &report, on_load.clone());
        results.push(result.map_err(|source| TaskFailure {
            method: spec.method,
            task,
            source,
        })?);
    }
    Ok(results)
}

/// Each task's row of the comparison with the paper and its verdict, as `asperity study
/// compare` writes them to `comparison.csv` ([`compare::rows`]): a study without roll-off
/// by its α against eq. (6)/(24) (Fig. 1), one with a roll-off by the steepest slope of its
/// mean curve against the paper's "≈ 1" (Fig. 2), with the bootstrap interval over the
/// sample curves that the folder `dir` keeps (BEM; without them the interval is the value
/// itself). `None` for a task without a fit or a slope. Refused for a roll-off study whose
/// samples ended their sweeps (an α study's): its curves stop short of the steepest decade.
pub fn comparison(
    spec: &StudySpec,
    dir: &Path,
    results: &[TaskResult],
) -> asperity::Result<Vec<Option<(compare::Row, compare::Verdict)>>> {
    let slopes = match spec.rolloff {
        Some(_) => {
            asperity::study::sensitivity::ensure_whole_sweep(spec, dir)?;
            asperity::study::sensitivity::study_slopes(dir)?
        }
        None => Vec::new(),
    };
    let row = |r: &TaskResult| {
        let one = std::slice::from_ref(r);
        let figure = match spec.rolloff {
            Some(_) => compare::Results::Fig2(one, spec.window),
            None => compare::Results::Fig1(one),
        };
        let row = compare::rows(&figure, &slopes).into_iter().next()?;
        let verdict = compare::verdict(&row);
        Some((row, verdict))
    };
    Ok(results.iter().map(row).collect())
}

/// The BEM method, as each front end asks for it.
pub const METHOD_BEM: Param = Param::new("--method bem", "method=\"bem\"");

/// Refuses Poisson's ratio in an MDR study, in the front end's words: the tangential
/// stiffness is computed on BEM's frozen contact set (Cerruti's kernel); an MDR line has
/// no tangential kernel (the library's own rule, [`StudySpec::validate`], says the same in
/// its words).
///
/// ```
/// use asperity::study::{Method, StudySpec};
/// use asperity_app::{study::check_tangential, Names};
///
/// let spec = StudySpec { method: Method::Mdr, poisson: Some(0.3), ..StudySpec::default() };
/// let refusal = check_tangential(&spec).unwrap_err();
/// assert_eq!(
///     refusal.words(Names::Flags),
///     "--poisson applies to BEM studies only (--method bem): an MDR line has no \
///      tangential kernel"
/// );
/// assert!(refusal.words(Names::Keywords).starts_with(
///     "poisson applies to BEM studies only (method=\"bem\")"));
/// assert!(check_tangential(&StudySpec { method: Method::Bem, ..spec }).is_ok());
/// ```
pub fn check_tangential(spec: &StudySpec) -> Result<(), Refusal> {
    if spec.poisson.is_none() || spec.method == Method::Bem {
        return Ok(());
    }
    Err(Refusal::of(crate::derived::params::POISSON)
        .text(" applies to BEM studies only (")
        .param(METHOD_BEM)
        .text("): an MDR line has no tangential kernel"))
}

/// The smallest number of contacts of the α fit window.
pub const MIN_CONTACTS: Param = Param::new("--min-contacts", "min_contacts");

/// Refuses a fit window that starts above the number of points of the smallest sample (N
/// springs on an MDR line, N×N on a BEM surface): no load could reach it, and every α of
/// that size would be empty.
pub fn check_min_contacts(spec: &StudySpec) -> Result<(), Refusal> {
    let Some(&n) = spec.sizes.iter().min() else {
        return Ok(());
    };
    let (points, grid) = match spec.method {
        Method::Mdr => (n, format!("a line of {n} springs")),
        Method::Bem => (n.saturating_mul(n), format!("a {n}x{n} surface")),
    };
    let min_contacts = spec.window.min_contacts;
    if min_contacts <= points {
        return Ok(());
    }
    Err(Refusal::of(MIN_CONTACTS).text(format!(
        " {min_contacts} is above the number of points of the smallest sample ({grid} has \
         {points}): no load reaches it"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Names;
    use asperity::study::{run_any_task, FitWindow};

    fn mdr_study() -> StudySpec {
        StudySpec {
            method: Method::Mdr,
            sizes: vec![64, 128],
            hursts: vec![0.5],
            samples: 6,
            rolloff: None,
            seed: 4,
            window: FitWindow {
                min_contacts: 4,
                max_fraction: 0.1,
            },
            levels: 12,
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
        }
    }

    #[test]
    fn the_tasks_run_in_order_as_the_library_runs_each_and_resume_from_the_folder() {
        let spec = mdr_study();
        validate(&spec).unwrap();
        let dir = tempfile::tempdir().unwrap();
        check(&spec, dir.path(), false).unwrap();
        let (lock, store) = open(&spec, dir.path(), false, Duration::ZERO, Stop::new()).unwrap();
        let reports = std::sync::Mutex::new(Vec::new());
        let progress = |task: usize, done: usize| reports.lock().unwrap().push((task, done));
        let results = run_tasks(&store, &progress, None).unwrap();
        drop(lock);
        // Each task's result is the library's, task by task, in another folder.
        let other = tempfile::tempdir().unwrap();
        let (_lock, alone) = open(&spec, other.path(), false, Duration::ZERO, Stop::new()).unwrap();
        for (result, &task) in results.iter().zip(&spec.tasks()) {
            assert_eq!(
                result,
                &run_any_task(&spec, task, &alone, &|_, _| {}).unwrap()
            );
        }
        let reports = reports.into_inner().unwrap();
        assert_eq!(reports.first(), Some(&(0, 0)));
        assert_eq!(reports.last(), Some(&(1, 6)));
        // Run again: every task is read back, whole, from its checkpoint.
        let (_lock, store) = open(&spec, dir.path(), false, Duration::ZERO, Stop::new()).unwrap();
        let again = std::sync::Mutex::new(Vec::new());
        let progress = |task: usize, done: usize| again.lock().unwrap().push((task, done));
        assert_eq!(run_tasks(&store, &progress, None).unwrap(), results);
        assert_eq!(again.into_inner().unwrap(), vec![(0, 6), (1, 6)]);
        let table = Kind::Alpha.table(&results, &Default::default());
        assert_eq!(table.rows.len(), 2);
    }

    #[test]
    fn a_stopped_study_starts_no_sample_and_names_its_task() {
        let spec = mdr_study();
        let dir = tempfile::tempdir().unwrap();
        let stop = Stop::new();
        stop.request();
        let (_lock, store) = open(&spec, dir.path(), false, Duration::ZERO, stop).unwrap();
        let failure = run_tasks(&store, &|_, _| {}, None).unwrap_err();
        assert_eq!(failure.to_string(), "mdr N = 64 H = 0.5");
        assert!(matches!(
            failure.source,
            asperity::Error::Interrupted { .. }
        ));
    }

    #[test]
    fn the_checkpoint_interval_and_the_resume_note_name_their_parameters() {
        assert_eq!(checkpoint_interval(0.0).unwrap(), Duration::ZERO);
        assert_eq!(
            checkpoint_interval(2.5).unwrap(),
            Duration::from_millis(2500)
        );
        for bad in [-1.0, f64::NAN, 1e7] {
            let refusal = checkpoint_interval(bad).unwrap_err();
            assert!(refusal
                .words(Names::Flags)
                .starts_with("--checkpoint-every must be between 0 and 1e6 seconds, got "));
            assert!(refusal
                .words(Names::Keywords)
                .starts_with("checkpoint_every must be between"));
        }
        // A folder that holds nothing resumes the study asked for, without a note.
        let dir = tempfile::tempdir().unwrap();
        let spec = mdr_study();
        assert_eq!(resumable(spec.clone(), dir.path(), false), (spec, None));
    }

    #[test]
    fn the_window_must_fit_the_grid() {
        let spec = |method, min_contacts| StudySpec {
            method,
            sizes: vec![64, 32],
            hursts: vec![0.5],
            samples: 1,
            rolloff: None,
            seed: 1,
            window: FitWindow {
                min_contacts,
                max_fraction: 0.1,
            },
            levels: 48,
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
        };
        assert!(check_min_contacts(&spec(Method::Mdr, 32)).is_ok());
        assert!(check_min_contacts(&spec(Method::Bem, 1024)).is_ok());
        let err = check_min_contacts(&spec(Method::Mdr, 33)).unwrap_err();
        assert_eq!(
            err.to_string(),
            "--min-contacts 33 is above the number of points of the smallest sample (a line of \
             32 springs has 32): no load reaches it"
        );
        assert!(check_min_contacts(&spec(Method::Bem, 1025)).is_err());
    }
}
