//! Adhesion in the MDR by **Heß's rule**: a line of linear springs (stiffness `E*Δx`) that
//! stick to the indenter once they touch it and let go, one at a time from the edges of a
//! contact, when stretched beyond the critical elongation
//!
//! `Δl(a) = √(2πaw/E*)` ([`crate::reference::adhesion::critical_elongation`]),
//!
//! `a` being the half-width of the contact the spring belongs to and `w = Δγ` the work of
//! adhesion (Popov & Heß, *Method of Dimensionality Reduction in Contact Mechanics and
//! Friction*, Springer 2015, ch. 6). For an axisymmetric indenter, mapped to its 1D profile
//! ([`super::Axisymmetric`]), the rule is exact: the edge condition is JKR's (energy
//! release rate `w` at the crack tip), so the retraction follows the JKR curve
//! ([`crate::reference::Jkr`]) and lets go at its pull-off forces, and a flat punch lets go
//! at Kendall's force ([`crate::reference::Kendall`]).
//!
//! **The model, precisely.** Spring `i` has the initial gap `s_i ≥ 0` (as in
//! [`super::Foundation`]: `z_max − z_i` for a line, `g_i − min g` for a profile; `+∞`
//! never touches), kept here in the springs' order along the line, since a contact is a
//! run of neighbours. At indentation `d` an attached spring carries `E*Δx (d − s_i)`,
//! tensile when `d < s_i`. Then
//! * **attachment**: a spring attaches when the indenter presses it (`d > s_i`), on
//!   approach and on re-approach alike; adhesion of zero range pulls nothing in from a
//!   distance, so the approach follows the non-adhesive curve;
//! * **detachment**: a *contact* is a maximal run of attached neighbours, of half-width
//!   `a = (springs in it)·Δx/2` (the same count-to-width rule as the flat punch's
//!   stiffness, [`super::indenter`]): each spring stands for a strip `Δx` wide, so the
//!   contact's edge lies half a spacing beyond its end spring. A spring lets go when its
//!   elongation exceeds `Δl(a)`. An end spring is judged *at the edge*: by the larger of
//!   its own gap and the edge's, extrapolated linearly from the end spring and its inner
//!   neighbour, `s_e + (s_e − s_{e∓1})/2` (exact for a punch; a lone spring uses its own
//!   gap), and never while it is still pressed (`d ≥ s_e`; on a rough line the
//!   extrapolation can reach far). Taking the end spring's own gap alone puts the edge half a spacing inside `a`:
//!   for a sphere that shifts the approach by `aΔx/R` and the pull-off force by
//!   `1.5·Δx/a` (measured: +1.0 % at `a/Δx = 152`, halving with `Δx`); with the edge gap
//!   the error is second order. Under a convex axisymmetric indenter the ends are always
//!   the most stretched, so this is Heß's rule and the contact shrinks from its edge; on
//!   a rough line a stretched valley inside a contact lets go too, which splits the
//!   contact in two (without it a line in full contact would hang by its valleys even as
//!   `Δγ → 0`; with it the non-adhesive curve is the limit). Each release shrinks or
//!   splits a contact and so lowers `Δl`: releases cascade until every spring holds.
//!   The stable state at `d` is unique (a release only lowers other springs'
//!   thresholds, the reason for the larger of the two gaps at the ends), so it does not
//!   depend on the steps by which `d` decreased;
//! * the result is **hysteresis**: retraction starts at the contact of the approach,
//!   holds it as a punch (slope `E*Δx·springs`) until the ends reach `Δl`, then shrinks
//!   along the JKR curve.
//!
//! On a rough line every contact (run) obeys the rule with its own width; this treats the
//! runs as independent axisymmetric contacts, which is the rule's reach and not more: for
//! one axisymmetric contact it is exact, for a rough line it is the MDR's model.
//!
//! A **retraction** is computed event by event ([`AdhesiveLine::retract`]): the next
//! release is at the largest `d` at which an end of some contact stops holding,
//! `d = s_end − Δl(a)`; between events the force is linear in `d`, so the curve of the
//! events (a point just before and just after each release) is exact, and
//! * the **force-controlled pull-off** is its least force (where the force can no longer
//!   be held; the tooth of one release, `E*Δx·Δl`, is below the discretisation);
//! * the **displacement-controlled pull-off** is the force just before the last cascade,
//!   the one that leaves no spring attached.
//!
//! Cost: `O(N)` per move, `O(N log N)` for a whole retraction (a heap of contacts).
//!
//! # Example
//! ```
//! use asperity::mdr::{AdhesiveLine, Axisymmetric};
//! use asperity::reference::{Jkr, PullOff};
//! let dx = 1e-3;
//! let profile = Axisymmetric::Sphere { radius: 1.0 }.sample(1001, dx)?;
//! let mut line = AdhesiveLine::from_profile(&profile, dx, 1.0, 1e-3)?;
//! line.move_to(0.09, &mut |_| {})?; // a = 0.3
//! let pull = line.retract(&mut |_| {}).expect("in contact");
//! let jkr = Jkr::new(1.0, 1.0, 1e-3)?;
//! let expected = jkr.pull_off_force(PullOff::ForceControlled);
//! assert!((pull.force_controlled.force / expected - 1.0).abs() < 1e-4);
//! # Ok::<(), asperity::Error>(())
//! ```

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::foundation::CurvePoint;
use crate::reference::adhesion::critical_elongation;
use crate::{Error, Result};

