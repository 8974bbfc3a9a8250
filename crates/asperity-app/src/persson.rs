//! `asperity persson` and Python's `persson()`: Persson's theory from a surface's own PSD
//! (the library's [`asperity::persson`], docs/persson.md) by one path for both front ends —
//! the request's rules, the pressures, the table's columns and its rows.

use asperity::bem::ContactSolver;
use asperity::persson::{Persson, PerssonParams};
use asperity::surface::Surface;

use crate::bem::{check_values, log_spaced};
use crate::refusal::{Refusal, RequestError};

/// The parameters of `asperity persson`: the load options of `asperity bem`, by the same
/// names and rules.
pub mod params {
    pub use crate::bem::params::{NLOADS, PMAX, PMIN, PRESSURES};
}

use params::*;

/// The table's columns, in order: the CLI's CSV header and Python's field names.
/// `pressure` (mean pressure, in the unit of E*), `area_fraction` (A/A₀), `mean_gap` (ū, in
/// the surface's length unit), `stiffness_per_area` (K = −dp/dū) and `contact_stiffness`
/// (K·A₀, comparable with the BEM's stiffness).
pub const COLUMNS: [&str; 5] = [
    "pressure",
    "area_fraction",
    "mean_gap",
    "stiffness_per_area",
    "contact_stiffness",
];

/// A Persson request: the theory's parameters and the mean pressures.
#[derive(Debug, Clone, PartialEq)]
pub struct PerssonRequest {
    /// E*, γ and κ.
    pub params: PerssonParams,
    /// Mean pressures, each positive and finite.
    pub pressures: Vec<f64>,
}

impl PerssonRequest {
    /// Refuses parameters the library refuses, no pressure, or one that is not finite and
    /// positive (the rule of `asperity bem`'s `--pressures`).
    pub fn validate(&self) -> Result<(), RequestError> {
        self.params
            .validate()
            .map_err(|e| RequestError::Invalid(Box::new(e)))?;
        check_values(PRESSURES, &self.pressures, false)?;
        Ok(())
    }
}

/// The request's pressures: the `list`, or `nloads` log-spaced from `pmin` to `pmax` by
/// `asperity bem`'s rule ([`log_spaced`]); exactly one of the two ways.
pub fn pressures(
    list: Option<Vec<f64>>,
    nloads: Option<usize>,
    pmin: Option<f64>,
    pmax: Option<f64>,
) -> Result<Vec<f64>, RequestError> {
    match (list, nloads, pmin, pmax) {
        (Some(list), None, None, None) => Ok(list),
        (None, Some(count), Some(min), Some(max)) => log_spaced(count, min, max, false),
        (None, Some(_), ..) => Err(Refusal::of(NLOADS)
            .text(" needs ")
            .param(PMIN)
            .text(" and ")
            .param(PMAX)
            .into()),
        _ => Err(Refusal::saying("give ")
            .param(PRESSURES)
            .text(" or ")
            .param(NLOADS)
            .text(" with ")
            .param(PMIN)
            .text(" and ")
            .param(PMAX)
            .text(", not both")
            .into()),
    }
}

/// The theory's table for one surface.
#[derive(Debug, Clone, PartialEq)]
pub struct PerssonTable {
    /// One row per pressure, in the order of [`COLUMNS`].
    pub rows: Vec<[f64; 5]>,
    /// rms height of the surface (from its PSD).
    pub rms_height: f64,
    /// rms gradient from the PSD (`√m₂`, spectral).
    pub rms_gradient: f64,
    /// The separation scale `u₀` of the exponential law at low load.
    pub u0: f64,
}

/// Persson's predictions for `surface` at the request's pressures.
pub fn compute(surface: &Surface, request: &PerssonRequest) -> Result<PerssonTable, RequestError> {
    request.validate()?;
    let library = |e| RequestError::Invalid(Box::new(e));
    let theory = Persson::from_surface(surface, request.params).map_err(library)?;
    let rows = request
        .pressures
        .iter()
        .map(|&p| {
            theory.predict(p).map(|point| {
                [
                    point.pressure,
                    point.area_fraction,
                    point.mean_gap,
                    point.stiffness,
                    point.contact_stiffness,
                ]
            })
        })
        .collect::<asperity::Result<Vec<_>>>()
        .map_err(library)?;
    Ok(PerssonTable {
        rows,
        rms_height: theory.rms_height(),
        rms_gradient: theory.rms_gradient(),
        u0: theory.u0(),
    })
}

