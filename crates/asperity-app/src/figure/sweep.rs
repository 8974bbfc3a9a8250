//! The figures of a load sweep (`asperity bem --plot`, `asperity.plot.stiffness` and
//! `asperity.plot.area` of a `Sweep`): k(F) and A/A₀(F), log–log.

use super::{Chart, Series, Style};

/// The sweep's columns the figure draws (one value per load; NaN where not computed).
#[derive(Debug, Clone, Copy)]
pub struct SweepColumns<'a> {
    /// Normal force F.
    pub force: &'a [f64],
    /// Frozen-set stiffness k.
    pub stiffness: &'a [f64],
    /// Finite-difference stiffness dF/dd, when computed (drawn beside k).
    pub stiffness_fd: Option<&'a [f64]>,
    /// Contact fraction A/A₀.
    pub area_fraction: &'a [f64],
}

/// What the sweep's figure says about its surface and units.
#[derive(Debug, Clone, Copy)]
pub struct SweepFigure<'a> {
    /// The surface's name in the titles (its file name, or what the caller calls it).
    pub name: &'a str,
    /// E* (in Pa where `physical`).
    pub modulus: f64,
    /// Forces in N and stiffness in N/m as the rows hold them (a measured surface, lengths
    /// in metres, E* in Pa); otherwise both are divided by E* (lengths in the surface's own
    /// unit).
    pub physical: bool,
    /// `free` or `periodic`.
    pub boundary: &'a str,
}

/// The two panels: k vs F (the frozen-set stiffness, and the finite difference dF/dd when
/// computed) and the contact fraction vs F.
pub fn sweep_charts(columns: SweepColumns<'_>, figure: SweepFigure<'_>) -> [Chart; 2] {
    let per = if figure.physical { 1.0 } else { figure.modulus };
    let points = |y: &[f64], scale: f64| {
        let force = columns.force.iter();
        force.zip(y).map(|(f, v)| (f / per, v / scale)).collect()
    };
    let (x_label, y_label) = if figure.physical {
        ("normal force F [N]", "contact stiffness k [N/m]")
    } else {
        (
            "normal force F / E*  [length²]",
            "contact stiffness k / E*  [length]",
        )
    };
    let mut series = vec![Series::new(
        "frozen contact set",
        points(columns.stiffness, per),
        Style::LinePoints,
    )];
    if let Some(fd) = columns.stiffness_fd {
        series.push(Series::new(
            "finite difference dF/dd",
            points(fd, per),
            Style::Dashed,
        ));
    }
    let stiffness = Chart {
        title: format!(
            "{}: contact stiffness (E* = {}{}, {} boundaries)",
            figure.name,
            asperity::input::short_number(figure.modulus),
            if figure.physical { " Pa" } else { "" },
            figure.boundary
        ),
        x_label: x_label.into(),
        y_label: y_label.into(),
        log_x: true,
        log_y: true,
        series,
    };
    let area = Chart {
        title: format!("{}: true contact area", figure.name),
        x_label: x_label.into(),
        y_label: "area fraction A / A0".into(),
        log_x: true,
        log_y: true,
        series: vec![Series::new(
            "",
            points(columns.area_fraction, 1.0),
            Style::LinePoints,
        )],
    };
    [stiffness, area]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn charts(physical: bool, fd: Option<&[f64]>) -> [Chart; 2] {
        let columns = SweepColumns {
            force: &[2.0, 4.0],
            stiffness: &[1.0, f64::NAN],
            stiffness_fd: fd,
            area_fraction: &[0.01, 0.02],
        };
        let figure = SweepFigure {
            name: "s.npy",
            modulus: 2.0,
            physical,
            boundary: "free",
        };
        sweep_charts(columns, figure)
    }

    #[test]
    fn forces_and_stiffness_are_divided_by_e_star_unless_physical() {
        let [k, a] = charts(false, None);
        assert_eq!(k.series.len(), 1);
        assert_eq!(k.series[0].points[0], (1.0, 0.5));
        assert!(k.series[0].points[1].1.is_nan());
        assert_eq!(a.series[0].points, vec![(1.0, 0.01), (2.0, 0.02)]);
        assert_eq!(
            k.title,
            "s.npy: contact stiffness (E* = 2, free boundaries)"
        );
        let [k, _] = charts(true, Some(&[1.5, 3.0]));
        assert_eq!(k.series[0].points[0], (2.0, 1.0));
        assert_eq!(k.series[1].points, vec![(2.0, 1.5), (4.0, 3.0)]);
        assert_eq!(k.series[1].style, Style::Dashed);
        assert!(k.title.ends_with("(E* = 2 Pa, free boundaries)"));
        assert_eq!(k.x_label, "normal force F [N]");
    }
}
