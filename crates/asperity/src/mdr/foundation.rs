//! The Winkler foundation of the MDR: independent springs at spacing `Δx`, each following
//! a [`Spring`] law, pressed by a rigid 1D profile; exact evaluation at given indentations.
//!
//! A profile is stored as the sorted **initial gaps** `s_i ≥ 0` between each spring and the
//! indenter at first contact (SCIENCE.md §3, paper *Methods* "1D MDR calculation"):
//! * a rough line of heights `z_i` (positive up): `s_i = z_max − z_i` — the indentation is
//!   measured from the highest point;
//! * an indenter profile `g(x_i)` (e.g. from [`super::Axisymmetric`]): `s_i = g_i − min g`;
//!   `+∞` marks springs that are never touched (outside a flat punch).
//!
//! At indentation `d` spring `i` is compressed by `u_i = d − s_i` and
//! `F(d) = Σ_i f(u_i)`, `k(d) = dF/dd = Σ_i f'(u_i)`, contacts = #{i : u_i > 0}.
//! With the gaps sorted once (`O(N log N)`), each evaluation visits only the springs in
//! contact. For linear springs, [`super::LinearCurve`] gives the whole curve at once.

use serde::Serialize;

use super::spring::Spring;
use crate::{Error, Result};

/// One point of a force–indentation–stiffness curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurvePoint {
    /// Indentation d from first contact.
    pub indentation: f64,
    /// Normal force F.
    pub force: f64,
    /// Contact stiffness k = dF/dd.
    pub stiffness: f64,
    /// Number of springs in contact (compressed by more than zero).
    pub contacts: usize,
}

/// A foundation of springs with the sorted gaps of one profile (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Foundation {
    gaps: Vec<f64>,
    spring: Spring,
}

fn check_profile(what: &str, values: &[f64]) -> Result<()> {
    if values.is_empty() {
        return Err(Error::invalid("profile", format!("{what} has no points")));
    }
    if let Some((index, &value)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| v.is_nan() || **v == f64::NEG_INFINITY)
    {
        return Err(Error::NonFinite {
            what: what.to_string(),
            index,
            value,
        });
    }
    Ok(())
}

impl Foundation {
    /// A rough line of heights `z_i` (positive up, finite) on springs of `spring`'s spacing:
    /// gaps `z_max − z_i`.
    pub fn from_heights(heights: &[f64], spring: Spring) -> Result<Self> {
        check_profile("line", heights)?;
        crate::ensure_finite("line", heights)?;
        let top = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut gaps: Vec<f64> = heights.iter().map(|z| top - z).collect();
        gaps.sort_unstable_by(f64::total_cmp);
        Ok(Foundation { gaps, spring })
    }

    /// An indenter profile `g_i` (lowest point touches first; `+∞` = never touches; NaN
    /// and `−∞` are refused): gaps `g_i − min g`.
    pub fn from_profile(profile: &[f64], spring: Spring) -> Result<Self> {
        check_profile("profile", profile)?;
        let bottom = profile.iter().copied().fold(f64::INFINITY, f64::min);
        if !bottom.is_finite() {
            return Err(Error::invalid(
                "profile",
                "no point of the profile is finite: nothing can touch",
            ));
        }
        let mut gaps: Vec<f64> = profile.iter().map(|g| g - bottom).collect();
        gaps.sort_unstable_by(f64::total_cmp);
        Ok(Foundation { gaps, spring })
    }

    /// The spring law, spacing and modulus.
    pub fn spring(&self) -> &Spring {
        &self.spring
    }

    /// Number of springs.
    pub fn len(&self) -> usize {
        self.gaps.len()
    }

    /// Always false: a foundation has at least one spring.
    pub fn is_empty(&self) -> bool {
        self.gaps.is_empty()
    }

    /// The gaps, sorted ascending (`+∞` last).
    pub fn gaps(&self) -> &[f64] {
        &self.gaps
    }

