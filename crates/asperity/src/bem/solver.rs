//! [`ContactSolver`]: the solver core shared by the iterations of [`crate::bem`].
//!
//! A solver is made of named parts, each owned by one piece of code:
//! * the [`Context`] (`context.rs`) that every iteration works on:
//!   - [`ContactProblem`] — what is solved: the indenter profile `f = max(h) − h` of one
//!     surface and its height scale, the half-space (the [`ElasticOperator`], with its
//!     boundary, spacings and modulus) and the grid. Only [`ContactSolver::set_surface`]
//!     changes it; every other piece of code reads it (and applies its operator);
//!   - `SolverState` — the state of the last solve: pressure, gap, the solved summary and
//!     the cached full-contact threshold. Its fields are written by the iterations only;
//!     the stiffness and threshold code reads them and keeps them intact (and caches the
//!     threshold);
//!   - the settings ([`SolverParams`]), the Fourier preconditioner shared by the BCCG and
//!     the CGs, the stop flag and the contact law ([`Interface`]);
//! * one scratch struct per algorithm, in its own file and used by no other: the
//!   iterations' `BccgScratch` (`iterations/bccg.rs`, with the coarse correction of
//!   `bccg/mean_gap.rs` and the direct solve of small sets of `bccg/small_set.rs`) and
//!   `PkScratch` (`iterations/polonsky_keer.rs`), each an [`Iteration`]
//!   (`iterations/mod.rs`); `StiffnessWork`
//!   (`stiffness/work.rs`: the frozen-set CG and the free-boundary threshold's CG) and
//!   `FullContactScratch` (`threshold.rs`, used by `full_contact.rs`: the periodic threshold
//!   and the lower bound). Scratch that not every solver needs is allocated on first use and
//!   kept, so warm solves allocate nothing.
//!
//! [`ContactSolver::solve`] validates the control, refuses a periodic load or indentation
//! beyond full contact before solving, sets the initial pressure (warm or cold start,
//! `initialise`) and runs the chosen iteration ([`SolverKind`], mapped to its [`Iteration`]
//! in one place, `ContactSolver::iteration`; or one plugged by `solve_with`) on the context: `(target, limits)` in,
//! `(ContactSummary, SolveInfo)` or a typed [`SolveError`] out, the summary of a converged
//! state made by [`Context::finish`].
//!
//! **The contact law** is the solver's [`Interface`] (`interface.rs`, set by
//! [`ContactSolver::set_interface`]): every rule of what "in contact" means is asked of it
//! (the BCCG picks the pass compiled for it, hard wall or cap). A new law that the existing iterations can solve
//! (as both solve the hardness cap, `plasticity.rs`) is a new variant there.
//!
//! **Extending the core** (an adhesive contact, say, which needs its own iteration): a new
//! file with the iteration's scratch struct implementing [`Iteration`] (`iterations/mod.rs` says
//! what it may read and write), which `ContactSolver::solve_with(control, &mut scratch)`
//! runs as it stands (the caller owns its fields; the solver's validation, start, capped
//! root search and solved state are those of every solve). To make it a choice of
//! [`SolverParams`]: one `Option<…>` field for it in [`ContactSolver`] allocated on first
//! use (as `pk_scratch` is), a [`SolverKind`] variant and its arm in
//! `ContactSolver::iteration`, and its fields in [`ContactSolver::memory_bytes`]. No other
//! algorithm's fields change meaning, and the stiffness and threshold code applies to its
//! solved state unchanged.

use ndarray::{Array2, ArrayView2};

use super::context::{ContactProblem, Context, SolverState, Target};
use super::interface::{restore_capped_load, Interface};
use super::iterations::BccgScratch;
use super::iterations::PkScratch;
use super::iterations::{Iteration, Limits, RING_MIN_POINTS};
use super::precondition::{FourierPreconditioner, Real};
use super::stagnation::Progress;
use super::stiffness::work::StiffnessWork;
use super::threshold::FullContactScratch;
use super::{
    ContactState, ContactSummary, Control, HalfSpace, SolveError, SolveInfo, SolverKind,
    SolverParams,
};
use crate::elastic::{Boundary, ContactOperator, ElasticOperator};
use crate::pool::on_worker;
use crate::stop::Stop;
use crate::surface::Surface;
use crate::{memory, Error};

/// Which iteration a solve runs: that of a [`SolverKind`] (its fields the solver's), or one
/// the caller plugs in ([`ContactSolver::solve_with`]).
pub(super) enum Runner<'a, K: ContactOperator> {
    Kind(SolverKind),
    // (No iteration of the library is plugged yet: the seam's test plugs two.)
    #[cfg_attr(not(test), allow(dead_code))]
    Plugged(&'a mut dyn Iteration<K>),
}

