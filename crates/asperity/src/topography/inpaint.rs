//! Harmonic (Laplace) inpainting of undefined points: the filled heights `u` solve the
//! discrete Laplace equation `(u_E − 2u + u_W)/Δx² + (u_N − 2u + u_S)/Δy² = 0` at every
//! undefined point, with the defined points as Dirichlet values and reflecting (Neumann)
//! edges of the grid. This is the smoothest fill (it minimises the discrete Dirichlet
//! energy `Σ |∇u|²`), reproduces every harmonic field (planes, `x² − y²`, ...) exactly on a
//! grid, and never overshoots the defined values around a hole (maximum principle).
//! On a profile the fill is the straight line between the defined neighbours (constant
//! beyond the last defined point).
//!
//! The symmetric positive-definite system is solved by conjugate gradients with a Jacobi
//! preconditioner to a relative residual of 1e-13, with a bounded number of iterations
//! (an error names the residual reached otherwise).

use ndarray::{Array1, Array2};

use super::Heights;
use crate::{Error, Result};

/// Relative residual of the CG solve.
const TOLERANCE: f64 = 1e-13;

/// Fills the undefined points of `heights` (spacings `[Δx]` or `[Δx, Δy]`); returns how
/// many were filled. Fails if every point is undefined.
pub fn fill_harmonic(heights: &mut Heights, spacings: &[f64]) -> Result<usize> {
    match heights {
        Heights::Profile(p) => fill_profile(p),
        Heights::Areal(h) => fill_map(h, spacings[0], spacings[spacings.len() - 1]),
    }
}

fn fill_profile(p: &mut Array1<f64>) -> Result<usize> {
    let defined: Vec<usize> = (0..p.len()).filter(|&i| !p[i].is_nan()).collect();
    let (Some(&first), Some(&last)) = (defined.first(), defined.last()) else {
        return Err(Error::invalid(
            "heights",
            "every point is undefined: nothing to fill from",
        ));
    };
    let filled = p.len() - defined.len();
    for i in 0..first {
        p[i] = p[first];
    }
    for i in last + 1..p.len() {
        p[i] = p[last];
    }
    for w in defined.windows(2) {
        let (a, b) = (w[0], w[1]);
        for i in a + 1..b {
            let t = (i - a) as f64 / (b - a) as f64;
            p[i] = p[a] + t * (p[b] - p[a]);
        }
    }
    Ok(filled)
}

/// The system over the undefined points: for each, its grid index, diagonal, and
/// neighbours that are unknowns (`index`, weight); the right-hand side holds the defined
/// neighbours.
struct System {
    cells: Vec<usize>,
    diagonal: Vec<f64>,
    neighbours: Vec<[(u32, f64); 4]>,
    rhs: Vec<f64>,
}

const NONE: u32 = u32::MAX;

fn system(h: &Array2<f64>, dx: f64, dy: f64) -> Result<System> {
    let (ny, nx) = h.dim();
    let flat = h.as_slice().expect("standard layout");
    let cells: Vec<usize> = (0..flat.len()).filter(|&i| flat[i].is_nan()).collect();
    if cells.len() > u32::MAX as usize - 1 {
        return Err(Error::invalid(
            "heights",
            "too many undefined points to fill",
        ));
    }
    let mut unknown = crate::memory::try_vec("the inpainting index", flat.len(), NONE)?;
    for (k, &i) in cells.iter().enumerate() {
        unknown[i] = k as u32;
    }
    let (wx, wy) = (1.0 / (dx * dx), 1.0 / (dy * dy));
    let mut s = System {
        diagonal: vec![0.0; cells.len()],
        neighbours: vec![[(NONE, 0.0); 4]; cells.len()],
        rhs: vec![0.0; cells.len()],
        cells: Vec::new(),
    };
    for (k, &i) in cells.iter().enumerate() {
        let (r, c) = (i / nx, i % nx);
        let around = [
            (c > 0).then(|| (i - 1, wx)),
            (c + 1 < nx).then(|| (i + 1, wx)),
            (r > 0).then(|| (i - nx, wy)),
            (r + 1 < ny).then(|| (i + nx, wy)),
        ];
        for (slot, (j, w)) in around.into_iter().flatten().enumerate() {
            s.diagonal[k] += w;
            if unknown[j] == NONE {
                s.rhs[k] += w * flat[j];
            } else {
                s.neighbours[k][slot] = (unknown[j], w);
            }
        }
    }
    s.cells = cells;
    Ok(s)
}

impl System {
    /// `y = A x` (A = diagonal − neighbour weights).
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        for k in 0..x.len() {
            let off: f64 = self.neighbours[k]
                .iter()
                .filter(|(j, _)| *j != NONE)
                .map(|&(j, w)| w * x[j as usize])
                .sum();
            y[k] = self.diagonal[k] * x[k] - off;
        }
    }
}

