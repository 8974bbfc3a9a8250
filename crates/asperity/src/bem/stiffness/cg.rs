//! One conjugate gradient on a set: `K_SS x = b_S` for the restriction of a
//! [`HalfSpaceOperator`] `K` to a set `S` of grid points (`x` zero off the set), by
//! preconditioned conjugate gradients. The frozen-set stiffness (`K_SS x = 1_S`) and the
//! free-boundary full-contact threshold (`K x = f`, `K x = 1` on the whole grid) are its
//! callers today; a tangential stiffness is the next.
//!
//! In the style of faer's iterative solvers: [`CgParams`] in (a documented `Default`),
//! [`CgInfo`] out (iterations, relative residual, the energy `bᵀx`, why it stopped), a typed
//! [`CgError`] where it does not converge or is stopped.
//!
//! * The restriction `K_SS` of a symmetric positive definite operator is symmetric positive
//!   definite, and so is the preconditioner restricted to the set, `P_S M P_S`: CG applies
//!   unchanged. On grids of at least [`super::super::iterations::RING_MIN_POINTS`] points the
//!   residual is extended over two rings of the set before `M`,
//!   `P_S (I + E)ᵀ M (I + E) P_S`, as in the BCCG (`ring_extension.rs`), when the work was
//!   made with rings ([`CgWork::new`]).
//! * Stops at `‖r‖ ≤ tolerance ‖b‖` (the unpreconditioned residual), or, with
//!   [`CgParams::energy_error`], once the estimated relative error of the energy `bᵀx` is
//!   below it ([`EnergyEstimate`]): a quantity such as the stiffness `k ∝ 1ᵀx` converges with
//!   the square of the residual, and is reported from the estimate's sum (see `mod.rs`).
//! * No allocation: the set is listed once per solve (its indices, in a field of capacity
//!   the grid); every pass but the operator's and the preconditioner's visits only its
//!   points, in index order, and the sums run in a fixed order ([`sum4`]), so the result is
//!   the same for any thread count.
//!
//! ## Another operator
//!
//! [`conjugate_gradient_on_set`] is generic over the operator and the preconditioner. A
//! tangential (Cerruti) operator plugs in by implementing [`HalfSpaceOperator`] (its `apply`
//! maps a shear traction field to the tangential displacement, symmetric positive definite
//! on a set) and passing an approximate inverse that implements [`Preconditioner`] (for
//! Cerruti, the Fourier inverse of its symbol, as [`FourierPreconditioner`] is for the
//! normal kernel's `2/(E*|q|)`); the work fields come from [`CgWork::new`] for its grid:
//!
//! ```text
//! let mut work = CgWork::new(rows, cols, periodic, rings);
//! let info = conjugate_gradient_on_set(
//!     &mut cerruti, &mut cerruti_inverse, |i| stuck[i], RightHandSide::Ones,
//!     &mut work, (&CgParams::default(), &stop),
//! )?;
//! let tangential_stiffness = info.energy * dx * dy;
//! ```
//!
//! [`FourierPreconditioner`]: super::super::precondition::FourierPreconditioner

use super::super::precondition::Preconditioner;
use super::super::precondition::{RingExtension, Ringed};
use super::super::SolveError;
use crate::elastic::HalfSpaceOperator;
use crate::stop::Stop;
use crate::sum::sum4;

/// When the CG stops (faer-style parameters).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CgParams {
    /// Relative residual `‖r‖/‖b‖` (unpreconditioned) at which it has converged.
    /// Default `1e-10`, as the stiffness of `SolverParams`.
    pub tolerance: f64,
    /// If set, it has also converged once the estimated relative error of the energy
    /// `bᵀx` is at most this ([`EnergyEstimate`]). Default `None`: the residual only.
    pub energy_error: Option<f64>,
    /// Iterations before [`CgError::NoConvergence`]. Default `10_000`.
    pub max_iterations: usize,
}

impl Default for CgParams {
    fn default() -> Self {
        CgParams {
            tolerance: 1e-10,
            energy_error: None,
            max_iterations: 10_000,
        }
    }
}

/// Why a converged CG stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum CgTermination {
    /// The relative residual reached [`CgParams::tolerance`] (or `b` is zero on the set).
    Residual,
    /// The energy estimate reached [`CgParams::energy_error`] first.
    Energy,
}

