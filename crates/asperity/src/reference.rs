//! Closed-form reference solutions, shipped as library code so that tests, benchmarks and
//! users check solvers against the same formulas.
//!
//! All quantities use the effective modulus `E*` (`1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂`).
//! Axisymmetric indenters: `d` is the indentation, `a` the contact radius.

use std::f64::consts::PI;

pub mod adhesion;

pub use adhesion::{Dmt, Jkr, JohnsonSinusoid, Kendall, MaugisDugdale, PullOff};

/// Hertz: a rigid sphere of radius `radius` (paraboloid `r²/2R`) on a half-space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hertz {
    /// Sphere radius R.
    pub radius: f64,
    /// Effective modulus E*.
    pub modulus: f64,
}

impl Hertz {
    /// Contact radius `a = sqrt(R d)`.
    pub fn contact_radius(&self, indentation: f64) -> f64 {
        (self.radius * indentation.max(0.0)).sqrt()
    }

    /// Normal force `F = 4/3 E* R^½ d^{3/2}`.
    pub fn force(&self, indentation: f64) -> f64 {
        4.0 / 3.0 * self.modulus * self.radius.sqrt() * indentation.max(0.0).powf(1.5)
    }

    /// Indentation at force `F`: `d = (3F / 4E* R^½)^{2/3}`.
    pub fn indentation(&self, force: f64) -> f64 {
        (3.0 * force.max(0.0) / (4.0 * self.modulus * self.radius.sqrt())).powf(2.0 / 3.0)
    }

    /// Contact stiffness `k = dF/dd = 2 E* a`.
    pub fn stiffness(&self, indentation: f64) -> f64 {
        2.0 * self.modulus * self.contact_radius(indentation)
    }

    /// Pressure at distance `r` from the axis: `p = (2E*/πR) sqrt(a² − r²)` inside the
    /// contact, zero outside.
    pub fn pressure(&self, indentation: f64, r: f64) -> f64 {
        let a = self.contact_radius(indentation);
        if r >= a {
            0.0
        } else {
            2.0 * self.modulus / (PI * self.radius) * (a * a - r * r).sqrt()
        }
    }
}

/// A rigid flat-ended cylindrical punch of radius `radius`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatPunch {
    /// Punch radius a.
    pub radius: f64,
    /// Effective modulus E*.
    pub modulus: f64,
}

impl FlatPunch {
    /// Stiffness `k = 2 E* a`, independent of indentation.
    pub fn stiffness(&self) -> f64 {
        2.0 * self.modulus * self.radius
    }

    /// Force `F = 2 E* a d`.
    pub fn force(&self, indentation: f64) -> f64 {
        self.stiffness() * indentation.max(0.0)
    }
}

/// A rigid cone `f(r) = r tan θ` (θ: angle between the flank and the surface).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone {
    /// `tan θ`, the flank slope.
    pub slope: f64,
    /// Effective modulus E*.
    pub modulus: f64,
}

impl Cone {
    /// Contact radius `a = 2d / (π tan θ)`.
    pub fn contact_radius(&self, indentation: f64) -> f64 {
        2.0 * indentation.max(0.0) / (PI * self.slope)
    }

    /// Force `F = 2 E* d² / (π tan θ)`.
    pub fn force(&self, indentation: f64) -> f64 {
        2.0 * self.modulus * indentation.max(0.0).powi(2) / (PI * self.slope)
    }

    /// Stiffness `k = 2 E* a`.
    pub fn stiffness(&self, indentation: f64) -> f64 {
        2.0 * self.modulus * self.contact_radius(indentation)
    }
}

/// A power-law indenter `f(r) = c rⁿ` (n > 0); Hertz is `n = 2, c = 1/2R`, the cone
/// `n = 1`. Results follow from the MDR (Popov & Heß, ch. 3): the 1D profile is
/// `g(x) = κ(n) c |x|ⁿ` with `κ(n) = √π Γ(n/2 + 1) / Γ(n/2 + 1/2)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerLaw {
    /// Prefactor c.
    pub coefficient: f64,
    /// Exponent n.
    pub exponent: f64,
    /// Effective modulus E*.
    pub modulus: f64,
}

