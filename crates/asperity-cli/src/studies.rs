//! What `asperity study` and the figures of `asperity reproduce` share: running a study
//! with progress into its folder ([`execute`]), and writing its results as `alpha.csv` or
//! `curve.csv` with their plots ([`write_alpha`], [`write_curves`]). The commands import
//! these from here, not from each other.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use anyhow::Result;
use asperity::study::samplers::OnLoad;
use asperity::study::{Method, StudyDir, StudySpec, TaskResult};
use asperity_app::study::progress::StudyProgress;
use asperity_app::study::{self, rows, rows::Cell};
use asperity_app::Names;

use crate::output::{format_number, Table};
use asperity_app::figure::study::{
    alpha_chart, curve_chart, derived_charts, title as titled, Derived,
};

use crate::plot::{Chart, ChartFiles};
use crate::progress::Progress;

pub use asperity_app::study::Kind;

/// `", loads up to the first past 8 % contact"` for a BEM study whose samples end their
/// sweep ([`StudySpec::sweep_end`]), empty for one that solves every load.
pub fn describe_sweep(spec: &StudySpec) -> String {
    spec.sweep_end.map_or(String::new(), |end| {
        format!(
            ", loads up to the first past {} % contact",
            asperity::input::short_number(end * 100.0)
        )
    })
}

/// The study to run in `dir` ([`asperity_app::study::resumable`]): `spec`, or the
/// whole-sweep study whose samples the folder holds, said on stderr; always `spec` when
/// `discard` (--force).
pub fn resumable(spec: StudySpec, dir: &Path, discard: bool, quiet: bool) -> StudySpec {
    let (run, note) = asperity_app::study::resumable(spec, dir, discard);
    if let Some(note) = note.filter(|_| !quiet) {
        eprintln!("{}", note.words(Names::Flags));
    }
    run
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
    /// The `reproduce` setting a figure's study runs under, marked on its plot.
    pub setting: Option<&'static str>,
    /// A curve study's Poisson's ratio and transport properties: its tangential-ratio
    /// and conductance columns and figures ([`derived_charts`]).
    pub derived: Derived,
}

/// The stem of a curve study's figures of `k_t/k_n` and `C(F)` ([`derived_charts`]).
pub const DERIVED_STEM: &str = "tangential";

/// The files a study of `kind` writes into `dir`.
pub fn outputs(kind: Kind, dir: &Path) -> Vec<PathBuf> {
    let stem = kind.stem();
    let mut files: Vec<PathBuf> = ["csv", "png", "svg"]
        .iter()
        .map(|ext| dir.join(format!("{stem}.{ext}")))
        .collect();
    if kind == Kind::Curve {
        files.extend(["png", "svg"].map(|ext| dir.join(format!("{DERIVED_STEM}.{ext}"))));
    }
    files
}

/// Validates (the spec, then whether its largest task fits in memory), checks outputs
/// (see [`crate::rerun`]: existing ones only if this study wrote them unchanged, or with
/// `--force`), locks the folder against other processes, opens (or resumes) the study and
/// runs every task with a progress bar, then writes its outputs of `kind` together (all or
/// none). Nothing is created before every check has passed. Returns the task results in
/// task order.
///
/// The progress bar counts samples (MDR) or solved loads (BEM, so that it moves within a
/// sample); its ETA weighs each by [`asperity::study::sample_cost`] and leaves out samples read back from
/// checkpoints (see [`crate::progress`]).
pub fn execute(
    spec: &StudySpec,
    dir: &Path,
    options: RunOptions,
    kind: Kind,
) -> Result<Vec<TaskResult>> {
    let RunOptions {
        force,
        quiet,
        checkpoint_every,
        setting,
        derived,
    } = options;
    study::validate(spec).map_err(crate::request::refused)?;
    study::check(spec, dir, force)?;
    let rewrite = crate::rerun::may_rewrite(dir, &outputs(kind, dir), force)?;
    let stop = crate::interrupt::stop();
    let (_lock, store) = study::open(spec, dir, force, checkpoint_every, stop)?;
    let plan = StudyProgress::of(&store)?;
    let progress = Arc::new(study_progress(spec, &plan, quiet));
    let results = run_tasks(&store, &plan, &progress, quiet);
    if crate::interrupt::stop_requested() {
        // The study checkpointed what it finished (Ctrl-C): exit as an interrupt does.
        progress.finish();
        crate::interrupt::exit_interrupted();
    }
    let results = results?;
    progress.finish();
    let title = titled(kind, setting);
    let chart = match kind {
        Kind::Alpha => alpha_chart(&results, &title),
        Kind::Curve => curve_chart(&results, &title),
    };
    let table = csv_table(&kind.table(&results, &derived.transport));
    let extra = match kind {
        Kind::Curve => derived_charts(&results, derived),
        Kind::Alpha => Vec::new(),
    };
    write_together(dir, kind.stem(), &table, (&chart, &extra), rewrite, true)?;
    Ok(results)
}