/// What a converged CG reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CgInfo {
    /// CG iterations, one operator application each.
    pub iterations: usize,
    /// The final relative residual `‖r‖/‖b‖`.
    pub residual: f64,
    /// `bᵀx` accumulated step by step (`Σ α_i r_iᵀz_i`, [`EnergyEstimate`]): far more
    /// precise than `bᵀx` summed from the solution.
    pub energy: f64,
    /// Why it stopped.
    pub termination: CgTermination,
}

/// A CG that did not converge.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub(crate) enum CgError {
    /// Out of iterations, or the residual is no longer finite.
    #[error("the conjugate gradient did not converge in {iterations} iterations (relative residual {residual:e})")]
    NoConvergence {
        /// Iterations done.
        iterations: usize,
        /// Relative residual reached.
        residual: f64,
    },
    /// A curvature `sᵀKs` or `rᵀMr` that is not positive (round-off on a set where `K_SS`
    /// and `M_SS` are positive definite).
    #[error("the conjugate gradient broke down after {iterations} iterations (relative residual {residual:e})")]
    Breakdown {
        /// Iterations done, the failed one included.
        iterations: usize,
        /// Relative residual before the failed iteration.
        residual: f64,
    },
    /// A stop was requested.
    #[error("the conjugate gradient was interrupted after {iterations} iterations")]
    Interrupted {
        /// Iterations done before the stop.
        iterations: usize,
    },
}

impl From<CgError> for SolveError {
    /// A breakdown is a failure to converge for the solver's callers.
    fn from(error: CgError) -> Self {
        match error {
            CgError::NoConvergence {
                iterations,
                residual,
            }
            | CgError::Breakdown {
                iterations,
                residual,
            } => SolveError::NoConvergence {
                iterations,
                residual,
            },
            CgError::Interrupted { iterations } => SolveError::Interrupted { iterations },
        }
    }
}

/// Right-hand side of a CG on a set.
#[derive(Clone, Copy)]
pub(crate) enum RightHandSide<'a> {
    /// A uniform unit value on the set.
    Ones,
    /// Given values (read on the set only).
    Values(&'a [f64]),
}

/// Where a CG on a set starts.
#[derive(Clone, Copy)]
pub(crate) enum Start<'a> {
    /// `x₀ = 0` (`r₀ = b`).
    Zero,
    /// `x₀` given (read on the set only): one more operator application for
    /// `r₀ = b − K x₀`; the energy is then `bᵀx₀ + x₀ᵀr₀` plus the CG's sum for the
    /// correction (`bᵀx = bᵀx₀ + x₀ᵀr₀ + r₀ᵀK⁻¹r₀` with `K` symmetric).
    From(&'a [f64]),
    /// `x₀` = the work's unknown as the previous solve on the same set and right-hand side
    /// left it (one computed with a cheaper, less precise operator: the tangential CGs'
    /// single-precision pass): one application for `r₀ = b − K x₀` and the energy base
    /// `bᵀx₀ + x₀ᵀr₀` as for [`Start::From`], exact to second order in `r₀`. The remainder
    /// `r₀ᵀK⁻¹r₀` is then of the order of the cheaper operator's rounding squared, and the
    /// energy estimate looks back one step instead of [`ENERGY_DELAY`]: the CG stops once
    /// its last step moved `bᵀx` by at most [`CgParams::energy_error`] of it (what is left
    /// falls geometrically, at the CG's rate, from there).
    Refine,
}

/// The fields of a CG on a set, allocated once for a grid.
pub(crate) struct CgWork {
    /// The CG's unknown: the solution, zero off the set, after a solve.
    pub x: Vec<f64>,
    residual: Vec<f64>,
    preconditioned: Vec<f64>,
    direction: Vec<f64>,
    response: Vec<f64>,
    /// The indices of the set, ascending (capacity: the grid).
    set: Vec<usize>,
    /// The rings around the set that extend the residual before the preconditioner, with
    /// the set as a mask.
    rings: Option<(RingExtension, Vec<bool>)>,
}

