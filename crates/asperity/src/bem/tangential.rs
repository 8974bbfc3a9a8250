//! Tangential (no-slip) contact stiffness of a solved state from its frozen contact set.
//!
//! Mindlin's no-slip limit: the contact set `S` of the solved normal state sticks, the
//! indenter is displaced tangentially by `Δu` along `x` (or `y`), and the tangential
//! tractions on the set solve `K^t_SS q = Δu · 1_S`, with `K^t` Cerruti's operator
//! ([`crate::elastic::cerruti`]: the displacement along the traction; the coupling to the
//! normal problem and the cross term neglected, as is standard — exact for bodies of the same
//! elastic constants). Then `k_x = Δ² Σ q / Δu`, as the normal frozen-set stiffness
//! ([`ContactSolver::frozen_set_stiffness`]) is `k = Δ² Σ p / Δd` with Love's operator, and
//! it is solved by the same conjugate gradients on the set, stopped on the same energy
//! estimate. For a circular contact `k_t/k = 2(1−ν)/(2−ν)` (Mindlin 1949).
//!
//! The preconditioner of each direction is the inverse of Cerruti's Fourier symbol,
//! `E*|q|/2 · (1−ν)/(1 − ν q_d²/|q|²)` along `d` (exact on the periodic grid, as the normal
//! one's `E*|q|/2` is for Love's operator; at `q = 0` the mean over directions). The first
//! implementation used the normal symbol scaled by `(1 − ν/2)` for both, halfway between the
//! tangential symbol's extremes ([`TangentialStiffness::with_isotropic_preconditioner`], for
//! comparison): the exact symbol takes 0–4 fewer iterations per direction (docs/tangential.md).
//!
//! **Start.** The two operators average to Love's times a constant: their symbols (and the
//! closed-form pixel kernels) give `(K^x + K^y)/2 = c K` with `c = (2−ν)/(2(1−ν))`, on any
//! set. So `w = x_n/c`, from the normal frozen-set solution `x_n = K_SS⁻¹ 1_S` that the
//! solver keeps after [`ContactSolver::frozen_set_stiffness`], solves the mean of the two
//! problems; it is the start of the `x` CG, and `2w − x` (exact to first order in the
//! anisotropy `ν/(2−ν)`) that of the `y` CG. Without a frozen-set solution of the solved
//! state (or with [`TangentialStiffness::with_warm_start`] off) both start from zero. The
//! same identity bounds the result: `(k_x + k_y)/2 ≥ k/c`, Mindlin's ratio, for every
//! contact set (the inverse is operator-convex).
//!
//! **Single precision.** Each direction's CG runs on the `f32` copy of Cerruti's operator
//! ([`ElasticOperator::single_precision`], about 0.7 of the cost of an application, its
//! rounding about 1e-7) to the usual stopping rule, then is refined in double precision
//! (`Start::Refine` of the CG): one `f64` application for the true residual `r₀ = 1 − K x₀`
//! and the energy `bᵀx₀ + x₀ᵀr₀`, exact to second order in `r₀`, and `f64` CG steps until
//! the last one moved the energy by at most the stiffness's energy error (usually one). The
//! stiffness is thus the double-precision one to the CG's tolerance: measured within 1e-13
//! of the CG all in `f64` ([`TangentialStiffness::with_single_precision`]`(false)`, for
//! comparison) at 64² to 1024², in one or two more iterations, each cheaper.
//!
//! # Example
//! ```
//! use asperity::bem::{tangential::TangentialStiffness, ContactSolver, Control, HalfSpace,
//!     SolverParams};
//! use asperity::elastic::Boundary;
//! use asperity::surface::Surface;
//! use ndarray::Array2;
//! // A sphere of radius 2 on a 64² grid of side 1: a ≈ 12 pixels.
//! let n = 64;
//! let heights = Array2::from_shape_fn((n, n), |(i, j)| {
//!     let (x, y) = ((j as f64 - 32.0) / n as f64, (i as f64 - 32.0) / n as f64);
//!     -(x * x + y * y) / 4.0
//! });
//! let surface = Surface::new(heights, 1.0)?;
//! let half_space = HalfSpace { modulus: 1.0, boundary: Boundary::Free };
//! let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default())?;
//! solver.solve(Control::Indentation(0.02))?;
//! let (k, _) = solver.frozen_set_stiffness()?;
//! let mut tangential = TangentialStiffness::new(&solver, 0.3)?;
//! let t = tangential.solve(&solver)?;
//! let mindlin = 2.0 * 0.7 / 1.7;
//! assert!((t.x / k / mindlin - 1.0).abs() < 0.02);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::precondition::FourierPreconditioner;
use super::solver::ContactSolver;
use super::stiffness::cg::{
    conjugate_gradient_on_set_from, CgError, CgParams, CgWork, RightHandSide, Start,
};
use super::{SolveError, SolveInfo};
use crate::elastic::{Direction, ElasticOperator};
use crate::Result;

