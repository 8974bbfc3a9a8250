//! Importing a measured topography (`asperity import`, Python's `import_topography`): the
//! cleaned heights written as a float64 `.npy` with the import sidecar `OUT.npy.json`
//! (where they came from, units, sizes per axis, every cleaning step), which every command
//! reads the sizes back from, or as an X3P file (maps only). Written all or nothing.
//!
//! In order: [`Import::stage`] checks the output's name and that nothing is overwritten
//! (nor the input) before the file is read; the front end opens the file
//! ([`crate::measured::open`]); [`Import::write`] writes and commits.

use std::path::{Path, PathBuf};

use asperity::io::{sidecar_path, StagedOutputs};
use asperity::topography::{x3p, Heights, Topography};
use serde_json::json;

use crate::measured::record;
use crate::refusal::{Param, Refusal, RequestError};

/// The output file.
pub const OUT: Param = Param::new("--out", "out");

/// What an import writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// `.npy` heights with the import sidecar.
    Npy,
    /// An X3P file (maps only).
    X3p,
}

/// An import whose outputs are staged: nothing exists yet, nothing is overwritten unless
/// forced.
pub struct Import {
    target: Target,
    out: PathBuf,
    staged: StagedOutputs,
}

impl std::fmt::Debug for Import {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Import")
            .field("target", &self.target)
            .field("out", &self.out)
            .finish_non_exhaustive()
    }
}

impl Import {
    /// Stages the outputs of importing `file` into `out` (by its extension: `.npy` with its
    /// sidecar, or `.x3p`): refused if the name ends otherwise, if an output exists (unless
    /// `force`) or if an output is the input or its sidecar.
    pub fn stage(file: &Path, out: &Path, force: bool) -> Result<Self, RequestError> {
        let ext = out
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        let target = match ext.as_deref() {
            Some("npy") => Target::Npy,
            Some("x3p") => Target::X3p,
            _ => {
                return Err(Refusal::of(OUT)
                    .text(format!(
                        " {}: the file name must end in .npy or .x3p",
                        out.display()
                    ))
                    .into())
            }
        };
        let mut outputs = vec![out.to_path_buf()];
        if target == Target::Npy {
            outputs.push(sidecar_path(out));
        }
        let library = |e| RequestError::Invalid(Box::new(e));
        let staged = StagedOutputs::new(&outputs, force).map_err(library)?;
        staged.ensure_not_input(file).map_err(library)?;
        Ok(Import {
            target,
            out: out.to_path_buf(),
            staged,
        })
    }

    /// Writes `topography`, read from `file`, and commits every output together. A line
    /// profile cannot be written as X3P (maps only).
    pub fn write(mut self, file: &Path, topography: &Topography) -> Result<(), RequestError> {
        let library = |e| RequestError::Invalid(Box::new(e));
        let out = &self.out;
        match (&topography.heights, self.target) {
            (Heights::Areal(h), Target::X3p) => {
                let sizes = [topography.sizes[0], topography.sizes[1]];
                let bytes = x3p::to_bytes(h.view(), sizes).map_err(library)?;
                self.staged.write_bytes(out, &bytes)
            }
            (Heights::Profile(_), Target::X3p) => {
                return Err(Refusal::saying(format!(
                    "{}: a line profile cannot be written as X3P here (maps only); use ",
                    file.display()
                ))
                .param(OUT)
                .text(" LINE.npy")
                .into())
            }
            (Heights::Areal(h), Target::Npy) => self.staged.write_npy_2d(out, h),
            (Heights::Profile(p), Target::Npy) => self.staged.write_npy_1d(out, p),
        }
        .map_err(library)?;
        if self.target == Target::Npy {
            let sidecar = sidecar_path(out);
            self.staged
                .write_json(&sidecar, &sidecar_record(topography))
                .map_err(library)?;
        }
        self.staged.commit().map_err(library)
    }
}

/// The import sidecar of `topography`: its provenance record ([`record`]), its `kind`
/// (`measured surface` or `measured line`), the `importer` and the `provenance` itself
/// (from which Python's `load` gives back the same `Topography`).
pub fn sidecar_record(topography: &Topography) -> serde_json::Value {
    let mut value = record(topography);
    value["kind"] = json!(match topography.heights {
        Heights::Areal(_) => "measured surface",
        Heights::Profile(_) => "measured line",
    });
    value["importer"] = json!(format!("asperity {}", env!("CARGO_PKG_VERSION")));
    value["provenance"] = json!(topography.provenance);
    value
}

