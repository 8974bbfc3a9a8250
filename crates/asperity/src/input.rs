//! Reading untrusted input files: regular files only, with a size cap, and one set of
//! rules for the JSON sidecars of arrays.
//!
//! A FIFO, a device or a folder given as an input would block forever, stream without end
//! (`/dev/zero`) or fail obscurely, so every input is opened without blocking and checked
//! to be a regular file on the opened descriptor (no race between the check and the read)
//! before a byte is read. Text inputs (study files, sidecars, checkpoints) are also capped
//! in size, checked from the file's length before reading.
//!
//! A sidecar (`surface.npy.json`) that exists is read by [`read_sidecar`] with the same
//! rules for every command: a regular file of at most [`SIDECAR_MAX_BYTES`], valid JSON
//! (corruption is an error, not "no sidecar"), and a `spec.size`, where present, that is a
//! positive finite number. A missing sidecar is not an error.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// The sidecar path of an array file: `surface.npy` → `surface.npy.json`.
pub fn sidecar_path(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_os_string();
    name.push(".json");
    PathBuf::from(name)
}

/// The largest sidecar read, in bytes (asperity writes a few hundred).
pub const SIDECAR_MAX_BYTES: u64 = 1 << 20;

/// The largest text input read (a study file, `study.json`), in bytes.
pub const TEXT_MAX_BYTES: u64 = 1 << 20;

fn bad_input(path: &Path, reason: impl Into<String>) -> Error {
    Error::BadInput {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// Opens `path` for reading if it is a regular file (links followed), without blocking on
/// a FIFO; returns the file and its length in bytes.
pub fn open_regular(path: &Path) -> Result<(File, u64)> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(|e| Error::io(path, e))?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a folder"
        } else {
            "a FIFO, socket or device"
        };
        return Err(bad_input(
            path,
            format!("is {what}, not a regular file; give a file"),
        ));
    }
    Ok((file, meta.len()))
}

