//! `asperity mdr` and Python's `mdr()`: the choice of indenter, its spring grid, the spring
//! law, the indentations and the curve, with every default once ([`DEFAULT_NLOADS`]).
//!
//! A front end reads what it reads (the CLI a file, Python an array) and gives the line or
//! the radial samples; everything else is decided here, so both give the same curve and
//! refuse the same requests in the same words.

use asperity::mdr::{
    log_spaced, AdhesiveLine, Axisymmetric, CurvePoint, Foundation, LinearCurve, PullOffs,
    RadialProfile, Spring, SpringLaw,
};
use asperity::memory::{array_bytes, ensure_fits};
use asperity::surface::stats::rms_height;
use serde::{Deserialize, Serialize};
use serde_json::json;

use crate::refusal::{Param, Refusal, RequestError};

/// The parameters of `asperity mdr`, as each front end names them.
pub mod params {
    use crate::refusal::Param;

    /// A rough line.
    pub const LINE: Param = Param::new("--line", "line");
    /// A closed-form indenter.
    pub const PROFILE: Param = Param::new("--profile", "profile");
    /// A sampled axisymmetric profile.
    pub const RADIAL: Param = Param::new("--radial", "radial");
    /// Its sample step.
    pub const RADIAL_STEP: Param = Param::new("--radial-step", "radial_step");
    /// Sphere or punch radius.
    pub const RADIUS: Param = Param::new("--radius", "radius");
    /// Cone slope.
    pub const SLOPE: Param = Param::new("--slope", "slope");
    /// Power-law prefactor.
    pub const COEFFICIENT: Param = Param::new("--coefficient", "coefficient");
    /// Power-law exponent.
    pub const EXPONENT: Param = Param::new("--exponent", "exponent");
    /// Number of springs.
    pub const N: Param = Param::new("--n", "n");
    /// Spring spacing.
    pub const DX: Param = Param::new("--dx", "dx");
    /// The spring law.
    pub const SPRING: Param = Param::new("--spring", "spring");
    /// H of the fractal law.
    pub const HURST: Param = Param::new("--hurst", "hurst");
    /// rms height of the fractal law.
    pub const RMS_HEIGHT: Param = Param::new("--rms-height", "rms_height");
    /// Radius of the Hertz law.
    pub const ASPERITY_RADIUS: Param = Param::new("--asperity-radius", "asperity_radius");
    /// A list of indentations.
    pub const INDENTATIONS: Param = Param::new("--indentations", "indentations");
    /// The number of log-spaced indentations.
    pub const NLOADS: Param = Param::new("--nloads", "nloads");
    /// The smallest of them.
    pub const DMIN: Param = Param::new("--dmin", "dmin");
    /// The largest of them.
    pub const DMAX: Param = Param::new("--dmax", "dmax");
    /// The exact curve of linear springs on a line.
    pub const BREAKPOINTS: Param = Param::new("--breakpoints", "breakpoints");
    /// The work of adhesion Δγ (Heß's rule).
    pub const WORK_OF_ADHESION: Param = Param::new("--work-of-adhesion", "work_of_adhesion");
}

use params::*;

/// Indentations of an `nloads` curve when none is given.
pub const DEFAULT_NLOADS: usize = 50;

/// `dmin` when not given: `dmax` × this.
pub const DEFAULT_DMIN_FRACTION: f64 = 1e-6;

/// The indenter on its spring grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Indenter {
    /// Line heights (positive up) or indenter profile g (lowest point touches first).
    pub values: Vec<f64>,
    /// A rough line (gaps from the highest point).
    pub is_line: bool,
    /// Spring spacing Δx.
    pub spacing: f64,
    /// Length L (used by the fractal law).
    pub size: f64,
    /// One line describing it.
    pub description: String,
    /// Where it came from, for a record.
    pub source: serde_json::Value,
}

impl Indenter {
    /// Its spring foundation: a rough line's gaps from its highest point, or the profile.
    fn foundation(&self, spring: Spring) -> asperity::Result<Foundation> {
        if self.is_line {
            Foundation::from_heights(&self.values, spring)
        } else {
            Foundation::from_profile(&self.values, spring)
        }
    }
}

