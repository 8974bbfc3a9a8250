//! `asperity bench`: timings of the library's kernels, for side-by-side comparisons with
//! other tools (see `bench/` for the scripts that run the peers in the same session).

use std::time::Instant;

use anyhow::{Context, Result};
use asperity::bem::{ContactSolver, Control, HalfSpace, SolveError, SolverKind, SolverParams};
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
    /// Up-front estimate of a BEM study's run time (the paper's full setting by default):
    /// measured cost per iteration at each N times iteration counts measured at small
    /// probe sizes and extrapolated in N (docs/bem.md, "Estimating a BEM study").
    BemEstimate,
    /// BEM solves: one cold solve of an N×N surface (H, roll-off 6, rms slope 1, seed 0) per
    /// mean pressure of --pressures, by each solver (pk, bccg), free and periodic, with the
    /// iterations, operator applications and the cost of an iteration in padded FFT pairs.
    BemSolve,
}

/// Arguments of `asperity bench`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "surface: prints the time with planning and buffer set-up (cold, what one\n\
                  `asperity surface` pays) and with the plan and buffers reused (steady, as in a study).\n\
                  fft-pair: prints the time of one padded forward + inverse real FFT pair and of one\n\
                  elastic operator application (plans and buffers reused), minimum and median.\n\
                  bem-estimate: prints, per N and in total, the estimated run time of a BEM study\n\
                  (free boundaries, 24 loads per sample, frozen-set stiffness at each).\n\
                  bem-solve: per boundary, pressure and solver, iterations, operator applications and\n\
                  the solve time, also in padded FFT pairs per iteration.\n\n\
                  Examples:\n  asperity bench surface --n 4096 --repeat 5\n  \
                  asperity bench fft-pair --n 512 --boundary free --repeat 20\n  \
                  asperity bench bem-estimate --sizes 256,512,1024 --samples 60 --hursts=-1:3:0.25\n  \
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
    /// Hurst exponent (surface).
    #[arg(long, default_value_t = 0.8)]
    pub hurst: f64,
    /// Boundary conditions (fft-pair): free (the pair is of the 2N×2N padded grid) or
    /// periodic (N×N).
    #[arg(long, default_value = "free")]
    pub boundary: String,
    /// Grid sizes N of the study (bem-estimate), comma-separated.
    #[arg(long, default_value = "1024")]
    pub sizes: String,
    /// Samples per (N, H) (bem-estimate).
    #[arg(long, default_value_t = 60)]
    pub samples: usize,
    /// Hurst exponents of the study (bem-estimate): values and ranges A:B:STEP.
    #[arg(long, default_value = "-1:3:0.25", allow_hyphen_values = true)]
    pub hursts: String,
    /// Roll-off q0·L/2π of the study's surfaces (bem-estimate); none by default, as in a
    /// study without `rolloff`.
    #[arg(long)]
    pub rolloff: Option<f64>,
    /// Two probe sizes at which iteration counts are measured (bem-estimate).
    #[arg(long, default_value = "64,128")]
    pub probes: String,
    /// Mean pressures in units of E* (bem-solve), comma separated.
    #[arg(long, value_delimiter = ',', default_value = "0.01,0.05")]
    pub pressures: Vec<f64>,
    /// Solver tolerance (bem-solve).
    #[arg(long, default_value_t = 1e-8)]
    pub tol: f64,
    /// Solvers to time (bem-solve), comma separated: pk, bccg.
    #[arg(long, value_delimiter = ',', default_value = "pk,bccg")]
    pub solvers: Vec<SolverKind>,
    /// Boundaries to time (bem-solve), comma separated: free, periodic.
    #[arg(long, value_delimiter = ',', default_value = "free,periodic")]
    pub boundaries: Vec<Boundary>,
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
        Kernel::BemEstimate => estimate_bem_study(args),
        Kernel::BemSolve => bem_solve(args),
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
    let pairs = fft_pair_times(n, boundary, args.repeat)?;
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

