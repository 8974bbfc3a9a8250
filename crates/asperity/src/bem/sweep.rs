//! A load sweep on one [`ContactSolver`]: the loop that `asperity bem` and Python's
//! `Solver.sweep` both run, so that the two give the same numbers bit for bit.
//!
//! 1. **Full contact, before any solve** ([`check_full_contact`]): the largest load of each
//!    kind (and, with a finite-difference step, its upper step) must lie below full contact.
//!    The cheap lower bound (`full_contact.rs`) clears most sweeps; the threshold itself
//!    (periodic: one FFT pair; free: about one solve) is computed only where it does not.
//! 2. **Per load, in the given order** (each solve warm-starts from the state left by the
//!    previous load): the solve; the frozen-set stiffness; [`SweepObserver::solved`], where
//!    a front end takes the fields; with [`SweepParams::tangential`] the tangential
//!    (no-slip) stiffnesses `k_x`, `k_y` of the same frozen set (Cerruti's operators
//!    planned once per sweep, [`TangentialStiffness`]) just before that hook; then, with [`SweepParams::fd_step`], `dF/dd` from two
//!    solves at the load × (1 ± step) (none at indentation 0), after which the load is solved
//!    again (warm, from the upper step) so that the next load warm-starts from it, except
//!    after the last load; finally [`SweepObserver::finished`] with the load's row.
//!
//! A front end stops the sweep by returning an error from either hook (progress bars,
//! cancellation between loads); inside a solve, the solver's [`crate::stop::Stop`] flag
//! ends it within an iteration.

use std::time::Instant;

use super::tangential::{Along, Directions, TangentialStiffness};
use super::{ContactSolver, ContactSummary, Control, SolveError, SolveInfo};
use crate::Error;

/// What a sweep computes besides the solves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepParams {
    /// The frozen-set stiffness of every load.
    pub stiffness: bool,
    /// Relative step of the finite-difference stiffness `dF/dd` (in `(0, 1)`), or none.
    pub fd_step: Option<f64>,
    /// Poisson's ratio (in `[0, 0.5]`) of the tangential (no-slip) frozen-set stiffnesses
    /// `k_x`, `k_y` of every load ([`TangentialStiffness`]), or none.
    pub tangential: Option<f64>,
    /// Which of `k_x`, `k_y` (with [`SweepParams::tangential`]): both by default, one for
    /// about half the cost ([`Directions`]).
    pub directions: Directions,
}

impl Default for SweepParams {
    /// The frozen-set stiffness, no finite differences, no tangential stiffness.
    fn default() -> Self {
        SweepParams {
            stiffness: true,
            fd_step: None,
            tangential: None,
            directions: Directions::Both,
        }
    }
}

impl SweepParams {
    /// Checks the finite-difference step (in `(0, 1)`) and the Poisson's ratio.
    pub fn validate(&self) -> crate::Result<()> {
        if let Some(poisson) = self.tangential {
            crate::mdr::check_poisson(poisson)?;
        }
        match self.fd_step {
            Some(step) if !(step > 0.0 && step < 1.0) => Err(Error::invalid(
                "relative step",
                format!(
                    "must lie in (0, 1), got {}",
                    crate::input::short_number(step)
                ),
            )),
            _ => Ok(()),
        }
    }
}

/// The results of one load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepRow {
    /// What was prescribed.
    pub control: Control,
    /// The solved contact's scalars.
    pub summary: ContactSummary,
    /// Iterations and residual of the solve.
    pub info: SolveInfo,
    /// Frozen-set stiffness, when asked for.
    pub stiffness: Option<f64>,
    /// Finite-difference `dF/dd`, when asked for (none at indentation 0).
    pub stiffness_fd: Option<f64>,
    /// Wall-clock seconds of the solve.
    pub solve_seconds: f64,
    /// Wall-clock seconds of the frozen-set stiffness (about 0 when not asked for).
    pub stiffness_seconds: f64,
    /// The tangential stiffnesses `k_x`, `k_y` asked for ([`SweepParams::directions`]),
    /// with their CGs, when asked for.
    pub tangential: Option<Along>,
    /// Wall-clock seconds of the tangential stiffnesses (0 when not asked for).
    pub tangential_seconds: f64,
}

