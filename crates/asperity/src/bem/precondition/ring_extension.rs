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
//! The rings are kept as lists: per row, the columns of its first-ring points, of its
//! second-ring points and of the set's edge (the points of the set with first-ring
//! neighbours), with the rings' neighbour counts (one byte per point), recounted in the
//! rows within two rows of a change of the free set. The extension and its transpose then
//! visit the listed points only (a quarter of the grid at 10 % contact): the first ring,
//! then the second from the first (extension), or the first ring from the second, then the
//! edge from the first (transpose), each update in two parallel passes — values from the
//! neighbours into a scratch field, then written in place. Every value is added from its
//! neighbours in a fixed order (above, below, left, right), so the results do not depend on
//! the thread count. Cost (docs/bem_history.md, "Fewer passes, no transposes"): at 512² and 10 %
//! contact about an eighth of an iteration with the recounts, four fifths of the
//! whole-grid stencil sweeps it replaced. Nothing is allocated after [`RingExtension::new`].

use rayon::prelude::*;

use super::fourier::{centre_on_set, Preconditioner};
use super::pyramid::Pyramid;
use crate::elastic::{Boundary, HalfSpaceOperator};

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

/// Points per block of rows of the parallel passes (whole rows, at least one). Every
/// pass writes each point from its neighbours' values only: the blocks change no bit.
const BLOCK: usize = 8192;

/// A `rows × cols` grid and whether it wraps around (periodic) or ends (free).
type Grid = (usize, usize, bool);

/// The lengths of a row's three lists, stored at the row's places in [`Listed::columns`].
#[derive(Clone, Copy, Default)]
struct RowLists {
    first: usize,
    second: usize,
    edge: usize,
}

/// Points of the grid listed row by row (the rings and the edge of a set), and a value per
/// listed point.
struct Listed {
    /// Per row, at the row's `cols` places: the columns of its first-ring points from the
    /// front, of its edge points (on the set, with first-ring neighbours) from the back.
    columns: Vec<u32>,
    /// Per row, at the row's places: the columns of its second-ring points.
    second_columns: Vec<u32>,
    /// Per row, the lengths of its three lists.
    rows: Vec<RowLists>,
    /// A value per point of the list being updated, at its place.
    values: Vec<f64>,
    cols: usize,
}

/// The rings' neighbour counts and lists for the current free set, the grid they live on,
/// and scratch.
pub(in crate::bem) struct RingExtension {
    /// Per point of the first ring (bounded points next to the set): its number of
    /// neighbours on the set; zero elsewhere.
    first: Vec<u8>,
    /// Per point of the second ring (bounded points next to the first ring only): its
    /// number of first-ring neighbours; zero elsewhere.
    second: Vec<u8>,
    /// The free set the counts and lists are for (they change only when it does).
    counted_for: Vec<bool>,
    /// Per row: whether the free set changed there since the last count.
    changed: Vec<bool>,
    /// The rings' points and the edge's, listed row by row.
    listed: Listed,
    /// A row of zeros of each type: the rows outside a free grid.
    zeros: (Vec<u8>, Vec<bool>),
    grid: Grid,
    /// Experiment (issue 39): the multilevel extension beyond the rings (`far`) or in
    /// their place (`all`), from `ASPERITY_PYRAMID=far|all:λ:γ`.
    pyramid: Option<(Pyramid, bool)>,
}

/// The experiment's switch (issue 39, item 1; off when unset): `ASPERITY_PYRAMID=all:λ:γ`
/// extends the preconditioned field by the multilevel pyramid (`pyramid.rs`) in place of
/// the rings, `far:λ:γ` beyond them. Read once, when the rings' fields are made.
const PYRAMID_ENV: &str = "ASPERITY_PYRAMID";

