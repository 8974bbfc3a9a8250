//! Statistics of surfaces and lines: rms height, slope and curvature; radially averaged PSD.
//!
//! Definitions (stated once, used everywhere, including by the normalisation of generated
//! surfaces, so that a requested rms slope is what `stats` reports):
//! * rms height: `sqrt(mean((h − mean h)²))`.
//! * rms slope: from forward differences, `sqrt(mean((Δh/Δx)²) + mean((Δh/Δy)²))` over all
//!   neighbouring pairs inside the grid (no wrap-around), so it also suits measured,
//!   non-periodic topographies. For a line, `sqrt(mean((Δh/Δx)²))`.
//! * rms curvature: half the rms of the five-point Laplacian over interior points (the rms
//!   mean curvature); for a line, the rms of the three-point second difference.
//! * PSD: the periodogram normalised so that `Σ_q C2D(q) (2π)²/A = rms²` (2D) and
//!   `Σ_q C1D(q) 2π/L = rms²` over both signs of q (1D), averaged radially over rings of
//!   width `2π/L` (2D). Each bin reports the mean `q` of the modes in it.

use ndarray::ArrayView2;
use num_complex::Complex64;
use rayon::prelude::*;
use realfft::RealFftPlanner;
use serde::Serialize;

use super::{Line, Surface};
use crate::fft::RealFft2;
use crate::memory::try_vec;
use crate::Result;

/// Root mean square about the mean.
pub fn rms_height(values: impl Iterator<Item = f64> + Clone) -> f64 {
    let (sum, count) = values
        .clone()
        .fold((0.0, 0usize), |(s, c), v| (s + v, c + 1));
    let mean = sum / count as f64;
    (values.map(|v| (v - mean).powi(2)).sum::<f64>() / count as f64).sqrt()
}

/// Sums `f(row_index)` over rows in parallel, then adds the per-row results in order, so
/// that the total does not depend on how rayon splits the work (bit-identical results
/// whatever the thread count).
fn ordered_row_sum(rows: usize, f: impl Fn(usize) -> f64 + Sync + Send) -> f64 {
    let per_row: Vec<f64> = (0..rows).into_par_iter().map(&f).collect();
    per_row.iter().sum()
}

/// rms height of a row-major grid (parallel, deterministic).
pub fn rms_height_2d(heights: ArrayView2<f64>) -> f64 {
    let (rows, cols) = heights.dim();
    let count = (rows * cols) as f64;
    let row = |r: usize| heights.row(r);
    let mean = ordered_row_sum(rows, |r| row(r).iter().sum()) / count;
    (ordered_row_sum(rows, |r| row(r).iter().map(|h| (h - mean).powi(2)).sum()) / count).sqrt()
}

/// rms slope of a grid with pixel spacing `spacing` (forward differences, no wrap-around).
pub fn rms_slope_2d(heights: ArrayView2<f64>, spacing: f64) -> f64 {
    let (rows, cols) = heights.dim();
    let standard = heights.as_standard_layout();
    let data = standard.as_slice().expect("standard layout");
    let row = |r: usize| &data[r * cols..(r + 1) * cols];
    let sum_x = ordered_row_sum(rows, |r| {
        row(r).windows(2).map(|w| (w[1] - w[0]).powi(2)).sum()
    });
    let sum_y = ordered_row_sum(rows - 1, |r| {
        row(r)
            .iter()
            .zip(row(r + 1))
            .map(|(a, b)| (b - a).powi(2))
            .sum()
    });
    let mean_x = sum_x / (rows * (cols - 1)) as f64;
    let mean_y = sum_y / ((rows - 1) * cols) as f64;
    (mean_x + mean_y).sqrt() / spacing
}

/// rms slope of a line with point spacing `spacing`.
pub fn rms_slope_1d(heights: &[f64], spacing: f64) -> f64 {
    let sum: f64 = heights.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
    (sum / (heights.len() - 1) as f64).sqrt() / spacing
}

