//! Polonsky & Keer's constrained conjugate gradients for the rough
//! contact problem of [`crate::bem`] (I. A. Polonsky, L. M. Keer, *A numerical method for
//! solving rough contact problems based on the multi-level multi-summation and conjugate
//! gradient techniques*, Wear 231, 206–219, 1999), on the FFT half-space operator.
//!
//! One iteration (load control; displacement control skips the mean subtractions and the
//! rescaling, with `d` fixed, on free and periodic boundaries alike: below full contact the
//! periodic objective is bounded along the constant mode, see [`super::bccg::mean_gap`]):
//! 1. `u = K p`; on the contact set `I_c = {p > 0}` the indentation is the mean of `u + f`,
//!    `g = u + f − d`, `G = Σ_{I_c} g²`.
//! 2. Direction `t = g + δ (G/G_old) t` on `I_c`, zero elsewhere (`δ = 0` after the contact
//!    set grew: a steepest-descent restart).
//! 3. `r = K t` minus its mean on `I_c`; step `τ = Σ g t / Σ r t`; `p ← max(p − τ t, 0)`.
//! 4. Points out of contact that penetrate (`p = 0, g < 0`) enter with `p = −τ g`.
//! 5. Rescale `p` to the prescribed mean pressure.
//!
//! Each iteration costs two operator applications and four fused passes over the grid.
//! The elementwise passes run serially: they are memory bound, and a fixed summation order
//! keeps results bit-identical for any thread count (the FFTs are parallel and
//! independent of it too).

use super::{Iteration, Limits};
use crate::bem::context::{Context, Target};
use crate::bem::interface::{restore_capped_load, CappedRestoration, Interface, LOST_SET_LIMIT};
use crate::bem::{ContactSummary, SolveError, SolveInfo};
use crate::elastic::ContactOperator;

/// The iteration's own fields: the conjugate direction `t` and its response `K t`. Owned
/// by the solver, allocated on the first Polonsky–Keer solve; nothing is kept in them
/// between solves.
pub(in crate::bem) struct PkScratch {
    direction: Vec<f64>,
    response: Vec<f64>,
    /// Under a cap and load control: the last solve stopped because its load
    /// restorations lost the plastic set more than [`LOST_SET_LIMIT`] times (cycling;
    /// `capped_load.rs` finishes it by displacement control).
    pub(in crate::bem) stalled: bool,
}

impl PkScratch {
    /// The fields for a grid of `len` points.
    pub(in crate::bem) fn new(len: usize) -> Self {
        PkScratch {
            direction: vec![0.0; len],
            response: vec![0.0; len],
            stalled: false,
        }
    }
}

impl<K: ContactOperator> Iteration<K> for PkScratch {
    /// The Polonsky–Keer iteration for `target` to the tolerance in at most the iterations
    /// of `limits`, from the solver's start in `cx` (see [`crate::bem::ContactSolver::solve`]),
    /// in its own fields.
    fn solve(
        &mut self,
        cx: &mut Context<K>,
        target: Target,
        limits: Limits,
    ) -> Result<(ContactSummary, SolveInfo), SolveError> {
        self.stalled = false;
        let Limits {
            tolerance,
            max_iterations,
        } = limits;
        let pk = self;
        let load_control = matches!(target, Target::MeanPressure(_));
        let interface = cx.interface;
        let mut indentation = match target {
            Target::Indentation(d) => d,
            Target::MeanPressure(_) => cx.state.solved.map_or(0.0, |s| s.indentation),
        };
        let mut g_old = 0.0;
        let mut conjugate = false;
        let (mut iteration, mut lost_sets) = (0, 0);
        loop {
            cx.check_stop(iteration)?;
            cx.problem
                .operator
                .apply(&cx.state.pressure, &mut cx.state.gap);
            let pass = gap_and_direction(
                interface,
                (&cx.state.pressure, &cx.problem.profile),
                &mut cx.state.gap,
                &mut pk.direction,
                load_control,
                &mut indentation,
                if conjugate { g_old } else { 0.0 },
            );
            let residual = pass.residual(cx.problem.height_scale);
            if residual < tolerance {
                let info = SolveInfo {
                    iterations: iteration,
                    residual,
                    operator_applications: 2 * iteration + 1,
                    energy_transforms: 0,
                };
                return Ok((cx.finish(indentation, pass.contact_points), info));
            }
            if iteration >= max_iterations || !residual.is_finite() {
                return Err(SolveError::NoConvergence {
                    iterations: iteration,
                    residual,
                });
            }
            cx.check_progress(iteration, residual)?;
            g_old = pass.gap_squared;
            iteration += 1;

            let (total, entered) = pk_step(cx, pk, load_control, pass.moving_points);
            // Pass E: the prescribed load (a reset pressure restarts the directions).
            let restoration = restore_load(cx, target, total);
            conjugate = !entered && restoration != CappedRestoration::Restarted;
            let capped = matches!(interface, Interface::Hardness { .. });
            lost_sets += (capped && restoration.lost_the_set()) as usize;
            if lost_sets > LOST_SET_LIMIT {
                pk.stalled = true;
                return Err(SolveError::NoConvergence {
                    iterations: iteration,
                    residual,
                });
            }
        }
    }

