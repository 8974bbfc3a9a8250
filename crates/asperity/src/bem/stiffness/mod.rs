//! Contact stiffness of a solved state.
//!
//! * [`ContactSolver::frozen_set_stiffness`] — the paper's method (*Methods*, "BEM
//!   calculations"): keep the contact set `S` of the solved state, impose a uniform extra
//!   displacement `Δd` on it and solve `K_SS Δp = Δd · 1_S` for the pressures on the set
//!   (the restriction of the elastic operator to `S` is symmetric positive definite, so
//!   plain conjugate gradients apply); `k = ΔF/Δd = Δ² Σ Δp / Δd`. It depends on the set
//!   only, not on the topography. With `x = K_SS⁻¹ 1_S`, `k = Δ² 1ᵀx` is the energy
//!   `xᵀK_SS x` of the CG's solution, which the CG accumulates step by step (`Σ α_i r_iᵀz_i`,
//!   Hestenes & Stiefel 1952) and which converges with the square of the residual: the CG
//!   stops once its last steps moved it by less than `SolverParams::stiffness_error`
//!   ([`EnergyEstimate`]; measured at 128² and 512², k within 1.5e-14 of a CG to residual
//!   1e-13, in 35–40 % fewer iterations than that CG and 7–19 % fewer than the residual
//!   1e-10 of before), and reports `k` from it, not from `Σ x_j`, whose rounding error is of
//!   the order of the residual (1e-10 at a residual of 1e-7).
//! * [`ContactSolver::finite_difference_stiffness`] — `dF/dd` by central differences of two
//!   more solves. By Barber's theorem (J. R. Barber, Proc. R. Soc. A 459, 2003) the two are
//!   equal as long as the contact set does not change within the step.
//!
//! The same CG on the full grid gives the indentation and mean pressure at which a
//! free-boundary surface comes into full contact: with `q = K⁻¹ 1` (a flat punch the size of
//! the grid) and `y = K⁻¹ f`, the pressure `d q − y` is non-negative everywhere from
//! `d* = max(y/q)` on.
//!
//! Both are the one conjugate gradient on a set of [`cg`] (generic over the
//! [`crate::elastic::HalfSpaceOperator`], faer-style `CgParams`/`CgInfo`/`CgError`), with
//! the solver's elastic operator. Both CGs are preconditioned with the Fourier approximate inverse of the operator
//! restricted to the set (`P_S M P_S`, [`super::preconditioner`]); on grids of at least
//! [`RING_MIN_POINTS`] points the residual is extended over two rings of the set first,
//! `P_S (I + E)ᵀ M (I + E) P_S`, as in the BCCG ([`super::ring_extension`]: 25–30 % fewer
//! iterations on study samples at 512² and 1024², 8–16 % less time). Neither allocates after
//! the first call: the set is listed once per CG (its indices, in a field of capacity the
//! grid) and every pass but the two transforms visits only its points, in index order, so
//! the sums are those of a full pass; the CG works in fields of its own ([`StiffnessWork`]),
//! so neither touches the solved state.
//!
//! The frozen-set solution `x = K_SS⁻¹ 1_S` is also the tangent `dp/dd` of the solved state
//! along its contact set: the next warm solve starts from `p + Δd x`
//! ([`ContactSolver::predict_from_tangent`], a continuation predictor), which is the next
//! state exactly as long as the set does not change.

pub(crate) mod cg;
pub(super) mod work;

use super::context::Target;
use super::interface::Interface;
use super::iterations::small_set;
use super::iterations::RING_MIN_POINTS;
use super::solver::ContactSolver;
use super::threshold::FullContactThreshold;
use super::{Control, SolveError, SolveInfo};
use crate::elastic::{Boundary, ContactOperator};
use crate::Error;
use cg::{
    conjugate_gradient_on_set, conjugate_gradient_on_set_from, CgError, CgInfo, CgParams,
    RightHandSide, Start,
};
use work::StiffnessWork;

/// Grids of at least this many points with free boundaries make the frozen-set CG's first
/// pass in single precision (`ContactSolver::frozen_set_cg`): those where it was measured
/// to pay (512² to 2048², docs/performance.md). Smaller grids and periodic ones keep the
/// all-`f64` CG and its bits.
pub(in crate::bem) const SINGLE_STIFFNESS_MIN_POINTS: usize = RING_MIN_POINTS;

