//! Contact patches: the connected components of a contact set on a grid, 4-neighbour
//! connectivity (points sharing an edge), no wrap-around.

use ndarray::{Array2, ArrayView2};

/// The number of 4-connected components of the `true` points of `set`: the patches that
/// [`label_patches`] labels.
pub fn count_patches(set: ArrayView2<bool>) -> usize {
    label_patches(set).1.len()
}

/// The 4-connected patches of the `true` points of `set`: a label per point (0 outside
/// contact, patches numbered 1, 2, … in the order of their first point, row by row) and the
/// number of points of each patch (`sizes[k]` for label `k + 1`). `sizes.len()` is
/// [`count_patches`]; a patch's area is its size times the pixel area.
pub fn label_patches(set: ArrayView2<bool>) -> (Array2<u32>, Vec<usize>) {
    let (rows, cols) = set.dim();
    let mut labels = Array2::<u32>::zeros((rows, cols));
    let mut sizes = Vec::new();
    let mut stack = Vec::new();
    for start in 0..rows * cols {
        let at = (start / cols, start % cols);
        if labels[at] != 0 || !set[at] {
            continue;
        }
        let label = u32::try_from(sizes.len() + 1).expect("fewer patches than 2^32");
        let mut size = 0;
        labels[at] = label;
        stack.push(start);
        // Depth-first flood fill over the patch (an explicit stack: no recursion depth).
        while let Some(i) = stack.pop() {
            size += 1;
            let (r, c) = (i / cols, i % cols);
            let around = [
                (c > 0).then(|| i - 1),
                (c + 1 < cols).then(|| i + 1),
                (r > 0).then(|| i - cols),
                (r + 1 < rows).then(|| i + cols),
            ];
            for j in around.into_iter().flatten() {
                let at = (j / cols, j % cols);
                if labels[at] == 0 && set[at] {
                    labels[at] = label;
                    stack.push(j);
                }
            }
        }
        sizes.push(size);
    }
    (labels, sizes)
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

    #[test]
    fn labels_and_sizes_agree_with_the_count() {
        let rows = ["##..#", "#...#", "..#..", "####."];
        let set = Array2::from_shape_fn((4, 5), |(r, c)| rows[r].as_bytes()[c] == b'#');
        let (labels, sizes) = label_patches(set.view());
        assert_eq!(sizes, vec![3, 2, 5]);
        assert_eq!(sizes.len(), count_patches(set.view()));
        assert_eq!(labels.row(0).to_vec(), vec![1, 1, 0, 0, 2]);
        assert_eq!(labels.row(3).to_vec(), vec![3, 3, 3, 3, 0]);
        assert_eq!(labels[(2, 2)], 3);
        // Every contact point has a label, every other point none.
        assert!(labels.iter().zip(set.iter()).all(|(l, s)| (*l > 0) == *s));
        // A random set: the sizes add up to the points in contact.
        let noise = Array2::from_shape_fn((40, 30), |(r, c)| (r * 7 + c * 13) % 5 < 2);
        let (_, sizes) = label_patches(noise.view());
        assert_eq!(sizes.len(), count_patches(noise.view()));
        assert_eq!(
            sizes.iter().sum::<usize>(),
            noise.iter().filter(|v| **v).count()
        );
    }
}
