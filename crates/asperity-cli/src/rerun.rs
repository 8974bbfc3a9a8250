//! The one rule for running a command again into a folder that already holds its outputs.
//!
//! * **Single commands** (`surface`, `line`, `stats`, `bem`, `mdr`): an existing output is
//!   refused without `--force`; nothing is resumable, so nothing is rewritten silently.
//! * **Studies and `reproduce`**: the same command run again on the same folder resumes
//!   and rewrites its outputs, but only files it wrote itself and nobody changed since. A
//!   record of what it wrote ([`RECORD`] in a study folder, `reproduce.json` in a figure
//!   folder) holds each output's FNV-1a-64 checksum; an output that is missing from the
//!   record, or whose content no longer matches it (edited by a user), is refused without
//!   `--force`, naming the file. A study's record is committed together with its outputs
//!   (all or none), so an interrupted run never leaves an output without its record.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use asperity::io::{fnv1a64, StagedOutputs};
use serde::{Deserialize, Serialize};

/// The record of a study folder's outputs.
pub const RECORD: &str = ".asperity-outputs.json";

/// What a command wrote into a folder: file name → `fnv1a64:<hex>`.
#[derive(Debug, Default, Clone, PartialEq, Serialize, Deserialize)]
pub struct Written {
    /// Checksums by file name.
    pub outputs: BTreeMap<String, String>,
}

/// `fnv1a64:<16 hex digits>`.
pub fn checksum(hash: u64) -> String {
    format!("fnv1a64:{hash:016x}")
}

impl Written {
    /// Reads a record; a missing, unreadable or corrupt one records nothing.
    pub fn read(path: &Path) -> Written {
        asperity::input::read_text(path, asperity::input::TEXT_MAX_BYTES)
            .ok()
            .and_then(|text| serde_json::from_str(&text).ok())
            .unwrap_or_default()
    }

    /// Whether `file` (in the record's folder) is unchanged since it was recorded.
    pub fn unchanged(&self, file: &Path) -> bool {
        let Some(name) = file.file_name().map(|n| n.to_string_lossy().into_owned()) else {
            return false;
        };
        let Some(recorded) = self.outputs.get(&name) else {
            return false;
        };
        let Ok((_, length)) = asperity::input::open_regular(file) else {
            return false;
        };
        asperity::memory::ensure_fits("checking an output's checksum", Some(length)).is_ok()
            && std::fs::read(file).is_ok_and(|bytes| &checksum(fnv1a64(&bytes)) == recorded)
    }
}

/// Whether a study may write `outputs` into `dir` over existing files: `Ok(false)` when
/// none exists (nothing to overwrite), `Ok(true)` when every existing one is unchanged
/// since this study wrote it (or only the record is left), or with `force`; else a
/// one-line refusal naming the file.
pub fn may_rewrite(dir: &Path, outputs: &[PathBuf], force: bool) -> Result<bool> {
    if force {
        return Ok(true);
    }
    let existing: Vec<&PathBuf> = outputs.iter().filter(|p| p.exists()).collect();
    if existing.is_empty() {
        // Only the record may be left (its outputs removed by hand): it is rewritten.
        return Ok(dir.join(RECORD).exists());
    }
    let record = Written::read(&dir.join(RECORD));
    if let Some(changed) = existing.iter().find(|p| !record.unchanged(p)) {
        bail!(
            "{}: output already exists and was not written by this study or was edited since; \
             use --force to overwrite it",
            changed.display()
        );
    }
    Ok(true)
}

/// Stages the record of every output staged so far in `staged` as `record` (declared
/// among its outputs), to be committed with them.
pub fn stage_record(staged: &mut StagedOutputs, record: &Path) -> Result<()> {
    let mut written = Written::default();
    for (path, hash) in staged.fingerprints()? {
        if path.as_path() != record {
            if let Some(name) = path.file_name() {
                written
                    .outputs
                    .insert(name.to_string_lossy().into_owned(), checksum(hash));
            }
        }
    }
    staged.write_json(record, &written)?;
    Ok(())
}