impl CgWork {
    /// The fields for a `rows × cols` grid (periodic or free), with the rings if `rings`.
    pub(crate) fn new(rows: usize, cols: usize, periodic: bool, rings: bool) -> Self {
        let len = rows * cols;
        CgWork {
            x: vec![0.0; len],
            residual: vec![0.0; len],
            preconditioned: vec![0.0; len],
            direction: vec![0.0; len],
            response: vec![0.0; len],
            set: Vec::with_capacity(len),
            rings: rings.then(|| (RingExtension::new(rows, cols, periodic), vec![false; len])),
        }
    }

    /// The fields for the grid of `operator`.
    pub(crate) fn for_operator(operator: &impl HalfSpaceOperator, rings: bool) -> Self {
        let periodic = operator.boundary() == crate::elastic::Boundary::Periodic;
        Self::new(operator.rows(), operator.cols(), periodic, rings)
    }
}

/// `z = M r`, or with the rings `(I + E)ᵀ M (I + E) r` ([`Ringed`] decorating `M`; read on
/// the set only: the CG never uses `z` off it; `r` is zero off the set); returns `rᵀz` on
/// the set (summed by [`sum4`], in a fixed order).
fn precondition_on_set<M: Preconditioner + ?Sized>(
    preconditioner: &mut M,
    rings: Option<&mut (RingExtension, Vec<bool>)>,
    set: &[usize],
    (residual, z): (&[f64], &mut Vec<f64>),
) -> f64 {
    match rings {
        Some((rings, on_set)) => Ringed {
            inner: preconditioner,
            rings,
            set: on_set,
        }
        .apply_into(residual, z),
        None => preconditioner.apply_into(residual, z),
    }
    sum4(set.len(), |k| residual[set[k]] * z[set[k]])
}

/// Iterations over which [`EnergyEstimate`] sums the decrease of the error (a delay of a
/// few iterations, as Strakoš & Tichý use; a longer one only delays the stop).
const ENERGY_DELAY: usize = 4;

/// The error of `bᵀx_j` in CG from `x₀ = 0`, estimated as it runs. In exact arithmetic
/// `bᵀx − bᵀx_j` is the energy norm `‖x − x_j‖²_K` of the error (`x_jᵀr_j = 0`), which falls
/// by exactly `α_i r_iᵀz_i` at step `i` (Hestenes & Stiefel 1952): so `bᵀx` is the sum of
/// those terms, and the last [`ENERGY_DELAY`] of them add up to `‖e_{j−d}‖² − ‖e_j‖²`, a
/// lower bound of the error `d` steps ago, close to it as soon as CG converges. Both hold in
/// floating point (Strakoš & Tichý, ETNA 13:56–80, 2002), where `bᵀx_j` summed from `x_j`
/// does not (it is off by the order of the residual). The frozen-set stiffness `k = 1ᵀx`
/// needs no more: its CG stops when `k` is known to the estimate's precision, where the
/// residual criterion would go on until `x` is.
struct EnergyEstimate {
    /// `Σ α_i r_iᵀz_i` so far (after the base of a given start, [`Start::From`]), `bᵀx_j`
    /// in exact arithmetic.
    total: f64,
    /// The last [`ENERGY_DELAY`] terms (cyclic).
    recent: [f64; ENERGY_DELAY],
    steps: usize,
    /// The steps the estimate sums: [`ENERGY_DELAY`], or 1 after a [`Start::Refine`].
    delay: usize,
}

impl EnergyEstimate {
    /// From `bᵀx₀ + x₀ᵀr₀` (zero from `x₀ = 0`), over the last `delay` (1 to
    /// [`ENERGY_DELAY`]) steps.
    fn new(base: f64, delay: usize) -> Self {
        EnergyEstimate {
            total: base,
            recent: [0.0; ENERGY_DELAY],
            steps: 0,
            delay: delay.clamp(1, ENERGY_DELAY),
        }
    }

    /// Records the step `α r_iᵀz_i`.
    fn add(&mut self, alpha: f64, rz: f64) {
        let term = alpha * rz;
        self.total += term;
        self.recent[self.steps % ENERGY_DELAY] = term;
        self.steps += 1;
    }

    /// Whether the last `delay` steps moved `bᵀx` by at most `relative` of it.
    fn converged(&self, relative: f64) -> bool {
        if self.steps < self.delay {
            return false;
        }
        // All of them in index order (the sum of before `delay`), or the last `delay`.
        let moved = match self.delay {
            ENERGY_DELAY => self.recent.iter().sum::<f64>(),
            d => (0..d)
                .map(|j| self.recent[(self.steps - 1 - j) % ENERGY_DELAY])
                .sum(),
        };
        moved <= relative * self.total.abs()
    }
}

