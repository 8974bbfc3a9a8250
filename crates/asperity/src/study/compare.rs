//! The comparison of a study with the paper: every result beside the paper's statement or
//! equation, with its 95 % interval, and a verdict — the rows that `asperity reproduce`
//! and `asperity study compare` write to `comparison.csv` and that Python's
//! `StudyResult.comparison()` returns.
//!
//! # The interval of an α
//! α is fitted on the ensemble-mean curve; its interval is that value ± `t·s/√m`, with `s`
//! the spread of the `m` per-sample α (Student t, 95 %): the uncertainty of a mean over
//! `m` samples, not the spread of single samples (the `alpha_low`, `alpha_high` columns
//! of `alpha.csv`). A result **agrees** when the reference lies inside its interval
//! widened by the reference's own looseness (`tolerance`: 0 for an equation, 0.1 for the
//! paper's "≈ 1"). Outside it but within [`CLOSE`] of the reference a result is **close**:
//! with hundreds of samples the interval shrinks below the estimator's own systematic
//! accuracy (the default window is within ±0.02 of theory for MDR lines of 2^15 points,
//! `docs/mdr.md`), so a difference that small says nothing about the paper.

use serde::Serialize;

use super::sensitivity::{self, TaskSlope};
use super::theory::{alpha_theory, alpha_white_noise};
use super::{FitWindow, TaskResult};
use crate::fit::student_t_975;

/// One result beside its reference: a row of `comparison.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// `mdr` or `bem`.
    pub method: String,
    /// Grid size as the reference reads it (Fig. 5: lines per side or grid points).
    pub n: f64,
    /// Hurst exponent.
    pub hurst: f64,
    /// What is compared (`alpha`, `steepest_slope`).
    pub quantity: String,
    /// Our value.
    pub ours: f64,
    /// 95 % interval of ours (module docs).
    pub low: f64,
    /// 95 % interval of ours, high end.
    pub high: f64,
    /// The paper's value.
    pub reference: f64,
    /// Where the paper's value comes from (`eq. (6)`, `eq. (24)`, `Hertz 1/3`, ...).
    pub source: String,
    /// How loosely the paper states its value (0 for an equation).
    pub tolerance: f64,
}

/// The results of one figure, as the figure code has them.
pub enum Results<'a> {
    /// Fig. 1: α(H) of both methods.
    Fig1(&'a [TaskResult]),
    /// Fig. 2: the mean curves of a roll-off study, its window and grid.
    Fig2(&'a [TaskResult], FitWindow),
    /// Fig. 5: MDR and BEM α at several N (H < 0).
    Fig5(&'a [TaskResult], &'a [TaskResult]),
}

/// The ensemble α and its 95 % interval (module docs); `None` without a fit.
pub fn alpha_interval(r: &TaskResult) -> Option<(f64, f64, f64)> {
    let alpha = r.alpha_ensemble?.exponent;
    let m = r.alpha_samples.len();
    if m < 2 {
        return Some((alpha, f64::NAN, f64::NAN));
    }
    let mean = r.alpha_samples.iter().sum::<f64>() / m as f64;
    let var = r
        .alpha_samples
        .iter()
        .map(|a| (a - mean).powi(2))
        .sum::<f64>()
        / (m - 1) as f64;
    let half = student_t_975(m - 1) * (var / m as f64).sqrt();
    Some((alpha, alpha - half, alpha + half))
}

/// Which theory the paper gives for α at `hurst` on `n` points (eq. 24 for H ≤ 0).
fn alpha_source(hurst: f64) -> &'static str {
    if hurst <= 0.0 {
        "eq. (24)"
    } else if hurst < 2.0 {
        "eq. (6)"
    } else {
        "Hertz 1/3"
    }
}

fn alpha_row(r: &TaskResult, n: f64, reference: f64, source: &str) -> Option<Row> {
    let (ours, low, high) = alpha_interval(r)?;
    Some(Row {
        method: r.method.name().to_string(),
        n,
        hurst: r.task.hurst,
        quantity: "alpha".into(),
        ours,
        low,
        high,
        reference,
        source: source.into(),
        tolerance: 0.0,
    })
}