/// The pull-off forces of a retraction (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PullOffs {
    /// The point of least force (force control).
    pub force_controlled: CurvePoint,
    /// The point just before the last cascade of releases (displacement control).
    pub displacement_controlled: CurvePoint,
}

/// Springs that stick by Heß's rule (module docs), with their state.
#[derive(Debug, Clone, PartialEq)]
pub struct AdhesiveLine {
    /// Initial gaps in the springs' order along the line.
    gaps: Vec<f64>,
    attached: Vec<bool>,
    spacing: f64,
    modulus: f64,
    work_of_adhesion: f64,
    indentation: f64,
    /// Springs attached, and the compensated sum of their gaps.
    count: usize,
    gap_sum: Compensated,
    /// The largest gap of any range of springs.
    widest: MaxTree,
}

/// A segment tree of `(gap, index)` for the largest gap of a range in `O(log N)` (the
/// gaps never change; ties go to the lower index).
#[derive(Debug, Clone, PartialEq)]
struct MaxTree {
    size: usize,
    nodes: Vec<(f64, usize)>,
}

impl MaxTree {
    fn new(values: &[f64]) -> Self {
        let size = values.len();
        let mut nodes = vec![(f64::NEG_INFINITY, usize::MAX); 2 * size];
        for (i, &v) in values.iter().enumerate() {
            nodes[size + i] = (v, i);
        }
        for i in (1..size).rev() {
            nodes[i] = Self::better(nodes[2 * i], nodes[2 * i + 1]);
        }
        MaxTree { size, nodes }
    }

    fn better(a: (f64, usize), b: (f64, usize)) -> (f64, usize) {
        match a.0.total_cmp(&b.0) {
            Ordering::Greater => a,
            Ordering::Less => b,
            Ordering::Equal if a.1 <= b.1 => a,
            Ordering::Equal => b,
        }
    }

    /// The largest value in `low..high` (non-empty) and its index.
    fn max(&self, low: usize, high: usize) -> (f64, usize) {
        let (mut l, mut h) = (low + self.size, high + self.size);
        let mut best = (f64::NEG_INFINITY, usize::MAX);
        while l < h {
            if l % 2 == 1 {
                best = Self::better(best, self.nodes[l]);
                l += 1;
            }
            if h % 2 == 1 {
                h -= 1;
                best = Self::better(best, self.nodes[h]);
            }
            l /= 2;
            h /= 2;
        }
        best
    }
}

/// A Neumaier sum that can add and remove terms.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Compensated {
    sum: f64,
    error: f64,
}

