//! `asperity mdr --tangential-force`: the partial-slip cycle of an MDR indenter at one
//! indentation (the rules and the cycle are the front-end layer's,
//! [`asperity_app::slip::SlipRequest`]).

use anyhow::{Context, Result};
use asperity::io::{sidecar_path, StagedOutputs};
use asperity::mdr::Spring;
use asperity_app::mdr::MdrRequest;
use asperity_app::slip::{SlipCycle, SlipRequest, COLUMNS};
use serde_json::json;

use super::mdr::{load_indenter, MdrArgs};
use crate::output::{format_number, Table};
use crate::plot::{stage_charts, Chart, ImageFormat, Series, Style};
use crate::request::refused;

fn slip_request(args: &MdrArgs) -> SlipRequest {
    SlipRequest {
        poisson: args.poisson,
        friction: args.friction,
        tangential_force: args.tangential_force.unwrap_or_default(),
        cycle_points: args.cycle_points,
    }
}

/// The table of the cycle (no `stick_radius` column for a line).
fn table_of(cycle: &SlipCycle) -> Table {
    let columns = if cycle.stick_radius.is_some() {
        &COLUMNS[..]
    } else {
        &COLUMNS[..4]
    };
    let mut table = Table::new(columns);
    for (i, p) in cycle.points.iter().enumerate() {
        let mut row = vec![
            p.branch.name().to_string(),
            format_number(p.displacement),
            format_number(p.force),
            p.stick_springs.to_string(),
        ];
        if let Some(radius) = &cycle.stick_radius {
            row.push(format_number(radius[i]));
        }
        table.push(&row);
    }
    table
}

/// The loop Q against u, linear axes.
fn loop_chart(cycle: &SlipCycle, description: &str) -> Chart {
    Chart {
        title: format!("{description}: tangential cycle"),
        x_label: "tangential displacement u  [length]".into(),
        y_label: "tangential force Q  [force]".into(),
        log_x: false,
        log_y: false,
        series: vec![Series::new(
            "",
            cycle
                .points
                .iter()
                .map(|p| (p.displacement, p.force))
                .collect(),
            Style::Line,
        )],
    }
}

/// Runs the cycle: check, compute, then write every output together.
pub fn run(args: &MdrArgs, request: &MdrRequest) -> Result<()> {
    let slip = slip_request(args);
    slip.check(request).map_err(refused)?;
    if let Some(plot) = &args.plot {
        ImageFormat::from_path(plot, "--plot")?;
    }
    let record_path = args.out.as_deref().map(sidecar_path);
    let outputs = args.out.iter().chain(&record_path).chain(&args.plot);
    let mut staged = StagedOutputs::new(outputs, args.force)?;
    for input in args.line.iter().chain(&args.radial) {
        staged.ensure_not_input(input)?;
    }
    let indenter = load_indenter(args, request)?;
    let law = request.spring_law(&indenter)?;
    let spring = Spring::new(law, indenter.spacing, args.modulus)?;
    let cycle = slip.run(request, &indenter, spring).map_err(refused)?;
    let table = table_of(&cycle);
    let columns: Vec<&str> = COLUMNS[..if cycle.stick_radius.is_some() { 5 } else { 4 }].to_vec();
    if let Some(plot) = &args.plot {
        stage_charts(
            &mut staged,
            plot,
            &[loop_chart(&cycle, &indenter.description)],
        )
        .with_context(|| format!("writing {}", plot.display()))?;
    }
    let summary = cycle.summary();
    if let (Some(out), Some(record_path)) = (&args.out, &record_path) {
        table
            .stage(&mut staged, out)
            .with_context(|| format!("writing {}", out.display()))?;
        let record = json!({
            "command": "asperity mdr --tangential-force",
            "version": env!("CARGO_PKG_VERSION"),
            "indenter": indenter.source,
            "springs": indenter.values.len(),
            "spacing": indenter.spacing,
            "modulus": args.modulus,
            "spring_law": law,
            "poisson": args.poisson,
            "friction": args.friction,
            "tangential_force": args.tangential_force,
            "cycle": summary,
            "columns": columns,
        });
        staged
            .write_json(record_path, &record)
            .with_context(|| format!("writing {}", record_path.display()))?;
    }
    staged.commit()?;
    eprintln!(
        "{}: F = {:.6e}, μF = {:.6e}, no-slip tangential stiffness {:.6e}, dissipation per \
         cycle {:.6e}",
        indenter.description,
        cycle.normal_force,
        cycle.friction_limit,
        cycle.no_slip_stiffness,
        cycle.dissipation
    );
    match &args.out {
        Some(out) => eprintln!(
            "wrote {} and {}",
            out.display(),
            sidecar_path(out).display()
        ),
        None => crate::output::print_stdout(&table.to_csv()?)?,
    }
    Ok(())
}
