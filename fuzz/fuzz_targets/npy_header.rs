//! The `.npy` header parser on arbitrary bytes: never a panic or a hang; a parsed header
//! has at most 64 dimensions and its data offset lies within the bytes given.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    match asperity::npy::parse_header(data) {
        Ok(header) => {
            assert!(header.shape.len() <= 64);
            assert!(header.data_offset <= data.len());
        }
        Err(message) => assert!(!message.contains('\n') && !message.contains('\0')),
    }
});
