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
    let mut series = Vec::new();
    for r in results {
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
        .color(task_color(results, r));
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
/// coloured by H as [`curve_chart`], with the 95 % interval of the mean as a band.
pub fn area_chart(results: &[TaskResult], title: &str) -> Chart {
    let series = results
        .iter()
        .map(|r| {
            let points = r.mean_curve.iter().map(|p| (p.force, p.fraction));
            let line = Series::new(
                format!("{} N = {} H = {}", r.method.name(), r.task.n, r.task.hurst),
                points.collect(),
                Style::Line,
            )
            .color(task_color(results, r));
            if r.samples > 1 {
                let interval = r
                    .mean_curve
                    .iter()
                    .map(|p| (p.fraction_low, p.fraction_high));
                line.interval(interval.collect())
            } else {
                line
            }
        })
        .collect();
    let scale = match results.first().map(|r| r.method) {
        Some(Method::Bem) => "L = 1, E* = 1, unit rms slope",
        _ => "L = 1, E* = 1, unit rms height",
    };
    Chart {
        title: title.into(),
        x_label: format!("normal force F ({scale})"),
        y_label: "contact fraction A/A₀ (band: 95 % interval of the mean)".into(),
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

/// The colour of task `r` of `results`, one per series: where every task has its own H,
/// its place on the H scale of `results`; where tasks of several N share an H, its place
/// among the tasks in order of H, then N (so that no two series share a colour, and the
/// N of one H stay neighbours).
fn task_color(results: &[TaskResult], r: &TaskResult) -> Color {
    let mut tasks: Vec<(f64, usize)> = results.iter().map(|r| (r.task.hurst, r.task.n)).collect();
    tasks.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    tasks.dedup();
    let one_per_h = tasks.windows(2).all(|w| w[0].0 != w[1].0);
    let (hmin, hmax) = (tasks.first(), tasks.last());
    let t = match (hmin, hmax) {
        (Some(&(lo, _)), Some(&(hi, _))) if one_per_h && hi > lo => (r.task.hurst - lo) / (hi - lo),
        _ if tasks.len() > 1 => {
            let place = tasks.iter().position(|&t| t == (r.task.hurst, r.task.n));
            place.unwrap_or(0) as f64 / (tasks.len() - 1) as f64
        }
        _ => 0.5,
    };
    Color::Ordered(t * 0.9)
}

/// What a study's tangential and conductance figures show besides its results: Poisson's
/// ratio (for Mindlin's line) and the bodies' transport properties (for `C(F)`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Derived {
    /// Poisson's ratio ν of the study's tangential stiffness.
    pub poisson: Option<f64>,
    /// Which of `k_x`, `k_y` the ratio is made of.
    pub directions: asperity::bem::tangential::Directions,
    /// The bodies' resistivities and conductivities.
    pub transport: asperity::bem::conductance::Transport,
}

impl From<crate::derived::Derived> for Derived {
    fn from(derived: crate::derived::Derived) -> Self {
        Derived {
            poisson: derived.tangential,
            directions: derived.directions,
            transport: derived.transport,
        }
    }
}

/// The figures of what the normal stiffness stands for, for a study that computed them:
/// `k_t/k_n = (k_x + k_y)/(2k)` against force (log x), one series per task coloured by H,
/// with the 95 % interval of the mean as a band and Mindlin's `2(1−ν)/(2−ν)` dashed (where
/// the samples have the ratio), and the conductance `C(F)`, log–log, with the interval of
/// the mean (electrical where resistivities are given, else thermal; none without either).
pub fn derived_charts(results: &[TaskResult], derived: Derived) -> Vec<Chart> {
    let mut charts = Vec::new();
    if crate::study::rows::has_tangential(results) {
        charts.push(tangential_chart(
            results,
            derived.poisson,
            derived.directions,
        ));
    }
    let modulus = |r: &TaskResult| asperity::study::Scales::of(r.method).modulus;
    let transport = derived.transport;
    let conductance = match (transport.resistivity, transport.thermal_conductivity) {
        (Some(_), _) => Some(("electrical conductance C = 2k/(E*(ρ₁+ρ₂))", true)),
        (None, Some(_)) => Some(("thermal conductance C = (2k/E*)κ₁κ₂/(κ₁+κ₂)", false)),
        (None, None) => None,
    };
    if let Some((label, electrical)) = conductance {
        let factor = |r: &TaskResult| {
            let c = match electrical {
                true => transport.electrical(1.0, modulus(r)),
                false => transport.thermal(1.0, modulus(r)),
            };
            c.unwrap_or(f64::NAN)
        };
        let series = results.iter().map(|r| {
            let c = factor(r);
            let points = r.mean_curve.iter().map(|p| (p.force, c * p.stiffness));
            let band = r
                .mean_curve
                .iter()
                .map(|p| (c * p.stiffness_low, c * p.stiffness_high));
            task_series(results, r, points.collect(), band.collect())
        });
        charts.push(Chart {
            title: "Contact conductance vs force (ensemble mean, Barber's analogy)".into(),
            x_label: force_label(results),
            y_label: format!("{label}  (band: 95 % of the mean)"),
            log_x: true,
            log_y: true,
            series: series.collect(),
        });
    }
    charts
}

/// One task's line with its band where it has more than one sample.
fn task_series(
    results: &[TaskResult],
    r: &TaskResult,
    points: Vec<(f64, f64)>,
    band: Vec<(f64, f64)>,
) -> Series {
    let label = format!("{} N = {} H = {}", r.method.name(), r.task.n, r.task.hurst);
    let line = Series::new(label, points, Style::Line).color(task_color(results, r));
    match r.samples > 1 {
        true => line.interval(band),
        false => line,
    }
}

fn force_label(results: &[TaskResult]) -> String {
    let scale = match results.first().map(|r| r.method) {
        Some(Method::Bem) => "L = 1, E* = 1, unit rms slope",
        _ => "L = 1, E* = 1, unit rms height",
    };
    format!("normal force F ({scale})")
}

/// `k_t/k_n` against force (see [`derived_charts`]): with ν known, as its excess over
/// Mindlin's ratio in per cent (Mindlin's line at 0; the ratio differs from it by parts in
/// 1e-3, which a plain ratio axis cannot resolve); without, the ratio itself. Mindlin's
/// ratio bounds the mean of the two directions from below, not one direction alone.
fn tangential_chart(
    results: &[TaskResult],
    poisson: Option<f64>,
    directions: asperity::bem::tangential::Directions,
) -> Chart {
    use asperity::bem::tangential::Directions;
    let (ratio_name, bound) = match directions {
        Directions::Both => ("(k_x + k_y)/(2k)", ": a lower bound"),
        Directions::X => ("k_x/k", ""),
        Directions::Y => ("k_y/k", ""),
    };
    let mindlin = poisson.map(|nu| 2.0 * (1.0 - nu) / (2.0 - nu));
    let shown = |ratio: f64| match mindlin {
        Some(m) => 100.0 * (ratio / m - 1.0),
        None => ratio,
    };
    let mut series: Vec<Series> = results
        .iter()
        .map(|r| {
            let ratio = |p: &asperity::study::EnsemblePoint| p.tangential_ratio;
            let points = r
                .mean_curve
                .iter()
                .map(|p| (p.force, ratio(p).map_or(f64::NAN, |t| shown(t.mean))));
            let band = r
                .mean_curve
                .iter()
                .map(|p| ratio(p).map_or((f64::NAN, f64::NAN), |t| (shown(t.low), shown(t.high))));
            task_series(results, r, points.collect(), band.collect())
        })
        .collect();
    let forces = results
        .iter()
        .flat_map(|r| r.mean_curve.iter().map(|p| p.force));
    let (lo, hi) = forces.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), f| {
        (a.min(f), b.max(f))
    });
    let y_label = match (poisson, mindlin) {
        (Some(nu), Some(m)) => {
            if hi > lo {
                let label = format!("Mindlin 2(1−ν)/(2−ν) = {m:.5} (ν = {nu}){bound}");
                let line = vec![(lo, 0.0), (hi, 0.0)];
                series.push(Series::new(label, line, Style::Dashed).color(Color::BLACK));
            }
            format!(
                "k_t/k_n = {ratio_name} over Mindlin's ratio − 1 [%], ν = {nu}  \
                 (band: 95 % of the mean)"
            )
        }
        _ => format!("k_t/k_n = {ratio_name}  (band: 95 % of the mean)"),
    };
    Chart {
        title: "Tangential over normal contact stiffness vs force (ensemble mean, full stick)"
            .into(),
        x_label: force_label(results),
        y_label,
        log_x: true,
        log_y: false,
        series,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use asperity::bem::conductance::Transport;
    use asperity::study::{EnsemblePoint, MeanInterval, Task};

    fn result(ratio: Option<f64>) -> TaskResult {
        let point = |force: f64| EnsemblePoint {
            force,
            stiffness: 2.0 * force,
            stiffness_low: force,
            stiffness_high: 3.0 * force,
            fraction: 0.1,
            fraction_low: 0.09,
            fraction_high: 0.11,
            samples: 4,
            tangential_ratio: ratio.map(|mean| MeanInterval {
                mean,
                low: mean - 1e-4,
                high: mean + 1e-4,
            }),
        };
        TaskResult {
            method: Method::Bem,
            task: Task { n: 64, hurst: 0.5 },
            samples: 4,
            mean_curve: vec![point(1.0), point(10.0)],
            alpha_ensemble: None,
            alpha_samples: Vec::new(),
        }
    }

    #[test]
    fn every_series_has_its_own_colour_when_sizes_share_an_h() {
        // The 256²/512² tangential study drew N = 256 and 512 of one H in one colour.
        let task = |n: usize, hurst: f64| TaskResult {
            task: Task { n, hurst },
            ..result(Some(0.824))
        };
        let results = [
            task(256, 0.0),
            task(256, 0.8),
            task(512, 0.0),
            task(512, 0.8),
        ];
        let transport = Transport::new(Some([1.0, 1.0]), None).unwrap();
        let derived = Derived {
            poisson: Some(0.3),
            transport,
            ..Derived::default()
        };
        let mut charts = derived_charts(&results, derived);
        charts.push(curve_chart(&results, "k(F)"));
        charts.push(area_chart(&results, "A(F)"));
        for chart in &charts {
            let mut colours: Vec<String> = chart.series[..4]
                .iter()
                .map(|s| format!("{:?}", s.color))
                .collect();
            colours.sort();
            colours.dedup();
            assert_eq!(colours.len(), 4, "{}: {colours:?}", chart.title);
        }
        // In order of H, then N: the two N of H = 0 first, at the ends of the scale 0, 0.9.
        let placed = |r: &TaskResult| match task_color(&results, r) {
            Color::Ordered(t) => t,
            other => panic!("{other:?}"),
        };
        let near = |t: Vec<f64>, expected: [f64; 4]| {
            t.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-12)
        };
        let t: Vec<f64> = results.iter().map(placed).collect();
        assert!(near(t.clone(), [0.0, 0.6, 0.3, 0.9]), "{t:?}");
        // One task per H keeps the H scale (the figures of single-N studies unchanged).
        let single = [
            task(256, 0.0),
            task(256, 0.5),
            task(256, 2.0),
            task(256, 4.0),
        ];
        let t: Vec<f64> = single
            .iter()
            .map(|r| {
                let Color::Ordered(t) = task_color(&single, r) else {
                    panic!()
                };
                t
            })
            .collect();
        assert!(near(t.clone(), [0.0, 0.1125, 0.45, 0.9]), "{t:?}");
    }

    #[test]
    fn derived_charts_show_the_excess_over_mindlin_and_the_conductance() {
        let mindlin = 2.0 * 0.7 / 1.7;
        let transport = Transport::new(Some([1.0, 3.0]), None).unwrap();
        let derived = Derived {
            poisson: Some(0.3),
            transport,
            ..Derived::default()
        };
        let charts = derived_charts(&[result(Some(mindlin * 1.001))], derived);
        assert_eq!(charts.len(), 2);
        // The ratio as its excess over Mindlin's, in per cent; Mindlin's line at 0.
        let excess = &charts[0].series[0];
        assert!(
            (excess.points[0].1 - 0.1).abs() < 1e-9,
            "{:?}",
            excess.points
        );
        assert!(charts[0].series[1].points.iter().all(|p| p.1 == 0.0));
        // C = 2k/(E*(ρ₁+ρ₂)) = k/2 here, its band the stiffness's.
        let c = &charts[1].series[0];
        assert_eq!(c.points, vec![(1.0, 1.0), (10.0, 10.0)]);
        assert_eq!(c.interval.as_ref().unwrap()[1], (5.0, 15.0));
        // Without ν the ratio itself; without the ratio or the properties, no chart.
        let plain = derived_charts(&[result(Some(0.8))], Derived::default());
        assert_eq!(plain.len(), 1);
        assert_eq!(plain[0].series[0].points[0].1, 0.8);
        assert!(derived_charts(&[result(None)], Derived::default()).is_empty());
    }
}
