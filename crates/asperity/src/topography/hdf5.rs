//! HDF5 files (`.h5`, `.hdf5`; also how the contact-mechanics challenge surface is
//! distributed), and Zygo's HDF5-based `.datx` ([`super::datx`]).
//!
//! The container is read by `hdf5-reader`, a read-only HDF5 decoder in Rust (no C
//! library, part of every build). It was chosen over the HDF5 C library because the C
//! library (1.10.8) crashed the process on corrupt files under our fuzz loop (in `H5HG_read`
//! and `H5T__conv_struct_opt`, where it only asserts what a file claims), whereas a Rust
//! decoder refuses them with an error: measured, 0 panics and no allocation over 4 GB in
//! about 560 000 mutated files (1–4 random bit flips, truncations) of the shared HDF5 file
//! and both `.datx` test files, slowest 134 ms.
//!
//! Generic HDF5 carries no units or physical sizes: every two-dimensional numeric dataset
//! (integers or floats, any depth of groups, in the order of their names) is a channel
//! named by its path without the leading `/`; its first index runs along x (as
//! SurfaceTopography's `H5Reader` reads it), so our map is the dataset's transpose; the
//! size must be given. The file is opened from memory (never a path on disk), so an
//! external link or external raw data (other files) cannot be followed; soft links inside
//! the file are (the decoder bounds their depth), and no dataset is read whose values need
//! more bytes than the file's bytes times deflate's largest expansion.

use hdf5_reader as h5;
use hdf5_reader::Datatype;
use ndarray::Array2;

use super::{bad, Channel, Heights, Reading};
use crate::Result;

pub(crate) const FORMAT: &str = "hdf5";

/// The 8-byte HDF5 signature.
const SIGNATURE: &[u8; 8] = b"\x89HDF\r\n\x1a\n";

/// Where the superblock starts: offset 0, or 512, 1024, 2048, ... after a user block.
fn superblock(bytes: &[u8]) -> Option<usize> {
    let mut at = 0usize;
    while at + SIGNATURE.len() <= bytes.len() {
        if &bytes[at..at + SIGNATURE.len()] == SIGNATURE {
            return Some(at);
        }
        at = if at == 0 { 512 } else { at.checked_mul(2)? };
    }
    None
}

/// An HDF5 signature at 0 or after a user block (a power of two from 512).
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    superblock(bytes).is_some()
}

/// The end of the file the superblock records (base address + end-of-file address), checked
/// before the library sees the bytes: a truncated file is named as such.
fn check_length(bytes: &[u8]) -> Result<()> {
    let at = superblock(bytes).ok_or_else(|| bad(FORMAT, "no HDF5 signature"))?;
    let sb = &bytes[at..];
    let truncated = || bad(FORMAT, "the file ends inside its superblock (truncated)");
    let version = *sb.get(8).ok_or_else(truncated)?;
    // Size of offsets, and where the base and end-of-file addresses are.
    let (offsets, base_at) = match version {
        0 => (*sb.get(13).ok_or_else(truncated)?, 24),
        1 => (*sb.get(13).ok_or_else(truncated)?, 28),
        2 | 3 => (*sb.get(9).ok_or_else(truncated)?, 12),
        v => return Err(bad(FORMAT, format!("superblock version {v} is not known"))),
    };
    let width = match offsets {
        2 | 4 | 8 => offsets as usize,
        o => return Err(bad(FORMAT, format!("{o}-byte file offsets are not HDF5's"))),
    };
    let eof_at = base_at + 2 * width;
    let address = |from: usize| -> Result<u64> {
        let field = sb.get(from..from + width).ok_or_else(truncated)?;
        Ok(field
            .iter()
            .rev()
            .fold(0u64, |acc, &b| (acc << 8) | u64::from(b)))
    };
    let base = address(base_at)?;
    let eof = address(eof_at)?;
    let end = base.saturating_add(eof);
    if end > bytes.len() as u64 {
        return Err(bad(
            FORMAT,
            format!(
                "the superblock records {end} bytes but the file has {} (truncated)",
                bytes.len()
            ),
        ));
    }
    Ok(())
}

/// Reads a generic HDF5 file, or a Zygo `.datx` (an HDF5 file with a `MetaData` table).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    check_length(bytes)?;
    read_owned(bytes.to_vec())
}

