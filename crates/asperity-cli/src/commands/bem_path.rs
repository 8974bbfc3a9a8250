//! `asperity bem --load-path`: the loads walked in the given order as one load path
//! (loading, unloading, reloading), each step warm from the last and its plastic
//! displacement kept (the library's [`load_path`], the one Python's `Solver.load_path`
//! runs), so a table shows the hysteresis of force, area and stiffness under a hardness.
//! The request is `asperity bem`'s ([`BemRequest`]); outputs as `asperity bem`'s: checked
//! before any work, written together at the end.

use anyhow::{bail, Context, Result};
use asperity::bem::{load_path, PathPoint};
use std::path::Path;

use asperity::io::{sidecar_path, StagedOutputs};
use asperity_app::bem::{branches, BemPlan, BemRequest, Branch, PATH_COLUMNS};
use asperity_app::figure::path::{PathColumns, PathFigure};
use serde_json::json;

use super::bem::{read_surface_for, request, BemArgs};
use super::fields_nc::{check_target, fields_folder, netcdf_target, stage_path, Grid as NcGrid};
use crate::output::{format_number, Table};
use crate::plot::{stage_charts, Chart, ImageFormat};
use asperity_app::argument::SizeSource;

/// The options of `asperity bem` that a load path refuses, with the flag named.
fn refuse_other_options(args: &BemArgs) -> Result<()> {
    let given = [
        (args.fd_stiffness, "--fd-stiffness"),
        (args.timing, "--timing"),
        (args.no_stiffness, "--no-stiffness"),
        (args.poisson.is_some(), "--poisson"),
        (args.resistivity.is_some(), "--resistivity"),
        (
            args.thermal_conductivity.is_some(),
            "--thermal-conductivity",
        ),
    ];
    if let Some((_, flag)) = given.iter().find(|(on, _)| *on) {
        bail!("--load-path does not go with {flag} (a path reports the frozen-set stiffness of each step)");
    }
    if let Some(plot) = &args.plot {
        ImageFormat::from_path(plot, "--plot")?;
    }
    Ok(())
}