/// The tangential stiffnesses of one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tangential {
    /// `k_x`: tangential force along x per unit displacement along x.
    pub x: f64,
    /// `k_y`: the same along y.
    pub y: f64,
    /// The CG of `k_x`.
    pub info_x: SolveInfo,
    /// The CG of `k_y`.
    pub info_y: SolveInfo,
}

/// Which tangential stiffnesses to compute: `k_x`, `k_y` or both (the default). One
/// direction costs about half of both ([`TangentialStiffness::solve_along`]) and is enough
/// for a statistically isotropic surface, whose `k_x` and `k_y` differ by the sample's own
/// anisotropy only.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Directions {
    /// `k_x` alone.
    X,
    /// `k_y` alone.
    Y,
    /// `k_x` and `k_y`.
    #[default]
    Both,
}

impl Directions {
    /// `x`, `y` or `both`.
    pub fn name(self) -> &'static str {
        match self {
            Directions::X => "x",
            Directions::Y => "y",
            Directions::Both => "both",
        }
    }

    /// Whether both directions are asked for (the default).
    pub fn is_both(&self) -> bool {
        *self == Directions::Both
    }
}

/// The tangential stiffnesses asked for by [`Directions`], each with its CG.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Along {
    /// `k_x` and its CG, if asked for.
    pub x: Option<(f64, SolveInfo)>,
    /// `k_y` and its CG, if asked for.
    pub y: Option<(f64, SolveInfo)>,
}

impl Along {
    /// `k_x`, if asked for.
    pub fn stiffness_x(&self) -> Option<f64> {
        self.x.map(|(k, _)| k)
    }

    /// `k_y`, if asked for.
    pub fn stiffness_y(&self) -> Option<f64> {
        self.y.map(|(k, _)| k)
    }

    /// The ratio to the normal stiffness `k`: `(k_x + k_y)/(2k)` with both directions,
    /// else the one direction's `k_d/k` (Mindlin: `2(1−ν)/(2−ν)` for a circle either way).
    pub fn ratio(&self, k: f64) -> f64 {
        match (self.x, self.y) {
            (Some((x, _)), Some((y, _))) => (x + y) / (2.0 * k),
            (Some((d, _)), None) | (None, Some((d, _))) => d / k,
            (None, None) => f64::NAN,
        }
    }

    /// The operator applications of the CGs asked for.
    pub fn operator_applications(&self) -> usize {
        [self.x, self.y]
            .iter()
            .flatten()
            .map(|(_, info)| info.operator_applications)
            .sum()
    }
}

impl From<Tangential> for Along {
    fn from(t: Tangential) -> Self {
        Along {
            x: Some((t.x, t.info_x)),
            y: Some((t.y, t.info_y)),
        }
    }
}

/// Cerruti's operators along x and y for a solver's grid, their preconditioners and the
/// CG's fields: planned once, then [`TangentialStiffness::solve`] for every state.
pub struct TangentialStiffness {
    operators: [ElasticOperator; 2],
    /// Their single-precision copies, for all but the last iterations (module docs).
    singles: [ElasticOperator<f32>; 2],
    single_precision: bool,
    preconditioners: [FourierPreconditioner; 2],
    work: CgWork,
    /// The start of a CG (see the module docs), a field of the grid.
    guess: Vec<f64>,
    poisson: f64,
    warm_start: bool,
}

impl TangentialStiffness {
    /// Estimated memory of the tangential stiffness of a `rows × cols` grid, in bytes
    /// (`None` on overflow): two operators and their single-precision copies, two
    /// preconditioners and the CG's fields (five, and the rings' bytes counted as four more).
    pub fn memory_bytes(
        rows: usize,
        cols: usize,
        boundary: crate::elastic::Boundary,
    ) -> Option<u64> {
        let operator = ElasticOperator::memory_bytes(rows, cols, boundary)?.checked_add(
            ElasticOperator::single_precision_memory_bytes(rows, cols, boundary)?,
        )?;
        let preconditioner = <FourierPreconditioner>::memory_bytes(rows, cols)?;
        let fields = crate::memory::array_bytes(&[9, rows, cols], 8)?;
        operator
            .checked_add(preconditioner)?
            .checked_mul(2)?
            .checked_add(fields)
    }