/// A contact solver for one surface: the problem, the state of the last solve, and the
/// scratch of each algorithm, each its own (module docs); successive solves allocate
/// nothing and start from the previous pressure. `K` is the elastic body's operator: the
/// homogeneous half-space's ([`ContactSolver::new`]) or any [`ContactOperator`]
/// ([`ContactSolver::with_operator`]).
pub struct ContactSolver<K: ContactOperator = ElasticOperator> {
    /// The problem, settings, state, preconditioner, stop flag and contact law that every
    /// iteration works on (`context.rs`).
    pub(super) cx: Context<K>,
    /// The BCCG's own fields (`bccg.rs`, with the coarse correction of `mean_gap.rs` and
    /// the direct solve of small sets of `small_set.rs`).
    pub(super) bccg_scratch: BccgScratch<K>,
    /// The Polonsky–Keer iteration's own fields (`polonsky_keer.rs`), allocated on its
    /// first solve.
    pub(super) pk_scratch: Option<PkScratch>,
    /// The fields of the frozen-set and free-boundary threshold CGs (`stiffness/`),
    /// allocated on first use.
    pub(super) stiffness_work: Option<StiffnessWork>,
    /// The fields of the periodic threshold and of the lower bound (`full_contact.rs`),
    /// allocated on first use.
    pub(super) full_contact_scratch: Option<FullContactScratch>,
    /// The permanent (plastic) displacement kept by
    /// [`ContactSolver::keep_plastic_displacement`], added to the profile; allocated on
    /// first use.
    pub(super) permanent: Option<Vec<f64>>,
    /// Whether the frozen-set CG of large grids makes its first pass in single precision
    /// (`stiffness/mod.rs`; on by default).
    pub(super) single_precision_stiffness: bool,
}

impl ContactSolver {
    /// Estimated peak memory of a solver for a `rows × cols` grid (bytes; `None` on
    /// overflow) once a BCCG solve, its frozen-set stiffness and the full-contact checks
    /// have run, all that `asperity bem` does with it: the sum of every buffer they
    /// allocate (an upper bound; `solver_bytes_per_point` lists them) and the plans and
    /// per-thread buffers of the three transforms. Not included: the caller's
    /// [`Surface`] (one more `rows × cols` field while the solver is built; `asperity bem`
    /// frees it before the first solve), a Polonsky–Keer solve's two fields
    /// ([`ContactSolver::new`] adds them when its parameters choose it), and the fields of
    /// a hardness cap (`K 1_C`) and of kept plastic displacement (one field each).
    ///
    /// Measured (`asperity bem --tol 1e-3 --timing`, peak resident set less the 5 MiB of
    /// `asperity --version`; docs/performance.md): 205 bytes per point free and 176
    /// periodic at 4096², p̄ = 0.05, and 220 and 184 at higher loads (p̄ = 0.2 free, a
    /// periodic indentation), where the CG's set fills; the estimate is 238 and 209 bytes
    /// per point there.
    pub fn memory_bytes(rows: usize, cols: usize, boundary: Boundary) -> Option<u64> {
        Self::memory_bytes_for(rows, cols, boundary, SolverKind::Bccg)
    }

    /// [`ContactSolver::memory_bytes`] with the fields of `solver`'s iteration: a
    /// Polonsky–Keer solver also holds its direction and response (two fields).
    pub fn memory_bytes_for(
        rows: usize,
        cols: usize,
        boundary: Boundary,
        solver: SolverKind,
    ) -> Option<u64> {
        let len = rows.checked_mul(cols)?;
        let per_point = solver_bytes_per_point(boundary, len >= RING_MIN_POINTS, solver);
        let fields = memory::array_bytes(&[len], per_point)?;
        let limit = super::iterations::small_set::limit(len);
        let factor = memory::array_bytes(&[limit + 3, limit], 8)?;
        let resident = ElasticOperator::resident_memory_bytes(rows, cols, boundary)?
            .checked_add(ElasticOperator::single_precision_memory_bytes(
                rows, cols, boundary,
            )?)?
            .checked_add(FourierPreconditioner::<Real>::memory_bytes(rows, cols)?)?
            .checked_add(fields)?
            .checked_add(factor)?;
        // The operator's set-up holds its kernel's whole spectrum before anything else of
        // the solver is allocated: the larger of the two is the peak.
        Some(resident.max(ElasticOperator::memory_bytes(rows, cols, boundary)?))
    }

    /// Plans a solver for `surface` on `half_space`; validates `params`, refuses grids that
    /// would not fit in memory ([`ContactSolver::memory_bytes_for`] of `params.solver`).
    pub fn new(
        surface: &Surface,
        half_space: HalfSpace,
        params: SolverParams,
    ) -> Result<Self, SolveError> {
        validate_params(&params)?;
        let (rows, cols) = surface.dim();
        memory::ensure_fits(
            &format!(
                "a BEM solver for a {rows}x{cols} grid ({} boundaries)",
                half_space.boundary.name()
            ),
            Self::memory_bytes_for(rows, cols, half_space.boundary, params.solver),
        )?;
        let problem = ContactProblem::new(surface, half_space)?;
        Self::assemble(problem, params)
    }
}

