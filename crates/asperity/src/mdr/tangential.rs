//! Tangential contact on the MDR foundation: no-slip stiffness and partial slip under a
//! tangential force `Q ≤ μF`, loading and unloading (Popov & Heß, ch. 7 and 15;
//! Ciavarella 1998, Jäger 1998).
//!
//! Beside every normal spring stands a tangential spring. For linear springs its stiffness
//! is `G*·Δx` with the effective shear modulus `G*` (`1/G* = (2−ν₁)/4G₁ + (2−ν₂)/4G₂`); for
//! the non-linear microscale laws (15.2) and (15.7) each spring stands for the asperities
//! below the resolution and gets Mindlin's ratio of its normal tangent stiffness,
//! `k_t,i = (G*/E*)·f'(u_i)`. For bodies of one Poisson's ratio ν (or one rigid body)
//! `G*/E* = 2(1−ν)/(2−ν)` ([`mindlin_ratio`]): the tangential to normal stiffness ratio of a
//! circular contact.
//!
//! The normal indentation `d` is held fixed while the indenter is displaced tangentially by
//! `u`; the normal–tangential coupling is neglected (exact when both bodies have the same
//! elastic constants, standard otherwise). Each spring is a Coulomb element: it sticks with
//! force `k_t,i·u` until that reaches `μ f_i` (its normal force times the friction
//! coefficient) and then slides at `μ f_i`. A spring's **slip displacement** is
//! `t_i = μ f_i / k_t,i` — for linear springs `t_i = μ(E*/G*)(d − s_i)`, so springs slip
//! from the edge of the contact (largest gaps) inwards: the Ciavarella–Jäger superposition
//! on a line, exact for axisymmetric profiles by the MDR. Under monotone loading from rest
//!
//! `Q(u) = Σ_{t_i ≤ u} μ f_i + u·Σ_{t_i > u} k_t,i`,
//!
//! evaluated in `O(log N)` from prefix sums over the springs sorted by `t_i`, and inverted
//! exactly ([`PartialSlip::displacement`]). Unloading from `(u*, Q*)` and reloading from
//! `(−u*, −Q*)` follow Masing's rule, `Q = Q* − 2·Q((u* − u)/2)`, which is exact for
//! parallel Coulomb elements that start from rest (each element's own loop obeys it), and
//! the energy dissipated per cycle is `Σ_{t_i < u*} 4 μ f_i (u* − t_i)`.
//!
//! For the sphere this reproduces Cattaneo–Mindlin ([`crate::reference::CattaneoMindlin`]):
//! stick radius `c/a = (1 − Q/μF)^{1/3}`, displacement `u = μ(E*/G*)d[1 − (1 − Q/μF)^{2/3}]`
//! and the no-slip stiffness `2G*a`.
//!
//! # Example
//! ```
//! use asperity::mdr::{mindlin_ratio, Axisymmetric, Foundation, PartialSlip, Spring};
//! use asperity::reference::CattaneoMindlin;
//! let (radius, dx, d) = (1.0, 1e-3, 0.25); // a = 500 Δx
//! let profile = Axisymmetric::Sphere { radius }.sample(1201, dx)?;
//! let foundation = Foundation::from_profile(&profile, Spring::linear(dx, 1.0)?)?;
//! let ratio = mindlin_ratio(0.3)?;
//! let slip = PartialSlip::new(&foundation, d, ratio, 0.4)?;
//! let q = 0.5 * slip.friction_limit();
//! let exact = CattaneoMindlin { radius, modulus: 1.0, ratio, friction: 0.4 };
//! let u = slip.displacement(q)?;
//! assert!((u / exact.displacement(d, q) - 1.0).abs() < 1e-3);
//! # Ok::<(), asperity::Error>(())
//! ```

use serde::Serialize;

use super::foundation::Foundation;
use crate::{Error, Result};

/// `G*/E* = 2(1−ν)/(2−ν)` for bodies of one Poisson's ratio ν (or one rigid): Mindlin's
/// ratio of tangential to normal stiffness of a circular contact. ν must be in `[0, 0.5]`.
pub fn mindlin_ratio(poisson: f64) -> Result<f64> {
    check_poisson(poisson)?;
    Ok(2.0 * (1.0 - poisson) / (2.0 - poisson))
}

