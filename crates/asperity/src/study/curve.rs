//! Force–stiffness curves of single samples and their ensemble mean at common forces,
//! and the exponent α of `k ∝ F^α` (paper eq. 3) in a low-force window.
//!
//! # The fit window
//! α is a low-force property, but the very first contacts are discrete (one spring, one
//! pixel) and at larger forces the curve bends away. The window is chosen by **contact
//! fraction** `φ` (springs or pixels in contact over all points), the same for every
//! method, H and N, and stated in every report:
//! `min_contacts / points ≤ φ ≤ max_fraction` ([`FitWindow`]). Per sample, α is the
//! least-squares slope of `ln k` on `ln F` over the curve's points in the window; on the
//! ensemble, it is the slope of the mean curve over the common force levels whose mean
//! contact fraction lies in the window.

use serde::{Deserialize, Serialize};

use crate::fit::{power_law_fit, student_t_975, PowerLawFit};
use crate::{Error, Result};

/// One point of a force–stiffness curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CurvePoint {
    /// Contact fraction (points in contact / all points).
    pub fraction: f64,
    /// Total normal force.
    pub force: f64,
    /// Contact stiffness dF/dd.
    pub stiffness: f64,
}

/// The force–stiffness curve of one realisation, sorted by increasing force.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleCurve {
    /// Number of grid points (springs or pixels) of the sample.
    pub points_total: usize,
    /// The curve, force increasing.
    pub points: Vec<CurvePoint>,
}

/// The low-force window of the α fit (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FitWindow {
    /// Fewest points in contact: skips single-spring / single-pixel discreteness.
    pub min_contacts: usize,
    /// Largest contact fraction: keeps the fit at low force.
    pub max_fraction: f64,
}

impl Default for FitWindow {
    /// From 4 points in contact up to 1 % contact fraction.
    fn default() -> Self {
        FitWindow {
            min_contacts: 4,
            max_fraction: 0.01,
        }
    }
}

impl FitWindow {
    /// Checks `min_contacts ≥ 1` and `0 < max_fraction ≤ 1`.
    pub fn validate(&self) -> Result<()> {
        if self.min_contacts == 0 || !(self.max_fraction > 0.0 && self.max_fraction <= 1.0) {
            return Err(Error::invalid(
                "fit window",
                format!("need min_contacts ≥ 1 and 0 < max_fraction ≤ 1, got {self:?}"),
            ));
        }
        Ok(())
    }

    /// Whether a point with `fraction` on a grid of `points_total` lies in the window.
    pub fn contains(&self, fraction: f64, points_total: usize) -> bool {
        fraction * points_total as f64 >= self.min_contacts as f64 - 1e-9
            && fraction <= self.max_fraction
    }

    /// One-line description for reports.
    pub fn describe(&self) -> String {
        format!(
            "contact fraction from {} points in contact up to {}",
            self.min_contacts, self.max_fraction
        )
    }
}

impl SampleCurve {
    /// α of this sample in `window`; `None` with fewer than 3 points in it.
    pub fn alpha(&self, window: &FitWindow) -> Option<PowerLawFit> {
        let (f, k): (Vec<f64>, Vec<f64>) = self
            .points
            .iter()
            .filter(|p| window.contains(p.fraction, self.points_total) && p.force > 0.0)
            .map(|p| (p.force, p.stiffness))
            .unzip();
        (f.len() >= 3).then(|| power_law_fit(&f, &k).ok()).flatten()
    }

    /// Stiffness and contact fraction at force `force` by log–log interpolation; `None`
    /// outside the curve.
    pub fn at_force(&self, force: f64) -> Option<(f64, f64)> {
        let pts = &self.points;
        let i = pts.partition_point(|p| p.force < force);
        if i == pts.len() || (i == 0 && pts[0].force > force) {
            return None;
        }
        if pts[i].force == force || i == 0 {
            return Some((pts[i].stiffness, pts[i].fraction));
        }
        let (a, b) = (pts[i - 1], pts[i]);
        let t = (force.ln() - a.force.ln()) / (b.force.ln() - a.force.ln());
        let lerp = |x: f64, y: f64| (x.ln() + t * (y.ln() - x.ln())).exp();
        Some((
            lerp(a.stiffness, b.stiffness),
            lerp(a.fraction.max(1e-300), b.fraction.max(1e-300)),
        ))
    }
}

/// One common force level of an ensemble: mean stiffness with its 95 % confidence
/// interval (Student t over samples) and the mean contact fraction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EnsemblePoint {
    /// Force level.
    pub force: f64,
    /// Mean stiffness over samples.
    pub stiffness: f64,
    /// Lower end of the 95 % confidence interval of the mean.
    pub stiffness_low: f64,
    /// Upper end of the 95 % confidence interval of the mean.
    pub stiffness_high: f64,
    /// Mean contact fraction.
    pub fraction: f64,
    /// Samples averaged.
    pub samples: usize,
}