/// Bytes per grid point of the fields a solver allocates for its solves (BCCG, or `solver`),
/// its frozen-set stiffness and its full-contact checks, each counted whole: a buffer is
/// written only in part by some loads (the CG's set list, the rings' lists, the small set's
/// entering list) but filled by others (measured: the peak rises from 212 to 227 bytes per
/// point at 1024² free from p̄ = 0.05 to 0.2). `rings`: the grid has the rings around the
/// free set ([`RING_MIN_POINTS`]). The operators' and the preconditioner's buffers are
/// counted apart ([`ContactSolver::memory_bytes`]).
fn solver_bytes_per_point(boundary: Boundary, rings: bool, solver: SolverKind) -> usize {
    const F64: usize = 8;
    const INDEX: usize = std::mem::size_of::<usize>();
    let free = boundary == Boundary::Free;
    // The problem's profile; the state's pressure and gap (`context.rs`).
    let problem = 3 * F64;
    // BCCG: direction, response, preconditioned gradient, gradient, previous gradient and
    // the impulse response; the free set and the previous one; the chunks' cut lists (96
    // pairs per 8192 points, 0.19 bytes per point: one) (`bccg.rs`).
    let bccg = 6 * F64 + 2 + 1;
    // The periodic coarse correction: 1_O and its free set (`mean_gap.rs`).
    let mean_gap = if free { 0 } else { F64 + 1 };
    // The small-set solve: membership and the entering list (`small_set.rs`; its dense
    // factor is counted apart).
    let small_set = 1 + INDEX;
    // Full contact: the weights, and K v of the free lower bound (`threshold.rs`).
    let full_contact = if free { 2 * F64 } else { F64 };
    // The stiffness CG: x, residual, preconditioned residual, direction, response and its
    // set's index list; K⁻¹f of the free threshold (`stiffness/`).
    let stiffness = 5 * F64 + INDEX + if free { F64 } else { 0 };
    // The rings of the BCCG and of the stiffness CG (two counts, a mask, two u32 column
    // lists and a value list each, `ring_extension.rs`), and the CG's set mask.
    let ring = 3 + 2 * 4 + F64;
    let rings = if rings { 2 * ring + 1 } else { 0 };
    // Polonsky–Keer: its direction and response (`polonsky_keer.rs`).
    let pk = match solver {
        SolverKind::PolonskyKeer => 2 * F64,
        SolverKind::Bccg => 0,
    };
    problem + bccg + mean_gap + small_set + full_contact + stiffness + rings + pk
}

impl<K: ContactOperator> ContactSolver<K> {
    /// Plans a solver for `surface` on the body of `operator` (any [`ContactOperator`]: a
    /// kernel other than the homogeneous half-space's plugs in here; it must have the
    /// surface's grid and spacings); validates `params`, refuses grids whose fields would
    /// not fit in memory (estimated as [`ContactSolver::memory_bytes`], with the
    /// homogeneous half-space's operator). The solver is compiled for `K`: no dynamic
    /// dispatch inside a solve. [`ContactSolver::new`] is this with the operator of the
    /// half-space, to the bit.
    ///
    /// ```
    /// use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
    /// use asperity::elastic::{Boundary, ElasticOperator};
    /// use asperity::surface::Surface;
    ///
    /// let heights = ndarray::Array2::from_shape_fn((32, 32), |(i, j)| {
    ///     ((i as f64) * 0.4).sin() * ((j as f64) * 0.3).cos()
    /// });
    /// let surface = Surface::new(heights, 1.0).unwrap();
    /// let dx = surface.spacing(); // (the side 1.0 over 32 points)
    /// let operator = ElasticOperator::new(32, 32, dx, 2.0, Boundary::Periodic).unwrap();
    /// let params = SolverParams::default();
    /// let mut plugged = ContactSolver::with_operator(&surface, operator, params).unwrap();
    /// let half_space = HalfSpace { modulus: 2.0, boundary: Boundary::Periodic };
    /// let mut built_in = ContactSolver::new(&surface, half_space, params).unwrap();
    /// let control = Control::MeanPressure(0.05);
    /// assert_eq!(plugged.solve(control).unwrap(), built_in.solve(control).unwrap());
    /// assert_eq!(plugged.pressure(), built_in.pressure());
    /// ```
    pub fn with_operator(
        surface: &Surface,
        operator: K,
        params: SolverParams,
    ) -> Result<Self, SolveError> {
        validate_params(&params)?;
        let (rows, cols, boundary) = (operator.rows(), operator.cols(), operator.boundary());
        memory::ensure_fits(
            &format!(
                "a BEM solver for a {rows}x{cols} grid ({} boundaries)",
                boundary.name()
            ),
            ContactSolver::memory_bytes_for(rows, cols, boundary, params.solver),
        )?;
        let problem = ContactProblem::with_operator(surface, operator)?;
        Self::assemble(problem, params)
    }

