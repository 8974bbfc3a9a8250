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
#[command(
    after_help = "Prints the time with planning and buffer set-up (cold, what one `asperity surface`\n\
                  pays) and with the plan and buffers reused (steady, as in a study).\n\n\
                  Example:\n  asperity bench surface --n 4096 --repeat 5"
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
    let (mut cold, mut steady) = (Vec::new(), Vec::new());
    match args.kernel {
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