/// The power of two by which the threshold's CG divides the profile `f`: 1 where its
/// largest value lies within 2^±64 (so the usual bits), else the power of two nearest it
/// (exact either way), so that sums of `f²` neither underflow nor overflow. (Not the rms
/// height: its own sum of squares underflows first.)
fn profile_unit(profile: &[f64]) -> f64 {
    let peak = profile.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let exponent = peak.log2().round();
    if peak > 0.0 && peak.is_finite() && exponent.abs() > 64.0 {
        2f64.powi(exponent as i32)
    } else {
        1.0
    }
}

/// The CG's info as the solver reports it.
fn solve_info(info: &CgInfo) -> SolveInfo {
    SolveInfo {
        iterations: info.iterations,
        residual: info.residual,
        operator_applications: info.iterations,
        energy_transforms: 0,
    }
}

impl<K: ContactOperator> ContactSolver<K> {
    fn stiffness_work(&mut self) -> StiffnessWork {
        let operator = &self.cx.problem.operator;
        let rings = operator.rows() * operator.cols() >= RING_MIN_POINTS;
        self.stiffness_work
            .take()
            .unwrap_or_else(|| StiffnessWork::new(operator, rings))
    }

    /// Contact stiffness `k = ΔF/Δd` of the last solved state by the frozen contact set
    /// (see the module docs), with the CG's iterations and relative residual. Zero when
    /// nothing is in contact.
    pub fn frozen_set_stiffness(&mut self) -> Result<(f64, SolveInfo), SolveError> {
        if self.cx.state.solved.is_none() {
            return Err(Error::invalid("stiffness", "no solved contact state yet").into());
        }
        let (tolerance, max_iterations) = (
            self.cx.params.stiffness_tolerance,
            self.cx.params.stiffness_max_iterations,
        );
        // On a worker of the pool, as the solves (`pool.rs`).
        crate::pool::on_worker(self.cx.params.parallelism, || {
            self.set_stiffness(tolerance, max_iterations)
        })
    }

