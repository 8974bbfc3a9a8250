//! Force–stiffness curves of single samples and their ensemble mean at common forces,
//! and the exponent α of `k ∝ F^α` (paper eq. 3) in a low-force window.
//!
//! # The fit window
//! α is a low-force property, but the very first contacts are discrete (one spring, one
//! pixel: the stiffness steps instead of following a power law) and at larger forces the
//! curve bends away. The window is chosen by **contact count**, the same for every method,
//! H and N, and stated in every report ([`FitWindow`]): it starts where `min_contacts`
//! points touch and ends where a fraction `max_fraction` of all points touch, but spans at
//! least a factor [`MIN_WINDOW_SPAN`] in contacts (so short lines and small grids keep
//! about a decade in force). The default, 8 contacts to 1 %, was chosen by experiment on
//! MDR lines of N = 2^15 (`samplers::tests::window_experiment`, `--ignored`; docs/mdr.md),
//! within ±0.012 of theory there (ensemble fit).
//!
//! Within the window the curve is sampled at `levels` log-spaced forces, so that every
//! decade of force weighs alike, and `ln k` is fitted on `ln F`: per sample between that
//! sample's window forces, and for the ensemble on the mean stiffness over samples at
//! common levels between the medians (over samples) of the window forces.
//!
//! MDR curves on linear springs are step functions (`k = E*Δx·j` between the j-th and the
//! (j+1)-th contact, [`SampleCurve::piecewise_constant`]) and are evaluated as such; BEM
//! curves are interpolated log–log between solved loads.

use serde::{Deserialize, Serialize};

use crate::fit::{log_levels, power_law_fit, student_t_975, PowerLawFit};
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
    /// The tangential (no-slip) stiffness over the normal one, `(k_x + k_y)/(2k)`, where
    /// the study asks for it ([`super::StudySpec::poisson`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential_ratio: Option<f64>,
}

/// The force–stiffness curve of one realisation, sorted by increasing force.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleCurve {
    /// Number of grid points (springs or pixels) of the sample.
    pub points_total: usize,
    /// The curve, force increasing.
    pub points: Vec<CurvePoint>,
    /// Stiffness and fraction hold from one point to the next (a step function, as for
    /// MDR on linear springs) instead of varying log-linearly between them.
    #[serde(default)]
    pub piecewise_constant: bool,
}

/// The low-force window of the α fit (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FitWindow {
    /// Fewest points in contact: skips single-spring / single-pixel discreteness.
    pub min_contacts: usize,
    /// Largest contact fraction: keeps the fit at low force.
    pub max_fraction: f64,
}

/// The window spans at least this factor in contact counts.
pub const MIN_WINDOW_SPAN: f64 = 4.0;

impl Default for FitWindow {
    /// From 8 points in contact up to 1 % contact fraction.
    fn default() -> Self {
        FitWindow {
            min_contacts: 8,
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
                format!(
                    "need min_contacts ≥ 1 and 0 < max_fraction ≤ 1, got min_contacts = {} and \
                     max_fraction = {}",
                    self.min_contacts,
                    crate::input::short_number(self.max_fraction)
                ),
            ));
        }
        Ok(())
    }

    /// The window's contact fractions `(low, high)` on a grid of `points_total` points:
    /// `low = min_contacts/N`, `high = max(max_fraction, MIN_WINDOW_SPAN · low)` (≤ 1).
    pub fn fraction_range(&self, points_total: usize) -> (f64, f64) {
        let low = self.min_contacts as f64 / points_total as f64;
        (low, self.max_fraction.max(MIN_WINDOW_SPAN * low).min(1.0))
    }

    /// Whether a point with `fraction` on a grid of `points_total` lies in the window.
    pub fn contains(&self, fraction: f64, points_total: usize) -> bool {
        let (low, high) = self.fraction_range(points_total);
        fraction >= low * (1.0 - 1e-12) && fraction <= high
    }

    /// One-line description for reports.
    pub fn describe(&self) -> String {
        format!(
            "from {} points in contact up to a contact fraction of {} (at least a factor {} in contacts)",
            self.min_contacts, self.max_fraction, MIN_WINDOW_SPAN
        )
    }
}

