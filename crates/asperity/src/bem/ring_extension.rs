//! [`RingExtension`]: the free set's gradient extended over two rings of bounded points
//! before the Fourier preconditioner, so that the preconditioner sees no jump at the edge
//! of the contact set.
//!
//! The preconditioner of the BCCG approximates the inverse of `K_FF`, the operator
//! restricted to the free set `F`. With `M = K⁻¹` (exact on periodic grids), the inverse is
//! the Schur complement `K_FF⁻¹ = M_FF − M_FO M_OO⁻¹ M_OF` (`O` the points off `F`), which
//! is also the minimum over every extension `e` of a field `g` on `F` to the whole grid of
//! the energy `(g, e)ᵀ M (g, e)` — the displacement outside the set that the pressure on
//! the set produces. `P_F M P_F` is that energy for the extension by zero: it over-estimates
//! `K_FF⁻¹` (the eigenvalues of `P_F M P_F K_FF` are ≥ 1), most on the smooth modes of
//! each contact patch, where the zero extension jumps at the edge and `M` (a derivative of
//! order one) turns the jump into a `1/δ` edge layer that the true pressure (a `1/√δ`
//! singularity) does not have: the largest eigenvalue grows like the log of the patches'
//! size in pixels (measured 7.5 at 256², 11.9 at 512² on the rough surface of
//! `asperity bench bem-solve`).
//!
//! Any extension `E` keeps `(I + E)ᵀ M (I + E) ≥ K_FF⁻¹` (symmetric positive definite on
//! `F`, the lower bound 1 of the spectrum unchanged) and a better one lowers the top. The
//! one here is local: the first ring (bounded points next to `F`) takes `γ₁` times the mean
//! of its neighbours on `F`, the second ring `γ₂` times the mean of its neighbours on the
//! first ring (4-neighbours; free boundaries have no neighbours outside the grid, periodic
//! ones wrap). The transpose gathers the preconditioned field back onto `F` along the same
//! weights. Measured at 512²: the largest eigenvalue 11.9 → 5.5 with `γ = (0.7, 0.5)`.
//!
//! The extension and its transpose are each one sweep over the grid of a two-stage
//! stencil (the first ring from the set, then the second ring from the first), both stages
//! in one pass over blocks of rows with three rows of the first stage in flight; the
//! rings' neighbour counts (one byte per point) are recounted only when the free set
//! changes. Every point is written from its neighbours' values in a fixed order, so the
//! results do not depend on the thread count. Cost (docs/bem.md): at 1024² about a fifth
//! of an iteration; at 128² about what the rings save in iterations, which is why the BCCG
//! uses them on large grids only. Nothing is allocated after [`RingExtension::new`].

use rayon::prelude::*;

use crate::elastic::{Boundary, ElasticOperator};

/// Weights of the first and the second ring (measured, see the module docs).
const GAMMA: [f64; 2] = [0.7, 0.5];

/// A ring point's weight by its count of neighbours one ring in (`γ/c`; no neighbours, or
/// off the ring: zero), for each ring; indexed by the count's low three bits.
const WEIGHTS: [[f64; 8]; 2] = [weights(GAMMA[0]), weights(GAMMA[1])];

/// `γ/c` for the counts `c` = 1 … 4, zero for the others.
const fn weights(gamma: f64) -> [f64; 8] {
    [
        0.0,
        gamma,
        gamma / 2.0,
        gamma / 3.0,
        gamma / 4.0,
        0.0,
        0.0,
        0.0,
    ]
}

/// The weight of a ring point with `count` neighbours one ring in, on ring `ring` (0, 1).
#[inline(always)]
fn weight(ring: usize, count: u8) -> f64 {
    WEIGHTS[ring][usize::from(count & 7)]
}

/// Points per block of rows of the parallel sweeps (whole rows, at least one). Every
/// sweep writes each point from its neighbours' values only: the blocks change no bit.
const BLOCK: usize = 8192;

/// A `rows × cols` grid and whether it wraps around (periodic) or ends (free).
type Grid = (usize, usize, bool);

