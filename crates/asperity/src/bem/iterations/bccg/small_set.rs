//! Small contact sets solved directly: an active-set iteration with a dense Cholesky factor
//! of `K_SS`, checked on the whole grid by the operator.
//!
//! At the first loads of a study the contact set is a few to a few hundred points of a grid
//! of up to a million, and every BCCG or frozen-set CG iteration still costs a transform of
//! the whole grid. On a set `S` the contact problem is linear: the pressures that close the
//! gap on `S` solve `K_SS p_S = d 1_S − f_S`, so with `x = K_SS⁻¹ 1_S` and `y = K_SS⁻¹ f_S`
//! they are `p_S = d x − y`, and load control fixes `d = (P + Σ y)/Σ x` (`P = Σ p`).
//! The iteration (a primal active-set method; Nocedal & Wright, *Numerical Optimization*,
//! 2006, §16.5, with the whole violated set added at once as in a primal–dual active set
//! method, Hintermüller, Ito & Kunisch, SIAM J. Optim. 13, 2002):
//! 1. factor `K_SS` (Cholesky, row by row: a point added to the set borders the factor of
//!    the points before it, so growing the set costs only the new rows) and solve for
//!    `p_S`;
//! 2. drop the points with `p ≤ 0` and go back to 1;
//! 3. apply the operator to `p` (the one transform of an iteration) and add the points off
//!    the set whose gap is negative — all of them, or where many are (a set that carried
//!    the load on too few points) the deepest [`MIN_ENTERING`] or twice the set's size;
//!    none: done.
//!
//! The start is the predicted or warm set, or under load control from cold the highest
//! point. The iteration gives up — leaving a pressure that keeps the load, from which the
//! BCCG goes on (from cold: the uniform pressure) — when the set would outgrow [`limit`]
//! points (where a transform costs less than the factor), after [`MAX_SOLVES`]
//! factorisations, if the factor breaks down, or at once when more than
//! [`GIVE_UP_ENTERING`] limits' worth of points have a negative gap (a load far too large
//! for a small set; from cold a bound tells that before the check's operator
//! application, `highest_point_gives_up`). Its result is only a start: the
//! BCCG's own residual, on an exact `u`, decides convergence, and a converged dense
//! solution passes it with no iteration.
//!
//! The factor also holds the frozen-set stiffness of the solved state: `x` is `K_SS⁻¹ 1_S`
//! exactly, and `tangent` hands it to the stiffness code when
//! the set is still the solved state's (its residual checked against the stiffness
//! tolerance).

use crate::bem::context::{Context, Target};
use crate::bem::interface::Interface;
use crate::bem::SolveError;

/// The contact rule of the direct solve (it serves the BCCG, which solves the hard wall).
const WALL: Interface = Interface::HardWall;
use crate::elastic::{Boundary, ContactOperator};

/// Factorisations per solve after which the iteration gives up (the active set cycles).
const MAX_SOLVES: usize = 24;

/// Points that enter the set at once at least, where more are below the slack.
const MIN_ENTERING: usize = 16;

/// The iteration gives up at once when this many times [`limit`] points are below the
/// slack (a load far too large for a small set, as from cold at high loads).
const GIVE_UP_ENTERING: usize = 8;

/// Gaps above `−GAP_SLACK · tolerance · height_scale` off the set do not enter it (the
/// residual counts them, far below its tolerance; rounding must not add points).
const GAP_SLACK: f64 = 1e-2;

/// The largest set solved directly on a `len`-point grid: `|S|³ = 48 len log₂ len` (the
/// factor's `|S|³/3` flops against a transform's `len log₂ len`), between 32 and 1024
/// points. The constant is measured on study samples (docs/bem_history.md): 48 is about 4 % faster
/// than 24 and as fast as 96 at 64² and 128²; 24 and 96 are alike at 1024².
pub(in crate::bem) fn limit(len: usize) -> usize {
    let transform = len as f64 * (len.max(2) as f64).log2();
    ((48.0 * transform).cbrt() as usize).clamp(32, 1024)
}

