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
//!
//! Units: `u` in the unit of lengths when `p` is in the unit of `E*`; displacement is
//! positive into the half-space (down), pressure positive in compression.

pub mod love;
pub mod operator;

pub use love::{love_pixel_displacement, rectangle_self_influence, self_influence};
pub use operator::{Boundary, ElasticOperator};
