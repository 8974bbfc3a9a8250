//! Adhesive contact on the boundary elements: Pohrt & Popov's mesh-dependent detachment
//! criterion (Facta Univ. Mech. Eng. 13, 3, 2015), a Maugis–Dugdale cohesive zone or an
//! exponential potential ([`AdhesionLaw`]), with loading, unloading, hysteresis and both pull-offs
//! ([`PixelAdhesion`]).
//!
//! **The model.** A pixel of the half-space is either *attached* to the rigid indenter or
//! free. On the attached set `S` the gap is held at zero and the pressure may have either
//! sign (tension is adhesion); off it the pressure is zero. A free pixel attaches when the
//! indenter presses it (its gap `g = u + f − d` turns negative: adhesion of vanishing range
//! pulls nothing in from a distance); an attached pixel lets go when its tension exceeds
//! the critical stress of one pixel,
//!
//! `σ_c = √(E*w/(cΔx))`, `c = c̄/2 ≈ 0.4732`
//!
//! ([`crate::reference::adhesion::pixel_critical_stress`]: releasing a pixel under tension `σ` frees
//! the energy its own load stored, `½σΔx²·c̄σΔx/E*`, with `c̄` the pixel's mean
//! self-compliance, and that pays for the work of adhesion `wΔx²` of its area). A pixel that
//! let go stays free until pressed again: detachment is irreversible at a given approach,
//! and loading then unloading traces a loop (the approach follows the non-adhesive curve,
//! the retraction holds the contact as a punch, then peels it as a crack, JKR's curve for a
//! sphere).
//!
//! **Steps of the approach matter.** A pixel attaches when a step leaves it penetrated, so
//! a long step attaches the whole area the indenter passed through at once; its edge then
//! holds tension and may pull more pixels in (a jump into contact). Approached in small
//! steps the contact follows the non-adhesive one (each pixel attaches as it is touched,
//! under no load); the tests approach in ten steps. The retraction from a contact larger
//! than the pull-off's does not depend on it.
//!
//! **The iteration** (one indentation `d`, from the state of the previous one): solve the
//! linear problem `K_SS p_S = (d − f)_S` on the attached set (the one conjugate gradient on
//! a set of `stiffness/cg.rs`, Fourier-preconditioned, warm-started by solving for the
//! correction to the previous pressure); attach the free pixels with `g < 0`, release the
//! attached ones with `p < −σ_c` (none that let go at this `d` re-attaches at it); repeat
//! until nothing changes. A state that does not settle within
//! [`AdhesionParams::max_rounds`] is an error, never a result. The iteration is built on the
//! seams of the BEM core, [`crate::elastic::HalfSpaceOperator`] and the CG on a set; it is
//! not an [`super::Interface`] variant because its state remembers its history (which
//! pixels are attached), which no pointwise law of `(p, g)` can.
//!
//! **The Maugis–Dugdale cohesive zone** ([`AdhesionLaw::MaugisDugdale`], range `h₀`,
//! stress `σ₀ = w/h₀`): the same attached set and the same linear solve, but a free pixel
//! whose gap is within `h₀` carries the tension `σ₀` (a known load in the solve), and an
//! attached pixel lets go (keeping `−σ₀`) when its tension exceeds `σ₀`. The law is
//! reversible (no pixel is locked out across indentations; within one, a pixel that let go
//! does not come back, so the rounds end), and its energy is not convex: the attach/release
//! rounds follow the branch the path is on, and where it ends the state jumps (into
//! contact on approach, off it on retraction). A free pixel is judged at the mean of its
//! states with and without its own tension, which removes a bias of order `Δx` (the
//! pixel's own opening would widen the range). The zone must span pixels:
//! [`PixelAdhesion::cohesive_resolution`] (`E*h₀²/(c̄wΔx)`) is the range over the
//! opening one pixel's tension causes. Measured on Maugis's sphere (force-controlled
//! pull-off, `a_c/Δx` = 10, 20, 40): λ = 0.5 +2.4 %, +0.8 %, +0.2 %; λ = 1 +4.9 %, +1.8 %,
//! +0.6 %; λ = 2 +5.5 %, +3.2 %, +1.4 % (about order 1.5 in `Δx`).
//!
//! **The exponential potential** ([`AdhesionLaw::Exponential`], range `ρ`, greatest tension
//! `σ_m = w/ρ`): a free pixel at gap `g` carries `σ_m e^{−g/ρ}` (a known load in the
//! solve), an attached one lets go beyond `σ_m`. The tensions are a fixed point: each round
//! solves the attached set under the free pixels' tensions, then sets every free pixel's
//! tension from its new gap, until no pixel attaches or lets go and no tension moves by more
//! than [`TENSION_TOLERANCE`]`·σ_m`. The fixed point's map has the Jacobian `D·K` (`D` the
//! potential's stiffness `σ_m e^{−g/ρ}/ρ` on the free pixels, `K` the elastic compliance),
//! whose spectral radius is below 1 exactly where the state is stable under displacement
//! control (the energy's Hessian `K⁻¹ − D` is positive definite): the iteration converges
//! on every stable branch, slowly near its end, and leaves it where the branch ends (the
//! jumps into and out of contact). One pixel alone is stable only while its own stiffness
//! against the potential wins, `σ_m κ/ρ < 1` with `κ ≈ 1.12Δx/E*` its self-compliance:
//! the pixel must resolve the range, [`PixelAdhesion::cohesive_resolution`] above 1.
//!
//! **Retraction** ([`PixelAdhesion::retract`]): the indentation falls in steps until no
//! pixel is attached; the force-controlled pull-off is the least force met (beyond it no
//! state carries the force), the displacement-controlled one the last state before the
//! contact lets go completely, located by bisection on `d` between the last attached step
//! and the first free one (whose force counts for the least too: a cohesive zone may still
//! pull there).
//!
//! **Oracles** (tests in `tests.rs`): JKR's sphere (the contact radius against the force
//! on retraction and the pull-off `−(3/2)πwR`, converging as the pixel shrinks), Kendall's
//! flat punch `−√(8πwE*a³)`, Maugis's sphere across λ from DMT toward JKR
//! ([`crate::reference::MaugisDugdale`]), and the non-adhesive solver as `w → 0`. The criterion
//! converges at first order on a sphere (+6.9 % in the pull-off at `a_c/Δx = 20`, +3.9 % at
//! 40; docs/adhesion.md has the table and a reading of it).
//!
//! ```
//! use asperity::bem::adhesion::PixelAdhesion;
//! use asperity::bem::HalfSpace;
//! use asperity::surface::Surface;
//! use ndarray::Array2;
//!
//! // A sphere R = 1 on 40² pixels of 5 mm, E* = 1, w = 2e-4.
//! let (n, dx) = (40, 5e-3);
//! let heights = Array2::from_shape_fn((n, n), |(i, j)| {
//!     let (y, x) = ((i as f64 - 20.0) * dx, (j as f64 - 20.0) * dx);
//!     -(x * x + y * y) / 2.0
//! });
//! let surface = Surface::new(heights, n as f64 * dx)?;
//! let mut contact = PixelAdhesion::new(&surface, HalfSpace::default(), 2e-4)?;
//! for k in 1..=5 {
//!     contact.move_to(2e-3 * k as f64)?; // approach
//! }
//! let pull = contact.retract(5e-5, |_, _| {})?.expect("in contact");
//! let jkr = -1.5 * std::f64::consts::PI * 2e-4;
//! assert!(pull.force_controlled.force < 0.0);
//! assert!((pull.force_controlled.force / jkr - 1.0).abs() < 0.25); // a_c/Δx ≈ 18
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod pixel;
#[cfg(test)]
mod tests;

