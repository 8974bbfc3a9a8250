//! Spring laws of the Winkler foundation: linear, the Hertz microscale law (15.2) and the
//! fractal microscale law (15.7) with its critical depth (15.6).
//!
//! Every spring of the MDR foundation stands for a strip of width `Δx` of the elastic
//! half-space. The *linear* spring has stiffness `E*·Δx` (book ch. 3; paper *Methods*).
//! Popov & Heß (ch. 15) make a single spring reproduce what is below the resolution `Δx`:
//! below a critical depth `u⁽⁰⁾` the spring follows a power law, above it a linear law with
//! the usual stiffness `E*·Δx`, shifted so that the force is continuous:
//!
//! * **Hertz microscale law, eq. (15.2)**, for a paraboloid `g(x) = x²/R` (15.1):
//!   `f = E*·4/3·R^½·u^(3/2)` for `u < u⁽⁰⁾ = Δx²/R`, else `f = E*·(Δx³/(3R) + Δx·u)`.
//!   Continuous in value at `u⁽⁰⁾` (both branches give `4/3·E*·Δx³/R`); the slope jumps from
//!   `2E*Δx` to `E*Δx` there — the book's "small irregularity".
//! * **Fractal microscale law, eq. (15.7)**, for a self-affine line of Hurst exponent `H`,
//!   rms height `h` and length `L`: below `u⁽⁰⁾` the force follows the asymptotic law of a
//!   whole fractal surface, eq. (15.3) (book eq. 10.48),
//!   `f = E*·h^(−1/H)·L·(1.9412·H/(H+1)²)^((H+1)/H)·u^((H+1)/H)`,
//!   and above it `f = E*·(C + Δx·u)`. The critical depth (15.6),
//!   `u⁽⁰⁾ = (H+1)²/(1.9412·H) · ((H+1)/1.9412 · Δx/L)^H · h`,
//!   is where the power law's stiffness equals that of one linear spring (15.4)–(15.5), so
//!   the slope is continuous by construction. The constant `C` is fixed by continuity of the
//!   force: with `f(u⁽⁰⁾) = Δx·u⁽⁰⁾·H/(H+1)` from the power branch (its slope there is
//!   `Δx`, its exponent `(H+1)/H`), `C = −Δx·u⁽⁰⁾/(H+1)`. **Checked against the printed
//!   book:** the constant of (15.7), `−(H+1)/H · ((H+1)/1.9412 · Δx/L)^H · Δx·h/1.9412`, is
//!   the same expression — no discrepancy; the unit tests check value and slope continuity
//!   and the printed constant.
//!
//! Validity: (15.3) and hence (15.7) need `H > 0` (the prefactor holds `h^(−1/H)`) and
//! describe the Pohrt–Popov regime `0 < H < 2` (paper eq. 6; for `H ≥ 2` a rough surface
//! behaves like a single Hertzian asperity instead), so [`SpringLaw::Fractal`] accepts
//! `0 < H < 2` only.
//!
//! A [`Spring`] is a law validated once together with the spacing `Δx` and the modulus
//! `E*`; its constants are precomputed so that [`Spring::force`] is a branch and a `powf`.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// The numerical constant of the book's asymptotic law (10.48) / (15.3)–(15.7).
pub const FRACTAL_CONSTANT: f64 = 1.9412;

/// Which force law each spring of the foundation follows (parameters not yet validated;
/// [`Spring::new`] checks them).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SpringLaw {
    /// Linear springs of stiffness `E*·Δx` (the standard MDR foundation).
    Linear,
    /// Hertz microscale law (15.2) for asperities of radius `radius` (the sphere radius `R`
    /// of the 3D problem; the 1D profile is `x²/R`, eq. 15.1).
    Hertz {
        /// Asperity radius R.
        radius: f64,
    },
    /// Fractal microscale law (15.7) with critical depth (15.6), for `0 < H < 2`.
    Fractal {
        /// Hurst exponent H of the rough line.
        hurst: f64,
        /// rms height h of the rough line.
        rms_height: f64,
        /// Length L of the rough line.
        size: f64,
    },
}

impl SpringLaw {
    /// A short name: `linear`, `hertz` or `fractal`.
    pub fn name(&self) -> &'static str {
        match self {
            SpringLaw::Linear => "linear",
            SpringLaw::Hertz { .. } => "hertz",
            SpringLaw::Fractal { .. } => "fractal",
        }
    }
}

