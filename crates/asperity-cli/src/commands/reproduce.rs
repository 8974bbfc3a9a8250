//! `asperity reproduce FIGURE`: regenerate a figure of the paper or the book chapter.

use std::path::{Path, PathBuf};

use super::setting::Setting;
use crate::rerun::{checksum, Written};

/// Which figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Figure {
    /// Paper Fig. 1: α(H) from BEM and MDR with theory.
    #[value(name = "fig1")]
    Fig1,
    /// Paper Fig. 2: k(F) for surfaces with roll-off.
    #[value(name = "fig2")]
    Fig2,
    /// Paper Fig. 5: α(N) for H < 0 against eq. (24).
    #[value(name = "fig5")]
    Fig5,
    /// Paper Fig. 6: grey-scale surfaces and lines for several H.
    #[value(name = "fig6")]
    Fig6,
    /// Book Fig. 15.1: Hertz with linear and non-linear springs.
    #[value(name = "fig15.1")]
    Fig15_1,
    /// Book Fig. 15.2: fractal lines with linear and non-linear springs.
    #[value(name = "fig15.2")]
    Fig15_2,
    /// Every figure.
    #[value(name = "all")]
    All,
}

/// Arguments of `asperity reproduce`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Examples:\n  asperity reproduce all --quick --out figs     # every figure, about a minute on 2 cores\n  asperity reproduce fig1 --quick --out figs\n  asperity reproduce fig1 --setting medium --out figs   # BEM on 256² and 512²: hours\n  asperity reproduce fig15.2 --out figs\n\nEach figure writes DIR/<figure>/ with CSV, PNG, SVG and report.md (the paper's values\nbeside ours); timings.json holds the run's wall time. Studies checkpoint: an interrupted
run resumes when the same command runs again (each folder's reproduce.json records the
figure and setting that made it, and the checksum of every file it wrote: a file edited
since is never overwritten without --force).\nSettings: quick (minutes), medium (BEM on 256² and 512², 20 samples: hours, with an
estimate printed before it starts), paper (the default: grids up to 1024², 60 samples: about 10 hours for all the figures)."
)]
pub struct ReproduceArgs {
    /// The figure to regenerate.
    pub figure: Figure,
    /// How closely to follow the paper's grids and samples: quick (minutes), medium (BEM on
    /// 256² and 512², hours), paper (grids up to 1024², about 10 hours for all the
    /// figures); stated in each report.
    #[arg(long, value_enum, default_value = "paper", conflicts_with = "quick")]
    pub setting: Setting,
    /// The quick setting: `--setting quick`.
    #[arg(long)]
    pub quick: bool,
    /// Output folder (one sub-folder per figure).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite existing outputs.
    #[arg(long)]
    pub force: bool,
}

impl Figure {
    /// Folder name under `--out`.
    pub fn folder(&self) -> &'static str {
        match self {
            Figure::Fig1 => "fig1",
            Figure::Fig2 => "fig2",
            Figure::Fig5 => "fig5",
            Figure::Fig6 => "fig6",
            Figure::Fig15_1 => "fig15.1",
            Figure::Fig15_2 => "fig15.2",
            Figure::All => ".",
        }
    }
}

/// What a figure folder was made by: `DIR/<figure>/reproduce.json`, with the checksum of
/// every file the figure wrote there once it is complete (see [`crate::rerun`]). The same
/// command run again on the same folder resumes there (study checkpoints are kept, and
/// the figure's own outputs, deterministic, are written anew) as long as no output was
/// edited since; a folder holding anything else is refused before any work unless
/// `--force`.
#[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct FolderStamp {
    figure: String,
    /// The setting's name (`quick`, `medium`, `paper`).
    #[serde(default)]
    setting: String,
    /// The stamp of asperity 0.1 before settings: `true` for `--quick` (read when
    /// `setting` is absent).
    #[serde(default, skip_serializing)]
    quick: bool,
    /// Whether the figure finished (an interrupted one is resumed, its partial outputs
    /// rewritten).
    #[serde(default)]
    complete: bool,
    /// Checksums of the files of a complete figure.
    #[serde(default)]
    written: Written,
}

/// Files in a figure folder that are not outputs: the stamp, the lock, the timings.
fn is_bookkeeping(name: &str) -> bool {
    name == STAMP || name == TIMINGS || name == asperity::lock::LOCK_FILE || name.starts_with('.')
}

/// The figure's own files in `dir` (top level; study sub-folders keep their own record).
fn figure_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<_> = entries
        .filter_map(|e| e.ok())
        .filter(|e| e.file_type().is_ok_and(|t| !t.is_dir()))
        .filter(|e| !is_bookkeeping(&e.file_name().to_string_lossy()))
        .map(|e| e.path())
        .collect();
    files.sort();
    files
}

/// Whether the figure may write over files in `dir`: yes when it is empty or new, when it
/// was made by this same figure and setting and none of its outputs was edited since, or
/// with `--force`; else a one-line refusal naming the folder or the edited file.
fn may_overwrite(dir: &Path, stamp: &FolderStamp, force: bool) -> anyhow::Result<bool> {
    let holds_files = std::fs::read_dir(dir).is_ok_and(|entries| {
        entries
            .filter_map(|e| e.ok())
            .any(|e| !is_bookkeeping(&e.file_name().to_string_lossy()))
    });
    if !holds_files || force {
        return Ok(force);
    }
    let found = asperity::input::read_text(&dir.join(STAMP), asperity::input::TEXT_MAX_BYTES)
        .ok()
        .and_then(|text| serde_json::from_str::<FolderStamp>(&text).ok());
    let command = format!(
        "`asperity reproduce {} --setting {}`",
        stamp.figure, stamp.setting
    );
    let Some(found) = found.filter(|f| f.figure == stamp.figure && f.setting() == stamp.setting)
    else {
        anyhow::bail!(
            "{} holds files not made by {command}: use another --out, or --force to overwrite \
             them",
            dir.display()
        );
    };
    if found.complete {
        if let Some(edited) = figure_files(dir)
            .iter()
            .find(|f| !found.written.unchanged(f))
        {
            anyhow::bail!(
                "{}: changed since {command} wrote it (or not written by it): use another \
                 --out, or --force to overwrite it",
                edited.display()
            );
        }
    }
    Ok(true)
}