/// rms mean curvature (half the rms five-point Laplacian); `None` below 3×3.
pub fn rms_curvature_2d(heights: ArrayView2<f64>, spacing: f64) -> Option<f64> {
    let (rows, cols) = heights.dim();
    if rows < 3 || cols < 3 {
        return None;
    }
    let mut sum = 0.0;
    for r in 1..rows - 1 {
        for c in 1..cols - 1 {
            let lap = heights[[r + 1, c]]
                + heights[[r - 1, c]]
                + heights[[r, c + 1]]
                + heights[[r, c - 1]]
                - 4.0 * heights[[r, c]];
            sum += lap * lap;
        }
    }
    Some(0.5 * (sum / ((rows - 2) * (cols - 2)) as f64).sqrt() / (spacing * spacing))
}

/// rms curvature of a line (three-point second difference); `None` below 3 points.
pub fn rms_curvature_1d(heights: &[f64], spacing: f64) -> Option<f64> {
    if heights.len() < 3 {
        return None;
    }
    let sum: f64 = heights
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).powi(2))
        .sum();
    Some((sum / (heights.len() - 2) as f64).sqrt() / (spacing * spacing))
}

/// One bin of a power spectrum: mean wavenumber `q` (physical units, `2π/length`), the
/// averaged PSD, and how many Fourier modes fell into it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PsdBin {
    /// Mean wavenumber of the modes in the bin.
    pub q: f64,
    /// Averaged power spectral density.
    pub psd: f64,
    /// Number of modes averaged.
    pub modes: usize,
}

/// Radially averaged 2D PSD `C2D(q)` of a surface, rings of width `2π/L` centred on
/// integer `κ = qL/2π` from 1 up to the smaller Nyquist wavenumber. Fails only with
/// [`crate::Error::OutOfMemory`] if its buffers (about 3× the surface) cannot be allocated.
pub fn radial_psd_2d(surface: &Surface) -> Result<Vec<PsdBin>> {
    let (rows, cols) = surface.dim();
    let size = surface.size();
    let area = size * size * rows as f64 / cols as f64;
    // Heights far from 1 are scaled by a power of two (exact) so that |c|² neither
    // overflows nor underflows; the PSD, in height², is scaled back and refused where it
    // leaves the range of f64.
    let scale = unit_scale(max_abs(surface.heights()));
    let mean = surface.heights().mean().unwrap_or(0.0);
    let mut centred = try_vec("the PSD's copy of the surface", rows * cols, 0.0)?;
    for (c, h) in centred.iter_mut().zip(surface.heights()) {
        *c = (h - mean) * scale;
    }
    let mut fft = RealFft2::new(rows, cols)?;
    let mut spectrum = try_vec(
        "the PSD's spectrum",
        fft.spectrum_len(),
        Complex64::default(),
    )?;
    fft.forward(&centred, &mut spectrum);
    let aspect = cols as f64 / rows as f64;
    let kappa_max = ((cols / 2) as f64).min((rows / 2) as f64 * aspect).floor() as usize;
    let norm = area / (std::f64::consts::TAU.powi(2) * ((rows * cols) as f64).powi(2));
    let sums = ring_sums(&spectrum, rows, cols, aspect, kappa_max, norm);
    let bins: Vec<PsdBin> = sums
        .into_iter()
        .skip(1)
        .filter(|s| s.2 > 0)
        .map(|(k, p, m)| PsdBin {
            q: std::f64::consts::TAU / size * k / m as f64,
            psd: p / m as f64,
            modes: m,
        })
        .collect();
    unscaled_psd(bins, scale)
}

/// The PSD bins of heights scaled by `scale` ([`unit_scale`]) brought back to the heights'
/// units (÷ scale²); an error where a value leaves the range of f64 (overflows, or a
/// nonzero value underflows to zero), which no front end should print as `inf` or 0.
fn unscaled_psd(mut bins: Vec<PsdBin>, scale: f64) -> Result<Vec<PsdBin>> {
    if scale == 1.0 {
        return Ok(bins);
    }
    for bin in &mut bins {
        let value = bin.psd / (scale * scale);
        if !value.is_finite() || (value == 0.0 && bin.psd != 0.0) || value.is_subnormal() {
            return Err(crate::Error::invalid(
                "heights",
                format!(
                    "their PSD (height² × length²) is beyond the range of f64 numbers \
                     (heights of order {:.0e}): give the heights in other units",
                    1.0 / scale
                ),
            ));
        }
        bin.psd = value;
    }
    Ok(bins)
}