/// Where in a sweep a solver error came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SweepStep {
    /// The full-contact check before the first solve.
    FullContactCheck,
    /// The load's solve.
    Solve,
    /// The load's frozen-set stiffness.
    Stiffness,
    /// The load's tangential stiffnesses.
    Tangential,
    /// The load's finite-difference stiffness or the re-solve after it.
    FiniteDifference,
}

/// Why a sweep stopped.
#[derive(Debug, thiserror::Error)]
pub enum SweepError<E> {
    /// Bad [`SweepParams`].
    #[error(transparent)]
    Input(Error),
    /// The solver failed (or refused a load beyond full contact) at `load`.
    #[error("{}: {source}", step_context(*step, *load, *control))]
    Solve {
        /// Index of the load (0-based).
        load: usize,
        /// The load.
        control: Control,
        /// The step that failed.
        step: SweepStep,
        /// The solver's error.
        source: SolveError,
    },
    /// The load itself is below full contact but its upper finite-difference step is not.
    #[error("at {} the upper finite-difference step ({} {upper:.6e}, the load × (1 + {relative_step})) is beyond full contact (the gap closes everywhere from {full_contact:.6e})", describe(*load, *control), control.quantity())]
    StepBeyondFullContact {
        /// Index of the load (0-based).
        load: usize,
        /// The load.
        control: Control,
        /// The upper step, `load × (1 + relative_step)`.
        upper: f64,
        /// The relative step.
        relative_step: f64,
        /// The threshold in the load's quantity.
        full_contact: f64,
    },
    /// An observer's hook returned an error.
    #[error("stopped by the caller")]
    Stopped(E),
}

/// A load as messages name it: `load 3 (mean pressure 0.01)`.
pub fn describe(load: usize, control: Control) -> String {
    format!("load {load} ({} {})", control.quantity(), control.value())
}

fn step_context(step: SweepStep, load: usize, control: Control) -> String {
    step_context_naming(step, load, control, "finite-difference stiffness")
}

/// [`step_context`] with the finite-difference stiffness called `fd_name`.
fn step_context_naming(step: SweepStep, load: usize, control: Control, fd_name: &str) -> String {
    let load = describe(load, control);
    match step {
        SweepStep::FullContactCheck | SweepStep::Solve => load,
        SweepStep::Stiffness => format!("stiffness at {load}"),
        SweepStep::Tangential => format!("tangential stiffness at {load}"),
        SweepStep::FiniteDifference => format!("{fd_name} at {load}"),
    }
}

/// A [`SweepError`] taken apart for a front end, which names the finite-difference option
/// its own way (`--fd-stiffness`, `fd_stiffness`) but should otherwise say the same.
#[derive(Debug)]
pub enum SweepFailure<E> {
    /// Bad parameters, or a solver error with no load to name: the full-contact threshold
    /// could not be computed (bad input, no convergence) before any solve.
    Input(SolveError),
    /// A solver error at a load, with where it happened: `load 3 (mean pressure 0.01)`,
    /// `stiffness at load 3 (…)` or `<fd option> at load 3 (…)`.
    AtLoad {
        /// Where, as the prefix of the solver's message.
        context: String,
        /// The solver's error.
        source: SolveError,
    },
    /// The upper finite-difference step of a load crosses full contact: the whole message,
    /// with the advice to lower the load or drop the option.
    StepBeyondFullContact(String),
    /// An observer's hook stopped the sweep.
    Stopped(E),
}

impl<E> SweepError<E> {
    /// This error in the words of a front end whose finite-difference stiffness option is
    /// called `fd_option`.
    pub fn explain(self, fd_option: &str) -> SweepFailure<E> {
        match self {
            SweepError::Input(e) => SweepFailure::Input(SolveError::Input(e)),
            // The threshold computations before any solve fail without a load to name.
            SweepError::Solve {
                step: SweepStep::FullContactCheck,
                source: source @ (SolveError::Input(_) | SolveError::NoConvergence { .. }),
                ..
            } => SweepFailure::Input(source),
            SweepError::Solve {
                load,
                control,
                step,
                source,
            } => SweepFailure::AtLoad {
                context: step_context_naming(step, load, control, fd_option),
                source,
            },
            e @ SweepError::StepBeyondFullContact { .. } => SweepFailure::StepBeyondFullContact(
                format!("{fd_option}: {e}; lower the load or drop {fd_option}"),
            ),
            SweepError::Stopped(e) => SweepFailure::Stopped(e),
        }
    }
}

