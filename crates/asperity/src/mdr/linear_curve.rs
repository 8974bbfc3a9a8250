//! The whole force–indentation–stiffness curve of a rough line on **linear** springs, in
//! `O(N log N)` — in fact `O(N)`: sort the heights once (a radix sort,
//! [`super::radix_sort`]), then accumulate.
//!
//! With springs of stiffness `E*·Δx` and gaps `s_(1) ≤ s_(2) ≤ … ≤ s_(N)` (sorted,
//! `s_i = z_max − z_i`, so `s_(1) = 0`), the curve is piecewise linear in `d` with a
//! breakpoint where each spring first touches (SCIENCE.md §3, paper *Methods*):
//!
//! * with `j` springs in contact the indentation is `d_j = s_(j)` (`j = 1..=N`),
//! * the force there is `F_j = E*Δx Σ_{i≤j} (d_j − s_(i))`, accumulated without
//!   cancellation as `F_{j+1} = F_j + E*Δx · j · (d_{j+1} − d_j)` (all terms ≥ 0),
//! * the stiffness on `d_j < d < d_{j+1}` (equivalently `F_j < F < F_{j+1}`) is
//!   `k_j = E*Δx · j`.
//!
//! So `k(F)` is a step function: `k(F) = E*Δx · #{j : F_j ≤ F}` for `F ≥ 0`, found by binary
//! search ([`LinearCurve::stiffness_at_force`]) or, for ascending force levels, by one merge
//! walk ([`LinearCurve::stiffness_at_forces`]). Ties (equal heights) give equal breakpoints;
//! the step function then counts all tied springs, as it should.
//!
//! # Reuse for ensembles
//! A [`LinearCurve`] owns two buffers of `N` values. [`LinearCurve::recompute`] refills them
//! for the next line without allocating (once the capacity is reached), so an ensemble of
//! thousands of lines needs one curve per thread (e.g. rayon's `map_init`):
//!
//! ```
//! use asperity::mdr::LinearCurve;
//! use asperity::spectrum::Psd;
//! use asperity::surface::{LineGenerator, LineSpec, Normalisation};
//! let spec = LineSpec::new(4096, 1.0, Psd::power_law(0.5)?, Normalisation::RmsHeight(1.0))?;
//! let mut generator = LineGenerator::new(&spec)?;
//! let mut heights = vec![0.0; spec.n];
//! let mut curve = LinearCurve::new();
//! let forces = [1e-6, 1e-5, 1e-4]; // ascending
//! let mut stiffness = [0.0; 3];
//! for seed in 0..10 {
//!     generator.generate_into(seed, &mut heights)?;
//!     curve.recompute(&heights, spec.size / spec.n as f64, 1.0)?;
//!     curve.stiffness_at_forces(&forces, &mut stiffness);
//!     assert!(stiffness[0] <= stiffness[2]);
//! }
//! # Ok::<(), asperity::Error>(())
//! ```

use super::foundation::CurvePoint;
use super::radix_sort::{sort_descending, RadixScratch};
use crate::{Error, Result};

/// Breakpoints of the force–indentation curve of a line on linear springs (module docs).
#[derive(Debug, Clone, Default)]
pub struct LinearCurve {
    /// `d_j`, ascending; index `j − 1`.
    indentations: Vec<f64>,
    /// `F_j`, ascending; index `j − 1`.
    forces: Vec<f64>,
    /// `E*·Δx`.
    spring_stiffness: f64,
    /// `Δx`.
    spacing: f64,
    /// Buffers of the sort, kept between lines.
    scratch: RadixScratch,
}

impl PartialEq for LinearCurve {
    /// Equal curves: same breakpoints and spring stiffness (the sort's scratch is ignored).
    fn eq(&self, other: &Self) -> bool {
        self.indentations == other.indentations
            && self.forces == other.forces
            && self.spring_stiffness == other.spring_stiffness
            && self.spacing == other.spacing
    }
}

