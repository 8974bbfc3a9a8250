//! The full-contact threshold of a surface, for front ends that check a whole load sweep
//! before solving any of it.
//!
//! [`ContactSolver::solve`] refuses a load or indentation that closes the gap everywhere
//! ([`SolveError::BeyondFullContact`]); on free boundaries it finds out only by solving.
//! [`ContactSolver::full_contact_threshold`] gives the threshold up front (the values the
//! solver's refusal states, cached per surface), and
//! [`ContactSolver::full_contact_lower_bound`] bounds below it that cost two operator
//! applications, so that the threshold need only be computed for loads above the bounds.
//!
//! **The bounds** (free boundaries). In full contact `u = K p = d − f` on every pixel, with
//! `p ≥ 0`. The kernel is positive, so `u ≥ 0` and `d ≥ max f`. And, `K` being symmetric,
//! `Σ v u = Σ p (K v) ≤ Σ p · max(K v)` for any weights `v`, so the mean pressure is at least
//! `Σ v u / (N max K v)`, with `Σ v u ≥ Σ v (max f − f)` for `v ≥ 0` and `Σ v u = −Σ v f`
//! for `Σ v = 0` (`d` drops out). Two weightings are used and the larger bound kept:
//! `v = max f − f` (the deep pixels, which need the most pressure) and the discrete
//! Laplacian `v = ∇²f` (zero flux at the edges, so `Σ v = 0`; it weighs the slopes, which
//! set the pressure of full contact). On self-affine surfaces the bound is a few percent of
//! the threshold (about 0.12 E*·h′ for an rms slope h′, measured: 512², H = 0.8, roll-off 6).
//!
//! The periodic threshold and the bounds work in fields of their own
//! ([`FullContactScratch`]); the free threshold in the stiffness CG's
//! ([`super::stiffness`]). None of them touches the solved state or another iteration's
//! fields.

use super::solver::ContactSolver;
use super::threshold::{FullContactScratch, FullContactThreshold};
use super::SolveError;
use crate::elastic::Boundary;
use crate::elastic::ContactOperator;

/// The weightings of the lower bound (module docs).
#[derive(Debug, Clone, Copy)]
enum Weights {
    Depth,
    Laplacian,
}

impl<K: ContactOperator> ContactSolver<K> {
    /// Where a periodic surface comes into full contact. Mean pressure: with `K p = d − f`
    /// everywhere, `p = p̄ − K⁺f`, non-negative iff `p̄ ≥ max(K⁺f)` (Westergaard's
    /// `p* = π E* Δ / λ` for a sinusoid). Indentation: `K p` has zero mean, so
    /// `d = mean(f) = max(h) − mean(h)`; below it some gap stays open (`d` is the mean of
    /// `u + f` on the contact set and `u + f ≥ d` elsewhere). Computed once per surface, in
    /// the full-contact fields.
    pub(super) fn periodic_full_contact(&mut self) -> FullContactThreshold {
        if let Some(full) = self
            .cx
            .state
            .full_contact
            .filter(|f| f.indentation.is_some())
        {
            return full;
        }
        let len = self.cx.problem.profile.len();
        let scratch = FullContactScratch::lend(&mut self.full_contact_scratch, len, false);
        if self
            .cx
            .problem
            .operator
            .apply_pseudo_inverse(&self.cx.problem.profile, &mut scratch.weights)
            .is_err()
        {
            // Free boundaries have no spectral inverse (callers check the boundary).
            return FullContactThreshold {
                mean_pressure: f64::INFINITY,
                indentation: None,
            };
        }
        let mean_pressure = scratch.weights.iter().fold(0.0f64, |m, &v| m.max(v));
        let indentation =
            self.cx.problem.profile.iter().sum::<f64>() / self.cx.problem.profile.len() as f64;
        let full = FullContactThreshold {
            mean_pressure,
            indentation: Some(indentation),
        };
        self.cx.state.full_contact = Some(full);
        full
    }

