//! Two-dimensional real FFTs, planned once and run many times without allocating: the one
//! engine behind surface synthesis, surface statistics and the elastic half-space operator.
//!
//! [`RealFft2`] transforms a real `rows × cols` grid (row-major) to its half spectrum and
//! back. The spectrum is kept **transposed**: `cols/2 + 1` rows (one per `kx`), each of
//! length `rows` (all `ky`), which makes both passes contiguous. Rows are transformed in
//! parallel with rayon; each worker lane owns a scratch buffer allocated at planning time,
//! so no transform allocates. Results do not depend on the number of threads (each row and
//! each column is one independent transform, always computed whole by one lane).
//!
//! **Zero padding, pruned** ([`RealFft2::zero_padded`]): convolutions without periodic
//! images (Hockney 1970) embed a `data_rows × data_cols` block in a larger transform grid,
//! typically `2·data_rows × 2·data_cols`. The forward transform then skips the rows of
//! zeros (only `data_rows` real row transforms, the columns get zeros appended), and the
//! inverse transform returns only the `data_rows × data_cols` block: after the column pass
//! only `data_rows` real row transforms are run. For a 2N × 2N grid padding an N × N block,
//! a forward + inverse pair costs N + N row transforms of length 2N instead of 2N + 2N, and
//! the 2·(N+1) column transforms of length 2N of the full pair.
//!
//! [`RealFft2::convolve`] fuses forward and inverse for filters applied column by column:
//! each `kx` column is transformed forward, filtered and transformed back while it is in
//! cache. Its column pass (and that of [`RealFft2::forward_reduce`]) never writes the
//! transposed spectrum: each lane gathers a strip of four values (a cache line) of every
//! row spectrum into columns of its own buffer (zeros below the data rows), transforms them
//! there and puts the data rows back — the two transposes of the row spectra through a
//! whole-grid spectrum were a third of a BEM solve's time at 512².
//!
//! Neither direction is normalised: `inverse(forward(x)) = rows·cols·x`.

use std::sync::Arc;

use num_complex::Complex;
use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftNum, FftPlanner};

use crate::memory::{array_bytes, try_vec};
use crate::{Error, Result};

/// The floating-point type a [`RealFft2`] computes in: `f64` (the default, and the only
/// one whose results are exact to rounding in double precision) or `f32` (faster, with
/// relative errors of about 1e-7: for approximations such as preconditioners). Its real
/// inputs and outputs are `f64` either way.
pub trait Precision: FftNum + Default {
    /// `x` rounded to this type.
    fn rounded(x: f64) -> Self;
    /// `self` in double precision (exact).
    fn widened(self) -> f64;
    /// `row` as a row of this type, if it is one (`f64`): written in place, not copied.
    fn as_own(row: &mut [f64]) -> Option<&mut [Self]>;
    /// `dst ← src` rounded to this type (a plain copy for `f64`).
    fn load(dst: &mut [Self], src: &[f64]);
    /// `dst ← src` in double precision (a plain copy for `f64`).
    fn store(dst: &mut [f64], src: &[Self]);
    /// Columns per strip of the fused column pass: a cache line of complex values.
    const STRIP: usize;
}

impl Precision for f64 {
    #[inline(always)]
    fn rounded(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn widened(self) -> f64 {
        self
    }
    fn as_own(row: &mut [f64]) -> Option<&mut [Self]> {
        Some(row)
    }
    fn load(dst: &mut [Self], src: &[f64]) {
        dst.copy_from_slice(src);
    }
    fn store(dst: &mut [f64], src: &[Self]) {
        dst.copy_from_slice(src);
    }
    const STRIP: usize = COLUMN_BLOCK;
}

impl Precision for f32 {
    #[inline(always)]
    fn rounded(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn widened(self) -> f64 {
        f64::from(self)
    }
    fn as_own(_: &mut [f64]) -> Option<&mut [Self]> {
        None
    }
    fn load(dst: &mut [Self], src: &[f64]) {
        for (d, &x) in dst.iter_mut().zip(src) {
            *d = x as f32;
        }
    }
    fn store(dst: &mut [f64], src: &[Self]) {
        for (d, &x) in dst.iter_mut().zip(src) {
            *d = f64::from(x);
        }
    }
    const STRIP: usize = 2 * COLUMN_BLOCK;
}

struct Lane<T> {
    real: Vec<T>,
    scratch: Vec<Complex<T>>,
    /// [`Precision::STRIP`] columns of the transform grid (`rows` values each), gathered from
    /// the row spectra by the fused column pass.
    columns: Vec<Complex<T>>,
}

/// Columns (`kx`) a lane gathers, transforms and returns at a time in the fused column pass
/// ([`RealFft2::convolve`], [`RealFft2::forward_reduce`]) in double precision: a strip of
/// four complex values of a row spectrum is one cache line (in single precision the strip
/// is of eight, the same line). Measured (cold BCCG solves, free boundaries, 2
/// threads, interleaved runs): 4 against 8 columns 1.34 against 1.61 s at 1024², 0.195
/// against 0.226 s at 512², 0.034 against 0.045 s at 256²; 2 columns as fast as 4, 16
/// slower than 8.
const COLUMN_BLOCK: usize = 4;

/// The row spectra (`rows × half`, row-major) shared by the lanes of the fused column pass,
/// each of which reads and writes only its own columns.
struct SharedRows<T> {
    ptr: *mut Complex<T>,
    rows: usize,
    half: usize,
}

// SAFETY: the lanes access disjoint column strips (`SharedRows::strip`'s contract).
unsafe impl<T: Send> Sync for SharedRows<T> {}

impl<T> SharedRows<T> {
    fn new(work: &mut [Complex<T>], rows: usize, half: usize) -> Self {
        assert_eq!(work.len(), rows * half, "row spectra length");
        SharedRows {
            ptr: work.as_mut_ptr(),
            rows,
            half,
        }
    }