impl LinearCurve {
    /// An empty curve, to be filled by [`LinearCurve::recompute`].
    pub fn new() -> Self {
        LinearCurve::default()
    }

    /// An empty curve with room for lines of `n` points (no allocation up to `n`).
    pub fn with_capacity(n: usize) -> Self {
        LinearCurve {
            indentations: Vec::with_capacity(n),
            forces: Vec::with_capacity(n),
            spring_stiffness: 0.0,
            spacing: 0.0,
            scratch: RadixScratch::default(),
        }
    }

    /// The curve of a rough line of `heights` (positive up) on springs at spacing `Δx`
    /// with modulus `E*`.
    pub fn from_heights(heights: &[f64], spacing: f64, modulus: f64) -> Result<Self> {
        let mut curve = LinearCurve::with_capacity(heights.len());
        curve.recompute(heights, spacing, modulus)?;
        Ok(curve)
    }

    /// Refills the curve for another line, reusing the buffers. Errors (and leaves the
    /// curve empty) on an empty or non-finite line, or on `Δx`, `E*` not positive and
    /// finite.
    pub fn recompute(&mut self, heights: &[f64], spacing: f64, modulus: f64) -> Result<()> {
        self.indentations.clear();
        self.forces.clear();
        for (name, value, what) in [
            ("dx", spacing, "the spring spacing Δx"),
            ("modulus", modulus, "the effective modulus E*"),
        ] {
            if !crate::is_positive_finite(value) {
                return Err(Error::invalid(
                    name,
                    format!(
                        "{what} must be positive and finite, got {}",
                        crate::input::short_number(value)
                    ),
                ));
            }
        }
        if heights.is_empty() {
            return Err(Error::invalid("line", "the line has no points"));
        }
        crate::ensure_finite("line", heights)?;
        self.spring_stiffness = modulus * spacing;
        self.spacing = spacing;
        // Sort heights descending (radix sort, O(N)); gaps z_max − z are then ascending.
        self.indentations.extend_from_slice(heights);
        sort_descending(&mut self.indentations, &mut self.scratch);
        let top = self.indentations[0];
        for value in self.indentations.iter_mut() {
            *value = top - *value;
        }
        self.forces.reserve(heights.len());
        let mut force = 0.0;
        let mut previous = 0.0;
        for (j, &d) in self.indentations.iter().enumerate() {
            // j springs were in contact between the previous breakpoint and this one.
            force += self.spring_stiffness * j as f64 * (d - previous);
            self.forces.push(force);
            previous = d;
        }
        Ok(())
    }

    /// Number of breakpoints = number of springs `N`.
    pub fn len(&self) -> usize {
        self.indentations.len()
    }

    /// True before the first [`LinearCurve::recompute`].
    pub fn is_empty(&self) -> bool {
        self.indentations.is_empty()
    }

    /// Spring spacing `Δx`.
    pub fn spacing(&self) -> f64 {
        self.spacing
    }

    /// Effective modulus `E*`.
    pub fn modulus(&self) -> f64 {
        self.spring_stiffness / self.spacing
    }

    /// Length of the line, `N·Δx`.
    pub fn size(&self) -> f64 {
        self.len() as f64 * self.spacing
    }

    /// Stiffness of one spring, `E*·Δx`.
    pub fn spring_stiffness(&self) -> f64 {
        self.spring_stiffness
    }

    /// `d_j` for `j = 1..=N` (index `j − 1`): the indentation at which the `j`-th spring
    /// touches. `d_1 = 0`; `d_N` is the peak-to-valley height.
    pub fn indentations(&self) -> &[f64] {
        &self.indentations
    }

    /// `F_j` for `j = 1..=N` (index `j − 1`): the force when the `j`-th spring touches.
    pub fn forces(&self) -> &[f64] {
        &self.forces
    }

    /// `k_j = E*·Δx·j`, the stiffness while `j` springs are in contact.
    pub fn stiffness_with(&self, contacts: usize) -> f64 {
        self.spring_stiffness * contacts as f64
    }

