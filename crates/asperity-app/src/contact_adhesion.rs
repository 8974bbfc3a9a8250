//! `asperity contact --work-of-adhesion` and Python's `contact(work_of_adhesion=…)`:
//! adhesive contact of a measured surface in SI units — the request's adhesive options
//! checked once ([`ContactRequest::adhesion_plan`]), run by the adhesive BEM of `asperity bem
//! --work-of-adhesion` ([`crate::adhesion::AdhesionPlan`], the same code), and its columns
//! with their units ([`COLUMNS`], [`values`]).
//!
//! Units: E* in Pa, heights, sizes, indentations and the range in m, the work of adhesion
//! in J/m² (= Pa·m); forces then come out in N and pressures in Pa. The solver has no unit
//! of its own: the SI run is the model-unit run of `asperity bem` with every quantity
//! scaled (a test checks it bit for bit at power-of-two scales).

use crate::adhesion::{
    AdhesionPlan, AdhesionRequest, AdhesionRow, ADHESION_MODEL, ADHESION_RANGE, RETRACT_STEP,
    WORK_OF_ADHESION,
};
use crate::bem::params::{HARDNESS, INDENTATIONS, PRESSURES};
use crate::contact::params::{RESISTIVITY, TANGENTIAL, THERMAL_CONDUCTIVITY};
use crate::contact::{ContactRequest, Value};
use crate::refusal::{Param, Refusal};

/// The columns of an adhesive `asperity contact` (SI units): those of `asperity bem
/// --work-of-adhesion` in the same order, with units, and the attached area in m² after
/// the force; the last, `branch`, is `path` or `retract`.
pub const COLUMNS: [&str; 9] = [
    "indentation_m",
    "force_n",
    "mean_pressure_pa",
    "contact_area_m2",
    "area_fraction",
    "tensile_fraction",
    "rounds",
    "cg_iterations",
    "branch",
];

/// A row's values in the order of [`COLUMNS`] but the last (`branch`: [`AdhesionRow`]'s
/// `branch.name()`): `pixel_area` in m², `points` the grid's points. The contact area is
/// the attached pixels' (the pixels held at zero gap).
pub fn values(row: &AdhesionRow, pixel_area: f64, points: usize) -> [Value; 8] {
    use Value::{Count, Number};
    let s = &row.summary;
    [
        Number(s.indentation),
        Number(s.force),
        Number(s.mean_pressure),
        Number(s.attached_points as f64 * pixel_area),
        Number(s.area_fraction),
        Number(s.tensile_points as f64 / points as f64),
        Count(row.info.rounds),
        Count(row.info.cg_iterations),
    ]
}

impl ContactRequest {
    /// Whether the request is adhesive (a work of adhesion is given).
    pub fn is_adhesive(&self) -> bool {
        self.work_of_adhesion.is_some()
    }

    /// The adhesive run's plan (the rules of `asperity bem --work-of-adhesion` on E* by
    /// `asperity contact`'s rule), or why not: a work of adhesion, a path of indentations,
    /// and none of the load sweep's options (pressures, hardness, tangential stiffness,
    /// conductances).
    pub fn adhesion_plan(&self) -> Result<AdhesionPlan, Refusal> {
        let Some(w) = self.work_of_adhesion else {
            return Err(Refusal::saying("an adhesive run needs ").param(WORK_OF_ADHESION));
        };
        let sweep_options: [(bool, Param); 5] = [
            (!self.pressures.is_empty(), PRESSURES),
            (self.hardness.is_some(), HARDNESS),
            (self.tangential, TANGENTIAL),
            (self.resistivity.is_some(), RESISTIVITY),
            (self.thermal_conductivity.is_some(), THERMAL_CONDUCTIVITY),
        ];
        if let Some((_, param)) = sweep_options.iter().find(|(on, _)| *on) {
            return Err(Refusal::of(WORK_OF_ADHESION)
                .text(" takes a path of ")
                .param(INDENTATIONS)
                .text(" (m; solved under displacement control, both pull-offs reported) and does not go with ")
                .param(*param));
        }
        if self.indentations.is_empty() {
            return Err(Refusal::of(WORK_OF_ADHESION)
                .text(" needs ")
                .param(INDENTATIONS)
                .text(" (m): the path to follow before the retraction"));
        }
        AdhesionRequest {
            modulus: self.modulus_pa()?,
            boundary: self.boundary.clone(),
            work_of_adhesion: w,
            adhesion_range: self.adhesion_range,
            adhesion_model: self.adhesion_model.clone(),
            indentations: self.indentations.clone(),
            retract_step: self.retract_step,
        }
        .validate()
    }

