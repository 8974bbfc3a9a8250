//! The BEM on rectangular pixels (Δx ≠ Δy): Hertz's closed form sampled on 2:1, 1:2 and
//! 3:2 pixels with free boundaries (the same bounds as the square-pixel Hertz tests in
//! `bem::polonsky_keer`), Hertz's stiffness `2E*a`, and the frozen-set stiffness against
//! finite differences on rough surfaces stretched to rectangular pixels.

use std::f64::consts::PI;

use crate::bem::{ContactSolver, Control, HalfSpace, SolverParams};
use crate::elastic::Boundary;
use crate::reference::Hertz;
use crate::spectrum::{LongWavelength, Psd};
use crate::surface::{Normalisation, Surface, SurfaceGenerator, SurfaceSpec};
use ndarray::Array2;

/// A sphere `h = −r²/2R` centred on pixel `(rows/2, cols/2)` of `Δx × Δy` pixels.
fn sphere(rows: usize, cols: usize, (dx, dy): (f64, f64), radius: f64) -> Surface {
    let heights = Array2::from_shape_fn((rows, cols), |(i, j)| {
        let y = (i as f64 - (rows / 2) as f64) * dy;
        let x = (j as f64 - (cols / 2) as f64) * dx;
        -(x * x + y * y) / (2.0 * radius)
    });
    Surface::with_sizes(heights, cols as f64 * dx, rows as f64 * dy).unwrap()
}

/// Errors of a load-controlled Hertz solve on `rows × cols` pixels of `Δx × Δy`, with the
/// contact radius 18 of the larger pixel sides (the square tests' 18 pixels): relative
/// indentation error, area-equivalent radius error in larger pixel sides, worst pressure
/// error inside 0.9 a relative to the peak pressure.
fn hertz_errors(rows: usize, cols: usize, spacings: (f64, f64)) -> (f64, f64, f64) {
    let (dx, dy) = spacings;
    let pixel = dx.max(dy);
    let (radius, modulus) = (2.0, 1.7);
    let hertz = Hertz { radius, modulus };
    let a_target = 18.0 * pixel;
    let d_target = a_target * a_target / radius;
    let force = hertz.force(d_target);
    let surface = sphere(rows, cols, spacings, radius);
    let half_space = HalfSpace {
        modulus,
        boundary: Boundary::Free,
    };
    let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
    assert_eq!(
        solver.nominal_area(),
        (rows * cols) as f64 * dx * dy,
        "nominal area is rows·cols·Δx·Δy"
    );
    let (s, info) = solver.solve(Control::Force(force)).unwrap();
    assert!(info.residual < 1e-8);
    assert!((s.force / force - 1.0).abs() < 1e-12);
    let d_error = s.indentation / d_target - 1.0;
    let a = (s.contact_points as f64 * dx * dy / PI).sqrt();
    let p0 = hertz.pressure(d_target, 0.0);
    let mut worst = 0.0f64;
    for ((i, j), &p) in solver.pressure().indexed_iter() {
        let y = (i as f64 - (rows / 2) as f64) * dy;
        let x = (j as f64 - (cols / 2) as f64) * dx;
        let r = x.hypot(y);
        if r < 0.9 * a_target {
            worst = worst.max((p - hertz.pressure(d_target, r)).abs() / p0);
        }
    }
    eprintln!(
        "hertz {rows}x{cols}, {dx:.4} x {dy:.4}: d error {d_error:.2e}, a error {:.3} px, \
         p error {worst:.2e}, {} iterations",
        (a - a_target) / pixel,
        info.iterations
    );
    (d_error, (a - a_target) / pixel, worst)
}

#[test]
fn hertz_on_rectangular_pixels_matches_the_closed_form() {
    // The square-pixel tests' bounds (bem::polonsky_keer, check_hertz): indentation within
    // 1 %, area-equivalent contact radius within one (larger) pixel side, pressure inside
    // 0.9 a within 0.5 % of the peak (the pixels at the edge average the square-root
    // profile). Grids: 2:1 (Δx = 2Δy), 1:2 and 3:2, each holding the contact with the same
    // margin to the free edges as the 64² square test.
    for (rows, cols, spacings) in [
        (128, 64, (1.0 / 64.0, 1.0 / 128.0)),
        (64, 128, (1.0 / 128.0, 1.0 / 64.0)),
        (96, 64, (1.0 / 64.0, 1.0 / 96.0)),
    ] {
        let (d_error, a_error, p_error) = hertz_errors(rows, cols, spacings);
        assert!(
            d_error.abs() < 0.01,
            "{rows}x{cols}: indentation error {d_error:e}"
        );
        assert!(
            a_error.abs() < 1.0,
            "{rows}x{cols}: radius error {a_error} pixels"
        );
        assert!(
            p_error < 0.005,
            "{rows}x{cols}: pressure error {p_error:e} of p0"
        );
    }
}