    /// The frozen-set stiffness of the current pressure's contact set, by CG to `tolerance`
    /// relative residual in at most `max_iterations` iterations.
    pub(super) fn set_stiffness(
        &mut self,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<(f64, SolveInfo), SolveError> {
        let mut work = self.stiffness_work();
        // A set solved directly (`small_set.rs`) has its x already (a stop request goes to
        // the CG, which reports it).
        // (The direct solve knows the hard wall's set only: not where a point is plastic.)
        let interface = self.cx.interface;
        let plastic = interface != Interface::HardWall
            && self.cx.state.pressure.iter().any(|&p| interface.plastic(p));
        let direct = match self.cx.stop.is_requested() || plastic {
            true => None,
            false => small_set::tangent(
                self.bccg_scratch.small_set.as_ref(),
                &self.bccg_scratch.impulse,
                &self.cx.state.pressure,
                (tolerance, &mut work.cg.x),
            ),
        };
        // k = 1ᵀx: from a CG its energy, which converges with the square of the residual
        // where 1ᵀx_j, summed, carries an error of the order of the residual (measured at
        // 64², 713 points: 1e-10 at a residual of 1e-7, against 1e-15 for the energy).
        let result = match direct {
            Some(residual) => Ok((
                SolveInfo {
                    iterations: 0,
                    residual,
                    operator_applications: 0,
                    energy_transforms: 0,
                },
                work.cg.x.iter().sum::<f64>(),
            )),
            None => {
                let params = CgParams {
                    tolerance,
                    energy_error: Some(self.cx.params.stiffness_error).filter(|&e| e > 0.0),
                    max_iterations,
                };
                self.frozen_set_cg(&mut work, &params)
            }
        };
        let (dx, dy) = self.cx.problem.operator.spacings();
        work.tangent = result.is_ok();
        self.stiffness_work = Some(work);
        result.map(|(info, ones_x)| (ones_x * dx * dy, info))
    }

    /// The frozen-set CG on the current pressure's set: `(info, 1ᵀx)`, `x` in `work`. On
    /// free grids of at least [`SINGLE_STIFFNESS_MIN_POINTS`] points (and operators whose scale
    /// `f32` holds) it runs first on the single-precision copy of the operator that the BCCG
    /// keeps, then is refined in double precision ([`Start::Refine`], as the tangential CGs:
    /// one `f64` application for the true residual and the energy `bᵀx₀ + x₀ᵀr₀`, then `f64`
    /// steps until the last one moved the energy by at most its error); where that pass
    /// fails the `f64` CG starts over from zero and decides alone. Elsewhere all in `f64`.
    fn frozen_set_cg(
        &mut self,
        work: &mut StiffnessWork,
        params: &CgParams,
    ) -> Result<(SolveInfo, f64), SolveError> {
        let (pressure, interface, stop) =
            (&self.cx.state.pressure, self.cx.interface, &self.cx.stop);
        let in_set = |i: usize| interface.elastic(pressure[i]);
        let operator = &mut self.cx.problem.operator;
        let scale = operator.self_influence();
        // Free boundaries only: on periodic grids the f32 pass measured no gain (0.92–1.34×,
        // noise; docs/performance.md), so they keep the all-f64 CG and its bits.
        let single_pass = self.single_precision_stiffness
            && operator.boundary() == Boundary::Free
            && operator.rows() * operator.cols() >= SINGLE_STIFFNESS_MIN_POINTS
            && scale > 2f64.powi(-40)
            && scale < 2f64.powi(40);
        let (mut single, mut start, mut refine) = (0, Start::Zero, 0);
        if single_pass {
            let singles = &mut self.bccg_scratch.single;
            match conjugate_gradient_on_set(
                singles,
                &mut self.cx.preconditioner,
                in_set,
                RightHandSide::Ones,
                &mut work.cg,
                (params, stop),
            ) {
                Ok(info) => (single, start, refine) = (info.iterations, Start::Refine, 1),
                Err(CgError::Interrupted { iterations }) => {
                    return Err(SolveError::Interrupted { iterations })
                }
                Err(
                    CgError::NoConvergence { iterations, .. }
                    | CgError::Breakdown { iterations, .. },
                ) => single = iterations,
            }
        }
        conjugate_gradient_on_set_from(
            operator,
            &mut self.cx.preconditioner,
            in_set,
            (RightHandSide::Ones, start),
            &mut work.cg,
            (params, stop),
        )
        .map(|info| {
            let mut solve = solve_info(&info);
            solve.iterations += single;
            solve.operator_applications += single + refine;
            (solve, info.energy)
        })
        .map_err(SolveError::from)
    }

    /// Whether the frozen-set CG of free grids of at least 2¹⁸ points (512² and up) makes its
    /// first pass in single precision (the default: yes; periodic grids never do); off, it runs all in
    /// double precision, bit for bit the CG of before (for comparisons: `asperity bench
    /// bem-solve` times both).
    pub fn set_single_precision_stiffness(&mut self, on: bool) {
        self.single_precision_stiffness = on;
    }

    /// The frozen-set solution `x = K_SS⁻¹ 1_S` of the solved state (zero off the set), if
    /// the last frozen-set stiffness left it and no solve has used it since: the start of
    /// the tangential CGs (`tangential.rs`).
    pub(crate) fn frozen_set_solution(&self) -> Option<&[f64]> {
        let work = self.stiffness_work.as_ref()?;
        (work.tangent && self.cx.state.solved.is_some()).then_some(&work.cg.x[..])
    }

    /// The continuation predictor of a warm start: if the last frozen-set stiffness left
    /// the tangent `x = dp/dd = K_SS⁻¹ 1_S` of the solved state (and no solve used it
    /// yet), `p ← max(p + Δd x, 0)` with `Δd` the step to `target` (load control: the
    /// step that carries `Σ p` to the load, then `p` rescaled to it exactly). Exact for the
    /// next state as long as the contact set does not change, far closer than the
    /// previous pressure where it does. Under a cap it predicts only while the predicted
    /// peak stays below it ([`predicted_below_cap`]). Returns whether it predicted; the
    /// tangent is used up either way (the solve replaces the state it belongs to).
    pub(super) fn predict_from_tangent(&mut self, target: Target) -> bool {
        let Some(work) = self.stiffness_work.as_mut() else {
            return false;
        };
        let (Some(solved), true) = (self.cx.state.solved, std::mem::take(&mut work.tangent)) else {
            return false;
        };
        let cap = self.cx.interface.cap();
        let n = self.cx.state.pressure.len() as f64;
        let step = match target {
            Target::MeanPressure(mean_pressure) => {
                let x_sum: f64 = work.cg.x.iter().sum();
                let p_sum: f64 = self.cx.state.pressure.iter().sum();
                if !crate::is_positive_finite(x_sum) {
                    return false;
                }
                (mean_pressure * n - p_sum) / x_sum
            }
            Target::Indentation(d) => d - solved.indentation,
        };
        // Under a cap the tangent holds while no point reaches it: where the predicted peak
        // would (or a point is at it already), the previous pressure is the safer start.
        if cap.is_finite()
            && !predicted_below_cap(&self.cx.state.pressure, &work.cg.x, step, (target, cap))
        {
            return false;
        }
        let mut total = 0.0;
        for (p, &x) in self.cx.state.pressure.iter_mut().zip(&work.cg.x) {
            *p = (*p + step * x).max(0.0);
            total += *p;
        }
        if let Target::MeanPressure(mean_pressure) = target {
            if !crate::is_positive_finite(total) {
                return false;
            }
            let scale = mean_pressure * n / total;
            self.cx.state.pressure.iter_mut().for_each(|p| *p *= scale);
        }
        true
    }

    /// `dF/dd` by central differences around `control`: two solves at `control·(1 ± step)`
    /// (`0 < step < 1`), `k = (F₊ − F₋)/(d₊ − d₋)`. Leaves the solver in the upper state.
    pub fn finite_difference_stiffness(
        &mut self,
        control: Control,
        relative_step: f64,
    ) -> Result<f64, SolveError> {
        if !(relative_step > 0.0 && relative_step < 1.0) {
            return Err(Error::invalid(
                "relative step",
                format!(
                    "must lie in (0, 1), got {}",
                    crate::input::short_number(relative_step)
                ),
            )
            .into());
        }
        let scaled = |factor: f64| match control {
            Control::MeanPressure(p) => Control::MeanPressure(p * factor),
            Control::Force(f) => Control::Force(f * factor),
            Control::Indentation(d) => Control::Indentation(d * factor),
        };
        let (lower, _) = self.solve(scaled(1.0 - relative_step))?;
        let (upper, _) = self.solve(scaled(1.0 + relative_step))?;
        Ok((upper.force - lower.force) / (upper.indentation - lower.indentation))
    }

    /// Indentation `d*` and mean pressure at which the whole free-boundary grid is in
    /// contact (two CG solves on the full grid, see the module docs); computed once per
    /// surface. Works in the CG's own fields: the solved state is kept.
    pub(super) fn free_full_contact(&mut self) -> Result<FullContactThreshold, SolveError> {
        if let Some(full) = self
            .cx
            .state
            .full_contact
            .filter(|f| f.indentation.is_some())
        {
            return Ok(full);
        }
        let n = self.cx.problem.rows * self.cx.problem.cols;
        let mut work = self.stiffness_work();
        // The threshold's CGs overwrite the frozen-set solution.
        work.tangent = false;
        let (tolerance, max_iterations) = (
            self.cx.params.stiffness_tolerance,
            self.cx.params.stiffness_max_iterations,
        );
        // The threshold reads q and y point by point: the residual criterion only.
        let params = CgParams {
            tolerance,
            energy_error: None,
            max_iterations,
        };
        let limits = (&params, &self.cx.stop);
        // f in a unit that keeps the CG's sums of squares inside f64's range (heights
        // ×1e-200 underflowed them: a threshold of 0 was reported, issue 33 item 15).
        let unit = profile_unit(&self.cx.problem.profile);
        let scaled = work
            .profile_pressure
            .iter_mut()
            .zip(&self.cx.problem.profile);
        scaled.for_each(|(s, f)| *s = f / unit);
        // y = K⁻¹f first, kept aside; then q = K⁻¹1 stays in the CG's unknown.
        let result = conjugate_gradient_on_set(
            &mut self.cx.problem.operator,
            &mut self.cx.preconditioner,
            |_| true,
            RightHandSide::Values(&work.profile_pressure),
            &mut work.cg,
            limits,
        )
        .and_then(|_| {
            std::mem::swap(&mut work.cg.x, &mut work.profile_pressure);
            conjugate_gradient_on_set(
                &mut self.cx.problem.operator,
                &mut self.cx.preconditioner,
                |_| true,
                RightHandSide::Ones,
                &mut work.cg,
                limits,
            )
        })
        .map_err(SolveError::from)
        .map(|_| {
            let q_y = work.cg.x.iter().zip(work.profile_pressure.iter());
            let indentation = q_y
                .clone()
                .fold(f64::NEG_INFINITY, |m, (q, y)| m.max(y / q));
            let mean_pressure = q_y.map(|(q, y)| indentation * q - y).sum::<f64>() / n as f64;
            FullContactThreshold {
                mean_pressure: mean_pressure * unit,
                indentation: Some(indentation * unit),
            }
        });
        self.stiffness_work = Some(work);
        if let Ok(full) = result {
            self.cx.state.full_contact = Some(full);
        }
        result
    }
}

/// Whether the continuation predictor's pressure `max(p + step x, 0)` (under load control
/// rescaled to `target`'s load, as [`ContactSolver::predict_from_tangent`] does) stays below
/// `cap` at every point; false where it cannot be rescaled. Writes nothing.
fn predicted_below_cap(
    pressure: &[f64],
    x: &[f64],
    step: f64,
    (target, cap): (Target, f64),
) -> bool {
    let (mut total, mut peak) = (0.0, 0.0f64);
    for (&p, &x) in pressure.iter().zip(x) {
        let predicted = (p + step * x).max(0.0);
        total += predicted;
        peak = peak.max(predicted);
    }
    let scale = match target {
        Target::MeanPressure(mean_pressure) => mean_pressure * pressure.len() as f64 / total,
        Target::Indentation(_) => 1.0,
    };
    // (Rounding is monotone: the largest scaled pressure is the scaled peak.)
    scale.is_finite() && peak * scale < cap
}

#[cfg(test)]
mod tests {
    use super::super::{HalfSpace, SolverParams};
    use super::*;
    use crate::bem::iterations::polonsky_keer::tests::{rough, rough_grid, sphere};
    use crate::elastic::Boundary;
    use crate::reference::{FlatPunch, Hertz};
    use crate::surface::Surface;
    use ndarray::Array2;
    use std::f64::consts::PI;

