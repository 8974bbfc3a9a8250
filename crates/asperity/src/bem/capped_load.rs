//! Load control under a hardness cap where the load restoration cycles: the solve is
//! finished by displacement control.
//!
//! Both iterations restore the load after each step by scaling
//! ([`super::interface::restore_capped_load`]): the points at the cap held there, the
//! others scaled. That is not the projection onto the loads `Σ p = n p̄` with
//! `0 ≤ p ≤ H`. Where a step overshoots — a thin elastic ring around a plastic core, as
//! on a paraboloid capped below its Hertz pressure, gives long steps — the capped points
//! end up carrying more than the load (every point is then scaled and the plastic set
//! released), or fewer points stay in contact than can carry the load below the cap (the
//! pressure restarts from the bearing area); the steps after a restart undo it, and the
//! iteration cycles. Measured (64², free, `z = −r²/2R`, R = 1 mm, 20 µm, E* = 1 GPa,
//! p̄ = 2.13e5 Pa, H = p_Hertz/2): Polonsky–Keer released the 725 capped points at its
//! 4th step, then restarted from the 686-point bearing area at every step for 10 000
//! iterations (residual 0.105); at p_Hertz/5 the BCCG too.
//!
//! Displacement control has no load restoration: at a fixed indentation `d` the capped
//! problem is the minimum of a strictly convex energy over the box `0 ≤ p ≤ H`, which both
//! iterations reach. The load `F(d)` of that minimum is continuous in `d` and
//! nondecreasing (its slope is the frozen-set stiffness `1ᵀ K_EE⁻¹ 1 ≥ 0` of the elastic
//! set `E`), zero at `d = 0` (the highest point just touches) and tends to `n H` (every
//! point at the cap), so the load `n p̄ < n H` is carried at some `d`. Where an iteration
//! has lost the set more than `LOST_SET_LIMIT` (`interface.rs`) times in a solve, [`ContactSolver::capped_load`]
//! finds that `d` by regula falsi (Illinois) on `F(d) − n p̄` from the bracket
//! `[0, d₁]`, `d₁` doubled from the bearing area's indentation until it carries more than
//! the load, each solve warm from the last; within [`LOAD_HANDOVER`] of the load the load
//! iteration finishes from that state (its restorations then scale by about
//! `1 ± LOAD_HANDOVER`, holding the sets), so the load is exact as in any load-controlled
//! solve and convergence is judged by the same residual.

use super::context::Target;
use super::interface::{bearing_start, Interface};
use super::solver::{ContactSolver, Runner};
use super::{ContactSummary, SolveError, SolveInfo};
use crate::elastic::ContactOperator;

/// The relative load error of a displacement-controlled solve at which the root search
/// hands over to the load iteration: well above the load's noise from the solves'
/// tolerance, small enough that the last restorations keep the sets.
const LOAD_HANDOVER: f64 = 1e-6;

/// Displacement-controlled solves of the root search at most.
const MAX_SOLVES: usize = 200;

/// Iterations and operator applications spent so far by a solve in several parts.
#[derive(Debug, Clone, Copy, Default)]
struct Spent {
    iterations: usize,
    applications: usize,
}

impl Spent {
    fn add(&mut self, info: &SolveInfo) {
        self.iterations += info.iterations;
        self.applications += info.operator_applications;
    }

    /// An error of a part, with the iterations of the parts before added.
    fn error(&self, error: SolveError) -> SolveError {
        match error {
            SolveError::NoConvergence {
                iterations,
                residual,
            } => SolveError::NoConvergence {
                iterations: iterations + self.iterations,
                residual,
            },
            SolveError::Interrupted { iterations } => SolveError::Interrupted {
                iterations: iterations + self.iterations,
            },
            SolveError::Stagnated {
                iterations,
                best,
                window,
            } => SolveError::Stagnated {
                iterations: iterations + self.iterations,
                best,
                window,
            },
            other => other,
        }
    }
}

