//! Elastic–perfectly-plastic contact: the pressure capped at a hardness `H`
//! ([`Interface::Hardness`]), the plastic displacement it leaves, and a load path that
//! keeps it (loading, unloading, reloading: hysteresis).
//!
//! Under a cap the solved state has three sets: out of contact (`p = 0`, `g ≥ 0`), elastic
//! (`0 < p < H`, `g = 0`) and plastic (`p = H`, `g ≤ 0`). On the plastic set the rigid
//! indenter has pushed into the surface by `−g ≥ 0` more than the elastic half-space
//! accommodates: that is the **plastic displacement** ([`ContactSolver::plastic_displacement`]).
//! A solve alone leaves the surface as it was (solving twice gives the same answer);
//! [`ContactSolver::keep_plastic_displacement`] makes it permanent (the profile `f` becomes
//! `f + w`, the surface flattened where it yielded), which is what a load path does after
//! each step ([`load_path`]): unloading from there is elastic on the flattened surface
//! until it separates, reloading is elastic up to the largest load reached before, and only
//! beyond it does the surface yield again.
//!
//! **Stiffness**: the frozen-set stiffness is taken on the *elastic* set `0 < p < H`. A
//! small extra approach `Δd` raises the pressure where the surface is elastic; where it is
//! at the hardness the pressure cannot rise (perfect plasticity), so those points carry
//! no extra load and are left out of the set: `k` is the loading tangent `dF/dd`, which the
//! finite-difference stiffness confirms (a test below). On unloading the plastic points
//! unload elastically; after [`ContactSolver::keep_plastic_displacement`] they are at
//! `g = 0` and, once the load drops, below the cap, so the unloading stiffness is that of
//! the whole contact set.
//!
//! The peers: ContactMechanics (`PlasticSystem`, `hardness=` on its Polonsky–Keer) and
//! tamaas (`KatoSaturated`) solve the same problem.

use crate::elastic::ContactOperator;
use ndarray::Array2;

use super::interface::Interface;
use super::solver::ContactSolver;
use super::{ContactSummary, Control, SolveError};

impl<K: ContactOperator> ContactSolver<K> {
    /// Solves with `interface` from now on (validated; the hard wall by default). The
    /// next solve starts cold; a kept plastic displacement stays.
    pub fn set_interface(&mut self, interface: Interface) -> Result<(), SolveError> {
        interface.validate()?;
        self.cx.interface = interface;
        self.reset();
        Ok(())
    }

    /// The solver with `interface` (builder form of [`ContactSolver::set_interface`]).
    pub fn with_interface(mut self, interface: Interface) -> Result<Self, SolveError> {
        self.set_interface(interface)?;
        Ok(self)
    }

    /// The interface in use.
    pub fn interface(&self) -> Interface {
        self.cx.interface
    }

    /// The plastic displacement of the last solve, `−g ≥ 0` where the pressure is at the
    /// hardness, zero elsewhere (`rows × cols`). `None` before a successful solve.
    pub fn plastic_displacement(&self) -> Option<Array2<f64>> {
        self.cx.state.solved?;
        let (rows, cols) = self.dim();
        let interface = self.cx.interface;
        let w = self
            .cx
            .state
            .pressure
            .iter()
            .zip(&self.cx.state.gap)
            .map(|(&p, &g)| match interface.plastic(p) {
                true => (-g).max(0.0),
                false => 0.0,
            })
            .collect();
        Some(Array2::from_shape_vec((rows, cols), w).expect("grid-sized"))
    }