/// `K` between grid points `a` and `b` of a `(rows, cols, periodic)` grid, from the
/// operator's response to a unit pressure on pixel `(0, 0)` (free boundaries at
/// `|Δi|, |Δj|`, periodic at the offsets modulo the grid).
fn kernel(
    impulse: &[f64],
    (rows, cols, periodic): (usize, usize, bool),
    a: usize,
    b: usize,
) -> f64 {
    let ((ai, aj), (bi, bj)) = ((a / cols, a % cols), (b / cols, b % cols));
    let (di, dj) = if periodic {
        ((ai + rows - bi) % rows, (aj + cols - bj) % cols)
    } else {
        (ai.abs_diff(bi), aj.abs_diff(bj))
    };
    impulse[di * cols + dj]
}

/// The dense fields of the iteration, allocated on first use for [`limit`] points.
pub(in crate::bem) struct SmallSet {
    /// The set's grid indices in the order of the factor's rows.
    set: Vec<usize>,
    /// Whether each grid point is in the set.
    member: Vec<bool>,
    /// The Cholesky factor `L` of `K_SS` (row-major, row `i` holds columns `0..=i` at
    /// `i · limit`).
    factor: Vec<f64>,
    /// Rows of `factor` that belong to the current set (a prefix).
    factored: usize,
    /// `x = K_SS⁻¹ 1_S`, `y = K_SS⁻¹ f_S` and the pressures `p_S`, in set order.
    x: Vec<f64>,
    y: Vec<f64>,
    pressure: Vec<f64>,
    /// The points below the slack off the set, before they are added (capacity: the
    /// grid).
    entering: Vec<usize>,
    /// Whether `x` belongs to the set of the last successful solve (for the stiffness).
    solved: bool,
    limit: usize,
    grid: (usize, usize, bool),
}

/// What the direct iteration left for the BCCG.
pub(in crate::bem) struct SmallSetRun {
    /// Operator applications (one per iteration).
    pub(in crate::bem) applications: usize,
    /// Whether the gap buffer holds `u = K p` for the pressure left.
    pub(in crate::bem) exact: bool,
}

impl SmallSet {
    fn new(rows: usize, cols: usize, periodic: bool) -> Self {
        let limit = limit(rows * cols);
        SmallSet {
            set: Vec::with_capacity(limit),
            member: vec![false; rows * cols],
            factor: vec![0.0; limit * limit],
            factored: 0,
            x: vec![0.0; limit],
            y: vec![0.0; limit],
            pressure: vec![0.0; limit],
            entering: Vec::with_capacity(rows * cols),
            solved: false,
            limit,
            grid: (rows, cols, periodic),
        }
    }

    /// Empties the set.
    fn clear(&mut self) {
        for &k in &self.set {
            self.member[k] = false;
        }
        self.set.clear();
        self.factored = 0;
        self.solved = false;
    }

    /// Adds grid point `k` (not yet in the set; room for it checked by the caller).
    fn push(&mut self, k: usize) {
        self.member[k] = true;
        self.set.push(k);
    }

    /// Extends the factor to the whole set by bordering: row `i` of `L` solves
    /// `L_{<i} l = K_{S_i, S_<i}`, its diagonal `√(K_ii − l·l)`. False if a pivot is not
    /// positive (rounding on a nearly dependent set).
    fn factorise(&mut self, impulse: &[f64]) -> bool {
        let (limit, grid, set) = (self.limit, self.grid, &self.set);
        for i in self.factored..set.len() {
            let (done, row) = self.factor.split_at_mut(i * limit);
            let row = &mut row[..=i];
            for j in 0..i {
                let l_j = &done[j * limit..j * limit + j];
                let dot: f64 = l_j.iter().zip(&row[..j]).map(|(a, b)| a * b).sum();
                row[j] = (kernel(impulse, grid, set[i], set[j]) - dot) / done[j * limit + j];
            }
            let squares: f64 = row[..i].iter().map(|l| l * l).sum();
            let pivot = kernel(impulse, grid, set[i], set[i]) - squares;
            if !crate::is_positive_finite(pivot) {
                self.factored = i;
                return false;
            }
            row[i] = pivot.sqrt();
        }
        self.factored = set.len();
        true
    }

