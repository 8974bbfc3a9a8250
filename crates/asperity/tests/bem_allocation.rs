//! The contact solver allocates nothing per iteration: a solve and a frozen-set stiffness
//! on a warm solver cost the same number of heap allocations whether they take few or many
//! iterations (and that number is small and fixed).
//!
//! The counting global allocator of `tests/common` applies to this test binary only (an
//! integration test); this binary holds one test so that no other test allocates while it
//! counts.

use asperity::bem::tangential::TangentialStiffness;
use asperity::bem::{
    ContactSolver, Control, HalfSpace, Interface, SolveError, SolverKind, SolverParams,
};
use asperity::elastic::Boundary;
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

mod common;
use common::count;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

#[test]
fn solves_and_stiffness_allocate_nothing_per_iteration() {
    // One rayon thread: the FFTs' parallel loops then run inline on this thread, so the
    // count holds the solver's allocations only (a multi-thread pool's job queues and
    // wake-ups may allocate a varying amount that says nothing about the solver).
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    pool.install(|| {
        // The counter sees this thread's allocations (a positive control: a zero below
        // means no allocation, not a counter that misses them).
        let (_, allocations, bytes) = count(|| std::hint::black_box(Vec::<u8>::with_capacity(24)));
        assert_eq!((allocations, bytes), (1, 24));
        let n = 64;
        let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 4.0 }, None).unwrap();
        let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(0.5)).unwrap();
        let surface = SurfaceGenerator::new(&spec).unwrap().generate(7);
        let cases = [SolverKind::Bccg, SolverKind::PolonskyKeer]
            .into_iter()
            .flat_map(|kind| [(kind, Boundary::Free), (kind, Boundary::Periodic)]);
        for (kind, boundary) in cases {
            let half_space = HalfSpace {
                modulus: 1.0,
                boundary,
            };
            let base = SolverParams {
                solver: kind,
                ..SolverParams::default()
            };
            let mut solver = ContactSolver::new(&surface, half_space, base).unwrap();
            let pressure = 0.03;
            // Warm up: the stiffness buffers are allocated on first use.
            solver.solve(Control::MeanPressure(pressure)).unwrap();
            solver.frozen_set_stiffness().unwrap();

            let mut run = |tolerance: f64| {
                solver
                    .set_params(SolverParams { tolerance, ..base })
                    .unwrap();
                solver.reset(); // a cold start: the iteration count follows the tolerance
                let ((iterations, cg_iterations), allocations, bytes) = count(|| {
                    let (_, info) = solver.solve(Control::MeanPressure(pressure)).unwrap();
                    let (_, cg) = solver.frozen_set_stiffness().unwrap();
                    (info.iterations, cg.iterations)
                });
                (iterations, cg_iterations, allocations, bytes)
            };
            let (few, cg_few, allocations_few, bytes_few) = run(1e-4);
            let (many, cg_many, allocations_many, bytes_many) = run(1e-10);
            eprintln!(
                "{kind:?} {boundary:?}: {few} and {many} iterations (+{cg_few}, {cg_many} CG): \
                 {allocations_few} and {allocations_many} allocations, \
                 {bytes_few} and {bytes_many} bytes"
            );
            assert!(many >= 2 * few, "{few} vs {many} iterations");
            assert_eq!(
                allocations_many, allocations_few,
                "allocations grow with the iterations"
            );
            // None at all: with one rayon thread nothing else allocates on the solver's
            // behalf (with more threads rayon's job bookkeeping may add a few).
            assert_eq!(allocations_few, 0, "{bytes_few} bytes");

            // A refused load beyond full contact computes its threshold in the solver's own
            // buffers, once per surface: a repeat allocates nothing.
            let beyond = Control::MeanPressure(1e3);
            assert!(matches!(
                solver.solve(beyond),
                Err(SolveError::BeyondFullContact { .. })
            ));
            let (result, allocations, bytes) = count(|| solver.solve(beyond));
            assert!(matches!(result, Err(SolveError::BeyondFullContact { .. })));
            eprintln!(
                "{kind:?} {boundary:?}: refused load: {allocations} allocations, {bytes} bytes"
            );
            assert_eq!(allocations, 0, "{kind:?} {boundary:?}: {bytes} bytes");

            // Displacement control (periodic: a root find over load-controlled solves with
            // frozen-set slopes) works in the same buffers.
            let (state, _) = solver.solve(Control::MeanPressure(pressure)).unwrap();
            let indentation = Control::Indentation(0.98 * state.indentation);
            let (result, allocations, bytes) = count(|| solver.solve(indentation));
            let (_, info) = result.unwrap();
            eprintln!(
                "{kind:?} {boundary:?}: displacement control, {} iterations: {allocations} \
                 allocations, {bytes} bytes",
                info.iterations
            );
            assert_eq!(allocations, 0, "{kind:?} {boundary:?}: {bytes} bytes");
            capped_solves_allocate_nothing(&surface, kind, boundary);
        }
        for boundary in [Boundary::Free, Boundary::Periodic] {
            tangential_stiffness_allocates_nothing(&surface, boundary);
        }
    });
}