    /// Plans the tangential operators of `solver`'s grid, E* and boundaries for Poisson's
    /// ratio `poisson` in `[0, 0.5]`; refuses a grid whose operators would not fit in memory.
    pub fn new(solver: &ContactSolver, poisson: f64) -> Result<Self> {
        crate::mdr::check_poisson(poisson)?;
        let normal = &solver.cx.problem.operator;
        let (rows, cols) = (normal.rows(), normal.cols());
        crate::memory::ensure_fits(
            &format!("the tangential stiffness of a {rows}x{cols} grid"),
            Self::memory_bytes(rows, cols, normal.boundary()),
        )?;
        let spacings = (normal.spacing(), normal.spacing_y());
        let (modulus, boundary) = (normal.modulus(), normal.boundary());
        let operator = |direction| {
            let kernel = (poisson, direction);
            ElasticOperator::tangential((rows, cols), spacings, modulus, boundary, kernel)
        };
        let operators = [operator(Direction::X)?, operator(Direction::Y)?];
        let singles = [
            operators[0].single_precision()?,
            operators[1].single_precision()?,
        ];
        let preconditioners = [
            Self::preconditioner((rows, cols), spacings, modulus, (poisson, Direction::X))?,
            Self::preconditioner((rows, cols), spacings, modulus, (poisson, Direction::Y))?,
        ];
        let rings = rows * cols >= super::iterations::RING_MIN_POINTS;
        let work = CgWork::for_operator(&operators[0], rings);
        Ok(TangentialStiffness {
            operators,
            singles,
            single_precision: true,
            preconditioners,
            work,
            guess: vec![0.0; rows * cols],
            poisson,
            warm_start: true,
        })
    }

    /// The inverse of Cerruti's symbol along `direction`, `E*|q|/2 · (1−ν)/(1 − ν q_d²/|q|²)`
    /// (exact on the periodic grid), and at `q = 0` the mean over directions (module docs).
    fn preconditioner(
        (rows, cols): (usize, usize),
        spacings: (f64, f64),
        modulus: f64,
        (poisson, direction): (f64, Direction),
    ) -> Result<FourierPreconditioner> {
        FourierPreconditioner::with_symbol(rows, cols, spacings, |qx, qy, q| {
            let along = match direction {
                Direction::X => qx * qx,
                Direction::Y => qy * qy,
            };
            let share = if qx == 0.0 && qy == 0.0 {
                0.5
            } else {
                along / (qx * qx + qy * qy)
            };
            0.5 * modulus * q * (1.0 - poisson) / (1.0 - poisson * share)
        })
    }

    /// Replaces the preconditioners by the isotropic one of the first implementation,
    /// `E*(1 − ν/2)|q|/2` in both directions (module docs), for comparison: the same
    /// stiffnesses to the CG's tolerance in a few more iterations.
    pub fn with_isotropic_preconditioner(mut self) -> Result<Self> {
        let operator = &self.operators[0];
        let (rows, cols) = (operator.rows(), operator.cols());
        let (dx, dy) = (operator.spacing(), operator.spacing_y());
        let scaled = operator.modulus() * (1.0 - 0.5 * self.poisson);
        for preconditioner in &mut self.preconditioners {
            *preconditioner = FourierPreconditioner::new(rows, cols, dx, dy, scaled)?;
        }
        Ok(self)
    }

    /// Whether the CGs start from the normal frozen-set solution (the default, module
    /// docs) or from zero (for comparison: the same stiffnesses to the CG's tolerance).
    pub fn with_warm_start(mut self, warm_start: bool) -> Self {
        self.warm_start = warm_start;
        self
    }

    /// Whether all but the last iterations apply Cerruti's operator in single precision
    /// (the default, module docs) or all in double precision (for comparison: the same
    /// stiffnesses to the CG's tolerance, in as many iterations, each dearer).
    pub fn with_single_precision(mut self, single_precision: bool) -> Self {
        self.single_precision = single_precision;
        self
    }

