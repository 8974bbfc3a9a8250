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

/// The restorations that may lose the plastic set (release it or restart the pressure) in
/// one load-controlled solve before it counts as cycling. The rough surfaces of the tests
/// converge with at most a few (near fully plastic contact the bearing restart is what
/// brings the iteration to the right contact size); the cycling paraboloid loses it at
/// every step.
pub(super) const LOST_SET_LIMIT: usize = 8;

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

/// The load restoration of Polonsky–Keer's pass E and of the BCCG's step under a cap `h`:
/// the pressures (summing to `total`) scaled to the load. Where no point is at or would
/// reach the cap that is the hard wall's scaling, bit for bit. Else the points at the cap
/// stay there (scaling them down would release the whole plastic set at every step that
/// overshot the load) and the others are scaled by the `s` for which
/// `n_H h + Σ min(s p, h) = n p̄` ([`capped_scale`]); if the capped points alone carry more
/// than the load, every point is scaled. Where the points in contact cannot carry the load
/// below the cap, the pressure restarts from the bearing area that can
/// ([`bearing_start`], ordered by `level`, the gap up to a constant). Says which of the
/// three it did.
pub(super) fn restore_capped_load(
    pressure: &mut [f64],
    (mean_pressure, h): (f64, f64),
    total: f64,
    level: impl Fn(usize) -> f64,
) -> CappedRestoration {
    let wanted = mean_pressure * pressure.len() as f64;
    let in_contact = pressure.iter().filter(|&&p| p > 0.0).count();
    if (in_contact as f64) * h <= wanted || total <= 0.0 {
        bearing_start(pressure, (mean_pressure, h), level);
        return CappedRestoration::Restarted;
    }
    let plain = wanted / total;
    let peak = pressure.iter().fold(0.0f64, |m, &p| m.max(p));
    if peak < h && peak * plain < h {
        pressure.iter_mut().for_each(|v| *v *= plain);
        return CappedRestoration::Held;
    }
    let capped = pressure.iter().filter(|&&p| p >= h).count();
    let keep_capped = (capped as f64) * h < wanted;
    let scale = capped_scale(pressure, wanted, h, keep_capped);
    for p in pressure.iter_mut() {
        if !(keep_capped && *p >= h) {
            *p = (scale * *p).min(h);
        }
    }
    match keep_capped {
        true => CappedRestoration::Held,
        false => CappedRestoration::Released,
    }
}

/// What a capped load restoration ([`restore_capped_load`]) did. Only [`Self::Held`] is a
/// restoration an iteration converges through: the other two throw away the plastic set
/// (or the whole pressure), and an iteration that needs them again and again is cycling
/// (`capped_load.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum CappedRestoration {
    /// The points at the cap held there (or none at it), the others scaled.
    Held,
    /// The capped points alone carried more than the load: every point scaled, the
    /// plastic set released.
    Released,
    /// The points in contact could not carry the load below the cap: the pressure
    /// restarted from the bearing area ([`bearing_start`]).
    Restarted,
}

impl CappedRestoration {
    /// Whether the restoration threw away the plastic set or the pressure.
    pub(super) fn lost_the_set(self) -> bool {
        self != CappedRestoration::Held
    }
}

/// A start that carries the load `n p̄` below the cap `h`: the pressure `n p̄ / m`, uniform
/// on the `m ≥ n p̄ / h` points of lowest `level` (the gap up to a constant: the points the
/// indenter penetrates most), zero elsewhere — the bearing area of a fully plastic contact,
/// the limit `h → 0` of the capped problem (ContactMechanics' capped Polonsky–Keer finds the
/// same set by bisection on a gap offset). The threshold is found by bisection on the
/// levels (at most 64 passes, no allocation); ties at the threshold all enter.
pub(super) fn bearing_start(
    pressure: &mut [f64],
    (mean_pressure, h): (f64, f64),
    level: impl Fn(usize) -> f64,
) {
    let n = pressure.len();
    let wanted = mean_pressure * n as f64;
    let needed = ((wanted / h).ceil() as usize).clamp(1, n);
    let (mut low, mut high) = (0..n).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), i| {
        (lo.min(level(i)), hi.max(level(i)))
    });
    // Invariant: fewer than `needed` points lie at or below `low`, at least `needed` at or
    // below `high` (unless `low` is the lowest level and enough points tie at it).
    let count = |t: f64| (0..n).filter(|&i| level(i) <= t).count();
    if count(low) < needed {
        for _ in 0..64 {
            let mid = 0.5 * (low + high);
            if !(mid > low && mid < high) {
                break;
            }
            if count(mid) >= needed {
                high = mid;
            } else {
                low = mid;
            }
        }
    } else {
        high = low;
    }
    let m = count(high).max(1);
    let value = wanted / m as f64;
    for (i, p) in pressure.iter_mut().enumerate() {
        *p = if level(i) <= high { value } else { 0.0 };
    }
}

/// The `s` for which the load `Σ min(s p, h)` (points at the cap held there if
/// `keep_capped`) is `wanted`: Newton's method on this increasing, concave,
/// piecewise-linear function of `s`, exact once the capped set settles (from below it
/// stays below and rises; the left slope at a kink, so that a scale that caps every point
/// still moves down). A step taken on the same linear piece as the one before (the same
/// slope) is the last: the root up to rounding (waiting for two equal iterates instead
/// let rounding run the 64 passes, a quarter of a capped BCCG solve's time at 256²).
pub(super) fn capped_scale(pressure: &[f64], wanted: f64, h: f64, keep_capped: bool) -> f64 {
    let mut scale = 1.0;
    let mut previous_slope = f64::NAN;
    for _ in 0..64 {
        let (mut carried, mut slope) = (0.0, 0.0);
        for &p in pressure {
            if keep_capped && p >= h {
                carried += h;
            } else if scale * p <= h {
                carried += scale * p;
                slope += p;
            } else {
                carried += h;
            }
        }
        if slope <= 0.0 {
            break;
        }
        let next = scale + (wanted - carried) / slope;
        let settled = slope == previous_slope;
        if next == scale || settled {
            scale = next;
            break;
        }
        (scale, previous_slope) = (next, slope);
    }
    scale
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