    /// `out = K_SS⁻¹ out` with the factor (forward, then backward by rows).
    fn solve_in_place(&self, out: &mut [f64]) {
        let (limit, n) = (self.limit, self.set.len());
        for i in 0..n {
            let row = &self.factor[i * limit..i * limit + i];
            let dot: f64 = row.iter().zip(&out[..i]).map(|(a, b)| a * b).sum();
            out[i] = (out[i] - dot) / self.factor[i * limit + i];
        }
        for i in (0..n).rev() {
            out[i] /= self.factor[i * limit + i];
            let (head, tail) = out.split_at_mut(i);
            let xi = tail[0];
            for (o, l) in head.iter_mut().zip(&self.factor[i * limit..i * limit + i]) {
                *o -= l * xi;
            }
        }
    }

    /// `x`, `y` and the pressures on the set for `target` (`profile` = f; under load
    /// control `P = p̄ · len`, `len` the grid's points); returns `d`.
    fn pressures(&mut self, target: Target, profile: &[f64], len: usize) -> f64 {
        let n = self.set.len();
        let (mut x, mut y) = (std::mem::take(&mut self.x), std::mem::take(&mut self.y));
        x[..n].fill(1.0);
        for (y, &k) in y[..n].iter_mut().zip(&self.set) {
            *y = profile[k];
        }
        self.solve_in_place(&mut x);
        self.solve_in_place(&mut y);
        let d = match target {
            Target::MeanPressure(p) => {
                let (x_sum, y_sum): (f64, f64) = (x[..n].iter().sum(), y[..n].iter().sum());
                (p * len as f64 + y_sum) / x_sum
            }
            Target::Indentation(d) => d,
        };
        for ((p, x), y) in self.pressure[..n].iter_mut().zip(&x[..n]).zip(&y[..n]) {
            *p = d * x - y;
        }
        (self.x, self.y) = (x, y);
        d
    }

    /// Adds the points off the set whose gap (`gap(k)`) is below `−slack`: all of them, or
    /// the deepest [`MIN_ENTERING`] or twice the set's size, whichever is more (a set that
    /// carried the load on too few points sees much of the grid go below it). Marks the
    /// set solved if none is; false where the set would outgrow the limit.
    fn enter(&mut self, gap: impl Fn(usize) -> f64, slack: f64) -> bool {
        self.entering.clear();
        for (k, &member) in self.member.iter().enumerate() {
            if !member && gap(k) < -slack {
                self.entering.push(k);
            }
        }
        self.solved = self.entering.is_empty();
        let room = self.limit - self.set.len();
        if self.solved {
            return true;
        }
        if self.entering.len() > GIVE_UP_ENTERING * self.limit || room == 0 {
            return false;
        }
        let take = self
            .entering
            .len()
            .min(room)
            .min(MIN_ENTERING.max(2 * self.set.len()));
        if take < self.entering.len() {
            let deepest = |a: &usize, b: &usize| gap(*a).total_cmp(&gap(*b));
            self.entering.select_nth_unstable_by(take, deepest);
            self.entering.truncate(take);
            self.entering.sort_unstable();
        }
        for i in 0..self.entering.len() {
            let k = self.entering[i];
            self.push(k);
        }
        true
    }

    /// Drops the points whose pressure is not positive; returns how many. The factor
    /// keeps the rows before the first one dropped.
    fn drop_unloaded(&mut self) -> usize {
        let Some(first) = self.pressure[..self.set.len()]
            .iter()
            .position(|&p| p <= 0.0)
        else {
            return 0;
        };
        let mut kept = first;
        for i in first..self.set.len() {
            let k = self.set[i];
            if self.pressure[i] > 0.0 {
                self.set[kept] = k;
                self.pressure[kept] = self.pressure[i];
                kept += 1;
            } else {
                self.member[k] = false;
            }
        }
        let dropped = self.set.len() - kept;
        self.set.truncate(kept);
        self.factored = self.factored.min(first);
        dropped
    }
}