    /// Values `kx0 .. kx0 + width` of row `r`.
    ///
    /// # Safety
    /// No two strips handed out at the same time may overlap, and the buffer must outlive
    /// them (both hold within one fused column pass, whose lanes own disjoint columns).
    #[allow(clippy::mut_from_ref)]
    unsafe fn strip(&self, r: usize, kx0: usize, width: usize) -> &mut [Complex<T>] {
        assert!(
            r < self.rows && kx0 + width <= self.half,
            "strip inside the rows"
        );
        // SAFETY: in bounds (checked above); exclusive by the caller's contract.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(r * self.half + kx0), width) }
    }
}

/// A planned 2D real-to-complex FFT of a `rows × cols` grid, optionally zero-padding a
/// smaller data block (see the module docs), computed in precision `T` ([`Precision`]).
pub struct RealFft2<T: Precision = f64> {
    rows: usize,
    cols: usize,
    data_rows: usize,
    data_cols: usize,
    r2c: Arc<dyn RealToComplex<T>>,
    c2r: Arc<dyn ComplexToReal<T>>,
    col_forward: Arc<dyn Fft<T>>,
    col_inverse: Arc<dyn Fft<T>>,
    /// Row-major half spectra of the data rows, `data_rows × (cols/2+1)`, between the row
    /// and the column passes.
    work: Vec<Complex<T>>,
    lanes: Vec<Lane<T>>,
}

/// Bytes of the plans and per-thread buffers of a `rows × cols` transform, an upper bound
/// (`None` on overflow); its half-spectrum work buffer is not included. Each lane (one per
/// thread of the pool) holds a strip of columns ([`Precision::STRIP`] × `rows` complex
/// values: 64 bytes per row in either precision), a row (at most 8 bytes per column) and
/// the transforms' scratch (at most 4 × max(rows, cols) complex values, Bluestein's for
/// sizes with large prime factors): at most 128 bytes per row and column. The four plans'
/// twiddles (at most about 9 complex values per point of their length, Bluestein's) are
/// bounded by as much as three lanes.
pub(crate) fn plan_memory_bytes(rows: usize, cols: usize) -> Option<u64> {
    let lanes = rayon::current_num_threads().max(1);
    array_bytes(&[lanes.checked_add(3)?, rows.checked_add(cols)?], 128)
}

impl RealFft2 {
    /// Plans double-precision transforms for a `rows × cols` real grid (both at least 1).
    /// The work buffers are allocated fallibly: [`Error::OutOfMemory`] if the system
    /// refuses them.
    pub fn new(rows: usize, cols: usize) -> Result<Self> {
        Self::zero_padded(rows, cols, rows, cols)
    }

