//! Periodic displacement control in the BCCG: the constant mode, which the periodic
//! operator does not see, handled by its exact curvature on the free set.
//!
//! **The `q = 0` mode.** A periodic half-space fixes displacements up to a constant: the
//! kernel's symbol vanishes at `q = 0`, so `K 1 = 0` and the mean pressure `p̄` does not move
//! the (zero-mean) displacement. It moves the gap only through the prescribed indentation:
//! `mean(g) = mean(u) + mean(f) − d = mean(f) − d`, the mean gap, is fixed by `d` alone.
//! Mean pressure and mean gap are the conjugate pair of that mode. Load control fixes `p̄`
//! and leaves `d` as the multiplier of `Σ p = n p̄` (the BCCG projects the constant out of
//! the free set). Displacement control fixes the mean gap `mean(f) − d > 0` and leaves `p̄`
//! free: the objective `½ pᵀK p + pᵀ(f − d)` is then linear along the constant mode with
//! slope `n (mean(f) − d)`, and the bound `p ≥ 0` (the open points) makes the minimiser
//! unique.
//!
//! **Why it needs its own treatment.** On the free set `F` the Hessian is `K_FF`, whose
//! softest direction is the constant on `F`: `1_Fᵀ K 1_F = 1_Oᵀ K 1_O` with `O` the points
//! off `F` (because `K 1 = 0`), which vanishes as the set fills. The Fourier preconditioner
//! `M ≈ K⁻¹` cannot know this curvature (it depends on `F`), so without help the
//! iteration crawls near full contact.
//!
//! **The remedy** is a two-level (coarse-space) preconditioner with the constant on `F` as
//! the coarse space (Nicolaides' deflation by subdomain constants, SIAM J. Numer. Anal. 24,
//! 355–365, 1987, here with one subdomain, `F`): the gradient `g` on `F` is split into its
//! mean `ḡ_F` and the rest `Πg`; the rest is preconditioned as under load control
//! (`Π M Π g`) and the mean by the exact inverse curvature of its mode:
//! `z = Π M Π g + 1_F (Σ_F g) / (1_Oᵀ K 1_O)`. Both parts are positive semi-definite and
//! act on complementary subspaces, so `z` is a valid preconditioned gradient, and the rest
//! of the iteration (Polak–Ribière direction, exact line minimum, projection) is unchanged.
//! The curvature costs one forward transform whenever `F` changes (the quadratic form
//! [`crate::elastic::ElasticOperator::energy`], a sum of non-negative terms; computed from `1_O`, not `1_F`,
//! so that it keeps its relative accuracy when `O` is small).

use crate::elastic::{ContactOperator, HalfSpaceOperator};

/// The fields of the coarse correction (periodic grids only).
pub(in crate::bem) struct MeanGapScratch {
    /// `1_O`, the indicator of the points off the free set.
    open: Vec<f64>,
    /// The free set of the last curvature (its recomputation is skipped while `F` stays).
    free: Vec<bool>,
    /// `1_Oᵀ K 1_O` of that set; `None` before the first.
    curvature: Option<f64>,
    /// The Fourier preconditioner's value at `q = 0`, `E* q₁/2` with `q₁ = 2π/max(L_x,
    /// L_y)`: the inverse curvature used when no point is open.
    zero_mode: f64,
}

impl MeanGapScratch {
    /// Fields for the grid of `operator`.
    pub(in crate::bem) fn new(operator: &impl ContactOperator) -> Self {
        let len = operator.rows() * operator.cols();
        let (dx, dy) = operator.spacings();
        let longest = (operator.cols() as f64 * dx).max(operator.rows() as f64 * dy);
        MeanGapScratch {
            open: vec![0.0; len],
            free: vec![false; len],
            curvature: None,
            zero_mode: 0.5 * operator.modulus() * 2.0 * std::f64::consts::PI / longest,
        }
    }

    /// Forgets the cached curvature (a new solve or a new surface).
    pub(in crate::bem) fn reset(&mut self) {
        self.curvature = None;
    }

