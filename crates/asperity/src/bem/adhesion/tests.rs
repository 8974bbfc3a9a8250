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
        .retract(3.0 * d0 / 1000.0, |s, _| {
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
    let pull = contact
        .retract(step, |_, _| {})
        .unwrap()
        .expect("in contact");
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
    let pull = contact
        .retract(1e-4, |_, _| {})
        .unwrap()
        .expect("in contact");
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

/// The retraction reports each step's counts: every step solves at least once (rounds ≥ 1,
/// CG iterations > 0), and the counts are those of the same steps taken one by one with
/// `move_to` from the same state (the callback passes the step's own `AdhesionInfo`).
#[test]
fn retraction_reports_each_steps_counts() {
    let (n, dx, radius, w, step) = (32, 0.01, 1.0, 2e-3, 1e-3);
    let surface = sphere(n, dx, radius);
    let mut contact = PixelAdhesion::new(&surface, HalfSpace::default(), w).unwrap();
    let mut replay = PixelAdhesion::new(&surface, HalfSpace::default(), w).unwrap();
    contact.move_to(0.01).unwrap();
    replay.move_to(0.01).unwrap();
    let mut reported = Vec::new();
    contact
        .retract(step, |s, info| reported.push((*s, *info)))
        .unwrap()
        .expect("in contact");
    assert!(reported.len() >= 5, "{} steps", reported.len());
    let mut d = 0.01;
    for (state, info) in &reported {
        assert!(info.rounds >= 1 && info.cg_iterations > 0, "{info:?}");
        d -= step;
        let (again, expected) = replay.move_to(d).unwrap();
        assert_eq!((state, info), (&again, &expected), "d = {d}");
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
    assert!(contact.retract(0.0, |_, _| {}).is_err());
    assert_eq!(contact.retract(1e-3, |_, _| {}).unwrap(), None);
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
        .retract(3.0 * d0 / 1000.0, |s, _| {
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

/// Johnson's adhesive sinusoid (`reference::JohnsonSinusoid`, λ = 1, Δ = 0.01, E* = 1,
/// α = 0.5) on a periodic grid, its crests along y (`diagonal` false: `n` pixels per
/// wavelength, 2 rows, a front along the grid) or along the diagonal (`diagonal` true:
/// `n × n` pixels, wave vector `(1, 1)·2π/L`, λ = L/√2, a staircase front), under `law`.
/// Loaded to a contact of half-width 0.2λ in 20 steps and retracted by steps of 1/`steps` of
/// the travel; returns the relative
/// errors of the force- and displacement-controlled pull-offs (mean pressure), the largest
/// distance of a peeling state's mean pressure from Johnson's at its half-width (contact
/// fraction · λ/2) over `|p̄_c|`, and the pull-off half-width in pixels (along x).
fn johnson_retraction(
    n: usize,
    diagonal: bool,
    law: AdhesionLaw,
    steps: f64,
) -> (f64, f64, f64, f64) {
    use crate::reference::JohnsonSinusoid;
    let (amplitude, modulus, size) = (0.01, 1.0, 1.0);
    let (rows, wavelength) = match diagonal {
        false => (2, size),
        true => (n, size / 2f64.sqrt()),
    };
    let w = johnson_work_of_adhesion(wavelength);
    let wavy = JohnsonSinusoid::new(wavelength, amplitude, modulus, w).unwrap();
    let dx = size / n as f64;
    let heights = Array2::from_shape_fn((rows, n), |(i, j)| {
        let phase = (j as f64 - (n / 2) as f64) + if diagonal { i as f64 } else { 0.0 };
        amplitude * (2.0 * PI * phase / n as f64).cos()
    });
    let surface = Surface::new(heights, size).unwrap();
    let half_space = HalfSpace {
        modulus,
        boundary: crate::elastic::Boundary::Periodic,
    };
    let mut contact = PixelAdhesion::with_law(&surface, half_space, w, law).unwrap();
    let d0 = wavy.approach(0.2 * wavelength).max(0.0) + 0.2 * amplitude;
    for k in 1..=20 {
        contact.move_to(d0 * k as f64 / 20.0).unwrap();
    }
    let (_, p_c) = wavy.pull_off(PullOff::ForceControlled).unwrap();
    let (_, p_d) = wavy.pull_off(PullOff::DisplacementControlled).unwrap();
    let start = contact.summary().attached_points;
    let half_width = |s: &AdhesiveSummary| s.area_fraction * wavelength / 2.0;
    let mut worst = 0.0f64;
    let pull = contact
        .retract((d0 + law.range().unwrap_or(0.0)) / steps, |s, _| {
            if s.attached_points < start {
                let p = wavy.mean_pressure(half_width(s));
                worst = worst.max((s.mean_pressure - p).abs() / p_c.abs());
            }
        })
        .unwrap()
        .expect("in contact");
    (
        pull.force_controlled.mean_pressure / p_c - 1.0,
        pull.displacement_controlled.mean_pressure / p_d - 1.0,
        worst,
        half_width(&pull.force_controlled) / dx,
    )
}

/// The work of adhesion of Johnson's parameter α = 0.5 (Δ = 0.01, E* = 1).
fn johnson_work_of_adhesion(wavelength: f64) -> f64 {
    0.25 * PI * PI * 1e-4 / (2.0 * wavelength)
}

/// The periodic grid reproduces Johnson's sinusoid with a cohesive law of short range
/// (slow tier, about a CPU-minute): the exponential potential on a front along the grid
/// (2 × 256 pixels, ρ = 1.35·10⁻³ for the resolution E*ρ²/(c̄wΔx) = 4) lets go within 2 %
/// of Johnson's force-controlled pull-off (measured +0.30 %, 19.5 pixels of half-width; at
/// the same resolution +0.48 % on 2 × 512 and +0.52 % on 2 × 1024 pixels, through `asperity
/// bem`: the finite range and the pixel, not the sinusoid). The retraction steps by 1/250 of
/// the travel: 1/500 and 1/2000 give the same pull-off to 1.5·10⁻⁵ (relative) at four and
/// twelve times the cost. It also checks `JohnsonSinusoid` by an independent method.
#[test]
#[ignore]
fn johnson_sinusoid_by_a_short_exponential_range() {
    let w = johnson_work_of_adhesion(1.0);
    let c_bar = crate::reference::adhesion::pixel_mean_compliance();
    let n = 256;
    let range = (4.0 * c_bar * w / n as f64).sqrt();
    let errors = johnson_retraction(n, false, AdhesionLaw::Exponential { range }, 250.0);
    println!("n = {n}, ρ = {range:e}: {errors:?}");
    assert!(errors.0.abs() < 0.02, "{errors:?}");
}

/// The pixel criterion on the periodic grid holds Johnson's fronts too strongly, by an
/// amount that depends on the front's orientation and does not vanish with the pixel
/// (a characterization, docs/adhesion.md): the force-controlled pull-off is +54.4 %,
/// +53.0 %, +52.3 %, +51.9 % off at 14, 28, 57, 114 pixels of pull-off half-width on a
/// front along the grid, and +24.2 %, +21.8 %, +20.5 % on a diagonal (staircase) front at
/// 5, 9, 17 pixels. Checked (256 along, 64² diagonal, seconds): both
/// above +15 %, the aligned one above +40 %.
#[test]
fn pixel_criterion_on_johnson_s_sinusoid_depends_on_the_front() {
    let aligned = johnson_retraction(256, false, AdhesionLaw::PixelCriterion, 2000.0);
    let diagonal = johnson_retraction(64, true, AdhesionLaw::PixelCriterion, 2000.0);
    println!("aligned {aligned:?}\ndiagonal {diagonal:?}");
    assert!(
        aligned.0 > 0.4 && diagonal.0 > 0.15,
        "{aligned:?} {diagonal:?}"
    );
    assert!(aligned.0 > diagonal.0 + 0.15, "{aligned:?} {diagonal:?}");
}

/// A sphere (`R = 1`, `E* = 1`, `w = 10⁻³`) under the exponential potential at Tabor's
/// parameter `μ = (Rw²/E*²ρ³)^{1/3}` on pixels of `a_c/Δx = pixels` (`a_c` JKR's
/// force-controlled pull-off radius), the grid wide enough for the potential's reach
/// (gaps to 15ρ); loaded to `1.25a_c` and retracted. Returns the force-controlled
/// pull-off over `πwR`, the resolution, and the rounds of the whole run.
fn exponential_sphere(mu: f64, pixels: f64) -> (f64, f64, usize) {
    let (radius, w) = (1.0f64, 1e-3f64);
    let range = (radius * w * w / mu.powi(3)).cbrt();
    let a_c = (9.0 * PI * w * radius * radius / 8.0).cbrt();
    let dx = a_c / pixels;
    let reach = (1.4 * a_c).max((2.0 * radius * 15.0 * range).sqrt());
    let n = (2.0 * reach / dx).ceil() as usize + 4;
    let law = AdhesionLaw::Exponential { range };
    let mut contact =
        PixelAdhesion::with_law(&sphere(n, dx, radius), HalfSpace::default(), w, law).unwrap();
    let d0 = (1.25 * a_c).powi(2) / radius;
    let mut rounds = 0;
    for k in 1..=10 {
        rounds += contact.move_to(d0 * k as f64 / 10.0).unwrap().1.rounds;
    }
    let resolution = contact.cohesive_resolution().unwrap();
    let pull = contact
        .retract((d0 + range) / 500.0, |_, _| {})
        .unwrap()
        .expect("in contact");
    (
        pull.force_controlled.force / (PI * w * radius),
        resolution,
        rounds,
    )
}

/// The exponential potential's sphere at small Tabor parameter is DMT's: at μ = 0.1 the
/// force-controlled pull-off is within 2.5 % of `−2πwR` (measured −1.9596πwR at
/// `a_c/Δx = 10`, resolution 694; the rest is the elastic correction of a finite μ, of
/// the order of Maugis–Dugdale's at λ ≈ 1.16μ, −1.940), and the fixed point
/// settles every state of the run.
#[test]
fn exponential_sphere_is_dmt_at_small_tabor_parameter() {
    let (force, resolution, _) = exponential_sphere(0.1, 10.0);
    assert!(resolution > 100.0, "{resolution}");
    assert!(force < -1.95 && force > -2.0, "{force}");
}

/// Across Tabor's parameter the exponential sphere's pull-off moves from DMT's `−2πwR`
/// toward JKR's `−1.5πwR` (slow tier, minutes): measured −1.856, −1.664 at μ = 0.3, 1
/// (`a_c/Δx = 10`) and −1.550 at μ = 3 (`a_c/Δx = 20`, resolution 1.5; −1.546 at 26 pixels,
/// resolution 2.0, at 2.3 times the cost). μ = 0.1 is the fast tier's
/// (`exponential_sphere_is_dmt_at_small_tabor_parameter`: below −1.95, measured −1.960), so
/// the sweep starts above that. The tolerance at μ = 3 (within 6 % of JKR) is the distance
/// of a finite μ from the limit (Maugis–Dugdale at λ = 1.16μ = 3.48 is −1.513), not the
/// solver's.
#[test]
#[ignore]
fn exponential_sphere_moves_from_dmt_to_jkr() {
    let mut last = -1.95;
    for (mu, pixels) in [(0.3, 10.0), (1.0, 10.0), (3.0, 20.0)] {
        let (force, resolution, _) = exponential_sphere(mu, pixels);
        println!("μ = {mu}: {force} (resolution {resolution})");
        assert!(force > last && force < -1.5, "μ = {mu}: {force}");
        last = force;
    }
    assert!(last < -1.5 && last > -1.59, "{last}");
}

/// A pixel that does not resolve the range is flagged: the resolution falls as `ρ²/Δx`.
#[test]
fn exponential_resolution_is_range_squared_over_pixel() {
    let law = AdhesionLaw::Exponential { range: 1e-3 };
    let coarse = PixelAdhesion::with_law(&sphere(16, 1e-2, 1.0), HalfSpace::default(), 1e-3, law);
    let fine = PixelAdhesion::with_law(&sphere(16, 5e-3, 1.0), HalfSpace::default(), 1e-3, law);
    let (coarse, fine) = (coarse.unwrap(), fine.unwrap());
    let expected = 1e-6 / (crate::reference::adhesion::pixel_mean_compliance() * 1e-3 * 1e-2);
    assert!((coarse.cohesive_resolution().unwrap() / expected - 1.0).abs() < 1e-12);
    assert!(
        (fine.cohesive_resolution().unwrap() / coarse.cohesive_resolution().unwrap() - 2.0).abs()
            < 1e-12
    );
    assert_eq!(coarse.critical_stress(), 1.0);
    for range in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let law = AdhesionLaw::Exponential { range };
        assert!(
            PixelAdhesion::with_law(&sphere(16, 1e-2, 1.0), HalfSpace::default(), 1e-3, law)
                .is_err()
        );
    }
}

/// As `w → 0` the exponential law is the hard wall: the non-adhesive solver's forces.
#[test]
fn vanishing_exponential_adhesion_is_the_hard_wall() {
    let surface = sphere(32, 1e-2, 1.0);
    let law = AdhesionLaw::Exponential { range: 1e-3 };
    let mut contact = PixelAdhesion::with_law(&surface, HalfSpace::default(), 1e-14, law).unwrap();
    let mut solver =
        crate::bem::ContactSolver::new(&surface, HalfSpace::default(), Default::default()).unwrap();
    for d in [0.002, 0.004, 0.008] {
        let (state, _) = contact.move_to(d).unwrap();
        let (plain, _) = solver.solve(crate::bem::Control::Indentation(d)).unwrap();
        let error = (state.force / plain.force - 1.0).abs();
        assert!(error < 1e-6, "d = {d}: {error:e}");
    }
}