/// 1D PSD `C1D(q)` of a line at `q = 2πk/L`, `k = 1 … n/2`.
pub fn line_psd(line: &Line) -> Vec<PsdBin> {
    let n = line.len();
    let size = line.size();
    let mean = line.heights().mean().unwrap_or(0.0);
    let mut centred: Vec<f64> = line.heights().iter().map(|h| h - mean).collect();
    let r2c = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut spectrum = r2c.make_output_vec();
    r2c.process(&mut centred, &mut spectrum)
        .expect("sizes from plan");
    let norm = size / (std::f64::consts::TAU * (n as f64).powi(2));
    spectrum
        .iter()
        .enumerate()
        .skip(1)
        .map(|(k, v)| PsdBin {
            q: std::f64::consts::TAU * k as f64 / size,
            psd: v.norm_sqr() * norm,
            modes: 1,
        })
        .collect()
}

/// Summary statistics of a surface or line (see the module docs for definitions).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Summary {
    /// rms height.
    pub rms_height: f64,
    /// rms slope.
    pub rms_slope: f64,
    /// rms curvature (`None` on grids too small for a second difference).
    pub rms_curvature: Option<f64>,
}

/// The power of two that brings heights whose largest magnitude is `max_abs` near 1, or 1
/// where they are within `2^±300` already. The rms sums square (and the PSD squares)
/// heights: beyond about `1e154` a square overflows to infinity, below about `1e-162` it
/// underflows to zero. Scaling by a power of two is exact, so heights in the usual range
/// give the same bits as unscaled and extreme ones their true statistics.
pub(crate) fn unit_scale(max_abs: f64) -> f64 {
    if !(max_abs.is_finite() && max_abs > 0.0) {
        return 1.0;
    }
    let exponent = max_abs.log2().floor() as i32;
    if exponent.abs() <= 300 {
        1.0
    } else {
        // Subnormal heights (below 2^-1022) would ask for a factor beyond 2^1023, which
        // overflows: 2^1000 still brings them near 2^-60, and is exact.
        2f64.powi(-exponent.clamp(-1000, 1000))
    }
}

fn max_abs<'a>(values: impl IntoIterator<Item = &'a f64>) -> f64 {
    values.into_iter().fold(0.0, |m: f64, v| m.max(v.abs()))
}

impl Summary {
    /// Every statistic divided by `scale` (they are all linear in the heights).
    fn unscaled(self, scale: f64) -> Summary {
        Summary {
            rms_height: self.rms_height / scale,
            rms_slope: self.rms_slope / scale,
            rms_curvature: self.rms_curvature.map(|c| c / scale),
        }
    }
}

/// Summary statistics of a surface, for heights of any magnitude (scaled by a power of two
/// when far from 1).
pub fn surface_summary(surface: &Surface) -> Summary {
    let scale = unit_scale(max_abs(surface.heights()));
    let scaled;
    let h = if scale == 1.0 {
        surface.heights().view()
    } else {
        scaled = surface.heights() * scale;
        scaled.view()
    };
    Summary {
        rms_height: rms_height_2d(h),
        rms_slope: rms_slope_2d(h, surface.spacing()),
        rms_curvature: rms_curvature_2d(h, surface.spacing()),
    }
    .unscaled(scale)
}

/// Summary statistics of a line, for heights of any magnitude (scaled by a power of two
/// when far from 1).
pub fn line_summary(line: &Line) -> Summary {
    let scale = unit_scale(max_abs(line.heights()));
    let scaled: Vec<f64>;
    let h = if scale == 1.0 {
        line.heights().as_slice().expect("contiguous")
    } else {
        scaled = line.heights().iter().map(|v| v * scale).collect();
        &scaled
    };
    Summary {
        rms_height: rms_height(h.iter().copied()),
        rms_slope: rms_slope_1d(h, line.spacing()),
        rms_curvature: rms_curvature_1d(h, line.spacing()),
    }
    .unscaled(scale)
}

