//! Sorting doubles in descending order by an LSD radix sort on order-preserving integer
//! keys — the `O(N)` core of [`super::LinearCurve`]. A comparison sort of 2^15 doubles
//! (≈ 0.65 ms) was its largest part, more than the FFT that makes the line (≈ 0.5 ms);
//! this sort takes ≈ 0.35–0.5 ms (see `docs/mdr.md`, "Speed").
//!
//! Each `f64` maps to a `u64` key whose unsigned order is [`f64::total_cmp`]'s order (flip
//! all bits of negatives, set the sign bit of the rest); descending order is ascending order
//! of the complemented key. Keys are sorted by six stable counting passes of 11 bits
//! (histograms for all passes in one read; a pass whose digit is the same for every key is
//! skipped). The result is bit-identical to `sort_unstable_by(|a, b| b.total_cmp(a))`
//! (equal keys are equal bits, so stability is invisible). Short slices use that sort.

const DIGIT_BITS: usize = 11;
const BUCKETS: usize = 1 << DIGIT_BITS;
const PASSES: usize = 64_usize.div_ceil(DIGIT_BITS);
const MASK: u64 = (BUCKETS - 1) as u64;
/// Below this length the comparison sort is faster than six passes.
const RADIX_THRESHOLD: usize = 512;

/// Reusable buffers of the radix sort (two key arrays and the digit histograms).
#[derive(Debug, Clone, Default)]
pub struct RadixScratch {
    keys: Vec<u64>,
    spare: Vec<u64>,
    counts: Vec<u32>,
}

/// Order-preserving key: `a.total_cmp(b) == key(a).cmp(key(b))`.
#[inline]
fn order_key(x: f64) -> u64 {
    let bits = x.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | (1 << 63)
    }
}

#[inline]
fn from_order_key(key: u64) -> f64 {
    f64::from_bits(if key >> 63 == 1 {
        key & !(1 << 63)
    } else {
        !key
    })
}

/// Sorts `values` in descending [`f64::total_cmp`] order, reusing `scratch`.
pub fn sort_descending(values: &mut [f64], scratch: &mut RadixScratch) {
    let n = values.len();
    if n < RADIX_THRESHOLD || n > u32::MAX as usize {
        values.sort_unstable_by(|a, b| b.total_cmp(a));
        return;
    }
    let RadixScratch {
        keys,
        spare,
        counts,
    } = scratch;
    keys.clear();
    keys.extend(values.iter().map(|&x| !order_key(x)));
    spare.clear();
    spare.resize(n, 0);
    counts.clear();
    counts.resize(PASSES * BUCKETS, 0);
    for &key in keys.iter() {
        for pass in 0..PASSES {
            counts[pass * BUCKETS + ((key >> (pass * DIGIT_BITS)) & MASK) as usize] += 1;
        }
    }
    let (mut source, mut target) = (keys, spare);
    for pass in 0..PASSES {
        let histogram = &mut counts[pass * BUCKETS..(pass + 1) * BUCKETS];
        if histogram.iter().any(|&c| c as usize == n) {
            continue; // every key has the same digit: the pass would not move anything
        }
        let mut offset = 0u32;
        for count in histogram.iter_mut() {
            let here = *count;
            *count = offset;
            offset += here;
        }
        let shift = pass * DIGIT_BITS;
        for &key in source.iter() {
            let bucket = ((key >> shift) & MASK) as usize;
            target[histogram[bucket] as usize] = key;
            histogram[bucket] += 1;
        }
        std::mem::swap(&mut source, &mut target);
    }
    for (value, &key) in values.iter_mut().zip(source.iter()) {
        *value = from_order_key(!key);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::ChaCha8Rng;
    use rand::{RngExt, SeedableRng};

    fn oracle(values: &[f64]) -> Vec<f64> {
        let mut sorted = values.to_vec();
        sorted.sort_unstable_by(|a, b| b.total_cmp(a));
        sorted
    }

    fn same_bits(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
    }

    #[test]
    fn keys_preserve_total_order() {
        let values = [
            f64::NEG_INFINITY,
            -1e300,
            -1.0,
            -f64::MIN_POSITIVE,
            -0.0,
            0.0,
            5e-324,
            1.0,
            1e300,
            f64::INFINITY,
        ];
        for w in values.windows(2) {
            assert!(order_key(w[0]) < order_key(w[1]), "{} vs {}", w[0], w[1]);
        }
        for v in values {
            assert_eq!(from_order_key(order_key(v)).to_bits(), v.to_bits());
        }
    }

    #[test]
    fn matches_the_comparison_sort_with_dirty_scratch() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut scratch = RadixScratch::default();
        for n in [0, 1, 7, 511, 512, 513, 4096, 32768, 40000] {
            // Mixed signs and magnitudes, ties, signed zeros.
            let values: Vec<f64> = (0..n)
                .map(|i| match i % 7 {
                    0 => 0.0,
                    1 => -0.0,
                    2 => (rng.random::<f64>() - 0.5) * 1e-12,
                    3 => ((rng.random::<f64>() * 20.0).round() - 10.0) * 0.25,
                    _ => (rng.random::<f64>() - 0.5) * 10f64.powi(rng.random_range(-30..30)),
                })
                .collect();
            let mut sorted = values.clone();
            sort_descending(&mut sorted, &mut scratch);
            assert!(same_bits(&sorted, &oracle(&values)), "n = {n}");
        }
        // Values sharing most digits (the skipped passes) and a constant slice.
        let close: Vec<f64> = (0..5000)
            .map(|i| 1.0 + (i % 97) as f64 * f64::EPSILON)
            .collect();
        let mut sorted = close.clone();
        sort_descending(&mut sorted, &mut scratch);
        assert!(same_bits(&sorted, &oracle(&close)));
        let mut constant = vec![3.5; 1000];
        sort_descending(&mut constant, &mut scratch);
        assert!(constant.iter().all(|&v| v == 3.5));
    }
}