    /// `1_Oᵀ K 1_O` for the free set `free` and whether it cost a forward transform (only
    /// when the set differs from the previous call's).
    pub(in crate::bem) fn curvature(
        &mut self,
        operator: &mut impl HalfSpaceOperator,
        free: &[bool],
    ) -> (f64, bool) {
        if let Some(c) = self.curvature.filter(|_| self.free[..] == free[..]) {
            return (c, false);
        }
        for ((o, &fr), kept) in self.open.iter_mut().zip(free).zip(self.free.iter_mut()) {
            *o = if fr { 0.0 } else { 1.0 };
            *kept = fr;
        }
        let c = operator.energy(&self.open);
        self.curvature = Some(c);
        (c, true)
    }
}

impl MeanGapScratch {
    /// The coarse part's value on `F`: `(Σ_F g) / (1_Oᵀ K 1_O)` for the free set of the
    /// last [`MeanGapScratch::curvature`]. With no open point (every point in contact or
    /// penetrating: the objective is linear along the constant, and only the bound
    /// `p ≥ 0` stops a step) the preconditioner's own `q = 0` value takes the curvature's
    /// place, `mean_F(g) E* q₁/2`, and the projection of the step cuts the pressures
    /// that reach zero.
    pub(in crate::bem) fn coarse_value(&self, gradient_sum: f64, free_points: usize) -> f64 {
        match self.curvature {
            Some(c) if crate::is_positive_finite(c) => gradient_sum / c,
            _ => gradient_sum / free_points.max(1) as f64 * self.zero_mode,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::bem::iterations::polonsky_keer::tests::{assert_no_convergence, rough_grid};
    use crate::bem::solver::ContactSolver;
    use crate::bem::{Control, HalfSpace, SolveError, SolverParams};
    use crate::elastic::Boundary;
    use crate::reference::Westergaard;
    use crate::surface::Surface;
    use ndarray::Array2;
    use std::f64::consts::PI;

    fn periodic(modulus: f64) -> HalfSpace {
        HalfSpace {
            modulus,
            boundary: Boundary::Periodic,
        }
    }

    fn contact_set(solver: &ContactSolver) -> Vec<bool> {
        solver.pressure().iter().map(|&p| p > 0.0).collect()
    }

    /// `max(h) − mean(h)`: the periodic full-contact indentation.
    fn mean_profile(surface: &Surface) -> f64 {
        let h = surface.heights();
        let top = h.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v));
        top - h.iter().sum::<f64>() / h.len() as f64
    }

    #[test]
    fn the_indentation_of_a_load_controlled_solve_gives_its_load_back() {
        // Load control at p̄ reports d (zero-mean displacements); displacement control at
        // that d must return p̄ and the same contact set: cold on a new solver, and warm from
        // a state at another load. Even, odd and non-square grids; light to heavy loads.
        for (rows, cols) in [(64, 64), (63, 63), (50, 72)] {
            let surface = rough_grid(rows, cols, 21);
            let params = SolverParams::default();
            let mut load = ContactSolver::new(&surface, periodic(1.3), params).unwrap();
            let p_star = load.periodic_full_contact().mean_pressure;
            let mut worst = 0.0f64;
            for ratio in [1e-3, 0.03, 0.3] {
                load.reset();
                let (s, load_info) = load.solve(Control::MeanPressure(ratio * p_star)).unwrap();
                let set = contact_set(&load);
                let d = s.indentation;
                assert!(d > 0.0 && d < mean_profile(&surface));
                let mut displacement = ContactSolver::new(&surface, periodic(1.3), params).unwrap();
                let (cold, info) = displacement.solve(Control::Indentation(d)).unwrap();
                assert_eq!(cold.indentation, d);
                assert!(info.iterations > 0 && info.residual < params.tolerance);
                assert_eq!(
                    contact_set(&displacement),
                    set,
                    "{rows}x{cols} {ratio}: cold"
                );
                assert_eq!(cold.contact_points, s.contact_points);
                displacement
                    .solve(Control::MeanPressure(2.0 * ratio * p_star))
                    .unwrap();
                let (warm, warm_info) = displacement.solve(Control::Indentation(d)).unwrap();
                assert_eq!(
                    contact_set(&displacement),
                    set,
                    "{rows}x{cols} {ratio}: warm"
                );
                for t in [cold, warm] {
                    let error = t.mean_pressure / s.mean_pressure - 1.0;
                    assert!(
                        error.abs() < 1e-6,
                        "{rows}x{cols} {ratio}: p̄ error {error:e}"
                    );
                    worst = worst.max(error.abs());
                }
                eprintln!(
                    "{rows}x{cols} p/p* = {ratio}: d/mean(f) = {:.6}, cold {} / warm {} \
                     iterations (load control {}), area {}",
                    d / mean_profile(&surface),
                    info.iterations,
                    warm_info.iterations,
                    load_info.iterations,
                    cold.area_fraction
                );
            }
            eprintln!("{rows}x{cols}: worst p̄ error {worst:.2e}");
        }
    }