/// The rings' neighbour counts for the current free set, the grid they live on, and
/// scratch.
pub(super) struct RingExtension {
    /// Per point of the first ring (bounded points next to the set): its number of
    /// neighbours on the set; zero elsewhere.
    first: Vec<u8>,
    /// Per point of the second ring (bounded points next to the first ring only): its
    /// number of first-ring neighbours; zero elsewhere.
    second: Vec<u8>,
    /// The free set the counts are for (they change only when it does).
    counted_for: Vec<bool>,
    /// Per block of rows: three rows of a sweep's first stage and one of neighbour sums.
    rolling: Vec<f64>,
    /// The result of a sweep, swapped with the caller's field.
    out: Vec<f64>,
    /// A row of zeros of each type: the rows outside a free grid.
    zeros: (Vec<f64>, Vec<u8>, Vec<bool>),
    grid: Grid,
}

/// The row above row `i` (periodic: wrapped; free: none above the first).
fn row_above((rows, _, periodic): Grid, i: usize) -> Option<usize> {
    match i {
        0 if periodic => Some(rows - 1),
        0 => None,
        _ => Some(i - 1),
    }
}

/// The row below row `i` (periodic: wrapped; free: none below the last).
fn row_below((rows, _, periodic): Grid, i: usize) -> Option<usize> {
    match i + 1 == rows {
        true if periodic => Some(0),
        true => None,
        false => Some(i + 1),
    }
}

/// Rows `i − 1`, `i`, `i + 1` of `field` (wrapped on periodic grids; a row of `zeros` in
/// place of those outside a free grid).
fn rows_of<'a, T>(grid: Grid, field: &'a [T], zeros: &'a [T], i: usize) -> [&'a [T]; 3] {
    let cols = grid.1;
    let row = |r: Option<usize>| r.map_or(zeros, |r| &field[r * cols..][..cols]);
    [
        row(row_above(grid, i)),
        row(Some(i)),
        row(row_below(grid, i)),
    ]
}

/// `out[j] = Σ f(a_m, b_m)` over the 4-neighbours `m` of point `j` of the middle row, from
/// the rows above, at and below it of two fields `a` and `b` (`f(0, 0) = 0`: a row of
/// zeros stands for one outside a free grid); periodic rows wrap, free ones end. Added in
/// a fixed order: above, below, left, right.
#[inline(always)]
fn stencil<A: Copy, B: Copy, T: Copy + Default + std::ops::Add<Output = T>>(
    periodic: bool,
    (a, b): ([&[A]; 3], [&[B]; 3]),
    f: impl Fn(A, B) -> T,
    out: &mut [T],
) {
    let n = out.len();
    let ([a0, a1, a2], [b0, b1, b2]) = (a.map(|r| &r[..n]), b.map(|r| &r[..n]));
    let vertical = |j: usize| f(a0[j], b0[j]) + f(a2[j], b2[j]);
    let side = |j: Option<usize>| j.map_or(T::default(), |j| f(a1[j], b1[j]));
    let wrap = |j: usize| periodic.then_some(j);
    if n == 1 {
        out[0] = vertical(0) + side(wrap(0)) + side(wrap(0));
        return;
    }
    let last = n - 1;
    out[0] = vertical(0) + side(wrap(last)) + side(Some(1));
    for j in 1..last {
        out[j] =
            f(a0[j], b0[j]) + f(a2[j], b2[j]) + f(a1[j - 1], b1[j - 1]) + f(a1[j + 1], b1[j + 1]);
    }
    out[last] = vertical(last) + side(Some(last - 1)) + side(wrap(0));
}

