//! Cerruti's influence coefficient: tangential surface displacement of an elastic half-space
//! under a uniform tangential traction on a rectangle, in the direction of the traction.
//!
//! Cerruti: a tangential point force `Q` in `x` at the surface displaces the surface by
//! (Johnson, *Contact Mechanics*, 1985, eq. 2.19)
//!
//! `u_x = Q/(2πG) · [(1−ν)/ρ + ν x²/ρ³]`, `u_y = Q/(2πG) · ν x y/ρ³`,
//! `u_z = −Q/(4πG) · (1−2ν) x/ρ²`.
//!
//! The tangential stiffness of a contact uses `u_x` from `q_x` (and `u_y` from `q_y`, the
//! same with `x` and `y` swapped); the cross term `u_y` from `q_x` integrates to zero over a
//! symmetric contact and is left out, and so is the normal–tangential coupling `u_z`
//! (exact for bodies of the same elastic constants, which gives the same `u_z` with opposite
//! signs in both; standard otherwise). With `1/G = 2/(E*(1−ν))` for a half-space on a rigid
//! body (or two bodies of the same ν, `E*` the combined modulus), integrating over the
//! rectangle `|ξ| ≤ a, |η| ≤ b` with the antiderivative
//! `H(X, Y) = (1−ν)·X ln(Y + ρ) + Y ln(X + ρ)` (`∂²H/∂X∂Y = (1−ν)/ρ + ν X²/ρ³`) gives
//!
//! `u_x(x, y) = q/(π E* (1−ν)) · [H(x+a, y+b) − H(x+a, y−b) − H(x−a, y+b) + H(x−a, y−b)]`.
//!
//! At `ν = 0` this is Love's coefficient ([`super::love_pixel_displacement`]). Far from the
//! pixel the corner terms cancel to many digits, so beyond eight pixel sizes the integral
//! is taken by 6 × 6 Gauss–Legendre quadrature of the point solution, as Love's is.
//!
//! The periodic kernel is the Fourier transform of the point solution:
//! `ũ_x/q̃_x = 2/(E* |q|) · (1 − ν q_x²/|q|²)/(1 − ν)` ([`cerruti_spectrum`]).

use std::f64::consts::PI;

// Love's cancellation-free logarithm and quadrature rule serve both kernels.
use super::love::{ln_y_plus_r, GAUSS_NODES, GAUSS_WEIGHTS};

/// Which tangential direction: the traction and the displacement it gives along it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Along the columns (`x`, spacing `Δx`).
    X,
    /// Along the rows (`y`, spacing `Δy`).
    Y,
}

/// `H(X, Y) = (1−ν)·X ln(Y + ρ) + Y ln(X + ρ)`; terms with a zero prefactor are zero.
fn antiderivative(x: f64, y: f64, poisson: f64) -> f64 {
    let first = if x == 0.0 {
        0.0
    } else {
        (1.0 - poisson) * x * ln_y_plus_r(x, y)
    };
    let second = if y == 0.0 { 0.0 } else { y * ln_y_plus_r(y, x) };
    first + second
}

/// The point solution's kernel `(1−ν)/ρ + ν x²/ρ³` (without `1/(2πG)`).
fn point_kernel(x: f64, y: f64, poisson: f64) -> f64 {
    let r = x.hypot(y);
    (1.0 - poisson) / r + poisson * x * x / (r * r * r)
}

/// Tangential displacement along `direction` at `(x, y)` (relative to the pixel centre)
/// caused by a unit tangential traction along `direction` on a `dx × dy` rectangle centred at
/// the origin, for effective modulus `modulus` (E*) and Poisson's ratio `poisson` in
/// `[0, 0.5]`. Even in `x` and `y`.
pub fn cerruti_pixel_displacement(
    x: f64,
    y: f64,
    dx: f64,
    dy: f64,
    modulus: f64,
    poisson: f64,
    direction: Direction,
) -> f64 {
    // The y-direction is the x-direction with the axes swapped.
    let (x, y, dx, dy) = match direction {
        Direction::X => (x.abs(), y.abs(), dx, dy),
        Direction::Y => (y.abs(), x.abs(), dy, dx),
    };
    let (a, b) = (0.5 * dx, 0.5 * dy);
    let far = x.hypot(y) > 8.0 * dx.max(dy);
    let integral = if far {
        let mut sum = 0.0;
        for (xi, wx) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
            for (eta, wy) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
                sum += wx * wy * point_kernel(x - a * xi, y - b * eta, poisson);
            }
        }
        sum * a * b
    } else {
        let h = |x, y| antiderivative(x, y, poisson);
        h(x + a, y + b) - h(x + a, y - b) - h(x - a, y + b) + h(x - a, y - b)
    };
    integral / (PI * modulus * (1.0 - poisson))
}

