//! `asperity bench`: timings of the library's kernels, for side-by-side comparisons with
//! other tools (see `bench/` for the scripts that run the peers in the same session).

use std::time::Instant;

use anyhow::Result;
use asperity::bem::{ContactSolver, Control, HalfSpace, SolverKind, SolverParams};
use asperity::elastic::{Boundary, ElasticOperator};
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

/// What to time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Kernel {
    /// Surface generation: one N×N realisation (spectrum, inverse real FFT, normalisation).
    Surface,
    /// BEM solves: one cold solve of an N×N surface (H, roll-off 6, rms slope 1, seed 0) per
    /// mean pressure of --pressures, by each solver (pk, bccg), free and periodic, with the
    /// iterations, operator applications and the time of one operator application (a
    /// padded FFT pair on free boundaries), to state an iteration's cost in FFT pairs.
    BemSolve,
}

/// Arguments of `asperity bench`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Prints the time with planning and buffer set-up (cold, what one `asperity surface`\n\
                  pays) and with the plan and buffers reused (steady, as in a study).\n\n\
                  Examples:\n  asperity bench surface --n 4096 --repeat 5\n  \
                  asperity bench bem-solve --n 512 --pressures 0.01,0.05 --repeat 3"
)]
pub struct BenchArgs {
    /// The kernel to time.
    pub kernel: Kernel,
    /// Grid size N (N×N).
    #[arg(long, default_value_t = 4096)]
    pub n: usize,
    /// Repetitions; the minimum and median of each figure are reported.
    #[arg(long, default_value_t = 5)]
    pub repeat: usize,
    /// Hurst exponent.
    #[arg(long, default_value_t = 0.8)]
    pub hurst: f64,
    /// bem-solve: mean pressures (units of E*), comma separated.
    #[arg(long, value_delimiter = ',', default_value = "0.01,0.05")]
    pub pressures: Vec<f64>,
    /// bem-solve: solver tolerance.
    #[arg(long, default_value_t = 1e-8)]
    pub tol: f64,
}

/// Minimum and median of some timings (seconds).
fn min_median(mut times: Vec<f64>) -> (f64, f64) {
    times.sort_by(f64::total_cmp);
    (times[0], times[times.len() / 2])
}

/// Runs `asperity bench`; prints one line
/// `kernel n threads cold_min_s cold_median_s steady_min_s steady_median_s`.
///
/// *Cold* is what a one-shot run pays: planning the FFTs, allocating the spectrum, work
/// and height buffers, and generating one surface (a new generator each repetition).
/// *Steady* is one more surface from a generator whose plans and buffers are reused, as in
/// a study that draws many realisations.
pub fn run(args: &BenchArgs) -> Result<()> {
    anyhow::ensure!(args.repeat > 0, "--repeat must be at least 1");
    if args.kernel == Kernel::BemSolve {
        return bem_solve(args);
    }
    let (mut cold, mut steady) = (Vec::new(), Vec::new());
    match args.kernel {
        Kernel::BemSolve => unreachable!("handled above"),
        Kernel::Surface => {
            let psd = Psd::new(args.hurst, LongWavelength::RollOff { q0: 6.0 }, None)?;
            let spec = SurfaceSpec::new(args.n, args.n, 1.0, psd, Normalisation::RmsSlope(1.0))?;
            for seed in 0..args.repeat as u64 {
                let start = Instant::now();
                let mut generator = SurfaceGenerator::new(&spec)?;
                let surface = generator.try_generate(seed)?;
                cold.push(start.elapsed().as_secs_f64());
                drop(surface);
                drop(generator);
            }
            let mut generator = SurfaceGenerator::new(&spec)?;
            let mut heights = vec![0.0; args.n * args.n];
            generator.generate_into(0, &mut heights)?; // first touch of the buffers
            for seed in 0..args.repeat as u64 {
                let start = Instant::now();
                generator.generate_into(seed, &mut heights)?;
                steady.push(start.elapsed().as_secs_f64());
            }
        }
    }
    let (cold_min, cold_median) = min_median(cold);
    let (steady_min, steady_median) = min_median(steady);
    println!(
        "kernel={:?} n={} threads={} cold_min_s={cold_min:.4} cold_median_s={cold_median:.4} \
         steady_min_s={steady_min:.4} steady_median_s={steady_median:.4}",
        args.kernel,
        args.n,
        rayon::current_num_threads(),
    );
    Ok(())
}

