//! Adhesive BEM contact for `asperity bem --work-of-adhesion` and Python's `bem_adhesion`:
//! Pohrt & Popov's pixel criterion, or where a range is given a Maugis–Dugdale cohesive
//! zone or an exponential potential ([`asperity::bem::adhesion::PixelAdhesion`]), along a path of indentations, then
//! retracted to pull-off. One request type, validated once, and
//! one run, for both front ends.

use asperity::bem::adhesion::{
    AdhesionInfo, AdhesionLaw, AdhesivePullOff, AdhesiveSummary, PixelAdhesion,
};
use asperity::bem::{HalfSpace, SolveError};
use asperity::surface::Surface;
use serde::{Deserialize, Serialize};

use crate::bem::{check_modulus, params::INDENTATIONS, params::MODULUS, parse_boundary};
use crate::refusal::{Param, Refusal};

/// The work of adhesion Δγ.
pub const WORK_OF_ADHESION: Param = Param::new("--work-of-adhesion", "work_of_adhesion");
/// The range h₀ of a Maugis–Dugdale cohesive zone.
pub const ADHESION_RANGE: Param = Param::new("--adhesion-range", "adhesion_range");
/// The cohesive law of a range: `maugis-dugdale` (the default) or `exponential`.
pub const ADHESION_MODEL: Param = Param::new("--adhesion-model", "adhesion_model");
/// The step of the retraction to pull-off.
pub const RETRACT_STEP: Param = Param::new("--retract-step", "retract_step");

/// Steps of the retraction from the path's deepest indentation to zero (to `−h₀` with a
/// cohesive zone of range `h₀`) when no step is given: the step is that distance over this.
pub const DEFAULT_RETRACT_STEPS: f64 = 200.0;

/// A cohesive range below this many times one pixel's own opening
/// ([`PixelAdhesion::cohesive_resolution`]) draws a warning: at 4.4 the Maugis–Dugdale
/// sphere's pull-off is off by 3.2 %, at 8.8 by 1.4–4.9 % (docs/adhesion.md); below 1 the
/// run is refused.
pub const COARSE_ZONE_RESOLUTION: f64 = 10.0;

/// A contact radius at pull-off below this many pixels draws a warning: the criterion's
/// error on a sphere is about `1.4 Δx/a` (docs/adhesion.md), 14 % here.
pub const COARSE_RADIUS_PIXELS: f64 = 10.0;

/// An adhesive BEM request: the half-space, Δγ, the path and the retraction's step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AdhesionRequest {
    /// E*.
    pub modulus: f64,
    /// `free` or `periodic`.
    pub boundary: String,
    /// Δγ, positive and finite.
    pub work_of_adhesion: f64,
    /// The range of a cohesive law, positive and finite: `h₀` of a Maugis–Dugdale zone
    /// (stress Δγ/h₀) or `ρ` of an exponential potential (greatest tension Δγ/ρ); `None`:
    /// the pixel criterion (adhesion of vanishing range).
    #[serde(default)]
    pub adhesion_range: Option<f64>,
    /// The cohesive law of the range: `maugis-dugdale` (`None`: this) or `exponential`;
    /// needs a range.
    #[serde(default)]
    pub adhesion_model: Option<String>,
    /// The indentations in the order visited (negative allowed: pulled back beyond first
    /// touch); the retraction to pull-off follows the last.
    pub indentations: Vec<f64>,
    /// The retraction's step (default: the deepest indentation, plus the range of a
    /// cohesive zone, over [`DEFAULT_RETRACT_STEPS`]).
    pub retract_step: Option<f64>,
}

/// A validated [`AdhesionRequest`].
#[derive(Debug, Clone, PartialEq)]
pub struct AdhesionPlan {
    /// The half-space.
    pub half_space: HalfSpace,
    /// Δγ.
    pub work_of_adhesion: f64,
    /// The adhesive law.
    pub law: AdhesionLaw,
    /// The path.
    pub indentations: Vec<f64>,
    /// The retraction's step.
    pub retract_step: f64,
}

/// The part of a run a row belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Branch {
    /// A point of the given path.
    Path,
    /// A step of the retraction to pull-off.
    Retract,
}

impl Branch {
    /// `path` or `retract`, as the CSV and Python write it.
    pub fn name(self) -> &'static str {
        match self {
            Branch::Path => "path",
            Branch::Retract => "retract",
        }
    }
}

