//! Power spectra of self-affine roughness, paper eqs. (1), (7), (8), (28), (29).
//!
//! A [`Psd`] describes the *shape* of the isotropic 2D power spectral density
//! `C2D(q) ∝ q^(-2H-2)` (1) with an optional long-wavelength roll-off (7) or cut-off (8)
//! and an optional short-wavelength cut-off. Wavenumbers are given dimensionless, as the
//! number of wavelengths per side, `κ = q·L/2π`: `κ = 6` is the paper's roll-off of Fig. 2.
//! The overall prefactor is fixed later, by normalising a realisation to a requested rms
//! height or rms slope (see [`crate::surface::Normalisation`]).
//!
//! The 1D spectrum of a rough line follows from (28), `C1D(q) = π q C2D(q)`, which for the
//! power law gives `C1D ∝ q^(-2H-1)` (29).

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// The smallest and largest Hurst exponent accepted (the paper's range).
pub const HURST_RANGE: (f64, f64) = (-1.0, 3.0);

/// What happens to the spectrum at wavelengths longer than `1/q0` of the side.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum LongWavelength {
    /// The power law holds down to the longest wavelength of the grid.
    #[default]
    None,
    /// Eq. (7): `C2D(q) = C2D(q0)` for `q < q0`.
    RollOff {
        /// Roll-off wavenumber as `q0·L/2π`.
        q0: f64,
    },
    /// Eq. (8): `C2D(q) = 0` for `q < q0`.
    CutOff {
        /// Cut-off wavenumber as `q0·L/2π`.
        q0: f64,
    },
}

/// Shape of a self-affine power spectrum; built only by [`Psd::new`], which validates (also
/// when read back from JSON).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PsdFields")]
pub struct Psd {
    hurst: f64,
    long_wavelength: LongWavelength,
    short_cutoff: Option<f64>,
}

/// The fields of a [`Psd`] as stored, before [`Psd::new`] checks them.
#[derive(Deserialize)]
struct PsdFields {
    hurst: f64,
    long_wavelength: LongWavelength,
    short_cutoff: Option<f64>,
}

impl TryFrom<PsdFields> for Psd {
    type Error = Error;

    fn try_from(f: PsdFields) -> Result<Self> {
        Psd::new(f.hurst, f.long_wavelength, f.short_cutoff)
    }
}

impl Psd {
    /// A power spectrum with Hurst exponent `hurst ∈ [-1, 3]`, a long-wavelength treatment
    /// and an optional short-wavelength cut-off `q1·L/2π` (power is zero above it).
    pub fn new(
        hurst: f64,
        long_wavelength: LongWavelength,
        short_cutoff: Option<f64>,
    ) -> Result<Self> {
        let (lo, hi) = HURST_RANGE;
        if !(hurst.is_finite() && (lo..=hi).contains(&hurst)) {
            return Err(Error::invalid(
                "hurst",
                format!("H = {hurst} is outside [{lo}, {hi}]"),
            ));
        }
        let q0 = match long_wavelength {
            LongWavelength::None => None,
            LongWavelength::RollOff { q0 } | LongWavelength::CutOff { q0 } => Some(q0),
        };
        if let Some(q0) = q0 {
            if !crate::is_positive_finite(q0) {
                return Err(Error::invalid(
                    "q0",
                    format!("roll-off / cut-off must be a positive number of wavelengths per side, got {q0}"),
                ));
            }
        }
        if let Some(q1) = short_cutoff {
            if !crate::is_positive_finite(q1) {
                return Err(Error::invalid(
                    "short_cutoff",
                    format!("must be a positive number of wavelengths per side, got {q1}"),
                ));
            }
            if let Some(q0) = q0 {
                if q1 <= q0 {
                    return Err(Error::invalid(
                        "short_cutoff",
                        format!("q1 = {q1} must be above the long-wavelength q0 = {q0}"),
                    ));
                }
            }
        }
        Ok(Psd {
            hurst,
            long_wavelength,
            short_cutoff,
        })
    }

    /// A pure power law with exponent `hurst`.
    pub fn power_law(hurst: f64) -> Result<Self> {
        Psd::new(hurst, LongWavelength::None, None)
    }

    /// The Hurst exponent H.
    pub fn hurst(&self) -> f64 {
        self.hurst
    }

    /// The long-wavelength treatment.
    pub fn long_wavelength(&self) -> LongWavelength {
        self.long_wavelength
    }

    /// The short-wavelength cut-off, if any.
    pub fn short_cutoff(&self) -> Option<f64> {
        self.short_cutoff
    }

    /// The wavenumber (as `κ = qL/2π`) at which the power law is evaluated for `kappa`,
    /// or `None` where the power is zero.
    fn effective_kappa(&self, kappa: f64) -> Option<f64> {
        if kappa <= 0.0 || self.short_cutoff.is_some_and(|q1| kappa > q1) {
            return None;
        }
        match self.long_wavelength {
            LongWavelength::None => Some(kappa),
            LongWavelength::RollOff { q0 } => Some(kappa.max(q0)),
            LongWavelength::CutOff { q0 } => (kappa >= q0).then_some(kappa),
        }
    }