/// Times of `repeat` forward + inverse real FFT pairs of the padded grid (`2N × 2N` free,
/// `N × N` periodic) after one untimed warm-up, checked against the memory guard first.
fn fft_pair_times(n: usize, boundary: Boundary, repeat: usize) -> Result<Vec<f64>> {
    let side = n * boundary.padding();
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
    let mut pairs = Vec::with_capacity(repeat);
    for i in 0..=repeat {
        let start = Instant::now();
        fft.forward(&input, &mut spectrum);
        fft.inverse(&mut spectrum, &mut real);
        if i > 0 {
            pairs.push(start.elapsed().as_secs_f64());
        }
    }
    Ok(pairs)
}

/// Loads per sample and their range, as the study's BEM sampler
/// (`asperity::study::samplers`): 24 mean pressures log-spaced from `0.05/N²` to `0.2` E*.
fn study_pressures(n: usize) -> Vec<f64> {
    const LOADS: usize = 24;
    let (lo, hi) = (0.05 / (n * n) as f64, 0.2f64);
    asperity::fit::log_levels(lo, hi, LOADS).collect()
}

/// The study's surface of size `n` and Hurst exponent `hurst` (unit rms slope, L = 1).
fn study_surface(n: usize, hurst: f64, rolloff: Option<f64>) -> Result<asperity::surface::Surface> {
    let long = rolloff.map_or(LongWavelength::None, |q0| LongWavelength::RollOff { q0 });
    let psd = Psd::new(hurst, long, None)?;
    let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(1.0))?;
    Ok(SurfaceGenerator::new(&spec)?.try_generate(1)?)
}

const FREE: HalfSpace = HalfSpace {
    modulus: 1.0,
    boundary: Boundary::Free,
};

/// Solver and frozen-set CG iterations of one study sample (seed 1): the 24 loads solved in
/// turn with warm starts, the stiffness after each.
fn sample_iterations(n: usize, hurst: f64, rolloff: Option<f64>) -> Result<(f64, f64)> {
    let surface = study_surface(n, hurst, rolloff)?;
    let mut solver = ContactSolver::new(&surface, FREE, SolverParams::default())?;
    let (mut solve, mut cg) = (0usize, 0usize);
    for p in study_pressures(n) {
        let (_, info) = solver.solve(Control::MeanPressure(p))?;
        let (_, stiffness) = solver.frozen_set_stiffness()?;
        solve += info.iterations;
        cg += stiffness.iterations;
    }
    Ok((solve as f64, cg as f64))
}

/// Seconds per solver iteration and per frozen-set CG iteration on an `n × n` grid: solves
/// and stiffness CGs cut off after a few iterations (their `NoConvergence` carries the
/// count; one that converges earlier counts its own iterations), timed; the minimum of three.
/// The CG runs on the contact set of a loose solve at p̄ = 0.01 E* (a few percent contact).
fn iteration_costs(n: usize) -> Result<(f64, f64)> {
    const CUT: usize = 6;
    let surface = study_surface(n, 0.8, None)?;
    let mut solver = ContactSolver::new(&surface, FREE, SolverParams::default())?;
    let loose = SolverParams {
        tolerance: 1e-4,
        ..SolverParams::default()
    };
    let cut = SolverParams {
        max_iterations: CUT,
        stiffness_max_iterations: CUT,
        ..SolverParams::default()
    };
    let per_iteration = |result: std::result::Result<usize, SolveError>, start: Instant| {
        let iterations = match result {
            Ok(iterations) | Err(SolveError::NoConvergence { iterations, .. }) => iterations,
            Err(e) => return Err(anyhow::Error::from(e)),
        };
        anyhow::ensure!(
            iterations > 0,
            "the cost probe at N = {n} took no iteration"
        );
        Ok(start.elapsed().as_secs_f64() / iterations as f64)
    };
    let (mut solve, mut cg) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..3 {
        solver.set_params(loose)?;
        solver.reset();
        solver.solve(Control::MeanPressure(0.01))?;
        solver.set_params(cut)?;
        let start = Instant::now();
        let result = solver
            .frozen_set_stiffness()
            .map(|(_, info)| info.iterations);
        cg = cg.min(per_iteration(result, start)?);
        solver.reset();
        let start = Instant::now();
        let result = solver
            .solve(Control::MeanPressure(0.05))
            .map(|(_, info)| info.iterations);
        solve = solve.min(per_iteration(result, start)?);
    }
    Ok((solve, cg))
}