impl FolderStamp {
    /// The setting that made the folder (a stamp without one: `quick` or `paper`).
    fn setting(&self) -> &str {
        match (self.setting.as_str(), self.quick) {
            ("", true) => "quick",
            ("", false) => "paper",
            (name, _) => name,
        }
    }
}

const STAMP: &str = "reproduce.json";

/// The record of a figure's last run: wall time, setting, command line and asperity
/// version (kept apart, so that every result file of a rerun is byte-identical).
const TIMINGS: &str = "timings.json";

/// Runs one figure in its folder, holding the folder's lock: `force` lets it write over
/// files there ([`may_overwrite`]); `discard` (the user's --force) lets its studies discard
/// another study's checkpoints. A refusal before any output leaves no folder behind.
fn run_one(
    figure: Figure,
    out: &Path,
    setting: Setting,
    force: bool,
    discard: bool,
) -> anyhow::Result<()> {
    let dir = out.join(figure.folder());
    let existed = dir.exists();
    std::fs::create_dir_all(&dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    let lock = asperity::lock::FolderLock::acquire(&dir)?;
    let mut stamp = FolderStamp {
        figure: figure.folder().to_string(),
        setting: setting.name().to_string(),
        quick: false,
        complete: false,
        written: Written::default(),
    };
    asperity::io::write_json(&dir.join(STAMP), true, &stamp)?;
    let start = std::time::Instant::now();
    if let Err(err) = run_figure(figure, &dir, out, setting, force, discard) {
        if !existed {
            remove_if_untouched(&dir, lock);
        }
        return Err(err);
    }
    let seconds = start.elapsed().as_secs_f64();
    for file in figure_files(&dir) {
        let bytes = std::fs::read(&file).map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
        let name = file
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        stamp
            .written
            .outputs
            .insert(name, checksum(asperity::io::fnv1a64(&bytes)));
    }
    stamp.complete = true;
    asperity::io::write_json(
        &dir.join(TIMINGS),
        true,
        &serde_json::json!({
            "seconds": seconds,
            "setting": setting.name(),
            "command": std::env::args().collect::<Vec<_>>().join(" "),
            "version": env!("CARGO_PKG_VERSION"),
        }),
    )?;
    asperity::io::write_json(&dir.join(STAMP), true, &stamp)?;
    eprintln!(
        "{}: done in {seconds:.1} s -> {}",
        figure.folder(),
        dir.display()
    );
    Ok(())
}

fn run_figure(
    figure: Figure,
    dir: &Path,
    out: &Path,
    setting: Setting,
    force: bool,
    discard: bool,
) -> anyhow::Result<()> {
    match figure {
        Figure::Fig1 => super::figures::fig1(dir, setting, force, discard),
        Figure::Fig2 => super::figures::fig2(dir, setting, force, discard),
        Figure::Fig5 => super::figures::fig5(dir, setting, force, discard),
        Figure::Fig6 => super::figures::fig6(dir, setting, force),
        // The book's figures name their own folder under `out`.
        Figure::Fig15_1 => super::figures::fig15_1(out, setting, force),
        Figure::Fig15_2 => super::figures::fig15_2(out, setting, force),
        Figure::All => unreachable!("expanded by run"),
    }
}

/// Removes a figure folder made by this run if it holds nothing but bookkeeping (the
/// figure was refused before writing anything, e.g. for memory).
fn remove_if_untouched(dir: &Path, lock: asperity::lock::FolderLock) {
    let only_ours = std::fs::read_dir(dir).is_ok_and(|entries| {
        entries.filter_map(|e| e.ok()).all(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            name == STAMP || name == asperity::lock::LOCK_FILE
        })
    });
    if only_ours {
        let _ = std::fs::remove_file(dir.join(STAMP));
        let _ = std::fs::remove_file(dir.join(asperity::lock::LOCK_FILE));
        drop(lock);
        let _ = std::fs::remove_dir(dir);
    }
}

/// Runs `asperity reproduce`.
pub fn run(args: &ReproduceArgs) -> anyhow::Result<()> {
    let setting = if args.quick {
        Setting::Quick
    } else {
        args.setting
    };
    let figures: Vec<Figure> = match args.figure {
        Figure::All => vec![
            Figure::Fig6,
            Figure::Fig15_1,
            Figure::Fig15_2,
            Figure::Fig1,
            Figure::Fig5,
            Figure::Fig2,
        ],
        one => vec![one],
    };
    // Every folder is checked before the first figure starts: a refusal loses no work.
    let overwrite = figures
        .iter()
        .map(|figure| {
            let stamp = FolderStamp {
                figure: figure.folder().to_string(),
                setting: setting.name().to_string(),
                quick: false,
                complete: false,
                written: Written::default(),
            };
            may_overwrite(&args.out.join(figure.folder()), &stamp, args.force)
        })
        .collect::<anyhow::Result<Vec<bool>>>()?;
    for (figure, force) in figures.into_iter().zip(overwrite) {
        run_one(figure, &args.out, setting, force, args.force)?;
    }
    Ok(())
}