/// The steepest log–log slope of a task's mean curve over one decade of force and the
/// contact fractions where it lies ([`sensitivity::steepest_slope`]).
pub fn steepest_slope(r: &TaskResult, window: &FitWindow) -> Option<(f64, f64, f64)> {
    let s = sensitivity::steepest_slope(&r.mean_curve, window, r.task.n * r.task.n)?;
    Some((s.slope, s.from_fraction, s.to_fraction))
}

/// The rows of a figure; a Fig. 2 slope takes its interval from `slopes` (the bootstrap
/// over the study's stored sample curves) where that has its task.
pub fn rows(results: &Results, slopes: &[TaskSlope]) -> Vec<Row> {
    match results {
        Results::Fig1(all) => all
            .iter()
            .filter_map(|r| {
                let theory = alpha_theory(r.task.hurst, r.task.n);
                alpha_row(r, r.task.n as f64, theory, alpha_source(r.task.hurst))
            })
            .collect(),
        Results::Fig2(all, window) => all
            .iter()
            .filter_map(|r| {
                let (slope, _, _) = steepest_slope(r, window)?;
                let (low, high) = slopes
                    .iter()
                    .find(|s| s.task == r.task && s.samples == r.samples)
                    .map_or((slope, slope), |s| (s.low, s.high));
                Some(Row {
                    method: r.method.name().to_string(),
                    n: r.task.n as f64,
                    hurst: r.task.hurst,
                    quantity: "steepest_slope".into(),
                    ours: slope,
                    low,
                    high,
                    reference: 1.0,
                    source: "paper: slope ≈ 1".into(),
                    tolerance: 0.1,
                })
            })
            .collect(),
        Results::Fig5(mdr, bem) => {
            let mut rows: Vec<Row> = mdr
                .iter()
                .filter_map(|r| {
                    let n = r.task.n as f64;
                    alpha_row(r, n, alpha_white_noise(n), "eq. (24), N = modes")
                })
                .collect();
            for r in bem.iter() {
                for (n, how) in [(r.task.n, "lines"), (r.task.n * r.task.n, "points")] {
                    let source = format!("eq. (24), N = {how}");
                    rows.extend(alpha_row(r, n as f64, alpha_white_noise(n as f64), &source));
                }
            }
            rows
        }
    }
}

/// Below this difference a result outside its interval is still **close** (module docs).
pub const CLOSE: f64 = 0.02;

/// Whether `row` agrees with its reference (module docs).
pub fn agrees(row: &Row) -> bool {
    row.reference >= row.low - row.tolerance && row.reference <= row.high + row.tolerance
}

/// How a result stands to its reference (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// The reference lies inside the interval (widened by its tolerance).
    Agrees,
    /// Outside, but within [`CLOSE`] (plus the tolerance) of the reference.
    Close,
    /// Further.
    Differs,
}

impl Verdict {
    /// `agrees`, `close` or `differs`.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Agrees => "agrees",
            Verdict::Close => "close",
            Verdict::Differs => "differs",
        }
    }
}

/// The verdict of a row (module docs).
pub fn verdict(row: &Row) -> Verdict {
    if agrees(row) {
        Verdict::Agrees
    } else if (row.ours - row.reference).abs() <= CLOSE + row.tolerance {
        Verdict::Close
    } else {
        Verdict::Differs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(ours: f64, low: f64, high: f64, reference: f64, tolerance: f64) -> Row {
        Row {
            method: "mdr".into(),
            n: 256.0,
            hurst: 0.5,
            quantity: "alpha".into(),
            ours,
            low,
            high,
            reference,
            source: "eq. (6)".into(),
            tolerance,
        }
    }

    #[test]
    fn verdicts_follow_the_interval_the_tolerance_and_close() {
        assert_eq!(verdict(&row(0.5, 0.4, 0.6, 0.6, 0.0)), Verdict::Agrees);
        assert_eq!(verdict(&row(0.5, 0.49, 0.51, 0.515, 0.0)), Verdict::Close);
        assert_eq!(verdict(&row(0.5, 0.49, 0.51, 0.53, 0.0)), Verdict::Differs);
        // The paper's "≈ 1": a tolerance of 0.1 widens the interval.
        assert_eq!(verdict(&row(0.85, 0.8, 0.9, 1.0, 0.1)), Verdict::Agrees);
        assert_eq!(verdict(&row(0.75, 0.7, 0.8, 1.0, 0.1)), Verdict::Differs);
        assert_eq!(
            serde_json::to_value(Verdict::Close).unwrap(),
            serde_json::json!("close")
        );
    }
}