    /// Poisson's ratio ν.
    pub fn poisson(&self) -> f64 {
        self.poisson
    }

    /// `k_x` and `k_y` of `solver`'s solved state (its grid must be the one planned for),
    /// by CG on its contact set to the solver's stiffness tolerance and energy estimate.
    pub fn solve(&mut self, solver: &ContactSolver) -> std::result::Result<Tangential, SolveError> {
        let (cg, normal) = self.prepare(solver)?;
        let mut guess = std::mem::take(&mut self.guess);
        let result = self.both(solver, &cg, normal, &mut guess);
        self.guess = guess;
        result
    }

    /// The stiffness along `direction` alone (`k_x` or `k_y`) and its CG: half the work of
    /// [`TangentialStiffness::solve`], for a surface that is statistically isotropic (whose
    /// `k_x` and `k_y` differ by the sample's own anisotropy only). From the normal
    /// frozen-set solution `w` (module docs) where the solver keeps it, else from zero; the
    /// same stiffness as [`TangentialStiffness::solve`]'s to the CG's tolerance.
    pub fn solve_along(
        &mut self,
        solver: &ContactSolver,
        direction: Direction,
    ) -> std::result::Result<(f64, SolveInfo), SolveError> {
        let (cg, normal) = self.prepare(solver)?;
        let mut guess = std::mem::take(&mut self.guess);
        if let Some(x_n) = normal {
            let ratio = self.mindlin();
            guess.iter_mut().zip(x_n).for_each(|(g, x)| *g = ratio * x);
        }
        let start = match normal {
            Some(_) => Start::From(&guess),
            None => Start::Zero,
        };
        let k = match direction {
            Direction::X => 0,
            Direction::Y => 1,
        };
        let result = self.direction(k, solver, &cg, start);
        self.guess = guess;
        result
    }

    /// The stiffnesses asked for by `directions`: [`TangentialStiffness::solve`] for both,
    /// [`TangentialStiffness::solve_along`] for one. `X` gives `solve`'s `k_x` bit for bit
    /// (the same start and CG); `Y` starts from Mindlin's ratio × the normal solution
    /// rather than from `2w − k_x`'s solution, so its `k_y` equals `solve`'s to the CG's
    /// tolerance.
    pub fn solve_directions(
        &mut self,
        solver: &ContactSolver,
        directions: Directions,
    ) -> std::result::Result<Along, SolveError> {
        Ok(match directions {
            Directions::Both => self.solve(solver)?.into(),
            Directions::X => Along {
                x: Some(self.solve_along(solver, Direction::X)?),
                y: None,
            },
            Directions::Y => Along {
                x: None,
                y: Some(self.solve_along(solver, Direction::Y)?),
            },
        })
    }

    /// Mindlin's ratio `2(1−ν)/(2−ν)`.
    fn mindlin(&self) -> f64 {
        2.0 * (1.0 - self.poisson) / (2.0 - self.poisson)
    }

