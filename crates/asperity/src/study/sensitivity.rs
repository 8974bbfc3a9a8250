//! How much α of `k ∝ F^α` (paper eq. 3) depends on the fit window: the estimator of
//! [`super::curve`] refitted on a study's stored sample curves with other windows, each α
//! with a bootstrap 95 % interval over samples.
//!
//! The default window (8 contacts up to 1 % contact, [`FitWindow::default`]) was chosen
//! on MDR lines of 2^15 points; on BEM grids of 64² … 1024² the window spans one to two
//! decades of contacts only, so a reader of a BEM α needs to know whether another
//! reasonable window moves it. [`sensitivity_windows`] is the grid of windows reported:
//! start at 4, 8 or 16 contacts, end at 0.5, 1 or 2 % contact (the floor of
//! [`super::curve::MIN_WINDOW_SPAN`] still applies on small grids).
//!
//! # The interval
//! The samples of a task are resampled with replacement [`BOOTSTRAP_RESAMPLES`] times
//! (deterministic draws, so a table is reproducible bit for bit) and the ensemble-mean
//! curve refitted each time; the interval is the 2.5 % to 97.5 % range of those α: the
//! uncertainty of the ensemble α from the finite number of samples, not the spread of
//! single samples.

use serde::{Deserialize, Serialize};

use super::curve::{ensemble_alpha_of, quantile, FitWindow, SampleCurve};
use super::{splitmix64, StudyDir, Task};
use crate::Result;

/// Window starts (points in contact) of the sensitivity table.
pub const WINDOW_STARTS: [usize; 3] = [4, 8, 16];

/// Window ends (contact fractions) of the sensitivity table.
pub const WINDOW_ENDS: [f64; 3] = [0.005, 0.01, 0.02];

/// Bootstrap resamples behind each interval.
pub const BOOTSTRAP_RESAMPLES: usize = 400;

/// The windows of the sensitivity table: every start of [`WINDOW_STARTS`] with every end
/// of [`WINDOW_ENDS`], start-major.
pub fn sensitivity_windows() -> Vec<FitWindow> {
    WINDOW_STARTS
        .iter()
        .flat_map(|&min_contacts| {
            WINDOW_ENDS.iter().map(move |&max_fraction| FitWindow {
                min_contacts,
                max_fraction,
            })
        })
        .collect()
}

/// α of one ensemble with one window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WindowAlpha {
    /// The window.
    pub window: FitWindow,
    /// α fitted on the ensemble-mean curve ([`super::ensemble_alpha`]).
    pub alpha: f64,
    /// 2.5 % quantile of the bootstrap α (module docs).
    pub low: f64,
    /// 97.5 % quantile of the bootstrap α.
    pub high: f64,
    /// Samples in the ensemble.
    pub samples: usize,
}

/// α of `samples` with `window` and its bootstrap interval (module docs); `None` when the
/// window holds too few force levels (fewer than 3) or fewer than 2 samples are given.
pub fn window_alpha(
    samples: &[SampleCurve],
    window: &FitWindow,
    levels: usize,
) -> Option<WindowAlpha> {
    if samples.len() < 2 {
        return None;
    }
    let all: Vec<&SampleCurve> = samples.iter().collect();
    let alpha = ensemble_alpha_of(&all, window, levels)?.exponent;
    let mut drawn: Vec<&SampleCurve> = Vec::with_capacity(samples.len());
    let mut alphas = Vec::with_capacity(BOOTSTRAP_RESAMPLES);
    for resample in 0..BOOTSTRAP_RESAMPLES {
        drawn.clear();
        let mut state = splitmix64(resample as u64);
        for _ in 0..samples.len() {
            state = splitmix64(state);
            drawn.push(&samples[(state % samples.len() as u64) as usize]);
        }
        if let Some(fit) = ensemble_alpha_of(&drawn, window, levels) {
            alphas.push(fit.exponent);
        }
    }
    Some(WindowAlpha {
        window: *window,
        alpha,
        low: quantile(&alphas, 0.025)?,
        high: quantile(&alphas, 0.975)?,
        samples: samples.len(),
    })
}

/// The sensitivity of one task of a study: α for every window of `windows` that fits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskSensitivity {
    /// The task.
    pub task: Task,
    /// One entry per window that fits (in the order asked).
    pub windows: Vec<WindowAlpha>,
}

/// The window sensitivity of every task of the study in `dir` whose checkpoint holds its
/// sample curves ([`StudyDir::stored_samples`]: finished BEM tasks, or tasks in progress
/// with at least 2 samples); tasks without stored samples are left out. Reads only.
pub fn study_sensitivity(
    dir: &std::path::Path,
    windows: &[FitWindow],
) -> Result<Vec<TaskSensitivity>> {
    let store = StudyDir::read(dir)?;
    let levels = store.spec().levels;
    let mut out = Vec::new();
    for task in store.spec().tasks() {
        let samples = store.stored_samples(task)?;
        if samples.len() < 2 {
            continue;
        }
        let windows = windows
            .iter()
            .filter_map(|w| window_alpha(&samples, w, levels))
            .collect();
        out.push(TaskSensitivity { task, windows });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::curve::tests::synthetic as power_law;

    #[test]
    fn an_exact_power_law_gives_its_exponent_in_every_window_with_a_zero_width_interval() {
        let samples: Vec<_> = (1..=6).map(|c| power_law(0.7, c as f64, 1 << 16)).collect();
        let windows = sensitivity_windows();
        assert_eq!(windows.len(), 9);
        for w in &windows {
            let r = window_alpha(&samples, w, 40).unwrap();
            assert!((r.alpha - 0.7).abs() < 1e-9, "{w:?}: {r:?}");
            assert!(r.high - r.low < 1e-9 && r.low <= r.alpha + 1e-12, "{r:?}");
        }
    }

    #[test]
    fn the_interval_widens_with_the_scatter_of_the_samples_and_is_reproducible() {
        // Exponents 0.6 … 0.8 across samples: the ensemble α lies inside its interval,
        // which is neither empty nor wider than the exponents' range.
        let samples: Vec<_> = (0..10)
            .map(|i| power_law(0.6 + 0.2 * i as f64 / 9.0, 1.0, 1 << 16))
            .collect();
        let w = FitWindow::default();
        let r = window_alpha(&samples, &w, 40).unwrap();
        assert!(r.low < r.alpha && r.alpha < r.high, "{r:?}");
        assert!(
            r.high - r.low > 0.01 && r.low > 0.6 && r.high < 0.8,
            "{r:?}"
        );
        assert_eq!(window_alpha(&samples, &w, 40), Some(r));
        assert!(window_alpha(&samples[..1], &w, 40).is_none());
    }
}
