//! [`ElasticOperator`]: the surface displacement `u = K * p` of an elastic half-space under a
//! pixel-wise uniform pressure `p`, computed by real FFTs with [`RealFft2`], the crate's one
//! 2D FFT engine.
//!
//! Pixels are rectangles `Δx × Δy` (columns run along x, rows along y); square pixels are
//! the case `Δx = Δy` ([`ElasticOperator::new`]).
//!
//! **Free boundaries** (the paper's choice, *Methods*): the `rows × cols` grid is embedded in
//! a zero-padded `2·rows × 2·cols` grid and convolved cyclically with Love's pixel
//! coefficients ([`love_pixel_displacement`], uniform pressure on a `Δx × Δy` rectangle)
//! sampled at offsets `−rows+1 … rows−1` (times Δy) and `−cols+1 … cols−1` (times Δx); the
//! padding keeps every periodic image out of the result, which equals the direct summation
//! `u_i = Σ_j K(x_i − x_j) p_j` to rounding (Hockney 1970; Liu, Wang & Liu, Wear 243, 2000).
//!
//! **Periodic boundaries**: the grid is one period `cols·Δx × rows·Δy`; the kernel is the
//! half-space Green's function in Fourier space, `û(q) = 2 p̂(q) / (E* |q|)` (Stanley & Kato
//! 1997) with `q = (2π kx / (cols·Δx), 2π ky / (rows·Δy))`, and the mean (`q = 0`) mode of
//! `u` set to zero: a periodic surface under a mean pressure sinks without bound, so
//! displacements are measured from their mean.
//!
//! Both kernels are even in x and in y, so their spectra are **real and even**: only the
//! `(cols_padded/2 + 1) × (rows_padded/2 + 1)` unique values are stored, as `f64`, with the
//! `1/(rows·cols)` normalisation folded in. One `apply` is one pruned, fused
//! [`RealFft2::convolve`] of the padded grid:
//! * `rows` real row transforms of length `cols_padded` (rows of zero padding are skipped),
//! * one fused pass per kept column: forward FFT, multiplication by the kernel, inverse FFT,
//! * `rows` inverse real row transforms (only the rows that are returned).
//!
//! [`ElasticOperator::single_precision`] makes a copy that computes in `f32`
//! (`ElasticOperator<f32>`: the kernel rounded, the transforms in single precision), with
//! relative errors of about 1e-7 at about 0.7 of the cost: for iterates that are recomputed
//! in double precision before anything is concluded from them.
//!
//! Plans, the kernel spectrum and all buffers are made in [`ElasticOperator::new`];
//! [`ElasticOperator::apply`] allocates nothing, and its result does not depend on the
//! number of threads (every row and column transform is independent).

use std::f64::consts::PI;

use num_complex::Complex64;

use super::cerruti::{cerruti_pixel_displacement, cerruti_spectrum, Direction};
use super::love::{love_pixel_displacement, rectangle_self_influence, self_influence};
use crate::fft::{Precision, RealFft2};
use crate::sum::sum4;
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
    pub fn padding(&self) -> usize {
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

/// Which displacement the operator gives for which load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kernel {
    /// Normal displacement from pressure (Love's coefficients; Boussinesq).
    Normal,
    /// Tangential displacement along `direction` from a tangential traction along it
    /// (Cerruti's coefficients, [`super::cerruti`]; the coupling to the normal problem and
    /// the cross term neglected), for Poisson's ratio `poisson` in `[0, 0.5]`.
    Tangential {
        /// Poisson's ratio ν.
        poisson: f64,
        /// The direction of traction and displacement.
        direction: Direction,
    },
}

impl Kernel {
    /// The displacement at `(x, y)` per unit load on a `dx × dy` pixel at the origin.
    fn pixel(self, x: f64, y: f64, dx: f64, dy: f64, modulus: f64) -> f64 {
        match self {
            Kernel::Normal => love_pixel_displacement(x, y, dx, dy, modulus),
            Kernel::Tangential { poisson, direction } => {
                cerruti_pixel_displacement(x, y, dx, dy, modulus, poisson, direction)
            }
        }
    }