    /// The CG's parameters for `solver`'s solved state and its normal frozen-set solution
    /// (if kept and the warm start is on); refuses an unsolved state or another grid.
    fn prepare<'s>(
        &self,
        solver: &'s ContactSolver,
    ) -> std::result::Result<(CgParams, Option<&'s [f64]>), SolveError> {
        if solver.cx.state.solved.is_none() {
            let reason = "no solved contact state yet";
            return Err(crate::Error::invalid("stiffness", reason).into());
        }
        let normal = &solver.cx.problem.operator;
        if (normal.rows(), normal.cols()) != (self.operators[0].rows(), self.operators[0].cols()) {
            let reason =
                "the solver's grid is not the one the tangential operators were planned for";
            return Err(crate::Error::invalid("stiffness", reason).into());
        }
        let params = &solver.cx.params;
        let cg = CgParams {
            tolerance: params.stiffness_tolerance,
            energy_error: Some(params.stiffness_error).filter(|&e| e > 0.0),
            max_iterations: params.stiffness_max_iterations,
        };
        let normal = self
            .warm_start
            .then(|| solver.frozen_set_solution())
            .flatten();
        Ok((cg, normal))
    }

    /// `k_x`, then `k_y`: from the normal frozen-set solution `normal` if given (module
    /// docs; `guess` holds each start), else from zero.
    fn both(
        &mut self,
        solver: &ContactSolver,
        cg: &CgParams,
        normal: Option<&[f64]>,
        guess: &mut [f64],
    ) -> std::result::Result<Tangential, SolveError> {
        // Mindlin's ratio 1/c: w = x_n/c solves the mean problem.
        let ratio = self.mindlin();
        if let Some(x_n) = normal {
            guess.iter_mut().zip(x_n).for_each(|(g, x)| *g = ratio * x);
        }
        fn start(warm: bool, guess: &[f64]) -> Start<'_> {
            if warm {
                Start::From(guess)
            } else {
                Start::Zero
            }
        }
        let warm = normal.is_some();
        let (x, info_x) = self.direction(0, solver, cg, start(warm, guess))?;
        if let Some(x_n) = normal {
            for ((g, x), x_x) in guess.iter_mut().zip(x_n).zip(&self.work.x) {
                *g = 2.0 * ratio * x - x_x;
            }
        }
        let (y, info_y) = self.direction(1, solver, cg, start(warm, guess))?;
        Ok(Tangential {
            x,
            y,
            info_x,
            info_y,
        })
    }

    /// `k` along direction `k` (0: x, 1: y) of `solver`'s solved state from `start`: with
    /// single precision, its CG on the `f32` copy, then the refinement in double precision
    /// ([`Start::Refine`]), which gives the stiffness (module docs).
    fn direction(
        &mut self,
        k: usize,
        solver: &ContactSolver,
        cg: &CgParams,
        start: Start<'_>,
    ) -> std::result::Result<(f64, SolveInfo), SolveError> {
        let (pressure, interface, stop) = (
            &solver.cx.state.pressure,
            solver.cx.interface,
            &solver.cx.stop,
        );
        let in_set = |i: usize| interface.elastic(pressure[i]);
        let normal = &solver.cx.problem.operator;
        let pixel = normal.spacing() * normal.spacing_y();
        // The applications beyond the CGs' iterations: a given start's (per pass) and the
        // refinement's.
        let given = matches!(start, Start::From(_)) as usize;
        let Self {
            operators,
            singles,
            preconditioners,
            work,
            single_precision,
            ..
        } = self;
        crate::pool::on_worker(solver.cx.params.parallelism, || {
            let (operator, preconditioner) = (&mut operators[k], &mut preconditioners[k]);
            let (mut single, mut starts) = (0, given);
            let mut start = start;
            if *single_precision {
                // Where the f32 pass fails (out of iterations, or broken down on its
                // rounding), the f64 CG starts over from the start: it decides alone.
                match conjugate_gradient_on_set_from(
                    &mut singles[k],
                    preconditioner,
                    in_set,
                    (RightHandSide::Ones, start),
                    work,
                    (cg, stop),
                ) {
                    Ok(info) => {
                        (single, start, starts) = (info.iterations, Start::Refine, given + 1)
                    }
                    Err(CgError::Interrupted { iterations }) => {
                        return Err(CgError::Interrupted { iterations })
                    }
                    Err(
                        CgError::NoConvergence { iterations, .. }
                        | CgError::Breakdown { iterations, .. },
                    ) => (single, starts) = (iterations, 2 * given),
                }
            }
            conjugate_gradient_on_set_from(
                operator,
                preconditioner,
                in_set,
                (RightHandSide::Ones, start),
                work,
                (cg, stop),
            )
            .map(|info| (info, single, starts))
        })
        .map(|(info, single, starts)| {
            let iterations = info.iterations + single;
            let solve = SolveInfo {
                iterations,
                residual: info.residual,
                operator_applications: iterations + starts,
                energy_transforms: 0,
            };
            (info.energy * pixel, solve)
        })
        .map_err(SolveError::from)
    }
}

#[cfg(test)]
mod tests {
    use ndarray::Array2;

    use super::*;
    use crate::bem::{Boundary, Control, HalfSpace, SolverParams};
    use crate::surface::Surface;

