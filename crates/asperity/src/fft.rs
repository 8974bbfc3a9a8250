//! Two-dimensional real FFTs, planned once and run many times without allocating.
//!
//! [`RealFft2`] transforms a real `rows × cols` grid (row-major) to its half spectrum and
//! back. The spectrum is kept **transposed**: `cols/2 + 1` rows (one per `kx`), each of
//! length `rows` (all `ky`), which makes both passes contiguous. Rows are transformed in
//! parallel with rayon; each worker lane owns a scratch buffer allocated at planning time,
//! so [`RealFft2::forward`] and [`RealFft2::inverse`] allocate nothing. Results do not depend
//! on the number of threads (each row is one independent transform).
//!
//! Neither direction is normalised: `inverse(forward(x)) = rows·cols·x`.

use std::sync::Arc;

use num_complex::Complex64;
use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};

use crate::memory::try_vec;
use crate::{Error, Result};

struct Lane {
    real: Vec<f64>,
    scratch: Vec<Complex64>,
}

/// A planned 2D real-to-complex FFT of a `rows × cols` grid (see the module docs).
pub struct RealFft2 {
    rows: usize,
    cols: usize,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    col_forward: Arc<dyn Fft<f64>>,
    col_inverse: Arc<dyn Fft<f64>>,
    /// Row-major half spectrum `rows × (cols/2+1)` between the two passes.
    work: Vec<Complex64>,
    lanes: Vec<Lane>,
}