fn fill_map(h: &mut Array2<f64>, dx: f64, dy: f64) -> Result<usize> {
    if h.iter().all(|v| !v.is_nan()) {
        return Ok(0);
    }
    if !h.is_standard_layout() {
        *h = h.as_standard_layout().into_owned();
    }
    // The grid is 4-connected, so every hole reaches a defined point (the system is
    // positive definite) as soon as one point is defined.
    if h.iter().all(|v| v.is_nan()) {
        return Err(Error::invalid(
            "heights",
            "every point is undefined: nothing to fill from",
        ));
    }
    let s = system(h, dx, dy)?;
    let n = s.cells.len();
    let x = conjugate_gradient(&s, (h.nrows() + h.ncols()) * 50 + 1000)?;
    let flat = h.as_slice_mut().expect("standard layout");
    for (k, &i) in s.cells.iter().enumerate() {
        flat[i] = x[k];
    }
    Ok(n)
}

/// Jacobi-preconditioned CG from the mean of the boundary values.
fn conjugate_gradient(s: &System, max_iterations: usize) -> Result<Vec<f64>> {
    let n = s.cells.len();
    let start = s.rhs.iter().sum::<f64>() / s.diagonal.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    let mut x = vec![start; n];
    let mut ax = vec![0.0; n];
    s.apply(&x, &mut ax);
    let mut r: Vec<f64> = (0..n).map(|k| s.rhs[k] - ax[k]).collect();
    let norm_b = s
        .rhs
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let mut z: Vec<f64> = (0..n).map(|k| r[k] / s.diagonal[k]).collect();
    let mut p = z.clone();
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
    let mut ap = vec![0.0; n];
    for _ in 0..max_iterations {
        let residual = r.iter().map(|v| v * v).sum::<f64>().sqrt() / norm_b;
        if residual <= TOLERANCE {
            return Ok(x);
        }
        s.apply(&p, &mut ap);
        let alpha = rz / p.iter().zip(&ap).map(|(a, b)| a * b).sum::<f64>();
        for k in 0..n {
            x[k] += alpha * p[k];
            r[k] -= alpha * ap[k];
            z[k] = r[k] / s.diagonal[k];
        }
        let rz_new: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
        let beta = rz_new / rz;
        rz = rz_new;
        for k in 0..n {
            p[k] = z[k] + beta * p[k];
        }
    }
    let residual = r.iter().map(|v| v * v).sum::<f64>().sqrt() / norm_b;
    if residual <= 1e3 * TOLERANCE {
        return Ok(x); // rounding floor of a large system: still 1e-10
    }
    Err(Error::invalid(
        "heights",
        format!("harmonic inpainting did not converge in {max_iterations} iterations (relative residual {residual:.1e})"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonic_field_on_a_masked_disc_is_reproduced() {
        // u = x² − y² (+ a plane) is harmonic, and its 5-point Laplacian vanishes exactly
        // for any Δx, Δy: the fill must reproduce it to the solver's tolerance. Tolerance
        // 1e-9 relative to the field's range: CG to 1e-13 relative residual on a system
        // whose condition number is ~(hole diameter)² ~ 1e3.
        for (dx, dy) in [(1.0, 1.0), (0.5, 1.3)] {
            let (ny, nx) = (48, 64);
            let u = |r: usize, c: usize| {
                let (x, y) = (dx * c as f64, dy * r as f64);
                x * x - y * y + 3.0 * x - y
            };
            let truth = Array2::from_shape_fn((ny, nx), |(r, c)| u(r, c));
            let mut h = truth.clone();
            let mut holes = 0;
            for ((r, c), v) in h.indexed_iter_mut() {
                let (x, y) = (c as f64 - 30.0, r as f64 - 20.0);
                if x * x + y * y < 15.0 * 15.0 {
                    *v = f64::NAN;
                    holes += 1;
                }
            }
            let mut heights = Heights::Areal(h);
            assert_eq!(fill_harmonic(&mut heights, &[dx, dy]).unwrap(), holes);
            let Heights::Areal(h) = heights else { panic!() };
            let range = truth.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in h.iter().zip(truth.iter()) {
                assert!((a - b).abs() < 1e-9 * range, "{a} vs {b}");
            }
        }
    }

    #[test]
    fn edges_profiles_and_refusals() {
        // A hole on the top edge (reflecting there) of a plane along x is filled with the
        // plane, whose derivative across that edge is zero.
        let mut h = Array2::from_shape_fn((10, 10), |(_, c)| c as f64);
        h[(0, 3)] = f64::NAN;
        h[(0, 4)] = f64::NAN;
        let mut heights = Heights::Areal(h);
        fill_harmonic(&mut heights, &[1.0, 1.0]).unwrap();
        let Heights::Areal(h) = heights else { panic!() };
        assert!((h[(0, 3)] - 3.0).abs() < 1e-12 && (h[(0, 4)] - 4.0).abs() < 1e-12);
        let mut p = Heights::Profile(Array1::from(vec![
            f64::NAN,
            1.0,
            f64::NAN,
            f64::NAN,
            4.0,
            f64::NAN,
        ]));
        assert_eq!(fill_harmonic(&mut p, &[1.0]).unwrap(), 4);
        assert_eq!(
            p,
            Heights::Profile(Array1::from(vec![1.0, 1.0, 2.0, 3.0, 4.0, 4.0]))
        );
        let mut all = Heights::Areal(Array2::from_elem((3, 3), f64::NAN));
        assert!(fill_harmonic(&mut all, &[1.0, 1.0]).is_err());
    }
}