/// [`read`] of a file's bytes given to the decoder without a copy. The maps are read in
/// the dataset's order, the file (its bytes) dropped, and only then transposed in place
/// ([`into_transposed`]): a 4096² `.h5` holds two 128 MiB buffers at a time, not four.
pub(crate) fn read_owned(bytes: Vec<u8>) -> Result<Reading> {
    check_length(&bytes)?;
    let file_len = bytes.len();
    let file = h5::Hdf5File::from_vec(bytes).map_err(lib)?;
    if super::datx::is_datx(&file) {
        return super::datx::read(&file, file_len);
    }
    let mut channels = Vec::new();
    let mut links = 0;
    let root = file.root_group().map_err(lib)?;
    collect(&root, "", 0, &mut links, file_len, &mut channels)?;
    drop(root);
    drop(file);
    if channels.is_empty() {
        return Err(bad(
            FORMAT,
            "no two-dimensional numeric dataset (a map) in the file",
        ));
    }
    for c in &mut channels {
        if let Heights::Areal(h) = &mut c.heights {
            let stored = std::mem::take(h);
            *h = into_transposed(stored);
        }
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

/// The deepest group nesting followed, and the most links visited (a file whose hard links
/// form a cycle must still end).
const MAX_DEPTH: usize = 32;
const MAX_LINKS: usize = 100_000;

/// Largest expansion of a compressed dataset over the file's bytes: deflate's limit
/// (1032:1) with a margin.
const MAX_EXPANSION: u64 = 1100;

/// Gives the decoder's error as one of ours, on one line.
pub(crate) fn lib(e: h5::error::Error) -> crate::Error {
    let words: Vec<String> = e
        .to_string()
        .split_whitespace()
        .map(str::to_string)
        .collect();
    let mut reason = words.join(" ");
    if reason.len() > 300 {
        let cut = (0..=300)
            .rev()
            .find(|&i| reason.is_char_boundary(i))
            .unwrap_or(0);
        reason.truncate(cut);
        reason.push('…');
    }
    bad(FORMAT, format!("not a readable HDF5 file: {reason}"))
}

/// The members of `group` in name order: datasets that are maps become channels, groups
/// are descended into.
fn collect(
    group: &h5::group::Group,
    prefix: &str,
    depth: usize,
    links: &mut usize,
    file_len: usize,
    out: &mut Vec<Channel>,
) -> Result<()> {
    let (mut groups, mut datasets) = group.members().map_err(lib)?;
    *links += groups.len() + datasets.len();
    if *links > MAX_LINKS {
        return Err(bad(FORMAT, format!("more than {MAX_LINKS} links")));
    }
    datasets.sort_by(|a, b| a.name().cmp(b.name()));
    groups.sort_by(|a, b| a.name().cmp(b.name()));
    let path = |name: &str| {
        if prefix.is_empty() {
            name.to_string()
        } else {
            format!("{prefix}/{name}")
        }
    };
    // Datasets and groups in one name order, as the peer lists them.
    let mut entries: Vec<(String, Option<&h5::Dataset>, Option<&h5::group::Group>)> = datasets
        .iter()
        .map(|d| (d.name().to_string(), Some(d), None))
        .chain(groups.iter().map(|g| (g.name().to_string(), None, Some(g))))
        .collect();
    entries.sort_by(|a, b| a.0.cmp(&b.0));
    for (name, dataset, subgroup) in entries {
        if let Some(ds) = dataset {
            if let Some(h) = map_of(ds, file_len)? {
                out.push(Channel {
                    name: path(&name),
                    heights: Heights::Areal(h),
                    size: [None, None],
                    unit: None,
                    is_height: true,
                });
            }
        } else if let Some(g) = subgroup {
            if depth + 1 >= MAX_DEPTH {
                return Err(bad(
                    FORMAT,
                    format!("groups nested deeper than {MAX_DEPTH}"),
                ));
            }
            collect(g, &path(&name), depth + 1, links, file_len, out)?;
        }
    }
    Ok(())
}

/// Whether a datatype is one of the numbers asperity reads (integers or floats).
pub(crate) fn numeric(t: &Datatype) -> bool {
    matches!(
        t,
        Datatype::FixedPoint {
            size: 1 | 2 | 4 | 8,
            ..
        } | Datatype::FloatingPoint { size: 4 | 8, .. }
    )
}

/// A two-dimensional numeric dataset as stored (`[x, y]`: [`read_owned`] transposes it
/// into our `(y, x)` map), `None` for anything else.
fn map_of(ds: &h5::Dataset, file_len: usize) -> Result<Option<Array2<f64>>> {
    let shape = ds.shape();
    if shape.len() != 2 || shape.contains(&0) || !numeric(ds.dtype()) {
        return Ok(None);
    }
    Ok(Some(read_values(ds, file_len)?))
}

/// The transpose of `a`, in place when `a` is in standard layout (else [`transposed`]'s
/// copy): a square map tile by tile; a map whose long side is a multiple of its short one
/// as square blocks (each transposed tile by tile) whose rows are moved as runs of the
/// short side; any other map element by element along the permutation's cycles (see
/// [`transpose_runs`]). A 4096 × 2048 map is never held twice.
pub(crate) fn into_transposed(mut a: Array2<f64>) -> Array2<f64> {
    let (rows, cols) = a.dim();
    // The cycles' index arithmetic multiplies an index by a side: it must not overflow.
    let fits = (rows * cols).checked_mul(rows.max(cols)).is_some();
    if !a.is_standard_layout() || !fits {
        return transposed(&a);
    }
    let v = a.as_slice_mut().expect("standard layout");
    if rows == cols {
        square_in_place(v, rows);
    } else if cols % rows == 0 {
        // Rows of k runs of `rows` values: runs moved block by block, then each square.
        transpose_runs(v, rows, cols / rows, rows);
        for block in v.chunks_exact_mut(rows * rows) {
            square_in_place(block, rows);
        }
    } else if rows % cols == 0 {
        // The inverse: each square of `cols` rows transposed, then its runs moved.
        for block in v.chunks_exact_mut(cols * cols) {
            square_in_place(block, cols);
        }
        transpose_runs(v, rows / cols, cols, cols);
    } else {
        transpose_runs(v, rows, cols, 1);
    }
    a.into_shape_with_order((cols, rows))
        .expect("the same values, rows and columns exchanged")
}

/// Transposes the square `n × n` row-major matrix `v` in place, 32 × 32 tiles at a time
/// (the diagonal tile, then each tile right of it swapped with its mirror below).
fn square_in_place(v: &mut [f64], n: usize) {
    const TILE: usize = 32;
    for r0 in (0..n).step_by(TILE) {
        for c0 in (r0..n).step_by(TILE) {
            for r in r0..(r0 + TILE).min(n) {
                let from = if c0 == r0 { r + 1 } else { c0 };
                for c in from..(c0 + TILE).min(n) {
                    v.swap(r * n + c, c * n + r);
                }
            }
        }
    }
}

/// Transposes in place the `rows × cols` row-major matrix whose entries are runs of `run`
/// consecutive values of `v`, by following the cycles of the permutation: the entry at
/// `p` goes to `p · rows mod (rows · cols − 1)` (the first and last stay), a bit per
/// entry marking those already moved; one run is held aside. `rows · cols · max(rows,
/// cols)` must fit a `usize` (see [`into_transposed`]).
fn transpose_runs(v: &mut [f64], rows: usize, cols: usize, run: usize) {
    let n = rows * cols;
    debug_assert_eq!(v.len(), n * run);
    if rows < 2 || cols < 2 {
        return; // a row or a column: the same values in the same order
    }
    let mut moved = vec![0u64; n.div_ceil(64)];
    let mut held = vec![0.0; run];
    for start in 1..n - 1 {
        if moved[start / 64] >> (start % 64) & 1 == 1 {
            continue;
        }
        held.copy_from_slice(&v[start * run..(start + 1) * run]);
        let mut p = start;
        loop {
            let q = p * rows % (n - 1);
            v[q * run..(q + 1) * run].swap_with_slice(&mut held);
            moved[q / 64] |= 1 << (q % 64);
            if q == start {
                break;
            }
            p = q;
        }
    }
}

/// The transpose of `a` in standard layout, copied tile by tile: a 4096² map in about a
/// fifth of the time of an element-by-element strided copy (which misses the cache on
/// every write).
pub(crate) fn transposed(a: &Array2<f64>) -> Array2<f64> {
    const TILE: usize = 32;
    let (rows, cols) = a.dim();
    let Some(src) = a.as_slice() else {
        return a.t().as_standard_layout().into_owned();
    };
    let mut out = vec![0.0; rows * cols];
    for r0 in (0..rows).step_by(TILE) {
        for c0 in (0..cols).step_by(TILE) {
            for r in r0..(r0 + TILE).min(rows) {
                for c in c0..(c0 + TILE).min(cols) {
                    out[c * rows + r] = src[r * cols + c];
                }
            }
        }
    }
    Array2::from_shape_vec((cols, rows), out).expect("cols × rows values")
}

/// The values of a two-dimensional numeric dataset as stored (`[first, second]` index),
/// as f64, after the bound on what the file's bytes can hold.
pub(crate) fn read_values(ds: &h5::Dataset, file_len: usize) -> Result<Array2<f64>> {
    let shape = ds.shape().to_vec();
    let count = shape.iter().try_fold(1u64, |a, &n| a.checked_mul(n));
    let element = match ds.dtype() {
        Datatype::FixedPoint { size, .. } | Datatype::FloatingPoint { size, .. } => *size,
        _ => 0,
    };
    let raw = count.and_then(|c| c.checked_mul(u64::from(element)));
    if shape.len() != 2 || element == 0 {
        return Err(bad(
            FORMAT,
            format!("dataset {} is no two-dimensional map of numbers", ds.name()),
        ));
    }
    match raw {
        Some(r) if r <= (file_len as u64).saturating_mul(MAX_EXPANSION) => {}
        _ => {
            return Err(bad(
                FORMAT,
                format!(
                    "dataset {} claims {shape:?} values, more than a {file_len}-byte file holds",
                    ds.name()
                ),
            ))
        }
    }
    crate::memory::ensure_fits(
        &format!("reading HDF5 dataset {}", ds.name()),
        count.and_then(|c| c.checked_mul(16)),
    )?;
    let values: Vec<f64> = match ds.dtype().clone() {
        Datatype::FloatingPoint { size: 8, .. } => {
            // Straight into our buffer (the decoder's bytes copied once, no array between).
            let mut v = vec![0.0; count.unwrap_or(0) as usize];
            ds.read_into(&mut v).map_err(lib)?;
            v
        }
        Datatype::FloatingPoint { size: 4, .. } => as_f64::<f32>(ds, f64::from)?,
        Datatype::FixedPoint { size, signed, .. } => match (size, signed) {
            (1, true) => as_f64::<i8>(ds, f64::from)?,
            (1, false) => as_f64::<u8>(ds, f64::from)?,
            (2, true) => as_f64::<i16>(ds, f64::from)?,
            (2, false) => as_f64::<u16>(ds, f64::from)?,
            (4, true) => as_f64::<i32>(ds, f64::from)?,
            (4, false) => as_f64::<u32>(ds, f64::from)?,
            (8, true) => as_f64::<i64>(ds, |v| v as f64)?,
            _ => as_f64::<u64>(ds, |v| v as f64)?,
        },
        _ => unreachable!("checked numeric"),
    };
    let dims = (shape[0] as usize, shape[1] as usize);
    Array2::from_shape_vec(dims, values).map_err(|_| {
        bad(
            FORMAT,
            format!("dataset {} holds fewer values than its shape", ds.name()),
        )
    })
}

/// A dataset's values read as `T` (its stored type) and converted to f64, in storage
/// order: the decoder's array taken as its vector (no copy), then one pass over it
/// (f64 datasets go straight into their buffer instead). Iterating the n-dimensional array
/// instead cost 4× the read.
fn as_f64<T: h5::H5Type + Copy>(ds: &h5::Dataset, to_f64: fn(T) -> f64) -> Result<Vec<f64>> {
    let a = ds.read_array::<T>().map_err(lib)?;
    let a = if a.is_standard_layout() {
        a
    } else {
        a.as_standard_layout().into_owned()
    };
    let (values, _) = a.into_raw_vec_and_offset();
    Ok(values.into_iter().map(to_f64).collect())
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_robust, check_shared, Expect};
    use super::*;
    use std::time::Duration;

    #[test]
    fn multiple_data_sets_reads_like_the_reference() {
        // No size or unit in the file: the reference was given one unit per pixel, ours
        // stays without (the size is asked for when the file is read).
        let expect = Expect {
            size: Some([None, None]),
            ..Expect::default()
        };
        check_shared("topographies-3", "multiple_data_sets.h5", expect);
    }

    #[test]
    fn read_file_reads_the_owned_bytes_like_the_slice() {
        // `read_file` gives its bytes to the decoder (`read_owned`) and transposes after
        // dropping them: in place for the square f64 `dataset1` (256²) and, along the
        // permutation's cycles, for the f32 `dataset2` (640 × 480 stored, 480 × 640 ours). The same numbers as the
        // slice reader, whose maps `multiple_data_sets_reads_like_the_reference` checks.
        use super::super::{read_file, ChannelChoice, ReadOptions};
        let Some(dir) = super::super::testkit::set_dir("topographies-3") else {
            return;
        };
        let path = dir.join("multiple_data_sets.h5");
        let reading = read(&std::fs::read(&path).unwrap()).unwrap();
        assert_eq!(reading.channels.len(), 2);
        for (i, c) in reading.channels.iter().enumerate() {
            let options = ReadOptions {
                channel: Some(ChannelChoice::Index(i)),
                size: Some([Some(1e-3), None]),
                ..ReadOptions::default()
            };
            let t = read_file(&path, &options).unwrap();
            assert_eq!(t.heights, c.heights, "{}", c.name);
        }
        let Heights::Areal(h) = &reading.channels[1].heights else {
            panic!("a map")
        };
        assert_eq!(h.dim(), (480, 640));
    }

    #[test]
    fn a_corrupt_hdf5_file_is_refused_without_a_panic() {
        let Some(dir) = super::super::testkit::set_dir("topographies-3") else {
            return;
        };
        let bytes = std::fs::read(dir.join("multiple_data_sets.h5")).unwrap();
        assert_robust(&bytes, sniff, read, 4096, Some(8), Duration::from_secs(3));
    }

    #[test]
    fn the_tiled_transpose_is_the_transpose() {
        // Sides that are not multiples of the tile, and a column-major input.
        for (rows, cols) in [(1, 1), (3, 70), (45, 33), (64, 64), (97, 5)] {
            let a = Array2::from_shape_fn((rows, cols), |(r, c)| (r * 1000 + c) as f64);
            let t = transposed(&a);
            assert_eq!(t, a.t());
            assert!(t.is_standard_layout());
            assert_eq!(transposed(&a.t().to_owned()), a);
            assert_eq!(transposed(&a.clone().reversed_axes()), a);
            assert_eq!(into_transposed(a.clone()), a.t());
            assert_eq!(into_transposed(a.clone().reversed_axes()), a);
        }
        // In place: square sides around the tile's; non-square odd and even grids whose
        // long side is a multiple of the short one (square blocks) or not (cycles);
        // against the naive transpose (element by element from the index rule).
        for (rows, cols) in [
            (1, 1),
            (2, 2),
            (31, 31),
            (32, 32),
            (33, 33),
            (64, 64),
            (100, 100),
            (1, 7),
            (7, 1),
            (2, 4),
            (4, 2),
            (3, 9),
            (9, 3),
            (33, 99),
            (99, 33),
            (64, 128),
            (96, 32),
            (2, 3),
            (3, 2),
            (5, 8),
            (8, 5),
            (45, 33),
            (70, 3),
            (17, 64),
        ] {
            let a = Array2::from_shape_fn((rows, cols), |(r, c)| (r * 1000 + c) as f64);
            let naive = Array2::from_shape_fn((cols, rows), |(c, r)| a[(r, c)]);
            let t = into_transposed(a.clone());
            assert_eq!(t, naive, "{rows} x {cols}");
            assert!(t.is_standard_layout());
        }
    }

    #[test]
    fn a_superblock_alone_is_refused_in_one_line() {
        // A whole superblock (version 0, 8-byte addresses, end of file at 0) and nothing
        // else: the decoder refuses it, in one line.
        let mut bytes = SIGNATURE.to_vec();
        bytes.extend_from_slice(&[0u8; 120]);
        bytes[13] = 8;
        let err = read(&bytes).unwrap_err().to_string();
        assert!(!err.contains('\n') && err.contains("hdf5"), "{err}");
    }
}