    fn stalled(&self) -> bool {
        self.stalled
    }

    /// Two: the step's response and the refreshed displacement.
    fn applications_per_iteration(&self) -> usize {
        2
    }
}

/// One step along `pk.direction`: its response, the step length τ, and the pressure
/// update (penetrating points enter with p = −τ g; before any step exists, the empty
/// set, a Jacobi step with the self-influence). Returns the pressures' sum and whether
/// points entered.
fn pk_step<K: ContactOperator>(
    cx: &mut Context<K>,
    pk: &mut PkScratch,
    load_control: bool,
    moving_points: usize,
) -> (f64, bool) {
    let interface = cx.interface;
    cx.problem.operator.apply(&pk.direction, &mut pk.response);
    let tau = step_length(
        interface,
        &cx.state.pressure,
        &cx.state.gap,
        &pk.direction,
        &pk.response,
        load_control,
        moving_points,
    );
    let self_influence = cx.problem.operator.self_influence();
    let entry_step = if tau > 0.0 { tau } else { 1.0 / self_influence };
    update_pressure(
        interface,
        &mut cx.state.pressure,
        &cx.state.gap,
        &pk.direction,
        tau,
        entry_step,
    )
}

/// Pass E: under load control, `p` rescaled to the prescribed mean pressure from its
/// sum `total` (or reset to uniform if nothing is left: `Restarted`); under a cap by
/// [`restore_capped_load`].
fn restore_load<K: ContactOperator>(
    cx: &mut Context<K>,
    target: Target,
    total: f64,
) -> CappedRestoration {
    let Target::MeanPressure(mean_pressure) = target else {
        return CappedRestoration::Held;
    };
    let pressure = &mut cx.state.pressure;
    if let Interface::Hardness { h } = cx.interface {
        let gap = &cx.state.gap;
        return restore_capped_load(pressure, (mean_pressure, h), total, |i| gap[i]);
    }
    if total > 0.0 {
        let scale = mean_pressure * pressure.len() as f64 / total;
        pressure.iter_mut().for_each(|v| *v *= scale);
        CappedRestoration::Held
    } else {
        pressure.fill(mean_pressure);
        CappedRestoration::Restarted
    }
}

/// Sums of passes A and B over the grid.
pub(in crate::bem) struct GapPass {
    /// Points in contact (`p > 0`).
    pub(in crate::bem) contact_points: usize,
    /// Points the conjugate gradients move ([`moves`]; the contact points for the hard
    /// wall).
    pub(in crate::bem) moving_points: usize,
    /// `G = Σ g²` on the points moved.
    pub(in crate::bem) gap_squared: f64,
    /// The squared violations off it (`Σ_{p=0} min(g, 0)²`, and `Σ_{p=H} max(g, 0)²`).
    pub(in crate::bem) penetration_squared: f64,
}

impl GapPass {
    /// The residual of the module docs: `sqrt[(G + Σ_{p=0} min(g,0)²) / n_c] / h_rms`.
    pub(in crate::bem) fn residual(&self, height_scale: f64) -> f64 {
        ((self.gap_squared + self.penetration_squared) / self.contact_points.max(1) as f64).sqrt()
            / height_scale
    }
}