    fn half_space(boundary: Boundary) -> HalfSpace {
        HalfSpace {
            modulus: 1.3,
            boundary,
        }
    }

    /// A solver with the default parameters, solved at `pressure` on the rough surface
    /// `rough_grid(rows, cols, seed)`.
    fn solved_rough(
        (rows, cols, seed): (usize, usize, u64),
        boundary: Boundary,
        pressure: f64,
    ) -> ContactSolver {
        let surface = rough_grid(rows, cols, seed);
        let mut solver =
            ContactSolver::new(&surface, half_space(boundary), SolverParams::default()).unwrap();
        solver.solve(Control::MeanPressure(pressure)).unwrap();
        solver
    }

    /// Grids the stiffness tests run on: even, odd, non-square.
    const GRIDS: [(usize, usize); 3] = [(64, 64), (63, 63), (50, 72)];

    #[test]
    fn frozen_set_equals_finite_difference_on_rough_surfaces() {
        // Barber: k = dF/dd. Central differences with ±1e-3 of the load; the contact set may
        // gain or lose a few points within the step (measured: 1e-5 free, 2e-4 periodic), so
        // 0.5 % here, tighter than the 2 % the issue asks for. Even, odd and non-square.
        let grids = [(96, 96), (95, 95), (80, 112)];
        for ((rows, cols), (boundary, pressure)) in grids
            .into_iter()
            .flat_map(|g| [(g, (Boundary::Free, 0.02)), (g, (Boundary::Periodic, 0.05))])
        {
            let mut solver = solved_rough((rows, cols, 11), boundary, pressure);
            let (frozen, _) = solver.frozen_set_stiffness().unwrap();
            let fd = solver
                .finite_difference_stiffness(Control::MeanPressure(pressure), 1e-3)
                .unwrap();
            let error = frozen / fd - 1.0;
            eprintln!(
                "{rows}x{cols} {boundary:?}: frozen {frozen:.6e}, fd {fd:.6e}, error {error:.2e}"
            );
            assert!(
                error.abs() < 0.005,
                "{rows}x{cols} {boundary:?}: frozen {frozen} vs fd {fd}"
            );
        }
    }

