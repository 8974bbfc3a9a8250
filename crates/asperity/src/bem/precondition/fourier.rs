//! [`FourierPreconditioner`]: an approximate inverse of the half-space operator, applied in
//! Fourier space on the unpadded grid.
//!
//! The periodic half-space operator has the symbol `2/(E*|q|)` (Stanley & Kato 1997); its
//! inverse `E*|q|/2` maps a displacement (a gap) to a pressure. Applied to the gradient of
//! the contact problem restricted to the free set `F` and restricted to `F` again
//! (`P_F M P_F`, symmetric positive semi-definite), it turns the gap into a pressure-like
//! search direction whose high-wavenumber content is no longer damped by `1/|q|`: the
//! preconditioned operator `M K` has a spectrum near 1 instead of the spread `q_max/q_min`
//! of `K` (Vollebregt, J. Comput. Phys. 257A, 333–351, 2014, who applies the same idea to
//! the BCCG of CONTACT).
//!
//! Free boundaries use the same symbol on the unpadded `rows × cols` grid: the zero-padded
//! Love kernel is not diagonal in that basis, but its symbol is close to `2/(E*|q|)` away from
//! the longest wavelengths, and one unpadded real FFT pair costs about a quarter of the
//! padded pair of the operator. The `q = 0` mode, where the periodic kernel vanishes, gets
//! the value of the smallest non-zero wavenumber of the grid, `E* q₁/2` with
//! `q₁ = 2π/max(L_x, L_y)`: finite, and of the size of the inverse flat-punch stiffness of
//! the grid.
//!
//! The solvers apply it in single precision ([`Real`]): `M` only shapes the search
//! directions, whose steps, residuals and convergence are computed in double precision, so
//! its rounding (about 1e-7) changes no iteration count of the BCCG measured (`bench
//! bem-solve`, study samples at 128² and 256²), and the frozen-set CG takes about 3 % more
//! iterations, each cheaper. At 512² an application costs 0.8 ms instead of 1.0 ms (2
//! threads).
//!
//! Planned once ([`FourierPreconditioner::new`]); [`FourierPreconditioner::apply`] allocates
//! nothing and does not depend on the thread count (it runs [`RealFft2`]).

use std::f64::consts::PI;
use std::ops::SubAssign;

use num_complex::Complex;

use crate::fft::{Precision, RealFft2};
use crate::memory::{self, try_vec};
use crate::Result;

/// The precision the solvers' preconditioner computes in: single. `M` is an approximation
/// of `K⁻¹` to begin with, and the iterations read `M g` only through the direction it
/// suggests; their residuals, steps and convergence are all in double precision. Single
/// precision takes a fifth off the preconditioner's time at 512² (docs/bem_history.md, "Single precision for the preconditioner").
pub(in crate::bem) type Real = f32;

/// `M ≈ K⁻¹` by its Fourier symbol `E*|q|/2` on the unpadded grid (see the module docs),
/// computed in precision `T` (the solvers use [`Real`]).
pub(in crate::bem) struct FourierPreconditioner<T: Precision = Real> {
    fft: RealFft2<T>,
    /// Symbol in the transposed half-spectrum layout of [`RealFft2`] (`kx`-major), with the
    /// FFT's `1/(rows·cols)` folded in.
    symbol: Vec<T>,
}

impl<T: Precision> FourierPreconditioner<T> {
    /// Bytes of a preconditioner for a `rows × cols` grid (`None` on overflow): the FFT's
    /// work buffer (complex, half grid) and the symbol (real, half grid), three values of
    /// `T` per point of the half grid, and the transform's plans and lanes (6 bytes per
    /// grid point in single precision, the solvers').
    pub(in crate::bem) fn memory_bytes(rows: usize, cols: usize) -> Option<u64> {
        let value = std::mem::size_of::<T>();
        memory::array_bytes(&[rows, cols / 2 + 1], 3 * value)?
            .checked_add(crate::fft::plan_memory_bytes(rows, cols)?)
    }

    /// Plans the transforms and tabulates the symbol for a `rows × cols` grid of pixels
    /// `dx × dy` on a half-space of modulus `modulus`.
    pub(in crate::bem) fn new(
        rows: usize,
        cols: usize,
        dx: f64,
        dy: f64,
        modulus: f64,
    ) -> Result<Self> {
        Self::with_symbol(rows, cols, (dx, dy), |_, _, q| 0.5 * modulus * q)
    }