/// `(all, λ, γ)` of a setting of [`PYRAMID_ENV`]; `None` (the rings alone) unless it is
/// `all` or `far` with `0 < λ ≤ 1` and `0 < γ ≤ 2`.
fn pyramid_setting(value: &str) -> Option<(bool, f64, f64)> {
    let mut parts = value.split(':');
    let all = match parts.next()? {
        "all" => true,
        "far" => false,
        _ => return None,
    };
    let lambda: f64 = parts.next()?.parse().ok()?;
    let gamma: f64 = parts.next()?.parse().ok()?;
    let valid = lambda > 0.0 && lambda <= 1.0 && gamma > 0.0 && gamma <= 2.0;
    (valid && parts.next().is_none()).then_some((all, lambda, gamma))
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

/// `out[j] = Σ f(a_m)` over the 4-neighbours `m` of point `j` of the middle row, from the
/// rows above, at and below it of a field `a` (`f(0) = 0`: a row of zeros stands for one
/// outside a free grid); periodic rows wrap, free ones end. Added in a fixed order: above,
/// below, left, right.
#[inline(always)]
fn stencil<A: Copy>(periodic: bool, a: [&[A]; 3], f: impl Fn(A) -> u8, out: &mut [u8]) {
    let n = out.len();
    let [a0, a1, a2] = a.map(|r| &r[..n]);
    let vertical = |j: usize| f(a0[j]) + f(a2[j]);
    let side = |j: Option<usize>| j.map_or(0, |j| f(a1[j]));
    let wrap = |j: usize| periodic.then_some(j);
    if n == 1 {
        out[0] = vertical(0) + side(wrap(0)) + side(wrap(0));
        return;
    }
    let last = n - 1;
    out[0] = vertical(0) + side(wrap(last)) + side(Some(1));
    for j in 1..last {
        out[j] = f(a0[j]) + f(a2[j]) + f(a1[j - 1]) + f(a1[j + 1]);
    }
    out[last] = vertical(last) + side(Some(last - 1)) + side(wrap(0));
}

/// Whether `test(r)` holds for a row `r` within `reach` rows of row `i` (periodic grids
/// wrap, free ones end).
fn within((rows, _, periodic): Grid, i: usize, reach: usize, test: impl Fn(usize) -> bool) -> bool {
    match periodic {
        true if 2 * reach + 1 >= rows => (0..rows).any(test),
        true => (rows + i - reach..=rows + i + reach).any(|r| test(r % rows)),
        false => (i.saturating_sub(reach)..=(i + reach).min(rows - 1)).any(test),
    }
}

/// `Σ f(m)` over the indices `m` of the 4-neighbours of point `(i, j)`, added in a fixed
/// order: above, below, left, right (periodic grids wrap, free ones end).
#[inline(always)]
fn around(grid: Grid, (i, j): (usize, usize), f: impl Fn(usize) -> f64) -> f64 {
    let (rows, cols, periodic) = grid;
    let k = i * cols + j;
    if 0 < i && i + 1 < rows && 0 < j && j + 1 < cols {
        // Inside the grid (nearly every point): no wrapping, no ends.
        return f(k - cols) + f(k + cols) + f(k - 1) + f(k + 1);
    }
    let left = match j {
        0 => periodic.then(|| k + cols - 1),
        _ => Some(k - 1),
    };
    let right = match j + 1 == cols {
        true => periodic.then(|| k + 1 - cols),
        false => Some(k + 1),
    };
    let vertical = [row_above(grid, i), row_below(grid, i)].map(|r| r.map(|r| r * cols + j));
    vertical
        .into_iter()
        .chain([left, right])
        .flatten()
        .fold(0.0, |sum, m| sum + f(m))
}

/// One of a row's three lists.
#[derive(Clone, Copy)]
enum List {
    FirstRing,
    SecondRing,
    Edge,
}

impl RowLists {
    /// The places of `list` in the row's segment of `cols` places (of
    /// [`Listed::second_columns`] for the second ring, else of [`Listed::columns`]).
    fn places(&self, list: List, cols: usize) -> std::ops::Range<usize> {
        match list {
            List::FirstRing => 0..self.first,
            List::SecondRing => 0..self.second,
            List::Edge => cols - self.edge..cols,
        }
    }
}

impl RingExtension {
    /// The fields for the grid of `operator` (its size and boundaries).
    pub(in crate::bem) fn on_grid_of(operator: &impl HalfSpaceOperator) -> Self {
        let periodic = operator.boundary() == Boundary::Periodic;
        Self::new(operator.rows(), operator.cols(), periodic)
    }

    /// The fields for a `rows × cols` grid (periodic or free boundaries).
    pub(in crate::bem) fn new(rows: usize, cols: usize, periodic: bool) -> Self {
        let len = rows * cols;
        assert!(
            u32::try_from(cols).is_ok(),
            "a row's columns are listed as u32"
        );
        RingExtension {
            first: vec![0; len],
            second: vec![0; len],
            counted_for: vec![false; len],
            changed: vec![false; rows],
            listed: Listed {
                columns: vec![0; len],
                second_columns: vec![0; len],
                rows: vec![RowLists::default(); rows],
                values: vec![0.0; len],
                cols,
            },
            zeros: (vec![0; cols], vec![false; cols]),
            grid: (rows, cols, periodic),
            pyramid: std::env::var(PYRAMID_ENV)
                .ok()
                .and_then(|v| pyramid_setting(&v))
                .map(|(all, lambda, gamma)| (Pyramid::new(rows, cols, lambda, gamma), all)),
        }
    }

    /// Counts the rings' neighbours and lists the rings and the edge for `free` unless
    /// they are for it already (two passes over one byte per point).
    fn count(&mut self, free: &[bool]) {
        let (grid, cols) = (self.grid, self.grid.1);
        // A row's counts and lists depend on the set two rows either side: only rows near
        // a change are recounted (late in a solve the set changes at a few points).
        let counted_for = &self.counted_for;
        self.changed
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, changed)| {
                let row = i * cols..(i + 1) * cols;
                *changed = free[row.clone()] != counted_for[row];
            });
        if !self.changed.contains(&true) {
            return;
        }
        let changed = &self.changed;
        let near_change = |i: usize, reach: usize| within(grid, i, reach, |r| changed[r]);
        let (zeros, falses) = (&self.zeros.0[..], &self.zeros.1[..]);
        // The first ring: bounded points with neighbours on the set.
        for_rows(grid, &mut self.first, |i, row| {
            if !near_change(i, 1) {
                return;
            }
            let rows = rows_of(grid, free, falses, i);
            stencil(grid.2, rows, u8::from, row);
            let own = &free[i * cols..][..cols];
            row.iter_mut()
                .zip(own)
                .for_each(|(c, &f)| *c *= u8::from(!f));
        });
        // Per row: first-ring neighbours of every point, kept as the second ring's counts
        // off the set and the first ring, and the row's lists.
        let first = &self.first;
        self.second
            .par_chunks_mut(cols)
            .zip(self.listed.columns.par_chunks_mut(cols))
            .zip(self.listed.second_columns.par_chunks_mut(cols))
            .zip(self.listed.rows.par_iter_mut())
            .enumerate()
            .with_min_len((BLOCK / cols).max(1))
            .for_each(|(i, (((second, columns), second_columns), lists))| {
                if !near_change(i, 2) {
                    return;
                }
                let rows = rows_of(grid, first, zeros, i);
                stencil(grid.2, rows, |c| u8::from(c > 0), second);
                let (free, first) = (&free[i * cols..][..cols], &first[i * cols..][..cols]);
                let columns = (columns, second_columns);
                *lists = list_row((free, first, &*second), columns);
                second
                    .iter_mut()
                    .zip(free.iter().zip(first))
                    .for_each(|(c, (&f, &r))| *c *= u8::from(!f && r == 0));
            });
        self.counted_for.copy_from_slice(free);
        if let Some((pyramid, _)) = self.pyramid.as_mut() {
            pyramid.count(free);
        }
    }

    /// `z ← (I + E) z` for the free set `free`, of the field that is `z − centre` on the
    /// set: `z`, zero off the set, keeps its values there (uncentred) and gets the
    /// extension of the centred field on the two rings (two updates of listed points, two
    /// passes over the grid's bytes where the set changed).
    pub(in crate::bem) fn extend(&mut self, free: &[bool], z: &mut [f64], centre: f64) {
        self.count(free);
        let (grid, cols) = (self.grid, self.grid.1);
        let (first, second) = (&self.first, &self.second);
        if let Some((pyramid, true)) = self.pyramid.as_mut() {
            pyramid.extend(free, |k: usize| !free[k], z, centre);
            return;
        }
        // The first ring: γ₁/c times the sum of its c neighbours on the set (z is zero off
        // it, and on the rings until they are written; `z − centre·1` there is `z − 0`).
        self.listed.update(z, List::FirstRing, |(i, j), z| {
            let centred = |m: usize| z[m] - centre_on_set(centre, free[m]);
            weight(0, first[i * cols + j]) * around(grid, (i, j), centred)
        });
        // The second ring: γ₂/c times the sum of its c first-ring neighbours (it has no
        // neighbours on the set).
        self.listed.update(z, List::SecondRing, |(i, j), z| {
            weight(1, second[i * cols + j]) * around(grid, (i, j), |m| z[m])
        });
        // Beyond the second ring (after it: the rings read zeros there).
        if let Some((pyramid, false)) = self.pyramid.as_mut() {
            let target = |k: usize| !free[k] && first[k] == 0 && second[k] == 0;
            pyramid.extend(free, target, z, centre);
        }
    }

    /// `z ← (I + E)ᵀ z` on the free set `free` of the last [`RingExtension::extend`]: there
    /// `z` plus what the rings took from each point. Off the set `z` is left unspecified
    /// (its callers read it on the set only, `P_F`). Two updates of listed points.
    pub(in crate::bem) fn gather(&mut self, free: &[bool], z: &mut [f64]) {
        debug_assert!(self.counted_for[..] == *free, "gather follows extend");
        let (grid, cols) = (self.grid, self.grid.1);
        let (first, second) = (&self.first, &self.second);
        if let Some((pyramid, all)) = self.pyramid.as_mut() {
            let all = *all;
            let target = |k: usize| !free[k] && (all || (first[k] == 0 && second[k] == 0));
            pyramid.gather(free, target, z);
            if all {
                return;
            }
        }
        // A first-ring point holds γ₁/c times its value and what its second-ring
        // neighbours took (γ₂/c′ each; the weight is zero off the second ring) …
        self.listed.update(z, List::FirstRing, |(i, j), z| {
            let taken = around(grid, (i, j), |m| weight(1, second[m]) * z[m]);
            weight(0, first[i * cols + j]) * (z[i * cols + j] + taken)
        });
        // … and gives it to its neighbours on the set.
        self.listed.update(z, List::Edge, |(i, j), z| {
            let ring = |m: usize| if first[m] > 0 { z[m] } else { 0.0 };
            z[i * cols + j] + around(grid, (i, j), ring)
        });
    }
}

