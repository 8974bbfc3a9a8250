//! The figure of an adhesive loop (`asperity bem|contact|mdr --work-of-adhesion --plot`,
//! `asperity.plot.adhesion_loop`): force against approach along the path and the
//! retraction to pull-off, an arrow on every monotone run of the path pointing the way
//! it was travelled (loading red, unloading blue), both pull-offs marked and named, and
//! an optional theory curve (JKR's for a sphere in the MDR).

use super::{Chart, Color, Series, Style};

/// Loading (approach increasing) colour.
const LOADING: Color = Color::RED;
/// Unloading colour (the retraction included).
const UNLOADING: Color = Color::BLUE;
/// The retraction's line.
const RETRACTION: Color = Color::Rgb(0, 150, 0);
/// The pull-off markers: force control, displacement control.
const PULL_OFF: [Color; 2] = [Color::Rgb(0, 0, 0), Color::Rgb(230, 120, 0)];

/// One settled state of the loop, in path order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopPoint {
    /// The approach (indentation) d.
    pub indentation: f64,
    /// The force F.
    pub force: f64,
    /// Whether it belongs to the retraction to pull-off (else to the given path).
    pub retract: bool,
}

/// The two pull-offs, `(d, F)` each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopPullOffs {
    /// Force control: the least force.
    pub force_controlled: (f64, f64),
    /// Displacement control: the last attached state.
    pub displacement_controlled: (f64, f64),
}

/// What the figure says: title, axis labels with units, the unit of the pull-off forces in
/// the legend (empty in model units), and a theory curve (label, points) or none.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopFigure {
    /// The title.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// The forces' unit in the legend (` N`, or empty).
    pub force_unit: String,
    /// A dashed theory curve.
    pub theory: Option<(String, Vec<(f64, f64)>)>,
}

/// A reversal of the approach shorter than this share of its whole range does not end a
/// run: the MDR's retraction writes a row before and after each release at one approach,
/// and rounding may step it back by an ulp.
const REVERSAL: f64 = 1e-3;

/// The monotone runs of the path and the retraction: `(first, last)` indices, inclusive,
/// each at least two points, over which d rises (loading) or falls (unloading); a reversal
/// shorter than [`REVERSAL`] of the range of d is not one.
fn runs(points: &[LoopPoint]) -> Vec<(usize, usize, bool)> {
    let d: Vec<f64> = points.iter().map(|p| p.indentation).collect();
    let (lo, hi) = d
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let tol = REVERSAL * (hi - lo).max(f64::MIN_POSITIVE);
    let mut runs: Vec<(usize, usize, bool)> = Vec::new();
    // The run under way: its start, its extreme so far, its direction (none yet).
    let (mut start, mut extreme, mut rising) = (0, 0, None::<bool>);
    for k in 1..d.len() {
        match rising {
            None if (d[k] - d[start]).abs() > tol => {
                rising = Some(d[k] > d[start]);
                extreme = k;
            }
            None => {}
            Some(up) if (d[k] > d[extreme]) == up && d[k] != d[extreme] => extreme = k,
            Some(up) if (d[k] - d[extreme]).abs() > tol => {
                runs.push((start, extreme, up));
                (start, rising) = (extreme, Some(!up));
                extreme = k;
            }
            Some(_) => {}
        }
    }
    if let Some(up) = rising {
        runs.push((start, extreme, up));
    }
    runs
}

