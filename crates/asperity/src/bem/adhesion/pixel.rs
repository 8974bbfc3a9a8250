//! [`PixelAdhesion`]: the Pohrt–Popov pixel criterion on the BEM (module docs of
//! [`super`]).

use ndarray::Array2;

use super::super::precondition::FourierPreconditioner;
use super::super::stiffness::cg::{conjugate_gradient_on_set, CgParams, CgWork, RightHandSide};
use super::super::{Control, HalfSpace, SolveError};
use super::{
    AdhesionInfo, AdhesionLaw, AdhesionParams, AdhesivePullOff, AdhesiveSummary,
    EXPONENTIAL_CUTOFF, RETRACT_BISECTIONS, TENSION_TOLERANCE,
};
use crate::elastic::{Boundary, ElasticOperator, HalfSpaceOperator};
use crate::reference::adhesion::{pixel_critical_stress, pixel_mean_compliance};
use crate::stop::Stop;
use crate::surface::Surface;
use crate::Error;

/// An adhesive contact of one surface on a half-space by the pixel criterion: the attached
/// set, the pressure and the displacement of the current state, and the fields of its
/// iteration (allocated once; moving to another indentation allocates nothing).
pub struct PixelAdhesion {
    operator: ElasticOperator,
    preconditioner: FourierPreconditioner,
    cg: CgWork,
    params: AdhesionParams,
    stop: Stop,
    /// Indenter profile `f = max(h) − h`, row-major.
    profile: Vec<f64>,
    /// Pressure of the current state (zero off the attached set).
    pressure: Vec<f64>,
    /// `u = K p` of the current state.
    displacement: Vec<f64>,
    /// The right-hand side of the correction's CG.
    rhs: Vec<f64>,
    attached: Vec<bool>,
    /// Pixels that let go at the current indentation (they may not re-attach at it).
    released_here: Vec<bool>,
    work_of_adhesion: f64,
    law: AdhesionLaw,
    /// The tension at which an attached pixel lets go: `σ_c` of the pixel criterion, or
    /// the Dugdale stress `σ₀ = w/h₀` (which free pixels within the range also carry).
    critical_stress: f64,
    modulus: f64,
    indentation: f64,
}

impl PixelAdhesion {
    /// The adhesive contact of `surface` (square pixels) on `half_space` with work of
    /// adhesion `w` (positive and finite) by the pixel criterion, not yet touching (`d` = 0,
    /// nothing attached).
    pub fn new(surface: &Surface, half_space: HalfSpace, w: f64) -> Result<Self, SolveError> {
        Self::with_law(surface, half_space, w, AdhesionLaw::PixelCriterion)
    }

    /// The same under `law` (a Maugis–Dugdale range positive and finite).
    pub fn with_law(
        surface: &Surface,
        half_space: HalfSpace,
        w: f64,
        law: AdhesionLaw,
    ) -> Result<Self, SolveError> {
        crate::positive_finite("work of adhesion", w, "")?;
        if let Some(range) = law.range() {
            crate::positive_finite("range", range, "")?;
        }
        crate::positive_finite("modulus", half_space.modulus, "")?;
        if !surface.has_square_pixels() {
            return Err(Error::invalid(
                "surface",
                format!(
                    "the pixel criterion needs square pixels, got {} x {}",
                    crate::input::short_number(surface.spacing()),
                    crate::input::short_number(surface.spacing_y())
                ),
            )
            .into());
        }
        let (rows, cols) = surface.dim();
        let dx = surface.spacing();
        // An upper bound: the contact solver's parts include every field used here.
        crate::memory::ensure_fits(
            &format!(
                "an adhesive BEM contact of a {rows}x{cols} grid ({} boundaries)",
                half_space.boundary.name()
            ),
            super::super::ContactSolver::memory_bytes(rows, cols, half_space.boundary),
        )?;
        let operator = ElasticOperator::with_spacings(
            rows,
            cols,
            dx,
            dx,
            half_space.modulus,
            half_space.boundary,
        )?;
        let preconditioner = FourierPreconditioner::new(rows, cols, dx, dx, half_space.modulus)?;
        let cg = CgWork::for_operator(&operator, false);
        let heights = surface.heights();
        let top = heights.iter().fold(f64::NEG_INFINITY, |m, &h| m.max(h));
        let len = rows * cols;
        Ok(PixelAdhesion {
            operator,
            preconditioner,
            cg,
            params: AdhesionParams::default(),
            stop: Stop::new(),
            profile: heights.iter().map(|&h| top - h).collect(),
            pressure: vec![0.0; len],
            displacement: vec![0.0; len],
            rhs: vec![0.0; len],
            attached: vec![false; len],
            released_here: vec![false; len],
            work_of_adhesion: w,
            law,
            critical_stress: match law {
                AdhesionLaw::PixelCriterion => pixel_critical_stress(half_space.modulus, w, dx),
                AdhesionLaw::MaugisDugdale { range } | AdhesionLaw::Exponential { range } => {
                    w / range
                }
            },
            modulus: half_space.modulus,
            indentation: 0.0,
        })
    }

