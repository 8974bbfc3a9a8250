//! `asperity bem` and Python's `Solver`: the solver's options ([`SolverRequest`]), the loads
//! of a sweep ([`Loads`]) and the whole request ([`BemRequest`]), each validated once.

use asperity::bem::sweep::SweepParams;
use asperity::bem::{ContactSolver, Control, HalfSpace, Interface, SolverKind, SolverParams};
use asperity::elastic::Boundary;
use asperity::fit::log_levels;
use asperity::input::short_number;
use asperity::memory::{array_bytes, ensure_fits};
use serde::{Deserialize, Serialize};

use crate::derived::Derived;
use crate::refusal::{number, Param, Refusal, RequestError};

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
    /// The hardness that caps the contact pressure (in the units of the pressures).
    pub const HARDNESS: Param = Param::new("--hardness", "hardness");
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

/// The timing columns of a sweep (`asperity bem --timing`, Python's `Solver.sweep(timing=True)`):
/// each load's solve and frozen-set stiffness in seconds and the process's peak resident
/// memory after it, then the tangential stiffness's seconds when it was asked for.
pub const TIMING_COLUMNS: [&str; 3] = ["solve_seconds", "stiffness_seconds", "peak_rss_mib"];

/// Peak resident memory of this process (MiB), from `/proc/self/status` (Linux; `None`
/// elsewhere): the `peak_rss_mib` column of a timed sweep.
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// A load's control of its value.
type LoadOf = fn(f64) -> Control;

/// The names of the loads' quantities as Python carries a load between its calls
/// (`Solver.solve`, `sweep`, `load_path`: the keywords of [`one_load`] without `=`),
/// with their controls: `pressure`, `force`, `indentation`.
const QUANTITIES: [(&str, LoadOf); 3] = [
    ("pressure", Control::MeanPressure),
    ("force", Control::Force),
    ("indentation", Control::Indentation),
];

/// The load of `value` in the quantity named `quantity` (`pressure`, `force` or
/// `indentation`: [`Loads::quantity`]'s names), refused in one wording otherwise.
///
/// ```
/// use asperity::bem::Control;
/// use asperity_app::bem::load_of;
///
/// assert_eq!(load_of("force", 0.5).unwrap(), Control::Force(0.5));
/// assert_eq!(
///     load_of("stress", 0.5).unwrap_err().to_string(),
///     "unknown load quantity \"stress\" (pressure, force or indentation)"
/// );
/// ```
pub fn load_of(quantity: &str, value: f64) -> Result<Control, Refusal> {
    match QUANTITIES.iter().find(|(name, _)| *name == quantity) {
        Some((_, control)) => Ok(control(value)),
        None => Err(Refusal::saying(format!(
            "unknown load quantity {:?} (pressure, force or indentation)",
            asperity::input::clip(quantity)
        ))),
    }
}

/// The name of the quantity of `control` ([`load_of`]'s names) and its value.
pub fn quantity_of(control: Control) -> (&'static str, f64) {
    let name = match control {
        Control::MeanPressure(_) => QUANTITIES[0].0,
        Control::Force(_) => QUANTITIES[1].0,
        Control::Indentation(_) => QUANTITIES[2].0,
    };
    (name, control.value())
}

/// The load of one solve (Python's `Solver.solve` and `Solver.fd_stiffness`; the CLI solves
/// sweeps, whose loads are [`Loads::from_options`]): exactly one of a mean `pressure`, a
/// `force` or an `indentation`; `context` (the method) begins the refusal.
///
/// ```
/// use asperity::bem::Control;
/// use asperity_app::bem::one_load;
///
/// assert_eq!(one_load("solve", None, Some(0.5), None).unwrap(), Control::Force(0.5));
/// let refusal = one_load("solve", Some(0.1), Some(0.5), None).unwrap_err();
/// assert_eq!(refusal.to_string(), "solve: give exactly one of pressure=, force= or indentation=");
/// ```
pub fn one_load(
    context: &str,
    pressure: Option<f64>,
    force: Option<f64>,
    indentation: Option<f64>,
) -> Result<Control, Refusal> {
    match (pressure, force, indentation) {
        (Some(p), None, None) => Ok(Control::MeanPressure(p)),
        (None, Some(f), None) => Ok(Control::Force(f)),
        (None, None, Some(d)) => Ok(Control::Indentation(d)),
        _ => Err(Refusal::saying(format!(
            "{context}: give exactly one of pressure=, force= or indentation="
        ))),
    }
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
    crate::refusal::positive(param, modulus).map(|_| ())
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
    /// The hardness that caps the contact pressure (elastic–perfectly-plastic contact,
    /// docs/hardness.md), in the units of E* and the pressures; none: the hard wall.
    #[serde(default)]
    pub hardness: Option<f64>,
}

impl Default for SolverRequest {
    /// E* = 1, free boundaries, the library's solver and its tolerance and iteration limit,
    /// no hardness.
    fn default() -> Self {
        let params = SolverParams::default();
        SolverRequest {
            modulus: 1.0,
            boundary: "free".into(),
            solver: params.solver.name().into(),
            tolerance: params.tolerance,
            max_iterations: params.max_iterations,
            hardness: None,
        }
    }
}

