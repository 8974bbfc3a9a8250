//! JSON sidecars through the one sidecar reader: a size it accepts is positive and finite.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("asperity-fuzz-sidecar-{}", std::process::id()));
    let _ = std::fs::create_dir(&dir);
    let array = dir.join("a.npy");
    std::fs::write(asperity::io::sidecar_path(&array), data).unwrap();
    match asperity::input::sidecar_size(&array) {
        Ok(Some(size)) => assert!(size.is_finite() && size > 0.0),
        Ok(None) => {}
        Err(e) => assert!(!e.to_string().contains('\n')),
    }
});
