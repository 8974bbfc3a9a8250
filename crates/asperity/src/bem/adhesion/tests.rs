//! Oracles of the adhesive BEM: JKR's sphere, Kendall's punch, the non-adhesive limit.

use std::f64::consts::PI;

use ndarray::Array2;

use super::*;
use crate::bem::HalfSpace;
use crate::reference::{Jkr, PullOff};
use crate::surface::Surface;

/// A sphere `h = −r²/2R` on `n × n` pixels of side `dx`, centred on pixel `(n/2, n/2)`.
fn sphere(n: usize, dx: f64, radius: f64) -> Surface {
    let c = (n / 2) as f64;
    let heights = Array2::from_shape_fn((n, n), |(i, j)| {
        let (y, x) = ((i as f64 - c) * dx, (j as f64 - c) * dx);
        -(x * x + y * y) / (2.0 * radius)
    });
    Surface::new(heights, n as f64 * dx).unwrap()
}

/// The JKR sphere retracted from a contact `1.25 a_c`: its pull-offs and the largest
/// distance of a peeling state from JKR's force at its contact radius `√(A/π)`, over
/// `|F_c|`.
fn jkr_retraction(pixels_per_radius: f64) -> (f64, f64, f64) {
    let (radius, modulus, a_c): (f64, f64, f64) = (1.0, 1.0, 0.1);
    let w = 8.0 * modulus * a_c.powi(3) / (9.0 * PI * radius * radius);
    let dx = a_c / pixels_per_radius;
    let n = (2.0 * 1.4 * a_c / dx).ceil() as usize + 4;
    let mut contact = PixelAdhesion::new(&sphere(n, dx, radius), HalfSpace::default(), w).unwrap();
    let d0 = (1.25 * a_c).powi(2) / radius;
    for k in 1..=10 {
        contact.move_to(d0 * k as f64 / 10.0).unwrap();
    }
    let jkr = Jkr::new(radius, modulus, w).unwrap();
    let f_c = jkr.pull_off_force(PullOff::ForceControlled);
    let start = contact.summary().attached_points;
    let mut worst = 0.0f64;
    let pull = contact
        .retract(3.0 * d0 / 1000.0, |s| {
            if s.attached_points < start {
                let a = (s.attached_points as f64 * dx * dx / PI).sqrt();
                worst = worst.max((s.force - jkr.force(a)).abs() / f_c.abs());
            }
        })
        .unwrap()
        .expect("in contact");
    let f_d = jkr.pull_off_force(PullOff::DisplacementControlled);
    (
        pull.force_controlled.force / f_c - 1.0,
        pull.displacement_controlled.force / f_d - 1.0,
        worst,
    )
}

/// Pohrt–Popov's criterion converges at first order in the pixel on a sphere: the
/// force-controlled pull-off of JKR (`−(3/2)πwR`) is reached with an error `≈ 1.37 Δx/a_c`
/// (measured: +13.8 % at `a_c/Δx = 10`, +6.9 % at 20, +3.9 % at 40: the slow test below),
/// the displacement-controlled one (`−(5/6)πwR`) with `≈ 2.5 Δx/a_c` (+24.9 %, +12.7 %, −0.8 %: it
/// oscillates with the pixel, as the radius at which the last ring lets go does),
/// and the peeling states' forces lie within `≈ 2 Δx/a_c · |F_c|` of JKR's at their contact
/// radius `√(A/π)` (0.189, 0.105, 0.042). (The contact holds too much; our reading: the
/// criterion is calibrated on the singular tension alone — Kendall's punch, which has no
/// other, is within 0.7 % and 0.24 % — while a sphere's edge pixel also carries Hertzian
/// compression, a share of order `Δx/a_c`; docs/adhesion.md.) Tolerances: halving the
/// pixel at least nearly halves each error
/// (ratio above 1.75; measured 2.00, 1.97, 1.79), and the first-order (Richardson)
/// extrapolation of the two pull-offs lands on JKR within 1 % (measured 1e-4 and 4e-3).
#[test]
fn jkr_sphere_converges_with_the_pixel() {
    let coarse = jkr_retraction(10.0);
    let fine = jkr_retraction(20.0);
    println!("a_c/dx = 10: {coarse:?}\na_c/dx = 20: {fine:?}");
    for (c, f) in [(coarse.0, fine.0), (coarse.1, fine.1), (coarse.2, fine.2)] {
        assert!(c > 0.0 && f > 0.0 && c / f > 1.75, "{c:e} {f:e}");
    }
    for (c, f) in [(coarse.0, fine.0), (coarse.1, fine.1)] {
        assert!((2.0 * f - c).abs() < 1e-2, "extrapolated {:e}", 2.0 * f - c);
    }
    assert!(fine.0 < 0.075, "{:e}", fine.0);
}