    /// The `j`-th breakpoint (`1 ≤ j ≤ N`) with the stiffness just after it, `k_j`.
    pub fn breakpoint(&self, contacts: usize) -> CurvePoint {
        assert!(
            (1..=self.len()).contains(&contacts),
            "contacts {contacts} outside 1..={}",
            self.len()
        );
        CurvePoint {
            indentation: self.indentations[contacts - 1],
            force: self.forces[contacts - 1],
            stiffness: self.stiffness_with(contacts),
            contacts,
        }
    }

    /// Springs in contact at force `F`: `#{j : F_j ≤ F}` (0 for `F < 0`).
    pub fn contacts_at_force(&self, force: f64) -> usize {
        self.forces.partition_point(|&f| f <= force)
    }

    /// Contact stiffness at force `F`, `E*Δx · #{j : F_j ≤ F}` (exact; a step function).
    pub fn stiffness_at_force(&self, force: f64) -> f64 {
        self.stiffness_with(self.contacts_at_force(force))
    }

    /// Stiffness at each of `forces` (which must be ascending) into `out`, by one merge
    /// walk: `O(N + M)`, no allocation. Panics if the lengths differ.
    pub fn stiffness_at_forces(&self, forces: &[f64], out: &mut [f64]) {
        assert_eq!(forces.len(), out.len(), "forces and out differ in length");
        let mut j = 0;
        let mut last = f64::NEG_INFINITY;
        for (&force, k) in forces.iter().zip(out.iter_mut()) {
            debug_assert!(force >= last, "force levels must be ascending");
            last = force;
            while j < self.forces.len() && self.forces[j] <= force {
                j += 1;
            }
            *k = self.stiffness_with(j);
        }
    }

    /// The curve at indentation `d` (exact, by binary search over the breakpoints).
    pub fn at_indentation(&self, indentation: f64) -> CurvePoint {
        // Springs in contact: gaps strictly below d.
        let contacts = self.indentations.partition_point(|&s| s < indentation);
        let force = if contacts == 0 {
            0.0
        } else {
            let j = contacts;
            self.forces[j - 1] + self.stiffness_with(j) * (indentation - self.indentations[j - 1])
        };
        CurvePoint {
            indentation,
            force,
            stiffness: self.stiffness_with(contacts),
            contacts,
        }
    }

    /// The indentation at force `F ≥ 0` (inverse of the piecewise-linear `F(d)`).
    pub fn indentation_at_force(&self, force: f64) -> f64 {
        let j = self.contacts_at_force(force).max(1);
        self.indentations[j - 1] + (force - self.forces[j - 1]) / self.stiffness_with(j)
    }
}

#[cfg(test)]
mod tests {
    use super::super::foundation::Foundation;
    use super::super::spring::Spring;
    use super::*;
    use crate::spectrum::Psd;
    use crate::surface::{LineGenerator, LineSpec, Normalisation};

    fn rough_line(n: usize, hurst: f64, seed: u64) -> Vec<f64> {
        let spec = LineSpec::new(
            n,
            1.0,
            Psd::power_law(hurst).unwrap(),
            Normalisation::RmsHeight(1.0),
        )
        .unwrap();
        LineGenerator::new(&spec)
            .unwrap()
            .generate(seed)
            .into_heights()
            .to_vec()
    }

