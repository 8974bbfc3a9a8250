//! Study files (`asperity study file`, Python's `study_file`): a TOML file of a study's
//! keys (Python's keywords) read into a [`StudyRequest`] once for both front ends, with
//! the same refusals in the same words.

use std::path::Path;

use asperity::study::{Method, StudySpec};
use serde::de::{self, Visitor};
use serde::Deserialize;

use super::request::StudyRequest;
use super::Kind;
use crate::derived::Derived;
use crate::figure::study as figure;
use crate::range::parse_range;
use crate::refusal::{Names, Refusal};

/// `method` of a study file (the flag `--method` is read by the front-end layer's rule,
/// [`asperity_app::study::request::method`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
enum MethodArg {
    /// 1D method of dimensionality reduction on rough lines.
    Mdr,
    /// 3D boundary elements on rough surfaces (free boundaries).
    Bem,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Mdr => Method::Mdr,
            MethodArg::Bem => Method::Bem,
        }
    }
}

/// `n` of a study file: one size or a list.
#[derive(Debug)]
struct Sizes(Vec<usize>);

impl<'de> Deserialize<'de> for Sizes {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visit;
        impl<'de> Visitor<'de> for Visit {
            type Value = Sizes;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a grid size (e.g. 512) or a list of sizes (e.g. [512, 2048])")
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> std::result::Result<Sizes, E> {
                usize::try_from(v)
                    .map(|n| Sizes(vec![n]))
                    .map_err(|_| E::invalid_value(de::Unexpected::Unsigned(v), &self))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> std::result::Result<Sizes, E> {
                usize::try_from(v)
                    .map(|n| Sizes(vec![n]))
                    .map_err(|_| E::invalid_value(de::Unexpected::Signed(v), &self))
            }
            fn visit_seq<A: de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> std::result::Result<Sizes, A::Error> {
                let mut sizes = Vec::new();
                while let Some(n) = seq.next_element::<usize>()? {
                    sizes.push(n);
                }
                Ok(Sizes(sizes))
            }
        }
        d.deserialize_any(Visit)
    }
}

/// `hurst` of a study file: a number, a range string (`"A:B:STEP"`, or anything
/// [`parse_range`] reads), or a list of numbers and range strings.
#[derive(Debug)]
struct Hursts(Vec<f64>);

struct HurstVisit {
    list: bool,
}