/// The JKR sphere at `a_c/Δx = 40` (slow tier, about ten seconds): the force-controlled
/// pull-off within 4.5 % (measured +3.93 %; first order from 20 would say 3.4 %).
#[test]
#[ignore]
fn jkr_sphere_at_forty_pixels() {
    let errors = jkr_retraction(40.0);
    println!("a_c/dx = 40: {errors:?}");
    assert!(errors.0 > 0.0 && errors.0 < 0.045, "{errors:?}");
}

/// A flat circular punch of radius `a_px` pixels (profile 0 on the disc, 1 beyond): the
/// attached disc lets go at Kendall's force `−√(8πwE*a³)`, `a = √(A/π)` of the pixels.
fn kendall_pull_off(a_px: f64) -> (f64, f64) {
    let (a, w): (f64, f64) = (0.1, 1e-3);
    let dx = a / a_px;
    let n = (2.0 * a_px).ceil() as usize + 8;
    let c = (n / 2) as f64;
    let heights = Array2::from_shape_fn((n, n), |(i, j)| {
        let r = (i as f64 - c).hypot(j as f64 - c);
        if r <= a_px {
            0.0
        } else {
            -1.0
        }
    });
    let surface = Surface::new(heights, n as f64 * dx).unwrap();
    let mut contact = PixelAdhesion::new(&surface, HalfSpace::default(), w).unwrap();
    let (pressed, _) = contact.move_to(1e-4).unwrap();
    let area = pressed.attached_points as f64 * dx * dx;
    let kendall = -(8.0 * PI * w * (area / PI).powf(1.5)).sqrt();
    let step = (2.0 * PI * a * w).sqrt() / 200.0;
    let pull = contact.retract(step, |_| {}).unwrap().expect("in contact");
    (
        pull.force_controlled.force / kendall - 1.0,
        pull.displacement_controlled.force / kendall - 1.0,
    )
}

/// Kendall's punch: the pull-off under either control is the force at which the edge
/// first lets go (the whole face follows). Measured: +0.71 % at `a/Δx = 10`, +0.24 % at
/// 20 (the staircase edge of a pixelated disc); tolerances 1 % and 0.4 %, and the two
/// controls agree (one event ends both).
#[test]
fn kendall_punch_lets_go_at_kendalls_force() {
    for a_px in [10.0, 20.0] {
        let (force, displacement) = kendall_pull_off(a_px);
        println!("a/dx = {a_px}: force-controlled {force:+.4e}, displacement-controlled {displacement:+.4e}");
        let tolerance = if a_px < 15.0 { 1e-2 } else { 4e-3 };
        assert!(force.abs() < tolerance, "{force:e}");
        assert!(
            (force - displacement).abs() < 1e-4,
            "{force:e} {displacement:e}"
        );
    }
}

/// As `w → 0` the adhesive contact is the non-adhesive one: the same force as the BCCG at
/// the same indentation (to 1e-6, the solvers' tolerances), no pixel in measurable tension,
/// and a pull-off that vanishes.
#[test]
fn vanishing_adhesion_is_the_hard_wall() {
    let (n, dx, radius) = (48, 0.01, 1.0);
    let surface = sphere(n, dx, radius);
    let mut contact = PixelAdhesion::new(&surface, HalfSpace::default(), 1e-14).unwrap();
    let mut solver =
        crate::bem::ContactSolver::new(&surface, HalfSpace::default(), Default::default()).unwrap();
    for d in [0.002, 0.008, 0.02] {
        let (adhesive, info) = contact.move_to(d).unwrap();
        let (plain, _) = solver.solve(crate::bem::Control::Indentation(d)).unwrap();
        let error = (adhesive.force / plain.force - 1.0).abs();
        assert!(error < 1e-6, "d = {d}: {error:e} ({info:?})");
    }
    let pull = contact.retract(1e-4, |_| {}).unwrap().expect("in contact");
    assert!(pull.force_controlled.force.abs() < 1e-6, "{pull:?}");
}