    /// The periodic kernel's spectrum at `(qx, qy) ≠ 0`.
    fn spectrum(self, qx: f64, qy: f64, modulus: f64) -> f64 {
        match self {
            Kernel::Normal => 2.0 / (modulus * qx.hypot(qy)),
            Kernel::Tangential { poisson, direction } => {
                cerruti_spectrum(qx, qy, modulus, poisson, direction)
            }
        }
    }
}

/// The half-space convolution operator of one grid (see the module docs), computing in
/// `T` (`f64`; `f32` for the copy of [`ElasticOperator::single_precision`]).
pub struct ElasticOperator<T: Precision = f64> {
    rows: usize,
    cols: usize,
    spacing_x: f64,
    spacing_y: f64,
    modulus: f64,
    boundary: Boundary,
    /// Normal (Love) or tangential (Cerruti) coefficients.
    kind: Kernel,
    /// The padded (free) or plain (periodic) transform of the grid.
    fft: RealFft2<T>,
    /// Unique values of the real, even kernel spectrum, `half_cols × kernel_rows`,
    /// normalised by `1/(padded_rows · padded_cols)`.
    kernel: Vec<T>,
    /// One partial sum of [`ElasticOperator::energy`] per `kx`.
    column_energies: Vec<f64>,
}

fn check_positive(name: &'static str, value: f64) -> Result<()> {
    crate::positive_finite(name, value, "").map(drop)
}

impl ElasticOperator {
    /// Estimated peak memory of an operator for a `rows × cols` grid, in bytes (`None` on
    /// overflow): row-pass buffer, kernel and the transforms' plans and lanes, and the
    /// whole spectrum the kernel's set-up holds for a while (free boundaries; an upper
    /// bound for periodic ones).
    pub fn memory_bytes(rows: usize, cols: usize, boundary: Boundary) -> Option<u64> {
        let [_, _, spectrum] = buffer_bytes(rows, cols, boundary, 8)?;
        spectrum.checked_add(Self::resident_memory_bytes(rows, cols, boundary)?)
    }

    /// Memory an operator for a `rows × cols` grid keeps once planned, in bytes (`None` on
    /// overflow): [`ElasticOperator::memory_bytes`] less the spectrum of the kernel's
    /// set-up, which is freed before the operator is returned.
    pub fn resident_memory_bytes(rows: usize, cols: usize, boundary: Boundary) -> Option<u64> {
        let [work, kernel, _] = buffer_bytes(rows, cols, boundary, 8)?;
        work.checked_add(kernel)?
            .checked_add(plans(rows, cols, boundary)?)
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
        Self::with_spacings(rows, cols, spacing, spacing, modulus, boundary)
    }

    /// Plans the operator of a `rows × cols` grid of rectangular pixels, `spacing_x` along
    /// the columns (x) by `spacing_y` along the rows (y), on a half-space of effective
    /// modulus `modulus` (E*). With equal spacings this is [`ElasticOperator::new`].
    pub fn with_spacings(
        rows: usize,
        cols: usize,
        spacing_x: f64,
        spacing_y: f64,
        modulus: f64,
        boundary: Boundary,
    ) -> Result<Self> {
        Self::with_kernel(
            rows,
            cols,
            (spacing_x, spacing_y),
            modulus,
            boundary,
            Kernel::Normal,
        )
    }

    /// The operator of the tangential displacement along `direction` from a tangential
    /// traction along it, for Poisson's ratio `poisson` in `[0, 0.5]` (Cerruti's
    /// coefficients; [`Kernel::Tangential`]), on the grid of
    /// [`ElasticOperator::with_spacings`].
    pub fn tangential(
        (rows, cols): (usize, usize),
        (spacing_x, spacing_y): (f64, f64),
        modulus: f64,
        boundary: Boundary,
        (poisson, direction): (f64, Direction),
    ) -> Result<Self> {
        crate::mdr::check_poisson(poisson)?;
        let kind = Kernel::Tangential { poisson, direction };
        Self::with_kernel(rows, cols, (spacing_x, spacing_y), modulus, boundary, kind)
    }