/// The columns `asperity bem --persson` and `Solver.sweep(persson=True)` add beside a
/// sweep, in order: the BEM's own `mean_gap` (the mean of the gap field: with periodic
/// boundaries Persson's ū, the separation of the mean planes; with free ones the mean over
/// the window, which is not), then Persson's `area_fraction_persson`, `mean_gap_persson`
/// and `stiffness_persson` (the interfacial `K·A₀`; the BEM's stiffness of free boundaries
/// also holds the bulk under the window, docs/persson.md) at each row's mean pressure.
pub const SWEEP_COLUMNS: [&str; 4] = [
    "mean_gap",
    "area_fraction_persson",
    "mean_gap_persson",
    "stiffness_persson",
];

/// Persson's theory beside a BEM sweep: γ and κ (E* is the solver's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepPersson {
    /// Yang & Persson's γ, in (0, 1].
    pub gamma: f64,
    /// The small-load area coefficient κ.
    pub kappa: f64,
}

impl Default for SweepPersson {
    /// The library's defaults (γ = 0.45, κ = √(8/π)).
    fn default() -> Self {
        let params = PerssonParams::default();
        SweepPersson {
            gamma: params.gamma,
            kappa: params.kappa,
        }
    }
}

/// `asperity bem --persson` with `--gamma` and `--kappa` (Python's `Solver.sweep(persson=,
/// gamma=, kappa=)`).
pub mod sweep_params {
    use crate::refusal::Param;

    /// Persson's theory beside the sweep.
    pub const PERSSON: Param = Param::new("--persson", "persson");
    /// γ.
    pub const GAMMA: Param = Param::new("--gamma", "gamma");
    /// κ.
    pub const KAPPA: Param = Param::new("--kappa", "kappa");
}

impl SweepPersson {
    /// The theory a sweep asks for: with `persson`, `gamma` and `kappa` as given, else the
    /// defaults; without it none, and a γ or κ given is refused (`--gamma goes with
    /// --persson`, `gamma goes with persson` in Python), the one rule of both front ends.
    ///
    /// ```
    /// use asperity_app::persson::SweepPersson;
    ///
    /// assert_eq!(SweepPersson::from_options(false, None, None).unwrap(), None);
    /// let theory = SweepPersson::from_options(true, Some(0.4), None).unwrap().unwrap();
    /// assert_eq!((theory.gamma, theory.kappa), (0.4, SweepPersson::default().kappa));
    /// let refusal = SweepPersson::from_options(false, None, Some(1.0)).unwrap_err();
    /// assert_eq!(refusal.to_string(), "--kappa goes with --persson");
    /// ```
    pub fn from_options(
        persson: bool,
        gamma: Option<f64>,
        kappa: Option<f64>,
    ) -> Result<Option<SweepPersson>, Refusal> {
        use sweep_params::{GAMMA, KAPPA, PERSSON};
        for (param, given) in [(GAMMA, gamma), (KAPPA, kappa)] {
            if given.is_some() && !persson {
                return Err(Refusal::of(param).text(" goes with ").param(PERSSON));
            }
        }
        let defaults = SweepPersson::default();
        Ok(persson.then(|| SweepPersson {
            gamma: gamma.unwrap_or(defaults.gamma),
            kappa: kappa.unwrap_or(defaults.kappa),
        }))
    }

    /// The theory's parameters on a half-space of effective modulus `modulus`, or why not
    /// (the library's rules for γ and κ), before any solve.
    pub fn params(self, modulus: f64) -> Result<PerssonParams, RequestError> {
        let params = PerssonParams {
            modulus,
            gamma: self.gamma,
            kappa: self.kappa,
        };
        params
            .validate()
            .map_err(|e| RequestError::Invalid(Box::new(e)))?;
        Ok(params)
    }
}

/// Persson's theory for the surface a BEM solver holds: from the PSD of its profile
/// `max(h) − h` (the heights' PSD, the sign aside), at the solver's E*. One path for both
/// front ends, so their columns agree bit for bit.
#[derive(Debug, Clone)]
pub struct SweepTheory(Persson);

impl SweepTheory {
    /// The theory of `solver`'s surface; refuses rectangular pixels (the radial PSD
    /// assumes square ones) and a flat surface.
    pub fn new(solver: &ContactSolver, options: SweepPersson) -> Result<Self, RequestError> {
        let problem = solver.problem();
        let params = options.params(problem.half_space().modulus)?;
        let (dx, dy) = problem.spacings();
        if dx != dy {
            return Err(Refusal::saying(
                "Persson's columns need square pixels (the radially averaged PSD assumes them)",
            )
            .into());
        }
        let (_, cols) = problem.dim();
        let library = |e| RequestError::Invalid(Box::new(e));
        let surface =
            Surface::new(problem.profile().to_owned(), dx * cols as f64).map_err(library)?;
        Ok(SweepTheory(
            Persson::from_surface(&surface, params).map_err(library)?,
        ))
    }

