//! Fourier synthesis of rough surfaces and lines with random phases.
//!
//! Each Fourier mode gets the amplitude `sqrt(C(q))` of the requested spectrum and a phase
//! drawn uniformly in `[0, 2π)`; Hermitian symmetry (`h(-q) = conj h(q)`) makes the heights
//! real. Modes that are their own conjugate (the Nyquist rows and columns of even grids) get
//! a random sign instead of a phase; the mean (`q = 0`) is zero. This is the paper's
//! "inverse Fourier transform with random phases" — eq. (1) with (7)/(8) for surfaces, and
//! eqs. (9)–(11) with `C1D = π q C2D` (28) for lines, all modes from `2π/L` to the Nyquist
//! wavenumber. The realisation is then scaled to the requested [`Normalisation`], exactly
//! (to rounding) for *this* realisation.
//!
//! # Determinism
//! Phases come from `ChaCha8Rng::seed_from_u64(seed)`, one stream per `kx` (surfaces) or a
//! single stream (lines), never from a thread-local or shared generator: the same seed
//! gives bit-identical heights whatever the number of threads.
//!
//! # Example
//! ```
//! use asperity::spectrum::Psd;
//! use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};
//! let spec = SurfaceSpec::new(64, 64, 1.0, Psd::power_law(0.8)?, Normalisation::RmsSlope(1.0))?;
//! let surface = SurfaceGenerator::new(&spec)?.generate(42);
//! let slope = asperity::surface::stats::rms_slope_2d(surface.heights().view(), surface.spacing());
//! assert!((slope - 1.0).abs() < 1e-12);
//! # Ok::<(), asperity::Error>(())
//! ```

use num_complex::Complex64;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

use super::{stats, validate_size, validate_spectrum_on_grid, Line, Normalisation, Surface};
use crate::fft::RealFft2;
use crate::memory::{array_bytes, ensure_fits, try_vec};
use crate::spectrum::Psd;
use crate::{Error, Result};

/// What to generate: grid, side length, spectrum and normalisation. Built only by
/// [`SurfaceSpec::new`] (also when read back from JSON), so every value is a valid one:
/// the generator relies on it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SurfaceSpecFields")]
pub struct SurfaceSpec {
    rows: usize,
    cols: usize,
    size: f64,
    psd: Psd,
    normalisation: Normalisation,
}

/// The fields of a [`SurfaceSpec`] as stored, before [`SurfaceSpec::new`] checks them.
#[derive(Deserialize)]
struct SurfaceSpecFields {
    rows: usize,
    cols: usize,
    size: f64,
    psd: Psd,
    normalisation: Normalisation,
}

impl TryFrom<SurfaceSpecFields> for SurfaceSpec {
    type Error = Error;

    fn try_from(f: SurfaceSpecFields) -> Result<Self> {
        SurfaceSpec::new(f.rows, f.cols, f.size, f.psd, f.normalisation)
    }
}

impl SurfaceSpec {
    /// Grid rows (y).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Grid columns (x).
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Side length along x.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// Spectrum shape.
    pub fn psd(&self) -> Psd {
        self.psd
    }

    /// Scaling of each realisation.
    pub fn normalisation(&self) -> Normalisation {
        self.normalisation
    }

    /// Checks the grid (at least 2×2), the size and the normalisation.
    pub fn new(
        rows: usize,
        cols: usize,
        size: f64,
        psd: Psd,
        normalisation: Normalisation,
    ) -> Result<Self> {
        if rows < 2 || cols < 2 {
            // Name the count that is wrong: `m` (rows) when only it is, else `n` (columns).
            let param = if cols >= 2 { "m" } else { "n" };
            return Err(Error::invalid(
                param,
                format!("grid must be at least 2x2, got {rows}x{cols}"),
            ));
        }
        validate_size(size)?;
        normalisation.validate()?;
        // Square pixels of side L/cols: the Nyquist wavenumber along either axis is cols/2.
        validate_spectrum_on_grid(&psd, cols as f64 / 2.0)?;
        Ok(SurfaceSpec {
            rows,
            cols,
            size,
            psd,
            normalisation,
        })
    }
}

/// Generates surfaces of one [`SurfaceSpec`], reusing its FFT plan and buffers.
pub struct SurfaceGenerator {
    spec: SurfaceSpec,
    fft: RealFft2,
    spectrum: Vec<Complex64>,
}

