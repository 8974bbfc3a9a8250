//! A study as a front end gives it ([`StudyRequest`]: `asperity study alpha|curve|file`,
//! Python's `study_alpha`/`study_curve`) and the one place it becomes the library's
//! [`StudySpec`]: the method by name, the counts refused alike when negative, and every
//! value left out taken from [`StudySpec::default`].

use asperity::study::{FitWindow, Method, StudySpec};

use super::{Kind, MIN_CONTACTS};
use crate::refusal::{count, Param, Refusal};
use crate::surface::parse_seed;

/// The study's solver.
pub const METHOD: Param = Param::new("--method", "method");
/// The grid sizes N.
pub const SIZES: Param = Param::new("--n", "n");
/// Realisations per (N, H).
pub const SAMPLES: Param = Param::new("--samples", "samples");
/// Common force levels of the ensemble-mean curves.
pub const LEVELS: Param = Param::new("--levels", "levels");

/// The method named `name` (`mdr` or `bem`), in one wording for both front ends.
///
/// ```
/// use asperity::study::Method;
/// use asperity_app::study::request::method;
/// use asperity_app::Names;
///
/// assert_eq!(method("bem").unwrap(), Method::Bem);
/// let refusal = method("fem").unwrap_err();
/// assert_eq!(refusal.words(Names::Flags), "--method must be mdr or bem, got \"fem\"");
/// assert_eq!(refusal.words(Names::Keywords), "method must be mdr or bem, got \"fem\"");
/// ```
pub fn method(name: &str) -> Result<Method, Refusal> {
    match name {
        "mdr" => Ok(Method::Mdr),
        "bem" => Ok(Method::Bem),
        other => {
            let shown = asperity::input::clip(other);
            Err(Refusal::of(METHOD).text(format!(" must be mdr or bem, got {shown:?}")))
        }
    }
}

/// A study as given: counts signed as a flag's text or a Python int holds them, the method
/// and the seed as written, and `None` where a value was left out.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyRequest {
    /// Alpha or curve: an α study's BEM samples stop loading past the fit windows unless
    /// `full_sweep` ([`Kind::spec`]).
    pub kind: Kind,
    /// `mdr` or `bem` ([`method`]).
    pub method: String,
    /// Grid sizes N.
    pub sizes: Vec<i128>,
    /// Hurst exponents.
    pub hursts: Vec<f64>,
    /// Realisations per (N, H).
    pub samples: i128,
    /// q0·L/2π of a roll-off.
    pub rolloff: Option<f64>,
    /// The study seed, as written ([`parse_seed`]).
    pub seed: Option<String>,
    /// α fit window: fewest points in contact.
    pub min_contacts: Option<i128>,
    /// α fit window: largest contact fraction.
    pub max_fraction: Option<f64>,
    /// Common force levels of the ensemble-mean curves.
    pub levels: Option<i128>,
    /// An α study that solves every load.
    pub full_sweep: bool,
    /// Poisson's ratio of the tangential stiffness (BEM curve studies).
    pub poisson: Option<f64>,
    /// Which tangential stiffnesses: `x`, `y` or `both` (none: both).
    pub tangential: Option<String>,
}

impl Default for StudyRequest {
    /// An α study of [`StudySpec::default`]'s method, sizes, H and samples, every other
    /// value left out.
    fn default() -> Self {
        let spec = StudySpec::default();
        StudyRequest {
            kind: Kind::Alpha,
            method: spec.method.name().into(),
            sizes: spec.sizes.iter().map(|&n| n as i128).collect(),
            hursts: spec.hursts,
            samples: spec.samples as i128,
            rolloff: None,
            seed: None,
            min_contacts: None,
            max_fraction: None,
            levels: None,
            full_sweep: false,
            poisson: None,
            tangential: None,
        }
    }
}

