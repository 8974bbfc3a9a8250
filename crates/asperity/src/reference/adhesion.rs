//! Adhesive contact of a rigid indenter on an elastic half-space: the closed forms of JKR,
//! DMT, Maugis–Dugdale, Kendall's flat punch and Johnson's adhesive wavy surface.
//!
//! Conventions, shared by every type here: `w` is the work of adhesion `Δγ` (energy per
//! unit area, `> 0`), `E*` the effective modulus, `R` the sphere's radius (a paraboloid
//! `r²/2R`), `a` the contact radius. A compressive force and an indentation into the
//! half-space are positive; adhesion makes both negative on retraction. A *pull-off* force
//! is the (negative) force at which the contact is lost:
//! * under **force control** the least force on the equilibrium curve (beyond it no
//!   equilibrium exists at the applied force);
//! * under **displacement control** the force where the approach `δ` is least (beyond it
//!   no equilibrium exists at the applied approach).
//!
//! The curves are written with the contact radius `a` as the parameter, since both `F` and
//! `δ` are single-valued in it across the stable and unstable branches.
//!
//! The edge of a JKR contact is a crack whose energy release rate equals `w`: in the
//! method of dimensionality reduction this is **Heß's rule** — the spring at the edge of a
//! contact of radius `a` detaches at the elongation `Δl(a) = √(2πaw/E*)`
//! ([`Jkr::critical_elongation`]); the JKR approach is `δ = a²/R − Δl(a)` and Kendall's
//! punch lets go at `δ = −Δl(a)`.
//!
//! ## References
//! * Johnson, Kendall & Roberts, Proc. R. Soc. A 324, 301 (1971).
//! * Derjaguin, Muller & Toporov, J. Colloid Interface Sci. 53, 314 (1975).
//! * Kendall, J. Phys. D 4, 1186 (1971) (flat punch).
//! * Maugis, J. Colloid Interface Sci. 150, 243 (1992); the dimensionless form of Johnson
//!   & Greenwood, J. Colloid Interface Sci. 192, 326 (1997).
//! * Johnson, Int. J. Solids Struct. 32, 423 (1995) (the adhesive sinusoid).
//! * Popov & Heß, *Method of Dimensionality Reduction in Contact Mechanics and Friction*
//!   (Springer 2015), ch. 6 (adhesion, Heß's rule).

use std::f64::consts::PI;

use crate::Result;

/// How the contact is driven when it comes apart (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PullOff {
    /// The force is prescribed: contact is lost at the least force of the curve.
    ForceControlled,
    /// The approach is prescribed: contact is lost at the least approach of the curve.
    DisplacementControlled,
}

fn checked(name: &'static str, value: f64) -> Result<f64> {
    crate::positive_finite(name, value, "")
}

/// Heß's critical elongation `√(2πaw/E*)` of the edge spring of a contact of radius `a`.
pub fn critical_elongation(radius: f64, modulus: f64, work_of_adhesion: f64) -> f64 {
    (2.0 * PI * radius.max(0.0) * work_of_adhesion / modulus).sqrt()
}

/// The mean self-compliance of a square pixel: a uniform pressure `p` on a pixel of side
/// `Δx` displaces it on average by `c̄·pΔx/E*`, with
/// `c̄ = (4/π)[ln(1 + √2) − (√2 − 1)/3] ≈ 0.9464` (Love's solution averaged over the
/// square; at the centre the factor is `4 ln(1 + √2)/π ≈ 1.1222`, the BEM's self-influence).
pub fn pixel_mean_compliance() -> f64 {
    let root2 = std::f64::consts::SQRT_2;
    4.0 / PI * ((1.0 + root2).ln() - (root2 - 1.0) / 3.0)
}

/// The tension at which one square pixel of an adhesive BEM contact lets go (the criterion
/// of Pohrt & Popov, Facta Univ. Mech. Eng. 13, 3 (2015), derived here from energy):
/// releasing a pixel that carries the tension `σ` frees the elastic energy its own load
/// stored, `½σΔx²·(c̄σΔx/E*)` ([`pixel_mean_compliance`]); it lets go when that reaches
/// the work of adhesion of its area, `wΔx²`:
/// `σ_c = √(2E*w/(c̄Δx)) = √(E*w/(cΔx))` with `c = c̄/2 ≈ 0.4732`.
/// The interaction with the neighbours' loads is left out, as in the criterion; the BEM
/// iteration that uses it is [`crate::bem::adhesion::PixelAdhesion`].
pub fn pixel_critical_stress(modulus: f64, work_of_adhesion: f64, spacing: f64) -> f64 {
    (2.0 * modulus * work_of_adhesion / (pixel_mean_compliance() * spacing)).sqrt()
}

/// JKR: a rigid sphere with adhesion of vanishing range (`a ≫` the range; Maugis
/// parameter `λ → ∞`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jkr {
    /// Sphere radius R.
    pub radius: f64,
    /// Effective modulus E*.
    pub modulus: f64,
    /// Work of adhesion w = Δγ.
    pub work_of_adhesion: f64,
}

