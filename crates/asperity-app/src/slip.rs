//! `asperity mdr --tangential-force` and Python's `mdr_slip()`: partial slip of an MDR
//! indenter under a tangential force `Q ≤ μF` at one indentation, loading, unloading and
//! reloading ([`asperity::mdr::PartialSlip`]), with its rules and words once.

use asperity::mdr::{check_friction, mindlin_ratio, Foundation, LoopPoint, PartialSlip, Spring};
use serde_json::json;

use crate::mdr::{Indenter, MdrRequest};
use crate::refusal::{Param, Refusal, RequestError};

/// The parameters of the tangential cycle, as each front end names them.
pub mod params {
    use crate::refusal::Param;

    /// Poisson's ratio ν (both bodies, or the elastic one against a rigid one).
    pub const POISSON: Param = Param::new("--poisson", "poisson");
    /// The friction coefficient μ.
    pub const FRICTION: Param = Param::new("--friction", "friction");
    /// The amplitude Q* of the tangential force.
    pub const TANGENTIAL_FORCE: Param = Param::new("--tangential-force", "tangential_force");
    /// Points per branch of the cycle.
    pub const CYCLE_POINTS: Param = Param::new("--cycle-points", "cycle_points");
}

use params::*;

/// Poisson's ratio when none is given.
pub const DEFAULT_POISSON: f64 = 0.3;

/// Points per branch of the cycle when none is given.
pub const DEFAULT_CYCLE_POINTS: usize = 50;

/// The columns of a cycle (`stick_radius` only for axisymmetric indenters).
pub const COLUMNS: [&str; 5] = [
    "branch",
    "tangential_displacement",
    "tangential_force",
    "stick_springs",
    "stick_radius",
];

/// A tangential cycle request, beside the [`MdrRequest`] of the indenter.
#[derive(Debug, Clone, PartialEq)]
pub struct SlipRequest {
    /// ν, in `[0, 0.5]`.
    pub poisson: f64,
    /// μ, positive and finite.
    pub friction: Option<f64>,
    /// Q*, positive and at most μF at the indentation.
    pub tangential_force: f64,
    /// Points per branch (default [`DEFAULT_CYCLE_POINTS`]), signed as a front end holds
    /// it: below 2 (negative ones too) refused by one rule, in one wording.
    pub cycle_points: Option<i128>,
}

/// The cycle and what characterises it.
#[derive(Debug, Clone, PartialEq)]
pub struct SlipCycle {
    /// Loading, unloading and reloading.
    pub points: Vec<LoopPoint>,
    /// The stick radius at each point (axisymmetric indenters only).
    pub stick_radius: Option<Vec<f64>>,
    /// Indentation d.
    pub indentation: f64,
    /// Normal force F.
    pub normal_force: f64,
    /// μF.
    pub friction_limit: f64,
    /// Mindlin's no-slip tangential stiffness.
    pub no_slip_stiffness: f64,
    /// Energy dissipated per cycle.
    pub dissipation: f64,
    /// Springs in contact.
    pub contacts: usize,
    /// G*/E*.
    pub ratio: f64,
}

fn param_refusal(param: Param, text: String) -> RequestError {
    Refusal::saying("invalid ").param(param).text(text).into()
}

impl SlipRequest {
    /// The rules that need no indenter: ν in `[0, 0.5]`, μ positive and finite, Q* positive
    /// and finite, at least 2 points per branch, and one indentation in `mdr`.
    pub fn check(&self, mdr: &MdrRequest) -> Result<(), RequestError> {
        mindlin_ratio(self.poisson).map_err(|e| RequestError::Invalid(Box::new(e)))?;
        let friction = self.friction.ok_or_else(|| {
            Refusal::of(TANGENTIAL_FORCE)
                .text(" needs ")
                .param(FRICTION)
        })?;
        check_friction(friction).map_err(|e| RequestError::Invalid(Box::new(e)))?;
        let q = self.tangential_force;
        if !(q.is_finite() && q > 0.0) {
            return Err(param_refusal(
                TANGENTIAL_FORCE,
                format!(
                    ": the tangential force Q* must be positive and finite, got {}",
                    crate::refusal::number(q)
                ),
            ));
        }
        if let Some(points) = self.cycle_points.filter(|p| *p < 2) {
            return Err(param_refusal(
                CYCLE_POINTS,
                format!(": a branch needs at least 2 points, got {points}"),
            ));
        }
        if let Some(points) = self.cycle_points {
            crate::refusal::count(CYCLE_POINTS, points)?;
        }
        if mdr.work_of_adhesion.is_some() {
            let refusal = Refusal::of(TANGENTIAL_FORCE)
                .text(" is for non-adhesive contact: drop ")
                .param(crate::mdr::params::WORK_OF_ADHESION);
            return Err(refusal.into());
        }
        let one = mdr
            .indentations
            .as_ref()
            .is_some_and(|list| list.len() == 1);
        if !one || mdr.breakpoints || mdr.nloads.is_some() {
            let refusal = Refusal::of(TANGENTIAL_FORCE)
                .text(" needs exactly one indentation: ")
                .param(crate::mdr::params::INDENTATIONS)
                .text(" d");
            return Err(refusal.into());
        }
        Ok(())
    }

