//! The method of dimensionality reduction (MDR): rough lines and axisymmetric indenters on
//! a Winkler foundation of independent springs (paper *Methods*, "1D MDR calculation";
//! Popov & Heß ch. 15; SCIENCE.md §3).
//!
//! * [`spring`]: the spring laws — linear (`E*·Δx`), the **Hertz microscale law (15.2)**
//!   and the **fractal microscale law (15.7)** with its critical depth (15.6); the
//!   asymptote (15.3).
//! * [`indenter`]: axisymmetric indenters mapped to 1D by the MDR transform
//!   `g(x) = |x| ∫₀^|x| f'(r)/sqrt(x²−r²) dr` — sphere (15.1), cone, flat punch, power
//!   laws, and sampled user profiles (numerical transform, singularity integrated exactly).
//! * [`foundation`]: exact force, stiffness and contact count at given indentations for
//!   any law (indentation measured from the first contact point — for a rough line, its
//!   highest point).
//! * [`linear_curve`]: the whole curve of a line on linear springs in `O(N log N)`, with a
//!   reusable buffer for ensembles of thousands of lines.
//! * [`adhesion`]: Heß's rule — springs that stick once touched and let go from the
//!   edges of a contact at `√(2πaΔγ/E*)`: JKR for a sphere, Kendall for a punch, loading–
//!   unloading loops and pull-off under force and displacement control.
//! * [`radix_sort`]: the `O(N)` descending sort of doubles behind [`LinearCurve`].
//! * [`tangential`]: tangential springs beside the normal ones — Mindlin's no-slip
//!   stiffness, partial slip under `Q ≤ μF` (Ciavarella–Jäger) and the hysteresis cycle
//!   ([`PartialSlip`]).
//!
//! The low-force exponent α of `k ∝ F^α` (3) of an ensemble of lines is the study's
//! ([`crate::study::curve`]: one fit window and estimator for MDR and BEM alike).
//!
//! # Example
//! ```
//! use asperity::mdr::{Axisymmetric, Foundation, Spring, SpringLaw};
//! use asperity::reference::Hertz;
//! let (radius, dx) = (1.0, 1e-3);
//! let profile = Axisymmetric::Sphere { radius }.sample(4001, dx)?;
//! let spring = Spring::new(SpringLaw::Hertz { radius }, dx, 1.0)?;
//! let foundation = Foundation::from_profile(&profile, spring)?;
//! let d = 0.25; // a = 500 Δx
//! let point = foundation.evaluate(d);
//! let hertz = Hertz { radius, modulus: 1.0 };
//! assert!((point.force / hertz.force(d) - 1.0).abs() < 5e-3);
//! assert!((point.stiffness / hertz.stiffness(d) - 1.0).abs() < 5e-3);
//! # Ok::<(), asperity::Error>(())
//! ```

pub mod adhesion;
pub mod foundation;
pub mod indenter;
pub mod linear_curve;
pub mod radix_sort;
pub mod spring;
pub mod tangential;

pub use adhesion::{AdhesiveLine, PullOffs};
pub use foundation::{log_spaced, CurvePoint, Foundation};
pub use indenter::{spring_positions, Axisymmetric, RadialProfile, PUNCH_EDGE_TOLERANCE};
pub use linear_curve::LinearCurve;
pub use spring::{fractal_asymptote, Spring, SpringLaw, FRACTAL_CONSTANT};
pub use tangential::{
    check_friction, check_poisson, mindlin_ratio, Branch, LoopPoint, PartialSlip,
};
