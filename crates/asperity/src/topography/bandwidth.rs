//! Variable-bandwidth analysis: the rms height of a topography after removing a mean plane
//! (a map) or a mean line (each scan line) in ever smaller sections, against the section's
//! size, the bandwidth `ℓ`. For a self-affine surface the rms height grows as `ℓ^H`.
//!
//! The definition is SurfaceTopography's (`variable_bandwidth_from_area` and
//! `variable_bandwidth_from_profile`, 1.27.1): at magnification `M = 1, 2, 4, …` the map is
//! cut into a checkerboard of `M·s_x × M·s_y` rectangles (`s = round(L/min(L_x, L_y))` per
//! axis, so that rectangles are nearly square), pixel `(i_y, i_x)` belonging to rectangle
//! `(⌊i_y·M s_y/n_y⌋, ⌊i_x·M s_x/n_x⌋)`; a least-squares plane `a + b x + c y` is removed
//! in each rectangle and the rms of all the residuals is the rms height at bandwidth
//! `ℓ = (L_x/(M s_x) + L_y/(M s_y))/2`. A profile (or each line of a map, in the profile
//! variant) is cut into `M` sections along x, each with its own straight line, `ℓ = L_x/M`.
//! Magnification stops before a section would have fewer than 4 grid points along an axis.
//! Undefined points (NaN) take no part in the fits or in the rms; the analysis stops before
//! a magnification at which some section has too few defined points to fix its plane or
//! line (and refuses a surface where that happens at the start).

use ndarray::ArrayView2;

use crate::{Error, Result};

/// The fewest grid points along an axis of one section (SurfaceTopography's default).
pub const MIN_SECTION_POINTS: usize = 4;

/// One magnification of a variable-bandwidth analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bandwidth {
    /// `M`: sections per side (1, 2, 4, …).
    pub magnification: usize,
    /// The sections' size `ℓ`, in the unit of the sizes.
    pub bandwidth: f64,
    /// The rms of the heights after each section's plane (or line) is removed.
    pub rms_height: f64,
}

/// Which trend each section loses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Trend {
    /// A straight line along x, in each section of each row.
    Line,
    /// A plane in x and y, in each rectangle.
    Plane,
}

fn refuse(reason: impl Into<String>) -> Error {
    Error::invalid("variable-bandwidth surface", reason)
}

/// The variable-bandwidth analysis of a map `(rows, cols) = (y, x)` of physical size
/// `size = [L_x, L_y]` (checkerboard of planes).
pub fn variable_bandwidth_area(h: ArrayView2<f64>, size: [f64; 2]) -> Result<Vec<Bandwidth>> {
    let [lx, ly] = size;
    if !(lx.is_finite() && ly.is_finite() && lx > 0.0 && ly > 0.0) {
        return Err(refuse("the sizes must be positive and finite"));
    }
    let min = lx.min(ly);
    let base = [(lx / min).round() as usize, (ly / min).round() as usize];
    series(h, base, size, Trend::Plane)
}

/// The variable-bandwidth analysis of line scans: each row of `rows` (a profile is one
/// row) of length `length` cut into sections along x, each losing its straight line.
pub fn variable_bandwidth_profile(rows: ArrayView2<f64>, length: f64) -> Result<Vec<Bandwidth>> {
    if !(length.is_finite() && length > 0.0) {
        return Err(refuse("the length must be positive and finite"));
    }
    series(rows, [1, 0], [length, 0.0], Trend::Line)
}

/// The magnifications 1, 2, 4, … while every section keeps enough points.
fn series(
    h: ArrayView2<f64>,
    base: [usize; 2],
    size: [f64; 2],
    trend: Trend,
) -> Result<Vec<Bandwidth>> {
    let (ny, nx) = h.dim();
    let fits = |m: usize| {
        let (sx, sy) = (base[0] * m, base[1] * m);
        nx / sx >= MIN_SECTION_POINTS && (trend == Trend::Line || ny / sy >= MIN_SECTION_POINTS)
    };
    if !fits(1) {
        return Err(refuse(format!(
            "{ny} × {nx} grid points: too few for one section of {MIN_SECTION_POINTS} points a side"
        )));
    }
    let mut out = Vec::new();
    let mut m = 1;
    while fits(m) {
        let sections = [base[0] * m, base[1] * m];
        let Some(rms) = detrended_rms(h, sections, trend) else {
            if m == 1 {
                return Err(refuse(
                    "too few defined points to fit a plane (or line) to the whole surface",
                ));
            }
            break;
        };
        let bandwidth = match trend {
            Trend::Plane => 0.5 * (size[0] / sections[0] as f64 + size[1] / sections[1] as f64),
            Trend::Line => size[0] / sections[0] as f64,
        };
        out.push(Bandwidth {
            magnification: m,
            bandwidth,
            rms_height: rms,
        });
        m *= 2;
    }
    Ok(out)
}

