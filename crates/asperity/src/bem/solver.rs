//! [`ContactSolver`]: the solver core shared by the iterations of [`crate::bem`].
//!
//! A solver is made of named parts, each owned by one piece of code:
//! * [`ContactProblem`] — what is solved: the indenter profile `f = max(h) − h` of one
//!   surface and its height scale, the half-space (the [`ElasticOperator`], with its
//!   boundary, spacings and modulus) and the grid. Only [`ContactSolver::set_surface`]
//!   changes it; every other piece of code reads it (and applies its operator).
//! * `SolverState` — the state of the last solve: pressure, gap, the solved summary and
//!   the cached full-contact threshold. Its fields are written by the iterations only; the
//!   stiffness and threshold code reads them and keeps them intact (and caches the
//!   threshold).
//! * One scratch struct per algorithm, in its own file and used by no other:
//!   `BccgScratch` (`bccg.rs`, with the coarse correction of `mean_gap.rs`), `PkScratch`
//!   (`polonsky_keer.rs`), `StiffnessWork` (`stiffness/`: the frozen-set CG and the
//!   free-boundary threshold's CG) and `FullContactScratch` (`full_contact.rs`: the
//!   periodic threshold and the lower bound). Scratch that not every solver needs is
//!   allocated on first use and kept, so warm solves allocate nothing.
//! * The settings ([`SolverParams`]), the Fourier preconditioner shared read-only by the
//!   BCCG and the CGs, and the stop flag.
//!
//! [`ContactSolver::solve`] validates the control, refuses a periodic load or indentation
//! beyond full contact before solving, and dispatches to the chosen iteration
//! ([`SolverKind`]): `bccg.rs` or `polonsky_keer.rs`, each `(target, tolerance,
//! max_iterations)` in, `(ContactSummary, SolveInfo)` or a typed [`SolveError`] out. Shared
//! by both: the initial pressure (warm or cold start, `initialise`) and
//! the summary of a converged state (`finish`).
//!
//! **The contact law** is the solver's [`Interface`] (`interface.rs`, set by
//! [`ContactSolver::set_interface`]): every rule of what "in contact" means is asked of it
//! (the BCCG asks the constant hard wall). A new law that the existing iterations can solve
//! (as Polonsky–Keer solves the hardness cap, `plasticity.rs`) is a new variant there.
//!
//! **Extending the core** (an adhesive contact, say, which needs its own iteration): put the new
//! iteration in a file of its own with its scratch struct (`struct AdhesionScratch`), add
//! one `Option<AdhesionScratch>` field to [`ContactSolver`] allocated on the iteration's
//! first use (as `pk_scratch` is), a [`SolverKind`] variant dispatched in
//! [`ContactSolver::solve`], and the fields to [`ContactSolver::memory_bytes`]. The
//! iteration reads [`ContactProblem`], writes `SolverState` through `initialise`, its own
//! loop and `finish`, and works in its own scratch only: no other algorithm's fields change
//! meaning, and the stiffness and threshold code applies to its solved state unchanged.

use ndarray::{Array2, ArrayView2};

use super::bccg::BccgScratch;
use super::full_contact::{FullContactScratch, FullContactThreshold};
use super::interface::{restore_capped_load, Interface};
use super::polonsky_keer::PkScratch;
use super::preconditioner::{FourierPreconditioner, Real};
use super::small_set::SmallSet;
use super::stiffness::StiffnessWork;
use super::{
    ContactState, ContactSummary, Control, HalfSpace, SolveError, SolveInfo, SolverKind,
    SolverParams,
};
use crate::elastic::{Boundary, ElasticOperator};
use crate::pool::on_worker;
use crate::stop::Stop;
use crate::surface::Surface;
use crate::{memory, Error};

/// What an iteration holds fixed (a force is turned into its mean pressure).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Target {
    MeanPressure(f64),
    Indentation(f64),
}