    /// The same with `params` (validated).
    pub fn with_params(mut self, params: AdhesionParams) -> Result<Self, SolveError> {
        params.validate()?;
        self.params = params;
        Ok(self)
    }

    /// The contact with `stop` polled by every CG iteration: a requested stop ends a move
    /// with [`SolveError::Interrupted`].
    pub fn with_stop(mut self, stop: Stop) -> Self {
        self.stop = stop;
        self
    }

    /// The tension at which an attached pixel lets go: `σ_c` of the pixel criterion, or
    /// the Dugdale stress `σ₀ = w/h₀`.
    pub fn critical_stress(&self) -> f64 {
        self.critical_stress
    }

    /// The adhesive law.
    pub fn law(&self) -> AdhesionLaw {
        self.law
    }

    /// How well the pixel resolves a cohesive law's range: the range (`h₀`, `ρ`) over the
    /// opening that the law's greatest tension on one pixel causes there, `c̄σΔx/E*`
    /// ([`pixel_mean_compliance`]; `σ = w/h₀` or `w/ρ`), i.e. `E*h₀²/(c̄wΔx)`. Below 1 a
    /// pixel's own tension closes more than the whole range: a pixel-by-pixel zone means
    /// nothing (Maugis–Dugdale), a lone pixel snaps against the potential (exponential;
    /// the issue's `Δx ≤ (8/3π)ρ²E*/w` is resolution 1.12 by this measure); `None` for the
    /// pixel criterion.
    pub fn cohesive_resolution(&self) -> Option<f64> {
        let range = self.law.range()?;
        Some(
            range
                / (pixel_mean_compliance() * self.critical_stress * self.spacing() / self.modulus),
        )
    }

    /// The work of adhesion `w`.
    pub fn work_of_adhesion(&self) -> f64 {
        self.work_of_adhesion
    }

    /// `(rows, cols)` of the grid.
    pub fn dim(&self) -> (usize, usize) {
        (self.operator.rows(), self.operator.cols())
    }

    /// The pixel side `Δx`.
    pub fn spacing(&self) -> f64 {
        self.operator.spacing()
    }

    /// The indentation of the current state.
    pub fn indentation(&self) -> f64 {
        self.indentation
    }

    /// The pressure of the current state (`rows × cols`; negative is tension).
    pub fn pressure(&self) -> Array2<f64> {
        Array2::from_shape_vec(self.dim(), self.pressure.clone()).expect("grid-sized")
    }

    /// The gap `u + f − d` of the current state (zero on the attached set).
    pub fn gap(&self) -> Array2<f64> {
        let d = self.indentation;
        let gap = (0..self.pressure.len())
            .map(|i| match self.attached[i] {
                true => 0.0,
                false => self.displacement[i] + self.profile[i] - d,
            })
            .collect();
        Array2::from_shape_vec(self.dim(), gap).expect("grid-sized")
    }

    /// Which pixels are attached.
    pub fn attached(&self) -> Array2<bool> {
        Array2::from_shape_vec(self.dim(), self.attached.clone()).expect("grid-sized")
    }

