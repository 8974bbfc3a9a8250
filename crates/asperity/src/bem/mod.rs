//! 3D boundary-element contact of a rigid rough indenter on an elastic half-space
//! (the paper, *Methods*, "BEM calculations"; Pohrt & Popov, Sci. Rep. 3, 3293, 2013).
//!
//! * **Problem**: a [`Surface`](crate::surface::Surface) (heights positive up) is pressed
//!   into a half-space of effective modulus E* with [`Boundary::Free`] or
//!   [`Boundary::Periodic`] boundaries ([`HalfSpace`]); frictionless and non-adhesive. The
//!   indenter's profile is `f = max(h) − h ≥ 0`, so the indentation `d` is measured from the
//!   highest point (first contact at `d = 0`). With the elastic displacement `u = K p`
//!   (positive down) the gap is `g = u + f − d`, and the solution satisfies
//!   `p ≥ 0, g ≥ 0, p·g = 0` with either the mean pressure (load control) or `d`
//!   (displacement control) prescribed ([`Control`]). A periodic half-space fixes
//!   displacements only up to a constant: there `u` has zero mean (the `q = 0` mode of the
//!   kernel is zero), so `d` is the approach of the highest point relative to the mean
//!   elastic displacement, the same under load and displacement control; full contact
//!   comes at `d = mean(f) = max(h) − mean(h)`.
//! * **Solver**: [`ContactSolver`] on the FFT operator of [`crate::elastic`], by default a
//!   Fourier-preconditioned bound-constrained conjugate gradient without restart
//!   ([`SolverKind::Bccg`], `bccg.rs`: Bugnicourt et al., Tribol. Lett. 66:29, 2018, with
//!   Vollebregt's preconditioner, J. Comput. Phys. 257A, 2014); Polonsky & Keer's constrained
//!   conjugate gradients (Wear 231, 206–219, 1999; [`SolverKind::PolonskyKeer`],
//!   `polonsky_keer.rs`) stay selectable as the reference. The solver owns the operator, its
//!   plans and every buffer, so one solver serves many loads, and it starts each solve from
//!   the previous pressure (warm start), moved along the tangent `dp/dd` to the new load
//!   when the frozen-set stiffness of the previous state computed it (`stiffness/`). Periodic displacement control is a direct solve
//!   with the indentation (equivalently the mean gap `mean(f) − d`) fixed: the BCCG
//!   preconditions the constant mode, which the periodic kernel does not see, by its exact
//!   curvature on the free set (`mean_gap.rs`); Polonsky–Keer runs its own iteration with `d`
//!   fixed (slow near full contact, but it converges: it is the reference).
//! * **Contact law**: [`Interface`] is the one place that knows what "in contact" means
//!   (`interface.rs`): [`Interface::HardWall`] (the above, the default) or
//!   [`Interface::Hardness`], the pressure capped at a hardness `H` (elastic–perfectly-plastic
//!   contact, solved by Polonsky–Keer; its plastic displacement and the loading–unloading
//!   [`load_path`] in `plasticity.rs`, docs/hardness.md). Set by
//!   [`ContactSolver::set_interface`].
//! * **Stopping**: [`ContactSolver::with_stop`] hands the solver a [`crate::stop::Stop`]
//!   flag, which every iteration (BCCG, Polonsky–Keer, the
//!   frozen-set and full-contact CGs) polls; a requested stop ends the solve with
//!   [`SolveError::Interrupted`] within one iteration.
//! * **Stiffness**: [`ContactSolver::frozen_set_stiffness`] — the paper's method: keep the
//!   contact set, impose a uniform `Δd` on it, solve the linear SPD problem for the pressures
//!   on the set (conjugate gradients with the Fourier preconditioner of the solver), `k = ΔF/Δd`; and
//!   [`ContactSolver::finite_difference_stiffness`], `dF/dd` from two more solves. Barber's
//!   theorem makes the two agree.
//!
//! ## Convergence measure
//! The residual of a state is the rms violation of the contact conditions, measured on the
//! contact set and normalised by the rms height `h_rms` of the surface:
//! `residual = sqrt[(Σ_{p>0} g² + Σ_{p=0} min(g, 0)²) / n_c] / h_rms`, where `n_c` counts the
//! points in contact. It is zero exactly when the state solves the problem. The solver stops
//! when `residual < tolerance` and fails with [`SolveError::NoConvergence`] at its iteration
//! limit, or earlier with [`SolveError::Stagnated`] where the residual has stopped
//! decreasing (`stagnation.rs`).

