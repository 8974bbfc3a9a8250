//! [`ElasticOperator`]: the surface displacement `u = K * p` of an elastic half-space under a
//! pixel-wise uniform pressure `p`, computed by real FFTs.
//!
//! **Free boundaries** (the paper's choice, *Methods*): the `rows × cols` grid is embedded in
//! a zero-padded `2·rows × 2·cols` grid and convolved cyclically with Love's pixel
//! coefficients ([`love_pixel_displacement`]) sampled at offsets `−rows+1 … rows−1`; the
//! padding keeps every periodic image out of the result, which equals the direct
//! summation `u_i = Σ_j K(x_i − x_j) p_j` to rounding (Hockney 1970; Liu, Wang & Liu,
//! Wear 243, 2000).
//!
//! **Periodic boundaries**: the grid is one period; the kernel is the half-space Green's
//! function in Fourier space, `û(q) = 2 p̂(q) / (E* |q|)` (Stanley & Kato 1997), with the
//! mean (`q = 0`) mode of `u` set to zero: a periodic surface under a mean pressure sinks
//! without bound, so displacements are measured from their mean.
//!
//! Both kernels are even in x and in y, so their spectra are **real and even**: only the
//! `(cols_padded/2 + 1) × (rows_padded/2 + 1)` unique values are stored, as `f64`, with the
//! `1/(rows·cols)` normalisation folded in. One `apply` runs
//! * `rows` real row transforms of length `cols_padded` (rows of zero padding are skipped),
//! * one fused pass per kept column: forward FFT, multiplication by the kernel, inverse FFT,
//! * `rows` inverse real row transforms (only the rows that are returned).
//!
//! Plans, the kernel spectrum and all buffers are made in [`ElasticOperator::new`];
//! [`ElasticOperator::apply`] allocates nothing, and its result does not depend on the
//! number of threads (every row and column transform is independent).

use std::f64::consts::PI;
use std::sync::Arc;

use num_complex::Complex64;
use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};

use super::love::love_pixel_displacement;
use crate::fft::transpose;
use crate::{memory, Error, Result};

/// Boundary conditions of the half-space grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Boundary {
    /// Isolated grid: zero padding to `2N × 2M`, no periodic images (the paper's choice).
    Free,
    /// The grid is one period of an infinite periodic surface.
    Periodic,
}

impl Boundary {
    /// `"free"` or `"periodic"`.
    pub fn name(&self) -> &'static str {
        match self {
            Boundary::Free => "free",
            Boundary::Periodic => "periodic",
        }
    }

    /// Padding factor per direction: 2 for free boundaries, 1 for periodic.
    fn padding(&self) -> usize {
        match self {
            Boundary::Free => 2,
            Boundary::Periodic => 1,
        }
    }
}

impl std::str::FromStr for Boundary {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "free" => Ok(Boundary::Free),
            "periodic" => Ok(Boundary::Periodic),
            other => Err(Error::invalid(
                "boundary",
                format!("expected free or periodic, got {other:?}"),
            )),
        }
    }
}

struct Lane {
    real: Vec<f64>,
    scratch: Vec<Complex64>,
}

/// The half-space convolution operator of one grid (see the module docs).
pub struct ElasticOperator {
    rows: usize,
    cols: usize,
    padded_rows: usize,
    padded_cols: usize,
    spacing: f64,
    modulus: f64,
    boundary: Boundary,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    column_forward: Arc<dyn Fft<f64>>,
    column_inverse: Arc<dyn Fft<f64>>,
    /// Unique values of the real, even kernel spectrum, `half_cols × kernel_rows`,
    /// normalised by `1/(padded_rows · padded_cols)`.
    kernel: Vec<f64>,
    /// Transposed half spectrum, `half_cols × padded_rows`.
    spectrum: Vec<Complex64>,
    /// Row-pass results of the `rows` data rows, `rows × half_cols`.
    work: Vec<Complex64>,
    lanes: Vec<Lane>,
}

