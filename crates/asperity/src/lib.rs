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
//! * **Grids** are row-major, index `(row, col)` = `(y, x)`, square pixels of spacing
//!   `size / cols`; the side `size` is the length along x.
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

#![warn(missing_docs)]

pub mod bem;
pub mod elastic;
mod error;
pub mod fft;
pub mod fit;
pub mod io;
pub mod mdr;
pub mod memory;
pub mod reference;
pub mod spectrum;
pub mod study;
pub mod surface;

pub use error::{ensure_finite, Error, Result};

#[cfg(test)]
pub(crate) mod test_support {
    //! Helpers shared by the unit tests.

    /// Runs `f` on a fresh rayon pool of `threads` threads (determinism tests).
    pub fn with_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
            .install(f)
    }
}