/// `asperity bench bem-solve`: one line per boundary, mean pressure and solver,
/// `kernel n threads boundary solver mean_pressure iterations operator_applications
/// area_fraction indentation solve_min_s solve_median_s fft_pair_s iteration_fft_pairs`.
/// Each repetition is a cold solve (the solver reset); `fft_pair_s` is the minimum time of
/// one operator application, `iteration_fft_pairs = solve_min_s / iterations / fft_pair_s`.
fn bem_solve(args: &BenchArgs) -> Result<()> {
    anyhow::ensure!(
        args.tol.is_finite() && args.tol > 0.0,
        "--tol must be positive and finite, got {}",
        args.tol
    );
    for &p in &args.pressures {
        anyhow::ensure!(
            p.is_finite() && p > 0.0,
            "--pressures must be positive, got {p}"
        );
    }
    let psd = Psd::new(args.hurst, LongWavelength::RollOff { q0: 6.0 }, None)?;
    let spec = SurfaceSpec::new(args.n, args.n, 1.0, psd, Normalisation::RmsSlope(1.0))?;
    let surface = SurfaceGenerator::new(&spec)?.try_generate(0)?;
    for boundary in [Boundary::Free, Boundary::Periodic] {
        let fft_pair = operator_time(args, boundary)?;
        let half_space = HalfSpace {
            modulus: 1.0,
            boundary,
        };
        for &pressure in &args.pressures {
            for solver in [SolverKind::PolonskyKeer, SolverKind::Bccg] {
                let params = SolverParams {
                    solver,
                    tolerance: args.tol,
                    ..SolverParams::default()
                };
                let mut contact = ContactSolver::new(&surface, half_space, params)?;
                let mut times = Vec::new();
                let mut last = None;
                for _ in 0..args.repeat {
                    contact.reset();
                    let start = Instant::now();
                    let solved = contact.solve(Control::MeanPressure(pressure))?;
                    times.push(start.elapsed().as_secs_f64());
                    last = Some(solved);
                }
                let (summary, info) = last.expect("repeat is at least 1");
                let (min, median) = min_median(times);
                println!(
                    "kernel=bem-solve n={} threads={} boundary={} solver={} mean_pressure={pressure} \
                     iterations={} operator_applications={} area_fraction={:.6} indentation={:.9e} \
                     solve_min_s={min:.4} solve_median_s={median:.4} fft_pair_s={fft_pair:.5} \
                     iteration_fft_pairs={:.2}",
                    args.n,
                    rayon::current_num_threads(),
                    boundary.name(),
                    solver.name(),
                    info.iterations,
                    info.operator_applications,
                    summary.area_fraction,
                    summary.indentation,
                    min / info.iterations.max(1) as f64 / fft_pair,
                );
            }
        }
    }
    Ok(())
}

/// Minimum time of one operator application on an N×N grid (plans and buffers reused).
fn operator_time(args: &BenchArgs, boundary: Boundary) -> Result<f64> {
    let mut operator = ElasticOperator::new(args.n, args.n, 1.0 / args.n as f64, 1.0, boundary)?;
    let pressure = vec![1.0; args.n * args.n];
    let mut displacement = vec![0.0; args.n * args.n];
    operator.apply(&pressure, &mut displacement); // first touch
    let times = (0..args.repeat.max(5))
        .map(|_| {
            let start = Instant::now();
            operator.apply(&pressure, &mut displacement);
            start.elapsed().as_secs_f64()
        })
        .collect();
    Ok(min_median(times).0)
}
