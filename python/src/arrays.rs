//! numpy arrays in and out.
//!
//! In: the Python layer hands over float64 arrays in native byte order (it converts any
//! other dtype that casts safely, and big-endian data, with `numpy.asarray`); their strides
//! may be anything. The library's `Surface` and `Line` own their heights, so one copy into a
//! row-major array is made here — the only copy — in whatever order the input is.
//! Out: owned library arrays become numpy arrays without a copy (`into_pyarray`).

use ndarray::{Array1, Array2};
use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArrayDyn};

use crate::errors::invalid;
use pyo3::prelude::*;

/// A row-major copy of a 2D float64 array.
pub fn owned_2d(array: &PyReadonlyArray2<'_, f64>) -> Array2<f64> {
    array.as_array().as_standard_layout().into_owned()
}

/// A contiguous copy of a 1D float64 array.
pub fn owned_1d(array: &PyReadonlyArray1<'_, f64>) -> Array1<f64> {
    array.as_array().as_standard_layout().into_owned()
}

/// A 1D or 2D array (`what` names it in the error).
pub enum Heights {
    /// A line.
    Line(Array1<f64>),
    /// A surface.
    Surface(Array2<f64>),
}

/// Bytes per point of the work on a copied height array (`stats`, `psd`): the copy, its
/// centred copy, the half spectrum and the FFT's buffer, and the PSD's ring sums, as the
/// CLI's `stats` counts them.
const HEIGHTS_WORK_BYTES: usize = 4 * 8 + 12;

/// Refuses, with `MemoryError`, an array whose copy and the work on it
/// (`bytes_per_point` a point) do not fit in the memory available ([`ensure_fits`]): a
/// broadcast array (`numpy.broadcast_to`) of a few bytes can stand for terabytes, and a
/// failed allocation would abort the interpreter.
pub fn ensure_copy_fits(shape: &[usize], bytes_per_point: usize, what: &str) -> PyResult<()> {
    asperity::memory::ensure_fits(
        &format!("copying {what} (shape {shape:?})"),
        asperity::memory::array_bytes(shape, bytes_per_point),
    )
    .map_err(crate::errors::from_error)
}

/// Splits a float64 array of any dimension into a line or a surface.
pub fn heights(array: &PyReadonlyArrayDyn<'_, f64>, what: &str) -> PyResult<Heights> {
    let view = array.as_array();
    ensure_copy_fits(view.shape(), HEIGHTS_WORK_BYTES, what)?;
    match view.ndim() {
        1 => Ok(Heights::Line(
            view.into_dimensionality::<ndarray::Ix1>()
                .expect("1D")
                .as_standard_layout()
                .into_owned(),
        )),
        2 => Ok(Heights::Surface(
            view.into_dimensionality::<ndarray::Ix2>()
                .expect("2D")
                .as_standard_layout()
                .into_owned(),
        )),
        d => Err(invalid(format!(
            "{what}: expected a 1D line or 2D surface, found {d} dimensions"
        ))),
    }
}
