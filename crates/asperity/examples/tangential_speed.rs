//! Time of the tangential frozen-set stiffness (`k_x` and `k_y`, two CGs with Cerruti's
//! operators) against the normal one (one CG with Love's) on the same solved states of a
//! rough surface, interleaved load by load: the CGs from zero (`cold`, the first
//! implementation) and from the normal frozen-set solution (`warm`, the default; module
//! docs of `bem::tangential`), in alternating order.
//!
//! Run: `cargo run --release -p asperity --example tangential_speed -- N [H] [SEED]`

use std::time::Instant;

use asperity::bem::tangential::TangentialStiffness;
use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
use asperity::elastic::Boundary;
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(256, |s| s.parse().unwrap());
    let hurst: f64 = args.get(2).map_or(0.8, |s| s.parse().unwrap());
    let seed: u64 = args.get(3).map_or(1, |s| s.parse().unwrap());
    let psd = Psd::new(hurst, LongWavelength::RollOff { q0: 4.0 }, None).unwrap();
    let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(1.0)).unwrap();
    let surface = SurfaceGenerator::new(&spec)
        .unwrap()
        .try_generate(seed)
        .unwrap();
    let half_space = HalfSpace {
        modulus: 1.0,
        boundary: Boundary::Free,
    };
    let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default()).unwrap();
    let t0 = Instant::now();
    let mut warm = TangentialStiffness::new(&solver, 0.3).unwrap();
    println!(
        "{n}²: planning the two tangential operators {:.3} s",
        t0.elapsed().as_secs_f64()
    );
    let mut cold = TangentialStiffness::new(&solver, 0.3)
        .unwrap()
        .with_warm_start(false);
    println!(
        "pressure,area_fraction,k_n,k_x/k_n,k_y/k_n,normal_s,normal_iter,\
         cold_s,cold_iter_x,cold_iter_y,warm_s,warm_iter_x,warm_iter_y,warm_vs_cold"
    );
    for (load, p) in [0.005, 0.02, 0.08].into_iter().enumerate() {
        let (summary, _) = solver.solve(Control::MeanPressure(p)).unwrap();
        let t = Instant::now();
        let (k, info) = solver.frozen_set_stiffness().unwrap();
        let normal = t.elapsed().as_secs_f64();
        let time = |t: &mut TangentialStiffness| {
            let start = Instant::now();
            let kt = t.solve(&solver).unwrap();
            (kt, start.elapsed().as_secs_f64())
        };
        let ((c, c_s), (w, w_s)) = if load % 2 == 0 {
            let c = time(&mut cold);
            (c, time(&mut warm))
        } else {
            let w = time(&mut warm);
            (time(&mut cold), w)
        };
        // The two starts give the same stiffnesses to the CG's precision.
        let agree = ((w.x / c.x - 1.0).abs()).max((w.y / c.y - 1.0).abs());
        println!(
            "{p},{:.4},{k:.6e},{:.5},{:.5},{normal:.3},{},{c_s:.3},{},{},{w_s:.3},{},{},{agree:.1e}",
            summary.area_fraction,
            w.x / k,
            w.y / k,
            info.iterations,
            c.info_x.iterations,
            c.info_y.iterations,
            w.info_x.iterations,
            w.info_y.iterations
        );
    }
}