    /// Plans double-precision transforms of a `rows × cols` grid whose input is a
    /// `data_rows × data_cols` block at its top-left corner, zeros elsewhere, and whose
    /// inverse returns that block only (see the module docs). `data_rows ≤ rows`,
    /// `data_cols ≤ cols`, all at least 1.
    pub fn zero_padded(
        data_rows: usize,
        data_cols: usize,
        rows: usize,
        cols: usize,
    ) -> Result<Self> {
        Self::planned(data_rows, data_cols, rows, cols)
    }
}

impl<T: Precision> RealFft2<T> {
    /// [`RealFft2::zero_padded`] in precision `T`: a `rows × cols` transform of a
    /// `data_rows × data_cols` data block (the same sizes for no padding).
    pub fn planned(data_rows: usize, data_cols: usize, rows: usize, cols: usize) -> Result<Self> {
        if data_rows < 1 || data_cols < 1 {
            return Err(Error::invalid(
                "grid",
                format!("an FFT grid needs at least 1x1 points, got {data_rows}x{data_cols}"),
            ));
        }
        if rows < data_rows || cols < data_cols {
            return Err(Error::invalid(
                "grid",
                format!(
                    "a {rows}x{cols} transform cannot hold a {data_rows}x{data_cols} data block"
                ),
            ));
        }
        let half = cols / 2 + 1;
        let what = format!("the FFT buffer of a {rows}x{cols} grid");
        let work_len = data_rows
            .checked_mul(half)
            .ok_or_else(|| Error::OutOfMemory {
                what: what.clone(),
                needed_mib: None,
                available_mib: None,
                limited_by: "the address space".into(),
            })?;
        let work = try_vec(&what, work_len, Complex::<T>::default())?;
        let mut real_planner = RealFftPlanner::<T>::new();
        let r2c = real_planner.plan_fft_forward(cols);
        let c2r = real_planner.plan_fft_inverse(cols);
        let mut planner = FftPlanner::<T>::new();
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
                    real: try_vec("an FFT row buffer", cols, T::default())?,
                    scratch: try_vec("an FFT scratch buffer", scratch_len, Complex::default())?,
                    columns: try_vec("an FFT column buffer", T::STRIP * rows, Complex::default())?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(RealFft2 {
            rows,
            cols,
            data_rows,
            data_cols,
            r2c,
            c2r,
            col_forward,
            col_inverse,
            work,
            lanes,
        })
    }

    /// Number of rows of the transform grid.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns of the transform grid.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Rows of the data block (`rows` unless zero-padded).
    pub fn data_rows(&self) -> usize {
        self.data_rows
    }

    /// Columns of the data block (`cols` unless zero-padded).
    pub fn data_cols(&self) -> usize {
        self.data_cols
    }

    /// Number of `kx` values kept, `cols/2 + 1` (rows of the transposed spectrum).
    pub fn half_cols(&self) -> usize {
        self.cols / 2 + 1
    }

    /// Length of a spectrum buffer: `(cols/2 + 1) · rows`.
    pub fn spectrum_len(&self) -> usize {
        self.half_cols() * self.rows
    }

    fn check_data(&self, real: &[f64]) {
        assert_eq!(
            real.len(),
            self.data_rows * self.data_cols,
            "real grid length"
        );
    }

    fn check_lengths(&self, real: &[f64], spectrum: &[Complex<T>]) {
        self.check_data(real);
        assert_eq!(spectrum.len(), self.spectrum_len(), "spectrum length");
    }

    /// Forward transform of `input` (the `data_rows × data_cols` block, row-major; the
    /// whole grid unless zero-padded) into `spectrum` (transposed half spectrum,
    /// `(cols/2+1) × rows`).
    pub fn forward(&mut self, input: &[f64], spectrum: &mut [Complex<T>]) {
        self.check_lengths(input, spectrum);
        self.rows_into_columns(input, spectrum);
        let fft = &self.col_forward;
        for_each_column(
            spectrum,
            self.rows,
            &mut self.lanes,
            |_, column, scratch| fft.process_with_scratch(column, scratch),
        );
    }

    /// Inverse transform of a transposed half `spectrum` (overwritten) into `output` (the
    /// `data_rows × data_cols` block; the whole grid unless zero-padded). The imaginary
    /// parts that a real signal cannot have (at `kx = 0` and, for even `cols`,
    /// `kx = cols/2`) are dropped.
    pub fn inverse(&mut self, spectrum: &mut [Complex<T>], output: &mut [f64]) {
        self.check_lengths(output, spectrum);
        let fft = &self.col_inverse;
        for_each_column(
            spectrum,
            self.rows,
            &mut self.lanes,
            |_, column, scratch| fft.process_with_scratch(column, scratch),
        );
        let half = self.half_cols();
        transpose_from_columns(spectrum, &mut self.work, self.data_rows, half, self.rows);
        self.inverse_rows(output);
    }

    /// `output = inverse(filter(forward(input)))` with the column passes fused: every
    /// `kx` column of the spectrum is transformed forward, handed to `filter(kx, column)`
    /// (all `rows` values of `ky`) and transformed back while it is in cache (gathered
    /// from the row spectra by its lane: no transposed spectrum is written). `input` and
    /// `output` are data blocks.
    pub fn convolve<F>(&mut self, input: &[f64], output: &mut [f64], filter: F)
    where
        F: Fn(usize, &mut [Complex<T>]) + Sync,
    {
        self.convolve_prepared(input, output, filter, |_, _| {});
    }