    /// The frozen-set stiffness of both precision tests below, and how each CG ran: on
    /// `rough_grid(512, 512, 11)` solved at `pressure`, first with the default switch
    /// (`default`), then with the single-precision pass switched off (`double`), and then
    /// Barber's dF/dd (central differences, ±1e-3 of the load) from that solved state.
    struct BothPrecisions {
        default: (f64, SolveInfo),
        double: (f64, SolveInfo),
        finite_difference: f64,
    }

    fn both_precisions(boundary: Boundary, pressure: f64) -> BothPrecisions {
        let (rows, cols) = (512, 512);
        assert!(rows * cols >= SINGLE_STIFFNESS_MIN_POINTS);
        let mut solver = solved_rough((rows, cols, 11), boundary, pressure);
        let default = solver.frozen_set_stiffness().unwrap();
        solver.set_single_precision_stiffness(false);
        let double = solver.frozen_set_stiffness().unwrap();
        solver.set_single_precision_stiffness(true);
        let finite_difference = solver
            .finite_difference_stiffness(Control::MeanPressure(pressure), 1e-3)
            .unwrap();
        BothPrecisions {
            default,
            double,
            finite_difference,
        }
    }

    #[test]
    fn single_precision_pass_gives_the_double_precision_stiffness() {
        // On free grids of at least SINGLE_STIFFNESS_MIN_POINTS points the frozen-set CG runs
        // on the f32 operator first and is refined in f64. Its stiffness must be the all-f64
        // CG's to their energy stops (each ends once a step moved the energy by at most
        // stiffness_error = 1e-12 of it, and what is left falls geometrically from there:
        // a few 1e-12 apart at most; the tangential CGs' same refinement measured 3.2e-13),
        // and Barber's dF/dd to the 0.5 % of the test above.
        let run = both_precisions(Boundary::Free, 0.02);
        let ((mixed, info), (double, info_f64)) = (run.default, run.double);
        // The f32 pass ran and was refined: one application (the refinement's start) more
        // than its iterations, both passes'.
        assert_eq!(info.operator_applications, info.iterations + 1);
        assert_eq!(info_f64.operator_applications, info_f64.iterations);
        let gap = (mixed / double - 1.0).abs();
        eprintln!(
            "k mixed / f64 - 1 = {gap:.2e}, iterations {} / {}",
            info.iterations, info_f64.iterations
        );
        assert!(gap < 1e-11, "{mixed} vs {double}");
        let fd = run.finite_difference;
        assert!((mixed / fd - 1.0).abs() < 5e-3, "{mixed} vs dF/dd {fd}");
    }

