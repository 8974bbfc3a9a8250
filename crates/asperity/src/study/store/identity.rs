//! The identity of a checkpoint: everything that changes a number of a task's samples or
//! result, and a checksum of the stored content.
//!
//! Every `checkpoint/<task>.json` is stored sealed ([`seal`]): the [`TaskIdentity`] of the
//! task that produced it (method, N, H, seed, roll-off, force levels, fit window, the
//! samplers' scales and solver settings, the BEM sweep's end, and the asperity version
//! that defines the numerics), the checkpoint itself, and the FNV-1a-64 hash
//! ([`fnv1a64`]) of the canonical bytes of both: their compact JSON serialisation by
//! `serde_json` (fields in declaration order, floats in shortest round-trip form).
//! [`unseal`] recomputes the hash from the parsed content, so any edit that changes a value
//! (or a corrupted byte that still parses) is detected, and compares the identity field by
//! field, naming what differs.
//!
//! FNV-1a (Fowler–Noll–Vo, 64-bit: offset basis `0xcbf29ce484222325`, prime
//! `0x100000001b3`) is not cryptographic: it detects accidents (truncation, bit flips, hand
//! edits), which is its purpose here, not deliberate forgery.

use serde::{Deserialize, Serialize};

use crate::bem::tangential::Directions;
use crate::study::samplers::Scales;
use crate::study::{FitWindow, Method, StudySpec, Task};

/// The format tag of sealed checkpoints.
pub const CHECKPOINT_FORMAT: &str = "asperity-checkpoint/2";

/// The solver settings of a BEM sample (`None` for MDR, which has no iterative solver).
/// Extend it with any new setting that changes a number.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolverIdentity {
    /// The iteration that solved the contact problem, by its command-line name (`bccg`,
    /// `pk`): both converge to the tolerance, but not to the same last digits.
    pub solver: String,
    /// Residual tolerance of the contact solve.
    pub tolerance: f64,
    /// Iteration limit of the contact solve.
    pub max_iterations: usize,
    /// Relative residual of the frozen-set stiffness solve.
    pub stiffness_tolerance: f64,
    /// Estimated relative error of the stiffness at which its solve stops; absent in the
    /// checkpoints of versions that stopped on the residual only (read as `None`, written
    /// back the same, so that their checksums hold and they are refused as made with other
    /// settings, not as damaged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness_error: Option<f64>,
    /// Iteration limit of the frozen-set stiffness solve.
    pub stiffness_max_iterations: usize,
}

impl From<&crate::bem::SolverParams> for SolverIdentity {
    fn from(p: &crate::bem::SolverParams) -> Self {
        SolverIdentity {
            solver: p.solver.name().to_owned(),
            tolerance: p.tolerance,
            max_iterations: p.max_iterations,
            stiffness_tolerance: p.stiffness_tolerance,
            stiffness_error: Some(p.stiffness_error),
            stiffness_max_iterations: p.stiffness_max_iterations,
        }
    }
}

/// Everything that changes a number of one task of a study (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskIdentity {
    /// The asperity version whose numerics produced it.
    pub numerics: String,
    /// Solver.
    pub method: Method,
    /// Grid size.
    pub n: usize,
    /// Hurst exponent.
    pub hurst: f64,
    /// Study seed.
    pub seed: u64,
    /// Long-wavelength roll-off, if any.
    pub rolloff: Option<f64>,
    /// Common force levels of the ensemble curve.
    pub levels: usize,
    /// Fit window of α.
    pub window: FitWindow,
    /// Scales (normalisation, L, E*) of the samples.
    pub scales: Scales,
    /// Solver settings (BEM).
    pub solver: Option<SolverIdentity>,
    /// The contact fraction past which BEM samples stop loading
    /// ([`StudySpec::sweep_end`]); absent (the whole sweep) in older checkpoints, which
    /// keep their checksums.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sweep_end: Option<f64>,
    /// Poisson's ratio of the tangential stiffness at every load ([`StudySpec::poisson`]);
    /// absent (none) in older checkpoints, which keep their checksums.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson: Option<f64>,
    /// Which tangential stiffnesses ([`StudySpec::tangential`]); absent when both (the
    /// only choice of older checkpoints, which keep their checksums).
    #[serde(default, skip_serializing_if = "Directions::is_both")]
    pub tangential: Directions,
}

impl TaskIdentity {
    /// The identity of `task` in `spec`, with this build's numerics.
    pub fn of(spec: &StudySpec, task: Task) -> Self {
        TaskIdentity {
            numerics: format!("asperity {}", env!("CARGO_PKG_VERSION")),
            method: spec.method,
            n: task.n,
            hurst: task.hurst,
            seed: spec.seed,
            rolloff: spec.rolloff,
            levels: spec.levels,
            window: spec.window,
            scales: Scales::of(spec.method),
            solver: match spec.method {
                Method::Bem => Some(SolverIdentity::from(
                    &crate::study::samplers::bem_solver_params(),
                )),
                Method::Mdr => None,
            },
            sweep_end: spec.sweep_end,
            poisson: spec.poisson,
            tangential: spec.tangential,
        }
    }

