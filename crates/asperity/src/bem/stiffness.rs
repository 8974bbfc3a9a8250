//! Contact stiffness of a solved state.
//!
//! * [`ContactSolver::frozen_set_stiffness`] — the paper's method (*Methods*, "BEM
//!   calculations"): keep the contact set `S` of the solved state, impose a uniform extra
//!   displacement `Δd` on it and solve `K_SS Δp = Δd · 1_S` for the pressures on the set
//!   (the restriction of the elastic operator to `S` is symmetric positive definite, so
//!   plain conjugate gradients apply); `k = ΔF/Δd = Δ² Σ Δp / Δd`. It depends on the set
//!   only, not on the topography.
//! * [`ContactSolver::finite_difference_stiffness`] — `dF/dd` by central differences of two
//!   more solves. By Barber's theorem (J. R. Barber, Proc. R. Soc. A 459, 2003) the two are
//!   equal as long as the contact set does not change within the step.
//!
//! The same CG on the full grid gives the mean pressure at which a free-boundary surface
//! comes into full contact: with `q = K⁻¹ 1` (a flat punch the size of the grid) and
//! `y = K⁻¹ f`, the pressure `d q − y` is non-negative everywhere from `d = max(y/q)` on.

use super::polonsky_keer::ContactSolver;
use super::{Control, SolveError, SolveInfo};
use crate::elastic::ElasticOperator;
use crate::Error;

/// Right-hand side of a CG on a set.
#[derive(Clone, Copy)]
enum RightHandSide<'a> {
    /// A uniform unit displacement on the set.
    Ones,
    /// Given values (read on the set only).
    Values(&'a [f64]),
}

/// Solves `K_SS x = b_S` by conjugate gradients (x zero off the set). `direction` and
/// `response` are scratch. Stops at `‖r‖ ≤ tolerance ‖b‖`.
#[allow(clippy::too_many_arguments)]
fn conjugate_gradient_on_set(
    operator: &mut ElasticOperator,
    in_set: &[bool],
    rhs: RightHandSide<'_>,
    x: &mut [f64],
    residual: &mut [f64],
    direction: &mut [f64],
    response: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
) -> Result<SolveInfo, SolveError> {
    let n = in_set.len();
    let mut rs = 0.0;
    for i in 0..n {
        x[i] = 0.0;
        let b = if in_set[i] {
            match rhs {
                RightHandSide::Ones => 1.0,
                RightHandSide::Values(v) => v[i],
            }
        } else {
            0.0
        };
        residual[i] = b;
        direction[i] = b;
        rs += b * b;
    }
    let b_norm = rs.sqrt();
    if b_norm == 0.0 {
        return Ok(SolveInfo {
            iterations: 0,
            residual: 0.0,
        });
    }
    let mut iterations = 0;
    loop {
        let relative = rs.sqrt() / b_norm;
        if relative <= tolerance {
            return Ok(SolveInfo {
                iterations,
                residual: relative,
            });
        }
        if iterations >= max_iterations || !relative.is_finite() {
            return Err(SolveError::NoConvergence {
                iterations,
                residual: relative,
            });
        }
        iterations += 1;
        operator.apply(direction, response);
        let mut curvature = 0.0;
        for i in 0..n {
            if in_set[i] {
                curvature += direction[i] * response[i];
            }
        }
        if curvature <= 0.0 {
            // K_SS is positive definite; this only happens at round-off level.
            return Err(SolveError::NoConvergence {
                iterations,
                residual: relative,
            });
        }
        let alpha = rs / curvature;
        let mut rs_new = 0.0;
        for i in 0..n {
            if in_set[i] {
                x[i] += alpha * direction[i];
                residual[i] -= alpha * response[i];
                rs_new += residual[i] * residual[i];
            }
        }
        let beta = rs_new / rs;
        for i in 0..n {
            if in_set[i] {
                direction[i] = residual[i] + beta * direction[i];
            }
        }
        rs = rs_new;
    }
}

impl ContactSolver {
    fn take_stiffness_work(&mut self) -> (Vec<f64>, Vec<f64>) {
        let n = self.rows * self.cols;
        self.stiffness_work
            .take()
            .unwrap_or_else(|| (vec![0.0; n], vec![0.0; n]))
    }

    /// Contact stiffness `k = ΔF/Δd` of the last solved state by the frozen contact set
    /// (see the module docs), with the CG's iterations and relative residual. Zero when
    /// nothing is in contact.
    pub fn frozen_set_stiffness(&mut self) -> Result<(f64, SolveInfo), SolveError> {
        if self.solved.is_none() {
            return Err(Error::invalid("stiffness", "no solved contact state yet").into());
        }
        let in_set: Vec<bool> = self.pressure.iter().map(|&p| p > 0.0).collect();
        let (mut x, mut residual) = self.take_stiffness_work();
        let result = conjugate_gradient_on_set(
            &mut self.operator,
            &in_set,
            RightHandSide::Ones,
            &mut x,
            &mut residual,
            &mut self.direction,
            &mut self.response,
            self.params.stiffness_tolerance,
            self.params.stiffness_max_iterations,
        );
        let dx = self.operator.spacing();
        let stiffness = x.iter().sum::<f64>() * dx * dx;
        self.stiffness_work = Some((x, residual));
        result.map(|info| (stiffness, info))
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
                format!("must lie in (0, 1), got {relative_step}"),
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

    /// Mean pressure at which the whole free-boundary grid is in contact (two CG solves on
    /// the full grid, see the module docs).
    pub(super) fn free_full_contact_pressure(&mut self) -> Result<f64, SolveError> {
        let n = self.rows * self.cols;
        let everywhere = vec![true; n];
        let (mut flat_punch, mut residual) = self.take_stiffness_work();
        let mut profile_pressure = vec![0.0; n];
        let (tolerance, max_iterations) = (
            self.params.stiffness_tolerance,
            self.params.stiffness_max_iterations,
        );
        let first = conjugate_gradient_on_set(
            &mut self.operator,
            &everywhere,
            RightHandSide::Ones,
            &mut flat_punch,
            &mut residual,
            &mut self.direction,
            &mut self.response,
            tolerance,
            max_iterations,
        );
        let second = first.and_then(|_| {
            conjugate_gradient_on_set(
                &mut self.operator,
                &everywhere,
                RightHandSide::Values(&self.profile),
                &mut profile_pressure,
                &mut residual,
                &mut self.direction,
                &mut self.response,
                tolerance,
                max_iterations,
            )
        });
        let result = second.map(|_| {
            let d = flat_punch
                .iter()
                .zip(&profile_pressure)
                .fold(f64::NEG_INFINITY, |m, (q, y)| m.max(y / q));
            flat_punch
                .iter()
                .zip(&profile_pressure)
                .map(|(q, y)| d * q - y)
                .sum::<f64>()
                / n as f64
        });
        self.stiffness_work = Some((flat_punch, residual));
        result
    }
}
