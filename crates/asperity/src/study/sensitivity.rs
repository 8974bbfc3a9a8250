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
//!
//! # The steepest slope (paper Fig. 2)
//! With roll-off the paper reads "almost linear" (`α ≈ 1`) off its log–log plot:
//! [`steepest_slope`] is the largest slope of the ensemble-mean curve over one decade of
//! force from the window's first contacts on (the stretch a reader of the plot sees;
//! single pixels dominate before), and [`slope_with_interval`] adds the same bootstrap
//! interval over samples.

use serde::{Deserialize, Serialize};

use super::curve::{
    ensemble_alpha_of, ensemble_curve_of, quantile, EnsemblePoint, FitWindow, SampleCurve,
};
use super::{splitmix64, StudyDir, Task};
use crate::fit::steepest_power_law;
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
    let (low, high) = bootstrap_interval(samples, |drawn| {
        ensemble_alpha_of(drawn, window, levels).map(|fit| fit.exponent)
    })?;
    Some(WindowAlpha {
        window: *window,
        alpha,
        low,
        high,
        samples: samples.len(),
    })
}

/// The 2.5 % and 97.5 % quantiles of `statistic` over [`BOOTSTRAP_RESAMPLES`]
/// deterministic resamples (with replacement) of `samples`; resamples where it is `None`
/// are left out.
fn bootstrap_interval(
    samples: &[SampleCurve],
    statistic: impl Fn(&[&SampleCurve]) -> Option<f64>,
) -> Option<(f64, f64)> {
    let mut drawn: Vec<&SampleCurve> = Vec::with_capacity(samples.len());
    let mut values = Vec::with_capacity(BOOTSTRAP_RESAMPLES);
    for resample in 0..BOOTSTRAP_RESAMPLES {
        drawn.clear();
        let mut state = splitmix64(resample as u64);
        for _ in 0..samples.len() {
            state = splitmix64(state);
            drawn.push(&samples[(state % samples.len() as u64) as usize]);
        }
        values.extend(statistic(&drawn));
    }
    Some((quantile(&values, 0.025)?, quantile(&values, 0.975)?))
}

/// Refuses a study whose samples ended their load sweeps for a steepest slope, which reads
/// the whole mean curve.
pub fn ensure_whole_sweep(spec: &super::StudySpec, dir: &std::path::Path) -> Result<()> {
    match spec.sweep_end {
        None => Ok(()),
        Some(end) => Err(crate::Error::invalid(
            "sweep_end",
            format!(
                "{}: its samples stopped loading past {} % contact (an α study's sweep), so \
                 its mean curves end there, and the steepest slope of a whole curve cannot be \
                 read off them; run the study with every load (a curve study, or an α study \
                 with a full sweep) to compare it",
                dir.display(),
                crate::input::short_number(end * 100.0)
            ),
        )),
    }
}

/// The steepest stretch of a mean curve: its log–log slope and where it lies.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SteepestSlope {
    /// The largest log–log slope over one decade of force.
    pub slope: f64,
    /// Mean contact fraction where that decade starts.
    pub from_fraction: f64,
    /// Mean contact fraction where it ends.
    pub to_fraction: f64,
}

/// The steepest log–log slope of the ensemble-mean curve `mean_curve` of a
/// `points_total`-point grid over one decade of force, from the window's first contacts on
/// (module docs); `None` when the curve spans less than a decade there.
pub fn steepest_slope(
    mean_curve: &[EnsemblePoint],
    window: &FitWindow,
    points_total: usize,
) -> Option<SteepestSlope> {
    let first_contacts = window.min_contacts as f64 / points_total as f64;
    let curve: Vec<&EnsemblePoint> = mean_curve
        .iter()
        .filter(|p| p.fraction >= first_contacts)
        .collect();
    let (f, k): (Vec<f64>, Vec<f64>) = curve.iter().map(|p| (p.force, p.stiffness)).unzip();
    let (fit, first, last) = steepest_power_law(&f, &k, 10.0)?;
    Some(SteepestSlope {
        slope: fit.exponent,
        from_fraction: curve[first].fraction,
        to_fraction: curve[last].fraction,
    })
}