pub mod adhesion;
mod capped_load;
pub mod conductance;
mod context;
mod full_contact;
mod grid_pass;
mod interface;
#[cfg(test)]
mod interruption;
mod iterations;
mod plastic_field;
mod plasticity;
mod precondition;
mod solver;
mod stagnation;
mod stiffness;
pub mod sweep;
pub mod tangential;
#[cfg(test)]
mod tests;
mod threshold;

pub use context::{ContactProblem, Monitor};
pub use interface::Interface;
pub use plasticity::{load_path, PathPoint};
pub use solver::ContactSolver;
pub use threshold::FullContactThreshold;

use ndarray::Array2;

use crate::elastic::Boundary;

/// The elastic body: effective modulus and boundary conditions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfSpace {
    /// Effective modulus E*, `1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂`.
    pub modulus: f64,
    /// Free (zero-padded, the paper's choice) or periodic boundaries.
    pub boundary: Boundary,
}

impl Default for HalfSpace {
    /// E* = 1, free boundaries (the paper's setting).
    fn default() -> Self {
        HalfSpace {
            modulus: 1.0,
            boundary: Boundary::Free,
        }
    }
}

/// What is prescribed in a solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Control {
    /// Load control: the mean pressure over the nominal area `rows·cols·Δ²` (> 0).
    MeanPressure(f64),
    /// Load control: the total force (> 0).
    Force(f64),
    /// Displacement control: the indentation `d` (≥ 0) of the highest point of the surface.
    /// Free boundaries: from first contact, the displacements vanishing far away; periodic:
    /// relative to the mean elastic displacement (zero-mean convention, as the indentation
    /// that load control reports), below full contact at `max(h) − mean(h)`.
    Indentation(f64),
}

impl Control {
    /// The prescribed quantity as messages name it: `force`, `mean pressure` or
    /// `indentation`.
    pub fn quantity(&self) -> &'static str {
        match self {
            Control::MeanPressure(_) => "mean pressure",
            Control::Force(_) => "force",
            Control::Indentation(_) => "indentation",
        }
    }

    /// The prescribed value.
    pub fn value(&self) -> f64 {
        match *self {
            Control::MeanPressure(v) | Control::Force(v) | Control::Indentation(v) => v,
        }
    }
}

/// The iteration that solves the contact problem.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum SolverKind {
    /// Fourier-preconditioned bound-constrained conjugate gradients without restart
    /// (Bugnicourt et al. 2018 with Vollebregt's 2014 preconditioner; `bccg.rs`): one
    /// operator application per iteration where no pressure is cut, tens of iterations.
    /// The default.
    #[default]
    Bccg,
    /// Polonsky & Keer's constrained conjugate gradients (Wear 231, 1999): two operator
    /// applications per iteration, a restart whenever the contact set grows; under
    /// displacement control with `d` fixed on either boundary. The reference.
    PolonskyKeer,
}

impl SolverKind {
    /// `"bccg"` or `"pk"`, as the command line names them.
    pub fn name(&self) -> &'static str {
        match self {
            SolverKind::Bccg => "bccg",
            SolverKind::PolonskyKeer => "pk",
        }
    }
}

impl std::str::FromStr for SolverKind {
    type Err = crate::Error;

