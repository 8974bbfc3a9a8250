//! Whole `.npy` files (header and body) through the reader every command uses: never a
//! panic, an abort or an allocation beyond the file's own size.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("asperity-fuzz-{}.npy", std::process::id()));
    std::fs::write(&path, data).unwrap();
    match asperity::io::read_npy(&path) {
        Ok(array) => assert!(array.iter().all(|v| v.is_finite())),
        Err(e) => assert!(!e.to_string().contains('\n')),
    }
});
