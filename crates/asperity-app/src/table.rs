//! CSV text, defined once for both front ends: a header row, then rows of fields already
//! formatted, numbers in the shortest form that parses back to the same `f64`
//! ([`format_number`]). The CLI's tables and the comparison with the paper
//! ([`crate::study::report`]) are written through [`csv_bytes`].

/// Shortest text that parses back to the same f64.
///
/// ```
/// assert_eq!(asperity_app::table::format_number(0.1), "0.1");
/// assert_eq!(asperity_app::table::format_number(1e-300), "1e-300");
/// ```
pub fn format_number(v: f64) -> String {
    format!("{v:?}")
}

/// Why a table's CSV text could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    /// A field is `NaN` or an infinity (no command writes one: it means an input beyond
    /// what float64 can compute with).
    #[error(
        "the result is not a finite number ({field} in column `{column}`, row {row}): an \
         input is beyond what float64 can compute with; nothing was written"
    )]
    NotFinite {
        /// The field as formatted.
        field: String,
        /// Its column's name (`?` past the header).
        column: String,
        /// Its data row, from 1.
        row: usize,
    },
    /// The CSV writer's own error.
    #[error(transparent)]
    Csv(#[from] csv::Error),
    /// The writer could not hand its text back.
    #[error("{0}")]
    Flush(String),
}

/// The CSV text of `header` and `rows`; refused, naming the column and the row, if a
/// field is a non-finite number.
///
/// ```
/// use asperity_app::table::csv_bytes;
///
/// let rows = vec![vec!["1".to_string(), "0.5".to_string()]];
/// assert_eq!(csv_bytes(&["n", "hurst"], &rows).unwrap(), b"n,hurst\n1,0.5\n");
/// let nan = vec![vec!["1".to_string(), "NaN".to_string()]];
/// let refused = csv_bytes(&["n", "hurst"], &nan).unwrap_err().to_string();
/// assert!(refused.starts_with("the result is not a finite number (NaN in column `hurst`, row 1)"));
/// ```
pub fn csv_bytes<S: AsRef<str>>(header: &[S], rows: &[Vec<String>]) -> Result<Vec<u8>, CsvError> {
    ensure_finite(header, rows)?;
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer.write_record(header.iter().map(AsRef::as_ref))?;
    for row in rows {
        writer.write_record(row)?;
    }
    writer
        .into_inner()
        .map_err(|e| CsvError::Flush(e.to_string()))
}

/// Fails, naming the column and row, if a field is `NaN` or an infinity.
fn ensure_finite<S: AsRef<str>>(header: &[S], rows: &[Vec<String>]) -> Result<(), CsvError> {
    for (r, row) in rows.iter().enumerate() {
        for (c, field) in row.iter().enumerate() {
            let lower = field.trim().to_ascii_lowercase();
            if lower == "nan" || lower.trim_start_matches(['-', '+']).starts_with("inf") {
                return Err(CsvError::NotFinite {
                    field: field.clone(),
                    column: header.get(c).map_or("?", AsRef::as_ref).to_string(),
                    row: r + 1,
                });
            }
        }
    }
    Ok(())
}
