//! Adhesive contact of a rigid indenter on an elastic half-space: the closed forms of JKR,
//! DMT, Maugis–Dugdale and Kendall's flat punch.
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
        let (low, high, count) = ((1e-6f64).ln(), 10f64.ln(), 400);
        let step = (high - low) / count as f64;
        let best = (0..=count)
            .map(|i| low + i as f64 * step)
            .min_by(|x, y| objective(*x).total_cmp(&objective(*y)))
            .unwrap_or(low);
        let (mut left, mut right) = ((best - step).max(low), (best + step).min(high));
        let golden = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..100 {
            let x1 = right - golden * (right - left);
            let x2 = left + golden * (right - left);
            if objective(x1) < objective(x2) {
                right = x2;
            } else {
                left = x1;
            }
        }
        self.at_radius((0.5 * (left + right)).exp())
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
}