/// Normal-equation sums of one section: `Σ tᵢtⱼ` (upper triangle) and `Σ tᵢh` for the
/// terms `t = (1, x, y)` (or `(1, x)`), x and y in pixels from the section's corner.
#[derive(Clone, Copy, Default)]
struct Sums {
    tt: [[f64; 3]; 3],
    th: [f64; 3],
}

/// The rms of the residuals after each section's trend is removed; `None` where a section
/// has too few defined points to fix its trend.
fn detrended_rms(h: ArrayView2<f64>, sections: [usize; 2], trend: Trend) -> Option<f64> {
    let (ny, nx) = h.dim();
    let terms = if trend == Trend::Plane { 3 } else { 2 };
    let sy = if trend == Trend::Plane {
        sections[1]
    } else {
        ny
    };
    let section = |iy: usize, ix: usize| (iy * sy / ny, ix * sections[0] / nx);
    // The first pixel of each section, along each axis.
    let start_x: Vec<usize> = (0..sections[0])
        .map(|r| (r * nx).div_ceil(sections[0]))
        .collect();
    let start_y: Vec<usize> = (0..sy).map(|r| (r * ny).div_ceil(sy)).collect();
    let local = |iy: usize, ix: usize| {
        let (ry, rx) = section(iy, ix);
        [1.0, (ix - start_x[rx]) as f64, (iy - start_y[ry]) as f64]
    };
    let mut sums = vec![Sums::default(); sy * sections[0]];
    for ((iy, ix), &v) in h.indexed_iter() {
        if v.is_nan() {
            continue;
        }
        let (ry, rx) = section(iy, ix);
        let s = &mut sums[ry * sections[0] + rx];
        let t = local(iy, ix);
        for i in 0..terms {
            for j in i..terms {
                s.tt[i][j] += t[i] * t[j];
            }
            s.th[i] += t[i] * v;
        }
    }
    let coefficients: Vec<[f64; 3]> = sums
        .iter()
        .map(|s| solve(s, terms))
        .collect::<Option<_>>()?;
    let (mut squares, mut count) = (0.0, 0usize);
    for ((iy, ix), &v) in h.indexed_iter() {
        if v.is_nan() {
            continue;
        }
        let (ry, rx) = section(iy, ix);
        let a = coefficients[ry * sections[0] + rx];
        let t = local(iy, ix);
        let fit: f64 = (0..terms).map(|i| a[i] * t[i]).sum();
        squares += (v - fit) * (v - fit);
        count += 1;
    }
    (count > 0).then(|| (squares / count as f64).sqrt())
}

