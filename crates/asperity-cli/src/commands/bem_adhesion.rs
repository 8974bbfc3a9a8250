//! `asperity bem --work-of-adhesion`: adhesive contact by Pohrt & Popov's pixel criterion
//! (or with `--adhesion-range` a Maugis–Dugdale cohesive zone or, `--adhesion-model
//! exponential`, an exponential potential) along the path of `--indentations`, then retracted to pull-off (the front-end layer's
//! [`AdhesionRequest`], the one Python's `bem_adhesion` runs). Outputs as `asperity bem`'s:
//! checked before any work, written together at the end.

use anyhow::{bail, Context, Result};
use asperity::bem::adhesion::AdhesionLaw;
use asperity::io::sidecar_path;
use asperity_app::adhesion::{AdhesionRequest, AdhesionRun};
use serde_json::json;

use super::bem::{read_surface_for, stage_outputs, BemArgs};
use crate::output::{format_number, pull_off_line, Table};
use crate::plot::stage_charts;
use asperity_app::figure::adhesion::LoopFigure;

/// The columns of the table.
pub const COLUMNS: [&str; 8] = [
    "indentation",
    "force",
    "mean_pressure",
    "area_fraction",
    "tensile_fraction",
    "rounds",
    "cg_iterations",
    "branch",
];

/// The options `asperity bem` has that an adhesive run refuses, with the flag named.
fn refuse_other_options(args: &BemArgs) -> Result<()> {
    let given = [
        (args.forces.is_some(), "--forces"),
        (args.pressures.is_some(), "--pressures"),
        (args.nloads.is_some(), "--nloads"),
        (args.pmin.is_some() || args.pmax.is_some(), "--pmin/--pmax"),
        (args.hardness.is_some(), "--hardness"),
        (args.load_path, "--load-path"),
        (args.solver != "bccg", "--solver"),
        (args.fd_stiffness, "--fd-stiffness"),
        (args.fields.is_some(), "--fields"),
        (args.timing || args.no_stiffness, "--timing"),
        (args.poisson.is_some(), "--poisson"),
        (args.resistivity.is_some(), "--resistivity"),
        (
            args.thermal_conductivity.is_some(),
            "--thermal-conductivity",
        ),
    ];
    if let Some((_, flag)) = given.iter().find(|(on, _)| *on) {
        bail!(
            "--work-of-adhesion takes a path of --indentations (the pixel criterion is solved \
             under displacement control, both pull-offs reported) and does not go with {flag}"
        );
    }
    if args.indentations.is_none() {
        bail!("--work-of-adhesion needs --indentations: the path to follow before the retraction");
    }
    Ok(())
}

/// The request of the arguments.
fn request(args: &BemArgs, w: f64) -> AdhesionRequest {
    AdhesionRequest {
        modulus: args.modulus,
        boundary: args.boundary.clone(),
        work_of_adhesion: w,
        adhesion_range: args.adhesion_range,
        adhesion_model: args.adhesion_model.clone(),
        indentations: args.indentations.clone().unwrap_or_default(),
        retract_step: args.retract_step,
    }
}

