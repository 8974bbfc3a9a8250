//! Why a request is refused, in words that name its parameters the way the front end that
//! made it does: a flag of the CLI (`--tol`) or a keyword of Python (`tolerance`).

use std::fmt;

/// One parameter of a request, as each front end names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Param {
    /// The CLI's flag, with its dashes (`--tol`).
    pub flag: &'static str,
    /// The Python keyword (`tolerance`).
    pub keyword: &'static str,
}

impl Param {
    /// A parameter called `flag` on the command line and `keyword` in Python.
    pub const fn new(flag: &'static str, keyword: &'static str) -> Self {
        Param { flag, keyword }
    }

    /// Its name in `names`.
    pub fn name(self, names: Names) -> &'static str {
        match names {
            Names::Flags => self.flag,
            Names::Keywords => self.keyword,
        }
    }
}

/// How a front end names parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Names {
    /// The CLI's flags (`--tol`).
    Flags,
    /// Python's keywords (`tolerance`).
    Keywords,
}

#[derive(Debug, Clone, PartialEq)]
enum Part {
    Text(String),
    Param(Param),
}

/// A refused request: one line of text in which the parameters are named by the front end
/// ([`Refusal::words`]). Built from pieces: `Refusal::of(TOL).text(" must be …")`.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    parts: Vec<Part>,
}

impl Refusal {
    /// A refusal that starts with the name of `param`.
    pub fn of(param: Param) -> Self {
        Refusal {
            parts: vec![Part::Param(param)],
        }
    }

    /// A refusal that starts with `text`.
    pub fn saying(text: impl Into<String>) -> Self {
        Refusal {
            parts: vec![Part::Text(text.into())],
        }
    }

    /// `text` appended.
    pub fn text(mut self, text: impl Into<String>) -> Self {
        self.parts.push(Part::Text(text.into()));
        self
    }

    /// The name of `param` appended.
    pub fn param(mut self, param: Param) -> Self {
        self.parts.push(Part::Param(param));
        self
    }

    /// The pieces of `other` appended.
    pub fn join(mut self, other: &Refusal) -> Self {
        self.parts.extend(other.parts.iter().cloned());
        self
    }

    /// The line, with every parameter named as `names` says.
    pub fn words(&self, names: Names) -> String {
        self.parts
            .iter()
            .map(|part| match part {
                Part::Text(text) => text.as_str(),
                Part::Param(param) => param.name(names),
            })
            .collect()
    }
}

/// A request that cannot be run: refused by a rule, or (the memory guard) refused by the
/// library for what it would need.
#[derive(Debug, thiserror::Error)]
pub enum RequestError {
    /// A rule of the request refuses it.
    #[error("{}", .0.words(Names::Flags))]
    Refused(Refusal),
    /// The library refuses what `param` asks for (memory, ...).
    #[error("{} {value}: {source}", .param.flag)]
    Library {
        /// The parameter that asks for it.
        param: Param,
        /// Its value, as given.
        value: String,
        /// The library's error.
        source: Box<asperity::Error>,
    },
    /// The library refuses the request in its own words, which name the parameter as
    /// Python does (`invalid rms_height: …`; the CLI turns the name into its flag's).
    #[error("{0}")]
    Invalid(Box<asperity::Error>),
}

impl RequestError {
    /// The line, with parameters named as `names` says.
    pub fn words(&self, names: Names) -> String {
        match self {
            RequestError::Refused(refusal) => refusal.words(names),
            RequestError::Library {
                param,
                value,
                source,
            } => format!("{} {value}: {source}", param.name(names)),
            RequestError::Invalid(source) => source.to_string(),
        }
    }
}

impl From<Refusal> for RequestError {
    fn from(refusal: Refusal) -> Self {
        RequestError::Refused(refusal)
    }
}

