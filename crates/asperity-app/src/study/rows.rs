//! The result tables of a study, defined once: the rows of `alpha.csv` and `curve.csv`
//! that the CLI writes and that Python returns as columns.

use asperity::bem::conductance::Transport;
use asperity::study::theory::alpha_theory;
use asperity::study::{Scales, TaskResult};
use serde::Serialize;

/// What a column holds (how a front end stores it: text, an integer, a float).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ColumnType {
    /// A name (`method`).
    Text,
    /// A count or a size (`n`, `samples`).
    Count,
    /// A number; a missing one is an empty CSV cell and a NaN in Python's columns.
    Number,
}

/// One cell of a row.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Cell {
    /// A name.
    Text(&'static str),
    /// A count.
    Count(usize),
    /// A number, or none (no fit, no interval).
    Number(Option<f64>),
}

/// A table of results: the columns, named and typed, and the rows of cells.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Table {
    /// `(name, type)` of each column, in order.
    pub columns: Vec<(&'static str, ColumnType)>,
    /// The rows, each a cell per column.
    pub rows: Vec<Vec<Cell>>,
}

use ColumnType::{Count, Number, Text};

/// The columns of `alpha.csv`: the contract columns first, then the extras.
pub const ALPHA_COLUMNS: &[(&str, ColumnType)] = &[
    ("method", Text),
    ("n", Count),
    ("hurst", Number),
    ("alpha", Number),
    ("alpha_low", Number),
    ("alpha_high", Number),
    ("samples", Count),
    ("alpha_fit_low", Number),
    ("alpha_fit_high", Number),
    ("alpha_sample_mean", Number),
    ("samples_fitted", Count),
    ("alpha_theory", Number),
];

/// The columns of `curve.csv`.
pub const CURVE_COLUMNS: &[(&str, ColumnType)] = &[
    ("method", Text),
    ("n", Count),
    ("hurst", Number),
    ("force", Number),
    ("stiffness", Number),
    ("stiffness_low", Number),
    ("stiffness_high", Number),
    ("samples", Count),
    ("area_fraction", Number),
    ("area_fraction_low", Number),
    ("area_fraction_high", Number),
];

/// The columns of `comparison.csv` ([`asperity::study::compare::Row`], in its order): the
/// CLI's header and the names and types of Python's `StudyResult.comparison()`.
pub const COMPARISON_COLUMNS: &[(&str, ColumnType)] = &[
    ("method", Text),
    ("n", Count),
    ("hurst", Number),
    ("quantity", Text),
    ("ours", Number),
    ("low", Number),
    ("high", Number),
    ("reference", Number),
    ("source", Text),
    ("tolerance", Number),
];

/// `alpha.csv`: per task, α fitted on the ensemble-mean curve (`alpha`), the 95 %
/// interval of the per-sample α (`alpha_low`, `alpha_high`), the fit's own interval, the
/// mean of the per-sample α, how many samples had a fit and eq. (6)/(24)'s α.
pub fn alpha_table(results: &[TaskResult]) -> Table {
    let rows = results
        .iter()
        .map(|r| {
            let (low, high) = r.alpha_sample_interval().unzip();
            let fit = r.alpha_ensemble;
            vec![
                Cell::Text(r.method.name()),
                Cell::Count(r.task.n),
                Cell::Number(Some(r.task.hurst)),
                Cell::Number(fit.map(|f| f.exponent)),
                Cell::Number(low),
                Cell::Number(high),
                Cell::Count(r.samples),
                Cell::Number(fit.map(|f| f.low)),
                Cell::Number(fit.map(|f| f.high)),
                Cell::Number(r.alpha_sample_mean()),
                Cell::Count(r.alpha_samples.len()),
                Cell::Number(Some(alpha_theory(r.task.hurst, r.task.n))),
            ]
        })
        .collect();
    Table {
        columns: ALPHA_COLUMNS.to_vec(),
        rows,
    }
}

/// The columns `curve.csv` adds for a study with a Poisson's ratio
/// ([`asperity::study::StudySpec::poisson`]): the ensemble-mean `(k_x + k_y)/(2k)` with the
/// 95 % interval of the mean.
pub const TANGENTIAL_COLUMNS: &[(&str, ColumnType)] = &[
    ("tangential_ratio", Number),
    ("tangential_ratio_low", Number),
    ("tangential_ratio_high", Number),
];

