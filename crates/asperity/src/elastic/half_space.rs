//! [`HalfSpaceOperator`]: what the contact iterations and the conjugate gradient on a set
//! need of an elastic body — a linear, symmetric positive (semi-)definite map from a load
//! field on a `rows × cols` grid of pixels to the displacement field it causes.
//!
//! [`ElasticOperator`] (the normal response of a homogeneous half-space, free or periodic
//! boundaries) is the one implementation today. Another kernel plugs in by implementing the
//! trait: a tangential (Cerruti) operator for the shear response, a layered body, a device
//! operator that keeps its fields on an accelerator. The contract:
//!
//! * [`HalfSpaceOperator::apply`] writes `K load` into `displacement` (both `rows · cols`
//!   values, row-major), allocates nothing and does not depend on the thread count (the
//!   operator owns whatever scratch it needs: it takes `&mut self`);
//! * `K` is symmetric and positive definite on every proper subset of the grid (periodic
//!   operators may be only semi-definite on the whole grid), so conjugate gradients apply
//!   to its restriction to a set (`crate::bem`'s CG on a set);
//! * [`HalfSpaceOperator::self_influence`] is the diagonal of `K` (the displacement of a
//!   pixel per unit load on it), [`HalfSpaceOperator::energy`] is `loadᵀ K load`.

use super::operator::{Boundary, ElasticOperator};
use crate::fft::Precision;
use crate::Result;

/// A linear elastic response on a grid of pixels (module docs).
pub trait HalfSpaceOperator {
    /// Rows of the grid.
    fn rows(&self) -> usize;

    /// Columns of the grid.
    fn cols(&self) -> usize;

    /// Points of the grid, `rows · cols`.
    fn len(&self) -> usize {
        self.rows() * self.cols()
    }

    /// Whether the grid is empty (never for a constructed operator).
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Pixel sides `(Δx, Δy)`: along the columns and along the rows.
    fn spacings(&self) -> (f64, f64);

    /// The boundary conditions of the grid (free: isolated, zero-padded; periodic).
    fn boundary(&self) -> Boundary;

    /// The diagonal of `K`: the displacement of a pixel per unit load on it.
    fn self_influence(&self) -> f64;

    /// `displacement ← K load` (row-major `rows × cols` fields); no allocation.
    fn apply(&mut self, load: &[f64], displacement: &mut [f64]);

    /// `loadᵀ K load` (per unit pixel area), in a fixed order of summation.
    fn energy(&mut self, load: &[f64]) -> f64;
}

impl<T: Precision> HalfSpaceOperator for ElasticOperator<T> {
    fn rows(&self) -> usize {
        ElasticOperator::rows(self)
    }

    fn cols(&self) -> usize {
        ElasticOperator::cols(self)
    }

    fn spacings(&self) -> (f64, f64) {
        (self.spacing(), self.spacing_y())
    }

    fn boundary(&self) -> Boundary {
        ElasticOperator::boundary(self)
    }

    fn self_influence(&self) -> f64 {
        ElasticOperator::self_influence(self)
    }

    fn apply(&mut self, load: &[f64], displacement: &mut [f64]) {
        ElasticOperator::apply(self, load, displacement);
    }

    fn energy(&mut self, load: &[f64]) -> f64 {
        ElasticOperator::energy(self, load)
    }
}

/// What the contact solver ([`crate::bem::ContactSolver`]: its iterations, BCCG and
/// Polonsky–Keer, and its services) needs of an elastic body beyond [`HalfSpaceOperator`].
/// The solver is generic over it and monomorphised: a body of another kernel (a layered or
/// anisotropic half-space) plugs in by implementing both traits and
/// [`crate::bem::ContactSolver::with_operator`], with no dynamic dispatch in the iterations.
///
/// The contract, beyond [`HalfSpaceOperator`]'s: `K` is translation invariant (the
/// displacement at `i` of a unit load at `j` depends on `i − j` alone, periodically
/// wrapped on periodic grids), so that its impulse response (`K e₀`, which the BCCG takes
/// once through [`HalfSpaceOperator::apply`]) describes it — the BCCG's corrections of cut
/// pressures and its direct solve of small sets read `K` from there.
pub trait ContactOperator: HalfSpaceOperator + Send {
    /// The operator the BCCG applies where single precision cannot change its iterates
    /// (`bem/iterations/bccg.rs`); the operator itself where there is no cheaper one.
    type Single: HalfSpaceOperator + Send;

    /// The single-precision copy (errors: memory).
    fn single_precision(&self) -> Result<Self::Single>;

    /// The effective modulus `E*` of the Fourier preconditioner's symbol `E*|q|/2` (an
    /// approximate inverse of `K`) and of the curvature of the periodic constant mode;
    /// for a kernel other than the homogeneous half-space's, the modulus whose symbol is
    /// closest to its own.
    fn modulus(&self) -> f64;

    /// Periodic boundaries: `load ← K⁺ displacement`, the zero-mean load whose
    /// displacement is `displacement` up to a constant (the periodic full-contact
    /// threshold, `bem/full_contact.rs`); an error on free boundaries.
    fn apply_pseudo_inverse(&mut self, displacement: &[f64], load: &mut [f64]) -> Result<()>;
}

impl ContactOperator for ElasticOperator {
    type Single = ElasticOperator<f32>;

    fn single_precision(&self) -> Result<ElasticOperator<f32>> {
        ElasticOperator::single_precision(self)
    }

    fn modulus(&self) -> f64 {
        ElasticOperator::modulus(self)
    }

    fn apply_pseudo_inverse(&mut self, displacement: &[f64], load: &mut [f64]) -> Result<()> {
        ElasticOperator::apply_pseudo_inverse(self, displacement, load)
    }
}
