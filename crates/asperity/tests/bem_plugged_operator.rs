//! A body's operator plugged into the contact solver from outside the crate
//! ([`ContactSolver::with_operator`] over a user's [`ContactOperator`]): the solver runs on
//! it, and on an operator that gives the half-space's responses it gives the built-in
//! solver's results bit for bit (issue 31: a different kernel — layered, anisotropic, on a
//! device — plugs in without an edit of the solver).

use asperity::bem::{ContactSolver, Control, HalfSpace, Interface, SolverKind, SolverParams};
use asperity::elastic::{Boundary, ContactOperator, ElasticOperator, HalfSpaceOperator};
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, Surface, SurfaceGenerator, SurfaceSpec};

/// A user's body: the homogeneous half-space's operator behind a type of its own that
/// counts its applications (what a layered kernel would compute instead).
struct Counting {
    inner: ElasticOperator,
    applications: usize,
}

impl HalfSpaceOperator for Counting {
    fn rows(&self) -> usize {
        self.inner.rows()
    }

    fn cols(&self) -> usize {
        self.inner.cols()
    }

    fn spacings(&self) -> (f64, f64) {
        HalfSpaceOperator::spacings(&self.inner)
    }

    fn boundary(&self) -> Boundary {
        self.inner.boundary()
    }

    fn self_influence(&self) -> f64 {
        self.inner.self_influence()
    }

    fn apply(&mut self, load: &[f64], displacement: &mut [f64]) {
        self.applications += 1;
        self.inner.apply(load, displacement);
    }

    fn energy(&mut self, load: &[f64]) -> f64 {
        self.inner.energy(load)
    }
}

impl ContactOperator for Counting {
    type Single = ElasticOperator<f32>;

    fn single_precision(&self) -> asperity::Result<ElasticOperator<f32>> {
        self.inner.single_precision()
    }

    fn modulus(&self) -> f64 {
        self.inner.modulus()
    }

    fn apply_pseudo_inverse(&mut self, u: &[f64], p: &mut [f64]) -> asperity::Result<()> {
        self.inner.apply_pseudo_inverse(u, p)
    }
}

fn rough(n: usize) -> Surface {
    let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 4.0 }, None).unwrap();
    let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(0.5)).unwrap();
    SurfaceGenerator::new(&spec).unwrap().generate(3)
}

#[test]
fn a_plugged_operator_gives_the_built_in_results_bit_for_bit() {
    let surface = rough(64);
    for boundary in [Boundary::Free, Boundary::Periodic] {
        for solver in [SolverKind::Bccg, SolverKind::PolonskyKeer] {
            for interface in [Interface::HardWall, Interface::hardness(0.3).unwrap()] {
                let params = SolverParams {
                    solver,
                    ..SolverParams::default()
                };
                let half_space = HalfSpace {
                    modulus: 1.3,
                    boundary,
                };
                let operator = Counting {
                    inner: ElasticOperator::new(64, 64, surface.spacing(), 1.3, boundary).unwrap(),
                    applications: 0,
                };
                let mut plugged = ContactSolver::with_operator(&surface, operator, params)
                    .unwrap()
                    .with_interface(interface)
                    .unwrap();
                let mut built_in = ContactSolver::new(&surface, half_space, params)
                    .unwrap()
                    .with_interface(interface)
                    .unwrap();
                let case = format!("{boundary:?} {solver:?} {interface:?}");
                // Load control, warm load control, then displacement control at the
                // solved indentation; with the frozen-set stiffness between (its tangent
                // predicts the next start).
                let mut controls = vec![Control::MeanPressure(0.02), Control::MeanPressure(0.05)];
                for control in controls.drain(..) {
                    let a = plugged.solve(control).unwrap();
                    let b = built_in.solve(control).unwrap();
                    assert_eq!(a, b, "{case} {control:?}");
                    assert_eq!(plugged.pressure(), built_in.pressure(), "{case}");
                    assert_eq!(plugged.gap(), built_in.gap(), "{case}");
                    let k = plugged.frozen_set_stiffness().unwrap();
                    assert_eq!(k, built_in.frozen_set_stiffness().unwrap(), "{case}");
                }
                let d = Control::Indentation(built_in.summary().unwrap().indentation);
                assert_eq!(
                    plugged.solve(d).unwrap(),
                    built_in.solve(d).unwrap(),
                    "{case}"
                );
                assert_eq!(plugged.state(), built_in.state(), "{case}");
                assert!(plugged.problem().operator().applications > 0, "{case}");
            }
        }
    }
}