/// A preconditioner `M` decorated with the rings of a set: `(I + E)ᵀ M (I + E)` on it (the
/// module docs), itself a [`Preconditioner`]. The BCCG decorates the Fourier
/// preconditioner with the rings of its free set, the CG on a set with those of its set;
/// any other preconditioner takes them alike. Nothing is allocated: the decorator borrows
/// the preconditioner, the rings' fields and the set's mask for one application.
pub(in crate::bem) struct Ringed<'a, M: ?Sized> {
    /// The preconditioner decorated.
    pub(in crate::bem) inner: &'a mut M,
    /// The rings' counts, lists and scratch.
    pub(in crate::bem) rings: &'a mut RingExtension,
    /// The set, as a mask of the grid.
    pub(in crate::bem) set: &'a [bool],
}

impl<M: Preconditioner + ?Sized> Preconditioner for Ringed<'_, M> {
    /// `output ← input`, then [`Preconditioner::apply`] in place.
    fn apply_into(&mut self, input: &[f64], output: &mut [f64]) {
        output.copy_from_slice(input);
        self.apply(output);
    }

    /// `data ← (I + E)ᵀ M (I + E) data` on the set (`data` zero off it before; read on the
    /// set only after).
    fn apply(&mut self, data: &mut [f64]) {
        self.rings.extend(self.set, data, 0.0);
        self.inner.apply(data);
        self.rings.gather(self.set, data);
    }

    /// `output ← (I + E)ᵀ M (I + E) Π input` on the decorator's set (which `set` must be):
    /// the extension of the centred field is written into `input` on the rings (zero
    /// there before), the centring made by `M` on the way into its transform.
    fn apply_centred(
        &mut self,
        input: &mut [f64],
        output: &mut [f64],
        (set, centre): (&[bool], f64),
    ) {
        debug_assert!(std::ptr::eq(set, self.set), "the rings' own set");
        self.rings.extend(self.set, input, centre);
        self.inner.apply_centred(input, output, (self.set, centre));
        self.rings.gather(self.set, output);
    }
}