    /// The indentation at which the last spring that can touch comes into contact (the
    /// largest finite gap): for a rough line, the peak-to-valley height.
    pub fn full_contact_indentation(&self) -> f64 {
        self.gaps
            .iter()
            .rev()
            .copied()
            .find(|g| g.is_finite())
            .unwrap_or(0.0)
    }

    /// The smallest positive gap: below this indentation only the springs at the first
    /// contact point carry load. `None` if all gaps are zero or infinite.
    pub fn first_positive_gap(&self) -> Option<f64> {
        self.gaps
            .iter()
            .copied()
            .find(|&g| crate::is_positive_finite(g))
    }

    /// Force, stiffness and contacts at indentation `d` (exact; `d ≤ 0` gives zeros).
    pub fn evaluate(&self, indentation: f64) -> CurvePoint {
        let mut force = 0.0;
        let mut stiffness = 0.0;
        let mut contacts = 0;
        for &gap in &self.gaps {
            if gap >= indentation {
                break;
            }
            let (f, k) = self.spring.force_and_stiffness(indentation - gap);
            force += f;
            stiffness += k;
            contacts += 1;
        }
        CurvePoint {
            indentation,
            force,
            stiffness,
            contacts,
        }
    }

    /// [`Foundation::evaluate`] at each indentation.
    pub fn curve(&self, indentations: &[f64]) -> Vec<CurvePoint> {
        indentations.iter().map(|&d| self.evaluate(d)).collect()
    }
}

/// `count` indentations spaced evenly in log from `low` to `high` (both included).
pub fn log_spaced(low: f64, high: f64, count: usize) -> Result<Vec<f64>> {
    if !(low.is_finite() && high.is_finite() && low > 0.0 && high > low) {
        return Err(Error::invalid(
            "range",
            format!(
                "need 0 < low < high, both finite, got {} and {}",
                crate::input::short_number(low),
                crate::input::short_number(high)
            ),
        ));
    }
    if count < 2 {
        return Err(Error::invalid(
            "count",
            format!("need at least 2 levels, got {count}"),
        ));
    }
    Ok(crate::fit::log_levels(low, high, count).collect())
}

#[cfg(test)]
mod tests {
    use super::super::indenter::Axisymmetric;
    use super::super::spring::SpringLaw;
    use super::*;
    use crate::reference::{Cone, FlatPunch, Hertz};

    fn hertz_foundation(law: SpringLaw, radius: f64, dx: f64, n: usize) -> Foundation {
        let profile = Axisymmetric::Sphere { radius }.sample(n, dx).unwrap();
        Foundation::from_profile(&profile, Spring::new(law, dx, 1.3).unwrap()).unwrap()
    }

    #[test]
    fn fine_linear_springs_reproduce_hertz_to_half_a_percent() {
        // Discretisation error: stiffness E*Δx·(2⌊a/Δx⌋+1) vs 2E*a is ≤ Δx/a, the force's
        // Riemann sum is better still; a ≥ 200 Δx gives ≤ 0.5 %.
        let (radius, dx) = (1.0, 1e-3);
        let foundation = hertz_foundation(SpringLaw::Linear, radius, dx, 8001);
        let hertz = Hertz {
            radius,
            modulus: 1.3,
        };
        let mut worst: (f64, f64) = (0.0, 0.0);
        for a_over_dx in [200.0, 317.0, 550.0, 1000.0, 2500.0, 3900.0] {
            let d = (a_over_dx * dx).powi(2) / radius;
            let p = foundation.evaluate(d);
            let force_error = (p.force / hertz.force(d) - 1.0).abs();
            let stiffness_error = (p.stiffness / hertz.stiffness(d) - 1.0).abs();
            worst = (worst.0.max(force_error), worst.1.max(stiffness_error));
            assert!(
                force_error < 5e-3,
                "a/Δx = {a_over_dx}: force {force_error}"
            );
            assert!(
                stiffness_error < 5e-3,
                "a/Δx = {a_over_dx}: stiffness {stiffness_error}"
            );
        }
        eprintln!(
            "MDR Hertz, a/Δx ∈ [200, 3900]: worst force error {:.2e}, stiffness {:.2e}",
            worst.0, worst.1
        );
    }

