//! `asperity bench`: timings of the library's kernels, for side-by-side comparisons with
//! other tools (see `bench/` for the scripts that run the peers in the same session).

use std::time::Instant;

use anyhow::Result;
use asperity::elastic::{Boundary, ElasticOperator};
use asperity::fft::RealFft2;
use asperity::memory::{self, try_vec};
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

/// What to time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Kernel {
    /// Surface generation: one N×N realisation (spectrum, inverse real FFT, normalisation).
    Surface,
    /// The BEM's unit of cost: one forward + inverse real FFT pair of the padded grid
    /// (2N×2N for free boundaries, N×N periodic), and one application of the elastic
    /// operator (the pruned, fused convolution) for comparison.
    FftPair,
}

/// Arguments of `asperity bench`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "surface: prints the time with planning and buffer set-up (cold, what one\n\
                  `asperity surface` pays) and with the plan and buffers reused (steady, as in a study).\n\
                  fft-pair: prints the time of one padded forward + inverse real FFT pair and of one\n\
                  elastic operator application (plans and buffers reused), minimum and median.\n\n\
                  Examples:\n  asperity bench surface --n 4096 --repeat 5\n  \
                  asperity bench fft-pair --n 512 --boundary free --repeat 20"
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
    /// Hurst exponent (surface).
    #[arg(long, default_value_t = 0.8)]
    pub hurst: f64,
    /// Boundary conditions (fft-pair): free (the pair is of the 2N×2N padded grid) or
    /// periodic (N×N).
    #[arg(long, default_value = "free")]
    pub boundary: String,
}

/// Minimum and median of some timings (seconds).
fn min_median(mut times: Vec<f64>) -> (f64, f64) {
    times.sort_by(f64::total_cmp);
    (times[0], times[times.len() / 2])
}

/// Runs `asperity bench` (see [`time_surface`] and [`time_fft_pair`]).
pub fn run(args: &BenchArgs) -> Result<()> {
    anyhow::ensure!(args.repeat > 0, "--repeat must be at least 1");
    anyhow::ensure!(args.n > 0, "--n must be at least 1");
    match args.kernel {
        Kernel::Surface => time_surface(args),
        Kernel::FftPair => time_fft_pair(args),
    }
}

/// Prints one line
/// `kernel n threads cold_min_s cold_median_s steady_min_s steady_median_s`.
///
/// *Cold* is what a one-shot run pays: planning the FFTs, allocating the spectrum, work
/// and height buffers, and generating one surface (a new generator each repetition).
/// *Steady* is one more surface from a generator whose plans and buffers are reused, as in
/// a study that draws many realisations.
fn time_surface(args: &BenchArgs) -> Result<()> {
    let (mut cold, mut steady) = (Vec::new(), Vec::new());
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

/// Prints one line `kernel n boundary grid threads pair_min_s pair_median_s apply_min_s
/// apply_median_s apply_per_pair`.
///
/// *pair*: [`RealFft2::forward`] then [`RealFft2::inverse`] of the whole padded grid
/// (`2N × 2N` for free boundaries, `N × N` periodic), plans and buffers reused: the unit
/// in which the BEM's per-iteration cost is quoted (docs/bem.md). *apply*: one
/// [`ElasticOperator::apply`] of the `N × N` grid, which prunes the padding and fuses the
/// column passes; `apply_per_pair` is the ratio of the minima. One untimed warm-up each.
fn time_fft_pair(args: &BenchArgs) -> Result<()> {
    let boundary: Boundary = args.boundary.parse()?;
    let (n, side) = (args.n, args.n * boundary.padding());
    let padded = side
        .checked_mul(side)
        .ok_or_else(|| anyhow::anyhow!("--n {n} is too large for this machine"))?;
    let needed = memory::array_bytes(&[padded], 8)
        .zip(memory::array_bytes(&[side / 2 + 1, side], 16))
        .and_then(|(real, spectrum)| real.checked_add(spectrum))
        .zip(ElasticOperator::memory_bytes(n, n, boundary))
        .and_then(|(pair, operator)| pair.checked_add(operator));
    memory::ensure_fits(&format!("an FFT pair of a {side}x{side} grid"), needed)?;
    let mut fft = RealFft2::new(side, side)?;
    let input: Vec<f64> = (0..padded).map(|i| ((i * 7919) % 101) as f64).collect();
    let mut real = try_vec("the FFT pair's real grid", padded, 0.0)?;
    let mut spectrum = try_vec(
        "the FFT pair's spectrum",
        fft.spectrum_len(),
        Default::default(),
    )?;
    let mut pairs = Vec::with_capacity(args.repeat);
    for i in 0..=args.repeat {
        let start = Instant::now();
        fft.forward(&input, &mut spectrum);
        fft.inverse(&mut spectrum, &mut real);
        if i > 0 {
            pairs.push(start.elapsed().as_secs_f64());
        }
    }
    drop((fft, real, spectrum));
    let mut operator = ElasticOperator::new(n, n, 1.0 / n as f64, 1.0, boundary)?;
    let pressure: Vec<f64> = (0..n * n).map(|i| ((i * 7919) % 101) as f64).collect();
    let mut displacement = try_vec("the displacement", n * n, 0.0)?;
    let mut applies = Vec::with_capacity(args.repeat);
    for i in 0..=args.repeat {
        let start = Instant::now();
        operator.apply(&pressure, &mut displacement);
        if i > 0 {
            applies.push(start.elapsed().as_secs_f64());
        }
    }
    let (pair_min, pair_median) = min_median(pairs);
    let (apply_min, apply_median) = min_median(applies);
    println!(
        "kernel=FftPair n={n} boundary={} grid={side}x{side} threads={} \
         pair_min_s={pair_min:.6} pair_median_s={pair_median:.6} \
         apply_min_s={apply_min:.6} apply_median_s={apply_median:.6} \
         apply_per_pair={:.3}",
        boundary.name(),
        rayon::current_num_threads(),
        apply_min / pair_min,
    );
    Ok(())
}
