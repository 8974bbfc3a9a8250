//! Contact conductance from the contact stiffness by Barber's analogy.
//!
//! The conductance of the contact spots between two half-spaces obeys the same equations as
//! their normal contact stiffness (Barber, Proc. R. Soc. A 459, 53 (2003)): the potential
//! (or temperature) is harmonic in each body, uniform on the contact spots and insulated
//! elsewhere on the surface, as the normal displacement of the elastic problem is. Hence
//!
//! * electrical: `C = 2k / (E*·(ρ₁ + ρ₂))`, resistivities `ρ` in Ω·m;
//! * thermal: `C = (2k / E*)·κ₁κ₂/(κ₁ + κ₂)`, conductivities `κ` in W/(m·K),
//!
//! with `k` the (frozen-set) normal stiffness and `E*` the effective modulus of the same
//! solve. One circular spot of radius `a` (`k = 2E*a`) gives Holm's constriction conductance
//! `C = 4a/(ρ₁ + ρ₂)`, `2a/ρ` for two equal bodies. The analogy neglects what is not in the
//! elastic problem: interface films, the gap's own conduction (gas, radiation) and the
//! bodies' finite size; the stiffness's discretisation error (about `Δx/a` per spot) is
//! passed on unchanged.
//!
//! # Example
//! ```
//! use asperity::bem::conductance::Transport;
//! // Holm: one spot of radius a = 1e-5 m between two copper bodies, k = 2E*a.
//! let (a, modulus, rho) = (1e-5, 70e9, 1.7e-8);
//! let transport = Transport::new(Some([rho, rho]), None)?;
//! let c = transport.electrical(2.0 * modulus * a, modulus).unwrap();
//! assert!((c / (2.0 * a / rho) - 1.0).abs() < 1e-15);
//! # Ok::<(), asperity::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// The two bodies' resistivities and thermal conductivities, either or both, validated.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Transport {
    /// Electrical resistivities of body 1 and body 2, Ω·m.
    pub resistivity: Option<[f64; 2]>,
    /// Thermal conductivities of body 1 and body 2, W/(m·K).
    pub thermal_conductivity: Option<[f64; 2]>,
}

fn check_pair(name: &'static str, what: &str, pair: Option<[f64; 2]>) -> Result<()> {
    for value in pair.into_iter().flatten() {
        if !crate::is_positive_finite(value) {
            return Err(Error::invalid(
                name,
                format!(
                    "each body's {what} must be positive and finite, got {}",
                    crate::input::short_number(value)
                ),
            ));
        }
    }
    Ok(())
}

impl Transport {
    /// Refuses a resistivity or conductivity that is not positive and finite.
    pub fn new(
        resistivity: Option<[f64; 2]>,
        thermal_conductivity: Option<[f64; 2]>,
    ) -> Result<Self> {
        check_pair("resistivity", "resistivity", resistivity)?;
        check_pair(
            "thermal_conductivity",
            "thermal conductivity",
            thermal_conductivity,
        )?;
        Ok(Transport {
            resistivity,
            thermal_conductivity,
        })
    }

    /// Electrical conductance `2k/(E*(ρ₁+ρ₂))` (S, for `k` in N/m, `E*` in Pa), if
    /// resistivities are given.
    pub fn electrical(&self, stiffness: f64, modulus: f64) -> Option<f64> {
        self.resistivity
            .map(|[a, b]| 2.0 * stiffness / (modulus * (a + b)))
    }

    /// Thermal conductance `(2k/E*)·κ₁κ₂/(κ₁+κ₂)` (W/K), if conductivities are given.
    pub fn thermal(&self, stiffness: f64, modulus: f64) -> Option<f64> {
        self.thermal_conductivity
            .map(|[a, b]| 2.0 * stiffness / modulus * (a * b / (a + b)))
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use ndarray::Array2;

    use super::*;
    use crate::bem::{Boundary, ContactSolver, Control, HalfSpace, SolverParams};
    use crate::surface::Surface;

    #[test]
    fn one_circular_spot_gives_holms_conductance() {
        // A flat circular punch of 16 pixels' radius on a BEM grid (free boundaries): the
        // frozen-set stiffness is 2E*a within its discretisation error (0.65 % measured in
        // stiffness.rs), and so is C against Holm's 2a/ρ and 2aκ (two equal bodies); 1 %.
        let (n, a_pixels, size) = (64, 16.0, 1e-3);
        let dx = size / n as f64;
        let heights = Array2::from_shape_fn((n, n), |(i, j)| {
            let r = (i as f64 - (n / 2) as f64).hypot(j as f64 - (n / 2) as f64) * dx;
            if r <= a_pixels * dx {
                0.0
            } else {
                -1e-3
            }
        });
        let surface = Surface::new(heights, size).unwrap();
        let modulus = 100e9;
        let half_space = HalfSpace {
            modulus,
            boundary: Boundary::Free,
        };
        let params = SolverParams {
            tolerance: 1e-11,
            ..SolverParams::default()
        };
        let mut solver = ContactSolver::new(&surface, half_space, params).unwrap();
        let (state, _) = solver.solve(Control::Indentation(1e-9)).unwrap();
        let (k, _) = solver.frozen_set_stiffness().unwrap();
        let a = (state.contact_points as f64 * dx * dx / PI).sqrt();
        let (rho, kappa) = (1.7e-8, 400.0);
        let transport = Transport::new(Some([rho, rho]), Some([kappa, kappa])).unwrap();
        let electrical = transport.electrical(k, modulus).unwrap() / (2.0 * a / rho);
        let thermal = transport.thermal(k, modulus).unwrap() / (2.0 * a * kappa);
        eprintln!("Holm, a = 16 px: electrical {electrical:.5}, thermal {thermal:.5}");
        assert!((electrical - 1.0).abs() < 0.01 && (thermal - 1.0).abs() < 0.01);
        // Unequal bodies: the series sum of the two bodies' constriction resistances.
        let two = Transport::new(Some([1.0, 3.0]), Some([1.0, 3.0])).unwrap();
        let one = Transport::new(Some([2.0, 2.0]), Some([1.5, 1.5])).unwrap();
        assert_eq!(two.electrical(k, modulus), one.electrical(k, modulus));
        assert!(
            (two.thermal(k, modulus).unwrap() / one.thermal(k, modulus).unwrap() - 1.0).abs()
                < 1e-15
        );
    }

    #[test]
    fn bad_properties_are_refused_in_one_line() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = Transport::new(Some([1.0, bad]), None)
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with(
                    "invalid resistivity: each body's resistivity must be positive and finite, got"
                ),
                "{err}"
            );
            let err = Transport::new(None, Some([bad, 1.0]))
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with("invalid thermal_conductivity: each body's thermal conductivity"),
                "{err}"
            );
        }
        assert_eq!(
            Transport::new(None, None).unwrap().electrical(1.0, 1.0),
            None
        );
    }
}