impl Indenter {
    /// A rough line of `heights` over the length `size` (spacing `size / n`); `name` says
    /// where it came from in the description (a file name, or empty).
    pub fn line(heights: Vec<f64>, size: f64, name: &str) -> Result<Indenter, Refusal> {
        if !(size.is_finite() && size > 0.0) {
            return Err(Refusal::saying("invalid ").param(SIZE).text(format!(
                ": the line length must be positive and finite, got {}",
                crate::refusal::number(size)
            )));
        }
        if heights.is_empty() {
            return Err(Refusal::saying("invalid ")
                .param(LINE)
                .text(": it has no points"));
        }
        let name = if name.is_empty() {
            String::new()
        } else {
            format!(" {name}")
        };
        Ok(Indenter {
            description: format!("line{name} ({} points, L = {size})", heights.len()),
            source: json!({ "kind": "line", "points": heights.len() }),
            spacing: size / heights.len() as f64,
            values: heights,
            is_line: true,
            size,
        })
    }
}

/// The line length of `asperity mdr` (both front ends' `size`).
pub const SIZE: Param = Param::new("--size", "size");

/// An `asperity mdr` request besides the line or radial samples themselves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MdrRequest {
    /// A line is given (its heights go to [`Indenter::line`]).
    pub line: bool,
    /// A closed-form indenter: `hertz`, `cone`, `punch` or `power`.
    pub profile: Option<String>,
    /// Radial samples are given.
    pub radial: bool,
    /// Their step.
    pub radial_step: Option<f64>,
    /// Sphere or punch radius.
    pub radius: Option<f64>,
    /// Cone slope tan θ.
    pub slope: Option<f64>,
    /// Power-law prefactor c.
    pub coefficient: Option<f64>,
    /// Power-law exponent n.
    pub exponent: Option<f64>,
    /// Springs of a profile or radial indenter.
    pub n: Option<usize>,
    /// Their spacing.
    pub dx: Option<f64>,
    /// Length L.
    pub size: Option<f64>,
    /// E*.
    pub modulus: f64,
    /// `linear`, `hertz` or `fractal`.
    pub spring: String,
    /// H of the fractal law.
    pub hurst: Option<f64>,
    /// rms height of the fractal law.
    pub rms_height: Option<f64>,
    /// Radius of the Hertz law.
    pub asperity_radius: Option<f64>,
    /// Indentations to evaluate.
    pub indentations: Option<Vec<f64>>,
    /// Log-spaced indentations (default [`DEFAULT_NLOADS`]).
    pub nloads: Option<usize>,
    /// The smallest.
    pub dmin: Option<f64>,
    /// The largest.
    pub dmax: Option<f64>,
    /// The exact curve of linear springs on a line.
    pub breakpoints: bool,
    /// The work of adhesion Δγ: springs stick by Heß's rule, the indentations are a load
    /// path, and a retraction to pull-off follows ([`MdrRequest::compute_adhesive`]).
    #[serde(default)]
    pub work_of_adhesion: Option<f64>,
}

impl Default for MdrRequest {
    /// No indenter yet; E* = 1, linear springs, [`DEFAULT_NLOADS`] indentations.
    fn default() -> Self {
        MdrRequest {
            line: false,
            profile: None,
            radial: false,
            radial_step: None,
            radius: None,
            slope: None,
            coefficient: None,
            exponent: None,
            n: None,
            dx: None,
            size: None,
            modulus: 1.0,
            spring: "linear".into(),
            hurst: None,
            rms_height: None,
            asperity_radius: None,
            indentations: None,
            nloads: None,
            dmin: None,
            dmax: None,
            breakpoints: false,
            work_of_adhesion: None,
        }
    }
}

fn needs(what: Refusal, param: Param) -> Refusal {
    what.text(" needs ").param(param)
}