/// A validated spring: law, spacing `Δx` and modulus `E*`, with precomputed constants.
///
/// Every law has the form `f(u) = E*·P·u^p` for `0 < u < u⁽⁰⁾` and `f(u) = E*·(C + Δx·u)`
/// for `u ≥ u⁽⁰⁾` (the linear law is `u⁽⁰⁾ = 0`, `C = 0`); `f = 0` for `u ≤ 0` (no
/// adhesion).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    law: SpringLaw,
    spacing: f64,
    modulus: f64,
    critical_depth: f64,
    prefactor: f64,
    exponent: f64,
    offset: f64,
}

impl Spring {
    /// Validates the law with spacing `Δx > 0` and modulus `E* > 0` and precomputes its
    /// constants. Errors name the offending parameter (`dx`, `modulus`, `radius`, `hurst`,
    /// `rms-height`, `size`).
    pub fn new(law: SpringLaw, spacing: f64, modulus: f64) -> Result<Self> {
        crate::positive_finite("dx", spacing, "the spring spacing Δx")?;
        crate::positive_finite("modulus", modulus, "the effective modulus E*")?;
        let (critical_depth, prefactor, exponent, offset) = match law {
            SpringLaw::Linear => (0.0, 0.0, 1.0, 0.0),
            SpringLaw::Hertz { radius } => {
                crate::positive_finite("radius", radius, "the asperity radius R")?;
                // (15.2): u0 = Δx²/R, P = 4/3 R^½, p = 3/2, C = Δx³/(3R).
                (
                    spacing * spacing / radius,
                    4.0 / 3.0 * radius.sqrt(),
                    1.5,
                    spacing.powi(3) / (3.0 * radius),
                )
            }
            SpringLaw::Fractal {
                hurst,
                rms_height,
                size,
            } => {
                if !(crate::is_positive_finite(hurst) && hurst < 2.0) {
                    return Err(Error::invalid(
                        "hurst",
                        format!(
                            "the fractal spring law (15.7) needs 0 < H < 2 (it holds h^(-1/H); \
                             for H >= 2 roughness acts as one Hertzian asperity), got {}",
                            crate::input::short_number(hurst)
                        ),
                    ));
                }
                crate::positive_finite("rms_height", rms_height, "the rms height h")?;
                crate::positive_finite("size", size, "the line length L")?;
                let h1 = hurst + 1.0;
                let exponent = h1 / hurst;
                // (15.3): P = h^(-1/H) L (1.9412 H/(H+1)²)^((H+1)/H).
                let prefactor = rms_height.powf(-1.0 / hurst)
                    * size
                    * (FRACTAL_CONSTANT * hurst / (h1 * h1)).powf(exponent);
                // (15.6).
                let critical_depth = h1 * h1 / (FRACTAL_CONSTANT * hurst)
                    * (h1 / FRACTAL_CONSTANT * spacing / size).powf(hurst)
                    * rms_height;
                // Continuity of the force at u0 (equal to the constant printed in 15.7).
                let offset = -spacing * critical_depth / h1;
                (critical_depth, prefactor, exponent, offset)
            }
        };
        Ok(Spring {
            law,
            spacing,
            modulus,
            critical_depth,
            prefactor,
            exponent,
            offset,
        })
    }

    /// Linear spring of stiffness `E*·Δx`.
    pub fn linear(spacing: f64, modulus: f64) -> Result<Self> {
        Spring::new(SpringLaw::Linear, spacing, modulus)
    }

    /// The law.
    pub fn law(&self) -> SpringLaw {
        self.law
    }

    /// Spacing `Δx`.
    pub fn spacing(&self) -> f64 {
        self.spacing
    }

    /// Effective modulus `E*`.
    pub fn modulus(&self) -> f64 {
        self.modulus
    }

    /// Stiffness of one linear spring (and of every spring beyond its critical depth),
    /// `E*·Δx`.
    pub fn linear_stiffness(&self) -> f64 {
        self.modulus * self.spacing
    }

    /// Critical depth `u⁽⁰⁾` below which the power-law branch holds: `Δx²/R` for (15.2),
    /// eq. (15.6) for (15.7), `0` for linear springs.
    pub fn critical_depth(&self) -> f64 {
        self.critical_depth
    }

    /// True for the linear law.
    pub fn is_linear(&self) -> bool {
        matches!(self.law, SpringLaw::Linear)
    }