    /// What differs from `other`, one `name: stored X, wanted Y` item per field (the field
    /// names of the stored JSON, nested ones as `solver.tolerance`), or an empty list when
    /// they are the same.
    pub fn differences(&self, wanted: &TaskIdentity) -> Vec<String> {
        let mut out = Vec::new();
        push_differences("", &to_map(self), &to_map(wanted), &mut out);
        out
    }
}

/// Compares two JSON objects key by key, descending into objects present on both sides; a
/// key on one side only is a difference with `null` on the other.
fn push_differences(
    prefix: &str,
    stored: &serde_json::Map<String, serde_json::Value>,
    wanted: &serde_json::Map<String, serde_json::Value>,
    out: &mut Vec<String>,
) {
    for (key, value) in stored {
        let other = wanted.get(key).unwrap_or(&serde_json::Value::Null);
        if value == other {
            continue;
        }
        let name = format!("{prefix}{key}");
        match (value, other) {
            (serde_json::Value::Object(a), serde_json::Value::Object(b)) => {
                push_differences(&format!("{name}."), a, b, out)
            }
            _ => out.push(format!(
                "{name}: stored {}, wanted {}",
                short(value),
                short(other)
            )),
        }
    }
    for (key, value) in wanted.iter().filter(|(key, _)| !stored.contains_key(*key)) {
        out.push(format!(
            "{prefix}{key}: stored {}, wanted {}",
            short(&serde_json::Value::Null),
            short(value)
        ));
    }
}

fn to_map(id: &TaskIdentity) -> serde_json::Map<String, serde_json::Value> {
    match serde_json::to_value(id) {
        Ok(serde_json::Value::Object(map)) => map,
        _ => serde_json::Map::new(),
    }
}

/// A JSON value in at most 60 characters.
fn short(value: &serde_json::Value) -> String {
    let text = value.to_string();
    if text.chars().count() <= 60 {
        text
    } else {
        format!("{}…", text.chars().take(60).collect::<String>())
    }
}

pub use crate::io::fnv1a64;

/// The file: format tag, checksum, and the hashed part (identity and content).
#[derive(Serialize, Deserialize)]
struct Sealed<T> {
    format: String,
    checksum: String,
    identity: TaskIdentity,
    content: T,
}

/// The checksum of the canonical bytes: the compact JSON of `[identity, content]`.
fn checksum_of<T: Serialize>(identity: &TaskIdentity, content: &T) -> Result<String, String> {
    let bytes = serde_json::to_vec(&(identity, content)).map_err(|e| e.to_string())?;
    Ok(format!("fnv1a64:{:016x}", fnv1a64(&bytes)))
}

/// The bytes of a sealed file holding `content` produced by `identity`.
pub fn seal<T: Serialize>(identity: &TaskIdentity, content: T) -> Result<Vec<u8>, String> {
    let checksum = checksum_of(identity, &content)?;
    serde_json::to_vec(&Sealed {
        format: CHECKPOINT_FORMAT.into(),
        checksum,
        identity: identity.clone(),
        content,
    })
    .map_err(|e| e.to_string())
}

/// Why a sealed file cannot be used.
#[derive(Debug, Clone, PartialEq)]
pub enum Unsealed {
    /// Not a sealed file of this format (unparseable, truncated, or an older format).
    Corrupt(String),
    /// The content does not match its checksum (edited or damaged).
    Checksum,
    /// Produced by another task or setting; the differences, one item per field.
    Foreign(Vec<String>),
}

/// Reads a sealed file: its content if intact and produced by `wanted`.
pub fn unseal<T>(bytes: &[u8], wanted: &TaskIdentity) -> Result<T, Unsealed>
where
    T: Serialize + for<'de> Deserialize<'de>,
{
    let format = serde_json::from_slice::<FormatOnly>(bytes)
        .map_err(|e| Unsealed::Corrupt(crate::input::one_line(&e.to_string())))?
        .format;
    if format.as_deref() != Some(CHECKPOINT_FORMAT) {
        return Err(Unsealed::Corrupt(
            "written by an older asperity, without identity or checksum".into(),
        ));
    }
    let sealed: Sealed<T> = serde_json::from_slice(bytes)
        .map_err(|e| Unsealed::Corrupt(crate::input::one_line(&e.to_string())))?;
    let checksum = checksum_of(&sealed.identity, &sealed.content).ok();
    if checksum.as_deref() != Some(sealed.checksum.as_str()) {
        return Err(Unsealed::Checksum);
    }
    let differences = sealed.identity.differences(wanted);
    if !differences.is_empty() {
        return Err(Unsealed::Foreign(differences));
    }
    Ok(sealed.content)
}