    /// The full-contact threshold of the surface: the values that
    /// [`SolveError::BeyondFullContact`] states. Periodic boundaries: `max(K⁺f)`, one
    /// spectral pseudo-inverse, and the indentation `max(h) − mean(h)`. Free boundaries:
    /// two preconditioned conjugate-gradient solves on the full grid, computed once per
    /// surface. Either way the last solved state and its warm start are kept.
    pub fn full_contact_threshold(&mut self) -> Result<FullContactThreshold, SolveError> {
        match self.cx.problem.operator.boundary() {
            Boundary::Periodic => Ok(self.periodic_full_contact()),
            // Two CG solves: on a worker of the pool, as the solves (`pool.rs`).
            Boundary::Free => {
                crate::pool::on_worker(self.cx.params.parallelism, || self.free_full_contact())
            }
        }
    }

    /// Cheap bounds below the full-contact threshold; loads below them are never beyond
    /// full contact. Periodic boundaries: the threshold itself (one pseudo-inverse).
    /// Free boundaries: the mean-pressure bound of the module docs (two operator
    /// applications) and `max f` (the depth of the deepest point) for the indentation.
    /// Works in the full-contact fields only: the last solved state is kept.
    pub fn full_contact_lower_bound(&mut self) -> Result<FullContactThreshold, SolveError> {
        if self.cx.problem.operator.boundary() == Boundary::Periodic {
            return self.full_contact_threshold();
        }
        let n = self.cx.problem.profile.len() as f64;
        let deepest = self
            .cx
            .problem
            .profile
            .iter()
            .fold(0.0f64, |m, &f| m.max(f));
        let scratch = FullContactScratch::lend(&mut self.full_contact_scratch, n as usize, true);
        let problem = &mut self.cx.problem;
        let mut bound = 0.0f64;
        for weights in [Weights::Depth, Weights::Laplacian] {
            let grid = (problem.rows, problem.cols);
            fill_weights(
                weights,
                deepest,
                grid,
                &problem.profile,
                &mut scratch.weights,
            );
            let weighted = scratch.weights.iter().zip(&problem.profile);
            let numerator: f64 = match weights {
                Weights::Depth => weighted.map(|(v, f)| v * (deepest - f)).sum(),
                Weights::Laplacian => -weighted.map(|(v, f)| v * f).sum::<f64>(),
            };
            problem
                .operator
                .apply(&scratch.weights, &mut scratch.response);
            let largest = scratch.response.iter().fold(0.0f64, |m, &v| m.max(v));
            let candidate = numerator / (n * largest);
            if largest > 0.0 && candidate.is_finite() {
                bound = bound.max(candidate);
            }
        }
        Ok(FullContactThreshold {
            // Rounding of the sums and of the operator: a margin far below the bound's slack.
            mean_pressure: bound * (1.0 - 1e-9),
            indentation: Some(deepest),
        })
    }
}

