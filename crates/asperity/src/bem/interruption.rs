//! Tests of stopping a solve through its [`Stop`] flag ([`ContactSolver::with_stop`]):
//! every solver path (BCCG and Polonsky–Keer; load and displacement control; free and
//! periodic boundaries) and the frozen-set CG end with [`SolveError::Interrupted`] when the flag is set before or during
//! the computation, and the solver then gives exactly what an uninterrupted one gives.

use std::time::{Duration, Instant};

use super::{ContactSolver, Control, HalfSpace, SolveError, SolverKind, SolverParams};
use crate::bem::iterations::polonsky_keer::tests::rough;
use crate::elastic::Boundary;
use crate::stop::Stop;
use crate::surface::Surface;

fn solver(surface: &Surface, boundary: Boundary, kind: SolverKind, tol: f64) -> ContactSolver {
    let half_space = HalfSpace {
        modulus: 1.0,
        boundary,
    };
    let params = SolverParams {
        solver: kind,
        tolerance: tol,
        max_iterations: usize::MAX / 4,
        ..SolverParams::default()
    };
    let mut solver = ContactSolver::new(surface, half_space, params).unwrap();
    // The unreachable tolerances below stagnate at the rounding floor: not given up here.
    solver.cx.progress.set_window(usize::MAX);
    solver
}

/// Every (solver, boundary, control) path: a load and an indentation below it.
fn cases() -> Vec<(SolverKind, Boundary, Control)> {
    let mut cases = Vec::new();
    for kind in [SolverKind::Bccg, SolverKind::PolonskyKeer] {
        for boundary in [Boundary::Free, Boundary::Periodic] {
            for control in [Control::MeanPressure(0.02), Control::Indentation(0.004)] {
                cases.push((kind, boundary, control));
            }
        }
    }
    cases
}

/// The pressure field, summary and iterations of a solve: what "the same" compares.
fn solved(s: &mut ContactSolver, control: Control) -> (Vec<f64>, String) {
    let (summary, info) = s.solve(control).unwrap();
    let pressure = s.pressure().iter().copied().collect();
    (pressure, format!("{summary:?} {info:?}"))
}

#[test]
fn a_stop_set_before_the_solve_stops_it_and_the_next_solve_is_unchanged() {
    let surface = rough(48, 5);
    for (kind, boundary, control) in cases() {
        let what = format!("{kind:?} {boundary:?} {control:?}");
        let mut fresh = solver(&surface, boundary, kind, 1e-8);
        let expected_cold = solved(&mut fresh, control);
        let stop = Stop::new();
        let mut s = solver(&surface, boundary, kind, 1e-8).with_stop(stop.clone());
        // Cold, then warm from an earlier load: both refused at once.
        for warm in [false, true] {
            if warm {
                s.solve(Control::MeanPressure(0.01)).unwrap();
            }
            stop.request();
            match s.solve(control) {
                Err(SolveError::Interrupted { iterations }) => assert_eq!(iterations, 0, "{what}"),
                other => panic!("{what}: {other:?}"),
            }
            assert!(
                s.summary().is_none(),
                "{what}: the unfinished state is forgotten"
            );
            stop.clear();
            // The next solve starts cold: bit for bit a new solver's.
            assert_eq!(
                solved(&mut s, control),
                expected_cold,
                "{what}, warm {warm}"
            );
        }
        // The frozen-set CG too; an interrupted stiffness keeps the solved state.
        let expected_k = fresh.frozen_set_stiffness().unwrap();
        stop.request();
        assert!(matches!(
            s.frozen_set_stiffness(),
            Err(SolveError::Interrupted { iterations: 0 })
        ));
        stop.clear();
        assert_eq!(s.frozen_set_stiffness().unwrap(), expected_k, "{what}");
    }
}

#[test]
fn a_stop_during_a_solve_ends_it_within_an_iteration() {
    // A tolerance no load-controlled solve reaches (they stagnate at ~1e-16 without
    // failing): without the stop each would run (practically) forever.
    let surface = rough(128, 6);
    let load_control = cases()
        .into_iter()
        .filter(|(_, _, c)| matches!(c, Control::MeanPressure(_)));
    for (kind, boundary, control) in load_control {
        let what = format!("{kind:?} {boundary:?} {control:?}");
        let stop = Stop::new();
        let mut s = solver(&surface, boundary, kind, 1e-300).with_stop(stop.clone());
        let remote = stop.clone();
        let requested = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(100));
            remote.request();
            Instant::now()
        });
        let result = s.solve(control);
        let ended = Instant::now();
        let requested = requested.join().unwrap();
        match result {
            Err(SolveError::Interrupted { iterations }) => assert!(iterations > 0, "{what}"),
            other => panic!("{what}: {other:?}"),
        }
        // One iteration at 128² takes about a millisecond; without the stop the solve
        // would not end at all. The bound only tells "polled" from "not polled": a busy
        // machine (load 20 on 2 cores) may hold the thread for seconds (issue 33 item 16).
        let late = ended.saturating_duration_since(requested);
        assert!(
            late < Duration::from_secs(60),
            "{what}: stopped {late:?} late"
        );
        stop.clear();
        // Usable again: the next solve (to a reachable tolerance) is a new solver's.
        s.set_params(SolverParams {
            tolerance: 1e-8,
            ..*s.params()
        })
        .unwrap();
        let mut fresh = solver(&surface, boundary, kind, 1e-8);
        assert_eq!(
            solved(&mut s, control),
            solved(&mut fresh, control),
            "{what}"
        );
    }
}