/// Under a hardness cap (`Interface::Hardness`, issue 31) a solve works in the same
/// buffers as the hard wall's: the capped load restoration (`u <- s u + (1 - s) H K 1_C`,
/// `plastic_field.rs`), its point responses and the frozen elastic set's CG allocate
/// nothing, a loose and a tight solve alike, under load and displacement control.
fn capped_solves_allocate_nothing(
    surface: &asperity::surface::Surface,
    kind: SolverKind,
    boundary: Boundary,
) {
    let half_space = HalfSpace {
        modulus: 1.0,
        boundary,
    };
    let base = SolverParams {
        solver: kind,
        ..SolverParams::default()
    };
    let pressure = 0.03;
    let mut solver = ContactSolver::new(surface, half_space, base)
        .unwrap()
        .with_interface(Interface::hardness(0.1).unwrap())
        .unwrap();
    // Warm up: the stiffness buffers and the capped set's field on first use.
    let (summary, _) = solver.solve(Control::MeanPressure(pressure)).unwrap();
    assert!(summary.plastic_points > 0, "the cap is reached");
    solver.frozen_set_stiffness().unwrap();
    let mut run = |tolerance: f64| {
        solver
            .set_params(SolverParams { tolerance, ..base })
            .unwrap();
        solver.reset();
        let ((iterations, plastic), allocations, bytes) = count(|| {
            let (summary, info) = solver.solve(Control::MeanPressure(pressure)).unwrap();
            solver.frozen_set_stiffness().unwrap();
            (info.iterations, summary.plastic_points)
        });
        assert!(plastic > 0, "the cap is reached");
        (iterations, allocations, bytes)
    };
    let (few, allocations_few, bytes_few) = run(1e-4);
    let (many, allocations_many, bytes_many) = run(1e-10);
    eprintln!(
        "capped {kind:?} {boundary:?}: {few} and {many} iterations: {allocations_few} and \
         {allocations_many} allocations, {bytes_few} and {bytes_many} bytes"
    );
    assert!(many >= 2 * few, "{few} vs {many} iterations");
    assert_eq!(
        allocations_few, 0,
        "{kind:?} {boundary:?}: {bytes_few} bytes"
    );
    assert_eq!(
        allocations_many, 0,
        "{kind:?} {boundary:?}: {bytes_many} bytes"
    );
    let (summary, _) = solver.solve(Control::MeanPressure(pressure)).unwrap();
    let indentation = Control::Indentation(0.98 * summary.indentation);
    let (result, allocations, bytes) = count(|| solver.solve(indentation));
    let (summary, info) = result.unwrap();
    eprintln!(
        "capped {kind:?} {boundary:?}: displacement control, {} iterations, {} plastic \
         points: {allocations} allocations, {bytes} bytes",
        info.iterations, summary.plastic_points
    );
    assert_eq!(allocations, 0, "{kind:?} {boundary:?}: {bytes} bytes");
}

/// The tangential frozen-set CGs (`k_x`, `k_y`: Cerruti's operators on the contact set)
/// work in the fields planned by `TangentialStiffness::new`: a loose and a tight CG cost
/// the same, zero, allocations.
fn tangential_stiffness_allocates_nothing(
    surface: &asperity::surface::Surface,
    boundary: Boundary,
) {
    let half_space = HalfSpace {
        modulus: 1.0,
        boundary,
    };
    let base = SolverParams::default();
    let mut solver = ContactSolver::new(surface, half_space, base).unwrap();
    solver.solve(Control::MeanPressure(0.03)).unwrap();
    let mut tangential = TangentialStiffness::new(&solver, 0.3).unwrap();
    tangential.solve(&solver).unwrap(); // warm up
    let mut run = |tolerance: f64| {
        let params = SolverParams {
            stiffness_tolerance: tolerance,
            stiffness_error: 0.0,
            ..base
        };
        solver.set_params(params).unwrap();
        let (result, allocations, bytes) = count(|| tangential.solve(&solver));
        let k = result.unwrap();
        (
            k.info_x.iterations + k.info_y.iterations,
            allocations,
            bytes,
        )
    };
    let (few, allocations_few, bytes_few) = run(1e-3);
    let (many, allocations_many, bytes_many) = run(1e-12);
    eprintln!(
        "tangential {boundary:?}: {few} and {many} CG iterations: {allocations_few} and \
         {allocations_many} allocations, {bytes_few} and {bytes_many} bytes"
    );
    assert!(many >= 2 * few, "{few} vs {many} iterations");
    assert_eq!(allocations_few, 0, "{bytes_few} bytes");
    assert_eq!(allocations_many, 0, "{bytes_many} bytes");
}
