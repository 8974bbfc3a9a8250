//! The fields of the frozen-set and full-contact CGs ([`StiffnessWork`]), owned by the
//! solver; the computations that use them are in `stiffness/mod.rs`.

use super::cg::CgWork;
use crate::elastic::HalfSpaceOperator;

/// The fields of the stiffness and full-contact CGs, owned by the solver and allocated on
/// first use: never the solved state's.
pub(in crate::bem) struct StiffnessWork {
    /// The CG's fields; its unknown `cg.x` holds the pressures on the set.
    pub(in crate::bem) cg: CgWork,
    /// `K⁻¹f` of the full-contact threshold of free boundaries (empty on periodic grids,
    /// whose threshold is spectral, `full_contact.rs`).
    pub(in crate::bem) profile_pressure: Vec<f64>,
    /// Whether `cg.x` is the frozen-set solution `K_SS⁻¹ 1_S` of the solved state (the
    /// tangent `dp/dd` of its pressure), not yet used by a solve.
    pub(in crate::bem) tangent: bool,
}

impl StiffnessWork {
    /// The fields for the grid of `operator`, with the rings around the set (as in the
    /// BCCG, `ring_extension.rs`) if `rings`.
    pub(in crate::bem) fn new(operator: &impl HalfSpaceOperator, rings: bool) -> Self {
        let len = operator.rows() * operator.cols();
        let free = operator.boundary() == crate::elastic::Boundary::Free;
        StiffnessWork {
            cg: CgWork::for_operator(operator, rings),
            profile_pressure: vec![0.0; if free { len } else { 0 }],
            tangent: false,
        }
    }
}