    #[test]
    fn displacement_controlled_state_satisfies_the_contact_conditions() {
        let surface = rough_grid(48, 56, 22);
        let mut solver =
            ContactSolver::new(&surface, periodic(1.0), SolverParams::default()).unwrap();
        let d = 0.5 * mean_profile(&surface);
        let (s, _) = solver.solve(Control::Indentation(d)).unwrap();
        let state = solver.state().unwrap();
        // Zero-mean displacements: the convention d is measured in.
        let mean_u = state.displacement.mean().unwrap();
        let max_u = state
            .displacement
            .iter()
            .fold(0.0f64, |m, &u| m.max(u.abs()));
        assert!(mean_u.abs() < 1e-12 * max_u, "mean u {mean_u}");
        let top = surface
            .heights()
            .iter()
            .fold(f64::NEG_INFINITY, |m, &h| m.max(h));
        let h_mean = surface.heights().mean().unwrap();
        let h_rms = (surface
            .heights()
            .iter()
            .map(|h| (h - h_mean).powi(2))
            .sum::<f64>()
            / (48.0 * 56.0))
            .sqrt();
        for ((&p, &u), &h) in state
            .pressure
            .iter()
            .zip(&state.displacement)
            .zip(surface.heights())
        {
            let g = u + (top - h) - d;
            assert!(p >= 0.0);
            if p > 0.0 {
                assert!(g.abs() < 1e-7 * h_rms, "gap {g} in contact");
            } else {
                assert!(g > -1e-7 * h_rms, "penetration {g}");
            }
        }
        assert!(state.gap.iter().all(|&g| g >= 0.0));
        assert!(s.area_fraction > 0.0 && s.area_fraction < 1.0);
        assert!(solver.frozen_set_stiffness().unwrap().0 > 0.0);
    }

    /// One wavelength of `h = Δ cos(2πx/λ)` along 128 columns, 8 rows.
    fn sinusoid(amplitude: f64) -> Surface {
        let (rows, cols, size) = (8, 128, 1.0);
        let dx = size / cols as f64;
        let heights = Array2::from_shape_fn((rows, cols), |(_, j)| {
            amplitude * (2.0 * PI * j as f64 * dx / size).cos()
        });
        Surface::new(heights, size).unwrap()
    }

    #[test]
    fn westergaard_under_displacement_control() {
        let (amplitude, modulus, cols) = (0.01, 2.0, 128);
        let reference = Westergaard {
            wavelength: 1.0,
            amplitude,
            modulus,
        };
        let p_star = reference.full_contact_pressure();
        let mut solver = ContactSolver::new(
            &sinusoid(amplitude),
            periodic(modulus),
            SolverParams::default(),
        )
        .unwrap();
        for ratio in [0.1, 0.5, 0.9] {
            let d = reference.indentation(ratio * p_star);
            let (s, info) = solver.solve(Control::Indentation(d)).unwrap();
            let expected = reference.contact_fraction(ratio * p_star);
            eprintln!(
                "westergaard d = {:.6} Δ (p/p* = {ratio}): area {} vs {expected:.5} \
                 ({:+.2} px), p̄/p* = {:.5}, {} iterations",
                d / amplitude,
                s.area_fraction,
                (s.area_fraction - expected) * cols as f64,
                s.mean_pressure / p_star,
                info.iterations
            );
            // The contact edge is resolved to a pixel on each side.
            assert!(
                (s.area_fraction - expected).abs() <= 2.0 / cols as f64,
                "p/p* = {ratio}: {} vs {expected}",
                s.area_fraction
            );
            // The load follows (the indentation's slope −Δ ln r is finite here).
            assert!(
                (s.mean_pressure / (ratio * p_star) - 1.0).abs() < 0.02,
                "p/p* = {ratio}: p̄/p* = {}",
                s.mean_pressure / p_star
            );
        }
        // Full contact at d = Δ, the mean of the profile, exactly: refused at and above it,
        // with the threshold as an indentation.
        for d in [amplitude, 1.001 * amplitude] {
            let err = solver.solve(Control::Indentation(d)).unwrap_err();
            let message = err.to_string();
            match err {
                SolveError::BeyondFullContact {
                    requested: Control::Indentation(requested),
                    full_contact: Some(full),
                } => {
                    assert_eq!(requested, d);
                    assert!((full / amplitude - 1.0).abs() < 1e-12, "{full}");
                }
                other => panic!("expected BeyondFullContact, got {other:?}"),
            }
            assert!(
                message.contains("is beyond full contact (the gap closes everywhere from an indentation of 1.000000e-2)"),
                "{message}"
            );
            assert!(solver.summary().is_none());
        }
        // Just below: a partial contact close to full (cold after the refusal).
        let (s, _) = solver
            .solve(Control::Indentation(0.999 * amplitude))
            .unwrap();
        assert!(s.area_fraction < 1.0 && s.mean_pressure < p_star);
        assert!(
            s.mean_pressure > 0.9 * p_star,
            "{}",
            s.mean_pressure / p_star
        );
    }

