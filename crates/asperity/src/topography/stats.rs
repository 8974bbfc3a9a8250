//! ISO 25178-2 areal and ISO 4287 profile parameters of a (levelled, filled) topography,
//! in the units of its heights (metres for a file with a length unit).
//!
//! Heights are taken about their mean (the reference after the chosen levelling); no
//! λs/λc filtering is applied (primary-surface / primary-profile parameters).
//! * `Sq`, `Rq`: rms height; `Sa`, `Ra`: mean absolute height; `Ssk`, `Rsk`: skewness
//!   `mean(z³)/Sq³`; `Sku`, `Rku`: kurtosis `mean(z⁴)/Sq⁴`.
//! * `Sz`: maximum height, highest peak plus deepest pit (`max − min`). `Rz`: the mean over
//!   five sampling lengths (the profile cut into five equal sections, ISO 4288's default)
//!   of each section's highest peak plus deepest valley; profiles of fewer than 10 points
//!   are one section.
//! * `Sdq`: rms gradient, and `Sdr`: developed interfacial area ratio
//!   `mean(sqrt(1 + |∇z|²)) − 1` (a fraction; × 100 for per cent), both from the gradient
//!   at the centre of each grid cell, `∂z/∂x` the mean of the cell's two x-differences over
//!   `Δx`, `∂z/∂y` likewise over `Δy` (pixels may be rectangular). For a plane wave this
//!   gradient is the exact continuous one times a known factor, which is what the tests
//!   check. `Rdq`: rms of the forward differences `Δz/Δx`.

use ndarray::{ArrayView1, ArrayView2};
use serde::Serialize;

use crate::{Error, Result};

/// ISO 25178-2 areal parameters (heights' unit; `sdq`, `sdr` dimensionless).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArealParameters {
    /// Root mean square height.
    pub sq: f64,
    /// Arithmetic mean height.
    pub sa: f64,
    /// Maximum height (peak to pit).
    pub sz: f64,
    /// Skewness.
    pub ssk: f64,
    /// Kurtosis.
    pub sku: f64,
    /// Root mean square gradient.
    pub sdq: f64,
    /// Developed interfacial area ratio, as a fraction.
    pub sdr: f64,
}

/// ISO 4287 profile parameters (heights' unit; `rdq` dimensionless).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProfileParameters {
    /// Root mean square height.
    pub rq: f64,
    /// Arithmetic mean height.
    pub ra: f64,
    /// Mean over five sampling lengths of the maximum height (peak plus valley).
    pub rz: f64,
    /// Skewness.
    pub rsk: f64,
    /// Kurtosis.
    pub rku: f64,
    /// Root mean square slope.
    pub rdq: f64,
}

/// Mean, and the central moments 2–4 with the mean absolute deviation.
struct Moments {
    rms: f64,
    abs: f64,
    skew: f64,
    kurt: f64,
}

fn moments(values: impl Iterator<Item = f64> + Clone) -> Moments {
    let (sum, n) = values
        .clone()
        .fold((0.0, 0.0), |(s, n), v| (s + v, n + 1.0));
    let mean = sum / n;
    // The fourth powers overflow from heights of about 1e77 on (Sku became NaN) and
    // underflow below about 1e-81: the deviations are scaled by a power of two near their
    // largest (exact), the moments computed, and the rms and mean deviation scaled back;
    // skewness and kurtosis do not depend on the scale.
    let largest = values.clone().fold(0.0f64, |m, v| m.max((v - mean).abs()));
    let scale = if largest.is_finite() && largest > 0.0 {
        2f64.powi(-(largest.log2().floor() as i32))
    } else {
        1.0
    };
    let (mut a, mut m2, mut m3, mut m4) = (0.0, 0.0, 0.0, 0.0);
    for v in values {
        let d = (v - mean) * scale;
        a += d.abs();
        m2 += d * d;
        m3 += d * d * d;
        m4 += d * d * d * d;
    }
    let (a, m2, m3, m4) = (a / n, m2 / n, m3 / n, m4 / n);
    let rms = m2.sqrt();
    // A flat surface has no defined skewness or kurtosis: report 0 and 0, never NaN.
    let (skew, kurt) = if m2 > 0.0 {
        (m3 / (rms * m2), m4 / (m2 * m2))
    } else {
        (0.0, 0.0)
    };
    Moments {
        rms: rms / scale,
        abs: a / scale,
        skew,
        kurt,
    }
}

fn ensure_usable(values: impl Iterator<Item = f64>, spacings: &[f64], min: usize) -> Result<()> {
    let mut n = 0;
    for v in values {
        if !v.is_finite() {
            return Err(Error::invalid(
                "heights",
                "undefined or non-finite points: fill them before computing parameters",
            ));
        }
        n += 1;
    }
    if n < min {
        return Err(Error::invalid(
            "heights",
            format!("at least {min} points are needed, got {n}"),
        ));
    }
    if let Some(s) = spacings.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(Error::invalid(
            "spacing",
            format!(
                "must be positive and finite, got {}",
                crate::input::short_number(*s)
            ),
        ));
    }
    Ok(())
}

/// The areal parameters of a map, rows along y, pixel spacings `dx`, `dy`.
pub fn areal(h: ArrayView2<f64>, dx: f64, dy: f64) -> Result<ArealParameters> {
    let (ny, nx) = h.dim();
    if ny < 2 || nx < 2 {
        return Err(Error::invalid(
            "heights",
            format!("a map of at least 2 x 2 points is needed, got {ny} x {nx}"),
        ));
    }
    ensure_usable(h.iter().copied(), &[dx, dy], 4)?;
    let m = moments(h.iter().copied());
    let (min, max) = h
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let (g2, area) = slope_sums(&h.as_standard_layout(), dx, dy);
    let cells = ((ny - 1) * (nx - 1)) as f64;
    Ok(ArealParameters {
        sq: m.rms,
        sa: m.abs,
        sz: max - min,
        ssk: m.skew,
        sku: m.kurt,
        sdq: (g2 / cells).sqrt(),
        sdr: area / cells,
    })
}

