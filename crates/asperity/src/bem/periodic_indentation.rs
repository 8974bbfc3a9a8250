//! Displacement control on periodic boundaries: [`ContactSolver::solve`] with
//! [`Control::Indentation`](super::Control::Indentation) on a periodic half-space.
//!
//! **Convention.** A periodic half-space fixes displacements only up to a constant; the
//! operator sets their mean (the `q = 0` mode) to zero, and a load-controlled solve reports
//! its indentation in that convention: `d` is the mean of `u + f` on the contact set with
//! `mean(u) = 0`, the approach of the indenter's highest point relative to the mean elastic
//! displacement. Then `d` is a function of the mean pressure alone, continuous and
//! increasing on `0 < p̄ < p*` — its slope is `A/k` (Barber's theorem; `K_SS` is positive
//! definite for every contact set `S` short of the whole grid, so the frozen-set stiffness
//! `k` is finite and positive) — from `d(0) = 0` to `d(p*) = mean(f) = max(h) − mean(h)`,
//! where the gap closes everywhere (`u = d − f` on the whole grid and `mean(u) = 0`). Below
//! `mean(f)` some gap stays open (`u + f ≥ d` everywhere and their means differ by the mean
//! gap), so every `0 ≤ d < mean(f)` belongs to exactly one partial contact, and
//! `d ≥ mean(f)` is refused as beyond full contact. The stiffness grows without bound as the
//! set fills: `d` flattens as `p̄ → p*` (Westergaard: `d = Δ r (1 − ln r)`, `r = p̄/p*`).
//!
//! **Method.** A root find of `d(p̄) = d` over load-controlled Polonsky–Keer solves, each
//! warm-started from the previous one, so the result *is* a load-controlled solution:
//! * Newton steps `p̄ ← p̄ − (d(p̄) − d) k/A` with the frozen-set stiffness of the state
//!   (conjugate gradients to 1e-2: on a fixed contact set `d` is affine in `p̄` with exactly
//!   this slope), a secant step where the stiffness is not available;
//! * kept inside a bracket `[p̄_lo, p̄_hi]` that starts from the exact ends `d(0) = 0`,
//!   `d(p*) = mean(f)`: a bisection in `log p̄` (a decade down while `p̄_lo = 0`) replaces any
//!   step that leaves the bracket or is not below half the step before last (Brent's test,
//!   in `log p̄`). A state moves an end of the bracket only when `|d(p̄) − d|` exceeds ten
//!   times its own residual, so a loosely solved state cannot put the root outside it;
//! * the first point is the current state when there is one (a free evaluation), else a
//!   local-spring estimate `mean(max(d − f, 0)) / K₀₀`;
//! * the load-controlled solves run to `10⁻³ |d(p̄) − d| / h_rms` of the previous state
//!   (at most 1e-4, at least half the tolerance): far from the root an accurate state is
//!   wasted work;
//! * a state is accepted when its residual measured against the given `d` (the module's
//!   residual with `d` fixed) is below the tolerance. On the contact set
//!   `Σ(u + f − d_lc) = 0`, so that residual is `sqrt(r_lc² + ((d_lc − d)/h_rms)²)`, and a
//!   state solved to half the tolerance is accepted once its own indentation is within
//!   `0.86 tol · h_rms` of `d`.
//!
//! [`SolveInfo`] sums the Polonsky–Keer iterations of every solve (bounded in total by
//! `max_iterations`; the short CGs of the Newton slopes, one operator application per
//! iteration against two per Polonsky–Keer iteration, are not counted); failure is
//! [`SolveError::NoConvergence`] with the residual against `d`.
//!
//! Polonsky & Keer's own displacement-controlled iteration (used for free boundaries) also
//! works with the zero-mean operator — the minimiser of `½ pᵀKp − pᵀ(d − f)` over `p ≥ 0` is
//! unique for `d < mean(f)`, since along the null space of `K` (constants) the objective is
//! linear with slope `n (mean(f) − d) > 0` — but its conjugate gradients see the condition
//! number of `K_SS`, which grows like `n / n_open` as the set fills (the constant mode is
//! held only by the open points), and nothing but its observed behaviour vouches for its
//! convergence there. The root find inherits the robustness of load control, whose mean
//! constraint removes that mode.

