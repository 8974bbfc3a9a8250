//! Book Fig. 15.1 (Popov & Heß ch. 15): a rigid sphere on the MDR foundation with linear
//! springs and with the Hertz microscale law (15.2), against Hertz, through the range where
//! a single spring is in contact; CSV, log–log PNG + SVG and a `report.md`.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use asperity::mdr::{log_spaced, Axisymmetric, CurvePoint, Foundation, Spring, SpringLaw};
use asperity::reference::Hertz;

use super::super::setting::Setting;
use super::{Outputs, BLACK, BLUE, GREEN, GREY};
use crate::output::{format_number, Table};
use crate::plot::{Chart, Series, Style};

/// The sphere, the grid and the two foundations.
struct Plan {
    radius: f64,
    dx: f64,
    modulus: f64,
    n: usize,
    /// Depth below which only the spring on the axis touches, Δx²/R.
    critical: f64,
    linear: Foundation,
    nonlinear: Foundation,
    hertz: Hertz,
    levels: Vec<f64>,
}

impl Plan {
    fn new() -> Result<Self> {
        let (radius, dx, modulus, n) = (1.0, 0.01, 1.0, 2001);
        let critical = dx * dx / radius;
        let profile = Axisymmetric::Sphere { radius }.sample(n, dx)?;
        let linear = Foundation::from_profile(&profile, Spring::linear(dx, modulus)?)?;
        let nonlinear = Foundation::from_profile(
            &profile,
            Spring::new(SpringLaw::Hertz { radius }, dx, modulus)?,
        )?;
        Ok(Plan {
            radius,
            dx,
            modulus,
            n,
            critical,
            linear,
            nonlinear,
            hertz: Hertz { radius, modulus },
            levels: log_spaced(1e-3 * critical, 1e3 * critical, 121)?,
        })
    }

    fn row(&self, d: f64) -> Row {
        Row {
            d,
            linear: self.linear.evaluate(d),
            nonlinear: self.nonlinear.evaluate(d),
        }
    }
}

/// Both foundations at one indentation.
struct Row {
    d: f64,
    linear: CurvePoint,
    nonlinear: CurvePoint,
}

/// Book Fig. 15.1: a sphere on linear springs and on springs with the Hertz law (15.2),
/// against Hertz, through the range where a single spring is in contact.
pub fn fig15_1(out: &Path, setting: Setting, force: bool) -> Result<()> {
    let outputs = Outputs::new(
        out.join("fig15.1"),
        &[
            "fig15_1.csv",
            "fig15_1.png",
            "fig15_1.svg",
            "fig15_1_stiffness.png",
            "fig15_1_stiffness.svg",
            "report.md",
        ],
        force,
    )?;
    let plan = Plan::new()?;
    let rows: Vec<Row> = plan.levels.iter().map(|&d| plan.row(d)).collect();
    write_table(&outputs, &plan, &rows)?;
    write_charts(&outputs, &plan, &rows, setting)?;
    outputs.write_report("fig15.1", &report(&plan, &rows)?)
}

fn write_table(outputs: &Outputs, plan: &Plan, rows: &[Row]) -> Result<()> {
    let mut table = Table::new(&[
        "indentation",
        "force_linear",
        "force_nonlinear",
        "force_hertz",
        "stiffness_linear",
        "stiffness_nonlinear",
        "stiffness_hertz",
        "contacts_linear",
        "contacts_nonlinear",
    ]);
    for r in rows {
        let (l, nl) = (&r.linear, &r.nonlinear);
        table.push(&[
            format_number(r.d),
            format_number(l.force),
            format_number(nl.force),
            format_number(plan.hertz.force(r.d)),
            format_number(l.stiffness),
            format_number(nl.stiffness),
            format_number(plan.hertz.stiffness(r.d)),
            l.contacts.to_string(),
            nl.contacts.to_string(),
        ]);
    }
    table.write(&outputs.path("fig15_1.csv"), outputs.force)
}

fn write_charts(outputs: &Outputs, plan: &Plan, rows: &[Row], setting: Setting) -> Result<()> {
    let mark = format!("({} setting)", setting.name());
    let series = |f: &dyn Fn(&Row) -> f64| rows.iter().map(|r| (r.d, f(r))).collect::<Vec<_>>();
    let (levels, hertz, critical) = (&plan.levels, &plan.hertz, plan.critical);
    let f_range = (
        hertz.force(levels[0]),
        hertz.force(levels[levels.len() - 1]),
    );
    let (radius, dx) = (plan.radius, plan.dx);
    let chart = Chart {
        title: format!("Fig. 15.1: sphere R = {radius}, Δx = {dx}: force {mark}"),
        x_label: "indentation d".into(),
        y_label: "normal force F / E*".into(),
        log_x: true,
        log_y: true,
        series: vec![
            Series::new("linear springs", series(&|r| r.linear.force), Style::Line).color(BLUE),
            Series::new(
                "non-linear springs (15.2)",
                series(&|r| r.nonlinear.force),
                Style::Line,
            )
            .color(GREEN),
            Series::new(
                "Hertz F = 4/3 E* R^1/2 d^3/2",
                levels.iter().map(|&d| (d, hertz.force(d))).collect(),
                Style::Dashed,
            )
            .color(BLACK),
            Series::new(
                "d = Δx²/R (one spring below)",
                vec![(critical, f_range.0), (critical, f_range.1)],
                Style::Dashed,
            )
            .color(GREY),
        ],
    };
    outputs.save_chart(&chart, "fig15_1")?;
    let chart = Chart {
        title: format!("Fig. 15.1: sphere R = {radius}, Δx = {dx}: stiffness {mark}"),
        y_label: "contact stiffness k / E*".into(),
        series: vec![
            Series::new(
                "linear springs",
                series(&|r| r.linear.stiffness),
                Style::Line,
            )
            .color(BLUE),
            Series::new(
                "non-linear springs (15.2)",
                series(&|r| r.nonlinear.stiffness),
                Style::Line,
            )
            .color(GREEN),
            Series::new(
                "Hertz k = 2 E* a",
                levels.iter().map(|&d| (d, hertz.stiffness(d))).collect(),
                Style::Dashed,
            )
            .color(BLACK),
        ],
        ..chart
    };
    outputs.save_chart(&chart, "fig15_1_stiffness")
}

