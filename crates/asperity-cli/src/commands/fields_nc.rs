//! `asperity bem --fields FILE.nc`: every load's pressure and gap in one NetCDF file (the
//! library's [`asperity::fields`], described by [`asperity_app::fields`]) instead of a
//! folder of `.npy` files; with `--load-path`, the permanent displacement and the steps.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use asperity::bem::ContactSolver;
use asperity::fields::{is_netcdf_path, Values};
use asperity::io::StagedOutputs;
use asperity_app::fields::{FieldsBuilder, Placement, Units};

/// The file of `--fields`, where it names a `.nc` file (else it is a folder).
pub fn netcdf_target(fields: Option<&PathBuf>) -> Option<&Path> {
    fields.map(PathBuf::as_path).filter(|p| is_netcdf_path(p))
}

/// The folder `--fields` names, made if missing (none for a `.nc` file).
pub fn fields_folder(fields: Option<&PathBuf>) -> Option<&Path> {
    fields.map(PathBuf::as_path).filter(|p| !is_netcdf_path(p))
}

/// Refuses `--fields FILE.nc` where the file cannot be a field file: its folder missing is
/// reported by the staging; here, a name that is an existing folder.
pub fn check_target(path: &Path) -> Result<()> {
    if path.is_dir() {
        bail!(
            "--fields {}: is a folder; a .nc name writes one NetCDF file, any other name a folder of .npy files",
            path.display()
        );
    }
    Ok(())
}

/// Every load's fields, kept in memory until the sweep ends (the file is written at once).
pub struct Stacks {
    pub path: PathBuf,
    pressure: Vec<f64>,
    gap: Vec<f64>,
}

impl Stacks {
    pub fn new(path: &Path) -> Self {
        Stacks {
            path: path.to_path_buf(),
            pressure: Vec::new(),
            gap: Vec::new(),
        }
    }

    /// Appends the solved load's pressure and gap (row-major).
    pub fn push(&mut self, solver: &ContactSolver) {
        self.pressure.extend(solver.pressure().iter());
        self.gap.extend(solver.gap().iter());
    }
}

/// The surface the fields lie on: grid, sides, and whether lengths are metres.
pub struct Grid {
    pub dim: (usize, usize),
    pub sizes: (f64, f64),
    pub metres: bool,
}

/// The units of `asperity bem`: metres for a measured surface (the topography reader's
/// unit), the user's otherwise; the modulus's unit is never known to the command.
fn units(grid: &Grid) -> Units {
    Units {
        metres: grid.metres,
        pascals: false,
    }
}

/// Stages the sweep's file: per-load `columns` (name, values) and the fields.
pub fn stage_sweep(
    staged: &mut StagedOutputs,
    stacks: Stacks,
    grid: &Grid,
    columns: &[(&str, Vec<f64>)],
    record: &serde_json::Value,
) -> Result<()> {
    let title = "asperity bem: contact fields per load";
    let mut file = FieldsBuilder::new(Some((grid.dim, grid.sizes)), units(grid), title, record);
    for (name, values) in columns {
        file.add(name, Placement::Load, Values::Real(values.clone()));
    }
    file.add(
        "pressure",
        Placement::LoadMap,
        Values::Real(stacks.pressure),
    );
    file.add("gap", Placement::LoadMap, Values::Real(stacks.gap));
    let bytes = file.finish().to_bytes()?;
    staged.write_bytes(&stacks.path, &bytes)?;
    Ok(())
}

/// Stages a load path's file: the steps' `columns` and the permanent displacement.
pub fn stage_path(
    staged: &mut StagedOutputs,
    path: &Path,
    grid: &Grid,
    (columns, solver): (&[(&str, Vec<f64>)], &ContactSolver),
    record: &serde_json::Value,
) -> Result<()> {
    let title = "asperity bem --load-path: permanent displacement after the path";
    let mut file = FieldsBuilder::new(Some((grid.dim, grid.sizes)), units(grid), title, record);
    for (name, values) in columns {
        file.add(name, Placement::Load, Values::Real(values.clone()));
    }
    let permanent = solver.permanent_displacement().iter().copied().collect();
    file.add(
        "permanent_displacement",
        Placement::Map,
        Values::Real(permanent),
    );
    staged.write_bytes(path, &file.finish().to_bytes()?)?;
    Ok(())
}
