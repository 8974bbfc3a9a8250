//! The comparison with the paper (`asperity study compare`, Python's `study_compare`, and
//! each `report.md` of `asperity reproduce`, Figs. 1, 2, 5): every result beside the
//! paper's statement or equation, with its 95 % interval, whether the two agree within
//! it, by how much, and the likely reason when they do not; how α moves with N; and how it
//! moves with the fit window.
//!
//! The rows go to `comparison.csv` ([`comparison_csv`]), and the tables of the report are
//! rendered **from that CSV** ([`parse`], [`render`]), so that the text a reader sees is
//! the file a script can check.
//!
//! The rows, their intervals and verdicts are the library's ([`asperity::study::compare`],
//! which Python's `StudyResult.comparison()` also uses); this module writes and renders
//! them, once for both front ends.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use asperity::study::compare;
pub use asperity::study::compare::{Results, Row, CLOSE};
use asperity::study::sensitivity::{sensitivity_windows, study_sensitivity, study_slopes};

use crate::study::rows::COMPARISON_COLUMNS;
use crate::table::{csv_bytes, format_number, CsvError};

/// Why a comparison could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The library's error: the study folder cannot be read, a roll-off study's sweeps
    /// ended, an output exists and overwriting was not allowed.
    #[error(transparent)]
    Library(#[from] asperity::Error),
    /// A table's CSV text could not be made.
    #[error(transparent)]
    Csv(#[from] CsvError),
    /// A task of the study is not finished.
    #[error(
        "{}: task N = {n}, H = {hurst} is not finished ({done} of {samples} samples): \
         rerun the study's command to finish it first",
        dir.display()
    )]
    Unfinished {
        /// The study folder.
        dir: PathBuf,
        /// The task's grid size.
        n: usize,
        /// The task's Hurst exponent.
        hurst: f64,
        /// Samples it has finished.
        done: usize,
        /// Samples it needs.
        samples: usize,
    },
    /// A row of `comparison.csv` has fewer fields than its header.
    #[error("short row in comparison.csv")]
    ShortRow,
    /// A field of `comparison.csv` that holds a number does not.
    #[error("comparison.csv: `{field}` is not a number")]
    NotANumber {
        /// The field.
        field: String,
        /// Why it does not parse.
        source: std::num::ParseFloatError,
    },
}

/// The text of `comparison.csv` of `rows`, under the front-end layer's header
/// ([`COMPARISON_COLUMNS`]).
pub fn comparison_csv(rows: &[Row]) -> Result<Vec<u8>, CsvError> {
    let header: Vec<&str> = COMPARISON_COLUMNS.iter().map(|(name, _)| *name).collect();
    let fields = |r: &Row| {
        vec![
            r.method.clone(),
            // A grid size: lines per side or grid points, always a whole number.
            format!("{}", r.n as u64),
            format_number(r.hurst),
            r.quantity.clone(),
            format_number(r.ours),
            format_number(r.low),
            format_number(r.high),
            format_number(r.reference),
            r.source.clone(),
            format_number(r.tolerance),
        ]
    };
    csv_bytes(&header, &rows.iter().map(fields).collect::<Vec<_>>())
}

/// Reads the rows back from the text of a `comparison.csv`.
pub fn parse(csv_text: &str) -> Result<Vec<Row>, ReportError> {
    let mut reader = csv::Reader::from_reader(csv_text.as_bytes());
    let mut rows = Vec::new();
    for record in reader.records() {
        let rec = record.map_err(CsvError::from)?;
        let num = |i: usize| -> Result<f64, ReportError> {
            let field = rec.get(i).ok_or(ReportError::ShortRow)?;
            field
                .parse::<f64>()
                .map_err(|source| ReportError::NotANumber {
                    field: field.to_string(),
                    source,
                })
        };
        rows.push(Row {
            method: rec.get(0).unwrap_or_default().to_string(),
            n: num(1)?,
            hurst: num(2)?,
            quantity: rec.get(3).unwrap_or_default().to_string(),
            ours: num(4)?,
            low: num(5)?,
            high: num(6)?,
            reference: num(7)?,
            source: rec.get(8).unwrap_or_default().to_string(),
            tolerance: num(9)?,
        });
    }
    Ok(rows)
}

/// The verdict of a row, as the report words it.
pub fn verdict(row: &Row) -> &'static str {
    compare::verdict(row).name()
}