impl StudyRequest {
    /// The library's spec of the request, not yet validated ([`super::validate`]): the
    /// method ([`method`]) and the seed ([`parse_seed`]) read, a negative count refused
    /// ([`count`]: `--samples must be at least 1, got -1`), the values left out taken from
    /// [`StudySpec::default`] (the defaults of both front ends, which live there only),
    /// and the load sweep of the kind ([`Kind::spec`]).
    ///
    /// ```
    /// use asperity::study::StudySpec;
    /// use asperity_app::study::request::StudyRequest;
    /// use asperity_app::Names;
    ///
    /// let spec = StudyRequest { sizes: vec![64], full_sweep: true, ..Default::default() };
    /// assert_eq!(spec.spec().unwrap(), StudySpec { sizes: vec![64], ..StudySpec::default() });
    /// let refusal = StudyRequest { samples: -1, ..Default::default() }.spec().unwrap_err();
    /// assert_eq!(refusal.words(Names::Keywords), "samples must be at least 1, got -1");
    /// ```
    pub fn spec(&self) -> Result<StudySpec, Refusal> {
        let defaults = StudySpec::default();
        let sizes = (self.sizes.iter())
            .map(|&n| count(SIZES, n))
            .collect::<Result<_, _>>()?;
        let window = FitWindow {
            min_contacts: optional_count(MIN_CONTACTS, self.min_contacts)?
                .unwrap_or(defaults.window.min_contacts),
            max_fraction: self.max_fraction.unwrap_or(defaults.window.max_fraction),
        };
        let seed = self.seed.as_deref().map(parse_seed).transpose()?;
        let tangential = (self.tangential.as_deref())
            .map(crate::derived::parse_directions)
            .transpose()?;
        let spec = StudySpec {
            method: method(&self.method)?,
            sizes,
            hursts: self.hursts.clone(),
            samples: count(SAMPLES, self.samples)?,
            rolloff: self.rolloff,
            seed: seed.unwrap_or(defaults.seed),
            window,
            levels: optional_count(LEVELS, self.levels)?.unwrap_or(defaults.levels),
            poisson: self.poisson,
            tangential: tangential.unwrap_or_default(),
            ..defaults
        };
        Ok(self.kind.spec(spec, self.full_sweep))
    }
}

fn optional_count(param: Param, value: Option<i128>) -> Result<Option<usize>, Refusal> {
    value.map(|v| count(param, v)).transpose()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Names;

    #[test]
    fn every_value_given_reaches_the_spec_and_an_alpha_study_ends_its_sweep() {
        let request = StudyRequest {
            kind: Kind::Alpha,
            method: "bem".into(),
            sizes: vec![32, 64],
            hursts: vec![0.3, 0.8],
            samples: 5,
            rolloff: Some(4.0),
            seed: Some("9".into()),
            min_contacts: Some(4),
            max_fraction: Some(0.2),
            levels: Some(12),
            full_sweep: false,
            poisson: None,
            tangential: None,
        };
        let whole = StudySpec {
            method: Method::Bem,
            sizes: vec![32, 64],
            hursts: vec![0.3, 0.8],
            samples: 5,
            rolloff: Some(4.0),
            seed: 9,
            window: FitWindow {
                min_contacts: 4,
                max_fraction: 0.2,
            },
            levels: 12,
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
        };
        assert_eq!(request.spec().unwrap(), whole.clone().with_alpha_sweep());
        let full = StudyRequest {
            full_sweep: true,
            ..request.clone()
        };
        assert_eq!(full.spec().unwrap(), whole);
        let curve = StudyRequest {
            kind: Kind::Curve,
            ..request
        };
        assert_eq!(curve.spec().unwrap(), whole);
    }

    #[test]
    fn negative_counts_a_bad_seed_and_an_unknown_method_are_refused_by_name() {
        let refused = |request: StudyRequest| request.spec().unwrap_err().words(Names::Flags);
        let base = StudyRequest::default;
        assert_eq!(
            refused(StudyRequest {
                sizes: vec![64, -32],
                ..base()
            }),
            "--n must be at least 1, got -32"
        );
        assert_eq!(
            refused(StudyRequest {
                levels: Some(-3),
                ..base()
            }),
            "--levels must be at least 1, got -3"
        );
        assert_eq!(
            refused(StudyRequest {
                min_contacts: Some(-1),
                ..base()
            }),
            "--min-contacts must be at least 1, got -1"
        );
        assert!(refused(StudyRequest {
            samples: i128::MAX,
            ..base()
        })
        .starts_with("--samples is too large, got "));
        assert!(refused(StudyRequest {
            seed: Some("-1".into()),
            ..base()
        })
        .starts_with("--seed must be a whole number from 0 to "));
        assert_eq!(
            refused(StudyRequest {
                method: "fem".into(),
                ..base()
            }),
            "--method must be mdr or bem, got \"fem\""
        );
    }
}