impl RealFft2 {
    /// Plans transforms for a `rows × cols` real grid (both at least 1). The work buffers
    /// are allocated fallibly: [`Error::OutOfMemory`] if the system refuses them.
    pub fn new(rows: usize, cols: usize) -> Result<Self> {
        if rows < 1 || cols < 1 {
            return Err(Error::invalid(
                "grid",
                format!("an FFT grid needs at least 1x1 points, got {rows}x{cols}"),
            ));
        }
        let half = cols / 2 + 1;
        let work_len = rows.checked_mul(half).ok_or_else(|| Error::OutOfMemory {
            what: format!("the FFT buffer of a {rows}x{cols} grid"),
            needed_mib: None,
            available_mib: None,
            limited_by: "the address space".into(),
        })?;
        let work = try_vec(
            &format!("the FFT buffer of a {rows}x{cols} grid"),
            work_len,
            Complex64::default(),
        )?;
        let mut real_planner = RealFftPlanner::<f64>::new();
        let r2c = real_planner.plan_fft_forward(cols);
        let c2r = real_planner.plan_fft_inverse(cols);
        let mut planner = FftPlanner::<f64>::new();
        let col_forward = planner.plan_fft_forward(rows);
        let col_inverse = planner.plan_fft_inverse(rows);
        let scratch_len = [
            r2c.get_scratch_len(),
            c2r.get_scratch_len(),
            col_forward.get_inplace_scratch_len(),
            col_inverse.get_inplace_scratch_len(),
        ]
        .into_iter()
        .max()
        .unwrap_or(0);
        let lanes = (0..rayon::current_num_threads().max(1))
            .map(|_| {
                Ok(Lane {
                    real: try_vec("an FFT row buffer", cols, 0.0)?,
                    scratch: try_vec("an FFT scratch buffer", scratch_len, Complex64::default())?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(RealFft2 {
            rows,
            cols,
            r2c,
            c2r,
            col_forward,
            col_inverse,
            work,
            lanes,
        })
    }

    /// Number of rows of the real grid.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns of the real grid.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Number of `kx` values kept, `cols/2 + 1` (rows of the transposed spectrum).
    pub fn half_cols(&self) -> usize {
        self.cols / 2 + 1
    }

    /// Length of a spectrum buffer: `(cols/2 + 1) · rows`.
    pub fn spectrum_len(&self) -> usize {
        self.half_cols() * self.rows
    }

    fn rows_per_lane(&self, total_rows: usize) -> usize {
        total_rows.div_ceil(self.lanes.len()).max(1)
    }

    /// Forward transform of `input` (`rows × cols`, row-major) into `spectrum`
    /// (transposed half spectrum, `(cols/2+1) × rows`).
    pub fn forward(&mut self, input: &[f64], spectrum: &mut [Complex64]) {
        let (rows, cols, half) = (self.rows, self.cols, self.half_cols());
        assert_eq!(input.len(), rows * cols, "input length");
        assert_eq!(spectrum.len(), half * rows, "spectrum length");
        let chunk = self.rows_per_lane(rows);
        let r2c = &self.r2c;
        input
            .par_chunks(chunk * cols)
            .zip(self.work.par_chunks_mut(chunk * half))
            .zip(self.lanes.par_iter_mut())
            .for_each(|((inp, out), lane)| {
                for (row_in, row_out) in inp.chunks_exact(cols).zip(out.chunks_exact_mut(half)) {
                    lane.real.copy_from_slice(row_in);
                    r2c.process_with_scratch(&mut lane.real, row_out, &mut lane.scratch)
                        .expect("buffer sizes are fixed at planning");
                }
            });
        transpose(&self.work, spectrum, rows, half);
        let chunk = self.rows_per_lane(half);
        let fft = &self.col_forward;
        spectrum
            .par_chunks_mut(chunk * rows)
            .zip(self.lanes.par_iter_mut())
            .for_each(|(block, lane)| fft.process_with_scratch(block, &mut lane.scratch));
    }

    /// Inverse transform of a transposed half `spectrum` (overwritten) into `output`
    /// (`rows × cols`). The imaginary parts that a real signal cannot have (at `kx = 0` and,
    /// for even `cols`, `kx = cols/2`) are dropped.
    pub fn inverse(&mut self, spectrum: &mut [Complex64], output: &mut [f64]) {
        let (rows, cols, half) = (self.rows, self.cols, self.half_cols());
        assert_eq!(output.len(), rows * cols, "output length");
        assert_eq!(spectrum.len(), half * rows, "spectrum length");
        let chunk = self.rows_per_lane(half);
        let fft = &self.col_inverse;
        spectrum
            .par_chunks_mut(chunk * rows)
            .zip(self.lanes.par_iter_mut())
            .for_each(|(block, lane)| fft.process_with_scratch(block, &mut lane.scratch));
        transpose(spectrum, &mut self.work, half, rows);
        let chunk = self.rows_per_lane(rows);
        let c2r = &self.c2r;
        self.work
            .par_chunks_mut(chunk * half)
            .zip(output.par_chunks_mut(chunk * cols))
            .zip(self.lanes.par_iter_mut())
            .for_each(|((inp, out), lane)| {
                for (row_in, row_out) in inp.chunks_exact_mut(half).zip(out.chunks_exact_mut(cols))
                {
                    row_in[0].im = 0.0;
                    if cols % 2 == 0 {
                        row_in[half - 1].im = 0.0;
                    }
                    c2r.process_with_scratch(row_in, row_out, &mut lane.scratch)
                        .expect("buffer sizes are fixed at planning");
                }
            });
    }
}

/// Blocked parallel transpose of a row-major `rows × cols` matrix into `cols × rows`.
pub fn transpose<T: Copy + Send + Sync>(input: &[T], output: &mut [T], rows: usize, cols: usize) {
    const BLOCK: usize = 32;
    assert_eq!(input.len(), rows * cols);
    assert_eq!(output.len(), rows * cols);
    output
        .par_chunks_mut(BLOCK * rows)
        .enumerate()
        .for_each(|(block_index, out_block)| {
            let c0 = block_index * BLOCK;
            let block_cols = out_block.len() / rows;
            for r0 in (0..rows).step_by(BLOCK) {
                let r1 = (r0 + BLOCK).min(rows);
                for dc in 0..block_cols {
                    let out_row = &mut out_block[dc * rows..(dc + 1) * rows];
                    for r in r0..r1 {
                        out_row[r] = input[r * cols + c0 + dc];
                    }
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Naive O(N²M²) DFT oracle of a real grid, in the transposed half layout.
    fn naive_forward(input: &[f64], rows: usize, cols: usize) -> Vec<Complex64> {
        let half = cols / 2 + 1;
        let mut out = vec![Complex64::default(); half * rows];
        for kx in 0..half {
            for ky in 0..rows {
                let mut sum = Complex64::default();
                for r in 0..rows {
                    for c in 0..cols {
                        let phase = -2.0
                            * PI
                            * ((kx * c) as f64 / cols as f64 + (ky * r) as f64 / rows as f64);
                        sum += input[r * cols + c] * Complex64::from_polar(1.0, phase);
                    }
                }
                out[kx * rows + ky] = sum;
            }
        }
        out
    }

    fn pseudo_random(n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| ((i * 7919 + 13) % 101) as f64 / 101.0 - 0.5)
            .collect()
    }

    #[test]
    fn forward_matches_naive_dft_on_odd_even_and_rectangular_grids() {
        for (rows, cols) in [(4, 4), (5, 7), (6, 9), (7, 4), (1, 8), (3, 1)] {
            let input = pseudo_random(rows * cols);
            let mut fft = RealFft2::new(rows, cols).unwrap();
            let mut spec = vec![Complex64::new(9.0, 9.0); fft.spectrum_len()];
            fft.forward(&input, &mut spec);
            let oracle = naive_forward(&input, rows, cols);
            for (a, b) in spec.iter().zip(&oracle) {
                assert!((a - b).norm() < 1e-12, "{rows}x{cols}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn inverse_undoes_forward_with_dirty_buffers() {
        for (rows, cols) in [(8, 8), (9, 15), (16, 10)] {
            let input = pseudo_random(rows * cols);
            let mut fft = RealFft2::new(rows, cols).unwrap();
            let mut spec = vec![Complex64::new(1.0, -3.0); fft.spectrum_len()];
            let mut back = vec![7.0; rows * cols];
            for _ in 0..2 {
                fft.forward(&input, &mut spec);
                fft.inverse(&mut spec, &mut back);
                let scale = (rows * cols) as f64;
                for (a, b) in back.iter().zip(&input) {
                    assert!((a / scale - b).abs() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn transpose_is_exact() {
        let (rows, cols) = (37, 70);
        let input: Vec<usize> = (0..rows * cols).collect();
        let mut out = vec![0; rows * cols];
        transpose(&input, &mut out, rows, cols);
        for r in 0..rows {
            for c in 0..cols {
                assert_eq!(out[c * rows + r], input[r * cols + c]);
            }
        }
    }
}