/// Whether `poisson` is a Poisson's ratio the library accepts: finite and in `[0, 0.5]`
/// (0.5, incompressible, included). The one rule for every quantity that takes ν.
pub fn is_poisson_ratio(poisson: f64) -> bool {
    poisson.is_finite() && (0.0..=0.5).contains(&poisson)
}

/// Refuses a Poisson's ratio outside `[0, 0.5]` (or not finite).
pub fn check_poisson(poisson: f64) -> Result<()> {
    if !is_poisson_ratio(poisson) {
        return Err(Error::invalid(
            "poisson",
            format!(
                "Poisson's ratio ν must be in [0, 0.5], got {}",
                crate::input::short_number(poisson)
            ),
        ));
    }
    Ok(())
}

/// Refuses a friction coefficient that is not positive and finite.
pub fn check_friction(friction: f64) -> Result<()> {
    if !crate::is_positive_finite(friction) {
        return Err(Error::invalid(
            "friction",
            format!(
                "the friction coefficient μ must be positive and finite, got {}",
                crate::input::short_number(friction)
            ),
        ));
    }
    Ok(())
}

/// Which part of a tangential loading cycle a point is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Branch {
    /// From rest to `(u*, Q*)`.
    Loading,
    /// From `(u*, Q*)` to `(−u*, −Q*)`.
    Unloading,
    /// From `(−u*, −Q*)` back to `(u*, Q*)`.
    Reloading,
}

impl Branch {
    /// `loading`, `unloading` or `reloading`.
    pub fn name(self) -> &'static str {
        match self {
            Branch::Loading => "loading",
            Branch::Unloading => "unloading",
            Branch::Reloading => "reloading",
        }
    }
}

/// One point of a tangential loading cycle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LoopPoint {
    /// The branch.
    pub branch: Branch,
    /// Tangential displacement u of the indenter.
    pub displacement: f64,
    /// Tangential force Q.
    pub force: f64,
    /// Springs that stick (do not slide) at this point.
    pub stick_springs: usize,
    /// The stick boundary as a normal compression: springs compressed by more stick.
    pub stick_compression: f64,
}

/// The springs in contact at one indentation, ready for tangential loading (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct PartialSlip {
    /// Slip displacements `t_i`, ascending.
    thresholds: Vec<f64>,
    /// `slipped[j] = Σ_{i<j} μ f_i` (springs sorted by `t_i`), length `n + 1`.
    slipped: Vec<f64>,
    /// `stuck[j] = Σ_{i≥j} k_t,i`, length `n + 1`.
    stuck: Vec<f64>,
    indentation: f64,
    normal_force: f64,
    friction: f64,
    ratio: f64,
    spring: super::Spring,
}

impl PartialSlip {
    /// The springs of `foundation` in contact at `indentation`, with tangential springs of
    /// `ratio` (`G*/E*`, e.g. [`mindlin_ratio`]) times their normal tangent stiffness and a
    /// friction coefficient `friction`. Refuses an indentation with no spring in contact.
    pub fn new(
        foundation: &Foundation,
        indentation: f64,
        ratio: f64,
        friction: f64,
    ) -> Result<Self> {
        check_friction(friction)?;
        if !(crate::is_positive_finite(ratio) && ratio <= 1.0) {
            return Err(Error::invalid(
                "ratio",
                format!(
                    "the stiffness ratio G*/E* must be in (0, 1], got {}",
                    crate::input::short_number(ratio)
                ),
            ));
        }
        crate::positive_finite("indentation", indentation, "the indentation d")?;
        let spring = *foundation.spring();
        let mut springs: Vec<(f64, f64, f64)> = foundation
            .gaps()
            .iter()
            .take_while(|&&gap| gap < indentation)
            .map(|&gap| {
                let (force, stiffness) = spring.force_and_stiffness(indentation - gap);
                let k = ratio * stiffness;
                (friction * force / k, friction * force, k)
            })
            .collect();
        if springs.is_empty() {
            return Err(Error::invalid(
                "indentation",
                format!("no spring is in contact at d = {indentation}"),
            ));
        }
        springs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let n = springs.len();
        let mut slipped = vec![0.0; n + 1];
        let mut stuck = vec![0.0; n + 1];
        for j in 0..n {
            slipped[j + 1] = slipped[j] + springs[j].1;
            stuck[n - 1 - j] = stuck[n - j] + springs[n - 1 - j].2;
        }
        Ok(PartialSlip {
            thresholds: springs.iter().map(|s| s.0).collect(),
            normal_force: slipped[n] / friction,
            slipped,
            stuck,
            indentation,
            friction,
            ratio,
            spring,
        })
    }