/// What a front end does during a sweep; both hooks default to nothing. An error from
/// either stops the sweep ([`SweepError::Stopped`]).
pub trait SweepObserver {
    /// The error a hook stops the sweep with.
    type Error;

    /// Load `load` is solved and its frozen-set stiffness computed; the finite-difference
    /// steps have not moved the solver yet: the place to take the fields
    /// ([`ContactSolver::pressure`], [`ContactSolver::gap`]).
    fn solved(&mut self, _load: usize, _solver: &ContactSolver) -> Result<(), Self::Error> {
        Ok(())
    }

    /// Load `load` is done (progress, cancellation between loads).
    fn finished(&mut self, _load: usize, _row: &SweepRow) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// An observer that does nothing.
impl SweepObserver for () {
    type Error = std::convert::Infallible;
}

/// Step 1 of the module docs: refuses, before any solve, the largest load of each kind if it
/// is beyond full contact, and with `fd_step` its upper step.
pub fn check_full_contact<E>(
    solver: &mut ContactSolver,
    loads: &[Control],
    fd_step: Option<f64>,
) -> Result<(), SweepError<E>> {
    let area = solver.nominal_area();
    let same_kind =
        |a: &Control, b: &Control| std::mem::discriminant(a) == std::mem::discriminant(b);
    let mut kinds: Vec<Control> = Vec::new();
    for c in loads {
        if !kinds.iter().any(|k| same_kind(k, c)) {
            kinds.push(*c);
        }
    }
    for kind in kinds {
        let Some((load, &largest)) = loads
            .iter()
            .enumerate()
            .filter(|(_, c)| same_kind(c, &kind))
            .max_by(|a, b| a.1.value().total_cmp(&b.1.value()))
        else {
            continue;
        };
        let failed = |source| SweepError::Solve {
            load,
            control: largest,
            step: SweepStep::FullContactCheck,
            source,
        };
        let upper = largest.value() * (1.0 + fd_step.unwrap_or(0.0));
        let bound = solver.full_contact_lower_bound().map_err(failed)?;
        match bound.in_units_of(largest, area) {
            Some(b) if upper < b => continue,
            None => continue, // no threshold in this quantity (left to the solver)
            Some(_) => {}
        }
        let threshold = solver.full_contact_threshold().map_err(failed)?;
        let Some(full) = threshold.in_units_of(largest, area) else {
            continue;
        };
        if largest.value() >= full {
            return Err(failed(SolveError::BeyondFullContact {
                requested: largest,
                full_contact: Some(full),
            }));
        }
        if upper >= full {
            return Err(SweepError::StepBeyondFullContact {
                load,
                control: largest,
                upper,
                relative_step: fd_step.unwrap_or(0.0),
                full_contact: full,
            });
        }
    }
    Ok(())
}

/// Runs the sweep of the module docs over `loads` and returns one row per load.
pub fn sweep<O: SweepObserver>(
    solver: &mut ContactSolver,
    loads: &[Control],
    params: SweepParams,
    observer: &mut O,
) -> Result<Vec<SweepRow>, SweepError<O::Error>> {
    params.validate().map_err(SweepError::Input)?;
    check_full_contact(solver, loads, params.fd_step)?;
    let mut tangential = params
        .tangential
        .map(|poisson| TangentialStiffness::new(solver, poisson))
        .transpose()
        .map_err(SweepError::Input)?;
    let mut rows = Vec::with_capacity(loads.len());
    for (load, &control) in loads.iter().enumerate() {
        let failed = |step| {
            move |source| SweepError::Solve {
                load,
                control,
                step,
                source,
            }
        };
        let start = Instant::now();
        let (summary, info) = solver.solve(control).map_err(failed(SweepStep::Solve))?;
        let solve_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let stiffness = match params.stiffness {
            true => Some(
                solver
                    .frozen_set_stiffness()
                    .map_err(failed(SweepStep::Stiffness))?
                    .0,
            ),
            false => None,
        };
        let stiffness_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let tangential = match &mut tangential {
            Some(t) => Some(
                t.solve_directions(solver, params.directions)
                    .map_err(failed(SweepStep::Tangential))?,
            ),
            None => None,
        };
        let tangential_seconds = start.elapsed().as_secs_f64();
        observer.solved(load, solver).map_err(SweepError::Stopped)?;
        // The two steps move the solver: the load is solved again (warm, from the upper
        // step) for the next load's warm start, except after the last one.
        let stiffness_fd = match params.fd_step {
            Some(step) if control.value() > 0.0 => {
                let fd = failed(SweepStep::FiniteDifference);
                let k = solver
                    .finite_difference_stiffness(control, step)
                    .map_err(fd)?;
                if load + 1 < loads.len() {
                    solver.solve(control).map_err(fd)?;
                }
                Some(k)
            }
            _ => None, // not asked for, or no central difference at indentation 0
        };
        let row = SweepRow {
            control,
            summary,
            info,
            stiffness,
            stiffness_fd,
            solve_seconds,
            stiffness_seconds,
            tangential,
            tangential_seconds,
        };
        observer.finished(load, &row).map_err(SweepError::Stopped)?;
        rows.push(row);
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bem::iterations::polonsky_keer::tests::rough;
    use crate::bem::{HalfSpace, SolverParams};

    fn solver() -> ContactSolver {
        ContactSolver::new(&rough(40, 3), HalfSpace::default(), SolverParams::default()).unwrap()
    }

    /// Counts the hooks; stops after `stop_after` loads.
    struct Count {
        solved: usize,
        finished: usize,
        stop_after: usize,
    }

    impl SweepObserver for Count {
        type Error = &'static str;
        fn solved(&mut self, load: usize, solver: &ContactSolver) -> Result<(), &'static str> {
            assert_eq!(load, self.solved);
            assert!(solver.summary().is_some());
            self.solved += 1;
            Ok(())
        }
        fn finished(&mut self, load: usize, _row: &SweepRow) -> Result<(), &'static str> {
            assert_eq!(load + 1, self.solved);
            self.finished += 1;
            if self.finished == self.stop_after {
                return Err("enough");
            }
            Ok(())
        }
    }