pub use pixel::PixelAdhesion;

/// The adhesive law between the indenter and the pixels of the half-space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AdhesionLaw {
    /// Pohrt & Popov's mesh-dependent criterion: adhesion of vanishing range; an attached
    /// pixel lets go when its tension exceeds `σ_c = √(E*w/(cΔx))`. Converges at first
    /// order in `Δx` to JKR.
    PixelCriterion,
    /// A Maugis–Dugdale cohesive zone of range `h₀` (`range`): a free pixel whose gap is at
    /// most `h₀` carries the constant tension `σ₀ = w/h₀`, one farther nothing, and an
    /// attached pixel lets go when its tension exceeds `σ₀`. Converges to Maugis's sphere
    /// ([`crate::reference::MaugisDugdale`]) once the cohesive zone spans pixels
    /// ([`PixelAdhesion::cohesive_resolution`]).
    MaugisDugdale {
        /// The range `h₀` of the Dugdale stress.
        range: f64,
    },
    /// The exponential potential of range `ρ` (`range`), as in Rey, Anciaux & Molinari
    /// (Comput. Mech. 60, 69, 2017) and the contact-mechanics challenge (Müser et al.,
    /// Tribol. Lett. 65, 118, 2017): a free pixel at gap `g` carries the tension
    /// `(w/ρ)e^{−g/ρ}`, an attached one (gap zero) lets go when its tension exceeds `w/ρ`.
    /// Its pixels' tensions are settled by a fixed point (type docs of [`PixelAdhesion`]'s
    /// module); the pixel must resolve the range ([`PixelAdhesion::cohesive_resolution`]).
    Exponential {
        /// The range `ρ` of the potential.
        range: f64,
    },
}