impl Compensated {
    fn add(&mut self, x: f64) {
        let t = self.sum + x;
        self.error += if self.sum.abs() >= x.abs() {
            (self.sum - t) + x
        } else {
            (x - t) + self.sum
        };
        self.sum = t;
    }

    fn value(&self) -> f64 {
        self.sum + self.error
    }
}

/// A contact (a run of attached springs `left..=right`) keyed by the indentation at which
/// its next release happens: the heap's largest first.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Release {
    at: f64,
    left: usize,
    right: usize,
    /// The spring that lets go.
    spring: usize,
}

impl Eq for Release {}

impl PartialOrd for Release {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Release {
    fn cmp(&self, other: &Self) -> Ordering {
        // Ties by position, so that the order of releases is the same on every run.
        self.at
            .total_cmp(&other.at)
            .then_with(|| other.left.cmp(&self.left))
    }
}

impl AdhesiveLine {
    /// A rough line of heights `z_i` (positive up, finite), springs `spacing` apart: gaps
    /// `z_max − z_i`; nothing attached, indentation 0.
    pub fn from_heights(
        heights: &[f64],
        spacing: f64,
        modulus: f64,
        work_of_adhesion: f64,
    ) -> Result<Self> {
        crate::ensure_finite("line", heights)?;
        let top = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let gaps = heights.iter().map(|z| top - z).collect();
        Self::new(gaps, spacing, modulus, work_of_adhesion)
    }

    /// An indenter profile `g_i` in the springs' order (lowest point touches first; `+∞`
    /// never touches; NaN and `−∞` refused): gaps `g_i − min g`.
    pub fn from_profile(
        profile: &[f64],
        spacing: f64,
        modulus: f64,
        work_of_adhesion: f64,
    ) -> Result<Self> {
        if let Some((index, &value)) = profile
            .iter()
            .enumerate()
            .find(|(_, v)| v.is_nan() || **v == f64::NEG_INFINITY)
        {
            return Err(Error::NonFinite {
                what: "profile".into(),
                index,
                value,
            });
        }
        let bottom = profile.iter().copied().fold(f64::INFINITY, f64::min);
        if !bottom.is_finite() {
            return Err(Error::invalid(
                "profile",
                "no point of the profile is finite: nothing can touch",
            ));
        }
        let gaps = profile.iter().map(|g| g - bottom).collect();
        Self::new(gaps, spacing, modulus, work_of_adhesion)
    }

    fn new(gaps: Vec<f64>, spacing: f64, modulus: f64, work_of_adhesion: f64) -> Result<Self> {
        if gaps.is_empty() {
            return Err(Error::invalid("profile", "it has no points"));
        }
        crate::positive_finite("dx", spacing, "the spring spacing Δx")?;
        crate::positive_finite("modulus", modulus, "the modulus E*")?;
        crate::positive_finite(
            "work_of_adhesion",
            work_of_adhesion,
            "the work of adhesion Δγ",
        )?;
        let attached = vec![false; gaps.len()];
        let widest = MaxTree::new(&gaps);
        Ok(AdhesiveLine {
            widest,
            gaps,
            attached,
            spacing,
            modulus,
            work_of_adhesion,
            indentation: 0.0,
            count: 0,
            gap_sum: Compensated::default(),
        })
    }

    /// The state now: indentation, force `E*Δx Σ (d − s_i)` over the attached springs,
    /// stiffness `E*Δx·(attached)` (the slope at a fixed set), springs attached.
    pub fn point(&self) -> CurvePoint {
        let k = self.modulus * self.spacing;
        let d = self.indentation;
        CurvePoint {
            indentation: d,
            force: k * (self.count as f64 * d - self.gap_sum.value()),
            stiffness: k * self.count as f64,
            contacts: self.count,
        }
    }

    /// Which springs are attached, in their order along the line.
    pub fn attached(&self) -> &[bool] {
        &self.attached
    }