impl SampleCurve {
    /// The loads around `force`: the last load `a` at or below it, and, unless `force` is
    /// `a`'s own or above the last load, the next load `b` with `t`, the position of
    /// `force` between the two in `ln F` (0 at `a`, 1 at `b`); `None` outside the curve.
    fn bracket(&self, force: f64) -> Option<(CurvePoint, Option<(CurvePoint, f64)>)> {
        let pts = &self.points;
        let (first, last) = (pts.first()?, pts.last()?);
        if !(force >= first.force && force <= last.force) {
            return None;
        }
        // Index of the first point with a force above `force` (≥ 1 here).
        let i = pts.partition_point(|p| p.force <= force);
        let a = pts[i - 1];
        if i == pts.len() || a.force == force {
            return Some((a, None));
        }
        let b = pts[i];
        let t = (force.ln() - a.force.ln()) / (b.force.ln() - a.force.ln());
        Some((a, Some((b, t))))
    }

    /// Stiffness and contact fraction at `force` (step or log–log interpolation, see the
    /// module docs); `None` outside the curve.
    pub fn at_force(&self, force: f64) -> Option<(f64, f64)> {
        let (a, next) = self.bracket(force)?;
        let Some((b, t)) = next.filter(|_| !self.piecewise_constant) else {
            return Some((a.stiffness, a.fraction));
        };
        let lerp = |x: f64, y: f64| (x.ln() + t * (y.ln() - x.ln())).exp();
        Some((
            lerp(a.stiffness, b.stiffness),
            lerp(a.fraction.max(1e-300), b.fraction.max(1e-300)),
        ))
    }

    /// The tangential ratio at `force`, linear in `ln F` between the two loads around it
    /// (it varies by parts in 1e-3 over the sweep); `None` outside the curve or where
    /// either load has none.
    pub fn tangential_ratio_at(&self, force: f64) -> Option<f64> {
        let (a, next) = self.bracket(force)?;
        let Some((b, t)) = next else {
            return a.tangential_ratio;
        };
        let (ra, rb) = (a.tangential_ratio?, b.tangential_ratio?);
        Some(ra + t * (rb - ra))
    }

    /// Forces at which the window starts and ends on this curve: the first point with at
    /// least the window's low contact fraction, and the last point not above its high one.
    pub fn window_forces(&self, window: &FitWindow) -> Option<(f64, f64)> {
        let (low, high) = window.fraction_range(self.points_total);
        let start = self
            .points
            .iter()
            .find(|p| p.fraction >= low * (1.0 - 1e-12))?;
        let end = self.points.iter().rev().find(|p| p.fraction <= high)?;
        (end.force > start.force && start.force > 0.0).then_some((start.force, end.force))
    }

    /// α of this sample: the curve sampled at `levels` log-spaced forces across its window
    /// and fitted; `None` when the window is empty.
    pub fn alpha(&self, window: &FitWindow, levels: usize) -> Option<PowerLawFit> {
        let (lo, hi) = self.window_forces(window)?;
        let (f, k): (Vec<f64>, Vec<f64>) = log_levels(lo, hi, levels)
            .filter_map(|f| self.at_force(f).map(|(k, _)| (f, k)))
            .unzip();
        (f.len() >= 3).then(|| power_law_fit(&f, &k).ok()).flatten()
    }
}

/// One common force level of an ensemble: mean stiffness and mean contact fraction, each
/// with its 95 % confidence interval (Student t over samples).
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
    /// Lower end of the 95 % confidence interval of the mean contact fraction. Unknown
    /// (NaN, and then not written) in a finished task's checkpoint written before the
    /// interval was kept (533a278), unless its sample curves give it back on reading
    /// ([`super::StudyDir`]); a table shows it as an empty cell.
    #[serde(default = "unknown", skip_serializing_if = "is_unknown")]
    pub fraction_low: f64,
    /// Upper end of the 95 % confidence interval of the mean contact fraction (unknown
    /// as [`EnsemblePoint::fraction_low`]).
    #[serde(default = "unknown", skip_serializing_if = "is_unknown")]
    pub fraction_high: f64,
    /// Samples averaged.
    pub samples: usize,
    /// The mean tangential ratio `(k_x + k_y)/(2k)` over samples with the 95 % interval of
    /// the mean, where every sample has one ([`CurvePoint::tangential_ratio`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential_ratio: Option<MeanInterval>,
}

/// An interval end that an older checkpoint did not keep.
fn unknown() -> f64 {
    f64::NAN
}

/// Whether an interval end is [`unknown`]: left out of the JSON, so that an older
/// checkpoint serialises to its own bytes again (its checksum).
fn is_unknown(value: &f64) -> bool {
    value.is_nan()
}

impl EnsemblePoint {
    /// Whether the contact fraction's interval is unknown (an older checkpoint).
    pub fn lacks_fraction_interval(&self) -> bool {
        is_unknown(&self.fraction_low) || is_unknown(&self.fraction_high)
    }
}