    #[test]
    fn hertz_law_15_2_keeps_hertz_far_below_the_resolution() {
        // Δx²/R = 1e-4. Linear springs: one spring, F = E*Δx d, off by 0.75 Δx/sqrt(Rd).
        let (radius, dx) = (1.0, 1e-2);
        let n = 2001;
        let linear = hertz_foundation(SpringLaw::Linear, radius, dx, n);
        let nonlinear = hertz_foundation(SpringLaw::Hertz { radius }, radius, dx, n);
        let hertz = Hertz {
            radius,
            modulus: 1.3,
        };
        let critical = dx * dx / radius;
        for t in [1e-8, 1e-6, 1e-4, 1e-2, 0.5, 0.99] {
            let d = t * critical;
            let ratio = nonlinear.evaluate(d).force / hertz.force(d);
            assert!((ratio - 1.0).abs() < 0.02, "d = {t} Δx²/R: ratio {ratio}");
            let k_ratio = nonlinear.evaluate(d).stiffness / hertz.stiffness(d);
            assert!(
                (k_ratio - 1.0).abs() < 0.02,
                "d = {t} Δx²/R: k ratio {k_ratio}"
            );
        }
        // Linear springs are off by orders of magnitude there.
        let d = 1e-6 * critical;
        let linear_ratio = linear.evaluate(d).force / hertz.force(d);
        assert!(linear_ratio > 500.0, "linear springs: ratio {linear_ratio}");
        // Well above the transition both agree with Hertz again (a ≥ 30 Δx).
        for t in [1e3, 1e4] {
            let d = t * critical;
            for f in [&linear, &nonlinear] {
                let ratio = f.evaluate(d).force / hertz.force(d);
                assert!((ratio - 1.0).abs() < 0.02, "d = {t} Δx²/R: ratio {ratio}");
            }
        }
    }

    #[test]
    fn cone_matches_its_closed_form() {
        let (slope, dx) = (0.2, 1e-3);
        let profile = Axisymmetric::Cone { slope }.sample(20001, dx).unwrap();
        let foundation =
            Foundation::from_profile(&profile, Spring::linear(dx, 2.0).unwrap()).unwrap();
        let cone = Cone {
            slope,
            modulus: 2.0,
        };
        // a = 2d/(π tanθ) ≥ 500 Δx: errors ≤ Δx/a = 0.2 %.
        for a in [0.5, 1.3, 4.0] {
            let d = a * PI_HALF * slope;
            let p = foundation.evaluate(d);
            assert!((cone.contact_radius(d) / a - 1.0).abs() < 1e-12);
            assert!((p.force / cone.force(d) - 1.0).abs() < 2e-3, "a = {a}");
            assert!(
                (p.stiffness / cone.stiffness(d) - 1.0).abs() < 2e-3,
                "a = {a}"
            );
        }
    }

    const PI_HALF: f64 = std::f64::consts::FRAC_PI_2;

    #[test]
    fn power_law_indenters_match_their_closed_forms() {
        // f = c rⁿ → g = κ(n) c |x|ⁿ; F = 2E* n/(n+1) d a, k = 2E*a (reference::PowerLaw).
        // a ≥ 1000 Δx: stiffness error ≤ Δx/a = 0.1 %, force better.
        let dx = 1e-3;
        for exponent in [0.7, 1.5, 3.0] {
            let (coefficient, modulus) = (0.4, 1.1);
            let profile = Axisymmetric::PowerLaw {
                coefficient,
                exponent,
            }
            .sample(8001, dx)
            .unwrap();
            let foundation =
                Foundation::from_profile(&profile, Spring::linear(dx, modulus).unwrap()).unwrap();
            let reference = crate::reference::PowerLaw {
                coefficient,
                exponent,
                modulus,
            };
            for a in [1.0, 2.5] {
                let d = reference.stretch() * coefficient * f64::powf(a, exponent);
                let p = foundation.evaluate(d);
                assert!((reference.contact_radius(d) / a - 1.0).abs() < 1e-12);
                assert!(
                    (p.force / reference.force(d) - 1.0).abs() < 1e-3,
                    "n = {exponent}, a = {a}"
                );
                assert!(
                    (p.stiffness / reference.stiffness(d) - 1.0).abs() < 1e-3,
                    "n = {exponent}, a = {a}"
                );
            }
        }
    }

