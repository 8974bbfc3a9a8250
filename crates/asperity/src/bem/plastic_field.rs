//! The BCCG's load restoration under a hardness cap, with the displacement kept exact.
//!
//! Once points sit at the cap `h`, a step that changed the load cannot be undone by scaling
//! `p` and `u` together (the hard wall's restoration, `bccg.rs`): the capped points stay at
//! `h` and only the others are scaled, by the `s` of [`super::interface::capped_scale`].
//! With `C` the capped set and `p = h 1_C + p_E`, the restored pressure is
//! `p' = h 1_C + s p_E + Σ_N (h − s p_t) e_t` (`N` the points that the scaling takes to the
//! cap), so its displacement is
//!
//! `u' = K p' = s u + (1 − s) h K 1_C + Σ_N (h − s p_t) K e_t`
//!
//! given `u = K p`. [`PlasticField`] keeps `K 1_C` as a field through the steps of a
//! solve: computed by one operator application the first time a restoration needs it,
//! then followed as `C` changes (each point entering or leaving the cap adds `± K e_t`, the
//! operator's point response, one grid pass for all of them). The restoration is then a
//! pass over the grid instead of the recomputation of `u` (an operator application) that
//! ended every such step before. Where the capped set changes at more than
//! [`CUT_LIMIT`] points in a step, the field is dropped and `u` recomputed (as before); it
//! is computed again at the next restoration that needs it.
//!
//! Errors in `K 1_C` (single precision, point responses) enter `u` multiplied by `1 − s`,
//! the step's relative load error; convergence is accepted only on a `u` recomputed in
//! double precision (`bccg.rs`), so they can cost iterations, never accuracy.

use rayon::prelude::*;

use super::grid_pass::{add_point_responses, CHUNK, CUT_LIMIT};
use super::interface::{capped_scale, restore_capped_load, CappedRestoration};

/// `K 1_C` of the capped set `C = {p ≥ h}` of the current iterate, kept through a solve.
#[derive(Default)]
pub(super) struct PlasticField {
    /// `K 1_C` (empty until a capped solve prepares it).
    response: Vec<f64>,
    /// Whether `response` is `K 1_C` of the current capped set.
    valid: bool,
    /// The first [`CUT_LIMIT`] points of each chunk of the restoration pass that it took to
    /// the cap, with `h − s p_t`.
    chunk_capped: Vec<(usize, f64)>,
    /// Per chunk: how many points the restoration pass took to the cap.
    chunk_counts: Vec<usize>,
    /// Per chunk: its [`Census`].
    chunk_census: Vec<Census>,
    /// The changes of the capped set gathered for one grid pass, `(t, ±1)` or
    /// `(t, h − s p_t)`.
    changes: Vec<(usize, f64)>,
    /// The restorations of this solve that released the plastic set or restarted the
    /// pressure ([`CappedRestoration::lost_the_set`]).
    pub(super) lost_sets: usize,
}

/// The pressures counted against the cap `h` (one chunk's, or the grid's).
#[derive(Debug, Clone, Copy, Default)]
struct Census {
    /// Points with `p > 0`.
    in_contact: usize,
    /// Points with `p ≥ h`.
    capped: usize,
    /// `Σ p` over the points below the cap.
    below: f64,
    /// The largest pressure below the cap.
    below_peak: f64,
}

/// What a capped load restoration did to `u`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Restored {
    /// `u` updated exactly (`u = K p` still holds as before the restoration).
    Exact,
    /// `u` does not follow: it must be recomputed.
    Stale,
    /// The points in contact cannot carry the load below the cap: the pressure restarted
    /// from the bearing area ([`super::interface::bearing_start`]).
    CapacityLost,
}

/// The grid as the point responses take it: `(rows, cols, periodic)`.
pub(super) type Grid = (usize, usize, bool);

impl PlasticField {
    /// Makes the fields for a grid of `len` points (allocated on the first capped solve
    /// only) and forgets the capped set (the next restoration computes `K 1_C` afresh) and
    /// the count of lost sets.
    pub(super) fn prepare(&mut self, len: usize) {
        if self.response.len() != len {
            let chunks = len.div_ceil(CHUNK);
            self.response = vec![0.0; len];
            self.chunk_capped = vec![(0, 0.0); chunks * CUT_LIMIT];
            self.chunk_counts = vec![0; chunks];
            self.chunk_census = vec![Census::default(); chunks];
            self.changes = Vec::with_capacity(CUT_LIMIT);
        }
        self.valid = false;
        self.lost_sets = 0;
    }

    /// Follows the changes of the capped set made by a step: `changes` are `(t, +1)` for a
    /// point that reached the cap and `(t, −1)` for one that left it. More than
    /// [`CUT_LIMIT`] of them drop the field.
    pub(super) fn follow(
        &mut self,
        changes: impl Iterator<Item = (usize, f64)>,
        count: usize,
        (impulse, grid): (&[f64], Grid),
    ) {
        if !self.valid || count == 0 {
            return;
        }
        if count > CUT_LIMIT {
            self.valid = false;
            return;
        }
        self.changes.clear();
        self.changes.extend(changes);
        add_point_responses(&mut self.response, impulse, grid, &self.changes);
    }