/// A unit complex number with uniformly distributed phase.
///
/// Drawn by rejection from the unit disk (a point uniform in the disk has a uniform angle),
/// which avoids a `sin_cos` per mode; the sequence is deterministic for a given stream.
fn random_phase(rng: &mut ChaCha8Rng) -> Complex64 {
    loop {
        let x = 2.0 * rng.random::<f64>() - 1.0;
        let y = 2.0 * rng.random::<f64>() - 1.0;
        let r2 = x * x + y * y;
        if r2 > 1e-12 && r2 <= 1.0 {
            let inv = 1.0 / r2.sqrt();
            return Complex64::new(x * inv, y * inv);
        }
    }
}

fn random_sign(rng: &mut ChaCha8Rng) -> f64 {
    if rng.random::<bool>() {
        1.0
    } else {
        -1.0
    }
}

/// Peak memory of generating a `rows`×`cols` surface, in bytes (`None` on overflow): the
/// heights (8 B per point), the half spectrum and the FFT's work buffer (2 × 16 B per point
/// of the `rows × (cols/2 + 1)` half grid, so a narrow grid costs up to 32 B per point), and
/// the plans and scratch of the transforms along each axis, which grow with the length of
/// that axis (measured with rustfft on 4 000 000 × 2 and 2 × 4 000 000 grids: about 75 B
/// per row and 42 B per column; 96 and 64 are taken), and never less than 32 B per point.
pub fn surface_generation_bytes(rows: usize, cols: usize) -> Option<u64> {
    let heights = array_bytes(&[rows, cols], 8)?;
    let half = array_bytes(&[rows, cols / 2 + 1], 2 * 16)?;
    let plans = array_bytes(&[rows], 96)?.checked_add(array_bytes(&[cols], 64)?)?;
    let estimate = heights.checked_add(half)?.checked_add(plans)?;
    // Never below the flat 32 B per point that square grids have always been sized with.
    Some(estimate.max(array_bytes(&[rows, cols], 32)?))
}

impl SurfaceGenerator {
    /// Plans the transforms; fails if the grid would not fit in memory.
    pub fn new(spec: &SurfaceSpec) -> Result<Self> {
        let what = format!("a {}x{} surface", spec.rows, spec.cols);
        ensure_fits(&what, surface_generation_bytes(spec.rows, spec.cols))?;
        let fft = RealFft2::new(spec.rows, spec.cols)?;
        let spectrum = try_vec(&what, fft.spectrum_len(), Complex64::default())?;
        Ok(SurfaceGenerator {
            spec: *spec,
            fft,
            spectrum,
        })
    }

    /// The specification this generator draws from.
    pub fn spec(&self) -> &SurfaceSpec {
        &self.spec
    }

    /// One realisation for `seed`.
    pub fn generate(&mut self, seed: u64) -> Surface {
        let mut heights = ndarray::Array2::zeros((self.spec.rows, self.spec.cols));
        self.generate_into(seed, heights.as_slice_mut().expect("standard layout"))
            .expect("a validated spec has power on its grid");
        let size_y = self.spec.size * self.spec.rows as f64 / self.spec.cols as f64;
        Surface {
            heights,
            size: self.spec.size,
            size_y,
        }
    }

    /// One realisation for `seed`. Fails if the spectrum has no power on this grid (e.g. a
    /// cut-off above Nyquist) or the heights cannot be allocated.
    pub fn try_generate(&mut self, seed: u64) -> Result<Surface> {
        let SurfaceSpec { rows, cols, .. } = self.spec;
        let mut heights = try_vec(&format!("a {rows}x{cols} surface"), rows * cols, 0.0)?;
        self.generate_into(seed, &mut heights)?;
        let heights = ndarray::Array2::from_shape_vec((rows, cols), heights)
            .map_err(|e| Error::invalid("grid", e.to_string()))?;
        let size_y = self.spec.size * rows as f64 / cols as f64;
        Ok(Surface {
            heights,
            size: self.spec.size,
            size_y,
        })
    }