    /// [`RealFft2::convolve`] of the input as changed row by row by `prepare(i, row)` (row
    /// `i` of the data block, `data_cols` values in precision `T`) on its way into the row
    /// transforms: for
    /// inputs that are a cheap function of a stored field, which then need not be
    /// written whole.
    pub fn convolve_prepared<F, P>(
        &mut self,
        input: &[f64],
        output: &mut [f64],
        filter: F,
        prepare: P,
    ) where
        F: Fn(usize, &mut [Complex<T>]) + Sync,
        P: Fn(usize, &mut [T]) + Sync,
    {
        self.check_data(input);
        self.check_data(output);
        self.forward_rows(input, prepare);
        self.filter_columns(filter);
        self.inverse_rows(output);
    }

    /// [`RealFft2::convolve`] with `data` both the input and the output (overwritten).
    pub fn convolve_in_place<F>(&mut self, data: &mut [f64], filter: F)
    where
        F: Fn(usize, &mut [Complex<T>]) + Sync,
    {
        self.check_data(data);
        self.forward_rows(data, |_, _| {});
        self.filter_columns(filter);
        self.inverse_rows(data);
    }

    /// The forward transform of `input` reduced column by column, for quadratic forms
    /// that need no inverse transform (Parseval): every `kx` column of the spectrum is
    /// transformed and handed to `reduce(kx, column)` while it is in cache, and the value
    /// stored in `values[kx]` (`half_cols` of them). Each column is one lane's, so the
    /// values do not depend on the thread count.
    pub fn forward_reduce<F>(&mut self, input: &[f64], values: &mut [f64], reduce: F)
    where
        F: Fn(usize, &[Complex<T>]) -> f64 + Sync,
    {
        self.check_data(input);
        assert_eq!(values.len(), self.half_cols(), "one value per kx");
        self.forward_rows(input, |_, _| {});
        // The plan is shared (an `Arc`): a handle, not a copy.
        let fft = Arc::clone(&self.col_forward);
        self.gathered_columns(values, false, |kx, column, scratch, value| {
            fft.process_with_scratch(column, scratch);
            *value = reduce(kx, column);
        });
    }

    /// The column passes of [`RealFft2::convolve`]: from the rows' half spectra in `work`
    /// through the fused forward, filter and inverse column transforms back to `work`.
    fn filter_columns<F>(&mut self, filter: F)
    where
        F: Fn(usize, &mut [Complex<T>]) + Sync,
    {
        let (forward, backward) = (Arc::clone(&self.col_forward), Arc::clone(&self.col_inverse));
        // Units take no memory: nothing is allocated.
        let mut nothing = vec![(); self.half_cols()];
        self.gathered_columns(&mut nothing, true, |kx, column, scratch, ()| {
            forward.process_with_scratch(column, scratch);
            filter(kx, column);
            backward.process_with_scratch(column, scratch);
        });
    }

    /// The fused column pass: every `kx` column of the transform grid is gathered from the
    /// row spectra in `work` (zeros below the data rows) into its lane's buffer, handed to
    /// `column(kx, values, scratch, &mut outputs[kx])`, and with `write_back` its first
    /// `data_rows` values returned to `work`. Lanes own contiguous runs of columns and take
    /// them [`COLUMN_BLOCK`] at a time (a strip of every row spectrum): each column is
    /// computed whole by one lane, whatever the number of threads.
    fn gathered_columns<O, F>(&mut self, outputs: &mut [O], write_back: bool, column: F)
    where
        O: Send,
        F: Fn(usize, &mut [Complex<T>], &mut [Complex<T>], &mut O) + Sync,
    {
        let (rows, data_rows, half) = (self.rows, self.data_rows, self.half_cols());
        assert_eq!(outputs.len(), half, "one output per column");
        let shared = SharedRows::new(&mut self.work, data_rows, half);
        let strip = T::STRIP;
        let lane_columns = per_lane(half.div_ceil(strip), self.lanes.len()) * strip;
        outputs
            .par_chunks_mut(lane_columns)
            .enumerate()
            .zip(self.lanes.par_iter_mut())
            .for_each(|((l, outputs), lane)| {
                for (b, outputs) in outputs.chunks_mut(strip).enumerate() {
                    let (kx0, width) = (l * lane_columns + b * strip, outputs.len());
                    let block = &mut lane.columns[..width * rows];
                    // SAFETY (both strips): columns kx0 .. kx0 + width are this lane's
                    // alone, and `work` outlives the pass.
                    for r in 0..data_rows {
                        let strip = unsafe { shared.strip(r, kx0, width) };
                        for (d, &v) in strip.iter().enumerate() {
                            block[d * rows + r] = v;
                        }
                    }
                    let columns = block.chunks_exact_mut(rows).zip(outputs).enumerate();
                    for (d, (values, out)) in columns {
                        values[data_rows..].fill(Complex::default());
                        column(kx0 + d, values, &mut lane.scratch, out);
                    }
                    if write_back {
                        for r in 0..data_rows {
                            let strip = unsafe { shared.strip(r, kx0, width) };
                            for (d, v) in strip.iter_mut().enumerate() {
                                *v = block[d * rows + r];
                            }
                        }
                    }
                }
            });
    }