/// `count(n)` from counts at two probe sizes by the power law through them (exponent
/// clamped at ≥ 0); the measured count at a probe size itself.
fn extrapolate(count: (f64, f64), probes: (usize, usize), n: usize) -> f64 {
    if n == probes.0 {
        return count.0;
    }
    let slope = ((count.1 / count.0).ln() / (probes.1 as f64 / probes.0 as f64).ln()).max(0.0);
    count.1 * (n as f64 / probes.1 as f64).powf(slope)
}

fn parse_sizes(text: &str, flag: &str) -> Result<Vec<usize>> {
    text.split(',')
        .map(|s| {
            s.trim()
                .parse::<usize>()
                .ok()
                .filter(|&n| n >= 8)
                .with_context(|| format!("{flag} takes sizes of at least 8, got {s:?}"))
        })
        .collect()
}

/// Prints per N one line `n samples hursts lanes solve_iterations cg_iterations
/// solve_iteration_s cg_iteration_s seconds`, then `total_seconds` and `total_hours`.
///
/// Per (N, H) one sample costs `I_solve·c_solve(N) + I_cg·c_cg(N)`: the per-iteration costs
/// `c` are measured at each N on one thread ([`iteration_costs`], so they include everything
/// an iteration does on this machine), the iteration counts `I` of a whole 24-load sample are
/// measured at the two probe sizes for every H ([`sample_iterations`]) and carried to N by
/// the power law through them ([`extrapolate`]). A study runs its samples side by side, one
/// lane per thread (`study::run_task`), so a task of S samples takes `⌈S/lanes⌉` sample
/// times; total = Σ_N Σ_H ⌈S/lanes⌉ · sample time. Left out: the lanes' competition for
/// memory bandwidth (the estimate is low where it matters, at large N on many lanes),
/// surface generation and planning (< 1 %).
fn estimate_bem_study(args: &BenchArgs) -> Result<()> {
    anyhow::ensure!(args.samples > 0, "--samples must be at least 1");
    let sizes = parse_sizes(&args.sizes, "--sizes")?;
    let probes = parse_sizes(&args.probes, "--probes")?;
    let probes = match probes[..] {
        [a, b] if a < b => (a, b),
        _ => anyhow::bail!("--probes takes two increasing sizes, got {:?}", args.probes),
    };
    let hursts = crate::range::parse_range(&args.hursts)?;
    let study = BemStudy {
        sizes: &sizes,
        samples: args.samples,
        hursts: &hursts,
        rolloff: args.rolloff,
    };
    let estimate = estimate_bem_seconds(&study, probes)?;
    let lanes = estimate.lanes;
    for row in &estimate.per_size {
        println!(
            "n={} samples={} hursts={} lanes={lanes} solve_iterations={:.0} \
             cg_iterations={:.0} solve_iteration_s={:.3e} cg_iteration_s={:.3e} \
             seconds={:.3}",
            row.n,
            args.samples,
            hursts.len(),
            row.solve_iterations,
            row.cg_iterations,
            row.solve_iteration_s,
            row.cg_iteration_s,
            row.seconds,
        );
    }
    println!(
        "total_seconds={:.3} total_hours={:.2} lanes={lanes}",
        estimate.seconds,
        estimate.seconds / 3600.0
    );
    Ok(())
}

/// A BEM study to estimate: grids, samples per (N, H), H values and roll-off.
pub struct BemStudy<'a> {
    /// Grid sizes N.
    pub sizes: &'a [usize],
    /// Samples per (N, H).
    pub samples: usize,
    /// Hurst exponents.
    pub hursts: &'a [f64],
    /// Roll-off wavenumber q0 L/2π, if any.
    pub rolloff: Option<f64>,
}

/// The estimate of one grid size (see [`estimate_bem_study`]).
pub struct SizeEstimate {
    pub n: usize,
    pub solve_iterations: f64,
    pub cg_iterations: f64,
    pub solve_iteration_s: f64,
    pub cg_iteration_s: f64,
    pub seconds: f64,
}

/// The estimated wall time of a BEM study on this machine, per N and in all.
pub struct StudyEstimate {
    pub per_size: Vec<SizeEstimate>,
    pub seconds: f64,
    pub lanes: usize,
}