impl Listed {
    /// `z[k] ← value((i, j), z)` at the points `k = (i, j)` of `list`, every value from
    /// `z` as it was before: all values first (into `values`), then written, each in
    /// parallel over blocks of rows.
    fn update(
        &mut self,
        z: &mut [f64],
        list: List,
        value: impl Fn((usize, usize), &[f64]) -> f64 + Sync,
    ) {
        let cols = self.cols;
        let rows_per_task = (BLOCK / cols).max(1);
        let columns = match list {
            List::SecondRing => &self.second_columns[..],
            List::FirstRing | List::Edge => &self.columns[..],
        };
        let (lists, before) = (&self.rows[..], &*z);
        self.values
            .par_chunks_mut(cols)
            .zip(columns.par_chunks(cols))
            .zip(lists.par_iter())
            .enumerate()
            .with_min_len(rows_per_task)
            .for_each(|(i, ((values, columns), lists))| {
                let places = lists.places(list, cols);
                for (&j, v) in columns[places.clone()].iter().zip(&mut values[places]) {
                    *v = value((i, j as usize), before);
                }
            });
        z.par_chunks_mut(cols)
            .zip(self.values.par_chunks(cols))
            .zip(columns.par_chunks(cols))
            .zip(lists.par_iter())
            .with_min_len(rows_per_task)
            .for_each(|(((z, values), columns), lists)| {
                let places = lists.places(list, cols);
                for (&j, &v) in columns[places.clone()].iter().zip(&values[places]) {
                    z[j as usize] = v;
                }
            });
    }
}