    /// A circular set of radius `a` pixels (a flat punch) on a `rows × cols` grid with
    /// pixels `1 × aspect`: `(k, k_x, k_y)`.
    fn punch(
        rows: usize,
        cols: usize,
        a: f64,
        aspect: f64,
        poisson: f64,
        boundary: Boundary,
    ) -> (f64, Tangential) {
        let size = cols as f64;
        let heights = Array2::from_shape_fn((rows, cols), |(i, j)| {
            let (x, y) = (
                j as f64 - (cols / 2) as f64,
                (i as f64 - (rows / 2) as f64) * aspect,
            );
            if x.hypot(y) <= a {
                0.0
            } else {
                -1.0
            }
        });
        let surface = Surface::with_sizes(heights, size, rows as f64 * aspect).unwrap();
        let half_space = HalfSpace {
            modulus: 1.3,
            boundary,
        };
        let params = SolverParams {
            tolerance: 1e-11,
            ..SolverParams::default()
        };
        let mut solver = ContactSolver::new(&surface, half_space, params).unwrap();
        solver.solve(Control::Indentation(1e-3)).unwrap();
        let (k, _) = solver.frozen_set_stiffness().unwrap();
        let mut tangential = TangentialStiffness::new(&solver, poisson).unwrap();
        (k, tangential.solve(&solver).unwrap())
    }

    fn mindlin(poisson: f64) -> f64 {
        2.0 * (1.0 - poisson) / (2.0 - poisson)
    }

    #[test]
    fn circular_contact_approaches_mindlins_ratio() {
        // The ratio's error at a/Δx = 10, 20, 40 (ν = 0.3): measured 2.0e-4, 8.4e-5 and
        // 3.5e-5 — far below either stiffness's own edge error (≈ Δx/a, 0.65 % at 16
        // pixels), which the two share and which cancels in the ratio.
        let mut errors = Vec::new();
        for (n, a) in [(32, 10.0), (64, 20.0), (128, 40.0)] {
            let (k, t) = punch(n, n, a, 1.0, 0.3, Boundary::Free);
            let error = t.x / k / mindlin(0.3) - 1.0;
            eprintln!("a/Δx = {a}: k_t/k_n = {:.6}, Mindlin {:.6}, error {error:.2e}; k_y/k_x - 1 = {:.1e}", t.x / k, mindlin(0.3), t.y / t.x - 1.0);
            // A circle on a square grid: k_x = k_y by the grid's symmetry.
            assert!((t.y / t.x - 1.0).abs() < 1e-9);
            errors.push(error.abs());
        }
        assert!(
            errors[0] < 5e-4 && errors[1] < 2e-4 && errors[2] < 1e-4,
            "{errors:?}"
        );
        assert!(errors[2] < errors[1] && errors[1] < errors[0], "{errors:?}");
    }

    #[test]
    fn poisson_limits() {
        // ν = 0: Cerruti's operator is Love's, k_t = k_n to the CG's precision.
        let (k, t) = punch(48, 48, 15.0, 1.0, 0.0, Boundary::Free);
        assert!((t.x / k - 1.0).abs() < 1e-9, "{}", t.x / k);
        // ν = 0.5: 2/3.
        let (k, t) = punch(48, 48, 15.0, 1.0, 0.5, Boundary::Free);
        assert!((t.x / k / mindlin(0.5) - 1.0).abs() < 1e-2, "{}", t.x / k);
    }

    #[test]
    fn rectangular_pixels_and_periodic_boundaries() {
        // Pixels 1 × 0.5 (twice the rows): the same circle, the same ratio to 1e-2.
        let (k, t) = punch(96, 48, 15.0, 0.5, 0.3, Boundary::Free);
        assert!(
            (t.x / k / mindlin(0.3) - 1.0).abs() < 1e-2,
            "x: {}",
            t.x / k
        );
        assert!(
            (t.y / k / mindlin(0.3) - 1.0).abs() < 1e-2,
            "y: {}",
            t.y / k
        );
        // Periodic: a small circle in a large period is nearly isolated (the images add a
        // compliance of order a/L to both stiffnesses).
        let (k, t) = punch(96, 96, 12.0, 1.0, 0.3, Boundary::Periodic);
        assert!(
            (t.x / k / mindlin(0.3) - 1.0).abs() < 3e-2,
            "periodic: {}",
            t.x / k
        );
    }

    #[test]
    fn refuses_bad_poisson_and_unsolved_states() {
        let surface = Surface::new(Array2::zeros((8, 8)), 1.0).unwrap();
        let half_space = HalfSpace {
            modulus: 1.0,
            boundary: Boundary::Free,
        };
        let solver = ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
        for bad in [-0.1, 0.6, f64::NAN] {
            let err = TangentialStiffness::new(&solver, bad)
                .err()
                .unwrap()
                .to_string();
            assert!(
                err.contains("Poisson's ratio ν must be in [0, 0.5]"),
                "{err}"
            );
        }
        let mut t = TangentialStiffness::new(&solver, 0.3).unwrap();
        assert!(t.solve(&solver).is_err());
    }

