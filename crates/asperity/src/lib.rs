//! # asperity: contact mechanics of randomly rough surfaces
//!
//! A library for the contact stiffness of self-affine rough surfaces after Pohrt & Popov,
//! *Contact stiffness of randomly rough surfaces*, and the method of dimensionality
//! reduction (Popov & Heß, ch. 15). Equation numbers `(1)`–`(29)` refer to the paper,
//! `(15.x)` to the book chapter.
//!
//! ## Conventions
//! * **Units** are the user's: lengths in the unit of the surface, moduli in any unit
//!   (E* defaults to 1 in the CLI). Forces come out in `E* · length²`.
//! * **Grids** are row-major, index `(row, col)` = `(y, x)`, pixels of spacing
//!   `Δx = size / cols` (the side `size` is the length along x) and `Δy = size_y / rows`,
//!   square unless made with `Surface::with_sizes` (the BEM takes either).
//! * **Wavenumbers** are given as wavelengths per side, `κ = q L / 2π` (roll-off `κ0 = 6`
//!   is the paper's Fig. 2).
//! * **Signs**: heights positive up; the rigid indenter is pushed down into the
//!   half-space; pressure ≥ 0 and gap ≥ 0.
//! * **Randomness** only from explicit seeds (`ChaCha8Rng`), so that results are
//!   bit-identical whatever the thread count.
//!
//! ## Quick start
//! ```
//! use asperity::spectrum::{LongWavelength, Psd};
//! use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec, stats};
//! let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 6.0 }, None)?;
//! let spec = SurfaceSpec::new(128, 128, 1.0, psd, Normalisation::RmsHeight(1e-3))?;
//! let surface = SurfaceGenerator::new(&spec)?.generate(7);
//! let summary = stats::surface_summary(&surface);
//! assert!((summary.rms_height - 1e-3).abs() < 1e-15);
//! # Ok::<(), asperity::Error>(())
//! ```
//!
//! ## A rough contact and its stiffness (BEM, [`bem`])
//! One [`bem::ContactSolver`] owns the FFT plans, the kernel spectrum and every buffer; it
//! serves a whole load sweep (each solve starts from the last pressure) and, through
//! [`bem::ContactSolver::set_surface`], further surfaces of the same size. Every solve
//! returns its iterations and residual, and fails with
//! [`bem::SolveError::NoConvergence`] rather than return an unconverged state.
//! ```
//! use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
//! use asperity::spectrum::{LongWavelength, Psd};
//! use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};
//! let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 4.0 }, None)?;
//! let spec = SurfaceSpec::new(64, 64, 1.0, psd, Normalisation::RmsSlope(1.0))?;
//! let surface = SurfaceGenerator::new(&spec)?.generate(1);
//! let mut solver = ContactSolver::new(&surface, HalfSpace::default(), SolverParams::default())?;
//! for p in [1e-3, 3e-3, 1e-2] {
//!     let (state, info) = solver.solve(Control::MeanPressure(p))?;
//!     assert!(info.residual < SolverParams::default().tolerance);
//!     // The paper's stiffness: freeze the contact set, push it down uniformly, k = ΔF/Δd.
//!     let (k, _) = solver.frozen_set_stiffness()?;
//!     assert!(state.area_fraction > 0.0 && state.area_fraction < 0.2 && k > 0.0);
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Rough lines and the exponent α (MDR, [`mdr`])
//! A line of independent linear springs gives its whole force–stiffness curve from one
//! sort; an ensemble of lines gives α of `k ∝ F^α` (paper eq. 3) in a stated low-force
//! window ([`study::FitWindow`]), the same estimator for lines (MDR) and surfaces (BEM).
//! ```
//! use asperity::study::{ensemble_alpha, FitWindow, Method, StudySpec, Task, TaskSamples};
//! use asperity::study::theory::alpha_theory;
//! let n = 1 << 12;
//! let spec = StudySpec {
//!     method: Method::Mdr,
//!     sizes: vec![n],
//!     hursts: vec![1.0],
//!     samples: 100,
//!     rolloff: None,
//!     seed: 1,
//!     window: FitWindow::default(), // 8 contacts up to 1 % contact
//!     levels: 48,
//!     sweep_end: None,
//!     poisson: None,
//!     tangential: Default::default(),
//! };
//! let task = Task { n, hurst: 1.0 };
//! let samples = TaskSamples::new(&spec, task)?.compute(&(0..100).collect::<Vec<_>>())?;
//! let alpha = ensemble_alpha(&samples, &spec.window, spec.levels).unwrap().exponent;
//! assert!((alpha - alpha_theory(1.0, n)).abs() < 0.05); // eq. (6): 1/(1+H) = 0.5
//! # Ok::<(), asperity::Error>(())
//! ```
//! Whole studies (many seeds, several N and H, checkpointed, thread-count independent)
//! are in [`study`]; the closed forms the solvers are tested against are in [`reference`](mod@reference).

#![warn(missing_docs)]

pub mod bem;
pub mod elastic;
mod error;
pub mod fft;
pub mod fields;
pub mod fit;
pub mod huge_pages;
pub mod input;
pub mod io;
pub mod lock;
pub mod mdr;
pub mod memory;
pub mod npy;
pub mod persson;
mod pool;
pub mod reference;
pub mod spectrum;
pub mod stop;
pub mod study;
mod sum;
pub mod surface;
pub mod topography;

pub use error::{ensure_finite, Error, Result};
pub(crate) use error::{is_positive_finite, positive_finite};

#[cfg(test)]
pub(crate) mod test_support {
    //! Helpers shared by the unit tests.

    /// `max |a − b| / max |a|`: the largest deviation of `b` from `a`, relative to the
    /// largest magnitude of `a` (for comparisons of precisions).
    pub fn relative_max_error(a: &[f64], b: &[f64]) -> f64 {
        assert_eq!(a.len(), b.len(), "compared fields differ in length");
        let largest = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let error = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        error / largest
    }

    /// Runs `f` on a fresh rayon pool of `threads` threads (determinism tests).
    pub fn with_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
            .install(f)
    }
}