/// One settled state of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdhesionRow {
    /// Where it belongs.
    pub branch: Branch,
    /// Its scalars.
    pub summary: AdhesiveSummary,
    /// How it was reached (for a retraction's step, that step's rounds and CG iterations;
    /// the bisection to pull-off is not a row).
    pub info: AdhesionInfo,
}

/// What a run gives.
#[derive(Debug, Clone, PartialEq)]
pub struct AdhesionRun {
    /// The path's states, then the retraction's.
    pub rows: Vec<AdhesionRow>,
    /// Both pull-offs, if the path left the surface in contact.
    pub pull_off: Option<AdhesivePullOff>,
    /// The critical stress of one pixel.
    pub critical_stress: f64,
    /// The pixel side.
    pub spacing: f64,
    /// [`PixelAdhesion::cohesive_resolution`] (`None` for the pixel criterion).
    pub zone_resolution: Option<f64>,
}

impl AdhesionRun {
    /// The loop figure of the run ([`crate::figure::adhesion::loop_chart`]): each row's
    /// `(d, F)` and whether it is the retraction's, and both pull-offs; `title`, the axes'
    /// labels and the forces' unit as the front end words them (model or SI units).
    pub fn loop_chart(&self, figure: crate::figure::adhesion::LoopFigure) -> crate::figure::Chart {
        use crate::figure::adhesion::{loop_chart, LoopPoint, LoopPullOffs};
        let points: Vec<LoopPoint> = self
            .rows
            .iter()
            .map(|r| LoopPoint {
                indentation: r.summary.indentation,
                force: r.summary.force,
                retract: r.branch == Branch::Retract,
            })
            .collect();
        let at = |s: &AdhesiveSummary| (s.indentation, s.force);
        let pull = self.pull_off.map(|p| LoopPullOffs {
            force_controlled: at(&p.force_controlled),
            displacement_controlled: at(&p.displacement_controlled),
        });
        loop_chart(&points, pull, figure)
    }

    /// The contact radius `√(A/π)` in pixels at the force-controlled pull-off.
    pub fn pull_off_radius_pixels(&self) -> Option<f64> {
        let p = self.pull_off?;
        Some((p.force_controlled.attached_points as f64 / std::f64::consts::PI).sqrt())
    }

    /// A warning where the contact at pull-off is too few pixels across for the criterion to
    /// be accurate ([`COARSE_RADIUS_PIXELS`]), or a cohesive zone too coarse
    /// ([`COARSE_ZONE_RESOLUTION`]), else `None`.
    pub fn resolution_warning(&self) -> Option<String> {
        if let Some(resolution) = self.zone_resolution {
            return (resolution < COARSE_ZONE_RESOLUTION).then(|| {
                format!(
                    "the cohesive zone is coarse: its range is {resolution:.1} times the \
                     opening one pixel's greatest adhesive tension causes (below \
                     {COARSE_ZONE_RESOLUTION} a sphere's pull-off is off by a few %, \
                     docs/adhesion.md); a finer grid or a longer range is more accurate"
                )
            });
        }
        let radius = self.pull_off_radius_pixels()?;
        (radius < COARSE_RADIUS_PIXELS).then(|| {
            format!(
                "the contact at pull-off spans {} pixels (radius {radius:.1} pixels): the pixel \
                 criterion's pull-off is then off by about {:.0} % on a sphere (1.4·Δx/a, \
                 docs/adhesion.md); a finer grid is more accurate",
                self.pull_off
                    .map_or(0, |p| p.force_controlled.attached_points),
                140.0 / radius.max(1.0)
            )
        })
    }
}