/// Γ(x) for x > 0 by the Lanczos approximation (g = 7, n = 9), relative error < 1e-13.
pub fn gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const COEFFS: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        PI / ((PI * x).sin() * gamma(1.0 - x))
    } else {
        let x = x - 1.0;
        let t = x + G + 0.5;
        let series = COEFFS[1..]
            .iter()
            .enumerate()
            .fold(COEFFS[0], |acc, (i, c)| acc + c / (x + i as f64 + 1.0));
        (2.0 * PI).sqrt() * t.powf(x + 0.5) * (-t).exp() * series
    }
}

impl PowerLaw {
    /// The MDR stretch factor `κ(n) = √π Γ(n/2 + 1) / Γ(n/2 + 1/2)`.
    pub fn stretch(&self) -> f64 {
        let n = self.exponent;
        PI.sqrt() * gamma(n / 2.0 + 1.0) / gamma(n / 2.0 + 0.5)
    }

    /// Contact radius from `d = κ(n) c aⁿ`.
    pub fn contact_radius(&self, indentation: f64) -> f64 {
        (indentation.max(0.0) / (self.stretch() * self.coefficient)).powf(1.0 / self.exponent)
    }

    /// Force `F = 2 E* n/(n+1) d a`.
    pub fn force(&self, indentation: f64) -> f64 {
        let n = self.exponent;
        2.0 * self.modulus * n / (n + 1.0) * indentation.max(0.0) * self.contact_radius(indentation)
    }

    /// Stiffness `k = 2 E* a`.
    pub fn stiffness(&self, indentation: f64) -> f64 {
        2.0 * self.modulus * self.contact_radius(indentation)
    }
}

/// Westergaard's periodic contact (Westergaard 1939; Johnson, *Contact Mechanics*, §13.2):
/// a rigid sinusoid `h(x) = amplitude · cos(2πx/λ)` (one-dimensional waviness, crests at
/// `x = 0, λ, …`) pressed onto a half-space with mean pressure `p̄`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Westergaard {
    /// Wavelength λ.
    pub wavelength: f64,
    /// Amplitude Δ of the sinusoid (half the peak-to-valley height).
    pub amplitude: f64,
    /// Effective modulus E*.
    pub modulus: f64,
}

impl Westergaard {
    /// Mean pressure of full contact `p* = π E* Δ / λ`.
    pub fn full_contact_pressure(&self) -> f64 {
        PI * self.modulus * self.amplitude / self.wavelength
    }

    /// Contact half-width `a` from `p̄ = p* sin²(πa/λ)` (λ/2 at and beyond full contact).
    pub fn contact_half_width(&self, mean_pressure: f64) -> f64 {
        let ratio = (mean_pressure.max(0.0) / self.full_contact_pressure()).min(1.0);
        self.wavelength / PI * ratio.sqrt().asin()
    }

    /// Fraction of the period in contact, `2a/λ`.
    pub fn contact_fraction(&self, mean_pressure: f64) -> f64 {
        2.0 * self.contact_half_width(mean_pressure) / self.wavelength
    }

    /// Pressure at distance `x` from a crest (`|x| ≤ λ/2`):
    /// `p = 2p̄ cos(πx/λ) sqrt(sin²(πa/λ) − sin²(πx/λ)) / sin²(πa/λ)` inside the contact.
    pub fn pressure(&self, mean_pressure: f64, x: f64) -> f64 {
        let a = self.contact_half_width(mean_pressure);
        let s_a = (PI * a / self.wavelength).sin().powi(2);
        let s_x = (PI * x / self.wavelength).sin().powi(2);
        if x.abs() >= a || s_a == 0.0 {
            return 0.0;
        }
        2.0 * mean_pressure * (PI * x / self.wavelength).cos().abs() * (s_a - s_x).sqrt() / s_a
    }