    /// The scalars of the current state.
    pub fn summary(&self) -> AdhesiveSummary {
        let dx = self.spacing();
        let n = self.pressure.len();
        let force = crate::sum::sum4(n, |i| self.pressure[i]) * dx * dx;
        let attached_points = self.attached.iter().filter(|&&a| a).count();
        let cohesive_points = (0..n)
            .filter(|&i| !self.attached[i] && self.pressure[i] < 0.0)
            .count();
        AdhesiveSummary {
            indentation: self.indentation,
            force,
            mean_pressure: force / (n as f64 * dx * dx),
            attached_points,
            area_fraction: attached_points as f64 / n as f64,
            tensile_points: self.pressure.iter().filter(|&&p| p < 0.0).count(),
            cohesive_points,
        }
    }

    /// Detaches every pixel and unloads the surface at indentation `d` (under the
    /// cohesive laws the next move settles the tensions of the free pixels).
    pub fn separate(&mut self, d: f64) {
        self.attached.fill(false);
        self.pressure.fill(0.0);
        self.displacement.fill(0.0);
        self.indentation = d;
    }

    /// Moves the indenter to `d` (finite) from the current state and lets the contact
    /// settle (module docs of [`super`]); the settled scalars and how they were reached.
    pub fn move_to(&mut self, d: f64) -> Result<(AdhesiveSummary, AdhesionInfo), SolveError> {
        if !d.is_finite() {
            return Err(Error::invalid(
                "indentation",
                format!("must be finite, got {}", crate::input::short_number(d)),
            )
            .into());
        }
        self.indentation = d;
        self.released_here.fill(false);
        let mut info = AdhesionInfo::default();
        loop {
            if info.rounds >= self.params.max_rounds {
                return Err(SolveError::NoConvergence {
                    iterations: info.rounds,
                    residual: f64::INFINITY,
                });
            }
            self.equilibrium(&mut info)?;
            let (attached, released) = self.update_sets();
            info.attached += attached;
            info.released += released;
            if attached + released == 0 {
                return Ok((self.summary(), info));
            }
            if self.boundary() == Boundary::Periodic && self.attached.iter().all(|&a| a) {
                return Err(SolveError::BeyondFullContact {
                    requested: Control::Indentation(d),
                    full_contact: None,
                });
            }
        }
    }

    fn boundary(&self) -> Boundary {
        HalfSpaceOperator::boundary(&self.operator)
    }

    /// The pressure on the attached set that holds its gap at zero, by the CG on the set
    /// for the correction to the present pressure; `u = K p` after it.
    fn equilibrium(&mut self, info: &mut AdhesionInfo) -> Result<(), SolveError> {
        info.rounds += 1;
        let d = self.indentation;
        self.operator.apply(&self.pressure, &mut self.displacement);
        info.operator_applications += 1;
        let mut residual = 0.0;
        for i in 0..self.rhs.len() {
            self.rhs[i] = 0.0;
            if self.attached[i] {
                self.rhs[i] = d - self.profile[i] - self.displacement[i];
                residual += self.rhs[i] * self.rhs[i];
            }
        }
        let scale = self.set_scale(d);
        let target = self.params.tolerance * scale;
        if residual.sqrt() <= target {
            return Ok(());
        }
        let params = CgParams {
            tolerance: target / residual.sqrt(),
            energy_error: None,
            max_iterations: self.params.max_iterations,
        };
        let attached = &self.attached;
        let cg = conjugate_gradient_on_set(
            &mut self.operator,
            &mut self.preconditioner,
            |i| attached[i],
            RightHandSide::Values(&self.rhs),
            &mut self.cg,
            (&params, &self.stop),
        )?;
        info.cg_iterations += cg.iterations;
        info.operator_applications += cg.iterations + 1;
        for (p, x) in self.pressure.iter_mut().zip(&self.cg.x) {
            *p += x;
        }
        self.operator.apply(&self.pressure, &mut self.displacement);
        Ok(())
    }

    /// The size of the linear problem's right-hand side on the attached set: the larger
    /// of `‖(d − f)_S‖` and `‖u_S‖` (the residual is measured against it).
    fn set_scale(&self, d: f64) -> f64 {
        let (mut prescribed, mut elastic) = (0.0, 0.0);
        for i in (0..self.attached.len()).filter(|&i| self.attached[i]) {
            prescribed += (d - self.profile[i]).powi(2);
            elastic += self.displacement[i].powi(2);
        }
        f64::max(prescribed, elastic).sqrt()
    }

