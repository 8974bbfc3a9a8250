//! The front-end layer's errors in the CLI's words.

use asperity_app::study::report::ReportError;
use asperity_app::RequestError;

/// A request the front-end layer refused, as the CLI reports it: its rules name flags; the
/// library's own refusals go through the CLI's mapping of library names to flags (main.rs).
pub fn refused(error: RequestError) -> anyhow::Error {
    match error {
        RequestError::Invalid(source) => anyhow::Error::from(*source),
        other => anyhow::Error::from(other),
    }
}

/// A comparison with the paper that could not be written
/// ([`asperity_app::study::report`]), as the CLI reports it: the library's errors through
/// the CLI's mapping of them (an existing output names `--force`).
pub fn report_error(error: ReportError) -> anyhow::Error {
    match error {
        ReportError::Library(source) => anyhow::Error::from(source),
        other => anyhow::Error::from(other),
    }
}