    /// Indentation `d = Δ r (1 − ln r)`, `r = p̄/p*` (`Δ` at and beyond full contact), in the
    /// convention of periodic half-spaces: displacements of zero mean, `d = u + f` at the
    /// crest with the profile `f = Δ(1 − cos 2πx/λ)` measured from the crest — the approach
    /// of the crest relative to the mean elastic displacement. From the zero-mean periodic
    /// kernel `u(x) = −(2/πE*) ∫ p(s) ln|2 sin(π(x − s)/λ)| ds` (the Fourier kernel
    /// `2/(E*|q|)` summed) at `x = 0`, with `sin(πs/λ) = sin(πa/λ) t`:
    /// `d = (λp̄/πE*)(1 − 2 ln sin(πa/λ))`. At full contact `d = Δ = mean(f)`; the slope
    /// `dd/dp̄ = −(λ/πE*) ln r` vanishes there (the stiffness diverges).
    pub fn indentation(&self, mean_pressure: f64) -> f64 {
        let ratio = (mean_pressure.max(0.0) / self.full_contact_pressure()).min(1.0);
        if ratio == 0.0 {
            return 0.0;
        }
        self.amplitude * ratio * (1.0 - ratio.ln())
    }
}

/// Boussinesq's point load: a force `F` on the surface of a half-space displaces it by
/// `u(r) = F / (π E* r)` at distance `r`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLoad {
    /// The normal force F.
    pub force: f64,
    /// Effective modulus E*.
    pub modulus: f64,
}

