//! Criterion benchmarks of the BEM building blocks: one application of the elastic
//! operator (free: zero-padded 2N × 2N; periodic) and one cold Polonsky–Keer solve of a
//! rough surface (H = 0.8, roll-off 6, rms slope 1) at mean pressure 0.01 E*.
//!
//! `cargo bench -p asperity --bench bem`. The comparison with other codes is
//! `bench/bem_peers.sh`.

use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
use asperity::elastic::{Boundary, ElasticOperator};
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, Surface, SurfaceGenerator, SurfaceSpec};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

fn surface(n: usize) -> Surface {
    let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 6.0 }, None).expect("valid spectrum");
    let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(1.0)).expect("valid spec");
    SurfaceGenerator::new(&spec).expect("plans").generate(1)
}

fn operator(c: &mut Criterion) {
    let mut group = c.benchmark_group("elastic_apply");
    for n in [256, 512, 1024] {
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let mut op = ElasticOperator::new(n, n, 1.0 / n as f64, 1.0, boundary).expect("fits");
            let pressure: Vec<f64> = (0..n * n).map(|i| ((i * 7919) % 101) as f64).collect();
            let mut displacement = vec![0.0; n * n];
            group.bench_function(BenchmarkId::new(boundary.name(), n), |b| {
                b.iter(|| op.apply(&pressure, &mut displacement))
            });
        }
    }
    group.finish();
}

fn solve(c: &mut Criterion) {
    let mut group = c.benchmark_group("polonsky_keer_cold_solve");
    group.sample_size(10);
    for n in [128, 256] {
        let surface = surface(n);
        for boundary in [Boundary::Free, Boundary::Periodic] {
            let half_space = HalfSpace {
                modulus: 1.0,
                boundary,
            };
            let mut solver =
                ContactSolver::new(&surface, half_space, SolverParams::default()).expect("fits");
            group.bench_function(BenchmarkId::new(boundary.name(), n), |b| {
                b.iter(|| {
                    solver.reset();
                    solver
                        .solve(Control::MeanPressure(0.01))
                        .expect("converges")
                })
            });
        }
    }
    group.finish();
}

fn stiffness(c: &mut Criterion) {
    let surface = surface(256);
    let mut solver =
        ContactSolver::new(&surface, HalfSpace::default(), SolverParams::default()).expect("fits");
    solver
        .solve(Control::MeanPressure(0.01))
        .expect("converges");
    c.bench_function("frozen_set_stiffness/free/256", |b| {
        b.iter(|| solver.frozen_set_stiffness().expect("converges"))
    });
}

criterion_group!(benches, operator, solve, stiffness);
criterion_main!(benches);