/// One sweep over the grid of a two-stage stencil: `stage_one(i, row)` writes row `i` of
/// an intermediate field, `stage_two(i, (row, sums), out)` row `i` of the result from that
/// field's row `i` and its neighbour sums. In parallel over blocks of rows; each block
/// computes stage one for its rows and one either side, keeping three rows at a time
/// (the intermediate field is never stored whole, and the grid is read once).
fn sweep(
    grid: Grid,
    (rolling, out, zeros): (&mut [f64], &mut [f64], &[f64]),
    stage_one: impl Fn(usize, &mut [f64]) + Sync,
    stage_two: impl Fn(usize, (&[f64], &[f64]), &mut [f64]) + Sync,
) {
    let cols = grid.1;
    let block_rows = (BLOCK / cols).max(1);
    out.par_chunks_mut(block_rows * cols)
        .zip(rolling.par_chunks_mut(4 * cols))
        .enumerate()
        .for_each(|(b, (out, rolling))| {
            let (slots, sums) = rolling.split_at_mut(3 * cols);
            let first_row = b * block_rows;
            // Slots of the rows above, at and below the current one.
            let mut slot = [0, 1, 2];
            let rows = [row_above(grid, first_row), Some(first_row)];
            for (&s, r) in slot.iter().zip(rows) {
                if let Some(r) = r {
                    stage_one(r, &mut slots[s * cols..][..cols]);
                }
            }
            for (r, out) in out.chunks_mut(cols).enumerate() {
                let i = first_row + r;
                if r > 0 {
                    slot.rotate_left(1);
                }
                let below = row_below(grid, i);
                if let Some(r) = below {
                    stage_one(r, &mut slots[slot[2] * cols..][..cols]);
                }
                let row = |s: usize| &slots[s * cols..][..cols];
                let present = |r: Option<usize>, s: usize| r.map_or(zeros, |_| row(s));
                let rows = [
                    present(row_above(grid, i), slot[0]),
                    row(slot[1]),
                    present(below, slot[2]),
                ];
                stencil(grid.2, (rows, rows), |v, _| v, sums);
                stage_two(i, (row(slot[1]), sums), out);
            }
        });
}

impl RingExtension {
    /// The fields for the grid of `operator` (its size and boundaries).
    pub(super) fn on_grid_of(operator: &ElasticOperator) -> Self {
        let periodic = operator.boundary() == Boundary::Periodic;
        Self::new(operator.rows(), operator.cols(), periodic)
    }

    /// The fields for a `rows × cols` grid (periodic or free boundaries).
    pub(super) fn new(rows: usize, cols: usize, periodic: bool) -> Self {
        let blocks = rows.div_ceil((BLOCK / cols).max(1));
        RingExtension {
            first: vec![0; rows * cols],
            second: vec![0; rows * cols],
            counted_for: vec![false; rows * cols],
            rolling: vec![0.0; blocks * 4 * cols],
            out: vec![0.0; rows * cols],
            zeros: (vec![0.0; cols], vec![0; cols], vec![false; cols]),
            grid: (rows, cols, periodic),
        }
    }

    /// Counts the rings' neighbours for `free` unless they are counted already (two
    /// passes over one byte per point).
    fn count(&mut self, free: &[bool]) {
        if self.counted_for[..] == *free {
            return;
        }
        let (grid, cols) = (self.grid, self.grid.1);
        let (zeros, falses) = (&self.zeros.1[..], &self.zeros.2[..]);
        // The first ring: bounded points with neighbours on the set.
        for_rows(grid, &mut self.first, |i, row| {
            let rows = rows_of(grid, free, falses, i);
            stencil(grid.2, (rows, rows), |f, _| u8::from(f), row);
            let own = &free[i * cols..][..cols];
            row.iter_mut()
                .zip(own)
                .for_each(|(c, &f)| *c *= u8::from(!f));
        });
        // The second ring: bounded points off the first ring with first-ring neighbours.
        let first = &self.first;
        for_rows(grid, &mut self.second, |i, row| {
            let rows = rows_of(grid, first, zeros, i);
            stencil(grid.2, (rows, rows), |c, _| u8::from(c > 0), row);
            let own = free[i * cols..][..cols]
                .iter()
                .zip(&first[i * cols..][..cols]);
            let inner = |(&f, &c): (&bool, &u8)| f || c > 0;
            row.iter_mut()
                .zip(own)
                .for_each(|(c, own)| *c *= u8::from(!inner(own)));
        });
        self.counted_for.copy_from_slice(free);
    }

