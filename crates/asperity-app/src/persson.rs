//! `asperity persson` and Python's `persson()`: Persson's theory from a surface's own PSD
//! (the library's [`asperity::persson`], docs/persson.md) by one path for both front ends —
//! the request's rules, the pressures, the table's columns and its rows.

use asperity::persson::{Persson, PerssonParams};
use asperity::surface::Surface;

use crate::refusal::{Refusal, RequestError};

/// The parameters of `asperity persson`.
pub mod params {
    use crate::refusal::Param;

    /// The mean pressures.
    pub const PRESSURES: Param = Param::new("--pressures", "pressures");
    /// The number of log-spaced pressures.
    pub const NLOADS: Param = Param::new("--nloads", "nloads");
    /// The smallest of them.
    pub const PMIN: Param = Param::new("--pmin", "pmin");
    /// The largest of them.
    pub const PMAX: Param = Param::new("--pmax", "pmax");
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
    /// Refuses parameters the library refuses, no pressure, or one that is not positive.
    pub fn validate(&self) -> Result<(), RequestError> {
        self.params
            .validate()
            .map_err(|e| RequestError::Invalid(Box::new(e)))?;
        if self.pressures.is_empty() {
            return Err(Refusal::of(PRESSURES).text(": give at least one").into());
        }
        if let Some(p) = self
            .pressures
            .iter()
            .find(|p| !(p.is_finite() && **p > 0.0))
        {
            let text = format!(" must be positive and finite, got {p}");
            return Err(Refusal::of(PRESSURES).text(text).into());
        }
        Ok(())
    }
}

/// `count` mean pressures log-spaced from `pmin` to `pmax` (both included).
pub fn log_pressures(count: usize, pmin: f64, pmax: f64) -> Result<Vec<f64>, Refusal> {
    if count == 0 || !(pmin > 0.0 && pmax >= pmin && pmax.is_finite()) {
        return Err(Refusal::of(NLOADS)
            .text(" needs K >= 1 and 0 < ")
            .param(PMIN)
            .text(" <= ")
            .param(PMAX)
            .text(format!(", finite; got {count}, {pmin}, {pmax}")));
    }
    Ok(asperity::fit::log_levels(pmin, pmax, count).collect())
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
        assert_eq!(flags, "--pressures must be positive and finite, got 0");
        assert_eq!(keywords, "pressures must be positive and finite, got 0");
        let (_, keywords) = words(PerssonRequest {
            pressures: vec![],
            ..base.clone()
        });
        assert_eq!(keywords, "pressures: give at least one");
        let gamma = PerssonParams {
            gamma: 0.0,
            ..PerssonParams::default()
        };
        let (_, keywords) = words(PerssonRequest {
            params: gamma,
            pressures: vec![0.1],
        });
        assert!(keywords.contains("gamma"), "{keywords}");
        let refusal = log_pressures(0, 1e-3, 1e-1).unwrap_err();
        assert_eq!(
            refusal.words(Names::Keywords),
            "nloads needs K >= 1 and 0 < pmin <= pmax, finite; got 0, 0.001, 0.1"
        );
        assert_eq!(log_pressures(3, 1e-3, 1e-1).unwrap().len(), 3);
    }
}
