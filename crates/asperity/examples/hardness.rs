//! Elastic–perfectly-plastic contact of a rough surface (docs/hardness.md):
//! 1. a loading–unloading–reloading path at H = 0.3 E* (force, area, plastic fraction,
//!    stiffness, permanent displacement): the hysteresis;
//! 2. the case ContactMechanics' capped Polonsky–Keer is reported not to converge in
//!    (H = 0.1 E*, rms gradient 0.08, mean pressure beyond 0.07 E*), with iterations;
//! 3. with `time N`: the time of a capped solve against the elastic one at N² (with
//!    `time N bccg`, the BCCG only).
//!
//! `cargo run --release -p asperity --example hardness [time N [bccg]]`

use std::time::Instant;

use asperity::bem::{
    load_path, ContactSolver, Control, HalfSpace, Interface, SolverKind, SolverParams,
};
use asperity::elastic::Boundary;
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, Surface, SurfaceGenerator, SurfaceSpec};

fn surface(n: usize, rms_slope: f64, seed: u64) -> Surface {
    let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 6.0 }, None).unwrap();
    let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(rms_slope)).unwrap();
    SurfaceGenerator::new(&spec).unwrap().generate(seed)
}

fn solver_of(kind: SolverKind, s: &Surface, boundary: Boundary, h: Option<f64>) -> ContactSolver {
    let params = SolverParams {
        solver: kind,
        ..SolverParams::default()
    };
    let half_space = HalfSpace {
        modulus: 1.0,
        boundary,
    };
    let solver = ContactSolver::new(s, half_space, params).unwrap();
    match h {
        Some(h) => solver
            .with_interface(Interface::hardness(h).unwrap())
            .unwrap(),
        None => solver,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() >= 3 && args[1] == "time" {
        time(args[2].parse().expect("N"), args.get(3).map(String::as_str));
        return;
    }
    hysteresis();
    open_case();
}

fn hysteresis() {
    println!("# 1. loading, unloading, reloading: 128², periodic, rms slope 0.5, H = 0.3 E*");
    let s = surface(128, 0.5, 1);
    let mut solver = solver_of(SolverKind::Bccg, &s, Boundary::Periodic, Some(0.3));
    let up = [0.01, 0.02, 0.04, 0.06];
    let loads: Vec<Control> = up
        .iter()
        .chain(up.iter().rev().skip(1))
        .chain(up.iter().skip(1))
        .map(|&p| Control::MeanPressure(p))
        .collect();
    let path = load_path(&mut solver, &loads).unwrap();
    println!("mean_pressure indentation area plastic stiffness permanent_max iterations");
    for point in path {
        let s = point.summary;
        println!(
            "{:.3} {:.6} {:.4} {:.4} {:.4} {:.3e} {}",
            s.mean_pressure,
            s.indentation,
            s.area_fraction,
            s.plastic_fraction,
            point.stiffness,
            point.permanent_max,
            point.iterations
        );
    }
}

fn open_case() {
    println!("\n# 2. H = 0.1 E*, rms gradient 0.08, 128², each load from cold");
    let s = surface(128, 0.08, 2);
    for (kind, boundary) in [SolverKind::Bccg, SolverKind::PolonskyKeer]
        .into_iter()
        .flat_map(|k| [(k, Boundary::Free), (k, Boundary::Periodic)])
    {
        println!("{kind:?} {boundary:?}: mean_pressure area plastic iterations residual seconds");
        for p in [0.01, 0.03, 0.05, 0.07, 0.08, 0.09, 0.095, 0.099] {
            let mut solver = solver_of(kind, &s, boundary, Some(0.1));
            let start = Instant::now();
            match solver.solve(Control::MeanPressure(p)) {
                Ok((sum, info)) => println!(
                    "{p:.3} {:.4} {:.4} {} {:.1e} {:.2}",
                    sum.area_fraction,
                    sum.plastic_fraction,
                    info.iterations,
                    info.residual,
                    start.elapsed().as_secs_f64()
                ),
                Err(e) => println!("{p:.3} error: {e}"),
            }
        }
    }
}

/// Cold solves at p̄ = 0.05 E* (rms slope 0.5), interleaved in 3 rounds, the minimum of
/// each: BCCG elastic, BCCG capped at H = 0.3 E*, PK capped; and the ratio capped ÷
/// elastic of the BCCG.
fn time(n: usize, only: Option<&str>) {
    let s = surface(n, 0.5, 3);
    let cases = [
        ("bccg elastic", None, SolverKind::Bccg),
        ("bccg H=0.3", Some(0.3), SolverKind::Bccg),
        ("pk H=0.3", Some(0.3), SolverKind::PolonskyKeer),
    ];
    for boundary in [Boundary::Free, Boundary::Periodic] {
        let mut best = [f64::INFINITY; 3];
        let mut report = [(); 3].map(|_| String::new());
        // PK (minutes per solve at 1024² on 2 cores) only up to 512².
        let timed = if n <= 512 && only != Some("bccg") {
            3
        } else {
            2
        };
        for _ in 0..3 {
            for (k, &(_, h, kind)) in cases.iter().enumerate().take(timed) {
                let mut solver = solver_of(kind, &s, boundary, h);
                let start = Instant::now();
                let (sum, info) = solver.solve(Control::MeanPressure(0.05)).unwrap();
                let t = start.elapsed().as_secs_f64();
                if t < best[k] {
                    best[k] = t;
                    report[k] = format!(
                        "area {:.4} plastic {:.4} iterations {} applications {} energies {}",
                        sum.area_fraction,
                        sum.plastic_fraction,
                        info.iterations,
                        info.operator_applications,
                        info.energy_transforms
                    );
                }
            }
        }
        for (k, (name, _, _)) in cases.iter().enumerate().take(timed) {
            println!("{n}² {boundary:?} {name}: {:.3} s ({})", best[k], report[k]);
        }
        println!(
            "{n}² {boundary:?} bccg capped / elastic: {:.2}",
            best[1] / best[0]
        );
    }
}