/// A mean over samples with the 95 % confidence interval of the mean (Student t).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeanInterval {
    /// The mean.
    pub mean: f64,
    /// Lower end of the interval.
    pub low: f64,
    /// Upper end of the interval.
    pub high: f64,
}

impl MeanInterval {
    /// The mean of `values` and the 95 % interval of the mean (zero width for one value);
    /// `None` for none.
    pub fn of(values: &[f64]) -> Option<MeanInterval> {
        let m = values.len();
        if m == 0 {
            return None;
        }
        let n = m as f64;
        let mean = values.iter().sum::<f64>() / n;
        let half = if m > 1 {
            let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
            student_t_975(m - 1) * (var / n).sqrt()
        } else {
            0.0
        };
        Some(MeanInterval {
            mean,
            low: mean - half,
            high: mean + half,
        })
    }
}

/// Mean curve over `samples` at `levels` log-spaced forces spanning the range that every
/// sample covers (from the largest first force to the smallest last force).
pub fn ensemble_curve(samples: &[SampleCurve], levels: usize) -> Result<Vec<EnsemblePoint>> {
    let refs: Vec<&SampleCurve> = samples.iter().collect();
    ensemble_curve_of(&refs, levels)
}

/// [`ensemble_curve`] of samples held by reference (a bootstrap resample repeats some).
pub fn ensemble_curve_of(samples: &[&SampleCurve], levels: usize) -> Result<Vec<EnsemblePoint>> {
    let usable: Vec<&SampleCurve> = samples
        .iter()
        .copied()
        .filter(|s| !s.points.is_empty())
        .collect();
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
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::invalid(
            "ensemble",
            "the samples' force ranges do not overlap",
        ));
    }
    Ok((0..levels)
        .map(|i| {
            let force = if i + 1 == levels {
                hi
            } else {
                (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (levels - 1) as f64)
                    .exp()
                    .clamp(lo, hi)
            };
            // Every usable sample covers [lo, hi], so each gives a value (and there is one).
            let values: Vec<(f64, f64)> = usable.iter().filter_map(|s| s.at_force(force)).collect();
            let of = |v: Vec<f64>| MeanInterval::of(&v).expect("a sample at every level");
            let stiffness = of(values.iter().map(|v| v.0).collect());
            let fraction = of(values.iter().map(|v| v.1).collect());
            let ratios: Option<Vec<f64>> = usable
                .iter()
                .map(|s| s.tangential_ratio_at(force))
                .collect();
            EnsemblePoint {
                force,
                stiffness: stiffness.mean,
                stiffness_low: stiffness.low,
                stiffness_high: stiffness.high,
                fraction: fraction.mean,
                fraction_low: fraction.low,
                fraction_high: fraction.high,
                samples: values.len(),
                tangential_ratio: ratios.and_then(|r| MeanInterval::of(&r)),
            }
        })
        .collect())
}

/// α of the ensemble: the mean stiffness over samples at `levels` log-spaced forces
/// between the medians of the samples' window forces, fitted; `None` when no sample has a
/// window or fewer than 3 levels are covered.
pub fn ensemble_alpha(
    samples: &[SampleCurve],
    window: &FitWindow,
    levels: usize,
) -> Option<PowerLawFit> {
    let refs: Vec<&SampleCurve> = samples.iter().collect();
    ensemble_alpha_of(&refs, window, levels)
}

/// [`ensemble_alpha`] of samples held by reference (a bootstrap resample repeats some).
pub fn ensemble_alpha_of(
    samples: &[&SampleCurve],
    window: &FitWindow,
    levels: usize,
) -> Option<PowerLawFit> {
    let (lo, hi) = ensemble_window(samples, window)?;
    let (f, k): (Vec<f64>, Vec<f64>) = log_levels(lo, hi, levels)
        .filter_map(|force| {
            let values: Vec<f64> = samples
                .iter()
                .filter_map(|s| s.at_force(force).map(|v| v.0))
                .collect();
            (!values.is_empty()).then(|| (force, values.iter().sum::<f64>() / values.len() as f64))
        })
        .unzip();
    (f.len() >= 3).then(|| power_law_fit(&f, &k).ok()).flatten()
}

