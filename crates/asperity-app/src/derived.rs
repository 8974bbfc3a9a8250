//! What the normal contact stiffness stands for, as result columns: the tangential (no-slip)
//! stiffnesses `k_x`, `k_y` of the frozen contact set and their ratio to the normal one
//! ([`asperity::bem::tangential`]), and the electrical and thermal contact conductances by
//! Barber's analogy ([`asperity::bem::conductance`]). One definition for `asperity bem`,
//! `asperity contact`, Python's `Solver.sweep` and `contact`: the same request fields, the
//! same refusals and the same numbers.
//!
//! * `tangential_ratio` is `(k_x + k_y)/(2k)`: the mean of the two directions over the
//!   normal frozen-set stiffness (Mindlin: `2(1−ν)/(2−ν)` for one circular contact); with
//!   one direction (`--tangential x|y`, `tangential="x"`: about half the cost) only that
//!   direction's column, and the ratio is `k_x/k` (or `k_y/k`);
//! * the conductances are `2k/(E*(ρ₁+ρ₂))` and `(2k/E*)·κ₁κ₂/(κ₁+κ₂)` from the same `k`.
//!
//! ```
//! use asperity_app::derived::{Derived, Units};
//! let derived =
//!     Derived::validate(Some(0.3), None, &Some(vec![1.7e-8, 1.7e-8]), &None).unwrap();
//! assert_eq!(
//!     derived.columns(Units::Si),
//!     ["stiffness_x_n_per_m", "stiffness_y_n_per_m", "tangential_ratio",
//!      "electrical_conductance_s"]
//! );
//! assert_eq!(derived.columns(Units::Model)[0], "stiffness_x");
//! // One direction: its column and k_y/k as the ratio.
//! let y = Derived::validate(Some(0.3), Some("y"), &None, &None).unwrap();
//! assert_eq!(y.columns(Units::Model), ["stiffness_y", "tangential_ratio"]);
//! ```

use asperity::bem::conductance::Transport;
use asperity::bem::sweep::SweepRow;
use asperity::bem::tangential::Directions;

use crate::refusal::{Param, Refusal};

/// The parameters of the derived columns, as each front end names them.
pub mod params {
    use crate::refusal::Param;

    /// Poisson's ratio ν (of Cerruti's kernel; in `asperity contact` also of E/(1 − ν²)).
    pub const POISSON: Param = Param::new("--poisson", "poisson");
    /// Which tangential stiffnesses: `x`, `y` or `both` (in `asperity contact` also the
    /// switch that asks for them).
    pub const TANGENTIAL: Param = Param::new("--tangential", "tangential");
    /// The two bodies' electrical resistivities.
    pub const RESISTIVITY: Param = Param::new("--resistivity", "resistivity");
    /// The two bodies' thermal conductivities.
    pub const THERMAL_CONDUCTIVITY: Param =
        Param::new("--thermal-conductivity", "thermal_conductivity");
}

use params::*;

/// Which names the columns get: the model's own units (`asperity bem`, `Solver.sweep`:
/// lengths and E* in the user's units) or SI (`asperity contact`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    /// `stiffness_x`, `electrical_conductance`, ….
    Model,
    /// `stiffness_x_n_per_m`, `electrical_conductance_s`, ….
    Si,
}

/// Checks a Poisson's ratio: in `[0, 0.5]` (the library's rule,
/// [`asperity::mdr::tangential::is_poisson_ratio`]).
pub fn check_poisson(poisson: f64) -> Result<(), Refusal> {
    if asperity::mdr::tangential::is_poisson_ratio(poisson) {
        return Ok(());
    }
    Err(Refusal::of(POISSON).text(format!(
        " must be in [0, 0.5] (Poisson's ratio), got {}",
        crate::refusal::number(poisson)
    )))
}

/// Which tangential stiffnesses: `x`, `y` or `both`.
pub fn parse_directions(name: &str) -> Result<Directions, Refusal> {
    match name {
        "x" => Ok(Directions::X),
        "y" => Ok(Directions::Y),
        "both" => Ok(Directions::Both),
        _ => Err(Refusal::of(TANGENTIAL).text(format!(" must be x, y or both, got {name:?}"))),
    }
}

/// Two values, one per body, each positive and finite.
pub fn body_pair(
    param: Param,
    what: &str,
    values: &Option<Vec<f64>>,
) -> Result<Option<[f64; 2]>, Refusal> {
    let Some(values) = values else {
        return Ok(None);
    };
    let invalid = || Refusal::saying("invalid ").param(param);
    if values.len() != 2 {
        return Err(invalid().text(format!(
            ": give two values, body 1 and body 2, got {}",
            values.len()
        )));
    }
    if let Some(bad) = values.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(invalid().text(format!(
            ": each body's {what} must be positive and finite, got {}",
            crate::refusal::number(*bad)
        )));
    }
    Ok(Some([values[0], values[1]]))
}

