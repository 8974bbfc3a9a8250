//! The figures of a contact sweep in SI units (`asperity contact --plot`,
//! `asperity.plot.stiffness` and `asperity.plot.area` of an `asperity.contact` sweep):
//! stiffness, true contact area and mean gap against the force, log–log.

use super::{Chart, Series, Style};

/// The sweep's columns the figure draws, one value per load.
#[derive(Debug, Clone, Copy)]
pub struct ContactColumns<'a> {
    /// Normal force F, N.
    pub force: &'a [f64],
    /// Frozen-set stiffness k, N/m.
    pub stiffness: &'a [f64],
    /// True contact area A, m².
    pub area: &'a [f64],
    /// Mean gap over the nominal area, m.
    pub mean_gap: &'a [f64],
}

/// The three panels: k(F) (the title names E*), A(F) and the mean gap against F. `name`:
/// the surface's name in the titles (its file name); `modulus`: E* in Pa.
pub fn contact_charts(columns: ContactColumns<'_>, name: &str, modulus: f64) -> [Chart; 3] {
    let chart = |title: String, y_label: &str, y: &[f64]| Chart {
        title,
        x_label: "normal force F  [N]".into(),
        y_label: y_label.into(),
        log_x: true,
        log_y: true,
        series: vec![Series::new(
            "",
            columns
                .force
                .iter()
                .copied()
                .zip(y.iter().copied())
                .collect(),
            Style::LinePoints,
        )],
    };
    [
        chart(
            format!("{name}: contact stiffness (E* = {modulus:.3e} Pa)"),
            "stiffness k  [N/m]",
            columns.stiffness,
        ),
        chart(
            format!("{name}: true contact area"),
            "contact area A  [m²]",
            columns.area,
        ),
        chart(
            format!("{name}: mean gap"),
            "mean gap  [m]",
            columns.mean_gap,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_log_log_panels_of_the_columns_against_force() {
        let columns = ContactColumns {
            force: &[1.0, 2.0],
            stiffness: &[10.0, 20.0],
            area: &[1e-9, 3e-9],
            mean_gap: &[2e-6, 1e-6],
        };
        let charts = contact_charts(columns, "scan.x3p", 1.1538e11);
        assert_eq!(
            charts[0].title,
            "scan.x3p: contact stiffness (E* = 1.154e11 Pa)"
        );
        let drawn: Vec<_> = charts.iter().map(|c| c.series[0].points.clone()).collect();
        assert_eq!(drawn[0], vec![(1.0, 10.0), (2.0, 20.0)]);
        assert_eq!(drawn[1], vec![(1.0, 1e-9), (2.0, 3e-9)]);
        assert_eq!(drawn[2], vec![(1.0, 2e-6), (2.0, 1e-6)]);
        assert!(charts.iter().all(|c| c.log_x && c.log_y));
    }
}