impl AdhesionLaw {
    /// The range of a cohesive law (`None` for the pixel criterion).
    pub fn range(&self) -> Option<f64> {
        match *self {
            AdhesionLaw::PixelCriterion => None,
            AdhesionLaw::MaugisDugdale { range } | AdhesionLaw::Exponential { range } => {
                Some(range)
            }
        }
    }

    /// The model's name in records: `pixel criterion`, `maugis-dugdale`, `exponential`.
    pub fn name(&self) -> &'static str {
        match self {
            AdhesionLaw::PixelCriterion => "pixel criterion",
            AdhesionLaw::MaugisDugdale { .. } => "maugis-dugdale",
            AdhesionLaw::Exponential { .. } => "exponential",
        }
    }
}

/// Relative change of a pixel's tension (over `w/ρ`) below which the exponential law's
/// fixed point counts as settled.
pub const TENSION_TOLERANCE: f64 = 1e-9;

/// Tensions of the exponential law below `e^{−CUTOFF}·w/ρ` (gaps beyond `CUTOFF·ρ`) are
/// left out: `e^{−36} ≈ 2·10⁻¹⁶`, under the rounding of the tension at contact.
pub const EXPONENTIAL_CUTOFF: f64 = 36.0;

/// How the adhesive iteration stops (documented defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdhesionParams {
    /// Relative residual of the linear solve on the attached set, measured against the
    /// prescribed displacement `(d − f)_S` (or the elastic one, if larger). Default `1e-10`.
    pub tolerance: f64,
    /// Rounds of attach/release at one indentation before the state is declared unsettled
    /// ([`super::SolveError::NoConvergence`]). Default `10_000`.
    pub max_rounds: usize,
    /// Iterations of one conjugate gradient before it is declared not converged. Default
    /// `10_000`.
    pub max_iterations: usize,
}

impl Default for AdhesionParams {
    fn default() -> Self {
        AdhesionParams {
            tolerance: 1e-10,
            max_rounds: 10_000,
            max_iterations: 10_000,
        }
    }
}

impl AdhesionParams {
    /// Checks the parameters: a tolerance positive and finite (below 1), limits at least 1.
    pub fn validate(&self) -> crate::Result<()> {
        crate::positive_finite("tolerance", self.tolerance, "")?;
        if self.tolerance >= 1.0 {
            return Err(crate::Error::invalid(
                "tolerance",
                format!(
                    "must be below 1, got {}",
                    crate::input::short_number(self.tolerance)
                ),
            ));
        }
        for (name, v) in [
            ("max rounds", self.max_rounds),
            ("max iterations", self.max_iterations),
        ] {
            if v == 0 {
                return Err(crate::Error::invalid(name, "must be at least 1, got 0"));
            }
        }
        Ok(())
    }
}

/// The scalars of a settled adhesive state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdhesiveSummary {
    /// The indentation `d` (negative once the indenter is pulled back beyond first touch).
    pub indentation: f64,
    /// Total force `Σ p ΔxΔy`, negative where tension wins.
    pub force: f64,
    /// Mean pressure over the nominal area.
    pub mean_pressure: f64,
    /// Pixels attached (the contact area in pixels, tensile ones included).
    pub attached_points: usize,
    /// Attached pixels over all pixels.
    pub area_fraction: f64,
    /// Pixels in tension (`p < 0`): attached ones, and free ones in a cohesive zone.
    pub tensile_points: usize,
    /// Free pixels that carry a cohesive tension (Maugis–Dugdale, exponential; 0 under the
    /// pixel criterion).
    pub cohesive_points: usize,
}

/// How a settled state was reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AdhesionInfo {
    /// Linear solves (rounds of attach/release), one at least.
    pub rounds: usize,
    /// Pixels that attached.
    pub attached: usize,
    /// Pixels that let go.
    pub released: usize,
    /// Conjugate-gradient iterations over all rounds.
    pub cg_iterations: usize,
    /// Applications of the elastic operator, those of the CGs included.
    pub operator_applications: usize,
}

/// The two pull-offs of a retraction ([`PixelAdhesion::retract`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdhesivePullOff {
    /// The state of least force met on the retraction (force control loses contact there).
    pub force_controlled: AdhesiveSummary,
    /// The last state with a pixel attached (displacement control loses contact there),
    /// located by bisection to [`RETRACT_BISECTIONS`] halvings of the step.
    pub displacement_controlled: AdhesiveSummary,
    /// The first indentation at which no pixel is attached.
    pub separated_at: f64,
}

/// Halvings of the last retraction step that locate the displacement-controlled pull-off.
pub const RETRACT_BISECTIONS: usize = 20;
