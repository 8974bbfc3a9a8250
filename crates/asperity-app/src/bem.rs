//! `asperity bem` and Python's `Solver`: the solver's options ([`SolverRequest`]), the loads
//! of a sweep ([`Loads`]) and the whole request ([`BemRequest`]), each validated once.

use asperity::bem::sweep::SweepParams;
use asperity::bem::{ContactSolver, Control, HalfSpace, SolverKind, SolverParams};
use asperity::elastic::Boundary;
use asperity::fit::log_levels;
use asperity::input::short_number;
use asperity::memory::{array_bytes, ensure_fits};
use serde::{Deserialize, Serialize};

use crate::derived::Derived;
use crate::refusal::{Param, Refusal, RequestError};

/// The parameters of `asperity bem` and Python's `Solver`, as each front end names them.
pub mod params {
    use crate::refusal::Param;

    /// Total forces.
    pub const FORCES: Param = Param::new("--forces", "forces");
    /// Mean pressures.
    pub const PRESSURES: Param = Param::new("--pressures", "pressures");
    /// Indentations.
    pub const INDENTATIONS: Param = Param::new("--indentations", "indentations");
    /// The number of log-spaced mean pressures.
    pub const NLOADS: Param = Param::new("--nloads", "nloads");
    /// The smallest of them.
    pub const PMIN: Param = Param::new("--pmin", "pmin");
    /// The largest of them.
    pub const PMAX: Param = Param::new("--pmax", "pmax");
    /// E*.
    pub const MODULUS: Param = Param::new("--modulus", "modulus");
    /// Free or periodic.
    pub const BOUNDARY: Param = Param::new("--boundary", "boundary");
    /// The iteration.
    pub const SOLVER: Param = Param::new("--solver", "solver");
    /// The convergence tolerance.
    pub const TOL: Param = Param::new("--tol", "tolerance");
    /// The iteration limit.
    pub const MAX_ITER: Param = Param::new("--max-iter", "max_iterations");
    /// The finite-difference stiffness.
    pub const FD_STIFFNESS: Param = Param::new("--fd-stiffness", "fd_stiffness");
    /// Its relative step (the CLI's is [`super::FD_STEP`]).
    pub const STEP: Param = Param::new("--fd-step", "fd_step");
}

use params::*;

/// The largest tolerance: a relative residual of 1e-2 (gaps on the contact set of 1 % of the
/// rms height) is already far coarser than any use of the results; at 1 and above the
/// criterion means nothing. One rule for every front end and command.
pub const MAX_TOLERANCE: f64 = 1e-2;

/// The relative step of the finite-difference stiffness: the load × (1 ± FD_STEP).
pub const FD_STEP: f64 = 1e-3;

/// Memory kept per load besides the solver (control, row, CSV cells, JSON record), and with
/// the fields kept, per load also (two field paths, their staged entries): generous.
const BYTES_PER_LOAD: usize = 1024;
const BYTES_PER_FIELD_LOAD: usize = 2048;

/// The memory of the per-load bookkeeping of `loads` loads (with their fields' paths).
pub fn bookkeeping_bytes(loads: usize, fields: bool) -> Option<u64> {
    let per_load = BYTES_PER_LOAD + if fields { BYTES_PER_FIELD_LOAD } else { 0 };
    array_bytes(&[loads], per_load)
}

/// Checks a tolerance: in `(0, MAX_TOLERANCE]`.
pub fn check_tolerance(tolerance: f64) -> Result<(), Refusal> {
    if tolerance > 0.0 && tolerance <= MAX_TOLERANCE {
        return Ok(());
    }
    Err(Refusal::of(TOL).text(format!(
        " must be positive and at most {MAX_TOLERANCE:e} (a relative residual), got {}",
        short_number(tolerance)
    )))
}