    /// The solver of `problem`: the preconditioner for its operator's grid and modulus, the
    /// BCCG's fields, the hard wall, no state.
    fn assemble(mut problem: ContactProblem<K>, params: SolverParams) -> Result<Self, SolveError> {
        let (rows, cols) = problem.dim();
        let (dx, dy) = problem.operator.spacings();
        let modulus = problem.operator.modulus();
        let preconditioner = FourierPreconditioner::new(rows, cols, dx, dy, modulus)?;
        let bccg_scratch = BccgScratch::new(&mut problem.operator)?;
        let cx = Context {
            problem,
            params,
            state: SolverState::new(rows * cols),
            preconditioner,
            stop: Stop::new(),
            progress: Progress::default(),
            monitor: None,
            interface: Interface::HardWall,
        };
        Ok(ContactSolver {
            cx,
            bccg_scratch,
            pk_scratch: None,
            stiffness_work: None,
            full_contact_scratch: None,
            permanent: None,
            single_precision_stiffness: true,
        })
    }

    /// Calls `monitor` with the iteration count and the residual (the module docs of
    /// [`crate::bem`]) of every iteration of every BCCG or Polonsky–Keer solve from now on
    /// (`None`, the default: nobody is told): progress inside a long solve. It runs on the
    /// solving thread between iterations, so it should be quick (a look at the clock);
    /// it changes no iterate.
    ///
    /// ```
    /// use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
    /// use asperity::elastic::Boundary;
    /// use asperity::surface::Surface;
    /// use std::sync::{Arc, Mutex};
    ///
    /// let heights = ndarray::Array2::from_shape_fn((32, 32), |(i, j)| {
    ///     ((i as f64) * 0.4).sin() * ((j as f64) * 0.3).cos()
    /// });
    /// let surface = Surface::new(heights, 1.0).unwrap();
    /// let half_space = HalfSpace { modulus: 1.0, boundary: Boundary::Periodic };
    /// let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
    /// let seen = Arc::new(Mutex::new(Vec::new()));
    /// let record = Arc::clone(&seen);
    /// solver.set_monitor(Some(Box::new(move |iteration: usize, residual: f64| {
    ///     record.lock().unwrap().push((iteration, residual));
    /// })));
    /// let (_, info) = solver.solve(Control::MeanPressure(0.05)).unwrap();
    /// let seen = seen.lock().unwrap();
    /// assert!(seen.len() <= info.iterations + 1);
    /// assert!(seen.iter().all(|&(_, r)| r >= info.residual));
    /// ```
    pub fn set_monitor(&mut self, monitor: Option<super::Monitor>) {
        self.cx.monitor = monitor;
    }

    /// The solver with `stop` as its stop flag (builder form of
    /// [`ContactSolver::set_stop`]).
    pub fn with_stop(mut self, stop: Stop) -> Self {
        self.set_stop(stop);
        self
    }

    /// Polls `stop` from now on: once it is requested, every solve, stiffness or threshold
    /// computation ends within one iteration with [`SolveError::Interrupted`], and keeps
    /// doing so until the flag is cleared. An interrupted solve leaves no state behind (the
    /// next solve starts cold, exactly as a new solver's); an interrupted stiffness or
    /// threshold keeps the solved state. A solver starts with a flag of its own that
    /// nothing sets.
    pub fn set_stop(&mut self, stop: Stop) {
        self.cx.stop = stop;
    }

    /// The stop flag polled by this solver (a clone shares it).
    pub fn stop(&self) -> &Stop {
        &self.cx.stop
    }

    /// Swaps in another surface with the same grid and spacing, keeping the operator (FFT
    /// plans, kernel spectrum) and all buffers: how an ensemble solves many realisations.
    /// The next solve starts cold, exactly as with a new solver.
    pub fn set_surface(&mut self, surface: &Surface) -> Result<(), SolveError> {
        self.cx.problem.set_surface(surface)?;
        self.permanent = None;
        self.cx.state.pressure.fill(0.0);
        self.cx.state.solved = None;
        self.cx.state.full_contact = None;
        Ok(())
    }

    /// The parameters in use.
    pub fn params(&self) -> &SolverParams {
        &self.cx.params
    }

    /// Replaces the parameters (validated).
    pub fn set_params(&mut self, params: SolverParams) -> Result<(), SolveError> {
        validate_params(&params)?;
        self.cx.params = params;
        Ok(())
    }

    /// `(rows, cols)` of the grid.
    pub fn dim(&self) -> (usize, usize) {
        self.cx.problem.dim()
    }

    /// Nominal (projected) area `rows · cols · Δx · Δy`.
    pub fn nominal_area(&self) -> f64 {
        self.cx.problem.nominal_area()
    }