/// A validated [`SolverRequest`]: what [`ContactSolver::new`] and
/// [`ContactSolver::set_interface`] take.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverPlan {
    /// E* and the boundary conditions.
    pub half_space: HalfSpace,
    /// The iteration, its tolerance and its iteration limit.
    pub params: SolverParams,
    /// The contact law: the hard wall, or the pressure capped at the hardness.
    pub interface: Interface,
}

impl SolverPlan {
    /// The solver of this plan on `surface`, with its interface.
    pub fn solver(
        &self,
        surface: &asperity::surface::Surface,
    ) -> Result<ContactSolver, asperity::bem::SolveError> {
        ContactSolver::new(surface, self.half_space, self.params)?.with_interface(self.interface)
    }
}

impl SolverRequest {
    /// The half-space, the solver's parameters and the interface, or why not (the
    /// boundary, E*, the solver's name, the tolerance, the iteration limit, the hardness).
    pub fn validate(&self) -> Result<SolverPlan, Refusal> {
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
        Ok(SolverPlan {
            half_space,
            params,
            interface: hardness_interface(self.hardness)?,
        })
    }
}

/// The contact law of a hardness or none: the hard wall without one, else the pressure
/// capped at `h`. The rule is the library's ([`Interface::hardness`]: positive and finite),
/// the words the front ends'; one definition for `asperity bem`, `asperity contact` and
/// Python's `Solver` and `contact`.
pub fn hardness_interface(hardness: Option<f64>) -> Result<Interface, Refusal> {
    let Some(h) = hardness else {
        return Ok(Interface::HardWall);
    };
    Interface::hardness(h).map_err(|_| {
        Refusal::of(HARDNESS).text(format!(" must be positive and finite, got {}", number(h)))
    })
}

/// Refuses the loads that `interface` cannot carry: a mean pressure at or above the
/// hardness ([`Interface::check_mean_pressure`]: more than a fully plastic contact carries)
/// and, where the `nominal_area` is known, a force whose mean pressure is (without it forces
/// are left to the library's check at their solve). `unit` follows each pressure in the
/// words (`" Pa"` for `asperity contact`, empty where pressures are in the units of E*).
/// Indentations are not limited: a capped contact carries less than `H` times the nominal
/// area at any approach.
pub fn check_capped_loads(
    interface: Interface,
    loads: &[Control],
    nominal_area: Option<f64>,
    unit: &str,
) -> Result<(), Refusal> {
    let h = interface.cap();
    for &load in loads {
        let (what, mean) = match (load, nominal_area) {
            (Control::MeanPressure(p), _) => (format!("a mean pressure of {p}{unit}"), p),
            (Control::Force(f), Some(area)) => (
                format!(
                    "a force of {f} (a mean pressure of {}{unit})",
                    short_number(f / area)
                ),
                f / area,
            ),
            _ => continue,
        };
        if interface.check_mean_pressure(mean).is_err() {
            return Err(Refusal::saying(format!(
                "{what} is at or above the hardness {h}{unit}: more than a fully plastic \
                 contact can carry (lower it or raise "
            ))
            .param(HARDNESS)
            .text(")"));
        }
    }
    Ok(())
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
    /// The name of their quantity ([`load_of`]'s names): `force`, `indentation` or
    /// `pressure` (a list of mean pressures or a log-spaced one).
    pub fn quantity(&self) -> &'static str {
        let control = match self {
            Loads::Forces(_) => Control::Force(0.0),
            Loads::Indentations(_) => Control::Indentation(0.0),
            Loads::Pressures(_) | Loads::LogPressures { .. } => Control::MeanPressure(0.0),
        };
        quantity_of(control).0
    }

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
    Err(Refusal::of(STEP).text(format!(" must lie in (0, 1), got {}", number(step))))
}

/// The columns of a load path's table (`asperity bem --load-path`, Python's
/// `Solver.load_path`), one row per step ([`asperity::bem::PathPoint`]): its [`Branch`],
/// the solved scalars, the frozen-set stiffness (on the elastic set under a hardness), the
/// solve's iterations and the largest permanent displacement so far.
pub const PATH_COLUMNS: [&str; 9] = [
    "branch",
    "force",
    "mean_pressure",
    "indentation",
    "area_fraction",
    "plastic_fraction",
    "stiffness",
    "iterations",
    "permanent_max",
];

/// Which way a step of a load path goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Branch {
    /// Beyond every earlier load (the first step too): the surface may yield.
    Loading,
    /// Below the step before: elastic on the flattened surface.
    Unloading,
    /// Above the step before but not beyond the largest earlier load: elastic.
    Reloading,
}

impl Branch {
    /// `loading`, `unloading` or `reloading`, as the tables write it.
    pub fn name(self) -> &'static str {
        match self {
            Branch::Loading => "loading",
            Branch::Unloading => "unloading",
            Branch::Reloading => "reloading",
        }
    }
}