/// The highest point of the surface: the first index of the smallest profile value
/// (`f = 0` there), where a load from cold begins.
fn highest_point(profile: &[f64]) -> usize {
    (0..profile.len()).fold(0, |t, k| if profile[k] < profile[t] { k } else { t })
}

/// Runs the direct iteration from the start the solver left in `cx`, if its set is small
/// (module docs), in the fields of `slot` (allocated there on first use) with the operator's
/// impulse response `impulse`; leaves a pressure for the BCCG to finish. At most
/// `max_iterations` operator applications.
pub(in crate::bem) fn small_set_start<K: ContactOperator>(
    slot: &mut Option<SmallSet>,
    impulse: &[f64],
    cx: &mut Context<K>,
    (target, max_iterations): (Target, usize),
) -> Result<SmallSetRun, SolveError> {
    let (rows, cols) = (cx.problem.rows, cx.problem.cols);
    let len = rows * cols;
    let limit = limit(len);
    let start = cx
        .state
        .pressure
        .iter()
        .filter(|&&p| WALL.in_contact(p))
        .count();
    let cold_load = cx.state.solved.is_none() && matches!(target, Target::MeanPressure(_));
    // The direct solve knows the hard wall only: from a start with points at a cap
    // it would throw the plastic set away (`capped_load.rs` finishes a search there).
    let cap = cx.interface.cap();
    let plastic_start = cx.state.pressure.iter().any(|&p| p >= cap);
    if (start > limit && !cold_load) || plastic_start {
        return Ok(SmallSetRun {
            applications: 0,
            exact: false,
        });
    }
    if let Target::MeanPressure(p) = target {
        if start > limit && highest_point_gives_up(impulse, cx, (p, limit)) {
            // The first solve would give up: straight to the uniform start.
            cx.state.pressure.fill(p);
            return Ok(SmallSetRun {
                applications: 0,
                exact: false,
            });
        }
    }
    let periodic = cx.problem.operator.boundary() == Boundary::Periodic;
    let small = slot.get_or_insert_with(|| SmallSet::new(rows, cols, periodic));
    small.clear();
    if start > limit {
        small.push(highest_point(&cx.problem.profile));
    } else {
        for (k, &p) in cx.state.pressure.iter().enumerate() {
            if WALL.in_contact(p) {
                small.push(k);
            }
        }
    }
    let run = small_set_iterate(slot, impulse, cx, (target, max_iterations))?;
    let solved = slot.as_ref().is_some_and(|s| s.solved);
    match target {
        // Gave up from cold (a load too large for a small set): back to the uniform
        // start, a better one for the BCCG than a few loaded points.
        Target::MeanPressure(p) if start > limit && !solved => {
            cx.state.pressure.fill(p);
            Ok(SmallSetRun {
                applications: run.applications,
                exact: false,
            })
        }
        _ => Ok(run),
    }
}

/// Whether the direct iteration from cold would give up at its first check, known
/// without it: the whole load `P = n p̄` on the highest point (`f = 0`) indents it by
/// `d = K₀₀ P` and opens the gap `f(x) − P (K₀₀ − K(x))` elsewhere, which is below
/// `f(x) − P (K₀₀ − K_max)` with `K_max` the largest response off the loaded pixel. The
/// points where that bound is below the entering slack (less a margin for the rounding
/// of the transforms) would all enter: more than [`GIVE_UP_ENTERING`] limits of them
/// and the check, an operator application, would give up.
fn highest_point_gives_up<K: ContactOperator>(
    impulse: &[f64],
    cx: &Context<K>,
    (mean_pressure, limit): (f64, usize),
) -> bool {
    let load = mean_pressure * impulse.len() as f64;
    let largest_off = impulse[1..]
        .iter()
        .fold(f64::NEG_INFINITY, |m, &k| m.max(k));
    let opened = load * (impulse[0] - largest_off);
    let slack = GAP_SLACK * cx.params.tolerance * cx.problem.height_scale;
    let below = opened - slack - 1e-9 * load * impulse[0];
    let entering = cx.problem.profile.iter().filter(|&&f| f < below).count();
    // The highest point itself (f = 0) is on the set, not entering.
    entering.saturating_sub(1) > GIVE_UP_ENTERING * limit
}