    /// What is solved: the surface's profile on the half-space, on the grid.
    pub fn problem(&self) -> &ContactProblem<K> {
        &self.cx.problem
    }

    /// Forgets the previous solution: the next solve starts cold.
    pub fn reset(&mut self) {
        self.cx.state.solved = None;
    }

    /// The last solved state's scalars, if any.
    pub fn summary(&self) -> Option<ContactSummary> {
        self.cx.state.solved
    }

    /// Solves the contact under `control`, starting from the previous solution when there
    /// is one (warm start). Fields of the result: [`ContactSolver::pressure`],
    /// [`ContactSolver::gap`], [`ContactSolver::state`].
    pub fn solve(&mut self, control: Control) -> Result<(ContactSummary, SolveInfo), SolveError> {
        self.solve_by(control, Runner::Kind(self.cx.params.solver))
    }

    /// [`ContactSolver::solve`] by an iteration that is not a [`SolverKind`] (a new
    /// algorithm in a file of `bem/`, before or without a variant of its own): everything
    /// around the iteration — validation, refusals beyond full contact, the start, the root
    /// search of a capped load, the solved state for the stiffness and thresholds — is the
    /// solver's, as for the built-in iterations.
    #[cfg_attr(not(test), allow(dead_code))]
    pub(super) fn solve_with(
        &mut self,
        control: Control,
        iteration: &mut dyn Iteration<K>,
    ) -> Result<(ContactSummary, SolveInfo), SolveError> {
        self.solve_by(control, Runner::Plugged(iteration))
    }

    /// [`ContactSolver::solve`] by the iteration of `runner`.
    fn solve_by(
        &mut self,
        control: Control,
        mut runner: Runner<'_, K>,
    ) -> Result<(ContactSummary, SolveInfo), SolveError> {
        let target = match control {
            Control::MeanPressure(p) => Target::MeanPressure(check_load("mean pressure", p)?),
            Control::Force(f) => {
                Target::MeanPressure(check_load("force", f)? / self.nominal_area())
            }
            Control::Indentation(d) => {
                if !(d.is_finite() && d >= 0.0) {
                    return Err(Error::invalid(
                        "indentation",
                        format!(
                            "must be finite and >= 0, got {}",
                            crate::input::short_number(d)
                        ),
                    )
                    .into());
                }
                Target::Indentation(d)
            }
        };
        self.check_interface(target)?;
        let periodic = self.cx.problem.operator.boundary() == Boundary::Periodic;
        if periodic {
            // Exact thresholds, known before solving: the mean pressure max(K⁺f) and, with
            // displacements of zero mean, the indentation mean(f).
            let full = self.periodic_full_contact();
            let beyond = match target {
                // (Not under a cap: the threshold is the elastic one, and a capped contact
                // may close at a lower load or stay open beyond it; a capped solution in
                // full contact without plastic points is refused after the solve.)
                Target::MeanPressure(_) if self.cx.interface != Interface::HardWall => false,
                Target::MeanPressure(p) => p >= full.mean_pressure,
                // The mean gap mean(f) − d within the rounding of the sum mean(f) (n ulps)
                // is no gap: full contact. (Not under a cap: the plastic points stand
                // below the indenter, so the mean gap may be negative short of full
                // contact; a solution in full contact is refused after the solve.)
                Target::Indentation(_) if self.cx.interface != Interface::HardWall => false,
                Target::Indentation(d) => full.indentation.is_some_and(|d_full| {
                    d >= d_full * (1.0 - self.cx.problem.profile.len() as f64 * f64::EPSILON)
                }),
            };
            if beyond {
                self.cx.state.solved = None;
                return Err(self.beyond_full_contact(control));
            }
        }
        let (tolerance, max_iterations) = (self.cx.params.tolerance, self.cx.params.max_iterations);
        // On a worker of the pool: the iteration's parallel passes are then forked, not
        // injected one by one, and the other workers wait for them awake (`pool.rs`).
        let parallelism = self.cx.params.parallelism;
        let result = on_worker(parallelism, || match target {
            Target::MeanPressure(p) if self.cx.interface != Interface::HardWall => {
                self.capped_load(&mut runner, p, tolerance, max_iterations)
            }
            _ => self.iterate(&mut runner, target, tolerance, max_iterations),
        });
        match result {
            // Every point in contact, under load or displacement control: no contact
            // problem is left; refused with the threshold (free boundaries: only known
            // from the solution, periodic: checked above, this is rounding at p ≈ p*).
            // Under a cap a full contact with points at the cap is a contact problem still
            // (the plastic points flattened, the rest elastic): kept.
            Ok((summary, _))
                if summary.contact_points == self.cx.problem.rows * self.cx.problem.cols
                    && summary.plastic_points == 0 =>
            {
                self.cx.state.solved = None;
                return Err(self.beyond_full_contact(control));
            }
            Ok((summary, _)) => self.cx.state.solved = Some(summary),
            Err(_) => self.cx.state.solved = None,
        }
        result
    }

