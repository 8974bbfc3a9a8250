//! `asperity persson` and Python's `persson()`: Persson's theory from a surface's own PSD
//! (the library's [`asperity::persson`], docs/persson.md) by one path for both front ends —
//! the request's rules, the pressures, the table's columns and its rows.

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
}