/// `(Σ |∇h|², Σ (√(1 + |∇h|²) − 1))` over the cells of a map, the gradient of a cell the
/// mean of its two edge differences per axis. Rows of cells are summed in parallel and
/// added in row order: the result does not depend on the thread count.
fn slope_sums(h: &ndarray::CowArray<'_, f64, ndarray::Ix2>, dx: f64, dy: f64) -> (f64, f64) {
    use rayon::prelude::*;
    let (ny, nx) = h.dim();
    let data = h.as_slice().expect("standard layout");
    let rows: Vec<(f64, f64)> = (0..ny - 1)
        .into_par_iter()
        .map(|r| {
            let (top, bottom) = (
                &data[r * nx..(r + 1) * nx],
                &data[(r + 1) * nx..(r + 2) * nx],
            );
            let (mut g2, mut area) = (0.0, 0.0);
            for c in 0..nx - 1 {
                let gx = (top[c + 1] - top[c] + bottom[c + 1] - bottom[c]) / (2.0 * dx);
                let gy = (bottom[c] - top[c] + bottom[c + 1] - top[c + 1]) / (2.0 * dy);
                let s = gx * gx + gy * gy;
                g2 += s;
                // sqrt(1 + s) − 1 without cancellation for small slopes.
                area += s / ((1.0 + s).sqrt() + 1.0);
            }
            (g2, area)
        })
        .collect();
    rows.iter()
        .fold((0.0, 0.0), |(g2, area), &(a, b)| (g2 + a, area + b))
}

/// The profile parameters of a line profile with spacing `dx`.
pub fn profile(z: ArrayView1<f64>, dx: f64) -> Result<ProfileParameters> {
    ensure_usable(z.iter().copied(), &[dx], 2)?;
    let n = z.len();
    let m = moments(z.iter().copied());
    let sections = if n >= 10 { 5 } else { 1 };
    let mut rz = 0.0;
    for s in 0..sections {
        let part = z.slice(ndarray::s![s * n / sections..(s + 1) * n / sections]);
        let (lo, hi) = part
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        rz += hi - lo;
    }
    let slopes = (1..n)
        .map(|i| ((z[i] - z[i - 1]) / dx).powi(2))
        .sum::<f64>();
    Ok(ProfileParameters {
        rq: m.rms,
        ra: m.abs,
        rz: rz / sections as f64,
        rsk: m.skew,
        rku: m.kurt,
        rdq: (slopes / (n - 1) as f64).sqrt(),
    })
}

/// Radially averaged 2D PSD `C2D(q)` of a map with sizes `size_x`, `size_y` (pixels may be
/// rectangular), in physical units: `q` in radians per unit length, `C2D` in length⁴,
/// normalised so that `Σ_q C2D(q) (2π)²/A = rms²` over all modes. Rings of width `2π/L_x`
/// centred on integer `κ = q L_x/2π`, from 1 up to the smaller of the two Nyquist
/// wavenumbers — the binning of [`crate::surface::stats::radial_psd_2d`], which this equals
/// for square pixels, with `q_y = 2π k_y / L_y`.
pub fn radial_psd(
    h: ArrayView2<f64>,
    size_x: f64,
    size_y: f64,
) -> Result<Vec<crate::surface::stats::PsdBin>> {
    use num_complex::Complex64;
    let (rows, cols) = h.dim();
    ensure_usable(h.iter().copied(), &[size_x, size_y], 4)?;
    let mean = h.mean().unwrap_or(0.0);
    let mut centred = crate::memory::try_vec("the PSD's copy of the map", rows * cols, 0.0)?;
    for (c, v) in centred.iter_mut().zip(h.iter()) {
        *c = v - mean;
    }
    let mut fft = crate::fft::RealFft2::new(rows, cols)?;
    let mut spectrum = crate::memory::try_vec(
        "the PSD's spectrum",
        fft.spectrum_len(),
        Complex64::default(),
    )?;
    fft.forward(&centred, &mut spectrum);
    // κ_y in units of 2π/L_x.
    let aspect = size_x / size_y;
    let kappa_max = ((cols / 2) as f64).min((rows / 2) as f64 * aspect).floor() as usize;
    let norm = size_x * size_y / (std::f64::consts::TAU.powi(2) * ((rows * cols) as f64).powi(2));
    let sums = crate::surface::stats::ring_sums(&spectrum, rows, cols, aspect, kappa_max, norm);
    Ok(sums
        .into_iter()
        .skip(1)
        .filter(|s| s.2 > 0)
        .map(|(k, p, m)| crate::surface::stats::PsdBin {
            q: std::f64::consts::TAU / size_x * k / m as f64,
            psd: p / m as f64,
            modes: m,
        })
        .collect())
}

/// rms slope from forward differences, `sqrt(mean((Δz/Δx)²) + mean((Δz/Δy)²))` over the
/// neighbouring pairs inside the grid (the crate's definition, see
/// [`crate::surface::stats`]), with separate spacings for rectangular pixels.
pub fn rms_slope_forward(h: ArrayView2<f64>, dx: f64, dy: f64) -> f64 {
    let (ny, nx) = h.dim();
    let mean_square = |pairs: usize, sum: f64| if pairs == 0 { 0.0 } else { sum / pairs as f64 };
    let sx: f64 = h
        .rows()
        .into_iter()
        .map(|r| {
            r.windows(2)
                .into_iter()
                .map(|w| ((w[1] - w[0]) / dx).powi(2))
                .sum::<f64>()
        })
        .sum();
    let sy: f64 = h
        .columns()
        .into_iter()
        .map(|c| {
            c.windows(2)
                .into_iter()
                .map(|w| ((w[1] - w[0]) / dy).powi(2))
                .sum::<f64>()
        })
        .sum();
    (mean_square(ny * (nx - 1), sx) + mean_square(nx * (ny - 1), sy)).sqrt()
}

/// rms mean curvature of a map on pixels `dx` × `dy` (rectangular allowed): half the rms of
/// the five-point Laplacian `(h[r,c+1] − 2h[r,c] + h[r,c−1])/Δx² + (h[r+1,c] − 2h[r,c] +
/// h[r−1,c])/Δy²` over the interior points, the definition of [`crate::surface::stats`]
/// with a spacing per axis; `None` below 3 × 3 points.
pub fn rms_curvature(h: ArrayView2<f64>, dx: f64, dy: f64) -> Option<f64> {
    let (rows, cols) = h.dim();
    if rows < 3 || cols < 3 {
        return None;
    }
    let (wx, wy) = (1.0 / (dx * dx), 1.0 / (dy * dy));
    let mut sum = 0.0;
    for r in 1..rows - 1 {
        for c in 1..cols - 1 {
            let centre = 2.0 * h[[r, c]];
            let lap = (h[[r, c + 1]] - centre + h[[r, c - 1]]) * wx
                + (h[[r + 1, c]] - centre + h[[r - 1, c]]) * wy;
            sum += lap * lap;
        }
    }
    Some(0.5 * (sum / ((rows - 2) * (cols - 2)) as f64).sqrt())
}