    /// Plans the transforms and tabulates `symbol(qx, qy, q)`, an approximate inverse of an
    /// operator's Fourier symbol, for a `rows × cols` grid of pixels `dx × dy`: `q` is
    /// `|(qx, qy)|`, or at `qx = qy = 0` the smallest non-zero wavenumber of the grid
    /// (module docs).
    pub(in crate::bem) fn with_symbol(
        rows: usize,
        cols: usize,
        (dx, dy): (f64, f64),
        symbol_at: impl Fn(f64, f64, f64) -> f64,
    ) -> Result<Self> {
        let fft = RealFft2::<T>::planned(rows, cols, rows, cols)?;
        let (half, len) = (fft.half_cols(), fft.spectrum_len());
        let mut symbol = try_vec("the preconditioner's symbol", len, T::default())?;
        let qx_unit = 2.0 * PI / (cols as f64 * dx);
        let qy_unit = 2.0 * PI / (rows as f64 * dy);
        let q_lowest = qx_unit.min(qy_unit);
        let normalisation = 1.0 / (rows * cols) as f64;
        for kx in 0..half {
            for ky in 0..rows {
                let ky_folded = ky.min(rows - ky);
                let (qx, qy) = (kx as f64 * qx_unit, ky_folded as f64 * qy_unit);
                let q = qx.hypot(qy);
                let q = if q > 0.0 { q } else { q_lowest };
                symbol[kx * rows + ky] = T::rounded(symbol_at(qx, qy, q) * normalisation);
            }
        }
        Ok(FourierPreconditioner { fft, symbol })
    }

    /// `output ← M input` (`rows × cols` row-major fields): [`FourierPreconditioner::apply`]
    /// without first copying the input into the output.
    pub(in crate::bem) fn apply_into(&mut self, input: &[f64], output: &mut [f64]) {
        self.apply_prepared(input, output, |_, _| {});
    }

    /// `output ← M x` for the field `x` that `prepare(i, row)` makes of row `i` of `input`
    /// (`cols` values) on its way into the transform; `input` is left alone.
    pub(in crate::bem) fn apply_prepared(
        &mut self,
        input: &[f64],
        output: &mut [f64],
        prepare: impl Fn(usize, &mut [T]) + Sync,
    ) {
        let rows = self.fft.rows();
        let multiply = multiplier(&self.symbol, rows);
        self.fft.convolve_prepared(input, output, multiply, prepare);
    }

    /// `data ← M data` (a `rows × cols` row-major field, overwritten).
    /// One fused convolution: each column of the spectrum is multiplied while in cache.
    pub(in crate::bem) fn apply(&mut self, data: &mut [f64]) {
        let rows = self.fft.rows();
        let multiply = multiplier(&self.symbol, rows);
        self.fft.convolve_in_place(data, multiply);
    }
}

/// An approximate inverse `M ≈ K⁻¹` of a [`crate::elastic::HalfSpaceOperator`], as the
/// conjugate gradients use it: it maps a residual (a displacement) to a search direction (a
/// load). Symmetric positive definite; allocates nothing; independent of the thread count.
///
/// [`FourierPreconditioner`] is the one made from a symbol; the rings around a set
/// (`ring_extension.rs`, [`super::Ringed`]) decorate any preconditioner,
/// and the BCCG and the CG on a set take either.
pub(crate) trait Preconditioner {
    /// `output ← M input` (`rows × cols` row-major fields).
    fn apply_into(&mut self, input: &[f64], output: &mut [f64]);

    /// `data ← M data` (overwritten).
    fn apply(&mut self, data: &mut [f64]);

    /// `output ← M x` for the field `x` that is `input − centre` on the set (`set[i]`) and
    /// `input` off it: the BCCG's centring `Π` on its free set, formed on the way into
    /// the transform (never stored). A decorator may write into `input` off the set (the
    /// rings put their extension there); on the set `input` is kept.
    fn apply_centred(&mut self, input: &mut [f64], output: &mut [f64], centred: (&[bool], f64));
}

impl<T: Precision + Masked + SubAssign> Preconditioner for FourierPreconditioner<T> {
    fn apply_into(&mut self, input: &[f64], output: &mut [f64]) {
        FourierPreconditioner::apply_into(self, input, output);
    }

    fn apply(&mut self, data: &mut [f64]) {
        FourierPreconditioner::apply(self, data);
    }

