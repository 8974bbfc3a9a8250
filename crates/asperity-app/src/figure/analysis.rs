//! The figures of the surface analyses (`asperity stats --acf acf.png`, … and
//! `asperity.plot.analysis`): one chart per [`Analysis`], drawn from the rows
//! [`crate::stats::analysis::analyse`] computes — the ACFs, the scale-dependent slope and
//! curvature and the variable-bandwidth rms height on log–log axes against the length
//! scale, the bearing-area curve and the distributions on linear axes.

use super::psd::{thin_log, MAX_PSD_POINTS};
use super::{Chart, Series, Style};
use crate::stats::analysis::Analysis;

/// What an analysis' figure says about its surface.
#[derive(Debug, Clone, Copy)]
pub struct AnalysisFigure<'a> {
    /// The surface's name in the title (a file name, or what the caller calls it).
    pub name: &'a str,
    /// The analysis the rows are of.
    pub analysis: Analysis,
    /// Lengths and heights in metres (a measured file); otherwise in the heights' own unit.
    pub metres: bool,
}

/// What each analysis' chart shows: title words, axis labels (`L` for the length unit),
/// log–log or linear axes.
struct Layout {
    what: &'static str,
    x: &'static str,
    y: &'static str,
    log: bool,
}

fn layout(analysis: Analysis) -> Layout {
    let (what, x, y, log) = match analysis {
        Analysis::BearingArea => (
            "bearing-area (Abbott–Firestone) curve",
            "material ratio Smr  [1]",
            "height c  [L]",
            false,
        ),
        Analysis::Acf => (
            "height-difference ACF along x",
            "distance r  [L]",
            "A(r) = ½⟨(h(x+r) − h(x))²⟩  [L²]",
            true,
        ),
        Analysis::Acf2d => (
            "height-difference ACF, radially averaged",
            "distance |r|  [L]",
            "A(|r|) = ½⟨(h(x+r) − h(x))²⟩  [L²]",
            true,
        ),
        Analysis::VariableBandwidth => (
            "variable-bandwidth rms height",
            "bandwidth ℓ  [L]",
            "rms height  [L]",
            true,
        ),
        Analysis::ScaleDependentSlope => (
            "scale-dependent rms slope along x",
            "distance r  [L]",
            "rms slope √(2A(r))/r  [1]",
            true,
        ),
        Analysis::ScaleDependentCurvature => (
            "scale-dependent rms curvature along x",
            "distance r  [L]",
            "rms curvature  [1/L]",
            true,
        ),
        Analysis::HeightDistribution => (
            "height distribution",
            "height  [L]",
            "probability density  [1/L]",
            false,
        ),
        Analysis::SlopeDistribution => (
            "slope distribution along x",
            "slope  [1]",
            "probability density  [1]",
            false,
        ),
        Analysis::CurvatureDistribution => (
            "curvature distribution along x",
            "curvature  [1/L]",
            "probability density  [L]",
            false,
        ),
    };
    Layout { what, x, y, log }
}

/// The chart of one analysis' rows `(x, y)` (the two columns of its CSV): on log–log
/// axes the points a log axis can show (thinned evenly in log x to about
/// [`MAX_PSD_POINTS`] when there are more), on linear axes every finite row; markers with
/// a line up to 300 points, markers alone beyond.
pub fn analysis_chart(rows: &[(f64, f64)], figure: AnalysisFigure<'_>) -> Chart {
    let Layout { what, x, y, log } = layout(figure.analysis);
    let unit = if figure.metres { "m" } else { "length" };
    let label = |text: &str| {
        (text.replace("[L]", &format!("[{unit}]")))
            .replace("[L²]", &format!("[{unit}²]"))
            .replace("[1/L]", &format!("[1/{unit}]"))
    };
    let points = if log {
        thin_log(rows.iter().copied(), MAX_PSD_POINTS)
    } else {
        (rows.iter().copied())
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect()
    };
    let style = if points.len() <= 300 {
        Style::LinePoints
    } else {
        Style::Points
    };
    let [_, column] = figure.analysis.columns();
    Chart {
        title: format!("{}: {what}", figure.name),
        x_label: label(x),
        y_label: label(y),
        log_x: log,
        log_y: log,
        series: vec![Series::new(column, points, style)],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure(analysis: Analysis, metres: bool) -> AnalysisFigure<'static> {
        AnalysisFigure {
            name: "scan",
            analysis,
            metres,
        }
    }

    #[test]
    fn the_scale_analyses_are_log_log_with_units_and_the_rows_as_points() {
        let rows: Vec<(f64, f64)> = (0..50).map(|k| (k as f64 * 0.5, (k * k) as f64)).collect();
        let chart = analysis_chart(&rows, figure(Analysis::Acf, true));
        assert!(chart.log_x && chart.log_y);
        assert_eq!(chart.x_label, "distance r  [m]");
        assert_eq!(chart.y_label, "A(r) = ½⟨(h(x+r) − h(x))²⟩  [m²]");
        assert_eq!(chart.title, "scan: height-difference ACF along x");
        // r = 0 (A = 0) cannot be drawn on log axes; every other row is a point, unchanged.
        assert_eq!(chart.series[0].points, rows[1..]);
        assert_eq!(chart.series[0].label, "acf");
        let curvature = analysis_chart(&rows, figure(Analysis::ScaleDependentCurvature, false));
        assert_eq!(curvature.y_label, "rms curvature  [1/length]");
        for a in [
            Analysis::Acf2d,
            Analysis::VariableBandwidth,
            Analysis::ScaleDependentSlope,
        ] {
            let chart = analysis_chart(&rows, figure(a, true));
            assert!(chart.log_x && chart.log_y, "{a:?}");
            assert!(chart.x_label.ends_with("[m]"), "{a:?}");
        }
    }

    #[test]
    fn the_bearing_curve_and_distributions_are_linear_and_keep_negative_values() {
        let rows = [(0.0, 2.0), (0.5, -1.0), (1.0, -3.0), (1.5, f64::NAN)];
        for a in [
            Analysis::BearingArea,
            Analysis::HeightDistribution,
            Analysis::SlopeDistribution,
            Analysis::CurvatureDistribution,
        ] {
            let chart = analysis_chart(&rows, figure(a, false));
            assert!(!chart.log_x && !chart.log_y, "{a:?}");
            assert_eq!(chart.series[0].points, rows[..3], "{a:?}");
        }
        let bearing = analysis_chart(&rows, figure(Analysis::BearingArea, true));
        assert_eq!(bearing.y_label, "height c  [m]");
        let curvature = analysis_chart(&rows, figure(Analysis::CurvatureDistribution, true));
        assert_eq!(curvature.x_label, "curvature  [1/m]");
        assert_eq!(curvature.y_label, "probability density  [m]");
    }
}