fn need(value: Option<f64>, param: Param, what: impl Fn() -> Refusal) -> Result<f64, Refusal> {
    value.ok_or_else(|| needs(what(), param))
}

impl MdrRequest {
    /// The choice of indenter and of indentations, checked before any file is read.
    pub fn check(&self) -> Result<(), Refusal> {
        let given = [self.line, self.profile.is_some(), self.radial];
        if given.iter().filter(|g| **g).count() > 1 {
            return Err(Refusal::saying("give one indenter: ")
                .param(LINE)
                .text(", ")
                .param(PROFILE)
                .text(" or ")
                .param(RADIAL));
        }
        if given.iter().all(|g| !g) {
            return Err(Refusal::saying("give an indenter: ")
                .param(LINE)
                .text(", ")
                .param(PROFILE)
                .text(" hertz|cone|punch|power or ")
                .param(RADIAL));
        }
        if self.line && (self.n.is_some() || self.dx.is_some()) {
            return Err(Refusal::of(N)
                .text(" and ")
                .param(DX)
                .text(" are for profile and radial indenters (a line's spacing is its length / its points)"));
        }
        if self.radial && self.radial_step.is_none() {
            return Err(needs(Refusal::of(RADIAL), RADIAL_STEP));
        }
        if self.breakpoints && (self.indentations.is_some() || self.nloads.is_some()) {
            return Err(Refusal::of(BREAKPOINTS)
                .text(" gives the exact curve: drop ")
                .param(INDENTATIONS)
                .text(" and ")
                .param(NLOADS));
        }
        self.check_adhesion()?;
        if self.indentations.is_some() && self.nloads.is_some() {
            return Err(Refusal::saying("give at most one of ")
                .param(INDENTATIONS)
                .text(" and ")
                .param(NLOADS));
        }
        Ok(())
    }

    /// With a work of adhesion: positive and finite, linear springs, no breakpoints.
    fn check_adhesion(&self) -> Result<(), Refusal> {
        let Some(w) = self.work_of_adhesion else {
            return Ok(());
        };
        if !(w.is_finite() && w > 0.0) {
            return Err(Refusal::saying("invalid ")
                .param(WORK_OF_ADHESION)
                .text(format!(
                    ": the work of adhesion Δγ must be positive and finite, got {}",
                    crate::refusal::number(w)
                )));
        }
        if self.spring != "linear" || self.breakpoints {
            return Err(Refusal::of(WORK_OF_ADHESION).text(
                " needs linear springs and a list of indentations or nloads (Heß's rule holds \
                 for springs of stiffness E*·Δx; the retraction's exact curve is always written)",
            ));
        }
        Ok(())
    }

    /// The springs of a profile or radial indenter: `(n, Δx)`.
    fn spring_grid(&self, what: Param) -> Result<(usize, f64), RequestError> {
        let n = self
            .n
            .ok_or_else(|| needs(Refusal::of(what), N).text(" (number of springs)"))?;
        let dx = need(self.dx, DX, || Refusal::of(what))?;
        if !(dx.is_finite() && dx > 0.0) {
            let refusal = Refusal::saying("invalid ").param(DX).text(format!(
                ": the spring spacing Δx must be positive and finite, got {}",
                crate::refusal::number(dx)
            ));
            return Err(refusal.into());
        }
        if n == 0 {
            let refusal = Refusal::saying("invalid ")
                .param(N)
                .text(": need at least one spring");
            return Err(refusal.into());
        }
        // The profile g(x_i) and the foundation's sorted copy of it: two f64 per spring.
        let what = format!("{n} springs (profile and sorted gaps, 16 bytes each)");
        ensure_fits(&what, array_bytes(&[n, 2], std::mem::size_of::<f64>())).map_err(|source| {
            RequestError::Library {
                param: N,
                value: n.to_string(),
                source: Box::new(source),
            }
        })?;
        Ok((n, dx))
    }

