//! The figure of a load path (`asperity bem --load-path --plot`, `asperity.plot.load_path`
//! of a `Solver.load_path` result): the loading–unloading loop of force against approach,
//! the contact fraction against approach, and the stiffness against force, each step
//! marked by its branch (loading, unloading, reloading).

use super::{Chart, Color, Series, Style};
use crate::bem::Branch;

/// The path's columns the figure draws (one value per step, in path order).
#[derive(Debug, Clone, Copy)]
pub struct PathColumns<'a> {
    /// The branch of each step ([`crate::bem::branches`]).
    pub branch: &'a [Branch],
    /// Indentation (approach) d.
    pub indentation: &'a [f64],
    /// Normal force F.
    pub force: &'a [f64],
    /// Contact fraction A/A₀.
    pub area_fraction: &'a [f64],
    /// Frozen-set stiffness k (the elastic set under a hardness).
    pub stiffness: &'a [f64],
}

/// What the path's figure says about its surface.
#[derive(Debug, Clone, Copy)]
pub struct PathFigure<'a> {
    /// The surface's name in the titles.
    pub name: &'a str,
    /// `free` or `periodic`.
    pub boundary: &'a str,
    /// The hardness (in the units of the pressures), or none.
    pub hardness: Option<f64>,
}

/// The colour of each branch's markers.
fn branch_color(branch: Branch) -> Color {
    match branch {
        Branch::Loading => Color::RED,
        Branch::Unloading => Color::BLUE,
        Branch::Reloading => Color::Rgb(0, 150, 0),
    }
}

/// One chart of `y` against `x`: the path in step order as a grey line, each branch's
/// steps as markers in its colour.
fn path_chart(
    columns: &PathColumns<'_>,
    (x, y): (&[f64], &[f64]),
    (title, x_label, y_label): (String, &str, &str),
) -> Chart {
    let points = |keep: &dyn Fn(Branch) -> bool| -> Vec<(f64, f64)> {
        let steps = columns.branch.iter().zip(x.iter().zip(y));
        steps
            .filter(|(b, _)| keep(**b))
            .map(|(_, (&a, &b))| (a, b))
            .collect()
    };
    let mut series = vec![Series::new("path", points(&|_| true), Style::Line).color(Color::GREY)];
    for branch in [Branch::Loading, Branch::Unloading, Branch::Reloading] {
        let mine = points(&|b| b == branch);
        if !mine.is_empty() {
            series
                .push(Series::new(branch.name(), mine, Style::Points).color(branch_color(branch)));
        }
    }
    Chart {
        title,
        x_label: x_label.into(),
        y_label: y_label.into(),
        log_x: false,
        log_y: false,
        series,
    }
}

/// The three panels: F against d (the hysteresis loop), A/A₀ against d, k against F.
pub fn path_charts(columns: PathColumns<'_>, figure: PathFigure<'_>) -> [Chart; 3] {
    let cap = match figure.hardness {
        Some(h) => format!("H = {}", asperity::input::short_number(h)),
        None => "no hardness".into(),
    };
    let (d, f) = (columns.indentation, columns.force);
    let loop_chart = path_chart(
        &columns,
        (d, f),
        (
            format!(
                "{}: load path ({cap}, {} boundaries)",
                figure.name, figure.boundary
            ),
            "indentation d",
            "normal force F",
        ),
    );
    let area = path_chart(
        &columns,
        (d, columns.area_fraction),
        (
            format!("{}: contact area", figure.name),
            "indentation d",
            "area fraction A / A0",
        ),
    );
    let stiffness = path_chart(
        &columns,
        (f, columns.stiffness),
        (
            format!("{}: contact stiffness (elastic set)", figure.name),
            "normal force F",
            "contact stiffness k",
        ),
    );
    [loop_chart, area, stiffness]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bem::branches;

    #[test]
    fn each_branch_is_marked_and_the_path_drawn_in_order() {
        let d = [1.0, 2.0, 1.5, 2.0];
        let branch = branches(&d);
        let columns = PathColumns {
            branch: &branch,
            indentation: &d,
            force: &[10.0, 30.0, 15.0, 30.0],
            area_fraction: &[0.1, 0.3, 0.2, 0.3],
            stiffness: &[5.0, 9.0, 8.0, 9.0],
        };
        let figure = PathFigure {
            name: "s.npy",
            boundary: "periodic",
            hardness: Some(0.3),
        };
        let [f, a, k] = path_charts(columns, figure);
        assert_eq!(f.title, "s.npy: load path (H = 0.3, periodic boundaries)");
        assert_eq!(
            f.series[0].points,
            vec![(1.0, 10.0), (2.0, 30.0), (1.5, 15.0), (2.0, 30.0)]
        );
        let labels: Vec<&str> = f.series.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(labels, ["path", "loading", "unloading", "reloading"]);
        assert_eq!(f.series[2].points, vec![(1.5, 15.0)]);
        assert_eq!(a.series[1].points, vec![(1.0, 0.1), (2.0, 0.3)]);
        assert_eq!(k.series[3].points, vec![(30.0, 9.0)]);
        assert!(!f.log_x && !k.log_y);
    }
}