/// The iteration of the module docs from the set in `small_set`.
fn small_set_iterate<K: ContactOperator>(
    slot: &mut Option<SmallSet>,
    impulse: &[f64],
    cx: &mut Context<K>,
    (target, max_iterations): (Target, usize),
) -> Result<SmallSetRun, SolveError> {
    let mut run = SmallSetRun {
        applications: 0,
        exact: false,
    };
    let slack = GAP_SLACK * cx.params.tolerance * cx.problem.height_scale;
    let len = cx.problem.rows * cx.problem.cols;
    let Some(small) = slot.as_mut() else {
        return Ok(run);
    };
    for _ in 0..MAX_SOLVES {
        if cx.stop.is_requested() {
            return Err(SolveError::Interrupted {
                iterations: run.applications,
            });
        }
        let spent = run.applications == max_iterations;
        if spent || small.set.is_empty() || !small.factorise(impulse) {
            return Ok(run);
        }
        let d = small.pressures(target, &cx.problem.profile, len);
        if small.drop_unloaded() > 0 {
            continue;
        }
        // All loaded: this pressure keeps the load; check the gap everywhere.
        cx.state.pressure.fill(0.0);
        for (&k, &p) in small.set.iter().zip(&small.pressure) {
            cx.state.pressure[k] = p;
        }
        cx.problem
            .operator
            .apply(&cx.state.pressure, &mut cx.state.gap);
        run = SmallSetRun {
            applications: run.applications + 1,
            exact: true,
        };
        let gap = |k: usize| cx.state.gap[k] + cx.problem.profile[k] - d;
        if !small.enter(gap, slack) || small.solved {
            return Ok(run);
        }
    }
    Ok(run)
}

