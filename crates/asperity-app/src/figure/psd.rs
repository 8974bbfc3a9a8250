//! The figure of a power spectrum (`asperity stats --plot`, `asperity.plot.psd`): the PSD
//! against q·L/2π, log–log, with the fitted power law over the fit range.

use std::f64::consts::TAU;

use super::{Chart, Color, Series, Style};

/// The most points a spectrum's series keeps (a line's many noisy bins, thinned evenly in
/// log q by [`thin_log`]).
pub const MAX_PSD_POINTS: usize = 5000;

/// A spectrum and its fit, as `asperity stats` and `asperity.psd` compute them.
#[derive(Debug, Clone, Copy)]
pub struct PsdFigure<'a> {
    /// The name in the title (a file name, or what the caller calls it).
    pub name: &'a str,
    /// The bins' wavenumbers q (radians per unit length).
    pub q: &'a [f64],
    /// The bins' PSD (in the convention asked for).
    pub psd: &'a [f64],
    /// The side length L along x.
    pub size: f64,
    /// 1 for a line (C1D), 2 for a surface (C2D).
    pub ndim: usize,
    /// The fit range in q·L/2π (bins whose rounded q·L/2π lies in it were fitted).
    pub range: Option<(f64, f64)>,
    /// The fitted power law `C = prefactor · q^exponent`, or none.
    pub fit: Option<(f64, f64)>,
    /// The Hurst estimate of the fit, or none.
    pub hurst: Option<f64>,
}

/// The PSD chart: every ring of a surface, a line's bins thinned to [`MAX_PSD_POINTS`]; the
/// fitted power law dashed and black from the first to the last bin fitted, its slope (and
/// H) in the legend.
pub fn psd_chart(figure: PsdFigure<'_>) -> Chart {
    let wavelengths = |q: f64| q * figure.size / TAU;
    let (kind, psd_name, unit) = if figure.ndim == 1 {
        ("line", "C1D(q)", "length³")
    } else {
        ("surface", "C2D(q)", "length⁴")
    };
    let bins = figure.q.iter().zip(figure.psd);
    let points = thin_log(
        bins.clone().map(|(&q, &c)| (wavelengths(q), c)),
        MAX_PSD_POINTS,
    );
    let style = if points.len() <= 300 {
        Style::LinePoints
    } else {
        Style::Points
    };
    let mut series = vec![Series::new("PSD", points, style)];
    if let (Some((prefactor, exponent)), Some((from, to))) = (figure.fit, figure.range) {
        let fitted: Vec<f64> = bins
            .filter(|(_, &c)| c > 0.0)
            .map(|(&q, _)| wavelengths(q))
            .filter(|k| (from..=to).contains(&k.round()))
            .collect();
        let ends = [fitted.first(), fitted.last()];
        let line = ends
            .into_iter()
            .flatten()
            .map(|&k| (k, prefactor * (k * TAU / figure.size).powf(exponent)))
            .collect();
        let label = match figure.hurst {
            Some(h) => format!("fit: slope {exponent:.3} (H ≈ {h:.3})"),
            None => format!("fit: slope {exponent:.3}"),
        };
        series.push(Series::new(label, line, Style::Dashed).color(Color::BLACK));
    }
    Chart {
        title: format!(
            "{}: power spectrum of the {kind} (L = {})",
            figure.name, figure.size
        ),
        x_label: "wavenumber q·L/2π".into(),
        y_label: format!("PSD {psd_name}  [{unit}]"),
        log_x: true,
        log_y: true,
        series,
    }
}

/// The points of a log–log series thinned to about `keep` per x range: a point is kept
/// when ln x moved by at least 1/`keep` of the range since the last one kept (the last
/// point is always kept). Points that log axes cannot show are dropped.
pub fn thin_log(points: impl Iterator<Item = (f64, f64)>, keep: usize) -> Vec<(f64, f64)> {
    let shown: Vec<(f64, f64)> = points
        .filter(|(x, y)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0)
        .collect();
    if shown.len() <= keep {
        return shown;
    }
    let (lo, hi) = shown
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.0.ln()), hi.max(p.0.ln()))
        });
    let step = (hi - lo) / keep as f64;
    let mut kept: Vec<(f64, f64)> = Vec::with_capacity(keep + 1);
    for (i, &p) in shown.iter().enumerate() {
        let far = kept
            .last()
            .is_none_or(|last: &(f64, f64)| (p.0.ln() - last.0.ln()).abs() >= step);
        if far || i + 1 == shown.len() {
            kept.push(p);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_is_drawn_over_the_bins_fitted() {
        let size = 2.0;
        let q: Vec<f64> = (1..=10).map(|k| k as f64 * TAU / size).collect();
        let psd: Vec<f64> = q.iter().map(|q| 3.0 * q.powf(-2.5)).collect();
        let figure = PsdFigure {
            name: "s",
            q: &q,
            psd: &psd,
            size,
            ndim: 2,
            range: Some((2.0, 6.0)),
            fit: Some((3.0, -2.5)),
            hurst: Some(0.25),
        };
        let chart = psd_chart(figure);
        assert_eq!(chart.series[0].points.len(), 10);
        assert_eq!(chart.series[0].points[0], (1.0, psd[0]));
        let fit = &chart.series[1];
        assert_eq!(fit.label, "fit: slope -2.500 (H ≈ 0.250)");
        assert_eq!(fit.points.len(), 2);
        assert_eq!(fit.points[0].0, 2.0);
        assert!((fit.points[1].1 / psd[5] - 1.0).abs() < 1e-12);
        assert_eq!(chart.y_label, "PSD C2D(q)  [length⁴]");
        assert_eq!(chart.title, "s: power spectrum of the surface (L = 2)");
        let no_fit = psd_chart(PsdFigure {
            fit: None,
            ndim: 1,
            ..figure
        });
        assert_eq!(no_fit.series.len(), 1);
        assert_eq!(no_fit.y_label, "PSD C1D(q)  [length³]");
    }

    #[test]
    fn thinning_keeps_log_spread_points_and_the_ends() {
        let dense: Vec<(f64, f64)> = (1..=100_000).map(|i| (i as f64, 1.0)).collect();
        let thin = thin_log(dense.iter().copied(), 100);
        assert!(thin.len() <= 102 && thin.len() > 50, "{}", thin.len());
        assert_eq!(thin.first(), Some(&(1.0, 1.0)));
        assert_eq!(thin.last(), Some(&(100_000.0, 1.0)));
        let few = [(0.0, 1.0), (1.0, 2.0), (2.0, -1.0), (3.0, 4.0)];
        assert_eq!(thin_log(few.into_iter(), 100), [(1.0, 2.0), (3.0, 4.0)]);
    }
}
