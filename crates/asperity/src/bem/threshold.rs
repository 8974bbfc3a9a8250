//! Where a surface comes into full contact: the value ([`FullContactThreshold`], cached in
//! the solver's state) and the fields that compute it on periodic grids and bound it on
//! free ones (`FullContactScratch`). The computations are in `full_contact.rs` and, for
//! the free threshold's CGs, `stiffness/`.

use super::Control;

/// Where the gap closes everywhere: the mean pressure and the indentation, as
/// [`super::ContactSolver::full_contact_threshold`] computes them; or bounds below them
/// ([`super::ContactSolver::full_contact_lower_bound`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FullContactThreshold {
    /// Mean pressure over the nominal area.
    pub mean_pressure: f64,
    /// Indentation of the highest point: free boundaries `d* = max(K⁻¹f / K⁻¹1)`;
    /// periodic boundaries, with displacements of zero mean, `max(h) − mean(h)` (see
    /// [`Control::Indentation`]). `None` where unknown.
    pub indentation: Option<f64>,
}

impl FullContactThreshold {
    /// The threshold in the quantity `control` prescribes (mean pressure, force or
    /// indentation), where known; `nominal_area` converts a mean pressure to a force.
    pub fn in_units_of(&self, control: Control, nominal_area: f64) -> Option<f64> {
        match control {
            Control::MeanPressure(_) => Some(self.mean_pressure),
            Control::Force(_) => Some(self.mean_pressure * nominal_area),
            Control::Indentation(_) => self.indentation,
        }
    }
}

/// The fields of the periodic threshold (`K⁺f`) and of the lower bound (the weights `v`
/// and `K v`), owned by the solver and allocated on first use.
pub(super) struct FullContactScratch {
    pub(super) weights: Vec<f64>,
    pub(super) response: Vec<f64>,
}

impl FullContactScratch {
    /// The fields in `slot`, allocated there for `len` points on first use: the weights,
    /// and `K v` only if `response` (the lower bound of free boundaries: the periodic
    /// threshold never reads it, and memory not allocated needs no estimate,
    /// `ContactSolver::memory_bytes`).
    pub(super) fn lend(slot: &mut Option<Self>, len: usize, response: bool) -> &mut Self {
        let scratch = slot.get_or_insert_with(|| FullContactScratch {
            weights: vec![0.0; len],
            response: Vec::new(),
        });
        if response && scratch.response.len() != len {
            scratch.response = vec![0.0; len];
        }
        scratch
    }
}
