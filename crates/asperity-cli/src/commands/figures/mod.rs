//! The figures of `asperity reproduce`, one file each: the paper's Figs. 1, 2, 5 and 6 and the
//! book's Figs. 15.1 and 15.2 (Popov & Heß ch. 15). Each is a plan (grids, samples, levels),
//! a compute step returning typed rows, and write steps (CSV, PNG + SVG, `report.md`). This
//! module holds what they share: the study runner of the BEM/MDR figures, the announcement
//! of a long run and the output folder of the book's figures.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use asperity::study::{FitWindow, Method, StudySpec, TaskResult};

use super::setting::Setting;
use crate::plot::{Chart, ChartFiles};
use crate::studies::{execute, Kind, RunOptions};

mod fig1;
mod fig15_1;
mod fig15_2;
mod fig2;
mod fig5;
mod fig6;

pub use fig1::fig1;
pub use fig15_1::fig15_1;
pub use fig15_2::fig15_2;
pub use fig2::fig2;
pub use fig5::fig5;
pub use fig6::fig6;

pub use asperity_app::study::report::write_report;

/// Output files of one book figure, checked before any work.
struct Outputs {
    dir: PathBuf,
    force: bool,
}

impl Outputs {
    fn new(dir: PathBuf, names: &[&str], force: bool) -> Result<Self> {
        for name in names {
            asperity::io::ensure_new_output(&dir.join(name), force)?;
        }
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Outputs { dir, force })
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Writes `chart` as `<stem>.png` and `<stem>.svg`.
    fn save_chart(&self, chart: &Chart, stem: &str) -> Result<()> {
        chart.save(
            &self.path(&format!("{stem}.png")),
            &self.path(&format!("{stem}.svg")),
            self.force,
        )
    }

    /// Writes `report.md` and says where the figure went (`figure`: its name on stderr).
    fn write_report(&self, figure: &str, text: &str) -> Result<()> {
        asperity::io::write_bytes(&self.path("report.md"), self.force, text.as_bytes())?;
        eprintln!("{figure}: wrote {}", self.dir.display());
        Ok(())
    }
}

const BLUE: asperity_app::figure::Color = asperity_app::figure::Color::Rgb(31, 119, 180);
const GREEN: asperity_app::figure::Color = asperity_app::figure::Color::Rgb(44, 160, 44);
const BLACK: asperity_app::figure::Color = asperity_app::figure::Color::Rgb(0, 0, 0);
const GREY: asperity_app::figure::Color = asperity_app::figure::Color::Rgb(150, 150, 150);

fn study_spec(
    method: Method,
    sizes: Vec<usize>,
    hursts: Vec<f64>,
    samples: usize,
    rolloff: Option<f64>,
) -> StudySpec {
    StudySpec {
        method,
        sizes,
        hursts,
        samples,
        rolloff,
        seed: 2013,
        window: FitWindow::default(),
        levels: asperity::study::DEFAULT_LEVELS,
        sweep_end: None,
        poisson: None,
        tangential: Default::default(),
    }
}

/// `-1 … 3 (17 values)`.
fn describe_hursts(hursts: &[f64]) -> String {
    match hursts {
        [] => "none".into(),
        [one] => format!("{one}"),
        [first, .., last] => format!("{first} … {last} ({} values)", hursts.len()),
    }
}

/// States a figure's BEM studies before they start: grids, samples and, for the settings
/// that take hours, the estimated run time measured on this machine
/// ([`crate::estimate::estimate_study`]: seconds to two minutes of probing).
fn announce(figure: &str, setting: Setting, dir: &Path, studies: &[&StudySpec]) -> Result<()> {
    if setting == Setting::Quick {
        // Minutes: the report states the setting; stderr stays for errors.
        return Ok(());
    }
    for spec in studies {
        eprintln!(
            "{figure} ({} setting): BEM on N = {:?}, {} samples per (N, H), H = {}{}",
            setting.name(),
            spec.sizes,
            spec.samples,
            describe_hursts(&spec.hursts),
            crate::studies::describe_sweep(spec)
        );
        if matches!(setting, Setting::Medium | Setting::Paper) {
            let (estimate, stored) = crate::estimate::estimate_study(spec, &dir.join("bem"))?;
            eprintln!(
                "{figure}: estimated BEM time on this machine {}{} ({} lanes; \
                 checkpointed: an interrupted run resumes with the same command)",
                crate::estimate::human_duration(estimate.seconds),
                match stored {
                    0 => String::new(),
                    s => format!(" for the samples left ({s} already checkpointed)"),
                },
                estimate.lanes
            );
        }
    }
    Ok(())
}

/// Runs one study of a figure in `dir/<name>/` (its own checkpoint, lock and record of
/// outputs) and returns results; `discard` is the user's --force.
fn figure_study(
    dir: &Path,
    name: &str,
    spec: &StudySpec,
    kind: Kind,
    setting: Setting,
    force: bool,
) -> Result<Vec<TaskResult>> {
    let sub = dir.join(name);
    let options = RunOptions {
        force,
        quiet: false,
        checkpoint_every: asperity::study::CHECKPOINT_INTERVAL,
        setting: Some(setting.name()),
        derived: Default::default(),
    };
    execute(spec, &sub, options, kind)
}