/// Checks a modulus (E*): positive and finite.
pub fn check_modulus(param: Param, modulus: f64) -> Result<(), Refusal> {
    if modulus.is_finite() && modulus > 0.0 {
        return Ok(());
    }
    Err(Refusal::of(param).text(format!(" must be positive and finite, got {modulus}")))
}

/// Parses the boundary conditions: `free` or `periodic`.
pub fn parse_boundary(name: &str) -> Result<Boundary, Refusal> {
    name.parse().map_err(|_| {
        Refusal::of(BOUNDARY).text(format!(
            " must be \"free\" (the default) or \"periodic\", got {name:?}"
        ))
    })
}

/// Parses the solver's name: `bccg` (`default` is kept as its alias, the name Python's
/// first release documented) or `pk` (Polonsky–Keer).
pub fn parse_solver(name: &str) -> Result<SolverKind, Refusal> {
    match name {
        "bccg" | "default" => Ok(SolverKind::Bccg),
        "pk" => Ok(SolverKind::PolonskyKeer),
        other => Err(Refusal::of(SOLVER).text(format!(
            " must be \"bccg\" (the default) or \"pk\" (Polonsky–Keer), got {other:?}"
        ))),
    }
}

/// The solver of a BEM request: the half-space and the iteration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolverRequest {
    /// E*.
    pub modulus: f64,
    /// `free` or `periodic`.
    pub boundary: String,
    /// `bccg` or `pk`.
    pub solver: String,
    /// Rms gap violation on the contact set over the rms height.
    pub tolerance: f64,
    /// Iterations per solve.
    pub max_iterations: usize,
}

impl Default for SolverRequest {
    /// E* = 1, free boundaries, the library's solver and its tolerance and iteration limit.
    fn default() -> Self {
        let params = SolverParams::default();
        SolverRequest {
            modulus: 1.0,
            boundary: "free".into(),
            solver: params.solver.name().into(),
            tolerance: params.tolerance,
            max_iterations: params.max_iterations,
        }
    }
}

impl SolverRequest {
    /// The half-space and the solver's parameters, or why not.
    pub fn validate(&self) -> Result<(HalfSpace, SolverParams), Refusal> {
        let boundary = parse_boundary(&self.boundary)?;
        check_modulus(MODULUS, self.modulus)?;
        let solver = parse_solver(&self.solver)?;
        check_tolerance(self.tolerance)?;
        if self.max_iterations == 0 {
            return Err(Refusal::of(MAX_ITER).text(" must be at least 1, got 0"));
        }
        let params = SolverParams {
            solver,
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            ..SolverParams::default()
        };
        let half_space = HalfSpace {
            modulus: self.modulus,
            boundary,
        };
        Ok((half_space, params))
    }
}

/// Refuses a solve of a `rows`×`cols` surface that does not fit in memory (`extra`: bytes
/// needed besides the solver).
pub fn ensure_solver_fits(
    rows: usize,
    cols: usize,
    boundary: Boundary,
    extra: Option<u64>,
) -> asperity::Result<()> {
    let bytes = ContactSolver::memory_bytes(rows, cols, boundary)
        .zip(extra)
        .and_then(|(solver, extra)| solver.checked_add(extra));
    let what = format!(
        "a BEM solve of a {rows}x{cols} surface ({} boundaries)",
        boundary.name()
    );
    ensure_fits(&what, bytes)
}

/// The loads of a sweep, as given.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Loads {
    /// Total forces (load control), > 0.
    Forces(Vec<f64>),
    /// Mean pressures over the nominal area (load control), > 0.
    Pressures(Vec<f64>),
    /// Indentations (displacement control), ≥ 0.
    Indentations(Vec<f64>),
    /// `count` mean pressures log-spaced from `min` to `max` ([`log_levels`]).
    LogPressures {
        /// How many.
        count: usize,
        /// The smallest.
        min: f64,
        /// The largest.
        max: f64,
    },
}