    /// Moves the indenter to `d` (finite): on approach every spring reached attaches; on
    /// retraction the releases happen, each reported to `emit` as in
    /// [`AdhesiveLine::retract`]. Returns the state at `d`.
    pub fn move_to(&mut self, d: f64, emit: &mut dyn FnMut(CurvePoint)) -> Result<CurvePoint> {
        if !d.is_finite() {
            return Err(Error::invalid(
                "indentation",
                format!("must be finite, got {}", crate::input::short_number(d)),
            ));
        }
        if d >= self.indentation {
            self.indentation = d;
            for (i, &gap) in self.gaps.iter().enumerate() {
                if gap < d && !self.attached[i] {
                    self.attached[i] = true;
                    self.count += 1;
                    self.gap_sum.add(gap);
                }
            }
        } else {
            self.release_down_to(d, emit);
            self.indentation = d;
        }
        Ok(self.point())
    }

    /// Retracts until no spring is attached, reporting the exact curve to `emit` (a point
    /// just before and just after each release; linear in between) and returning the
    /// pull-offs; `None` if nothing was attached.
    pub fn retract(&mut self, emit: &mut dyn FnMut(CurvePoint)) -> Option<PullOffs> {
        if self.count == 0 {
            return None;
        }
        let mut least = self.point();
        let mut cascade_start = least;
        let mut last_at = f64::INFINITY;
        self.release_down_to(f64::NEG_INFINITY, &mut |p| {
            // Points come in pairs (before, after): the before point is the one that
            // carries the tension a release relieves.
            if p.force < least.force {
                least = p;
            }
            if p.indentation < last_at {
                cascade_start = p;
                last_at = p.indentation;
            }
            emit(p);
        });
        Some(PullOffs {
            force_controlled: least,
            displacement_controlled: cascade_start,
        })
    }

    /// The indentation at which the first spring of the contact `left..=right` lets go,
    /// and which: the inside by its own gap, the ends by their edge gap
    /// ([`Self::end_gap`]) but never while still pressed (`d < s_e` too).
    fn release_at(&self, left: usize, right: usize) -> Release {
        let half_width = (right - left + 1) as f64 * self.spacing / 2.0;
        let limit = critical_elongation(half_width, self.modulus, self.work_of_adhesion);
        let end = |e: usize, other: usize| (self.gaps[e].min(self.end_gap(e, other) - limit), e);
        let mut best = end(left, right);
        if right > left {
            best = MaxTree::better(best, end(right, left));
        }
        if right > left + 1 {
            let (gap, inside) = self.widest.max(left + 1, right);
            best = MaxTree::better(best, (gap - limit, inside));
        }
        Release {
            at: best.0,
            left,
            right,
            spring: best.1,
        }
    }

    /// The gap at which the end spring `end` of a contact (whose other end is `other`) is
    /// judged: the larger of its own and the edge's, half a spacing beyond it, extrapolated
    /// from the end spring and its inner neighbour; a lone spring's own gap. The larger
    /// of the two, so that a spring's threshold only falls as its contact shrinks or
    /// splits, which makes the stable state unique.
    fn end_gap(&self, end: usize, other: usize) -> f64 {
        let gap = self.gaps[end];
        let edge = match end.cmp(&other) {
            Ordering::Equal => gap,
            Ordering::Less => gap + (gap - self.gaps[end + 1]) / 2.0,
            Ordering::Greater => gap + (gap - self.gaps[end - 1]) / 2.0,
        };
        edge.max(gap)
    }