/// The progress bar of a study: in samples, or in loads for BEM, each step weighed by its
/// cost, the samples already stored counted as restored at once, so that a resumed study
/// shows all it holds and its ETA covers only the samples left (the front-end layer's
/// [`StudyProgress`]).
fn study_progress(spec: &StudySpec, plan: &StudyProgress, quiet: bool) -> Progress {
    let name = match spec.method {
        Method::Bem => "bem study (loads)",
        Method::Mdr => "mdr study",
    };
    let progress = Progress::weighted(name, &plan.segments(), quiet);
    progress.restore(plan.restored() as u64 * plan.steps_per_sample());
    progress
}

/// Runs (or resumes) every task of the study in `store`, in this process or, on rank 0 of
/// an MPI job of several ranks, over all ranks ([`crate::distributed`]): the same
/// results either way. Progress moves per sample, and per solved load of the BEM samples
/// computed here.
fn run_tasks(
    store: &StudyDir,
    plan: &StudyProgress,
    progress: &Arc<Progress>,
    quiet: bool,
) -> Result<Vec<TaskResult>> {
    let steps = plan.steps_per_sample();
    #[cfg(feature = "mpi")]
    if crate::distributed::active() {
        // The ledger counts samples held in all: the restored ones first, as the bar does.
        let progress = |done, restored| {
            if restored {
                progress.restore(done * steps)
            } else {
                progress.set(done * steps)
            }
        };
        return crate::distributed::run_study(store, &progress, quiet);
    }
    // Without MPI, `quiet` is the progress bar's alone.
    let _ = quiet;
    // The first Ctrl-C stops the samples and checkpoints the finished ones.
    let _graceful = crate::interrupt::graceful();
    // Every load solved in this run is one step; at the end of a batch of samples the
    // count is set to what the finished samples hold, which all their loads reached.
    let on_load = (steps > 1).then(|| {
        let progress = Arc::clone(progress);
        OnLoad::new(move || progress.inc())
    });
    // Every sample held in all, whichever task holds it (`study_progress`).
    let report = |i: usize, done: usize| progress.set(plan.held(i, done) as u64 * steps);
    Ok(study::run_tasks(store, &report, on_load)?)
}

/// Writes `<stem>.csv`, `.png` and `.svg`, the `extra` charts side by side as
/// `tangential.png` and `.svg` ([`DERIVED_STEM`]) where there are any (and, with `record`,
/// the record of what was written, [`crate::rerun::RECORD`]) into `dir`, all or none.
pub fn write_together(
    dir: &Path,
    stem: &str,
    table: &Table,
    (chart, extra): (&Chart, &[Chart]),
    force: bool,
    record: bool,
) -> Result<()> {
    let (csv, png, svg) = (
        dir.join(format!("{stem}.csv")),
        dir.join(format!("{stem}.png")),
        dir.join(format!("{stem}.svg")),
    );
    let derived = ["png", "svg"].map(|ext| dir.join(format!("{DERIVED_STEM}.{ext}")));
    let record_path = dir.join(crate::rerun::RECORD);
    let mut paths = vec![&csv, &png, &svg];
    if !extra.is_empty() {
        paths.extend(&derived);
    }
    if record {
        paths.push(&record_path);
    }
    let mut staged = asperity::io::StagedOutputs::new(paths, force)?;
    table.stage(&mut staged, &csv)?;
    chart.stage(&mut staged, &png, &svg)?;
    if !extra.is_empty() {
        for path in &derived {
            crate::plot::stage_charts(&mut staged, path, extra)?;
        }
    }
    if record {
        crate::rerun::stage_record(&mut staged, &record_path)?;
    }
    staged.commit()?;
    Ok(())
}

/// The CSV of a result table ([`asperity_app::study::rows`]): numbers as the CLI writes
/// them ([`format_number`]), a missing one as an empty cell.
fn csv_table(table: &rows::Table) -> Table {
    let names: Vec<&str> = table.columns.iter().map(|(name, _)| *name).collect();
    let mut csv = Table::new(&names);
    for row in &table.rows {
        let cells: Vec<String> = row
            .iter()
            .map(|cell| match *cell {
                Cell::Text(text) => text.to_string(),
                Cell::Count(count) => count.to_string(),
                Cell::Number(value) => value.map(format_number).unwrap_or_default(),
            })
            .collect();
        csv.push(&cells);
    }
    csv
}

