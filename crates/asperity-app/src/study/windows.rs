//! `asperity study windows` and Python's `study_windows`: α of a finished or running BEM
//! study refitted with the windows of [`sensitivity_windows`], each with its bootstrap
//! interval, from the sample curves its checkpoints keep; one row per (task, window), the
//! same rows for both front ends.

use std::path::Path;

use asperity::study::sensitivity::{sensitivity_windows, study_sensitivity, TaskSensitivity};

use crate::refusal::{Refusal, RequestError};
use crate::table::{csv_bytes, format_number, CsvError};

/// The columns of the table, in order.
pub const COLUMNS: [&str; 8] = [
    "n",
    "hurst",
    "min_contacts",
    "max_fraction",
    "alpha",
    "low",
    "high",
    "samples",
];

/// One row: a task and one window that fits it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowRow {
    /// Grid size N.
    pub n: usize,
    /// Hurst exponent.
    pub hurst: f64,
    /// The window's start: fewest points in contact.
    pub min_contacts: usize,
    /// The window's end: largest contact fraction.
    pub max_fraction: f64,
    /// α of the ensemble-mean curve in the window.
    pub alpha: f64,
    /// 2.5 % quantile of the bootstrap α.
    pub low: f64,
    /// 97.5 % quantile of the bootstrap α.
    pub high: f64,
    /// Samples in the ensemble.
    pub samples: usize,
}

/// The rows of `found`, task by task, window by window.
pub fn rows(found: &[TaskSensitivity]) -> Vec<WindowRow> {
    found
        .iter()
        .flat_map(|t| {
            t.windows.iter().map(|w| WindowRow {
                n: t.task.n,
                hurst: t.task.hurst,
                min_contacts: w.window.min_contacts,
                max_fraction: w.window.max_fraction,
                alpha: w.alpha,
                low: w.low,
                high: w.high,
                samples: w.samples,
            })
        })
        .collect()
}

/// The CSV text of `rows` under [`COLUMNS`] (`asperity study windows`, and
/// `window_sensitivity.csv` beside a comparison with the paper): counts as integers
/// ("256", not "256.0"), measurements as round-trip floats.
pub fn csv(rows: &[WindowRow]) -> Result<Vec<u8>, CsvError> {
    let fields = |r: &WindowRow| {
        let mut row = vec![r.n.to_string(), format_number(r.hurst)];
        row.push(r.min_contacts.to_string());
        row.extend([r.max_fraction, r.alpha, r.low, r.high].map(format_number));
        row.push(r.samples.to_string());
        row
    };
    csv_bytes(&COLUMNS, &rows.iter().map(fields).collect::<Vec<_>>())
}

/// The window sensitivity of the study in `dir` (read only); refused where no task has
/// stored sample curves.
pub fn window_sensitivity(dir: &Path) -> Result<Vec<WindowRow>, RequestError> {
    let found = study_sensitivity(dir, &sensitivity_windows())
        .map_err(|e| RequestError::Invalid(Box::new(e)))?;
    if found.is_empty() {
        return Err(Refusal::saying(format!(
            "{}: no task of this study has stored sample curves (MDR tasks and BEM tasks \
             finished before asperity kept them have none)",
            dir.display()
        ))
        .into());
    }
    Ok(rows(&found))
}