    /// Releases, event by event, every end spring that does not hold at `d`.
    fn release_down_to(&mut self, d: f64, emit: &mut dyn FnMut(CurvePoint)) {
        let mut heap = BinaryHeap::new();
        let mut i = 0;
        while i < self.attached.len() {
            if self.attached[i] {
                let left = i;
                while i + 1 < self.attached.len() && self.attached[i + 1] {
                    i += 1;
                }
                heap.push(self.release_at(left, i));
            }
            i += 1;
        }
        while let Some(next) = heap.peek().copied() {
            if next.at <= d {
                break;
            }
            heap.pop();
            self.indentation = next.at.min(self.indentation);
            emit(self.point());
            let (left, right, gone) = (next.left, next.right, next.spring);
            self.attached[gone] = false;
            self.count -= 1;
            self.gap_sum.add(-self.gaps[gone]);
            if self.count == 0 {
                self.gap_sum = Compensated::default();
            }
            emit(self.point());
            // What is left of the contact: one run, or two when it split inside.
            if gone > left {
                heap.push(self.release_at(left, gone - 1));
            }
            if gone < right {
                heap.push(self.release_at(gone + 1, right));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::indenter::Axisymmetric;
    use super::super::{Foundation, Spring, SpringLaw};
    use super::*;
    use crate::reference::{Jkr, Kendall, PullOff};
    use rand::{RngExt, SeedableRng};

    fn sphere(radius: f64, dx: f64, n: usize, w: f64) -> AdhesiveLine {
        let profile = Axisymmetric::Sphere { radius }.sample(n, dx).unwrap();
        AdhesiveLine::from_profile(&profile, dx, 1.0, w).unwrap()
    }

    /// Relative errors of the two pull-offs of a sphere (R = 1, E* = 1, w = 1e-3) retracted
    /// from a = 0.3 on springs Δx apart.
    fn jkr_errors(dx: f64) -> (f64, f64) {
        let n = (1.0 / dx) as usize | 1;
        let mut line = sphere(1.0, dx, n, 1e-3);
        line.move_to(0.09, &mut |_| {}).unwrap();
        let pull = line.retract(&mut |_| {}).unwrap();
        let jkr = Jkr::new(1.0, 1.0, 1e-3).unwrap();
        let relative = |p: CurvePoint, control| p.force / jkr.pull_off_force(control) - 1.0;
        (
            relative(pull.force_controlled, PullOff::ForceControlled),
            relative(
                pull.displacement_controlled,
                PullOff::DisplacementControlled,
            ),
        )
    }

    #[test]
    fn a_sphere_lets_go_at_the_jkr_pull_offs_converging_with_dx() {
        // At Δx = 1e-3 the pull-off radii are 152 Δx (force) and 73 Δx (displacement).
        // Force control converges at second order (measured: 4.2e-4, 1.3e-4, 4.0e-5 at
        // Δx = 4, 2, 1 ·1e-3). Under displacement control the contact lets go at the grid
        // radius nearest the least approach, where F' = −8E*a²/R: an error up to
        // 1.2·(Δx/2)/a of the force that oscillates with Δx (+1.3e-2, −3.6e-3, +4.5e-3).
        let jkr = Jkr::new(1.0, 1.0, 1e-3).unwrap();
        let mut last = f64::INFINITY;
        for dx in [4e-3, 2e-3, 1e-3, 5e-4] {
            let (force, displacement) = jkr_errors(dx);
            eprintln!("Δx = {dx}: force control {force:+.2e}, displacement {displacement:+.2e}");
            assert!(force.abs() < last && force.abs() < 1e-3, "{force}");
            last = force.abs();
            let radius = jkr.pull_off_radius(PullOff::DisplacementControlled);
            assert!(
                displacement.abs() < 0.6 * dx / radius + 1e-4,
                "{displacement}"
            );
        }
    }

    #[test]
    fn the_retraction_of_a_sphere_is_the_jkr_curve() {
        // Just before each release of a symmetric contact (2m + 1 springs, a = (m + ½)Δx)
        // the edge condition holds, so the point is JKR's at that a: d = a²/R − Δl(a) up
        // to the edge gap's extrapolation, ¾Δx²/R, and the force up to that shift times
        // 2E*a (2.4e-5 of the pull-off force here; the midpoint sum adds 1e-9).
        let (dx, w) = (5e-4, 1e-3);
        let mut line = sphere(1.0, dx, 2001, w);
        line.move_to(0.09, &mut |_| {}).unwrap();
        let jkr = Jkr::new(1.0, 1.0, w).unwrap();
        let scale = jkr.pull_off_force(PullOff::ForceControlled).abs();
        // Below the displacement-controlled pull-off radius the last cascade runs at one
        // d, past each state's own threshold: those points are not on the curve.
        let cascade = jkr.pull_off_radius(PullOff::DisplacementControlled) + dx;
        let (mut checked, mut index) = (0, 0);
        line.retract(&mut |p| {
            let before = index % 2 == 0;
            index += 1;
            let a = p.contacts as f64 * dx / 2.0;
            if before && p.contacts % 2 == 1 && a > cascade {
                assert!((p.indentation - jkr.approach(a)).abs() < dx * dx, "{p:?}");
                assert!((p.force - jkr.force(a)).abs() < 1e-4 * scale, "{p:?}");
                checked += 1;
            }
        });
        // Releases go in pairs down to the displacement-controlled pull-off at a = 146 Δx.
        assert!(checked > 400, "{checked}");
    }

    #[test]
    fn a_punch_lets_go_at_kendalls_force() {
        // 2m + 1 = 41 springs under a = 20.5 Δx: exact, both controls.
        let dx = 0.01;
        let radius = 20.5 * dx;
        let profile = Axisymmetric::FlatPunch { radius }.sample(81, dx).unwrap();
        let mut line = AdhesiveLine::from_profile(&profile, dx, 2.0, 0.05).unwrap();
        line.move_to(1e-3, &mut |_| {}).unwrap();
        let pull = line.retract(&mut |_| {}).unwrap();
        let kendall = Kendall::new(radius, 2.0, 0.05).unwrap();
        for p in [pull.force_controlled, pull.displacement_controlled] {
            assert!(
                (p.force / kendall.pull_off_force() - 1.0).abs() < 1e-12,
                "{p:?}"
            );
            assert!((p.indentation / kendall.pull_off_approach() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn the_approach_is_non_adhesive_and_the_loop_has_hysteresis() {
        let (dx, w) = (1e-3, 1e-3);
        let mut line = sphere(1.0, dx, 1001, w);
        let profile = Axisymmetric::Sphere { radius: 1.0 }
            .sample(1001, dx)
            .unwrap();
        let spring = Spring::new(SpringLaw::Linear, dx, 1.0).unwrap();
        let plain = Foundation::from_profile(&profile, spring).unwrap();
        for d in [1e-4, 1e-3, 0.01, 0.05] {
            let p = line.move_to(d, &mut |_| {}).unwrap();
            let q = plain.evaluate(d);
            assert_eq!(p.contacts, q.contacts);
            assert!((p.force - q.force).abs() <= 1e-12 * q.force, "{p:?} {q:?}");
        }
        // Back to d = 0.01: the contact of d = 0.05 holds, so the force is below the
        // approach's at the same d (and tensile at d = 0).
        let back = line.move_to(0.01, &mut |_| {}).unwrap();
        assert!(back.force < plain.evaluate(0.01).force);
        assert!(back.contacts > plain.evaluate(0.01).contacts);
        let zero = line.move_to(0.0, &mut |_| {}).unwrap();
        assert!(zero.force < 0.0 && zero.contacts > 0, "{zero:?}");
        // Re-approach: springs reattach on touching; deeper than before, all of them.
        let again = line.move_to(0.06, &mut |_| {}).unwrap();
        assert_eq!(again.contacts, plain.evaluate(0.06).contacts);
    }

    /// The naive rule: scan every run, release every spring stretched beyond Δl (the ends
    /// judged at their end gap), until none.
    fn naive_release(line: &AdhesiveLine, d: f64) -> Vec<bool> {
        let mut attached = line.attached.clone();
        loop {
            let mut changed = false;
            let n = attached.len();
            let mut i = 0;
            while i < n {
                if !attached[i] {
                    i += 1;
                    continue;
                }
                let left = i;
                while i + 1 < n && attached[i + 1] {
                    i += 1;
                }
                let a = (i - left + 1) as f64 * line.spacing / 2.0;
                let limit = critical_elongation(a, line.modulus, line.work_of_adhesion);
                let right = i;
                for (k, slot) in attached.iter_mut().enumerate().take(right + 1).skip(left) {
                    let pressed = line.gaps[k] <= d;
                    let stretched = match k {
                        _ if k == left => line.end_gap(left, right) - d > limit && !pressed,
                        _ if k == right => line.end_gap(right, left) - d > limit && !pressed,
                        _ => line.gaps[k] - d > limit,
                    };
                    if stretched {
                        *slot = false;
                        changed = true;
                    }
                }
                i += 1;
            }
            if !changed {
                return attached;
            }
        }
    }

    #[test]
    fn rough_line_releases_match_the_naive_rule_in_any_steps() {
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(7);
        let heights: Vec<f64> = (0..400).map(|_| rng.random::<f64>()).collect();
        let mut line = AdhesiveLine::from_heights(&heights, 0.01, 1.0, 2e-3).unwrap();
        line.move_to(0.6, &mut |_| {}).unwrap();
        let start = line.clone();
        let mut direct = start.clone();
        for d in [0.5, 0.3, 0.1, -0.05, -0.2] {
            let expected = naive_release(&line, d);
            line.move_to(d, &mut |_| {}).unwrap();
            assert_eq!(line.attached, expected, "d = {d}, in steps");
            let mut once = start.clone();
            once.move_to(d, &mut |_| {}).unwrap();
            assert_eq!(once.attached, expected, "d = {d}, in one move");
            let sum: f64 = (0..400)
                .filter(|&i| expected[i])
                .map(|i| d - line.gaps[i])
                .sum();
            assert!((line.point().force - 0.01 * sum).abs() < 1e-12, "d = {d}");
        }
        let pull = direct.retract(&mut |_| {}).unwrap();
        assert!(pull.force_controlled.force <= pull.displacement_controlled.force);
        assert_eq!(direct.point().contacts, 0);
        assert_eq!(direct.point().force, 0.0);
    }

    #[test]
    fn a_faint_adhesion_on_a_rough_line_gives_the_non_adhesive_curve() {
        // Δγ → 0: Δl → 0, so no spring holds a tension beyond E*Δx·Δl(L/2); the least force
        // of a retraction from full contact is bounded by E*·L·Δl(L/2) = 1.4e-4 here. (A
        // rule that let only the ends of a contact go would hold the whole line by its
        // valleys: about −2.)
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(3);
        let heights: Vec<f64> = (0..400).map(|_| rng.random::<f64>()).collect();
        let w = 1e-10;
        let mut line = AdhesiveLine::from_heights(&heights, 0.01, 1.0, w).unwrap();
        line.move_to(1.0, &mut |_| {}).unwrap();
        assert_eq!(line.point().contacts, 400);
        let pull = line.retract(&mut |_| {}).unwrap();
        let bound = 4.0 * critical_elongation(2.0, 1.0, w);
        assert!(
            pull.force_controlled.force > -bound,
            "{:?}",
            pull.force_controlled
        );
        let spring = Spring::new(SpringLaw::Linear, 0.01, 1.0).unwrap();
        let plain = Foundation::from_heights(&heights, spring).unwrap();
        let mut again = AdhesiveLine::from_heights(&heights, 0.01, 1.0, w).unwrap();
        again.move_to(1.0, &mut |_| {}).unwrap();
        for d in [0.9, 0.5, 0.2, 0.05] {
            let p = again.move_to(d, &mut |_| {}).unwrap();
            let q = plain.evaluate(d);
            assert!((p.force - q.force).abs() < bound, "d = {d}: {p:?} {q:?}");
        }
    }

    #[test]
    fn bad_parameters_are_refused() {
        for w in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = AdhesiveLine::from_heights(&[0.0, 1.0], 0.1, 1.0, w).unwrap_err();
            assert!(err.to_string().contains("work of adhesion"), "{err}");
        }
        assert!(AdhesiveLine::from_profile(&[f64::NAN], 0.1, 1.0, 1.0).is_err());
        let mut line = AdhesiveLine::from_heights(&[0.0, 1.0], 0.1, 1.0, 1.0).unwrap();
        assert!(line.move_to(f64::NAN, &mut |_| {}).is_err());
        assert!(line.retract(&mut |_| {}).is_none());
    }
}
