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
//! one here is local and costs two grid passes besides the labelling: the first ring
//! (bounded points next to `F`) takes `γ₁` times the mean of its neighbours on `F`, the
//! second ring `γ₂` times the mean of its neighbours on the first ring (4-neighbours; free
//! boundaries have no neighbours outside the grid, periodic ones wrap). The transpose
//! gathers the preconditioned field back onto `F` along the same weights. Measured at 512²:
//! the largest eigenvalue 11.9 → 5.5 with `γ = (0.7, 0.5)`.
//!
//! The passes run in parallel over rows, each point written by one thread from values no
//! pass writes, so results do not depend on the thread count; nothing is allocated after
//! [`RingExtension::new`].

use rayon::prelude::*;

/// Weights of the first and the second ring (measured, see the module docs).
const GAMMA: [f64; 2] = [0.7, 0.5];

/// Points per parallel task (rounded up to whole rows).
const BLOCK_POINTS: usize = 8192;

/// Label of a point: 0 on the free set, 1 and 2 on the rings, 3 beyond.
const BEYOND: u8 = 3;

/// `1/c` for a count `c` of neighbours (0 for none).
const RECIPROCAL: [f64; 5] = [0.0, 1.0, 0.5, 1.0 / 3.0, 0.25];

/// The ring labels of the current free set, the grid they live on, and the weights.
pub(super) struct RingExtension {
    /// Per point: the label (bits 0–1) and, on the rings, the number of its neighbours one
    /// label lower (bits 2–4).
    ring: Vec<u8>,
    /// The first pass's labels (free set and first ring only).
    first: Vec<u8>,
    rows: usize,
    cols: usize,
    periodic: bool,
    gamma: [f64; 2],
    /// By label byte: `γ_r / count` on ring `r` (index 0: first ring, 1: second), else 0.
    share: [[f64; 32]; 2],
}

/// The 4-neighbours of `(i, j)` on a `rows × cols` grid and whether each exists (1 or 0):
/// periodic grids wrap; on free boundaries a missing neighbour is the point itself with
/// weight 0. Interior points take the fixed offsets, so the passes below run without
/// data-dependent branches (the labels of a rough contact set are too irregular for the
/// branch predictor).
#[inline(always)]
fn neighbours(
    (rows, cols, periodic): (usize, usize, bool),
    (i, j): (usize, usize),
) -> ([usize; 4], [f64; 4]) {
    let k = i * cols + j;
    if i > 0 && i + 1 < rows && j > 0 && j + 1 < cols {
        return ([k - cols, k + cols, k - 1, k + 1], [1.0; 4]);
    }
    let wrap = |inside: bool, index: usize, wrapped: usize| match (inside, periodic) {
        (true, _) => (index, 1.0),
        (false, true) => (wrapped, 1.0),
        (false, false) => (k, 0.0),
    };
    let up = wrap(i > 0, k.wrapping_sub(cols), (rows - 1) * cols + j);
    let down = wrap(i + 1 < rows, k + cols, j);
    let left = wrap(j > 0, k.wrapping_sub(1), i * cols + cols - 1);
    let right = wrap(j + 1 < cols, k + 1, i * cols);
    (
        [up.0, down.0, left.0, right.0],
        [up.1, down.1, left.1, right.1],
    )
}

impl RingExtension {
    /// The fields for a `rows × cols` grid (periodic or free boundaries).
    pub(super) fn new(rows: usize, cols: usize, periodic: bool) -> Self {
        let gamma = GAMMA;
        let mut share = [[0.0; 32]; 2];
        for byte in 0..32 {
            let reciprocal = RECIPROCAL[(byte >> 2).min(4)];
            match byte & 3 {
                1 => share[0][byte] = gamma[0] * reciprocal,
                2 => share[1][byte] = gamma[1] * reciprocal,
                _ => {}
            }
        }
        RingExtension {
            ring: vec![BEYOND; rows * cols],
            first: vec![BEYOND; rows * cols],
            rows,
            cols,
            periodic,
            gamma,
            share,
        }
    }

    fn grid(&self) -> (usize, usize, bool) {
        (self.rows, self.cols, self.periodic)
    }

    /// Points and rows of one parallel task: whole rows, at least [`BLOCK_POINTS`] points
    /// (fewer tasks on small grids, where one per row costs more than its work).
    fn block(&self) -> (usize, usize) {
        let rows_per_block = BLOCK_POINTS.div_ceil(self.cols).max(1);
        (rows_per_block * self.cols, rows_per_block)
    }