impl<K: ContactOperator> ContactSolver<K> {
    /// Load control at the mean pressure `mean_pressure` under a cap, by the iteration of `runner`: its load
    /// iteration, and where that cycles the root search of the module docs. The
    /// iterations and applications reported are those of all the parts.
    pub(super) fn capped_load(
        &mut self,
        runner: &mut Runner<'_, K>,
        mean_pressure: f64,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<(ContactSummary, SolveInfo), SolveError> {
        let target = Target::MeanPressure(mean_pressure);
        let result = self.iterate(runner, target, tolerance, max_iterations);
        let Err(SolveError::NoConvergence { iterations, .. }) = result else {
            return result;
        };
        let stalled = self.stalled(runner);
        if !stalled {
            return result;
        }
        // (The cycling part's applications: one per BCCG step, two per PK step.)
        let per_step = self.iteration(runner).0.applications_per_iteration();
        let mut spent = Spent {
            iterations,
            applications: per_step * iterations,
        };
        self.indentation_for_load(runner, mean_pressure, tolerance, max_iterations, &mut spent)
            .map_err(|e| spent.error(e))?;
        let left = max_iterations.saturating_sub(spent.iterations).max(1);
        let (summary, info) = self
            .iterate(runner, target, tolerance, left)
            .map_err(|e| spent.error(e))?;
        spent.add(&info);
        Ok((
            summary,
            SolveInfo {
                iterations: spent.iterations,
                operator_applications: spent.applications,
                ..info
            },
        ))
    }

    /// Leaves the solver in the displacement-controlled solution whose load is within
    /// [`LOAD_HANDOVER`] of `n p̄` (marked solved: the next solve starts warm from it), by
    /// the regula falsi of the module docs; adds what it spent to `spent`.
    fn indentation_for_load(
        &mut self,
        runner: &mut Runner<'_, K>,
        mean_pressure: f64,
        tolerance: f64,
        max_iterations: usize,
        spent: &mut Spent,
    ) -> Result<(), SolveError> {
        let mut d = self.bearing_indentation(mean_pressure);
        self.cx.state.solved = None;
        // Brackets (d, F(d) − p̄): F(0) = 0 below the load; `above` once found. Illinois:
        // the value kept at an end that stays twice in a row is halved.
        let mut below = (0.0, -mean_pressure);
        let mut above: Option<(f64, f64)> = None;
        let (mut last_side, mut load_error) = (0i8, f64::INFINITY);
        for _ in 0..MAX_SOLVES {
            let left = max_iterations.saturating_sub(spent.iterations).max(1);
            let (summary, info) = self.iterate(runner, Target::Indentation(d), tolerance, left)?;
            spent.add(&info);
            self.cx.state.solved = Some(summary);
            let excess = summary.mean_pressure - mean_pressure;
            load_error = (excess / mean_pressure).abs();
            if load_error < LOAD_HANDOVER {
                return Ok(());
            }
            if excess < 0.0 {
                below = (d, excess);
                if last_side == -1 {
                    if let Some(a) = above.as_mut() {
                        a.1 *= 0.5;
                    }
                }
                last_side = -1;
            } else {
                if last_side == 1 {
                    below.1 *= 0.5;
                }
                above = Some((d, excess));
                last_side = 1;
            }
            d = match above {
                None => 2.0 * d,
                Some((b, fb)) => {
                    let (a, fa) = below;
                    let next = (a * fb - b * fa) / (fb - fa);
                    match next > a && next < b {
                        true => next,
                        false => 0.5 * (a + b),
                    }
                }
            };
        }
        // (The residual of a search that ran out: its relative load error.)
        Err(SolveError::NoConvergence {
            iterations: 0,
            residual: load_error,
        })
    }

    /// The indentation of the bearing area that carries `n p̄` fully plastically (the
    /// highest profile value among the `⌈n p̄ / H⌉` lowest, [`bearing_start`]); a small
    /// positive one where that is the top itself. Overwrites the pressure (the solve that
    /// follows starts cold).
    fn bearing_indentation(&mut self, mean_pressure: f64) -> f64 {
        let Interface::Hardness { h } = self.cx.interface else {
            unreachable!("the root search runs under a cap only")
        };
        let profile = &self.cx.problem.profile;
        bearing_start(&mut self.cx.state.pressure, (mean_pressure, h), |i| {
            profile[i]
        });
        let d = self
            .cx
            .state
            .pressure
            .iter()
            .zip(profile)
            .filter(|(&p, _)| p > 0.0)
            .fold(0.0f64, |m, (_, &f)| m.max(f));
        match d > 0.0 {
            true => d,
            false => 1e-3 * self.cx.problem.height_scale,
        }
    }
}
