//! Love's influence coefficient: surface displacement of an elastic half-space under a
//! uniform pressure on a rectangle.
//!
//! Boussinesq: a point force `P` at the surface displaces the surface by
//! `u(r) = P / (π E* r)`. Integrating over a rectangle `|ξ| ≤ a, |η| ≤ b` with uniform
//! pressure `p` gives Love's closed form (Love 1929; Johnson, *Contact Mechanics*, 1985,
//! eq. 3.25), written here with the antiderivative `F(x, y) = x ln(y + r) + y ln(x + r)`,
//! `∂²F/∂x∂y = 1/r`:
//!
//! `u(x, y) = p/(π E*) · [F(x+a, y+b) − F(x+a, y−b) − F(x−a, y+b) + F(x−a, y−b)]`.
//!
//! At the centre of a square pixel of side Δ this is `4 ln(1+√2)/π · pΔ/E*` ([`self_influence`]).
//! Far from the pixel the four terms cancel to many digits, so beyond eight pixel sizes the
//! same integral is evaluated by 6 × 6 Gauss–Legendre quadrature, whose error there is below
//! 1e-14 relative.

use std::f64::consts::PI;

/// `ln(y + sqrt(x² + y²))` without cancellation for negative `y`.
pub(super) fn ln_y_plus_r(x: f64, y: f64) -> f64 {
    let r = x.hypot(y);
    if y >= 0.0 {
        (y + r).ln()
    } else {
        // y + r = x² / (r − y)
        2.0 * x.abs().ln() - (r - y).ln()
    }
}

/// The antiderivative `F(x, y) = x ln(y + r) + y ln(x + r)` of `1/r`; terms with a zero
/// prefactor are zero (their logarithm may be infinite).
fn antiderivative(x: f64, y: f64) -> f64 {
    let first = if x == 0.0 { 0.0 } else { x * ln_y_plus_r(x, y) };
    let second = if y == 0.0 { 0.0 } else { y * ln_y_plus_r(y, x) };
    first + second
}

/// Nodes and weights of 6-point Gauss–Legendre quadrature on [−1, 1].
pub(super) const GAUSS_NODES: [f64; 6] = [
    -0.932_469_514_203_152,
    -0.661_209_386_466_264_5,
    -0.238_619_186_083_196_9,
    0.238_619_186_083_196_9,
    0.661_209_386_466_264_5,
    0.932_469_514_203_152,
];
pub(super) const GAUSS_WEIGHTS: [f64; 6] = [
    0.171_324_492_379_170_3,
    0.360_761_573_048_138_6,
    0.467_913_934_572_691,
    0.467_913_934_572_691,
    0.360_761_573_048_138_6,
    0.171_324_492_379_170_3,
];

/// Displacement at `(x, y)` (relative to the pixel centre) caused by a unit pressure on a
/// `dx × dy` rectangle centred at the origin, for effective modulus `modulus` (E*).
///
/// Multiply by the pressure to get the displacement; the result is even in `x` and `y`.
pub fn love_pixel_displacement(x: f64, y: f64, dx: f64, dy: f64, modulus: f64) -> f64 {
    // Evaluated in the first quadrant so that the result is exactly even.
    let (x, y) = (x.abs(), y.abs());
    let (a, b) = (0.5 * dx, 0.5 * dy);
    let far = x.hypot(y) > 8.0 * dx.max(dy);
    let integral = if far {
        let mut sum = 0.0;
        for (xi, wx) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
            for (eta, wy) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
                sum += wx * wy / (x - a * xi).hypot(y - b * eta);
            }
        }
        sum * a * b
    } else {
        antiderivative(x + a, y + b) - antiderivative(x + a, y - b) - antiderivative(x - a, y + b)
            + antiderivative(x - a, y - b)
    };
    integral / (PI * modulus)
}

/// Self-influence of a square pixel of side `spacing`: `4 ln(1+√2)/π · Δ/E*`, the
/// displacement at its centre per unit pressure on it.
pub fn self_influence(spacing: f64, modulus: f64) -> f64 {
    4.0 * (1.0 + 2f64.sqrt()).ln() / PI * spacing / modulus
}