    /// The normal force F at the indentation.
    pub fn normal_force(&self) -> f64 {
        self.normal_force
    }

    /// The indentation d.
    pub fn indentation(&self) -> f64 {
        self.indentation
    }

    /// The friction limit μF: the largest tangential force before gross sliding.
    pub fn friction_limit(&self) -> f64 {
        self.slipped[self.slipped.len() - 1]
    }

    /// Springs in contact.
    pub fn contacts(&self) -> usize {
        self.thresholds.len()
    }

    /// The tangential stiffness before any slip (Mindlin's no-slip stiffness),
    /// `Σ k_t,i` (`2G*a` for a circular contact).
    pub fn no_slip_stiffness(&self) -> f64 {
        self.stuck[0]
    }

    /// The displacement at which the whole contact slides, `max t_i`.
    pub fn sliding_displacement(&self) -> f64 {
        self.thresholds[self.thresholds.len() - 1]
    }

    /// Springs still sliding-free (`t_i > u`) after monotone loading to `|u|`.
    pub fn stick_springs(&self, displacement: f64) -> usize {
        let u = displacement.abs();
        self.thresholds.len() - self.thresholds.partition_point(|&t| t <= u)
    }

    /// Tangential force after monotone loading from rest to displacement `u` (odd in `u`;
    /// `μF` beyond [`PartialSlip::sliding_displacement`]).
    pub fn force(&self, displacement: f64) -> f64 {
        let u = displacement.abs();
        let j = self.thresholds.partition_point(|&t| t <= u);
        (self.slipped[j] + u * self.stuck[j]).copysign(displacement)
    }

    /// The displacement of monotone loading at tangential force `Q`, `|Q| ≤ μF` (exact
    /// inverse of [`PartialSlip::force`]; at `|Q| = μF` the displacement where the last
    /// spring starts to slide).
    pub fn displacement(&self, force: f64) -> Result<f64> {
        self.check_force(force)?;
        let q = force.abs();
        let n = self.thresholds.len();
        // The first spring j whose force at its own threshold reaches q (binary search;
        // Q(t_j) grows with j): the springs before it have slid, the others stick.
        let (mut low, mut high) = (0, n);
        while low < high {
            let mid = low + (high - low) / 2;
            if self.force(self.thresholds[mid]) < q {
                low = mid + 1;
            } else {
                high = mid;
            }
        }
        let j = low;
        let u = if j == n {
            self.sliding_displacement()
        } else {
            (q - self.slipped[j]) / self.stuck[j]
        };
        Ok(u.copysign(force))
    }

    /// Refuses a tangential force that is not finite or exceeds `μF`.
    pub fn check_force(&self, force: f64) -> Result<()> {
        let limit = self.friction_limit();
        if !force.is_finite() || force.abs() > limit * (1.0 + 1e-12) {
            return Err(Error::invalid(
                "tangential_force",
                format!(
                    "the tangential force Q must be finite with |Q| <= μF = {} \
                     (beyond it the contact slides as a whole), got {}",
                    crate::input::short_number(limit),
                    crate::input::short_number(force)
                ),
            ));
        }
        Ok(())
    }