/// The periodic kernel's spectrum at wavevector `(qx, qy)` (not zero):
/// `2/(E* |q|) · (1 − ν q_d²/|q|²)/(1 − ν)` with `q_d` the component along `direction`.
pub fn cerruti_spectrum(qx: f64, qy: f64, modulus: f64, poisson: f64, direction: Direction) -> f64 {
    let q2 = qx * qx + qy * qy;
    let along = match direction {
        Direction::X => qx * qx,
        Direction::Y => qy * qy,
    };
    2.0 / (modulus * q2.sqrt()) * (1.0 - poisson * along / q2) / (1.0 - poisson)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elastic::love_pixel_displacement;

    /// `∫∫ point_kernel` over the rectangle by composite Gauss–Legendre on `m × m` cells,
    /// split at the field point so that the 1/ρ singularity sits at a cell corner (where
    /// Gauss nodes do not reach it): converges like a regular integral of an integrable
    /// singularity, to about 1e-6 relative with 64 × 64 cells.
    fn quadrature(x: f64, y: f64, dx: f64, dy: f64, poisson: f64) -> f64 {
        let (a, b) = (0.5 * dx, 0.5 * dy);
        // Breakpoints: the rectangle's edges and the field point if inside.
        let cuts = |lo: f64, hi: f64, p: f64| {
            if p > lo && p < hi {
                vec![(lo, p), (p, hi)]
            } else {
                vec![(lo, hi)]
            }
        };
        let m = 64;
        let mut sum = 0.0;
        for (x0, x1) in cuts(-a, a, x) {
            for (y0, y1) in cuts(-b, b, y) {
                // Geometric grading towards the field point makes the singular cells small.
                let grade = |lo: f64, hi: f64, p: f64, i: usize| {
                    let t = (i as f64 / m as f64).powi(3);
                    if (p - lo).abs() < (p - hi).abs() {
                        lo + (hi - lo) * t
                    } else {
                        hi - (hi - lo) * t
                    }
                };
                for i in 0..m {
                    let (u0, u1) = (grade(x0, x1, x, i), grade(x0, x1, x, i + 1));
                    for j in 0..m {
                        let (v0, v1) = (grade(y0, y1, y, j), grade(y0, y1, y, j + 1));
                        let (hu, hv) = (0.5 * (u1 - u0), 0.5 * (v1 - v0));
                        for (s, ws) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
                            for (t, wt) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
                                let xi = 0.5 * (u0 + u1) + hu * s;
                                let eta = 0.5 * (v0 + v1) + hv * t;
                                sum += ws
                                    * wt
                                    * hu.abs()
                                    * hv.abs()
                                    * point_kernel(x - xi, y - eta, poisson);
                            }
                        }
                    }
                }
            }
        }
        sum
    }

    #[test]
    fn closed_form_matches_numerical_integration_of_the_point_solution() {
        let (e, dx, dy) = (1.3, 1.0, 0.6);
        let mut worst: f64 = 0.0;
        for poisson in [0.0, 0.25, 0.5] {
            for (x, y) in [
                (0.0, 0.0),
                (0.2, 0.1),
                (0.5, 0.0),
                (1.0, 0.0),
                (0.0, 1.0),
                (1.7, -2.3),
                (6.0, 5.0),
                (9.0, 1.0),
            ] {
                let closed = cerruti_pixel_displacement(x, y, dx, dy, e, poisson, Direction::X);
                let numerical = quadrature(x, y, dx, dy, poisson) / (PI * e * (1.0 - poisson));
                let error = (closed / numerical - 1.0).abs();
                worst = worst.max(error);
                assert!(
                    error < 1e-6,
                    "ν = {poisson}, ({x}, {y}): {closed} vs {numerical}"
                );
            }
        }
        eprintln!("Cerruti pixel vs quadrature: worst relative error {worst:.1e}");
    }

    #[test]
    fn limits_and_symmetries() {
        let (e, dx, dy) = (2.0, 0.7, 1.1);
        for (x, y) in [(0.0, 0.0), (0.3, 0.9), (2.0, 1.0), (20.0, 3.0)] {
            // ν = 0: Love's coefficient.
            let cerruti = cerruti_pixel_displacement(x, y, dx, dy, e, 0.0, Direction::X);
            let love = love_pixel_displacement(x, y, dx, dy, e);
            assert!((cerruti / love - 1.0).abs() < 1e-13, "({x}, {y})");
            // Even in x and y; Y is X with the axes swapped.
            for nu in [0.3, 0.5] {
                let u = cerruti_pixel_displacement(x, y, dx, dy, e, nu, Direction::X);
                assert_eq!(
                    u,
                    cerruti_pixel_displacement(-x, -y, dx, dy, e, nu, Direction::X)
                );
                let swapped = cerruti_pixel_displacement(y, x, dy, dx, e, nu, Direction::Y);
                assert_eq!(u, swapped);
            }
        }
        // Along the load the displacement falls off more slowly than across it (ν > 0):
        // (1−ν)/ρ + ν/ρ along x, (1−ν)/ρ across.
        let along = cerruti_pixel_displacement(30.0, 0.0, 1.0, 1.0, 1.0, 0.5, Direction::X);
        let across = cerruti_pixel_displacement(0.0, 30.0, 1.0, 1.0, 1.0, 0.5, Direction::X);
        assert!((along / across - 2.0).abs() < 1e-3, "{along} / {across}");
        // The closed form and the quadrature agree where the switch is made.
        let near = cerruti_pixel_displacement(7.99, 0.0, 1.0, 1.0, 1.0, 0.4, Direction::X);
        let far = cerruti_pixel_displacement(8.01, 0.0, 1.0, 1.0, 1.0, 0.4, Direction::X);
        assert!((near / far - 8.01 / 7.99).abs() < 1e-5);
    }

    #[test]
    fn spectrum_has_the_normal_limit_and_the_anisotropy() {
        let e = 1.5;
        assert!((cerruti_spectrum(0.3, 0.4, e, 0.0, Direction::X) - 2.0 / (e * 0.5)).abs() < 1e-14);
        // Along x: (1 − ν)/(1 − ν) = 1; across: 1/(1 − ν).
        let along = cerruti_spectrum(1.0, 0.0, e, 0.5, Direction::X);
        let across = cerruti_spectrum(0.0, 1.0, e, 0.5, Direction::X);
        assert!((along - 2.0 / e).abs() < 1e-14 && (across - 4.0 / e).abs() < 1e-14);
        assert_eq!(
            cerruti_spectrum(0.3, 0.7, e, 0.2, Direction::X),
            cerruti_spectrum(0.7, 0.3, e, 0.2, Direction::Y)
        );
    }
}
