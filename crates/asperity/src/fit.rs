//! Least-squares power-law fits `y = A x^p` in log–log coordinates, with a 95 % interval.
//!
//! Used for the PSD slope of [`crate::surface::stats`] and for the exponent α of
//! `k ∝ F^α` (paper eq. 3). The fit is ordinary least squares of `ln y` on `ln x`; the
//! interval is `p ± t(0.975, n−2) · se(p)` from the residuals (Student t). The levels a
//! power law is sampled at (loads, forces, indentations) are spaced evenly in log
//! ([`log_levels`]), so that every decade weighs alike in the fit.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// A fitted power law.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PowerLawFit {
    /// Exponent p.
    pub exponent: f64,
    /// Prefactor A.
    pub prefactor: f64,
    /// Standard error of the exponent (0 when only two points).
    pub stderr: f64,
    /// Lower end of the 95 % interval of the exponent.
    pub low: f64,
    /// Upper end of the 95 % interval of the exponent.
    pub high: f64,
    /// Number of points used.
    pub points: usize,
}

/// `count` values spaced evenly in log from `lo` to `hi`, both ends included exactly (the
/// inner values clamped into `[lo, hi]`); `lo` alone for `count == 1`. The one log spacing
/// of the crate: `0 < lo ≤ hi`, both finite, is the caller's to check.
pub fn log_levels(lo: f64, hi: f64, count: usize) -> impl Iterator<Item = f64> {
    let step = (hi / lo).ln() / (count.max(2) - 1) as f64;
    (0..count).map(move |i| {
        if i == 0 {
            lo
        } else if i + 1 == count {
            hi
        } else {
            (lo.ln() + step * i as f64).exp().clamp(lo, hi)
        }
    })
}

/// Two-sided 97.5 % quantile of Student's t with `dof` degrees of freedom.
pub fn student_t_975(dof: usize) -> f64 {
    const TABLE: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
        2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
        2.052, 2.048, 2.045, 2.042,
    ];
    match dof {
        0 => f64::INFINITY,
        1..=30 => TABLE[dof - 1],
        // Cornish–Fisher style expansion around the normal quantile; < 1e-3 off above 30.
        _ => {
            let z: f64 = 1.959964;
            let d = dof as f64;
            z + (z.powi(3) + z) / (4.0 * d)
                + (5.0 * z.powi(5) + 16.0 * z.powi(3) + 3.0 * z) / (96.0 * d * d)
        }
    }
}