impl AdhesionRequest {
    /// The plan, or why not: Δγ positive and finite, a path of finite indentations that
    /// presses the surface, a step positive and finite, the half-space's options.
    pub fn validate(&self) -> Result<AdhesionPlan, Refusal> {
        let w = self.work_of_adhesion;
        if !(w.is_finite() && w > 0.0) {
            return Err(Refusal::saying("invalid ")
                .param(WORK_OF_ADHESION)
                .text(format!(
                    ": the work of adhesion Δγ must be positive and finite, got {}",
                    crate::refusal::number(w)
                )));
        }
        if let Some(h) = self.adhesion_range {
            if !(h.is_finite() && h > 0.0) {
                return Err(Refusal::saying("invalid ")
                    .param(ADHESION_RANGE)
                    .text(format!(
                        ": the range of the adhesive law must be positive and finite, got {}",
                        crate::refusal::number(h)
                    )));
            }
        }
        let law = self.law()?;
        check_modulus(MODULUS, self.modulus)?;
        let boundary = parse_boundary(&self.boundary)?;
        let path = &self.indentations;
        if path.is_empty() {
            return Err(Refusal::of(INDENTATIONS).text(": give at least one value"));
        }
        if let Some(v) = path.iter().find(|v| !v.is_finite()) {
            return Err(Refusal::of(INDENTATIONS).text(format!(": {v} is not finite")));
        }
        let deepest = path.iter().fold(f64::NEG_INFINITY, |m, &d| m.max(d));
        let reach = self.adhesion_range.unwrap_or(0.0);
        if deepest <= -reach {
            return Err(Refusal::of(INDENTATIONS).text(match self.adhesion_range {
                None => format!(
                    " never press the surface (the deepest is {deepest}): with adhesion of \
                     vanishing range nothing attaches before the indenter touches"
                ),
                Some(h) => format!(
                    " never come within the range {h} of the surface (the deepest is \
                     {deepest}): nothing is attracted"
                ),
            }));
        }
        let step = self
            .retract_step
            .unwrap_or((deepest + reach) / DEFAULT_RETRACT_STEPS);
        if !(step.is_finite() && step > 0.0) {
            return Err(Refusal::of(RETRACT_STEP).text(format!(
                " must be positive and finite, got {}",
                crate::refusal::number(step)
            )));
        }
        Ok(AdhesionPlan {
            half_space: HalfSpace {
                modulus: self.modulus,
                boundary,
            },
            work_of_adhesion: w,
            law,
            indentations: path.clone(),
            retract_step: step,
        })
    }
}

impl AdhesionRequest {
    /// The law of the range and model (the range already checked).
    fn law(&self) -> Result<AdhesionLaw, Refusal> {
        Ok(
            match (self.adhesion_range, self.adhesion_model.as_deref()) {
                (None, None) => AdhesionLaw::PixelCriterion,
                (None, Some(_)) => {
                    return Err(Refusal::of(ADHESION_MODEL)
                        .text(" needs ")
                        .param(ADHESION_RANGE)
                        .text(": the pixel criterion has no range"))
                }
                (Some(range), None | Some("maugis-dugdale")) => {
                    AdhesionLaw::MaugisDugdale { range }
                }
                (Some(range), Some("exponential")) => AdhesionLaw::Exponential { range },
                (Some(_), Some(other)) => {
                    return Err(Refusal::saying("invalid ")
                        .param(ADHESION_MODEL)
                        .text(format!(
                            ": {other:?} is not a cohesive law; use maugis-dugdale or exponential"
                        )))
                }
            },
        )
    }
}