/// What an import found and wrote, in one line for the terminal: the output, the format
/// (the instrument's file format) and file, the channel chosen among all the file's
/// channels, the grid and sizes, the heights' unit in the file, the undefined points, and
/// the cleaning steps.
pub fn summary(out: &Path, file: &Path, topography: &Topography) -> String {
    let p = &topography.provenance;
    let shape: Vec<String> = topography
        .heights
        .shape()
        .iter()
        .map(|d| d.to_string())
        .collect();
    let sizes: Vec<String> = topography.sizes.iter().map(|s| format!("{s:e}")).collect();
    let channel = if p.channels.len() > 1 {
        let all: Vec<String> = p.channels.iter().map(|c| format!("{c:?}")).collect();
        format!(
            "channel {:?} ({} of {}: {})",
            p.channel,
            p.channel_index,
            p.channels.len(),
            all.join(", ")
        )
    } else {
        format!("channel {:?}", p.channel)
    };
    let unit = match (&p.file_unit, &p.unit) {
        (Some(f), Some(_)) => format!("heights in {f} in the file"),
        (Some(f), None) => format!("heights in {f} (no length: kept as they are)"),
        (None, Some(u)) => format!("heights in {u}"),
        (None, None) => "no height unit in the file".to_string(),
    };
    let undefined = match topography.heights.undefined_count() {
        0 if p.cleaning.iter().any(|c| c.starts_with("filled ")) => String::new(),
        0 => ", no undefined points".to_string(),
        n => format!(", {n} undefined points kept"),
    };
    let cleaning = if p.cleaning.is_empty() {
        String::new()
    } else {
        format!("; {}", p.cleaning.join("; "))
    };
    format!(
        "wrote {} ({} {}, {channel}, {} grid, sizes {} m, {unit}{undefined}{cleaning})",
        out.display(),
        p.format,
        file.display(),
        shape.join("x"),
        sizes.join(" x "),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Names;

    #[test]
    fn outputs_are_named_and_checked_before_the_file_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("scan.txt");
        let words = |e: RequestError| e.words(Names::Keywords);
        let err = Import::stage(&input, &dir.path().join("s.csv"), false).unwrap_err();
        assert!(words(err).starts_with("out "), "names the parameter");
        let err = Import::stage(&input, &dir.path().join("s.csv"), false).unwrap_err();
        assert!(err
            .words(Names::Flags)
            .ends_with("s.csv: the file name must end in .npy or .x3p"));
        // An output that exists is refused unless forced; the input is never an output.
        std::fs::write(dir.path().join("s.npy.json"), "{}").unwrap();
        assert!(Import::stage(&input, &dir.path().join("s.npy"), false).is_err());
        assert!(Import::stage(&input, &dir.path().join("s.npy"), true).is_ok());
        assert!(Import::stage(&input, &input.with_extension("x3p"), false).is_ok());
        let npy = dir.path().join("in.npy");
        std::fs::write(&npy, "").unwrap();
        let err = Import::stage(&npy, &npy, true).unwrap_err();
        assert!(
            err.words(Names::Flags).contains("is the input file"),
            "{err}"
        );
    }

    #[test]
    fn the_summary_says_what_was_found() {
        use asperity::topography::Provenance;
        let mut t = Topography {
            heights: Heights::Areal(ndarray::array![[1e-9, f64::NAN, 0.0]]),
            sizes: vec![3e-6, 1e-6],
            provenance: Provenance {
                source: "scan.nid".into(),
                format: "nid".into(),
                channel: "Z-Axis".into(),
                channel_index: 1,
                channels: vec!["Amplitude".into(), "Z-Axis".into()],
                file_unit: Some("nm".into()),
                unit: Some("m".into()),
                size_source: "file".into(),
                cleaning: vec!["no levelling".into()],
            },
        };
        let line = summary(Path::new("s.npy"), Path::new("scan.nid"), &t);
        assert_eq!(
            line,
            "wrote s.npy (nid scan.nid, channel \"Z-Axis\" (1 of 2: \"Amplitude\", \"Z-Axis\"), \
             1x3 grid, sizes 3e-6 x 1e-6 m, heights in nm in the file, 1 undefined points kept; \
             no levelling)"
        );
        // Filled: the cleaning step counts them; one channel, no unit.
        t.heights = Heights::Areal(ndarray::array![[1.0, 2.0, 0.0]]);
        t.provenance.channels.truncate(1);
        (t.provenance.file_unit, t.provenance.unit) = (None, None);
        t.provenance.cleaning =
            vec!["filled 1 undefined points by harmonic (Laplace) inpainting".into()];
        let line = summary(Path::new("s.npy"), Path::new("scan.nid"), &t);
        assert!(
            line.contains("channel \"Z-Axis\", 1x3 grid")
                && line.contains("no height unit in the file; filled 1 undefined"),
            "{line}"
        );
    }
}