    /// The closed-form indenter of `profile` on its springs.
    pub fn closed_form(&self) -> Result<Indenter, RequestError> {
        let kind = self.profile.as_deref().unwrap_or_default();
        let of = |name: &'static str| move || Refusal::of(PROFILE).text(format!(" {name}"));
        let shape = match kind {
            "hertz" => Axisymmetric::Sphere {
                radius: need(self.radius, RADIUS, of("hertz"))?,
            },
            "punch" => Axisymmetric::FlatPunch {
                radius: need(self.radius, RADIUS, of("punch"))?,
            },
            "cone" => Axisymmetric::Cone {
                slope: need(self.slope, SLOPE, of("cone"))?,
            },
            "power" => Axisymmetric::PowerLaw {
                coefficient: need(self.coefficient, COEFFICIENT, of("power"))?,
                exponent: need(self.exponent, EXPONENT, of("power"))?,
            },
            other => {
                let refusal = Refusal::of(PROFILE).text(format!(
                    " must be hertz, cone, punch or power, got {other:?}"
                ));
                return Err(refusal.into());
            }
        };
        shape.validate().map_err(invalid)?;
        let (n, dx) = self.spring_grid(PROFILE)?;
        let values = shape.sample(n, dx).map_err(invalid)?;
        Ok(self.axisymmetric(
            values,
            dx,
            format!("{shape}, n = {n}, Δx = {dx}"),
            json!({ "kind": "profile", "shape": shape }),
        ))
    }

    /// The axisymmetric profile f(r) sampled at `samples` (step `radial_step`) on its
    /// springs; `name` says where it came from in the description (a file name, or empty).
    pub fn radial(&self, samples: &[f64], name: &str) -> Result<Indenter, RequestError> {
        let step = need(self.radial_step, RADIAL_STEP, || Refusal::of(RADIAL))?;
        let profile = RadialProfile::new(samples, step).map_err(invalid)?;
        let (n, dx) = self.spring_grid(RADIAL)?;
        let values = profile.sample(n, dx).map_err(invalid)?;
        let name = if name.is_empty() {
            String::new()
        } else {
            format!(" {name}")
        };
        let description = format!(
            "radial profile{name} ({} samples, Δr = {step}), n = {n}, Δx = {dx}",
            samples.len()
        );
        let source = json!({
            "kind": "radial profile", "samples": samples.len(), "radial_step": step,
        });
        Ok(self.axisymmetric(values, dx, description, source))
    }

    /// An axisymmetric indenter mapped to `values` on springs `dx` apart (L: `size`, else
    /// the grid's n·Δx).
    fn axisymmetric(
        &self,
        values: Vec<f64>,
        dx: f64,
        description: String,
        source: serde_json::Value,
    ) -> Indenter {
        Indenter {
            size: self.size.unwrap_or(values.len() as f64 * dx),
            values,
            is_line: false,
            spacing: dx,
            description,
            source,
        }
    }

    /// The spring law for `indenter`.
    pub fn spring_law(&self, indenter: &Indenter) -> Result<SpringLaw, Refusal> {
        Ok(match self.spring.as_str() {
            "linear" => SpringLaw::Linear,
            "hertz" => {
                let radius = match (self.asperity_radius, self.profile.as_deref()) {
                    (Some(r), _) => r,
                    (None, Some("hertz")) => {
                        need(self.radius, RADIUS, || Refusal::of(PROFILE).text(" hertz"))?
                    }
                    _ => {
                        let law = Refusal::saying("the hertz spring law (15.2)");
                        return Err(needs(law, ASPERITY_RADIUS));
                    }
                };
                SpringLaw::Hertz { radius }
            }
            "fractal" => {
                let law = || Refusal::saying("the fractal spring law (15.7)");
                let hurst = need(self.hurst, HURST, law)?;
                let rms = match (self.rms_height, indenter.is_line) {
                    (Some(h), _) => h,
                    (None, true) => rms_height(indenter.values.iter().copied()),
                    (None, false) => return Err(needs(law().text(" on a profile"), RMS_HEIGHT)),
                };
                SpringLaw::Fractal {
                    hurst,
                    rms_height: rms,
                    size: indenter.size,
                }
            }
            other => {
                return Err(Refusal::of(SPRING)
                    .text(format!(" must be linear, hertz or fractal, got {other:?}")))
            }
        })
    }