    /// Refuses the adhesive options without a work of adhesion (a load sweep's request).
    pub(crate) fn refuse_adhesion_options(&self) -> Result<(), Refusal> {
        let adhesive: [(bool, Param); 4] = [
            (self.adhesion_range.is_some(), ADHESION_RANGE),
            (self.adhesion_model.is_some(), ADHESION_MODEL),
            (!self.indentations.is_empty(), INDENTATIONS),
            (self.retract_step.is_some(), RETRACT_STEP),
        ];
        match adhesive.iter().find(|(on, _)| *on) {
            Some((_, param)) if !self.is_adhesive() => Err(Refusal::of(*param)
                .text(" needs ")
                .param(WORK_OF_ADHESION)
                .text(" (J/m²): it belongs to an adhesive run")),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;

    fn adhesive() -> ContactRequest {
        ContactRequest {
            modulus: Some(1e9),
            work_of_adhesion: Some(0.05),
            indentations: vec![1e-7, 2e-7],
            ..ContactRequest::default()
        }
    }

    #[test]
    fn an_adhesive_request_is_bems_with_the_modulus_of_contact() {
        let plan = ContactRequest {
            modulus: None,
            young: Some(2e9),
            poisson: Some(0.5),
            adhesion_range: Some(2e-9),
            adhesion_model: Some("exponential".into()),
            ..adhesive()
        }
        .adhesion_plan()
        .unwrap();
        let bem = AdhesionRequest {
            modulus: 2e9 / 0.75,
            boundary: "free".into(),
            work_of_adhesion: 0.05,
            adhesion_range: Some(2e-9),
            adhesion_model: Some("exponential".into()),
            indentations: vec![1e-7, 2e-7],
            retract_step: None,
        }
        .validate()
        .unwrap();
        assert_eq!(plan, bem);
    }

    #[test]
    fn refuses_mixed_or_incomplete_requests_in_one_line() {
        let words = |r: ContactRequest| r.adhesion_plan().unwrap_err().words(Names::Flags);
        let text = words(ContactRequest {
            pressures: vec![1e6],
            ..adhesive()
        });
        assert!(
            text.starts_with("--work-of-adhesion takes a path of --indentations")
                && text.ends_with("does not go with --pressures"),
            "{text}"
        );
        let text = words(ContactRequest {
            hardness: Some(1e9),
            ..adhesive()
        });
        assert!(text.ends_with("--hardness"), "{text}");
        let text = words(ContactRequest {
            indentations: vec![],
            ..adhesive()
        });
        assert!(text.contains("needs --indentations"), "{text}");
        // The bem rules, in contact's words: Δγ positive and finite.
        let text = words(ContactRequest {
            work_of_adhesion: Some(-1.0),
            ..adhesive()
        });
        assert!(text.starts_with("invalid --work-of-adhesion"), "{text}");
        // The adhesive options without Δγ, for a load sweep.
        let sweep = ContactRequest {
            modulus: Some(1e9),
            pressures: vec![1e6],
            adhesion_range: Some(1e-9),
            ..ContactRequest::default()
        };
        let text = sweep.validate().unwrap_err().words(Names::Keywords);
        assert_eq!(
            text,
            "adhesion_range needs work_of_adhesion (J/m²): it belongs to an adhesive run"
        );
    }
}