    /// `z ← (I + E) z` for the free set `free`: `z`, zero off the set, keeps its values
    /// there and gets the extension on the two rings (one sweep, two more passes where the
    /// set changed).
    pub(super) fn extend(&mut self, free: &[bool], z: &mut Vec<f64>) {
        self.count(free);
        let (grid, cols) = (self.grid, self.grid.1);
        let (first, second, zr, zeros) = (&self.first, &self.second, &z[..], &self.zeros.0[..]);
        // Stage one, the first ring: γ₁/c times the sum of its c neighbours on the set.
        let first_ring = |i: usize, row: &mut [f64]| {
            let rows = rows_of(grid, zr, zeros, i);
            stencil(grid.2, (rows, rows), |z, _| z, row);
            let own = &first[i * cols..][..cols];
            row.iter_mut()
                .zip(own)
                .for_each(|(v, &c)| *v *= weight(0, c));
        };
        // Stage two: z on the set, the first ring, and on the second ring γ₂/c times the
        // sum of its c first-ring neighbours.
        let both_rings = |i: usize, (ring, sums): (&[f64], &[f64]), out: &mut [f64]| {
            let own = (&free[i * cols..][..cols], &second[i * cols..][..cols]);
            let own = own.0.iter().zip(own.1).zip(&zr[i * cols..][..cols]);
            let rings = ring.iter().zip(sums);
            for ((o, (v, s)), ((&f, &c), &z)) in out.iter_mut().zip(rings).zip(own) {
                *o = if f { z } else { v + weight(1, c) * s };
            }
        };
        let fields = (&mut self.rolling[..], &mut self.out[..], zeros);
        sweep(grid, fields, first_ring, both_rings);
        std::mem::swap(z, &mut self.out);
    }

    /// `z ← (I + E)ᵀ z` on the free set `free` of the last [`RingExtension::extend`]: there
    /// `z` plus what the rings took from each point. Off the set `z` is left unspecified
    /// (its callers read it on the set only, `P_F`). One sweep.
    pub(super) fn gather(&mut self, free: &[bool], z: &mut Vec<f64>) {
        let (grid, cols) = (self.grid, self.grid.1);
        let (first, second, zr) = (&self.first, &self.second, &z[..]);
        let (zeros, counts) = (&self.zeros.0[..], &self.zeros.1[..]);
        // Stage one: the second ring gives to the first, which holds γ₁/c (z + what it got).
        let first_ring = |i: usize, row: &mut [f64]| {
            let rows = (
                rows_of(grid, second, counts, i),
                rows_of(grid, zr, zeros, i),
            );
            stencil(grid.2, rows, |c, z| weight(1, c) * z, row);
            let own = first[i * cols..][..cols]
                .iter()
                .zip(&zr[i * cols..][..cols]);
            row.iter_mut()
                .zip(own)
                .for_each(|(v, (&c, z))| *v = weight(0, c) * (z + *v));
        };
        // Stage two: the first ring gives to the set.
        let to_set = |i: usize, (_, sums): (&[f64], &[f64]), out: &mut [f64]| {
            let own = free[i * cols..][..cols].iter().zip(&zr[i * cols..][..cols]);
            for ((o, s), (&f, z)) in out.iter_mut().zip(sums).zip(own) {
                *o = if f { z + s } else { *z };
            }
        };
        let fields = (&mut self.rolling[..], &mut self.out[..], zeros);
        sweep(grid, fields, first_ring, to_set);
        std::mem::swap(z, &mut self.out);
    }
}