    /// The indentations to evaluate: the list, or `nloads` log-spaced from `dmin` to
    /// `dmax` (default: full contact); `row_bytes` of memory kept per indentation.
    pub fn levels(
        &self,
        foundation: &Foundation,
        row_bytes: usize,
    ) -> Result<Vec<f64>, RequestError> {
        if let Some(list) = &self.indentations {
            // An adhesive load path may retract past first contact (d < 0).
            let adhesive = self.work_of_adhesion.is_some();
            if let Some(bad) = list
                .iter()
                .find(|d| !d.is_finite() || (**d < 0.0 && !adhesive))
            {
                let rule = if adhesive {
                    "finite"
                } else {
                    "finite and >= 0"
                };
                let refusal = Refusal::saying("invalid ")
                    .param(INDENTATIONS)
                    .text(format!(
                        ": each must be {rule}, got {}",
                        crate::refusal::number(*bad)
                    ));
                return Err(refusal.into());
            }
            return Ok(list.clone());
        }
        let count = self.nloads.unwrap_or(DEFAULT_NLOADS);
        ensure_rows_fit(count, NLOADS, row_bytes)?;
        let dmax = match self.dmax {
            Some(d) => d,
            None => {
                let full = foundation.full_contact_indentation();
                if full <= 0.0 {
                    let refusal = Refusal::saying(
                        "every spring touches at the first contact (all gaps are equal, e.g. a \
                         flat punch, or a profile sampled by one or two springs), so there is \
                         no range of indentations to sweep: give ",
                    )
                    .param(DMAX)
                    .text(", or ")
                    .param(INDENTATIONS);
                    return Err(refusal.into());
                }
                full
            }
        };
        let dmin = self.dmin.unwrap_or(dmax * DEFAULT_DMIN_FRACTION);
        log_spaced(dmin, dmax, count).map_err(|e| {
            let refusal = Refusal::of(DMIN)
                .text("/")
                .param(DMAX)
                .text("/")
                .param(NLOADS)
                .text(format!(": {e}"));
            refusal.into()
        })
    }

    /// The curve, one point at a time (`emit`): the exact breakpoints of linear springs on a
    /// line, or the foundation at every indentation asked for (`row_bytes` kept per point).
    /// Returns the indentations evaluated (none for the breakpoints).
    pub fn compute(
        &self,
        indenter: &Indenter,
        spring: Spring,
        row_bytes: usize,
        emit: &mut dyn FnMut(CurvePoint),
    ) -> Result<Option<Vec<f64>>, RequestError> {
        if self.breakpoints {
            if !(spring.is_linear() && indenter.is_line) {
                let refusal = Refusal::of(BREAKPOINTS)
                    .text(" needs ")
                    .param(LINE)
                    .text(" with linear springs (the exact piecewise-linear curve)");
                return Err(refusal.into());
            }
            // One row per spring, besides the curve's breakpoints and forces (two f64 each).
            let per_row = row_bytes + 2 * std::mem::size_of::<f64>();
            ensure_rows_fit(indenter.values.len(), BREAKPOINTS, per_row)?;
            let curve = LinearCurve::from_heights(&indenter.values, spring.spacing(), self.modulus)
                .map_err(invalid)?;
            (1..=curve.len()).for_each(|j| emit(curve.breakpoint(j)));
            return Ok(None);
        }
        let foundation = indenter.foundation(spring).map_err(invalid)?;
        let levels = self.levels(&foundation, row_bytes)?;
        levels.iter().for_each(|&d| emit(foundation.evaluate(d)));
        Ok(Some(levels))
    }
}

/// The columns of an MDR curve.
pub const COLUMNS: [&str; 4] = ["indentation", "force", "stiffness", "contacts"];

/// The columns of an adhesive MDR curve: [`COLUMNS`] and the branch.
pub const ADHESIVE_COLUMNS: [&str; 5] = ["indentation", "force", "stiffness", "contacts", "branch"];