    #[test]
    fn the_two_tangential_kernels_average_to_loves() {
        // (K^x + K^y)/2 = c K with c = (2 − ν)/(2(1 − ν)), free and periodic, rectangular
        // pixels: the identity behind the start of the CGs and the bound k_t ≥ Mindlin k.
        let (rows, cols, spacings, nu) = (20, 24, (0.7, 0.4), 0.3);
        let c = (2.0 - nu) / (2.0 * (1.0 - nu));
        let load: Vec<f64> = (0..rows * cols)
            .map(|i| ((i * 7919) % 113) as f64 / 113.0 - 0.3)
            .collect();
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let mut normal =
                ElasticOperator::with_spacings(rows, cols, spacings.0, spacings.1, 1.3, boundary)
                    .unwrap();
            let tangential = |d| {
                ElasticOperator::tangential((rows, cols), spacings, 1.3, boundary, (nu, d)).unwrap()
            };
            let (mut kx, mut ky) = (tangential(Direction::X), tangential(Direction::Y));
            let mut u = [
                vec![0.0; rows * cols],
                vec![0.0; rows * cols],
                vec![0.0; rows * cols],
            ];
            normal.apply(&load, &mut u[0]);
            kx.apply(&load, &mut u[1]);
            ky.apply(&load, &mut u[2]);
            let scale = u[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for ((n, x), y) in u[0].iter().zip(&u[1]).zip(&u[2]) {
                let mean = 0.5 * (x + y);
                assert!((mean - c * n).abs() < 1e-12 * scale, "{boundary:?}");
            }
        }
    }

    #[test]
    fn the_warm_start_gives_the_cold_stiffnesses_in_fewer_iterations() {
        let surface = crate::bem::iterations::polonsky_keer::tests::rough(64, 5);
        let half_space = HalfSpace::default();
        let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
        let mut warm = TangentialStiffness::new(&solver, 0.3).unwrap();
        let mut cold = TangentialStiffness::new(&solver, 0.3)
            .unwrap()
            .with_warm_start(false);
        let (mut warm_iterations, mut cold_iterations) = (0, 0);
        for p in [0.005, 0.02, 0.08] {
            solver.solve(Control::MeanPressure(p)).unwrap();
            let (k, _) = solver.frozen_set_stiffness().unwrap();
            let (w, c) = (warm.solve(&solver).unwrap(), cold.solve(&solver).unwrap());
            assert!((w.x / c.x - 1.0).abs() < 1e-9, "{} {}", w.x, c.x);
            assert!((w.y / c.y - 1.0).abs() < 1e-9, "{} {}", w.y, c.y);
            // Mindlin's ratio is a lower bound of the mean (operator convexity).
            assert!((w.x + w.y) / (2.0 * k) >= mindlin(0.3) * (1.0 - 1e-9));
            // The start's application and the double-precision refinement's.
            assert_eq!(w.info_x.operator_applications, w.info_x.iterations + 2);
            warm_iterations += w.info_x.iterations + w.info_y.iterations + 2;
            cold_iterations += c.info_x.iterations + c.info_y.iterations;
        }
        eprintln!("operator applications: warm {warm_iterations}, cold {cold_iterations}");
        assert!(warm_iterations < cold_iterations);
        // Without a frozen-set solution of the state (a new solve used it up): from zero.
        solver.solve(Control::MeanPressure(0.01)).unwrap();
        let w = warm.solve(&solver).unwrap();
        assert_eq!(w.info_x.operator_applications, w.info_x.iterations + 1);
    }