    fn with_kernel(
        rows: usize,
        cols: usize,
        (spacing_x, spacing_y): (f64, f64),
        modulus: f64,
        boundary: Boundary,
        kind: Kernel,
    ) -> Result<Self> {
        if rows < 1 || cols < 1 {
            return Err(Error::invalid(
                "grid",
                format!("need at least 1x1 points, got {rows}x{cols}"),
            ));
        }
        check_positive("spacing", spacing_x)?;
        check_positive("spacing_y", spacing_y)?;
        check_positive("modulus", modulus)?;
        memory::ensure_fits(
            &format!(
                "the {} elastic operator of a {rows}x{cols} grid",
                boundary.name()
            ),
            Self::memory_bytes(rows, cols, boundary),
        )?;
        let pad = boundary.padding();
        let fft = RealFft2::zero_padded(rows, cols, rows * pad, cols * pad)?;
        let (kernel_len, spectrum_len, half_cols) = (
            fft.half_cols() * (fft.rows() / 2 + 1),
            fft.spectrum_len(),
            fft.half_cols(),
        );
        let mut operator = ElasticOperator {
            rows,
            cols,
            spacing_x,
            spacing_y,
            modulus,
            boundary,
            kind,
            fft,
            kernel: memory::try_vec("the elastic kernel's spectrum", kernel_len, 0.0)?,
            column_energies: memory::try_vec("the energy's partial sums", half_cols, 0.0)?,
        };
        match boundary {
            Boundary::Free => operator.fill_free_kernel(spectrum_len)?,
            Boundary::Periodic => operator.fill_periodic_kernel(),
        }
        Ok(operator)
    }

    /// A copy of this operator that computes in single precision: the same grid, the
    /// kernel spectrum rounded to `f32`, its own transform plans and buffers (module
    /// docs).
    pub fn single_precision(&self) -> Result<ElasticOperator<f32>> {
        let (rows, cols, boundary) = (self.rows, self.cols, self.boundary);
        memory::ensure_fits(
            &format!(
                "the single-precision {} elastic operator of a {rows}x{cols} grid",
                boundary.name()
            ),
            Self::single_precision_memory_bytes(rows, cols, boundary),
        )?;
        let (prow, pcol) = (self.fft.rows(), self.fft.cols());
        let fft = RealFft2::<f32>::planned(rows, cols, prow, pcol)?;
        let mut kernel = memory::try_vec("the elastic kernel's spectrum", self.kernel.len(), 0.0)?;
        for (single, &double) in kernel.iter_mut().zip(&self.kernel) {
            *single = f32::rounded(double);
        }
        Ok(ElasticOperator {
            rows,
            cols,
            spacing_x: self.spacing_x,
            spacing_y: self.spacing_y,
            modulus: self.modulus,
            boundary,
            kind: self.kind,
            fft,
            kernel,
            column_energies: self.column_energies.clone(),
        })
    }

    /// Estimated memory of [`ElasticOperator::single_precision`]'s copy for a `rows × cols`
    /// grid, in bytes (`None` on overflow): its row-pass buffer and kernel in `f32`, and
    /// its transforms' plans and lanes.
    pub fn single_precision_memory_bytes(
        rows: usize,
        cols: usize,
        boundary: Boundary,
    ) -> Option<u64> {
        let [work, kernel, _] = buffer_bytes(rows, cols, boundary, 4)?;
        work.checked_add(kernel)?
            .checked_add(plans(rows, cols, boundary)?)
    }
}

/// The plans and lanes of the transforms of an operator for a `rows × cols` grid (the
/// padded grid of free boundaries), in bytes (`None` on overflow).
fn plans(rows: usize, cols: usize, boundary: Boundary) -> Option<u64> {
    let pad = boundary.padding();
    crate::fft::plan_memory_bytes(rows.checked_mul(pad)?, cols.checked_mul(pad)?)
}