/// The forces of the ensemble's window: the medians over samples of their window forces
/// ([`SampleCurve::window_forces`]); `None` when no sample has a window or the medians
/// leave none.
pub fn ensemble_window(samples: &[&SampleCurve], window: &FitWindow) -> Option<(f64, f64)> {
    let (starts, ends): (Vec<f64>, Vec<f64>) = samples
        .iter()
        .filter_map(|s| s.window_forces(window))
        .unzip();
    let (lo, hi) = (quantile(&starts, 0.5)?, quantile(&ends, 0.5)?);
    (hi.partial_cmp(&lo) == Some(std::cmp::Ordering::Greater)).then_some((lo, hi))
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
pub(crate) mod tests {
    use super::*;

    /// Synthetic curve k = c F^a with fraction ∝ F (like a GW-type law).
    pub(crate) fn synthetic(a: f64, c: f64, points_total: usize) -> SampleCurve {
        let points = (0..200)
            .map(|i| {
                let force = 10f64.powf(-6.0 + 6.0 * i as f64 / 199.0);
                CurvePoint {
                    fraction: (force * 0.5).min(1.0),
                    force,
                    stiffness: c * force.powf(a),
                    tangential_ratio: None,
                }
            })
            .collect();
        SampleCurve {
            points_total,
            points,
            piecewise_constant: false,
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
            let fit = s.alpha(&window, 40).unwrap();
            assert!((fit.exponent - a).abs() < 1e-10, "{a}: {fit:?}");
            let samples = vec![synthetic(a, 1.0, 1 << 14), synthetic(a, 3.0, 1 << 14)];
            let mean = ensemble_curve(&samples, 40).unwrap();
            let fit = ensemble_alpha(&samples, &window, 40).unwrap();
            assert!((fit.exponent - a).abs() < 1e-9, "ensemble {a}: {fit:?}");
            // mean of 1 and 3 is 2: interval must straddle it.
            assert!(mean
                .iter()
                .all(|p| p.stiffness_low <= p.stiffness && p.stiffness <= p.stiffness_high));
            // The samples share their fractions: the fraction's interval has no width.
            assert!(mean
                .iter()
                .all(|p| p.fraction_low == p.fraction && p.fraction_high == p.fraction));
        }
    }

    #[test]
    fn the_fraction_interval_is_students_t_of_the_sample_fractions() {
        // Three samples with fractions 0.5F, 0.6F, 1.0F (below 1): mean 0.7F, sample
        // standard deviation 0.2646F, t(0.975, 2) = 4.303 (the library's table, to 3
        // decimals), so a half-width of F · 4.303 · 0.2646/√3.
        let scaled = |c: f64| SampleCurve {
            points: synthetic(0.5, 1.0, 1 << 14)
                .points
                .into_iter()
                .map(|p| CurvePoint {
                    fraction: (c * p.force).min(1.0),
                    ..p
                })
                .collect(),
            points_total: 1 << 14,
            piecewise_constant: false,
        };
        let samples = [scaled(0.5), scaled(0.6), scaled(1.0)];
        let mean = ensemble_curve(&samples, 20).unwrap();
        let sd = ((0.04f64 + 0.01 + 0.09) / 2.0).sqrt();
        for p in mean.iter().filter(|p| p.force < 0.5) {
            let half = 4.303 * sd / 3f64.sqrt() * p.force;
            assert!(
                (p.fraction - 0.7 * p.force).abs() < 1e-12 * p.force,
                "{p:?}"
            );
            assert!(
                (p.fraction_high - p.fraction - half).abs() < 1e-9 * half,
                "{p:?}"
            );
            assert!(
                (p.fraction - p.fraction_low - half).abs() < 1e-9 * half,
                "{p:?}"
            );
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
        // On a small grid the window still spans a factor 4 in contacts.
        assert_eq!(w.fraction_range(100), (0.04, 0.16));
        assert!(FitWindow {
            min_contacts: 0,
            max_fraction: 0.1
        }
        .validate()
        .is_err());
    }

    #[test]
    fn step_curves_follow_their_steps() {
        // k = j from F_j = j² on: the corners lie on k = F^(1/2); in between, a step.
        let points = (1..=400)
            .map(|j| CurvePoint {
                fraction: j as f64 / 40000.0,
                force: (j * j) as f64,
                stiffness: j as f64,
                tangential_ratio: None,
            })
            .collect();
        let s = SampleCurve {
            points_total: 40000,
            points,
            piecewise_constant: true,
        };
        assert_eq!(s.at_force(10.0), Some((3.0, 3.0 / 40000.0)));
        assert_eq!(s.at_force(16.0), Some((4.0, 4.0 / 40000.0)));
        let window = FitWindow {
            min_contacts: 8,
            max_fraction: 0.01,
        };
        let fit = s.alpha(&window, 40).unwrap();
        // Sampling a step evenly in ln F biases α by O(1/j) at the window's low end.
        assert!((fit.exponent - 0.5).abs() < 0.02, "{fit:?}");
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