/// Passes A and B of an iteration. `gap` holds `u = K p` on entry and `g = u + f − d` on
/// exit. Under load control `indentation` becomes the mean of `u + f` on the contact set
/// (summed about its previous value, so that `G` does not cancel); `t` becomes the new
/// conjugate direction (`previous_g = 0`: steepest descent).
pub(in crate::bem) fn gap_and_direction(
    interface: Interface,
    (p, f): (&[f64], &[f64]),
    gap: &mut [f64],
    t: &mut [f64],
    load_control: bool,
    indentation: &mut f64,
    previous_g: f64,
) -> GapPass {
    // Pass A: u + f, its mean and spread on the contact set about the last indentation.
    let shift = *indentation;
    let (mut contact_points, mut elastic_points, mut sum, mut sum_sq) = (0usize, 0usize, 0.0, 0.0);
    for ((g, &fi), &pi) in gap.iter_mut().zip(f).zip(p) {
        *g += fi;
        contact_points += interface.in_contact(pi) as usize;
        if interface.elastic(pi) {
            let w = *g - shift;
            elastic_points += 1;
            sum += w;
            sum_sq += w * w;
        }
    }
    let g_estimate = if load_control && elastic_points > 0 {
        let mean = sum / elastic_points as f64;
        *indentation = shift + mean;
        (sum_sq - elastic_points as f64 * mean * mean).max(0.0)
    } else {
        sum_sq
    };
    // Pass B: the gap, exact G, penetration outside the set, the new direction.
    let beta = if previous_g > 0.0 {
        g_estimate / previous_g
    } else {
        0.0
    };
    let d = *indentation;
    let (mut gap_squared, mut penetration_squared, mut moving_points) = (0.0, 0.0, 0);
    for ((g, ti), &pi) in gap.iter_mut().zip(t.iter_mut()).zip(p) {
        *g -= d;
        if moves(interface, pi, *g) {
            gap_squared += *g * *g;
            *ti = *g + beta * *ti;
            moving_points += 1;
        } else {
            *ti = 0.0;
            let v = interface.violation(pi, *g);
            if v != 0.0 {
                penetration_squared += v * v;
            }
        }
    }
    GapPass {
        contact_points,
        moving_points,
        gap_squared,
        penetration_squared,
    }
}

/// Whether the conjugate gradients move the point: the elastic set, and under a cap the
/// capped points whose gap opens (`p = H, g > 0`). Those leave the cap along the
/// direction, with the step fitted to it: moved by a step of their own (as the points
/// entering the contact are) they all left the cap at once for zero where the cold start
/// had put most of the contact at the cap (a paraboloid: 665 of 681 points), the next
/// steps put them all back, and the iteration alternated between the two for ever.
#[inline]
fn moves(interface: Interface, p: f64, g: f64) -> bool {
    interface.elastic(p) || (interface.plastic(p) && g > 0.0)
}

/// Pass C: `τ = Σ g t / Σ (r − r̄) t` on the contact set, `r̄` its mean there under load
/// control (zero under displacement control). Zero when the set is empty.
fn step_length(
    interface: Interface,
    p: &[f64],
    gap: &[f64],
    t: &[f64],
    r: &[f64],
    load_control: bool,
    contact_points: usize,
) -> f64 {
    let (mut sum_r, mut sum_rt, mut sum_t, mut sum_gt) = (0.0, 0.0, 0.0, 0.0);
    for (((&pi, &gi), &ti), &ri) in p.iter().zip(gap).zip(t).zip(r) {
        if moves(interface, pi, gi) {
            sum_r += ri;
            sum_rt += ri * ti;
            sum_t += ti;
            sum_gt += gi * ti;
        }
    }
    let mean_r = if load_control && contact_points > 0 {
        sum_r / contact_points as f64
    } else {
        0.0
    };
    let denominator = sum_rt - mean_r * sum_t;
    if contact_points > 0 && denominator > 0.0 {
        sum_gt / denominator
    } else {
        0.0
    }
}

/// Pass D: `p ← max(p − τ t, 0)` on the contact set; penetrating points outside it enter
/// with `p = −entry_step · g`. Returns `Σ p` and whether any point entered.
fn update_pressure(
    interface: Interface,
    p: &mut [f64],
    gap: &[f64],
    t: &[f64],
    tau: f64,
    entry_step: f64,
) -> (f64, bool) {
    let (mut total, mut entered) = (0.0, false);
    for ((pi, &gi), &ti) in p.iter_mut().zip(gap).zip(t) {
        if moves(interface, *pi, gi) {
            *pi = interface.project(*pi - tau * ti);
        } else if interface.is_free(*pi, gi) {
            // Out of contact and penetrating (enters): the hard wall's `max(−e g, 0)` is
            // `−e g` itself.
            *pi = interface.project(*pi - entry_step * gi);
            entered = true;
        }
        total += *pi;
    }
    (total, entered)
}