impl ElasticOperator {
    /// Estimated peak memory of an operator for a `rows × cols` grid, in bytes (`None` on
    /// overflow): spectrum, row-pass buffer and kernel.
    pub fn memory_bytes(rows: usize, cols: usize, boundary: Boundary) -> Option<u64> {
        let pad = boundary.padding();
        let padded_rows = rows.checked_mul(pad)?;
        let half_cols = cols.checked_mul(pad)? / 2 + 1;
        let spectrum = memory::array_bytes(&[half_cols, padded_rows], 16)?;
        let work = memory::array_bytes(&[rows, half_cols], 16)?;
        let kernel = memory::array_bytes(&[half_cols, padded_rows / 2 + 1], 8)?;
        spectrum.checked_add(work)?.checked_add(kernel)
    }

    /// Plans the operator of a `rows × cols` grid of square pixels of side `spacing` on a
    /// half-space of effective modulus `modulus` (E*).
    pub fn new(
        rows: usize,
        cols: usize,
        spacing: f64,
        modulus: f64,
        boundary: Boundary,
    ) -> Result<Self> {
        if rows < 1 || cols < 1 {
            return Err(Error::invalid(
                "grid",
                format!("need at least 1x1 points, got {rows}x{cols}"),
            ));
        }
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(Error::invalid(
                "spacing",
                format!("must be positive and finite, got {spacing}"),
            ));
        }
        if !(modulus.is_finite() && modulus > 0.0) {
            return Err(Error::invalid(
                "modulus",
                format!("must be positive and finite, got {modulus}"),
            ));
        }
        memory::ensure_fits(
            &format!(
                "the {} elastic operator of a {rows}x{cols} grid",
                boundary.name()
            ),
            Self::memory_bytes(rows, cols, boundary),
        )?;
        let pad = boundary.padding();
        let (padded_rows, padded_cols) = (rows * pad, cols * pad);
        let half_cols = padded_cols / 2 + 1;
        let mut real_planner = RealFftPlanner::<f64>::new();
        let r2c = real_planner.plan_fft_forward(padded_cols);
        let c2r = real_planner.plan_fft_inverse(padded_cols);
        let mut planner = FftPlanner::<f64>::new();
        let column_forward = planner.plan_fft_forward(padded_rows);
        let column_inverse = planner.plan_fft_inverse(padded_rows);
        let scratch_len = [
            r2c.get_scratch_len(),
            c2r.get_scratch_len(),
            column_forward.get_inplace_scratch_len(),
            column_inverse.get_inplace_scratch_len(),
        ]
        .into_iter()
        .max()
        .unwrap_or(0);
        let lanes = (0..rayon::current_num_threads().max(1))
            .map(|_| Lane {
                real: vec![0.0; padded_cols],
                scratch: vec![Complex64::default(); scratch_len],
            })
            .collect();
        let mut operator = ElasticOperator {
            rows,
            cols,
            padded_rows,
            padded_cols,
            spacing,
            modulus,
            boundary,
            r2c,
            c2r,
            column_forward,
            column_inverse,
            kernel: vec![0.0; half_cols * (padded_rows / 2 + 1)],
            spectrum: vec![Complex64::default(); half_cols * padded_rows],
            work: vec![Complex64::default(); rows * half_cols],
            lanes,
        };
        match boundary {
            Boundary::Free => operator.fill_free_kernel(),
            Boundary::Periodic => operator.fill_periodic_kernel(),
        }
        Ok(operator)
    }

    /// Rows of the grid.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Columns of the grid.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Pixel side Δ.
    pub fn spacing(&self) -> f64 {
        self.spacing
    }

    /// Effective modulus E*.
    pub fn modulus(&self) -> f64 {
        self.modulus
    }

    /// The boundary conditions.
    pub fn boundary(&self) -> Boundary {
        self.boundary
    }

    fn half_cols(&self) -> usize {
        self.padded_cols / 2 + 1
    }

    fn kernel_rows(&self) -> usize {
        self.padded_rows / 2 + 1
    }

    /// Spectrum of Love's coefficients sampled on the padded grid. Built row by row with the
    /// operator's own plans and buffers: each padded row's real transform is real (the row
    /// is even), the columns are then transformed in place.
    fn fill_free_kernel(&mut self) {
        let (prow, pcol, half) = (self.padded_rows, self.padded_cols, self.half_cols());
        let (dx, e) = (self.spacing, self.modulus);
        let kernel_rows = self.kernel_rows();
        let offset = |m: usize, n: usize| {
            if m <= n / 2 {
                m as f64
            } else {
                m as f64 - n as f64
            }
        };
        let lane = &mut self.lanes[0];
        let mut row_out = vec![Complex64::default(); half];
        for r in 0..prow {
            let y = offset(r, prow) * dx;
            for (c, value) in lane.real.iter_mut().enumerate() {
                *value = love_pixel_displacement(offset(c, pcol) * dx, y, dx, dx, e);
            }
            self.r2c
                .process_with_scratch(&mut lane.real, &mut row_out, &mut lane.scratch)
                .expect("buffer sizes are fixed at planning");
            for (kx, v) in row_out.iter().enumerate() {
                self.spectrum[kx * prow + r] = *v;
            }
        }
        let scale = 1.0 / (prow * pcol) as f64;
        for (kx, column) in self.spectrum.chunks_exact_mut(prow).enumerate() {
            self.column_forward
                .process_with_scratch(column, &mut lane.scratch);
            let kernel_column = &mut self.kernel[kx * kernel_rows..(kx + 1) * kernel_rows];
            for (k, value) in kernel_column.iter_mut().zip(column.iter()) {
                *k = value.re * scale;
            }
        }
    }

    /// `2 / (E* |q|) / (rows · cols)`, zero at `q = 0`.
    fn fill_periodic_kernel(&mut self) {
        let (prow, pcol, half) = (self.padded_rows, self.padded_cols, self.half_cols());
        let kernel_rows = self.kernel_rows();
        let scale = 1.0 / (prow * pcol) as f64;
        let qx_unit = 2.0 * PI / (pcol as f64 * self.spacing);
        let qy_unit = 2.0 * PI / (prow as f64 * self.spacing);
        for kx in 0..half {
            for ky in 0..kernel_rows {
                let q = (kx as f64 * qx_unit).hypot(ky as f64 * qy_unit);
                self.kernel[kx * kernel_rows + ky] = if kx == 0 && ky == 0 {
                    0.0
                } else {
                    2.0 / (self.modulus * q) * scale
                };
            }
        }
    }

    /// The kernel's spectrum value at `(kx, ky)` of the padded grid (normalised), for tests
    /// and preconditioners.
    pub fn kernel_spectrum(&self, kx: usize, ky: usize) -> f64 {
        let ky = ky.min(self.padded_rows - ky);
        self.kernel[kx * self.kernel_rows() + ky]
    }

    fn rows_per_lane(&self, total: usize) -> usize {
        total.div_ceil(self.lanes.len()).max(1)
    }

    /// `displacement = K * pressure` on the `rows × cols` grid (row-major slices).
    pub fn apply(&mut self, pressure: &[f64], displacement: &mut [f64]) {
        self.convolve(pressure, displacement, false);
    }

    /// Periodic boundaries only: the pressure whose displacement is `displacement` up to a
    /// constant, `p = K⁺ u` (pseudo-inverse: the mean of `u` is ignored and `p` has zero
    /// mean). Free boundaries have no such spectral inverse: an error.
    pub fn apply_pseudo_inverse(
        &mut self,
        displacement: &[f64],
        pressure: &mut [f64],
    ) -> Result<()> {
        if self.boundary != Boundary::Periodic {
            return Err(Error::invalid(
                "boundary",
                "the spectral pseudo-inverse exists for periodic boundaries only",
            ));
        }
        self.convolve(displacement, pressure, true);
        Ok(())
    }

    fn convolve(&mut self, pressure: &[f64], displacement: &mut [f64], inverse: bool) {
        let (rows, cols) = (self.rows, self.cols);
        let (prow, pcol, half) = (self.padded_rows, self.padded_cols, self.half_cols());
        let kernel_rows = self.kernel_rows();
        let normalisation = (prow * pcol) as f64;
        assert_eq!(pressure.len(), rows * cols, "pressure length");
        assert_eq!(displacement.len(), rows * cols, "displacement length");

        // 1. Real transforms of the data rows (the padding rows are zero: skipped).
        let chunk = self.rows_per_lane(rows);
        let r2c = &self.r2c;
        pressure
            .par_chunks(chunk * cols)
            .zip(self.work.par_chunks_mut(chunk * half))
            .zip(self.lanes.par_iter_mut())
            .for_each(|((input, output), lane)| {
                for (row_in, row_out) in input.chunks_exact(cols).zip(output.chunks_exact_mut(half))
                {
                    lane.real[..cols].copy_from_slice(row_in);
                    lane.real[cols..].fill(0.0);
                    r2c.process_with_scratch(&mut lane.real, row_out, &mut lane.scratch)
                        .expect("buffer sizes are fixed at planning");
                }
            });

        // 2. Into the transposed spectrum, padding rows zero.
        transpose_into_columns(&self.work, &mut self.spectrum, rows, half, prow);

        // 3. Per column: forward FFT, multiply by the real kernel, inverse FFT.
        let chunk = self.rows_per_lane(half);
        let (forward, backward, kernel) =
            (&self.column_forward, &self.column_inverse, &self.kernel);
        self.spectrum
            .par_chunks_mut(chunk * prow)
            .enumerate()
            .zip(self.lanes.par_iter_mut())
            .for_each(|((block_index, block), lane)| {
                for (i, column) in block.chunks_exact_mut(prow).enumerate() {
                    let kx = block_index * chunk + i;
                    let k = &kernel[kx * kernel_rows..(kx + 1) * kernel_rows];
                    forward.process_with_scratch(column, &mut lane.scratch);
                    let factor = |k: f64| {
                        if !inverse {
                            k
                        } else if k != 0.0 {
                            1.0 / (k * normalisation * normalisation)
                        } else {
                            0.0
                        }
                    };
                    column[0] *= factor(k[0]);
                    for ky in 1..kernel_rows {
                        let f = factor(k[ky]);
                        column[ky] *= f;
                        if ky < prow - ky {
                            column[prow - ky] *= f;
                        }
                    }
                    backward.process_with_scratch(column, &mut lane.scratch);
                }
            });

        // 4. Back to rows, only the `rows` that are returned.
        transpose_from_columns(&self.spectrum, &mut self.work, rows, half, prow);

        // 5. Inverse real transforms of the returned rows.
        let chunk = self.rows_per_lane(rows);
        let c2r = &self.c2r;
        self.work
            .par_chunks_mut(chunk * half)
            .zip(displacement.par_chunks_mut(chunk * cols))
            .zip(self.lanes.par_iter_mut())
            .for_each(|((input, output), lane)| {
                for (row_in, row_out) in input
                    .chunks_exact_mut(half)
                    .zip(output.chunks_exact_mut(cols))
                {
                    row_in[0].im = 0.0;
                    if pcol % 2 == 0 {
                        row_in[half - 1].im = 0.0;
                    }
                    c2r.process_with_scratch(row_in, &mut lane.real, &mut lane.scratch)
                        .expect("buffer sizes are fixed at planning");
                    row_out.copy_from_slice(&lane.real[..cols]);
                }
            });
    }
}