/// Loading then unloading is a loop: on the way back the contact holds on, so at every
/// indentation the retraction's force is below the approach's, and tension appears.
#[test]
fn retraction_lies_below_the_approach() {
    let (n, dx, radius, w) = (48, 0.01, 1.0, 2e-3);
    let mut contact = PixelAdhesion::new(&sphere(n, dx, radius), HalfSpace::default(), w).unwrap();
    let depths: Vec<f64> = (1..=8).map(|k| 0.0025 * k as f64).collect();
    let approach: Vec<f64> = depths
        .iter()
        .map(|&d| contact.move_to(d).unwrap().0.force)
        .collect();
    for (k, &d) in depths.iter().enumerate().rev().skip(1) {
        let (back, _) = contact.move_to(d).unwrap();
        assert!(
            back.force < approach[k],
            "d = {d}: {} vs {}",
            back.force,
            approach[k]
        );
        assert!(back.tensile_points > 0);
    }
}

#[test]
fn refuses_meaningless_inputs() {
    let surface = sphere(16, 0.01, 1.0);
    for w in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        assert!(
            PixelAdhesion::new(&surface, HalfSpace::default(), w).is_err(),
            "{w}"
        );
    }
    let heights = Array2::zeros((8, 16));
    let rectangular = Surface::with_sizes(heights, 1.0, 1.0).unwrap();
    let error = PixelAdhesion::new(&rectangular, HalfSpace::default(), 1e-3)
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("square pixels"), "{error}");
    let mut contact = PixelAdhesion::new(&surface, HalfSpace::default(), 1e-3).unwrap();
    assert!(contact.move_to(f64::NAN).is_err());
    assert!(contact.retract(0.0, |_| {}).is_err());
    assert_eq!(contact.retract(1e-3, |_| {}).unwrap(), None);
}

/// Maugis–Dugdale's sphere on the BEM at Maugis parameter `λ`, `a_c/Δx` pixels in JKR's
/// pull-off radius `a_c` (R = 1, E* = 1, a_c = 0.1), approached to `1.25 a_c` in ten steps
/// and retracted: the relative errors of the force-controlled pull-off, of the contact
/// radius there against Maugis's, and the largest distance of a retraction state's force
/// from Maugis's at its contact radius `√(A/π)`, over `|F_c|`; and the zone's resolution.
fn maugis_retraction(lambda: f64, pixels_per_radius: f64) -> (f64, f64, f64, f64) {
    use crate::reference::MaugisDugdale;
    let (radius, modulus, a_c): (f64, f64, f64) = (1.0, 1.0, 0.1);
    let w = 8.0 * modulus * a_c.powi(3) / (9.0 * PI * radius * radius);
    let unit = MaugisDugdale::scales(radius, modulus, w, 1.0);
    let stress = lambda / unit.lambda;
    let dx = a_c / pixels_per_radius;
    let n = (2.0 * 2.0 * a_c / dx).ceil() as usize + 4;
    let law = AdhesionLaw::MaugisDugdale { range: w / stress };
    let surface = sphere(n, dx, radius);
    let mut contact = PixelAdhesion::with_law(&surface, HalfSpace::default(), w, law).unwrap();
    let d0 = (1.25 * a_c).powi(2) / radius;
    for k in 1..=10 {
        contact.move_to(d0 * k as f64 / 10.0).unwrap();
    }
    let md = MaugisDugdale::new(lambda).unwrap();
    let reference = md.pull_off(PullOff::ForceControlled);
    let f_c = reference.force * unit.force;
    let start = contact.summary().attached_points;
    let mut worst = 0.0f64;
    let pull = contact
        .retract(3.0 * d0 / 1000.0, |s| {
            if s.attached_points < start {
                let a = (s.attached_points as f64 * dx * dx / PI).sqrt();
                let f = md.at_radius(a / unit.radius).force * unit.force;
                worst = worst.max((s.force - f).abs() / f_c.abs());
            }
        })
        .unwrap()
        .expect("in contact");
    let at = pull.force_controlled;
    let a = (at.attached_points as f64 * dx * dx / PI).sqrt();
    (
        at.force / f_c - 1.0,
        a / (reference.radius * unit.radius) - 1.0,
        worst,
        contact.cohesive_resolution().unwrap(),
    )
}

