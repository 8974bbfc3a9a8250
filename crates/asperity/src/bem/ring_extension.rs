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
//! The rings are kept as lists of their points: one pass over the grid finds the first
//! ring, and everything else visits the rings only. That is still not cheap where the
//! contact set is many small islands, whose rings cover much of the grid: at 128², H = −1,
//! the extension and its transpose take a fifth of a solve (docs/bem.md), which is why the
//! BCCG leaves them off. The lists are built and used serially, in index order: the
//! results do not depend on the thread count. Nothing is allocated after
//! [`RingExtension::new`].

/// Weights of the first and the second ring (measured, see the module docs).
const GAMMA: [f64; 2] = [0.7, 0.5];

/// Label of a point off the rings.
const OFF: u8 = 0;
/// Label of a first-ring point.
const FIRST: u8 = 1;
/// Label of a second-ring point.
const SECOND: u8 = 2;

/// The rings of the current free set, the grid they live on, and the weights.
pub(super) struct RingExtension {
    /// Per point: [`OFF`], [`FIRST`] or [`SECOND`] for the rings of the last extension.
    label: Vec<u8>,
    /// The first ring's points, ascending, with `γ₁` over their number of free neighbours.
    first: Vec<Entry>,
    /// The second ring's points (in the order they were found from the first), with `γ₂`
    /// over their number of first-ring neighbours.
    second: Vec<Entry>,
    rows: usize,
    cols: usize,
    periodic: bool,
}

/// Calls `visit` with each 4-neighbour of point `k` of a `rows × cols` grid (periodic:
/// wrapped; free: those inside the grid only).
#[inline(always)]
fn neighbours(
    (rows, cols, periodic): (usize, usize, bool),
    k: usize,
    mut visit: impl FnMut(usize),
) {
    let (i, j) = (k / cols, k % cols);
    if i > 0 {
        visit(k - cols);
    } else if periodic {
        visit((rows - 1) * cols + j);
    }
    if i + 1 < rows {
        visit(k + cols);
    } else if periodic {
        visit(j);
    }
    if j > 0 {
        visit(k - 1);
    } else if periodic {
        visit(k + cols - 1);
    }
    if j + 1 < cols {
        visit(k + 1);
    } else if periodic {
        visit(k + 1 - cols);
    }
}

/// A point of a ring: its index, its weight over its number of neighbours one ring in, and
/// whether it is away from the grid's edges (its neighbours then are `k ± 1`, `k ± cols`,
/// found without a division).
#[derive(Clone, Copy)]
struct Entry {
    k: usize,
    share: f64,
    interior: bool,
}

impl Entry {
    fn new(k: usize, (rows, cols): (usize, usize)) -> Self {
        let (i, j) = (k / cols, k % cols);
        Entry {
            k,
            share: 0.0,
            interior: i > 0 && i + 1 < rows && j > 0 && j + 1 < cols,
        }
    }

    /// Calls `visit` with each 4-neighbour (as [`neighbours`]).
    #[inline(always)]
    fn neighbours(self, grid: (usize, usize, bool), mut visit: impl FnMut(usize)) {
        if self.interior {
            let (k, cols) = (self.k, grid.1);
            visit(k - cols);
            visit(k + cols);
            visit(k - 1);
            visit(k + 1);
        } else {
            neighbours(grid, self.k, visit);
        }
    }
}

impl RingExtension {
    /// The fields for a `rows × cols` grid (periodic or free boundaries).
    pub(super) fn new(rows: usize, cols: usize, periodic: bool) -> Self {
        RingExtension {
            label: vec![OFF; rows * cols],
            first: Vec::with_capacity(rows * cols),
            second: Vec::with_capacity(rows * cols),
            rows,
            cols,
            periodic,
        }
    }

    /// Lists the rings of `free` (clearing the labels of the last ones first).
    fn find_rings(&mut self, free: &[bool]) {
        let grid = (self.rows, self.cols, self.periodic);
        for entry in self.first.iter().chain(&self.second) {
            self.label[entry.k] = OFF;
        }
        let (mut first, mut second) = (
            std::mem::take(&mut self.first),
            std::mem::take(&mut self.second),
        );
        first.clear();
        second.clear();
        // The first ring, row by row (so that no division finds a point's row and column):
        // a point off the set with a neighbour on it.
        let (rows, cols) = (self.rows, self.cols);
        for i in 0..rows {
            let row = i * cols;
            for j in 0..cols {
                let k = row + j;
                if free[k] {
                    continue;
                }
                let mut entry = Entry {
                    k,
                    share: 0.0,
                    interior: i > 0 && i + 1 < rows && j > 0 && j + 1 < cols,
                };
                let mut count = 0u32;
                entry.neighbours(grid, |m| count += free[m] as u32);
                if count > 0 {
                    self.label[k] = FIRST;
                    entry.share = GAMMA[0] / f64::from(count);
                    first.push(entry);
                }
            }
        }
        for entry in &first {
            entry.neighbours(grid, |m| {
                if !free[m] && self.label[m] == OFF {
                    // Marked now, weighed below (its first-ring neighbours are all known).
                    self.label[m] = SECOND;
                    second.push(Entry::new(m, (rows, cols)));
                }
            });
        }
        for entry in second.iter_mut() {
            let mut count = 0u32;
            entry.neighbours(grid, |m| count += (self.label[m] == FIRST) as u32);
            entry.share = GAMMA[1] / f64::from(count);
        }
        (self.first, self.second) = (first, second);
    }

    /// `z ← (I + E) z` for the free set `free`: `z` (zero off the set) keeps its values on
    /// the set and gets the extension on the two rings.
    pub(super) fn extend(&mut self, free: &[bool], z: &mut [f64]) {
        self.find_rings(free);
        let grid = (self.rows, self.cols, self.periodic);
        for &entry in &self.first {
            let mut sum = 0.0;
            entry.neighbours(grid, |m| {
                if free[m] {
                    sum += z[m];
                }
            });
            z[entry.k] = entry.share * sum;
        }
        for &entry in &self.second {
            let mut sum = 0.0;
            entry.neighbours(grid, |m| {
                if self.label[m] == FIRST {
                    sum += z[m];
                }
            });
            z[entry.k] = entry.share * sum;
        }
    }

    /// `z ← (I + E)ᵀ z` on the free set `free` of the last [`RingExtension::extend`]: there
    /// `z` plus what the rings took from each point. Off the set `z` is left unspecified
    /// (its callers read it on the set only, `P_F`).
    pub(super) fn gather(&self, free: &[bool], z: &mut [f64]) {
        let grid = (self.rows, self.cols, self.periodic);
        // The second ring gives to the first, then the first (with what it got) to the set.
        for &entry in &self.second {
            let give = entry.share * z[entry.k];
            entry.neighbours(grid, |m| {
                if self.label[m] == FIRST {
                    z[m] += give;
                }
            });
        }
        for &entry in &self.first {
            let give = entry.share * z[entry.k];
            entry.neighbours(grid, |m| {
                if free[m] {
                    z[m] += give;
                }
            });
        }
    }
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
        // second extension starts from the first one's labels.
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