/// `x = x₀`, `r = b − K x₀` on the set (zero off it), from `x₀` given ([`Start::From`]) or,
/// with `None`, the work's own `x` ([`Start::Refine`]); returns `‖b‖²`, `‖r₀‖²` and the
/// energy base `bᵀx₀ + x₀ᵀr₀`.
fn start_from<A: HalfSpaceOperator + ?Sized>(
    operator: &mut A,
    work: &mut CgWork,
    rhs: RightHandSide<'_>,
    x0: Option<&[f64]>,
) -> (f64, f64, f64) {
    let CgWork {
        x,
        residual,
        response,
        set,
        ..
    } = work;
    // x off the set is zero: after `start_on_set`, or as the previous solve left it.
    let bb = match x0 {
        Some(x0) => {
            let bb = start_on_set((x, residual), set, rhs);
            set.iter().for_each(|&i| x[i] = x0[i]);
            bb
        }
        None => rhs_on_set(residual, set, rhs),
    };
    operator.apply(x, response);
    for &i in set.iter() {
        residual[i] -= response[i];
    }
    let rr = sum4(set.len(), |k| residual[set[k]] * residual[set[k]]);
    // bᵀx₀ = (r₀ + K x₀)ᵀx₀ on the set.
    let base = sum4(set.len(), |k| {
        let i = set[k];
        x[i] * (2.0 * residual[i] + response[i])
    });
    (bb, rr, base)
}

/// `x = 0`, `r = b` on the set (zero off it); returns `‖b‖²`.
fn start_on_set(
    (x, residual): (&mut [f64], &mut [f64]),
    set: &[usize],
    rhs: RightHandSide<'_>,
) -> f64 {
    x.fill(0.0);
    rhs_on_set(residual, set, rhs)
}

/// `r = b` on the set (zero off it); returns `‖b‖²`.
fn rhs_on_set(residual: &mut [f64], set: &[usize], rhs: RightHandSide<'_>) -> f64 {
    residual.fill(0.0);
    let mut rr = 0.0;
    for &i in set {
        let b = match rhs {
            RightHandSide::Ones => 1.0,
            RightHandSide::Values(v) => v[i],
        };
        residual[i] = b;
        rr += b * b;
    }
    rr
}

/// The end of a CG at relative residual `relative` after `iterations`, if it ends there:
/// converged (on the residual or on the estimate `energy`), out of iterations (or not
/// finite), or stopped.
fn finished(
    (relative, energy): (f64, &EnergyEstimate),
    iterations: usize,
    (params, stop): (&CgParams, &Stop),
) -> Option<Result<CgInfo, CgError>> {
    if stop.is_requested() {
        return Some(Err(CgError::Interrupted { iterations }));
    }
    let on_energy = params.energy_error.is_some_and(|e| energy.converged(e));
    let on_residual = relative <= params.tolerance;
    if relative.is_finite() && (on_residual || on_energy) {
        return Some(Ok(CgInfo {
            iterations,
            residual: relative,
            energy: energy.total,
            termination: match on_residual {
                true => CgTermination::Residual,
                false => CgTermination::Energy,
            },
        }));
    }
    if iterations >= params.max_iterations || !relative.is_finite() {
        return Some(Err(CgError::NoConvergence {
            iterations,
            residual: relative,
        }));
    }
    None
}

/// One CG step on the set: `w = K s`, `α = rz / sᵀw`, `x += α s`, `r −= α w`; returns the
/// new `‖r‖²` and `α`, or `None` when the curvature `sᵀw` or `rz` is not positive (`K_SS`
/// and `M_SS` are positive definite: round-off only).
fn step_on_set<A: HalfSpaceOperator + ?Sized>(
    operator: &mut A,
    work: &mut CgWork,
    rz: f64,
) -> Option<(f64, f64)> {
    let CgWork {
        x,
        residual,
        direction,
        response,
        set,
        ..
    } = work;
    operator.apply(direction, response);
    let curvature = sum4(set.len(), |k| direction[set[k]] * response[set[k]]);
    if !(curvature > 0.0 && rz > 0.0) {
        return None;
    }
    let alpha = rz / curvature;
    for &i in set.iter() {
        x[i] += alpha * direction[i];
        residual[i] -= alpha * response[i];
    }
    let rr = sum4(set.len(), |k| residual[set[k]] * residual[set[k]]);
    Some((rr, alpha))
}