/// The buffers of an operator for a `rows × cols` grid computing with `real` bytes per real
/// value (8 or 4), in bytes (`None` on overflow): its row-pass buffer and its kernel, and
/// the whole spectrum (complex `f64`) that the kernel's set-up holds for a while.
fn buffer_bytes(rows: usize, cols: usize, boundary: Boundary, real: usize) -> Option<[u64; 3]> {
    let pad = boundary.padding();
    let padded_rows = rows.checked_mul(pad)?;
    let half_cols = cols.checked_mul(pad)? / 2 + 1;
    Some([
        memory::array_bytes(&[rows, half_cols], 2 * real)?,
        memory::array_bytes(&[half_cols, padded_rows / 2 + 1], real)?,
        memory::array_bytes(&[half_cols, padded_rows], 16)?,
    ])
}

impl<T: Precision> ElasticOperator<T> {
    /// Rows of the grid.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Columns of the grid.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Pixel side along x (columns), Δx; the pixel side for square pixels.
    pub fn spacing(&self) -> f64 {
        self.spacing_x
    }

    /// Pixel side along y (rows), Δy.
    pub fn spacing_y(&self) -> f64 {
        self.spacing_y
    }

    /// Area of one pixel, `Δx · Δy`.
    pub fn pixel_area(&self) -> f64 {
        self.spacing_x * self.spacing_y
    }

    /// Effective modulus E*.
    pub fn modulus(&self) -> f64 {
        self.modulus
    }

    /// The boundary conditions.
    pub fn boundary(&self) -> Boundary {
        self.boundary
    }

    /// Displacement at a pixel's centre per unit pressure on it, Love's value for a
    /// `Δx × Δy` rectangle ([`rectangle_self_influence`]; for square pixels exactly
    /// [`self_influence`]).
    pub fn self_influence(&self) -> f64 {
        if let Kernel::Tangential { .. } = self.kind {
            let (dx, dy) = (self.spacing_x, self.spacing_y);
            return self.kind.pixel(0.0, 0.0, dx, dy, self.modulus);
        }
        if self.spacing_x == self.spacing_y {
            self_influence(self.spacing_x, self.modulus)
        } else {
            rectangle_self_influence(self.spacing_x, self.spacing_y, self.modulus)
        }
    }

    fn padded_rows(&self) -> usize {
        self.fft.rows()
    }

    fn kernel_rows(&self) -> usize {
        self.padded_rows() / 2 + 1
    }
}

impl ElasticOperator {
    /// Spectrum of Love's coefficients sampled on the padded grid, row by row in parallel
    /// (the samples are never stored): each padded row's real transform is real (the row is
    /// even), so the real parts of the column transforms are the whole kernel.
    fn fill_free_kernel(&mut self, spectrum_len: usize) -> Result<()> {
        // The kernel's whole spectrum is needed once, here: not kept.
        let mut spectrum = memory::try_vec(
            "the elastic kernel's spectrum",
            spectrum_len,
            Complex64::default(),
        )?;
        let (prow, pcol) = (self.fft.rows(), self.fft.cols());
        let (dx, dy, e, kind) = (self.spacing_x, self.spacing_y, self.modulus, self.kind);
        let kernel_rows = self.kernel_rows();
        let offset = |m: usize, n: usize| {
            if m <= n / 2 {
                m as f64
            } else {
                m as f64 - n as f64
            }
        };
        self.fft.forward_rows_from(
            |r, row| {
                // Even in x: columns past the middle mirror those before it (the kernel
                // takes |x|, so the values are the same bits).
                let y = offset(r, prow) * dy;
                for (c, value) in row[..=pcol / 2].iter_mut().enumerate() {
                    *value = kind.pixel(offset(c, pcol) * dx, y, dx, dy, e);
                }
                for c in pcol / 2 + 1..pcol {
                    row[c] = row[pcol - c];
                }
            },
            &mut spectrum,
        );
        let scale = 1.0 / (prow * pcol) as f64;
        for (column, kernel_column) in spectrum
            .chunks_exact(prow)
            .zip(self.kernel.chunks_exact_mut(kernel_rows))
        {
            for (k, value) in kernel_column.iter_mut().zip(column) {
                *k = value.re * scale;
            }
        }
        Ok(())
    }

