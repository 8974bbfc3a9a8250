//! Typed errors of the library.
//!
//! Every fallible function of `asperity` returns [`Result<T>`](crate::Result) with this
//! [`Error`]. Messages are one line, name the offending value and say what is allowed, so
//! that a command-line front end can print them as they are.

use std::path::PathBuf;

/// The error type of the `asperity` library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A parameter is outside its allowed range (checked once, at construction).
    #[error("invalid {name}: {reason}")]
    InvalidParameter {
        /// The parameter's name as a user would write it (e.g. `hurst`).
        name: &'static str,
        /// What is wrong and what is allowed.
        reason: String,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A file exists where an output should go and overwriting was not allowed (the
    /// `force` argument of the writers).
    #[error("{0}: output already exists (allow overwriting to replace it)")]
    OutputExists(PathBuf),
    /// An output path cannot be written: its folder is missing, it is a folder, it is
    /// named twice among one command's outputs, or it is the command's input.
    #[error("{path}: {reason}")]
    BadOutput {
        /// The output concerned.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// A `.npy` or topography file could not be read as the array that was expected.
    #[error("{path}: {reason}")]
    BadArrayFile {
        /// The file concerned.
        path: PathBuf,
        /// What was wrong (dtype, shape, ...).
        reason: String,
    },
    /// The bytes of a topography file do not hold what its format prescribes (a reader's
    /// error, before the file's path is known; [`crate::topography::read_file`] adds it).
    #[error("{format} file: {reason}")]
    BadTopography {
        /// The format's short name (e.g. `x3p`).
        format: &'static str,
        /// What is wrong (truncated, wrong magic, impossible size, ...).
        reason: String,
    },
    /// An input file cannot be read as given: not a regular file, too large, corrupt.
    #[error("{path}: {reason}")]
    BadInput {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// An input array holds NaN or infinity.
    #[error("{what} holds a non-finite value ({value}) at index {index}")]
    NonFinite {
        /// What array (file name or description).
        what: String,
        /// Flat (row-major) index of the first bad value.
        index: usize,
        /// The bad value.
        value: f64,
    },
    /// A computation would need more memory than is available to this process, more than
    /// the address space can hold, or an allocation was refused.
    #[error("{}", out_of_memory_message(.what, *.needed_mib, *.available_mib, .limited_by))]
    OutOfMemory {
        /// What was to be allocated.
        what: String,
        /// Estimated need in MiB (rounded up); `None` when it exceeds the address space.
        needed_mib: Option<u64>,
        /// Memory available now in MiB; `None` when the allocator refused the request.
        available_mib: Option<u64>,
        /// What sets the available figure (e.g. `cgroup memory.max`), or why it failed.
        limited_by: String,
    },
    /// A study folder already holds the checkpoint of a different study.
    #[error("{dir}: holds the checkpoint of another study ({reason}); use another folder, or discard it (force)")]
    ForeignCheckpoint {
        /// The study folder.
        dir: PathBuf,
        /// What differs.
        reason: String,
    },
    /// A study was stopped on request ([`crate::study::StudyDir::with_stop`]); the samples
    /// it finished are checkpointed.
    #[error("{dir}: study interrupted; its finished samples are checkpointed, and it resumes when run again")]
    Interrupted {
        /// The study folder.
        dir: PathBuf,
    },
    /// A study folder holds samples of the same study over (N, H) values or a sample count
    /// that a run would leave out of its results: a folder only grows ([`crate::study::StudyDir::check`]).
    #[error("{dir}: holds results this run would leave out: {reason}; include them (the folder's study grows, its checkpoints are reused), use another folder, or leave them out anyway (force; their checkpoints are kept)")]
    NarrowerStudy {
        /// The study folder.
        dir: PathBuf,
        /// What the run leaves out.
        reason: String,
    },
    /// A study file or checkpoint in a study folder is damaged or from an older version: the
    /// study goes on once it is repaired or removed, or once the folder's checkpoints are
    /// discarded (`force`).
    #[error("{path}: {reason}, or discard the folder's checkpoints (force)")]
    DamagedStudy {
        /// The study file or checkpoint.
        path: PathBuf,
        /// What is wrong and how to repair it (e.g. `corrupt checkpoint (...); delete it to
        /// recompute its task`).
        reason: String,
    },
    /// Another process holds the lock of an output folder ([`crate::lock::FolderLock`]).
    #[error("{dir}: in use by another asperity process ({holder}); wait for it to finish, or use another folder")]
    FolderInUse {
        /// The folder.
        dir: PathBuf,
        /// Who holds it, e.g. `PID 1234`.
        holder: String,
    },
    /// A contact solve inside a larger computation (a study sample) failed for a reason of
    /// the solver's own: no convergence, a stop request, a load beyond full contact (bad
    /// input to the solver is returned as the [`Error`] it is).
    #[error("{context}: {source}")]
    Solve {
        /// Which computation (e.g. the sample's seed).
        context: String,
        /// The solver's error, a [`crate::bem::SolveError`] (downcast it to read its
        /// residual or iterations). Held as a trait object so that the two error types do
        /// not contain each other: a `SolveError` holds an `Error` (bad input), not the
        /// other way round.
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// A metadata (JSON / TOML) file could not be parsed or written.
    #[error("{path}: {reason}")]
    Metadata {
        /// The file concerned.
        path: PathBuf,
        /// The parser's message.
        reason: String,
    },
}

impl Error {
    /// Shorthand for [`Error::InvalidParameter`].
    pub fn invalid(name: &'static str, reason: impl Into<String>) -> Self {
        Error::InvalidParameter {
            name,
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

fn out_of_memory_message(
    what: &str,
    needed_mib: Option<u64>,
    available_mib: Option<u64>,
    limited_by: &str,
) -> String {
    match (needed_mib, available_mib) {
        (None, _) => format!("{what} exceeds addressable memory"),
        (Some(needed), Some(available)) if needed > available => format!(
            "{what} needs about {needed} MiB of memory but only {available} MiB are available \
             (limited by {limited_by})"
        ),
        // Refused by the 90 % margin of `memory::ensure_fits`: say so, not "only".
        (Some(needed), Some(available)) => format!(
            "{what} needs about {needed} MiB of memory, more than 90 % of the {available} MiB \
             available (limited by {limited_by}); asperity keeps a tenth free"
        ),
        (Some(needed), None) => {
            format!("{what} needs about {needed} MiB of memory, which could not be allocated ({limited_by})")
        }
    }
}

/// `Result` with the library's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

/// Whether `value` is a positive, finite number (NaN is not): the check behind every
/// length, modulus, load and tolerance of the library.
pub(crate) fn is_positive_finite(value: f64) -> bool {
    value.is_finite() && value > 0.0
}

/// `value` if it is positive and finite, else [`Error::InvalidParameter`] naming `name`:
/// "`{what} `must be positive and finite, got {value}" (`what` may be empty).
pub(crate) fn positive_finite(name: &'static str, value: f64, what: &str) -> Result<f64> {
    if is_positive_finite(value) {
        return Ok(value);
    }
    let what = if what.is_empty() {
        String::new()
    } else {
        format!("{what} ")
    };
    Err(Error::invalid(
        name,
        format!(
            "{what}must be positive and finite, got {}",
            crate::input::short_number(value)
        ),
    ))
}

/// Checks that every value is finite; the error names `what` and the first bad index.
pub fn ensure_finite<'a>(what: &str, values: impl IntoIterator<Item = &'a f64>) -> Result<()> {
    match values.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((index, &value)) => Err(Error::NonFinite {
            what: what.to_string(),
            index,
            value,
        }),
        None => Ok(()),
    }
}