#[derive(Deserialize)]
struct FormatOnly {
    format: Option<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a64_matches_the_published_test_vectors() {
        // From the FNV reference test suite (Landon Curt Noll's fnv test vectors).
        assert_eq!(fnv1a64(b""), 0xcbf29ce484222325);
        assert_eq!(fnv1a64(b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x85944171f73967e8);
    }

    fn identity() -> TaskIdentity {
        let spec = StudySpec {
            method: Method::Bem,
            sizes: vec![16],
            hursts: vec![0.5],
            samples: 2,
            rolloff: Some(2.0),
            seed: 11,
            window: FitWindow::default(),
            levels: 10,
            sweep_end: None,
            poisson: None,
            tangential: Default::default(),
        };
        TaskIdentity::of(&spec, Task { n: 16, hurst: 0.5 })
    }

    #[test]
    fn a_poisson_ratio_is_part_of_the_identity_and_none_leaves_it_as_before() {
        // Without one the identity has no `poisson` key: older checkpoints keep their
        // checksums. With one, a study of another ν (or none) is another study.
        let plain = identity();
        let text = serde_json::to_string(&plain).unwrap();
        assert!(!text.contains("poisson"), "{text}");
        let spec = StudySpec {
            method: Method::Bem,
            sizes: vec![16],
            hursts: vec![0.5],
            samples: 2,
            rolloff: Some(2.0),
            seed: 11,
            window: FitWindow::default(),
            levels: 10,
            sweep_end: None,
            poisson: Some(0.3),
            tangential: Default::default(),
        };
        let with = TaskIdentity::of(&spec, Task { n: 16, hurst: 0.5 });
        let differences = with.differences(&plain);
        assert_eq!(differences.len(), 1, "{differences:?}");
        assert!(differences[0].starts_with("poisson"), "{differences:?}");
    }

    /// Inputs tried by the property test below.
    const FUZZ_CASES: u32 = 2000;

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: FUZZ_CASES, failure_persistence: None, ..Default::default() })]

        /// A sealed checkpoint with one byte changed, bytes cut off or inserted is either
        /// refused (one line) or, where the change left its content intact (whitespace),
        /// read back as the very values sealed.
        #[test]
        fn mutated_checkpoints_are_refused_or_intact(
            values in proptest::collection::vec(-1e6f64..1e6, 1..20),
            at in 0usize..100_000,
            byte in proptest::prelude::any::<u8>(),
            mode in 0u8..3,
        ) {
            let id = identity();
            let mut bytes = seal(&id, &values).unwrap();
            let i = at % bytes.len();
            match mode {
                0 => bytes[i] = byte,
                1 => bytes.truncate(i),
                _ => bytes.insert(i, byte),
            }
            match unseal::<Vec<f64>>(&bytes, &id) {
                Ok(read) => proptest::prop_assert_eq!(read, values),
                Err(Unsealed::Corrupt(why)) => proptest::prop_assert!(!why.contains('\n')),
                Err(_) => {}
            }
        }
    }

    #[test]
    fn other_identities_are_named_field_by_field() {
        let id = identity();
        let bytes = seal(&id, 1.5f64).unwrap();
        let mut other = id.clone();
        other.seed = 12;
        other.numerics = "asperity 9.9.9".into();
        match unseal::<f64>(&bytes, &other) {
            Err(Unsealed::Foreign(d)) => {
                assert_eq!(d.len(), 2, "{d:?}");
                assert!(
                    d.contains(&"seed: stored 11, wanted 12".to_string()),
                    "{d:?}"
                );
                assert!(d[0].starts_with("numerics: stored \"asperity "), "{d:?}");
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(unseal::<f64>(&bytes, &id).unwrap(), 1.5);
    }

    #[test]
    fn a_checkpoint_without_a_newer_setting_is_foreign_not_damaged() {
        // Checkpoints written before `stiffness_error` existed (the frozen-set CG stopped on
        // its residual only) lack the field: their checksum still holds, and they are
        // refused for the setting, by name.
        let mut old = identity();
        old.solver.as_mut().unwrap().stiffness_error = None;
        let bytes = seal(&old, 1.5f64).unwrap();
        assert!(!String::from_utf8_lossy(&bytes).contains("stiffness_error"));
        let id = identity();
        match unseal::<f64>(&bytes, &id) {
            Err(Unsealed::Foreign(d)) => {
                assert_eq!(
                    d,
                    ["solver.stiffness_error: stored null, wanted 1e-12"],
                    "{d:?}"
                );
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(unseal::<f64>(&bytes, &old).unwrap(), 1.5);
    }

    #[test]
    fn a_checkpoint_of_another_solver_is_foreign() {
        let id = identity();
        assert_eq!(id.solver.as_ref().unwrap().solver, "bccg");
        let bytes = seal(&id, 1.5f64).unwrap();
        let mut other = id.clone();
        other.solver.as_mut().unwrap().solver = "pk".into();
        match unseal::<f64>(&bytes, &other) {
            Err(Unsealed::Foreign(d)) => {
                assert_eq!(d.len(), 1, "{d:?}");
                assert_eq!(d[0], "solver.solver: stored \"bccg\", wanted \"pk\"");
            }
            other => panic!("{other:?}"),
        }
    }
}
