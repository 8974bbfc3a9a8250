//! The preconditioners of the BEM's conjugate gradients, `M ≈ K⁻¹` behind one trait,
//! [`Preconditioner`]: the Fourier preconditioner (`fourier.rs`, the inverse of the
//! periodic kernel's symbol on the unpadded grid, Vollebregt 2014) and the rings
//! (`ring_extension.rs`), a decorator that extends a preconditioned field on a set over two
//! rings of the points around it, and (an experiment, off by default) the multilevel
//! extension `pyramid.rs` that the rings can carry beyond them or in their place. The BCCG
//! (`iterations/bccg.rs`), the frozen-set CG (`stiffness/`) and the tangential CG
//! (`tangential.rs`) use both.

mod fourier;
mod pyramid;
mod ring_extension;

pub(super) use fourier::{FourierPreconditioner, Preconditioner, Real};
pub(super) use ring_extension::{RingExtension, Ringed};