    /// The library's theory.
    pub fn theory(&self) -> &Persson {
        &self.0
    }

    /// Persson's three columns at `mean_pressure` (none at a pressure that is not positive:
    /// an indentation of 0).
    pub fn row(&self, mean_pressure: f64) -> Result<[Option<f64>; 3], RequestError> {
        if mean_pressure.is_nan() || mean_pressure <= 0.0 {
            return Ok([None; 3]);
        }
        let point = self
            .0
            .predict(mean_pressure)
            .map_err(|e| RequestError::Invalid(Box::new(e)))?;
        Ok([
            Some(point.area_fraction),
            Some(point.mean_gap),
            Some(point.contact_stiffness),
        ])
    }
}

/// The BEM's mean gap of the solver's current contact (the first of [`SWEEP_COLUMNS`]),
/// taken where a sweep's observer sees each load solved.
pub fn bem_mean_gap(solver: &ContactSolver) -> f64 {
    solver.gap().mean().unwrap_or(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;
    use asperity::spectrum::{LongWavelength, Psd};
    use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

    fn surface() -> Surface {
        let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 4.0 }, None).unwrap();
        let spec = SurfaceSpec::new(64, 64, 1.0, psd, Normalisation::RmsSlope(1.0)).unwrap();
        SurfaceGenerator::new(&spec).unwrap().generate(3)
    }

    #[test]
    fn the_table_is_the_library_s_predictions_row_by_row() {
        let s = surface();
        let params = PerssonParams::default();
        let request = PerssonRequest {
            params,
            pressures: vec![1e-3, 1e-2],
        };
        let table = compute(&s, &request).unwrap();
        let theory = Persson::from_surface(&s, params).unwrap();
        for (row, &p) in table.rows.iter().zip(&request.pressures) {
            let point = theory.predict(p).unwrap();
            assert_eq!(row[0], point.pressure);
            assert_eq!(row[1], point.area_fraction);
            assert_eq!(row[2], point.mean_gap);
            assert_eq!(row[3], point.stiffness);
            assert_eq!(row[4], point.contact_stiffness);
        }
        assert_eq!(table.u0, theory.u0());
    }

    #[test]
    fn bad_requests_are_refused_in_each_front_end_s_words() {
        let s = surface();
        let words = |request: PerssonRequest| {
            let e = compute(&s, &request).unwrap_err();
            (e.words(Names::Flags), e.words(Names::Keywords))
        };
        let base = PerssonRequest {
            params: PerssonParams::default(),
            pressures: vec![0.0],
        };
        let (flags, keywords) = words(base.clone());
        assert_eq!(
            flags,
            "--pressures: 0 is not allowed (values must be finite and > 0)"
        );
        assert_eq!(
            keywords,
            "pressures: 0 is not allowed (values must be finite and > 0)"
        );
        let (_, keywords) = words(PerssonRequest {
            pressures: vec![],
            ..base.clone()
        });
        assert_eq!(keywords, "pressures: give at least one value");
        let gamma = PerssonParams {
            gamma: 0.0,
            ..PerssonParams::default()
        };
        let (_, keywords) = words(PerssonRequest {
            params: gamma,
            pressures: vec![0.1],
        });
        assert!(keywords.contains("gamma"), "{keywords}");
    }

    #[test]
    fn the_pressures_are_the_list_or_bem_s_log_spaced_ones() {
        let list = pressures(Some(vec![0.1, 0.2]), None, None, None).unwrap();
        assert_eq!(list, vec![0.1, 0.2]);
        let spaced = pressures(None, Some(3), Some(1e-3), Some(1e-1)).unwrap();
        let levels: Vec<f64> = asperity::fit::log_levels(1e-3, 1e-1, 3).collect();
        assert_eq!(spaced, levels);
        assert_eq!((spaced[0], spaced[2]), (1e-3, 1e-1));
        let words = |r: Result<Vec<f64>, RequestError>| r.unwrap_err().words(Names::Keywords);
        let either = "give pressures or nloads with pmin and pmax, not both";
        assert_eq!(words(pressures(None, None, None, None)), either);
        let both = pressures(Some(vec![0.1]), Some(3), Some(1e-3), Some(1e-1));
        assert_eq!(words(both), either);
        assert_eq!(
            words(pressures(Some(vec![0.1]), None, Some(1.0), None)),
            either
        );
        assert_eq!(words(pressures(None, None, Some(1e-3), Some(1.0))), either);
        let half = pressures(None, Some(3), Some(1e-3), None).unwrap_err();
        assert_eq!(half.words(Names::Flags), "--nloads needs --pmin and --pmax");
        // The rules of bem's --nloads, word for word.
        let bem = |count, min, max| {
            let loads = crate::bem::Loads::LogPressures { count, min, max };
            loads.controls(false).unwrap_err().words(Names::Keywords)
        };
        for (count, min, max) in [
            (0, 1e-3, 1e-1),
            (3, -1.0, 1.0),
            (3, 0.1, 0.01),
            (3, 1e-3, f64::NAN),
        ] {
            let ours = words(pressures(None, Some(count), Some(min), Some(max)));
            assert_eq!(ours, bem(count, min, max));
        }
        assert_eq!(
            words(pressures(None, Some(0), Some(1.0), Some(2.0))),
            "nloads must be at least 1, got 0"
        );
    }

    fn solver(surface: &Surface, boundary: asperity::elastic::Boundary) -> ContactSolver {
        let half_space = asperity::bem::HalfSpace {
            modulus: 2.0,
            boundary,
        };
        ContactSolver::new(surface, half_space, Default::default()).unwrap()
    }

    #[test]
    fn sweep_columns_are_the_theory_of_the_solver_s_surface() {
        let s = surface();
        let options = SweepPersson {
            gamma: 0.4,
            kappa: 2.0,
        };
        let sweep =
            SweepTheory::new(&solver(&s, asperity::elastic::Boundary::Free), options).unwrap();
        // The profile max(h) − h has the heights' PSD: the theory of the surface itself,
        // to rounding (the subtraction), at the solver's E* = 2.
        let params = PerssonParams {
            modulus: 2.0,
            gamma: 0.4,
            kappa: 2.0,
        };
        let direct = Persson::from_surface(&s, params).unwrap();
        assert_eq!(sweep.theory().params(), params);
        for p in [1e-4, 1e-2, 0.3] {
            let row = sweep.row(p).unwrap();
            let point = direct.predict(p).unwrap();
            let expected = [point.area_fraction, point.mean_gap, point.contact_stiffness];
            for (got, want) in row.iter().zip(expected) {
                let got = got.unwrap();
                assert!((got - want).abs() <= 1e-12 * want.abs(), "{got} vs {want}");
            }
        }
        assert_eq!(sweep.row(0.0).unwrap(), [None; 3]);
    }

    #[test]
    fn periodic_mean_gap_is_the_mean_profile_less_the_indentation() {
        // Periodic: the displacement has zero mean, so mean(g) = mean(f) − d exactly (to
        // rounding): the BEM's ū is the separation of the mean planes, Persson's.
        let s = surface();
        let mut solver = solver(&s, asperity::elastic::Boundary::Periodic);
        let mean_f = solver.problem().profile().mean().unwrap();
        for p in [1e-3, 3e-2] {
            let (summary, _) = solver
                .solve(asperity::bem::Control::MeanPressure(p))
                .unwrap();
            let gap = bem_mean_gap(&solver);
            let expected = mean_f - summary.indentation;
            assert!(
                (gap - expected).abs() <= 1e-9 * mean_f,
                "{gap} vs {expected}"
            );
        }
    }

    #[test]
    fn sweep_persson_refuses_what_the_library_refuses() {
        let s = surface();
        let words = |options: SweepPersson| {
            SweepTheory::new(&solver(&s, asperity::elastic::Boundary::Free), options)
                .unwrap_err()
                .words(Names::Keywords)
        };
        let gamma = words(SweepPersson {
            gamma: 1.5,
            ..SweepPersson::default()
        });
        assert!(gamma.contains("γ must lie in (0, 1]"), "{gamma}");
        let kappa = words(SweepPersson {
            kappa: f64::NAN,
            ..SweepPersson::default()
        });
        assert!(kappa.contains("κ must be positive"), "{kappa}");
        let rectangular = Surface::with_sizes(s.heights().to_owned(), 1.0, 2.0).unwrap();
        let e = SweepTheory::new(
            &solver(&rectangular, asperity::elastic::Boundary::Free),
            SweepPersson::default(),
        )
        .unwrap_err();
        assert!(e.words(Names::Flags).contains("square pixels"));
    }
}
