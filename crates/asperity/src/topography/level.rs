//! Levelling (form removal) by least squares over the defined points: the mean, a mean
//! plane, a polynomial of degree 1–3 in x and y, or line by line (each row's mean or
//! straight line, for AFM scan lines).
//!
//! The polynomial is fitted in the Legendre basis `P_i(u) P_j(v)`, `i + j ≤ d`, of the
//! coordinates mapped to `[-1, 1]` along each axis, where the normal equations are nearly
//! orthogonal on a uniform grid (well conditioned for any pixel aspect), and solved by
//! Gaussian elimination with partial pivoting. Undefined (NaN) points are left undefined and
//! take no part in the fit.

use ndarray::{Array2, ArrayViewMut1};

use super::Heights;
use crate::{Error, Result};

/// A levelling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Detrend {
    /// Subtract the mean height.
    Mean,
    /// Subtract the least-squares polynomial of this degree (1: the mean plane, 2, 3).
    Polynomial(usize),
    /// Subtract each row's mean (line-by-line offsets).
    RowMeans,
    /// Subtract each row's least-squares straight line.
    RowLines,
}

impl Detrend {
    /// How the step is recorded in a sidecar.
    pub fn describe(&self) -> String {
        match self {
            Detrend::Mean => "levelled: mean height subtracted".into(),
            Detrend::Polynomial(1) => "levelled: least-squares mean plane subtracted".into(),
            Detrend::Polynomial(d) => {
                format!("levelled: least-squares polynomial of degree {d} in x and y subtracted")
            }
            Detrend::RowMeans => "levelled line by line: each row's mean subtracted".into(),
            Detrend::RowLines => {
                "levelled line by line: each row's least-squares line subtracted".into()
            }
        }
    }
}

/// Legendre polynomial `P_n(u)`, `n ≤ 3`.
fn legendre(n: usize, u: f64) -> f64 {
    match n {
        0 => 1.0,
        1 => u,
        2 => 1.5 * u * u - 0.5,
        _ => 2.5 * u * u * u - 1.5 * u,
    }
}

/// Grid index → `[-1, 1]` (0 for a single point).
fn unit(i: usize, n: usize) -> f64 {
    if n < 2 {
        0.0
    } else {
        2.0 * i as f64 / (n - 1) as f64 - 1.0
    }
}