/// The least-squares coefficients of one section (Gaussian elimination with partial
/// pivoting on its `terms × terms` normal equations), `None` where they are singular.
fn solve(s: &Sums, terms: usize) -> Option<[f64; 3]> {
    // The augmented matrix [T | h] of the normal equations, symmetric from the upper triangle.
    let mut a: Vec<Vec<f64>> = (0..terms)
        .map(|i| {
            let mut row: Vec<f64> = (0..terms).map(|j| s.tt[i.min(j)][i.max(j)]).collect();
            row.push(s.th[i]);
            row
        })
        .collect();
    let scale = (0..terms).map(|i| a[i][i]).fold(0.0, f64::max);
    for col in 0..terms {
        let pivot = (col..terms).max_by(|&p, &q| a[p][col].abs().total_cmp(&a[q][col].abs()))?;
        // A NaN or (near) zero pivot: the section's points do not fix the trend.
        if a[pivot][col].abs().partial_cmp(&(1e-12 * scale)) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        a.swap(col, pivot);
        let (done, rest) = a.split_at_mut(col + 1);
        let top = &done[col];
        for row in rest.iter_mut() {
            let f = row[col] / top[col];
            row.iter_mut()
                .zip(top)
                .skip(col)
                .for_each(|(r, t)| *r -= f * t);
        }
    }
    let mut x = [0.0; 3];
    for row in (0..terms).rev() {
        let known: f64 = (row + 1..terms).map(|k| a[row][k] * x[k]).sum();
        x[row] = (a[row][terms] - known) / a[row][row];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    /// A deterministic pseudo-random number in [-0.5, 0.5).
    fn noise(k: usize) -> f64 {
        let mut z = (k as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    #[test]
    fn a_plane_has_no_height_at_any_bandwidth() {
        let h = Array2::from_shape_fn((24, 40), |(y, x)| 3.0 + 0.25 * x as f64 - 0.5 * y as f64);
        let out = variable_bandwidth_area(h.view(), [4.0, 2.4]).unwrap();
        // s = (round(4/2.4), 1) = (2, 1): 2·M × M rectangles while 40/(2M) and 24/M ≥ 4.
        let ms: Vec<usize> = out.iter().map(|b| b.magnification).collect();
        assert_eq!(ms, [1, 2, 4]);
        for b in &out {
            assert!(b.rms_height < 1e-12, "{b:?}");
        }
        assert!((out[0].bandwidth - 0.5 * (4.0 / 2.0 + 2.4)).abs() < 1e-15);
    }

    #[test]
    fn sections_lose_exactly_their_own_planes() {
        // A different plane in each rectangle of the M = 2 checkerboard (2 × 2 on a square):
        // nothing is left at M = 2 and beyond, but something at M = 1.
        let n = 32;
        let h = Array2::from_shape_fn((n, n), |(y, x)| {
            let (ry, rx) = (y * 2 / n, x * 2 / n);
            (rx as f64 + 1.0) * x as f64 - (ry as f64 * 3.0 - 1.0) * y as f64 + (rx * 7 + ry) as f64
        });
        let out = variable_bandwidth_area(h.view(), [1.0, 1.0]).unwrap();
        assert!(out[0].rms_height > 1.0);
        for b in &out[1..] {
            assert!(b.rms_height < 1e-10, "{b:?}");
        }
    }

    /// The residual rms of one least-squares fit of `t` to `h`, by modified Gram–Schmidt:
    /// a second, independent route to the same numbers.
    fn residual_rms(columns: Vec<Vec<f64>>, h: &[f64]) -> f64 {
        let mut r = h.to_vec();
        let mut basis: Vec<Vec<f64>> = Vec::new();
        for mut c in columns {
            for q in &basis {
                let d: f64 = c.iter().zip(q).map(|(a, b)| a * b).sum();
                c.iter_mut().zip(q).for_each(|(a, b)| *a -= d * b);
            }
            let norm = c.iter().map(|a| a * a).sum::<f64>().sqrt();
            c.iter_mut().for_each(|a| *a /= norm);
            let d: f64 = r.iter().zip(&c).map(|(a, b)| a * b).sum();
            r.iter_mut().zip(&c).for_each(|(a, b)| *a -= d * b);
            basis.push(c);
        }
        r.iter().map(|a| a * a).sum::<f64>()
    }

    #[test]
    fn random_heights_with_undefined_points_match_a_direct_fit() {
        let (ny, nx) = (20, 27);
        let mut h = Array2::from_shape_fn((ny, nx), |(y, x)| noise(y * nx + x));
        for k in [5, 77, 300, 301, 450] {
            h[(k / nx, k % nx)] = f64::NAN;
        }
        for (m, b) in variable_bandwidth_area(h.view(), [2.7, 2.0])
            .unwrap()
            .iter()
            .enumerate()
        {
            let (sx, sy) = (b.magnification, b.magnification); // s = (1, 1): 2.7/2 rounds to 1
            let mut total = 0.0;
            let mut count = 0;
            for ry in 0..sy {
                for rx in 0..sx {
                    let pts: Vec<(usize, usize)> = (0..ny)
                        .flat_map(|y| (0..nx).map(move |x| (y, x)))
                        .filter(|&(y, x)| {
                            y * sy / ny == ry && x * sx / nx == rx && !h[(y, x)].is_nan()
                        })
                        .collect();
                    let cols = vec![
                        pts.iter().map(|_| 1.0).collect(),
                        pts.iter().map(|p| p.1 as f64).collect(),
                        pts.iter().map(|p| p.0 as f64).collect(),
                    ];
                    let v: Vec<f64> = pts.iter().map(|&p| h[p]).collect();
                    total += residual_rms(cols, &v);
                    count += v.len();
                }
            }
            let want = (total / count as f64).sqrt();
            assert!(
                (b.rms_height - want).abs() < 1e-12 * want,
                "M = {m}: {} vs {want}",
                b.rms_height
            );
        }
    }

    #[test]
    fn profile_sections_lose_their_lines() {
        // Two rows; at M = 4 each section of each row is a straight line.
        let nx = 64;
        let rows = Array2::from_shape_fn((2, nx), |(r, x)| {
            let s = x * 4 / nx;
            (s as f64 - 1.5 + r as f64) * x as f64 + (s * s) as f64
        });
        let out = variable_bandwidth_profile(rows.view(), 6.4).unwrap();
        let ms: Vec<usize> = out.iter().map(|b| b.magnification).collect();
        assert_eq!(ms, [1, 2, 4, 8, 16]);
        assert!(out[0].rms_height > 1.0 && out[1].rms_height > 0.1);
        assert!(out[2..].iter().all(|b| b.rms_height < 1e-10), "{out:?}");
        assert!((out[2].bandwidth - 1.6).abs() < 1e-15);
    }

    #[test]
    fn too_small_or_empty_surfaces_are_refused() {
        let h = Array2::from_elem((3, 10), 1.0);
        assert!(variable_bandwidth_area(h.view(), [1.0, 0.3]).is_err());
        let h = Array2::from_elem((8, 8), f64::NAN);
        assert!(variable_bandwidth_area(h.view(), [1.0, 1.0]).is_err());
        assert!(variable_bandwidth_area(h.view(), [1.0, f64::NAN]).is_err());
    }
}
