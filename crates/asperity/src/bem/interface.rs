//! [`Interface`]: what "in contact" means between the indenter and the half-space — the
//! only place in [`crate::bem`] that knows it. The iterations, the residual, the clean-up
//! of a converged state and the frozen-set stiffness ask it rather than writing the rule.
//!
//! For a pressure `p` and a gap `g = u + f − d` (module docs of [`crate::bem`]), an
//! interface gives
//! * [`Interface::project`]: the nearest admissible pressure (the projection of the bound
//!   constraints);
//! * [`Interface::in_contact`]: whether the point carries load (`p > 0`), what the contact
//!   area counts;
//! * [`Interface::elastic`]: whether the point is on the *elastic* set, where the gap is
//!   held at zero and the pressure is free to move both ways (the set of the conjugate
//!   gradients and of the frozen-set stiffness);
//! * [`Interface::is_free`]: whether an iteration may move the pressure (the elastic set
//!   and the bounded points whose gap says the bound should be left);
//! * [`Interface::violation`]: the point's share of the residual, zero exactly where the
//!   conditions hold.
//!
//! [`Interface::HardWall`] is the frictionless, non-adhesive contact of the paper:
//! `p ≥ 0, g ≥ 0, p·g = 0`. [`Interface::Hardness`] caps the pressure at a hardness `H`
//! (elastic–perfectly-plastic contact, Johnson, *Contact Mechanics* §6; the "saturated"
//! pressure of tamaas and the `hardness` of ContactMechanics): `0 ≤ p ≤ H`, `g ≥ 0` where
//! `p = 0`, `g = 0` where `0 < p < H`, `g ≤ 0` where `p = H` (the indenter has pushed the
//! surface in by the plastic displacement `−g`).

use crate::Error;

/// The contact law between the rigid indenter and the half-space (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub enum Interface {
    /// `p ≥ 0, g ≥ 0, p·g = 0`: frictionless, non-adhesive, purely elastic. The default.
    #[default]
    HardWall,
    /// `0 ≤ p ≤ h`: the pressure is capped at the hardness `h` (> 0, finite, in the units
    /// of the modulus), where the surface yields perfectly plastically.
    Hardness {
        /// The hardness (indentation pressure of the softer body).
        h: f64,
    },
}

impl Interface {
    /// An interface with a pressure cap `h`, refused unless `h` is positive and finite.
    pub fn hardness(h: f64) -> crate::Result<Self> {
        crate::positive_finite("hardness", h, "")?;
        Ok(Interface::Hardness { h })
    }

    /// The upper bound of the pressure (infinite for the hard wall).
    #[inline]
    pub fn cap(&self) -> f64 {
        match *self {
            Interface::HardWall => f64::INFINITY,
            Interface::Hardness { h } => h,
        }
    }

    /// The nearest admissible pressure: `max(p, 0)` (hard wall), `min(max(p, 0), h)`.
    #[inline]
    pub fn project(&self, p: f64) -> f64 {
        match *self {
            Interface::HardWall => p.max(0.0),
            Interface::Hardness { h } => p.max(0.0).min(h),
        }
    }

    /// Whether the point carries load: `p > 0`.
    #[inline]
    pub fn in_contact(&self, p: f64) -> bool {
        p > 0.0
    }

    /// Whether the point is on the elastic set, where the gap is zero and the pressure may
    /// move both ways: `p > 0` (hard wall), `0 < p < h`.
    #[inline]
    pub fn elastic(&self, p: f64) -> bool {
        match *self {
            Interface::HardWall => p > 0.0,
            Interface::Hardness { h } => p > 0.0 && p < h,
        }
    }

    /// Whether the point is at the cap (`p ≥ h`; never for the hard wall).
    #[inline]
    pub fn plastic(&self, p: f64) -> bool {
        match *self {
            Interface::HardWall => false,
            Interface::Hardness { h } => p >= h,
        }
    }