    #[test]
    fn breakpoints_agree_with_direct_evaluation() {
        let heights = rough_line(1000, 0.6, 4);
        let dx = 1e-3;
        let curve = LinearCurve::from_heights(&heights, dx, 2.0).unwrap();
        let foundation =
            Foundation::from_heights(&heights, Spring::linear(dx, 2.0).unwrap()).unwrap();
        assert_eq!(curve.len(), 1000);
        assert_eq!(curve.indentations()[0], 0.0);
        for j in [1, 2, 3, 10, 100, 999, 1000] {
            let p = curve.breakpoint(j);
            let direct = foundation.evaluate(p.indentation);
            // At d_j the j-th spring touches with zero force: the force agrees exactly,
            // the j-th spring is not yet counted by the strict inequality.
            assert!((p.force - direct.force).abs() <= 1e-12 * p.force.max(1e-300));
            assert_eq!(direct.contacts, j - 1);
            // Just beyond d_j: j contacts and stiffness E*Δx·j.
            let next = curve
                .indentations()
                .get(j)
                .copied()
                .unwrap_or(p.indentation + 1.0);
            let mid = 0.5 * (p.indentation + next);
            let direct = foundation.evaluate(mid);
            let interp = curve.at_indentation(mid);
            assert_eq!(direct.contacts, j);
            assert!((direct.stiffness - p.stiffness).abs() < 1e-12 * p.stiffness);
            assert!((interp.force - direct.force).abs() <= 1e-11 * direct.force);
            assert_eq!(interp.contacts, j);
        }
    }

    #[test]
    fn stiffness_at_force_is_the_step_function() {
        let heights = rough_line(513, -0.5, 9);
        let curve = LinearCurve::from_heights(&heights, 0.01, 1.0).unwrap();
        let forces = curve.forces().to_vec();
        for j in [1, 2, 50, 513] {
            let f = forces[j - 1];
            assert_eq!(curve.stiffness_at_force(f), 0.01 * j as f64);
            if j < 513 {
                let between = 0.5 * (f + forces[j]);
                assert_eq!(curve.contacts_at_force(between), j);
                let d = curve.indentation_at_force(between);
                assert!((curve.at_indentation(d).force / between - 1.0).abs() < 1e-12);
            }
        }
        assert_eq!(curve.stiffness_at_force(-1.0), 0.0);
        // Merge walk = binary search at ascending levels.
        let levels: Vec<f64> = (0..200)
            .map(|i| forces[512] * (i as f64 / 150.0).powi(3))
            .collect();
        let mut walked = vec![0.0; levels.len()];
        curve.stiffness_at_forces(&levels, &mut walked);
        for (f, k) in levels.iter().zip(&walked) {
            assert_eq!(*k, curve.stiffness_at_force(*f));
        }
    }

    #[test]
    fn ties_count_all_tied_springs() {
        let curve = LinearCurve::from_heights(&[1.0, 1.0, 0.0, 0.5], 1.0, 1.0).unwrap();
        assert_eq!(curve.indentations(), &[0.0, 0.0, 0.5, 1.0]);
        assert_eq!(curve.forces(), &[0.0, 0.0, 1.0, 2.5]);
        assert_eq!(curve.stiffness_at_force(0.0), 2.0);
        assert_eq!(curve.stiffness_at_force(1.0), 3.0);
        assert_eq!(curve.stiffness_at_force(100.0), 4.0);
        assert_eq!(curve.at_indentation(2.0).force, 2.5 + 4.0);
    }

    #[test]
    fn recompute_reuses_buffers_and_validates() {
        let mut curve = LinearCurve::with_capacity(2048);
        let first = rough_line(2048, 0.8, 1);
        curve.recompute(&first, 1.0 / 2048.0, 1.0).unwrap();
        let pointer = curve.indentations().as_ptr();
        let second = rough_line(2048, 0.8, 2);
        curve.recompute(&second, 1.0 / 2048.0, 1.0).unwrap();
        assert_eq!(pointer, curve.indentations().as_ptr(), "no reallocation");
        assert_eq!(
            curve,
            LinearCurve::from_heights(&second, 1.0 / 2048.0, 1.0).unwrap()
        );
        assert!(curve.recompute(&[0.0, f64::NAN], 1.0, 1.0).is_err());
        assert!(curve.is_empty());
        assert!(curve.recompute(&first, 0.0, 1.0).is_err());
        assert!(curve.recompute(&first, 1.0, -2.0).is_err());
        assert!(curve.recompute(&[], 1.0, 1.0).is_err());
    }
}
