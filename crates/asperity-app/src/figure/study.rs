//! The figures of an ensemble study (`asperity study`, `asperity reproduce`, and
//! `asperity.plot.alpha` / `asperity.plot.stiffness` of a Python study result): α(H) with
//! the theory curves, α(N) for a study of one H, and the ensemble-mean k(F); and
//! `asperity.plot.area` of a Python study result: the ensemble-mean contact fraction
//! against F (which the CLI's `curve.csv` tabulates but does not draw).

use asperity::study::theory::{alpha_pohrt_popov, alpha_white_noise, ALPHA_HERTZ};
use asperity::study::{Method, TaskResult};

use super::{Chart, Color, Series, Style};
use crate::study::Kind;

/// The title of a study's plot, marked with the `reproduce` setting, if any.
pub fn title(kind: Kind, setting: Option<&str>) -> String {
    let title = match kind {
        Kind::Alpha => "α of k ∝ F^α vs H",
        Kind::Curve => "Contact stiffness vs force (ensemble mean)",
    };
    match setting {
        Some(name) => format!("{title} ({name} setting)"),
        None => title.to_string(),
    }
}

/// The 95 % interval of each task's per-sample α (`alpha_low`, `alpha_high` of
/// `alpha.csv`; NaN where there is none, which the plot leaves out).
fn alpha_interval(r: &TaskResult) -> (f64, f64) {
    r.alpha_sample_interval().unwrap_or((f64::NAN, f64::NAN))
}

/// The (method, N) pairs of `results` in order of appearance.
fn method_sizes(results: &[TaskResult]) -> Vec<(Method, usize)> {
    let mut sizes: Vec<(Method, usize)> = Vec::new();
    for r in results {
        if !sizes.contains(&(r.method, r.task.n)) {
            sizes.push((r.method, r.task.n));
        }
    }
    sizes
}

fn family_color(k: usize, count: usize) -> Color {
    let t = if count > 1 {
        k as f64 / (count - 1) as f64
    } else {
        0.5
    };
    Color::Ordered(t * 0.85)
}

/// The α(H) chart: one series per (method, N) with the 95 % interval of the samples as
/// error bars, and the theory curves (6), 1/3 and (24), the last once per N in that
/// series' colour. A study of a single H over several N is drawn as α(N) instead
/// (`alpha_n_chart`).
pub fn alpha_chart(results: &[TaskResult], title: &str) -> Chart {
    let single_h = results
        .windows(2)
        .all(|w| w[0].task.hurst == w[1].task.hurst);
    let sizes = method_sizes(results);
    if single_h && sizes.len() > 1 {
        return alpha_n_chart(results, title);
    }
    let mut series = Vec::new();
    // Series at the same H are shifted apart so that their error bars do not overlap.
    let shift = |k: usize| 0.03 * (k as f64 - (sizes.len() as f64 - 1.0) / 2.0);
    for (k, &(method, n)) in sizes.iter().enumerate() {
        let rows: Vec<&TaskResult> = results
            .iter()
            .filter(|r| r.method == method && r.task.n == n)
            .filter(|r| r.alpha_ensemble.is_some())
            .collect();
        let points = rows
            .iter()
            .map(|r| {
                (
                    r.task.hurst + shift(k),
                    r.alpha_ensemble.map_or(f64::NAN, |f| f.exponent),
                )
            })
            .collect();
        series.push(
            Series::new(
                format!("{} N = {n}", method.name()),
                points,
                Style::LinePoints,
            )
            .color(family_color(k, sizes.len()))
            .interval(rows.iter().map(|r| alpha_interval(r)).collect()),
        );
    }
    // (6) on (0, 2]: H = 0 itself belongs to (24), drawn below on [-1, 0].
    let pp: Vec<(f64, f64)> = (1..=40)
        .map(|i| 0.05 * i as f64)
        .map(|h| (h, alpha_pohrt_popov(h)))
        .collect();
    series.push(Series::new("1/(1+H) (6)", pp, Style::Dashed).color(Color::BLACK));
    series.push(
        Series::new(
            "1/3 (Hertz)",
            vec![(2.0, ALPHA_HERTZ), (3.0, ALPHA_HERTZ)],
            Style::Dashed,
        )
        .color(Color::RED),
    );
    for (k, &(_, n)) in sizes.iter().enumerate() {
        let a = alpha_white_noise(n as f64);
        series.push(
            Series::new(
                format!("(24), N = {n}"),
                vec![(-1.0, a), (0.0, a)],
                Style::Dashed,
            )
            .color(family_color(k, sizes.len())),
        );
    }
    Chart {
        title: title.into(),
        x_label: "Hurst exponent H (series shifted apart by 0.03)".into(),
        y_label: "α (bars: 95 % of the single-sample α)".into(),
        log_x: false,
        log_y: false,
        series,
    }
}