/// Solves the small dense system `a x = b` (Gaussian elimination, partial pivoting);
/// `None` when singular.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let m = b.len();
    let scale = a.iter().flatten().fold(0.0f64, |s, v| s.max(v.abs()));
    for k in 0..m {
        let p = (k..m).max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))?;
        if a[p][k].abs() <= 1e-13 * scale {
            return None;
        }
        a.swap(k, p);
        b.swap(k, p);
        for i in k + 1..m {
            let f = a[i][k] / a[k][k];
            // Row k lies above row i (k < i): split so both rows can be borrowed at once.
            let (above, below) = a.split_at_mut(i);
            for (x, pivot) in below[0][k..m].iter_mut().zip(&above[k][k..m]) {
                *x -= f * pivot;
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = vec![0.0; m];
    for k in (0..m).rev() {
        let s: f64 = (k + 1..m).map(|j| a[k][j] * x[j]).sum();
        x[k] = (b[k] - s) / a[k][k];
    }
    Some(x)
}

/// The exponents `(i, j)` of the basis of degree `d`.
fn basis(degree: usize, two_d: bool) -> Vec<(usize, usize)> {
    let mut terms = Vec::new();
    for total in 0..=degree {
        for i in (0..=total).rev() {
            let j = total - i;
            if two_d || j == 0 {
                terms.push((i, j));
            }
        }
    }
    terms
}

/// Fits and subtracts the polynomial of `degree` from `h` (rows along y).
fn subtract_polynomial(h: &mut Array2<f64>, degree: usize) -> Result<()> {
    let (ny, nx) = h.dim();
    let terms = basis(degree, ny > 1);
    let m = terms.len();
    let mut a = vec![vec![0.0; m]; m];
    let mut b = vec![0.0; m];
    let mut phi = vec![0.0; m];
    let eval = |r: usize, c: usize, phi: &mut [f64]| {
        let (u, v) = (unit(c, nx), unit(r, ny));
        for (p, &(i, j)) in phi.iter_mut().zip(&terms) {
            *p = legendre(i, u) * legendre(j, v);
        }
    };
    for ((r, c), &z) in h.indexed_iter() {
        if z.is_nan() {
            continue;
        }
        eval(r, c, &mut phi);
        for k in 0..m {
            b[k] += phi[k] * z;
            for l in 0..m {
                a[k][l] += phi[k] * phi[l];
            }
        }
    }
    let coef = solve(a, b).ok_or_else(|| {
        Error::invalid(
            "levelling",
            format!("too few defined points to fit a polynomial of degree {degree}"),
        )
    })?;
    for ((r, c), z) in h.indexed_iter_mut() {
        eval(r, c, &mut phi);
        *z -= phi.iter().zip(&coef).map(|(p, k)| p * k).sum::<f64>();
    }
    Ok(())
}

/// Subtracts a row's mean (`line = false`) or least-squares line.
fn level_row(mut row: ArrayViewMut1<f64>, line: bool) {
    let n = row.len();
    let (mut s, mut su, mut suu, mut sz, mut suz) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (c, &z) in row.iter().enumerate() {
        if z.is_nan() {
            continue;
        }
        let u = unit(c, n);
        s += 1.0;
        su += u;
        suu += u * u;
        sz += z;
        suz += u * z;
    }
    if s == 0.0 {
        return;
    }
    let det = s * suu - su * su;
    let (offset, slope) = if line && det > 1e-12 * s * s {
        ((suu * sz - su * suz) / det, (s * suz - su * sz) / det)
    } else {
        (sz / s, 0.0)
    };
    for (c, z) in row.iter_mut().enumerate() {
        *z -= offset + slope * unit(c, n);
    }
}

/// Levels the heights in place (see the module docs). Line-by-line levelling needs a map.
pub fn detrend(heights: &mut Heights, how: Detrend) -> Result<()> {
    if let Detrend::Polynomial(d) = how {
        if !(1..=3).contains(&d) {
            return Err(Error::invalid(
                "levelling",
                format!("polynomial degree must be 1, 2 or 3, got {d}"),
            ));
        }
    }
    match (heights, how) {
        (Heights::Areal(h), Detrend::Mean) => subtract_polynomial(h, 0),
        (Heights::Areal(h), Detrend::Polynomial(d)) => subtract_polynomial(h, d),
        (Heights::Areal(h), Detrend::RowMeans | Detrend::RowLines) => {
            for row in h.rows_mut() {
                level_row(row, how == Detrend::RowLines);
            }
            Ok(())
        }
        (Heights::Profile(p), how) => {
            let degree = match how {
                Detrend::Mean => 0,
                Detrend::Polynomial(d) => d,
                _ => {
                    return Err(Error::invalid(
                        "levelling",
                        "line-by-line levelling needs a map, not a profile",
                    ))
                }
            };
            let mut h = p.view().insert_axis(ndarray::Axis(0)).to_owned();
            subtract_polynomial(&mut h, degree)?;
            p.assign(&h.row(0));
            Ok(())
        }
    }
}

/// A warning when the heights look tilted: the rms of the mean plane (about the mean) is at
/// least a fifth of the rms left after removing it — a tilt comparable to the roughness,
/// which would dominate slopes and contact (set a levelling to remove it, or say none).
pub fn tilt_warning(heights: &Heights) -> Option<String> {
    let rms = |h: &Heights| {
        let (s, n) = h
            .values()
            .filter(|v| !v.is_nan())
            .fold((0.0, 0.0), |(s, n), v| (s + v, n + 1.0));
        let mean = s / n;
        (h.values()
            .filter(|v| !v.is_nan())
            .map(|v| (v - mean).powi(2))
            .sum::<f64>()
            / n)
            .sqrt()
    };
    let mut levelled = heights.clone();
    detrend(&mut levelled, Detrend::Polynomial(1)).ok()?;
    let (total, rough) = (rms(heights), rms(&levelled));
    let plane = (total * total - rough * rough).max(0.0).sqrt();
    (plane >= 0.2 * rough && plane > 0.0).then(|| {
        format!(
            "the surface looks tilted (mean plane rms {plane:.3e} vs {rough:.3e} rms roughness about it) and no levelling was chosen; the heights are used as they are"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array1;

    /// The largest |value| of the defined points.
    fn max_abs(h: &Heights) -> f64 {
        h.values()
            .filter(|v| !v.is_nan())
            .fold(0.0, |m, v| m.max(v.abs()))
    }

    #[test]
    fn exact_polynomials_are_removed_to_rounding() {
        // Physical coordinates on rectangular pixels (Δx = 0.3, Δy = 0.7), one undefined
        // point; a cubic of amplitude ~1e3 leaves rounding only.
        let (ny, nx) = (37, 53);
        let f = |r: usize, c: usize, d: usize| {
            let (x, y) = (0.3 * c as f64, 0.7 * r as f64);
            let mut z = 5.0 + 2.0 * x - 3.0 * y;
            if d >= 2 {
                z += 0.4 * x * x - 0.25 * x * y + 0.1 * y * y;
            }
            if d >= 3 {
                z += 0.02 * x * x * x - 0.01 * x * x * y + 0.003 * x * y * y - 0.004 * y * y * y;
            }
            z
        };
        for d in 1..=3 {
            let mut h = Array2::from_shape_fn((ny, nx), |(r, c)| f(r, c, d));
            h[(4, 5)] = f64::NAN;
            let amplitude = h
                .iter()
                .filter(|v| !v.is_nan())
                .fold(0.0f64, |m, v| m.max(v.abs()));
            let mut heights = Heights::Areal(h);
            detrend(&mut heights, Detrend::Polynomial(d)).unwrap();
            assert!(
                max_abs(&heights) < 1e-12 * amplitude,
                "degree {d}: {}",
                max_abs(&heights)
            );
            assert_eq!(heights.undefined_count(), 1);
        }
        // A cubic is not removed by a plane.
        let mut heights = Heights::Areal(Array2::from_shape_fn((ny, nx), |(r, c)| f(r, c, 3)));
        detrend(&mut heights, Detrend::Polynomial(1)).unwrap();
        assert!(max_abs(&heights) > 1.0);
    }

    #[test]
    fn row_lines_and_profiles() {
        // Each row its own offset and slope: removed exactly by RowLines, only offsets by RowMeans.
        let h = Array2::from_shape_fn((6, 9), |(r, c)| {
            r as f64 * 10.0 + (r as f64 - 2.0) * c as f64
        });
        let mut a = Heights::Areal(h.clone());
        detrend(&mut a, Detrend::RowLines).unwrap();
        assert!(max_abs(&a) < 1e-12);
        let mut b = Heights::Areal(h);
        detrend(&mut b, Detrend::RowMeans).unwrap();
        let Heights::Areal(b) = b else { panic!() };
        for row in b.rows() {
            assert!(row.sum().abs() < 1e-12);
        }
        let mut p = Heights::Profile(Array1::from_shape_fn(11, |i| {
            1.0 + 0.5 * i as f64 - 0.01 * (i * i) as f64
        }));
        detrend(&mut p, Detrend::Polynomial(2)).unwrap();
        assert!(max_abs(&p) < 1e-13);
        assert!(detrend(&mut p, Detrend::RowLines).is_err());
        assert!(detrend(&mut p, Detrend::Polynomial(4)).is_err());
    }

    #[test]
    fn tilt_is_noticed() {
        let rough = |r: usize, c: usize| ((r * 13 + c * 7) as f64).sin() * 1e-9;
        let flat = Heights::Areal(Array2::from_shape_fn((32, 32), |(r, c)| rough(r, c)));
        assert!(tilt_warning(&flat).is_none());
        let tilted = Heights::Areal(Array2::from_shape_fn((32, 32), |(r, c)| {
            rough(r, c) + 1e-10 * c as f64
        }));
        assert!(tilt_warning(&tilted).is_some());
    }
}
