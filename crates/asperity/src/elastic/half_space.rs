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