/// What is solved: the indenter profile of one surface on a half-space, on a grid. Read by
/// every iteration; changed only by [`ContactSolver::set_surface`] (a new profile on the same
/// grid). The operator applies `K` in place of the half-space (its FFT buffers are its own).
pub struct ContactProblem {
    /// The half-space (modulus, boundary) on the grid and spacings of the surface.
    pub(super) operator: ElasticOperator,
    pub(super) rows: usize,
    pub(super) cols: usize,
    /// Indenter profile `f = max(h) − h ≥ 0`, row-major.
    pub(super) profile: Vec<f64>,
    /// rms height about the mean (1 for a flat surface), the residual's scale.
    pub(super) height_scale: f64,
}

impl ContactProblem {
    /// The problem of `surface` on `half_space` (plans the operator).
    fn new(surface: &Surface, half_space: HalfSpace) -> Result<Self, SolveError> {
        let (rows, cols) = surface.dim();
        let operator = ElasticOperator::with_spacings(
            rows,
            cols,
            surface.spacing(),
            surface.spacing_y(),
            half_space.modulus,
            half_space.boundary,
        )?;
        let mut profile = Vec::with_capacity(rows * cols);
        let height_scale = fill_profile(surface, &mut profile);
        Ok(ContactProblem {
            operator,
            rows,
            cols,
            profile,
            height_scale,
        })
    }

    /// Swaps in the profile of `surface`, which must have the grid and spacings of the
    /// problem (the operator is kept).
    fn set_surface(&mut self, surface: &Surface) -> Result<(), SolveError> {
        if surface.dim() != (self.rows, self.cols)
            || surface.spacing() != self.operator.spacing()
            || surface.spacing_y() != self.operator.spacing_y()
        {
            return Err(Error::invalid(
                "surface",
                format!(
                    "the solver was planned for {}x{} points at spacings {} x {}, got {:?} at {} x {}",
                    self.rows,
                    self.cols,
                    self.operator.spacing(),
                    self.operator.spacing_y(),
                    surface.dim(),
                    surface.spacing(),
                    surface.spacing_y()
                ),
            )
            .into());
        }
        self.height_scale = fill_profile(surface, &mut self.profile);
        Ok(())
    }

    /// `(rows, cols)` of the grid.
    pub fn dim(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Pixel spacings `(Δx, Δy)`.
    pub fn spacings(&self) -> (f64, f64) {
        (self.operator.spacing(), self.operator.spacing_y())
    }

    /// The half-space: effective modulus and boundary.
    pub fn half_space(&self) -> HalfSpace {
        HalfSpace {
            modulus: self.operator.modulus(),
            boundary: self.operator.boundary(),
        }
    }

    /// Nominal (projected) area `rows · cols · Δx · Δy`.
    pub fn nominal_area(&self) -> f64 {
        // Multiplied in this order so that square pixels give today's value bit for bit.
        (self.rows * self.cols) as f64 * self.operator.spacing() * self.operator.spacing_y()
    }

    /// The indenter profile `f = max(h) − h`, `rows × cols`.
    pub fn profile(&self) -> ArrayView2<'_, f64> {
        ArrayView2::from_shape((self.rows, self.cols), &self.profile)
            .expect("buffer has the grid's shape")
    }

    /// rms of the profile about its mean (1 for a flat surface): the scale of the
    /// residual.
    pub fn height_scale(&self) -> f64 {
        self.height_scale
    }
}

/// The state of the last solve: its fields and scalars, and the full-contact threshold of
/// the surface once known. Written by the iterations (through [`ContactSolver::initialise`]
/// and [`ContactSolver::finish`]); the stiffness and threshold code reads the fields and
/// only caches the threshold.
pub(super) struct SolverState {
    pub(super) pressure: Vec<f64>,
    /// `u` during an iteration, the gap `g` after a solve.
    pub(super) gap: Vec<f64>,
    /// The last solved state, if any (its pressure is in `pressure`).
    pub(super) solved: Option<ContactSummary>,
    /// Where the surface comes into full contact (computed once per surface, when first
    /// needed).
    pub(super) full_contact: Option<FullContactThreshold>,
}