/// Reads a regular file of at most `cap` bytes as UTF-8 text.
pub fn read_text(path: &Path, cap: u64) -> Result<String> {
    let (file, length) = open_regular(path)?;
    if length > cap {
        return Err(bad_input(
            path,
            format!("is {length} bytes long, more than the {cap} accepted for this file"),
        ));
    }
    let mut bytes = Vec::with_capacity(length as usize);
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > cap {
        return Err(bad_input(path, "grew beyond its size limit while read"));
    }
    String::from_utf8(bytes).map_err(|e| {
        bad_input(
            path,
            format!("is not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })
}

/// The JSON sidecar of an array file (see the module docs): `Ok(None)` when there is none.
pub fn read_sidecar(array: &Path) -> Result<Option<serde_json::Value>> {
    let path = sidecar_path(array);
    match std::fs::metadata(&path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        _ => {}
    }
    let text = read_text(&path, SIDECAR_MAX_BYTES)?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        bad_input(
            &path,
            format!(
                "is a corrupt sidecar (not JSON: {}); fix or remove it",
                one_line(&e.to_string())
            ),
        )
    })?;
    if !value.is_object() {
        return Err(bad_input(&path, "is a corrupt sidecar (not a JSON object)"));
    }
    let size = &value["spec"]["size"];
    if !size.is_null() && !size.as_f64().is_some_and(crate::is_positive_finite) {
        return Err(bad_input(
            &path,
            format!(
                "gives spec.size = {}, not a positive finite length",
                clip(&size.to_string())
            ),
        ));
    }
    Ok(Some(value))
}

/// The side length `spec.size` of the sidecar of `array`, where it has one (checked by
/// [`read_sidecar`]).
pub fn sidecar_size(array: &Path) -> Result<Option<f64>> {
    Ok(read_sidecar(array)?.and_then(|v| v["spec"]["size"].as_f64()))
}

/// A message on one line: line breaks become spaces, NUL and other control characters `?`.
pub fn one_line(text: &str) -> String {
    text.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .chars()
        .map(|c| if c.is_control() { '?' } else { c })
        .collect()
}

/// A number for a message: whole numbers below 10^6 as they are, others in short
/// scientific form (`4.295e9`, `1e-300`, `inf`), never hundreds of digits.
pub fn short_number(v: f64) -> String {
    if v.is_finite() && v.fract() == 0.0 && v.abs() < 1e6 {
        return format!("{v}");
    }
    if !v.is_finite() || (1e-3..1e6).contains(&v.abs()) {
        return format!("{}", (v * 1e4).round() / 1e4).replace("inf", "infinity");
    }
    let text = format!("{v:.3e}");
    match text.split_once('e') {
        Some((mantissa, exp)) if mantissa.contains('.') => {
            let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{mantissa}e{exp}")
        }
        _ => text,
    }
}

/// At most 40 characters of untrusted text on one line (for messages that quote it).
pub fn clip(text: &str) -> String {
    let line = one_line(text);
    if line.chars().count() <= 40 {
        line
    } else {
        format!("{}…", line.chars().take(40).collect::<String>())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn special_files_are_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_text(dir.path(), 10).unwrap_err().to_string();
        assert!(err.contains("a folder, not a regular file"), "{err}");
        #[cfg(unix)]
        {
            let fifo = dir.path().join("f");
            let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
            assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
            let err = read_text(&fifo, 10).unwrap_err().to_string();
            assert!(err.contains("FIFO"), "{err}");
            let err = read_text(Path::new("/dev/zero"), 10)
                .unwrap_err()
                .to_string();
            assert!(err.contains("not a regular file"), "{err}");
        }
        let big = dir.path().join("big");
        std::fs::write(&big, vec![b' '; 11]).unwrap();
        assert!(read_text(&big, 10)
            .unwrap_err()
            .to_string()
            .contains("more than"));
    }

    #[test]
    fn sidecars_have_one_set_of_rules() {
        let dir = tempfile::tempdir().unwrap();
        let array = dir.path().join("a.npy");
        assert_eq!(sidecar_size(&array).unwrap(), None, "no sidecar");
        let side = sidecar_path(&array);
        std::fs::write(&side, r#"{"spec": {"size": 2.5}}"#).unwrap();
        assert_eq!(sidecar_size(&array).unwrap(), Some(2.5));
        std::fs::write(&side, r#"{"spec": {}}"#).unwrap();
        assert_eq!(sidecar_size(&array).unwrap(), None, "no size recorded");
        for (text, want) in [
            ("{\"spec\": {\"size\": 2.5", "corrupt"),
            ("[1, 2]", "corrupt"),
            (r#"{"spec": {"size": -1}}"#, "spec.size = -1"),
            (r#"{"spec": {"size": 0}}"#, "spec.size = 0"),
            (r#"{"spec": {"size": "1"}}"#, "positive finite"),
            (r#"{"spec": {"size": 1e999}}"#, "corrupt"),
        ] {
            std::fs::write(&side, text).unwrap();
            let err = sidecar_size(&array).unwrap_err().to_string();
            assert!(err.contains(want), "{text}: {err}");
            assert!(!err.contains('\n'), "{err}");
        }
        std::fs::write(&side, vec![b' '; SIDECAR_MAX_BYTES as usize + 1]).unwrap();
        assert!(sidecar_size(&array)
            .unwrap_err()
            .to_string()
            .contains("more than"));
    }

    #[test]
    fn short_numbers_are_short() {
        assert_eq!(short_number(12.0), "12");
        assert_eq!(short_number(4294967296.0), "4.295e9");
        assert_eq!(short_number(1e-300), "1e-300");
        assert_eq!(short_number(0.25), "0.25");
        assert_eq!(short_number(-1e308), "-1e308");
        assert!(short_number(f64::MIN_POSITIVE / 3.0).len() < 12);
        assert_eq!(short_number(f64::NAN), "NaN");
    }

    /// Inputs tried by the property test below.
    const FUZZ_CASES: u32 = 2000;

    proptest! {
        #![proptest_config(ProptestConfig { cases: FUZZ_CASES, failure_persistence: None, ..ProptestConfig::default() })]

        /// Random and mutated sidecars: a size that is accepted is positive and finite;
        /// every refusal is one line.
        #[test]
        fn sidecar_bytes_never_panic(
            size in prop::sample::select(vec!["1", "0", "-2", "1e308", "1e-320", "null", "\"x\"", "[1]", "{}", "NaN"]),
            cut in 0usize..60,
            noise in proptest::collection::vec(any::<u8>(), 0..8),
        ) {
            let dir = tempfile::tempdir().unwrap();
            let array = dir.path().join("a.npy");
            let mut bytes = format!("{{\"spec\": {{\"size\": {size}, \"psd\": {{}}}}}}").into_bytes();
            bytes.truncate(bytes.len().saturating_sub(cut % 30));
            if cut >= 30 { bytes.extend(&noise); }
            std::fs::write(sidecar_path(&array), &bytes).unwrap();
            match sidecar_size(&array) {
                Ok(Some(s)) => prop_assert!(s.is_finite() && s > 0.0),
                Ok(None) => {}
                Err(e) => prop_assert!(!e.to_string().contains('\n')),
            }
        }
    }
}
