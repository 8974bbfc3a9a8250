//! The library's errors as Python exceptions.
//!
//! * bad input ([`Error::InvalidParameter`], non-finite values, bad files, foreign
//!   checkpoints, ...) → `ValueError` with the library's one-line message, the line the
//!   CLI prints after `error: `;
//! * the memory guard ([`Error::OutOfMemory`]) → `MemoryError`;
//! * [`SolveError::NoConvergence`] and [`SolveError::Stagnated`] (given up early: the
//!   residual stopped decreasing) → `asperity.ConvergenceError` with `.iterations` and
//!   `.residual` (the best one reached);
//! * [`SolveError::BeyondFullContact`] → `asperity.BeyondFullContactError` (a
//!   `ValueError`) with `.threshold` (the full-contact value in the quantity asked for, or
//!   `None`), `.quantity` and `.requested`;
//! * [`SolveError::Interrupted`] → `KeyboardInterrupt` (normally the signal's own exception
//!   is raised instead, see [`crate::interrupt`]);
//! * I/O errors → `OSError`; a study folder locked by another process
//!   ([`Error::FolderInUse`]) → `BlockingIOError`, naming the holder's PID.

use asperity::bem::SolveError;
use asperity::Error;
use asperity_app::{Names, Refusal, RequestError};
use pyo3::exceptions::{
    PyBlockingIOError, PyKeyboardInterrupt, PyMemoryError, PyOSError, PyRuntimeError, PyValueError,
};
use pyo3::prelude::*;

pyo3::create_exception!(
    asperity,
    ConvergenceError,
    PyRuntimeError,
    "A contact solve (or the frozen-set CG) did not reach its tolerance.\n\n\
     Attributes: ``iterations`` (done) and ``residual`` (reached)."
);
pyo3::create_exception!(
    asperity,
    BeyondFullContactError,
    PyValueError,
    "The load or indentation closes the gap everywhere: no contact problem is left.\n\n\
     Attributes: ``threshold`` (the full-contact value in the quantity asked for, or None),\n\
     ``quantity`` ('force', 'mean pressure' or 'indentation') and ``requested``."
);

/// A library error as a Python exception.
pub fn from_error(error: Error) -> PyErr {
    match error {
        Error::OutOfMemory { .. } => PyMemoryError::new_err(error.to_string()),
        Error::Io { .. } => PyOSError::new_err(error.to_string()),
        Error::FolderInUse { .. } => PyBlockingIOError::new_err(error.to_string()),
        Error::Solve { context, source } => {
            let err = match source.downcast::<SolveError>() {
                Ok(solve) => from_solve(*solve),
                Err(other) => PyValueError::new_err(other.to_string()),
            };
            Python::attach(|py| prefix(py, err, &context))
        }
        other => PyValueError::new_err(other.to_string()),
    }
}

/// A solver error as a Python exception (see the module docs).
pub fn from_solve(error: SolveError) -> PyErr {
    let message = error.to_string();
    match error {
        SolveError::Input(e) => from_error(e),
        SolveError::NoConvergence {
            iterations,
            residual,
        }
        | SolveError::Stagnated {
            iterations,
            best: residual,
            ..
        } => Python::attach(|py| {
            let err = ConvergenceError::new_err(message);
            let value = err.value(py);
            // Setting attributes on a fresh exception instance cannot fail.
            let _ = value.setattr("iterations", iterations);
            let _ = value.setattr("residual", residual);
            err
        }),
        // A stop requested through the solver's flag: Ctrl-C or an exception of a progress
        // callback, which `run_detached` raises instead; this is the fallback.
        SolveError::Interrupted { .. } => PyKeyboardInterrupt::new_err(message),
        SolveError::BeyondFullContact {
            requested,
            full_contact,
        } => Python::attach(|py| {
            let err = BeyondFullContactError::new_err(message);
            let value = err.value(py);
            let _ = value.setattr("threshold", full_contact);
            let _ = value.setattr("quantity", requested.quantity());
            let _ = value.setattr("requested", requested.value());
            err
        }),
    }
}

/// The same exception with `context: ` before its message (attributes kept).
fn prefix(py: Python<'_>, err: PyErr, context: &str) -> PyErr {
    let value = err.value(py);
    let message = value.str().map(|s| s.to_string()).unwrap_or_default();
    let _ = value.setattr("args", (format!("{context}: {message}"),));
    err
}

/// A request refused by the front-end layer's rules: `ValueError` in Python's words
/// (keywords, not flags).
pub fn refused(refusal: Refusal) -> PyErr {
    PyValueError::new_err(refusal.words(Names::Keywords))
}

/// A request the front-end layer cannot run: refused by a rule (`ValueError`), or by the
/// library for what it would need (`MemoryError` for memory), in Python's words.
pub fn request_error(error: RequestError) -> PyErr {
    let words = error.words(Names::Keywords);
    match error {
        RequestError::Invalid(source) => from_error(*source),
        RequestError::Library { source, .. } if matches!(*source, Error::OutOfMemory { .. }) => {
            PyMemoryError::new_err(words)
        }
        _ => PyValueError::new_err(words),
    }
}

/// `ValueError(message)`: for the binding's own checks of its arguments.
pub fn invalid(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