/// The frozen-set solution `x = K_SS⁻¹ 1_S` from the factor of the last direct solve
/// in `slot` (with the operator's impulse response `impulse`), written into `x_field`
/// (zero off the set), if the contact set of `pressure` is that solve's set and `x`
/// solves the system to `tolerance` (relative residual, computed here from the
/// kernel); returns the residual.
pub(in crate::bem) fn tangent(
    slot: Option<&SmallSet>,
    impulse: &[f64],
    pressure: &[f64],
    (tolerance, x_field): (f64, &mut [f64]),
) -> Option<f64> {
    let small = slot.filter(|s| s.solved)?;
    let (set, n) = (&small.set, small.set.len());
    let loaded = pressure.iter().filter(|&&p| WALL.in_contact(p)).count();
    if loaded != n || set.iter().any(|&k| !WALL.in_contact(pressure[k])) {
        return None;
    }
    let squares: f64 = set
        .iter()
        .map(|&a| {
            let row = set.iter().zip(&small.x[..n]);
            let kx: f64 = row
                .map(|(&b, x)| kernel(impulse, small.grid, a, b) * x)
                .sum();
            (1.0 - kx).powi(2)
        })
        .sum();
    let residual = (squares / n as f64).sqrt();
    if residual.is_nan() || residual > tolerance {
        return None;
    }
    x_field.fill(0.0);
    for (&k, &x) in set.iter().zip(&small.x[..n]) {
        x_field[k] = x;
    }
    Some(residual)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bem::iterations::polonsky_keer::tests::rough_grid;
    use crate::bem::{ContactSolver, Control, HalfSpace, SolverKind, SolverParams};
    use crate::elastic::ElasticOperator;

    fn half_space(boundary: Boundary) -> HalfSpace {
        HalfSpace {
            modulus: 1.0,
            boundary,
        }
    }

    #[test]
    fn the_factor_solves_the_dense_system_after_growing_and_dropping() {
        // K_SS from the operator's impulse response against K_SS assembled point by point
        // from operator applications (the naive oracle), on odd, even and rectangular
        // grids; the factor grown by bordering, then cut after a dropped point and grown
        // again, must solve K_SS x = 1.
        // The last grid has rectangular pixels (Δx = 1, Δy = 0.4).
        for (rows, cols, dy) in [(31, 31, 1.0), (32, 32, 1.0), (20, 36, 0.4)] {
            for boundary in [Boundary::Free, Boundary::Periodic] {
                let mut operator =
                    ElasticOperator::with_spacings(rows, cols, 1.0, dy, 1.0, boundary).unwrap();
                let len = rows * cols;
                let mut unit = vec![0.0; len];
                unit[0] = 1.0;
                let mut impulse = vec![0.0; len];
                operator.apply(&unit, &mut impulse);
                let periodic = boundary == Boundary::Periodic;
                let mut small = SmallSet::new(rows, cols, periodic);
                // Scattered points, two of them neighbours, one at a corner.
                let points = [0, 5, 6, cols + 6, len / 2 + 3, len - 1, 3 * cols + 17];
                for &k in &points[..4] {
                    small.push(k);
                }
                assert!(small.factorise(&impulse));
                for &k in &points[4..] {
                    small.push(k);
                }
                assert!(small.factorise(&impulse));
                // Drop the second point: the factor keeps its first row only.
                let n = small.set.len();
                small.pressure[..n].fill(1.0);
                small.pressure[1] = 0.0;
                assert_eq!(small.drop_unloaded(), 1);
                assert_eq!(small.factored, 1);
                assert!(small.factorise(&impulse));
                let set = small.set.clone();
                let mut x = vec![1.0; set.len()];
                small.solve_in_place(&mut x);
                for (i, &a) in set.iter().enumerate() {
                    let mut field = vec![0.0; len];
                    for (&b, &xb) in set.iter().zip(&x) {
                        field[b] = xb;
                    }
                    let mut response = vec![0.0; len];
                    operator.apply(&field, &mut response);
                    let direct: f64 = set
                        .iter()
                        .zip(&x)
                        .map(|(&b, xb)| kernel(&impulse, small.grid, a, b) * xb)
                        .sum();
                    // The FFT's rounding (1e-15 of the largest entry) bounds both.
                    assert!(
                        (response[a] - 1.0).abs() < 1e-12,
                        "{rows}x{cols} {boundary:?} {i}"
                    );
                    assert!(
                        (direct - 1.0).abs() < 1e-12,
                        "{rows}x{cols} {boundary:?} {i}"
                    );
                }
            }
        }
    }

    /// A sweep of small loads (warm starts, and the first cold) with `kind`: per load the
    /// contact set, indentation, stiffness, and the solve's and stiffness's information.
    fn sweep(
        surface: &crate::surface::Surface,
        boundary: Boundary,
        kind: SolverKind,
        controls: &[Control],
    ) -> Vec<(Vec<bool>, f64, f64, usize, usize)> {
        let params = SolverParams {
            solver: kind,
            tolerance: 1e-11,
            ..SolverParams::default()
        };
        let mut solver = ContactSolver::new(surface, half_space(boundary), params).unwrap();
        controls
            .iter()
            .map(|&control| {
                let (summary, info) = solver.solve(control).unwrap();
                let (k, k_info) = solver.frozen_set_stiffness().unwrap();
                let set = solver.pressure().iter().map(|&p| p > 0.0).collect();
                let applications = info.operator_applications + k_info.operator_applications;
                (set, summary.indentation, k, applications, k_info.iterations)
            })
            .collect()
    }

    #[test]
    fn small_loads_agree_with_polonsky_keer_and_skip_the_iterations() {
        // Loads from a few points of contact to about the limit, under load control (the
        // first cold) and then displacement control; free and periodic; odd, even and
        // rectangular grids. The direct solve must give Polonsky–Keer's contact set,
        // indentation to 1e-9 and stiffness to 1e-6 (PK's own CG), with no stiffness
        // iteration and a few operator applications per load; the same bits on 1 and 2
        // threads.
        for (rows, cols) in [(63, 63), (64, 64), (50, 72)] {
            for boundary in [Boundary::Free, Boundary::Periodic] {
                let surface = rough_grid(rows, cols, 11);
                let loads = [2e-5, 1e-4, 5e-4, 2e-3].map(Control::MeanPressure);
                let pk = sweep(&surface, boundary, SolverKind::PolonskyKeer, &loads);
                let indentations = pk.iter().map(|r| Control::Indentation(0.97 * r.1));
                let controls: Vec<Control> = loads.into_iter().chain(indentations).collect();
                let pk = sweep(&surface, boundary, SolverKind::PolonskyKeer, &controls);
                let run = |threads| {
                    crate::test_support::with_threads(threads, || {
                        sweep(&surface, boundary, SolverKind::Bccg, &controls)
                    })
                };
                let direct = run(1);
                assert_eq!(direct, run(2), "{rows}x{cols} {boundary:?}: threads");
                for (control, (a, b)) in controls.iter().zip(pk.iter().zip(&direct)) {
                    let what = format!("{rows}x{cols} {boundary:?} {control:?}");
                    let points = b.0.iter().filter(|&&s| s).count();
                    eprintln!("{what}: {points} points, {} applications", b.3);
                    assert!(
                        points > 0 && points <= limit(rows * cols),
                        "{what}: {points}"
                    );
                    assert_eq!(a.0, b.0, "{what}: contact sets");
                    assert!((b.1 / a.1 - 1.0).abs() < 1e-9, "{what}: d {} {}", a.1, b.1);
                    assert!((b.2 / a.2 - 1.0).abs() < 1e-6, "{what}: k {} {}", a.2, b.2);
                    assert_eq!(b.4, 0, "{what}: stiffness iterations");
                    assert!(b.3 <= 6, "{what}: {} applications", b.3);
                }
            }
        }
    }

    #[test]
    fn the_cold_shortcut_predicts_only_checks_that_give_up() {
        // From cold, the whole load on the highest point: wherever the bound says the
        // first check gives up, running it (one operator application) must give up, and
        // the bound must say so at all but the loads just past where the check starts to
        // give up (else it saves nothing); free and periodic, odd, even and rectangular
        // grids.
        for (rows, cols) in [(63, 63), (64, 64), (50, 72)] {
            for boundary in [Boundary::Free, Boundary::Periodic] {
                let surface = rough_grid(rows, cols, 11);
                let params = SolverParams::default();
                let mut solver =
                    ContactSolver::new(&surface, half_space(boundary), params).unwrap();
                let limit = limit(rows * cols);
                let (mut predicted, mut missed) = (0, 0);
                // Loads 1e-4 … 1e-1 in steps of 10^(1/8): the bound must follow the check
                // closely (a bound that ignores the response off the loaded point predicts
                // give-ups a step or more early).
                for p in (0..=24).map(|e| 1e-4 * 10f64.powf(e as f64 / 8.0)) {
                    let ContactSolver {
                        cx, bccg_scratch, ..
                    } = &mut solver;
                    let impulse = &bccg_scratch.impulse;
                    let shortcut = highest_point_gives_up(impulse, cx, (p, limit));
                    let top = highest_point(&cx.problem.profile);
                    let periodic = boundary == Boundary::Periodic;
                    let slot = &mut bccg_scratch.small_set;
                    let small = slot.get_or_insert_with(|| SmallSet::new(rows, cols, periodic));
                    small.clear();
                    small.push(top);
                    let target = (Target::MeanPressure(p), 100);
                    let run = small_set_iterate(slot, impulse, cx, target).unwrap();
                    let solved = slot.as_ref().unwrap().solved;
                    let gave_up = run.applications == 1 && !solved;
                    let what = format!("{rows}x{cols} {boundary:?} p = {p}");
                    assert!(!shortcut || gave_up, "{what}: predicted a give-up");
                    predicted += usize::from(shortcut);
                    missed += usize::from(gave_up && !shortcut);
                }
                // And close behind it: at most two steps of load where the check gives up
                // and the bound does not yet know (measured: one or two).
                let what = format!("{rows}x{cols} {boundary:?}: {predicted} predicted");
                assert!(predicted >= 2 && missed <= 2, "{what}, {missed} missed");
            }
        }
    }
}