/// The up-front estimate of [`estimate_bem_study`] for `study`, iteration counts measured
/// at the two `probes` sizes.
pub fn estimate_bem_seconds(study: &BemStudy, probes: (usize, usize)) -> Result<StudyEstimate> {
    for n in study.sizes.iter().copied().chain([probes.0, probes.1]) {
        memory::ensure_fits(
            &format!("a BEM solver for a {n}x{n} grid"),
            ContactSolver::memory_bytes(n, n, Boundary::Free),
        )?;
    }
    let lanes = rayon::current_num_threads().max(1);
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut counts = Vec::with_capacity(study.hursts.len());
    for &hurst in study.hursts {
        let small = sample_iterations(probes.0, hurst, study.rolloff)?;
        let large = sample_iterations(probes.1, hurst, study.rolloff)?;
        counts.push(((small.0, large.0), (small.1, large.1)));
    }
    let samples_per_lane = study.samples.div_ceil(lanes) as f64;
    let mut per_size = Vec::with_capacity(study.sizes.len());
    for &n in study.sizes {
        let (c_solve, c_cg) = one_thread.install(|| iteration_costs(n))?;
        // Iterations of one sample per H, summed over H.
        let (solve, cg) = counts.iter().fold((0.0, 0.0), |(s, c), (solve, cg)| {
            (
                s + extrapolate(*solve, probes, n),
                c + extrapolate(*cg, probes, n),
            )
        });
        per_size.push(SizeEstimate {
            n,
            solve_iterations: solve,
            cg_iterations: cg,
            solve_iteration_s: c_solve,
            cg_iteration_s: c_cg,
            seconds: samples_per_lane * (solve * c_solve + cg * c_cg),
        });
    }
    let seconds = per_size.iter().map(|s| s.seconds).sum();
    Ok(StudyEstimate {
        per_size,
        seconds,
        lanes,
    })
}

/// `asperity bench bem-solve`: one line per boundary, mean pressure and solver,
/// `kernel n threads boundary solver mean_pressure iterations operator_applications
/// area_fraction indentation solve_min_s solve_median_s fft_pair_s iteration_fft_pairs`.
/// Each repetition is a cold solve (the solver reset); `fft_pair_s` is the minimum time of
/// one unpruned forward + inverse real FFT pair of the padded grid (as `fft-pair`), and
/// `iteration_fft_pairs = solve_min_s / iterations / fft_pair_s`.
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
    for &boundary in &args.boundaries {
        let fft_pair = min_median(fft_pair_times(args.n, boundary, args.repeat.max(5))?).0;
        let half_space = HalfSpace {
            modulus: 1.0,
            boundary,
        };
        for &pressure in &args.pressures {
            for &solver in &args.solvers {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extrapolation_is_the_power_law_through_the_probes() {
        let probes = (64, 128);
        // Doubling per doubling of N: exponent 1.
        assert_eq!(extrapolate((10.0, 20.0), probes, 64), 10.0);
        assert!((extrapolate((10.0, 20.0), probes, 128) - 20.0).abs() < 1e-12);
        assert!((extrapolate((10.0, 20.0), probes, 1024) - 160.0).abs() < 1e-9);
        // ×1.45 per doubling (Polonsky–Keer's growth): 1.45³ from 128 to 1024.
        let grown = extrapolate((100.0, 145.0), probes, 1024);
        assert!((grown - 145.0 * 1.45f64.powi(3)).abs() < 1e-9, "{grown}");
        // Fewer iterations at the larger probe: held flat, never extrapolated down.
        assert_eq!(extrapolate((30.0, 20.0), probes, 1024), 20.0);
    }

    #[test]
    fn study_pressures_span_the_samplers_range() {
        for n in [16, 256, 1024] {
            let p = study_pressures(n);
            assert_eq!(p.len(), 24);
            assert!((p[0] / (0.05 / (n * n) as f64) - 1.0).abs() < 1e-12);
            assert!((p[23] / 0.2 - 1.0).abs() < 1e-12);
            let ratio = p[1] / p[0];
            assert!(p
                .windows(2)
                .all(|w| (w[1] / w[0] / ratio - 1.0).abs() < 1e-9));
        }
    }
}