    /// Restores the load `n p̄` of `pressure` (summing to `total`) under the cap `h`, the
    /// capped points held there, as [`restore_capped_load`] does; with `exact_u` (`u = K p`
    /// on entry) also `u`, by the module docs' update. `apply` computes `K x` (for
    /// `K 1_C`, where the field is not valid); `levels` is the profile `f` (the bearing
    /// start orders the points by `u + f`).
    pub(super) fn restore_load(
        &mut self,
        (pressure, u, f): (&mut [f64], &mut [f64], &[f64]),
        (mean_pressure, h, total): (f64, f64, f64),
        exact_u: bool,
        indicator: &mut [f64],
        apply: impl FnOnce(&[f64], &mut [f64]),
        (impulse, grid): (&[f64], Grid),
    ) -> Restored {
        let wanted = mean_pressure * pressure.len() as f64;
        let Census {
            in_contact,
            capped,
            below,
            below_peak,
        } = self.census(pressure, h);
        let keep_capped = (capped as f64) * h < wanted;
        if (in_contact as f64) * h <= wanted || total <= 0.0 || !keep_capped {
            // A restart from the bearing area, or every point scaled: the capped set is
            // not held, `u` is recomputed.
            self.valid = false;
            let level = |i: usize| u[i] + f[i];
            let restoration = restore_capped_load(pressure, (mean_pressure, h), total, level);
            self.lost_sets += restoration.lost_the_set() as usize;
            return match restoration {
                CappedRestoration::Restarted => Restored::CapacityLost,
                _ => Restored::Stale,
            };
        }
        let update_u = exact_u && self.ensure(pressure, h, indicator, apply);
        // The load is linear in the scale until a point below the cap reaches it: the
        // scale of that piece, exact where it takes none there (else Newton's method).
        let first = (wanted - capped as f64 * h) / below;
        let scale = match below > 0.0 && first * below_peak <= h {
            true => first,
            false => capped_scale(pressure, wanted, h, true),
        };
        let newly = self.scale_pass((pressure, u), (scale, h), update_u);
        if newly > CUT_LIMIT {
            self.valid = false;
            return Restored::Stale;
        }
        self.changes.clear();
        for (slots, &n) in self.chunk_capped.chunks(CUT_LIMIT).zip(&self.chunk_counts) {
            self.changes.extend_from_slice(&slots[..n]);
        }
        if update_u {
            add_point_responses(u, impulse, grid, &self.changes);
        }
        if self.valid {
            self.changes.iter_mut().for_each(|(_, c)| *c = 1.0);
            add_point_responses(&mut self.response, impulse, grid, &self.changes);
        }
        match update_u {
            true => Restored::Exact,
            false => Restored::Stale,
        }
    }

    /// The points in contact and at the cap, the sum and the largest of the pressures below
    /// the cap: one parallel pass, summed by chunks in chunk order (the same bits for any
    /// thread count).
    fn census(&mut self, pressure: &[f64], h: f64) -> Census {
        pressure
            .par_chunks(CHUNK)
            .zip(self.chunk_census.par_iter_mut())
            .for_each(|(p, out)| {
                let mut c = Census::default();
                for &pi in p {
                    c.in_contact += (pi > 0.0) as usize;
                    if pi >= h {
                        c.capped += 1;
                    } else {
                        c.below += pi;
                        c.below_peak = c.below_peak.max(pi);
                    }
                }
                *out = c;
            });
        self.chunk_census
            .iter()
            .fold(Census::default(), |a, c| Census {
                in_contact: a.in_contact + c.in_contact,
                capped: a.capped + c.capped,
                below: a.below + c.below,
                below_peak: a.below_peak.max(c.below_peak),
            })
    }

    /// Makes the field `K 1_C` of `pressure`'s capped set if it is not (one application,
    /// by `apply`, through `indicator`). True: the field is valid.
    fn ensure(
        &mut self,
        pressure: &[f64],
        h: f64,
        indicator: &mut [f64],
        apply: impl FnOnce(&[f64], &mut [f64]),
    ) -> bool {
        if self.response.len() != pressure.len() {
            return false;
        }
        if !self.valid {
            for (x, &p) in indicator.iter_mut().zip(pressure) {
                *x = if p >= h { 1.0 } else { 0.0 };
            }
            apply(indicator, &mut self.response);
            self.valid = true;
        }
        true
    }

