//! Contact fields as NetCDF, described once for both front ends: `asperity bem --fields
//! FILE.nc` and Python's `save("….nc")` build their files here, so a variable has the
//! same name, `long_name`, `units` and `comment` whoever wrote it.
//!
//! Units: a quantity's CF `units` is written where the unit is known: lengths in metres
//! (a measured surface, or Python's SI `contact`), pressures in pascals (SI `contact`),
//! and what follows from them (N, N/m, m²). Where the unit is the user's (a generated
//! surface, `--modulus` without a unit), `units` is left out and `comment` says which unit
//! it is (e.g. "in the units of the heights"); dimensionless quantities have `units = "1"`.

use asperity::fields::{FieldFile, Grid, Values, Variable};

/// Which units are known: of the lengths (heights, sides) and of the pressures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Units {
    /// The lengths are metres.
    pub metres: bool,
    /// The pressures (and the modulus) are pascals.
    pub pascals: bool,
}

/// How a quantity's unit is made from length and pressure.
#[derive(Clone, Copy)]
enum Dimension {
    Length,
    Pressure,
    /// pressure × length²
    Force,
    /// pressure × length
    Stiffness,
    Area,
    One,
    /// No unit (a flag).
    Flag,
}

/// What each known quantity is: (name, long_name, dimension).
const QUANTITIES: &[(&str, &str, Dimension)] = &[
    ("pressure", "contact pressure", Dimension::Pressure),
    (
        "gap",
        "gap between the indenter and the deformed surface",
        Dimension::Length,
    ),
    (
        "displacement",
        "elastic normal displacement of the surface, positive into the half-space",
        Dimension::Length,
    ),
    (
        "plastic_displacement",
        "plastic displacement at the points at the hardness",
        Dimension::Length,
    ),
    (
        "permanent_displacement",
        "permanent (plastic) displacement after the load path",
        Dimension::Length,
    ),
    ("map", "contact set (in contact: p > 0)", Dimension::Flag),
    (
        "contact",
        "contact set (in contact: p > 0)",
        Dimension::Flag,
    ),
    (
        "patch_labels",
        "4-connected contact patch number, 0 outside contact",
        Dimension::One,
    ),
    (
        "patch_areas_m2",
        "area of each contact patch, by label",
        Dimension::Area,
    ),
    ("force", "normal force", Dimension::Force),
    ("force_n", "normal force", Dimension::Force),
    (
        "mean_pressure",
        "mean pressure over the nominal area",
        Dimension::Pressure,
    ),
    (
        "mean_pressure_pa",
        "mean pressure over the nominal area",
        Dimension::Pressure,
    ),
    ("indentation", "indentation", Dimension::Length),
    ("indentation_m", "indentation", Dimension::Length),
    (
        "area_fraction",
        "real contact area over the nominal area",
        Dimension::One,
    ),
    (
        "plastic_fraction",
        "share of the points at the hardness",
        Dimension::One,
    ),
    ("contact_area_m2", "real contact area", Dimension::Area),
    ("mean_gap_m", "mean gap", Dimension::Length),
    ("mean_gap", "mean gap", Dimension::Length),
    (
        "stiffness",
        "normal contact stiffness of the frozen contact set",
        Dimension::Stiffness,
    ),
    (
        "stiffness_fd",
        "normal contact stiffness dF/dd by central differences",
        Dimension::Stiffness,
    ),
    (
        "stiffness_n_per_m",
        "normal contact stiffness",
        Dimension::Stiffness,
    ),
    (
        "permanent_max",
        "largest permanent displacement so far",
        Dimension::Length,
    ),
    ("contact_points", "points in contact", Dimension::One),
    ("plastic_points", "points at the hardness", Dimension::One),
    (
        "patches",
        "number of 4-connected contact patches",
        Dimension::One,
    ),
    ("iterations", "solver iterations", Dimension::One),
    ("residual", "solver residual (relative)", Dimension::One),
];

/// A quantity's CF attributes: `long_name`, `units` (where known), `comment` (where the
/// unit is the user's).
pub fn describe(name: &str, units: Units) -> (String, Option<String>, Option<String>) {
    let Some(&(_, long_name, dimension)) = QUANTITIES.iter().find(|q| q.0 == name) else {
        return (name.replace('_', " "), None, None);
    };
    let (metres, pascals) = (units.metres, units.pascals);
    let (known, unit, user) = match dimension {
        Dimension::Length => (metres, "m", "in the units of the heights"),
        Dimension::Area => (metres, "m2", "in the units of the heights, squared"),
        Dimension::Pressure => (pascals, "Pa", "in the units of the modulus E*"),
        Dimension::Force => (
            metres && pascals,
            "N",
            "in the units of the modulus E* times the heights' unit squared",
        ),
        Dimension::Stiffness => (
            metres && pascals,
            "N/m",
            "in the units of the modulus E* times the heights' unit",
        ),
        Dimension::One => (true, "1", ""),
        Dimension::Flag => return (long_name.to_string(), None, None),
    };
    match known {
        true => (long_name.to_string(), Some(unit.to_string()), None),
        false => (long_name.to_string(), None, Some(user.to_string())),
    }
}