impl Jkr {
    /// A JKR contact, refused unless every parameter is positive and finite.
    pub fn new(radius: f64, modulus: f64, work_of_adhesion: f64) -> Result<Self> {
        Ok(Jkr {
            radius: checked("radius", radius)?,
            modulus: checked("modulus", modulus)?,
            work_of_adhesion: checked("work of adhesion", work_of_adhesion)?,
        })
    }

    /// Heß's critical elongation `Δl(a) = √(2πaw/E*)` at contact radius `a`.
    pub fn critical_elongation(&self, a: f64) -> f64 {
        critical_elongation(a, self.modulus, self.work_of_adhesion)
    }

    /// The approach `δ = a²/R − √(2πaw/E*)`.
    pub fn approach(&self, a: f64) -> f64 {
        a * a / self.radius - self.critical_elongation(a)
    }

    /// The force `F = 4E*a³/3R − √(8πwE*a³)`.
    pub fn force(&self, a: f64) -> f64 {
        let a = a.max(0.0);
        4.0 * self.modulus * a.powi(3) / (3.0 * self.radius)
            - (8.0 * PI * self.work_of_adhesion * self.modulus * a.powi(3)).sqrt()
    }

    /// The contact radius on the stable branch at force `F ≥` the force-controlled
    /// pull-off: `a³ = (3R/4E*)(F + 3πwR + √(6πwRF + (3πwR)²))`; `None` below pull-off.
    pub fn contact_radius_at_force(&self, force: f64) -> Option<f64> {
        let scale = 3.0 * PI * self.work_of_adhesion * self.radius;
        let discriminant = 2.0 * scale * force + scale * scale;
        if discriminant < 0.0 {
            return None;
        }
        let cube = 3.0 * self.radius / (4.0 * self.modulus) * (force + scale + discriminant.sqrt());
        Some(cube.cbrt())
    }

    /// The contact radius at zero force, `a₀ = (9πwR²/2E*)^{1/3}`.
    pub fn zero_force_radius(&self) -> f64 {
        (4.5 * PI * self.work_of_adhesion * self.radius.powi(2) / self.modulus).cbrt()
    }

    /// The contact radius at pull-off: `(9πwR²/8E*)^{1/3}` (force control, where
    /// `dF/da = 0`) or `(πwR²/8E*)^{1/3}` (displacement control, where `dδ/da = 0`).
    pub fn pull_off_radius(&self, control: PullOff) -> f64 {
        let factor = match control {
            PullOff::ForceControlled => 9.0 / 8.0,
            PullOff::DisplacementControlled => 1.0 / 8.0,
        };
        (factor * PI * self.work_of_adhesion * self.radius.powi(2) / self.modulus).cbrt()
    }

    /// The pull-off force: `−(3/2)πwR` (force control), `−(5/6)πwR` (displacement
    /// control).
    pub fn pull_off_force(&self, control: PullOff) -> f64 {
        let factor = match control {
            PullOff::ForceControlled => 1.5,
            PullOff::DisplacementControlled => 5.0 / 6.0,
        };
        -factor * PI * self.work_of_adhesion * self.radius
    }
}

/// DMT: a sphere whose contact is Hertz's, with the adhesive force `2πwR` acting outside
/// it (long-range adhesion on a stiff sphere; Maugis parameter `λ → 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dmt {
    /// Sphere radius R.
    pub radius: f64,
    /// Effective modulus E*.
    pub modulus: f64,
    /// Work of adhesion w = Δγ.
    pub work_of_adhesion: f64,
}

impl Dmt {
    /// A DMT contact, refused unless every parameter is positive and finite.
    pub fn new(radius: f64, modulus: f64, work_of_adhesion: f64) -> Result<Self> {
        Ok(Dmt {
            radius: checked("radius", radius)?,
            modulus: checked("modulus", modulus)?,
            work_of_adhesion: checked("work of adhesion", work_of_adhesion)?,
        })
    }

    /// The approach `δ = a²/R` (Hertz's).
    pub fn approach(&self, a: f64) -> f64 {
        a * a / self.radius
    }

    /// The force `F = 4E*a³/3R − 2πwR`.
    pub fn force(&self, a: f64) -> f64 {
        4.0 * self.modulus * a.max(0.0).powi(3) / (3.0 * self.radius)
            - 2.0 * PI * self.work_of_adhesion * self.radius
    }

    /// The pull-off force `−2πwR`, at `a = 0`, under either control.
    pub fn pull_off_force(&self) -> f64 {
        -2.0 * PI * self.work_of_adhesion * self.radius
    }
}

/// Kendall's rigid flat-ended punch of radius `a` in full adhesive contact: `F = 2E*aδ`
/// until the edge lets go at `δ = −√(2πaw/E*)`, i.e. at `F = −√(8πwE*a³)` (under either
/// control: the contact radius cannot shrink, so the whole face lets go at once).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kendall {
    /// Punch radius a.
    pub radius: f64,
    /// Effective modulus E*.
    pub modulus: f64,
    /// Work of adhesion w = Δγ.
    pub work_of_adhesion: f64,
}