/// `curve.csv`: per task and force level, the ensemble-mean stiffness with the 95 %
/// interval of the mean, the samples that reach the level and the mean contact fraction.
pub fn curve_table(results: &[TaskResult]) -> Table {
    curve_table_with(results, &Transport::default())
}

/// [`curve_table`], and where the samples have them the tangential ratio's columns
/// ([`TANGENTIAL_COLUMNS`]), and for the bodies of `transport` the conductances by
/// Barber's analogy with their intervals (`electrical_conductance`, `…_low`, `…_high`,
/// then the thermal ones; [`conductance_factors`]): the stiffness's columns times
/// `2/(E*(ρ₁+ρ₂))` or `(2/E*)κ₁κ₂/(κ₁+κ₂)`, with the study's E* = 1.
pub fn curve_table_with(results: &[TaskResult], transport: &Transport) -> Table {
    let tangential = has_tangential(results);
    let rows = results
        .iter()
        .flat_map(|r| {
            let conductances = conductance_factors(transport, Scales::of(r.method).modulus);
            r.mean_curve.iter().map(move |p| {
                let mut row = vec![
                    Cell::Text(r.method.name()),
                    Cell::Count(r.task.n),
                    Cell::Number(Some(r.task.hurst)),
                    Cell::Number(Some(p.force)),
                    Cell::Number(Some(p.stiffness)),
                    Cell::Number(Some(p.stiffness_low)),
                    Cell::Number(Some(p.stiffness_high)),
                    Cell::Count(p.samples),
                    Cell::Number(Some(p.fraction)),
                    // Unknown (NaN) in a checkpoint older than the interval: no number.
                    Cell::Number(Some(p.fraction_low).filter(|v| v.is_finite())),
                    Cell::Number(Some(p.fraction_high).filter(|v| v.is_finite())),
                ];
                if tangential {
                    let t = p.tangential_ratio;
                    row.extend(
                        [t.map(|t| t.mean), t.map(|t| t.low), t.map(|t| t.high)].map(Cell::Number),
                    );
                }
                for (_, factor) in &conductances {
                    let k = [p.stiffness, p.stiffness_low, p.stiffness_high];
                    row.extend(k.map(|k| Cell::Number(Some(factor * k))));
                }
                row
            })
        })
        .collect();
    let mut columns = CURVE_COLUMNS.to_vec();
    if tangential {
        columns.extend_from_slice(TANGENTIAL_COLUMNS);
    }
    for (names, _) in conductance_factors(transport, 1.0) {
        columns.extend(names.iter().map(|&name| (name, Number)));
    }
    Table { columns, rows }
}

/// Whether any task's curve has the tangential ratio.
pub fn has_tangential(results: &[TaskResult]) -> bool {
    let mut points = results.iter().flat_map(|r| &r.mean_curve);
    points.any(|p| p.tangential_ratio.is_some())
}