/// Solves `K_SS x = b_S` on the set `S = {i : in_set(i)}` by preconditioned conjugate
/// gradients (module docs); the solution is in `work.x` (zero off the set), its energy
/// `bᵀx` in the info. `work` must be made for the operator's grid.
pub(crate) fn conjugate_gradient_on_set<A, M>(
    operator: &mut A,
    preconditioner: &mut M,
    in_set: impl Fn(usize) -> bool,
    rhs: RightHandSide<'_>,
    work: &mut CgWork,
    (params, stop): (&CgParams, &Stop),
) -> Result<CgInfo, CgError>
where
    A: HalfSpaceOperator + ?Sized,
    M: Preconditioner + ?Sized,
{
    let problem = (rhs, Start::Zero);
    conjugate_gradient_on_set_from(
        operator,
        preconditioner,
        in_set,
        problem,
        work,
        (params, stop),
    )
}

/// [`conjugate_gradient_on_set`] from `start`: with [`Start::From`] an initial guess `x₀`
/// (one more operator application; the energy and its estimate as from zero).
pub(crate) fn conjugate_gradient_on_set_from<A, M>(
    operator: &mut A,
    preconditioner: &mut M,
    in_set: impl Fn(usize) -> bool,
    (rhs, start): (RightHandSide<'_>, Start<'_>),
    work: &mut CgWork,
    (params, stop): (&CgParams, &Stop),
) -> Result<CgInfo, CgError>
where
    A: HalfSpaceOperator + ?Sized,
    M: Preconditioner + ?Sized,
{
    let n = work.x.len();
    assert_eq!(n, operator.len(), "the CG's fields are for another grid");
    work.set.clear();
    work.set.extend((0..n).filter(|&i| in_set(i)));
    // The rings of the set (none where the set is the whole grid), out of `work` while the
    // CG runs.
    let mut taken = work.rings.take();
    let mut rings = taken.as_mut().filter(|_| work.set.len() < n);
    if let Some((_, on_set)) = rings.as_mut() {
        on_set.fill(false);
        work.set.iter().for_each(|&i| on_set[i] = true);
    }
    let result = iterate_on_set(
        operator,
        (preconditioner, rings),
        (rhs, start),
        work,
        (params, stop),
    );
    work.rings = taken;
    result
}