/// Fits `y = A x^p` to points with `x > 0`, `y > 0` (others are an error).
pub fn power_law_fit(x: &[f64], y: &[f64]) -> Result<PowerLawFit> {
    if x.len() != y.len() {
        return Err(Error::invalid("fit", "x and y differ in length"));
    }
    if x.len() < 2 {
        return Err(Error::invalid(
            "fit",
            format!("need at least 2 points, got {}", x.len()),
        ));
    }
    if let Some(i) =
        (0..x.len()).find(|&i| !(x[i] > 0.0 && y[i] > 0.0 && x[i].is_finite() && y[i].is_finite()))
    {
        return Err(Error::invalid(
            "fit",
            format!("point {i} ({}, {}) is not positive and finite", x[i], y[i]),
        ));
    }
    let n = x.len() as f64;
    let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let ly: Vec<f64> = y.iter().map(|v| v.ln()).collect();
    let mx = lx.iter().sum::<f64>() / n;
    let my = ly.iter().sum::<f64>() / n;
    let sxx: f64 = lx.iter().map(|a| (a - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return Err(Error::invalid("fit", "all x values are equal"));
    }
    let sxy: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let exponent = sxy / sxx;
    let intercept = my - exponent * mx;
    let dof = x.len() - 2;
    let stderr = if dof > 0 {
        let sse: f64 = lx
            .iter()
            .zip(&ly)
            .map(|(a, b)| (b - intercept - exponent * a).powi(2))
            .sum();
        (sse / dof as f64 / sxx).sqrt()
    } else {
        0.0
    };
    let half_width = if dof > 0 {
        student_t_975(dof) * stderr
    } else {
        0.0
    };
    Ok(PowerLawFit {
        exponent,
        prefactor: intercept.exp(),
        stderr,
        low: exponent - half_width,
        high: exponent + half_width,
        points: x.len(),
    })
}

/// The steepest power law over any window of `x` spanning at least `span` (a ratio,
/// e.g. 10 for one decade): slides the window's lower end over the points, fits each
/// window by [`power_law_fit`] and keeps the largest exponent, with the window's first
/// and last index. `None` when no window of that span (and at least 3 points) exists.
///
/// This is how a person reads "the curve is almost linear over a decade" off a log–log
/// plot whose slope keeps changing (paper Fig. 2); `x` must be ascending.
pub fn steepest_power_law(x: &[f64], y: &[f64], span: f64) -> Option<(PowerLawFit, usize, usize)> {
    let mut best: Option<(PowerLawFit, usize, usize)> = None;
    for first in 0..x.len() {
        let Some(last) = (first + 2..x.len()).find(|&j| x[j] >= x[first] * span) else {
            break;
        };
        if let Ok(fit) = power_law_fit(&x[first..=last], &y[first..=last]) {
            if best.is_none_or(|(b, _, _)| fit.exponent > b.exponent) {
                best = Some((fit, first, last));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steepest_window_finds_the_linear_stretch() {
        // y = x^0.3 up to x = 1, then y ∝ x^1 up to x = 100, then flat: the steepest
        // decade is the linear part, and it is found wherever it starts.
        let x: Vec<f64> = (0..=80)
            .map(|i| 10f64.powf(-2.0 + i as f64 * 0.05))
            .collect();
        let y: Vec<f64> = x
            .iter()
            .map(|&v| match v {
                v if v <= 1.0 => v.powf(0.3),
                v if v <= 100.0 => v,
                _ => 100.0,
            })
            .collect();
        let (fit, first, last) = steepest_power_law(&x, &y, 10.0).unwrap();
        assert!((fit.exponent - 1.0).abs() < 1e-9, "{}", fit.exponent);
        assert!(x[first] >= 1.0 - 1e-12 && x[last] <= 100.0 + 1e-9);
        assert!(x[last] / x[first] >= 10.0 - 1e-9);
        // No window spans a factor 1e5.
        assert!(steepest_power_law(&x, &y, 1e5).is_none());
    }

    #[test]
    fn log_levels_have_exact_ends_and_one_ratio() {
        for (lo, hi, count) in [(1e-6, 3.0, 64), (0.05 / 65536.0, 0.2, 24), (2.0, 2.0, 5)] {
            let levels: Vec<f64> = log_levels(lo, hi, count).collect();
            assert_eq!(levels.len(), count);
            assert_eq!((levels[0], levels[count - 1]), (lo, hi));
            // Every step is the same ratio (hi/lo)^(1/(count-1)), to rounding.
            let ratio = (hi / lo).powf(1.0 / (count - 1) as f64);
            for pair in levels.windows(2) {
                assert!((pair[1] / pair[0] / ratio - 1.0).abs() < 1e-12, "{pair:?}");
            }
        }
        assert_eq!(log_levels(0.5, 8.0, 1).collect::<Vec<_>>(), [0.5]);
        assert_eq!(log_levels(0.5, 8.0, 2).collect::<Vec<_>>(), [0.5, 8.0]);
        assert_eq!(log_levels(0.5, 8.0, 0).count(), 0);
    }

    #[test]
    fn recovers_a_known_exponent_exactly() {
        let x: Vec<f64> = (1..50).map(|i| i as f64 * 0.37).collect();
        let y: Vec<f64> = x.iter().map(|v| 2.5 * v.powf(0.6667)).collect();
        let fit = power_law_fit(&x, &y).unwrap();
        assert!((fit.exponent - 0.6667).abs() < 1e-12);
        assert!((fit.prefactor - 2.5).abs() < 1e-12);
        assert!(fit.stderr < 1e-10);
    }

    #[test]
    fn interval_covers_the_truth_with_noise() {
        // Deterministic multiplicative "noise" of ±5 %: the interval must contain 1.5.
        let x: Vec<f64> = (1..200).map(|i| i as f64).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, v)| v.powf(1.5) * (1.0 + 0.05 * ((i * 7919) % 13) as f64 / 6.0 - 0.05))
            .collect();
        let fit = power_law_fit(&x, &y).unwrap();
        assert!(fit.low < 1.5 && 1.5 < fit.high, "{fit:?}");
        assert!(fit.high - fit.low < 0.05);
    }

    #[test]
    fn rejects_non_positive_points() {
        assert!(power_law_fit(&[1.0, 2.0], &[1.0, 0.0]).is_err());
        assert!(power_law_fit(&[1.0], &[1.0]).is_err());
        assert!(power_law_fit(&[2.0, 2.0], &[1.0, 3.0]).is_err());
    }

    #[test]
    fn t_quantiles() {
        assert!((student_t_975(10) - 2.228).abs() < 1e-9);
        assert!((student_t_975(60) - 2.000).abs() < 2e-3);
        assert!((student_t_975(100000) - 1.96).abs() < 1e-3);
    }
}