/// A number as every refusal writes it (`got 1e-6`, `got 0.25`, `got infinity`): the
/// library's [`asperity::input::short_number`], so that a rule of the front-end layer and
/// one of the library word the same value alike, and the CLI (which shortens numbers of
/// more than 20 characters) and Python alike.
///
/// ```
/// use asperity_app::refusal::number;
///
/// assert_eq!(number(-1e-6), "-1e-6");
/// assert_eq!(number(0.7), "0.7");
/// assert_eq!(number(100000.0), "100000");
/// assert_eq!(number(f64::INFINITY), "infinity");
/// assert_eq!(number(f64::NAN), "NaN");
/// ```
pub fn number(value: f64) -> String {
    asperity::input::short_number(value)
}

/// A count as a front end holds it, signed (a flag's text, a Python int), as a request's
/// `usize`: a negative one is refused in the words of the requests' rule for 0, so that
/// `--max-iter -1` and `max_iterations=-1` are refused alike (every count of a request is
/// at least 1; 0 is refused by the request's own rule).
///
/// ```
/// use asperity_app::refusal::{count, Names, Param};
///
/// const NLOADS: Param = Param::new("--nloads", "nloads");
/// assert_eq!(count(NLOADS, 3).unwrap(), 3);
/// let refusal = count(NLOADS, -2).unwrap_err();
/// assert_eq!(refusal.words(Names::Keywords), "nloads must be at least 1, got -2");
/// let refusal = count(NLOADS, i128::MAX).unwrap_err();
/// assert!(refusal.words(Names::Flags).starts_with("--nloads is too large, got "));
/// ```
pub fn count(param: Param, value: impl Into<i128>) -> Result<usize, Refusal> {
    let value: i128 = value.into();
    usize::try_from(value).map_err(|_| {
        let rule = if value < 0 {
            "must be at least 1"
        } else {
            "is too large"
        };
        // Past 20 digits, shortened as the CLI shortens every long number of its errors.
        let shown = match value.to_string() {
            digits if digits.len() > 20 => number(value as f64),
            digits => digits,
        };
        Refusal::of(param).text(format!(" {rule}, got {shown}"))
    })
}

/// A value that must be positive and finite (a modulus, a side length, an area), refused
/// otherwise in one wording: `--size must be positive and finite, got -1` (CLI),
/// `size must be positive and finite, got -1` (Python), the number as [`number`] writes it.
///
/// ```
/// use asperity_app::refusal::{positive, Names, Param};
///
/// const SIZE: Param = Param::new("--size", "size");
/// assert_eq!(positive(SIZE, 2.0).unwrap(), 2.0);
/// let refusal = positive(SIZE, f64::NAN).unwrap_err();
/// assert_eq!(refusal.words(Names::Keywords), "size must be positive and finite, got NaN");
/// let refusal = positive(SIZE, -1e-6).unwrap_err();
/// assert_eq!(refusal.words(Names::Flags), "--size must be positive and finite, got -1e-6");
/// ```
pub fn positive(param: Param, value: f64) -> Result<f64, Refusal> {
    if value.is_finite() && value > 0.0 {
        return Ok(value);
    }
    Err(Refusal::of(param).text(format!(
        " must be positive and finite, got {}",
        number(value)
    )))
}

impl fmt::Display for Refusal {
    /// The CLI's words (flags); Python renders [`Refusal::words`] with [`Names::Keywords`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.words(Names::Flags))
    }
}

impl std::error::Error for Refusal {}

#[cfg(test)]
mod tests {
    use super::*;

    const TOL: Param = Param::new("--tol", "tolerance");
    const PMIN: Param = Param::new("--pmin", "pmin");

    #[test]
    fn refusals_name_parameters_as_the_front_end_does() {
        let r = Refusal::of(TOL)
            .text(" must be below ")
            .param(PMIN)
            .text(", got 2");
        assert_eq!(r.words(Names::Flags), "--tol must be below --pmin, got 2");
        assert_eq!(
            r.words(Names::Keywords),
            "tolerance must be below pmin, got 2"
        );
        assert_eq!(r.to_string(), r.words(Names::Flags));
        let e = RequestError::from(Refusal::saying("give one of ").param(TOL));
        assert_eq!(e.words(Names::Keywords), "give one of tolerance");
    }
}
