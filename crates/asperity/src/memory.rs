//! Memory guard: refuse a grid that would not fit before allocating it.
//!
//! A 2D problem is sized by the user, and a typo (`--n 100000`) would otherwise end in the
//! operating system killing the process. [`ensure_fits`] compares an estimate with the
//! memory the kernel reports as available (`MemAvailable` in `/proc/meminfo`); where that
//! is unknown (not Linux) it only rejects sizes that overflow.

use crate::{Error, Result};

/// Bytes of memory available now, if the platform reports it.
pub fn available_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    text.lines()
        .find(|l| l.starts_with("MemAvailable:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|kib| kib.parse::<u64>().ok())
        .map(|kib| kib * 1024)
}

/// Fails with [`Error::OutOfMemory`] when `bytes` (an estimate of the peak need of
/// `what`) exceeds 90 % of the available memory. `bytes = None` means the estimate
/// itself overflowed.
pub fn ensure_fits(what: &str, bytes: Option<u64>) -> Result<()> {
    let available = available_bytes().unwrap_or(u64::MAX);
    let mib = |b: u64| b / (1024 * 1024);
    match bytes {
        Some(b) if (b as f64) <= 0.9 * available as f64 => Ok(()),
        _ => Err(Error::OutOfMemory {
            what: what.to_string(),
            needed_mib: bytes.map(mib).unwrap_or(u64::MAX),
            available_mib: mib(available),
        }),
    }
}

/// `count × size` in bytes, `None` on overflow.
pub fn array_bytes(dims: &[usize], bytes_per_element: usize) -> Option<u64> {
    dims.iter().try_fold(bytes_per_element as u64, |acc, &d| {
        acc.checked_mul(d as u64)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_grid_is_refused() {
        let bytes = array_bytes(&[1 << 20, 1 << 20], 8);
        let err = ensure_fits("a 2^20 x 2^20 grid", bytes).unwrap_err();
        assert!(err.to_string().contains("MiB"), "{err}");
        assert!(ensure_fits("overflow", None).is_err());
    }

    #[test]
    fn small_grid_fits() {
        ensure_fits("a 64 x 64 grid", array_bytes(&[64, 64], 8)).unwrap();
    }
}