    /// Forward transform of a whole `rows × cols` grid (padding included) whose rows are
    /// produced by `row(r, buffer)`, which must fill all `cols` values: for inputs that fill
    /// the transform grid but need not be stored, such as a sampled convolution kernel. Rows
    /// are generated and transformed in parallel, `data_rows` at a time (the work buffer's
    /// capacity), and scattered into the columns; the result does not depend on the thread
    /// count.
    pub fn forward_rows_from<G>(&mut self, row: G, spectrum: &mut [Complex<T>])
    where
        G: Fn(usize, &mut [T]) + Sync,
    {
        let (rows, half) = (self.rows, self.half_cols());
        assert_eq!(spectrum.len(), self.spectrum_len(), "spectrum length");
        for first in (0..rows).step_by(self.data_rows) {
            let count = self.data_rows.min(rows - first);
            let chunk = per_lane(count, self.lanes.len());
            let r2c = &self.r2c;
            self.work[..count * half]
                .par_chunks_mut(chunk * half)
                .enumerate()
                .zip(self.lanes.par_iter_mut())
                .for_each(|((block, out), lane)| {
                    for (i, row_out) in out.chunks_exact_mut(half).enumerate() {
                        row(first + block * chunk + i, &mut lane.real);
                        r2c.process_with_scratch(&mut lane.real, row_out, &mut lane.scratch)
                            .expect("buffer sizes are fixed at planning");
                    }
                });
            let work = &self.work;
            spectrum
                .par_chunks_mut(rows)
                .enumerate()
                .for_each(|(kx, column)| {
                    for (i, value) in column[first..first + count].iter_mut().enumerate() {
                        *value = work[i * half + kx];
                    }
                });
        }
        let fft = &self.col_forward;
        for_each_column(spectrum, rows, &mut self.lanes, |_, column, scratch| {
            fft.process_with_scratch(column, scratch)
        });
    }

    /// The row pass of a forward transform of `input`, its half spectra transposed into
    /// the columns of `spectrum` (zeros below the data rows), ready for the column pass.
    fn rows_into_columns(&mut self, input: &[f64], spectrum: &mut [Complex<T>]) {
        self.forward_rows(input, |_, _| {});
        transpose_into_columns(
            &self.work,
            spectrum,
            self.data_rows,
            self.half_cols(),
            self.rows,
        );
    }

    /// Real transforms of the `data_rows` input rows, each changed by `prepare(i, row)` and
    /// zero-extended to `cols`, into `work`.
    fn forward_rows(&mut self, input: &[f64], prepare: impl Fn(usize, &mut [T]) + Sync) {
        let (data_cols, half) = (self.data_cols, self.half_cols());
        let chunk = per_lane(self.data_rows, self.lanes.len());
        let r2c = &self.r2c;
        input
            .par_chunks(chunk * data_cols)
            .zip(self.work.par_chunks_mut(chunk * half))
            .enumerate()
            .zip(self.lanes.par_iter_mut())
            .for_each(|((block, (inp, out)), lane)| {
                let rows = inp.chunks_exact(data_cols).zip(out.chunks_exact_mut(half));
                for (r, (row_in, row_out)) in rows.enumerate() {
                    // The transform uses its input as scratch: refill the zeros every row.
                    T::load(&mut lane.real[..data_cols], row_in);
                    prepare(block * chunk + r, &mut lane.real[..data_cols]);
                    lane.real[data_cols..].fill(T::default());
                    r2c.process_with_scratch(&mut lane.real, row_out, &mut lane.scratch)
                        .expect("buffer sizes are fixed at planning");
                }
            });
    }