    #[test]
    fn periodic_grids_take_the_double_precision_stiffness_cg() {
        // The f32 first pass measured no gain on periodic grids (docs/performance.md), so
        // they run the all-f64 CG whatever the switch says: as many applications as
        // iterations (no refinement's start), and bit for bit the stiffness with the
        // single-precision pass switched off.
        let run = both_precisions(Boundary::Periodic, 0.05);
        let ((default, info), (double, info_f64)) = (run.default, run.double);
        assert_eq!(info.operator_applications, info.iterations);
        assert_eq!(info_f64.iterations, info.iterations);
        assert_eq!(default.to_bits(), double.to_bits(), "{default} vs {double}");
        let fd = run.finite_difference;
        assert!((default / fd - 1.0).abs() < 5e-3, "{default} vs dF/dd {fd}");
    }

    #[test]
    fn energy_stop_knows_the_stiffness_to_its_estimate() {
        // The default CG stops once its last iterations moved its energy bᵀx by at most
        // 1e-12 of it, and reports k from that energy: k agrees with a CG run to a relative
        // residual of 1e-13 to that 1e-12 (measured: 3e-16 at most), in fewer iterations.
        // Contact sets above the direct solve's limit (a few % to ~40 % of the grid).
        for ((rows, cols), boundary) in GRIDS
            .into_iter()
            .flat_map(|g| [(g, Boundary::Free), (g, Boundary::Periodic)])
        {
            for pressure in [0.05, 0.2] {
                let mut solver = solved_rough((rows, cols, 17), boundary, pressure);
                let (k, info) = solver.frozen_set_stiffness().unwrap();
                solver
                    .set_params(SolverParams {
                        stiffness_tolerance: 1e-13,
                        stiffness_error: 0.0,
                        ..SolverParams::default()
                    })
                    .unwrap();
                let (exact, reference) = solver.frozen_set_stiffness().unwrap();
                let error = k / exact - 1.0;
                eprintln!(
                    "{rows}x{cols} {boundary:?} p {pressure}: {} its (residual {:.1e}) vs {} \
                     its, error {error:.1e}",
                    info.iterations, info.residual, reference.iterations
                );
                assert!(reference.iterations > 0, "a set solved directly");
                assert!(
                    error.abs() <= 1e-12,
                    "{rows}x{cols} {boundary:?} {pressure}: {error}"
                );
                assert!(info.iterations < reference.iterations);
            }
        }
    }