/// Runs `pass(i, row)` on every row `i` of `field`, in parallel over blocks of rows.
fn for_rows<T: Send>(grid: Grid, field: &mut [T], pass: impl Fn(usize, &mut [T]) + Sync) {
    let cols = grid.1;
    let block_rows = (BLOCK / cols).max(1);
    field
        .par_chunks_mut(block_rows * cols)
        .enumerate()
        .for_each(|(b, block)| {
            for (r, row) in block.chunks_mut(cols).enumerate() {
                pass(b * block_rows + r, row);
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// The 4-neighbours of `k` by coordinates (the oracle of the lists' neighbours).
    fn naive_neighbours(k: usize, (rows, cols, periodic): (usize, usize, bool)) -> Vec<usize> {
        let (i, j) = ((k / cols) as i64, (k % cols) as i64);
        [(-1, 0), (1, 0), (0, -1), (0, 1)]
            .iter()
            .filter_map(|&(di, dj)| {
                let (mut a, mut b) = (i + di, j + dj);
                if periodic {
                    a = a.rem_euclid(rows as i64);
                    b = b.rem_euclid(cols as i64);
                }
                let inside = (0..rows as i64).contains(&a) && (0..cols as i64).contains(&b);
                inside.then_some(a as usize * cols + b as usize)
            })
            .collect()
    }

    /// A random set of density `fill`, a field on it, and one everywhere.
    fn case(len: usize, fill: f64, state: &mut u64) -> (Vec<bool>, Vec<f64>, Vec<f64>) {
        let free: Vec<bool> = (0..len).map(|_| random(state) + 0.5 < fill).collect();
        let z = free
            .iter()
            .map(|&f| if f { random(state) } else { 0.0 })
            .collect();
        let y = (0..len).map(|_| random(state)).collect();
        (free, z, y)
    }

    #[test]
    fn extend_follows_the_definition_and_gather_is_its_transpose() {
        // Odd, even and rectangular grids, free and periodic, sparse sets (isolated points,
        // which have a second ring) and dense ones; the extension is checked against the
        // definition written out with coordinates, and ⟨(I + E) z, y⟩ = ⟨z, (I + E)ᵀ y⟩ on
        // the set (so that (I + E)ᵀ M (I + E) is symmetric). Twice per grid, so that the
        // second extension overwrites the first one's fields.
        for (rows, cols) in [(31, 31), (32, 32), (50, 72), (700, 13)] {
            for periodic in [false, true] {
                let grid = (rows, cols, periodic);
                let mut rings = RingExtension::new(rows, cols, periodic);
                let mut state = 7u64;
                for fill in [0.05, 0.6] {
                    let (free, z, y) = case(rows * cols, fill, &mut state);
                    let mut extended = z.clone();
                    rings.extend(&free, &mut extended);
                    let first = |k: usize| {
                        let near = naive_neighbours(k, grid);
                        let on: Vec<usize> = near.into_iter().filter(|&m| free[m]).collect();
                        (!free[k] && !on.is_empty()).then(|| {
                            GAMMA[0] * on.iter().map(|&m| z[m]).sum::<f64>() / on.len() as f64
                        })
                    };
                    for k in 0..rows * cols {
                        let expected = if free[k] {
                            z[k]
                        } else if let Some(v) = first(k) {
                            v
                        } else {
                            let on: Vec<usize> = naive_neighbours(k, grid)
                                .into_iter()
                                .filter(|&m| first(m).is_some())
                                .collect();
                            let sum: f64 = on.iter().map(|&m| first(m).unwrap()).sum();
                            if on.is_empty() {
                                0.0
                            } else {
                                GAMMA[1] * sum / on.len() as f64
                            }
                        };
                        // Rounding only: the values are below 1 and both sides add a few
                        // of them, in different orders.
                        let tolerance = 1e-15;
                        assert!(
                            (extended[k] - expected).abs() <= tolerance,
                            "{k}: {} {expected} free {} grid {rows}x{cols} {periodic} {fill}",
                            extended[k],
                            free[k]
                        );
                    }
                    let mut gathered = y.clone();
                    rings.gather(&free, &mut gathered);
                    let dot =
                        |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
                    let on_set = |v: &[f64]| -> Vec<f64> {
                        v.iter()
                            .zip(&free)
                            .map(|(&x, &f)| if f { x } else { 0.0 })
                            .collect()
                    };
                    let (left, right) = (dot(&extended, &y), dot(&z, &on_set(&gathered)));
                    assert!(
                        (left - right).abs() < 1e-12 * left.abs().max(1.0),
                        "{left} {right}"
                    );
                }
            }
        }
    }
}