    #[test]
    fn flat_punch_has_stiffness_two_modulus_radius() {
        // (2m+1) springs cover |x| ≤ a = (m + ½)Δx exactly: k = E*Δx(2m+1) = 2E*a.
        let dx = 0.01;
        let punch = FlatPunch {
            radius: 100.5 * dx,
            modulus: 0.8,
        };
        let profile = Axisymmetric::FlatPunch {
            radius: punch.radius,
        }
        .sample(401, dx)
        .unwrap();
        let foundation =
            Foundation::from_profile(&profile, Spring::linear(dx, 0.8).unwrap()).unwrap();
        for d in [1e-6, 0.3] {
            let p = foundation.evaluate(d);
            assert_eq!(p.contacts, 201);
            assert!((p.stiffness / punch.stiffness() - 1.0).abs() < 1e-12);
            assert!((p.force / punch.force(d) - 1.0).abs() < 1e-12);
        }
        assert_eq!(foundation.full_contact_indentation(), 0.0);
    }

    #[test]
    fn evaluation_matches_a_naive_sum_for_every_law() {
        let heights: Vec<f64> = (0..257)
            .map(|i| ((i * 7919 % 257) as f64 / 257.0).powf(1.3) - 0.4 * (i as f64 * 0.1).sin())
            .collect();
        let top = heights.iter().copied().fold(f64::MIN, f64::max);
        for law in [
            SpringLaw::Linear,
            SpringLaw::Hertz { radius: 0.01 },
            SpringLaw::Fractal {
                hurst: 0.8,
                rms_height: 0.3,
                size: 1.0,
            },
        ] {
            let spring = Spring::new(law, 1.0 / 257.0, 1.7).unwrap();
            let foundation = Foundation::from_heights(&heights, spring).unwrap();
            for d in [0.0, 1e-5, 0.01, 0.3, 5.0] {
                let p = foundation.evaluate(d);
                let naive_force: f64 = heights.iter().map(|z| spring.force(d - (top - z))).sum();
                let naive_k: f64 = heights
                    .iter()
                    .map(|z| spring.stiffness(d - (top - z)))
                    .sum();
                let naive_contacts = heights.iter().filter(|z| d - (top - *z) > 0.0).count();
                assert!((p.force - naive_force).abs() <= 1e-12 * naive_force.max(1e-300));
                assert!((p.stiffness - naive_k).abs() <= 1e-12 * naive_k.max(1e-300));
                assert_eq!(p.contacts, naive_contacts);
            }
        }
    }

    #[test]
    fn bad_profiles_are_refused() {
        let spring = Spring::linear(0.1, 1.0).unwrap();
        let err = Foundation::from_heights(&[0.0, f64::NAN, 1.0], spring).unwrap_err();
        assert!(matches!(err, Error::NonFinite { index: 1, .. }), "{err}");
        assert!(Foundation::from_heights(&[0.0, f64::INFINITY], spring).is_err());
        assert!(Foundation::from_profile(&[f64::INFINITY; 3], spring).is_err());
        assert!(Foundation::from_profile(&[], spring).is_err());
        assert!(log_spaced(0.0, 1.0, 10).is_err());
        let levels = log_spaced(1e-3, 10.0, 5).unwrap();
        assert_eq!(levels.len(), 5);
        assert!((levels[1] / 1e-2 - 1.0).abs() < 1e-12);
        assert_eq!(levels[4], 10.0);
    }
}