impl SolverState {
    fn new(len: usize) -> Self {
        SolverState {
            pressure: vec![0.0; len],
            gap: vec![0.0; len],
            solved: None,
            full_contact: None,
        }
    }
}

/// A contact solver for one surface: the problem, the state of the last solve, and the
/// scratch of each algorithm, each its own (module docs); successive solves allocate
/// nothing and start from the previous pressure.
pub struct ContactSolver {
    pub(super) problem: ContactProblem,
    pub(super) params: SolverParams,
    pub(super) state: SolverState,
    /// `M ≈ K⁻¹` in Fourier space, for the BCCG and the frozen-set CG (read-only but for
    /// its own FFT buffer).
    pub(super) preconditioner: FourierPreconditioner,
    /// The BCCG's own fields (`bccg.rs`, with the coarse correction of `mean_gap.rs`).
    pub(super) bccg_scratch: BccgScratch,
    /// The Polonsky–Keer iteration's own fields (`polonsky_keer.rs`), allocated on its
    /// first solve.
    pub(super) pk_scratch: Option<PkScratch>,
    /// The fields of the frozen-set and free-boundary threshold CGs (`stiffness/`),
    /// allocated on first use.
    pub(super) stiffness_work: Option<StiffnessWork>,
    /// The fields of the periodic threshold and of the lower bound (`full_contact.rs`),
    /// allocated on first use.
    pub(super) full_contact_scratch: Option<FullContactScratch>,
    /// The dense fields of the direct solve of small contact sets (`small_set.rs`),
    /// allocated on first use.
    pub(super) small_set: Option<SmallSet>,
    /// Polled once per iteration of every loop ([`ContactSolver::with_stop`]).
    pub(super) stop: Stop,
    /// What "in contact" means ([`ContactSolver::set_interface`]; the hard wall by
    /// default).
    pub(super) interface: Interface,
    /// The permanent (plastic) displacement kept by
    /// [`ContactSolver::keep_plastic_displacement`], added to the profile; allocated on
    /// first use.
    pub(super) permanent: Option<Vec<f64>>,
}

/// Writes the indenter profile `f = h_max − h` (≥ 0, zero at the highest point) into
/// `profile` and returns its rms, the scale of the solver's height tolerances.
fn fill_profile(surface: &Surface, profile: &mut Vec<f64>) -> f64 {
    let heights = surface.heights();
    let top = heights.iter().fold(f64::NEG_INFINITY, |m, &h| m.max(h));
    profile.clear();
    profile.extend(heights.iter().map(|&h| top - h));
    let n = profile.len() as f64;
    let mean = profile.iter().sum::<f64>() / n;
    let rms = (profile.iter().map(|f| (f - mean).powi(2)).sum::<f64>() / n).sqrt();
    if rms > 0.0 {
        rms
    } else {
        1.0
    }
}

impl ContactSolver {
    /// Estimated peak memory of a solver for a `rows × cols` grid (bytes; `None` on
    /// overflow), an upper bound on what its parts hold once all have been used: the
    /// operator, its single-precision copy and the preconditioner; the profile, pressure
    /// and gap; the BCCG's five fields and its mask, with the rings of large grids one more
    /// field and eleven bytes per point (counts and lists); the Polonsky–Keer iteration's
    /// two; the six of the stiffness CG and its set's index list (on large grids its rings'
    /// field and twelve bytes per point); the two of the full-contact code (periodic: three
    /// more for the coarse correction of displacement control); the direct solve of small
    /// sets, a field of indices, a mask and its dense factor. The caller's [`Surface`] (one
    /// more `rows × cols` field while the solver is built) is not included.
    pub fn memory_bytes(rows: usize, cols: usize, boundary: Boundary) -> Option<u64> {
        // The masks and the rings' bytes (27 per point) count as four fields (rounding up);
        // periodic grids add the coarse correction's two fields and its mask (`mean_gap.rs`).
        let count = if boundary == Boundary::Periodic {
            29
        } else {
            26
        };
        let fields = memory::array_bytes(&[count, rows, cols], 8)?;
        let limit = super::small_set::limit(rows.checked_mul(cols)?);
        let factor = memory::array_bytes(&[limit + 3, limit], 8)?;
        ElasticOperator::memory_bytes(rows, cols, boundary)?
            .checked_add(ElasticOperator::single_precision_memory_bytes(
                rows, cols, boundary,
            )?)?
            .checked_add(FourierPreconditioner::<Real>::memory_bytes(rows, cols)?)?
            .checked_add(fields)?
            .checked_add(factor)
    }