    /// The cycle of `indenter` on `spring` at the request's one indentation.
    pub fn run(
        &self,
        mdr: &MdrRequest,
        indenter: &Indenter,
        spring: Spring,
    ) -> Result<SlipCycle, RequestError> {
        self.check(mdr)?;
        let invalid = |e| RequestError::Invalid(Box::new(e));
        let d = mdr.indentations.as_ref().map_or(0.0, |list| list[0]);
        let foundation = if indenter.is_line {
            Foundation::from_heights(&indenter.values, spring)
        } else {
            Foundation::from_profile(&indenter.values, spring)
        }
        .map_err(invalid)?;
        let ratio = mindlin_ratio(self.poisson).map_err(invalid)?;
        let friction = self.friction.unwrap_or_default();
        let slip = PartialSlip::new(&foundation, d, ratio, friction).map_err(invalid)?;
        let points = match self.cycle_points {
            Some(points) => crate::refusal::count(CYCLE_POINTS, points)?,
            None => DEFAULT_CYCLE_POINTS,
        };
        let cycle = slip.cycle(self.tangential_force, points).map_err(invalid)?;
        let top = slip.displacement(self.tangential_force).map_err(invalid)?;
        let stick_radius = (!indenter.is_line).then(|| {
            let bottom = indenter
                .values
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min);
            let level = |p: &LoopPoint| bottom + d - p.stick_compression;
            cycle
                .iter()
                .map(|p| half_width(indenter, level(p)))
                .collect()
        });
        Ok(SlipCycle {
            stick_radius,
            indentation: d,
            normal_force: slip.normal_force(),
            friction_limit: slip.friction_limit(),
            no_slip_stiffness: slip.no_slip_stiffness(),
            dissipation: slip.dissipation(top),
            contacts: slip.contacts(),
            ratio,
            points: cycle,
        })
    }
}

impl SlipCycle {
    /// What characterises the cycle, for a record.
    pub fn summary(&self) -> serde_json::Value {
        json!({
            "indentation": self.indentation,
            "normal_force": self.normal_force,
            "friction_limit": self.friction_limit,
            "no_slip_stiffness": self.no_slip_stiffness,
            "stiffness_ratio": self.ratio,
            "dissipation_per_cycle": self.dissipation,
            "contacts": self.contacts,
        })
    }
}

/// The radius `x ≥ 0` where the axisymmetric profile, walked outwards from the axis, first
/// reaches `level` (linear interpolation between springs); the last spring's radius if it
/// never does.
fn half_width(indenter: &Indenter, level: f64) -> f64 {
    let values = &indenter.values;
    let n = values.len();
    let centre = (n as f64 - 1.0) / 2.0;
    let x = |i: usize| (i as f64 - centre) * indenter.spacing;
    let start = n / 2;
    if values[start] >= level {
        return x(start).max(0.0);
    }
    for i in start + 1..n {
        if values[i] >= level {
            let t = (level - values[i - 1]) / (values[i] - values[i - 1]);
            return (x(i - 1) + t * indenter.spacing).max(0.0);
        }
    }
    x(n - 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;

    fn sphere() -> MdrRequest {
        MdrRequest {
            profile: Some("hertz".into()),
            radius: Some(1.0),
            n: Some(4001),
            dx: Some(1e-3),
            indentations: Some(vec![1.0]),
            ..MdrRequest::default()
        }
    }

    fn slip(q: f64) -> SlipRequest {
        SlipRequest {
            poisson: 0.3,
            friction: Some(0.5),
            tangential_force: q,
            cycle_points: Some(11),
        }
    }

    #[test]
    fn bad_requests_have_one_set_of_words() {
        let mdr = sphere();
        let words = |r: SlipRequest| r.check(&mdr).unwrap_err().words(Names::Keywords);
        let bad_poisson = SlipRequest {
            poisson: 0.6,
            ..slip(0.1)
        };
        assert_eq!(
            words(bad_poisson),
            "invalid poisson: Poisson's ratio ν must be in [0, 0.5], got 0.6"
        );
        let no_mu = SlipRequest {
            friction: None,
            ..slip(0.1)
        };
        assert_eq!(words(no_mu), "tangential_force needs friction");
        let bad_mu = SlipRequest {
            friction: Some(-1.0),
            ..slip(0.1)
        };
        assert_eq!(
            words(bad_mu),
            "invalid friction: the friction coefficient μ must be positive and finite, got -1"
        );
        let err = slip(-1.0).check(&mdr).unwrap_err().words(Names::Flags);
        assert_eq!(err, "invalid --tangential-force: the tangential force Q* must be positive and finite, got -1");
        let two = MdrRequest {
            indentations: Some(vec![0.1, 0.2]),
            ..sphere()
        };
        let err = slip(0.1).check(&two).unwrap_err().words(Names::Flags);
        assert_eq!(
            err,
            "--tangential-force needs exactly one indentation: --indentations d"
        );
    }

    #[test]
    fn a_sphere_gives_the_cattaneo_mindlin_stick_radius() {
        // d = 1, R = 1: a = 1, F = 4/3, μF = 2/3; a/Δx = 1000.
        let mdr = sphere();
        let indenter = mdr.closed_form().unwrap();
        let spring = Spring::linear(indenter.spacing, 1.0).unwrap();
        let q_star = 0.5 * 2.0 / 3.0;
        let cycle = slip(q_star).run(&mdr, &indenter, spring).unwrap();
        assert_eq!(cycle.points.len(), 33);
        let radius = cycle.stick_radius.unwrap();
        // The top of the loading branch: c/a = (1/2)^{1/3}.
        assert!((radius[10] - 0.5f64.cbrt()).abs() < 2e-3, "{}", radius[10]);
        assert!((radius[0] - 1.0).abs() < 2e-3);
        let too_much = slip(0.7)
            .run(&mdr, &indenter, spring)
            .unwrap_err()
            .words(Names::Keywords);
        assert!(
            too_much.starts_with(
                "invalid tangential_force: the tangential force Q must be finite with |Q| <= μF"
            ),
            "{too_much}"
        );
    }
}