impl Kendall {
    /// A punch, refused unless every parameter is positive and finite.
    pub fn new(radius: f64, modulus: f64, work_of_adhesion: f64) -> Result<Self> {
        Ok(Kendall {
            radius: checked("radius", radius)?,
            modulus: checked("modulus", modulus)?,
            work_of_adhesion: checked("work of adhesion", work_of_adhesion)?,
        })
    }

    /// The force `2E*aδ` while in contact.
    pub fn force(&self, approach: f64) -> f64 {
        2.0 * self.modulus * self.radius * approach
    }

    /// The approach at which the punch lets go, `−√(2πaw/E*)`.
    pub fn pull_off_approach(&self) -> f64 {
        -critical_elongation(self.radius, self.modulus, self.work_of_adhesion)
    }

    /// The pull-off force `−√(8πwE*a³)`.
    pub fn pull_off_force(&self) -> f64 {
        -(8.0 * PI * self.work_of_adhesion * self.modulus * self.radius.powi(3)).sqrt()
    }
}

/// Johnson's adhesive wavy surface (Int. J. Solids Struct. 32, 423 (1995)): a rigid
/// sinusoid `f(x) = Δ(1 − cos 2πx/λ)` (one-dimensional waviness, crests at `x = 0, λ, …`)
/// on a periodic half-space with adhesion of vanishing range (JKR's limit), in strips of
/// contact `|x| < a` per period.
///
/// The state at contact half-width `a` (`ψ = πa/λ`) is Westergaard's non-adhesive one at
/// that width ([`crate::reference::Westergaard`], no stress singularity) plus a periodic
/// array of flat punches of width `2a`, `p = p̄ₚ cos(πx/λ)/√(sin²ψ − sin²(πx/λ))`, whose
/// edge carries the stress intensity `K = p̄ₚ √(λ/tan ψ)`. Griffith's balance at the edge,
/// `K²/2E* = w`, fixes the punches' tension `p̄ₚ = −√(2E*w tan ψ/λ)`, so
///
/// `p̄ = p*[sin²ψ − α √(tan ψ)]`, `p* = πE*Δ/λ`, `α = √(2wλ/(π²E*Δ²))`,
///
/// and the approach (the convention of periodic half-spaces, displacements of zero mean,
/// as in [`crate::reference::Westergaard::indentation`]) adds the punches' rigid
/// displacement `(2λp̄ₚ/πE*) ln(1/sin ψ)` (their compliance, by Barber's theorem the
/// inverse of Westergaard's `dp̄/dd` at the same width) to Westergaard's
/// `d = Δr(1 − ln r)`, `r = sin²ψ`.
///
/// Along `ψ` the mean pressure falls from zero to a least value (the force-controlled
/// pull-off), rises to a greatest one and falls without bound as `ψ → π/2` (the gaps
/// close: the surfaces snap into full contact beyond the greatest value). The stable
/// branch exists while `α < 4 sin^{3/2}ψ cos^{5/2}ψ` somewhere, i.e. below
/// [`JohnsonSinusoid::ALPHA_STABLE`] `= 4(3/8)^{3/4}(5/8)^{5/4} ≈ 1.065`; its greatest
/// pressure is negative — the surfaces pull themselves into full contact under no load —
/// from [`JohnsonSinusoid::ALPHA_SNAP`] `= max sin^{3/2}ψ cos^{1/2}ψ = (3/4)^{3/4}/√2 ≈ 0.570`
/// (Johnson's 0.57).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JohnsonSinusoid {
    /// Wavelength λ.
    pub wavelength: f64,
    /// Amplitude Δ (half the peak-to-valley height).
    pub amplitude: f64,
    /// Effective modulus E*.
    pub modulus: f64,
    /// Work of adhesion w = Δγ.
    pub work_of_adhesion: f64,
}

impl JohnsonSinusoid {
    /// Johnson's parameter above which no partial contact is stable.
    pub const ALPHA_STABLE: f64 = 1.065_205_656_063_280_8;
    /// Johnson's parameter above which the surfaces snap into full contact under no load.
    pub const ALPHA_SNAP: f64 = 0.569_876_764_238_694_4;

    /// The wavy contact, refused unless every parameter is positive and finite.
    pub fn new(wavelength: f64, amplitude: f64, modulus: f64, w: f64) -> Result<Self> {
        Ok(JohnsonSinusoid {
            wavelength: checked("wavelength", wavelength)?,
            amplitude: checked("amplitude", amplitude)?,
            modulus: checked("modulus", modulus)?,
            work_of_adhesion: checked("work of adhesion", w)?,
        })
    }

    /// Westergaard's mean pressure of full contact, `p* = πE*Δ/λ`.
    pub fn full_contact_pressure(&self) -> f64 {
        PI * self.modulus * self.amplitude / self.wavelength
    }

