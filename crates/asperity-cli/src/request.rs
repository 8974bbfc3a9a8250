//! The front-end layer's errors in the CLI's words.

use asperity_app::RequestError;

/// A request the front-end layer refused, as the CLI reports it: its rules name flags; the
/// library's own refusals go through the CLI's mapping of library names to flags (main.rs).
pub fn refused(error: RequestError) -> anyhow::Error {
    match error {
        RequestError::Invalid(source) => anyhow::Error::from(*source),
        other => anyhow::Error::from(other),
    }
}