    /// Writes a realisation into `heights` (`rows × cols`, row-major).
    pub fn generate_into(&mut self, seed: u64, heights: &mut [f64]) -> Result<()> {
        let SurfaceSpec {
            rows, cols, psd, ..
        } = self.spec;
        // κ_y = ky · (L / Ly) because Ly = L·rows/cols.
        let aspect = cols as f64 / rows as f64;
        let nyquist_x = (cols % 2 == 0).then_some(cols / 2);
        let nyquist_y = (rows % 2 == 0).then_some(rows / 2);
        self.spectrum
            .par_chunks_mut(rows)
            .enumerate()
            .for_each(|(kx, column)| {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                rng.set_stream(kx as u64);
                for (ky_index, value) in column.iter_mut().enumerate() {
                    let ky = if ky_index <= rows / 2 {
                        ky_index as f64
                    } else {
                        ky_index as f64 - rows as f64
                    };
                    let kappa_sq = (kx * kx) as f64 + (ky * aspect).powi(2);
                    let amplitude = psd.sqrt_c2d_of_squared(kappa_sq);
                    *value = amplitude * random_phase(&mut rng);
                }
                // Columns kx = 0 and kx = Nyquist hold both ±ky: impose h(-ky) = conj h(ky).
                if kx == 0 || Some(kx) == nyquist_x {
                    for ky_index in rows / 2 + 1..rows {
                        column[ky_index] = column[rows - ky_index].conj();
                    }
                    for self_conjugate in std::iter::once(0).chain(nyquist_y) {
                        let v = &mut column[self_conjugate];
                        *v = Complex64::new(v.norm() * random_sign(&mut rng), 0.0);
                    }
                }
            });
        self.fft.inverse(&mut self.spectrum, heights);
        let view = ndarray::ArrayView2::from_shape((rows, cols), &*heights).expect("shape");
        let realised = match self.spec.normalisation {
            Normalisation::RmsHeight(_) => stats::rms_height_2d(view),
            Normalisation::RmsSlope(_) => stats::rms_slope_2d(view, self.spec.size / cols as f64),
        };
        scale_to(heights, realised, self.spec.normalisation)
    }
}

fn scale_to(heights: &mut [f64], realised: f64, target: Normalisation) -> Result<()> {
    let want = match target {
        Normalisation::RmsHeight(v) | Normalisation::RmsSlope(v) => v,
    };
    if !crate::is_positive_finite(realised) {
        return Err(Error::invalid(
            "spectrum",
            "no power on this grid (is the cut-off above the grid's Nyquist wavenumber?)",
        ));
    }
    let factor = want / realised;
    // Beyond 1e150 in magnitude, squares (rms, slopes, the solvers' norms) overflow.
    const LARGEST: f64 = 1e150;
    let largest = heights
        .par_iter_mut()
        .map(|h| {
            *h *= factor;
            h.abs()
        })
        .reduce(|| 0.0, f64::max);
    // NaN compares false, so it is refused too.
    if largest.partial_cmp(&LARGEST) != Some(std::cmp::Ordering::Less) {
        let (name, _) = target.name_and_value();
        return Err(Error::invalid(
            name,
            format!(
                "{want} would make heights of {largest:e}, beyond {LARGEST:e} where their \
                 squares overflow: express the lengths in a larger unit"
            ),
        ));
    }
    Ok(())
}

/// What line to generate: points, length, spectrum (given as the 2D spectrum it is a
/// cut through; the line uses `C1D = π q C2D`, eq. 28) and normalisation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineSpec {
    /// Number of points.
    pub n: usize,
    /// Length of the line.
    pub size: f64,
    /// The 2D spectrum shape the line represents.
    pub psd: Psd,
    /// Scaling of each realisation.
    pub normalisation: Normalisation,
}

impl LineSpec {
    /// Checks `n ≥ 2`, the size and the normalisation.
    pub fn new(n: usize, size: f64, psd: Psd, normalisation: Normalisation) -> Result<Self> {
        if n < 2 {
            return Err(Error::invalid(
                "n",
                format!("a line needs at least 2 points, got {n}"),
            ));
        }
        validate_size(size)?;
        normalisation.validate()?;
        validate_spectrum_on_grid(&psd, n as f64 / 2.0)?;
        Ok(LineSpec {
            n,
            size,
            psd,
            normalisation,
        })
    }
}

/// Generates rough lines of one [`LineSpec`], eqs. (9)–(11), reusing plan and buffers.
pub struct LineGenerator {
    spec: LineSpec,
    c2r: Arc<dyn ComplexToReal<f64>>,
    amplitudes: Vec<f64>,
    spectrum: Vec<Complex64>,
    scratch: Vec<Complex64>,
}