/// The likely reason of a disagreement, by where the row lies (the crossovers of the
/// theory, the grid): a reading to check, not a measurement.
fn reason(row: &Row) -> String {
    let grid = match (row.method.as_str(), row.source.contains("N = points")) {
        ("mdr", _) => format!("finite line ({} points)", row.n),
        (_, true) => format!("finite grid ({} points)", row.n),
        _ => format!("finite grid ({}²)", row.n),
    };
    if row.quantity == "steepest_slope" {
        return if row.n < 1024.0 {
            format!("{grid}: the paper's curves are on 1024²")
        } else {
            "the paper's grid: the paper reads \"≈ 1\" off its plot, this is the steepest \
             decade of the mean curve"
                .into()
        };
    }
    if row.hurst > 0.0 && row.hurst <= 0.5 {
        return "crossover of eq. (24) and eq. (6) at H = 0: the theory's kink is sharp, \
                finite ensembles round it"
            .into();
    }
    if (row.hurst - 2.0).abs() <= 0.5 {
        return "crossover of eq. (6) and Hertz at H = 2: sharp in theory, rounded here".into();
    }
    grid
}

/// The comparison table of `rows` (rendered from `comparison.csv`), one verdict a row.
pub fn render(rows: &[Row]) -> String {
    let mut md = String::from(
        "| method | N | H | quantity | ours | 95 % interval | paper | source | verdict | \
         ours − paper | likely reason |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let interval = if r.low == r.high || r.low.is_nan() {
            "—".to_string()
        } else {
            format!("{:.3} – {:.3}", r.low, r.high)
        };
        let verdict = verdict(r);
        let why = match verdict {
            "differs" => reason(r),
            _ => "—".to_string(),
        };
        let half = 0.5 * (r.high - r.low);
        let by = if half > 0.0 {
            format!(
                "{:+.3} ({:+.1} half-widths)",
                r.ours - r.reference,
                (r.ours - r.reference) / half
            )
        } else {
            format!("{:+.3}", r.ours - r.reference)
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.3} | {interval} | {:.3} | {} | {verdict} | {by} | {why} |",
            r.method, r.n, r.hurst, r.quantity, r.ours, r.reference, r.source
        );
    }
    let count = |v: &str| rows.iter().filter(|r| verdict(r) == v).count();
    let _ = writeln!(
        md,
        "\n{} of {} rows agree with the paper within their 95 % interval, {} more are within \
         {CLOSE} of it, {} differ.",
        count("agrees"),
        rows.len(),
        count("close"),
        count("differs")
    );
    md
}

/// How α moves with N: for every (method, H, source) measured at two or more N, the change
/// of ours and of the paper's value between the smallest and the largest N, and whether
/// ours changes by more than the paper's within the combined interval.
pub fn trend(rows: &[Row]) -> String {
    let mut md = String::from(
        "| method | H | source | N | ours | Δ ours | Δ paper | Δ ours − Δ paper | reading |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let mut keys: Vec<(String, f64, String)> = Vec::new();
    for r in rows.iter().filter(|r| r.quantity == "alpha") {
        let key = (r.method.clone(), r.hurst, r.source.clone());
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    let mut lines = 0;
    for (method, hurst, source) in keys {
        let group: Vec<&Row> = rows
            .iter()
            .filter(|r| r.method == method && r.hurst == hurst && r.source == source)
            .collect();
        let (Some(a), Some(b)) = (group.first(), group.last()) else {
            continue;
        };
        if group.len() < 2 || a.n == b.n {
            continue;
        }
        let (ours, paper) = (b.ours - a.ours, b.reference - a.reference);
        let half = (0.25 * ((a.high - a.low).powi(2) + (b.high - b.low).powi(2))).sqrt();
        let excess = ours - paper;
        // Pastewka et al.'s reading concerns the elastic interaction of contact spots on
        // a surface (BEM); an MDR line has none, its N trend is the window's.
        let reading = match (excess.abs() <= half, excess > 0.0, method.as_str()) {
            (true, _, _) => "as the paper (within the interval)",
            (false, true, "bem") => "rises faster than the paper's: the finite-size reading",
            (false, true, _) => {
                "rises faster than the paper's (short lines: the window covers a large part)"
            }
            (false, false, _) => "rises slower than the paper's",
        };
        let sizes: Vec<String> = group.iter().map(|r| r.n.to_string()).collect();
        let values: Vec<String> = group.iter().map(|r| format!("{:.3}", r.ours)).collect();
        let _ = writeln!(
            md,
            "| {method} | {hurst} | {source} | {} | {} | {ours:+.3} | {paper:+.3} | {excess:+.3} ± {half:.3} | {reading} |",
            sizes.join(", "),
            values.join(", ")
        );
        lines += 1;
    }
    if lines == 0 {
        return String::new();
    }
    md.push_str(
        "\nΔ: from the smallest to the largest N. The paper's α depends on N only through \
         eq. (24) (H ≤ 0); Pastewka et al. (PRE 87, 062809, 2013) read the sublinear k ∝ F^α \
         at low load as a finite-size effect, which would make α rise with N towards 1 for \
         every H, faster than eq. (24) and also where eq. (6) has no N at all.\n",
    );
    md
}

/// The window sensitivity of the study in `study_dir` (from the sample curves its
/// checkpoints keep): `window_sensitivity.csv` in `dir` and a markdown table, or a
/// sentence saying why there is none.
fn sensitivity(dir: &Path, study_dir: &Path, force: bool) -> Result<String, ReportError> {
    let windows = sensitivity_windows();
    let found = study_sensitivity(study_dir, &windows)?;
    if found.is_empty() {
        return Ok(
            "No sample curves are stored for this figure's BEM study (its checkpoints \
                   predate stored curves): rerun it to get the window sensitivity.\n"
                .into(),
        );
    }
    let mut md = String::from("| N | H | window start (contacts) | end (contact fraction) | α | bootstrap 95 % |\n|---|---|---|---|---|---|\n");
    for t in &found {
        for w in &t.windows {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.3} | {:.3} – {:.3} |",
                t.task.n,
                t.task.hurst,
                w.window.min_contacts,
                w.window.max_fraction,
                w.alpha,
                w.low,
                w.high
            );
        }
    }
    let table = crate::study::windows::csv(&crate::study::windows::rows(&found))?;
    asperity::io::write_bytes(&dir.join("window_sensitivity.csv"), force, &table)?;
    Ok(md)
}