/// What a sweep computes besides the normal stiffness, validated.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Derived {
    /// Poisson's ratio of the tangential stiffness, if asked for.
    pub tangential: Option<f64>,
    /// Which of `k_x`, `k_y` (both unless asked otherwise).
    pub directions: Directions,
    /// The bodies' resistivities and conductivities, if given.
    pub transport: Transport,
}

/// One load's derived values (none where not asked for, or where the normal stiffness they
/// come from was not computed).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DerivedRow {
    /// `k_x`.
    pub stiffness_x: Option<f64>,
    /// `k_y`.
    pub stiffness_y: Option<f64>,
    /// `(k_x + k_y)/(2k)`, or with one direction `k_x/k` (`k_y/k`).
    pub tangential_ratio: Option<f64>,
    /// Electrical conductance.
    pub electrical_conductance: Option<f64>,
    /// Thermal conductance.
    pub thermal_conductance: Option<f64>,
}

impl Derived {
    /// The derived columns of a request, or why not: `poisson` (tangential stiffness),
    /// `directions` (`x`, `y` or `both`, the default; only with `poisson`), the two bodies'
    /// resistivities and thermal conductivities.
    pub fn validate(
        poisson: Option<f64>,
        directions: Option<&str>,
        resistivity: &Option<Vec<f64>>,
        thermal_conductivity: &Option<Vec<f64>>,
    ) -> Result<Derived, Refusal> {
        if let Some(poisson) = poisson {
            check_poisson(poisson)?;
        }
        let directions = directions.map(parse_directions).transpose()?;
        if directions.is_some() && poisson.is_none() {
            return Err(Refusal::of(TANGENTIAL)
                .text(" needs ")
                .param(POISSON)
                .text(" ν (of Cerruti's kernel)"));
        }
        let resistivity = body_pair(RESISTIVITY, "resistivity", resistivity)?;
        let thermal_conductivity = body_pair(
            THERMAL_CONDUCTIVITY,
            "thermal conductivity",
            thermal_conductivity,
        )?;
        Ok(Derived {
            tangential: poisson,
            directions: directions.unwrap_or_default(),
            transport: Transport {
                resistivity,
                thermal_conductivity,
            },
        })
    }

