//! `asperity bench`: timings of the library's kernels, for side-by-side comparisons with
//! other tools (see `bench/` for the scripts that run the peers in the same session).

use std::time::Instant;

use anyhow::Result;
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

/// What to time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Kernel {
    /// Surface generation: one N×N realisation (spectrum, inverse real FFT, normalisation).
    Surface,
}

/// Arguments of `asperity bench`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Example:\n  asperity bench surface --n 4096 --repeat 5")]
pub struct BenchArgs {
    /// The kernel to time.
    pub kernel: Kernel,
    /// Grid size N (N×N).
    #[arg(long, default_value_t = 4096)]
    pub n: usize,
    /// Repetitions; the minimum and median are reported.
    #[arg(long, default_value_t = 5)]
    pub repeat: usize,
    /// Hurst exponent.
    #[arg(long, default_value_t = 0.8)]
    pub hurst: f64,
}

/// Runs `asperity bench`; prints one line `kernel n threads min_s median_s`.
pub fn run(args: &BenchArgs) -> Result<()> {
    anyhow::ensure!(args.repeat > 0, "--repeat must be at least 1");
    let mut times = Vec::with_capacity(args.repeat);
    match args.kernel {
        Kernel::Surface => {
            let psd = Psd::new(args.hurst, LongWavelength::RollOff { q0: 6.0 }, None)?;
            let spec = SurfaceSpec::new(args.n, args.n, 1.0, psd, Normalisation::RmsSlope(1.0))?;
            let plan_start = Instant::now();
            let mut generator = SurfaceGenerator::new(&spec)?;
            let plan = plan_start.elapsed().as_secs_f64();
            let mut heights = vec![0.0; args.n * args.n];
            for seed in 0..args.repeat as u64 {
                let start = Instant::now();
                generator.generate_into(seed, &mut heights)?;
                times.push(start.elapsed().as_secs_f64());
            }
            eprintln!("planning (once per grid size): {plan:.4} s");
        }
    }
    times.sort_by(f64::total_cmp);
    println!(
        "kernel={:?} n={} threads={} min_s={:.4} median_s={:.4}",
        args.kernel,
        args.n,
        rayon::current_num_threads(),
        times[0],
        times[times.len() / 2]
    );
    Ok(())
}