/// Writes `comparison.csv` and `report.md`: the figure's own `report` text, then the
/// comparison rendered from the CSV, the N trend and the window sensitivity of its BEM
/// study (folder `dir/bem`).
pub fn write(dir: &Path, results: Results, report: &str, force: bool) -> Result<(), ReportError> {
    write_for_study(dir, &dir.join("bem"), results, report, force).map(drop)
}

/// [`write`] with the BEM study in `study_dir` (its stored sample curves give the window
/// sensitivity and the slopes' intervals); the rows as read back from `comparison.csv`.
fn write_for_study(
    dir: &Path,
    study_dir: &Path,
    results: Results,
    report: &str,
    force: bool,
) -> Result<Vec<Row>, ReportError> {
    let slopes = match results {
        Results::Fig2(..) if study_dir.join("study.json").is_file() => study_slopes(study_dir)?,
        _ => Vec::new(),
    };
    let path = dir.join("comparison.csv");
    let table = comparison_csv(&compare::rows(&results, &slopes))?;
    asperity::io::write_bytes(&path, force, &table)?;
    let text = asperity::input::read_text(&path, asperity::input::TEXT_MAX_BYTES)?;
    let rows = parse(&text)?;
    let mut md = format!(
        "{report}\n## Verdicts (generated from `comparison.csv`)\n\
         Interval: the ensemble α ± t·s/√m over the m per-sample α (95 %; a steepest slope: \
         2.5 – 97.5 % of 400 bootstrap resamples of the samples); *agrees* when the \
         paper's value lies inside it (widened by 0.1 for the paper's \"≈ 1\"); *close* when \
         outside it by at most {CLOSE} (the estimator's own accuracy, docs/mdr.md).\n\n{}",
        render(&rows)
    );
    let trend = trend(&rows);
    if !trend.is_empty() {
        let _ = write!(md, "\n## How α moves with N\n\n{trend}");
    }
    let _ = write!(
        md,
        "\n## How α moves with the fit window (BEM)\n\n\
         α refitted on the stored sample curves with windows starting at 4, 8, 16 contacts and \
         ending at 0.5, 1, 2 % contact (`window_sensitivity.csv`; also `asperity study \
         windows DIR/bem`); interval: bootstrap over samples.\n\n{}",
        sensitivity(dir, study_dir, force)?
    );
    write_report(dir, &md, force)?;
    Ok(rows)
}

/// Writes `report.md` into `dir` atomically.
pub fn write_report(dir: &Path, text: &str, force: bool) -> asperity::Result<()> {
    asperity::io::write_bytes(&dir.join("report.md"), force, text.as_bytes())
}