    /// Johnson's parameter `α = √(2wλ/(π²E*Δ²))`.
    pub fn alpha(&self) -> f64 {
        (2.0 * self.work_of_adhesion * self.wavelength
            / (PI * PI * self.modulus * self.amplitude * self.amplitude))
            .sqrt()
    }

    fn angle(&self, half_width: f64) -> f64 {
        PI * half_width.clamp(0.0, 0.5 * self.wavelength) / self.wavelength
    }

    /// The mean tension of the punch array that holds the edges at Griffith's balance,
    /// `p̄ₚ = −√(2E*w tan ψ/λ)`.
    fn punch_pressure(&self, psi: f64) -> f64 {
        -(2.0 * self.modulus * self.work_of_adhesion * psi.tan() / self.wavelength).sqrt()
    }

    /// The mean pressure `p̄ = p*[sin²ψ − α√(tan ψ)]` at contact half-width `a` (`0 ≤ a < λ/2`).
    pub fn mean_pressure(&self, half_width: f64) -> f64 {
        let psi = self.angle(half_width);
        self.full_contact_pressure() * psi.sin().powi(2) + self.punch_pressure(psi)
    }

    /// The approach at contact half-width `a` (`0 < a < λ/2`): Westergaard's plus the
    /// punches' `(2λp̄ₚ/πE*) ln(1/sin ψ)` (type docs).
    pub fn approach(&self, half_width: f64) -> f64 {
        let psi = self.angle(half_width);
        let r = psi.sin().powi(2);
        let westergaard = self.amplitude * r * (1.0 - r.ln());
        let punch = -2.0 * self.wavelength * self.punch_pressure(psi) / (PI * self.modulus)
            * psi.sin().ln();
        westergaard + punch
    }

    /// The half-widths where `p̄` is least and greatest on the stable branch (the roots of
    /// `dp̄/dψ = 0`, i.e. `4 sin^{3/2}ψ cos^{5/2}ψ = α`, either side of its peak at
    /// `tan²ψ = 3/5`); `None` when `α ≥ ALPHA_STABLE` (no partial contact is stable).
    pub fn stable_branch(&self) -> Option<(f64, f64)> {
        let alpha = self.alpha();
        let g = |psi: f64| 4.0 * psi.sin().powf(1.5) * psi.cos().powf(2.5);
        let peak = (0.6f64).sqrt().atan();
        if alpha >= g(peak) {
            return None;
        }
        let root = |mut rising: f64, mut falling: f64| {
            // g − α changes sign between the two ends; bisect to rounding.
            for _ in 0..200 {
                let mid = 0.5 * (rising + falling);
                if g(mid) < alpha {
                    rising = mid;
                } else {
                    falling = mid;
                }
            }
            0.5 * (rising + falling)
        };
        let least = root(0.0, peak);
        let greatest = root(0.5 * PI, peak);
        let to_width = |psi: f64| psi * self.wavelength / PI;
        Some((to_width(least), to_width(greatest)))
    }

    /// The pull-off under `control` as `(half-width, mean pressure)`: the least mean
    /// pressure of the stable branch (force control) or the pressure where the approach is
    /// least (displacement control, over `ψ` up to the stable branch's greatest pressure,
    /// by a logarithmic scan and golden-section refinement); `None` when no partial contact
    /// is stable.
    pub fn pull_off(&self, control: PullOff) -> Option<(f64, f64)> {
        let (least, greatest) = self.stable_branch()?;
        let a = match control {
            PullOff::ForceControlled => least,
            PullOff::DisplacementControlled => {
                let objective = |ln_a: f64| self.approach(ln_a.exp());
                let (low, high) = ((1e-9 * self.wavelength).ln(), greatest.ln());
                golden_minimum(objective, low, high).exp()
            }
        };
        Some((a, self.mean_pressure(a)))
    }
}

/// The least value's abscissa of `f` over `[low, high]`: a scan of 400 points, then 100
/// golden-section steps around the best.
fn golden_minimum(f: impl Fn(f64) -> f64, low: f64, high: f64) -> f64 {
    let count = 400;
    let step = (high - low) / count as f64;
    let best = (0..=count)
        .map(|i| low + i as f64 * step)
        .min_by(|x, y| f(*x).total_cmp(&f(*y)))
        .unwrap_or(low);
    let (mut left, mut right) = ((best - step).max(low), (best + step).min(high));
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..100 {
        let x1 = right - golden * (right - left);
        let x2 = left + golden * (right - left);
        if f(x1) < f(x2) {
            right = x2;
        } else {
            left = x1;
        }
    }
    0.5 * (left + right)
}

/// One point of the Maugis–Dugdale curve, dimensionless (Johnson & Greenwood 1997):
/// `Ā = a (K/πwR²)^{1/3}`, `P̄ = F/(πwR)`, `Δ̄ = δ (K²/π²w²R)^{1/3}` with `K = 4E*/3`,
/// and `m = c/a` (`c`: the outer radius of the cohesive zone).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaugisPoint {
    /// Contact radius Ā.
    pub radius: f64,
    /// Force P̄.
    pub force: f64,
    /// Approach Δ̄.
    pub approach: f64,
    /// `m = c/a ≥ 1`.
    pub zone_ratio: f64,
}

