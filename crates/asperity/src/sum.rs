//! Sums in a fixed order that do not wait on one addition at a time.

/// `Σ term(k)` over `k < len` with four accumulators (`k mod 4`), added as
/// `(a₀ + a₁) + (a₂ + a₃)` and then the remainder in order: a fixed order (the same bits for
/// any thread count) whose four chains of additions do not wait on each other, where one
/// chain would wait an addition's latency per term.
#[inline]
pub(crate) fn sum4(len: usize, term: impl Fn(usize) -> f64) -> f64 {
    let whole = len / 4 * 4;
    let mut acc = [0.0; 4];
    for k in (0..whole).step_by(4) {
        acc[0] += term(k);
        acc[1] += term(k + 1);
        acc[2] += term(k + 2);
        acc[3] += term(k + 3);
    }
    let tail = (whole..len).map(term).fold(0.0, |a, b| a + b);
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adds_in_four_chains_then_the_tail() {
        // Integers (exact in any order) for the value; the order shows on terms whose sum
        // rounds: 1e16 + 1 + 1 + … differs between one chain and four.
        for len in 0..11 {
            let naive: f64 = (0..len).map(|k| (k * k) as f64).sum();
            assert_eq!(sum4(len, |k| (k * k) as f64), naive, "len {len}");
        }
        let terms = [1e16, 1.0, 1.0, 1.0, -1e16, 1.0, 1.0, 1.0, 1.0];
        let four = ((1e16 + -1e16) + (1.0 + 1.0)) + (1.0f64 + 1.0 + 1.0 + 1.0) + 1.0;
        assert_eq!(sum4(terms.len(), |k| terms[k]), four);
    }
}