    /// Releases the attached pixels whose tension exceeds `σ_c` and attaches the free ones
    /// the indenter penetrates (not those released at this indentation); returns the counts
    /// `(attached, released)`.
    fn update_sets(&mut self) -> (usize, usize) {
        match self.law {
            AdhesionLaw::MaugisDugdale { range } => return self.update_cohesive(range),
            AdhesionLaw::Exponential { range } => return self.update_exponential(range),
            AdhesionLaw::PixelCriterion => {}
        }
        let (d, sigma) = (self.indentation, self.critical_stress);
        let (mut attached, mut released) = (0, 0);
        for i in 0..self.pressure.len() {
            if self.attached[i] {
                if self.pressure[i] < -sigma {
                    self.attached[i] = false;
                    self.released_here[i] = true;
                    self.pressure[i] = 0.0;
                    released += 1;
                }
            } else if !self.released_here[i] && self.displacement[i] + self.profile[i] - d < 0.0 {
                self.attached[i] = true;
                attached += 1;
            }
        }
        (attached, released)
    }

    /// The Maugis–Dugdale update: an attached pixel in tension beyond `σ₀` lets go (and
    /// carries `−σ₀`), a free one the indenter penetrates attaches, and a free one carries
    /// `−σ₀` where its gap is within `range`, nothing beyond; returns `(attached, released)`
    /// with the free pixels whose traction changed counted as released.
    ///
    /// A free pixel is judged at the mean of its two states, with and without its own
    /// tension (the gap less or plus half the opening `κσ₀` it causes itself, `κ` the
    /// self-influence): judged in its present state it would keep the tension up to a
    /// range widened by that opening on retraction (a bias of order `Δx`, +12 % in the
    /// pull-off at λ = 1, `a_c/Δx` = 10). The zone grows first: pixels leave it only in a
    /// round where none enters, and a pixel that let go of the indenter or left the zone
    /// does not come back at this indentation (simultaneous swaps of neighbours could
    /// otherwise cycle; so each pixel changes at most four times per indentation).
    fn update_cohesive(&mut self, range: f64) -> (usize, usize) {
        let (d, sigma) = (self.indentation, self.critical_stress);
        let half_own = 0.5 * sigma * self.operator.self_influence();
        let (attached, let_go, entered) = self.sweep_laws(|pressure, released_here, gap| {
            let enters = !released_here && *pressure == 0.0 && gap - half_own <= range;
            if enters {
                *pressure = -sigma;
            }
            enters
        });
        if entered > 0 {
            return (attached, let_go + entered);
        }
        let mut released = let_go;
        for i in 0..self.pressure.len() {
            let gap = self.displacement[i] + self.profile[i] - d;
            if !self.attached[i] && self.pressure[i] < 0.0 && gap + half_own > range {
                self.pressure[i] = 0.0;
                self.released_here[i] = true;
                released += 1;
            }
        }
        (attached, released)
    }

    /// The exponential law's update: an attached pixel in tension beyond `σ_m = w/ρ` lets
    /// go (and carries `−σ_m`), a free one the indenter penetrates attaches (unless it let
    /// go at this indentation), and every other free one takes the tension
    /// `−σ_m e^{−g/ρ}` of its gap (zero beyond [`EXPONENTIAL_CUTOFF`]`·ρ`); returns
    /// `(attached, released)` with the free pixels whose tension moved by more than
    /// [`TENSION_TOLERANCE`]`·σ_m` counted as released (module docs of [`super`]).
    fn update_exponential(&mut self, range: f64) -> (usize, usize) {
        let sigma = self.critical_stress;
        let (attached, let_go, moved) = self.sweep_laws(|pressure, _, gap| {
            let opening = gap.max(0.0) / range;
            let tension = match opening < EXPONENTIAL_CUTOFF {
                true => -sigma * (-opening).exp(),
                false => 0.0,
            };
            let moves = (tension - *pressure).abs() > TENSION_TOLERANCE * sigma;
            *pressure = tension;
            moves
        });
        (attached, let_go + moved)
    }