/// Maugis–Dugdale: the sphere with a Dugdale (constant) adhesive stress `σ₀` acting over
/// the range `h₀ = w/σ₀` outside the contact; it spans JKR (`λ → ∞`) and DMT (`λ → 0`)
/// with the Maugis parameter `λ = 2σ₀ (R/πwK²)^{1/3}`, `K = 4E*/3` (Tabor's parameter
/// `μ = (Rw²/E*²z₀³)^{1/3}` is about `λ/1.16` for a Lennard-Jones law of equilibrium
/// spacing `z₀`). Everything here is dimensionless (see [`MaugisPoint`]); [`Self::scales`]
/// converts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaugisDugdale {
    /// The Maugis parameter λ.
    pub lambda: f64,
}

/// The units of the dimensionless Maugis–Dugdale quantities for a given sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaugisScales {
    /// `(πwR²/K)^{1/3}`: multiplies Ā.
    pub radius: f64,
    /// `πwR`: multiplies P̄.
    pub force: f64,
    /// `(π²w²R/K²)^{1/3}`: multiplies Δ̄.
    pub approach: f64,
    /// The Maugis parameter λ of the Dugdale stress σ₀.
    pub lambda: f64,
}

impl MaugisDugdale {
    /// The model at Maugis parameter `λ` (positive and finite).
    pub fn new(lambda: f64) -> Result<Self> {
        Ok(MaugisDugdale {
            lambda: checked("Maugis parameter", lambda)?,
        })
    }

    /// The units of a sphere of radius `R`, modulus `E*`, work of adhesion `w` and Dugdale
    /// stress `σ₀`, with its λ.
    pub fn scales(radius: f64, modulus: f64, work_of_adhesion: f64, stress: f64) -> MaugisScales {
        let k = 4.0 * modulus / 3.0;
        let w = work_of_adhesion;
        MaugisScales {
            radius: (PI * w * radius * radius / k).cbrt(),
            force: PI * w * radius,
            approach: (PI * PI * w * w * radius / (k * k)).cbrt(),
            lambda: 2.0 * stress * (radius / (PI * w * k * k)).cbrt(),
        }
    }

    /// The point of the curve at contact radius Ā > 0: `m` solves Maugis' energy balance
    /// `(λĀ²/2)[s + (m²−2) atan s] + (4λ²Ā/3)[s atan s − m + 1] = 1` (`s = √(m²−1)`), then
    /// `P̄ = Ā³ − λĀ²[s + m² atan s]` and `Δ̄ = Ā² − (4/3)λĀs`.
    pub fn at_radius(&self, radius: f64) -> MaugisPoint {
        let (lambda, a) = (self.lambda, radius);
        let balance = |s: f64| {
            let m_minus_1 = s * s / ((1.0 + s * s).sqrt() + 1.0);
            let t = s.atan();
            lambda * a * a / 2.0 * (s + (s * s - 1.0) * t)
                + 4.0 * lambda * lambda * a / 3.0 * (s * t - m_minus_1)
        };
        // The balance rises from 0 at s = 0: bracket, then bisect to rounding.
        let mut high = 1.0;
        while balance(high) < 1.0 {
            high *= 2.0;
        }
        let mut low = 0.0;
        for _ in 0..200 {
            let mid = 0.5 * (low + high);
            if balance(mid) < 1.0 {
                low = mid;
            } else {
                high = mid;
            }
            if high - low <= f64::EPSILON * high {
                break;
            }
        }
        let s = 0.5 * (low + high);
        let m2 = 1.0 + s * s;
        MaugisPoint {
            radius: a,
            force: a.powi(3) - lambda * a * a * (s + m2 * s.atan()),
            approach: a * a - 4.0 / 3.0 * lambda * a * s,
            zone_ratio: m2.sqrt(),
        }
    }