impl LineGenerator {
    /// Plans the inverse real FFT of length `n` and tabulates the amplitudes `B(q)` (10).
    pub fn new(spec: &LineSpec) -> Result<Self> {
        let what = format!("a line of {} points", spec.n);
        ensure_fits(&what, array_bytes(&[spec.n], 8 + 16 + 16))?;
        let c2r = RealFftPlanner::<f64>::new().plan_fft_inverse(spec.n);
        let half = spec.n / 2 + 1;
        let mut amplitudes = try_vec(&what, half, 0.0)?;
        for (k, a) in amplitudes.iter_mut().enumerate() {
            *a = spec.psd.c1d(k as f64).sqrt();
        }
        let scratch = try_vec(&what, c2r.get_scratch_len(), Complex64::default())?;
        let spectrum = try_vec(&what, half, Complex64::default())?;
        Ok(LineGenerator {
            spec: *spec,
            c2r,
            amplitudes,
            spectrum,
            scratch,
        })
    }

    /// The specification this generator draws from.
    pub fn spec(&self) -> &LineSpec {
        &self.spec
    }

    /// One realisation for `seed`.
    pub fn generate(&mut self, seed: u64) -> Line {
        let mut heights = ndarray::Array1::zeros(self.spec.n);
        self.generate_into(seed, heights.as_slice_mut().expect("contiguous"))
            .expect("a line spectrum always has power at q = 2π/L unless cut off");
        Line {
            heights,
            size: self.spec.size,
        }
    }

    /// One realisation for `seed`, failing if the spectrum has no power on this grid or
    /// the heights cannot be allocated.
    pub fn try_generate(&mut self, seed: u64) -> Result<Line> {
        let n = self.spec.n;
        let mut heights = try_vec(&format!("a line of {n} points"), n, 0.0)?;
        self.generate_into(seed, &mut heights)?;
        let heights = ndarray::Array1::from_vec(heights);
        Ok(Line {
            heights,
            size: self.spec.size,
        })
    }

    /// Writes a realisation into `heights` (length `n`).
    pub fn generate_into(&mut self, seed: u64, heights: &mut [f64]) -> Result<()> {
        let n = self.spec.n;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for (value, &amplitude) in self.spectrum.iter_mut().zip(&self.amplitudes) {
            *value = amplitude * random_phase(&mut rng);
        }
        self.spectrum[0] = Complex64::default();
        if n.is_multiple_of(2) {
            let v = &mut self.spectrum[n / 2];
            *v = Complex64::new(v.norm() * random_sign(&mut rng), 0.0);
        }
        self.c2r
            .process_with_scratch(&mut self.spectrum, heights, &mut self.scratch)
            .expect("buffer sizes fixed at planning");
        let realised = match self.spec.normalisation {
            Normalisation::RmsHeight(_) => stats::rms_height(heights.iter().copied()),
            Normalisation::RmsSlope(_) => stats::rms_slope_1d(heights, self.spec.size / n as f64),
        };
        scale_to(heights, realised, self.spec.normalisation)
    }
}

#[cfg(test)]
mod memory_estimate_tests {
    use super::surface_generation_bytes;