    /// Unnormalised 2D spectrum `C2D(κ) = κ^(-2H-2)`, (1) with (7) or (8); zero at `κ = 0`.
    pub fn c2d(&self, kappa: f64) -> f64 {
        self.effective_kappa(kappa)
            .map_or(0.0, |k| k.powf(-2.0 * self.hurst - 2.0))
    }

    /// `sqrt(C2D(κ)) = κ^(-H-1)`: the Fourier amplitude of a mode (one `powf`, no `sqrt`).
    pub fn sqrt_c2d(&self, kappa: f64) -> f64 {
        self.effective_kappa(kappa)
            .map_or(0.0, |k| k.powf(-self.hurst - 1.0))
    }

    /// [`Psd::sqrt_c2d`] of `κ²`, computed as `(κ²)^(-(H+1)/2)` to spare a square root in
    /// the synthesis loop.
    pub fn sqrt_c2d_of_squared(&self, kappa_sq: f64) -> f64 {
        let kappa = kappa_sq.sqrt();
        match self.effective_kappa(kappa) {
            None => 0.0,
            Some(k) if k == kappa => kappa_sq.powf(-0.5 * (self.hurst + 1.0)),
            Some(k) => k.powf(-self.hurst - 1.0),
        }
    }

    /// Unnormalised 1D spectrum of the equivalent line, `C1D = π κ C2D(κ)` (28); for the
    /// pure power law this is `π κ^(-2H-1)` (29).
    pub fn c1d(&self, kappa: f64) -> f64 {
        std::f64::consts::PI * kappa * self.c2d(kappa)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_is_read_back_through_the_same_checks() {
        let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 4.0 }, Some(64.0)).unwrap();
        let text = serde_json::to_string(&psd).unwrap();
        assert_eq!(serde_json::from_str::<Psd>(&text).unwrap(), psd);
        // The same fields with a Hurst exponent Psd::new refuses.
        let bad = text.replace("0.8", "7.5");
        assert_ne!(bad, text);
        let err = serde_json::from_str::<Psd>(&bad).unwrap_err().to_string();
        assert_eq!(
            err,
            Psd::new(7.5, LongWavelength::RollOff { q0: 4.0 }, Some(64.0))
                .unwrap_err()
                .to_string()
        );
    }

    #[test]
    fn hurst_range_is_enforced() {
        assert!(Psd::power_law(-1.0).is_ok());
        assert!(Psd::power_law(3.0).is_ok());
        for bad in [-1.0001, 3.5, f64::NAN, f64::INFINITY] {
            let err = Psd::power_law(bad).unwrap_err().to_string();
            assert!(err.contains("hurst"), "{err}");
        }
    }

    #[test]
    fn roll_off_is_flat_and_cut_off_is_zero_below_q0() {
        let h = 0.8;
        let roll = Psd::new(h, LongWavelength::RollOff { q0: 6.0 }, None).unwrap();
        let cut = Psd::new(h, LongWavelength::CutOff { q0: 6.0 }, None).unwrap();
        let plain = Psd::power_law(h).unwrap();
        for k in [1.0, 2.5, 5.99] {
            assert_eq!(roll.c2d(k), roll.c2d(6.0));
            assert_eq!(cut.c2d(k), 0.0);
        }
        for k in [6.0, 7.0, 100.0] {
            assert_eq!(roll.c2d(k), plain.c2d(k));
            assert_eq!(cut.c2d(k), plain.c2d(k));
        }
        assert_eq!(plain.c2d(0.0), 0.0);
        for k in [0.0, 1.0, 3.0, 7.5] {
            assert!(
                (roll.sqrt_c2d(k) - roll.c2d(k).sqrt()).abs()
                    <= 1e-15 * roll.c2d(k).sqrt().max(1.0)
            );
            let via_sq = roll.sqrt_c2d_of_squared(k * k);
            assert!((via_sq - roll.sqrt_c2d(k)).abs() <= 1e-14 * roll.sqrt_c2d(k).max(1.0));
            let far = plain.sqrt_c2d_of_squared((k + 9.0).powi(2));
            assert!((far / plain.sqrt_c2d(k + 9.0) - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn exponents_of_2d_and_1d_spectra() {
        let psd = Psd::power_law(0.5).unwrap();
        let slope = |f: &dyn Fn(f64) -> f64| (f(20.0) / f(10.0)).ln() / 2f64.ln();
        assert!((slope(&|k| psd.c2d(k)) - (-3.0)).abs() < 1e-12);
        assert!((slope(&|k| psd.c1d(k)) - (-2.0)).abs() < 1e-12);
    }

    #[test]
    fn short_cutoff_must_exceed_q0() {
        assert!(Psd::new(0.5, LongWavelength::RollOff { q0: 8.0 }, Some(4.0)).is_err());
        let psd = Psd::new(0.5, LongWavelength::None, Some(16.0)).unwrap();
        assert_eq!(psd.c2d(16.5), 0.0);
        assert!(psd.c2d(16.0) > 0.0);
        assert!(Psd::new(0.5, LongWavelength::CutOff { q0: -1.0 }, None).is_err());
    }
}