#[cfg(test)]
pub(in crate::bem) mod tests {
    use super::*;
    use crate::bem::{ContactSolver, Control, HalfSpace, SolverParams};
    use crate::elastic::Boundary;
    use crate::reference::{Hertz, Westergaard};
    use crate::surface::Surface;
    use crate::{memory, Error};
    use ndarray::Array2;
    use std::f64::consts::PI;

    /// A sphere `h = −r²/2R` (peak up) centred on pixel `(rows/2, cols/2)`.
    pub(crate) fn sphere(rows: usize, cols: usize, size: f64, radius: f64) -> Surface {
        let dx = size / cols as f64;
        let heights = Array2::from_shape_fn((rows, cols), |(i, j)| {
            let y = (i as f64 - (rows / 2) as f64) * dx;
            let x = (j as f64 - (cols / 2) as f64) * dx;
            -(x * x + y * y) / (2.0 * radius)
        });
        Surface::new(heights, size).unwrap()
    }

    pub(crate) fn rough(n: usize, seed: u64) -> Surface {
        rough_grid(n, n, seed)
    }

    /// A rough surface on a `rows × cols` grid (L = 1 along the columns).
    pub(crate) fn rough_grid(rows: usize, cols: usize, seed: u64) -> Surface {
        use crate::spectrum::{LongWavelength, Psd};
        use crate::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};
        let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 4.0 }, None).unwrap();
        let spec = SurfaceSpec::new(rows, cols, 1.0, psd, Normalisation::RmsSlope(0.5)).unwrap();
        SurfaceGenerator::new(&spec).unwrap().generate(seed)
    }

    fn free() -> HalfSpace {
        HalfSpace {
            modulus: 1.0,
            boundary: Boundary::Free,
        }
    }

    /// Hertz on a grid: force–indentation, contact radius and pressure profile.
    fn check_hertz(rows: usize, cols: usize) {
        // Contact radius ≈ 18 pixels on a grid of 48+ pixels: far from the free edges.
        let (size, radius, modulus) = (1.0, 2.0, 1.7);
        let dx = size / cols as f64;
        let hertz = Hertz { radius, modulus };
        let a_target = 18.0 * dx;
        let d_target = a_target * a_target / radius;
        let force = hertz.force(d_target);
        let surface = sphere(rows, cols, size, radius);
        let half_space = HalfSpace { modulus, ..free() };
        let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
        let (s, info) = solver.solve(Control::Force(force)).unwrap();
        assert!(info.residual < 1e-8);
        assert!((s.force / force - 1.0).abs() < 1e-12);
        // Force–indentation within 1 %.
        let d_error = s.indentation / d_target - 1.0;
        assert!(
            d_error.abs() < 0.01,
            "{rows}x{cols}: indentation error {d_error:e}"
        );
        // Contact radius (area-equivalent) within one pixel.
        let a = (s.contact_points as f64 * dx * dx / PI).sqrt();
        assert!(
            (a - a_target).abs() < dx,
            "{rows}x{cols}: a = {a}, Hertz {a_target}"
        );
        // Pressure profile inside 0.9 a, relative to the peak pressure: measured 1.7e-3 on
        // all three grids, bound 0.5 % (the pixels near the edge average the square-root
        // profile over a pixel, which is where the largest pointwise error sits).
        let p0 = hertz.pressure(d_target, 0.0);
        let pressure = solver.pressure();
        let mut worst = 0.0f64;
        for ((i, j), &p) in pressure.indexed_iter() {
            let r = (((i as f64) - (rows / 2) as f64).hypot(j as f64 - (cols / 2) as f64)) * dx;
            if r < 0.9 * a_target {
                worst = worst.max((p - hertz.pressure(d_target, r)).abs() / p0);
            }
        }
        assert!(
            worst < 0.005,
            "{rows}x{cols}: pressure error {worst:e} of p0"
        );
        eprintln!(
            "hertz {rows}x{cols}: d error {d_error:.2e}, a {:.3} px, p error {worst:.2e}, {} iterations",
            (a - a_target) / dx,
            info.iterations
        );
    }

    #[test]
    fn hertz_even_grid() {
        check_hertz(64, 64);
    }

    #[test]
    fn hertz_odd_grid() {
        check_hertz(63, 63);
    }

    #[test]
    fn hertz_non_square_grid() {
        check_hertz(50, 72);
    }

    #[test]
    fn hertz_displacement_control_gives_the_hertz_force() {
        let (size, radius) = (1.0, 2.0);
        let n = 64;
        let dx = size / n as f64;
        let hertz = Hertz {
            radius,
            modulus: 1.0,
        };
        let d = (16.0 * dx).powi(2) / radius;
        let mut solver =
            ContactSolver::new(&sphere(n, n, size, radius), free(), SolverParams::default())
                .unwrap();
        let (s, _) = solver.solve(Control::Indentation(d)).unwrap();
        let error = s.force / hertz.force(d) - 1.0;
        assert!(error.abs() < 0.01, "force error {error:e}");
        assert_eq!(s.indentation, d);
        // Load control at that force returns the same state.
        let (t, _) = solver.solve(Control::Force(s.force)).unwrap();
        assert!((t.indentation / d - 1.0).abs() < 1e-6);
        assert_eq!(t.contact_points, s.contact_points);
    }

    #[test]
    fn westergaard_partial_contact_and_full_contact() {
        // Non-square: 8 rows (the problem is one-dimensional), 128 columns = one wavelength.
        let (rows, cols, size, amplitude, modulus) = (8, 128, 1.0, 0.01, 2.0);
        let dx = size / cols as f64;
        let heights = Array2::from_shape_fn((rows, cols), |(_, j)| {
            amplitude * (2.0 * PI * j as f64 * dx / size).cos()
        });
        let surface = Surface::new(heights, size).unwrap();
        let reference = Westergaard {
            wavelength: size,
            amplitude,
            modulus,
        };
        let p_star = reference.full_contact_pressure();
        let half_space = HalfSpace {
            modulus,
            boundary: Boundary::Periodic,
        };
        let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
        for ratio in [0.1, 0.5, 0.9] {
            let (s, _) = solver.solve(Control::MeanPressure(ratio * p_star)).unwrap();
            let expected = reference.contact_fraction(ratio * p_star);
            // The contact edge is resolved to a pixel on each side.
            assert!(
                (s.area_fraction - expected).abs() <= 2.0 / cols as f64,
                "p/p* = {ratio}: {} vs {expected}",
                s.area_fraction
            );
            eprintln!(
                "westergaard p/p* = {ratio}: area {} vs {expected:.5}",
                s.area_fraction
            );
            let pressure = solver.pressure();
            let p_max = reference.pressure(ratio * p_star, 0.0);
            let mut worst = 0.0f64;
            for j in 0..cols {
                let x = if j <= cols / 2 {
                    j as f64
                } else {
                    j as f64 - cols as f64
                } * dx;
                let a = reference.contact_half_width(ratio * p_star);
                if x.abs() < a - 2.0 * dx {
                    let error = (pressure[[3, j]] - reference.pressure(ratio * p_star, x)).abs();
                    assert!(
                        error < 0.01 * p_max,
                        "p/p* = {ratio}, x = {x}: error {error}"
                    );
                    worst = worst.max(error / p_max);
                }
            }
            eprintln!("westergaard p/p* = {ratio}: pressure error {worst:.2e} of p_max");
        }
        // Full contact at p* = π E* Δ / λ: the threshold is exact for a single mode.
        match solver.solve(Control::MeanPressure(1.001 * p_star)) {
            Err(SolveError::BeyondFullContact {
                full_contact: Some(full),
                ..
            }) => {
                eprintln!("westergaard full contact {full:.12e} vs p* {p_star:.12e}");
                assert!((full / p_star - 1.0).abs() < 1e-12, "{full} vs {p_star}")
            }
            other => panic!("expected BeyondFullContact, got {other:?}"),
        }
    }

    #[test]
    fn free_load_beyond_full_contact_is_an_error() {
        let surface = rough(32, 1);
        let mut solver = ContactSolver::new(&surface, free(), SolverParams::default()).unwrap();
        match solver.solve(Control::MeanPressure(1e3)) {
            Err(SolveError::BeyondFullContact {
                requested,
                full_contact: Some(full),
            }) => {
                assert_eq!(requested, Control::MeanPressure(1e3));
                assert!(full > 0.0 && full < 1e3, "{full}");
                // Just below the threshold the contact is partial, just above it is full.
                let (below, _) = solver.solve(Control::MeanPressure(0.9 * full)).unwrap();
                assert!(below.area_fraction < 1.0);
                assert!(matches!(
                    solver.solve(Control::MeanPressure(1.1 * full)),
                    Err(SolveError::BeyondFullContact { .. })
                ));
                // A force is refused in its own terms: the message names the force and the
                // threshold force (mean pressure × nominal area, here L = 2).
                let surface = Surface::new(surface.heights().clone(), 2.0).unwrap();
                let mut solver =
                    ContactSolver::new(&surface, free(), SolverParams::default()).unwrap();
                let err = solver.solve(Control::Force(20.0)).unwrap_err();
                let message = err.to_string();
                assert!(
                    message.starts_with("force 2.000000e1 is beyond full contact")
                        && message.contains("from a force of")
                        && !message.contains("mean pressure"),
                    "{message}"
                );
                match err {
                    SolveError::BeyondFullContact {
                        requested: Control::Force(f),
                        full_contact: Some(full_force),
                    } => {
                        assert_eq!(f, 20.0);
                        // Pressures scale with 1/L for the same heights: p*(L=2) = p*(1)/2.
                        assert!((full_force / (4.0 * full / 2.0) - 1.0).abs() < 1e-6);
                    }
                    other => panic!("expected BeyondFullContact, got {other:?}"),
                }
            }
            other => panic!("expected BeyondFullContact, got {other:?}"),
        }
    }

    #[test]
    fn free_indentation_beyond_full_contact_is_an_error() {
        // Displacement control is refused beyond full contact like load control, with the
        // smallest indentation that brings every pixel into contact, d* = max(K⁻¹f / K⁻¹1).
        let surface = rough(32, 1);
        let mut solver = ContactSolver::new(&surface, free(), SolverParams::default()).unwrap();
        let err = solver.solve(Control::Indentation(5.0)).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("indentation 5.000000e0 is beyond full contact"),
            "{err}"
        );
        let SolveError::BeyondFullContact {
            requested: Control::Indentation(requested),
            full_contact: Some(d_star),
        } = err
        else {
            panic!("expected BeyondFullContact, got {err:?}");
        };
        assert_eq!(requested, 5.0);
        assert!(solver.summary().is_none());
        assert!(solver.frozen_set_stiffness().is_err());
        // Full contact needs d = u + f everywhere with u ≥ 0 (positive pressures push a
        // free half-space down everywhere): d* is at least the deepest valley, max f.
        let depth = surface
            .heights()
            .iter()
            .fold(f64::NEG_INFINITY, |m, &h| m.max(h))
            - surface
                .heights()
                .iter()
                .fold(f64::INFINITY, |m, &h| m.min(h));
        assert!(d_star > depth && d_star < 5.0, "{d_star} vs depth {depth}");
        // Just below d* the contact is partial (a cold start after the error), and the load
        // it carries is just below the full-contact mean pressure; just above, refused.
        let (below, _) = solver.solve(Control::Indentation(0.999 * d_star)).unwrap();
        assert!(below.area_fraction < 1.0 && below.area_fraction > 0.9);
        let p_star = match solver.solve(Control::MeanPressure(1e3)) {
            Err(SolveError::BeyondFullContact {
                full_contact: Some(p),
                ..
            }) => p,
            other => panic!("expected BeyondFullContact, got {other:?}"),
        };
        let ratio = below.mean_pressure / p_star;
        eprintln!(
            "free full contact: d* = {d_star:.6e} (depth {depth:.3e}), p(0.999 d*) / p* = {ratio:.6}, area {}",
            below.area_fraction
        );
        assert!(ratio < 1.0 && ratio > 0.99, "{ratio}");
        assert!(matches!(
            solver.solve(Control::Indentation(1.001 * d_star)),
            Err(SolveError::BeyondFullContact {
                requested: Control::Indentation(_),
                full_contact: Some(_),
            })
        ));
        // A partial contact still solves after the refusals.
        let (partial, _) = solver.solve(Control::Indentation(0.5 * d_star)).unwrap();
        assert!(partial.area_fraction < 1.0);
    }

    #[test]
    fn free_and_periodic_agree_for_a_small_contact() {
        // Contact radius 5 pixels on a 96² grid: the periodic images shift the indentation
        // but barely change the contact area and pressures.
        let (n, size, radius) = (96, 1.0, 1.0);
        let dx = size / n as f64;
        let force = Hertz {
            radius,
            modulus: 1.0,
        }
        .force((5.0 * dx).powi(2) / radius);
        let surface = sphere(n, n, size, radius);
        let mut results = Vec::new();
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let half_space = HalfSpace {
                modulus: 1.0,
                boundary,
            };
            let mut solver =
                ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
            let (s, _) = solver.solve(Control::Force(force)).unwrap();
            let p_max = solver.pressure().iter().fold(0.0f64, |m, &p| m.max(p));
            results.push((s.contact_points, p_max));
        }
        let (free_points, free_peak) = results[0];
        let (periodic_points, periodic_peak) = results[1];
        eprintln!(
            "free vs periodic: contact points {free_points} vs {periodic_points}, peak pressure \
             ratio {:.4}",
            free_peak / periodic_peak
        );
        // The two kernels differ at the pixel scale (Love vs 2/(E*q)) and by the images
        // (measured: the same 89 points, peak pressures 8e-4 apart); allow a few edge
        // pixels and 0.5 %.
        assert!(
            (free_points as i64 - periodic_points as i64).abs() <= 4,
            "{free_points} vs {periodic_points}"
        );
        assert!(
            (free_peak / periodic_peak - 1.0).abs() < 0.005,
            "{free_peak} vs {periodic_peak}"
        );
    }

    #[test]
    fn warm_start_saves_iterations() {
        let surface = rough(64, 2);
        let mut solver = ContactSolver::new(&surface, free(), SolverParams::default()).unwrap();
        let (_, first) = solver.solve(Control::MeanPressure(0.02)).unwrap();
        let (warm_state, warm) = solver.solve(Control::MeanPressure(0.022)).unwrap();
        solver.reset();
        let (cold_state, cold) = solver.solve(Control::MeanPressure(0.022)).unwrap();
        assert!(
            warm.iterations < cold.iterations,
            "warm {} vs cold {}",
            warm.iterations,
            cold.iterations
        );
        assert!(first.iterations > 0);
        assert_eq!(warm_state.contact_points, cold_state.contact_points);
        assert!((warm_state.indentation / cold_state.indentation - 1.0).abs() < 1e-7);
    }

    #[test]
    fn a_reused_solver_equals_a_new_one() {
        let (first, second) = (rough(40, 1), rough(40, 2));
        let mut reused = ContactSolver::new(&first, free(), SolverParams::default()).unwrap();
        reused.solve(Control::MeanPressure(0.02)).unwrap();
        reused.frozen_set_stiffness().unwrap();
        reused.set_surface(&second).unwrap();
        let mut fresh = ContactSolver::new(&second, free(), SolverParams::default()).unwrap();
        for p in [0.01, 0.03] {
            let (a, ia) = reused.solve(Control::MeanPressure(p)).unwrap();
            let (b, ib) = fresh.solve(Control::MeanPressure(p)).unwrap();
            assert_eq!((a, ia), (b, ib));
            assert_eq!(
                reused.frozen_set_stiffness().unwrap(),
                fresh.frozen_set_stiffness().unwrap()
            );
        }
        assert!(
            reused.set_surface(&rough(32, 1)).is_err(),
            "other grid refused"
        );
    }

    #[test]
    fn results_do_not_depend_on_the_thread_count() {
        let surface = rough(48, 3);
        let run = |threads: usize| {
            crate::test_support::with_threads(threads, || {
                let mut solver =
                    ContactSolver::new(&surface, free(), SolverParams::default()).unwrap();
                let (s, info) = solver.solve(Control::MeanPressure(0.05)).unwrap();
                let (k, _) = solver.frozen_set_stiffness().unwrap();
                (
                    solver.pressure().to_owned(),
                    s.indentation,
                    info.iterations,
                    k,
                )
            })
        };
        let one = run(1);
        for threads in [2, 3] {
            assert_eq!(one, run(threads), "{threads} threads");
        }
    }

    #[test]
    fn bad_input_is_refused() {
        let surface = rough(16, 4);
        let bad_tolerance = SolverParams {
            tolerance: 0.0,
            ..SolverParams::default()
        };
        assert!(matches!(
            ContactSolver::new(&surface, free(), bad_tolerance),
            Err(SolveError::Input(Error::InvalidParameter { .. }))
        ));
        let negative = SolverParams {
            tolerance: -1e-6,
            ..SolverParams::default()
        };
        assert!(ContactSolver::new(&surface, free(), negative).is_err());
        let mut solver = ContactSolver::new(&surface, free(), SolverParams::default()).unwrap();
        for control in [
            Control::MeanPressure(-1.0),
            Control::MeanPressure(0.0),
            Control::Force(f64::NAN),
            Control::Indentation(-0.1),
        ] {
            assert!(
                matches!(solver.solve(control), Err(SolveError::Input(_))),
                "{control:?}"
            );
        }
        let periodic = HalfSpace {
            modulus: 1.0,
            boundary: Boundary::Periodic,
        };
        let mut solver = ContactSolver::new(&surface, periodic, SolverParams::default()).unwrap();
        for control in [Control::Indentation(-0.1), Control::Indentation(f64::NAN)] {
            assert!(
                matches!(solver.solve(control), Err(SolveError::Input(_))),
                "{control:?}"
            );
        }
        // A NaN surface cannot be built.
        let mut heights = surface.heights().clone();
        heights[[3, 4]] = f64::NAN;
        assert!(Surface::new(heights, 1.0).is_err());
        // A grid too large for memory is refused before anything is allocated.
        let err = memory::ensure_fits(
            "test",
            ContactSolver::memory_bytes(1 << 19, 1 << 19, Boundary::Free),
        )
        .unwrap_err();
        assert!(matches!(err, Error::OutOfMemory { .. }));
    }

    #[test]
    fn no_convergence_is_an_error_with_the_residual() {
        let surface = rough(32, 5);
        let params = SolverParams {
            max_iterations: 3,
            ..SolverParams::default()
        };
        let mut solver = ContactSolver::new(&surface, free(), params).unwrap();
        assert_no_convergence(&mut solver, Control::MeanPressure(0.01), &params);
    }

    /// `control` stops at the iteration limit with `NoConvergence` (the iterations and a
    /// finite residual above the tolerance) and leaves no solved state behind.
    pub(crate) fn assert_no_convergence(
        solver: &mut ContactSolver,
        control: Control,
        params: &SolverParams,
    ) {
        match solver.solve(control) {
            Err(SolveError::NoConvergence {
                iterations,
                residual,
            }) => {
                assert_eq!(iterations, params.max_iterations);
                assert!(residual > params.tolerance && residual.is_finite());
            }
            other => panic!("expected NoConvergence, got {other:?}"),
        }
        assert!(solver.summary().is_none());
        assert!(solver.frozen_set_stiffness().is_err());
    }

    #[test]
    fn solution_satisfies_the_contact_conditions() {
        let surface = rough(64, 6);
        let mut solver = ContactSolver::new(&surface, free(), SolverParams::default()).unwrap();
        let (s, _) = solver.solve(Control::MeanPressure(0.03)).unwrap();
        let state = solver.state().unwrap();
        let f_top = surface
            .heights()
            .iter()
            .fold(f64::NEG_INFINITY, |m, &h| m.max(h));
        let rms = 0.5 / (2.0 * PI); // loose scale: rms slope 0.5, wavelengths ≥ L/4
        for ((&p, &u), &h) in state
            .pressure
            .iter()
            .zip(&state.displacement)
            .zip(surface.heights())
        {
            assert!(p >= 0.0);
            let g = u + (f_top - h) - s.indentation;
            if p > 0.0 {
                assert!(g.abs() < 1e-6 * rms, "gap {g} in contact");
            } else {
                assert!(g > -1e-6 * rms, "penetration {g}");
            }
        }
        let total: f64 = state.pressure.iter().sum::<f64>() / (64.0 * 64.0);
        assert!((total / 0.03 - 1.0).abs() < 1e-12);
        assert!(state.gap.iter().all(|&g| g >= 0.0));
    }
}