    /// The stick boundary after monotone loading to `u`, as the normal compression `w` of
    /// a spring that just starts to slide: springs compressed by more than `w` stick. Its
    /// gap is `d − w`; for linear springs `w = (G*/E*)·|u|/μ` exactly.
    pub fn stick_compression(&self, displacement: f64) -> f64 {
        let u = displacement.abs();
        let threshold = |w: f64| {
            let (f, k) = self.spring.force_and_stiffness(w);
            self.friction * f / (self.ratio * k)
        };
        if self.spring.is_linear() {
            return (self.ratio * u / self.friction).min(self.indentation);
        }
        // t(w) = μ f(w) / k_t(w) increases with w for every law; bisect.
        let (mut low, mut high) = (0.0, self.indentation);
        if threshold(high) <= u {
            return high;
        }
        for _ in 0..200 {
            let mid = 0.5 * (low + high);
            if threshold(mid) <= u {
                low = mid;
            } else {
                high = mid;
            }
        }
        0.5 * (low + high)
    }

    /// Energy dissipated per full cycle `±u*`: `Σ_{t_i < u*} 4 μ f_i (u* − t_i)`.
    pub fn dissipation(&self, amplitude: f64) -> f64 {
        let u = amplitude.abs();
        let j = self.thresholds.partition_point(|&t| t < u);
        let weighted: f64 = (0..j)
            .map(|i| (self.slipped[i + 1] - self.slipped[i]) * (u - self.thresholds[i]))
            .sum();
        4.0 * weighted
    }

    /// The cycle of amplitude `Q*` (`0 < Q* ≤ μF`): loading from rest to `Q*`, unloading
    /// to `−Q*` and reloading to `Q*` (Masing's rule), each branch at `points ≥ 2`
    /// displacements evenly spaced.
    pub fn cycle(&self, amplitude: f64, points: usize) -> Result<Vec<LoopPoint>> {
        if points < 2 {
            return Err(Error::invalid(
                "points",
                format!("a branch needs at least 2 points, got {points}"),
            ));
        }
        if amplitude.is_nan() || amplitude <= 0.0 {
            return Err(Error::invalid(
                "tangential_force",
                format!(
                    "the cycle's amplitude Q* must be positive, got {}",
                    crate::input::short_number(amplitude)
                ),
            ));
        }
        let top = self.displacement(amplitude)?;
        let q_top = self.force(top);
        let step = |i: usize| i as f64 / (points - 1) as f64;
        let mut cycle = Vec::with_capacity(3 * points);
        for i in 0..points {
            let u = top * step(i);
            cycle.push(self.point(Branch::Loading, u, self.force(u), u));
        }
        for (branch, sign) in [(Branch::Unloading, 1.0), (Branch::Reloading, -1.0)] {
            for i in 0..points {
                // Distance travelled since the turning point at sign·u*.
                let travel = 2.0 * top * step(i);
                let u = sign * (top - travel) + 0.0; // no -0.0
                let q = sign * (q_top - 2.0 * self.force(0.5 * travel));
                cycle.push(self.point(branch, u, q, 0.5 * travel));
            }
        }
        Ok(cycle)
    }

