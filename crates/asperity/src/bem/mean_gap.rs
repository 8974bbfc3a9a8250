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
//! The curvature costs one operator application whenever `F` changes (computed from `1_O`,
//! not `1_F`, so that it keeps its relative accuracy when `O` is small).

use crate::elastic::ElasticOperator;

/// The fields of the coarse correction (periodic grids only).
pub(super) struct MeanGapScratch {
    /// `1_O`, the indicator of the points off the free set.
    open: Vec<f64>,
    /// `K 1_O`.
    response: Vec<f64>,
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
    pub(super) fn new(operator: &ElasticOperator) -> Self {
        let len = operator.rows() * operator.cols();
        let longest = (operator.cols() as f64 * operator.spacing())
            .max(operator.rows() as f64 * operator.spacing_y());
        MeanGapScratch {
            open: vec![0.0; len],
            response: vec![0.0; len],
            free: vec![false; len],
            curvature: None,
            zero_mode: 0.5 * operator.modulus() * 2.0 * std::f64::consts::PI / longest,
        }
    }

    /// Forgets the cached curvature (a new solve or a new surface).
    pub(super) fn reset(&mut self) {
        self.curvature = None;
    }

    /// `1_Oᵀ K 1_O` for the free set `free` and whether it cost an operator application
    /// (only when the set differs from the previous call's).
    pub(super) fn curvature(
        &mut self,
        operator: &mut ElasticOperator,
        free: &[bool],
    ) -> (f64, bool) {
        if let Some(c) = self.curvature.filter(|_| self.free[..] == free[..]) {
            return (c, false);
        }
        for ((o, &fr), kept) in self.open.iter_mut().zip(free).zip(self.free.iter_mut()) {
            *o = if fr { 0.0 } else { 1.0 };
            *kept = fr;
        }
        operator.apply(&self.open, &mut self.response);
        let c = self
            .open
            .iter()
            .zip(&self.response)
            .map(|(o, r)| o * r)
            .fold(0.0, |a, b| a + b);
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
    pub(super) fn coarse_value(&self, gradient_sum: f64, free_points: usize) -> f64 {
        match self.curvature {
            Some(c) if crate::is_positive_finite(c) => gradient_sum / c,
            _ => gradient_sum / free_points.max(1) as f64 * self.zero_mode,
        }
    }
}