/// Sums over the rings `round(|(kx, ky·aspect)|) = κ` of a half spectrum in transposed
/// layout (`cols/2+1` columns of `rows`): per ring `(Σ w κ, Σ w |c|² norm, Σ w)`, where
/// `w = 2` for the columns `0 < kx < cols/2` that stand for ±kx; index 0 of the result
/// is unused (the mean is no ring).
///
/// Blocks of [`RING_BLOCK`] columns are summed in parallel and their sums added in block
/// order: the result does not depend on the thread count.
pub(crate) fn ring_sums(
    spectrum: &[num_complex::Complex64],
    rows: usize,
    cols: usize,
    aspect: f64,
    kappa_max: usize,
    norm: f64,
) -> Vec<(f64, f64, usize)> {
    use rayon::prelude::*;
    let width = ring_block_width(rows, cols / 2 + 1, kappa_max);
    let blocks: Vec<Vec<(f64, f64, usize)>> = spectrum
        .par_chunks(rows * width)
        .enumerate()
        .map(|(block, columns)| {
            let mut sums = vec![(0.0f64, 0.0f64, 0usize); kappa_max + 1];
            let first = block * width;
            for (dk, column) in columns.chunks(rows).enumerate() {
                add_column_rings(&mut sums, column, first + dk, cols, aspect, norm);
            }
            sums
        })
        .collect();
    let mut sums = vec![(0.0f64, 0.0f64, 0usize); kappa_max + 1];
    for block in blocks {
        for (total, part) in sums.iter_mut().zip(block) {
            total.0 += part.0;
            total.1 += part.1;
            total.2 += part.2;
        }
    }
    sums
}

/// Columns of the half spectrum per parallel block of [`ring_sums`] (at least).
const RING_BLOCK: usize = 64;

/// The columns per block of [`ring_sums`]: [`RING_BLOCK`], or more where the blocks' ring
/// sums (one array of `kappa_max + 1` per block) would hold more entries than the spectrum
/// has values — a map of a few rows and millions of columns (2 × 4,000,000) made 31,250
/// blocks of 2,000,001 rings each (1.5 TB) before. Depends on the shape only, so the sums
/// stay independent of the thread count; square and most rectangular grids keep
/// [`RING_BLOCK`].
fn ring_block_width(rows: usize, columns: usize, kappa_max: usize) -> usize {
    let max_blocks = (rows * columns / (kappa_max + 1)).max(1);
    RING_BLOCK.max(columns.div_ceil(max_blocks))
}