    /// Parses `bccg` or `pk` (also `polonsky-keer`).
    fn from_str(s: &str) -> crate::Result<Self> {
        match s {
            "bccg" => Ok(SolverKind::Bccg),
            "pk" | "polonsky-keer" => Ok(SolverKind::PolonskyKeer),
            other => Err(crate::Error::invalid(
                "solver",
                format!("must be bccg or pk, got {other:?}"),
            )),
        }
    }
}

/// How a solve shares the threads of the rayon pool it runs on. The numbers do not depend
/// on it (nor on the number of threads); the time does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Parallelism {
    /// The solve has the pool to itself, as when solves run one at a time (the CLI's `bem`
    /// and `contact`, the Python package): while it runs, the pool's other threads wait for
    /// its parallel passes awake instead of sleeping between them. Measured at 256² on 2
    /// threads, 14–21 % off a solve (`pool.rs`). Solves started at the same time from
    /// several threads fall back to [`Parallelism::Shared`].
    #[default]
    Exclusive,
    /// The pool runs other work beside the solve (a study's lanes, each solving its own
    /// sample): idle threads sleep as rayon's do, so that they take up that work.
    Shared,
}

/// Parameters of the contact solver (validated by [`ContactSolver::new`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverParams {
    /// The iteration ([`SolverKind::Bccg`] by default).
    pub solver: SolverKind,
    /// Stop when the residual (see the module docs) is below this; > 0.
    pub tolerance: f64,
    /// Iterations before [`SolveError::NoConvergence`]; ≥ 1.
    pub max_iterations: usize,
    /// Relative residual `‖K_SS x − 1‖/‖1‖` at which the frozen-set CG stops (and the CGs
    /// of the full-contact threshold); > 0.
    pub stiffness_tolerance: f64,
    /// Estimated relative error of the frozen-set stiffness `k = 1ᵀx` at which its CG
    /// stops if the residual has not stopped it yet (the decrease of the CG's energy error
    /// over its last iterations, see `stiffness/`); ≥ 0, 0 for the residual only.
    pub stiffness_error: f64,
    /// Iterations of the frozen-set CG before [`SolveError::NoConvergence`]; ≥ 1.
    pub stiffness_max_iterations: usize,
    /// How the solves share the thread pool ([`Parallelism::Exclusive`] by default).
    pub parallelism: Parallelism,
}

impl Default for SolverParams {
    /// The BCCG solver, `tolerance = 1e-8` (gaps on the contact set below 1e-8 rms
    /// heights), at most 10 000 iterations; frozen-set CG until `k` is known to `1e-12`
    /// (estimated relative error) or to `1e-10` relative residual, in at most 10 000
    /// iterations. The stiffness is then far more precise than the contact set it belongs
    /// to: a solve to `1e-8` may leave a point of pressure `~1e-8` in or out, which moves
    /// `k` by up to `~1e-7` (measured at 128²). [`Parallelism::Exclusive`].
    fn default() -> Self {
        SolverParams {
            solver: SolverKind::Bccg,
            tolerance: 1e-8,
            max_iterations: 10_000,
            stiffness_tolerance: 1e-10,
            stiffness_error: 1e-12,
            stiffness_max_iterations: 10_000,
            parallelism: Parallelism::Exclusive,
        }
    }
}

impl SolverParams {
    /// Checks the parameters: tolerances positive and finite, iteration limits at least 1.
    /// [`ContactSolver::new`] and [`ContactSolver::set_params`] call it; a front end can call
    /// it before any work.
    pub fn validate(&self) -> crate::Result<()> {
        let positive = |name: &'static str, v: f64| {
            if crate::is_positive_finite(v) {
                Ok(())
            } else {
                Err(crate::Error::invalid(
                    name,
                    format!(
                        "must be positive and finite, got {}",
                        crate::input::short_number(v)
                    ),
                ))
            }
        };
        positive("tolerance", self.tolerance)?;
        positive("stiffness tolerance", self.stiffness_tolerance)?;
        if !(self.stiffness_error >= 0.0 && self.stiffness_error.is_finite()) {
            return Err(crate::Error::invalid(
                "stiffness error",
                format!(
                    "must be zero or positive and finite, got {}",
                    crate::input::short_number(self.stiffness_error)
                ),
            ));
        }
        for (name, v) in [
            ("max iterations", self.max_iterations),
            ("stiffness max iterations", self.stiffness_max_iterations),
        ] {
            if v == 0 {
                return Err(crate::Error::invalid(name, "must be at least 1, got 0"));
            }
        }
        Ok(())
    }
}