    #[test]
    fn single_precision_iterations_give_the_double_precision_stiffnesses() {
        // The f32 CG and its f64 refinement against the CG all in f64, free and periodic,
        // both directions together and each alone: the same stiffnesses to 1e-12 (measured
        // at most 1e-13 at 128² to 1024²; the CGs' own energy error is 1e-12).
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let surface = crate::bem::iterations::polonsky_keer::tests::rough(64, 5);
            let half_space = HalfSpace {
                modulus: 1.0,
                boundary,
            };
            let params = SolverParams::default();
            let mut solver = ContactSolver::new(&surface, half_space, params).unwrap();
            let mut mixed = TangentialStiffness::new(&solver, 0.3).unwrap();
            let mut double = TangentialStiffness::new(&solver, 0.3)
                .unwrap()
                .with_single_precision(false);
            let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-12;
            for p in [0.005, 0.08] {
                solver.solve(Control::MeanPressure(p)).unwrap();
                solver.frozen_set_stiffness().unwrap();
                let (m, d) = (
                    mixed.solve(&solver).unwrap(),
                    double.solve(&solver).unwrap(),
                );
                assert!(
                    close(m.x, d.x) && close(m.y, d.y),
                    "{boundary:?} {m:?} {d:?}"
                );
                assert_ne!((m.x, m.y), (d.x, d.y), "the f32 pass changed nothing");
                // The refinement is short: the f32 pass left little to do.
                assert!(
                    m.info_x.iterations <= d.info_x.iterations + 3,
                    "{m:?} {d:?}"
                );
                let (x, info) = mixed.solve_along(&solver, Direction::X).unwrap();
                let (y, _) = mixed.solve_along(&solver, Direction::Y).unwrap();
                assert!(close(x, d.x) && close(y, d.y), "alone: {x} {y} {d:?}");
                assert_eq!(info.operator_applications, info.iterations + 2);
            }
        }
    }

    #[test]
    fn each_directions_preconditioner_inverts_its_periodic_operator() {
        // On periodic boundaries the preconditioner of direction d is the exact inverse of
        // Cerruti's symbol: M_d K^d p = p for a zero-mean field, to double rounding.
        let (rows, cols, spacings, nu) = (18, 22, (0.3, 0.2), 0.3);
        let mut state = 7u64;
        let mut p: Vec<f64> = (0..rows * cols)
            .map(|_| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let mean = p.iter().sum::<f64>() / p.len() as f64;
        p.iter_mut().for_each(|v| *v -= mean);
        for direction in [Direction::X, Direction::Y] {
            let kernel = (nu, direction);
            let mut k = ElasticOperator::tangential(
                (rows, cols),
                spacings,
                1.3,
                Boundary::Periodic,
                kernel,
            )
            .unwrap();
            let mut m =
                FourierPreconditioner::<f64>::with_symbol(rows, cols, spacings, |qx, qy, q| {
                    let along = match direction {
                        Direction::X => qx * qx,
                        Direction::Y => qy * qy,
                    };
                    0.5 * 1.3 * q * (1.0 - nu)
                        / (1.0 - nu * along / (qx * qx + qy * qy).max(1e-300))
                })
                .unwrap();
            let mut u = vec![0.0; rows * cols];
            k.apply(&p, &mut u);
            m.apply(&mut u);
            let error = p
                .iter()
                .zip(&u)
                .fold(0.0f64, |e, (a, b)| e.max((a - b).abs()));
            assert!(error < 1e-12, "{direction:?}: {error}");
        }
        // The solvers' single-precision one is the same symbol (built by `preconditioner`).
        let made =
            TangentialStiffness::preconditioner((rows, cols), spacings, 1.3, (nu, Direction::X));
        assert!(made.is_ok());
    }

    #[test]
    fn each_directions_preconditioner_gives_the_isotropic_ones_stiffnesses() {
        let surface = crate::bem::iterations::polonsky_keer::tests::rough(64, 5);
        let mut solver =
            ContactSolver::new(&surface, HalfSpace::default(), SolverParams::default()).unwrap();
        let mut exact = TangentialStiffness::new(&solver, 0.3).unwrap();
        let mut isotropic = TangentialStiffness::new(&solver, 0.3)
            .unwrap()
            .with_isotropic_preconditioner()
            .unwrap();
        let (mut exact_iterations, mut isotropic_iterations) = (0, 0);
        for p in [0.005, 0.02, 0.08] {
            solver.solve(Control::MeanPressure(p)).unwrap();
            solver.frozen_set_stiffness().unwrap();
            let (e, i) = (
                exact.solve(&solver).unwrap(),
                isotropic.solve(&solver).unwrap(),
            );
            assert!((e.x / i.x - 1.0).abs() < 1e-9, "{} {}", e.x, i.x);
            assert!((e.y / i.y - 1.0).abs() < 1e-9, "{} {}", e.y, i.y);
            exact_iterations += e.info_x.iterations + e.info_y.iterations;
            isotropic_iterations += i.info_x.iterations + i.info_y.iterations;
        }
        eprintln!("iterations: exact symbol {exact_iterations}, isotropic {isotropic_iterations}");
        assert!(exact_iterations <= isotropic_iterations + 2);
    }
}
