//! Giving up early on a solve that cannot converge.
//!
//! A converging BCCG or Polonsky–Keer solve halves its residual every few to a few tens of
//! iterations (conjugate gradients on the contact set; measured on the fingerprint's grids
//! and the shared scans: at most a few hundred iterations from the start to `1e-8`). A
//! solve whose residual has not halved in [`WINDOW`] iterations will not converge: the
//! contact set cycles, the iterate wanders at the rounding floor (a tolerance far below
//! `1e-14`), or the problem is hopeless for its grid. Such a solve used to run to its
//! iteration limit (10 000 by default: minutes on a measured scan); it now ends with
//! [`SolveError::Stagnated`] after at most [`WINDOW`] iterations without progress.
//!
//! The check only reads the residual that each iteration computes anyway: it never changes
//! an iterate, so a solve that converges gives the same bits with or without it.

use super::SolveError;

/// Iterations in which the best residual must at least halve.
pub(super) const WINDOW: usize = 1000;

/// The best residual of a solve and where it last halved.
#[derive(Debug, Clone, Copy)]
pub(super) struct Progress {
    /// The best residual so far.
    best: f64,
    /// The residual at the last halving (of the previous mark), and its iteration.
    mark: f64,
    mark_at: usize,
    /// Iterations without a halving after which the solve is given up.
    window: usize,
}

impl Default for Progress {
    fn default() -> Self {
        Progress::with_window(WINDOW)
    }
}

impl Progress {
    /// Forgets the last solve's residuals (at the start of every solve).
    pub(super) fn restart(&mut self) {
        *self = Progress {
            window: self.window,
            ..Progress::default()
        };
    }

    /// Records the residual of `iteration`; [`SolveError::Stagnated`] where the best
    /// residual has not halved in the last `window` iterations. A residual that is not a
    /// number never counts as progress.
    pub(super) fn observe(&mut self, iteration: usize, residual: f64) -> Result<(), SolveError> {
        if residual < self.best {
            self.best = residual;
        }
        if residual <= 0.5 * self.mark {
            (self.mark, self.mark_at) = (residual, iteration);
        } else if iteration.saturating_sub(self.mark_at) >= self.window {
            return Err(SolveError::Stagnated {
                iterations: iteration,
                best: self.best,
                window: self.window,
            });
        }
        Ok(())
    }

    /// A record that gives up after `window` iterations without a halving (the BCCG's
    /// check on its edge rings, `bccg.rs`).
    pub(super) const fn with_window(window: usize) -> Self {
        Progress {
            best: f64::INFINITY,
            mark: f64::INFINITY,
            mark_at: 0,
            window,
        }
    }

    /// Sets the window (tests: a long solve that must not be given up).
    #[cfg(test)]
    pub(super) fn set_window(&mut self, window: usize) {
        self.window = window;
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ContactSolver, Control, HalfSpace, SolverKind, SolverParams};
    use super::*;
    use crate::bem::iterations::polonsky_keer::tests::rough;
    use crate::elastic::Boundary;

    fn solver(kind: SolverKind, boundary: Boundary, tolerance: f64) -> ContactSolver {
        let half_space = HalfSpace {
            modulus: 1.0,
            boundary,
        };
        let params = SolverParams {
            solver: kind,
            tolerance,
            max_iterations: 1_000_000,
            ..SolverParams::default()
        };
        ContactSolver::new(&rough(32, 7), half_space, params).unwrap()
    }

    /// Both iterations with a tolerance no solve reaches (the residual wanders
    /// at the rounding floor, ~1e-16): given up [`WINDOW`] iterations after its last halving
    /// instead of running to the limit of a million iterations, with the best residual; a
    /// reachable tolerance then solves as a new solver does, bit for bit.
    #[test]
    fn a_solve_at_the_rounding_floor_is_given_up_after_a_window() {
        // (Polonsky–Keer under displacement control may reach a residual of exactly 0 on
        // this small grid: it then converges, whatever the tolerance.)
        let cases = [
            (SolverKind::Bccg, Control::MeanPressure(0.02)),
            (SolverKind::Bccg, Control::Indentation(0.01)),
            (SolverKind::PolonskyKeer, Control::MeanPressure(0.02)),
        ];
        for (kind, control) in cases {
            for boundary in [Boundary::Free, Boundary::Periodic] {
                let what = format!("{kind:?} {boundary:?} {control:?}");
                let mut s = solver(kind, boundary, 1e-300);
                match s.solve(control) {
                    Err(SolveError::Stagnated {
                        iterations,
                        best,
                        window,
                    }) => {
                        assert_eq!(window, WINDOW, "{what}");
                        assert!(
                            (WINDOW..2 * WINDOW).contains(&iterations),
                            "{what}: {iterations}"
                        );
                        assert!(best > 0.0 && best < 1e-12, "{what}: {best}");
                    }
                    other => panic!("{what}: {other:?}"),
                }
                assert!(s.summary().is_none(), "{what}");
                s.set_params(SolverParams {
                    tolerance: 1e-8,
                    ..*s.params()
                })
                .unwrap();
                let again = s.solve(control).unwrap();
                let fresh = solver(kind, boundary, 1e-8).solve(control).unwrap();
                assert_eq!(format!("{again:?}"), format!("{fresh:?}"), "{what}");
            }
        }
    }

    #[test]
    fn a_residual_that_keeps_halving_is_never_given_up() {
        // Slow but steady: halving every window − 1 iterations, for ten windows.
        let mut progress = Progress::default();
        progress.set_window(10);
        let rate = 0.5f64.powf(1.0 / 9.0);
        for k in 0..100 {
            progress.observe(k, rate.powi(k as i32)).unwrap();
        }
    }

    #[test]
    fn a_residual_without_halving_for_a_window_is_given_up_with_its_best() {
        let mut progress = Progress::default();
        progress.set_window(10);
        progress.observe(0, 1.0).unwrap();
        progress.observe(1, 0.4).unwrap();
        // Oscillating above 0.2 (half of the last mark): no progress.
        for k in 2..11 {
            let r = if k % 2 == 0 { 0.9 } else { 0.25 };
            progress.observe(k, r).unwrap();
        }
        match progress.observe(11, 0.3) {
            Err(SolveError::Stagnated {
                iterations: 11,
                best,
                window: 10,
            }) => assert_eq!(best, 0.25),
            other => panic!("{other:?}"),
        }
        // A restart forgets it all, the window kept.
        progress.restart();
        for k in 0..10 {
            progress.observe(k, 1.0).unwrap();
        }
        assert!(progress.observe(10, 1.0).is_err());
    }

    #[test]
    fn the_message_says_the_residual_stopped_decreasing() {
        let text = SolveError::Stagnated {
            iterations: 1234,
            best: 3.1e-5,
            window: 1000,
        }
        .to_string();
        assert_eq!(
            text,
            "no convergence: the residual stopped decreasing (not halved in the last 1000 of \
             1234 iterations, best 3.100e-5); the solve was given up before its iteration limit"
        );
        let text = SolveError::Stagnated {
            iterations: 1100,
            best: 2e-16,
            window: 1000,
        }
        .to_string();
        assert!(
            text.contains("best 2.000e-16: near the rounding floor, ask for a larger tolerance)"),
            "{text}"
        );
    }
}