    /// Makes the plastic displacement of the last solve permanent: the profile becomes
    /// `f + w` (the surface flattened where it yielded) and the gap there zero, so the
    /// solved state stays a solution of the new profile. Returns the largest `w` added.
    /// Without a solved state nothing changes.
    pub fn keep_plastic_displacement(&mut self) -> f64 {
        if self.cx.state.solved.is_none() {
            return 0.0;
        }
        let len = self.cx.problem.profile.len();
        let permanent = self.permanent.get_or_insert_with(|| vec![0.0; len]);
        let interface = self.cx.interface;
        let mut largest = 0.0f64;
        for (((f, g), &p), total) in self
            .cx
            .problem
            .profile
            .iter_mut()
            .zip(self.cx.state.gap.iter_mut())
            .zip(&self.cx.state.pressure)
            .zip(permanent.iter_mut())
        {
            if interface.plastic(p) && *g < 0.0 {
                let w = -*g;
                *f += w;
                *total += w;
                *g = 0.0;
                largest = largest.max(w);
            }
        }
        largest
    }

    /// The permanent displacement kept so far (zero before any), `rows × cols`.
    pub fn permanent_displacement(&self) -> Array2<f64> {
        let (rows, cols) = self.dim();
        match &self.permanent {
            Some(w) => Array2::from_shape_vec((rows, cols), w.clone()).expect("grid-sized"),
            None => Array2::zeros((rows, cols)),
        }
    }
}

/// One step of a [`load_path`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    /// The load or indentation of the step.
    pub control: Control,
    /// The solved scalars (force, indentation, contact and plastic fractions).
    pub summary: ContactSummary,
    /// The frozen-set stiffness (on the elastic set, see the module docs).
    pub stiffness: f64,
    /// Iterations of the solve.
    pub iterations: usize,
    /// The largest permanent displacement so far.
    pub permanent_max: f64,
}