impl Loads {
    /// The one load specification among a front end's options, or why not: exactly one of
    /// the three lists or `nloads` (with `pmin` and `pmax`, which go with it only).
    pub fn from_options(
        forces: Option<Vec<f64>>,
        pressures: Option<Vec<f64>>,
        indentations: Option<Vec<f64>>,
        nloads: Option<usize>,
        range: (Option<f64>, Option<f64>),
    ) -> Result<Loads, Refusal> {
        let given = [
            forces.is_some(),
            pressures.is_some(),
            indentations.is_some(),
        ]
        .into_iter()
        .chain([nloads.is_some()])
        .filter(|&g| g)
        .count();
        if given != 1 {
            return Err(Refusal::saying("give one of ")
                .param(FORCES)
                .text(", ")
                .param(PRESSURES)
                .text(", ")
                .param(INDENTATIONS)
                .text(" or ")
                .param(NLOADS)
                .text(" with ")
                .param(PMIN)
                .text(" and ")
                .param(PMAX));
        }
        match (forces, pressures, indentations, nloads, range) {
            (Some(v), ..) => Ok(Loads::Forces(v)),
            (_, Some(v), ..) => Ok(Loads::Pressures(v)),
            (_, _, Some(v), ..) => Ok(Loads::Indentations(v)),
            (.., Some(count), (Some(min), Some(max))) => {
                Ok(Loads::LogPressures { count, min, max })
            }
            _ => Err(Refusal::of(NLOADS)
                .text(" needs ")
                .param(PMIN)
                .text(" and ")
                .param(PMAX)),
        }
    }

