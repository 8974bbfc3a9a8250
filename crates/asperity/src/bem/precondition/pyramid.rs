//! [`Pyramid`]: a multilevel extension of a field on a set to the points far from it
//! (issue 39, item 1; an experiment beside the rings of `ring_extension.rs`).
//!
//! The rings extend a field on the free set over two rings of bounded points; the optimal
//! extension (the Schur complement's, the displacement outside the set that the set's
//! pressure produces) reaches as far as the patches are wide. The pyramid gives each point
//! off the set a value from the set at every scale: level `ℓ` (blocks of `2^ℓ × 2^ℓ`
//! points) holds the sum `S` of the field over the set's points in each block and their
//! count `C`; from the coarsest level down, a block's value is
//! `f_ℓ = w S/C + (1 − w) λ f_{ℓ+1}(parent)`, `w = (C/|B|)^γ` the block's covered fraction
//! raised to `γ` (a block without set points takes `λ` times its parent's value), and a
//! target point takes `λ f_1` of its 2 × 2 block. Linear in the field (the weights depend
//! on the set only), so `(I + E)ᵀ M (I + E)` stays symmetric positive definite on the set
//! with any `λ`, `γ`; [`Pyramid::gather`] is the transpose. Nothing is allocated after
//! [`Pyramid::new`].

use rayon::prelude::*;

/// One coarse level: its grid, and per block the size `|B|` (points of the grid in it),
/// the set's count `C`, the coefficients `a = w/C` and `d = (1 − w) λ`, and two fields.
struct Level {
    rows: usize,
    cols: usize,
    size: Vec<f64>,
    count: Vec<f64>,
    a: Vec<f64>,
    d: Vec<f64>,
    /// `S` (extension) or the transpose's pulled field `h`.
    sum: Vec<f64>,
    /// `f` (extension) or the transpose's pushed field `q`.
    value: Vec<f64>,
}

impl Level {
    fn new(rows: usize, cols: usize) -> Self {
        let len = rows * cols;
        Level {
            rows,
            cols,
            size: vec![0.0; len],
            count: vec![0.0; len],
            a: vec![0.0; len],
            d: vec![0.0; len],
            sum: vec![0.0; len],
            value: vec![0.0; len],
        }
    }
}

/// The levels of a grid's pyramid and its two parameters.
pub(in crate::bem) struct Pyramid {
    levels: Vec<Level>,
    rows: usize,
    cols: usize,
    lambda: f64,
    gamma: f64,
}

/// `Σ` over the 2 × 2 children of coarse point `(i, j)` of a `rows × cols` grid of `f(k)`,
/// `k` the child's index (children outside the grid left out), in a fixed order.
#[inline(always)]
fn children(rows: usize, cols: usize, (i, j): (usize, usize), f: impl Fn(usize) -> f64) -> f64 {
    let mut s = 0.0;
    for r in 2 * i..(2 * i + 2).min(rows) {
        for c in 2 * j..(2 * j + 2).min(cols) {
            s += f(r * cols + c);
        }
    }
    s
}

/// `sum[j] = Σ keep(k)` over the fine points `k` of coarse point `(i, j)`, by pairs of
/// columns of fine rows `2i` and `2i + 1` (the last fine row or column may be alone).
#[inline(always)]
fn pull_rows((rows, cols): (usize, usize), i: usize, sum: &mut [f64], keep: impl Fn(usize) -> f64) {
    let top = 2 * i * cols;
    let bottom = (2 * i + 1 < rows).then_some(top + cols);
    let pairs = cols / 2;
    for (j, s) in sum[..pairs].iter_mut().enumerate() {
        let k = top + 2 * j;
        let mut v = keep(k) + keep(k + 1);
        if let Some(b) = bottom {
            v += keep(b + 2 * j) + keep(b + 2 * j + 1);
        }
        *s = v;
    }
    if cols % 2 == 1 {
        let mut v = keep(top + cols - 1);
        if let Some(b) = bottom {
            v += keep(b + cols - 1);
        }
        sum[pairs] = v;
    }
}

