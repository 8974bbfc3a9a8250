//! [`Context`]: what every iteration of [`crate::bem`] works on — the problem, the
//! settings, the state of the last solve, the Fourier preconditioner, the stop flag and the
//! contact law — and the start and end every iteration shares (`check_stop`, `finish`).
//!
//! The solver ([`super::ContactSolver`], `solver.rs`) owns one context beside the
//! iterations' own fields and lends it to the iteration it runs ([`super::iteration`]); an
//! iteration reads [`ContactProblem`], writes [`SolverState`] (its pressure and gap, through
//! its own loop and [`Context::finish`]) and works in its own scratch only.

use super::interface::Interface;
use super::precondition::FourierPreconditioner;
use super::stagnation::Progress;
use super::threshold::FullContactThreshold;
use super::{ContactSummary, HalfSpace, SolveError, SolverParams};
use crate::elastic::{ContactOperator, ElasticOperator};
use crate::stop::Stop;
use crate::surface::Surface;
use crate::Error;
use ndarray::ArrayView2;

/// What an iteration holds fixed (a force is turned into its mean pressure).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Target {
    MeanPressure(f64),
    Indentation(f64),
}

/// What is solved: the indenter profile of one surface on a half-space, on a grid. Read by
/// every iteration; changed only by [`super::ContactSolver::set_surface`] (a new profile on
/// the same grid). The operator applies `K` in place of the half-space (its FFT buffers are
/// its own). `K` is the body's operator: the homogeneous half-space's by default, any
/// [`ContactOperator`] through [`super::ContactSolver::with_operator`].
pub struct ContactProblem<K: ContactOperator = ElasticOperator> {
    /// The half-space (modulus, boundary) on the grid and spacings of the surface.
    pub(super) operator: K,
    pub(super) rows: usize,
    pub(super) cols: usize,
    /// Indenter profile `f = max(h) − h ≥ 0`, row-major.
    pub(super) profile: Vec<f64>,
    /// rms height about the mean (1 for a flat surface), the residual's scale.
    pub(super) height_scale: f64,
}

impl ContactProblem {
    /// The problem of `surface` on `half_space` (plans the operator).
    pub(super) fn new(surface: &Surface, half_space: HalfSpace) -> Result<Self, SolveError> {
        let (rows, cols) = surface.dim();
        let operator = ElasticOperator::with_spacings(
            rows,
            cols,
            surface.spacing(),
            surface.spacing_y(),
            half_space.modulus,
            half_space.boundary,
        )?;
        ContactProblem::with_operator(surface, operator)
    }
}

impl<K: ContactOperator> ContactProblem<K> {
    /// The problem of `surface` on the body of `operator`, which must have the surface's
    /// grid and spacings.
    pub(super) fn with_operator(surface: &Surface, operator: K) -> Result<Self, SolveError> {
        let (rows, cols) = (operator.rows(), operator.cols());
        let mut problem = ContactProblem {
            operator,
            rows,
            cols,
            profile: Vec::with_capacity(rows * cols),
            height_scale: 1.0,
        };
        problem.set_surface(surface)?;
        Ok(problem)
    }

    /// Swaps in the profile of `surface`, which must have the grid and spacings of the
    /// problem (the operator is kept).
    pub(super) fn set_surface(&mut self, surface: &Surface) -> Result<(), SolveError> {
        let (dx, dy) = self.operator.spacings();
        if surface.dim() != (self.rows, self.cols)
            || surface.spacing() != dx
            || surface.spacing_y() != dy
        {
            return Err(Error::invalid(
                "surface",
                format!(
                    "the solver was planned for {}x{} points at spacings {} x {}, got {:?} at {} x {}",
                    self.rows,
                    self.cols,
                    dx,
                    dy,
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

    /// The body's operator (the half-space's, or the one given to
    /// [`super::ContactSolver::with_operator`]).
    pub fn operator(&self) -> &K {
        &self.operator
    }

    /// Pixel spacings `(Δx, Δy)`.
    pub fn spacings(&self) -> (f64, f64) {
        self.operator.spacings()
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
        let (dx, dy) = self.operator.spacings();
        (self.rows * self.cols) as f64 * dx * dy
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
/// the surface once known. Written by the solver's start (`ContactSolver::initialise`) and
/// the iterations (their loops and [`Context::finish`]); the stiffness and threshold code
/// reads the fields and only caches the threshold.
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
    pub(super) fn new(len: usize) -> Self {
        SolverState {
            pressure: vec![0.0; len],
            gap: vec![0.0; len],
            solved: None,
            full_contact: None,
        }
    }
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

/// Called with the count and the residual of every iteration of a BCCG or Polonsky–Keer
/// solve ([`super::ContactSolver::set_monitor`]): progress inside one long solve. `Send`
/// and `Sync` as the solver is (the Python binding shares it between threads).
pub type Monitor = Box<dyn FnMut(usize, f64) + Send + Sync>;

/// What the iterations work on (module docs): owned by the solver, lent to one iteration at
/// a time.
pub(super) struct Context<K: ContactOperator = ElasticOperator> {
    pub(super) problem: ContactProblem<K>,
    pub(super) params: SolverParams,
    pub(super) state: SolverState,
    /// `M ≈ K⁻¹` in Fourier space, for the BCCG and the frozen-set CG (read-only but for
    /// its own FFT buffer).
    pub(super) preconditioner: FourierPreconditioner,
    /// Polled once per iteration of every loop ([`super::ContactSolver::with_stop`]).
    pub(super) stop: Stop,
    /// The residuals of the running BCCG or Polonsky–Keer solve (`stagnation.rs`).
    pub(super) progress: Progress,
    /// Told of every iteration's residual, if set.
    pub(super) monitor: Option<Monitor>,
    /// What "in contact" means ([`super::ContactSolver::set_interface`]; the hard wall by
    /// default).
    pub(super) interface: Interface,
}

impl<K: ContactOperator> Context<K> {
    /// The residual of `iteration` of a BCCG or Polonsky–Keer solve, told to the monitor:
    /// [`SolveError::Stagnated`] where it has stopped decreasing (`stagnation.rs`).
    #[inline]
    pub(super) fn check_progress(
        &mut self,
        iteration: usize,
        residual: f64,
    ) -> Result<(), SolveError> {
        if let Some(monitor) = self.monitor.as_mut() {
            monitor(iteration, residual);
        }
        self.progress.observe(iteration, residual)
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
            force: mean_pressure * self.problem.nominal_area(),
            indentation,
            area_fraction: contact_points as f64 / n as f64,
            contact_points,
            plastic_fraction: plastic_points as f64 / n as f64,
            plastic_points,
        }
    }
}