/// How a solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveInfo {
    /// Iterations (BCCG or Polonsky–Keer steps, or CG steps for the stiffness).
    pub iterations: usize,
    /// Final residual (see the module docs; relative CG residual for the stiffness).
    pub residual: f64,
    /// Applications of the elastic operator (padded FFT pairs on free boundaries): with
    /// `energy_transforms`, the cost of the solve; the preconditioner's unpadded
    /// transforms are not counted. The BCCG makes some in single precision (about 0.7 of
    /// the cost; `bccg.rs`), counted here alike.
    pub operator_applications: usize,
    /// Forward transforms of the operator alone, each about half an application: quadratic
    /// forms `sᵀK s` ([`crate::elastic::ElasticOperator::energy`]) where `K s` itself is
    /// not needed.
    pub energy_transforms: usize,
}

/// The scalar results of a solved contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSummary {
    /// Mean pressure over the nominal area.
    pub mean_pressure: f64,
    /// Total force `Σ p Δ²`.
    pub force: f64,
    /// Indentation `d` of the highest point of the surface (periodic: relative to the mean
    /// elastic displacement, see [`Control::Indentation`]).
    pub indentation: f64,
    /// Fraction of grid points in contact (`p > 0`).
    pub area_fraction: f64,
    /// Number of grid points in contact.
    pub contact_points: usize,
    /// Fraction of grid points at the hardness (`p = H`, [`Interface::Hardness`]; zero for
    /// the hard wall).
    pub plastic_fraction: f64,
    /// Number of grid points at the hardness.
    pub plastic_points: usize,
}

/// A solved contact with its fields (`rows × cols`, row-major like the surface).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactState {
    /// The scalar results.
    pub summary: ContactSummary,
    /// Contact pressure, ≥ 0.
    pub pressure: Array2<f64>,
    /// Gap `u + f − d`, ≥ 0 (zero on the contact set).
    pub gap: Array2<f64>,
    /// Elastic surface displacement `u = K p`, positive into the half-space.
    pub displacement: Array2<f64>,
}

/// Why a contact solve failed.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    /// Bad input (parameters, surface, memory).
    #[error(transparent)]
    Input(#[from] crate::Error),
    /// The iteration did not reach the tolerance.
    #[error("{}", no_convergence_message(*iterations, *residual))]
    NoConvergence {
        /// Iterations done.
        iterations: usize,
        /// Residual reached.
        residual: f64,
    },
    /// The residual stopped decreasing: its best value has not halved in the last `window`
    /// iterations, so the solve was given up before its iteration limit (a cycling contact
    /// set, the rounding floor under a tolerance far below `1e-14`, a problem hopeless for
    /// its grid; `stagnation.rs`).
    #[error("{}", stagnation_message(*iterations, *best, *window))]
    Stagnated {
        /// Iterations done.
        iterations: usize,
        /// The best residual reached.
        best: f64,
        /// Iterations without a halving of the best residual.
        window: usize,
    },
    /// A stop was requested through the solver's [`crate::stop::Stop`] (checked once per
    /// iteration of every solver loop). The solver forgets its unfinished state: the next
    /// solve starts cold, as after [`ContactSolver::reset`].
    #[error("interrupted after {iterations} iterations")]
    Interrupted {
        /// Iterations done before the stop.
        iterations: usize,
    },
    /// The load or indentation closes the gap everywhere: no contact problem is left to
    /// solve. The message names the quantity that was given (force, mean pressure or
    /// indentation) and the threshold in that quantity.
    #[error("{}", beyond_full_contact_message(requested, *full_contact))]
    BeyondFullContact {
        /// What was asked for, as given.
        requested: Control,
        /// The threshold in the same quantity as `requested` from which the gap is closed
        /// everywhere, where known: the free-boundary indentation `d* = max(K⁻¹f / K⁻¹1)`
        /// and the load it carries, or the periodic full-contact mean pressure `max(K⁺f)`
        /// (times the nominal area for a force) and indentation `mean(f) = max(h) − mean(h)`.
        full_contact: Option<f64>,
    },
}