    #[test]
    fn a_sweep_is_the_loop_of_solves_stiffnesses_and_finite_differences() {
        let loads = [Control::MeanPressure(0.01), Control::Force(0.02)];
        let params = SweepParams {
            stiffness: true,
            fd_step: Some(1e-3),
            tangential: Some(0.3),
            directions: Directions::Both,
        };
        let rows = sweep(&mut solver(), &loads, params, &mut ()).unwrap();
        // The same steps by hand, in the same order, give the same numbers bit for bit.
        let mut s = solver();
        let mut tangential = TangentialStiffness::new(&s, 0.3).unwrap();
        for (row, &control) in rows.iter().zip(&loads) {
            let (summary, info) = s.solve(control).unwrap();
            let k = s.frozen_set_stiffness().unwrap().0;
            let t = tangential.solve(&s).unwrap();
            let fd = s.finite_difference_stiffness(control, 1e-3).unwrap();
            s.solve(control).unwrap();
            assert_eq!(
                (row.summary, row.info, row.stiffness, row.stiffness_fd),
                (summary, info, Some(k), Some(fd))
            );
            assert_eq!(row.tangential, Some(t.into()));
            // Mindlin's ratio within a few per cent on a coarse rough contact.
            let ratio = (t.x + t.y) / (2.0 * k) / (1.4 / 1.7);
            assert!((ratio - 1.0).abs() < 0.05, "{ratio}");
        }
        // Without it, no tangential row and no time spent.
        let plain = sweep(&mut solver(), &loads, SweepParams::default(), &mut ()).unwrap();
        assert!(plain
            .iter()
            .all(|r| r.tangential.is_none() && r.tangential_seconds < 1e-3));
        let bad = SweepParams {
            tangential: Some(0.6),
            ..SweepParams::default()
        };
        let e = sweep(&mut solver(), &loads, bad, &mut ()).unwrap_err();
        assert!(e.to_string().contains("Poisson's ratio"), "{e}");
    }

