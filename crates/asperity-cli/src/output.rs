//! Tables: CSV files with a header row, written atomically; and JSON sidecars.

use std::path::Path;

use anyhow::Result;
use asperity::io::StagedOutputs;
pub use asperity_app::table::format_number;

/// A CSV table under construction: header plus rows of already formatted fields.
#[derive(Debug, Clone, Default)]
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these column names.
    pub fn new<S: AsRef<str>>(header: &[S]) -> Self {
        Table {
            header: header.iter().map(|s| s.as_ref().to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row of numbers, printed with full precision (`{:e}` round-trips f64).
    pub fn push_numbers(&mut self, values: &[f64]) {
        self.rows
            .push(values.iter().map(|v| format_number(*v)).collect());
    }

    /// Appends a row of fields.
    pub fn push<S: ToString>(&mut self, fields: &[S]) {
        self.rows
            .push(fields.iter().map(|f| f.to_string()).collect());
    }

    /// The table as CSV text ([`asperity_app::table::csv_bytes`]); refused if a field is a
    /// non-finite number (no command writes one: it means an input beyond what float64 can
    /// compute with).
    pub fn to_csv(&self) -> Result<Vec<u8>> {
        Ok(asperity_app::table::csv_bytes(&self.header, &self.rows)?)
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Writes the table atomically.
    pub fn write(&self, path: &Path, force: bool) -> Result<()> {
        asperity::io::write_bytes(path, force, &self.to_csv()?)?;
        Ok(())
    }

    /// Stages the table as the output `path` of `staged` (renamed into place on commit).
    pub fn stage(&self, staged: &mut StagedOutputs, path: &Path) -> Result<()> {
        staged.write_bytes(path, &self.to_csv()?)?;
        Ok(())
    }
}

/// The stderr line of an adhesive run's pull-offs (`bem`, `contact` and `mdr` with
/// `--work-of-adhesion`): force and indentation `(F, d)` under force control, then under
/// displacement control, each number followed by its unit (`""` in model units).
pub fn pull_off_line(
    force_controlled: (f64, f64),
    displacement_controlled: (f64, f64),
    (force_unit, length_unit): (&str, &str),
) -> String {
    let point = |(f, d): (f64, f64)| {
        format!(
            "F = {}{force_unit} at d = {}{length_unit}",
            format_number(f),
            format_number(d)
        )
    };
    format!(
        "pull-off: force control {}; displacement control {}",
        point(force_controlled),
        point(displacement_controlled)
    )
}

/// Writes `bytes` to standard output; a closed pipe (`| head`) is not an error of ours.
pub fn print_stdout(bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    match std::io::stdout().write_all(bytes) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => Ok(other?),
    }
}