use super::polonsky_keer::{gap_and_direction, ContactSolver, Target};
use super::{ContactSummary, SolveError, SolveInfo, SolverKind};

/// Evaluations of `d(p̄)` after which the root find gives up (bisection alone shrinks the
/// bracket geometrically; never approached in the tests).
const MAX_EVALUATIONS: usize = 100;

/// Relative CG residual of the frozen-set stiffness used as the Newton slope.
const SLOPE_TOLERANCE: f64 = 1e-2;

/// Loosest residual of a load-controlled solve inside the root find.
const LOOSEST_INNER_TOLERANCE: f64 = 1e-4;

/// One evaluation: a mean pressure and `d(p̄) − d`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Point {
    pressure: f64,
    excess: f64,
    /// `dp̄/dd = k/A` at this state, where known.
    slope: Option<f64>,
}

/// The root of the line through `a` and `b` (NaN when they are level).
fn secant(a: Point, b: Point) -> f64 {
    b.pressure - b.excess * (b.pressure - a.pressure) / (b.excess - a.excess)
}

/// Distance of two pressures in `log p̄`.
fn log_distance(a: f64, b: f64) -> f64 {
    (a / b).ln().abs()
}

/// The bracket and the two latest evaluations of the root find.
struct RootFind {
    /// Largest pressure known to give `d(p̄) < d`.
    lo: Point,
    /// Smallest pressure known to give `d(p̄) ≥ d`.
    hi: Point,
    older: Option<Point>,
    newer: Option<Point>,
    /// The last two steps in `log p̄` (older first; infinite before two evaluations).
    steps: [f64; 2],
}

impl RootFind {
    /// Records an evaluation; it moves an end of the bracket only if `trusted` (its sign is
    /// certain).
    fn record(&mut self, point: Point, trusted: bool) {
        let step = self
            .newer
            .map_or(f64::INFINITY, |b| log_distance(point.pressure, b.pressure));
        self.steps = [self.steps[1], step];
        if trusted {
            if point.excess < 0.0 {
                if point.pressure > self.lo.pressure {
                    self.lo = point;
                }
            } else if point.pressure < self.hi.pressure {
                self.hi = point;
            }
        }
        self.older = self.newer;
        self.newer = Some(point);
    }

    /// The next pressure to try; `first_guess` when nothing has been evaluated yet.
    fn next(&self, first_guess: f64) -> f64 {
        let (lo, hi) = (self.lo, self.hi);
        let candidate = match (self.older, self.newer) {
            (_, None) if first_guess < hi.pressure => first_guess,
            (_, None) => secant(lo, hi),
            (_, Some(b)) => match (b.slope, self.older) {
                (Some(slope), _) => b.pressure - b.excess * slope,
                (None, Some(a)) => secant(a, b),
                (None, None) => secant(if b.excess < 0.0 { hi } else { lo }, b),
            },
        };
        // Too slow (Brent's test): the step is not below half the step before last.
        let slow = self
            .newer
            .is_some_and(|b| log_distance(candidate, b.pressure) >= 0.5 * self.steps[0]);
        if candidate > lo.pressure && candidate < hi.pressure && !slow {
            candidate
        } else if lo.pressure > 0.0 {
            (lo.pressure * hi.pressure).sqrt()
        } else {
            0.1 * hi.pressure
        }
    }
}