    /// Inverse real transforms of the `data_rows` rows in `work`, cropped to `data_cols`.
    fn inverse_rows(&mut self, output: &mut [f64]) {
        let (cols, data_cols, half) = (self.cols, self.data_cols, self.half_cols());
        let chunk = per_lane(self.data_rows, self.lanes.len());
        let c2r = &self.c2r;
        self.work
            .par_chunks_mut(chunk * half)
            .zip(output.par_chunks_mut(chunk * data_cols))
            .zip(self.lanes.par_iter_mut())
            .for_each(|((inp, out), lane)| {
                for (row_in, row_out) in inp
                    .chunks_exact_mut(half)
                    .zip(out.chunks_exact_mut(data_cols))
                {
                    row_in[0].im = T::default();
                    if cols % 2 == 0 {
                        row_in[half - 1].im = T::default();
                    }
                    match T::as_own(row_out) {
                        // Double precision, no padding: straight into the output.
                        Some(row_out) if data_cols == cols => c2r
                            .process_with_scratch(row_in, row_out, &mut lane.scratch)
                            .expect("buffer sizes are fixed at planning"),
                        _ => {
                            c2r.process_with_scratch(row_in, &mut lane.real, &mut lane.scratch)
                                .expect("buffer sizes are fixed at planning");
                            T::store(row_out, &lane.real[..data_cols]);
                        }
                    }
                }
            });
    }
}

/// Rows per lane when `total` rows are shared among `lanes` lanes.
fn per_lane(total: usize, lanes: usize) -> usize {
    total.div_ceil(lanes.max(1)).max(1)
}

/// Runs `f(kx, column, scratch)` on every `rows`-long column of the transposed `spectrum`,
/// the columns shared among the lanes in contiguous blocks.
fn for_each_column<T, F>(spectrum: &mut [Complex<T>], rows: usize, lanes: &mut [Lane<T>], f: F)
where
    T: Precision,
    F: Fn(usize, &mut [Complex<T>], &mut [Complex<T>]) + Sync,
{
    let chunk = per_lane(spectrum.len() / rows, lanes.len());
    spectrum
        .par_chunks_mut(chunk * rows)
        .enumerate()
        .zip(lanes.par_iter_mut())
        .for_each(|((block_index, block), lane)| {
            for (i, column) in block.chunks_exact_mut(rows).enumerate() {
                f(block_index * chunk + i, column, &mut lane.scratch);
            }
        });
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

/// `work` (`rows × half`, row-major) into `spectrum` (`half × padded_rows`): column `kx`
/// gets the `rows` values followed by zeros.
fn transpose_into_columns<T: Precision>(
    work: &[Complex<T>],
    spectrum: &mut [Complex<T>],
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
                out_block[dk * padded_rows + rows..(dk + 1) * padded_rows].fill(Complex::default());
            }
        });
}