/// `asperity study compare DIR` (Python's `study_compare`): the finished study in `dir`
/// beside the paper — `comparison.csv` and `report.md` (and `window_sensitivity.csv` of a
/// BEM study with stored sample curves) in `dir`, overwritten only if `force`. A study
/// with roll-off is compared like Fig. 2 (steepest slope against "≈ 1"), one without like
/// Fig. 1 (α against eqs. (6), (24)). Returns the rows of `comparison.csv` as read back
/// from it ([`verdict`] gives each one's verdict).
pub fn compare_study(dir: &Path, force: bool) -> Result<Vec<Row>, ReportError> {
    use asperity::study::{Restored, StudyDir};
    let store = StudyDir::read(dir)?;
    let spec = store.spec().clone();
    let mut results = Vec::new();
    for task in spec.tasks() {
        match store.restore(task)? {
            Restored::Done(r) => results.push(r),
            Restored::Partial(done) => {
                return Err(ReportError::Unfinished {
                    dir: dir.to_path_buf(),
                    n: task.n,
                    hurst: task.hurst,
                    done: done.len(),
                    samples: spec.samples,
                })
            }
        }
    }
    if spec.rolloff.is_some() {
        asperity::study::sensitivity::ensure_whole_sweep(&spec, dir)?;
    }
    let (kind, figure) = match spec.rolloff {
        Some(_) => ("steepest slope", Results::Fig2(&results, spec.window)),
        None => ("α", Results::Fig1(&results)),
    };
    let report = format!(
        "# Comparison with the paper: {} study in `{}`\n\n{} of N = {:?}, H = {:?}, {} \
         samples each, roll-off {}, seed {}, window {}; asperity {}. Regenerate with \
         `asperity study compare {} --force`.\n",
        spec.method.name(),
        dir.display(),
        kind,
        spec.sizes,
        spec.hursts,
        spec.samples,
        spec.rolloff.map_or("none".into(), |r| r.to_string()),
        spec.seed,
        spec.window.describe(),
        env!("CARGO_PKG_VERSION"),
        dir.display()
    );
    write_for_study(dir, dir, figure, &report, force)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(ours: f64, low: f64, high: f64, reference: f64, tolerance: f64) -> Row {
        Row {
            method: "bem".into(),
            n: 512.0,
            hurst: -1.0,
            quantity: "alpha".into(),
            ours,
            low,
            high,
            reference,
            source: "eq. (24)".into(),
            tolerance,
        }
    }

    #[test]
    fn verdicts_follow_the_interval_and_the_tolerance() {
        let rows = vec![
            row(0.80, 0.78, 0.84, 0.833, 0.0),
            row(0.72, 0.70, 0.74, 0.833, 0.0),
            row(0.93, 0.93, 0.93, 1.0, 0.1),
            row(0.85, 0.85, 0.85, 1.0, 0.1),
            row(0.85, 0.84, 0.86, 0.833, 0.0),
        ];
        let csv = String::from_utf8(comparison_csv(&rows).unwrap()).unwrap();
        let back = parse(&csv).unwrap();
        assert_eq!(back, rows);
        let verdicts: Vec<&str> = back.iter().map(verdict).collect();
        assert_eq!(
            verdicts,
            ["agrees", "differs", "agrees", "differs", "close"]
        );
        let md = render(&back);
        assert_eq!(md.matches("| agrees |").count(), 2, "{md}");
        assert_eq!(md.matches("| differs |").count(), 2, "{md}");
        assert_eq!(md.matches("| close |").count(), 1, "{md}");
        // 0.72 − 0.833 in half-widths of 0.02.
        assert!(md.contains("-0.113 (-5.6 half-widths)"), "{md}");
        assert!(
            md.contains("2 of 5 rows agree with the paper within their 95 % interval, 1 more"),
            "{md}"
        );
    }

    #[test]
    fn the_trend_compares_the_change_with_n_against_the_papers() {
        let mut small = row(0.70, 0.68, 0.72, 0.818, 0.0);
        small.n = 256.0;
        let large = row(0.80, 0.78, 0.82, 0.833, 0.0);
        let md = trend(&[small.clone(), large.clone()]);
        // Δ ours 0.10, Δ paper 0.015: 0.085 > 0.028 (the combined half-width).
        assert!(md.contains("+0.100 | +0.015 | +0.085 ± 0.028"), "{md}");
        assert!(md.contains("finite-size reading"), "{md}");
        let flat = row(0.715, 0.695, 0.735, 0.833, 0.0);
        assert!(trend(&[small, flat]).contains("as the paper"));
        assert!(trend(&[large]).is_empty());
    }
}
