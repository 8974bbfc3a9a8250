//! `asperity reproduce FIGURE`: regenerate a figure of the paper or the book chapter.

use std::path::PathBuf;

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
    after_help = "Examples:\n  asperity reproduce all --quick --out figs     # every figure, about a minute on 2 cores\n  asperity reproduce fig1 --quick --out figs\n  asperity reproduce fig15.2 --out figs\n\nEach figure writes DIR/<figure>/ with CSV, PNG, SVG and report.md (the paper's values\nbeside ours). Studies checkpoint: an interrupted run resumes when the same command runs
again (each folder's reproduce.json records the figure and setting that made it).\nWithout --quick the BEM parts follow the paper (grids up to 1024², 60 samples): days."
)]
pub struct ReproduceArgs {
    /// The figure to regenerate.
    pub figure: Figure,
    /// Fewer samples and smaller grids (minutes instead of hours); stated in each report.
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

/// What a figure folder was made by: `DIR/<figure>/reproduce.json`. The same command run
/// again on the same folder resumes there (study checkpoints are kept, and the figure's own
/// outputs, deterministic, are written anew); a folder holding anything else is refused
/// before any work unless `--force`.
#[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct FolderStamp {
    figure: String,
    quick: bool,
}

/// Whether the figure may write over files in `dir`: yes when it is empty or new, when it
/// was made by this same figure and setting, or with `--force`; else a one-line refusal.
fn may_overwrite(dir: &std::path::Path, stamp: &FolderStamp, force: bool) -> anyhow::Result<bool> {
    let holds_files = std::fs::read_dir(dir).is_ok_and(|mut entries| entries.next().is_some());
    if !holds_files {
        return Ok(force);
    }
    let same = std::fs::read_to_string(dir.join(STAMP))
        .ok()
        .and_then(|text| serde_json::from_str::<FolderStamp>(&text).ok())
        .is_some_and(|found| &found == stamp);
    if same || force {
        return Ok(true);
    }
    anyhow::bail!(
        "{} holds files not made by `asperity reproduce {}{}`: use another --out, or --force to \
         overwrite them",
        dir.display(),
        stamp.figure,
        if stamp.quick { " --quick" } else { "" }
    )
}

const STAMP: &str = "reproduce.json";

/// Runs one figure; `force` lets it write over files in its folder ([`may_overwrite`]).
fn run_one(figure: Figure, out: &std::path::Path, quick: bool, force: bool) -> anyhow::Result<()> {
    let dir = out.join(figure.folder());
    let stamp = FolderStamp {
        figure: figure.folder().to_string(),
        quick,
    };
    std::fs::create_dir_all(&dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    asperity::io::write_json(&dir.join(STAMP), true, &stamp)?;
    let start = std::time::Instant::now();
    match figure {
        Figure::Fig1 => super::figures::fig1(&dir, quick, force)?,
        Figure::Fig2 => super::figures::fig2(&dir, quick, force)?,
        Figure::Fig5 => super::figures::fig5(&dir, quick, force)?,
        Figure::Fig6 => super::figures::fig6(&dir, quick, force)?,
        // The book's figures name their own folder under `out`.
        Figure::Fig15_1 => super::fig15::fig15_1(out, quick, force)?,
        Figure::Fig15_2 => super::fig15::fig15_2(out, quick, force)?,
        Figure::All => unreachable!("expanded by run"),
    }
    eprintln!(
        "{}: done in {:.1} s -> {}",
        figure.folder(),
        start.elapsed().as_secs_f64(),
        dir.display()
    );
    Ok(())
}

/// Runs `asperity reproduce`.
pub fn run(args: &ReproduceArgs) -> anyhow::Result<()> {
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
                quick: args.quick,
            };
            may_overwrite(&args.out.join(figure.folder()), &stamp, args.force)
        })
        .collect::<anyhow::Result<Vec<bool>>>()?;
    for (figure, force) in figures.into_iter().zip(overwrite) {
        run_one(figure, &args.out, args.quick, force)?;
    }
    Ok(())
}