/// `no convergence after 12 iterations (residual 3.2e-4)`; a residual that is not a
/// number says the solve broke down, which more iterations would not mend.
fn no_convergence_message(iterations: usize, residual: f64) -> String {
    if residual.is_finite() {
        return format!("no convergence after {iterations} iterations (residual {residual:.3e})");
    }
    let when = match iterations {
        0 => "before its first iteration".to_string(),
        1 => "in its first iteration".to_string(),
        n => format!("after {n} iterations"),
    };
    format!(
        "the solve broke down {when}: its residual is not a finite number (heights, loads \
         or modulus too large or too small for floating-point arithmetic: give them in \
         other units)"
    )
}

/// `no convergence: the residual stopped decreasing (not halved in the last 1000 of 1234
/// iterations, best 3.100e-5); …`, with advice where the best is at the rounding floor.
fn stagnation_message(iterations: usize, best: f64, window: usize) -> String {
    let floor = if best < 1e-12 {
        ": near the rounding floor, ask for a larger tolerance"
    } else {
        ""
    };
    format!(
        "no convergence: the residual stopped decreasing (not halved in the last {window} of \
         {iterations} iterations, best {best:.3e}{floor}); the solve was given up before its \
         iteration limit"
    )
}

fn beyond_full_contact_message(requested: &Control, full_contact: Option<f64>) -> String {
    let quantity = requested.quantity();
    let threshold = match full_contact {
        // A flat surface (every height the same): "from 0" read as a value lost.
        Some(0.0) => {
            format!(" (the surface is flat: any {quantity} closes the gap everywhere)")
        }
        Some(t) => {
            let article = if quantity.starts_with('i') { "an" } else { "a" };
            format!(" (the gap closes everywhere from {article} {quantity} of {t:.6e})")
        }
        None => String::new(),
    };
    format!(
        "{quantity} {:.6e} is beyond full contact{threshold}",
        requested.value()
    )
}

#[cfg(test)]
mod message_tests {
    use super::*;

    /// Issue 33 item 15: "no convergence after 0 iterations (residual NaN)" told the user
    /// to iterate more; a residual that is not a number is a breakdown, said as one.
    #[test]
    fn a_solve_that_broke_down_says_so() {
        let text = SolveError::NoConvergence {
            iterations: 0,
            residual: f64::NAN,
        }
        .to_string();
        assert!(
            !text.contains("NaN") && !text.contains("after 0 iterations"),
            "{text}"
        );
        assert!(
            text.contains("broke down before its first iteration"),
            "{text}"
        );
        let text = SolveError::NoConvergence {
            iterations: 12,
            residual: 3.2e-4,
        }
        .to_string();
        assert_eq!(
            text,
            "no convergence after 12 iterations (residual 3.200e-4)"
        );
    }

    /// Issue 33 item 15: a flat surface's full-contact threshold was printed as a value,
    /// "from a mean pressure of 0.000000e0"; it is said to be flat.
    #[test]
    fn a_flat_surface_beyond_full_contact_is_said_to_be_flat() {
        let text = SolveError::BeyondFullContact {
            requested: Control::MeanPressure(0.01),
            full_contact: Some(0.0),
        }
        .to_string();
        assert_eq!(
            text,
            "mean pressure 1.000000e-2 is beyond full contact (the surface is flat: any mean \
             pressure closes the gap everywhere)"
        );
    }
}