/// Writes the weights `v` of the lower bound for the profile `f` on a `(rows, cols)` grid.
fn fill_weights(
    weights: Weights,
    deepest: f64,
    (rows, cols): (usize, usize),
    f: &[f64],
    v: &mut [f64],
) {
    match weights {
        Weights::Depth => v.iter_mut().zip(f).for_each(|(v, f)| *v = deepest - f),
        Weights::Laplacian => {
            for r in 0..rows {
                for c in 0..cols {
                    let i = r * cols + c;
                    let neighbours = [
                        (r > 0).then(|| i - cols),
                        (r + 1 < rows).then(|| i + cols),
                        (c > 0).then(|| i - 1),
                        (c + 1 < cols).then(|| i + 1),
                    ];
                    v[i] = neighbours.iter().flatten().map(|&j| f[j] - f[i]).sum();
                }
            }
            // Zero to rounding already (each pair cancels); exactly zero-sum now.
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            v.iter_mut().for_each(|x| *x -= mean);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Control, HalfSpace, SolverParams};
    use super::*;
    use crate::bem::iterations::polonsky_keer::tests::{rough, rough_grid, sphere};

    fn solver(surface: &crate::surface::Surface, boundary: Boundary) -> ContactSolver {
        let half_space = HalfSpace {
            modulus: 1.3,
            boundary,
        };
        ContactSolver::new(surface, half_space, SolverParams::default()).unwrap()
    }

    /// The threshold is what the solver refuses with, and the bounds lie below it.
    #[test]
    fn threshold_matches_the_refusal_and_bounds_lie_below() {
        for (boundary, surface) in [
            (Boundary::Free, rough(32, 1)),
            (Boundary::Free, rough_grid(24, 40, 2)),
            (Boundary::Free, sphere(33, 33, 1.0, 0.5)),
            (Boundary::Periodic, rough(32, 3)),
            (Boundary::Periodic, rough_grid(24, 40, 4)),
        ] {
            let mut s = solver(&surface, boundary);
            let bound = s.full_contact_lower_bound().unwrap();
            let threshold = s.full_contact_threshold().unwrap();
            assert!(
                bound.mean_pressure > 0.0 && bound.mean_pressure <= threshold.mean_pressure,
                "{boundary:?}: {bound:?} vs {threshold:?}"
            );
            match (bound.indentation, threshold.indentation) {
                (Some(b), Some(t)) => assert!(b > 0.0 && b <= t, "{b} vs {t}"),
                other => panic!("{other:?}"),
            }
            // A fresh solver refuses 10 × the threshold stating the same threshold.
            let mut fresh = solver(&surface, boundary);
            let requested = Control::Force(10.0 * threshold.mean_pressure * s.nominal_area());
            match fresh.solve(requested) {
                Err(SolveError::BeyondFullContact {
                    full_contact: Some(t),
                    ..
                }) => {
                    let want = threshold.in_units_of(requested, s.nominal_area()).unwrap();
                    assert!((t / want - 1.0).abs() < 1e-12, "{t} vs {want}");
                }
                other => panic!("{boundary:?}: {other:?}"),
            }
            // Below the threshold the contact is partial.
            let (below, _) = s
                .solve(Control::MeanPressure(0.9 * threshold.mean_pressure))
                .unwrap();
            assert!(below.area_fraction < 1.0);
        }
    }

    /// Asked for before the first solve, neither changes any result (bit for bit); after a
    /// solve both keep the state (the free threshold works in fields of its own).
    #[test]
    fn asking_first_changes_nothing() {
        let surface = rough(40, 5);
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let loads = [1e-3, 4e-3, 1e-2].map(Control::MeanPressure);
            let run = |ask: bool| {
                let mut s = solver(&surface, boundary);
                if ask {
                    s.full_contact_lower_bound().unwrap();
                    s.full_contact_threshold().unwrap();
                }
                loads
                    .iter()
                    .map(|&c| {
                        let (summary, info) = s.solve(c).unwrap();
                        (summary, info.iterations, s.pressure().to_owned())
                    })
                    .collect::<Vec<_>>()
            };
            assert_eq!(run(false), run(true), "{boundary:?}");
            let mut s = solver(&surface, boundary);
            s.solve(loads[0]).unwrap();
            s.full_contact_lower_bound().unwrap();
            assert!(s.summary().is_some());
            let kept = (s.summary(), s.pressure().to_owned(), s.gap().to_owned());
            s.full_contact_threshold().unwrap();
            assert_eq!(
                (s.summary(), s.pressure().to_owned(), s.gap().to_owned()),
                kept,
                "{boundary:?}"
            );
        }
    }

    /// Issue 33 item 15: heights ×1e-200 on a free boundary gave a threshold of 0 (the
    /// CG's sums of f² underflowed), printed in the refusal as "from a mean pressure of
    /// 0.000000e0"; the threshold scales with the heights like the periodic one.
    #[test]
    fn the_free_threshold_of_tiny_or_huge_heights_scales_with_them() {
        let surface = rough(32, 1);
        let mut s = solver(&surface, Boundary::Free);
        let unit = s.full_contact_threshold().unwrap();
        for factor in [1e-200, 1e-120, 1e120, 1e200] {
            let heights = surface.heights().mapv(|h| h * factor);
            let scaled = crate::surface::Surface::new(heights, surface.size()).unwrap();
            let got = solver(&scaled, Boundary::Free)
                .full_contact_threshold()
                .unwrap();
            let (p, d) = (
                got.mean_pressure / factor,
                got.indentation.unwrap() / factor,
            );
            let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-9;
            assert!(
                close(p, unit.mean_pressure),
                "×{factor}: {got:?} vs {unit:?}"
            );
            assert!(close(d, unit.indentation.unwrap()), "×{factor}: {got:?}");
        }
    }
}