    /// The column names asked for, in the order of [`Derived::values`].
    pub fn columns(&self, units: Units) -> Vec<&'static str> {
        let si = units == Units::Si;
        let mut columns = Vec::new();
        if self.tangential.is_some() {
            let (x, y) = match si {
                true => ("stiffness_x_n_per_m", "stiffness_y_n_per_m"),
                false => ("stiffness_x", "stiffness_y"),
            };
            columns.extend(match self.directions {
                Directions::X => vec![x],
                Directions::Y => vec![y],
                Directions::Both => vec![x, y],
            });
            columns.push("tangential_ratio");
        }
        if self.transport.resistivity.is_some() {
            columns.push(if si {
                "electrical_conductance_s"
            } else {
                "electrical_conductance"
            });
        }
        if self.transport.thermal_conductivity.is_some() {
            columns.push(if si {
                "thermal_conductance_w_per_k"
            } else {
                "thermal_conductance"
            });
        }
        columns
    }

    /// The derived values of a sweep's row on a half-space of effective modulus `modulus`.
    pub fn row(&self, row: &SweepRow, modulus: f64) -> DerivedRow {
        let k = row.stiffness;
        let t = row.tangential;
        DerivedRow {
            stiffness_x: t.and_then(|t| t.stiffness_x()),
            stiffness_y: t.and_then(|t| t.stiffness_y()),
            tangential_ratio: t.zip(k).map(|(t, k)| t.ratio(k)),
            electrical_conductance: k.and_then(|k| self.transport.electrical(k, modulus)),
            thermal_conductance: k.and_then(|k| self.transport.thermal(k, modulus)),
        }
    }

    /// A row's values in the order of [`Derived::columns`].
    pub fn values(&self, row: &DerivedRow) -> Vec<Option<f64>> {
        let mut values = Vec::new();
        if self.tangential.is_some() {
            match self.directions {
                Directions::X => values.push(row.stiffness_x),
                Directions::Y => values.push(row.stiffness_y),
                Directions::Both => values.extend([row.stiffness_x, row.stiffness_y]),
            }
            values.push(row.tangential_ratio);
        }
        if self.transport.resistivity.is_some() {
            values.push(row.electrical_conductance);
        }
        if self.transport.thermal_conductivity.is_some() {
            values.push(row.thermal_conductance);
        }
        values
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;

    #[test]
    fn refusals_in_both_front_ends_words() {
        let refused = |nu: Option<f64>, r: Option<Vec<f64>>, t: Option<Vec<f64>>| {
            let refusal = Derived::validate(nu, None, &r, &t).unwrap_err();
            (refusal.words(Names::Flags), refusal.words(Names::Keywords))
        };
        for bad in [-0.1, 0.51, f64::NAN, f64::INFINITY] {
            let (flags, keywords) = refused(Some(bad), None, None);
            assert_eq!(
                flags,
                format!(
                    "--poisson must be in [0, 0.5] (Poisson's ratio), got {}",
                    crate::refusal::number(bad)
                )
            );
            assert!(keywords.starts_with("poisson must be"), "{keywords}");
        }
        assert_eq!(
            refused(None, Some(vec![1e-8]), None).0,
            "invalid --resistivity: give two values, body 1 and body 2, got 1"
        );
        assert_eq!(
            refused(None, None, Some(vec![1.0, 0.0])).1,
            "invalid thermal_conductivity: each body's thermal conductivity must be positive \
             and finite, got 0"
        );
        for nu in [0.0, 0.5] {
            assert!(Derived::validate(Some(nu), None, &None, &None).is_ok());
        }
        let along = |nu: Option<f64>, d: &str| {
            let refusal = Derived::validate(nu, Some(d), &None, &None).unwrap_err();
            (refusal.words(Names::Flags), refusal.words(Names::Keywords))
        };
        assert_eq!(
            along(Some(0.3), "z"),
            (
                "--tangential must be x, y or both, got \"z\"".to_string(),
                "tangential must be x, y or both, got \"z\"".to_string()
            )
        );
        assert_eq!(
            along(None, "x").0,
            "--tangential needs --poisson ν (of Cerruti's kernel)"
        );
        for (name, d) in [
            ("x", Directions::X),
            ("y", Directions::Y),
            ("both", Directions::Both),
        ] {
            let derived = Derived::validate(Some(0.3), Some(name), &None, &None).unwrap();
            assert_eq!((derived.directions, d.name()), (d, name));
        }
    }

    #[test]
    fn columns_and_values_line_up() {
        use asperity::bem::{ContactSummary, Control, SolveInfo};
        let derived = Derived::validate(
            Some(0.3),
            None,
            &Some(vec![1e-8, 3e-8]),
            &Some(vec![50.0, 200.0]),
        )
        .unwrap();
        let info = SolveInfo {
            iterations: 1,
            residual: 0.0,
            operator_applications: 1,
            energy_transforms: 0,
        };
        let tangential = asperity::bem::tangential::Along {
            x: Some((0.8, info)),
            y: Some((0.9, info)),
        };
        let row = SweepRow {
            control: Control::MeanPressure(0.01),
            summary: ContactSummary {
                mean_pressure: 0.01,
                force: 0.01,
                indentation: 0.1,
                area_fraction: 0.1,
                contact_points: 10,
                plastic_fraction: 0.0,
                plastic_points: 0,
            },
            info,
            stiffness: Some(1.0),
            stiffness_fd: None,
            solve_seconds: 0.0,
            stiffness_seconds: 0.0,
            tangential: Some(tangential),
            tangential_seconds: 0.0,
        };
        let values = derived.values(&derived.row(&row, 2.0));
        assert_eq!(derived.columns(Units::Model).len(), values.len());
        // k_x, k_y, (k_x + k_y)/2k, 2k/(E*(ρ₁+ρ₂)), (2k/E*)κ₁κ₂/(κ₁+κ₂).
        let expected = [0.8, 0.9, 0.85, 2.0 / (2.0 * 4e-8), 40.0];
        for (v, e) in values.iter().zip(expected) {
            assert!((v.unwrap() / e - 1.0).abs() < 1e-15, "{v:?} {e}");
        }
        // No normal stiffness: no ratio and no conductance (empty cells), k_x still there.
        let without = derived.row(
            &SweepRow {
                stiffness: None,
                ..row
            },
            2.0,
        );
        assert_eq!(without.stiffness_x, Some(0.8));
        assert_eq!(
            (without.tangential_ratio, without.electrical_conductance),
            (None, None)
        );
        assert!(Derived::default().columns(Units::Si).is_empty());
        // One direction: its column, and its own ratio to k.
        let x = Derived {
            directions: Directions::X,
            ..derived
        };
        let one = SweepRow {
            tangential: Some(asperity::bem::tangential::Along {
                x: Some((0.8, info)),
                y: None,
            }),
            ..row
        };
        let values = x.values(&x.row(&one, 2.0));
        assert_eq!(
            x.columns(Units::Model)[..2],
            ["stiffness_x", "tangential_ratio"]
        );
        assert_eq!(values[..2], [Some(0.8), Some(0.8)]);
        assert_eq!(values.len(), x.columns(Units::Model).len());
    }
}