/// Lists a row's first-ring points (from the front of `columns.0`), its edge points (from
/// the back) and its second-ring points (in `columns.1`) from its free set, its first-ring
/// counts and the number of first-ring neighbours of each point, `near`.
fn list_row(
    (free, first, near): (&[bool], &[u8], &[u8]),
    (columns, second_columns): (&mut [u32], &mut [u32]),
) -> RowLists {
    let n = free.len();
    let mut lists = RowLists::default();
    // Every point is written to the next place of each list and kept where it belongs: no
    // branch on the set, which would be mispredicted at every edge. The places do not
    // collide: point j is written after at most j points were kept, so the first ring
    // (ending at `first`) and the edge (from `n − edge`) leave its places apart, and
    // the last point written where both meet is the one kept there. Runs of points with
    // neither first-ring counts nor first-ring neighbours (on no list: far from the set,
    // or deep inside it) are skipped whole; that keeps every argument above.
    for start in (0..n).step_by(SKIPPED_RUN) {
        let run = start..(start + SKIPPED_RUN).min(n);
        let listed = first[run.clone()]
            .iter()
            .zip(&near[run.clone()])
            .fold(0, |any, (&f, &m)| any | f | m);
        if listed == 0 {
            continue;
        }
        for j in run {
            let on_first = first[j] > 0;
            let near_first = near[j] > 0;
            columns[lists.first] = j as u32;
            columns[n - 1 - lists.edge] = j as u32;
            second_columns[lists.second] = j as u32;
            lists.first += usize::from(on_first);
            lists.edge += usize::from(free[j] && near_first);
            lists.second += usize::from(!free[j] && !on_first && near_first);
        }
    }
    lists
}