/// Adds column `kx` (its `rows` values over ky) to the ring sums.
fn add_column_rings(
    sums: &mut [(f64, f64, usize)],
    column: &[num_complex::Complex64],
    kx: usize,
    cols: usize,
    aspect: f64,
    norm: f64,
) {
    let rows = column.len();
    let kappa_max = sums.len() - 1;
    let weight = if kx == 0 || (cols.is_multiple_of(2) && kx == cols / 2) {
        1
    } else {
        2
    };
    let kx2 = (kx * kx) as f64;
    for (index, value) in column.iter().enumerate() {
        let ky = if index <= rows / 2 {
            index as f64
        } else {
            index as f64 - rows as f64
        };
        // Wavenumbers are far from overflow: the plain root is exact enough and much
        // cheaper than `hypot`.
        let kappa = (kx2 + (ky * aspect) * (ky * aspect)).sqrt();
        let bin = kappa.round() as usize;
        if bin == 0 || bin > kappa_max {
            continue;
        }
        let s = &mut sums[bin];
        s.0 += weight as f64 * kappa;
        s.1 += weight as f64 * value.norm_sqr() * norm;
        s.2 += weight;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;
    use std::f64::consts::TAU;

    /// Issue 33 item 14: the ring sums of a map of 2 rows and millions of columns stay
    /// within about the spectrum's size (before: one array of all rings per 64 columns).
    #[test]
    fn ring_blocks_of_a_very_wide_map_stay_within_the_spectrum_size() {
        let (rows, cols) = (2usize, 4_000_000usize);
        let columns = cols / 2 + 1;
        let aspect = cols as f64 / rows as f64;
        let kappa_max = ((cols / 2) as f64).min((rows / 2) as f64 * aspect).floor() as usize;
        let blocks = columns.div_ceil(ring_block_width(rows, columns, kappa_max));
        assert!(
            blocks * (kappa_max + 1) <= 2 * rows * columns,
            "{blocks} blocks"
        );
        // A square grid keeps its blocks (and so its bits).
        assert_eq!(ring_block_width(1024, 513, 512), RING_BLOCK);
        assert_eq!(ring_block_width(4096, 2049, 2048), RING_BLOCK);
        // And the PSD of a wide map is computed (small enough for a test).
        let wide = Surface::new(
            Array2::from_shape_fn((2, 20_000), |(r, c)| ((c * 13 + r) as f64 * 0.01).sin()),
            1.0,
        )
        .unwrap();
        assert!(!radial_psd_2d(&wide).unwrap().is_empty());
    }

    /// Subnormal heights (×2^-1060: only a few bits each) still give finite statistics
    /// within a few per cent of the true ones, not NaN from an overflowing scale factor.
    #[test]
    fn subnormal_heights_give_finite_statistics() {
        let heights = Array2::from_shape_fn((16, 16), |(r, c)| ((r * 5 + c * 3) as f64).sin());
        let reference = surface_summary(&Surface::new(heights.clone(), 1.0).unwrap());
        let factor = 2f64.powi(-1060);
        let got = surface_summary(&Surface::new(&heights * factor, 1.0).unwrap());
        // 2^-1060 leaves about 14 bits of each height: 1e-3 is what they can carry.
        let ratio = got.rms_height / factor / reference.rms_height;
        assert!((ratio - 1.0).abs() < 1e-3, "{got:?}");
        assert!(got.rms_slope.is_finite() && got.rms_slope > 0.0, "{got:?}");
    }

    /// Issue 33 item 5: heights ×1e200 and ×1e-170 have the statistics of the unscaled
    /// heights times the factor (exactly, for a power of two; to rounding otherwise), not
    /// inf or 0; a PSD beyond the range of f64 is refused, one within it is scaled.
    #[test]
    fn statistics_do_not_depend_on_the_heights_units() {
        let heights = Array2::from_shape_fn((32, 48), |(r, c)| {
            ((r * 7 + c * 3) as f64 * 0.37).sin() + 0.1 * (c as f64).cos()
        });
        let plain = Surface::new(heights.clone(), 1.0).unwrap();
        let reference = surface_summary(&plain);
        let line = Line::new(heights.row(3).to_owned(), 1.0).unwrap();
        let line_reference = line_summary(&line);
        for factor in [1e200, 1e-170, 2f64.powi(700), 2f64.powi(-600)] {
            let scaled = Surface::new(&heights * factor, 1.0).unwrap();
            let got = surface_summary(&scaled);
            let close = |a: f64, b: f64| ((a / factor) / b - 1.0).abs() < 1e-14;
            assert!(
                close(got.rms_height, reference.rms_height),
                "{factor:e} {got:?}"
            );
            assert!(
                close(got.rms_slope, reference.rms_slope),
                "{factor:e} {got:?}"
            );
            let curvature = (got.rms_curvature.unwrap(), reference.rms_curvature.unwrap());
            assert!(close(curvature.0, curvature.1), "{factor:e} {got:?}");
            let scaled_line = Line::new(heights.row(3).to_owned() * factor, 1.0).unwrap();
            let got = line_summary(&scaled_line);
            assert!(
                close(got.rms_height, line_reference.rms_height),
                "{factor:e}"
            );
            assert!(close(got.rms_slope, line_reference.rms_slope), "{factor:e}");
        }
        let psd = radial_psd_2d(&plain).unwrap();
        let small = radial_psd_2d(&Surface::new(&heights * 1e-100, 1.0).unwrap()).unwrap();
        for (a, b) in small.iter().zip(&psd) {
            assert!((a.psd / 1e-200 / b.psd - 1.0).abs() < 1e-12, "{a:?} {b:?}");
        }
        for factor in [1e200, 1e-170] {
            let err = radial_psd_2d(&Surface::new(&heights * factor, 1.0).unwrap()).unwrap_err();
            assert!(err.to_string().contains("beyond the range"), "{err}");
        }
    }

    #[test]
    fn sinusoid_statistics_match_closed_forms() {
        // h = a sin(2π x / λ) sampled finely: rms a/√2, rms slope a(2π/λ)/√2,
        // rms curvature (Laplacian/2 in 2D) a(2π/λ)²/(2√2).
        let (n, a, size) = (512, 0.3, 1.0);
        let k = TAU * 4.0 / size;
        let dx = size / n as f64;
        let heights = Array2::from_shape_fn((n, n), |(_, c)| a * (k * c as f64 * dx).sin());
        let s = surface_summary(&Surface::new(heights, size).unwrap());
        assert!((s.rms_height / (a / 2f64.sqrt()) - 1.0).abs() < 1e-12);
        // Finite differences are off by (k dx)²/24 ≈ 1e-4, and dropping the one wrap-around
        // pair of each row (no periodicity assumed) by up to 1/(2n) ≈ 1e-3: allow 2e-3.
        assert!(
            (s.rms_slope / (a * k / 2f64.sqrt()) - 1.0).abs() < 2e-3,
            "{}",
            s.rms_slope
        );
        let curvature = s.rms_curvature.unwrap();
        assert!(
            (curvature / (a * k * k / (2.0 * 2f64.sqrt())) - 1.0).abs() < 4e-3,
            "{curvature}"
        );
    }

    #[test]
    fn psd_satisfies_parseval() {
        let n = 64;
        let heights =
            Array2::from_shape_fn((n, n + 3), |(r, c)| ((r * 31 + c * 17) % 23) as f64 / 23.0);
        let surface = Surface::new(heights, 2.0).unwrap();
        let (rows, cols) = surface.dim();
        // Sum over the full spectrum = rms²: use all modes, not only the radial bins.
        let area = 4.0 * rows as f64 / cols as f64;
        let mean = surface.heights().mean().unwrap();
        let centred: Vec<f64> = surface.heights().iter().map(|h| h - mean).collect();
        let mut fft = RealFft2::new(rows, cols).unwrap();
        let mut spec = vec![Complex64::default(); fft.spectrum_len()];
        fft.forward(&centred, &mut spec);
        let mut total = 0.0;
        for (kx, col) in spec.chunks(rows).enumerate() {
            let w = if kx == 0 || (cols % 2 == 0 && kx == cols / 2) {
                1.0
            } else {
                2.0
            };
            total += w * col.iter().map(|v| v.norm_sqr()).sum::<f64>();
        }
        let c_sum = total * area / (TAU.powi(2) * ((rows * cols) as f64).powi(2));
        let rms = rms_height(surface.heights().iter().copied());
        assert!((c_sum * TAU.powi(2) / area / rms.powi(2) - 1.0).abs() < 1e-12);
        assert!(!radial_psd_2d(&surface).unwrap().is_empty());
    }

    #[test]
    fn line_psd_parseval() {
        let h: Vec<f64> = (0..101).map(|i| ((i * 37) % 11) as f64).collect();
        let line = Line::new(ndarray::Array1::from(h), 3.0).unwrap();
        let bins = line_psd(&line);
        // Both signs of q: every bin but Nyquist (odd n has none) counts twice.
        let sum: f64 = bins.iter().map(|b| 2.0 * b.psd).sum::<f64>() * TAU / 3.0;
        let rms = rms_height(line.heights().iter().copied());
        assert!((sum / rms.powi(2) - 1.0).abs() < 1e-12);
    }
}