/// The branch of each step of a path of `values` (loads or indentations, in order).
pub fn branches(values: &[f64]) -> Vec<Branch> {
    let mut largest = f64::NEG_INFINITY;
    let mut previous = f64::NEG_INFINITY;
    values
        .iter()
        .map(|&v| {
            let branch = if v > largest {
                Branch::Loading
            } else if v < previous {
                Branch::Unloading
            } else {
                Branch::Reloading
            };
            largest = largest.max(v);
            previous = v;
            branch
        })
        .collect()
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
    /// Which tangential stiffnesses with `poisson`: `x`, `y` or `both` (none: both).
    #[serde(default)]
    pub tangential: Option<String>,
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
            tangential: None,
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
    /// The contact law: the hard wall, or the pressure capped at the hardness.
    pub interface: Interface,
}

impl BemPlan {
    /// The plan's solver on `surface`, with its interface.
    pub fn solver(
        &self,
        surface: &asperity::surface::Surface,
    ) -> Result<ContactSolver, asperity::bem::SolveError> {
        ContactSolver::new(surface, self.half_space, self.params)?.with_interface(self.interface)
    }

    /// Refuses the forces the hardness cannot carry over the surface's `nominal_area`
    /// ([`check_capped_loads`]; the mean pressures were checked by
    /// [`BemRequest::validate`]), before any solve.
    pub fn check_forces(&self, nominal_area: f64) -> Result<(), Refusal> {
        check_capped_loads(self.interface, &self.loads, Some(nominal_area), "")
    }

    /// The hardness where the pressure is capped (the plastic column, the record's
    /// hardness), else none.
    pub fn hardness(&self) -> Option<f64> {
        match self.interface {
            Interface::Hardness { h } => Some(h),
            _ => None,
        }
    }
}

impl BemRequest {
    /// The plan, or why not (the loads first, then the solver with its hardness, then the
    /// step, then the derived columns, then the mean pressures against the hardness).
    pub fn validate(&self) -> Result<BemPlan, RequestError> {
        let loads = self.loads.controls(self.fields)?;
        let SolverPlan {
            half_space,
            params,
            interface,
        } = self.solver.validate()?;
        if let Some(step) = self.fd_step {
            check_fd_step(step)?;
        }
        let derived = Derived::validate(
            self.poisson,
            self.tangential.as_deref(),
            &self.resistivity,
            &self.thermal_conductivity,
        )?;
        check_capped_loads(interface, &loads, None, "")?;
        Ok(BemPlan {
            half_space,
            params,
            interface,
            loads,
            sweep: SweepParams {
                stiffness: self.stiffness,
                fd_step: self.fd_step,
                tangential: derived.tangential,
                directions: derived.directions,
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
    fn a_hardness_is_one_rule_for_every_front_end() {
        let capped = |hardness, loads| BemRequest {
            solver: SolverRequest {
                hardness: Some(hardness),
                ..SolverRequest::default()
            },
            loads,
            ..BemRequest::default()
        };
        // The plan carries the library's interface; forces wait for the nominal area.
        let plan = capped(0.3, Loads::Forces(vec![0.1, 0.5]))
            .validate()
            .unwrap();
        assert_eq!(plan.interface, Interface::Hardness { h: 0.3 });
        assert_eq!(plan.hardness(), Some(0.3));
        assert!(plan.check_forces(2.0).is_ok());
        assert_eq!(
            plan.check_forces(1.0).unwrap_err().words(Names::Keywords),
            "a force of 0.5 (a mean pressure of 0.5) is at or above the hardness 0.3: more \
             than a fully plastic contact can carry (lower it or raise hardness)"
        );
        let words = refused(&capped(0.3, Loads::Pressures(vec![0.01, 0.3])));
        assert_eq!(
            words,
            "a mean pressure of 0.3 is at or above the hardness 0.3: more than a fully \
             plastic contact can carry (lower it or raise --hardness)"
        );
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let words = refused(&capped(bad, Loads::Pressures(vec![0.01])));
            assert_eq!(
                words,
                format!(
                    "--hardness must be positive and finite, got {}",
                    number(bad)
                )
            );
        }
        // Indentations are not limited; no hardness is the hard wall.
        assert!(capped(0.3, Loads::Indentations(vec![10.0]))
            .validate()
            .is_ok());
        let plan = BemRequest::default().validate().unwrap();
        assert_eq!(
            (plan.interface, plan.hardness()),
            (Interface::HardWall, None)
        );
    }

    #[test]
    fn a_path_names_its_branches() {
        let names: Vec<&str> = branches(&[0.01, 0.04, 0.02, 0.01, 0.03, 0.04, 0.05, 0.05])
            .into_iter()
            .map(Branch::name)
            .collect();
        assert_eq!(
            names,
            [
                "loading",
                "loading",
                "unloading",
                "unloading",
                "reloading",
                "reloading",
                "loading",
                "reloading"
            ]
        );
    }

    #[test]
    fn solver_and_boundary_names() {
        let solver = |name: &str| SolverRequest {
            solver: name.into(),
            ..SolverRequest::default()
        };
        assert_eq!(
            solver("default").validate().unwrap().params.solver,
            SolverKind::Bccg
        );
        assert_eq!(
            solver("pk").validate().unwrap().params.solver,
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