    #[test]
    fn frozen_set_under_displacement_control_matches_finite_difference() {
        let surface = rough(64, 12);
        let mut solver = ContactSolver::new(
            &surface,
            half_space(Boundary::Free),
            SolverParams::default(),
        )
        .unwrap();
        let d = 0.01;
        solver.solve(Control::Indentation(d)).unwrap();
        let (frozen, _) = solver.frozen_set_stiffness().unwrap();
        let fd = solver
            .finite_difference_stiffness(Control::Indentation(d), 1e-3)
            .unwrap();
        assert!(
            (frozen / fd - 1.0).abs() < 0.02,
            "frozen {frozen} vs fd {fd}"
        );
    }

    #[test]
    fn periodic_frozen_set_under_displacement_control_matches_finite_difference() {
        // Periodic displacement control (zero-mean displacements): the frozen-set k after a
        // solve at d equals dF/dd from two more displacement-controlled solves at d(1 ± 1e-3)
        // (Barber), on even, odd and non-square grids; d is the indentation of light and
        // moderate loads (p̄/p* = 0.01 and 0.1, where d/mean(f) ≈ 0.6 and 0.9).
        for (rows, cols) in GRIDS {
            let surface = rough_grid(rows, cols, 14);
            let periodic = half_space(Boundary::Periodic);
            let mut load = ContactSolver::new(&surface, periodic, SolverParams::default()).unwrap();
            let p_star = match load.solve(Control::MeanPressure(1e6)) {
                Err(SolveError::BeyondFullContact {
                    full_contact: Some(p),
                    ..
                }) => p,
                other => panic!("expected BeyondFullContact, got {other:?}"),
            };
            for ratio in [0.01, 0.1] {
                let (s, _) = load.solve(Control::MeanPressure(ratio * p_star)).unwrap();
                let d = s.indentation;
                let mut solver =
                    ContactSolver::new(&surface, periodic, SolverParams::default()).unwrap();
                solver.solve(Control::Indentation(d)).unwrap();
                let (frozen, info) = solver.frozen_set_stiffness().unwrap();
                // Converged on k's energy estimate (1e-12) at residuals of about 1e-6.
                assert!(info.residual <= 1e-4);
                let fd = solver
                    .finite_difference_stiffness(Control::Indentation(d), 1e-3)
                    .unwrap();
                let error = frozen / fd - 1.0;
                eprintln!(
                    "periodic displacement control {rows}x{cols}, p/p* = {ratio}: frozen \
                     {frozen:.6e}, fd {fd:.6e}, error {error:.2e}"
                );
                assert!(
                    error.abs() < 0.02,
                    "{rows}x{cols} p/p* = {ratio}: frozen {frozen} vs fd {fd}"
                );
            }
        }
    }

    #[test]
    fn hertz_stiffness_is_two_e_a() {
        for (rows, cols) in GRIDS {
            let (size, radius) = (1.0, 2.0);
            let dx = size / cols as f64;
            let hertz = Hertz {
                radius,
                modulus: 1.3,
            };
            let d = (18.0 * dx).powi(2) / radius;
            let mut solver = ContactSolver::new(
                &sphere(rows, cols, size, radius),
                half_space(Boundary::Free),
                SolverParams::default(),
            )
            .unwrap();
            solver.solve(Control::Indentation(d)).unwrap();
            let (k, _) = solver.frozen_set_stiffness().unwrap();
            let error = k / hertz.stiffness(d) - 1.0;
            eprintln!("hertz stiffness {rows}x{cols}: error {error:.2e}");
            // The pixelated contact edge costs O(Δ/a) (measured 0.5 % at a = 18 pixels; see
            // the punch test for the 1/a convergence).
            assert!(error.abs() < 0.01, "{rows}x{cols}: k error {error:e}");
        }
    }

