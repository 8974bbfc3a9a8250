//! Iterations and time of the BEM sampler's load sweep (24 loads, each a warm solve and a
//! frozen-set stiffness) on one surface: where a study sample's time goes.
//!
//! Run: `RAYON_NUM_THREADS=2 cargo run --release -p asperity --example bem_sample_profile -- N H SEED [SAMPLES]`
//! (samples in parallel, one solver per rayon thread, as a study runs them).

use std::time::Instant;

use rayon::prelude::*;

use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
use asperity::elastic::Boundary;
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

/// User + system CPU seconds of this process (Linux `/proc/self/stat`; 0 elsewhere): on a
/// shared machine the CPU time is the steadier measure.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let after_name = &stat[stat.rfind(')').map_or(0, |i| i + 2)..];
    let fields: Vec<&str> = after_name.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(128, |s| s.parse().unwrap());
    let hurst: f64 = args.get(2).map_or(0.5, |s| s.parse().unwrap());
    let seed: u64 = args.get(3).map_or(1, |s| s.parse().unwrap());
    let samples: u64 = args.get(4).map_or(1, |s| s.parse().unwrap());
    let verbose = samples == 1;
    let psd = Psd::new(hurst, LongWavelength::None, None).unwrap();
    let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(1.0)).unwrap();
    let loads: Vec<f64> = asperity::fit::log_levels(0.05 / (n * n) as f64, 0.2, 24).collect();
    let half_space = HalfSpace {
        modulus: 1.0,
        boundary: Boundary::Free,
    };
    let run = |seed: u64, solver: &mut Option<ContactSolver>, generator: &mut SurfaceGenerator| {
        let surface = generator.try_generate(seed).unwrap();
        let solver = match solver.as_mut() {
            Some(s) => {
                s.set_surface(&surface).unwrap();
                s
            }
            None => solver
                .insert(ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap()),
        };
        let mut totals = [0.0; 6];
        for &p in &loads {
            let t0 = Instant::now();
            let (summary, info) = solver.solve(Control::MeanPressure(p)).unwrap();
            let t1 = Instant::now();
            let (k, kinfo) = solver.frozen_set_stiffness().unwrap();
            let t2 = Instant::now();
            let add = [
                (t1 - t0).as_secs_f64(),
                (t2 - t1).as_secs_f64(),
                info.iterations as f64,
                kinfo.iterations as f64,
                info.operator_applications as f64,
                k + summary.indentation,
            ];
            totals.iter_mut().zip(add).for_each(|(t, a)| *t += a);
            if verbose {
                println!(
                    "p {p:.3e} area {:.4} solve {:3} it {:3} K {:7.2} ms | stiffness {:3} it {:3} K {:7.2} ms k {k:.10e} d {:.10e}",
                    summary.area_fraction,
                    info.iterations,
                    info.operator_applications,
                    add[0] * 1e3,
                    kinfo.iterations,
                    kinfo.operator_applications,
                    add[1] * 1e3,
                    summary.indentation,
                );
            }
        }
        totals
    };
    let start = Instant::now();
    let cpu = cpu_seconds();
    let totals = (seed..seed + samples)
        .into_par_iter()
        .map_init(
            || (None, SurfaceGenerator::new(&spec).unwrap()),
            |(solver, generator), s| run(s, solver, generator),
        )
        .reduce(
            || [0.0; 6],
            |mut a, b| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                a
            },
        );
    let wall = start.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - cpu;
    println!(
        "N {n} H {hurst} samples {samples}: wall {wall:.3} s cpu {cpu:.2} s; solve {} it ({} K) {:.3} s, stiffness {} it {:.3} s; checksum {:.12e}",
        totals[2], totals[4], totals[0], totals[3], totals[1], totals[5]
    );
}
