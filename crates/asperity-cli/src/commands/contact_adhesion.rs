//! `asperity contact --work-of-adhesion`: adhesive contact of a measured surface in SI units
//! along the path of `--indentations`, then retracted to pull-off — the front-end layer's
//! [`asperity_app::contact_adhesion`] (the request of `asperity contact`, the adhesive BEM
//! of `asperity bem --work-of-adhesion`, the one Python's `contact(work_of_adhesion=…)`
//! runs). Outputs checked before any work and written together at the end.

use anyhow::{Context, Result};
use asperity::bem::adhesion::AdhesiveSummary;
use asperity::io::sidecar_path;
use asperity_app::adhesion::{AdhesionPlan, AdhesionRun};
use asperity_app::contact::Value;
use asperity_app::contact_adhesion::{values, COLUMNS};
use serde_json::json;

use super::contact::{file_name, request, ContactArgs};
use crate::output::{format_number, Table};
use crate::plot::stage_charts;
use asperity_app::figure::adhesion::LoopFigure;

/// Runs `asperity contact --work-of-adhesion`: check (every refusal before the surface is
/// read), read, the path and the retraction, then the table, its record and the loop's plot.
pub fn run(args: &ContactArgs) -> Result<()> {
    let request = request(args)?;
    // The front-end layer's rule: no --map, no --load-path.
    request.refuse_run_options(args.load_path, args.map.is_some())?;
    let plan = request.adhesion_plan()?;
    if let Some(plot) = &args.plot {
        crate::plot::ImageFormat::from_path(plot, "--plot")?;
    }
    let record_path = args.out.as_deref().map(sidecar_path);
    let outputs = args.out.iter().chain(&record_path).chain(&args.plot);
    let (mut staged, surface, provenance) = super::contact::staged_surface(args, outputs)?;
    let points = surface.dim().0 * surface.dim().1;
    let pixel_area = surface.spacing() * surface.spacing_y();
    let mut table = Table::new(&COLUMNS);
    let run = plan
        .run(&surface, &mut |row| {
            let mut cells: Vec<String> = values(row, pixel_area, points)
                .iter()
                .map(|v| match *v {
                    Value::Number(x) => format_number(x),
                    Value::Count(n) => n.to_string(),
                })
                .collect();
            cells.push(row.branch.name().to_string());
            table.push(&cells);
        })
        .with_context(|| format!("adhesive contact of {}", args.file.display()))?;
    drop(surface);
    if let Some(plot) = &args.plot {
        let chart = run.loop_chart(LoopFigure {
            title: format!(
                "{}: {}, Δγ = {} J/m², E* = {} Pa",
                file_name(args),
                plan.law.name(),
                plan.work_of_adhesion,
                plan.half_space.modulus
            ),
            x_label: "indentation d  [m]".into(),
            y_label: "normal force F  [N]".into(),
            force_unit: " N".into(),
            theory: None,
        });
        stage_charts(&mut staged, plot, &[chart])
            .with_context(|| format!("writing {}", plot.display()))?;
    }
    match (&args.out, &record_path) {
        (Some(out), Some(record_path)) => {
            table
                .stage(&mut staged, out)
                .with_context(|| format!("writing {}", out.display()))?;
            let inputs = inputs_record(args, &plan, provenance);
            staged.write_json(record_path, &adhesion_record(inputs, &plan, &run))?;
        }
        _ => crate::output::print_stdout(&table.to_csv()?)?,
    }
    staged.commit()?;
    super::bem_adhesion::report_pull_off(&run, (" N", " m"));
    Ok(())
}

/// What OUT.csv.json records of the inputs (SI units).
fn inputs_record(
    args: &ContactArgs,
    plan: &AdhesionPlan,
    surface: serde_json::Value,
) -> serde_json::Value {
    json!({
        "surface": surface,
        "effective_modulus_pa": plan.half_space.modulus,
        "young_pa": args.young,
        "poisson": args.poisson,
        "boundary": plan.half_space.boundary.name(),
        "units": "SI: m, Pa, N, m², J/m²",
    })
}

/// OUT.csv.json: `asperity contact`'s inputs, then the adhesive law, the path and both
/// pull-offs, in SI units.
fn adhesion_record(
    mut inputs: serde_json::Value,
    plan: &AdhesionPlan,
    run: &AdhesionRun,
) -> serde_json::Value {
    let point = |s: &AdhesiveSummary| {
        json!({ "force_n": s.force, "indentation_m": s.indentation,
                "attached_points": s.attached_points })
    };
    inputs["command"] = json!("asperity contact --work-of-adhesion");
    inputs["adhesion"] = json!({
        "model": plan.law.name(),
        "work_of_adhesion_j_per_m2": plan.work_of_adhesion,
        "range_m": plan.law.range(),
        "zone_resolution": run.zone_resolution,
        "critical_stress_pa": run.critical_stress,
        "indentations_m": plan.indentations,
        "retract_step_m": plan.retract_step,
        "pull_off": run.pull_off.map(|p| json!({
            "force_controlled": point(&p.force_controlled),
            "displacement_controlled": point(&p.displacement_controlled),
            "separated_at_m": p.separated_at,
        })),
        "warning": run.resolution_warning(),
    });
    inputs["columns"] = json!(COLUMNS);
    inputs
}