/// `alpha.csv` (contract columns first, then extras) and the α(H) plot with theory curves,
/// written together.
/// `setting`: the `reproduce` setting, marked on the plot.
pub fn write_alpha(
    dir: &Path,
    results: &[TaskResult],
    force: bool,
    setting: Option<&str>,
) -> Result<()> {
    let chart = alpha_chart(results, &titled(Kind::Alpha, setting));
    let table = csv_table(&rows::alpha_table(results));
    write_together(dir, "alpha", &table, (&chart, &[]), force, false)
}

/// `<stem>.csv` with the ensemble-mean curves and a log–log plot of k(F), written together.
/// `setting`: the `reproduce` setting, marked on the plot.
pub fn write_curves(
    dir: &Path,
    results: &[TaskResult],
    force: bool,
    stem: &str,
    setting: Option<&str>,
) -> Result<()> {
    let chart = curve_chart(results, &titled(Kind::Curve, setting));
    let table = csv_table(&rows::curve_table(results));
    write_together(dir, stem, &table, (&chart, &[]), force, false)
}

#[cfg(test)]
mod tests {
    use super::*;
    use asperity::study::samplers::BemSampler;
    use asperity::study::{sample_cost, EnsemblePoint, Task};

    #[test]
    fn a_resumed_study_counts_what_its_checkpoints_hold_and_times_only_what_is_left() {
        // Two tasks (N = 64, 128) of 4 samples; the second task's checkpoint holds 3, the
        // first none: the bar starts at 3 samples' loads, and the cost left is that of the
        // 4 + 1 samples to compute, whatever the task order.
        let spec = StudySpec {
            method: Method::Bem,
            sizes: vec![64, 128],
            hursts: vec![0.5],
            samples: 4,
            rolloff: None,
            seed: 1,
            window: asperity::study::FitWindow::default(),
            levels: 48,
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
        };
        let segments = StudyProgress::new(&spec, vec![0, 3]).segments();
        let mut eta = asperity_app::study::progress::Eta::weighted(&segments);
        let loads = BemSampler::LOADS as u64;
        assert_eq!(eta.total(), 8 * loads);
        eta.restore(0, 3 * loads);
        let (small, large) = (sample_cost(Method::Bem, 64), sample_cost(Method::Bem, 128));
        let left = eta.cost_to(eta.total()) - eta.cost_to(3 * loads);
        assert!((left - (4.0 * small + large)).abs() < 1e-6 * left, "{left}");
        // The announcement states an α study's sweep (the same loads counted: an ended
        // sweep reports the loads it skips).
        assert_eq!(describe_sweep(&spec), "");
        let alpha = spec.clone().with_alpha_sweep();
        assert_eq!(
            describe_sweep(&alpha),
            ", loads up to the first past 8 % contact"
        );
        assert_eq!(StudyProgress::new(&alpha, vec![0, 3]).segments(), segments);
        // One sample of N = 64 computed in 10 s: 10 s per `small`, the rest in proportion.
        let eta_s = eta.remaining(4 * loads, 10.0).unwrap();
        assert!((eta_s - 10.0 * (3.0 * small + large) / small).abs() < 1e-9 * eta_s);
    }

    fn result(lows: &[f64]) -> TaskResult {
        let point = |i: usize, &low: &f64| EnsemblePoint {
            force: (i + 1) as f64,
            stiffness: 1.0,
            stiffness_low: low,
            stiffness_high: 2.0,
            fraction: 0.1,
            fraction_low: 0.1,
            fraction_high: 0.1,
            samples: 3,
            tangential_ratio: None,
        };
        TaskResult {
            method: Method::Mdr,
            task: Task { n: 64, hurst: 0.5 },
            samples: 3,
            mean_curve: lows.iter().enumerate().map(|(i, l)| point(i, l)).collect(),
            alpha_ensemble: None,
            alpha_samples: vec![],
        }
    }

    #[test]
    fn curve_plots_carry_the_interval_and_a_slope_one_line() {
        let chart = curve_chart(&[result(&[0.5, 0.6, -0.3, 0.0, 0.7, 0.8])], "t");
        assert_eq!(chart.series.len(), 2, "the mean and the reference");
        let interval = chart.series[0].interval.clone().expect("an interval");
        assert_eq!(interval.len(), 6);
        assert_eq!(interval[2], (-0.3, 2.0), "kept: the plot leaves it out");
        // The reference has slope 1 and ends at the largest force.
        let line = &chart.series[1].points;
        let (a, b) = (line[0], line[1]);
        assert!(((b.1 / a.1).ln() / (b.0 / a.0).ln() - 1.0).abs() < 1e-12);
        assert_eq!(b.0, 6.0);
    }
}