/// `work` (`rows × half`, row-major) into `spectrum` (`half × padded_rows`): column `kx`
/// gets the `rows` values followed by zeros.
fn transpose_into_columns(
    work: &[Complex64],
    spectrum: &mut [Complex64],
    rows: usize,
    half: usize,
    padded_rows: usize,
) {
    if rows == padded_rows {
        transpose(work, spectrum, rows, half);
        return;
    }
    const BLOCK: usize = 16;
    spectrum
        .par_chunks_mut(BLOCK * padded_rows)
        .enumerate()
        .for_each(|(block_index, out_block)| {
            let kx0 = block_index * BLOCK;
            let block_cols = out_block.len() / padded_rows;
            for r0 in (0..rows).step_by(BLOCK) {
                let r1 = (r0 + BLOCK).min(rows);
                for dk in 0..block_cols {
                    let column = &mut out_block[dk * padded_rows..(dk + 1) * padded_rows];
                    for r in r0..r1 {
                        column[r] = work[r * half + kx0 + dk];
                    }
                }
            }
            for dk in 0..block_cols {
                out_block[dk * padded_rows + rows..(dk + 1) * padded_rows]
                    .fill(Complex64::default());
            }
        });
}

/// The first `rows` values of every column of `spectrum` back into `work` (`rows × half`).
fn transpose_from_columns(
    spectrum: &[Complex64],
    work: &mut [Complex64],
    rows: usize,
    half: usize,
    padded_rows: usize,
) {
    if rows == padded_rows {
        transpose(spectrum, work, half, rows);
        return;
    }
    const BLOCK: usize = 16;
    work.par_chunks_mut(BLOCK * half)
        .enumerate()
        .for_each(|(block_index, out_block)| {
            let r0 = block_index * BLOCK;
            let block_rows = out_block.len() / half;
            for k0 in (0..half).step_by(BLOCK) {
                let k1 = (k0 + BLOCK).min(half);
                for dr in 0..block_rows {
                    let row = &mut out_block[dr * half..(dr + 1) * half];
                    for kx in k0..k1 {
                        row[kx] = spectrum[kx * padded_rows + r0 + dr];
                    }
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pseudo_random(n: usize, seed: usize) -> Vec<f64> {
        (0..n)
            .map(|i| (((i + seed) * 7919 + 13) % 101) as f64 / 101.0)
            .collect()
    }

    /// Direct O(N²M²) summation with Love's coefficients: the free-boundary oracle.
    fn direct_free(p: &[f64], rows: usize, cols: usize, dx: f64, e: f64) -> Vec<f64> {
        let mut u = vec![0.0; rows * cols];
        for i in 0..rows {
            for j in 0..cols {
                let mut sum = 0.0;
                for k in 0..rows {
                    for l in 0..cols {
                        let x = (j as f64 - l as f64) * dx;
                        let y = (i as f64 - k as f64) * dx;
                        sum += love_pixel_displacement(x, y, dx, dx, e) * p[k * cols + l];
                    }
                }
                u[i * cols + j] = sum;
            }
        }
        u
    }

    /// Direct periodic oracle: kernel by a naive inverse DFT of 2/(E*|q|), then a cyclic
    /// direct sum.
    fn direct_periodic(p: &[f64], rows: usize, cols: usize, dx: f64, e: f64) -> Vec<f64> {
        let mut kernel = vec![0.0; rows * cols];
        for (idx, value) in kernel.iter_mut().enumerate() {
            let (y, x) = (idx / cols, idx % cols);
            let mut sum = 0.0;
            for ky in 0..rows {
                for kx in 0..cols {
                    let sx = if kx <= cols / 2 {
                        kx as f64
                    } else {
                        kx as f64 - cols as f64
                    };
                    let sy = if ky <= rows / 2 {
                        ky as f64
                    } else {
                        ky as f64 - rows as f64
                    };
                    let q = (2.0 * PI * sx / (cols as f64 * dx))
                        .hypot(2.0 * PI * sy / (rows as f64 * dx));
                    if q > 0.0 {
                        let phase = 2.0
                            * PI
                            * (kx as f64 * x as f64 / cols as f64
                                + ky as f64 * y as f64 / rows as f64);
                        sum += 2.0 / (e * q) * phase.cos();
                    }
                }
            }
            *value = sum / (rows * cols) as f64;
        }
        let mut u = vec![0.0; rows * cols];
        for i in 0..rows {
            for j in 0..cols {
                let mut sum = 0.0;
                for k in 0..rows {
                    for l in 0..cols {
                        let y = (i + rows - k) % rows;
                        let x = (j + cols - l) % cols;
                        sum += kernel[y * cols + x] * p[k * cols + l];
                    }
                }
                u[i * cols + j] = sum;
            }
        }
        u
    }

    fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            assert!((x - y).abs() <= tol * scale, "{what} [{i}]: {x} vs {y}");
        }
    }

    #[test]
    fn free_operator_matches_direct_summation_on_odd_even_and_rectangular_grids() {
        for (rows, cols) in [(8, 8), (7, 7), (6, 9), (9, 4), (1, 5), (12, 5)] {
            let (dx, e) = (0.3, 2.0);
            let mut op = ElasticOperator::new(rows, cols, dx, e, Boundary::Free).unwrap();
            let p = pseudo_random(rows * cols, rows + cols);
            let mut u = vec![f64::NAN; rows * cols];
            // Twice, with dirty buffers in between: apply must not depend on leftovers.
            for _ in 0..2 {
                op.apply(&p, &mut u);
                assert_close(&u, &direct_free(&p, rows, cols, dx, e), 1e-13, "free");
            }
        }
    }

    #[test]
    fn periodic_operator_matches_direct_summation_on_odd_even_and_rectangular_grids() {
        for (rows, cols) in [(8, 8), (7, 7), (6, 9), (9, 4), (5, 12)] {
            let (dx, e) = (0.5, 1.3);
            let mut op = ElasticOperator::new(rows, cols, dx, e, Boundary::Periodic).unwrap();
            let p = pseudo_random(rows * cols, 3 * rows + cols);
            let mut u = vec![f64::NAN; rows * cols];
            for _ in 0..2 {
                op.apply(&p, &mut u);
                assert_close(
                    &u,
                    &direct_periodic(&p, rows, cols, dx, e),
                    1e-12,
                    "periodic",
                );
            }
        }
    }

    #[test]
    fn free_kernel_spectrum_is_real_and_even() {
        // Built from the real part only; check that the imaginary parts it dropped vanish
        // by transforming the sampled kernel with the general 2D real FFT.
        let (rows, cols, dx) = (5, 6, 1.0);
        let op = ElasticOperator::new(rows, cols, dx, 1.0, Boundary::Free).unwrap();
        let (prow, pcol) = (2 * rows, 2 * cols);
        let offset = |m: usize, n: usize| {
            if m <= n / 2 {
                m as f64
            } else {
                m as f64 - n as f64
            }
        };
        let mut samples = vec![0.0; prow * pcol];
        for r in 0..prow {
            for c in 0..pcol {
                samples[r * pcol + c] =
                    love_pixel_displacement(offset(c, pcol), offset(r, prow), dx, dx, 1.0);
            }
        }
        let mut fft = crate::fft::RealFft2::new(prow, pcol).unwrap();
        let mut spectrum = vec![Complex64::default(); fft.spectrum_len()];
        fft.forward(&samples, &mut spectrum);
        let scale = 1.0 / (prow * pcol) as f64;
        for kx in 0..pcol / 2 + 1 {
            for ky in 0..prow {
                let v = spectrum[kx * prow + ky] * scale;
                assert!(v.im.abs() < 1e-15, "imaginary part {v}");
                assert!((v.re - op.kernel_spectrum(kx, ky)).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn free_point_load_decays_as_one_over_pi_e_r() {
        // One loaded pixel in a corner of a 64² grid; far pixels see u = F/(π E* r) with
        // F = pΔ², up to the pixel's quadrupole correction Δ²/(24 r²).
        let (n, dx, e) = (64, 0.1, 3.0);
        let mut op = ElasticOperator::new(n, n, dx, e, Boundary::Free).unwrap();
        let mut p = vec![0.0; n * n];
        p[0] = 2.0;
        let mut u = vec![0.0; n * n];
        op.apply(&p, &mut u);
        let force = 2.0 * dx * dx;
        for &(i, j) in &[(0, 20), (30, 40), (63, 63), (50, 0)] {
            let r = ((i * i + j * j) as f64).sqrt() * dx;
            let expected = force / (PI * e * r);
            let rel = u[i * n + j] / expected - 1.0;
            let bound = 1.1 / 24.0 * (dx / r).powi(2);
            assert!(rel.abs() <= bound, "({i},{j}): rel {rel:e} > {bound:e}");
        }
        // Self-influence through the operator.
        let expected = 2.0 * 4.0 * (1.0 + 2f64.sqrt()).ln() / PI * dx / e;
        assert!((u[0] / expected - 1.0).abs() < 1e-13);
    }

    #[test]
    fn periodic_operator_reproduces_a_sinusoid_exactly() {
        // p = cos(q x) gives u = 2 cos(q x) / (E* q) on the grid points.
        let (rows, cols, dx, e) = (6, 16, 0.25, 2.0);
        let mut op = ElasticOperator::new(rows, cols, dx, e, Boundary::Periodic).unwrap();
        let q = 2.0 * PI * 3.0 / (cols as f64 * dx);
        let p: Vec<f64> = (0..rows * cols)
            .map(|i| (q * (i % cols) as f64 * dx).cos())
            .collect();
        let mut u = vec![0.0; rows * cols];
        op.apply(&p, &mut u);
        for (ui, pi) in u.iter().zip(&p) {
            assert!((ui - 2.0 * pi / (e * q)).abs() < 1e-13);
        }
    }

    #[test]
    fn periodic_pseudo_inverse_undoes_the_operator_up_to_the_mean() {
        let (rows, cols) = (9, 12);
        let mut op = ElasticOperator::new(rows, cols, 0.2, 1.5, Boundary::Periodic).unwrap();
        let p = pseudo_random(rows * cols, 1);
        let mean = p.iter().sum::<f64>() / p.len() as f64;
        let mut u = vec![0.0; rows * cols];
        let mut back = vec![0.0; rows * cols];
        op.apply(&p, &mut u);
        op.apply_pseudo_inverse(&u, &mut back).unwrap();
        for (b, p) in back.iter().zip(&p) {
            assert!((b - (p - mean)).abs() < 1e-13);
        }
        let mut free = ElasticOperator::new(rows, cols, 0.2, 1.5, Boundary::Free).unwrap();
        assert!(free.apply_pseudo_inverse(&u, &mut back).is_err());
    }

    #[test]
    fn results_do_not_depend_on_the_thread_count() {
        let (rows, cols) = (33, 20);
        let p = pseudo_random(rows * cols, 5);
        let run = |threads: usize, boundary: Boundary| {
            crate::test_support::with_threads(threads, || {
                let mut op = ElasticOperator::new(rows, cols, 0.1, 1.0, boundary).unwrap();
                let mut u = vec![0.0; rows * cols];
                op.apply(&p, &mut u);
                u
            })
        };
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let one = run(1, boundary);
            for threads in [2, 3, 7] {
                assert_eq!(one, run(threads, boundary), "{threads} threads");
            }
        }
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(ElasticOperator::new(0, 4, 1.0, 1.0, Boundary::Free).is_err());
        assert!(ElasticOperator::new(4, 4, -1.0, 1.0, Boundary::Free).is_err());
        assert!(ElasticOperator::new(4, 4, 1.0, f64::NAN, Boundary::Free).is_err());
        let err = ElasticOperator::new(1 << 20, 1 << 20, 1.0, 1.0, Boundary::Free)
            .err()
            .unwrap();
        assert!(matches!(err, Error::OutOfMemory { .. }), "{err}");
    }
}