impl Pyramid {
    /// The levels of a `rows × cols` grid, down to one block.
    pub(in crate::bem) fn new(rows: usize, cols: usize, lambda: f64, gamma: f64) -> Self {
        let mut levels = Vec::new();
        let (mut r, mut c) = (rows, cols);
        while r > 1 || c > 1 {
            (r, c) = (r.div_ceil(2), c.div_ceil(2));
            levels.push(Level::new(r, c));
        }
        Pyramid {
            levels,
            rows,
            cols,
            lambda,
            gamma,
        }
    }

    /// The blocks' sizes, counts and coefficients for the set `free`.
    pub(in crate::bem) fn count(&mut self, free: &[bool]) {
        let (rows, cols) = (self.rows, self.cols);
        let (lambda, gamma) = (self.lambda, self.gamma);
        for l in 0..self.levels.len() {
            let (below, rest) = self.levels.split_at_mut(l);
            let level = &mut rest[0];
            let lc = level.cols;
            let fine = below.last();
            level
                .size
                .par_chunks_mut(lc)
                .zip(level.count.par_chunks_mut(lc))
                .enumerate()
                .for_each(|(i, (size, count))| {
                    for j in 0..lc {
                        (size[j], count[j]) = match fine {
                            None => (
                                children(rows, cols, (i, j), |_| 1.0),
                                children(rows, cols, (i, j), |k| f64::from(u8::from(free[k]))),
                            ),
                            Some(f) => (
                                children(f.rows, f.cols, (i, j), |k| f.size[k]),
                                children(f.rows, f.cols, (i, j), |k| f.count[k]),
                            ),
                        };
                    }
                });
            for k in 0..level.size.len() {
                let (c, b) = (level.count[k], level.size[k]);
                let w = if gamma == 0.5 {
                    (c / b).sqrt()
                } else {
                    (c / b).powf(gamma)
                };
                level.a[k] = if c > 0.0 { w / c } else { 0.0 };
                level.d[k] = (1.0 - w) * lambda;
            }
        }
    }

    /// `z[k] ← λ f_1(parent of k)` at the points with `target(k)`, from the field
    /// `z − centre` on the set `free` (module docs).
    pub(in crate::bem) fn extend(
        &mut self,
        free: &[bool],
        target: impl Fn(usize) -> bool + Sync,
        z: &mut [f64],
        centre: f64,
    ) {
        let (rows, cols) = (self.rows, self.cols);
        let Some(top) = self.levels.len().checked_sub(1) else {
            return;
        };
        // Pull: the set's sums, level by level.
        for l in 0..=top {
            let (below, rest) = self.levels.split_at_mut(l);
            let level = &mut rest[0];
            let lc = level.cols;
            let fine = below.last();
            let zr = &*z;
            level
                .sum
                .par_chunks_mut(lc)
                .enumerate()
                .for_each(|(i, sum)| {
                    for (j, s) in sum.iter_mut().enumerate() {
                        if let Some(f) = fine {
                            *s = children(f.rows, f.cols, (i, j), |k| f.sum[k]);
                        }
                    }
                    if fine.is_none() {
                        let keep = |k: usize| if free[k] { zr[k] - centre } else { 0.0 };
                        pull_rows((rows, cols), i, sum, keep);
                    }
                });
        }
        // Push: the blocks' values from the coarsest down.
        for l in (0..=top).rev() {
            let (here, above) = self.levels.split_at_mut(l + 1);
            let level = &mut here[l];
            let parent = above.first();
            let lc = level.cols;
            let (a, d, sum) = (&level.a, &level.d, &level.sum);
            level
                .value
                .par_chunks_mut(lc)
                .enumerate()
                .for_each(|(i, value)| {
                    for (j, v) in value.iter_mut().enumerate() {
                        let k = i * lc + j;
                        let up = parent.map_or(0.0, |p| p.value[(i / 2) * p.cols + j / 2]);
                        *v = a[k] * sum[k] + d[k] * up;
                    }
                });
        }
        let first = &self.levels[0];
        let lambda = self.lambda;
        z.par_chunks_mut(cols).enumerate().for_each(|(i, row)| {
            for (j, zk) in row.iter_mut().enumerate() {
                if target(i * cols + j) {
                    *zk = lambda * first.value[(i / 2) * first.cols + j / 2];
                }
            }
        });
    }