    /// How many loads.
    pub fn len(&self) -> usize {
        match self {
            Loads::Forces(v) | Loads::Pressures(v) | Loads::Indentations(v) => v.len(),
            Loads::LogPressures { count, .. } => *count,
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The loads as solver controls, in the given order, or why not. `fields`: every
    /// load's fields are kept (memory of the bookkeeping of `--nloads`).
    pub fn controls(&self, fields: bool) -> Result<Vec<Control>, RequestError> {
        let listed = |param, values: &[f64], allow_zero, control: fn(f64) -> Control| {
            check_values(param, values, allow_zero)?;
            Ok(values.iter().map(|&v| control(v)).collect())
        };
        match self {
            Loads::Forces(v) => listed(FORCES, v, false, Control::Force),
            Loads::Pressures(v) => listed(PRESSURES, v, false, Control::MeanPressure),
            Loads::Indentations(v) => listed(INDENTATIONS, v, true, Control::Indentation),
            &Loads::LogPressures { count, min, max } => Ok(log_spaced(count, min, max, fields)?
                .into_iter()
                .map(Control::MeanPressure)
                .collect()),
        }
    }

    /// The loads as the record of a run (OUT.csv.json) states them.
    pub fn record(&self) -> serde_json::Value {
        use serde_json::json;
        match self {
            Loads::Forces(v) => json!({ "quantity": "force", "values": v }),
            Loads::Pressures(v) => json!({ "quantity": "mean pressure", "values": v }),
            Loads::Indentations(v) => json!({ "quantity": "indentation", "values": v }),
            Loads::LogPressures { count, min, max } => json!({
                "quantity": "mean pressure", "nloads": count, "pmin": min,
                "pmax": max, "spacing": "logarithmic",
            }),
        }
    }
}

/// A list of loads: not empty, each finite and > 0 (or ≥ 0 with `allow_zero`).
pub fn check_values(param: Param, values: &[f64], allow_zero: bool) -> Result<(), Refusal> {
    if values.is_empty() {
        return Err(Refusal::of(param).text(": give at least one value"));
    }
    for &v in values {
        if !(v.is_finite() && (v > 0.0 || (allow_zero && v == 0.0))) {
            return Err(Refusal::of(param).text(format!(
                ": {v} is not allowed (values must be finite and {})",
                if allow_zero { ">= 0" } else { "> 0" }
            )));
        }
    }
    Ok(())
}

/// `count` mean pressures log-spaced from `min` to `max` (both included; [`log_levels`]),
/// or why not: at least one, `min` and `max` finite and > 0, `max` not below `min`, and the
/// bookkeeping of `count` loads (with `fields`, their fields' too) within memory. The rule
/// of `--nloads` for every command that takes it.
pub fn log_spaced(
    count: usize,
    min: f64,
    max: f64,
    fields: bool,
) -> Result<Vec<f64>, RequestError> {
    if count == 0 {
        return Err(Refusal::of(NLOADS)
            .text(" must be at least 1, got 0")
            .into());
    }
    check_values(PMIN, &[min], false)?;
    check_values(PMAX, &[max], false)?;
    if max < min {
        let refusal = Refusal::of(PMAX)
            .text(format!(" ({max}) must not be smaller than "))
            .param(PMIN)
            .text(format!(" ({min})"));
        return Err(refusal.into());
    }
    // `count` loads are listed (and with the fields 2·count files): check before allocating.
    let what = format!("the bookkeeping of {count} loads");
    ensure_fits(&what, bookkeeping_bytes(count, fields)).map_err(|source| {
        RequestError::Library {
            param: NLOADS,
            value: count.to_string(),
            source: Box::new(source),
        }
    })?;
    Ok(log_levels(min, max, count).collect())
}

/// Checks the relative step of the finite-difference stiffness: in `(0, 1)`.
pub fn check_fd_step(step: f64) -> Result<(), Refusal> {
    if step > 0.0 && step < 1.0 {
        return Ok(());
    }
    Err(Refusal::of(STEP).text(format!(" must lie in (0, 1), got {step}")))
}

/// A whole `asperity bem` request: the solver, the loads and what each load computes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BemRequest {
    /// The half-space and the iteration.
    pub solver: SolverRequest,
    /// The loads.
    pub loads: Loads,
    /// The frozen-set stiffness of every load.
    pub stiffness: bool,
    /// The finite-difference stiffness's relative step, or none.
    pub fd_step: Option<f64>,
    /// Every load's fields are kept (bookkeeping memory).
    pub fields: bool,
    /// Poisson's ratio of the tangential (no-slip) stiffness of every load, or none.
    #[serde(default)]
    pub poisson: Option<f64>,
    /// The two bodies' electrical resistivities (conductance by Barber's analogy).
    #[serde(default)]
    pub resistivity: Option<Vec<f64>>,
    /// The two bodies' thermal conductivities.
    #[serde(default)]
    pub thermal_conductivity: Option<Vec<f64>>,
}

impl Default for BemRequest {
    /// One mean pressure of 0.01 on the default solver, with the frozen-set stiffness.
    fn default() -> Self {
        BemRequest {
            solver: SolverRequest::default(),
            loads: Loads::Pressures(vec![0.01]),
            stiffness: true,
            fd_step: None,
            fields: false,
            poisson: None,
            resistivity: None,
            thermal_conductivity: None,
        }
    }
}

/// A validated [`BemRequest`]: what the library's sweep takes.
#[derive(Debug, Clone, PartialEq)]
pub struct BemPlan {
    /// The half-space.
    pub half_space: HalfSpace,
    /// The solver's parameters.
    pub params: SolverParams,
    /// The loads, in the given order.
    pub loads: Vec<Control>,
    /// What each load computes besides the solve.
    pub sweep: SweepParams,
    /// The tangential stiffness and the conductances asked for (their columns).
    pub derived: Derived,
}

impl BemRequest {
    /// The plan, or why not (the loads first, then the solver, then the step, then the
    /// derived columns).
    pub fn validate(&self) -> Result<BemPlan, RequestError> {
        let loads = self.loads.controls(self.fields)?;
        let (half_space, params) = self.solver.validate()?;
        if let Some(step) = self.fd_step {
            check_fd_step(step)?;
        }
        let derived =
            Derived::validate(self.poisson, &self.resistivity, &self.thermal_conductivity)?;
        Ok(BemPlan {
            half_space,
            params,
            loads,
            sweep: SweepParams {
                stiffness: self.stiffness,
                fd_step: self.fd_step,
                tangential: derived.tangential,
            },
            derived,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;

    fn refused(request: &BemRequest) -> String {
        request.validate().unwrap_err().words(Names::Flags)
    }

    #[test]
    fn tolerance_has_one_rule() {
        for tolerance in [0.0, -1e-6, 0.5, 10.0, f64::NAN, f64::INFINITY] {
            let solver = SolverRequest {
                tolerance,
                ..SolverRequest::default()
            };
            let err = solver.validate().unwrap_err().words(Names::Keywords);
            assert!(
                err.starts_with("tolerance must be positive and at most 1e-2"),
                "{tolerance}: {err}"
            );
        }
        for tolerance in [1e-300, 1e-8, 1e-2] {
            let solver = SolverRequest {
                tolerance,
                ..SolverRequest::default()
            };
            assert!(solver.validate().is_ok(), "{tolerance}");
        }
    }

    #[test]
    fn log_pressures_are_the_crates_log_levels() {
        let request = BemRequest {
            loads: Loads::LogPressures {
                count: 5,
                min: 1e-4,
                max: 1e-1,
            },
            ..BemRequest::default()
        };
        let loads: Vec<f64> = request
            .validate()
            .unwrap()
            .loads
            .iter()
            .map(|c| c.value())
            .collect();
        assert_eq!(loads, log_levels(1e-4, 1e-1, 5).collect::<Vec<_>>());
        assert_eq!((loads[0], loads[4]), (1e-4, 1e-1));
        let one = Loads::LogPressures {
            count: 1,
            min: 2.0,
            max: 3.0,
        };
        assert_eq!(
            one.controls(false).unwrap(),
            vec![Control::MeanPressure(2.0)]
        );
    }

    #[test]
    fn loads_are_refused_in_the_front_ends_words() {
        let with = |loads| BemRequest {
            loads,
            ..BemRequest::default()
        };
        assert_eq!(
            refused(&with(Loads::Forces(vec![]))),
            "--forces: give at least one value"
        );
        assert_eq!(
            refused(&with(Loads::Indentations(vec![-1.0]))),
            "--indentations: -1 is not allowed (values must be finite and >= 0)"
        );
        let reversed = Loads::LogPressures {
            count: 3,
            min: 2.0,
            max: 1.0,
        };
        assert_eq!(
            with(reversed)
                .validate()
                .unwrap_err()
                .words(Names::Keywords),
            "pmax (1) must not be smaller than pmin (2)"
        );
        let none = Loads::from_options(None, None, None, None, (None, None));
        assert!(none
            .unwrap_err()
            .to_string()
            .starts_with("give one of --forces"));
        let two = Loads::from_options(Some(vec![1.0]), Some(vec![1.0]), None, None, (None, None));
        assert!(two.is_err());
        let half = Loads::from_options(None, None, None, Some(3), (Some(1.0), None));
        assert_eq!(
            half.unwrap_err().to_string(),
            "--nloads needs --pmin and --pmax"
        );
    }

    #[test]
    fn solver_and_boundary_names() {
        let solver = |name: &str| SolverRequest {
            solver: name.into(),
            ..SolverRequest::default()
        };
        assert_eq!(
            solver("default").validate().unwrap().1.solver,
            SolverKind::Bccg
        );
        assert_eq!(
            solver("pk").validate().unwrap().1.solver,
            SolverKind::PolonskyKeer
        );
        let err = solver("cg").validate().unwrap_err().words(Names::Keywords);
        assert_eq!(
            err,
            "solver must be \"bccg\" (the default) or \"pk\" (Polonsky–Keer), got \"cg\""
        );
        let boundary = SolverRequest {
            boundary: "open".into(),
            ..SolverRequest::default()
        };
        assert!(boundary
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("--boundary must be"));
    }
}