#[test]
fn hertz_stiffness_on_rectangular_pixels_is_two_e_a() {
    // As the square-pixel test (bem::stiffness): the pixelated contact edge costs O(Δ/a),
    // 1 % at a = 18 (larger) pixel sides.
    let (radius, modulus) = (2.0, 1.3);
    let hertz = Hertz { radius, modulus };
    let grids: [(usize, usize, (f64, f64)); 2] = [
        (128, 64, (1.0 / 64.0, 1.0 / 128.0)),
        (64, 96, (1.0 / 96.0, 1.0 / 64.0)),
    ];
    for (rows, cols, spacings) in grids {
        let (dx, dy) = spacings;
        let d = (18.0 * dx.max(dy)).powi(2) / radius;
        let half_space = HalfSpace {
            modulus,
            boundary: Boundary::Free,
        };
        let surface = sphere(rows, cols, spacings, radius);
        let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
        solver.solve(Control::Indentation(d)).unwrap();
        let (k, _) = solver.frozen_set_stiffness().unwrap();
        let error = k / hertz.stiffness(d) - 1.0;
        eprintln!("hertz stiffness {rows}x{cols}: error {error:.2e}");
        assert!(error.abs() < 0.01, "{rows}x{cols}: k error {error:e}");
    }
}

/// A rough surface (H = 0.8, roll-off 4, rms slope 0.5 on square pixels of side 1/cols),
/// then stretched along y to pixels `Δy = aspect · Δx`.
fn stretched_rough(rows: usize, cols: usize, aspect: f64, seed: u64) -> Surface {
    let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 4.0 }, None).unwrap();
    let spec = SurfaceSpec::new(rows, cols, 1.0, psd, Normalisation::RmsSlope(0.5)).unwrap();
    let square = SurfaceGenerator::new(&spec).unwrap().generate(seed);
    let size_y = rows as f64 / cols as f64 * aspect;
    Surface::with_sizes(square.into_heights(), 1.0, size_y).unwrap()
}

#[test]
fn frozen_set_stiffness_on_rectangular_pixels_equals_finite_difference() {
    // Barber: k = dF/dd. Central differences with ±1e-3 of the load, as the square-pixel
    // test (bem::stiffness): the contact set may gain or lose a few points within the
    // step, so 0.5 %. Free and periodic, Δy = 2Δx and Δy = Δx/1.5.
    for (rows, cols, aspect) in [(96, 96, 2.0), (80, 112, 1.0 / 1.5)] {
        let surface = stretched_rough(rows, cols, aspect, 11);
        assert!(!surface.has_square_pixels());
        for (boundary, pressure) in [(Boundary::Free, 0.02), (Boundary::Periodic, 0.05)] {
            let half_space = HalfSpace {
                modulus: 1.3,
                boundary,
            };
            let mut solver =
                ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
            let (s, _) = solver.solve(Control::MeanPressure(pressure)).unwrap();
            assert!((s.force / (pressure * surface.size() * surface.size_y()) - 1.0).abs() < 1e-12);
            let (frozen, info) = solver.frozen_set_stiffness().unwrap();
            // Converged on k's energy estimate (1e-12) at residuals of about 1e-6.
            assert!(info.residual <= 1e-4);
            let fd = solver
                .finite_difference_stiffness(Control::MeanPressure(pressure), 1e-3)
                .unwrap();
            let error = frozen / fd - 1.0;
            eprintln!("{rows}x{cols} aspect {aspect:.3} {boundary:?}: frozen {frozen:.6e}, fd {fd:.6e}, error {error:.2e}");
            assert!(
                error.abs() < 0.005,
                "{rows}x{cols} {boundary:?}: frozen {frozen} vs fd {fd}"
            );
        }
    }
}

#[test]
fn a_solver_refuses_a_surface_with_other_pixels() {
    let surface = stretched_rough(32, 32, 2.0, 1);
    let half_space = HalfSpace {
        modulus: 1.0,
        boundary: Boundary::Free,
    };
    let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
    let other = stretched_rough(32, 32, 1.5, 2);
    assert!(solver.set_surface(&other).is_err());
    let same_pixels = stretched_rough(32, 32, 2.0, 3);
    assert!(solver.set_surface(&same_pixels).is_ok());
}