    /// Force of one spring compressed by `u` (zero for `u ≤ 0`).
    #[inline]
    pub fn force(&self, compression: f64) -> f64 {
        if compression <= 0.0 {
            0.0
        } else if compression < self.critical_depth {
            self.modulus * self.prefactor * compression.powf(self.exponent)
        } else {
            self.modulus * (self.offset + self.spacing * compression)
        }
    }

    /// Tangent stiffness `df/du` of one spring compressed by `u` (zero for `u ≤ 0`).
    #[inline]
    pub fn stiffness(&self, compression: f64) -> f64 {
        if compression <= 0.0 {
            0.0
        } else if compression < self.critical_depth {
            self.modulus * self.prefactor * self.exponent * compression.powf(self.exponent - 1.0)
        } else {
            self.modulus * self.spacing
        }
    }

    /// Force and tangent stiffness together (one `powf`).
    #[inline]
    pub fn force_and_stiffness(&self, compression: f64) -> (f64, f64) {
        if compression <= 0.0 {
            (0.0, 0.0)
        } else if compression < self.critical_depth {
            let power = self.prefactor * compression.powf(self.exponent - 1.0);
            (
                self.modulus * power * compression,
                self.modulus * power * self.exponent,
            )
        } else {
            (
                self.modulus * (self.offset + self.spacing * compression),
                self.modulus * self.spacing,
            )
        }
    }
}