/// [`steepest_slope`] of the samples' mean curve at `levels` forces, with its bootstrap
/// 95 % interval over samples (module docs); `None` with fewer than 2 samples or no
/// decade to fit.
pub fn slope_with_interval(
    samples: &[SampleCurve],
    window: &FitWindow,
    levels: usize,
) -> Option<(SteepestSlope, f64, f64)> {
    let points_total = samples.first()?.points_total;
    if samples.len() < 2 || samples.iter().any(|s| s.points_total != points_total) {
        return None;
    }
    let slope_of = |drawn: &[&SampleCurve]| {
        let curve = ensemble_curve_of(drawn, levels).ok()?;
        steepest_slope(&curve, window, points_total).map(|s| s.slope)
    };
    let all: Vec<&SampleCurve> = samples.iter().collect();
    let curve = ensemble_curve_of(&all, levels).ok()?;
    let slope = steepest_slope(&curve, window, points_total)?;
    let (low, high) = bootstrap_interval(samples, slope_of)?;
    Some((slope, low, high))
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

/// The steepest slope of one task of a study, with its bootstrap interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TaskSlope {
    /// The task.
    pub task: Task,
    /// The steepest stretch of the task's ensemble-mean curve.
    pub steepest: SteepestSlope,
    /// 2.5 % quantile of the bootstrap slopes.
    pub low: f64,
    /// 97.5 % quantile of the bootstrap slopes.
    pub high: f64,
    /// Samples in the ensemble.
    pub samples: usize,
}

/// [`slope_with_interval`] for every task of the study in `dir` whose checkpoint holds at
/// least 2 sample curves, with the study's window and force levels. Reads only. A study
/// whose BEM samples ended their sweeps ([`super::StudySpec::sweep_end`], an α study's) is
/// refused: the steepest decade may lie past the end.
pub fn study_slopes(dir: &std::path::Path) -> Result<Vec<TaskSlope>> {
    let store = StudyDir::read(dir)?;
    ensure_whole_sweep(store.spec(), dir)?;
    let (window, levels) = (store.spec().window, store.spec().levels);
    let mut out = Vec::new();
    for task in store.spec().tasks() {
        let samples = store.stored_samples(task)?;
        if let Some((steepest, low, high)) = slope_with_interval(&samples, &window, levels) {
            out.push(TaskSlope {
                task,
                steepest,
                low,
                high,
                samples: samples.len(),
            });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::curve::tests::synthetic as power_law;
    use crate::study::curve::CurvePoint;

    /// A curve `k = c·g(F)` whose log–log slope is 0.5 up to F = 1e-4, `steep` over the
    /// two decades to 1e-2, and 0.2 beyond; contact fraction ∝ F.
    fn bent(steep: f64, c: f64) -> SampleCurve {
        let log_k = |lf: f64| -> f64 {
            let (a, b) = (lf.min(-4.0), lf.clamp(-4.0, -2.0));
            0.5 * a + steep * (b + 4.0) + 0.2 * (lf.max(-2.0) + 2.0)
        };
        let points = (0..=120)
            .map(|i| {
                let lf = -6.0 + 6.0 * i as f64 / 120.0;
                CurvePoint {
                    fraction: 0.5 * 10f64.powf(lf),
                    force: 10f64.powf(lf),
                    stiffness: c * 10f64.powf(log_k(lf)),
                    tangential_ratio: None,
                }
            })
            .collect();
        SampleCurve {
            points_total: 1 << 20,
            points,
            piecewise_constant: false,
        }
    }

    #[test]
    fn the_steepest_decade_is_found_with_a_zero_width_interval_when_samples_agree() {
        let samples: Vec<_> = (1..=6).map(|c| bent(1.0, c as f64)).collect();
        let (s, low, high) = slope_with_interval(&samples, &FitWindow::default(), 96).unwrap();
        assert!((s.slope - 1.0).abs() < 1e-6, "{s:?}");
        // The decade lies inside the steep stretch (fractions 0.5e-4 … 0.5e-2).
        assert!(
            s.from_fraction >= 0.5e-4 * 0.99 && s.to_fraction <= 0.5e-2 * 1.01,
            "{s:?}"
        );
        assert!(
            (high - low).abs() < 1e-6 && (low - s.slope).abs() < 1e-6,
            "{low} {high}"
        );
    }

    #[test]
    fn the_slope_interval_covers_the_scatter_of_the_samples() {
        let samples: Vec<_> = (0..10)
            .map(|i| bent(0.9 + 0.2 * i as f64 / 9.0, 1.0))
            .collect();
        let w = FitWindow::default();
        let (s, low, high) = slope_with_interval(&samples, &w, 96).unwrap();
        assert!(low < s.slope && s.slope < high, "{low} {s:?} {high}");
        assert!(
            high - low > 0.005 && low > 0.85 && high < 1.15,
            "{low} {high}"
        );
        assert_eq!(slope_with_interval(&samples, &w, 96), Some((s, low, high)));
        assert!(slope_with_interval(&samples[..1], &w, 96).is_none());
    }

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