    /// `2 / (E* |q|) / (rows · cols)`, zero at `q = 0`, on the period `cols·Δx × rows·Δy`.
    fn fill_periodic_kernel(&mut self) {
        let (prow, pcol, half) = (self.fft.rows(), self.fft.cols(), self.fft.half_cols());
        let kernel_rows = self.kernel_rows();
        let scale = 1.0 / (prow * pcol) as f64;
        let qx_unit = 2.0 * PI / (pcol as f64 * self.spacing_x);
        let qy_unit = 2.0 * PI / (prow as f64 * self.spacing_y);
        for kx in 0..half {
            for ky in 0..kernel_rows {
                let (qx, qy) = (kx as f64 * qx_unit, ky as f64 * qy_unit);
                self.kernel[kx * kernel_rows + ky] = if kx == 0 && ky == 0 {
                    0.0
                } else {
                    self.kind.spectrum(qx, qy, self.modulus) * scale
                };
            }
        }
    }

    /// The kernel's spectrum value at `(kx, ky)` of the padded grid (normalised), for tests
    /// and preconditioners.
    pub fn kernel_spectrum(&self, kx: usize, ky: usize) -> f64 {
        let ky = ky.min(self.padded_rows() - ky);
        self.kernel[kx * self.kernel_rows() + ky]
    }
}

impl<T: Precision> ElasticOperator<T> {
    /// `displacement = K * pressure` on the `rows × cols` grid (row-major slices).
    pub fn apply(&mut self, pressure: &[f64], displacement: &mut [f64]) {
        self.convolve(pressure, displacement, false);
    }