/// The iterations of [`conjugate_gradient_on_set`] on the set listed in `work.set`.
fn iterate_on_set<A, M>(
    operator: &mut A,
    (preconditioner, mut rings): (&mut M, Option<&mut (RingExtension, Vec<bool>)>),
    (rhs, start): (RightHandSide<'_>, Start<'_>),
    work: &mut CgWork,
    limits: (&CgParams, &Stop),
) -> Result<CgInfo, CgError>
where
    A: HalfSpaceOperator + ?Sized,
    M: Preconditioner + ?Sized,
{
    let (bb, mut rr, base) = match start {
        Start::Zero => {
            let bb = start_on_set((&mut work.x, &mut work.residual), &work.set, rhs);
            (bb, bb, 0.0)
        }
        Start::From(x0) => start_from(operator, work, rhs, Some(x0)),
        Start::Refine => start_from(operator, work, rhs, None),
    };
    let b_norm = bb.sqrt();
    let mut rz = precondition_on_set(
        preconditioner,
        rings.as_deref_mut(),
        &work.set,
        (&work.residual, &mut work.preconditioned),
    );
    // The direction is zero off the set (the operator reads all of it).
    work.direction.fill(0.0);
    for &i in &work.set {
        work.direction[i] = work.preconditioned[i];
    }
    let mut iterations = 0;
    let delay = match start {
        Start::Refine => 1,
        Start::Zero | Start::From(_) => ENERGY_DELAY,
    };
    let mut energy = EnergyEstimate::new(base, delay);
    loop {
        let relative = if b_norm > 0.0 {
            rr.sqrt() / b_norm
        } else {
            0.0
        };
        if let Some(end) = finished((relative, &energy), iterations, limits) {
            return end;
        }
        iterations += 1;
        let alpha;
        (rr, alpha) = step_on_set(operator, work, rz).ok_or(CgError::Breakdown {
            iterations,
            residual: relative,
        })?;
        energy.add(alpha, rz);
        let rz_new = precondition_on_set(
            preconditioner,
            rings.as_deref_mut(),
            &work.set,
            (&work.residual, &mut work.preconditioned),
        );
        let beta = rz_new / rz;
        let (direction, z) = (&mut work.direction, &work.preconditioned);
        for &i in &work.set {
            direction[i] = z[i] + beta * direction[i];
        }
        rz = rz_new;
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::precondition::FourierPreconditioner;
    use super::*;
    use crate::elastic::{Boundary, ElasticOperator};

    /// A diagonal "operator" `K = diag(d)`: symmetric positive definite, not a half-space,
    /// to show that any [`HalfSpaceOperator`] plugs in (the solution is `b/d` exactly).
    struct Diagonal {
        d: Vec<f64>,
        cols: usize,
    }

    impl HalfSpaceOperator for Diagonal {
        fn rows(&self) -> usize {
            self.d.len() / self.cols
        }
        fn cols(&self) -> usize {
            self.cols
        }
        fn spacings(&self) -> (f64, f64) {
            (1.0, 1.0)
        }
        fn boundary(&self) -> Boundary {
            Boundary::Periodic
        }
        fn self_influence(&self) -> f64 {
            self.d[0]
        }
        fn apply(&mut self, load: &[f64], displacement: &mut [f64]) {
            for ((u, p), d) in displacement.iter_mut().zip(load).zip(&self.d) {
                *u = d * p;
            }
        }
        fn energy(&mut self, load: &[f64]) -> f64 {
            load.iter().zip(&self.d).map(|(p, d)| d * p * p).sum()
        }
    }

    /// No preconditioning.
    struct Identity;

    impl Preconditioner for Identity {
        fn apply_into(&mut self, input: &[f64], output: &mut [f64]) {
            output.copy_from_slice(input);
        }
        fn apply(&mut self, _: &mut [f64]) {}
        fn apply_centred(&mut self, x: &mut [f64], y: &mut [f64], (set, c): (&[bool], f64)) {
            y.iter_mut()
                .zip(x.iter().zip(set))
                .for_each(|(y, (&x, &on))| *y = if on { x - c } else { x });
        }
    }

    /// Solves the dense `K_SS x = b_S` by Gaussian elimination (the oracle), with `K` the
    /// columns of `operator` applied to unit loads.
    fn dense_solution(operator: &mut impl HalfSpaceOperator, set: &[usize], b: &[f64]) -> Vec<f64> {
        let (n, m) = (operator.len(), set.len());
        let (mut unit, mut column) = (vec![0.0; n], vec![0.0; n]);
        let mut a = vec![vec![0.0; m + 1]; m];
        for (c, &j) in set.iter().enumerate() {
            unit.fill(0.0);
            unit[j] = 1.0;
            operator.apply(&unit, &mut column);
            for (r, &i) in set.iter().enumerate() {
                a[r][c] = column[i];
            }
        }
        for (r, &i) in set.iter().enumerate() {
            a[r][m] = b[i];
        }
        for k in 0..m {
            let pivot = a[k].clone();
            for row in a.iter_mut().skip(k + 1) {
                let f = row[k] / pivot[k];
                row.iter_mut()
                    .zip(&pivot)
                    .skip(k)
                    .for_each(|(v, p)| *v -= f * p);
            }
        }
        let mut x = vec![0.0; m];
        for k in (0..m).rev() {
            let tail: f64 = (k + 1..m).map(|c| a[k][c] * x[c]).sum();
            x[k] = (a[k][m] - tail) / a[k][k];
        }
        x
    }

    #[test]
    fn solves_the_restricted_half_space_to_its_tolerance() {
        // Free and periodic operators on an odd, non-square grid, a scattered set of about
        // half the grid, with and without the rings: x agrees with the dense solve to the
        // CG's tolerance (relative residual 1e-12 → x to about 1e-10 of its size, through
        // the condition number of K_SS of a few hundred), and is zero off the set.
        let (rows, cols) = (9, 14);
        for boundary in [Boundary::Free, Boundary::Periodic] {
            for rings in [false, true] {
                let mut operator = ElasticOperator::new(rows, cols, 0.1, 1.3, boundary).unwrap();
                let mut m = FourierPreconditioner::<f32>::new(rows, cols, 0.1, 0.1, 1.3).unwrap();
                let in_set = |i: usize| !(i * 7 + i / 5).is_multiple_of(3);
                let set: Vec<usize> = (0..rows * cols).filter(|&i| in_set(i)).collect();
                let b: Vec<f64> = (0..rows * cols).map(|i| 1.0 + (i % 5) as f64).collect();
                let expected = dense_solution(&mut operator, &set, &b);
                let mut work = CgWork::for_operator(&operator, rings);
                let params = CgParams {
                    tolerance: 1e-12,
                    ..CgParams::default()
                };
                let info = conjugate_gradient_on_set(
                    &mut operator,
                    &mut m,
                    in_set,
                    RightHandSide::Values(&b),
                    &mut work,
                    (&params, &Stop::new()),
                )
                .unwrap();
                assert_eq!(info.termination, CgTermination::Residual);
                assert!(info.residual <= 1e-12 && info.iterations > 1, "{info:?}");
                let scale = expected.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                for (k, &i) in set.iter().enumerate() {
                    let error = (work.x[i] - expected[k]).abs() / scale;
                    assert!(error < 1e-9, "{boundary:?} rings {rings}: {error:e} at {i}");
                }
                assert!((0..rows * cols).all(|i| in_set(i) || work.x[i] == 0.0));
                // The energy bᵀx accumulated by the CG equals bᵀx of the dense solution.
                let btx: f64 = set.iter().zip(&expected).map(|(&i, x)| b[i] * x).sum();
                assert!(
                    (info.energy / btx - 1.0).abs() < 1e-12,
                    "{} {btx}",
                    info.energy
                );
            }
        }
    }

    #[test]
    fn another_operator_plugs_in() {
        // A diagonal K with distinct entries: CG without preconditioning needs one step per
        // distinct value on the set (here 4), and x = b/d.
        let d: Vec<f64> = (0..24).map(|i| 1.0 + (i % 4) as f64).collect();
        let mut operator = Diagonal {
            d: d.clone(),
            cols: 6,
        };
        let mut work = CgWork::new(4, 6, true, false);
        let info = conjugate_gradient_on_set(
            &mut operator,
            &mut Identity,
            |i| i != 5,
            RightHandSide::Ones,
            &mut work,
            (&CgParams::default(), &Stop::new()),
        )
        .unwrap();
        assert_eq!(info.iterations, 4);
        for (i, &di) in d.iter().enumerate() {
            let expected = if i == 5 { 0.0 } else { 1.0 / di };
            assert!((work.x[i] - expected).abs() < 1e-14, "{i}");
        }
    }

    #[test]
    fn refuses_to_report_what_did_not_converge() {
        let d: Vec<f64> = (0..24).map(|i| 1.0 + (i % 4) as f64).collect();
        let mut operator = Diagonal { d, cols: 6 };
        let mut work = CgWork::new(4, 6, true, false);
        let mut solve = |params: CgParams, stop: &Stop| {
            conjugate_gradient_on_set(
                &mut operator,
                &mut Identity,
                |_| true,
                RightHandSide::Ones,
                &mut work,
                (&params, stop),
            )
        };
        let few = CgParams {
            max_iterations: 2,
            ..CgParams::default()
        };
        match solve(few, &Stop::new()) {
            Err(CgError::NoConvergence {
                iterations: 2,
                residual,
            }) => assert!(residual > 1e-10, "{residual}"),
            other => panic!("expected no convergence, got {other:?}"),
        }
        let stop = Stop::new();
        stop.request();
        assert_eq!(
            solve(CgParams::default(), &stop),
            Err(CgError::Interrupted { iterations: 0 })
        );
        // The solver's callers see the errors as the solve's.
        let error = SolveError::from(CgError::Breakdown {
            iterations: 3,
            residual: 0.5,
        });
        assert!(matches!(
            error,
            SolveError::NoConvergence { iterations: 3, .. }
        ));
    }
}