/// The Maugis–Dugdale cohesive zone converges to Maugis's sphere once the zone spans
/// pixels: at λ = 1 the force-controlled pull-off (`−1.601πwR`) is reached within +4.87 %,
/// +1.78 % at `a_c/Δx` = 10, 20 (and +2.23 %, +1.32 %, +0.60 % at 14, 30, 40: the slow
/// test; about order 1.5, `log(4.87/0.60)/log 4 = 1.51`), and the retraction's forces lie
/// within 0.165, 0.066 of `|F_c|` of Maugis's at their contact radius. Tolerances: the
/// error falls by more than 2 when the pixel halves (measured 2.7), and within the
/// issue's 2 % at 20 pixels.
#[test]
fn maugis_dugdale_sphere_converges_with_the_pixel() {
    let coarse = maugis_retraction(1.0, 10.0);
    let fine = maugis_retraction(1.0, 20.0);
    println!("lambda = 1, a_c/dx = 10: {coarse:?}\na_c/dx = 20: {fine:?}");
    assert!(fine.0 > 0.0 && fine.0 < 0.02, "{fine:?}");
    assert!(coarse.0 / fine.0 > 2.0, "{coarse:?} {fine:?}");
    assert!(fine.1.abs() < 0.03, "contact radius at pull-off {fine:?}");
    assert!(
        fine.2 < 0.08 && coarse.2 / fine.2 > 2.0,
        "{coarse:?} {fine:?}"
    );
    // The zone spans pixels: a pixel's own tension closes a fraction of the range.
    assert!(fine.3 > 10.0, "{fine:?}");
}

/// Toward DMT: at λ = 0.5 (cohesive zone 1.4 times the contact radius at pull-off, which
/// Maugis puts at `−1.718πwR`, between JKR's 1.5 and DMT's 2) the force-controlled
/// pull-off within +2.38 % and +0.81 % at `a_c/Δx` = 10, 20 (+0.24 % at 40). Tolerances 3 %
/// and 1.2 %, and the error falls by more than 2.
#[test]
fn maugis_dugdale_sphere_toward_dmt() {
    let coarse = maugis_retraction(0.5, 10.0);
    let fine = maugis_retraction(0.5, 20.0);
    println!("lambda = 0.5, a_c/dx = 10: {coarse:?}\na_c/dx = 20: {fine:?}");
    assert!(coarse.0 > 0.0 && coarse.0 < 0.03, "{coarse:?}");
    assert!(fine.0 > 0.0 && fine.0 < 0.012, "{fine:?}");
    assert!(coarse.0 / fine.0 > 2.0, "{coarse:?} {fine:?}");
}

/// The Tabor/Maugis sweep from DMT toward JKR (slow tier, about four minutes) at
/// `a_c/Δx = 40`: the force-controlled pull-off `|F|/πwR` lies between JKR's 1.5 and DMT's
/// 2, falls as λ grows, and is Maugis's within 1.5 % (measured +0.24 %, +0.60 %, +1.35 % at
/// λ = 0.5, 1, 2; at λ = 2 the zone is 0.14 of the contact radius, 5.8 pixels).
#[test]
#[ignore]
fn maugis_dugdale_sweep_from_dmt_to_jkr() {
    let mut previous = 2.0;
    for lambda in [0.5, 1.0, 2.0] {
        let (error, ..) = maugis_retraction(lambda, 40.0);
        let md = crate::reference::MaugisDugdale::new(lambda).unwrap();
        let normalised = -md.pull_off(PullOff::ForceControlled).force * (1.0 + error);
        println!("lambda = {lambda}: |F|/(pi w R) = {normalised:.4}, error {error:+.4e}");
        assert!(error.abs() < 0.015, "{error:e}");
        assert!(normalised > 1.5 && normalised < previous, "{normalised}");
        previous = normalised;
    }
}

/// As `w → 0` at a fixed range the cohesive zone carries nothing: the forces are the
/// non-adhesive solver's to 1e-6; and a range that is not positive and finite is refused.
#[test]
fn vanishing_dugdale_stress_is_the_hard_wall() {
    let (n, dx, radius) = (48, 0.01, 1.0);
    let surface = sphere(n, dx, radius);
    let law = AdhesionLaw::MaugisDugdale { range: 1e-3 };
    let mut contact = PixelAdhesion::with_law(&surface, HalfSpace::default(), 1e-14, law).unwrap();
    let mut solver =
        crate::bem::ContactSolver::new(&surface, HalfSpace::default(), Default::default()).unwrap();
    for d in [0.002, 0.008, 0.02] {
        let (adhesive, info) = contact.move_to(d).unwrap();
        let (plain, _) = solver.solve(crate::bem::Control::Indentation(d)).unwrap();
        let error = (adhesive.force / plain.force - 1.0).abs();
        assert!(error < 1e-6, "d = {d}: {error:e} ({info:?})");
        assert!(adhesive.cohesive_points > 0);
    }
    for range in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        let law = AdhesionLaw::MaugisDugdale { range };
        let refused = PixelAdhesion::with_law(&surface, HalfSpace::default(), 1e-3, law);
        assert!(refused.is_err(), "{range}");
    }
}