    /// `z ← (I + E) z` for the free set `free`: `z` (zero off the set) keeps its values on
    /// the set and gets the extension on the two rings; `spare` is overwritten. Labels the
    /// rings on the way (two parallel passes).
    pub(super) fn extend(&mut self, free: &[bool], z: &mut [f64], spare: &mut [f64]) {
        let (grid, cols, gamma) = (self.grid(), self.cols, self.gamma);
        // First ring: γ₁ times the mean of the free neighbours (z is zero off the set, so
        // the sum of all four is the sum over the free ones).
        let z_read: &[f64] = z;
        let (block, rows_per_block) = self.block();
        self.first
            .par_chunks_mut(block)
            .zip(spare.par_chunks_mut(block))
            .enumerate()
            .for_each(|(b, (labels, values))| {
                let rows = labels.chunks_mut(cols).zip(values.chunks_mut(cols));
                for (r, (labels, values)) in rows.enumerate() {
                    let i = b * rows_per_block + r;
                    for (j, (label, value)) in labels.iter_mut().zip(values.iter_mut()).enumerate()
                    {
                        let k = i * cols + j;
                        let (near, exists) = neighbours(grid, (i, j));
                        let (mut count, mut sum) = (0u8, 0.0);
                        for (&m, &e) in near.iter().zip(&exists) {
                            count += (free[m] && e > 0.0) as u8;
                            sum += e * z_read[m];
                        }
                        let ring = if count > 0 { 1 | count << 2 } else { BEYOND };
                        *label = if free[k] { 0 } else { ring };
                        let on_ring = (*label & 3 == 1) as u8 as f64;
                        *value = on_ring * gamma[0] * sum * RECIPROCAL[count.min(4) as usize];
                    }
                }
            });
        // Second ring: γ₂ times the mean of the first-ring neighbours (`spare` is zero off
        // the first ring); every point adds its ring value to z.
        let (first, spare): (&[u8], &[f64]) = (&self.first, spare);
        self.ring
            .par_chunks_mut(block)
            .zip(z.par_chunks_mut(block))
            .enumerate()
            .for_each(|(b, (labels, values))| {
                let rows = labels.chunks_mut(cols).zip(values.chunks_mut(cols));
                for (r, (labels, values)) in rows.enumerate() {
                    let i = b * rows_per_block + r;
                    for (j, (label, value)) in labels.iter_mut().zip(values.iter_mut()).enumerate()
                    {
                        let k = i * cols + j;
                        let (near, exists) = neighbours(grid, (i, j));
                        let (mut count, mut sum) = (0u8, 0.0);
                        for (&m, &e) in near.iter().zip(&exists) {
                            count += (first[m] & 3 == 1 && e > 0.0) as u8;
                            sum += e * spare[m];
                        }
                        let second = first[k] == BEYOND && count > 0;
                        *label = if second { 2 | count << 2 } else { first[k] };
                        let weight =
                            second as u8 as f64 * gamma[1] * RECIPROCAL[count.min(4) as usize];
                        *value += spare[k] + weight * sum;
                    }
                }
            });
    }

    /// `z ← P_F (I + E)ᵀ z` for the rings of the last [`RingExtension::extend`]: on the
    /// free set, `z` plus what the rings took from each point; zero elsewhere. `spare` is
    /// overwritten (two parallel passes).
    pub(super) fn gather(&self, z: &mut [f64], spare: &mut [f64]) {
        let (grid, cols, ring, share) = (self.grid(), self.cols, &self.ring[..], &self.share);
        // First ring: its own value plus the shares the second ring took from it.
        let z_read: &[f64] = z;
        let (block, rows_per_block) = self.block();
        spare
            .par_chunks_mut(block)
            .enumerate()
            .for_each(|(b, values)| {
                for (r, values) in values.chunks_mut(cols).enumerate() {
                    let i = b * rows_per_block + r;
                    for (j, value) in values.iter_mut().enumerate() {
                        let k = i * cols + j;
                        let (near, exists) = neighbours(grid, (i, j));
                        let mut sum = z_read[k];
                        for (&m, &e) in near.iter().zip(&exists) {
                            sum += e * share[1][ring[m] as usize & 31] * z_read[m];
                        }
                        *value = (ring[k] & 3 == 1) as u8 as f64 * sum;
                    }
                }
            });
        // The free set: its own value plus the shares the first ring took from it.
        let spare: &[f64] = spare;
        z.par_chunks_mut(block).enumerate().for_each(|(b, values)| {
            for (r, values) in values.chunks_mut(cols).enumerate() {
                let i = b * rows_per_block + r;
                for (j, value) in values.iter_mut().enumerate() {
                    let k = i * cols + j;
                    let (near, exists) = neighbours(grid, (i, j));
                    let mut sum = *value;
                    for (&m, &e) in near.iter().zip(&exists) {
                        sum += e * share[0][ring[m] as usize & 31] * spare[m];
                    }
                    *value = (ring[k] & 3 == 0) as u8 as f64 * sum;
                }
            }
        });
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

    #[test]
    fn gather_is_the_transpose_of_extend_restricted_to_the_set() {
        // ⟨(I + E) z, y⟩ = ⟨z, P_F (I + E)ᵀ y⟩ for z on the set: the preconditioner
        // (I + E)ᵀ M (I + E) is then symmetric. Checked on small sets (isolated points,
        // which have a second ring) and on large ones, free and periodic, on a grid with
        // more rows than a block holds.
        let (rows, cols) = (700, 13);
        for (periodic, fill) in [(false, 0.05), (true, 0.05), (false, 0.6), (true, 0.6)] {
            let mut state = 7u64;
            let free: Vec<bool> = (0..rows * cols)
                .map(|_| random(&mut state) + 0.5 < fill)
                .collect();
            let z: Vec<f64> = free
                .iter()
                .map(|&f| if f { random(&mut state) } else { 0.0 })
                .collect();
            let y: Vec<f64> = (0..rows * cols).map(|_| random(&mut state)).collect();
            let mut rings = RingExtension::new(rows, cols, periodic);
            let (mut extended, mut spare) = (z.clone(), vec![0.0; rows * cols]);
            rings.extend(&free, &mut extended, &mut spare);
            let mut gathered = y.clone();
            rings.gather(&mut gathered, &mut spare);
            let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
            let (left, right) = (dot(&extended, &y), dot(&z, &gathered));
            assert!(
                (left - right).abs() < 1e-12 * left.abs().max(1.0),
                "{left} {right}"
            );
            // The set keeps its values; the rings get some; the gather is zero off the set.
            for k in 0..rows * cols {
                if free[k] {
                    assert_eq!(extended[k], z[k]);
                } else {
                    assert_eq!(gathered[k], 0.0);
                }
            }
            let ring_points = (0..rows * cols)
                .filter(|&k| !free[k] && extended[k] != 0.0)
                .count();
            assert!(ring_points > 0);
        }
    }
}