    #[test]
    fn one_direction_gives_the_both_runs_stiffness_alone() {
        let loads = [0.005, 0.02, 0.06].map(Control::MeanPressure);
        let run = |directions| {
            let params = SweepParams {
                tangential: Some(0.3),
                directions,
                ..SweepParams::default()
            };
            sweep(&mut solver(), &loads, params, &mut ()).unwrap()
        };
        let (both, x, y) = (
            run(Directions::Both),
            run(Directions::X),
            run(Directions::Y),
        );
        for ((b, x), y) in both.iter().zip(&x).zip(&y) {
            let (b, x, y) = (
                b.tangential.unwrap(),
                x.tangential.unwrap(),
                y.tangential.unwrap(),
            );
            // k_x: the same start and CG, bit for bit.
            assert_eq!(x.x, b.x);
            assert_eq!((x.y, y.x), (None, None));
            // k_y starts elsewhere (Mindlin × the normal solution, not 2w − x): the same
            // stiffness to the CG's energy tolerance (1e-12 relative by default).
            let (ky, kb) = (y.stiffness_y().unwrap(), b.stiffness_y().unwrap());
            assert!((ky / kb - 1.0).abs() < 1e-11, "{ky} {kb}");
            assert!(x.operator_applications() < b.operator_applications());
        }
    }

    #[test]
    fn hooks_run_per_load_and_an_error_stops_the_sweep() {
        let loads = [0.005, 0.01, 0.02].map(Control::MeanPressure);
        let mut count = Count {
            solved: 0,
            finished: 0,
            stop_after: 2,
        };
        let result = sweep(&mut solver(), &loads, SweepParams::default(), &mut count);
        assert!(matches!(result, Err(SweepError::Stopped("enough"))));
        assert_eq!((count.solved, count.finished), (2, 2));
        let bad = SweepParams {
            fd_step: Some(1.5),
            ..SweepParams::default()
        };
        assert!(matches!(
            sweep(&mut solver(), &loads, bad, &mut ()),
            Err(SweepError::Input(_))
        ));
    }

    #[test]
    fn loads_beyond_full_contact_are_refused_before_any_solve() {
        let mut s = solver();
        let full = s.full_contact_threshold().unwrap().mean_pressure;
        let loads = [
            Control::MeanPressure(0.01),
            Control::MeanPressure(2.0 * full),
        ];
        let mut count = Count {
            solved: 0,
            finished: 0,
            stop_after: usize::MAX,
        };
        match sweep(&mut s, &loads, SweepParams::default(), &mut count) {
            Err(e @ SweepError::Solve { load: 1, .. }) => {
                assert!(e.to_string().starts_with("load 1 (mean pressure"), "{e}");
                // A front end names the same load, the solver's error kept as it is.
                match e.explain("fd") {
                    SweepFailure::AtLoad { context, source } => {
                        assert!(context.starts_with("load 1 (mean pressure"), "{context}");
                        assert!(matches!(source, SolveError::BeyondFullContact { .. }));
                    }
                    other => panic!("{other:?}"),
                }
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(count.solved, 0);
        // Below full contact, but the upper finite-difference step is not.
        let loads = [Control::MeanPressure(0.9995 * full)];
        let params = SweepParams {
            fd_step: Some(1e-3),
            ..SweepParams::default()
        };
        let e = sweep(&mut s, &loads, params, &mut ()).unwrap_err();
        assert!(
            matches!(e, SweepError::StepBeyondFullContact { load: 0, .. }),
            "{e}"
        );
        match e.explain("fd") {
            SweepFailure::StepBeyondFullContact(text) => {
                assert!(text.starts_with("fd: at load 0 (mean pressure"), "{text}");
                assert!(text.ends_with("; lower the load or drop fd"), "{text}");
            }
            other => panic!("{other:?}"),
        }
    }
}