/// Points of a row that [`list_row`] tests for a list at once (one vector of bytes).
const SKIPPED_RUN: usize = 16;

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
    fn a_recount_after_a_few_changes_is_a_fresh_count() {
        // The counts and lists of the rows near a change are recounted, the others kept:
        // after changes at a few points (in the first and last rows too, where periodic
        // grids wrap), the extension and its transpose are those of a fresh count, bit for
        // bit.
        for (rows, cols) in [(31, 31), (50, 72), (7, 13)] {
            for periodic in [false, true] {
                let mut kept = RingExtension::new(rows, cols, periodic);
                let mut state = 11u64;
                let (mut free, z, y) = case(rows * cols, 0.3, &mut state);
                let mut scratch = z.clone();
                kept.extend(&free, &mut scratch, 0.5);
                for k in [
                    0,
                    cols + 3,
                    rows * cols / 2,
                    rows * cols - 1,
                    (rows - 1) * cols,
                ] {
                    free[k] = !free[k];
                    let on_set = |v: &[f64]| -> Vec<f64> {
                        v.iter()
                            .zip(&free)
                            .map(|(&x, &f)| if f { x } else { 0.0 })
                            .collect()
                    };
                    let mut fresh = RingExtension::new(rows, cols, periodic);
                    let results = [&mut kept, &mut fresh].map(|rings| {
                        let mut extended = on_set(&z);
                        rings.extend(&free, &mut extended, 0.5);
                        let mut gathered = y.clone();
                        rings.gather(&free, &mut gathered);
                        (extended, on_set(&gathered))
                    });
                    assert!(results[0] == results[1], "{rows}x{cols} {periodic} at {k}");
                }
            }
        }
    }

    #[test]
    fn extend_follows_the_definition_and_gather_is_its_transpose() {
        // Odd, even and rectangular grids, free and periodic, sparse sets (isolated points,
        // which have a second ring) and dense ones (rows whose every point is listed, where
        // the first ring's list meets the edge's); the extension is checked against the
        // definition written out with coordinates, and ⟨(I + E) z, y⟩ = ⟨z, (I + E)ᵀ y⟩ on
        // the set (so that (I + E)ᵀ M (I + E) is symmetric). Thrice per grid, so that each
        // extension overwrites the last one's fields, the last one extending `z − 0.25` on
        // the set (the rings of the centred field, the set's values kept).
        for (rows, cols) in [(31, 31), (32, 32), (50, 72), (700, 13)] {
            for periodic in [false, true] {
                let grid = (rows, cols, periodic);
                let mut rings = RingExtension::new(rows, cols, periodic);
                let mut state = 7u64;
                for (fill, centre) in [(0.05, 0.0), (0.6, 0.0), (0.95, 0.25)] {
                    let (free, z, y) = case(rows * cols, fill, &mut state);
                    let mut extended = z.clone();
                    rings.extend(&free, &mut extended, centre);
                    let centred: Vec<f64> = (0..z.len())
                        .map(|k| if free[k] { z[k] - centre } else { 0.0 })
                        .collect();
                    let first = |k: usize| {
                        let near = naive_neighbours(k, grid);
                        let on: Vec<usize> = near.into_iter().filter(|&m| free[m]).collect();
                        (!free[k] && !on.is_empty()).then(|| {
                            let sum = on.iter().map(|&m| centred[m]).sum::<f64>();
                            GAMMA[0] * sum / on.len() as f64
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
                    let extended_centred: Vec<f64> = (0..z.len())
                        .map(|k| if free[k] { centred[k] } else { extended[k] })
                        .collect();
                    let left = dot(&extended_centred, &y);
                    let right = dot(&centred, &on_set(&gathered));
                    assert!(
                        (left - right).abs() < 1e-12 * left.abs().max(1.0),
                        "{left} {right}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_ringed_preconditioner_is_symmetric_and_centres_like_its_core() {
        // The decorator of any preconditioner: (I + E)ᵀ M (I + E) on the set. With the
        // Fourier M (double precision) it is symmetric on the set (xᵀR y = yᵀR x) and at
        // least as large as M there would be on the set's fields' extension by zero …
        use crate::bem::precondition::FourierPreconditioner;
        for (rows, cols, periodic) in [(31, 31, false), (24, 40, true), (50, 72, false)] {
            let len = rows * cols;
            let mut m = FourierPreconditioner::<f64>::new(rows, cols, 0.1, 0.1, 1.3).unwrap();
            let mut rings = RingExtension::new(rows, cols, periodic);
            let mut state = 5u64;
            let (set, x, _) = case(len, 0.3, &mut state);
            let (_, y, _) = case(len, 0.0, &mut state);
            let y: Vec<f64> = y
                .iter()
                .zip(&set)
                .map(|(_, &f)| if f { random(&mut state) } else { 0.0 })
                .collect();
            let on_set_dot = |a: &[f64], b: &[f64]| -> f64 {
                (0..len).filter(|&k| set[k]).map(|k| a[k] * b[k]).sum()
            };
            let mut ringed = Ringed {
                inner: &mut m,
                rings: &mut rings,
                set: &set,
            };
            let (mut rx, mut ry) = (vec![0.0; len], vec![0.0; len]);
            ringed.apply_into(&x, &mut rx);
            ringed.apply_into(&y, &mut ry);
            let (xry, yrx) = (on_set_dot(&x, &ry), on_set_dot(&y, &rx));
            assert!(
                (xry - yrx).abs() <= 1e-12 * xry.abs().max(1.0),
                "{xry} {yrx}"
            );
            assert!(on_set_dot(&x, &rx) > 0.0);
            // … and its centred form is its plain form of the centred field, on the set.
            let centre = 0.37;
            let centred: Vec<f64> = x
                .iter()
                .zip(&set)
                .map(|(&v, &f)| if f { v - centre } else { v })
                .collect();
            let mut plain = vec![0.0; len];
            ringed.apply_into(&centred, &mut plain);
            let (mut input, mut output) = (x.clone(), vec![0.0; len]);
            ringed.apply_centred(&mut input, &mut output, (&set, centre));
            for k in (0..len).filter(|&k| set[k]) {
                assert!(
                    (plain[k] - output[k]).abs() <= 1e-12 * plain[k].abs().max(1.0),
                    "{k}"
                );
                assert_eq!(input[k], x[k], "the input is kept on the set");
            }
        }
    }
}
