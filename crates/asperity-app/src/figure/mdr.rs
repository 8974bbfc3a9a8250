//! The figure of an MDR curve (`asperity mdr --plot`, `asperity.plot.mdr`): the normal
//! force F/E* against the indentation d and the stiffness k/E* against F/E*, log–log
//! (points at zero left out), each thinned evenly in log x to what a figure shows.

use super::psd::thin_log;
use super::{Chart, Series, Style};

/// Curves of at most this many points are drawn with markers; denser ones (the exact
/// curve of `--breakpoints`) with a line alone.
pub const MARKED_POINTS: usize = 200;

/// The points kept per panel ([`thin_log`]).
pub const KEPT_POINTS: usize = 4000;

/// The curve's columns the figure draws, one value per row (the CLI's `d`, `F`, `k`).
#[derive(Debug, Clone, Copy)]
pub struct MdrColumns<'a> {
    /// The indentation d (from first contact).
    pub indentation: &'a [f64],
    /// The normal force F.
    pub force: &'a [f64],
    /// The contact stiffness k = dF/dd.
    pub stiffness: &'a [f64],
}

/// What the figure says: the indenter's description, the spring law's name and E*.
#[derive(Debug, Clone, Copy)]
pub struct MdrFigure<'a> {
    /// The indenter (e.g. `Hertz sphere R = 1`), as the curve describes it.
    pub description: &'a str,
    /// The spring law (`linear`, `hertz`, `fractal`).
    pub law: &'a str,
    /// E*: forces and stiffnesses are drawn over it.
    pub modulus: f64,
}

/// The two panels: F/E* against d, k/E* against F/E*.
pub fn mdr_charts(columns: MdrColumns<'_>, figure: MdrFigure<'_>) -> [Chart; 2] {
    let style = if columns.indentation.len() <= MARKED_POINTS {
        Style::LinePoints
    } else {
        Style::Line
    };
    let e = figure.modulus;
    let force = || columns.force.iter().map(move |f| f / e);
    let force_chart = Chart {
        title: format!("{}, {} springs", figure.description, figure.law),
        x_label: "indentation d  [length]".into(),
        y_label: "normal force F / E*  [length²]".into(),
        log_x: true,
        log_y: true,
        series: vec![Series::new(
            "",
            thin_log(
                columns.indentation.iter().copied().zip(force()),
                KEPT_POINTS,
            ),
            style,
        )],
    };
    let stiffness = columns.stiffness.iter().map(|k| k / e);
    let stiffness_chart = Chart {
        title: format!("E* = {e}"),
        x_label: "normal force F / E*  [length²]".into(),
        y_label: "contact stiffness k / E*  [length]".into(),
        log_x: true,
        log_y: true,
        series: vec![Series::new(
            "",
            thin_log(force().zip(stiffness), KEPT_POINTS),
            style,
        )],
    };
    [force_chart, stiffness_chart]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hertzs_curve_is_drawn_over_e_star_without_its_zero() {
        // F = (4/3)E*√R d^{3/2}, k = 2E*√(Rd) at R = 1, E* = 2: the panels hold F/E* and
        // k/E*, the row at d = 0 left out of the log–log axes.
        let d = [0.0, 0.01, 0.04, 0.09];
        let f: Vec<f64> = d
            .iter()
            .map(|&d: &f64| 2.0 * 4.0 / 3.0 * d.powf(1.5))
            .collect();
        let k: Vec<f64> = d.iter().map(|&d: &f64| 2.0 * 2.0 * d.sqrt()).collect();
        let [force, stiffness] = mdr_charts(
            MdrColumns {
                indentation: &d,
                force: &f,
                stiffness: &k,
            },
            MdrFigure {
                description: "Hertz sphere R = 1",
                law: "linear",
                modulus: 2.0,
            },
        );
        let drawn = &force.series[0].points;
        assert_eq!(drawn.len(), 3);
        for &(d, f) in drawn {
            assert!(
                (f - 4.0 / 3.0 * d.powf(1.5)).abs() < 1e-15 * f.max(1.0),
                "{d} {f}"
            );
        }
        for &(f, k) in &stiffness.series[0].points {
            // k/E* = 2√d with d = (3F/4)^{2/3}.
            let d = (0.75 * f).powf(2.0 / 3.0);
            assert!((k - 2.0 * d.sqrt()).abs() < 1e-12, "{f} {k}");
        }
        assert_eq!(force.series[0].style, Style::LinePoints);
        assert!(force
            .title
            .starts_with("Hertz sphere R = 1, linear springs"));
        assert_eq!(stiffness.title, "E* = 2");
    }
}
