//! `--hurst` / study-file ranges: never a panic, never more than the bounded number of
//! values, never a non-finite value.
#![no_main]
use libfuzzer_sys::fuzz_target;

// The CLI's parser (a module of the binary crate), included as the Python package does.
#[path = "../../crates/asperity-cli/src/range.rs"]
mod range;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(values) = range::parse_range(text) {
            assert!(values.iter().all(|v| v.is_finite()));
        }
    }
});