/// Self-influence of a `dx × dy` rectangular pixel: the displacement at its centre per unit
/// pressure on it, `2/(π E*) · [Δx ln((Δy + r)/Δx) + Δy ln((Δx + r)/Δy)]` with
/// `r = √(Δx² + Δy²)` (Love's form at the origin; `4 ln(1+√2)/π · Δ/E*` when `Δx = Δy`).
pub fn rectangle_self_influence(dx: f64, dy: f64, modulus: f64) -> f64 {
    let r = dx.hypot(dy);
    2.0 / (PI * modulus) * (dx * ((dy + r) / dx).ln() + dy * ((dx + r) / dy).ln())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn self_influence_matches_closed_form() {
        for (dx, e) in [(1.0, 1.0), (0.01, 2.5), (3.0, 0.2)] {
            let u = love_pixel_displacement(0.0, 0.0, dx, dx, e);
            let expected = 4.0 * (1.0 + 2f64.sqrt()).ln() / PI * dx / e;
            assert!((u / expected - 1.0).abs() < 1e-14, "{u} vs {expected}");
            assert!((self_influence(dx, e) / expected - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn rectangle_self_influence_matches_the_kernel_and_the_square_case() {
        for (dx, dy, e) in [
            (1.0, 2.0, 1.0),
            (0.3, 0.1, 2.5),
            (1.0, 1.5, 0.7),
            (2.0, 2.0, 1.3),
        ] {
            let closed = rectangle_self_influence(dx, dy, e);
            let kernel = love_pixel_displacement(0.0, 0.0, dx, dy, e);
            assert!(
                (closed / kernel - 1.0).abs() < 1e-14,
                "{closed} vs {kernel}"
            );
            assert!((closed - rectangle_self_influence(dy, dx, e)).abs() <= 1e-15 * closed);
        }
        let (dx, e) = (0.7, 1.9);
        let square = rectangle_self_influence(dx, dx, e);
        assert!((square / self_influence(dx, e) - 1.0).abs() < 1e-15);
    }

    /// Boussinesq oracle: the point-load displacement `1/(π E* r)` integrated over the
    /// `dx × dy` pixel by a composite midpoint rule (`n × n` cells, 1/r singular only when
    /// the target is inside the pixel, which these points avoid).
    fn boussinesq_midpoint(x: f64, y: f64, dx: f64, dy: f64, e: f64, n: usize) -> f64 {
        let (hx, hy) = (dx / n as f64, dy / n as f64);
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let xi = -0.5 * dx + (i as f64 + 0.5) * hx;
                let eta = -0.5 * dy + (j as f64 + 0.5) * hy;
                sum += 1.0 / (x - xi).hypot(y - eta);
            }
        }
        sum * hx * hy / (PI * e)
    }

    #[test]
    fn rectangular_pixel_kernel_matches_integrated_boussinesq_load() {
        // Neighbours, diagonal and far points of 2:1, 1:3 and 3:2 pixels (both branches of
        // the kernel). The midpoint rule's error is O(h²/d²) (h the cell, d the distance to
        // the pixel): 1e-6 with 800² cells at half a pixel's distance.
        let e = 1.4;
        for &(dx, dy) in &[(2.0, 1.0), (0.5, 1.5), (0.3, 0.2)] {
            for &(i, j) in &[
                (1.0, 0.0),
                (0.0, 1.0),
                (1.0, 1.0),
                (-2.0, 3.0),
                (7.0, -9.0),
                (20.0, 5.0),
            ] {
                let (x, y) = (i * dx, j * dy);
                let kernel = love_pixel_displacement(x, y, dx, dy, e);
                let oracle = boussinesq_midpoint(x, y, dx, dy, e, 800);
                assert!(
                    (kernel / oracle - 1.0).abs() < 1e-6,
                    "{dx}x{dy} at ({i},{j}): {kernel} vs {oracle}"
                );
            }
        }
    }

    #[test]
    fn rectangular_kernel_is_symmetric_under_swapping_the_axes() {
        // A dx × dy pixel seen from (x, y) is a dy × dx pixel seen from (y, x); the four
        // terms (or the quadrature nodes) are summed in another order, hence a few ulps.
        for &(x, y, dx, dy) in &[
            (1.0, 2.0, 1.0, 0.5),
            (3.0, 0.0, 0.4, 1.1),
            (15.0, 9.0, 2.0, 1.0),
        ] {
            let a = love_pixel_displacement(x, y, dx, dy, 1.0);
            let b = love_pixel_displacement(y, x, dy, dx, 1.0);
            assert!((a - b).abs() <= 1e-14 * a.abs(), "{a} vs {b}");
        }
    }

    /// Midpoint-rule oracle of ∫∫ 1/r over the rectangle (target point outside it).
    fn quadrature_oracle(x: f64, y: f64, dx: f64, dy: f64) -> f64 {
        let n = 400;
        let (hx, hy) = (dx / n as f64, dy / n as f64);
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let xi = -0.5 * dx + (i as f64 + 0.5) * hx;
                let eta = -0.5 * dy + (j as f64 + 0.5) * hy;
                sum += 1.0 / (x - xi).hypot(y - eta);
            }
        }
        sum * hx * hy / PI
    }

    #[test]
    fn closed_form_matches_quadrature_on_rectangles() {
        // Points outside the rectangle, near and far, all quadrants, non-square pixels.
        for &(x, y, dx, dy) in &[
            (1.0, 0.0, 1.0, 1.0),
            (-2.0, 1.5, 1.0, 0.5),
            (0.3, -3.0, 0.4, 1.2),
            (5.0, 5.0, 1.0, 2.0),
            (-9.0, -2.0, 1.0, 1.0),
            (12.0, 0.0, 1.0, 1.0),
        ] {
            let closed = love_pixel_displacement(x, y, dx, dy, 1.0);
            let oracle = quadrature_oracle(x, y, dx, dy);
            assert!(
                (closed / oracle - 1.0).abs() < 2e-5,
                "({x},{y}) {dx}x{dy}: {closed} vs {oracle}"
            );
        }
    }

    #[test]
    fn near_and_far_branches_agree_at_the_switch() {
        // Just inside and outside 8 pixel sizes, the closed form and the quadrature give
        // the same value (the closed form still has ~9 good digits there).
        for &(x, y) in &[(8.0, 0.0), (5.0, 6.3), (-7.99, 0.3)] {
            let exact = antiderivative(x + 0.5, y + 0.5)
                - antiderivative(x + 0.5, y - 0.5)
                - antiderivative(x - 0.5, y + 0.5)
                + antiderivative(x - 0.5, y - 0.5);
            let exact = exact / PI;
            let mut gauss = 0.0;
            for (xi, wx) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
                for (eta, wy) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
                    gauss += wx * wy / (x - 0.5 * xi).hypot(y - 0.5 * eta);
                }
            }
            let gauss = gauss * 0.25 / PI;
            assert!((exact / gauss - 1.0).abs() < 1e-9, "{exact} vs {gauss}");
        }
    }

    #[test]
    fn far_field_is_a_point_load() {
        // u → F/(π E* r) with F = p Δ²; the correction is O((Δ/r)²)/24.
        let e = 1.7;
        for r in [20.0, 50.0, 200.0] {
            let u = love_pixel_displacement(r * 0.6, r * 0.8, 1.0, 1.0, e);
            let point = 1.0 / (PI * e * r);
            assert!(
                (u / point - 1.0).abs() < 0.1 / (r * r),
                "r={r}: {u} vs {point}"
            );
        }
    }

    #[test]
    fn kernel_is_even() {
        for &(x, y) in &[(1.0, 2.0), (3.0, 0.5), (10.0, 7.0)] {
            let u = love_pixel_displacement(x, y, 1.0, 1.3, 1.0);
            for (sx, sy) in [(-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
                let v = love_pixel_displacement(sx * x, sy * y, 1.0, 1.3, 1.0);
                assert!((u - v).abs() <= 1e-15 * u.abs());
            }
        }
    }
}
