//! [`Iteration`]: the seam between the solver core and an algorithm that solves the contact
//! problem.
//!
//! An iteration is a struct of its own fields (its scratch) in a file of its own, and
//! implements [`Iteration::solve`] over a [`Context`] (`context.rs`: the problem, the
//! settings, the state of the last solve, the preconditioner, the stop flag and the contact
//! law). The solver ([`super::ContactSolver`], `solver.rs`) owns one context and each
//! iteration's fields, and lends the context to the iteration it runs:
//!
//! * before [`Iteration::solve`] the solver has set the initial pressure in
//!   `cx.state.pressure` (warm, predicted along the frozen-set tangent, or cold:
//!   `ContactSolver::initialise`), so that every iteration starts the same way;
//! * the iteration iterates in its own fields and `cx.state` (pressure; `u`, then the gap,
//!   in `cx.state.gap`), asks `cx.interface` what "in contact" means, polls
//!   [`Context::check_stop`] once per iteration, and ends with [`Context::finish`] (the
//!   summary of the converged state) or a typed [`SolveError`];
//! * what the solver does around a solve — validation, refusals beyond full contact, the
//!   root search of a capped load (`capped_load.rs`), the stiffness and thresholds of the
//!   solved state — applies to every iteration unchanged.
//!
//! The iterations today, each in this folder: the BCCG (`bccg.rs`, with its direct solve of
//! small sets, `bccg/small_set.rs`, and the coarse correction of periodic displacement
//! control, `bccg/mean_gap.rs`) and Polonsky–Keer's constrained conjugate gradients
//! (`polonsky_keer.rs`).
//! A new one (an adhesive iteration, say) is a new file with `struct AdhesiveScratch` and
//! `impl Iteration for AdhesiveScratch`, which `ContactSolver::solve_with(control, &mut
//! scratch)` runs with no edit of the core (the caller owns its fields); to make it a
//! choice of [`super::SolverParams`] as well, two lines name it: a [`super::SolverKind`]
//! variant and its arm in `ContactSolver::iteration` (with its field in the solver,
//! allocated on first use).

pub(super) mod bccg;
pub(super) mod polonsky_keer;

pub(super) use bccg::{small_set, BccgScratch, RING_MIN_POINTS};
pub(super) use polonsky_keer::PkScratch;

use super::context::{Context, Target};
use super::{ContactSummary, SolveError, SolveInfo};
use crate::elastic::ContactOperator;

/// When an iteration stops: at a residual (the module docs of [`crate::bem`]) below
/// `tolerance`, or with [`SolveError::NoConvergence`] after `max_iterations`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Limits {
    /// The residual at which the state is solved; > 0.
    pub(super) tolerance: f64,
    /// Iterations before [`SolveError::NoConvergence`]; ≥ 1.
    pub(super) max_iterations: usize,
}

/// An algorithm that solves the contact problem of a [`Context`] (module docs) on the body
/// of `K` (monomorphised: no dynamic dispatch inside a solve). `Send`: a solve runs on a
/// worker of the thread pool.
pub(super) trait Iteration<K: ContactOperator>: Send {
    /// Solves for `target` within `limits` from the initial pressure in `cx.state`; on
    /// success `cx.state` holds the solved pressure and gap and the summary comes from
    /// [`Context::finish`]. Allocates nothing once its fields exist.
    fn solve(
        &mut self,
        cx: &mut Context<K>,
        target: Target,
        limits: Limits,
    ) -> Result<(ContactSummary, SolveInfo), SolveError>;

    /// Whether its last solve stopped because, under a cap and load control, its load
    /// restorations were cycling (`capped_load.rs` then finds the load by displacement
    /// control and finishes from there). False for an iteration that never stalls.
    fn stalled(&self) -> bool {
        false
    }

    /// Operator applications (FFT pairs) per iteration, for the accounting of a stalled
    /// part of a solve whose error carries only its iterations: one by default (the BCCG).
    fn applications_per_iteration(&self) -> usize {
        1
    }
}
