//! Tables: CSV files with a header row, written atomically; and JSON sidecars.

use std::path::Path;

use anyhow::Result;
use asperity::io::StagedOutputs;

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

    /// The table as CSV text; refused if a field is a non-finite number (no command writes
    /// one: it means an input beyond what float64 can compute with).
    pub fn to_csv(&self) -> Result<Vec<u8>> {
        self.ensure_finite()?;
        let mut writer = csv::Writer::from_writer(Vec::new());
        writer.write_record(&self.header)?;
        for row in &self.rows {
            writer.write_record(row)?;
        }
        writer.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
    }

    /// Fails, naming the column and row, if a field is `NaN` or an infinity.
    fn ensure_finite(&self) -> Result<()> {
        for (r, row) in self.rows.iter().enumerate() {
            for (c, field) in row.iter().enumerate() {
                let lower = field.trim().to_ascii_lowercase();
                if lower == "nan" || lower.trim_start_matches(['-', '+']).starts_with("inf") {
                    anyhow::bail!(
                        "the result is not a finite number ({field} in column `{}`, row {}): \
                         an input is beyond what float64 can compute with; nothing was written",
                        self.header.get(c).map_or("?", String::as_str),
                        r + 1
                    );
                }
            }
        }
        Ok(())
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

/// Shortest text that parses back to the same f64.
pub fn format_number(v: f64) -> String {
    format!("{v:?}")
}

/// Writes `bytes` to standard output; a closed pipe (`| head`) is not an error of ours.
pub fn print_stdout(bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    match std::io::stdout().write_all(bytes) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => Ok(other?),
    }
}