    /// A cycle point; `memory` is the monotone displacement that decides who sticks.
    fn point(&self, branch: Branch, u: f64, q: f64, memory: f64) -> LoopPoint {
        LoopPoint {
            branch,
            displacement: u,
            force: q,
            stick_springs: self.stick_springs(memory),
            stick_compression: self.stick_compression(memory),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdr::{Axisymmetric, Spring, SpringLaw};
    use crate::reference::CattaneoMindlin;

    const RADIUS: f64 = 1.0;
    const MODULUS: f64 = 1.7;
    const FRICTION: f64 = 0.35;

    /// A sphere on linear springs, `a/Δx` = `resolution`, ν = 0.3.
    fn sphere(resolution: f64) -> (PartialSlip, CattaneoMindlin, f64) {
        let dx = 1.0 / resolution;
        let d = 1.0; // a = sqrt(R d) = 1
        let n = 2 * (1.2 * resolution) as usize + 1;
        let profile = Axisymmetric::Sphere { radius: RADIUS }
            .sample(n, dx)
            .unwrap();
        let spring = Spring::linear(dx, MODULUS).unwrap();
        let foundation = Foundation::from_profile(&profile, spring).unwrap();
        let ratio = mindlin_ratio(0.3).unwrap();
        let slip = PartialSlip::new(&foundation, d, ratio, FRICTION).unwrap();
        let exact = CattaneoMindlin {
            radius: RADIUS,
            modulus: MODULUS,
            ratio,
            friction: FRICTION,
        };
        (slip, exact, d)
    }

    #[test]
    fn mindlin_ratio_has_its_limits_and_refuses_bad_poisson() {
        assert_eq!(mindlin_ratio(0.0).unwrap(), 1.0);
        assert!((mindlin_ratio(0.5).unwrap() - 2.0 / 3.0).abs() < 1e-15);
        assert!((mindlin_ratio(0.3).unwrap() - 1.4 / 1.7).abs() < 1e-15);
        for bad in [-0.1, 0.51, f64::NAN, f64::INFINITY] {
            let err = mindlin_ratio(bad).unwrap_err().to_string();
            assert!(err.starts_with("invalid poisson: Poisson's ratio ν must be in [0, 0.5]"));
        }
        assert!(check_friction(0.0).is_err() && check_friction(f64::NAN).is_err());
    }

    #[test]
    fn sphere_follows_cattaneo_mindlin_to_1e_3() {
        // a/Δx = 2000. The force sums are Riemann sums of smooth integrands with a
        // square-root edge: errors ~ (Δx/a)^{3/2} ≈ 1e-5 in F; the stick radius follows from
        // the exact stick compression, so it inherits only the error of u.
        let (slip, exact, d) = sphere(2000.0);
        let hertz = crate::reference::Hertz {
            radius: RADIUS,
            modulus: MODULUS,
        };
        assert!((slip.normal_force() / hertz.force(d) - 1.0).abs() < 1e-4);
        let k = slip.no_slip_stiffness() / exact.no_slip_stiffness(d);
        assert!((k - 1.0).abs() < 1e-3, "no-slip stiffness ratio {k}");
        let mu_f = slip.friction_limit();
        for fraction in [0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99] {
            let q = fraction * mu_f;
            let u = slip.displacement(q).unwrap();
            assert!((slip.force(u) / q - 1.0).abs() < 1e-12, "inverse");
            let u_exact = exact.displacement(d, fraction * exact.friction * hertz.force(d));
            assert!(
                (u / u_exact - 1.0).abs() < 1e-3,
                "Q/μF = {fraction}: u {u} vs {u_exact}"
            );
            let c = (RADIUS * (d - slip.stick_compression(u))).sqrt();
            let c_exact = (1.0 - fraction).cbrt();
            assert!(
                (c - c_exact).abs() < 1e-3,
                "Q/μF = {fraction}: c/a {c} vs {c_exact}"
            );
        }
        // Sliding as a whole at μF, refused beyond.
        assert!(slip.displacement(mu_f).is_ok());
        let err = slip.displacement(1.01 * mu_f).unwrap_err().to_string();
        assert!(err.contains("|Q| <= μF"), "{err}");
    }

    #[test]
    fn cycle_follows_mindlin_deresiewicz_and_its_dissipation() {
        let (slip, exact, d) = sphere(2000.0);
        let f = crate::reference::Hertz {
            radius: RADIUS,
            modulus: MODULUS,
        }
        .force(d);
        for fraction in [0.2, 0.6, 0.95] {
            let top = fraction * slip.friction_limit();
            let cycle = slip.cycle(top, 41).unwrap();
            assert_eq!(cycle.len(), 123);
            let exact_top = fraction * FRICTION * f;
            let scale = exact.displacement(d, exact_top);
            for p in cycle.iter().filter(|p| p.branch == Branch::Unloading) {
                let q = p.force / slip.friction_limit() * FRICTION * f;
                let u = exact.unloading_displacement(d, exact_top, q);
                assert!(
                    (p.displacement - u).abs() < 1e-3 * scale,
                    "Q*/μF = {fraction}: u {} vs {u}",
                    p.displacement
                );
            }
            // The loop closes, and its area (trapezoids on a fine cycle) is the dissipation.
            let last = cycle[cycle.len() - 1];
            assert!((last.force / top - 1.0).abs() < 1e-12);
            let fine = slip.cycle(top, 4001).unwrap();
            let area: f64 = fine[4001..]
                .windows(2)
                .filter(|w| w[0].branch == w[1].branch)
                .map(|w| -0.5 * (w[0].force + w[1].force) * (w[1].displacement - w[0].displacement))
                .sum();
            let w = slip.dissipation(slip.displacement(top).unwrap());
            let w_exact = exact.dissipation(d, exact_top);
            assert!((w / w_exact - 1.0).abs() < 2e-3, "W {w} vs {w_exact}");
            assert!(
                (area.abs() / w - 1.0).abs() < 1e-3,
                "loop area {area} vs {w}"
            );
        }
    }

    #[test]
    fn cycle_matches_coulomb_springs_stepped_one_by_one() {
        // Naive oracle: every spring a Coulomb element updated along the displacement path,
        // on a rough line with the non-linear law (15.7).
        let heights: Vec<f64> = (0..301)
            .map(|i| ((i * 7919 % 301) as f64 / 301.0).powf(1.3) - 0.4 * (i as f64 * 0.1).sin())
            .collect();
        let law = SpringLaw::Fractal {
            hurst: 0.7,
            rms_height: 0.3,
            size: 1.0,
        };
        let spring = Spring::new(law, 1.0 / 301.0, 2.0).unwrap();
        let foundation = Foundation::from_heights(&heights, spring).unwrap();
        let (d, ratio, mu) = (0.4, mindlin_ratio(0.2).unwrap(), 0.5);
        let slip = PartialSlip::new(&foundation, d, ratio, mu).unwrap();
        let top = 0.8 * slip.friction_limit();
        let cycle = slip.cycle(top, 101).unwrap();
        let top_u = cycle[100].displacement;
        let top_gap: f64 = heights.iter().copied().fold(f64::MIN, f64::max);
        let elements: Vec<(f64, f64)> = heights
            .iter()
            .map(|z| spring.force_and_stiffness(d - (top_gap - z)))
            .filter(|(f, _)| *f > 0.0)
            .map(|(f, k)| (mu * f, ratio * k))
            .collect();
        let mut state = vec![0.0; elements.len()];
        let mut previous = 0.0;
        for p in &cycle {
            let du = p.displacement - previous;
            previous = p.displacement;
            let mut q = 0.0;
            for (s, (limit, k)) in state.iter_mut().zip(&elements) {
                *s = (*s + k * du).clamp(-limit, *limit);
                q += *s;
            }
            assert!(
                (q - p.force).abs() < 1e-9 * top,
                "{:?}: {q} vs {}",
                p.branch,
                p.force
            );
            let sliding = state
                .iter()
                .zip(&elements)
                .filter(|(s, (limit, _))| s.abs() >= limit * (1.0 - 1e-12))
                .count();
            if p.displacement != 0.0 && p.displacement.abs() != top_u {
                assert_eq!(p.stick_springs + sliding, elements.len(), "{p:?}");
            }
        }
        assert!(slip.dissipation(top_u) > 0.0);
    }

    #[test]
    fn flat_punch_sticks_until_it_slides_as_a_whole() {
        // Equal compression everywhere: one slip displacement for all springs.
        let dx = 0.01;
        let profile = Axisymmetric::FlatPunch { radius: 0.505 }
            .sample(201, dx)
            .unwrap();
        let foundation =
            Foundation::from_profile(&profile, Spring::linear(dx, 1.0).unwrap()).unwrap();
        let slip = PartialSlip::new(&foundation, 0.01, 1.0, 0.5).unwrap();
        let u = slip.displacement(0.5 * slip.friction_limit()).unwrap();
        assert_eq!(slip.stick_springs(u), slip.contacts());
        assert!((slip.no_slip_stiffness() - 2.0 * 0.505).abs() < 1e-12);
    }
}