/// Mean curve over `samples` at `levels` log-spaced forces spanning the range that every
/// sample covers (from the largest first force to the smallest last force).
pub fn ensemble_curve(samples: &[SampleCurve], levels: usize) -> Result<Vec<EnsemblePoint>> {
    let usable: Vec<&SampleCurve> = samples.iter().filter(|s| !s.points.is_empty()).collect();
    if usable.is_empty() || levels < 2 {
        return Err(Error::invalid(
            "ensemble",
            "need at least one non-empty curve and 2 levels",
        ));
    }
    let lo = usable
        .iter()
        .map(|s| s.points[0].force)
        .fold(f64::MIN_POSITIVE, f64::max);
    let hi = usable
        .iter()
        .map(|s| s.points[s.points.len() - 1].force)
        .fold(f64::INFINITY, f64::min);
    if !(hi > lo) {
        return Err(Error::invalid(
            "ensemble",
            "the samples' force ranges do not overlap",
        ));
    }
    let n = usable.len() as f64;
    Ok((0..levels)
        .map(|i| {
            let force = (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (levels - 1) as f64).exp();
            let force = force.clamp(lo, hi);
            let values: Vec<(f64, f64)> = usable.iter().filter_map(|s| s.at_force(force)).collect();
            let mean = values.iter().map(|v| v.0).sum::<f64>() / n;
            let fraction = values.iter().map(|v| v.1).sum::<f64>() / n;
            let half_width = if usable.len() > 1 {
                let var = values.iter().map(|v| (v.0 - mean).powi(2)).sum::<f64>() / (n - 1.0);
                student_t_975(usable.len() - 1) * (var / n).sqrt()
            } else {
                0.0
            };
            EnsemblePoint {
                force,
                stiffness: mean,
                stiffness_low: mean - half_width,
                stiffness_high: mean + half_width,
                fraction,
                samples: values.len(),
            }
        })
        .collect())
}

/// α of the ensemble-mean curve over the levels whose mean contact fraction is in the
/// window; `None` with fewer than 3 such levels.
pub fn ensemble_alpha(
    curve: &[EnsemblePoint],
    window: &FitWindow,
    points_total: usize,
) -> Option<PowerLawFit> {
    let (f, k): (Vec<f64>, Vec<f64>) = curve
        .iter()
        .filter(|p| window.contains(p.fraction, points_total))
        .map(|p| (p.force, p.stiffness))
        .unzip();
    (f.len() >= 3).then(|| power_law_fit(&f, &k).ok()).flatten()
}

/// The `q`-quantile (0..1) of values by linear interpolation between order statistics.
pub fn quantile(values: &[f64], q: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let pos = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (i, t) = (pos.floor() as usize, pos.fract());
    Some(if i + 1 < v.len() {
        v[i] + t * (v[i + 1] - v[i])
    } else {
        v[i]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic curve k = c F^a with fraction ∝ F (like a GW-type law).
    fn synthetic(a: f64, c: f64, points_total: usize) -> SampleCurve {
        let points = (0..200)
            .map(|i| {
                let force = 10f64.powf(-6.0 + 6.0 * i as f64 / 199.0);
                CurvePoint {
                    fraction: (force * 0.5).min(1.0),
                    force,
                    stiffness: c * force.powf(a),
                }
            })
            .collect();
        SampleCurve {
            points_total,
            points,
        }
    }

    #[test]
    fn fit_recovers_a_known_exponent_from_synthetic_data() {
        let window = FitWindow {
            min_contacts: 4,
            max_fraction: 0.01,
        };
        for a in [1.0 / 3.0, 0.5, 0.8, 0.95] {
            let s = synthetic(a, 2.0, 1 << 14);
            let fit = s.alpha(&window).unwrap();
            assert!((fit.exponent - a).abs() < 1e-10, "{a}: {fit:?}");
            let samples = vec![synthetic(a, 1.0, 1 << 14), synthetic(a, 3.0, 1 << 14)];
            let mean = ensemble_curve(&samples, 40).unwrap();
            let fit = ensemble_alpha(&mean, &window, 1 << 14).unwrap();
            assert!((fit.exponent - a).abs() < 1e-9, "ensemble {a}: {fit:?}");
            // mean of 1 and 3 is 2: interval must straddle it.
            assert!(mean
                .iter()
                .all(|p| p.stiffness_low <= p.stiffness && p.stiffness <= p.stiffness_high));
        }
    }

    #[test]
    fn window_excludes_first_contacts_and_large_fractions() {
        let w = FitWindow {
            min_contacts: 4,
            max_fraction: 0.01,
        };
        assert!(!w.contains(3.0 / 1000.0, 1000));
        assert!(w.contains(4.0 / 1000.0, 1000));
        assert!(!w.contains(0.02, 1000));
        assert!(FitWindow {
            min_contacts: 0,
            max_fraction: 0.1
        }
        .validate()
        .is_err());
    }

    #[test]
    fn interpolation_and_quantiles() {
        let s = synthetic(0.5, 1.0, 100);
        let (k, _) = s.at_force(1e-3).unwrap();
        assert!((k / 1e-3f64.sqrt() - 1.0).abs() < 1e-12);
        assert!(s.at_force(1e-7).is_none());
        assert_eq!(quantile(&[3.0, 1.0, 2.0], 0.5), Some(2.0));
        assert_eq!(quantile(&[1.0, 2.0], 0.25), Some(1.25));
    }
}
