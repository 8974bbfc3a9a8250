//! Theory curves for the exponent α of `k ∝ F^α` (paper eq. 3), as drawn in Fig. 1 and 5.
//!
//! * `0 < H < 2`: α = 1/(1+H), the Pohrt–Popov relation (6).
//! * `H > 2`: α = 1/3, Hertzian behaviour of the single smooth asperity.
//! * `H ≤ 0`: α = (1 + log₂N)/(3 + log₂N) (24), N the number of modes (lines) or grid points.
//!   The paper derives (24) for H = 0 (equal amplitudes) and states that it "is valid not
//!   only for H = 0, but also for smaller values"; at H = 0 itself (6) would give 1, which
//!   neither the derivation nor MDR (α ≈ 0.87 at H = 0) supports, so H = 0 takes (24).

/// α = 1/(1+H), eq. (6), valid for 0 < H < 2.
pub fn alpha_pohrt_popov(hurst: f64) -> f64 {
    1.0 / (1.0 + hurst)
}

/// α = 1/3 for H > 2 (Hertz).
pub const ALPHA_HERTZ: f64 = 1.0 / 3.0;

/// α = (1 + log₂N)/(3 + log₂N), eq. (24), for H ≤ 0; `n` counts modes or grid points.
pub fn alpha_white_noise(n: f64) -> f64 {
    let m = n.log2();
    (1.0 + m) / (3.0 + m)
}

/// The theory value for any H in [-1, 3] on a grid of `n` points per side: (24) for
/// H ≤ 0, (6) for 0 < H ≤ 2, 1/3 above 2.
pub fn alpha_theory(hurst: f64, n: usize) -> f64 {
    if hurst <= 0.0 {
        alpha_white_noise(n as f64)
    } else if hurst <= 2.0 {
        alpha_pohrt_popov(hurst)
    } else {
        ALPHA_HERTZ
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq_24_values() {
        // N = 2^15: (1 + 15)/(3 + 15) = 8/9.
        assert!((alpha_white_noise(32768.0) - 8.0 / 9.0).abs() < 1e-15);
        assert!((alpha_white_noise(512.0) - 10.0 / 12.0).abs() < 1e-15);
        assert!(alpha_white_noise(1e12) > alpha_white_noise(1e3));
    }

    #[test]
    fn branches() {
        assert_eq!(alpha_theory(0.5, 1024), 1.0 / 1.5);
        assert_eq!(alpha_theory(2.5, 1024), 1.0 / 3.0);
        assert_eq!(alpha_theory(-0.5, 1024), alpha_white_noise(1024.0));
        // H = 0 belongs to (24) (the paper derives it there), not to (6)'s limit 1/(1+0) = 1.
        assert_eq!(alpha_theory(0.0, 1024), alpha_white_noise(1024.0));
        assert_eq!(alpha_theory(-0.0, 32768), 8.0 / 9.0);
        assert!(alpha_theory(0.0, 32768) < 0.9);
        // Just above 0, (6) applies.
        assert!((alpha_theory(1e-9, 1024) - 1.0).abs() < 1e-8);
        // Continuous at H = 2: 1/(1+2) = 1/3.
        assert!((alpha_theory(2.0, 8) - alpha_theory(2.0001, 8)).abs() < 1e-12);
    }
}