/// The conductance columns of `transport` with the factor each applies to the stiffness
/// on a half-space of effective modulus `modulus` (the study's, [`Scales`]): electrical,
/// then thermal.
pub fn conductance_factors(transport: &Transport, modulus: f64) -> Vec<([&'static str; 3], f64)> {
    let mut out = Vec::new();
    if let Some(c) = transport.electrical(1.0, modulus) {
        let names = [
            "electrical_conductance",
            "electrical_conductance_low",
            "electrical_conductance_high",
        ];
        out.push((names, c));
    }
    if let Some(c) = transport.thermal(1.0, modulus) {
        let names = [
            "thermal_conductance",
            "thermal_conductance_low",
            "thermal_conductance_high",
        ];
        out.push((names, c));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use asperity::fit::PowerLawFit;
    use asperity::study::{EnsemblePoint, Method, Task};

    fn result(fit: Option<PowerLawFit>, alpha_samples: Vec<f64>) -> TaskResult {
        let point = EnsemblePoint {
            force: 2.0,
            stiffness: 3.0,
            stiffness_low: 2.5,
            stiffness_high: 3.5,
            fraction: 0.1,
            fraction_low: 0.08,
            fraction_high: 0.12,
            samples: 4,
            tangential_ratio: None,
        };
        TaskResult {
            method: Method::Bem,
            task: Task { n: 64, hurst: 0.5 },
            samples: 4,
            mean_curve: vec![point; 3],
            alpha_ensemble: fit,
            alpha_samples,
        }
    }

    #[test]
    fn every_row_has_a_cell_of_its_columns_type() {
        let fit = PowerLawFit {
            exponent: 0.6,
            low: 0.55,
            high: 0.65,
            prefactor: 1.0,
            stderr: 0.02,
            points: 9,
        };
        let results = [result(Some(fit), vec![0.5, 0.6, 0.7]), result(None, vec![])];
        for table in [alpha_table(&results), curve_table(&results)] {
            for row in &table.rows {
                assert_eq!(row.len(), table.columns.len());
                for (cell, (name, kind)) in row.iter().zip(table.columns.iter()) {
                    let matches = matches!(
                        (cell, kind),
                        (Cell::Text(_), Text) | (Cell::Count(_), Count) | (Cell::Number(_), Number)
                    );
                    assert!(matches, "{name}: {cell:?}");
                }
            }
        }
        let alpha = alpha_table(&results);
        assert_eq!(alpha.rows[0][3], Cell::Number(Some(0.6)));
        assert_eq!(alpha.rows[0][10], Cell::Count(3));
        // No fit: no α, no interval, no mean; the theory is still there.
        assert_eq!(alpha.rows[1][3], Cell::Number(None));
        assert_eq!(alpha.rows[1][4], Cell::Number(None));
        assert!(matches!(alpha.rows[1][11], Cell::Number(Some(_))));
        assert_eq!(curve_table(&results).rows.len(), 6);
        // Python reads the cells as JSON: a missing number is null.
        let json = serde_json::to_string(&alpha.rows[1][..5]).unwrap();
        assert_eq!(json, r#"["bem",64,0.5,null,null]"#);
    }

    #[test]
    fn curve_rows_add_the_tangential_ratio_and_the_conductances() {
        let mut with = result(None, vec![]);
        for p in &mut with.mean_curve {
            p.tangential_ratio = Some(asperity::study::MeanInterval {
                mean: 0.824,
                low: 0.823,
                high: 0.825,
            });
        }
        let transport = Transport::new(Some([1.0, 3.0]), Some([2.0, 2.0])).unwrap();
        let table = curve_table_with(std::slice::from_ref(&with), &transport);
        let names: Vec<&str> = table.columns.iter().map(|c| c.0).collect();
        assert_eq!(
            names[CURVE_COLUMNS.len()..],
            [
                "tangential_ratio",
                "tangential_ratio_low",
                "tangential_ratio_high",
                "electrical_conductance",
                "electrical_conductance_low",
                "electrical_conductance_high",
                "thermal_conductance",
                "thermal_conductance_low",
                "thermal_conductance_high"
            ]
        );
        // E* = 1: electrical 2k/(1 + 3) = k/2, thermal 2k·(2·2/4) = 2k, for k and its ends.
        let n = CURVE_COLUMNS.len();
        let row = &table.rows[0];
        assert_eq!(row[n], Cell::Number(Some(0.824)));
        let expected = [1.5, 1.25, 1.75, 6.0, 5.0, 7.0];
        for (cell, e) in row[n + 3..].iter().zip(expected) {
            assert_eq!(*cell, Cell::Number(Some(e)));
        }
        // Without the ratio or the properties: the columns of before.
        let plain = curve_table_with(&[result(None, vec![])], &Transport::default());
        assert_eq!(plain.columns, CURVE_COLUMNS.to_vec());
    }

    #[test]
    fn the_comparison_columns_are_the_rows_fields_in_order() {
        let row = asperity::study::compare::Row {
            method: "bem".into(),
            n: 64.0,
            hurst: 0.5,
            quantity: "alpha".into(),
            ours: 0.9,
            low: 0.8,
            high: 1.0,
            reference: 0.95,
            source: "eq. (6)".into(),
            tolerance: 0.0,
        };
        let text = serde_json::to_string(&row).unwrap();
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(value.as_object().unwrap().len(), COMPARISON_COLUMNS.len());
        let mut at = 0;
        for (name, kind) in COMPARISON_COLUMNS {
            let key = format!("\"{name}\":");
            let found = text[at..]
                .find(&key)
                .unwrap_or_else(|| panic!("{name} in order"));
            at += found + key.len();
            assert_eq!(value[name].is_string(), *kind == Text, "{name}");
        }
    }
}