/// The bearing-area (Abbott–Firestone) curve: at each of `points` material ratios
/// `p = k / (points − 1)` (0 to 1), the height `c` above which the fraction `p` of the defined
/// heights lies (ISO 25178-2's areal material ratio `Smr(c) = p`, inverted), from the sorted
/// heights by linear interpolation between order statistics. Undefined (NaN) heights are
/// left out; refused when none is defined or fewer than 2 points are asked for.
pub fn bearing_area_curve(
    heights: impl IntoIterator<Item = f64>,
    points: usize,
) -> Result<Vec<(f64, f64)>> {
    let mut z: Vec<f64> = heights.into_iter().filter(|v| !v.is_nan()).collect();
    if z.is_empty() || points < 2 {
        return Err(Error::invalid(
            "bearing-area curve",
            format!("{} defined heights and {points} ratios asked for", z.len()),
        ));
    }
    z.sort_by(|a, b| b.total_cmp(a));
    let last = (z.len() - 1) as f64;
    Ok((0..points)
        .map(|k| {
            let p = k as f64 / (points - 1) as f64;
            let at = p * last;
            let (i, t) = (at.floor() as usize, at.fract());
            let c = if i + 1 < z.len() {
                z[i] + t * (z[i + 1] - z[i])
            } else {
                z[i]
            };
            (p, c)
        })
        .collect())
}

/// The probability density of `values` (NaN left out) as `(bin centre, density)` over
/// `bins` equal bins from the smallest to the largest value (the last bin closed), the
/// density `count / (n · width)` so that it integrates to 1 (numpy's
/// `histogram(density=True)`). Refused where no value is defined, fewer than one bin is
/// asked for, or every value is the same (a distribution of zero width has no density).
pub fn distribution(values: impl IntoIterator<Item = f64>, bins: usize) -> Result<Vec<(f64, f64)>> {
    let z: Vec<f64> = values.into_iter().filter(|v| !v.is_nan()).collect();
    let (lo, hi) = z
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let width = (hi - lo) / bins as f64;
    if z.is_empty() || bins == 0 || !(width.is_finite() && width > 0.0) {
        return Err(Error::invalid(
            "distribution",
            format!(
                "{} defined values from {lo:e} to {hi:e} in {bins} bins",
                z.len()
            ),
        ));
    }
    let mut counts = vec![0usize; bins];
    for v in &z {
        let k = (((v - lo) / width) as usize).min(bins - 1);
        counts[k] += 1;
    }
    let n = z.len() as f64;
    Ok(counts
        .iter()
        .enumerate()
        .map(|(k, &c)| (lo + (k as f64 + 0.5) * width, c as f64 / (n * width)))
        .collect())
}

/// The slopes along x, `(h[i+1] − h[i])/Δx` within each row (pairs with an undefined
/// point left out), and the curvatures along x, `(h[i+1] − 2h[i] + h[i−1])/Δx²`: the values
/// whose distributions contact.engineering shows beside the heights'.
pub fn slopes_and_curvatures_along_x(rows: ArrayView2<f64>, dx: f64) -> (Vec<f64>, Vec<f64>) {
    let mut slopes = Vec::new();
    let mut curvatures = Vec::new();
    for row in rows.rows() {
        let r: Vec<f64> = row.iter().copied().collect();
        slopes.extend(
            r.windows(2)
                .map(|w| (w[1] - w[0]) / dx)
                .filter(|v| !v.is_nan()),
        );
        curvatures.extend(
            r.windows(3)
                .map(|w| (w[2] - 2.0 * w[1] + w[0]) / (dx * dx))
                .filter(|v| !v.is_nan()),
        );
    }
    (slopes, curvatures)
}

/// The material ratio `Smr(c)`: the fraction of the defined heights at or above `c`.
pub fn material_ratio(heights: impl IntoIterator<Item = f64>, c: f64) -> f64 {
    let (mut above, mut n) = (0usize, 0usize);
    for v in heights.into_iter().filter(|v| !v.is_nan()) {
        n += 1;
        above += usize::from(v >= c);
    }
    above as f64 / n.max(1) as f64
}

/// The scale-dependent rms slope `s(r) = √(2A(r))/r` from the height-difference ACF
/// `(r, A)` (as [`height_difference_acf`] gives it, distances in length): the rms of the
/// two-point slope `(h(x + r) − h(x))/r` at each distance `r > 0` (SurfaceTopography's
/// `scale_dependent_slope_from_profile`). `r = 0` is left out.
pub fn scale_dependent_slope(acf: &[(f64, f64)]) -> Vec<(f64, f64)> {
    acf.iter()
        .filter(|&&(r, _)| r > 0.0)
        .map(|&(r, a)| (r, (2.0 * a).sqrt() / r))
        .collect()
}

/// Scale factors per decade of [`scale_dependent_curvature`] (SurfaceTopography's default
/// log collocation).
pub const CURVATURE_FACTORS_PER_DECADE: f64 = 10.0;

/// The scale-dependent rms curvature along x: at each integer scale factor `s` (log-spaced,
/// [`CURVATURE_FACTORS_PER_DECADE`] a decade, every distinct integer from 1 to
/// `⌊(n − 1)/2⌋`), the rms of the three-point second difference
/// `(h[i+s] − 2h[i] + h[i−s])/(sΔx)²` over every triple of defined points within a row,
/// pooled over the rows, reported at the stencil's length `r = 2sΔx`
/// (SurfaceTopography's `scale_dependent_statistical_property(n=2, scale_factor=s)` of a
/// profile, whose `distance` is that length). Returns `(r, rms curvature)` for each factor
/// with at least one defined triple, in the heights' unit per length squared; `O(N)` a
/// factor. Refused where no row has three points.
pub fn scale_dependent_curvature(rows: ArrayView2<f64>, dx: f64) -> Result<Vec<(f64, f64)>> {
    let n = rows.ncols();
    if n < 3 || !(dx.is_finite() && dx > 0.0) {
        return Err(Error::invalid(
            "scale-dependent curvature",
            format!("{n} points per row at a spacing of {dx:e}"),
        ));
    }
    let largest = (n - 1) / 2;
    let mut factors: Vec<usize> = (0..)
        .map(|k| (10f64.powf(k as f64 / CURVATURE_FACTORS_PER_DECADE)).round() as usize)
        .take_while(|&s| s <= largest)
        .collect();
    factors.dedup();
    let mut out = Vec::with_capacity(factors.len());
    for s in factors {
        let (mut sum, mut count) = (0.0, 0usize);
        for row in rows.rows() {
            for i in s..n - s {
                let c = row[i + s] - 2.0 * row[i] + row[i - s];
                if !c.is_nan() {
                    sum += c * c;
                    count += 1;
                }
            }
        }
        if count > 0 {
            let step = s as f64 * dx;
            out.push((2.0 * step, (sum / count as f64).sqrt() / (step * step)));
        }
    }
    Ok(out)
}