    /// Refuses what the interface cannot solve: a mean pressure at or above the hardness.
    fn check_interface(&self, target: Target) -> Result<(), SolveError> {
        if let Target::MeanPressure(p) = target {
            self.cx.interface.check_mean_pressure(p)?;
        }
        Ok(())
    }

    /// The error for a `requested` load or indentation that closes the gap everywhere, with
    /// the threshold in the same quantity where it is known.
    fn beyond_full_contact(&mut self, requested: Control) -> SolveError {
        let threshold = match self.cx.problem.operator.boundary() {
            Boundary::Periodic => Some(self.periodic_full_contact()),
            Boundary::Free => self.free_full_contact().ok(),
        };
        let full_contact = threshold.and_then(|t| match requested {
            Control::MeanPressure(_) => Some(t.mean_pressure),
            Control::Force(_) => Some(t.mean_pressure * self.nominal_area()),
            Control::Indentation(_) => t.indentation,
        });
        SolveError::BeyondFullContact {
            requested,
            full_contact,
        }
    }

    /// Pressure of the last solve, `rows × cols`.
    pub fn pressure(&self) -> ArrayView2<'_, f64> {
        ArrayView2::from_shape(
            (self.cx.problem.rows, self.cx.problem.cols),
            &self.cx.state.pressure,
        )
        .expect("buffer has the grid's shape")
    }

    /// Gap of the last solve, `rows × cols` (≥ 0, zero on the contact set).
    pub fn gap(&self) -> ArrayView2<'_, f64> {
        ArrayView2::from_shape(
            (self.cx.problem.rows, self.cx.problem.cols),
            &self.cx.state.gap,
        )
        .expect("buffer has the grid's shape")
    }

    /// The last solved state with owned copies of its fields; the displacement is computed
    /// afresh (one operator application). `None` before a successful solve.
    pub fn state(&mut self) -> Option<ContactState> {
        let summary = self.cx.state.solved?;
        let mut displacement = Array2::zeros((self.cx.problem.rows, self.cx.problem.cols));
        let out = displacement
            .as_slice_mut()
            .expect("a fresh array is contiguous");
        self.cx.problem.operator.apply(&self.cx.state.pressure, out);
        Some(ContactState {
            summary,
            pressure: self.pressure().to_owned(),
            gap: self.gap().to_owned(),
            displacement,
        })
    }

    /// The iteration `runner` names (for a [`SolverKind`]: `bccg.rs`, `polonsky_keer.rs`;
    /// Polonsky–Keer's fields allocated on its first use) and the context it works on: the
    /// one place that maps a [`SolverKind`] to its [`Iteration`].
    pub(super) fn iteration<'s>(
        &'s mut self,
        runner: &'s mut Runner<'_, K>,
    ) -> (&'s mut dyn Iteration<K>, &'s mut Context<K>) {
        match runner {
            Runner::Kind(SolverKind::Bccg) => (&mut self.bccg_scratch, &mut self.cx),
            Runner::Kind(SolverKind::PolonskyKeer) => {
                let len = self.cx.problem.profile.len();
                let pk = self.pk_scratch.get_or_insert_with(|| PkScratch::new(len));
                (pk, &mut self.cx)
            }
            Runner::Plugged(iteration) => (&mut **iteration, &mut self.cx),
        }
    }

    /// Whether the last solve of the iteration of `runner` stalled
    /// ([`Iteration::stalled`]).
    pub(super) fn stalled(&mut self, runner: &mut Runner<'_, K>) -> bool {
        self.iteration(runner).0.stalled()
    }

    /// Solves for `target` by the iteration of `runner` to `tolerance` in at most
    /// `max_iterations` iterations, from the start of [`Self::initialise`] (warm, predicted
    /// or cold).
    pub(super) fn iterate(
        &mut self,
        runner: &mut Runner<'_, K>,
        target: Target,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<(ContactSummary, SolveInfo), SolveError> {
        let self_influence = self.cx.problem.operator.self_influence();
        self.initialise(target, self_influence);
        let (iteration, cx) = self.iteration(runner);
        let limits = Limits {
            tolerance,
            max_iterations,
        };
        iteration.solve(cx, target, limits)
    }

    /// Initial pressure: the continuation predictor when the last solve's frozen-set
    /// stiffness left its tangent (`stiffness/`), else the previous solution (rescaled to
    /// the new load) or a cold start (uniform pressure under load control; local springs
    /// `max(d − f, 0)/K₀₀` under displacement control).
    pub(super) fn initialise(&mut self, target: Target, self_influence: f64) {
        self.cx.progress.restart();
        let n = (self.cx.problem.rows * self.cx.problem.cols) as f64;
        let warm = self.cx.state.solved.is_some();
        if self.predict_from_tangent(target) {
            return;
        }
        match target {
            Target::MeanPressure(mean_pressure) => {
                let current = self.cx.state.pressure.iter().sum::<f64>() / n;
                if warm && current > 0.0 {
                    let (scale, interface) = (mean_pressure / current, self.cx.interface);
                    let cap = interface.cap();
                    if self.cx.state.pressure.iter().any(|&p| p >= cap) {
                        // Points at the cap stay there, the others scaled (scaled down
                        // with the rest they would all leave the plastic set).
                        let (pressure, gap) = (&mut self.cx.state.pressure, &self.cx.state.gap);
                        let total = current * n;
                        restore_capped_load(pressure, (mean_pressure, cap), total, |i| gap[i]);
                        return;
                    }
                    // (The hard wall's projection of p·scale ≥ 0 is the identity.)
                    for p in self.cx.state.pressure.iter_mut() {
                        *p = interface.project(*p * scale);
                    }
                } else {
                    self.cx.state.pressure.fill(mean_pressure);
                }
            }
            Target::Indentation(d) => {
                let interface = self.cx.interface;
                let any = self
                    .cx
                    .state
                    .pressure
                    .iter()
                    .any(|&p| interface.in_contact(p));
                if !(warm && any) {
                    for (p, f) in self
                        .cx
                        .state
                        .pressure
                        .iter_mut()
                        .zip(&self.cx.problem.profile)
                    {
                        *p = interface.project((d - f).max(0.0) / self_influence);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
impl<K: ContactOperator> ContactSolver<K> {
    /// Switches the rings of the BCCG and of the frozen-set CG on or off whatever the grid's
    /// size (to test the solver both ways on small grids).
    pub(super) fn set_edge_rings(&mut self, on: bool) {
        let operator = &self.cx.problem.operator;
        self.bccg_scratch.rings =
            on.then(|| super::precondition::RingExtension::on_grid_of(operator));
        self.stiffness_work = Some(StiffnessWork::new(operator, on));
    }
}

fn check_load(name: &'static str, value: f64) -> Result<f64, SolveError> {
    Ok(crate::positive_finite(name, value, "")?)
}

fn validate_params(params: &SolverParams) -> Result<(), SolveError> {
    Ok(params.validate()?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bem::iterations::polonsky_keer::tests::rough_grid;

    #[test]
    fn thresholds_keep_the_solved_state_and_its_stiffness() {
        // The full-contact threshold and its lower bound work in their own fields: after
        // them the frozen-set stiffness of the last solve is still there, bit for bit, and
        // so are the pressure and gap.
        let surface = rough_grid(40, 48, 4);
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let half_space = HalfSpace {
                modulus: 1.0,
                boundary,
            };
            let mut solver =
                ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
            solver.solve(Control::MeanPressure(0.02)).unwrap();
            let (pressure, gap) = (solver.pressure().to_owned(), solver.gap().to_owned());
            let before = solver.frozen_set_stiffness().unwrap();
            assert!(before.0 > 0.0);
            let full = solver.full_contact_threshold().unwrap();
            assert!(full.mean_pressure > 0.02, "{boundary:?}");
            assert_eq!(
                solver.frozen_set_stiffness().unwrap(),
                before,
                "{boundary:?}"
            );
            solver.full_contact_lower_bound().unwrap();
            assert_eq!(
                solver.frozen_set_stiffness().unwrap(),
                before,
                "{boundary:?}"
            );
            assert_eq!(solver.pressure(), pressure);
            assert_eq!(solver.gap(), gap);
        }
    }

    #[test]
    fn the_problem_is_the_surface_on_the_half_space() {
        let (a, b) = (rough_grid(24, 40, 1), rough_grid(24, 40, 2));
        let half_space = HalfSpace {
            modulus: 1.7,
            boundary: Boundary::Periodic,
        };
        let mut solver = ContactSolver::new(&a, half_space, SolverParams::default()).unwrap();
        let profile_of = |surface: &Surface| {
            let top = surface.heights().fold(f64::NEG_INFINITY, |m, &h| m.max(h));
            surface.heights().mapv(|h| top - h)
        };
        let problem = solver.problem();
        assert_eq!(problem.dim(), (24, 40));
        assert_eq!(problem.half_space(), half_space);
        assert_eq!(problem.spacings(), (a.spacing(), a.spacing_y()));
        assert_eq!(problem.nominal_area(), solver.nominal_area());
        assert_eq!(problem.profile(), profile_of(&a));
        let before = problem.height_scale();
        assert!(before > 0.0);
        solver.set_surface(&b).unwrap();
        assert_eq!(solver.problem().profile(), profile_of(&b));
        assert_ne!(solver.problem().height_scale(), before);
        // A surface on another grid is refused and leaves the problem as it was.
        assert!(solver.set_surface(&rough_grid(24, 41, 1)).is_err());
        assert_eq!(solver.problem().profile(), profile_of(&b));
    }

    #[test]
    fn each_iteration_works_in_its_own_fields() {
        // A solver that ran the other iteration (and the thresholds) first gives, from a
        // cold start, the same bits as a fresh solver: no iteration reads what another
        // left in its fields.
        let surface = rough_grid(40, 48, 6);
        let load = Control::MeanPressure(0.02);
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let half_space = HalfSpace {
                modulus: 1.0,
                boundary,
            };
            for (first, then) in [
                (SolverKind::Bccg, SolverKind::PolonskyKeer),
                (SolverKind::PolonskyKeer, SolverKind::Bccg),
            ] {
                let params = |solver| SolverParams {
                    solver,
                    ..SolverParams::default()
                };
                let mut fresh = ContactSolver::new(&surface, half_space, params(then)).unwrap();
                let want = (fresh.solve(load).unwrap(), fresh.pressure().to_owned());
                let mut used = ContactSolver::new(&surface, half_space, params(first)).unwrap();
                used.solve(Control::MeanPressure(0.03)).unwrap();
                used.full_contact_lower_bound().unwrap();
                used.full_contact_threshold().unwrap();
                used.set_params(params(then)).unwrap();
                used.reset();
                let got = (used.solve(load).unwrap(), used.pressure().to_owned());
                assert_eq!(got, want, "{boundary:?}: {first:?} then {then:?}");
            }
        }
    }

    /// An iteration from outside the [`SolverKind`]s: the BCCG's own fields, owned by the
    /// caller, behind a counter of its solves.
    struct Counted {
        inner: BccgScratch,
        solves: usize,
    }

    impl Iteration<ElasticOperator> for Counted {
        fn solve(
            &mut self,
            cx: &mut Context,
            target: Target,
            limits: Limits,
        ) -> Result<(ContactSummary, SolveInfo), SolveError> {
            self.solves += 1;
            self.inner.solve(cx, target, limits)
        }

        fn stalled(&self) -> bool {
            self.inner.stalled()
        }
    }

    /// An iteration that gives up at once.
    struct GivesUp;

    impl Iteration<ElasticOperator> for GivesUp {
        fn solve(
            &mut self,
            _cx: &mut Context,
            _target: Target,
            _limits: Limits,
        ) -> Result<(ContactSummary, SolveInfo), SolveError> {
            Err(SolveError::NoConvergence {
                iterations: 0,
                residual: f64::INFINITY,
            })
        }
    }

    #[test]
    fn an_iteration_outside_the_solver_kinds_plugs_in() {
        // Run by `solve_with`, the BCCG's fields held by the caller give the built-in
        // BCCG's results bit for bit, warm and capped (the capped load's solver logic runs
        // around the plugged iteration as around its own); its failure is the solve's.
        let surface = rough_grid(40, 48, 7);
        for boundary in [Boundary::Free, Boundary::Periodic] {
            for interface in [Interface::HardWall, Interface::hardness(0.08).unwrap()] {
                let half_space = HalfSpace {
                    modulus: 1.0,
                    boundary,
                };
                let new = || {
                    ContactSolver::new(&surface, half_space, SolverParams::default())
                        .unwrap()
                        .with_interface(interface)
                        .unwrap()
                };
                let (mut built_in, mut plugged) = (new(), new());
                let mut counted = Counted {
                    inner: BccgScratch::new(&mut plugged.cx.problem.operator).unwrap(),
                    solves: 0,
                };
                let loads = [0.02, 0.04, 0.03].map(Control::MeanPressure);
                let mut plastic = 0;
                for (k, control) in loads
                    .into_iter()
                    .chain([Control::Indentation(0.03)])
                    .enumerate()
                {
                    let want = built_in.solve(control).unwrap();
                    plastic = plastic.max(want.0.plastic_points);
                    let got = plugged.solve_with(control, &mut counted).unwrap();
                    let case = format!("{boundary:?} {interface:?} {control:?}");
                    assert_eq!(got, want, "{case}");
                    assert_eq!(plugged.pressure(), built_in.pressure(), "{case}");
                    assert_eq!(plugged.gap(), built_in.gap(), "{case}");
                    assert!(counted.solves > k, "{case}");
                    assert_eq!(
                        plugged.frozen_set_stiffness().unwrap().0,
                        built_in.frozen_set_stiffness().unwrap().0,
                        "{case}"
                    );
                }
                assert_eq!(
                    plastic > 0,
                    interface != Interface::HardWall,
                    "{interface:?}"
                );
                let e = plugged.solve_with(Control::MeanPressure(0.02), &mut GivesUp);
                assert!(matches!(e, Err(SolveError::NoConvergence { .. })), "{e:?}");
                assert!(plugged.summary().is_none());
            }
        }
    }
}