/// The asymptotic force of a whole fractal line of length `L`, rms height `h` and Hurst
/// exponent `H` at indentation `d`, eq. (15.3) (book eq. 10.48):
/// `F = E*·h^(−1/H)·L·(1.9412·H/(H+1)²)^((H+1)/H)·d^((H+1)/H)`.
pub fn fractal_asymptote(hurst: f64, rms_height: f64, size: f64, modulus: f64, d: f64) -> f64 {
    let exponent = (hurst + 1.0) / hurst;
    modulus
        * rms_height.powf(-1.0 / hurst)
        * size
        * (FRACTAL_CONSTANT * hurst / (hurst + 1.0).powi(2)).powf(exponent)
        * d.max(0.0).powf(exponent)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fractal(hurst: f64, h: f64, size: f64, dx: f64, modulus: f64) -> Spring {
        Spring::new(
            SpringLaw::Fractal {
                hurst,
                rms_height: h,
                size,
            },
            dx,
            modulus,
        )
        .unwrap()
    }

    /// Relative jump of `f` across `u0`: values just below and just above.
    fn jump(f: impl Fn(f64) -> f64, u0: f64) -> f64 {
        let below = f(u0 * (1.0 - 1e-13));
        let above = f(u0);
        (above - below).abs() / above.abs()
    }

    #[test]
    fn linear_spring_has_stiffness_modulus_times_spacing() {
        let s = Spring::linear(0.01, 3.0).unwrap();
        assert_eq!(s.critical_depth(), 0.0);
        assert!((s.force(0.2) - 3.0 * 0.01 * 0.2).abs() < 1e-15);
        assert_eq!(s.stiffness(0.2), 0.03);
        assert_eq!(s.force(-1.0), 0.0);
        assert_eq!(s.stiffness(0.0), 0.0);
    }

    #[test]
    fn hertz_law_15_2_is_continuous_at_its_critical_depth() {
        let (dx, radius, modulus) = (0.013, 2.5, 1.7);
        let s = Spring::new(SpringLaw::Hertz { radius }, dx, modulus).unwrap();
        let u0 = dx * dx / radius;
        assert!((s.critical_depth() / u0 - 1.0).abs() < 1e-15);
        assert!(jump(|u| s.force(u), u0) < 1e-11, "force jumps at u0");
        // Both branches give 4/3 E* Δx³/R at u0.
        let expected = 4.0 / 3.0 * modulus * dx.powi(3) / radius;
        assert!((s.force(u0) / expected - 1.0).abs() < 1e-13);
        // Below u0 it is exactly Hertz (15.2, first line) ...
        let u = 1e-3 * u0;
        let hertz = modulus * 4.0 / 3.0 * radius.sqrt() * u.powf(1.5);
        assert!((s.force(u) / hertz - 1.0).abs() < 1e-13);
        // ... and the slope halves across u0 (2E*Δx → E*Δx): (15.2) is not C¹.
        let below = s.stiffness(u0 * (1.0 - 1e-12));
        assert!((below / (2.0 * modulus * dx) - 1.0).abs() < 1e-9);
        assert_eq!(s.stiffness(u0), modulus * dx);
    }

    #[test]
    fn fractal_law_15_7_is_continuous_with_continuous_slope() {
        for (hurst, h, size, dx) in [
            (0.3, 0.02, 1.0, 1.0 / 1024.0),
            (0.5, 1.0, 1.0, 1.0 / 2049.0),
            (1.0, 1.0, 1.0, 1.0 / 2049.0),
            (1.0, 3e-3, 7.0, 7.0 / 500.0),
            (1.8, 0.4, 2.0, 2.0 / 32768.0),
        ] {
            let s = fractal(hurst, h, size, dx, 2.3);
            let u0 = s.critical_depth();
            assert!(
                jump(|u| s.force(u), u0) < 1e-11,
                "H = {hurst}: force jumps at u0"
            );
            assert!(
                jump(|u| s.stiffness(u), u0) < 1e-11,
                "H = {hurst}: slope jumps at u0"
            );
            assert!((s.stiffness(u0 * (1.0 - 1e-14)) / (2.3 * dx) - 1.0).abs() < 1e-11);
        }
    }

    #[test]
    fn fractal_constant_equals_the_printed_15_7() {
        // The book prints C = −(H+1)/H · ((H+1)/1.9412 · Δx/L)^H · Δx h / 1.9412.
        for (hurst, h, size, dx) in [
            (0.5, 1.0, 1.0, 1e-3),
            (1.0, 0.2, 3.0, 0.01),
            (1.5, 2.0, 1.0, 1e-4),
        ] {
            let s = fractal(hurst, h, size, dx, 1.0);
            let printed = -(hurst + 1.0) / hurst
                * ((hurst + 1.0) / FRACTAL_CONSTANT * dx / size).powf(hurst)
                * dx
                * h
                / FRACTAL_CONSTANT;
            assert!(
                (s.offset / printed - 1.0).abs() < 1e-13,
                "H = {hurst}: {} vs printed {printed}",
                s.offset
            );
        }
    }

    #[test]
    fn fractal_law_follows_the_asymptote_15_3_below_u0() {
        let (hurst, h, size, dx, modulus) = (0.7, 0.5, 2.0, 2.0 / 4096.0, 1.3);
        let s = fractal(hurst, h, size, dx, modulus);
        for u in [1e-6, 1e-3, 0.5].map(|t| t * s.critical_depth()) {
            let expected = fractal_asymptote(hurst, h, size, modulus, u);
            assert!((s.force(u) / expected - 1.0).abs() < 1e-13);
        }
        // Above u0 the stiffness is that of a linear spring.
        assert_eq!(s.stiffness(10.0 * s.critical_depth()), modulus * dx);
    }

    #[test]
    fn stiffness_is_the_derivative_of_force() {
        let springs = [
            Spring::linear(0.1, 1.0).unwrap(),
            Spring::new(SpringLaw::Hertz { radius: 1.0 }, 0.1, 2.0).unwrap(),
            fractal(0.8, 1.0, 1.0, 1.0 / 512.0, 1.0),
        ];
        for s in springs {
            let u0 = s.critical_depth().max(1e-3);
            for u in [0.1 * u0, 0.6 * u0, 3.0 * u0] {
                let step = 1e-6 * u;
                let fd = (s.force(u + step) - s.force(u - step)) / (2.0 * step);
                assert!(
                    (fd / s.stiffness(u) - 1.0).abs() < 1e-6,
                    "{:?} at {u}",
                    s.law()
                );
                let (f, k) = s.force_and_stiffness(u);
                assert!((f / s.force(u) - 1.0).abs() < 1e-14);
                assert!((k / s.stiffness(u) - 1.0).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn invalid_parameters_are_refused() {
        let bad_hurst = |hurst| {
            Spring::new(
                SpringLaw::Fractal {
                    hurst,
                    rms_height: 1.0,
                    size: 1.0,
                },
                0.01,
                1.0,
            )
        };
        for hurst in [0.0, -0.5, 2.0, f64::NAN] {
            let err = bad_hurst(hurst).unwrap_err().to_string();
            assert!(err.contains("hurst"), "{err}");
        }
        for dx in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = Spring::linear(dx, 1.0).unwrap_err().to_string();
            assert!(err.contains("dx"), "{err}");
        }
        assert!(Spring::linear(0.1, 0.0).is_err());
        assert!(Spring::new(SpringLaw::Hertz { radius: -1.0 }, 0.1, 1.0).is_err());
        assert!(Spring::new(
            SpringLaw::Fractal {
                hurst: 0.5,
                rms_height: 0.0,
                size: 1.0
            },
            0.1,
            1.0
        )
        .is_err());
    }
}