impl PointLoad {
    /// Surface displacement at distance `r > 0`.
    pub fn displacement(&self, r: f64) -> f64 {
        self.force / (PI * self.modulus * r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_law_reduces_to_hertz_and_cone() {
        let hertz = Hertz {
            radius: 2.0,
            modulus: 3.0,
        };
        let as_power = PowerLaw {
            coefficient: 1.0 / (2.0 * 2.0),
            exponent: 2.0,
            modulus: 3.0,
        };
        for d in [1e-4, 0.01, 0.3] {
            assert!((as_power.force(d) / hertz.force(d) - 1.0).abs() < 1e-12);
            assert!((as_power.stiffness(d) / hertz.stiffness(d) - 1.0).abs() < 1e-12);
        }
        let cone = Cone {
            slope: 0.2,
            modulus: 1.5,
        };
        let as_power = PowerLaw {
            coefficient: 0.2,
            exponent: 1.0,
            modulus: 1.5,
        };
        for d in [1e-3, 0.1] {
            assert!((as_power.force(d) / cone.force(d) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn stiffness_is_derivative_of_force() {
        let hertz = Hertz {
            radius: 1.3,
            modulus: 0.7,
        };
        let d = 0.02;
        let h = 1e-6;
        let fd = (hertz.force(d + h) - hertz.force(d - h)) / (2.0 * h);
        assert!((fd / hertz.stiffness(d) - 1.0).abs() < 1e-8);
        assert!((hertz.indentation(hertz.force(d)) / d - 1.0).abs() < 1e-12);
    }

    #[test]
    fn westergaard_limits() {
        let w = Westergaard {
            wavelength: 2.0,
            amplitude: 0.1,
            modulus: 3.0,
        };
        let p_star = w.full_contact_pressure();
        assert!((p_star - PI * 3.0 * 0.1 / 2.0).abs() < 1e-15);
        assert!((w.contact_fraction(p_star) - 1.0).abs() < 1e-12);
        assert!((w.contact_fraction(0.5 * p_star) - 0.5).abs() < 1e-12);
        // The pressure integrates to the mean pressure over one period.
        let p_mean = 0.3 * p_star;
        let n = 200_000;
        let dx = w.wavelength / n as f64;
        let integral: f64 = (0..n)
            .map(|i| w.pressure(p_mean, -1.0 + (i as f64 + 0.5) * dx) * dx)
            .sum();
        assert!((integral / w.wavelength / p_mean - 1.0).abs() < 1e-3);
        // At full contact the pressure is p̄(1 + cos 2πx/λ).
        let x = 0.3;
        let full = w.pressure(p_star * (1.0 - 1e-12), x);
        assert!((full - p_star * (1.0 + (2.0 * PI * x / 2.0).cos())).abs() < 1e-5 * p_star);
        // The indentation: 0 without load, Δ (the mean of the profile) at full contact.
        assert_eq!(w.indentation(0.0), 0.0);
        assert!((w.indentation(p_star) - 0.1).abs() < 1e-15);
        assert!((w.indentation(2.0 * p_star) - 0.1).abs() < 1e-15);
    }

    #[test]
    fn westergaard_indentation_matches_the_periodic_kernel() {
        // d = u(0) with u = −(2/πE*) ∫ p(s) ln|2 sin(πs/λ)| ds, summed numerically from the
        // closed-form pressure (midpoint rule; the log and the square-root edge are
        // integrable): fails if the closed form, its derivation or the kernel's
        // normalisation is wrong.
        let w = Westergaard {
            wavelength: 2.0,
            amplitude: 0.1,
            modulus: 3.0,
        };
        let p_star = w.full_contact_pressure();
        for ratio in [0.05, 0.3, 0.5, 0.9] {
            let p_mean = ratio * p_star;
            let a = w.contact_half_width(p_mean);
            let n = 400_000;
            let ds = 2.0 * a / n as f64;
            let u0: f64 = (0..n)
                .map(|i| {
                    let s = -a + (i as f64 + 0.5) * ds;
                    let log = (2.0 * (PI * s / w.wavelength).sin().abs()).ln();
                    -2.0 / (PI * w.modulus) * w.pressure(p_mean, s) * log * ds
                })
                .sum();
            let closed = w.indentation(p_mean);
            assert!(
                (u0 / closed - 1.0).abs() < 1e-4,
                "p/p* = {ratio}: {u0} vs {closed}"
            );
        }
    }

    #[test]
    fn point_loads_superpose_to_the_known_centre_displacements() {
        // Boussinesq's u = F/(πE*r) summed over rings of an axisymmetric pressure must give
        // the displacement at the centre known independently: 2pa/E* under a uniform disk
        // (Johnson, Contact Mechanics, eq. 3.28) and d = a²/R under the Hertz pressure.
        // Fails if the point load's normalisation (or the Hertz pressure) is wrong.
        let (modulus, a) = (0.7, 0.3);
        let centre = |pressure: &dyn Fn(f64) -> f64| {
            let n = 200_000;
            let dr = a / n as f64;
            (0..n)
                .map(|i| {
                    let r = (i as f64 + 0.5) * dr;
                    let ring = PointLoad {
                        force: pressure(r) * 2.0 * PI * r * dr,
                        modulus,
                    };
                    ring.displacement(r)
                })
                .sum::<f64>()
        };
        let p = 1.3;
        let uniform = centre(&|_| p);
        assert!(
            (uniform / (2.0 * p * a / modulus) - 1.0).abs() < 1e-10,
            "{uniform}"
        );
        let hertz = Hertz {
            radius: 2.0,
            modulus,
        };
        let d = a * a / hertz.radius;
        assert!((hertz.contact_radius(d) / a - 1.0).abs() < 1e-12);
        // The midpoint rule on the square-root edge converges like (Δr/a)^1.5.
        let u = centre(&|r| hertz.pressure(d, r));
        assert!((u / d - 1.0).abs() < 1e-6, "{u} vs {d}");
    }

    #[test]
    fn gamma_known_values() {
        assert!((gamma(0.5) - PI.sqrt()).abs() < 1e-13);
        assert!((gamma(5.0) - 24.0).abs() < 1e-10);
        assert!((gamma(2.5) - 1.329_340_388_179_137).abs() < 1e-13);
    }
}

/// Cattaneo–Mindlin: a rigid sphere of radius `radius` pressed to indentation `d` on a
/// half-space, then loaded monotonically by a tangential force `Q ≤ μF` (normal–tangential
/// coupling neglected; Johnson, *Contact Mechanics*, §7.2; Popov & Heß ch. 7). `ratio` is
/// `G*/E*` (`2(1−ν)/(2−ν)` for one Poisson's ratio ν, [`crate::mdr::mindlin_ratio`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CattaneoMindlin {
    /// Sphere radius R.
    pub radius: f64,
    /// Effective modulus E*.
    pub modulus: f64,
    /// `G*/E*`.
    pub ratio: f64,
    /// Friction coefficient μ.
    pub friction: f64,
}

impl CattaneoMindlin {
    fn hertz(&self) -> Hertz {
        Hertz {
            radius: self.radius,
            modulus: self.modulus,
        }
    }

    /// `Q / μF` at indentation `d`.
    fn load_ratio(&self, indentation: f64, force: f64) -> f64 {
        force / (self.friction * self.hertz().force(indentation))
    }

    /// Stick radius `c = a (1 − Q/μF)^{1/3}`.
    pub fn stick_radius(&self, indentation: f64, force: f64) -> f64 {
        let a = self.hertz().contact_radius(indentation);
        a * (1.0 - self.load_ratio(indentation, force)).cbrt()
    }

    /// Tangential displacement `u = μ (E*/G*) d [1 − (1 − Q/μF)^{2/3}]`.
    pub fn displacement(&self, indentation: f64, force: f64) -> f64 {
        let scale = self.friction / self.ratio * indentation;
        scale * (1.0 - (1.0 - self.load_ratio(indentation, force)).powf(2.0 / 3.0))
    }

    /// Displacement on unloading from `Q*` to `Q` (Mindlin & Deresiewicz):
    /// `u = μ (E*/G*) d [2(1 − (Q*−Q)/2μF)^{2/3} − (1 − Q*/μF)^{2/3} − 1]`.
    pub fn unloading_displacement(&self, indentation: f64, amplitude: f64, force: f64) -> f64 {
        let scale = self.friction / self.ratio * indentation;
        let back = self.load_ratio(indentation, amplitude - force) / 2.0;
        let top = self.load_ratio(indentation, amplitude);
        scale * (2.0 * (1.0 - back).powf(2.0 / 3.0) - (1.0 - top).powf(2.0 / 3.0) - 1.0)
    }

    /// Mindlin's no-slip tangential stiffness `2 G* a`.
    pub fn no_slip_stiffness(&self, indentation: f64) -> f64 {
        2.0 * self.ratio * self.modulus * self.hertz().contact_radius(indentation)
    }

    /// Energy dissipated per cycle of amplitude `Q*` (Mindlin & Deresiewicz):
    /// `9μ²F²/(10a)·((2−ν₁)/G₁ + (2−ν₂)/G₂)·[1 − (1 − Q*/μF)^{5/3} −
    /// (5Q*/6μF)(1 + (1 − Q*/μF)^{2/3})]`, where the compliance sum is `4/G*`. Its
    /// small-amplitude limit `(16/81) μ²E*²a⁵q³/(G*R²)` (`q = Q*/μF`) is what the slipping
    /// edge of width `∝ q` gives by direct integration.
    pub fn dissipation(&self, indentation: f64, amplitude: f64) -> f64 {
        let hertz = self.hertz();
        let (f, a) = (hertz.force(indentation), hertz.contact_radius(indentation));
        let q = self.load_ratio(indentation, amplitude);
        let g = self.ratio * self.modulus;
        let bracket =
            1.0 - (1.0 - q).powf(5.0 / 3.0) - 5.0 * q / 6.0 * (1.0 + (1.0 - q).powf(2.0 / 3.0));
        18.0 * (self.friction * f).powi(2) / (5.0 * g * a) * bracket
    }
}