    /// The pull-off point (dimensionless): the least force (force control) or the point
    /// of least approach (displacement control) on the curve, found over `Ā ∈ [10⁻⁶, 10]`
    /// by a logarithmic scan and a golden-section refinement. At small λ the least approach
    /// lies at the smallest radius, where `P̄ → −2` (DMT).
    pub fn pull_off(&self, control: PullOff) -> MaugisPoint {
        let objective = |ln_a: f64| {
            let point = self.at_radius(ln_a.exp());
            match control {
                PullOff::ForceControlled => point.force,
                PullOff::DisplacementControlled => point.approach,
            }
        };
        self.at_radius(golden_minimum(objective, (1e-6f64).ln(), 10f64.ln()).exp())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The least value of `f` over a fine logarithmic grid of `a`, refined: an oracle for
    /// pull-off radii and forces independent of the closed forms.
    fn least(f: impl Fn(f64) -> f64, low: f64, high: f64) -> (f64, f64) {
        let n = 200_000;
        (0..=n)
            .map(|i| low * (high / low).powf(i as f64 / n as f64))
            .map(|a| (a, f(a)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap()
    }

    #[test]
    fn jkr_pull_off_is_the_least_force_and_the_least_approach() {
        let jkr = Jkr::new(2.0, 3.0, 0.05).unwrap();
        let (a, f) = least(|a| jkr.force(a), 1e-4, 10.0);
        let closed = jkr.pull_off_force(PullOff::ForceControlled);
        // The grid's step is 6e-5 relative, and the force is quadratic at its least value:
        // the grid misses it by ~(6e-5)² · (a²F''/2F) ≈ 2e-9.
        assert!((f / closed - 1.0).abs() < 1e-8, "{f} vs {closed}");
        assert!((a / jkr.pull_off_radius(PullOff::ForceControlled) - 1.0).abs() < 1e-4);
        let (a, _) = least(|a| jkr.approach(a), 1e-4, 10.0);
        let closed = jkr.pull_off_radius(PullOff::DisplacementControlled);
        assert!((a / closed - 1.0).abs() < 1e-4, "{a} vs {closed}");
        let f = jkr.force(closed);
        let expected = jkr.pull_off_force(PullOff::DisplacementControlled);
        assert!((f / expected - 1.0).abs() < 1e-12, "{f} vs {expected}");
        assert!((expected / (-5.0 / 6.0 * PI * 0.05 * 2.0) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn jkr_inverts_its_force_and_reduces_to_hertz() {
        let jkr = Jkr::new(1.5, 0.8, 0.02).unwrap();
        assert!(jkr.force(jkr.zero_force_radius()).abs() < 1e-14);
        for a in [0.3, 0.5, 1.0, 2.0] {
            if a < jkr.pull_off_radius(PullOff::ForceControlled) {
                continue;
            }
            let back = jkr.contact_radius_at_force(jkr.force(a)).unwrap();
            assert!((back / a - 1.0).abs() < 1e-12, "{back} vs {a}");
        }
        let below = 1.01 * jkr.pull_off_force(PullOff::ForceControlled);
        assert!(jkr.contact_radius_at_force(below).is_none());
        // w → 0: Hertz's force and approach at the same radius.
        let faint = Jkr::new(1.5, 0.8, 1e-14).unwrap();
        let hertz = crate::reference::Hertz {
            radius: 1.5,
            modulus: 0.8,
        };
        let a = 0.4;
        let d = a * a / 1.5;
        assert!((faint.force(a) / hertz.force(d) - 1.0).abs() < 1e-5);
        assert!((faint.approach(a) / d - 1.0).abs() < 1e-5);
    }

    #[test]
    fn kendall_is_hess_rule_on_a_punch() {
        let punch = Kendall::new(0.3, 2.0, 0.01).unwrap();
        let at_pull_off = punch.force(punch.pull_off_approach());
        assert!((at_pull_off / punch.pull_off_force() - 1.0).abs() < 1e-14);
        let stiffness = crate::reference::FlatPunch {
            radius: 0.3,
            modulus: 2.0,
        }
        .stiffness();
        assert!((punch.force(1.0) / stiffness - 1.0).abs() < 1e-15);
    }

    #[test]
    fn maugis_dugdale_tends_to_jkr_and_dmt() {
        // λ → ∞: the JKR curve, P̄ = Ā³ − √6 Ā^{3/2}, Δ̄ = Ā² − √(8Ā/3); the cohesive
        // zone shrinks like 1/λ, so the error does too (1e-3 at λ = 1e4 is ≥ 10× margin).
        let jkr = MaugisDugdale::new(1e4).unwrap();
        for a in [0.3, 0.8, 1.5, 3.0] {
            let p = jkr.at_radius(a);
            let force = a.powi(3) - 6f64.sqrt() * a.powf(1.5);
            let approach = a * a - (8.0 * a / 3.0).sqrt();
            assert!((p.force - force).abs() < 1e-3, "Ā = {a}: {p:?}");
            assert!((p.approach - approach).abs() < 1e-3, "Ā = {a}: {p:?}");
        }
        let f = jkr.pull_off(PullOff::ForceControlled).force;
        assert!((f + 1.5).abs() < 2e-3, "{f}");
        let d = jkr.pull_off(PullOff::DisplacementControlled).force;
        assert!((d + 5.0 / 6.0).abs() < 2e-3, "{d}");
        // λ → 0: DMT, P̄ = Ā³ − 2, Δ̄ = Ā²; the approach converges like (8/3)√(λ/π) (1.5e-4 at
        // λ = 1e-8).
        let dmt = MaugisDugdale::new(1e-8).unwrap();
        for a in [0.3, 1.0, 2.0] {
            let p = dmt.at_radius(a);
            assert!((p.force - (a.powi(3) - 2.0)).abs() < 1e-3, "Ā = {a}: {p:?}");
            assert!((p.approach - a * a).abs() < 1e-3, "Ā = {a}: {p:?}");
        }
        let f = dmt.pull_off(PullOff::ForceControlled).force;
        assert!((f + 2.0).abs() < 1e-3, "{f}");
    }

    #[test]
    fn maugis_dugdale_pull_off_moves_monotonically_from_dmt_to_jkr() {
        let mut last = -2.0 - 1e-9;
        for lambda in [0.01, 0.1, 0.3, 1.0, 3.0, 10.0, 100.0] {
            let f = MaugisDugdale::new(lambda)
                .unwrap()
                .pull_off(PullOff::ForceControlled)
                .force;
            assert!(f > last && f < -1.5 + 1e-9, "λ = {lambda}: {f}");
            last = f;
        }
    }

    #[test]
    fn pixel_compliance_is_loves_solution_averaged() {
        // u(x, y) = (1/πE*) ∫∫ p/r dA over the unit square, summed from its four corner
        // rectangles (∫∫ 1/r over [0, X]×[0, Y] = X asinh(Y/X) + Y asinh(X/Y)), averaged
        // over a 400² midpoint grid (error ~1e-5 from the log corners).
        let corner = |x: f64, y: f64| x * (y / x).asinh() + y * (x / y).asinh();
        let u = |x: f64, y: f64| {
            let (l, r, b, t) = (0.5 + x, 0.5 - x, 0.5 + y, 0.5 - y);
            (corner(l, b) + corner(l, t) + corner(r, b) + corner(r, t)) / PI
        };
        let centre = 4.0 * (1.0 + 2f64.sqrt()).ln() / PI;
        assert!((u(0.0, 0.0) - centre).abs() < 1e-14);
        let n = 400;
        let at = |i: usize| (i as f64 + 0.5) / n as f64 - 0.5;
        let mean = (0..n * n).map(|k| u(at(k % n), at(k / n))).sum::<f64>() / (n * n) as f64;
        assert!((mean - pixel_mean_compliance()).abs() < 2e-5, "{mean}");
        let sigma = pixel_critical_stress(2.0, 0.05, 0.01);
        let energy = 0.5 * sigma * sigma * pixel_mean_compliance() * 0.01 / 2.0;
        assert!((energy / 0.05 - 1.0).abs() < 1e-14);
    }

    #[test]
    fn maugis_scales_make_jkr_dimensional() {
        let (radius, modulus, w) = (2.0, 3.0, 0.05);
        let scales = MaugisDugdale::scales(radius, modulus, w, 1e6);
        let jkr = Jkr::new(radius, modulus, w).unwrap();
        let a = 1.3 * scales.radius;
        let bar = a / scales.radius;
        let force = (bar.powi(3) - 6f64.sqrt() * bar.powf(1.5)) * scales.force;
        let approach = (bar * bar - (8.0 * bar / 3.0).sqrt()) * scales.approach;
        assert!((force / jkr.force(a) - 1.0).abs() < 1e-12);
        assert!((approach / jkr.approach(a) - 1.0).abs() < 1e-12);
        assert!(Jkr::new(1.0, 1.0, 0.0).is_err());
        assert!(Jkr::new(1.0, 1.0, f64::NAN).is_err());
        assert!(MaugisDugdale::new(f64::INFINITY).is_err());
    }
    #[test]
    fn johnson_sinusoid_without_adhesion_is_westergaard() {
        let faint = JohnsonSinusoid::new(2.0, 0.1, 3.0, 1e-18).unwrap();
        let westergaard = crate::reference::Westergaard {
            wavelength: 2.0,
            amplitude: 0.1,
            modulus: 3.0,
        };
        for a in [0.1, 0.4, 0.7, 0.95] {
            let p = faint.mean_pressure(a);
            assert!(
                (westergaard.contact_half_width(p) / a - 1.0).abs() < 1e-7,
                "a = {a}"
            );
            let d = westergaard.indentation(p);
            assert!((faint.approach(a) / d - 1.0).abs() < 1e-7, "a = {a}");
        }
    }

    #[test]
    fn johnson_sinusoid_at_long_wavelength_is_the_jkr_cylinder() {
        // A crest of curvature 4π²Δ/λ² = 1/R: an isolated cylinder, whose JKR force per
        // length is P = πE*a²/4R − √(2πE*wa) (Barquins 1988); the error is O(ψ²) ≈ 3e-6.
        let (radius, modulus, w, wavelength) = (1.0, 2.0, 1e-3, 100.0);
        let amplitude = wavelength * wavelength / (4.0 * PI * PI * radius);
        let wavy = JohnsonSinusoid::new(wavelength, amplitude, modulus, w).unwrap();
        for a in [0.02, 0.05, 0.1] {
            let cylinder =
                PI * modulus * a * a / (4.0 * radius) - (2.0 * PI * modulus * w * a).sqrt();
            let force = wavy.mean_pressure(a) * wavelength;
            assert!(
                (force / cylinder - 1.0).abs() < 1e-4,
                "a = {a}: {force} vs {cylinder}"
            );
        }
    }

    #[test]
    fn johnson_edges_release_the_work_of_adhesion() {
        // Griffith from the compliance, independently of the stress intensity: the punches'
        // compliance per period is 1/(λk), k = dp̄/dd of Westergaard at the same width
        // (Barber), and two edges advance per period, so G = ¼ p̄ₚ²λ |d(1/k)/da| must be w.
        let (wavelength, amplitude, modulus, w) = (2.0, 0.1, 3.0, 0.01);
        let wavy = JohnsonSinusoid::new(wavelength, amplitude, modulus, w).unwrap();
        let westergaard = crate::reference::Westergaard {
            wavelength,
            amplitude,
            modulus,
        };
        let p_star = westergaard.full_contact_pressure();
        let pressure_at = |a: f64| p_star * (PI * a / wavelength).sin().powi(2);
        let compliance = |a: f64| {
            let (p, h) = (pressure_at(a), 1e-6 * pressure_at(a));
            (westergaard.indentation(p + h) - westergaard.indentation(p - h)) / (2.0 * h)
        };
        for a in [0.1, 0.3, 0.6, 0.8] {
            let punch = wavy.mean_pressure(a) - pressure_at(a);
            let h = 1e-4;
            let slope = (compliance(a + h) - compliance(a - h)) / (2.0 * h);
            let release = 0.25 * punch * punch * wavelength * slope.abs();
            assert!((release / w - 1.0).abs() < 1e-5, "a = {a}: G = {release}");
            let rigid = wavy.approach(a) - westergaard.indentation(pressure_at(a));
            assert!(
                (rigid / (punch * compliance(a)) - 1.0).abs() < 1e-6,
                "a = {a}"
            );
        }
    }

    #[test]
    fn johnson_pull_offs_are_the_least_pressure_and_approach() {
        let wavy = JohnsonSinusoid::new(2.0, 0.1, 3.0, 0.01).unwrap();
        let alpha = wavy.alpha();
        assert!(
            alpha > 0.0 && alpha < JohnsonSinusoid::ALPHA_SNAP,
            "{alpha}"
        );
        let (_, greatest) = wavy.stable_branch().unwrap();
        let n = 400_000;
        let widths = (1..n).map(|i| greatest * i as f64 / n as f64);
        let least = |f: &dyn Fn(f64) -> f64| {
            widths
                .clone()
                .min_by(|x, y| f(*x).total_cmp(&f(*y)))
                .unwrap()
        };
        let a_f = least(&|a| wavy.mean_pressure(a));
        let (a, p) = wavy.pull_off(PullOff::ForceControlled).unwrap();
        assert!((a / a_f - 1.0).abs() < 1e-4, "{a} vs {a_f}");
        assert!((p / wavy.mean_pressure(a_f) - 1.0).abs() < 1e-8);
        let a_d = least(&|a| wavy.approach(a));
        let (a, p_d) = wavy.pull_off(PullOff::DisplacementControlled).unwrap();
        assert!((a / a_d - 1.0).abs() < 1e-4, "{a} vs {a_d}");
        assert!(p_d < 0.0 && p_d > p, "{p_d} vs {p}");
    }

    #[test]
    fn johnson_thresholds_are_where_the_branch_ends_and_snaps() {
        let g = |psi: f64| 4.0 * psi.sin().powf(1.5) * psi.cos().powf(2.5);
        let peak = (0.6f64).sqrt().atan();
        assert!((g(peak) - JohnsonSinusoid::ALPHA_STABLE).abs() < 1e-14);
        let snap = (PI / 3.0).sin().powf(1.5) * (PI / 3.0).cos().sqrt();
        assert!((snap - JohnsonSinusoid::ALPHA_SNAP).abs() < 1e-14);
        // α set through w (λ = 2, Δ = 0.1, E* = 3): w = α²π²E*Δ²/2λ.
        let with_alpha =
            |alpha: f64| JohnsonSinusoid::new(2.0, 0.1, 3.0, alpha * alpha * PI * PI * 0.03 / 4.0);
        let greatest = |alpha: f64| {
            let wavy = with_alpha(alpha).unwrap();
            assert!((wavy.alpha() / alpha - 1.0).abs() < 1e-12);
            wavy.mean_pressure(wavy.stable_branch().unwrap().1)
        };
        assert!(greatest(0.99 * JohnsonSinusoid::ALPHA_SNAP) > 0.0);
        assert!(greatest(1.01 * JohnsonSinusoid::ALPHA_SNAP) < 0.0);
        let stable = JohnsonSinusoid::ALPHA_STABLE;
        assert!(with_alpha(0.999 * stable)
            .unwrap()
            .stable_branch()
            .is_some());
        assert!(with_alpha(1.001 * stable)
            .unwrap()
            .stable_branch()
            .is_none());
        assert!(with_alpha(1.001 * stable)
            .unwrap()
            .pull_off(PullOff::ForceControlled)
            .is_none());
        assert!(JohnsonSinusoid::new(2.0, 0.0, 3.0, 0.01).is_err());
        assert!(JohnsonSinusoid::new(2.0, 0.1, 3.0, f64::NAN).is_err());
    }
}