    /// A flat circular punch of radius `a_pixels` centred on a `rows × cols` grid (heights 0
    /// inside, far below outside) at d = 1e-3: relative error of k against 2E*a with the
    /// pixelated disk's area-equivalent radius.
    fn punch_stiffness_error(rows: usize, cols: usize, a_pixels: f64) -> f64 {
        let size = 1.0;
        let dx = size / cols as f64;
        let heights = Array2::from_shape_fn((rows, cols), |(i, j)| {
            let r = ((i as f64 - (rows / 2) as f64).hypot(j as f64 - (cols / 2) as f64)) * dx;
            if r <= a_pixels * dx {
                0.0
            } else {
                -1.0
            }
        });
        let surface = Surface::new(heights, size).unwrap();
        // The residual is measured in rms heights (≈ 0.4 here, 400 d): a tight tolerance so
        // that the solved force is k d to ~1e-9.
        let params = SolverParams {
            tolerance: 1e-11,
            ..SolverParams::default()
        };
        let mut solver = ContactSolver::new(&surface, half_space(Boundary::Free), params).unwrap();
        let (s, _) = solver.solve(Control::Indentation(1e-3)).unwrap();
        let (k, _) = solver.frozen_set_stiffness().unwrap();
        let a = (s.contact_points as f64 * dx * dx / PI).sqrt();
        let punch = FlatPunch {
            radius: a,
            modulus: 1.3,
        };
        // Under displacement control the punch's force is k d exactly.
        // Under displacement control the punch's force is k d exactly (measured 4e-10).
        assert!((s.force / (k * 1e-3) - 1.0).abs() < 1e-8);
        let error = k / punch.stiffness() - 1.0;
        eprintln!("punch {rows}x{cols}, a = {a_pixels} px: k error {error:.3e}");
        error
    }

    #[test]
    fn flat_punch_stiffness_is_two_e_a() {
        // k = 2E*a; the remaining discretisation error (the edge singularity averaged over a
        // pixel) shrinks like Δ/a: measured 0.65 % at a = 16 pixels and 0.33 % at 32.
        let coarse = punch_stiffness_error(64, 64, 16.0);
        let fine = punch_stiffness_error(128, 128, 32.0);
        assert!(coarse.abs() < 0.01, "{coarse}");
        assert!(fine.abs() < 0.005, "{fine}");
        assert!(fine.abs() < coarse.abs(), "{coarse} vs {fine}");
        // The same punch on an odd and a non-square grid (free boundaries: the same error).
        for (rows, cols) in GRIDS[1..].iter().copied() {
            let error = punch_stiffness_error(rows, cols, 16.0);
            assert!(error.abs() < 0.01, "{rows}x{cols}: {error}");
        }
    }

    #[test]
    fn stiffness_needs_a_solved_state() {
        let surface = rough(16, 13);
        let mut solver = ContactSolver::new(
            &surface,
            half_space(Boundary::Free),
            SolverParams::default(),
        )
        .unwrap();
        // Refused for the missing state (not for some other reason) ...
        match solver.frozen_set_stiffness() {
            Err(SolveError::Input(Error::InvalidParameter { name, reason })) => {
                assert_eq!(name, "stiffness");
                assert!(reason.contains("no solved contact state"), "{reason}");
            }
            other => panic!("expected the missing state to be named, got {other:?}"),
        }
        // ... and answered once a state is solved.
        solver.solve(Control::MeanPressure(0.01)).unwrap();
        let (stiffness, _) = solver.frozen_set_stiffness().unwrap();
        assert!(stiffness > 0.0, "{stiffness}");
    }

    #[test]
    fn finite_difference_step_must_lie_in_zero_one() {
        let surface = rough(16, 13);
        let mut solver = ContactSolver::new(
            &surface,
            half_space(Boundary::Free),
            SolverParams::default(),
        )
        .unwrap();
        for step in [0.0, 1.0, 1.5, -0.1, f64::NAN] {
            match solver.finite_difference_stiffness(Control::MeanPressure(0.01), step) {
                Err(SolveError::Input(Error::InvalidParameter { name, .. })) => {
                    assert_eq!(name, "relative step", "{step}");
                }
                other => panic!("step {step}: expected a refused step, got {other:?}"),
            }
        }
        // No solved state is needed: the two solves are its own.
        let k = solver
            .finite_difference_stiffness(Control::MeanPressure(0.01), 0.01)
            .unwrap();
        assert!(k.is_finite() && k > 0.0, "{k}");
    }
}
