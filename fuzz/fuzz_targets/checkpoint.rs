//! Sealed checkpoints (study/store/identity.rs) on arbitrary bytes: never a panic; anything
//! accepted was sealed with the identity asked for and matches its checksum.
#![no_main]
use asperity::study::identity::{seal, unseal, TaskIdentity};
use asperity::study::{FitWindow, Method, StudySpec, Task};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let spec = StudySpec {
        method: Method::Mdr,
        sizes: vec![64],
        hursts: vec![0.5],
        samples: 2,
        rolloff: None,
        seed: 1,
        window: FitWindow::default(),
        levels: 10,
    };
    let identity = TaskIdentity::of(&spec, Task { n: 64, hurst: 0.5 });
    if let Ok(content) = unseal::<serde_json::Value>(data, &identity) {
        // Accepted: sealing it again gives a file that is accepted too.
        let again = seal(&identity, &content).unwrap();
        assert!(unseal::<serde_json::Value>(&again, &identity).is_ok());
    }
});