    #[test]
    fn rough_indentation_beyond_full_contact_is_refused() {
        let surface = rough_grid(40, 40, 23);
        let d_full = mean_profile(&surface);
        let mut solver =
            ContactSolver::new(&surface, periodic(1.0), SolverParams::default()).unwrap();
        // The threshold a front end checks up front is the one the solver refuses with.
        let threshold = solver
            .full_contact_threshold()
            .unwrap()
            .indentation
            .unwrap();
        assert!(
            (threshold / d_full - 1.0).abs() < 1e-12,
            "{threshold} vs {d_full}"
        );
        // At and above the solver's own threshold (d_full above is summed in another order
        // and may lie an ulp below it, where a solver may find a partial contact with one
        // point open by rounding).
        for d in [threshold, 1.5 * threshold] {
            match solver.solve(Control::Indentation(d)) {
                Err(SolveError::BeyondFullContact {
                    requested: Control::Indentation(requested),
                    full_contact: Some(full),
                }) => {
                    assert_eq!(requested, d);
                    assert!((full / d_full - 1.0).abs() < 1e-12, "{full} vs {d_full}");
                }
                other => panic!("expected BeyondFullContact, got {other:?}"),
            }
        }
        // Below it every indentation is a partial contact, below full-contact load.
        let p_star = solver.periodic_full_contact().mean_pressure;
        let (s, _) = solver.solve(Control::Indentation(0.99 * d_full)).unwrap();
        assert!(s.area_fraction < 1.0 && s.mean_pressure < p_star);
    }

    #[test]
    fn zero_indentation_is_the_unloaded_state() {
        let surface = rough_grid(32, 32, 24);
        let mut solver =
            ContactSolver::new(&surface, periodic(1.0), SolverParams::default()).unwrap();
        let (s, info) = solver.solve(Control::Indentation(0.0)).unwrap();
        assert_eq!((s.force, s.contact_points, s.indentation), (0.0, 0, 0.0));
        assert_eq!(info.iterations, 0);
        assert!(solver.gap().iter().all(|&g| g >= 0.0));
        assert_eq!(solver.frozen_set_stiffness().unwrap().0, 0.0);
        // A little more carries a little load.
        let d = 1e-3 * mean_profile(&surface);
        let (s, _) = solver.solve(Control::Indentation(d)).unwrap();
        assert!(s.force > 0.0 && s.contact_points > 0);
    }

    #[test]
    fn no_convergence_is_an_error_with_the_iterations_and_residual() {
        let surface = rough_grid(32, 32, 25);
        let params = SolverParams {
            max_iterations: 3,
            ..SolverParams::default()
        };
        let mut solver = ContactSolver::new(&surface, periodic(1.0), params).unwrap();
        // Deep enough that the set is too large for the direct solve (`small_set.rs`).
        let control = Control::Indentation(0.9 * mean_profile(&surface));
        assert_no_convergence(&mut solver, control, &params);
    }
}
