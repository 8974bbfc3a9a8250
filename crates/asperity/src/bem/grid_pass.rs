//! What the BCCG's parallel passes (`bccg.rs`) share with the plastic field
//! (`plastic_field.rs`): the chunks of the passes, the limit on the pressures a step
//! corrects by their point responses, and those point responses.

use rayon::prelude::*;

/// Pressures cut by the projection in one step that are corrected in `u` by their point
/// responses (each one pass over the grid); beyond this many `u` is recomputed. Measured
/// (free boundaries, 1 and 2 threads), the corrections cost as much as an operator
/// application from 54 cuts at 64² and 128², 62–73 at 256², 75–84 at 512² and 108–128 at
/// 1024² on: below all of them.
pub(super) const CUT_LIMIT: usize = 48;

/// Elements per chunk of the parallel passes. Fixed, never derived from the thread count:
/// each chunk is summed in index order and the chunks' partial sums are added in chunk
/// order, so every sum is the same bits for any number of threads.
pub(super) const CHUNK: usize = 8192;

/// Adds `c K e_t` to `u` for every `(t, c)` of `points`, from the operator's response to a
/// unit pressure on pixel `(0, 0)`, `impulse`: free boundaries `K(Δi, Δj)` at
/// `impulse[|Δi|][|Δj|]` (the kernel is even in both), periodic at the offsets modulo the
/// grid. `grid` is `(rows, cols, periodic)`. `u` is row-major `rows × cols`. One parallel
/// pass over the rows with all points (each value sums them in their order).
pub(super) fn add_point_responses(
    u: &mut [f64],
    impulse: &[f64],
    (rows, cols, periodic): (usize, usize, bool),
    points: &[(usize, f64)],
) {
    u.par_chunks_mut(cols).enumerate().for_each(|(i, row)| {
        for &(t, c) in points {
            let (ti, tj) = (t / cols, t % cols);
            let di = if periodic {
                (i + rows - ti) % rows
            } else {
                i.abs_diff(ti)
            };
            let kernel = &impulse[di * cols..(di + 1) * cols];
            // Columns j ≥ tj: offset j − tj.
            for (uj, &k) in row[tj..].iter_mut().zip(&kernel[..cols - tj]) {
                *uj += c * k;
            }
            // Columns j < tj: offset tj − j (free) or j − tj + cols (periodic).
            if periodic {
                for (uj, &k) in row[..tj].iter_mut().zip(&kernel[cols - tj..]) {
                    *uj += c * k;
                }
            } else {
                for (uj, &k) in row[..tj].iter_mut().rev().zip(&kernel[1..=tj]) {
                    *uj += c * k;
                }
            }
        }
    });
}