/// α against log2 N for a study of one H: one series per method with the 95 % interval
/// of the samples as error bars, beside eq. (24) (paper Fig. 5).
fn alpha_n_chart(results: &[TaskResult], title: &str) -> Chart {
    let mut methods: Vec<Method> = results.iter().map(|r| r.method).collect();
    methods.dedup();
    let mut series = Vec::new();
    for (k, &method) in methods.iter().enumerate() {
        let rows: Vec<&TaskResult> = results
            .iter()
            .filter(|r| r.method == method && r.alpha_ensemble.is_some())
            .collect();
        let points = rows
            .iter()
            .map(|r| {
                (
                    (r.task.n as f64).log2(),
                    r.alpha_ensemble.map_or(f64::NAN, |f| f.exponent),
                )
            })
            .collect();
        series.push(
            Series::new(
                format!("{} (H = {})", method.name(), results[0].task.hurst),
                points,
                Style::LinePoints,
            )
            .color(family_color(k, methods.len()))
            .interval(rows.iter().map(|r| alpha_interval(r)).collect()),
        );
    }
    let (lo, hi) = results
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
            let m = (r.task.n as f64).log2();
            (a.min(m), b.max(m))
        });
    let theory = (0..=40)
        .map(|i| lo - 0.5 + (hi - lo + 1.0) * i as f64 / 40.0)
        .map(|m| (m, alpha_white_noise(2f64.powf(m))))
        .collect();
    series
        .push(Series::new("(1+log2 N)/(3+log2 N) (24)", theory, Style::Dashed).color(Color::BLUE));
    Chart {
        title: title.replace("vs H", "vs N"),
        x_label: "log2 N (N: modes of a line, points a side of a surface)".into(),
        y_label: "α (bars: 95 % of the single-sample α)".into(),
        log_x: false,
        log_y: false,
        series,
    }
}

/// Log–log k(F), one series per task, coloured by H, with the 95 % interval of the mean
/// as a band in the same colour (ends that a log axis cannot show are left out, see
/// [`Series::interval`]), and a slope-1 reference line (k ∝ F).
pub fn curve_chart(results: &[TaskResult], title: &str) -> Chart {
    let (hmin, hmax) = results
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
            (a.min(r.task.hurst), b.max(r.task.hurst))
        });
    let mut series = Vec::new();
    for r in results {
        let t = if hmax > hmin {
            (r.task.hurst - hmin) / (hmax - hmin)
        } else {
            0.5
        };
        let points = r
            .mean_curve
            .iter()
            .map(|p| (p.force, p.stiffness))
            .collect();
        let mut line = Series::new(
            format!("{} N = {} H = {}", r.method.name(), r.task.n, r.task.hurst),
            points,
            Style::Line,
        )
        .color(Color::Ordered(t * 0.9));
        if r.samples > 1 {
            let interval = r
                .mean_curve
                .iter()
                .map(|p| (p.stiffness_low, p.stiffness_high));
            line = line.interval(interval.collect());
        }
        series.push(line);
    }
    series.extend(slope_one(results));
    let scale = match results.first().map(|r| r.method) {
        Some(Method::Bem) => "L = 1, E* = 1, unit rms slope",
        _ => "L = 1, E* = 1, unit rms height",
    };
    Chart {
        title: title.into(),
        x_label: format!("normal force F ({scale})"),
        y_label: "contact stiffness k (band: 95 % interval of the mean)".into(),
        log_x: true,
        log_y: true,
        series,
    }
}

/// Log–log A/A₀(F): the ensemble-mean contact fraction of each task against the force,
/// coloured by H as [`curve_chart`] (no band: the study records no interval of the
/// fraction).
pub fn area_chart(results: &[TaskResult], title: &str) -> Chart {
    let (hmin, hmax) = results
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
            (a.min(r.task.hurst), b.max(r.task.hurst))
        });
    let series = results
        .iter()
        .map(|r| {
            let t = if hmax > hmin {
                (r.task.hurst - hmin) / (hmax - hmin)
            } else {
                0.5
            };
            let points = r.mean_curve.iter().map(|p| (p.force, p.fraction));
            Series::new(
                format!("{} N = {} H = {}", r.method.name(), r.task.n, r.task.hurst),
                points.collect(),
                Style::Line,
            )
            .color(Color::Ordered(t * 0.9))
        })
        .collect();
    let scale = match results.first().map(|r| r.method) {
        Some(Method::Bem) => "L = 1, E* = 1, unit rms slope",
        _ => "L = 1, E* = 1, unit rms height",
    };
    Chart {
        title: title.into(),
        x_label: format!("normal force F ({scale})"),
        y_label: "contact fraction A/A₀ (ensemble mean)".into(),
        log_x: true,
        log_y: true,
        series,
    }
}

/// A k ∝ F line over the last two decades of force (fewer where the curves span less),
/// from the smallest stiffness up: below the curves, whose slope is at most 1.
fn slope_one(results: &[TaskResult]) -> Option<Series> {
    let points = results.iter().flat_map(|r| &r.mean_curve);
    let shown = points.filter(|p| p.force > 0.0 && p.stiffness > 0.0 && p.stiffness.is_finite());
    let (f_lo, f_hi, k_lo) = shown.fold(
        (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY),
        |(a, b, c), p| (a.min(p.force), b.max(p.force), c.min(p.stiffness)),
    );
    // No drawable point leaves f_lo infinite and f_hi below it.
    if f_hi <= f_lo {
        return None;
    }
    let span = (f_hi / f_lo).min(100.0);
    Some(
        Series::new(
            "slope 1 (k ∝ F)",
            vec![(f_hi / span, k_lo), (f_hi, k_lo * span)],
            Style::Dashed,
        )
        .color(Color::GREY),
    )
}