    #[test]
    fn elongated_grids_are_not_underestimated() {
        // Peak resident memory measured with /usr/bin/time for `asperity surface` (which
        // also holds the binary: 6 MiB for a 16x16 surface): 4 000 000 × 2 used 586 MiB and
        // 2 × 4 000 000 used 341 MiB, while the old estimate (32 B per point) gave 244 MiB
        // for both; 2000 × 4000 used 189 MiB.
        let mib = |b: Option<u64>| b.unwrap() as f64 / (1 << 20) as f64;
        assert!(mib(surface_generation_bytes(4_000_000, 2)) >= 586.0 - 6.0);
        assert!(mib(surface_generation_bytes(2, 4_000_000)) >= 341.0 - 6.0);
        assert!(mib(surface_generation_bytes(2000, 4000)) >= 189.0 - 6.0);
        // Not wildly above either (the guard should not refuse what fits).
        assert!(mib(surface_generation_bytes(2000, 4000)) < 1.3 * 189.0);
        assert_eq!(surface_generation_bytes(usize::MAX, 3), None);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::power_law_fit;
    use crate::spectrum::LongWavelength;
    use crate::surface::stats::{line_psd, radial_psd_2d, rms_slope_1d, rms_slope_2d};

    fn surface_spec(rows: usize, cols: usize, hurst: f64, norm: Normalisation) -> SurfaceSpec {
        SurfaceSpec::new(rows, cols, 1.0, Psd::power_law(hurst).unwrap(), norm).unwrap()
    }

    #[test]
    fn a_spec_read_from_json_is_checked_like_a_new_one() {
        let spec = surface_spec(16, 32, 0.5, Normalisation::RmsSlope(1.0));
        let text = serde_json::to_string(&spec).unwrap();
        assert_eq!(serde_json::from_str::<SurfaceSpec>(&text).unwrap(), spec);
        // A 1-row grid: refused by new, and so when read back (it would panic in generate).
        let bad = text.replace("\"rows\":16", "\"rows\":1");
        assert_ne!(bad, text);
        let err = serde_json::from_str::<SurfaceSpec>(&bad).unwrap_err();
        assert!(err.to_string().contains("at least 2x2"), "{err}");
        let err =
            serde_json::from_str::<SurfaceSpec>(&text.replace("\"size\":1.0", "\"size\":-1.0"))
                .unwrap_err();
        assert!(err.to_string().contains("size"), "{err}");
    }

    /// A grid below 2x2 names the count that is wrong: `m` (the rows) when only it is,
    /// else `n` (the columns; both when both are).
    #[test]
    fn a_grid_too_small_names_the_count_that_is() {
        let refused = |rows, cols| {
            let psd = Psd::power_law(0.5).unwrap();
            SurfaceSpec::new(rows, cols, 1.0, psd, Normalisation::RmsHeight(1.0))
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            refused(0, 16),
            "invalid m: grid must be at least 2x2, got 0x16"
        );
        assert_eq!(
            refused(16, 1),
            "invalid n: grid must be at least 2x2, got 16x1"
        );
        assert_eq!(
            refused(1, 1),
            "invalid n: grid must be at least 2x2, got 1x1"
        );
    }

    /// Slope of the ensemble-averaged radial PSD, fitted over κ ∈ [4, κ_max].
    fn fitted_psd_exponent_2d(hurst: f64, realisations: u64) -> f64 {
        let spec = surface_spec(128, 128, hurst, Normalisation::RmsHeight(1.0));
        let mut generator = SurfaceGenerator::new(&spec).unwrap();
        let mut mean: Vec<(f64, f64)> = Vec::new();
        for seed in 0..realisations {
            let psd = radial_psd_2d(&generator.generate(seed)).unwrap();
            if mean.is_empty() {
                mean = psd.iter().map(|b| (b.q, 0.0)).collect();
            }
            for (m, b) in mean.iter_mut().zip(&psd) {
                m.1 += b.psd / realisations as f64;
            }
        }
        let kappa_of = |q: f64| q / std::f64::consts::TAU;
        let (q, c): (Vec<f64>, Vec<f64>) = mean
            .into_iter()
            .filter(|(q, _)| kappa_of(*q) >= 4.0)
            .unzip();
        power_law_fit(&q, &c).unwrap().exponent
    }

    #[test]
    fn surface_psd_follows_power_law() {
        // Random phases give each mode exactly its target power; what remains is the radial
        // binning of lattice points and the two self-conjugate Nyquist lines, so 0.05 on the
        // exponent is generous for κ ≥ 4 (steep spectra are most sensitive to binning).
        for hurst in [-0.5, 0.5, 0.8, 2.5] {
            let exponent = fitted_psd_exponent_2d(hurst, 8);
            let expected = -2.0 * hurst - 2.0;
            assert!(
                (exponent - expected).abs() < 0.05,
                "H = {hurst}: slope {exponent} vs {expected}"
            );
        }
    }

    #[test]
    fn line_psd_follows_power_law() {
        for hurst in [-0.5, 0.5, 0.8, 2.5] {
            let spec = LineSpec::new(
                4096,
                1.0,
                Psd::power_law(hurst).unwrap(),
                Normalisation::RmsHeight(1.0),
            )
            .unwrap();
            let mut generator = LineGenerator::new(&spec).unwrap();
            let mut mean = vec![0.0; 2048];
            let mut q = vec![0.0; 2048];
            for seed in 0..8 {
                for (i, b) in line_psd(&generator.generate(seed))
                    .iter()
                    .take(2048)
                    .enumerate()
                {
                    q[i] = b.q;
                    mean[i] += b.psd / 8.0;
                }
            }
            // Exactly the target power in each mode, so the fit is exact but for rounding.
            let fit = power_law_fit(&q[..2047], &mean[..2047]).unwrap();
            let expected = -2.0 * hurst - 1.0;
            assert!(
                (fit.exponent - expected).abs() < 1e-6,
                "H = {hurst}: {} vs {expected}",
                fit.exponent
            );
        }
    }

    #[test]
    fn roll_off_flat_and_cut_off_empty_below_q0() {
        let q0 = 6.0;
        for (long, flat) in [
            (LongWavelength::RollOff { q0 }, true),
            (LongWavelength::CutOff { q0 }, false),
        ] {
            let psd = Psd::new(0.8, long, None).unwrap();
            let spec = SurfaceSpec::new(64, 64, 1.0, psd, Normalisation::RmsHeight(1.0)).unwrap();
            let bins = radial_psd_2d(&SurfaceGenerator::new(&spec).unwrap().generate(3)).unwrap();
            let kappa = |q: f64| q / std::f64::consts::TAU;
            let at_q0 = bins
                .iter()
                .find(|b| (kappa(b.q) - q0).abs() < 0.5)
                .unwrap()
                .psd;
            for b in bins.iter().filter(|b| kappa(b.q) < q0 - 0.5) {
                if flat {
                    assert!(
                        (b.psd / at_q0 - 1.0).abs() < 0.25,
                        "roll-off bin κ={} ratio {}",
                        kappa(b.q),
                        b.psd / at_q0
                    );
                } else {
                    assert!(
                        b.psd < 1e-20 * at_q0,
                        "cut-off bin κ={} has power {}",
                        kappa(b.q),
                        b.psd
                    );
                }
            }
        }
    }

    #[test]
    fn normalisation_is_exact() {
        for (rows, cols) in [(64, 64), (33, 47), (40, 90)] {
            let h = SurfaceGenerator::new(&surface_spec(
                rows,
                cols,
                0.8,
                Normalisation::RmsHeight(2.5),
            ))
            .unwrap()
            .generate(1);
            let rms = stats::rms_height(h.heights().iter().copied());
            assert!((rms / 2.5 - 1.0).abs() < 1e-10, "{rows}x{cols}: {rms}");
            let s =
                SurfaceGenerator::new(&surface_spec(rows, cols, 0.3, Normalisation::RmsSlope(0.7)))
                    .unwrap()
                    .generate(1);
            let slope = rms_slope_2d(s.heights().view(), s.spacing());
            assert!((slope / 0.7 - 1.0).abs() < 1e-10, "{rows}x{cols}: {slope}");
        }
        let line_spec = LineSpec::new(
            1001,
            2.0,
            Psd::power_law(1.0).unwrap(),
            Normalisation::RmsSlope(0.3),
        )
        .unwrap();
        let line = LineGenerator::new(&line_spec).unwrap().generate(5);
        let slope = rms_slope_1d(line.heights().as_slice().unwrap(), line.spacing());
        assert!((slope / 0.3 - 1.0).abs() < 1e-10);
        for (n, hurst, long) in [
            (1001, 0.8, LongWavelength::None),
            (4096, -0.5, LongWavelength::RollOff { q0: 6.0 }),
            (4097, 2.5, LongWavelength::CutOff { q0: 3.0 }),
        ] {
            let psd = Psd::new(hurst, long, None).unwrap();
            let spec = LineSpec::new(n, 3.0, psd, Normalisation::RmsHeight(0.02)).unwrap();
            let line = LineGenerator::new(&spec).unwrap().generate(11);
            let rms = stats::rms_height(line.heights().iter().copied());
            assert!(
                (rms / 0.02 - 1.0).abs() < 1e-10,
                "n = {n}, H = {hurst}: {rms}"
            );
        }
    }

    #[test]
    fn same_seed_same_bits_whatever_the_thread_count() {
        let spec = surface_spec(96, 130, 0.8, Normalisation::RmsHeight(1.0));
        let run = |threads: usize| {
            crate::test_support::with_threads(threads, || {
                SurfaceGenerator::new(&spec).unwrap().generate(77)
            })
        };
        let reference = run(1);
        for threads in [2, 3, 7] {
            assert!(run(threads)
                .heights()
                .iter()
                .zip(reference.heights())
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        assert_ne!(
            SurfaceGenerator::new(&spec).unwrap().generate(78),
            reference
        );
    }

    /// Checks every Fourier mode of a generated surface against `sqrt(C2D)` up to one
    /// common factor (and empty modes empty).
    fn assert_modes_follow_spectrum(spec: &SurfaceSpec, label: &str) {
        let (rows, cols) = (spec.rows, spec.cols);
        let s = SurfaceGenerator::new(spec).unwrap().generate(9);
        let mean = s.heights().mean().unwrap();
        assert!(mean.abs() < 1e-12, "{label}: mean {mean}");
        let mut fft = RealFft2::new(rows, cols).unwrap();
        let mut spectrum = vec![Complex64::default(); fft.spectrum_len()];
        fft.forward(s.heights().as_slice().unwrap(), &mut spectrum);
        let aspect = cols as f64 / rows as f64;
        let mut ratio = None;
        let (mut full, mut empty) = (0, 0);
        for (kx, column) in spectrum.chunks(rows).enumerate() {
            for (ky_index, value) in column.iter().enumerate() {
                let ky = if ky_index <= rows / 2 {
                    ky_index as f64
                } else {
                    ky_index as f64 - rows as f64
                };
                let target = spec.psd.c2d((kx as f64).hypot(ky * aspect)).sqrt();
                if target == 0.0 {
                    assert!(
                        value.norm() < 1e-9,
                        "{label}: mode ({kx},{ky}) should be empty, has {}",
                        value.norm()
                    );
                    empty += 1;
                    continue;
                }
                let r = value.norm() / target;
                let r0 = *ratio.get_or_insert(r);
                assert!(
                    (r / r0 - 1.0).abs() < 1e-9,
                    "{label}: mode ({kx},{ky}) ratio {r} vs {r0}"
                );
                full += 1;
            }
        }
        assert!(full > 0, "{label}: no mode has power");
        assert!(empty > 0, "{label}: at least the mean is empty");
    }

    #[test]
    fn every_mode_keeps_its_amplitude_on_odd_even_grids() {
        // If Hermitian symmetry were broken, the inverse real FFT would drop part of some
        // modes; the forward FFT of the heights would then not reproduce sqrt(C2D) · const.
        for (rows, cols) in [(2, 2), (3, 3), (16, 16), (17, 16), (16, 17), (5, 64)] {
            let spec = surface_spec(rows, cols, 0.5, Normalisation::RmsHeight(1.0));
            assert_modes_follow_spectrum(&spec, &format!("{rows}x{cols}"));
        }
    }

    #[test]
    fn roll_off_cut_off_and_short_cut_off_hold_mode_by_mode_on_odd_and_rectangular_grids() {
        // Roll-off: modes below q0 all at the amplitude of q0 (flat); cut-off: modes below
        // q0 empty; short cut-off: modes above q1 empty. Checked on every mode, against
        // C2D of eqs. (7)/(8), on odd, even and rectangular grids (κ_y = ky·cols/rows).
        let spectra = [
            ("roll-off", LongWavelength::RollOff { q0: 4.0 }, None),
            ("cut-off", LongWavelength::CutOff { q0: 4.0 }, None),
            ("short cut-off", LongWavelength::None, Some(9.0)),
            (
                "roll-off + short",
                LongWavelength::RollOff { q0: 3.0 },
                Some(7.5),
            ),
            (
                "cut-off + short",
                LongWavelength::CutOff { q0: 2.5 },
                Some(11.0),
            ),
        ];
        for (name, long, short) in spectra {
            for (rows, cols) in [(33, 33), (32, 32), (17, 48), (48, 17), (31, 40)] {
                for hurst in [-0.5, 0.8] {
                    let psd = Psd::new(hurst, long, short).unwrap();
                    let spec = SurfaceSpec::new(rows, cols, 1.0, psd, Normalisation::RmsSlope(1.0))
                        .unwrap();
                    assert_modes_follow_spectrum(
                        &spec,
                        &format!("{name}, {rows}x{cols}, H {hurst}"),
                    );
                }
            }
        }
    }

    #[test]
    fn line_roll_off_flat_and_cut_off_empty_below_q0() {
        // On a line, C1D = π q C2D (28): below a roll-off C2D is flat, so C1D/q is constant;
        // below a cut-off C1D is zero; above q0 every mode has exactly its power (random
        // phases), for odd and even n.
        let q0 = 6.0;
        for n in [1024, 1025] {
            for (long, flat) in [
                (LongWavelength::RollOff { q0 }, true),
                (LongWavelength::CutOff { q0 }, false),
            ] {
                let psd = Psd::new(0.8, long, None).unwrap();
                let spec = LineSpec::new(n, 1.0, psd, Normalisation::RmsHeight(1.0)).unwrap();
                let bins = line_psd(&LineGenerator::new(&spec).unwrap().generate(3));
                let kappa = |q: f64| q / std::f64::consts::TAU;
                let at_q0 = bins.iter().find(|b| kappa(b.q) == q0).unwrap();
                // Below n/2 (the Nyquist mode of an even line carries a random sign only).
                for b in bins.iter().filter(|b| kappa(b.q) < (n / 2) as f64) {
                    let k = kappa(b.q);
                    if k < q0 {
                        if flat {
                            let ratio = (b.psd / k) / (at_q0.psd / q0);
                            assert!((ratio - 1.0).abs() < 1e-9, "n {n}: roll-off κ={k}: {ratio}");
                        } else {
                            assert!(b.psd < 1e-20 * at_q0.psd, "n {n}: cut-off κ={k}: {}", b.psd);
                        }
                    }
                    let expected = psd.c1d(k) / psd.c1d(q0);
                    let got = b.psd / at_q0.psd;
                    if expected > 0.0 {
                        assert!(
                            (got / expected - 1.0).abs() < 1e-9,
                            "n {n}: κ={k}: {got} vs {expected}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn heights_too_large_to_square_are_refused() {
        let psd = Psd::power_law(0.5).unwrap();
        let huge = Normalisation::RmsHeight(1e160);
        let spec = SurfaceSpec::new(16, 16, 1.0, psd, huge).unwrap();
        let err = SurfaceGenerator::new(&spec)
            .unwrap()
            .try_generate(1)
            .unwrap_err();
        assert!(err.to_string().contains("rms_height"), "{err}");
        let spec = LineSpec::new(64, 1.0, psd, huge).unwrap();
        assert!(LineGenerator::new(&spec).unwrap().try_generate(1).is_err());
        let fine = SurfaceSpec::new(16, 16, 1.0, psd, Normalisation::RmsHeight(1e100)).unwrap();
        assert!(SurfaceGenerator::new(&fine)
            .unwrap()
            .try_generate(1)
            .is_ok());
    }

    #[test]
    fn wavenumbers_beyond_the_grid_are_refused_by_the_spec() {
        let height = Normalisation::RmsHeight(1.0);
        for long in [
            LongWavelength::CutOff { q0: 100.0 },
            LongWavelength::RollOff { q0: 100.0 },
            LongWavelength::RollOff { q0: 8.0 }, // = Nyquist of 16 points per side
        ] {
            let psd = Psd::new(0.5, long, None).unwrap();
            let err = SurfaceSpec::new(16, 16, 1.0, psd, height).unwrap_err();
            assert!(err.to_string().contains("Nyquist"), "{err}");
            // Nyquist follows the columns (square pixels of side L/cols): 64 rows don't help.
            assert!(SurfaceSpec::new(64, 16, 1.0, psd, height).is_err());
            assert!(LineSpec::new(16, 1.0, psd, height).is_err());
        }
        let just_below = Psd::new(0.5, LongWavelength::RollOff { q0: 7.9 }, None).unwrap();
        assert!(SurfaceSpec::new(16, 16, 1.0, just_below, height).is_ok());
        // 64 columns: Nyquist 32, so q0 = 8 is fine there.
        let eight = Psd::new(0.5, LongWavelength::RollOff { q0: 8.0 }, None).unwrap();
        assert!(SurfaceSpec::new(16, 64, 1.0, eight, height).is_ok());
        assert!(LineSpec::new(16, 1.0, just_below, height).is_ok());
        let no_modes = Psd::new(0.5, LongWavelength::None, Some(0.5)).unwrap();
        let err = SurfaceSpec::new(16, 16, 1.0, no_modes, height).unwrap_err();
        assert!(err.to_string().contains("short_cutoff"), "{err}");
        assert!(LineSpec::new(16, 1.0, no_modes, height).is_err());
    }
}
