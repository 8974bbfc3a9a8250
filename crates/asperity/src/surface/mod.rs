//! Rough surfaces (2D grids) and rough lines (1D), their synthesis and their statistics.
//!
//! * [`generate`]: Fourier synthesis with random phases — the paper's "inverse Fourier
//!   transform with random phases" for surfaces (eq. 1 with 7/8) and lines (eqs. 9–11, 28).
//! * [`stats`]: rms height, rms slope, rms curvature and the radially averaged PSD.
//!
//! Layout: a [`Surface`] holds `rows × cols` heights, row-major, index `(row, col)` =
//! `(y, x)`; the side along x is `size`, pixels are square with spacing `size / cols`,
//! so the side along y is `size · rows / cols`. A [`Line`] holds `n` heights with spacing
//! `size / n`. Heights are positive up.

pub mod generate;
pub mod stats;
pub mod window;

use ndarray::{Array1, Array2};
use serde::{Deserialize, Serialize};

use crate::{Error, Result};

pub use generate::{LineGenerator, LineSpec, SurfaceGenerator, SurfaceSpec};

/// How a generated realisation is scaled (checked by [`Normalisation::validate`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", content = "value", rename_all = "snake_case")]
pub enum Normalisation {
    /// Scale so that the rms height (about the mean) equals the value.
    RmsHeight(f64),
    /// Scale so that the rms slope (finite differences, see [`stats`]) equals the value.
    RmsSlope(f64),
}

impl Default for Normalisation {
    /// Unit rms height.
    fn default() -> Self {
        Normalisation::RmsHeight(1.0)
    }
}

impl Normalisation {
    /// The parameter that sets it and the requested value.
    pub(crate) fn name_and_value(&self) -> (&'static str, f64) {
        match *self {
            Normalisation::RmsHeight(v) => ("rms_height", v),
            Normalisation::RmsSlope(v) => ("rms_slope", v),
        }
    }

    /// Checks that the target is positive and finite.
    pub fn validate(&self) -> Result<()> {
        let (name, value) = self.name_and_value();
        crate::positive_finite(name, value, "").map(drop)
    }
}

/// Checks a physical side length.
pub(crate) fn validate_size(size: f64) -> Result<()> {
    crate::positive_finite("size", size, "side length").map(drop)
}

/// Checks that the spectrum's wavenumbers fit the grid: a roll-off or cut-off `q0` must lie
/// below the grid's Nyquist wavenumber `nyquist` (both as `q·L/2π`), else the roll-off
/// would flatten every mode (white noise) and the cut-off remove them all; a short
/// cut-off `q1` must keep at least the fundamental, `q1 ≥ 1`.
pub(crate) fn validate_spectrum_on_grid(psd: &crate::spectrum::Psd, nyquist: f64) -> Result<()> {
    use crate::spectrum::LongWavelength;
    let long = match psd.long_wavelength() {
        LongWavelength::None => None,
        LongWavelength::RollOff { q0 } => Some(("rolloff", q0)),
        LongWavelength::CutOff { q0 } => Some(("cutoff", q0)),
    };
    if let Some((name, q0)) = long.filter(|&(_, q0)| q0 >= nyquist) {
        return Err(Error::invalid(
            name,
            format!(
                "q0 = {q0} wavelengths per side is not below the grid's Nyquist wavenumber \
                 {nyquist} (half the points per side): refine the grid or lower q0"
            ),
        ));
    }
    if let Some(q1) = psd.short_cutoff().filter(|&q1| q1 < 1.0) {
        return Err(Error::invalid(
            "short_cutoff",
            format!("q1 = {q1} removes every mode: the longest wavelength is the side (q1 ≥ 1)"),
        ));
    }
    Ok(())
}

/// A rough surface: heights on a grid of pixels `Δx = size_x / cols` by `Δy = size_y / rows`
/// (see the module docs for layout); square unless made by [`Surface::with_sizes`].
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    heights: Array2<f64>,
    size: f64,
    size_y: f64,
}

impl Surface {
    /// Wraps heights with the side length along x; checks for ≥ 2×2, finite values and a
    /// positive size.
    pub fn new(heights: Array2<f64>, size: f64) -> Result<Self> {
        validate_size(size)?;
        if heights.nrows() < 2 || heights.ncols() < 2 {
            return Err(Error::invalid(
                "grid",
                format!(
                    "a surface needs at least 2x2 points, got {:?}",
                    heights.dim()
                ),
            ));
        }
        crate::ensure_finite("surface", heights.iter())?;
        let size_y = size * heights.nrows() as f64 / heights.ncols() as f64;
        Ok(Surface {
            heights,
            size,
            size_y,
        })
    }

    /// Wraps heights with the physical sizes along x (columns) and y (rows), for pixels
    /// that need not be square (measured topographies); the checks of [`Surface::new`].
    pub fn with_sizes(heights: Array2<f64>, size_x: f64, size_y: f64) -> Result<Self> {
        validate_size(size_y)?;
        let mut surface = Surface::new(heights, size_x)?;
        surface.size_y = size_y;
        Ok(surface)
    }

    /// Side length along y (rows).
    pub fn size_y(&self) -> f64 {
        self.size_y
    }

    /// Pixel spacing along y, `size_y / rows`.
    pub fn spacing_y(&self) -> f64 {
        self.size_y / self.heights.nrows() as f64
    }

    /// Whether `Δx = Δy` to rounding (relative 1e-12).
    pub fn has_square_pixels(&self) -> bool {
        let (dx, dy) = (self.spacing(), self.spacing_y());
        (dx - dy).abs() <= 1e-12 * dx.max(dy)
    }

    /// Heights, `rows × cols`.
    pub fn heights(&self) -> &Array2<f64> {
        &self.heights
    }

    /// Consumes the surface, returning its heights.
    pub fn into_heights(self) -> Array2<f64> {
        self.heights
    }

    /// Side length along x (columns), `size_x`.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// Pixel spacing along x, `size / cols` (`Δx`).
    pub fn spacing(&self) -> f64 {
        self.size / self.heights.ncols() as f64
    }

    /// `(rows, cols)`.
    pub fn dim(&self) -> (usize, usize) {
        self.heights.dim()
    }
}

/// A rough line: heights at spacing `size / n`.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    heights: Array1<f64>,
    size: f64,
}

impl Line {
    /// Wraps heights with the line's length; checks for ≥ 2 points, finite values and a
    /// positive size.
    pub fn new(heights: Array1<f64>, size: f64) -> Result<Self> {
        validate_size(size)?;
        if heights.len() < 2 {
            return Err(Error::invalid(
                "grid",
                format!("a line needs at least 2 points, got {}", heights.len()),
            ));
        }
        crate::ensure_finite("line", heights.iter())?;
        Ok(Line { heights, size })
    }

    /// Heights.
    pub fn heights(&self) -> &Array1<f64> {
        &self.heights
    }

    /// Consumes the line, returning its heights.
    pub fn into_heights(self) -> Array1<f64> {
        self.heights
    }

    /// Length of the line.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// Point spacing `size / n`.
    pub fn spacing(&self) -> f64 {
        self.size / self.heights.len() as f64
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.heights.len()
    }

    /// Always false: a line has at least two points.
    pub fn is_empty(&self) -> bool {
        self.heights.is_empty()
    }
}
