//! `--hurst` / study-file ranges: never a panic, never more than the bounded number of
//! values, never a non-finite value.
#![no_main]
use libfuzzer_sys::fuzz_target;

// The front ends' one parser (crates/asperity-app), the one the CLI and Python use.
use asperity_app::range;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(values) = range::parse_range(text) {
            assert!(values.iter().all(|v| v.is_finite()));
        }
    }
});
