//! `asperity contact --load-path`: the pressures walked in the given order as one load
//! path (loading, unloading, reloading) on a measured surface, in SI units, each step warm
//! from the last and its plastic displacement kept (the front-end layer's
//! [`asperity_app::contact::load_path`], the library's load path that `asperity bem
//! --load-path` runs). The request is `asperity contact`'s; outputs checked before any
//! work and written together at the end.

use anyhow::{Context, Result};
use asperity::bem::{ContactSolver, PathPoint};
use asperity::io::sidecar_path;
use asperity_app::bem::{branches, ensure_solver_fits, Branch};
use asperity_app::contact::{self, ContactPlan, PATH_COLUMNS};
use asperity_app::figure::path::{path_charts, PathColumns, PathFigure};
use serde_json::json;

use super::bem_path::cells;
use super::contact::{check_args, file_name, inputs_record, request, ContactArgs};
use crate::output::Table;
use crate::plot::{stage_charts, Chart};

/// The `--plot` panels ([`asperity_app::figure::path`]): F(d), A/A₀(d) and k(F), each
/// step marked by its branch, in SI units.
fn charts(
    args: &ContactArgs,
    plan: &ContactPlan,
    branch: &[Branch],
    points: &[PathPoint],
) -> [Chart; 3] {
    let column = |f: fn(&PathPoint) -> f64| -> Vec<f64> { points.iter().map(f).collect() };
    let (indentation, force) = (
        column(|p| p.summary.indentation),
        column(|p| p.summary.force),
    );
    let area_fraction = column(|p| p.summary.area_fraction);
    let stiffness = column(|p| p.stiffness);
    let columns = PathColumns {
        branch,
        indentation: &indentation,
        force: &force,
        area_fraction: &area_fraction,
        stiffness: &stiffness,
    };
    let name = file_name(args);
    let figure = PathFigure {
        name: &name,
        boundary: plan.half_space.boundary.name(),
        hardness: args.hardness,
    };
    path_charts(columns, figure)
}

/// Runs `asperity contact --load-path`: check (every refusal before the surface is read),
/// read, the path, then the table, its record and the plot, written together.
pub fn run(args: &ContactArgs) -> Result<()> {
    // The front-end layer's rule: no --map, --tangential or conductance on a path.
    request(args)?.refuse_run_options(true, args.map.is_some())?;
    let plan = check_args(args)?;
    let record_path = args.out.as_deref().map(sidecar_path);
    let outputs = args.out.iter().chain(&record_path).chain(&args.plot);
    let (mut staged, surface, provenance) = super::contact::staged_surface(args, outputs)?;
    let (rows, cols) = surface.dim();
    ensure_solver_fits(rows, cols, plan.half_space.boundary, Some(0))?;
    let mut solver = ContactSolver::new(&surface, plan.half_space, plan.params)
        .with_context(|| format!("{}", args.file.display()))?;
    drop(surface);
    let points = contact::load_path(&mut solver, &plan).context("load path")?;
    let branch = branches(&args.pressures);
    let mut table = Table::new(&PATH_COLUMNS);
    for (&b, point) in branch.iter().zip(&points) {
        table.push(&cells(b, point));
    }
    if let Some(plot) = &args.plot {
        stage_charts(&mut staged, plot, &charts(args, &plan, &branch, &points))
            .with_context(|| format!("writing {}", plot.display()))?;
    }
    match (&args.out, &record_path) {
        (Some(out), Some(record_path)) => {
            table
                .stage(&mut staged, out)
                .with_context(|| format!("writing {}", out.display()))?;
            let mut inputs = inputs_record(args, &plan, provenance);
            inputs["command"] = json!("asperity contact --load-path");
            inputs["stiffness"] =
                json!("frozen contact set (the elastic set 0 < p < H under a hardness)");
            inputs["columns"] = json!(PATH_COLUMNS);
            staged.write_json(record_path, &inputs)?;
        }
        _ => crate::output::print_stdout(&table.to_csv()?)?,
    }
    staged.commit()?;
    Ok(())
}