impl ContactSolver {
    /// Displacement control on periodic boundaries (see the module docs); the caller has
    /// checked `0 ≤ indentation < mean(f)`.
    /// A load-controlled solve by the chosen iteration.
    fn load_controlled(
        &mut self,
        target: Target,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<(ContactSummary, SolveInfo), SolveError> {
        match self.params.solver {
            SolverKind::Bccg => self.bccg(target, tolerance, max_iterations),
            SolverKind::PolonskyKeer => self.polonsky_keer(target, tolerance, max_iterations),
        }
    }

    pub(super) fn periodic_indentation(
        &mut self,
        indentation: f64,
        spent: usize,
    ) -> Result<(ContactSummary, SolveInfo), SolveError> {
        let full = self.periodic_full_contact();
        let full_indentation = full
            .indentation
            .expect("the periodic threshold has an indentation");
        let (tolerance, max_iterations) = (self.params.tolerance, self.params.max_iterations);
        let n = self.profile.len() as f64;

        // Zero load: accepted when only penetrations below the tolerance remain.
        let penetration = self
            .profile
            .iter()
            .map(|f| (indentation - f).max(0.0).powi(2))
            .sum::<f64>();
        let mut residual = penetration.sqrt() / self.height_scale;
        if residual < tolerance {
            self.pressure.fill(0.0);
            for (g, f) in self.gap.iter_mut().zip(&self.profile) {
                *g = f - indentation;
            }
            let info = SolveInfo {
                iterations: 0,
                residual,
                operator_applications: 0,
            };
            return Ok((self.finish(indentation, 0), info));
        }

        let mut root = RootFind {
            lo: Point {
                pressure: 0.0,
                excess: -indentation,
                slope: None,
            },
            hi: Point {
                pressure: full.mean_pressure,
                excess: full_indentation - indentation,
                slope: None,
            },
            older: None,
            newer: None,
            steps: [f64::INFINITY; 2],
        };
        // The current state is a free evaluation (and may already be the answer); its
        // residual is the solver's tolerance.
        if let Some(current) = self.solved {
            let (r, contact_points) = self.residual_at(indentation);
            if r < tolerance {
                let info = SolveInfo {
                    iterations: 0,
                    residual: r,
                    operator_applications: 1,
                };
                return Ok((self.finish(indentation, contact_points), info));
            }
            residual = r;
            let excess = current.indentation - indentation;
            let slope = self.newton_slope();
            let trusted = excess.abs() > 10.0 * tolerance * self.height_scale;
            root.record(
                Point {
                    pressure: current.mean_pressure,
                    excess,
                    slope,
                },
                trusted,
            );
        }
        // Cold: local springs, each pixel pressed by max(d − f, 0) alone.
        let springs = self
            .profile
            .iter()
            .map(|f| (indentation - f).max(0.0))
            .sum::<f64>()
            / (n * self.operator.self_influence());

        let (mut used, mut applications) = (spent, 0);
        for _ in 0..MAX_EVALUATIONS {
            self.check_stop(used)?;
            if root.hi.pressure - root.lo.pressure <= 4.0 * f64::EPSILON * root.hi.pressure {
                break;
            }
            let pressure = root.next(springs);
            let inner_tolerance = root
                .newer
                .map_or(LOOSEST_INNER_TOLERANCE, |b| {
                    (1e-3 * b.excess.abs() / self.height_scale).min(LOOSEST_INNER_TOLERANCE)
                })
                .max(0.5 * tolerance);
            let solved = self.load_controlled(
                Target::MeanPressure(pressure),
                inner_tolerance,
                max_iterations - used,
            );
            let (summary, info) = match solved {
                Ok(solved) => solved,
                Err(SolveError::NoConvergence { iterations, .. }) => {
                    used += iterations;
                    residual = self.residual_at(indentation).0;
                    break;
                }
                Err(SolveError::Interrupted { iterations }) => {
                    return Err(SolveError::Interrupted {
                        iterations: used + iterations,
                    })
                }
                Err(other) => return Err(other),
            };
            used += info.iterations;
            applications += info.operator_applications;
            self.solved = Some(summary);
            let (r, contact_points) = self.residual_at(indentation);
            residual = r;
            if r < tolerance {
                let info = SolveInfo {
                    iterations: used,
                    residual,
                    operator_applications: applications,
                };
                return Ok((self.finish(indentation, contact_points), info));
            }
            let excess = summary.indentation - indentation;
            let slope = self.newton_slope();
            let trusted = excess.abs() > 10.0 * info.residual * self.height_scale;
            root.record(
                Point {
                    pressure: summary.mean_pressure,
                    excess,
                    slope,
                },
                trusted,
            );
        }
        Err(SolveError::NoConvergence {
            iterations: used,
            residual,
        })
    }

    /// `dp̄/dd = k/A` of the current contact set (frozen-set stiffness to
    /// [`SLOPE_TOLERANCE`]); `None` if the CG fails or nothing is in contact.
    fn newton_slope(&mut self) -> Option<f64> {
        let max_iterations = self.params.stiffness_max_iterations;
        match self.set_stiffness(SLOPE_TOLERANCE, max_iterations) {
            Ok((k, _)) if k > 0.0 => Some(k / self.nominal_area()),
            _ => None,
        }
    }

    /// Residual (module docs) of the current pressure against the indentation `d`, and the
    /// number of contact points. Leaves `g = K p + f − d` in the gap buffer (uses the
    /// direction buffer as scratch).
    fn residual_at(&mut self, indentation: f64) -> (f64, usize) {
        self.operator.apply(&self.pressure, &mut self.gap);
        let mut d = indentation;
        let pass = gap_and_direction(
            &self.pressure,
            &mut self.gap,
            &mut self.direction,
            &self.profile,
            false,
            &mut d,
            0.0,
        );
        (pass.residual(self.height_scale), pass.contact_points)
    }
}

#[cfg(test)]
mod tests {
    use super::super::polonsky_keer::tests::rough_grid;
    use super::super::{Control, HalfSpace, SolverParams};
    use super::*;
    use crate::elastic::Boundary;
    use crate::reference::Westergaard;
    use crate::surface::Surface;
    use ndarray::Array2;
    use std::f64::consts::PI;