/// Walks `controls` in order (e.g. loading up, unloading, reloading), each step warm from
/// the last, keeping the plastic displacement of each
/// ([`ContactSolver::keep_plastic_displacement`]): the force, area and stiffness of the
/// way down differ from the way up (hysteresis). The first error ends the path.
pub fn load_path(
    solver: &mut ContactSolver,
    controls: &[Control],
) -> Result<Vec<PathPoint>, SolveError> {
    let mut points = Vec::with_capacity(controls.len());
    let mut permanent_max = 0.0f64;
    for &control in controls {
        let (summary, info) = solver.solve(control)?;
        let (stiffness, _) = solver.frozen_set_stiffness()?;
        permanent_max = permanent_max.max(solver.keep_plastic_displacement());
        if let Some(w) = &solver.permanent {
            permanent_max = w.iter().fold(permanent_max, |m, &x| m.max(x));
        }
        points.push(PathPoint {
            control,
            summary,
            stiffness,
            iterations: info.iterations,
            permanent_max,
        });
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::super::{HalfSpace, SolverKind, SolverParams};
    use super::*;
    use crate::bem::iterations::polonsky_keer::tests::rough_grid;
    use crate::elastic::Boundary;
    use crate::surface::Surface;
    use std::f64::consts::PI;

    /// Both solvers know the cap: every test runs on each.
    const KINDS: [SolverKind; 2] = [SolverKind::Bccg, SolverKind::PolonskyKeer];

    fn solver_of(
        solver: SolverKind,
        (rows, cols, seed): (usize, usize, u64),
        boundary: Boundary,
    ) -> ContactSolver {
        let params = SolverParams {
            solver,
            ..SolverParams::default()
        };
        let half_space = HalfSpace {
            modulus: 1.0,
            boundary,
        };
        ContactSolver::new(&rough_grid(rows, cols, seed), half_space, params).unwrap()
    }

    const GRIDS: [(usize, usize); 3] = [(31, 31), (32, 32), (24, 40)];
    const BOUNDARIES: [Boundary; 2] = [Boundary::Free, Boundary::Periodic];

    /// Every point satisfies the capped contact conditions: `0 ≤ p ≤ H`; `g = 0` on the
    /// elastic set (the cleaned gap), `g ≥ 0` out of contact, `g ≤ 0` at the cap; the
    /// summary counts what the fields say.
    fn check_complementarity(solver: &ContactSolver, h: f64) {
        let summary = solver.summary().unwrap();
        let (mut contact, mut plastic) = (0, 0);
        for (&p, &g) in solver.pressure().iter().zip(solver.gap()) {
            assert!((0.0..=h).contains(&p), "p = {p} outside [0, {h}]");
            if p == h {
                assert!(g <= 0.0, "g = {g} at the cap");
                plastic += 1;
            } else if p > 0.0 {
                assert_eq!(g, 0.0);
            } else {
                assert!(g >= 0.0);
            }
            contact += (p > 0.0) as usize;
        }
        assert_eq!(summary.contact_points, contact);
        assert_eq!(summary.plastic_points, plastic);
        let w = solver.plastic_displacement().unwrap();
        for ((&wi, &p), &g) in w.iter().zip(solver.pressure()).zip(solver.gap()) {
            assert_eq!(wi, if p == h { -g } else { 0.0 });
        }
    }

    #[test]
    fn a_capped_full_contact_with_plastic_points_is_solved_not_refused() {
        // A periodic sinusoid pressed beyond its elastic full-contact load p* (which the
        // hard wall refuses) under a cap H = 2 p* that the elastic pressure p̄ + p* cos
        // would pass: every point in contact, the crests at the cap, the rest elastic —
        // a contact problem still, solved by both solvers to the load, with the conditions
        // at every point; odd, even and rectangular grids.
        for (rows, cols) in GRIDS {
            let heights = ndarray::Array2::from_shape_fn((rows, cols), |(_, j)| {
                0.05 * (2.0 * std::f64::consts::PI * j as f64 / cols as f64).cos()
            });
            let surface = crate::surface::Surface::new(heights, cols as f64).unwrap();
            let half_space = HalfSpace {
                modulus: 1.0,
                boundary: Boundary::Periodic,
            };
            for kind in KINDS {
                let params = SolverParams {
                    solver: kind,
                    ..SolverParams::default()
                };
                let mut solver = ContactSolver::new(&surface, half_space, params).unwrap();
                let p_star = solver.full_contact_threshold().unwrap().mean_pressure;
                let load = Control::MeanPressure(1.2 * p_star);
                assert!(matches!(
                    solver.solve(load),
                    Err(SolveError::BeyondFullContact { .. })
                ));
                let h = 2.0 * p_star;
                solver
                    .set_interface(Interface::hardness(h).unwrap())
                    .unwrap();
                let (summary, info) = solver.solve(load).unwrap();
                let case = format!("{rows}x{cols} {kind:?}");
                eprintln!(
                    "{case}: {} iterations, plastic {:.3}",
                    info.iterations, summary.plastic_fraction
                );
                assert_eq!(summary.contact_points, rows * cols, "{case}");
                assert!(summary.plastic_points > 0, "{case}");
                assert!(summary.plastic_points < rows * cols, "{case}");
                assert!(
                    (summary.mean_pressure / (1.2 * p_star) - 1.0).abs() < 1e-12,
                    "{case}"
                );
                check_complementarity(&solver, h);
            }
        }
    }

    #[test]
    fn capped_solves_satisfy_the_conditions_at_every_point() {
        for kind in KINDS {
            // Odd, even and non-square grids, free and periodic, load and displacement
            // control, at a hardness that caps part of the contact.
            for (rows, cols) in GRIDS {
                for boundary in BOUNDARIES {
                    let mut solver = solver_of(kind, (rows, cols, 3), boundary);
                    let (elastic, _) = solver.solve(Control::MeanPressure(0.02)).unwrap();
                    let peak = solver.pressure().fold(0.0f64, |m, &p| m.max(p));
                    let h = 0.5 * peak;
                    solver
                        .set_interface(Interface::hardness(h).unwrap())
                        .unwrap();
                    let (s, info) = solver.solve(Control::MeanPressure(0.02)).unwrap();
                    let case = format!("{kind:?} {rows}x{cols} {boundary:?}");
                    assert!(s.plastic_points > 0, "{case}");
                    assert!((s.mean_pressure - 0.02).abs() < 1e-12, "{case}: {s:?}");
                    // Capping spreads the load: more area, a deeper indenter.
                    assert!(s.contact_points > elastic.contact_points, "{case}");
                    assert!(s.indentation > elastic.indentation, "{case}");
                    assert!(info.residual < 1e-8, "{case}");
                    check_complementarity(&solver, h);
                    check_recomputed(&mut solver, h, &case);
                    // Displacement control at that indentation gives the same state.
                    solver.reset();
                    let (d, _) = solver.solve(Control::Indentation(s.indentation)).unwrap();
                    assert!(
                        (d.mean_pressure / s.mean_pressure - 1.0).abs() < 1e-6,
                        "{case}"
                    );
                    assert_eq!(d.plastic_points, s.plastic_points, "{case}");
                    check_complementarity(&solver, h);
                    check_recomputed(&mut solver, h, &case);
                }
            }
        }
    }

    #[test]
    fn a_cap_no_iterate_reaches_gives_the_elastic_result_exactly() {
        for kind in KINDS {
            for (rows, cols) in GRIDS {
                for boundary in BOUNDARIES {
                    for control in [Control::MeanPressure(0.03), Control::Indentation(0.02)] {
                        let mut wall = solver_of(kind, (rows, cols, 5), boundary);
                        let want = wall.solve(control).unwrap();
                        // Above the solution's peak and above the cold start of displacement
                        // control (local springs (d − f)/K₀₀): no iterate reaches it.
                        let peak = wall.pressure().fold(0.0f64, |m, &p| m.max(p));
                        let springs = match control {
                            Control::Indentation(d) => {
                                d / wall.cx.problem.operator.self_influence()
                            }
                            _ => 0.0,
                        };
                        let peak = peak.max(springs);
                        let mut capped = solver_of(kind, (rows, cols, 5), boundary)
                            .with_interface(Interface::hardness(1.5 * peak).unwrap())
                            .unwrap();
                        let got = capped.solve(control).unwrap();
                        assert_eq!(got, want, "{rows}x{cols} {boundary:?} {control:?}");
                        assert_eq!(capped.pressure(), wall.pressure());
                        assert_eq!(capped.gap(), wall.gap());
                        assert_eq!(
                            capped.frozen_set_stiffness().unwrap().0,
                            wall.frozen_set_stiffness().unwrap().0
                        );
                    }
                }
            }
        }
    }

    /// Records the pressure of every load of a sweep.
    struct Fields(Vec<Vec<f64>>);

    impl crate::bem::sweep::SweepObserver for Fields {
        type Error = std::convert::Infallible;
        fn solved(&mut self, _load: usize, solver: &ContactSolver) -> Result<(), Self::Error> {
            self.0.push(solver.pressure().iter().copied().collect());
            Ok(())
        }
    }

    #[test]
    fn a_warm_sweep_under_a_cap_no_point_reaches_is_the_hard_walls() {
        use crate::bem::sweep::{sweep, SweepParams};
        // Up, down and up again: every warm solve after the first starts from the
        // continuation predictor of the frozen-set stiffness before it.
        let sweeps = [
            [0.01, 0.02, 0.04, 0.03, 0.05].map(Control::MeanPressure),
            [0.005, 0.01, 0.02, 0.015, 0.025].map(Control::Indentation),
        ];
        for kind in KINDS {
            for (rows, cols) in GRIDS {
                for boundary in BOUNDARIES {
                    for loads in &sweeps {
                        let case = format!("{kind:?} {rows}x{cols} {boundary:?} {:?}", loads[0]);
                        let mut wall = solver_of(kind, (rows, cols, 5), boundary);
                        let mut wall_fields = Fields(Vec::new());
                        let want =
                            sweep(&mut wall, loads, SweepParams::default(), &mut wall_fields)
                                .unwrap();
                        // Above every solution's peak and the cold start of displacement
                        // control (local springs (d − f)/K₀₀): a predicted peak above the
                        // cap would fall back to the previous pressure, and differ.
                        let peak = wall_fields
                            .0
                            .iter()
                            .flatten()
                            .fold(0.0f64, |m, &p| m.max(p));
                        let springs = 0.025 / wall.cx.problem.operator.self_influence();
                        let h = 1.5 * peak.max(springs);
                        let mut capped = solver_of(kind, (rows, cols, 5), boundary)
                            .with_interface(Interface::hardness(h).unwrap())
                            .unwrap();
                        let mut capped_fields = Fields(Vec::new());
                        let got = sweep(
                            &mut capped,
                            loads,
                            SweepParams::default(),
                            &mut capped_fields,
                        )
                        .unwrap();
                        for (w, g) in want.iter().zip(&got) {
                            assert_eq!(
                                (w.summary, w.info, w.stiffness),
                                (g.summary, g.info, g.stiffness),
                                "{case}"
                            );
                        }
                        assert!(wall_fields.0 == capped_fields.0, "{case}: pressures differ");
                    }
                }
            }
        }
    }

    #[test]
    fn a_vanishing_hardness_gives_the_bearing_area_fully_plastic() {
        for kind in KINDS {
            // H → 0 at a fixed approach d: the elastic displacements (of order H) vanish, the
            // surface is cut where the indenter passes through it, {f < d}, and every contact
            // point is at the cap: F = H·A.
            for (rows, cols) in GRIDS {
                for boundary in BOUNDARIES {
                    let mut solver = solver_of(kind, (rows, cols, 8), boundary);
                    let h = 1e-9;
                    solver
                        .set_interface(Interface::hardness(h).unwrap())
                        .unwrap();
                    let profile = solver.problem().profile().to_owned();
                    let mut sorted: Vec<f64> = profile.iter().copied().collect();
                    sorted.sort_by(f64::total_cmp);
                    // An approach midway between two profile values near 10 % bearing area,
                    // far from both compared with the elastic displacements (~1e-9).
                    let k = sorted.len() / 10;
                    let d = 0.5 * (sorted[k] + sorted[k + 1]);
                    assert!(sorted[k + 1] - sorted[k] > 1e-6);
                    let (s, _) = solver.solve(Control::Indentation(d)).unwrap();
                    let case = format!("{kind:?} {rows}x{cols} {boundary:?}");
                    let bearing: Vec<bool> = profile.iter().map(|&f| f < d).collect();
                    let contact: Vec<bool> = solver.pressure().iter().map(|&p| p > 0.0).collect();
                    assert_eq!(contact, bearing, "{case}");
                    assert_eq!(s.plastic_points, s.contact_points, "{case}");
                    let (dx, dy) = solver.problem().spacings();
                    let fully_plastic = h * s.contact_points as f64 * dx * dy;
                    assert!((s.force / fully_plastic - 1.0).abs() < 1e-12, "{case}");
                    check_complementarity(&solver, h);
                }
            }
        }
    }

    #[test]
    fn the_frozen_elastic_set_gives_the_loading_tangent() {
        for kind in KINDS {
            // k on 0 < p < H against dF/dd by central differences of two capped solves; the
            // sets move within the step (points reach the cap), hence 3 %.
            for boundary in BOUNDARIES {
                let mut solver = solver_of(kind, (48, 48, 2), boundary);
                solver
                    .set_interface(Interface::hardness(0.3).unwrap())
                    .unwrap();
                let (s, _) = solver.solve(Control::MeanPressure(0.03)).unwrap();
                assert!(s.plastic_points > 0);
                let (k, _) = solver.frozen_set_stiffness().unwrap();
                let d = s.indentation;
                let (up, _) = solver.solve(Control::Indentation(d * 1.001)).unwrap();
                let (down, _) = solver.solve(Control::Indentation(d * 0.999)).unwrap();
                let fd = (up.force - down.force) / (up.indentation - down.indentation);
                assert!((k / fd - 1.0).abs() < 0.03, "{boundary:?}: {k} vs {fd}");
            }
        }
    }

    #[test]
    fn a_load_path_keeps_the_plastic_displacement() {
        for kind in KINDS {
            for boundary in BOUNDARIES {
                let mut solver = solver_of(kind, (40, 40, 4), boundary);
                solver
                    .set_interface(Interface::hardness(0.3).unwrap())
                    .unwrap();
                let loads = [0.01, 0.04, 0.01, 0.04].map(Control::MeanPressure);
                let path = load_path(&mut solver, &loads).unwrap();
                let [first, top, down, again] = [path[0], path[1], path[2], path[3]];
                assert!(top.summary.plastic_points > 0 && top.permanent_max > 0.0);
                // Unloading is elastic on the flattened surface: the indenter stands deeper
                // than on the way up at the same load, nothing yields, the area is larger.
                assert!(
                    down.summary.indentation > first.summary.indentation,
                    "{boundary:?}"
                );
                assert_eq!(down.summary.plastic_points, 0, "{boundary:?}");
                assert_eq!(down.permanent_max, top.permanent_max);
                assert!(down.summary.contact_points >= first.summary.contact_points);
                // Reloading to the largest load comes back to the state of the way up and
                // adds (to the tolerance) no plastic displacement.
                let dd = again.summary.indentation / top.summary.indentation - 1.0;
                assert!(dd.abs() < 1e-6, "{boundary:?}: {dd}");
                assert!(again.permanent_max - top.permanent_max < 1e-8 * top.permanent_max);
                // The solver keeps the permanent field; a new surface forgets it.
                let w = solver.permanent_displacement();
                assert!(w.iter().all(|&x| x >= 0.0));
                assert_eq!(w.fold(0.0f64, |m, &x| m.max(x)), again.permanent_max);
            }
        }
    }

    #[test]
    fn bad_hardness_and_loads_beyond_it_are_refused() {
        for kind in KINDS {
            let mut solver = solver_of(kind, (16, 16, 1), Boundary::Free);
            for h in [0.0, -1.0, f64::NAN, f64::INFINITY] {
                let err = solver.set_interface(Interface::Hardness { h }).unwrap_err();
                assert!(err.to_string().contains("hardness"), "{err}");
            }
            solver
                .set_interface(Interface::hardness(0.1).unwrap())
                .unwrap();
            let err = solver.solve(Control::MeanPressure(0.1)).unwrap_err();
            assert!(
                err.to_string().contains("at or above the hardness"),
                "{err}"
            );
            let area = solver.nominal_area();
            assert!(solver.solve(Control::Force(0.2 * area)).is_err());
        }
    }

    /// A rough surface of `n²` points, rms gradient `rms_slope` (Hurst 0.8, roll-off 6).
    fn rough_surface(n: usize, rms_slope: f64, seed: u64) -> crate::surface::Surface {
        use crate::spectrum::{LongWavelength, Psd};
        use crate::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};
        let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 6.0 }, None).unwrap();
        let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(rms_slope)).unwrap();
        SurfaceGenerator::new(&spec).unwrap().generate(seed)
    }

    #[test]
    fn the_bccg_and_polonsky_keer_agree_up_to_fully_plastic_contact() {
        // ContactMechanics' open case (H = 0.1 E*, rms gradient 0.08; its capped PK does not
        // converge above p̄ ≈ 0.07 E*), up to 95 % of the fully plastic load (at 99 % this 64² grid is in full contact, which
        // is refused): both solvers
        // converge from cold, at every point within the conditions, with the same contact
        // and plastic sets and pressures within 1e-6 H (two solutions to the tolerance
        // 1e-8 of the residual, in rms heights). Free and periodic, load control, and
        // displacement control at the solved indentation.
        let surface = rough_surface(64, 0.08, 2);
        let h = 0.1;
        for boundary in BOUNDARIES {
            for p in [0.03, 0.07, 0.09, 0.095] {
                let solve = |kind, control| {
                    let params = SolverParams {
                        solver: kind,
                        ..SolverParams::default()
                    };
                    let half_space = HalfSpace {
                        modulus: 1.0,
                        boundary,
                    };
                    let mut solver = ContactSolver::new(&surface, half_space, params)
                        .unwrap()
                        .with_interface(Interface::hardness(h).unwrap())
                        .unwrap();
                    let (summary, info) = solver.solve(control).unwrap();
                    check_complementarity(&solver, h);
                    check_recomputed(&mut solver, h, &format!("{kind:?} {control:?}"));
                    (summary, info, solver.pressure().to_owned())
                };
                let load = Control::MeanPressure(p);
                let (bccg, info, bccg_p) = solve(SolverKind::Bccg, load);
                let (pk, pk_info, pk_p) = solve(SolverKind::PolonskyKeer, load);
                let case = format!("{boundary:?} p = {p}");
                eprintln!(
                    "{case}: area {:.4} plastic {:.4}, BCCG {} iterations, PK {}",
                    bccg.area_fraction, bccg.plastic_fraction, info.iterations, pk_info.iterations
                );
                assert_eq!(bccg.contact_points, pk.contact_points, "{case}");
                assert_eq!(bccg.plastic_points, pk.plastic_points, "{case}");
                let gap = bccg_p
                    .iter()
                    .zip(&pk_p)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(gap < 1e-6 * h, "{case}: max |Δp| {gap:e}");
                let by_displacement = Control::Indentation(bccg.indentation);
                let (d, _, d_p) = solve(SolverKind::Bccg, by_displacement);
                assert_eq!(d.plastic_points, bccg.plastic_points, "{case}");
                let gap = bccg_p
                    .iter()
                    .zip(&d_p)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(
                    gap < 1e-5 * h,
                    "{case}: displacement control, max |Δp| {gap:e}"
                );
            }
        }
    }

    /// The conditions checked against the gap recomputed from the pressure (`u = K p`
    /// afresh, `g = u + f − d`), not the solver's cleaned gap: `0 ≤ p ≤ H`; on the
    /// elastic set `|g|`, at the cap `max(g, 0)` and out of contact `max(−g, 0)` within
    /// the tolerance's pointwise bound (the residual is the rms of these violations over
    /// the `n_c` contact points in units of `h_rms`, so none exceeds
    /// `tolerance · h_rms · √n_c`; twice that for rounding). Returns the pressure.
    fn check_recomputed(solver: &mut ContactSolver, h: f64, case: &str) -> Array2<f64> {
        let summary = solver.summary().unwrap();
        let bound = 2.0
            * solver.params().tolerance
            * solver.problem().height_scale()
            * (summary.contact_points as f64).sqrt();
        let profile = solver.problem().profile().to_owned();
        let state = solver.state().unwrap();
        for ((&p, &u), &f) in state.pressure.iter().zip(&state.displacement).zip(&profile) {
            let g = u + f - summary.indentation;
            assert!(
                (0.0..=h).contains(&p),
                "{case}: p = {p:e} outside [0, {h:e}]"
            );
            let violation = match p {
                p if p >= h => g.max(0.0),
                p if p > 0.0 => g.abs(),
                _ => (-g).max(0.0),
            };
            assert!(
                violation <= bound,
                "{case}: violation {violation:e} > {bound:e}"
            );
        }
        state.pressure
    }

    /// Solves `surface` under `load` at the hardness `fraction` × the elastic solution's
    /// peak pressure with both solvers: each converges from cold, to the load (1e-12),
    /// with the conditions at every point against the recomputed gap, and the two agree:
    /// the same contact and plastic sets, pressures within the tolerance's pointwise gap
    /// bound (see [`check_recomputed`]) over the self-influence `K₀₀` (a point's own
    /// displacement per unit of its pressure): two solutions each within the tolerance,
    /// not the same bits (measured: 1.8e-6 H on the paraboloid, where the bound is
    /// 2e-5 H).
    fn capped_solves_agree(surface: &Surface, half_space: HalfSpace, load: f64, fraction: f64) {
        let mut elastic = ContactSolver::new(surface, half_space, SolverParams::default()).unwrap();
        elastic.solve(Control::MeanPressure(load)).unwrap();
        let h = fraction * elastic.pressure().fold(0.0f64, |m, &p| m.max(p));
        let (rows, cols) = surface.heights().dim();
        let mut results = Vec::new();
        for kind in KINDS {
            let params = SolverParams {
                solver: kind,
                ..SolverParams::default()
            };
            let mut solver = ContactSolver::new(surface, half_space, params)
                .unwrap()
                .with_interface(Interface::hardness(h).unwrap())
                .unwrap();
            let case = format!(
                "{rows}x{cols} {:?} p = {load:e}, H = {fraction} p_max, {kind:?}",
                half_space.boundary
            );
            let (s, info) = match solver.solve(Control::MeanPressure(load)) {
                Ok(solved) => solved,
                Err(e) => panic!("{case}: {e}"),
            };
            eprintln!(
                "{case}: {} iterations, area {:.4}, plastic {:.4}",
                info.iterations, s.area_fraction, s.plastic_fraction
            );
            assert!((s.mean_pressure / load - 1.0).abs() < 1e-12, "{case}");
            assert!(s.plastic_points > 0, "{case}");
            check_complementarity(&solver, h);
            results.push((s, check_recomputed(&mut solver, h, &case)));
        }
        let [(bccg, bccg_p), (pk, pk_p)] = [&results[0], &results[1]];
        let case = format!(
            "{rows}x{cols} {:?} {load:e} {fraction}",
            half_space.boundary
        );
        assert_eq!(bccg.contact_points, pk.contact_points, "{case}");
        assert_eq!(bccg.plastic_points, pk.plastic_points, "{case}");
        let bound = 2.0
            * SolverParams::default().tolerance
            * elastic.problem().height_scale()
            * (bccg.contact_points as f64).sqrt()
            / elastic.cx.problem.operator.self_influence();
        let gap = bccg_p
            .iter()
            .zip(pk_p)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        eprintln!(
            "{case}: max |Δp| {:.1e} H, bound {:.1e} H",
            gap / h,
            bound / h
        );
        assert!(gap < bound, "{case}: max |Δp| {gap:e} > {bound:e}");
    }

    #[test]
    fn a_capped_paraboloid_converges_from_cold() {
        // docs/hardness.md's defect, now fixed: 64², free, z = −r²/2R with R = 1 mm on a
        // 20 µm window, E* = 1 GPa, p̄ = 2.13e5 Pa, H = p_Hertz/2, /5, /10 (before: the
        // capped Polonsky–Keer cycled at /2 — residual 0.105 after 10 000 iterations — and
        // both solvers at /5 and /10). Odd, even and non-square grids, free and periodic.
        for (rows, cols) in [(64, 64), (63, 63), (50, 72)] {
            let surface =
                crate::bem::iterations::polonsky_keer::tests::sphere(rows, cols, 20e-6, 1e-3);
            for boundary in BOUNDARIES {
                let half_space = HalfSpace {
                    modulus: 1e9,
                    boundary,
                };
                for fraction in [0.5, 0.2, 0.1] {
                    capped_solves_agree(&surface, half_space, 2.13e5, fraction);
                }
            }
        }
    }

    #[test]
    fn a_capped_sinusoid_in_two_directions_converges() {
        // z = A sin(2πx/L) cos(2πy/L) (one crest and one trough per period along each
        // axis): at H = 0.3 of the elastic peak and p̄ = 1e-3 E*, on 24² and 25², both
        // solvers cycled (residual 0.19 after 10 000 iterations, periodic); now both
        // converge, at H = 0.6 and 0.3 p_max, three loads, free and periodic.
        for (rows, cols) in [(24, 24), (25, 25), (24, 30)] {
            let heights = Array2::from_shape_fn((rows, cols), |(i, j)| {
                let (x, y) = (j as f64 / cols as f64, i as f64 / rows as f64);
                0.01 * (2.0 * PI * x).sin() * (2.0 * PI * y).cos()
            });
            let surface = Surface::new(heights, 1.0).unwrap();
            for boundary in BOUNDARIES {
                let half_space = HalfSpace {
                    modulus: 1.0,
                    boundary,
                };
                for load in [1e-3, 3e-3, 1e-2] {
                    for fraction in [0.6, 0.3] {
                        capped_solves_agree(&surface, half_space, load, fraction);
                    }
                }
            }
        }
    }
}
