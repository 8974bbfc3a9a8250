//! Contact patches: the connected components of a contact set on a grid, 4-neighbour
//! connectivity (points sharing an edge), no wrap-around.

use ndarray::ArrayView2;

/// The number of 4-connected components of the `true` points of `set`.
pub fn count_patches(set: ArrayView2<bool>) -> usize {
    let (rows, cols) = set.dim();
    let mut seen = vec![false; rows * cols];
    let mut stack = Vec::new();
    let mut patches = 0;
    for start in 0..rows * cols {
        if seen[start] || !set[(start / cols, start % cols)] {
            continue;
        }
        patches += 1;
        seen[start] = true;
        stack.push(start);
        // Depth-first flood fill over the patch (an explicit stack: no recursion depth).
        while let Some(i) = stack.pop() {
            let (r, c) = (i / cols, i % cols);
            let around = [
                (c > 0).then(|| i - 1),
                (c + 1 < cols).then(|| i + 1),
                (r > 0).then(|| i - cols),
                (r + 1 < rows).then(|| i + cols),
            ];
            for j in around.into_iter().flatten() {
                if !seen[j] && set[(j / cols, j % cols)] {
                    seen[j] = true;
                    stack.push(j);
                }
            }
        }
    }
    patches
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    #[test]
    fn patches_by_edges_not_corners() {
        let grid = |rows: &[&str]| {
            Array2::from_shape_fn((rows.len(), rows[0].len()), |(r, c)| {
                rows[r].as_bytes()[c] == b'#'
            })
        };
        // Two diagonal neighbours are two patches; an L and a bar are one each.
        let set = grid(&["#.#..", ".#...", "...##", "#..#."]);
        assert_eq!(count_patches(set.view()), 5);
        assert_eq!(count_patches(grid(&["###", "#.#", "###"]).view()), 1);
        assert_eq!(count_patches(grid(&["...", "..."]).view()), 0);
        // A checkerboard: every point its own patch.
        let board = Array2::from_shape_fn((8, 8), |(r, c)| (r + c) % 2 == 0);
        assert_eq!(count_patches(board.view()), 32);
    }
}
