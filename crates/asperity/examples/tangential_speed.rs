//! Time of the tangential frozen-set stiffness (`k_x` and `k_y`, two CGs with Cerruti's
//! operators) against the normal one (one CG with Love's) on the same solved states of a
//! rough surface, interleaved load by load and round by round, the minimum over rounds:
//! `cold` (from zero, the isotropic preconditioner: the first implementation), `before`
//! (from the normal frozen-set solution, the isotropic preconditioner) and `after` (from
//! the normal solution, each direction's exact inverse symbol: the default; module docs
//! of `bem::tangential`), in rotating order.
//!
//! Run: `cargo run --release -p asperity --example tangential_speed -- N [H] [SEED] [ROUNDS]`

use std::time::Instant;

use asperity::bem::tangential::{Tangential, TangentialStiffness};
use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
use asperity::elastic::Boundary;
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(256, |s| s.parse().unwrap());
    let hurst: f64 = args.get(2).map_or(0.8, |s| s.parse().unwrap());
    let seed: u64 = args.get(3).map_or(1, |s| s.parse().unwrap());
    let rounds: usize = args.get(4).map_or(3, |s| s.parse().unwrap());
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
    let after = TangentialStiffness::new(&solver, 0.3).unwrap();
    println!(
        "{n}²: planning the two tangential operators {:.3} s; {rounds} rounds, minimum",
        t0.elapsed().as_secs_f64()
    );
    let isotropic = || {
        TangentialStiffness::new(&solver, 0.3)
            .unwrap()
            .with_isotropic_preconditioner()
            .unwrap()
    };
    let before = isotropic();
    let cold = isotropic().with_warm_start(false);
    let mut variants = [cold, before, after];
    println!(
        "pressure,area_fraction,k_n,k_x/k_n,k_y/k_n,normal_s,normal_iter,cold_s,cold_iter,\
         before_s,before_iter,after_s,after_iter,after/normal,after/before,agree"
    );
    for p in [0.005, 0.02, 0.08] {
        let mut normal = (f64::INFINITY, 0);
        let mut best = [(f64::INFINITY, None::<Tangential>); 3];
        let mut area = 0.0;
        let mut k = 0.0;
        for round in 0..rounds {
            // Each round solves the state again: the normal CG leaves its solution for the
            // warm starts, and the next solve uses it up.
            let (summary, _) = solver.solve(Control::MeanPressure(p)).unwrap();
            area = summary.area_fraction;
            for v in 0..3 {
                let which = (round + v) % 3;
                let t = Instant::now();
                let (kn, info) = solver.frozen_set_stiffness().unwrap();
                let s = t.elapsed().as_secs_f64();
                if s < normal.0 {
                    normal = (s, info.iterations);
                }
                k = kn;
                let start = Instant::now();
                let kt = variants[which].solve(&solver).unwrap();
                let s = start.elapsed().as_secs_f64();
                if s < best[which].0 {
                    best[which] = (s, Some(kt));
                }
            }
        }
        let [c, b, a] = best.map(|(s, t)| (s, t.unwrap()));
        let iterations = |t: &Tangential| {
            format!(
                "{}+{}",
                t.info_x.operator_applications, t.info_y.operator_applications
            )
        };
        let agree = [&c.1, &b.1]
            .iter()
            .map(|t| ((t.x / a.1.x - 1.0).abs()).max((t.y / a.1.y - 1.0).abs()))
            .fold(0.0f64, f64::max);
        println!(
            "{p},{area:.4},{k:.6e},{:.5},{:.5},{:.3},{},{:.3},{},{:.3},{},{:.3},{},{:.2},{:.2},{agree:.1e}",
            a.1.x / k,
            a.1.y / k,
            normal.0,
            normal.1,
            c.0,
            iterations(&c.1),
            b.0,
            iterations(&b.1),
            a.0,
            iterations(&a.1),
            a.0 / normal.0,
            a.0 / b.0
        );
    }
}
