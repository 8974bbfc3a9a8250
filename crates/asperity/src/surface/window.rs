//! Windows for the power spectrum of a non-periodic scan: the heights, with their mean
//! removed, are multiplied by a window that falls to zero at the edges before the FFT, so
//! that the jump between opposite edges (which a periodogram takes as part of the surface)
//! does not leak power into every wavenumber.
//!
//! Each window is scaled so that the mean of its square is 1, which keeps the total power
//! of a stationary surface: a windowed PSD stays comparable with an unwindowed one. The
//! shapes are those of SurfaceTopography (Jacobs, Junge & Pastewka, Surf. Topogr. Metrol.
//! Prop. 5, 013001 (2017)): along a line the periodic Hann window, on a map the radial
//! one, so that PSDs computed with the same window agree with it.

use ndarray::{Array1, Array2, ArrayView1, ArrayView2};
use serde::{Deserialize, Serialize};

/// The window applied before a PSD's FFT.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Window {
    /// None: the scan is taken as one period of a periodic surface (right for generated
    /// surfaces, which are periodic).
    #[default]
    None,
    /// Hann: `w = (1 − cos 2πi/n)/2` along a line (periodic form, as `scipy.signal`'s);
    /// on a map the radial `w = (1 + cos πr/r_max)/2` for `r < r_max = min(Lx, Ly)/2`, `r`
    /// the distance from the grid point `(cols/2, rows/2)` (integer halves) in physical
    /// units, and 0 beyond.
    Hann,
}

impl Window {
    /// The window's name, as both front ends spell it.
    pub fn name(self) -> &'static str {
        match self {
            Window::None => "none",
            Window::Hann => "hann",
        }
    }
}

/// `w` scaled so that the mean of `w²` is 1.
fn unit_power(mut w: Vec<f64>) -> Vec<f64> {
    let power = w.iter().map(|v| v * v).sum::<f64>() / w.len().max(1) as f64;
    if power > 0.0 {
        let scale = power.sqrt().recip();
        w.iter_mut().for_each(|v| *v *= scale);
    }
    w
}

/// The Hann window of a line of `n` points (see [`Window::Hann`]), mean square 1.
pub fn hann_1d(n: usize) -> Array1<f64> {
    let tau = std::f64::consts::TAU;
    let w = (0..n)
        .map(|i| 0.5 - 0.5 * (tau * i as f64 / n as f64).cos())
        .collect();
    Array1::from(unit_power(w))
}

/// The radial Hann window of a `rows × cols` map of sizes `size_x × size_y` (see
/// [`Window::Hann`]), mean square 1.
pub fn hann_2d(rows: usize, cols: usize, size_x: f64, size_y: f64) -> Array2<f64> {
    let r_max = size_x.min(size_y) / 2.0;
    let mut w = Vec::with_capacity(rows * cols);
    for row in 0..rows {
        let y = size_y * (row as f64 - (rows / 2) as f64) / rows as f64;
        for col in 0..cols {
            let x = size_x * (col as f64 - (cols / 2) as f64) / cols as f64;
            let r = x.hypot(y);
            w.push(if r > r_max {
                0.0
            } else {
                0.5 + 0.5 * (std::f64::consts::PI * r / r_max).cos()
            });
        }
    }
    Array2::from_shape_vec((rows, cols), unit_power(w)).expect("rows × cols values")
}

/// The heights of a line, mean removed, times `window`.
pub fn windowed_line(heights: ArrayView1<f64>, window: Window) -> Array1<f64> {
    let mean = heights.mean().unwrap_or(0.0);
    let centred = heights.mapv(|h| h - mean);
    match window {
        Window::None => centred,
        Window::Hann => centred * hann_1d(heights.len()),
    }
}

/// The heights of a map of sizes `size_x × size_y`, mean removed, times `window`.
pub fn windowed_map(
    heights: ArrayView2<f64>,
    size_x: f64,
    size_y: f64,
    window: Window,
) -> Array2<f64> {
    let mean = heights.mean().unwrap_or(0.0);
    let centred = heights.mapv(|h| h - mean);
    match window {
        Window::None => centred,
        Window::Hann => {
            let (rows, cols) = heights.dim();
            centred * hann_2d(rows, cols, size_x, size_y)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_keep_the_power_and_vanish_at_the_edge() {
        for n in [7, 8, 64] {
            let w = hann_1d(n);
            assert!((w.mapv(|v| v * v).mean().unwrap() - 1.0).abs() < 1e-14);
            assert_eq!(w[0], 0.0);
            // Periodic Hann: symmetric about n/2, w_i = w_{n-i}.
            for i in 1..n {
                assert!((w[i] - w[n - i]).abs() < 1e-14);
            }
        }
        let w = hann_2d(9, 16, 2.0, 1.0);
        assert!((w.mapv(|v| v * v).mean().unwrap() - 1.0).abs() < 1e-14);
        // Peak at (cols/2, rows/2); zero at the corners, beyond r_max = 0.5.
        let peak = w.iter().cloned().fold(0.0, f64::max);
        assert_eq!(w[(4, 8)], peak);
        assert_eq!(w[(0, 0)], 0.0);
        // Radially symmetric on a square grid: three points right of the centre equal
        // three points below it, and left equals above.
        let w = hann_2d(16, 16, 1.0, 1.0);
        assert!((w[(8, 11)] - w[(11, 8)]).abs() < 1e-15);
        assert!((w[(8, 5)] - w[(5, 8)]).abs() < 1e-15);
    }

    #[test]
    fn no_window_removes_the_mean_only() {
        let h = ndarray::arr1(&[1.0, 2.0, 6.0]);
        assert_eq!(
            windowed_line(h.view(), Window::None),
            ndarray::arr1(&[-2.0, -1.0, 3.0])
        );
    }
}