/// A point `share` of the way along the polyline `xy[first..=last]`, its length measured
/// on axes scaled to `span`.
fn along(
    xy: &[(f64, f64)],
    (first, last): (usize, usize),
    span: (f64, f64),
    share: f64,
) -> (f64, f64) {
    let length = |a: (f64, f64), b: (f64, f64)| ((b.0 - a.0) / span.0).hypot((b.1 - a.1) / span.1);
    let total: f64 = (first + 1..=last).map(|k| length(xy[k - 1], xy[k])).sum();
    let mut left = share * total;
    for k in first + 1..=last {
        let step = length(xy[k - 1], xy[k]);
        if step > 0.0 && left <= step {
            let t = left / step;
            let (a, b) = (xy[k - 1], xy[k]);
            return (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        }
        left -= step;
    }
    xy[last]
}

/// An arrow on the run `first..=last` of `xy`: from the point 45 % along it to the one
/// 55 % along (lengths on axes scaled to `span`), so it sits mid-run and follows it.
fn arrow(xy: &[(f64, f64)], run: (usize, usize), span: (f64, f64)) -> [(f64, f64); 2] {
    [along(xy, run, span, 0.45), along(xy, run, span, 0.55)]
}

/// The loop chart: the path (loading and unloading steps, a line with markers), the
/// retraction from the path's last point on (a line), one arrow per monotone run in the
/// direction travelled, the pull-offs as named markers, and the theory curve.
pub fn loop_chart(points: &[LoopPoint], pull: Option<LoopPullOffs>, figure: LoopFigure) -> Chart {
    let xy: Vec<(f64, f64)> = points.iter().map(|p| (p.indentation, p.force)).collect();
    let first_retract = points.iter().position(|p| p.retract).unwrap_or(xy.len());
    let mut series = vec![
        Series::new("path", xy[..first_retract].to_vec(), Style::LinePoints).color(Color::GREY),
    ];
    if first_retract < xy.len() {
        let from = first_retract.saturating_sub(1);
        series.push(
            Series::new("retraction to pull-off", xy[from..].to_vec(), Style::Line)
                .color(RETRACTION),
        );
    }
    let extent = |f: fn(&(f64, f64)) -> f64| {
        let (lo, hi) = xy
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if hi > lo {
            hi - lo
        } else {
            1.0
        }
    };
    let span = (extent(|p| p.0), extent(|p| p.1));
    let (mut loading, mut unloading) = (Vec::new(), Vec::new());
    for (first, last, rising) in runs(points) {
        let target = if rising { &mut loading } else { &mut unloading };
        target.extend(arrow(&xy, (first, last), span));
    }
    for (label, arrows, color) in [
        ("loading", loading, LOADING),
        ("unloading", unloading, UNLOADING),
    ] {
        if !arrows.is_empty() {
            series.push(Series::new(label, arrows, Style::Arrows).color(color));
        }
    }
    if let Some((label, curve)) = figure.theory {
        series.push(Series::new(label, curve, Style::Dashed).color(Color::GREY));
    }
    if let Some(p) = pull {
        let marks = [
            ("force control", p.force_controlled),
            ("displacement control", p.displacement_controlled),
        ];
        for ((control, (d, f)), color) in marks.into_iter().zip(PULL_OFF) {
            let label = format!("pull-off, {control}: F = {f:.4e}{}", figure.force_unit);
            series.push(Series::new(label, vec![(d, f)], Style::Points).color(color));
        }
    }
    Chart {
        title: figure.title,
        x_label: figure.x_label,
        y_label: figure.y_label,
        log_x: false,
        log_y: false,
        series,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(indentation: f64, force: f64, retract: bool) -> LoopPoint {
        LoopPoint {
            indentation,
            force,
            retract,
        }
    }

    #[test]
    fn arrows_point_the_way_each_run_was_travelled() {
        // Load to 3, unload to 1, reload to 4, then retract to −1: four runs, arrows
        // loading, unloading, loading, unloading, each head beyond its tail in the run's
        // direction; the retraction's line starts at the path's last point.
        let mut points: Vec<LoopPoint> = [0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 2.0, 3.0, 4.0]
            .iter()
            .map(|&d| point(d, d * d, false))
            .collect();
        points.extend(
            [3.0, 2.0, 1.0, 0.0, -1.0]
                .iter()
                .map(|&d| point(d, d - 2.0, true)),
        );
        assert_eq!(
            runs(&points),
            vec![(0, 3, true), (3, 5, false), (5, 8, true), (8, 13, false)]
        );
        // A sawtooth at one approach (the MDR's release rows) and an ulp back is one run.
        let saw: Vec<LoopPoint> = [1.0, 0.9, 0.9, 0.9 + 1e-16, 0.8, 0.8, 0.7]
            .iter()
            .enumerate()
            .map(|(k, &d)| point(d, k as f64, true))
            .collect();
        assert_eq!(runs(&saw), vec![(0, 6, false)]);
        let pull = LoopPullOffs {
            force_controlled: (-1.0, -3.0),
            displacement_controlled: (-0.5, -2.5),
        };
        let figure = LoopFigure {
            title: "t".into(),
            x_label: "d [m]".into(),
            y_label: "F [N]".into(),
            force_unit: " N".into(),
            theory: None,
        };
        let chart = loop_chart(&points, Some(pull), figure);
        let named = |label: &str| {
            chart
                .series
                .iter()
                .find(|s| s.label.starts_with(label))
                .unwrap()
        };
        assert_eq!(named("retraction").points[0], (4.0, 16.0));
        let loading = &named("loading").points;
        let unloading = &named("unloading").points;
        assert_eq!((loading.len(), unloading.len()), (4, 4));
        for pair in loading.chunks(2) {
            assert!(pair[1].0 > pair[0].0, "{pair:?}");
        }
        for pair in unloading.chunks(2) {
            assert!(pair[1].0 < pair[0].0, "{pair:?}");
        }
        assert_eq!(named("loading").style, Style::Arrows);
        let force = named("pull-off, force control");
        assert_eq!(force.points, vec![(-1.0, -3.0)]);
        assert_eq!(force.label, "pull-off, force control: F = -3.0000e0 N");
        assert_eq!(named("pull-off, displacement").points, vec![(-0.5, -2.5)]);
    }
}