/// Where a variable lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placement<'a> {
    /// One value per load (dimension `load`).
    Load,
    /// A map (`y`, `x`).
    Map,
    /// A map per load (`load`, `y`, `x`).
    LoadMap,
    /// Along a dimension of its own, e.g. `patch`.
    Along(&'a str),
}

/// A field file being assembled: the grid, the units, what produced it.
pub struct FieldsBuilder {
    file: FieldFile,
    units: Units,
}

impl FieldsBuilder {
    /// A file on the grid `(rows, cols)` of sides `(size, size_y)` (none for a file
    /// without maps), with its global attributes: `title`, `source` (`asperity VERSION`)
    /// and `asperity_record` (what produced it, JSON).
    pub fn new(
        grid: Option<((usize, usize), (f64, f64))>,
        units: Units,
        title: &str,
        record: &serde_json::Value,
    ) -> Self {
        let grid = grid.map(|((rows, cols), (size, size_y))| Grid {
            rows,
            cols,
            size,
            size_y,
            units: units.metres.then(|| "m".to_string()),
        });
        let attributes = vec![
            ("title".to_string(), title.to_string()),
            (
                "source".to_string(),
                format!("asperity {}", env!("CARGO_PKG_VERSION")),
            ),
            ("asperity_record".to_string(), record.to_string()),
        ];
        FieldsBuilder {
            file: FieldFile {
                grid,
                dims: Vec::new(),
                variables: Vec::new(),
                attributes,
            },
            units,
        }
    }

    /// Adds a variable (its dimension `load`, or its own, made on first use with the
    /// length of these values).
    pub fn add(&mut self, name: &str, placement: Placement<'_>, values: Values) {
        let along = match placement {
            Placement::Load | Placement::LoadMap => Some("load"),
            Placement::Along(dim) => Some(dim),
            Placement::Map => None,
        };
        let per_map = self.file.grid.as_ref().map_or(1, |g| g.rows * g.cols);
        let count = match placement {
            Placement::LoadMap => values.len() / per_map.max(1),
            _ => values.len(),
        };
        if let Some(dim) = along {
            if !self.file.dims.iter().any(|d| d.0 == dim) {
                self.file.dims.push((dim.to_string(), count));
            }
        }
        let dims: Vec<String> = match placement {
            Placement::Load => vec!["load".into()],
            Placement::Map => vec!["y".into(), "x".into()],
            Placement::LoadMap => vec!["load".into(), "y".into(), "x".into()],
            Placement::Along(dim) => vec![dim.into()],
        };
        let (long_name, units, comment) = describe(name, self.units);
        self.file.variables.push(Variable {
            name: name.to_string(),
            dims,
            long_name,
            units,
            comment,
            values,
        });
    }

    /// The file, to be written by [`FieldFile::write`] (or staged with its bytes).
    pub fn finish(self) -> FieldFile {
        self.file
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_written_only_where_known() {
        let si = Units {
            metres: true,
            pascals: true,
        };
        let user = Units {
            metres: false,
            pascals: false,
        };
        assert_eq!(describe("force_n", si).1.as_deref(), Some("N"));
        assert_eq!(describe("stiffness", si).1.as_deref(), Some("N/m"));
        let (_, units, comment) = describe("gap", user);
        assert_eq!(
            (units, comment.as_deref()),
            (None, Some("in the units of the heights"))
        );
        // Metres but no pascals (a measured surface, --modulus without a unit).
        let measured = Units {
            metres: true,
            pascals: false,
        };
        assert_eq!(describe("gap", measured).1.as_deref(), Some("m"));
        assert_eq!(describe("force", measured).1, None);
        assert_eq!(describe("area_fraction", user).1.as_deref(), Some("1"));
        assert_eq!(describe("map", si).1, None);
        assert_eq!(describe("new_thing", si).0, "new thing");
    }

    #[test]
    fn a_sweep_round_trips_through_a_file() {
        let units = Units {
            metres: false,
            pascals: false,
        };
        let record = serde_json::json!({"command": "test"});
        let mut b = FieldsBuilder::new(Some(((2, 3), (1.0, 0.5))), units, "t", &record);
        b.add("force", Placement::Load, Values::Real(vec![1.0, 2.0]));
        b.add(
            "pressure",
            Placement::LoadMap,
            Values::Real((0..12).map(f64::from).collect()),
        );
        b.add(
            "patch_areas_m2",
            Placement::Along("patch"),
            Values::Real(vec![0.5]),
        );
        let file = b.finish();
        assert_eq!(
            file.dims,
            vec![("load".to_string(), 2), ("patch".to_string(), 1)]
        );
        let back = FieldFile::from_bytes(&file.to_bytes().unwrap()).unwrap();
        assert_eq!(back, file);
        assert_eq!(back.attributes[2].1, "{\"command\":\"test\"}");
    }
}