/// Whether a row of an adhesive curve was reached going in or coming out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Branch {
    /// The indentation grew (or stayed): springs attach as they are pressed.
    Approach,
    /// The indentation fell: springs let go by Heß's rule.
    Retract,
}

impl Branch {
    /// `approach` or `retract`.
    pub fn name(self) -> &'static str {
        match self {
            Branch::Approach => "approach",
            Branch::Retract => "retract",
        }
    }
}

impl MdrRequest {
    /// The adhesive curve (a work of adhesion given): the indenter follows the
    /// indentations in their order (a load path: any finite values, up and down), every
    /// release on the way reported, then retracts until the last spring lets go (the exact
    /// curve, [`AdhesiveLine::retract`]). Returns the path and the pull-offs (`None` if
    /// nothing was in contact at the end of the path).
    pub fn compute_adhesive(
        &self,
        indenter: &Indenter,
        row_bytes: usize,
        emit: &mut dyn FnMut(CurvePoint, Branch),
    ) -> Result<(Vec<f64>, Option<PullOffs>), RequestError> {
        let w = self.work_of_adhesion.unwrap_or_default();
        let (spacing, modulus) = (indenter.spacing, self.modulus);
        let mut line = if indenter.is_line {
            AdhesiveLine::from_heights(&indenter.values, spacing, modulus, w)
        } else {
            AdhesiveLine::from_profile(&indenter.values, spacing, modulus, w)
        }
        .map_err(invalid)?;
        let spring = Spring::new(SpringLaw::Linear, spacing, modulus).map_err(invalid)?;
        let foundation = indenter.foundation(spring).map_err(invalid)?;
        let levels = self.levels(&foundation, row_bytes)?;
        // Each retraction reports two rows per release, at most one release per spring
        // attached before it: one full retraction's rows besides the path's.
        ensure_rows_fit(
            levels.len() + 2 * indenter.values.len(),
            INDENTATIONS,
            row_bytes,
        )?;
        let mut last = 0.0;
        for &d in &levels {
            let branch = if d >= last {
                Branch::Approach
            } else {
                Branch::Retract
            };
            let point = line
                .move_to(d, &mut |p| emit(p, Branch::Retract))
                .map_err(invalid)?;
            emit(point, branch);
            last = d;
        }
        let pull_offs = line.retract(&mut |p| emit(p, Branch::Retract));
        Ok((levels, pull_offs))
    }
}

/// Refuses `rows` output rows of `per_row` bytes that would not fit in memory.
fn ensure_rows_fit(rows: usize, param: Param, per_row: usize) -> Result<(), RequestError> {
    let what = format!("{rows} rows of about {per_row} bytes");
    ensure_fits(&what, array_bytes(&[rows], per_row)).map_err(|source| RequestError::Library {
        param,
        value: rows.to_string(),
        source: Box::new(source),
    })
}