impl<'de> Visitor<'de> for HurstVisit {
    type Value = Hursts;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        if self.list {
            f.write_str(
                "a Hurst exponent (e.g. 0.5), a range \"A:B:STEP\" or a list of them \
                 (e.g. [0.5, \"1:2:0.5\"])",
            )
        } else {
            f.write_str("a Hurst exponent or a range \"A:B:STEP\" in a list")
        }
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> std::result::Result<Hursts, E> {
        Ok(Hursts(vec![v]))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> std::result::Result<Hursts, E> {
        Ok(Hursts(vec![v as f64]))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> std::result::Result<Hursts, E> {
        Ok(Hursts(vec![v as f64]))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> std::result::Result<Hursts, E> {
        parse_range(v).map(Hursts).map_err(E::custom)
    }
    fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<Hursts, A::Error> {
        if !self.list {
            return Err(de::Error::invalid_type(de::Unexpected::Seq, &self));
        }
        let mut values = Vec::new();
        while let Some(item) = seq.next_element::<HurstItem>()? {
            values.extend(item.0 .0);
        }
        Ok(Hursts(values))
    }
}

impl<'de> Deserialize<'de> for Hursts {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(HurstVisit { list: true })
    }
}

/// One item of a `hurst` list: a number or a range string.
struct HurstItem(Hursts);

impl<'de> Deserialize<'de> for HurstItem {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(HurstVisit { list: false }).map(HurstItem)
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyFile {
    kind: Kind,
    method: MethodArg,
    n: Sizes,
    hurst: Hursts,
    samples: usize,
    rolloff: Option<f64>,
    seed: Option<u64>,
    min_contacts: Option<usize>,
    max_fraction: Option<f64>,
    levels: Option<usize>,
    full_sweep: Option<bool>,
    poisson: Option<f64>,
    tangential: Option<String>,
    resistivity: Option<Vec<f64>>,
    thermal_conductivity: Option<Vec<f64>>,
}

/// A study file read and checked: the study request (its keys as Python's keywords), the
/// bodies' pairs of a curve study, and what the request becomes (the spec, not yet
/// validated against the library's limits, and the derived columns).
#[derive(Debug, Clone)]
pub struct StudyFileRequest {
    /// The study as the file gives it.
    pub request: StudyRequest,
    /// `resistivity`: the bodies' resistivities.
    pub resistivity: Option<Vec<f64>>,
    /// `thermal_conductivity`: the bodies' thermal conductivities.
    pub thermal_conductivity: Option<Vec<f64>>,
    /// The spec of the request ([`StudyRequest::spec`]).
    pub spec: StudySpec,
    /// The tangential and conductance columns of a curve study.
    pub derived: figure::Derived,
}

/// Reads a study file's text (`asperity study file`, Python's `study_file`): the request,
/// its spec and a curve study's tangential and conductance columns (`poisson`,
/// `resistivity`, `thermal_conductivity`, refused as `study curve` refuses its flags, in the
/// keys' words). A refusal names the file, the line and column, and the key concerned, in
/// one line.
pub fn read(path: &Path, text: &str) -> Result<StudyFileRequest, Refusal> {
    let file: StudyFile =
        toml::from_str(text).map_err(|e| Refusal::saying(toml_error(path, text, &e)))?;
    let derived = file_derived(path, &file)?;
    // The keys left out take the library's defaults (`StudySpec::default`).
    let request = StudyRequest {
        kind: file.kind,
        method: Method::from(file.method).name().into(),
        sizes: file.n.0.iter().map(|&n| n as i128).collect(),
        hursts: file.hurst.0,
        samples: file.samples as i128,
        rolloff: file.rolloff,
        seed: file.seed.map(|seed| seed.to_string()),
        min_contacts: file.min_contacts.map(|c| c as i128),
        max_fraction: file.max_fraction,
        levels: file.levels.map(|l| l as i128),
        full_sweep: file.full_sweep.unwrap_or(false),
        poisson: file.poisson,
        tangential: file.tangential.clone(),
    };
    if file.kind == Kind::Curve && file.full_sweep.is_some() {
        return Err(Refusal::saying(format!(
            "{}: full_sweep applies to alpha studies only (a curve study solves every load)",
            path.display()
        )));
    }
    let in_keys =
        |r: Refusal| Refusal::saying(format!("{}: {}", path.display(), r.words(Names::Keywords)));
    let spec = request.spec().map_err(in_keys)?;
    super::check_tangential(&spec).map_err(in_keys)?;
    Ok(StudyFileRequest {
        request,
        resistivity: file.resistivity,
        thermal_conductivity: file.thermal_conductivity,
        spec,
        derived,
    })
}

/// The tangential and conductance columns of a study file, refused as `study curve`
/// refuses them ([`Derived::validate`]) but in the file's words (its keys are Python's
/// keywords).
fn file_derived(path: &Path, file: &StudyFile) -> Result<figure::Derived, Refusal> {
    let given = [
        file.resistivity.is_some(),
        file.thermal_conductivity.is_some(),
    ];
    let tangential = file.poisson.is_some() || file.tangential.is_some();
    if file.kind == Kind::Alpha && (tangential || given.contains(&true)) {
        return Err(Refusal::saying(format!(
            "{}: poisson, tangential, resistivity and thermal_conductivity apply to curve \
             studies only",
            path.display()
        )));
    }
    let refused =
        |r: Refusal| Refusal::saying(format!("{}: {}", path.display(), r.words(Names::Keywords)));
    let derived = Derived::validate(
        file.poisson,
        file.tangential.as_deref(),
        &file.resistivity,
        &file.thermal_conductivity,
    )
    .map_err(refused)?;
    Ok(derived.into())
}

/// `FILE, line L, column C (key K): MESSAGE`, in one line. The key is the one assigned on
/// the line the error points at; line and column are left out where toml gives no span.
fn toml_error(path: &Path, text: &str, error: &toml::de::Error) -> String {
    let message = error.message().trim().replace('\n', " ");
    // A missing key is reported at the start of its table: a place that means nothing.
    let Some(span) = error
        .span()
        .filter(|s| s.start < text.len().max(1) && !message.starts_with("missing field"))
    else {
        return format!("{}: {message}", path.display());
    };
    let before = &text[..span.start.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    let line_text = text[line_start..].lines().next().unwrap_or("");
    let key = line_text
        .split_once('=')
        .map(|(k, _)| k.trim().trim_matches('"'))
        .filter(|k| !k.is_empty() && !k.starts_with('#') && !k.starts_with('['));
    match key {
        Some(key) if !message.contains(&format!("`{key}`")) => format!(
            "{}, line {line}, column {column} (key `{key}`): {message}",
            path.display()
        ),
        _ => format!(
            "{}, line {line}, column {column}: {message}",
            path.display()
        ),
    }
}