/// The largest relative deviation of `pick(row)` from the Hertz force over the rows with
/// `lo ≤ d/u0 ≤ hi`, as `(d/u0, deviation)` (NaN where none).
fn worst(plan: &Plan, rows: &[Row], (lo, hi): (f64, f64), pick: fn(&Row) -> f64) -> (f64, f64) {
    let critical = plan.critical;
    rows.iter()
        .filter(|r| r.d >= lo * critical && r.d <= hi * critical)
        .map(|r| (r.d / critical, pick(r) / plan.hertz.force(r.d) - 1.0))
        .fold((f64::NAN, 0.0f64), |acc, (t, e)| {
            if e.abs() > acc.1.abs() {
                (t, e)
            } else {
                acc
            }
        })
}

fn report(plan: &Plan, rows: &[Row]) -> Result<String> {
    let (radius, dx, modulus, n, critical) =
        (plan.radius, plan.dx, plan.modulus, plan.n, plan.critical);
    let hertz = &plan.hertz;
    let mut report = String::new();
    writeln!(
        report,
        "# Book Fig. 15.1 — Hertz contact with linear and non-linear springs\n"
    )?;
    writeln!(
        report,
        "A rigid sphere of radius R = {radius} on the MDR foundation (profile g = x²/R, eq. 15.1), \
         {n} springs at Δx = {dx}, E* = {modulus}; force, stiffness and contacts at {} indentations \
         log-spaced from 1e-3 to 1e3 times the critical depth u⁽⁰⁾ = Δx²/R = {critical:e}, below \
         which only the spring on the axis touches. Springs: linear (stiffness E*Δx) and the Hertz \
         microscale law (15.2). Reference: Hertz, F = 4/3 E* R^½ d^(3/2), k = 2E*a, a = sqrt(Rd). \
         `--quick` changes nothing here (the computation takes milliseconds).\n",
        plan.levels.len()
    )?;
    writeln!(
        report,
        "| d / u⁽⁰⁾ | F linear / F Hertz | F (15.2) / F Hertz |"
    )?;
    writeln!(report, "|---|---|---|")?;
    for &t in &[1e-3, 1e-2, 0.1, 1.0, 2.0, 10.0, 100.0, 1e3] {
        let r = plan.row(t * critical);
        writeln!(
            report,
            "| {t} | {:.4} | {:.4} |",
            r.linear.force / hertz.force(r.d),
            r.nonlinear.force / hertz.force(r.d)
        )?;
    }
    writeln!(report)?;
    write_findings(&mut report, plan, rows)?;
    writeln!(
        report,
        "\nFiles: `fig15_1.csv` (columns indentation, force_linear, force_nonlinear, force_hertz, \
         stiffness_linear, stiffness_nonlinear, stiffness_hertz, contacts_linear, \
         contacts_nonlinear), `fig15_1.png/svg` (force), `fig15_1_stiffness.png/svg`."
    )?;
    Ok(report)
}

/// The three ranges of the report: one spring, the transition, many springs.
fn write_findings(report: &mut String, plan: &Plan, rows: &[Row]) -> Result<()> {
    let hertz = &plan.hertz;
    let nl_single = worst(plan, rows, (0.0, 0.999), |r| r.nonlinear.force);
    let nl_transition = worst(plan, rows, (1.0, 100.0), |r| r.nonlinear.force);
    let nl_many = worst(plan, rows, (100.0, 1e3), |r| r.nonlinear.force);
    let lin_many = worst(plan, rows, (100.0, 1e3), |r| r.linear.force);
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    writeln!(
        report,
        "- One spring in contact (d < u⁽⁰⁾): linear springs give F = E*Δx·d, {:.0}× Hertz at \
         d = 1e-3 u⁽⁰⁾; the law (15.2) gives Hertz exactly (largest deviation {:.1e}).",
        first.linear.force / hertz.force(first.d),
        nl_single.1.abs()
    )?;
    writeln!(
        report,
        "- Transition (u⁽⁰⁾ ≤ d ≤ 100 u⁽⁰⁾): the book's \"small irregularity\": the largest \
         deviation of (15.2) from Hertz is {:+.1} % at d = {:.2} u⁽⁰⁾ (the neighbours of the axis \
         spring join on their own Hertz branch while the axis spring is already linear).",
        100.0 * nl_transition.1,
        nl_transition.0
    )?;
    writeln!(
        report,
        "- Many springs (100 u⁽⁰⁾ ≤ d ≤ 1000 u⁽⁰⁾, a ≥ 10 Δx): linear springs within {:.2} %, \
         (15.2) within {:.2} % of Hertz; at d = 1000 u⁽⁰⁾ the stiffness is {:.4} (linear) and \
         {:.4} (15.2) of 2E*a.",
        100.0 * lin_many.1.abs(),
        100.0 * nl_many.1.abs(),
        last.linear.stiffness / hertz.stiffness(last.d),
        last.nonlinear.stiffness / hertz.stiffness(last.d)
    )?;
    Ok(())
}