/// The first `rows` values of every column of `spectrum` (`half × padded_rows`) back into
/// `work` (`rows × half`).
fn transpose_from_columns<T: Precision>(
    spectrum: &[Complex<T>],
    work: &mut [Complex<T>],
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
    use crate::test_support::relative_max_error;
    use num_complex::Complex64;
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

    /// `data` (`data_rows × data_cols`) at the top-left corner of a zero `rows × cols` grid.
    fn embed(
        data: &[f64],
        data_rows: usize,
        data_cols: usize,
        rows: usize,
        cols: usize,
    ) -> Vec<f64> {
        let mut grid = vec![0.0; rows * cols];
        for r in 0..data_rows {
            grid[r * cols..r * cols + data_cols]
                .copy_from_slice(&data[r * data_cols..(r + 1) * data_cols]);
        }
        grid
    }

    const PADDED_SHAPES: [(usize, usize, usize, usize); 5] = [
        (4, 4, 8, 8),
        (5, 7, 10, 14),
        (3, 6, 7, 9),
        (6, 1, 12, 2),
        (1, 5, 1, 10),
    ];

    #[test]
    fn zero_padded_forward_matches_naive_dft_of_the_padded_grid() {
        for (data_rows, data_cols, rows, cols) in PADDED_SHAPES {
            let data = pseudo_random(data_rows * data_cols);
            let mut fft = RealFft2::zero_padded(data_rows, data_cols, rows, cols).unwrap();
            let mut spec = vec![Complex64::new(5.0, -2.0); fft.spectrum_len()];
            fft.forward(&data, &mut spec);
            let oracle = naive_forward(&embed(&data, data_rows, data_cols, rows, cols), rows, cols);
            for (a, b) in spec.iter().zip(&oracle) {
                assert!((a - b).norm() < 1e-12, "{rows}x{cols}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn zero_padded_inverse_returns_the_data_block_of_the_full_inverse() {
        for (data_rows, data_cols, rows, cols) in PADDED_SHAPES {
            // A full-grid signal (not zero outside the block): its spectrum, inverted by
            // the pruned transform, gives back the block, scaled by rows·cols.
            let full = pseudo_random(rows * cols);
            let mut plain = RealFft2::new(rows, cols).unwrap();
            let mut spec = vec![Complex64::default(); plain.spectrum_len()];
            plain.forward(&full, &mut spec);
            let mut pruned = RealFft2::zero_padded(data_rows, data_cols, rows, cols).unwrap();
            let mut block = vec![f64::NAN; data_rows * data_cols];
            pruned.inverse(&mut spec, &mut block);
            let scale = (rows * cols) as f64;
            for r in 0..data_rows {
                for c in 0..data_cols {
                    let (a, b) = (block[r * data_cols + c] / scale, full[r * cols + c]);
                    assert!((a - b).abs() < 1e-14, "{rows}x{cols} ({r},{c}): {a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn convolve_prepared_convolves_the_prepared_rows() {
        // Preparing row i by adding i·j to value j is the convolution of the field with
        // those additions, bit for bit, on plain and padded grids whose rows do not divide
        // evenly among the lanes.
        for (data_rows, data_cols, rows, cols) in [(7, 5, 7, 5), (5, 7, 10, 14), (3, 4, 6, 8)] {
            let data = pseudo_random(data_rows * data_cols);
            let mut fft = RealFft2::zero_padded(data_rows, data_cols, rows, cols).unwrap();
            let filter = |kx: usize, column: &mut [Complex64]| {
                column.iter_mut().for_each(|v| *v *= 1.0 / (1 + kx) as f64);
            };
            let added = |i: usize, j: usize| (i * j) as f64;
            let mut prepared = vec![f64::NAN; data.len()];
            let prepare = |i: usize, row: &mut [f64]| {
                row.iter_mut()
                    .enumerate()
                    .for_each(|(j, v)| *v += added(i, j));
            };
            fft.convolve_prepared(&data, &mut prepared, filter, prepare);
            let changed: Vec<f64> = (0..data.len())
                .map(|k| data[k] + added(k / data_cols, k % data_cols))
                .collect();
            let mut plain = vec![f64::NAN; data.len()];
            fft.convolve(&changed, &mut plain, filter);
            assert_eq!(prepared, plain, "{data_rows}x{data_cols} in {rows}x{cols}");
            assert_ne!(prepared, {
                fft.convolve(&data, &mut plain, filter);
                plain
            });
        }
    }

    #[test]
    fn single_precision_convolves_as_double_to_its_rounding() {
        // The same prepared convolution in f32 and f64 (plain, padded, odd and rectangular
        // grids, rows that do not divide among the lanes): equal to single precision's
        // rounding (2⁻²⁴ ≈ 6e-8 per operation, a few tens deep: 1e-5 of the largest
        // value), and not closer than 1e-9 (the f32 path is really single).
        for (data_rows, data_cols, rows, cols) in [
            (7, 5, 7, 5),
            (16, 24, 16, 24),
            (5, 7, 10, 14),
            (9, 13, 18, 26),
        ] {
            let data = pseudo_random(data_rows * data_cols);
            let gain = |kx: usize| 1.0 / (1 + kx) as f64;
            let mut double = vec![f64::NAN; data.len()];
            RealFft2::zero_padded(data_rows, data_cols, rows, cols)
                .unwrap()
                .convolve_prepared(
                    &data,
                    &mut double,
                    |kx, column: &mut [Complex64]| column.iter_mut().for_each(|v| *v *= gain(kx)),
                    |i, row: &mut [f64]| row.iter_mut().for_each(|v| *v -= i as f64),
                );
            let mut single = vec![f64::NAN; data.len()];
            RealFft2::<f32>::planned(data_rows, data_cols, rows, cols)
                .unwrap()
                .convolve_prepared(
                    &data,
                    &mut single,
                    |kx, column: &mut [Complex<f32>]| {
                        column.iter_mut().for_each(|v| *v *= gain(kx) as f32)
                    },
                    |i, row: &mut [f32]| row.iter_mut().for_each(|v| *v -= i as f32),
                );
            let error = relative_max_error(&double, &single);
            let shape = format!("{data_rows}x{data_cols} in {rows}x{cols}");
            assert!(error < 1e-5, "{shape}: {error} of the largest value");
            assert!(error > 1e-9, "{shape}: f32 computed in double? {error}");
        }
    }

    #[test]
    fn convolve_equals_forward_filter_inverse_and_a_cyclic_direct_sum() {
        // Filter: multiplication by the spectrum of a kernel k on the padded grid, so the
        // result is the cyclic convolution k ⊛ embed(x), cropped: checked against the
        // direct sum and against forward, multiply, inverse done separately.
        for (data_rows, data_cols, rows, cols) in PADDED_SHAPES {
            let data = pseudo_random(data_rows * data_cols);
            let kernel: Vec<f64> = (0..rows * cols)
                .map(|i| ((i * 31 + 7) % 17) as f64 - 8.0)
                .collect();
            let mut plain = RealFft2::new(rows, cols).unwrap();
            let mut kernel_spec = vec![Complex64::default(); plain.spectrum_len()];
            plain.forward(&kernel, &mut kernel_spec);
            let scale = 1.0 / (rows * cols) as f64;
            let mut fft = RealFft2::zero_padded(data_rows, data_cols, rows, cols).unwrap();
            let mut spec = vec![Complex64::default(); fft.spectrum_len()];
            let mut fused = vec![f64::NAN; data_rows * data_cols];
            fft.convolve(&data, &mut fused, |kx, column| {
                for (v, k) in column
                    .iter_mut()
                    .zip(&kernel_spec[kx * rows..(kx + 1) * rows])
                {
                    *v *= k * scale;
                }
            });
            let mut separate = vec![f64::NAN; data_rows * data_cols];
            fft.forward(&data, &mut spec);
            for (v, k) in spec.iter_mut().zip(&kernel_spec) {
                *v *= k * scale;
            }
            fft.inverse(&mut spec, &mut separate);
            let grid = embed(&data, data_rows, data_cols, rows, cols);
            for r in 0..data_rows {
                for c in 0..data_cols {
                    let mut direct = 0.0;
                    for i in 0..rows {
                        for j in 0..cols {
                            let k = kernel[((r + rows - i) % rows) * cols + (c + cols - j) % cols];
                            direct += k * grid[i * cols + j];
                        }
                    }
                    let got = fused[r * data_cols + c];
                    assert!(
                        (got - direct).abs() < 1e-11,
                        "{rows}x{cols} ({r},{c}): {got} vs {direct}"
                    );
                    assert_eq!(got, separate[r * data_cols + c]);
                }
            }
        }
    }

    #[test]
    fn rows_from_a_generator_equal_the_forward_transform_of_the_whole_grid() {
        for (data_rows, data_cols, rows, cols) in PADDED_SHAPES {
            let full = pseudo_random(rows * cols);
            let mut plain = RealFft2::new(rows, cols).unwrap();
            let mut expected = vec![Complex64::default(); plain.spectrum_len()];
            plain.forward(&full, &mut expected);
            let mut padded = RealFft2::zero_padded(data_rows, data_cols, rows, cols).unwrap();
            let mut spec = vec![Complex64::new(3.0, 3.0); padded.spectrum_len()];
            padded.forward_rows_from(
                |r, row| row.copy_from_slice(&full[r * cols..(r + 1) * cols]),
                &mut spec,
            );
            assert_eq!(spec, expected, "{rows}x{cols}");
        }
    }

    #[test]
    fn forward_reduce_sees_the_columns_of_the_forward_transform() {
        // Each column's value is the reduction of that column of `forward`'s spectrum
        // (identical bits), whatever the thread count; padded and plain grids.
        let norms = |kx: usize, column: &[Complex64]| {
            column.iter().map(|v| v.norm_sqr()).sum::<f64>() * (kx + 1) as f64
        };
        for (data_rows, data_cols, rows, cols) in PADDED_SHAPES {
            let data = pseudo_random(data_rows * data_cols);
            let mut fft = RealFft2::zero_padded(data_rows, data_cols, rows, cols).unwrap();
            let mut spectrum = vec![Complex64::default(); fft.spectrum_len()];
            fft.forward(&data, &mut spectrum);
            let expected: Vec<f64> = spectrum
                .chunks(rows)
                .enumerate()
                .map(|(kx, column)| norms(kx, column))
                .collect();
            for threads in [1, 2, 3] {
                let values = crate::test_support::with_threads(threads, || {
                    let mut fft = RealFft2::zero_padded(data_rows, data_cols, rows, cols).unwrap();
                    let mut values = vec![f64::NAN; fft.half_cols()];
                    fft.forward_reduce(&data, &mut values, norms);
                    values
                });
                assert_eq!(values, expected, "{rows}x{cols}, {threads} threads");
            }
        }
    }

    #[test]
    fn padded_results_do_not_depend_on_the_thread_count() {
        let (data_rows, data_cols) = (19, 23);
        let data = pseudo_random(data_rows * data_cols);
        let run = |threads: usize| {
            crate::test_support::with_threads(threads, || {
                let mut fft = RealFft2::zero_padded(data_rows, data_cols, 38, 46).unwrap();
                let mut out = vec![0.0; data_rows * data_cols];
                fft.convolve(&data, &mut out, |kx, column| {
                    column
                        .iter_mut()
                        .enumerate()
                        .for_each(|(ky, v)| *v *= 1.0 / (1.0 + (kx + ky) as f64));
                });
                out
            })
        };
        let one = run(1);
        for threads in [2, 3, 8] {
            assert_eq!(one, run(threads), "{threads} threads");
        }
    }

    #[test]
    fn bad_shapes_are_refused() {
        assert!(RealFft2::new(0, 4).is_err());
        assert!(RealFft2::zero_padded(4, 4, 3, 8).is_err());
        assert!(RealFft2::zero_padded(4, 5, 8, 4).is_err());
        assert!(RealFft2::zero_padded(0, 5, 8, 8).is_err());
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