    /// Plans a solver for `surface` on `half_space`; validates `params`, refuses grids that
    /// would not fit in memory.
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
            Self::memory_bytes(rows, cols, half_space.boundary),
        )?;
        let mut problem = ContactProblem::new(surface, half_space)?;
        let preconditioner = FourierPreconditioner::new(
            rows,
            cols,
            surface.spacing(),
            surface.spacing_y(),
            half_space.modulus,
        )?;
        let bccg_scratch = BccgScratch::new(&mut problem.operator)?;
        Ok(ContactSolver {
            problem,
            params,
            state: SolverState::new(rows * cols),
            preconditioner,
            bccg_scratch,
            pk_scratch: None,
            stiffness_work: None,
            full_contact_scratch: None,
            small_set: None,
            stop: Stop::new(),
            interface: Interface::HardWall,
            permanent: None,
        })
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
        self.stop = stop;
    }

    /// The stop flag polled by this solver (a clone shares it).
    pub fn stop(&self) -> &Stop {
        &self.stop
    }

    /// [`SolveError::Interrupted`] after `iterations` if a stop is requested.
    #[inline]
    pub(super) fn check_stop(&self, iterations: usize) -> Result<(), SolveError> {
        if self.stop.is_requested() {
            Err(SolveError::Interrupted { iterations })
        } else {
            Ok(())
        }
    }

    /// Swaps in another surface with the same grid and spacing, keeping the operator (FFT
    /// plans, kernel spectrum) and all buffers: how an ensemble solves many realisations.
    /// The next solve starts cold, exactly as with a new solver.
    pub fn set_surface(&mut self, surface: &Surface) -> Result<(), SolveError> {
        self.problem.set_surface(surface)?;
        self.permanent = None;
        self.state.pressure.fill(0.0);
        self.state.solved = None;
        self.state.full_contact = None;
        Ok(())
    }

    /// The parameters in use.
    pub fn params(&self) -> &SolverParams {
        &self.params
    }

    /// Replaces the parameters (validated).
    pub fn set_params(&mut self, params: SolverParams) -> Result<(), SolveError> {
        validate_params(&params)?;
        self.params = params;
        Ok(())
    }

    /// `(rows, cols)` of the grid.
    pub fn dim(&self) -> (usize, usize) {
        self.problem.dim()
    }

    /// Nominal (projected) area `rows · cols · Δx · Δy`.
    pub fn nominal_area(&self) -> f64 {
        self.problem.nominal_area()
    }

    /// What is solved: the surface's profile on the half-space, on the grid.
    pub fn problem(&self) -> &ContactProblem {
        &self.problem
    }

    /// Forgets the previous solution: the next solve starts cold.
    pub fn reset(&mut self) {
        self.state.solved = None;
    }

    /// The last solved state's scalars, if any.
    pub fn summary(&self) -> Option<ContactSummary> {
        self.state.solved
    }

    /// Solves the contact under `control`, starting from the previous solution when there
    /// is one (warm start). Fields of the result: [`ContactSolver::pressure`],
    /// [`ContactSolver::gap`], [`ContactSolver::state`].
    pub fn solve(&mut self, control: Control) -> Result<(ContactSummary, SolveInfo), SolveError> {
        let target = match control {
            Control::MeanPressure(p) => Target::MeanPressure(check_load("mean pressure", p)?),
            Control::Force(f) => {
                Target::MeanPressure(check_load("force", f)? / self.nominal_area())
            }
            Control::Indentation(d) => {
                if !(d.is_finite() && d >= 0.0) {
                    return Err(Error::invalid(
                        "indentation",
                        format!("must be finite and >= 0, got {d}"),
                    )
                    .into());
                }
                Target::Indentation(d)
            }
        };
        self.check_interface(target)?;
        let periodic = self.problem.operator.boundary() == Boundary::Periodic;
        if periodic {
            // Exact thresholds, known before solving: the mean pressure max(K⁺f) and, with
            // displacements of zero mean, the indentation mean(f).
            let full = self.periodic_full_contact();
            let beyond = match target {
                // (Not under a cap: the threshold is the elastic one, and a capped contact
                // may close at a lower load or stay open beyond it; a capped solution in
                // full contact without plastic points is refused after the solve.)
                Target::MeanPressure(_) if self.interface != Interface::HardWall => false,
                Target::MeanPressure(p) => p >= full.mean_pressure,
                // The mean gap mean(f) − d within the rounding of the sum mean(f) (n ulps)
                // is no gap: full contact. (Not under a cap: the plastic points stand
                // below the indenter, so the mean gap may be negative short of full
                // contact; a solution in full contact is refused after the solve.)
                Target::Indentation(_) if self.interface != Interface::HardWall => false,
                Target::Indentation(d) => full.indentation.is_some_and(|d_full| {
                    d >= d_full * (1.0 - self.problem.profile.len() as f64 * f64::EPSILON)
                }),
            };
            if beyond {
                self.state.solved = None;
                return Err(self.beyond_full_contact(control));
            }
        }
        let (tolerance, max_iterations) = (self.params.tolerance, self.params.max_iterations);
        // On a worker of the pool: the iteration's parallel passes are then forked, not
        // injected one by one, and the other workers wait for them awake (`pool.rs`).
        let parallelism = self.params.parallelism;
        let result = on_worker(parallelism, || match (self.params.solver, target) {
            (SolverKind::Bccg, Target::Indentation(d)) if periodic => {
                self.bccg_periodic_indentation(d)
            }
            (kind, Target::MeanPressure(p)) if self.interface != Interface::HardWall => {
                self.capped_load(kind, p, tolerance, max_iterations)
            }
            (SolverKind::Bccg, _) => self.bccg(target, tolerance, max_iterations),
            (SolverKind::PolonskyKeer, _) => self.polonsky_keer(target, tolerance, max_iterations),
        });
        match result {
            // Every point in contact, under load or displacement control: no contact
            // problem is left; refused with the threshold (free boundaries: only known
            // from the solution, periodic: checked above, this is rounding at p ≈ p*).
            // Under a cap a full contact with points at the cap is a contact problem still
            // (the plastic points flattened, the rest elastic): kept.
            Ok((summary, _))
                if summary.contact_points == self.problem.rows * self.problem.cols
                    && summary.plastic_points == 0 =>
            {
                self.state.solved = None;
                return Err(self.beyond_full_contact(control));
            }
            Ok((summary, _)) => self.state.solved = Some(summary),
            Err(_) => self.state.solved = None,
        }
        result
    }

    /// Refuses what the interface cannot solve: a mean pressure at or above the hardness.
    fn check_interface(&self, target: Target) -> Result<(), SolveError> {
        if let Target::MeanPressure(p) = target {
            self.interface.check_mean_pressure(p)?;
        }
        Ok(())
    }

    /// The error for a `requested` load or indentation that closes the gap everywhere, with
    /// the threshold in the same quantity where it is known.
    fn beyond_full_contact(&mut self, requested: Control) -> SolveError {
        let threshold = match self.problem.operator.boundary() {
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
        ArrayView2::from_shape((self.problem.rows, self.problem.cols), &self.state.pressure)
            .expect("buffer has the grid's shape")
    }

    /// Gap of the last solve, `rows × cols` (≥ 0, zero on the contact set).
    pub fn gap(&self) -> ArrayView2<'_, f64> {
        ArrayView2::from_shape((self.problem.rows, self.problem.cols), &self.state.gap)
            .expect("buffer has the grid's shape")
    }

    /// The last solved state with owned copies of its fields; the displacement is computed
    /// afresh (one operator application). `None` before a successful solve.
    pub fn state(&mut self) -> Option<ContactState> {
        let summary = self.state.solved?;
        let mut displacement = Array2::zeros((self.problem.rows, self.problem.cols));
        let out = displacement
            .as_slice_mut()
            .expect("a fresh array is contiguous");
        self.problem.operator.apply(&self.state.pressure, out);
        Some(ContactState {
            summary,
            pressure: self.pressure().to_owned(),
            gap: self.gap().to_owned(),
            displacement,
        })
    }

    /// Initial pressure: the continuation predictor when the last solve's frozen-set
    /// stiffness left its tangent (`stiffness/`), else the previous solution (rescaled to
    /// the new load) or a cold start (uniform pressure under load control; local springs
    /// `max(d − f, 0)/K₀₀` under displacement control).
    pub(super) fn initialise(&mut self, target: Target, self_influence: f64) {
        let n = (self.problem.rows * self.problem.cols) as f64;
        let warm = self.state.solved.is_some();
        if self.predict_from_tangent(target) {
            return;
        }
        match target {
            Target::MeanPressure(mean_pressure) => {
                let current = self.state.pressure.iter().sum::<f64>() / n;
                if warm && current > 0.0 {
                    let (scale, interface) = (mean_pressure / current, self.interface);
                    let cap = interface.cap();
                    if self.state.pressure.iter().any(|&p| p >= cap) {
                        // Points at the cap stay there, the others scaled (scaled down
                        // with the rest they would all leave the plastic set).
                        let (pressure, gap) = (&mut self.state.pressure, &self.state.gap);
                        let total = current * n;
                        restore_capped_load(pressure, (mean_pressure, cap), total, |i| gap[i]);
                        return;
                    }
                    // (The hard wall's projection of p·scale ≥ 0 is the identity.)
                    for p in self.state.pressure.iter_mut() {
                        *p = interface.project(*p * scale);
                    }
                } else {
                    self.state.pressure.fill(mean_pressure);
                }
            }
            Target::Indentation(d) => {
                let interface = self.interface;
                let any = self.state.pressure.iter().any(|&p| interface.in_contact(p));
                if !(warm && any) {
                    for (p, f) in self.state.pressure.iter_mut().zip(&self.problem.profile) {
                        *p = interface.project((d - f).max(0.0) / self_influence);
                    }
                }
            }
        }
    }

    /// Scalars of the converged state; the gap buffer is cleaned by the interface
    /// ([`Interface::clean_gap`]: `g ≥ 0`, zero on the contact set, its residual there
    /// being below the tolerance; at a hardness `g ≤ 0` on the capped points).
    pub(super) fn finish(&mut self, indentation: f64, contact_points: usize) -> ContactSummary {
        let interface = self.interface;
        let mut plastic_points = 0;
        for (g, &p) in self.state.gap.iter_mut().zip(&self.state.pressure) {
            *g = interface.clean_gap(p, *g);
            plastic_points += interface.plastic(p) as usize;
        }
        let n = self.problem.rows * self.problem.cols;
        let mean_pressure = self.state.pressure.iter().sum::<f64>() / n as f64;
        ContactSummary {
            mean_pressure,
            force: mean_pressure * self.nominal_area(),
            indentation,
            area_fraction: contact_points as f64 / n as f64,
            contact_points,
            plastic_fraction: plastic_points as f64 / n as f64,
            plastic_points,
        }
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
    use super::super::polonsky_keer::tests::rough_grid;
    use super::*;

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
}
