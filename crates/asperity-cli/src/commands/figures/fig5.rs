//! Paper Fig. 5: the exponent α versus the number of modes N for H = −0.5 (MDR lines and
//! BEM grids), against eq. (24), α = (1 + log2 N)/(3 + log2 N).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use asperity::study::theory::alpha_white_noise;
use asperity::study::{Method, TaskResult};
use asperity_app::study::report::{write as write_comparison, Results};

use super::super::setting::Setting;
use super::{announce, figure_study, study_spec};
use crate::output::{format_number, Table};
use crate::plot::{Chart, ChartFiles, Series, Style};
use crate::request::report_error;
use crate::studies::Kind;

/// How a row's N counts modes: the paper plots each BEM grid twice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Counting {
    /// MDR: N is the number of modes of the line.
    Modes,
    /// BEM: N is the number of lines per side.
    Lines,
    /// BEM: N² grid points.
    Points,
}

impl Counting {
    fn name(self) -> &'static str {
        match self {
            Counting::Modes => "modes",
            Counting::Lines => "lines",
            Counting::Points => "points",
        }
    }

    fn method(self) -> &'static str {
        match self {
            Counting::Modes => "mdr",
            Counting::Lines | Counting::Points => "bem",
        }
    }
}

/// One point of the figure.
struct Row {
    counting: Counting,
    n: f64,
    /// α of the ensemble fit (NaN where it failed).
    alpha: f64,
    /// The 95 % interval of the per-sample α (NaN where there is none).
    interval: (f64, f64),
}

fn rows(mdr: &[TaskResult], bem: &[TaskResult]) -> Vec<Row> {
    let alpha = |r: &TaskResult| r.alpha_ensemble.map_or(f64::NAN, |a| a.exponent);
    let interval = |r: &TaskResult| r.alpha_sample_interval().unwrap_or((f64::NAN, f64::NAN));
    let mut rows: Vec<Row> = mdr
        .iter()
        .map(|r| Row {
            counting: Counting::Modes,
            n: r.task.n as f64,
            alpha: alpha(r),
            interval: interval(r),
        })
        .collect();
    for r in bem {
        let (n, a, interval) = (r.task.n as f64, alpha(r), interval(r));
        rows.push(Row {
            counting: Counting::Lines,
            n,
            alpha: a,
            interval,
        });
        rows.push(Row {
            counting: Counting::Points,
            n: n * n,
            alpha: a,
            interval,
        });
    }
    rows
}

/// Paper Fig. 5: α versus N for H < 0 against eq. (24).
pub fn fig5(dir: &Path, setting: Setting, force: bool, discard: bool) -> Result<()> {
    let (mdr_sizes, mdr_samples) = setting.fig5_mdr();
    let mdr = study_spec(Method::Mdr, mdr_sizes, vec![-0.5], mdr_samples, None);
    let plan = setting.fig5_bem();
    let bem =
        study_spec(Method::Bem, plan.sizes, plan.hursts, plan.samples, None).with_alpha_sweep();
    let bem = crate::studies::resumable(bem, &dir.join("bem"), discard, false);
    announce("fig5", setting, dir, &[&bem])?;
    let mdr_results = figure_study(dir, "mdr", &mdr, Kind::Alpha, setting, discard)?;
    let bem_results = figure_study(dir, "bem", &bem, Kind::Alpha, setting, discard)?;
    let rows = rows(&mdr_results, &bem_results);
    write_table(dir, &rows, force)?;
    write_chart(dir, &rows, setting, force)?;
    let mut md = String::from(
        "| method | N as | N | log2 N | α (ours) | eq. (24) |\n|---|---|---|---|---|---|\n",
    );
    for r in &rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.0} | {:.3} | {:.3} |",
            r.counting.method(),
            r.counting.name(),
            r.n,
            r.n.log2(),
            r.alpha,
            alpha_white_noise(r.n)
        );
    }
    let report = format!(
        "# Fig. 5: α versus N for H < 0\n\n{}\n\n\
         H = -0.5. MDR: N = {:?}, {} samples each. BEM: free boundaries, N = {:?}, {} samples each,\n\
         each shown twice: N as lines per side and N² as grid points (as the paper does).\n\
         α window: {}.\n\n\
         ## The paper's values beside ours\n\
         The paper: MDR follows eq. (24), α = (1 + log2 N)/(3 + log2 N), closely; BEM follows a\n\
         similar dependence.\n\n{md}\n",
        setting.describe(),
        mdr.sizes,
        mdr.samples,
        bem.sizes,
        bem.samples,
        mdr.window.describe()
    );
    let results = Results::Fig5(&mdr_results, &bem_results);
    write_comparison(dir, results, &report, force).map_err(report_error)
}

fn write_table(dir: &Path, rows: &[Row], force: bool) -> Result<()> {
    let mut table = Table::new(&[
        "method",
        "n_interpretation",
        "n",
        "log2_n",
        "alpha",
        "alpha_eq24",
        "alpha_low",
        "alpha_high",
    ]);
    for r in rows {
        table.push(&[
            r.counting.method().to_string(),
            r.counting.name().to_string(),
            format_number(r.n),
            format_number(r.n.log2()),
            format_number(r.alpha),
            format_number(alpha_white_noise(r.n)),
            format_number(r.interval.0),
            format_number(r.interval.1),
        ]);
    }
    table.write(&dir.join("fig5.csv"), force)
}

fn write_chart(dir: &Path, rows: &[Row], setting: Setting, force: bool) -> Result<()> {
    let theory: Vec<(f64, f64)> = (4..=21)
        .map(|m| (m as f64, alpha_white_noise(2f64.powi(m))))
        .collect();
    // Markers with the 95 % interval of the samples as error bars.
    let pick = |label: &str, counting: Counting, color| {
        let rows: Vec<&Row> = rows.iter().filter(|r| r.counting == counting).collect();
        // MDR and BEM share some N: their bars are shifted apart by 0.2.
        let shift = if counting == Counting::Modes {
            -0.1
        } else {
            0.1
        };
        let points = rows.iter().map(|r| (r.n.log2() + shift, r.alpha)).collect();
        Series::new(label, points, Style::Points)
            .color(color)
            .interval(rows.iter().map(|r| r.interval).collect())
    };
    Chart {
        title: format!(
            "Fig. 5: α vs grid size for H = -0.5 ({} setting)",
            setting.name()
        ),
        x_label: "log2 N (MDR shifted by -0.1, BEM by +0.1)".into(),
        y_label: "α (bars: 95 % of the single-sample α)".into(),
        log_x: false,
        log_y: false,
        series: vec![
            Series::new("eq. (24)", theory, Style::Line).color(asperity_app::figure::Color::RED),
            pick(
                "MDR (N = modes)",
                Counting::Modes,
                asperity_app::figure::Color::BLACK,
            ),
            pick(
                "BEM (N = lines per side)",
                Counting::Lines,
                asperity_app::figure::Color::Rgb(0, 255, 0),
            ),
            pick(
                "BEM (N = grid points)",
                Counting::Points,
                asperity_app::figure::Color::Rgb(255, 0, 255),
            ),
        ],
    }
    .save(&dir.join("fig5.png"), &dir.join("fig5.svg"), force)
}