    /// The quadratic form `pᵀK p` (the pressure's elastic energy, times two, per unit
    /// pixel area) from the forward transform alone: `K` is a circulant on the transform
    /// grid, so by Parseval `pᵀK p = Σ_q k̂(q) |p̂(q)|² / M` over the `M` wave vectors —
    /// about half the cost of [`ElasticOperator::apply`] and a dot product. The half
    /// spectrum holds `kx` and `−kx` in one column but for `kx = 0` and, on an even grid,
    /// the Nyquist column. The sum runs in column order: independent of the thread count.
    pub fn energy(&mut self, pressure: &[f64]) -> f64 {
        assert_eq!(pressure.len(), self.rows * self.cols, "pressure length");
        let kernel_rows = self.kernel_rows();
        let pcols = self.fft.cols();
        let kernel = &self.kernel;
        self.fft
            .forward_reduce(pressure, &mut self.column_energies, |kx, column| {
                let k = &kernel[kx * kernel_rows..(kx + 1) * kernel_rows];
                let (low, high) = column.split_at(kernel_rows);
                // `high` read backwards meets the kernel from `ky = 1` (`with_even_kernel`);
                // four chains of additions, not one.
                let last = high.len().wrapping_sub(1);
                let sum = sum4(low.len(), |m| (k[m] * low[m].norm_sqr()).widened())
                    + sum4(high.len(), |m| {
                        (k[m + 1] * high[last - m].norm_sqr()).widened()
                    });
                let mirrored = kx != 0 && 2 * kx != pcols;
                sum * if mirrored { 2.0 } else { 1.0 }
            });
        self.column_energies.iter().sum()
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

    /// One fused, pruned convolution with the kernel (`inverse`: with its pseudo-inverse).
    fn convolve(&mut self, input: &[f64], output: &mut [f64], inverse: bool) {
        assert_eq!(input.len(), self.rows * self.cols, "input length");
        assert_eq!(output.len(), self.rows * self.cols, "output length");
        let prow = self.padded_rows();
        let kernel_rows = self.kernel_rows();
        let normalisation = (prow * self.fft.cols()) as f64;
        let kernel = &self.kernel;
        self.fft.convolve(input, output, |kx, column| {
            let k = &kernel[kx * kernel_rows..(kx + 1) * kernel_rows];
            let (low, high) = column.split_at_mut(kernel_rows);
            let pairs = with_even_kernel((low.iter_mut(), high.iter_mut()), k);
            if inverse {
                let factor = |k: T| match k.widened() {
                    0.0 => T::default(),
                    k => T::rounded(1.0 / (k * normalisation * normalisation)),
                };
                pairs.for_each(|(v, k)| *v = v.scale(factor(k)));
            } else {
                pairs.for_each(|(v, k)| *v = v.scale(k));
            }
        });
    }
}

/// The values of a spectrum column, split at the kernel's `kernel_rows` values
/// (`ky = 0 … prow/2`) into `(low, high)`, each with the kernel at its `ky`: the spectrum is
/// even in `ky`, so value `ky` serves `ky` and `prow − ky`, and the upper part, read
/// backwards, meets the kernel from `ky = 1`. Two runs, which `for_each` and `sum` fold one
/// after the other.
fn with_even_kernel<'a, T, K: Copy>(
    (low, high): (
        impl Iterator<Item = T> + 'a,
        impl DoubleEndedIterator<Item = T> + 'a,
    ),
    k: &'a [K],
) -> impl Iterator<Item = (T, K)> + 'a {
    let k_from = |first: usize| k[first..].iter().copied();
    low.zip(k_from(0)).chain(high.rev().zip(k_from(1)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::relative_max_error;

    fn pseudo_random(n: usize, seed: usize) -> Vec<f64> {
        (0..n)
            .map(|i| (((i + seed) * 7919 + 13) % 101) as f64 / 101.0)
            .collect()
    }

    /// Direct O(N²M²) summation with Love's coefficients: the free-boundary oracle.
    fn direct_free(p: &[f64], rows: usize, cols: usize, (dx, dy): (f64, f64), e: f64) -> Vec<f64> {
        let mut u = vec![0.0; rows * cols];
        for i in 0..rows {
            for j in 0..cols {
                let mut sum = 0.0;
                for k in 0..rows {
                    for l in 0..cols {
                        let x = (j as f64 - l as f64) * dx;
                        let y = (i as f64 - k as f64) * dy;
                        sum += love_pixel_displacement(x, y, dx, dy, e) * p[k * cols + l];
                    }
                }
                u[i * cols + j] = sum;
            }
        }
        u
    }

    /// Direct periodic oracle: kernel by a naive inverse DFT of 2/(E*|q|), then a cyclic
    /// direct sum.
    fn direct_periodic(
        p: &[f64],
        rows: usize,
        cols: usize,
        (dx, dy): (f64, f64),
        e: f64,
    ) -> Vec<f64> {
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
                        .hypot(2.0 * PI * sy / (rows as f64 * dy));
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
                assert_close(&u, &direct_free(&p, rows, cols, (dx, dx), e), 1e-13, "free");
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
                    &direct_periodic(&p, rows, cols, (dx, dx), e),
                    1e-12,
                    "periodic",
                );
            }
        }
    }

    #[test]
    fn rectangular_pixels_match_direct_summation_free_and_periodic() {
        // Δx ≠ Δy, both orientations, even, odd and non-square grids: the FFT operator
        // equals the direct sums with Love's rectangle coefficients (free) and with the
        // q-grid 2π(kx/(cols Δx), ky/(rows Δy)) (periodic).
        for (rows, cols) in [(8, 8), (7, 9), (10, 5)] {
            for spacings in [(0.3, 0.15), (0.2, 0.5), (1.0, 2.0 / 3.0)] {
                let (dx, dy) = spacings;
                let p = pseudo_random(rows * cols, rows * cols);
                let mut u = vec![f64::NAN; rows * cols];
                let mut free =
                    ElasticOperator::with_spacings(rows, cols, dx, dy, 1.7, Boundary::Free)
                        .unwrap();
                free.apply(&p, &mut u);
                let direct = direct_free(&p, rows, cols, spacings, 1.7);
                assert_close(&u, &direct, 1e-13, "free, rectangular pixels");
                let mut periodic =
                    ElasticOperator::with_spacings(rows, cols, dx, dy, 1.7, Boundary::Periodic)
                        .unwrap();
                periodic.apply(&p, &mut u);
                let direct = direct_periodic(&p, rows, cols, spacings, 1.7);
                assert_close(&u, &direct, 1e-12, "periodic, rectangular pixels");
            }
        }
    }

    #[test]
    fn equal_spacings_are_the_square_pixel_operator() {
        // `with_spacings(Δ, Δ)` and `new(Δ)` give identical bits, and a rectangular pixel
        // 1e-9 away from square changes u by O(1e-9) only (no special case hides a jump).
        let (rows, cols, dx) = (9, 14, 0.37);
        let p = pseudo_random(rows * cols, 2);
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let mut square = ElasticOperator::new(rows, cols, dx, 1.1, boundary).unwrap();
            let mut same =
                ElasticOperator::with_spacings(rows, cols, dx, dx, 1.1, boundary).unwrap();
            let mut near =
                ElasticOperator::with_spacings(rows, cols, dx, dx * (1.0 + 1e-9), 1.1, boundary)
                    .unwrap();
            let (mut a, mut b, mut c) =
                (vec![0.0; p.len()], vec![0.0; p.len()], vec![0.0; p.len()]);
            square.apply(&p, &mut a);
            same.apply(&p, &mut b);
            near.apply(&p, &mut c);
            assert_eq!(a, b);
            assert_close(&c, &a, 1e-8, "nearly square");
            assert!((near.self_influence() / square.self_influence() - 1.0).abs() < 1e-8);
        }
    }

    #[test]
    fn periodic_rectangular_pixels_reproduce_a_sinusoid_along_y() {
        // p = cos(q y), q = 2π·2/(rows Δy): u = 2 cos(q y)/(E* q) whatever Δx is.
        let (rows, cols, dx, dy, e) = (16, 6, 0.7, 0.25, 2.0);
        let mut op =
            ElasticOperator::with_spacings(rows, cols, dx, dy, e, Boundary::Periodic).unwrap();
        let q = 2.0 * PI * 2.0 / (rows as f64 * dy);
        let p: Vec<f64> = (0..rows * cols)
            .map(|i| (q * (i / cols) as f64 * dy).cos())
            .collect();
        let mut u = vec![0.0; rows * cols];
        op.apply(&p, &mut u);
        for (ui, pi) in u.iter().zip(&p) {
            assert!((ui - 2.0 * pi / (e * q)).abs() < 1e-13);
        }
    }

    #[test]
    fn free_point_load_on_a_rectangular_pixel_decays_as_one_over_pi_e_r() {
        // F = p Δx Δy; far pixels see F/(π E* r) up to the pixel's quadrupole correction
        // (3 cos²θ Δx² + 3 sin²θ Δy² − Δx² − Δy²)/(24 r²), at most (2 max² − min²)/(24 r²)
        // in size (Δ²/(24 r²) for a square); bound: that times 1.1.
        let (n, dx, dy, e) = (64, 0.1, 0.05, 3.0);
        let mut op = ElasticOperator::with_spacings(n, n, dx, dy, e, Boundary::Free).unwrap();
        let mut p = vec![0.0; n * n];
        p[0] = 2.0;
        let mut u = vec![0.0; n * n];
        op.apply(&p, &mut u);
        let force = 2.0 * dx * dy;
        for &(i, j) in &[(0, 20), (30, 40), (63, 63), (50, 0)] {
            let r = (i as f64 * dy).hypot(j as f64 * dx);
            let expected = force / (PI * e * r);
            let rel = u[i * n + j] / expected - 1.0;
            let bound = 1.1 / 24.0 * (2.0 * dx.max(dy).powi(2) - dx.min(dy).powi(2)) / (r * r);
            assert!(rel.abs() <= bound, "({i},{j}): rel {rel:e} > {bound:e}");
        }
        let expected = 2.0 * love_pixel_displacement(0.0, 0.0, dx, dy, e);
        assert!((u[0] / expected - 1.0).abs() < 1e-13);
        assert!((op.self_influence() / (expected / 2.0) - 1.0).abs() < 1e-14);
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
    fn the_single_precision_copy_is_the_operator_to_its_rounding() {
        // apply and energy of `single_precision()` against the operator: within 1e-5 of the
        // largest value (single precision's rounding, a few tens of operations deep) and
        // not within 1e-9 (the copy really computes in f32). Odd, even and rectangular
        // grids, rectangular pixels, both boundaries.
        for boundary in [Boundary::Free, Boundary::Periodic] {
            for (i, &(rows, cols, dy)) in [(31, 31, 1.0), (32, 32, 1.0), (20, 37, 0.6)]
                .iter()
                .enumerate()
            {
                let mut op =
                    ElasticOperator::with_spacings(rows, cols, 0.7, 0.7 * dy, 2.0, boundary)
                        .unwrap();
                let mut single = op.single_precision().unwrap();
                assert_eq!((single.rows(), single.cols()), (rows, cols));
                assert_eq!(single.self_influence(), op.self_influence());
                let p = pseudo_random(rows * cols, i + 11);
                let (mut u, mut u_single) = (vec![0.0; p.len()], vec![f64::NAN; p.len()]);
                op.apply(&p, &mut u);
                single.apply(&p, &mut u_single);
                let error = relative_max_error(&u, &u_single);
                let case = format!("{rows}x{cols} {boundary:?}");
                assert!(error < 1e-5, "{case}: {error:e} of the largest value");
                assert!(error > 1e-9, "{case}: not single? {error:e}");
                let (energy, energy_single) = (op.energy(&p), single.energy(&p));
                let relative = (energy_single / energy - 1.0).abs();
                assert!(
                    relative < 1e-5 && relative > 1e-12,
                    "{case}: energy {relative:e}"
                );
            }
        }
    }

    #[test]
    fn energy_is_the_quadratic_form_of_the_operator() {
        // Odd, even and rectangular grids, square and rectangular pixels: Parseval's sum
        // over the half spectrum against pᵀ(K p) summed in real space.
        let cases = [(31, 31, 1.0), (32, 32, 1.0), (20, 37, 1.0), (24, 17, 0.6)];
        for boundary in [Boundary::Free, Boundary::Periodic] {
            for (i, &(rows, cols, dy)) in cases.iter().enumerate() {
                let mut op =
                    ElasticOperator::with_spacings(rows, cols, 0.7, 0.7 * dy, 2.0, boundary)
                        .unwrap();
                // Centred, so that the mean does not dominate the sum.
                let p: Vec<f64> = pseudo_random(rows * cols, i + 3)
                    .iter()
                    .map(|v| v - 0.5)
                    .collect();
                let mut u = vec![0.0; rows * cols];
                op.apply(&p, &mut u);
                let direct: f64 = p.iter().zip(&u).map(|(a, b)| a * b).sum();
                let energy = op.energy(&p);
                assert!(
                    (energy - direct).abs() <= 1e-12 * direct.abs(),
                    "{boundary:?} {rows}x{cols}: {energy} against {direct}"
                );
            }
        }
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
        assert!(ElasticOperator::with_spacings(4, 4, 1.0, 0.0, 1.0, Boundary::Free).is_err());
        assert!(
            ElasticOperator::with_spacings(4, 4, 1.0, f64::INFINITY, 1.0, Boundary::Periodic)
                .is_err()
        );
        let err = ElasticOperator::new(1 << 20, 1 << 20, 1.0, 1.0, Boundary::Free)
            .err()
            .unwrap();
        assert!(matches!(err, Error::OutOfMemory { .. }), "{err}");
    }
}