fn invalid(source: asperity::Error) -> RequestError {
    RequestError::Invalid(Box::new(source))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;

    #[test]
    fn the_choice_of_indenter_has_one_set_of_words() {
        let none = MdrRequest::default();
        let err = none.check().unwrap_err().words(Names::Keywords);
        assert_eq!(
            err,
            "give an indenter: line, profile hertz|cone|punch|power or radial"
        );
        let two = MdrRequest {
            line: true,
            radial: true,
            ..MdrRequest::default()
        };
        assert_eq!(
            two.check().unwrap_err().to_string(),
            "give one indenter: --line, --profile or --radial"
        );
        let cone = MdrRequest {
            profile: Some("cone".into()),
            n: Some(11),
            dx: Some(0.1),
            ..MdrRequest::default()
        };
        let err = cone.closed_form().unwrap_err().words(Names::Flags);
        assert_eq!(err, "--profile cone needs --slope");
    }

    #[test]
    fn a_closed_form_curve_is_the_librarys() {
        let request = MdrRequest {
            profile: Some("hertz".into()),
            radius: Some(1.0),
            n: Some(201),
            dx: Some(0.01),
            indentations: Some(vec![1e-4, 1e-3]),
            ..MdrRequest::default()
        };
        request.check().unwrap();
        let indenter = request.closed_form().unwrap();
        let law = request.spring_law(&indenter).unwrap();
        let spring = Spring::new(law, indenter.spacing, 1.0).unwrap();
        let mut points = Vec::new();
        let levels = request
            .compute(&indenter, spring, 0, &mut |p| points.push(p))
            .unwrap();
        let shape = Axisymmetric::Sphere { radius: 1.0 };
        let foundation =
            Foundation::from_profile(&shape.sample(201, 0.01).unwrap(), spring).unwrap();
        assert_eq!(levels, Some(vec![1e-4, 1e-3]));
        assert_eq!(
            points,
            vec![foundation.evaluate(1e-4), foundation.evaluate(1e-3)]
        );
    }

    #[test]
    fn an_adhesive_sphere_retracts_to_the_jkr_pull_off() {
        let request = MdrRequest {
            profile: Some("hertz".into()),
            radius: Some(1.0),
            n: Some(1001),
            dx: Some(1e-3),
            indentations: Some(vec![0.01, 0.09, 0.05]),
            work_of_adhesion: Some(1e-3),
            ..MdrRequest::default()
        };
        request.check().unwrap();
        let indenter = request.closed_form().unwrap();
        let mut rows = Vec::new();
        let (levels, pull_offs) = request
            .compute_adhesive(&indenter, 0, &mut |p, b| rows.push((p, b)))
            .unwrap();
        assert_eq!(levels, vec![0.01, 0.09, 0.05]);
        assert_eq!(rows[0].1, Branch::Approach);
        assert_eq!(rows.last().unwrap().1, Branch::Retract);
        assert_eq!(rows.last().unwrap().0.contacts, 0);
        let jkr = asperity::reference::Jkr::new(1.0, 1.0, 1e-3).unwrap();
        let expected = jkr.pull_off_force(asperity::reference::PullOff::ForceControlled);
        let force = pull_offs.unwrap().force_controlled.force;
        assert!(
            (force / expected - 1.0).abs() < 1e-3,
            "{force} vs {expected}"
        );
    }

    #[test]
    fn adhesion_is_refused_in_one_set_of_words() {
        let base = MdrRequest {
            profile: Some("hertz".into()),
            radius: Some(1.0),
            n: Some(11),
            dx: Some(0.1),
            ..MdrRequest::default()
        };
        for w in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let request = MdrRequest {
                work_of_adhesion: Some(w),
                ..base.clone()
            };
            let words = request.check().unwrap_err().words(Names::Keywords);
            assert_eq!(
                words,
                format!(
                    "invalid work_of_adhesion: the work of adhesion Δγ must be positive and \
                     finite, got {}",
                    crate::refusal::number(w)
                )
            );
        }
        let hertz_springs = MdrRequest {
            work_of_adhesion: Some(1.0),
            spring: "hertz".into(),
            ..base.clone()
        };
        let words = hertz_springs.check().unwrap_err().to_string();
        assert!(
            words.starts_with("--work-of-adhesion needs linear springs"),
            "{words}"
        );
        // A path may go below first contact with adhesion, not without.
        let path = MdrRequest {
            indentations: Some(vec![0.01, -0.01]),
            ..base.clone()
        };
        let indenter = path.closed_form().unwrap();
        let err = path
            .compute(
                &indenter,
                Spring::new(SpringLaw::Linear, 0.1, 1.0).unwrap(),
                0,
                &mut |_| {},
            )
            .unwrap_err();
        assert!(
            err.to_string().contains("finite and >= 0, got -0.01"),
            "{err}"
        );
        let adhesive = MdrRequest {
            work_of_adhesion: Some(1e-3),
            ..path
        };
        assert!(adhesive
            .compute_adhesive(&indenter, 0, &mut |_, _| {})
            .is_ok());
    }
}
