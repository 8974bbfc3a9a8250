//! The elastic half-space: surface displacement caused by a pressure field on a grid.
//!
//! * [`love`]: Love's closed form for the displacement caused by a **uniform pressure on a
//!   rectangular pixel** (Love 1929; Johnson, *Contact Mechanics*, eq. 3.25). For a square
//!   pixel of side Δ its value at the pixel's own centre, the self-influence, is
//!   `4 ln(1+√2)/π · pΔ/E*` (the paper, *Methods*, "BEM calculations").
//! * [`operator`]: [`ElasticOperator`], the convolution `u = K * p` over the whole grid by
//!   real FFTs, with **free** boundaries (the grid zero-padded to `2N × 2M`, no periodic
//!   images; Hockney 1970) or **periodic** boundaries. Plans, the kernel's spectrum and all
//!   buffers are made once; [`ElasticOperator::apply`] allocates nothing.
//! * [`half_space`]: [`HalfSpaceOperator`], what the contact solvers need of an elastic
//!   body (apply, self-influence, energy, the grid), which [`ElasticOperator`] implements:
//!   the place where another kernel (tangential, layered, on a device) plugs in.
//!
//! * [`cerruti`]: Cerruti's closed form for the **tangential** displacement caused by a
//!   uniform tangential traction on a rectangular pixel, along the traction (the kernel of
//!   the tangential stiffness; normal–tangential coupling neglected), and its periodic
//!   spectrum.
//!
//! Units: `u` in the unit of lengths when `p` is in the unit of `E*`; displacement is
//! positive into the half-space (down), pressure positive in compression.

pub mod cerruti;
pub mod half_space;
pub mod love;
pub mod operator;

pub use cerruti::{cerruti_pixel_displacement, cerruti_spectrum, Direction};
pub use half_space::{ContactOperator, HalfSpaceOperator};
pub use love::{love_pixel_displacement, rectangle_self_influence, self_influence};
pub use operator::{Boundary, ElasticOperator, Kernel};