/// Runs `asperity bem --work-of-adhesion`.
pub fn run(args: &BemArgs, w: f64) -> Result<()> {
    refuse_other_options(args)?;
    let request = request(args, w);
    let plan = request.validate()?;
    if let Some(plot) = &args.plot {
        crate::plot::ImageFormat::from_path(plot, "--plot")?;
    }
    let mut outputs = stage_outputs(args, 0)?;
    let (surface, size_source) = read_surface_for(args, plan.half_space.boundary)?;
    let mut table = Table::new(&COLUMNS);
    let points = surface.dim().0 * surface.dim().1;
    let run = plan
        .run(&surface, &mut |row| {
            let s = &row.summary;
            table.push(&[
                format_number(s.indentation),
                format_number(s.force),
                format_number(s.mean_pressure),
                format_number(s.area_fraction),
                format_number(s.tensile_points as f64 / points as f64),
                row.info.rounds.to_string(),
                row.info.cg_iterations.to_string(),
                row.branch.name().to_string(),
            ]);
        })
        .context("adhesive BEM")?;
    if let Some(plot) = &args.plot {
        let name = args
            .surface
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into());
        let chart = run.loop_chart(LoopFigure {
            title: format!(
                "{name}: {}, Δγ = {w}, E* = {}",
                plan.law.name(),
                request.modulus
            ),
            x_label: "indentation d  [length]".into(),
            y_label: "normal force F  [E*·length²]".into(),
            force_unit: String::new(),
            theory: None,
        });
        stage_charts(&mut outputs.staged, plot, &[chart])
            .with_context(|| format!("writing {}", plot.display()))?;
    }
    if let Some(out) = &args.out {
        table
            .stage(&mut outputs.staged, out)
            .with_context(|| format!("writing {}", out.display()))?;
        let record_path = sidecar_path(out);
        let record = record(args, (&request, plan.law), (&surface, size_source), &run);
        outputs
            .staged
            .write_json(&record_path, &record)
            .with_context(|| format!("writing {}", record_path.display()))?;
    }
    outputs.staged.commit()?;
    report(args, &run, &table)
}

/// The inputs and the pull-offs of a run, for OUT.csv.json.
fn record(
    args: &BemArgs,
    (request, law): (&AdhesionRequest, AdhesionLaw),
    (surface, size_source): (&asperity::surface::Surface, &'static str),
    run: &AdhesionRun,
) -> serde_json::Value {
    let point = |s: &asperity::bem::adhesion::AdhesiveSummary| {
        json!({ "force": s.force, "indentation": s.indentation,
                "attached_points": s.attached_points })
    };
    json!({
        "command": "asperity bem --work-of-adhesion",
        "version": env!("CARGO_PKG_VERSION"),
        "surface": args.surface,
        "grid": [surface.dim().0, surface.dim().1],
        "size": surface.size(),
        "size_source": size_source,
        "modulus": request.modulus,
        "boundary": request.boundary,
        "adhesion": {
            "model": match law {
                AdhesionLaw::PixelCriterion => "Pohrt–Popov pixel criterion",
                AdhesionLaw::MaugisDugdale { .. } => "Maugis–Dugdale cohesive zone",
                AdhesionLaw::Exponential { .. } => "exponential potential",
            },
            "work_of_adhesion": request.work_of_adhesion,
            "range": request.adhesion_range,
            "zone_resolution": run.zone_resolution,
            "critical_stress": run.critical_stress,
            "indentations": request.indentations,
            "retract_step": request.retract_step,
            "pull_off": run.pull_off.map(|p| json!({
                "force_controlled": point(&p.force_controlled),
                "displacement_controlled": point(&p.displacement_controlled),
                "separated_at": p.separated_at,
            })),
        },
        "columns": COLUMNS,
    })
}

/// The pull-offs and any resolution warning on stderr; the table on stdout without --out.
fn report(args: &BemArgs, run: &AdhesionRun, table: &Table) -> Result<()> {
    report_pull_off(run, ("", ""));
    match &args.out {
        Some(out) if !args.quiet => eprintln!(
            "wrote {} and {} ({} rows)",
            out.display(),
            sidecar_path(out).display(),
            run.rows.len()
        ),
        Some(_) => {}
        None => crate::output::print_stdout(&table.to_csv()?)?,
    }
    Ok(())
}

/// The pull-offs (numbers followed by `units`: force, length) and any resolution warning,
/// on stderr: `bem` in model units, `contact` in SI.
pub(super) fn report_pull_off(run: &AdhesionRun, units: (&str, &str)) {
    match &run.pull_off {
        Some(p) => eprintln!(
            "{}",
            pull_off_line(
                (p.force_controlled.force, p.force_controlled.indentation),
                (
                    p.displacement_controlled.force,
                    p.displacement_controlled.indentation
                ),
                units,
            )
        ),
        None => eprintln!("pull-off: nothing attached at the end of the path"),
    }
    if let Some(warning) = run.resolution_warning() {
        eprintln!("warning: {warning}");
    }
}