    /// The centring is made in `T` row by row on the way into the transform.
    fn apply_centred(
        &mut self,
        input: &mut [f64],
        output: &mut [f64],
        (set, centre): (&[bool], f64),
    ) {
        let cols = self.fft.cols();
        let centre = T::rounded(centre);
        let centred = |i: usize, row: &mut [T]| {
            let set = &set[i * cols..][..cols];
            for (v, &on_set) in row.iter_mut().zip(set) {
                *v -= centre_on_set(centre, on_set);
            }
        };
        self.apply_prepared(input, output, centred);
    }
}

/// What the centring `Π` subtracts from a value of a gradient field: `centre` on the set
/// (`on_set`), +0 off it (`v − 0 = v`), chosen by a mask of its bits, not a branch (which
/// would be mispredicted at every edge of the set). In double precision, or in the
/// preconditioner's single.
#[inline(always)]
pub(in crate::bem) fn centre_on_set<T: Masked>(centre: T, on_set: bool) -> T {
    centre.kept(on_set)
}

/// Floating-point values that can be kept or zeroed by a mask of their bits.
pub(in crate::bem) trait Masked: Copy {
    /// `self` if `keep`, else +0.
    fn kept(self, keep: bool) -> Self;
}

impl Masked for f64 {
    #[inline(always)]
    fn kept(self, keep: bool) -> Self {
        f64::from_bits(self.to_bits() & u64::from(keep).wrapping_neg())
    }
}

impl Masked for f32 {
    #[inline(always)]
    fn kept(self, keep: bool) -> Self {
        f32::from_bits(self.to_bits() & u32::from(keep).wrapping_neg())
    }
}

/// The filter of the fused convolution: column `kx` of the spectrum times its symbol.
fn multiplier<T: Precision>(
    symbol: &[T],
    rows: usize,
) -> impl Fn(usize, &mut [Complex<T>]) + Sync + '_ {
    move |kx, column| {
        let m = &symbol[kx * rows..(kx + 1) * rows];
        column.iter_mut().zip(m).for_each(|(c, &m)| *c = c.scale(m));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elastic::{Boundary, ElasticOperator};
    use crate::test_support::relative_max_error;

    /// Max error of `M K p` against `p` for a zero-mean random `p` on a periodic grid,
    /// relative to max |p|, and that of `M 1` against `E* q₁/2`, in precision `T`.
    fn inversion_errors<T: Precision>() -> (f64, f64) {
        let (rows, cols, dx, modulus) = (24, 30, 0.1, 1.7);
        let mut op = ElasticOperator::new(rows, cols, dx, modulus, Boundary::Periodic).unwrap();
        let mut m = FourierPreconditioner::<T>::new(rows, cols, dx, dx, modulus).unwrap();
        let mut state = 12345u64;
        let mut p: Vec<f64> = (0..rows * cols)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let mean = p.iter().sum::<f64>() / p.len() as f64;
        p.iter_mut().for_each(|v| *v -= mean);
        let mut u = vec![0.0; rows * cols];
        op.apply(&p, &mut u);
        m.apply(&mut u);
        let error = relative_max_error(&p, &u);
        // The mean mode is kept with the finite value E* q₁/2 (q₁ = 2π/(cols·Δ) here).
        let mut ones = vec![1.0; rows * cols];
        m.apply(&mut ones);
        let expected = 0.5 * modulus * 2.0 * PI / (cols as f64 * dx);
        let mean_error = ones
            .iter()
            .fold(0.0f64, |a, v| a.max((v / expected - 1.0).abs()));
        (error, mean_error)
    }

    #[test]
    fn inverts_the_periodic_operator_on_zero_mean_fields() {
        // On periodic boundaries M K = 1 on every mode but q = 0 (the operator's symbol is
        // exactly 2/(E*|q|)): a zero-mean random field comes back to rounding, in double
        // precision to 1e-12 …
        let (error, mean_error) = inversion_errors::<f64>();
        assert!(error < 1e-12 && mean_error < 1e-12, "{error} {mean_error}");
        // … and in the solvers' single precision to its rounding (2⁻²⁴ ≈ 6e-8 per
        // operation, a few tens of operations deep): 1e-5, and not better than 1e-9 (the
        // transforms are single).
        let (error, mean_error) = inversion_errors::<Real>();
        assert!(error < 1e-5 && mean_error < 1e-5, "{error} {mean_error}");
        assert!(error > 1e-9, "single precision computed in double? {error}");
    }
}