    /// `p ← min(s p, h)` off the cap and, with `update_u`, `u ← s u + (1 − s) h K 1_C`;
    /// lists per chunk the first [`CUT_LIMIT`] points taken to the cap with `h − s p`, and
    /// counts them all. Returns how many in all.
    fn scale_pass(
        &mut self,
        (pressure, u): (&mut [f64], &mut [f64]),
        (scale, h): (f64, f64),
        update_u: bool,
    ) -> usize {
        let shift = (1.0 - scale) * h;
        let response = &self.response[..];
        pressure
            .par_chunks_mut(CHUNK)
            .zip(u.par_chunks_mut(CHUNK))
            .zip(self.chunk_capped.par_chunks_mut(CUT_LIMIT))
            .zip(self.chunk_counts.par_iter_mut())
            .enumerate()
            .for_each(|(chunk, (((p, u), slots), count))| {
                let mut newly = 0;
                for (index, (pi, ui)) in p.iter_mut().zip(u.iter_mut()).enumerate() {
                    let t = chunk * CHUNK + index;
                    if update_u {
                        *ui = scale * *ui + shift * response[t];
                    }
                    if *pi >= h {
                        continue;
                    }
                    let next = scale * *pi;
                    if next > h {
                        if newly < CUT_LIMIT {
                            slots[newly] = (t, h - next);
                        }
                        newly += 1;
                        *pi = h;
                    } else {
                        *pi = next;
                    }
                }
                *count = newly;
            });
        self.chunk_counts.iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elastic::{Boundary, ElasticOperator};

    /// A pressure field of `rows × cols` with points at zero, below the cap and at it.
    fn pressures(len: usize, h: f64) -> Vec<f64> {
        (0..len)
            .map(|i| match (i * 7919) % 13 {
                0..=3 => 0.0,
                4..=5 => h,
                k => 0.08 * h * k as f64,
            })
            .collect()
    }

    #[test]
    fn a_restoration_keeps_the_displacement_exact() {
        // The oracle: after the restoration (and the field followed through a step's
        // changes of the capped set), u equals K p recomputed from scratch, and K 1_C that
        // of the new capped set, both to rounding; on odd, even and rectangular grids, free
        // and periodic; loads that scale the points below the cap up (some of them to the
        // cap) and down.
        for (rows, cols) in [(15, 15), (16, 16), (12, 20)] {
            for boundary in [Boundary::Free, Boundary::Periodic] {
                let mut operator = ElasticOperator::new(rows, cols, 1.0, 1.0, boundary).unwrap();
                let len = rows * cols;
                let mut impulse = vec![0.0; len];
                let mut unit = vec![0.0; len];
                unit[0] = 1.0;
                operator.apply(&unit, &mut impulse);
                let grid = (rows, cols, boundary == Boundary::Periodic);
                let h = 1.0;
                for factor in [1.05, 0.97] {
                    let mut p = pressures(len, h);
                    let mut field = PlasticField::default();
                    field.prepare(len);
                    let mut u = vec![0.0; len];
                    operator.apply(&p, &mut u);
                    // A step's change of the capped set: one point leaves it, one enters.
                    let (leaves, enters) = (
                        p.iter().position(|&v| v >= h).unwrap(),
                        p.iter().position(|&v| v > 0.0 && v < h).unwrap(),
                    );
                    let mut indicator = vec![0.0; len];
                    let apply = |x: &[f64], y: &mut [f64]| operator.apply(x, y);
                    assert!(field.ensure(&p, h, &mut indicator, apply));
                    for (t, to) in [(leaves, 0.5 * h), (enters, h)] {
                        let mut delta = vec![0.0; len];
                        delta[t] = to - p[t];
                        let mut response = vec![0.0; len];
                        operator.apply(&delta, &mut response);
                        u.iter_mut().zip(&response).for_each(|(a, b)| *a += b);
                        p[t] = to;
                    }
                    let changes = [(leaves, -1.0), (enters, 1.0)];
                    field.follow(changes.into_iter(), 2, (&impulse, grid));
                    let total: f64 = p.iter().sum();
                    let mean = factor * total / len as f64;
                    let f = vec![0.0; len];
                    let restored = field.restore_load(
                        (&mut p, &mut u, &f),
                        (mean, h, total),
                        true,
                        &mut indicator,
                        |_: &[f64], _: &mut [f64]| panic!("the field was kept"),
                        (&impulse, grid),
                    );
                    let case = format!("{rows}x{cols} {boundary:?} ×{factor}");
                    assert_eq!(restored, Restored::Exact, "{case}");
                    let load: f64 = p.iter().sum();
                    assert!((load / (mean * len as f64) - 1.0).abs() < 1e-13, "{case}");
                    assert!(p.iter().all(|&v| (0.0..=h).contains(&v)), "{case}");
                    let mut exact = vec![0.0; len];
                    operator.apply(&p, &mut exact);
                    let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    let error = u
                        .iter()
                        .zip(&exact)
                        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    assert!(error < 1e-12 * scale, "{case}: u off by {error:e}");
                    let capped: Vec<f64> =
                        p.iter().map(|&v| if v >= h { 1.0 } else { 0.0 }).collect();
                    operator.apply(&capped, &mut exact);
                    let error = field
                        .response
                        .iter()
                        .zip(&exact)
                        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    assert!(error < 1e-12 * scale, "{case}: K 1_C off by {error:e}");
                    if factor > 1.0 {
                        assert!(
                            pressures(len, h).iter().filter(|&&v| v >= h).count()
                                < p.iter().filter(|&&v| v >= h).count(),
                            "{case}: no point scaled to the cap"
                        );
                    }
                }
            }
        }
    }
}