    /// The sweep the cohesive laws share: an attached pixel in tension beyond `σ` lets go
    /// (and carries `−σ`), a free one the indenter penetrates attaches unless it let go at
    /// this indentation, and every other free pixel is handed to the law,
    /// `law(pressure, released_here, gap)`, which sets its tension and says whether it
    /// changed; returns the counts `(attached, let go, changed by the law)`.
    fn sweep_laws(
        &mut self,
        mut law: impl FnMut(&mut f64, bool, f64) -> bool,
    ) -> (usize, usize, usize) {
        let (d, sigma) = (self.indentation, self.critical_stress);
        let (mut attached, mut let_go, mut changed) = (0, 0, 0);
        for i in 0..self.pressure.len() {
            if self.attached[i] {
                if self.pressure[i] < -sigma {
                    self.attached[i] = false;
                    self.released_here[i] = true;
                    self.pressure[i] = -sigma;
                    let_go += 1;
                }
                continue;
            }
            let gap = self.displacement[i] + self.profile[i] - d;
            if gap < 0.0 && !self.released_here[i] {
                self.attached[i] = true;
                attached += 1;
            } else if law(&mut self.pressure[i], self.released_here[i], gap) {
                changed += 1;
            }
        }
        (attached, let_go, changed)
    }

    /// Retracts from the current state in steps of `step` (> 0) until no pixel is attached,
    /// calling `on_point` with each settled state and how it was reached (the step's rounds
    /// and CG iterations; the bisection's states are not reported); the two pull-offs (module docs of
    /// [`super`]), or `None` if nothing is attached to begin with. The contact is left
    /// separated at [`AdhesivePullOff::separated_at`].
    pub fn retract(
        &mut self,
        step: f64,
        mut on_point: impl FnMut(&AdhesiveSummary, &AdhesionInfo),
    ) -> Result<Option<AdhesivePullOff>, SolveError> {
        crate::positive_finite("retraction step", step, "")?;
        let mut last = self.summary();
        if last.attached_points == 0 {
            return Ok(None);
        }
        let mut least = last;
        let mut saved = Snapshot::of(self);
        loop {
            saved.take(self);
            let (state, info) = self.move_to(self.indentation - step)?;
            if state.attached_points == 0 {
                // A cohesive zone may still pull just after contact is lost.
                least = lesser(least, state);
                break;
            }
            on_point(&state, &info);
            least = lesser(least, state);
            last = state;
        }
        // Contact is lost between the last attached state and the first free one.
        let (mut attached_at, mut free_at) = (saved.indentation, self.indentation);
        for _ in 0..RETRACT_BISECTIONS {
            saved.restore(self);
            let (state, _) = self.move_to(0.5 * (attached_at + free_at))?;
            if state.attached_points == 0 {
                free_at = state.indentation;
            } else {
                attached_at = state.indentation;
                least = lesser(least, state);
                last = state;
                saved.take(self);
            }
        }
        self.separate(free_at);
        Ok(Some(AdhesivePullOff {
            force_controlled: least,
            displacement_controlled: last,
            separated_at: free_at,
        }))
    }
}

/// The state with the lesser force.
fn lesser(a: AdhesiveSummary, b: AdhesiveSummary) -> AdhesiveSummary {
    if b.force < a.force {
        b
    } else {
        a
    }
}

/// A copy of a state to return to (the retraction's bisection).
struct Snapshot {
    attached: Vec<bool>,
    pressure: Vec<f64>,
    indentation: f64,
}

impl Snapshot {
    fn of(contact: &PixelAdhesion) -> Self {
        Snapshot {
            attached: contact.attached.clone(),
            pressure: contact.pressure.clone(),
            indentation: contact.indentation,
        }
    }

    fn take(&mut self, contact: &PixelAdhesion) {
        self.attached.copy_from_slice(&contact.attached);
        self.pressure.copy_from_slice(&contact.pressure);
        self.indentation = contact.indentation;
    }

    fn restore(&self, contact: &mut PixelAdhesion) {
        contact.attached.copy_from_slice(&self.attached);
        contact.pressure.copy_from_slice(&self.pressure);
        contact.indentation = self.indentation;
    }
}