    fn periodic(modulus: f64) -> HalfSpace {
        HalfSpace {
            modulus,
            boundary: Boundary::Periodic,
        }
    }

    fn contact_set(solver: &ContactSolver) -> Vec<bool> {
        solver.pressure().iter().map(|&p| p > 0.0).collect()
    }

    /// `max(h) − mean(h)`: the periodic full-contact indentation.
    fn mean_profile(surface: &Surface) -> f64 {
        let h = surface.heights();
        let top = h.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v));
        top - h.iter().sum::<f64>() / h.len() as f64
    }

    #[test]
    fn the_indentation_of_a_load_controlled_solve_gives_its_load_back() {
        // Load control at p̄ reports d (zero-mean displacements); displacement control at
        // that d must return p̄ and the same contact set: cold on a new solver, and warm from
        // a state at another load. Even, odd and non-square grids; light to heavy loads.
        for (rows, cols) in [(64, 64), (63, 63), (50, 72)] {
            let surface = rough_grid(rows, cols, 21);
            let params = SolverParams::default();
            let mut load = ContactSolver::new(&surface, periodic(1.3), params).unwrap();
            let p_star = load.periodic_full_contact().mean_pressure;
            let mut worst = 0.0f64;
            for ratio in [1e-3, 0.03, 0.3] {
                load.reset();
                let (s, load_info) = load.solve(Control::MeanPressure(ratio * p_star)).unwrap();
                let set = contact_set(&load);
                let d = s.indentation;
                assert!(d > 0.0 && d < mean_profile(&surface));
                let mut displacement = ContactSolver::new(&surface, periodic(1.3), params).unwrap();
                let (cold, info) = displacement.solve(Control::Indentation(d)).unwrap();
                assert_eq!(cold.indentation, d);
                assert!(info.iterations > 0 && info.residual < params.tolerance);
                assert_eq!(
                    contact_set(&displacement),
                    set,
                    "{rows}x{cols} {ratio}: cold"
                );
                assert_eq!(cold.contact_points, s.contact_points);
                displacement
                    .solve(Control::MeanPressure(2.0 * ratio * p_star))
                    .unwrap();
                let (warm, warm_info) = displacement.solve(Control::Indentation(d)).unwrap();
                assert_eq!(
                    contact_set(&displacement),
                    set,
                    "{rows}x{cols} {ratio}: warm"
                );
                for t in [cold, warm] {
                    let error = t.mean_pressure / s.mean_pressure - 1.0;
                    assert!(
                        error.abs() < 1e-6,
                        "{rows}x{cols} {ratio}: p̄ error {error:e}"
                    );
                    worst = worst.max(error.abs());
                }
                eprintln!(
                    "{rows}x{cols} p/p* = {ratio}: d/mean(f) = {:.6}, cold {} / warm {} \
                     iterations (load control {}), area {}",
                    d / mean_profile(&surface),
                    info.iterations,
                    warm_info.iterations,
                    load_info.iterations,
                    cold.area_fraction
                );
            }
            eprintln!("{rows}x{cols}: worst p̄ error {worst:.2e}");
        }
    }

    #[test]
    fn displacement_controlled_state_satisfies_the_contact_conditions() {
        let surface = rough_grid(48, 56, 22);
        let mut solver =
            ContactSolver::new(&surface, periodic(1.0), SolverParams::default()).unwrap();
        let d = 0.5 * mean_profile(&surface);
        let (s, _) = solver.solve(Control::Indentation(d)).unwrap();
        let state = solver.state().unwrap();
        // Zero-mean displacements: the convention d is measured in.
        let mean_u = state.displacement.mean().unwrap();
        let max_u = state
            .displacement
            .iter()
            .fold(0.0f64, |m, &u| m.max(u.abs()));
        assert!(mean_u.abs() < 1e-12 * max_u, "mean u {mean_u}");
        let top = surface
            .heights()
            .iter()
            .fold(f64::NEG_INFINITY, |m, &h| m.max(h));
        let h_mean = surface.heights().mean().unwrap();
        let h_rms = (surface
            .heights()
            .iter()
            .map(|h| (h - h_mean).powi(2))
            .sum::<f64>()
            / (48.0 * 56.0))
            .sqrt();
        for ((&p, &u), &h) in state
            .pressure
            .iter()
            .zip(&state.displacement)
            .zip(surface.heights())
        {
            let g = u + (top - h) - d;
            assert!(p >= 0.0);
            if p > 0.0 {
                assert!(g.abs() < 1e-7 * h_rms, "gap {g} in contact");
            } else {
                assert!(g > -1e-7 * h_rms, "penetration {g}");
            }
        }
        assert!(state.gap.iter().all(|&g| g >= 0.0));
        assert!(s.area_fraction > 0.0 && s.area_fraction < 1.0);
        assert!(solver.frozen_set_stiffness().unwrap().0 > 0.0);
    }

    /// One wavelength of `h = Δ cos(2πx/λ)` along 128 columns, 8 rows.
    fn sinusoid(amplitude: f64) -> Surface {
        let (rows, cols, size) = (8, 128, 1.0);
        let dx = size / cols as f64;
        let heights = Array2::from_shape_fn((rows, cols), |(_, j)| {
            amplitude * (2.0 * PI * j as f64 * dx / size).cos()
        });
        Surface::new(heights, size).unwrap()
    }

    #[test]
    fn westergaard_under_displacement_control() {
        let (amplitude, modulus, cols) = (0.01, 2.0, 128);
        let reference = Westergaard {
            wavelength: 1.0,
            amplitude,
            modulus,
        };
        let p_star = reference.full_contact_pressure();
        let mut solver = ContactSolver::new(
            &sinusoid(amplitude),
            periodic(modulus),
            SolverParams::default(),
        )
        .unwrap();
        for ratio in [0.1, 0.5, 0.9] {
            let d = reference.indentation(ratio * p_star);
            let (s, info) = solver.solve(Control::Indentation(d)).unwrap();
            let expected = reference.contact_fraction(ratio * p_star);
            eprintln!(
                "westergaard d = {:.6} Δ (p/p* = {ratio}): area {} vs {expected:.5} \
                 ({:+.2} px), p̄/p* = {:.5}, {} iterations",
                d / amplitude,
                s.area_fraction,
                (s.area_fraction - expected) * cols as f64,
                s.mean_pressure / p_star,
                info.iterations
            );
            // The contact edge is resolved to a pixel on each side.
            assert!(
                (s.area_fraction - expected).abs() <= 2.0 / cols as f64,
                "p/p* = {ratio}: {} vs {expected}",
                s.area_fraction
            );
            // The load follows (the indentation's slope −Δ ln r is finite here).
            assert!(
                (s.mean_pressure / (ratio * p_star) - 1.0).abs() < 0.02,
                "p/p* = {ratio}: p̄/p* = {}",
                s.mean_pressure / p_star
            );
        }
        // Full contact at d = Δ, the mean of the profile, exactly: refused at and above it,
        // with the threshold as an indentation.
        for d in [amplitude, 1.001 * amplitude] {
            let err = solver.solve(Control::Indentation(d)).unwrap_err();
            let message = err.to_string();
            match err {
                SolveError::BeyondFullContact {
                    requested: Control::Indentation(requested),
                    full_contact: Some(full),
                } => {
                    assert_eq!(requested, d);
                    assert!((full / amplitude - 1.0).abs() < 1e-12, "{full}");
                }
                other => panic!("expected BeyondFullContact, got {other:?}"),
            }
            assert!(
                message.contains("is beyond full contact (the gap closes everywhere from an indentation of 1.000000e-2)"),
                "{message}"
            );
            assert!(solver.summary().is_none());
        }
        // Just below: a partial contact close to full (cold after the refusal).
        let (s, _) = solver
            .solve(Control::Indentation(0.999 * amplitude))
            .unwrap();
        assert!(s.area_fraction < 1.0 && s.mean_pressure < p_star);
        assert!(
            s.mean_pressure > 0.9 * p_star,
            "{}",
            s.mean_pressure / p_star
        );
    }

    #[test]
    fn rough_indentation_beyond_full_contact_is_refused() {
        let surface = rough_grid(40, 40, 23);
        let d_full = mean_profile(&surface);
        let mut solver =
            ContactSolver::new(&surface, periodic(1.0), SolverParams::default()).unwrap();
        // The threshold a front end checks up front is the one the solver refuses with.
        let threshold = solver
            .full_contact_threshold()
            .unwrap()
            .indentation
            .unwrap();
        assert!(
            (threshold / d_full - 1.0).abs() < 1e-12,
            "{threshold} vs {d_full}"
        );
        // At and above the solver's own threshold (d_full above is summed in another order
        // and may lie an ulp below it, where a solver may find a partial contact with one
        // point open by rounding).
        for d in [threshold, 1.5 * threshold] {
            match solver.solve(Control::Indentation(d)) {
                Err(SolveError::BeyondFullContact {
                    requested: Control::Indentation(requested),
                    full_contact: Some(full),
                }) => {
                    assert_eq!(requested, d);
                    assert!((full / d_full - 1.0).abs() < 1e-12, "{full} vs {d_full}");
                }
                other => panic!("expected BeyondFullContact, got {other:?}"),
            }
        }
        // Below it every indentation is a partial contact, below full-contact load.
        let p_star = solver.periodic_full_contact().mean_pressure;
        let (s, _) = solver.solve(Control::Indentation(0.99 * d_full)).unwrap();
        assert!(s.area_fraction < 1.0 && s.mean_pressure < p_star);
    }

    #[test]
    fn zero_indentation_is_the_unloaded_state() {
        let surface = rough_grid(32, 32, 24);
        let mut solver =
            ContactSolver::new(&surface, periodic(1.0), SolverParams::default()).unwrap();
        let (s, info) = solver.solve(Control::Indentation(0.0)).unwrap();
        assert_eq!((s.force, s.contact_points, s.indentation), (0.0, 0, 0.0));
        assert_eq!(info.iterations, 0);
        assert!(solver.gap().iter().all(|&g| g >= 0.0));
        assert_eq!(solver.frozen_set_stiffness().unwrap().0, 0.0);
        // A little more carries a little load.
        let d = 1e-3 * mean_profile(&surface);
        let (s, _) = solver.solve(Control::Indentation(d)).unwrap();
        assert!(s.force > 0.0 && s.contact_points > 0);
    }

    #[test]
    fn no_convergence_is_an_error_with_the_iterations_and_residual() {
        let surface = rough_grid(32, 32, 25);
        let params = SolverParams {
            max_iterations: 3,
            ..SolverParams::default()
        };
        let mut solver = ContactSolver::new(&surface, periodic(1.0), params).unwrap();
        match solver.solve(Control::Indentation(0.5 * mean_profile(&surface))) {
            Err(SolveError::NoConvergence {
                iterations,
                residual,
            }) => {
                assert_eq!(iterations, 3);
                assert!(residual > params.tolerance && residual.is_finite());
            }
            other => panic!("expected NoConvergence, got {other:?}"),
        }
        assert!(solver.summary().is_none());
        assert!(solver.frozen_set_stiffness().is_err());
    }
}