/// The `--plot` panels ([`asperity_app::figure::path`]): F(d), A/A₀(d) and k(F), each
/// step marked by its branch.
fn path_charts(
    args: &BemArgs,
    plan: &BemPlan,
    branch: &[Branch],
    points: &[PathPoint],
) -> [Chart; 3] {
    let column = |f: &dyn Fn(&PathPoint) -> f64| -> Vec<f64> { points.iter().map(f).collect() };
    let (indentation, force) = (
        column(&|p| p.summary.indentation),
        column(&|p| p.summary.force),
    );
    let area_fraction = column(&|p| p.summary.area_fraction);
    let stiffness = column(&|p| p.stiffness);
    let name = args.surface.file_name().map_or_else(
        || args.surface.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    let columns = PathColumns {
        branch,
        indentation: &indentation,
        force: &force,
        area_fraction: &area_fraction,
        stiffness: &stiffness,
    };
    let figure = PathFigure {
        name: &name,
        boundary: plan.half_space.boundary.name(),
        hardness: plan.hardness(),
    };
    asperity_app::figure::path::path_charts(columns, figure)
}

/// The outputs, checked before any work (as `asperity bem`'s): the table, its record, the
/// plot and `permanent` (in `--fields DIR`, made here and removed again on any error).
fn stage(args: &BemArgs, permanent: Option<&Path>) -> Result<StagedOutputs> {
    let record_path = args.out.as_deref().map(sidecar_path);
    let paths = args
        .out
        .as_deref()
        .into_iter()
        .chain(record_path.as_deref())
        .chain(args.plot.as_deref())
        .chain(permanent);
    let folder = fields_folder(args.fields.as_ref());
    let staged = StagedOutputs::in_new_folders(folder, paths, args.force)?;
    staged.ensure_not_input(&args.surface)?;
    Ok(staged)
}

/// One step's CSV cells, in the order of [`PATH_COLUMNS`] (and of `asperity contact
/// --load-path`'s, whose units are SI).
pub(super) fn cells(branch: Branch, point: &PathPoint) -> Vec<String> {
    let s = &point.summary;
    vec![
        branch.name().to_string(),
        format_number(s.force),
        format_number(s.mean_pressure),
        format_number(s.indentation),
        format_number(s.area_fraction),
        format_number(s.plastic_fraction),
        format_number(point.stiffness),
        point.iterations.to_string(),
        format_number(point.permanent_max),
    ]
}

/// Runs `asperity bem --load-path`: plan (every check before the first solve), the path,
/// then the table, its record and `--fields DIR/permanent.npy`, written together.
pub fn run(args: &BemArgs) -> Result<()> {
    refuse_other_options(args)?;
    let request = request(args)?;
    let plan = request.validate()?;
    let netcdf = netcdf_target(args.fields.as_ref());
    if let Some(path) = netcdf {
        check_target(path)?;
    }
    let folder = fields_folder(args.fields.as_ref());
    let permanent_path = folder.map(|dir| dir.join("permanent.npy"));
    let mut staged = stage(args, permanent_path.as_deref().or(netcdf))?;
    let (surface, size_source) = read_surface_for(args, plan.half_space.boundary)?;
    let mut solver = plan.solver(&surface)?;
    plan.check_forces(solver.nominal_area())?;
    if args.plot.is_some() && plan.loads.len() < 2 {
        bail!("--plot needs at least 2 loads (a path), got 1");
    }
    let values: Vec<f64> = plan.loads.iter().map(|c| c.value()).collect();
    let points = load_path(&mut solver, &plan.loads).context("load path")?;
    let branch = branches(&values);
    let mut table = Table::new(&PATH_COLUMNS);
    for (&b, point) in branch.iter().zip(&points) {
        table.push(&cells(b, point));
    }
    if let Some(plot) = &args.plot {
        let charts = path_charts(args, &plan, &branch, &points);
        stage_charts(&mut staged, plot, &charts)
            .with_context(|| format!("writing {}", plot.display()))?;
    }
    if let Some(path) = &permanent_path {
        staged.write_npy_2d(path, &solver.permanent_displacement())?;
    }
    if let Some(path) = netcdf {
        let record = record(args, (&request, &plan), (&surface, size_source));
        let grid = NcGrid {
            dim: surface.dim(),
            sizes: (surface.size(), surface.size_y()),
            metres: size_source == SizeSource::File.name(),
        };
        stage_netcdf(&mut staged, (path, &grid), (&points, &solver), &record)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(out) = &args.out {
        table
            .stage(&mut staged, out)
            .with_context(|| format!("writing {}", out.display()))?;
        let record_path = sidecar_path(out);
        let record = record(args, (&request, &plan), (&surface, size_source));
        staged
            .write_json(&record_path, &record)
            .with_context(|| format!("writing {}", record_path.display()))?;
    }
    staged.commit()?;
    match &args.out {
        Some(out) if !args.quiet => eprintln!(
            "wrote {} and {} ({} steps)",
            out.display(),
            sidecar_path(out).display(),
            points.len()
        ),
        Some(_) => {}
        None => crate::output::print_stdout(&table.to_csv()?)?,
    }
    Ok(())
}

/// Stages `--fields FILE.nc`: the steps' columns and the permanent displacement, with the
/// path's record.
fn stage_netcdf(
    staged: &mut StagedOutputs,
    (path, grid): (&Path, &NcGrid),
    (points, solver): (&[PathPoint], &asperity::bem::ContactSolver),
    record: &serde_json::Value,
) -> Result<()> {
    let column = |f: fn(&PathPoint) -> f64| -> Vec<f64> { points.iter().map(f).collect() };
    let columns = [
        ("force", column(|p| p.summary.force)),
        ("mean_pressure", column(|p| p.summary.mean_pressure)),
        ("indentation", column(|p| p.summary.indentation)),
        ("area_fraction", column(|p| p.summary.area_fraction)),
        ("plastic_fraction", column(|p| p.summary.plastic_fraction)),
        ("permanent_max", column(|p| p.permanent_max)),
    ];
    stage_path(staged, path, grid, (&columns, solver), record)
}

/// The inputs of a path, for OUT.csv.json.
fn record(
    args: &BemArgs,
    (request, plan): (&BemRequest, &BemPlan),
    (surface, size_source): (&asperity::surface::Surface, &'static str),
) -> serde_json::Value {
    json!({
        "command": "asperity bem --load-path",
        "version": env!("CARGO_PKG_VERSION"),
        "surface": args.surface,
        "grid": [surface.dim().0, surface.dim().1],
        "size": surface.size(),
        "size_y": surface.size_y(),
        "size_source": size_source,
        "modulus": plan.half_space.modulus,
        "boundary": plan.half_space.boundary.name(),
        "solver": plan.params.solver.name(),
        "tolerance": plan.params.tolerance,
        "max_iterations": plan.params.max_iterations,
        "hardness": plan.hardness(),
        "loads": request.loads.record(),
        "stiffness": "frozen contact set (the elastic set 0 < p < H under a hardness)",
        "fields": args.fields,
        "columns": PATH_COLUMNS,
    })
}