    /// Whether an iteration may move the pressure: the elastic set, the points out of
    /// contact that penetrate (`p = 0, g < 0`) and the capped ones that pull away
    /// (`p = h, g > 0`).
    #[inline]
    pub fn is_free(&self, p: f64, g: f64) -> bool {
        match *self {
            Interface::HardWall => p > 0.0 || g < 0.0,
            Interface::Hardness { h } => (p > 0.0 || g < 0.0) && (p < h || g > 0.0),
        }
    }

    /// The point's violation of the contact conditions, whose squares the residual sums:
    /// `g` on the elastic set, `min(g, 0)` out of contact, `max(g, 0)` at the cap.
    #[inline]
    pub fn violation(&self, p: f64, g: f64) -> f64 {
        if self.plastic(p) {
            g.max(0.0)
        } else if p > 0.0 {
            g
        } else {
            g.min(0.0)
        }
    }

    /// The gap of a converged state, cleaned: zero on the elastic set, `max(g, 0)` out of
    /// contact, `min(g, 0)` at the cap (minus the plastic displacement).
    #[inline]
    pub fn clean_gap(&self, p: f64, g: f64) -> f64 {
        if self.plastic(p) {
            g.min(0.0)
        } else if p > 0.0 {
            0.0
        } else {
            g.max(0.0)
        }
    }

    /// Refuses a mean pressure the interface cannot carry: at or above the cap, even a
    /// fully plastic contact (every point at `h`) carries less.
    pub fn check_mean_pressure(&self, mean_pressure: f64) -> crate::Result<()> {
        match *self {
            Interface::Hardness { h } if mean_pressure >= h => Err(Error::invalid(
                "mean pressure",
                format!(
                    "{mean_pressure:e} is at or above the hardness {h:e}: more than a fully \
                     plastic contact can carry"
                ),
            )),
            _ => Ok(()),
        }
    }

    /// Checks the interface's parameters (a hardness positive and finite).
    pub fn validate(&self) -> crate::Result<()> {
        match *self {
            Interface::HardWall => Ok(()),
            Interface::Hardness { h } => Interface::hardness(h).map(|_| ()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hard_wall_is_the_papers_rule() {
        let wall = Interface::HardWall;
        for (p, g) in [(0.0, 1.0), (0.0, -1.0), (2.0, 0.5), (2.0, -0.5)] {
            assert_eq!(wall.project(p - 3.0), (p - 3.0f64).max(0.0));
            assert_eq!(wall.elastic(p), p > 0.0);
            assert_eq!(wall.is_free(p, g), p > 0.0 || g < 0.0);
            assert_eq!(wall.violation(p, g), if p > 0.0 { g } else { g.min(0.0) });
            assert_eq!(wall.clean_gap(p, g), if p > 0.0 { 0.0 } else { g.max(0.0) });
            assert!(!wall.plastic(p));
        }
    }

    #[test]
    fn hardness_caps_the_pressure() {
        let cap = Interface::hardness(2.0).unwrap();
        assert_eq!(cap.project(3.0), 2.0);
        assert_eq!(cap.project(-1.0), 0.0);
        assert_eq!(cap.project(1.5), 1.5);
        assert!(cap.elastic(1.0) && !cap.elastic(2.0) && !cap.elastic(0.0));
        // At the cap: bounded while the surface is pushed in (g ≤ 0), free once it pulls
        // away; the violation is the pull.
        assert!(!cap.is_free(2.0, -0.1) && cap.is_free(2.0, 0.1));
        assert_eq!(cap.violation(2.0, -0.1), 0.0);
        assert_eq!(cap.violation(2.0, 0.1), 0.1);
        assert_eq!(cap.clean_gap(2.0, -0.1), -0.1);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = Interface::hardness(bad).unwrap_err().to_string();
            assert!(err.contains("hardness"), "{err}");
        }
        assert!(cap.check_mean_pressure(1.99).is_ok());
        let err = cap.check_mean_pressure(2.0).unwrap_err().to_string();
        assert!(
            err.contains("mean pressure") && err.contains("hardness"),
            "{err}"
        );
    }
}
