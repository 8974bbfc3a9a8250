//! Axisymmetric indenters mapped to 1D profiles by the MDR transform.
//!
//! A rigid axisymmetric indenter `f(r)` (`f(0) = 0`, pointing down into the half-space) is
//! equivalent, for force, indentation and contact radius, to the 1D profile (Popov & Heß,
//! ch. 3; SCIENCE.md §3)
//!
//! `g(x) = |x| ∫₀^|x| f'(r) / sqrt(x² − r²) dr`
//!
//! pressed into a foundation of springs of stiffness `E*·Δx` (see [`super::Foundation`]).
//! Closed forms ([`Axisymmetric`]):
//! * sphere (paraboloid `f = r²/2R`): `g = x²/R` — eq. (15.1), `R₁ = R/2`;
//! * cone `f = r·tan θ`: `g = (π/2)·tan θ·|x|`;
//! * flat punch of radius `a`: `g = 0` for `|x| ≤ a`, `+∞` outside (those springs never
//!   touch). A spring exactly at the edge, `|x| = a`, is inside: the test is
//!   `|x| ≤ a·(1 + 1e-12)` ([`PUNCH_EDGE_TOLERANCE`]), so that a radius that is a multiple
//!   `m·Δx` of the spacing takes its `2m + 1` springs (odd `n`) whatever the rounding of
//!   `x_i = (i − (n−1)/2)·Δx` (e.g. `3 × 0.1 = 0.30000000000000004 > 0.3`). The stiffness is
//!   then `E*Δx·(springs inside)`, within `Δx/a` of `2E*a`; exactly `2E*a` for
//!   `a = (m + ½)Δx`;
//! * power law `f = c·rⁿ`: `g = κ(n)·c·|x|ⁿ` with the stretch factor
//!   `κ(n) = √π Γ(n/2+1)/Γ(n/2+1/2)` of [`crate::reference::PowerLaw::stretch`].
//!
//! A **user profile** sampled at `r_k = k·Δr` ([`RadialProfile`]) is transformed
//! numerically. The integrand is singular (integrably, like `1/sqrt(x−r)`) at `r = |x|`;
//! instead of quadrature we take `f'` piecewise linear between its values at the samples
//! (second-order finite differences: central inside, one-sided at the ends), so on each
//! segment `f'(r) = α + β r` and the integral is exact in closed form (the substitution
//! `r = x sin t` done analytically):
//! `∫ₐᵇ (α + β r)/sqrt(x² − r²) dr = α·(asin(b/x) − asin(a/x)) − β·(sqrt(x²−b²) − sqrt(x²−a²))`.
//! This is exact for linear and quadratic profiles (cone, sphere) and `O(Δr²)` for smooth
//! ones. (Taking `f` itself piecewise linear — a constant `f'` per segment — converges
//! only like `(Δr/x)^{3/2}`: the singular weight does not average the slope error of the
//! last segment.) Cost `O(samples below |x|)` per evaluated `x`.
//!
//! Springs are placed symmetrically, `x_i = (i − (n−1)/2)·Δx`, `i = 0..n`: for odd `n`
//! one spring sits on the axis (as in the book's Fig. 15.1), for even `n` two at `±Δx/2`.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::reference::PowerLaw;
use crate::{Error, Result};

/// Relative tolerance of the flat punch's edge: a spring at `|x| ≤ a·(1 + 1e-12)` is under
/// the punch, so springs exactly at `|x| = a` count although their computed position may
/// be rounded a few ulps outwards. 1e-12 is far above rounding (≈ 1e-16 per operation) and
/// far below any deliberate distinction between radii.
pub const PUNCH_EDGE_TOLERANCE: f64 = 1e-12;

/// Closed-form axisymmetric indenters (parameters checked by [`Axisymmetric::validate`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Axisymmetric {
    /// Sphere of radius R, as the paraboloid `r²/2R`: `g = x²/R` (15.1).
    Sphere {
        /// Radius R.
        radius: f64,
    },
    /// Cone `f = r tan θ`: `g = (π/2) tan θ |x|`.
    Cone {
        /// Flank slope `tan θ`.
        slope: f64,
    },
    /// Flat-ended cylindrical punch of radius a: `g = 0` on `|x| ≤ a` (edge included, up to
    /// a relative [`PUNCH_EDGE_TOLERANCE`]), `+∞` outside.
    FlatPunch {
        /// Punch radius a.
        radius: f64,
    },
    /// Power law `f = c rⁿ`: `g = κ(n) c |x|ⁿ`.
    PowerLaw {
        /// Prefactor c.
        coefficient: f64,
        /// Exponent n > 0.
        exponent: f64,
    },
}