/// The height-difference autocorrelation function along x, `A(r_k) = ½⟨(h(x + r_k) −
/// h(x))²⟩` at `r_k = kΔx` (SurfaceTopography's `autocorrelation_from_profile` of a
/// non-periodic scan, on the grid): the mean over every pair of defined points at distance
/// `k` pixels along a row, pooled over the rows of a map (the average of the rows' ACFs
/// where none is undefined). Returns `(k, A)` for each `k` with at least one such pair, in
/// the heights' unit squared. From three cross-correlations by zero-padded FFTs
/// (`Σ m_i m_{i+k}`, `Σ g_i g_{i+k}`, `Σ (s_i m_{i+k} + m_i s_{i+k})` with `g = (h − h̄)m`,
/// `s = g²`, `m` the defined points), summed over rows in Fourier space: `O(N log N)`.
pub fn height_difference_acf(rows: ArrayView2<f64>) -> Result<Vec<(usize, f64)>> {
    let (ny, n) = rows.dim();
    let defined = rows.iter().filter(|v| !v.is_nan()).count();
    if n < 2 || defined == 0 {
        return Err(Error::invalid(
            "autocorrelation",
            format!("{n} points per row and {defined} defined heights"),
        ));
    }
    let mean = rows.iter().filter(|v| !v.is_nan()).sum::<f64>() / defined as f64;
    let len = (2 * n - 1).next_power_of_two();
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    let (fwd, inv) = (planner.plan_fft_forward(len), planner.plan_fft_inverse(len));
    let bins = len / 2 + 1;
    let zero = num_complex::Complex64::new(0.0, 0.0);
    let mut sums = vec![vec![zero; bins]; 3]; // mm, gg, sm + ms
    let mut spectra = vec![vec![zero; bins]; 3]; // m, g, s
    let mut input = vec![0.0; len];
    for r in 0..ny {
        for (which, spectrum) in spectra.iter_mut().enumerate() {
            input.fill(0.0);
            for (i, &v) in rows.row(r).iter().enumerate() {
                if !v.is_nan() {
                    let g = v - mean;
                    input[i] = [1.0, g, g * g][which];
                }
            }
            fwd.process(&mut input, spectrum).map_err(fft_error)?;
        }
        let [m, g, s] = [&spectra[0], &spectra[1], &spectra[2]];
        for b in 0..bins {
            sums[0][b] += m[b].conj() * m[b];
            sums[1][b] += g[b].conj() * g[b];
            sums[2][b] += s[b].conj() * m[b] + m[b].conj() * s[b];
        }
    }
    let mut lags = vec![vec![0.0; len]; 3];
    for (sum, lag) in sums.iter_mut().zip(&mut lags) {
        sum[0].im = 0.0;
        sum[bins - 1].im = 0.0;
        inv.process(sum, lag).map_err(fft_error)?;
    }
    let scale = 1.0 / len as f64;
    Ok((0..n)
        .filter_map(|k| {
            let pairs = (lags[0][k] * scale).round();
            (pairs >= 1.0).then(|| {
                let a = (0.5 * lags[2][k] - lags[1][k]) * scale / pairs;
                (k, a.max(0.0))
            })
        })
        .collect())
}

/// The radially averaged two-dimensional height-difference ACF of a map,
/// `A(r) = ½⟨(h(x + r) − h(x))²⟩` over every pair of defined points whose separation `r`
/// (any direction; `Δx`, `Δy` may differ) has a length in the bin: bins of width
/// `Δ = min(Δx, Δy)` centred on `0, Δ, 2Δ, …` (`|r|/Δ` rounded). Returns
/// `(mean |r| of the bin's pairs, A)` for every bin holding a pair, in the heights' unit
/// squared. The pair sums over every lag vector come from three 2-D cross-correlations by
/// zero-padded FFTs (as [`height_difference_acf`] along x); they need about
/// `48 · (2n_x)(2n_y)` bytes, checked against the memory first.
/// SurfaceTopography's `autocorrelation_from_area` of a non-periodic map differs by
/// definition: it averages the map over lag vectors with non-negative components only,
/// unweighted by their pair counts, in log-spaced bins.
pub fn radial_height_difference_acf(
    h: ArrayView2<f64>,
    dx: f64,
    dy: f64,
) -> Result<Vec<(f64, f64)>> {
    use rustfft::num_complex::Complex64;
    let (ny, nx) = h.dim();
    let defined = h.iter().filter(|v| !v.is_nan()).count();
    if nx < 2 || ny < 2 || defined == 0 || !(dx > 0.0 && dy > 0.0) {
        return Err(Error::invalid(
            "radial autocorrelation",
            format!("a {ny} × {nx} map with {defined} defined heights (a map is needed)"),
        ));
    }
    let (py, px) = (
        (2 * ny - 1).next_power_of_two(),
        (2 * nx - 1).next_power_of_two(),
    );
    crate::memory::ensure_fits(
        "the radially averaged ACF",
        (py as u64)
            .checked_mul(px as u64)
            .map(|n| n.saturating_mul(48)),
    )?;
    let mean = h.iter().filter(|v| !v.is_nan()).sum::<f64>() / defined as f64;
    let field = |which: usize| {
        let mut f = vec![Complex64::new(0.0, 0.0); py * px];
        for ((r, c), &v) in h.indexed_iter() {
            if !v.is_nan() {
                let g = v - mean;
                f[r * px + c].re = [1.0, g, g * g][which];
            }
        }
        f
    };
    let (mut m, mut g, mut s) = (field(0), field(1), field(2));
    let mut planner = rustfft::FftPlanner::<f64>::new();
    for f in [&mut m, &mut g, &mut s] {
        fft_2d(&mut planner, f, py, px, rustfft::FftDirection::Forward);
    }
    for ((mi, gi), si) in m.iter_mut().zip(&mut g).zip(&mut s) {
        *si = si.conj() * *mi + mi.conj() * *si;
        *gi = gi.conj() * *gi;
        *mi = mi.conj() * *mi;
    }
    for f in [&mut m, &mut g, &mut s] {
        fft_2d(&mut planner, f, py, px, rustfft::FftDirection::Inverse);
    }
    let scale = 1.0 / (py * px) as f64;
    let step = dx.min(dy);
    let mut bins: Vec<[f64; 3]> = Vec::new(); // Σ pairs, Σ pairs · A, Σ pairs · |r|
                                              // Half of the lag vectors (ky > 0, or ky = 0 and kx ≥ 0): A(−r) = A(r).
    for ky in 0..ny {
        let lo = if ky == 0 { 0 } else { 1 - nx as isize };
        for kx in lo..nx as isize {
            let at = ky * px + kx.rem_euclid(px as isize) as usize;
            let pairs = (m[at].re * scale).round();
            if pairs < 1.0 {
                continue;
            }
            let sum = (0.5 * s[at].re - g[at].re) * scale; // Σ ½(h_i − h_j)²
            let r = ((kx as f64 * dx).powi(2) + (ky as f64 * dy).powi(2)).sqrt();
            let b = (r / step).round() as usize;
            if bins.len() <= b {
                bins.resize(b + 1, [0.0; 3]);
            }
            bins[b][0] += pairs;
            bins[b][1] += sum.max(0.0);
            bins[b][2] += pairs * r;
        }
    }
    Ok(bins
        .iter()
        .filter(|b| b[0] > 0.0)
        .map(|b| (b[2] / b[0], b[1] / b[0]))
        .collect())
}