    /// The transpose of [`Pyramid::extend`]: `z[k] += Σ` of what the targets took from
    /// point `k` of the set, from `z` at the targets (read there, left unspecified).
    pub(in crate::bem) fn gather(
        &mut self,
        free: &[bool],
        target: impl Fn(usize) -> bool + Sync,
        z: &mut [f64],
    ) {
        let (rows, cols) = (self.rows, self.cols);
        let Some(top) = self.levels.len().checked_sub(1) else {
            return;
        };
        let lambda = self.lambda;
        // Pull: h_1 = R (λ z on the targets), h_{ℓ+1} = R (d_ℓ h_ℓ).
        for l in 0..=top {
            let (below, rest) = self.levels.split_at_mut(l);
            let level = &mut rest[0];
            let lc = level.cols;
            let fine = below.last();
            let zr = &*z;
            let target = &target;
            level
                .sum
                .par_chunks_mut(lc)
                .enumerate()
                .for_each(|(i, sum)| {
                    for (j, s) in sum.iter_mut().enumerate() {
                        if let Some(f) = fine {
                            *s = children(f.rows, f.cols, (i, j), |k| f.d[k] * f.sum[k]);
                        }
                    }
                    if fine.is_none() {
                        let keep = |k: usize| if target(k) { lambda * zr[k] } else { 0.0 };
                        pull_rows((rows, cols), i, sum, keep);
                    }
                });
        }
        // Push: q_L = a_L h_L, q_ℓ = a_ℓ h_ℓ + U q_{ℓ+1}.
        for l in (0..=top).rev() {
            let (here, above) = self.levels.split_at_mut(l + 1);
            let level = &mut here[l];
            let parent = above.first();
            let lc = level.cols;
            let (a, sum) = (&level.a, &level.sum);
            level
                .value
                .par_chunks_mut(lc)
                .enumerate()
                .for_each(|(i, value)| {
                    for (j, v) in value.iter_mut().enumerate() {
                        let k = i * lc + j;
                        let up = parent.map_or(0.0, |p| p.value[(i / 2) * p.cols + j / 2]);
                        *v = a[k] * sum[k] + up;
                    }
                });
        }
        let first = &self.levels[0];
        z.par_chunks_mut(cols).enumerate().for_each(|(i, row)| {
            for (j, zk) in row.iter_mut().enumerate() {
                if free[i * cols + j] {
                    *zk += first.value[(i / 2) * first.cols + j / 2];
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

    /// `vᵀ (E x) = (Eᵀ v)ᵀ x` on random sets, fields and odd grids.
    #[test]
    fn gather_is_the_transpose_of_extend() {
        let mut state = 7u64;
        for (rows, cols) in [(13, 9), (16, 16), (1, 7), (33, 20)] {
            let n = rows * cols;
            let free: Vec<bool> = (0..n).map(|_| random(&mut state) > 0.2).collect();
            let target = |k: usize| !free[k] && !k.is_multiple_of(3);
            let mut pyramid = Pyramid::new(rows, cols, 0.9, 0.5);
            pyramid.count(&free);
            let x: Vec<f64> = (0..n)
                .map(|k| if free[k] { random(&mut state) } else { 0.0 })
                .collect();
            let v: Vec<f64> = (0..n).map(|_| random(&mut state)).collect();
            let mut ex = x.clone();
            pyramid.extend(&free, target, &mut ex, 0.0);
            let lhs: f64 = (0..n).filter(|&k| target(k)).map(|k| v[k] * ex[k]).sum();
            let mut g = v.clone();
            g.iter_mut()
                .zip(&free)
                .for_each(|(g, &f)| *g = if f { 0.0 } else { *g });
            pyramid.gather(&free, target, &mut g);
            let rhs: f64 = (0..n).filter(|&k| free[k]).map(|k| g[k] * x[k]).sum();
            assert!(
                (lhs - rhs).abs() <= 1e-12 * lhs.abs().max(1.0),
                "{rows}×{cols}: {lhs} {rhs}"
            );
            assert!(ex
                .iter()
                .zip(&x)
                .enumerate()
                .all(|(k, (e, x))| !free[k] || e == x));
        }
    }
}