impl std::fmt::Display for Axisymmetric {
    /// The profile as a reader writes it, e.g. `sphere R = 1` or `power law f = 0.5 r^3`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Axisymmetric::Sphere { radius } => write!(f, "sphere R = {radius}"),
            Axisymmetric::Cone { slope } => write!(f, "cone tan θ = {slope}"),
            Axisymmetric::FlatPunch { radius } => write!(f, "flat punch a = {radius}"),
            Axisymmetric::PowerLaw {
                coefficient,
                exponent,
            } => write!(f, "power law f = {coefficient} r^{exponent}"),
        }
    }
}

impl Axisymmetric {
    /// Checks that every parameter is positive and finite.
    pub fn validate(&self) -> Result<()> {
        let checks: &[(&'static str, f64)] = match self {
            Axisymmetric::Sphere { radius } | Axisymmetric::FlatPunch { radius } => {
                &[("radius", *radius)]
            }
            Axisymmetric::Cone { slope } => &[("slope", *slope)],
            Axisymmetric::PowerLaw {
                coefficient,
                exponent,
            } => &[("coefficient", *coefficient), ("exponent", *exponent)],
        };
        for &(name, value) in checks {
            if !crate::is_positive_finite(value) {
                return Err(Error::invalid(
                    name,
                    format!(
                        "must be positive and finite, got {}",
                        crate::input::short_number(value)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The MDR profile `g(x)`.
    pub fn mdr_profile(&self, x: f64) -> f64 {
        let x = x.abs();
        match *self {
            Axisymmetric::Sphere { radius } => x * x / radius,
            Axisymmetric::Cone { slope } => PI / 2.0 * slope * x,
            Axisymmetric::FlatPunch { radius } => {
                if x <= radius * (1.0 + PUNCH_EDGE_TOLERANCE) {
                    0.0
                } else {
                    f64::INFINITY
                }
            }
            Axisymmetric::PowerLaw {
                coefficient,
                exponent,
            } => {
                let stretch = PowerLaw {
                    coefficient,
                    exponent,
                    modulus: 1.0,
                }
                .stretch();
                stretch * coefficient * x.powf(exponent)
            }
        }
    }

    /// `g` at the `n` symmetric spring positions `x_i = (i − (n−1)/2)·Δx`.
    pub fn sample(&self, n: usize, spacing: f64) -> Result<Vec<f64>> {
        self.validate()?;
        check_grid(n, spacing)?;
        Ok(spring_positions(n, spacing)
            .map(|x| self.mdr_profile(x))
            .collect())
    }
}

fn check_grid(n: usize, spacing: f64) -> Result<()> {
    if n == 0 {
        return Err(Error::invalid("n", "need at least one spring"));
    }
    if !crate::is_positive_finite(spacing) {
        return Err(Error::invalid(
            "dx",
            format!(
                "the spring spacing Δx must be positive and finite, got {}",
                crate::input::short_number(spacing)
            ),
        ));
    }
    // The sampled profile is one f64 per spring; refuse it before allocating.
    crate::memory::ensure_fits(
        &format!("a profile of {n} springs"),
        crate::memory::array_bytes(&[n], std::mem::size_of::<f64>()),
    )
}

/// The symmetric spring positions `x_i = (i − (n−1)/2)·Δx`, `i = 0..n`.
pub fn spring_positions(n: usize, spacing: f64) -> impl Iterator<Item = f64> {
    let centre = (n as f64 - 1.0) / 2.0;
    (0..n).map(move |i| (i as f64 - centre) * spacing)
}

/// A user's axisymmetric profile `f(r_k)` sampled at `r_k = k·Δr`, `k = 0..m`, with
/// `f(0)` the tip; transformed numerically with `f'` piecewise linear (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct RadialProfile {
    step: f64,
    /// `f'(r_k)` from second-order differences.
    derivatives: Vec<f64>,
}

impl RadialProfile {
    /// Checks at least three finite samples and a positive step.
    pub fn new(values: &[f64], step: f64) -> Result<Self> {
        if values.len() < 3 {
            return Err(Error::invalid(
                "profile",
                format!(
                    "a radial profile needs at least 3 samples, got {}",
                    values.len()
                ),
            ));
        }
        crate::ensure_finite("radial profile", values)?;
        if !crate::is_positive_finite(step) {
            return Err(Error::invalid(
                "radial_step",
                format!(
                    "the radial sample step must be positive and finite, got {}",
                    crate::input::short_number(step)
                ),
            ));
        }
        let m = values.len();
        let mut derivatives = Vec::with_capacity(m);
        derivatives.push((-3.0 * values[0] + 4.0 * values[1] - values[2]) / (2.0 * step));
        derivatives.extend(values.windows(3).map(|w| (w[2] - w[0]) / (2.0 * step)));
        derivatives
            .push((3.0 * values[m - 1] - 4.0 * values[m - 2] + values[m - 3]) / (2.0 * step));
        Ok(RadialProfile { step, derivatives })
    }

    /// The largest radius sampled, `(m−1)·Δr`.
    pub fn max_radius(&self) -> f64 {
        (self.derivatives.len() - 1) as f64 * self.step
    }

    /// `g(x) = |x| ∫₀^|x| f'(r)/sqrt(x²−r²) dr` with `f'` piecewise linear; `None` beyond
    /// the sampled radius (where `f` is unknown).
    pub fn mdr_profile(&self, x: f64) -> Option<f64> {
        let x = x.abs();
        if x > self.max_radius() * (1.0 + 1e-12) {
            return None;
        }
        if x == 0.0 {
            return Some(0.0);
        }
        let mut sum = 0.0;
        let mut lower_angle = 0.0;
        let mut lower_root = x;
        for (k, pair) in self.derivatives.windows(2).enumerate() {
            let lower = k as f64 * self.step;
            if lower >= x {
                break;
            }
            let beta = (pair[1] - pair[0]) / self.step;
            let alpha = pair[0] - beta * lower;
            let upper = ((k + 1) as f64 * self.step).min(x);
            let ratio = (upper / x).min(1.0);
            let upper_angle = ratio.asin();
            let upper_root = x * (1.0 - ratio * ratio).max(0.0).sqrt();
            sum += alpha * (upper_angle - lower_angle) - beta * (upper_root - lower_root);
            lower_angle = upper_angle;
            lower_root = upper_root;
        }
        Some(x * sum)
    }

    /// `g` at the `n` symmetric spring positions; fails if they reach beyond the samples.
    pub fn sample(&self, n: usize, spacing: f64) -> Result<Vec<f64>> {
        check_grid(n, spacing)?;
        spring_positions(n, spacing)
            .map(|x| {
                self.mdr_profile(x).ok_or_else(|| {
                    Error::invalid(
                        "n",
                        format!(
                            "springs reach |x| = {:.6e}, beyond the radial profile's last sample \
                             at r = {:.6e}",
                            x.abs(),
                            self.max_radius()
                        ),
                    )
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampled(f: impl Fn(f64) -> f64, step: f64, m: usize) -> RadialProfile {
        let values: Vec<f64> = (0..m).map(|k| f(k as f64 * step)).collect();
        RadialProfile::new(&values, step).unwrap()
    }

    #[test]
    fn numerical_transform_of_a_cone_is_exact() {
        // A cone is piecewise linear, so the per-segment arcsine integral is exact.
        let slope = 0.3;
        let profile = sampled(|r| slope * r, 0.01, 201);
        for x in [0.005, 0.37, 1.0, 2.0] {
            let g = profile.mdr_profile(x).unwrap();
            let exact = PI / 2.0 * slope * x;
            assert!((g / exact - 1.0).abs() < 1e-12, "x = {x}: {g} vs {exact}");
        }
        assert!(profile.mdr_profile(2.01).is_none());
    }

    #[test]
    fn numerical_transform_of_a_sphere_gives_15_1() {
        // f = r²/2R → g = x²/R: f' is linear, so the transform is exact but for rounding.
        let radius = 2.0;
        let step = 1e-3;
        let profile = sampled(|r| r * r / (2.0 * radius), step, 1001);
        for x in [0.0015, 0.02, 0.1, 0.5, 1.0] {
            let g = profile.mdr_profile(x).unwrap();
            let exact = Axisymmetric::Sphere { radius }.mdr_profile(x);
            assert!((g / exact - 1.0).abs() < 1e-12, "x = {x}: {g} vs {exact}");
        }
    }

    #[test]
    fn numerical_transform_of_power_laws_matches_the_stretch_factor() {
        // g = κ(n) c xⁿ with κ from reference::PowerLaw::stretch. Exact (rounding) for n = 1
        // and 2, where f' is linear; otherwise O(n²(Δr/x)²) for smooth f (6e-6 for n = 3 and
        // 1.9e-5 for n = 4.5 at x = 0.1), hence 5e-5. Tips that are not smooth converge more slowly and get their own,
        // stated, tolerances: n = 0.5 has f' ∝ r^(-1/2), infinite at the tip, which no
        // sampled derivative represents (6e-3 at x = 0.1, 400 samples in); n = 1.5 has
        // f'' ∝ r^(-1/2) (1.4e-5).
        for (exponent, tolerance) in [
            (0.5, 1e-2),
            (1.0, 1e-12),
            (1.5, 1e-4),
            (2.0, 1e-12),
            (3.0, 5e-5),
            (4.5, 5e-5),
        ] {
            let coefficient = 0.7;
            let profile = sampled(|r| coefficient * r.powf(exponent), 2.5e-4, 4001);
            let closed = Axisymmetric::PowerLaw {
                coefficient,
                exponent,
            };
            let mut worst: f64 = 0.0;
            for x in [0.1, 0.55, 1.0] {
                let g = profile.mdr_profile(x).unwrap();
                let exact = closed.mdr_profile(x);
                worst = worst.max((g / exact - 1.0).abs());
                assert!(
                    (g / exact - 1.0).abs() < tolerance,
                    "n = {exponent}, x = {x}: {g} vs {exact}"
                );
            }
            eprintln!("power law n = {exponent}: worst relative error {worst:.2e}");
        }
        // κ(1) = π/2 (cone) and κ(2) = 2 (sphere, c = 1/2R → g = x²/R).
        let cone = Axisymmetric::PowerLaw {
            coefficient: 1.0,
            exponent: 1.0,
        };
        assert!((cone.mdr_profile(1.0) - PI / 2.0).abs() < 1e-12);
        let sphere = Axisymmetric::PowerLaw {
            coefficient: 0.25,
            exponent: 2.0,
        };
        let r2 = Axisymmetric::Sphere { radius: 2.0 };
        assert!((sphere.mdr_profile(0.3) / r2.mdr_profile(0.3) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn springs_are_symmetric_and_validated() {
        let xs: Vec<f64> = spring_positions(5, 0.5).collect();
        assert_eq!(xs, vec![-1.0, -0.5, 0.0, 0.5, 1.0]);
        let xs: Vec<f64> = spring_positions(2, 1.0).collect();
        assert_eq!(xs, vec![-0.5, 0.5]);
        assert!(Axisymmetric::Sphere { radius: 1.0 }.sample(5, 0.0).is_err());
        assert!(Axisymmetric::Cone { slope: -1.0 }.sample(5, 0.1).is_err());
        let punch = Axisymmetric::FlatPunch { radius: 0.1 }
            .sample(5, 0.1)
            .unwrap();
        assert_eq!(punch, vec![f64::INFINITY, 0.0, 0.0, 0.0, f64::INFINITY]);
        assert!(RadialProfile::new(&[0.0, 0.1, f64::NAN], 0.1).is_err());
        // The edge belongs to the punch: a = 0.1 = Δx takes x = ±0.1 above.
        let one_sided = Axisymmetric::FlatPunch { radius: 0.1 }
            .sample(4, 0.1)
            .unwrap();
        assert_eq!(one_sided, vec![f64::INFINITY, 0.0, 0.0, f64::INFINITY]);
        assert!(RadialProfile::new(&[0.0, 0.1], 0.1).is_err());
        let short = sampled(|r| r, 0.1, 11);
        assert!(short.sample(31, 0.1).is_err());
        assert!(short.sample(21, 0.1).is_ok());
    }

    #[test]
    fn a_profile_that_cannot_fit_is_refused_before_allocating() {
        for n in [1usize << 60, usize::MAX] {
            let err = Axisymmetric::Sphere { radius: 1.0 }
                .sample(n, 0.1)
                .unwrap_err();
            assert!(matches!(err, Error::OutOfMemory { .. }), "{err}");
            let err = sampled(|r| r, 0.1, 11).sample(n, 0.1).unwrap_err();
            assert!(matches!(err, Error::OutOfMemory { .. }), "{err}");
        }
    }

    #[test]
    fn punch_radius_on_the_grid_takes_the_edge_springs() {
        // a = m·Δx puts springs exactly at the edge, where the computed x_i = (i − c)·Δx may
        // round either way (3 × 0.1 = 0.30000000000000004 > 0.3). The edge is in, whatever
        // the rounding: 2m + 1 springs, as for a radius a hair larger, and a hair smaller
        // (beyond the 1e-12 tolerance) drops them.
        let count = |radius: f64, n: usize, dx: f64| {
            Axisymmetric::FlatPunch { radius }
                .sample(n, dx)
                .unwrap()
                .iter()
                .filter(|g| g.is_finite())
                .count()
        };
        for (m, dx) in [
            (3usize, 0.1),
            (7, 0.1),
            (1, 0.3),
            (5, 1e-3),
            (100, 0.01),
            (13, 0.7),
        ] {
            let radius = m as f64 * dx;
            let n = 2 * m + 41;
            assert_eq!(count(radius, n, dx), 2 * m + 1, "a = {m}·{dx}");
            assert_eq!(
                count(radius * (1.0 + 1e-8), n, dx),
                2 * m + 1,
                "a hair larger"
            );
            assert_eq!(
                count(radius * (1.0 - 1e-8), n, dx),
                2 * m - 1,
                "a hair smaller"
            );
        }
        // The case of the audit: radius 0.3 and 0.30000001 with Δx = 0.1 agree.
        assert_eq!(count(0.3, 11, 0.1), 7);
        assert_eq!(count(0.300_000_01, 11, 0.1), 7);
    }
}