/// An in-place 2-D FFT of a row-major `rows × cols` array (unnormalised).
fn fft_2d(
    planner: &mut rustfft::FftPlanner<f64>,
    data: &mut [rustfft::num_complex::Complex64],
    rows: usize,
    cols: usize,
    direction: rustfft::FftDirection,
) {
    planner.plan_fft(cols, direction).process(data);
    let column = planner.plan_fft(rows, direction);
    let mut buffer = vec![rustfft::num_complex::Complex64::new(0.0, 0.0); rows];
    for c in 0..cols {
        for (r, b) in buffer.iter_mut().enumerate() {
            *b = data[r * cols + c];
        }
        column.process(&mut buffer);
        for (r, b) in buffer.iter().enumerate() {
            data[r * cols + c] = *b;
        }
    }
}

fn fft_error(e: impl std::fmt::Display) -> Error {
    Error::invalid("autocorrelation", e.to_string())
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_uniform_sample_has_a_flat_density_that_integrates_to_one() {
        // 0, 1, ..., 99 and two undefined points in 10 bins of width 9.9: 10 values each.
        let values = (0..100).map(f64::from).chain([f64::NAN, f64::NAN]);
        let d = super::distribution(values, 10).unwrap();
        assert_eq!(d.len(), 10);
        for (k, &(centre, density)) in d.iter().enumerate() {
            assert!((centre - (k as f64 + 0.5) * 9.9).abs() < 1e-12, "{centre}");
            assert!((density - 10.0 / (100.0 * 9.9)).abs() < 1e-15, "{density}");
        }
        let total: f64 = d.iter().map(|&(_, p)| p * 9.9).sum();
        assert!((total - 1.0).abs() < 1e-12);
        // No width, no values, no bins: refused.
        assert!(super::distribution([2.0, 2.0, f64::NAN], 5).is_err());
        assert!(super::distribution([f64::NAN], 5).is_err());
        assert!(super::distribution([1.0, 2.0], 0).is_err());
    }

    #[test]
    fn slopes_and_curvatures_of_a_parabola() {
        // h = x² at x = iΔx: slopes (2i + 1)Δx, curvature 2 everywhere; an undefined point
        // removes the pairs and triples it is in.
        let dx = 0.25;
        let mut h = ndarray::Array2::from_shape_fn((2, 6), |(_, i)| (i as f64 * dx).powi(2));
        h[(1, 5)] = f64::NAN;
        let (slopes, curvatures) = super::slopes_and_curvatures_along_x(h.view(), dx);
        let row: Vec<f64> = (0..5).map(|i| (2 * i + 1) as f64 * dx).collect();
        let want: Vec<f64> = row.iter().chain(&row[..4]).copied().collect();
        assert_eq!(slopes.len(), want.len());
        for (g, w) in slopes.iter().zip(&want) {
            assert!((g - w).abs() < 1e-12, "{g} vs {w}");
        }
        assert_eq!(curvatures.len(), 4 + 3);
        assert!(
            curvatures.iter().all(|c| (c - 2.0).abs() < 1e-12),
            "{curvatures:?}"
        );
    }

    use super::*;
    use ndarray::{Array1, Array2};
    use std::f64::consts::PI;

    /// Issue 33 item 15: heights near 1e80 gave `Sku: NaN` (their fourth powers
    /// overflow); heights of any magnitude now give the moments of the unscaled ones.
    #[test]
    fn moments_do_not_depend_on_the_heights_units() {
        let h = Array2::from_shape_fn((16, 16), |(r, c)| ((r * 5 + c * 11) as f64 * 0.3).sin());
        let reference = areal(h.view(), 0.1, 0.1).unwrap();
        for factor in [1e80, 1e150, 1e-90, 2f64.powi(300)] {
            let got = areal((&h * factor).view(), 0.1, 0.1).unwrap();
            assert!(
                got.sku.is_finite() && got.ssk.is_finite(),
                "{factor:e}: {got:?}"
            );
            assert!((got.sku / reference.sku - 1.0).abs() < 1e-13, "{factor:e}");
            assert!((got.ssk / reference.ssk - 1.0).abs() < 1e-12, "{factor:e}");
            assert!(
                (got.sq / factor / reference.sq - 1.0).abs() < 1e-14,
                "{factor:e}"
            );
            let p = profile((&h.row(2) * factor).view(), 0.1).unwrap();
            assert!(
                p.rku.is_finite() && p.rq.is_finite() && p.rq > 0.0,
                "{factor:e}"
            );
        }
    }

    /// The parallel sums (cell slopes by rows, PSD rings by column blocks) are added in a
    /// fixed order: 1, 2 and 3 threads give the very same bits, on a grid with several
    /// blocks of each (odd, non-square).
    #[test]
    fn parameters_do_not_depend_on_the_thread_count() {
        let (rows, cols) = (151, 290);
        let h = Array2::from_shape_fn((rows, cols), |(r, c)| {
            ((r * 7 + c * 13) % 17) as f64 * 0.1 + (r as f64 * 0.3).sin() * (c as f64 * 0.05).cos()
        });
        let run = || {
            let a = areal(h.view(), 0.5, 0.7).unwrap();
            let psd = radial_psd(h.view(), 145.0, 105.7).unwrap();
            (
                format!("{a:?}"),
                psd.iter()
                    .map(|b| (b.q.to_bits(), b.psd.to_bits()))
                    .collect::<Vec<_>>(),
            )
        };
        let one = crate::test_support::with_threads(1, run);
        for threads in [2, 3] {
            assert_eq!(
                crate::test_support::with_threads(threads, run),
                one,
                "{threads} threads"
            );
        }
    }

    fn close(a: f64, b: f64, rel: f64, what: &str) {
        assert!(
            (a - b).abs() <= rel * b.abs().max(1e-300),
            "{what}: {a} vs {b}"
        );
    }

    /// Complete elliptic integral of the second kind E(m) by the arithmetic–geometric mean.
    fn elliptic_e(m: f64) -> f64 {
        let (mut a, mut b) = (1.0f64, (1.0 - m).sqrt());
        let mut sum = m / 2.0; // 2^(n−1) c_n² for n = 0, c_0² = m
        let mut power = 0.5;
        for _ in 0..40 {
            let c = (a - b) / 2.0;
            let (a1, b1) = ((a + b) / 2.0, (a * b).sqrt());
            power *= 2.0;
            sum += power * c * c;
            a = a1;
            b = b1;
        }
        PI / (2.0 * a) * (1.0 - sum)
    }

    #[test]
    fn elliptic_e_known_values() {
        close(elliptic_e(0.0), PI / 2.0, 1e-15, "E(0)");
        close(elliptic_e(0.5), 1.350_643_881_047_675_5, 1e-14, "E(1/2)");
    }

    /// z = A sin(2π x/λ), λ = M Δx, on j whole periods plus one point (a non-periodic
    /// grid: N = jM + 1 samples, the last at phase 2πj where sin = 0). Closed forms of the
    /// sampled sinusoid: Σ sin² = jM/2, Σ |sin| = 2j cot(π/M) (M even), Σ sin³ = 0,
    /// Σ sin⁴ = 3jM/8 (M ≥ 5); max − min = 2A when M is a multiple of 4; forward
    /// differences are (2A sin(π/M)/Δx) cos(phase + π/M), whose mean square over whole
    /// periods is half the square amplitude.
    #[test]
    fn sinusoid_profile_and_map_match_closed_forms() {
        let (a, m, j, dx, dy) = (2.5e-7, 64usize, 5usize, 0.3e-6, 0.7e-6);
        let n = j * m + 1;
        let wave = |i: usize| a * (2.0 * PI * i as f64 / m as f64).sin();
        let nf = n as f64;
        let jm = (j * m) as f64;
        let sq = a * (jm / 2.0 / nf).sqrt();
        let sa = a * 2.0 * j as f64 / (PI / m as f64).tan() / nf;
        let sku = (3.0 * jm / 8.0 / nf) / (jm / 2.0 / nf).powi(2);
        let slope = 2.0 * a * (PI / m as f64).sin() / dx / 2f64.sqrt();
        // Profile (five sections of 64 points, each with a whole period).
        let z = Array1::from_shape_fn(n, wave);
        let p = profile(z.view(), dx).unwrap();
        close(p.rq, sq, 1e-13, "Rq");
        close(p.ra, sa, 1e-13, "Ra");
        close(p.rz, 2.0 * a, 1e-13, "Rz");
        assert!(p.rsk.abs() < 1e-12, "Rsk {}", p.rsk);
        close(p.rku, sku, 1e-12, "Rku");
        close(p.rdq, slope, 1e-12, "Rdq");
        // The same wave along x of a map (rows identical, Δy ≠ Δx).
        let h = Array2::from_shape_fn((7, n), |(_, c)| wave(c));
        let s = areal(h.view(), dx, dy).unwrap();
        close(s.sq, sq, 1e-13, "Sq");
        close(s.sa, sa, 1e-13, "Sa");
        close(s.sz, 2.0 * a, 1e-13, "Sz");
        assert!(s.ssk.abs() < 1e-12);
        close(s.sku, sku, 1e-12, "Sku");
        close(s.sdq, slope, 1e-12, "Sdq");
    }

    /// A plane wave z = A sin(a x + b y) on rectangular pixels: the cell-centre gradient is
    /// G cos(θ_c) with G² = (2A sin(aΔx/2) cos(bΔy/2)/Δx)² + (2A sin(bΔy/2) cos(aΔx/2)/Δy)²,
    /// so Sdq = G/√2 and Sdr = (2/π) sqrt(1 + G²) E(G²/(1 + G²)) − 1 (the mean of
    /// sqrt(1 + G² cos² θ) over whole periods; the sampled mean equals it to rounding, the
    /// integrand's Fourier coefficients decaying geometrically).
    #[test]
    fn plane_wave_on_rectangular_pixels_sdq_sdr() {
        let (amp, dx, dy) = (0.6e-6, 0.5e-6, 1.25e-6);
        let (cx, cy, mx, my) = (48usize, 40usize, 5.0, 3.0); // cells per axis, periods
        let (a, b) = (
            2.0 * PI * mx / (cx as f64 * dx),
            2.0 * PI * my / (cy as f64 * dy),
        );
        let h = Array2::from_shape_fn((cy + 1, cx + 1), |(r, c)| {
            amp * (a * c as f64 * dx + b * r as f64 * dy).sin()
        });
        let s = areal(h.view(), dx, dy).unwrap();
        let gx = 2.0 * amp * (a * dx / 2.0).sin() * (b * dy / 2.0).cos() / dx;
        let gy = 2.0 * amp * (b * dy / 2.0).sin() * (a * dx / 2.0).cos() / dy;
        let g2 = gx * gx + gy * gy;
        close(s.sdq, (g2 / 2.0).sqrt(), 1e-12, "Sdq");
        let sdr = 2.0 / PI * (1.0 + g2).sqrt() * elliptic_e(g2 / (1.0 + g2)) - 1.0;
        close(s.sdr, sdr, 1e-11, "Sdr");
        assert!(g2 > 0.5, "a test with slopes of order one: G² = {g2}");
    }

    #[test]
    fn forward_rms_slope_matches_the_square_pixel_definition() {
        let h = Array2::from_shape_fn((9, 13), |(r, c)| ((r * 5 + c * 3) as f64 * 0.7).sin());
        let ours = rms_slope_forward(h.view(), 0.25, 0.25);
        let crate_wide = crate::surface::stats::rms_slope_2d(h.view(), 0.25);
        close(ours, crate_wide, 1e-13, "rms slope");
        // Along x only, Δy does not matter.
        let wave = Array2::from_shape_fn((4, 9), |(_, c)| c as f64 * 2.0);
        close(
            rms_slope_forward(wave.view(), 0.5, 3.0),
            4.0,
            1e-15,
            "slope 4",
        );
    }

    #[test]
    fn curvature_on_rectangular_pixels_is_exact_for_a_quadratic() {
        // h = a x² + b y²: the five-point Laplacian is exactly 2a + 2b at every interior
        // point, on any pixels, so the rms mean curvature is |a + b|.
        let (dx, dy, a, b) = (0.3, 0.7, 1.5, -0.25);
        let h = Array2::from_shape_fn((7, 11), |(r, c)| {
            let (x, y) = (c as f64 * dx, r as f64 * dy);
            a * x * x + b * y * y
        });
        close(
            rms_curvature(h.view(), dx, dy).unwrap(),
            a + b,
            1e-12,
            "quadratic",
        );
        // On square pixels, the crate's definition.
        let rough = Array2::from_shape_fn((9, 13), |(r, c)| ((r * 5 + c * 3) as f64 * 0.7).sin());
        close(
            rms_curvature(rough.view(), 0.25, 0.25).unwrap(),
            crate::surface::stats::rms_curvature_2d(rough.view(), 0.25).unwrap(),
            1e-13,
            "square pixels",
        );
        assert_eq!(rms_curvature(Array2::zeros((2, 5)).view(), 1.0, 1.0), None);
    }

    #[test]
    fn psd_equals_the_square_pixel_one_and_holds_a_plane_wave_on_rectangular_pixels() {
        let h = Array2::from_shape_fn((24, 32), |(r, c)| {
            ((r * 7 + c * 3) as f64 * 0.37).sin() + (c as f64 * 0.11).cos()
        });
        let surface = crate::surface::Surface::new(h.clone(), 3.2).unwrap();
        let theirs = crate::surface::stats::radial_psd_2d(&surface).unwrap();
        let ours = radial_psd(h.view(), 3.2, 2.4).unwrap();
        assert_eq!(ours.len(), theirs.len());
        for (a, b) in ours.iter().zip(&theirs) {
            close(a.q, b.q, 1e-14, "q");
            close(a.psd, b.psd, 1e-12, "psd");
        }
        // A plane wave A cos(2π(3x/Lx + 2y/Ly)) with Lx = 2e-5 m, Ly = 1e-5 m on 40 x 30
        // pixels: all its power A²/2 in the ring κ = round(hypot(3, 2 Lx/Ly)) = 5,
        // in m⁴: Σ C (2π)²/A_nominal over the ring's modes = A²/2.
        let (lx, ly, amp) = (2e-5, 1e-5, 3e-8);
        let (ny, nx) = (30, 40);
        let wave = Array2::from_shape_fn((ny, nx), |(r, c)| {
            let (x, y) = (c as f64 * lx / nx as f64, r as f64 * ly / ny as f64);
            amp * (2.0 * PI * (3.0 * x / lx + 2.0 * y / ly)).cos()
        });
        let bins = radial_psd(wave.view(), lx, ly).unwrap();
        let power = |b: &crate::surface::stats::PsdBin| {
            b.psd * b.modes as f64 * (2.0 * PI).powi(2) / (lx * ly)
        };
        // The ring holding the power is κ = 5 (its q is the mean over all the ring's modes,
        // within half a ring of 5).
        let ring = bins
            .iter()
            .max_by(|a, b| power(a).total_cmp(&power(b)))
            .unwrap();
        assert!(
            (ring.q * lx / (2.0 * PI) - 5.0).abs() < 0.5,
            "ring at {}",
            ring.q
        );
        close(power(ring), amp * amp / 2.0, 1e-12, "ring power");
        let rest: f64 = bins.iter().map(power).sum::<f64>() - power(ring);
        assert!(rest.abs() < 1e-12 * amp * amp, "other rings hold {rest}");
    }

    #[test]
    fn undefined_points_are_refused() {
        let mut h = Array2::<f64>::zeros((3, 3));
        h[(1, 1)] = f64::NAN;
        assert!(areal(h.view(), 1.0, 1.0).is_err());
        let flat = areal(Array2::<f64>::zeros((3, 3)).view(), 1.0, 1.0).unwrap();
        assert_eq!(
            (flat.sq, flat.ssk, flat.sku, flat.sdr),
            (0.0, 0.0, 0.0, 0.0)
        );
    }

    #[test]
    fn height_difference_acf_against_its_definition() {
        // A ramp h_i = i gives A(k) = k²/2 exactly; random heights with undefined points
        // give the direct pair average, ½ Σ (h_i − h_{i+k})² / pairs over the rows.
        let ramp = Array2::from_shape_fn((3, 40), |(_, c)| c as f64 * 0.5);
        for (k, a) in height_difference_acf(ramp.view()).unwrap() {
            let want = 0.5 * (0.5 * k as f64).powi(2);
            assert!(
                (a - want).abs() <= 1e-9 * want.max(1.0),
                "{k}: {a} vs {want}"
            );
        }
        let mut h = Array2::from_shape_fn((5, 37), |(r, c)| {
            ((r * 37 + c) as f64 * 0.7).sin() * 3.0 + ((c * c) as f64 * 0.01).cos() + 1e3
        });
        for (r, c) in [(0, 3), (1, 0), (2, 36), (4, 17), (4, 18)] {
            h[(r, c)] = f64::NAN;
        }
        let acf = height_difference_acf(h.view()).unwrap();
        assert_eq!(acf.len(), 37);
        for (k, a) in acf {
            let (mut sum, mut pairs) = (0.0, 0);
            for row in h.rows() {
                for i in 0..37 - k {
                    let d = row[i] - row[i + k];
                    if !d.is_nan() {
                        sum += d * d;
                        pairs += 1;
                    }
                }
            }
            let want = 0.5 * sum / pairs as f64;
            assert!(
                (a - want).abs() <= 1e-9 * want.max(1e-3),
                "{k}: {a} vs {want}"
            );
        }
        assert!(height_difference_acf(Array2::from_elem((2, 1), 1.0).view()).is_err());
    }

    #[test]
    fn scale_dependent_curvature_of_polynomials_in_closed_form() {
        // h = x² (x = iΔx): every second difference is 2(sΔx)², the curvature 2 at every
        // scale. h = x³: (h[i+s] − 2h[i] + h[i−s])/(sΔx)² = 6x exactly, so the rms over
        // i = s..n−s−1 is 6Δx √(Σ i²/count).
        let (n, dx) = (40, 0.25);
        let x = |i: usize| i as f64 * dx;
        let sq = ndarray::Array2::from_shape_fn((3, n), |(_, i)| x(i) * x(i));
        let rows = super::scale_dependent_curvature(sq.view(), dx).unwrap();
        let factors: Vec<f64> = rows.iter().map(|r| r.0 / (2.0 * dx)).collect();
        assert_eq!(
            factors,
            [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 13.0, 16.0]
        );
        for &(_, c) in &rows {
            close(c, 2.0, 1e-12, "curvature of x²");
        }
        let mut cube = ndarray::Array2::from_shape_fn((2, n), |(_, i)| x(i).powi(3));
        cube[(1, 7)] = f64::NAN; // its three triples left out
        let rows = super::scale_dependent_curvature(cube.view(), dx).unwrap();
        for &(r, c) in &rows {
            let s = (r / (2.0 * dx)).round() as usize;
            let (mut sum, mut count) = (0.0, 0.0);
            for row in 0..2 {
                for i in s..n - s {
                    if row == 1 && [i - s, i, i + s].contains(&7) {
                        continue;
                    }
                    sum += (6.0 * x(i)).powi(2);
                    count += 1.0;
                }
            }
            close(c, (sum / count).sqrt(), 1e-9, "curvature of x³");
        }
        assert!(super::scale_dependent_curvature(cube.slice(ndarray::s![.., ..2]), dx).is_err());
    }

    #[test]
    fn radial_acf_against_its_definition_and_a_plane() {
        // Every pair of defined points, binned by round(|r|/min(Δx, Δy)): the definition.
        let (ny, nx, dx, dy) = (5, 7, 0.5, 0.75);
        let mut h = ndarray::Array2::from_shape_fn((ny, nx), |(r, c)| {
            ((r * 7 + c * 3) as f64).sin() + 0.1 * (r * c) as f64
        });
        h[(2, 3)] = f64::NAN;
        let got = super::radial_height_difference_acf(h.view(), dx, dy).unwrap();
        let mut bins: Vec<[f64; 3]> = Vec::new();
        for (i, &a) in h.indexed_iter() {
            for (j, &b) in h.indexed_iter() {
                let (ky, kx) = (j.0 as f64 - i.0 as f64, j.1 as f64 - i.1 as f64);
                let half = ky > 0.0 || (ky == 0.0 && kx >= 0.0);
                if !half || a.is_nan() || b.is_nan() {
                    continue;
                }
                let r = ((kx * dx).powi(2) + (ky * dy).powi(2)).sqrt();
                let k = (r / dx).round() as usize;
                if bins.len() <= k {
                    bins.resize(k + 1, [0.0; 3]);
                }
                bins[k][0] += 1.0;
                bins[k][1] += 0.5 * (a - b).powi(2);
                bins[k][2] += r;
            }
        }
        let want: Vec<(f64, f64)> = bins
            .iter()
            .filter(|b| b[0] > 0.0)
            .map(|b| (b[2] / b[0], b[1] / b[0]))
            .collect();
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            close(g.0, w.0, 1e-12, "mean distance");
            assert!((g.1 - w.1).abs() <= 1e-12 * w.1.max(1.0), "{g:?} vs {w:?}");
        }
        // A plane h = a·x: every pair at lag (kx, ky) differs by a·kx·Δx, so the bin of
        // the lags along y alone (kx = 0, |r| = kyΔy) holds zero where no other lag falls.
        let plane = ndarray::Array2::from_shape_fn((4, 4), |(_, c)| 3.0 * c as f64);
        let got = super::radial_height_difference_acf(plane.view(), 1.0, 10.0).unwrap();
        // Bins at 0, 1, 2, 3 (lags along x: A = ½(3k)²) and 10, 20, 30 (along y, plus
        // the diagonal lags, whose |r| rounds to the same bins).
        close(got[1].1, 4.5, 1e-12, "A(Δx) = ½ · 3²");
        close(got[3].1, 40.5, 1e-12, "A(3Δx) = ½ · 9²");
        assert!(
            super::radial_height_difference_acf(plane.slice(ndarray::s![..1, ..]), 1.0, 1.0)
                .is_err()
        );
    }

    #[test]
    fn bearing_area_of_a_sinusoid_is_its_arccosine() {
        // z = A sin(2π x / L) over 4 periods, 4096 midpoint samples: the fraction above c
        // is acos(c / A) / π exactly in the continuum; sampling errs by at most a few 1/n.
        let (n, a) = (4096, 2e-6);
        let z: Vec<f64> = (0..n)
            .map(|i| a * (2.0 * std::f64::consts::PI * 4.0 * (i as f64 + 0.5) / n as f64).sin())
            .collect();
        for c in [-1.5e-6, -0.5e-6, 0.0, 0.7e-6, 1.9e-6] {
            let want = (c / a).acos() / std::f64::consts::PI;
            let got = material_ratio(z.iter().copied(), c);
            assert!(
                (got - want).abs() < 4.0 / n as f64,
                "c {c}: {got} vs {want}"
            );
        }
        let curve = bearing_area_curve(z.iter().copied(), 11).unwrap();
        assert_eq!(curve.len(), 11);
        for &(p, c) in &curve[1..10] {
            // The inverse: c(p) = A cos(π p).
            let want = a * (std::f64::consts::PI * p).cos();
            assert!((c - want).abs() < 1e-3 * a * 8.0, "p {p}: {c} vs {want}");
        }
        assert_eq!(curve[0].1, z.iter().copied().fold(f64::MIN, f64::max));
        assert!(bearing_area_curve([f64::NAN], 5).is_err());
    }
}