impl AdhesionPlan {
    /// Runs the path on `surface` (square pixels), then the retraction to pull-off,
    /// calling `on_row` with each settled state as it comes. A cohesive zone that spans no
    /// pixel (resolution below 1) is refused before the first solve.
    pub fn run(
        &self,
        surface: &Surface,
        on_row: &mut dyn FnMut(&AdhesionRow),
    ) -> Result<AdhesionRun, SolveError> {
        let mut contact =
            PixelAdhesion::with_law(surface, self.half_space, self.work_of_adhesion, self.law)?;
        let zone_resolution = contact.cohesive_resolution();
        if let (Some(r), Some(range)) = (zone_resolution, self.law.range()) {
            if r < 1.0 {
                let finest = contact.spacing() * r;
                return Err(asperity::Error::invalid(
                    "adhesion range",
                    format!(
                        "the cohesive zone spans no pixel: one pixel's greatest adhesive \
                         tension ({}) opens it by {:.3e}, more than the range {range}; use \
                         pixels below {finest:.3e} or a longer range",
                        self.law.name(),
                        range / r
                    ),
                )
                .into());
            }
        }
        let mut rows = Vec::with_capacity(self.indentations.len());
        for &d in &self.indentations {
            let (summary, info) = contact.move_to(d)?;
            let row = AdhesionRow {
                branch: Branch::Path,
                summary,
                info,
            };
            on_row(&row);
            rows.push(row);
        }
        let pull_off = contact.retract(self.retract_step, |summary, info| {
            let row = AdhesionRow {
                branch: Branch::Retract,
                summary: *summary,
                info: *info,
            };
            on_row(&row);
            rows.push(row);
        })?;
        Ok(AdhesionRun {
            rows,
            pull_off,
            critical_stress: contact.critical_stress(),
            spacing: contact.spacing(),
            zone_resolution,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;
    use ndarray::Array2;

    fn request() -> AdhesionRequest {
        AdhesionRequest {
            modulus: 1.0,
            boundary: "free".into(),
            work_of_adhesion: 2e-4,
            adhesion_range: None,
            adhesion_model: None,
            indentations: vec![0.004, 0.008],
            retract_step: None,
        }
    }

    #[test]
    fn refuses_meaningless_requests_in_one_line() {
        let words = |r: AdhesionRequest| r.validate().unwrap_err().words(Names::Flags);
        for w in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
            let text = words(AdhesionRequest {
                work_of_adhesion: w,
                ..request()
            });
            assert!(text.starts_with("invalid --work-of-adhesion"), "{text}");
        }
        let text = words(AdhesionRequest {
            indentations: vec![0.0, -0.01],
            ..request()
        });
        assert!(text.contains("never press the surface"), "{text}");
        let text = words(AdhesionRequest {
            retract_step: Some(-1.0),
            ..request()
        });
        assert!(
            text.starts_with("--retract-step must be positive"),
            "{text}"
        );
        assert!(words(AdhesionRequest {
            indentations: vec![],
            ..request()
        })
        .contains("at least one"));
        let python = AdhesionRequest {
            work_of_adhesion: -1.0,
            ..request()
        }
        .validate()
        .unwrap_err()
        .words(Names::Keywords);
        assert!(python.starts_with("invalid work_of_adhesion"), "{python}");
    }

    #[test]
    fn a_sphere_sticks_and_lets_go() {
        // A coarse sphere (R = 1 on 30² pixels of 1e-2; a_c ≈ 8.9 pixels): the run's rows
        // follow the path then retract, the least force is the pull-off and is tensile, and
        // the warning names the coarse contact.
        let (n, dx) = (30, 1e-2);
        let heights = Array2::from_shape_fn((n, n), |(i, j)| {
            let (y, x) = ((i as f64 - 15.0) * dx, (j as f64 - 15.0) * dx);
            -(x * x + y * y) / 2.0
        });
        let surface = Surface::new(heights, n as f64 * dx).unwrap();
        let plan = AdhesionRequest {
            indentations: vec![0.005, 0.012],
            ..request()
        }
        .validate()
        .unwrap();
        let mut seen = 0;
        let run = plan.run(&surface, &mut |_| seen += 1).unwrap();
        assert_eq!(seen, run.rows.len());
        assert_eq!(run.rows[0].branch, Branch::Path);
        assert_eq!(run.rows.last().unwrap().branch, Branch::Retract);
        // Every row, the retraction's included, reports the solves that settled it.
        for row in &run.rows {
            assert!(
                row.info.rounds >= 1 && row.info.cg_iterations > 0,
                "{row:?}"
            );
        }
        let pull = run.pull_off.unwrap();
        let least = run.rows.iter().map(|r| r.summary.force).fold(0.0, f64::min);
        // The bisection's states (not rows) may only lower it.
        assert!(pull.force_controlled.force <= least && least < 0.0);
        let jkr = -1.5 * std::f64::consts::PI * 2e-4;
        assert!((least / jkr - 1.0).abs() < 0.25, "{least} vs {jkr}");
        assert!(run.resolution_warning().unwrap().contains("pixels"));
    }

    #[test]
    fn a_cohesive_zone_is_checked_and_runs() {
        let words = |r: AdhesionRequest| r.validate().unwrap_err().words(Names::Flags);
        for h in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
            let text = words(AdhesionRequest {
                adhesion_range: Some(h),
                ..request()
            });
            assert!(text.starts_with("invalid --adhesion-range"), "{text}");
        }
        // Within the range of the surface without touching it: attracted, so accepted.
        let near = AdhesionRequest {
            adhesion_range: Some(1e-3),
            indentations: vec![-5e-4],
            ..request()
        };
        assert!(near.validate().is_ok());
        let far = AdhesionRequest {
            indentations: vec![-2e-3],
            ..near.clone()
        };
        assert!(words(far).contains("never come within the range"));
        // A sphere at λ = 1 on 30² pixels of 1e-2 (a_c ≈ 8.9 pixels): tensile pull-off near
        // Maugis's −1.601πwR (within 10 % this coarse; docs/adhesion.md: +4.9 % at 10).
        let (n, dx) = (30, 1e-2);
        let heights = Array2::from_shape_fn((n, n), |(i, j)| {
            let (y, x) = ((i as f64 - 15.0) * dx, (j as f64 - 15.0) * dx);
            -(x * x + y * y) / 2.0
        });
        let surface = Surface::new(heights, n as f64 * dx).unwrap();
        let w = 2e-4;
        let unit = asperity::reference::MaugisDugdale::scales(1.0, 1.0, w, 1.0);
        let plan = AdhesionRequest {
            adhesion_range: Some(w * unit.lambda),
            indentations: vec![0.005, 0.012],
            ..request()
        }
        .validate()
        .unwrap();
        let run = plan.run(&surface, &mut |_| {}).unwrap();
        let maugis = -1.601 * std::f64::consts::PI * w;
        let least = run.pull_off.unwrap().force_controlled.force;
        assert!((least / maugis - 1.0).abs() < 0.1, "{least} vs {maugis}");
        assert!(run.zone_resolution.unwrap() > 1.0);
        // A range a pixel's own tension closes is refused before any solve.
        let coarse = AdhesionRequest {
            adhesion_range: Some(1e-9),
            ..request()
        }
        .validate()
        .unwrap();
        let error = coarse.run(&surface, &mut |_| {}).unwrap_err().to_string();
        assert!(error.contains("spans no pixel"), "{error}");
    }
    #[test]
    fn an_exponential_potential_is_chosen_checked_and_runs() {
        let words = |r: AdhesionRequest| r.validate().unwrap_err().words(Names::Flags);
        let exponential = || Some("exponential".to_string());
        let text = words(AdhesionRequest {
            adhesion_model: exponential(),
            ..request()
        });
        assert!(
            text.starts_with("--adhesion-model needs --adhesion-range"),
            "{text}"
        );
        let python = AdhesionRequest {
            adhesion_model: exponential(),
            ..request()
        }
        .validate()
        .unwrap_err()
        .words(Names::Keywords);
        assert!(
            python.starts_with("adhesion_model needs adhesion_range"),
            "{python}"
        );
        let text = words(AdhesionRequest {
            adhesion_range: Some(1e-3),
            adhesion_model: Some("lennard-jones".into()),
            ..request()
        });
        assert!(text.starts_with("invalid --adhesion-model"), "{text}");
        // A sphere (R = 1, 40² pixels of 1e-2, w = 2e-4: a_c ≈ 8.9 pixels) at Tabor's μ = 1
        // (ρ = w^{2/3}, resolution ≈ 6): a tensile pull-off between JKR's −1.5πwR and
        // DMT's −2πwR (the grid cuts the potential's far tail, gaps beyond about 3ρ, so a
        // little less than the full force; loose on purpose: the library's tests hold the
        // limits).
        let (n, dx, w) = (40, 1e-2, 2e-4f64);
        let heights = Array2::from_shape_fn((n, n), |(i, j)| {
            let (y, x) = ((i as f64 - 20.0) * dx, (j as f64 - 20.0) * dx);
            -(x * x + y * y) / 2.0
        });
        let surface = Surface::new(heights, n as f64 * dx).unwrap();
        let range = w.powf(2.0 / 3.0);
        let plan = AdhesionRequest {
            adhesion_range: Some(range),
            adhesion_model: exponential(),
            indentations: vec![0.005, 0.012],
            ..request()
        }
        .validate()
        .unwrap();
        assert_eq!(plan.law, AdhesionLaw::Exponential { range });
        let run = plan.run(&surface, &mut |_| {}).unwrap();
        let force = run.pull_off.unwrap().force_controlled.force / (std::f64::consts::PI * w);
        assert!(force < -1.3 && force > -2.0, "{force}");
        assert!(run.zone_resolution.unwrap() > 3.0);
        let coarse = AdhesionRequest {
            adhesion_range: Some(1e-9),
            adhesion_model: exponential(),
            ..request()
        }
        .validate()
        .unwrap();
        let error = coarse.run(&surface, &mut |_| {}).unwrap_err().to_string();
        assert!(
            error.contains("spans no pixel") && error.contains("exponential"),
            "{error}"
        );
    }
}
