//! `asperity bench`: timings of the library's kernels, for side-by-side comparisons with
//! other tools (see `bench/` for the scripts that run the peers in the same session).

use std::time::Instant;

use anyhow::{Context, Result};
use asperity::bem::{ContactSolver, Control, HalfSpace, SolverKind, SolverParams};
use asperity::elastic::{Boundary, ElasticOperator};
use asperity::fft::RealFft2;
use asperity::memory::{self, try_vec};
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

use crate::estimate::{estimate_bem_seconds, BemStudy};

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
    /// BEM solves: one cold solve of an N×N surface (H, roll-off 6, rms slope 1, seed of
    /// --seed) per mean pressure of --pressures, by each solver (pk, bccg), free and periodic,
    /// with the iterations, operator applications and the cost of an iteration in padded FFT
    /// pairs; after each solve its frozen-set stiffness, by the default CG and all in double
    /// precision, in CPU seconds against the solve's.
    BemSolve,
    /// The tangential frozen-set stiffness against the normal one: on the solved states of
    /// an N×N surface (H, roll-off --rolloff or 4, rms slope 1, seed of --seed, free
    /// boundaries) at each mean pressure of --pressures, the normal frozen-set CG, then `k_x`
    /// alone, `k_y` alone and both, all in double precision (`f64`) and with the
    /// single-precision iterations (`mixed`, the default), interleaved in rotating order,
    /// --repeat rounds, in CPU seconds of the process.
    Tangential,
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
                  the solve time, also in padded FFT pairs per iteration; then (kernel=bem-stiffness)\n\
                  the frozen-set stiffness after it, mixed and f64, in CPU seconds over the solve's.\n\
                  tangential: per mean pressure and solve (normal; x, y, both in f64 and mixed), the\n\
                  operator applications and the CPU seconds (median, min, max over --repeat rounds).\n\n\
                  Examples:\n  asperity bench surface --n 4096 --repeat 5\n  \
                  asperity bench fft-pair --n 512 --boundary free --repeat 20\n  \
                  asperity bench bem-estimate --sizes 256,512,1024 --samples 60 --hursts=-1:3:0.25\n  \
                  asperity bench bem-solve --n 512 --pressures 0.01,0.05 --repeat 3\n  \
                  asperity bench tangential --n 512 --pressures 0.005,0.02,0.08 --repeat 5"
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
    /// study without `rolloff`. The surface's (tangential): 4 by default.
    #[arg(long)]
    pub rolloff: Option<f64>,
    /// Estimate a study that solves every load (`study curve`, `study alpha --full-sweep`)
    /// instead of an α study's sweep, which ends past its fit windows (bem-estimate).
    #[arg(long)]
    pub full_sweep: bool,
    /// Two probe sizes at which iteration counts are measured (bem-estimate); by default
    /// those a study on `--sizes` uses (32,64 up to 256; 128,256 up to 512; 256,512 above).
    #[arg(long)]
    pub probes: Option<String>,
    /// Poisson's ratio of a study that also computes the tangential stiffness at every load
    /// (`study curve --poisson`; bem-estimate): adds its CGs to the estimate; the kernel's ν
    /// (tangential; 0.3 if not given).
    #[arg(long, value_name = "NU")]
    pub poisson: Option<f64>,
    /// Mean pressures in units of E* (bem-solve, tangential), comma separated.
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
    /// Seed of the surface (bem-solve, tangential): the surface of `asperity surface --seed` with the same
    /// N, H, roll-off 6 and rms slope 1.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
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
        Kernel::Tangential => tangential(args),
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

/// Prints per N one line `n samples hursts lanes solve_iterations direct_applications
/// cg_iterations tangential_applications solve_iteration_s cg_iteration_s
/// tangential_iteration_s seconds` (the tangential ones 0 without `--poisson`), then `total_seconds`,
/// `total_hours`, `lanes` and, for an α study's sweep, `sweep_end`.
///
/// Per (N, H) one sample costs `I_solve·c_solve(N) + (A_direct + I_cg)·c_cg(N)` (`A_direct`
/// the operator applications of the loads solved directly): the per-iteration costs
/// `c` are measured at each N on one thread ([`crate::estimate`], so they include everything
/// an iteration does on this machine), the iteration counts `I` of a whole sample (the
/// loads of `study alpha`'s sweep, or all 24 with `--full-sweep`) are measured at the two
/// probe sizes for every H and carried to N by the power law through them. A study runs its samples side by side, one
/// lane per thread (`study::run_task`), so a task of S samples takes `⌈S/lanes⌉` sample
/// times; total = Σ_N Σ_H ⌈S/lanes⌉ · sample time. Left out: the lanes' competition for
/// memory bandwidth (the estimate is low where it matters, at large N on many lanes),
/// surface generation and planning (< 1 %).
fn estimate_bem_study(args: &BenchArgs) -> Result<()> {
    anyhow::ensure!(args.samples > 0, "--samples must be at least 1");
    let sizes = parse_sizes(&args.sizes, "--sizes")?;
    let hursts = asperity_app::range::parse_range(&args.hursts)?;
    // The sweep of `study alpha` with its default window on these grids.
    let alpha = asperity::study::StudySpec {
        method: asperity::study::Method::Bem,
        sizes: sizes.clone(),
        hursts: hursts.clone(),
        samples: args.samples,
        rolloff: args.rolloff,
        seed: 1,
        window: asperity::study::FitWindow::default(),
        levels: asperity::study::DEFAULT_LEVELS,
        sweep_end: None,
        poisson: None,
        tangential: Default::default(),
    }
    .with_alpha_sweep();
    let sweep_end = alpha.sweep_end.filter(|_| !args.full_sweep);
    let probes = match &args.probes {
        None => crate::estimate::probes_for(&sizes, sweep_end),
        Some(text) => match parse_sizes(text, "--probes")?[..] {
            [a, b] if a < b => (a, b),
            _ => anyhow::bail!("--probes takes two increasing sizes, got {text:?}"),
        },
    };
    let study = BemStudy {
        sizes: &sizes,
        samples: args.samples,
        hursts: &hursts,
        rolloff: args.rolloff,
        sweep_end,
        stored: &[],
        poisson: args.poisson,
    };
    let estimate = estimate_bem_seconds(&study, probes)?;
    let lanes = estimate.lanes;
    for row in &estimate.per_size {
        println!(
            "n={} samples={} hursts={} lanes={lanes} solve_iterations={:.0} \
             direct_applications={:.0} cg_iterations={:.0} tangential_applications={:.0} \
             solve_iteration_s={:.3e} cg_iteration_s={:.3e} tangential_iteration_s={:.3e} \
             seconds={:.3}",
            row.n,
            args.samples,
            hursts.len(),
            row.solve_iterations,
            row.direct_applications,
            row.cg_iterations,
            row.tangential_applications,
            row.solve_iteration_s,
            row.cg_iteration_s,
            row.tangential_iteration_s,
            row.seconds,
        );
    }
    let sweep = sweep_end.map_or(String::new(), |end| format!(" sweep_end={end}"));
    println!(
        "total_seconds={:.3} total_hours={:.2} lanes={lanes}{sweep}",
        estimate.seconds,
        estimate.seconds / 3600.0
    );
    Ok(())
}

/// `asperity bench bem-solve`: one line per boundary, mean pressure and solver,
/// `kernel n seed threads boundary solver mean_pressure iterations operator_applications
/// energy_transforms area_fraction indentation solve_min_s solve_median_s fft_pair_s iteration_fft_pairs
/// padded_fft_pair_s iteration_padded_pairs`.
/// Each repetition is a cold solve (the solver reset); `fft_pair_s` is the minimum time of
/// one unpruned forward + inverse real FFT pair of the boundary's own grid (as `fft-pair`:
/// 2N×2N free, N×N periodic), `iteration_fft_pairs = solve_min_s / iterations /
/// fft_pair_s`; `padded_fft_pair_s` is that of the 2N×2N grid whatever the boundary (issue
/// 10's unit of cost), and `iteration_padded_pairs` the iteration in it.
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
    let surface = SurfaceGenerator::new(&spec)?.try_generate(args.seed)?;
    let pair_of = |boundary| -> Result<f64> {
        Ok(min_median(fft_pair_times(args.n, boundary, args.repeat.max(5))?).0)
    };
    let padded_pair = pair_of(Boundary::Free)?;
    for &boundary in &args.boundaries {
        let fft_pair = match boundary {
            Boundary::Free => padded_pair,
            Boundary::Periodic => pair_of(boundary)?,
        };
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
                let mut stiffness = StiffnessTimes::default();
                for round in 0..args.repeat {
                    contact.reset();
                    let (start, cpu) = (Instant::now(), cpu_seconds());
                    let solved = contact.solve(Control::MeanPressure(pressure))?;
                    times.push(start.elapsed().as_secs_f64());
                    stiffness.solve_cpu.push(cpu_seconds() - cpu);
                    last = Some(solved);
                    stiffness.time(&mut contact, round)?;
                }
                let (summary, info) = last.expect("repeat is at least 1");
                let (min, median) = min_median(times);
                println!(
                    "kernel=bem-solve n={} seed={} threads={} boundary={} solver={} mean_pressure={pressure} \
                     iterations={} operator_applications={} energy_transforms={} area_fraction={:.6} indentation={:.9e} \
                     solve_min_s={min:.4} solve_median_s={median:.4} fft_pair_s={fft_pair:.5} \
                     iteration_fft_pairs={:.2} padded_fft_pair_s={padded_pair:.5} \
                     iteration_padded_pairs={:.2}",
                    args.n,
                    args.seed,
                    rayon::current_num_threads(),
                    boundary.name(),
                    solver.name(),
                    info.iterations,
                    info.operator_applications,
                    info.energy_transforms,
                    summary.area_fraction,
                    summary.indentation,
                    min / info.iterations.max(1) as f64 / fft_pair,
                    min / info.iterations.max(1) as f64 / padded_pair,
                );
                stiffness.print(args, boundary, pressure);
            }
        }
    }
    Ok(())
}

/// `bench bem-solve`'s frozen-set stiffness after each cold solve, by the default CG (a
/// single-precision pass refined in double on large grids, `mixed`) and all in double
/// precision (`f64`), in alternating order: CPU seconds of the process (and of the solves),
/// the last applications and stiffnesses.
#[derive(Default)]
struct StiffnessTimes {
    solve_cpu: Vec<f64>,
    cpu: [Vec<f64>; 2],
    applications: [usize; 2],
    k: [f64; 2],
}

impl StiffnessTimes {
    /// Times both stiffnesses of `contact`'s solved state, `mixed` first in even rounds.
    fn time(&mut self, contact: &mut ContactSolver, round: usize) -> Result<()> {
        for which in [round % 2, 1 - round % 2] {
            contact.set_single_precision_stiffness(which == 0);
            let cpu = cpu_seconds();
            let (k, info) = contact.frozen_set_stiffness()?;
            self.cpu[which].push(cpu_seconds() - cpu);
            (self.k[which], self.applications[which]) = (k, info.operator_applications);
        }
        contact.set_single_precision_stiffness(true);
        Ok(())
    }

    /// One line: the solve's CPU time, each stiffness's applications and CPU time (minimum
    /// over the rounds) and its ratio to the solve's, and the two stiffnesses' difference.
    fn print(&mut self, args: &BenchArgs, boundary: Boundary, pressure: f64) {
        let solve = median_spread(&mut self.solve_cpu).1;
        let [mixed, double] = [0, 1].map(|i| median_spread(&mut self.cpu[i]).1);
        println!(
            "kernel=bem-stiffness n={} seed={} threads={} boundary={} mean_pressure={pressure} \
             solve_cpu_min_s={solve:.4} mixed_applications={} mixed_cpu_min_s={mixed:.4} \
             mixed_over_solve={:.3} f64_applications={} f64_cpu_min_s={double:.4} \
             f64_over_solve={:.3} mixed_vs_f64_relative={:.2e}",
            args.n,
            args.seed,
            rayon::current_num_threads(),
            boundary.name(),
            self.applications[0],
            mixed / solve,
            self.applications[1],
            double / solve,
            (self.k[0] / self.k[1] - 1.0).abs(),
        );
    }
}

/// CPU seconds of this process, all threads (`CLOCK_PROCESS_CPUTIME_ID`): on a shared
/// machine the steadier measure of a computation's cost than the wall clock.
#[cfg(unix)]
fn cpu_seconds() -> f64 {
    let mut now = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `now` is a valid timespec for the call to write.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut now) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_PROCESS_CPUTIME_ID) failed");
    now.tv_sec as f64 + now.tv_nsec as f64 * 1e-9
}

/// The wall clock where there is no process CPU clock.
#[cfg(not(unix))]
fn cpu_seconds() -> f64 {
    use std::sync::OnceLock;
    static ORIGIN: OnceLock<Instant> = OnceLock::new();
    ORIGIN.get_or_init(Instant::now).elapsed().as_secs_f64()
}

/// The solves `bench tangential` times after the normal one, in rotating order: which
/// directions, in single precision (`mixed`) or not.
const TANGENTIAL_SOLVES: [(&str, bool); 6] = [
    ("x", false),
    ("y", false),
    ("both", false),
    ("x", true),
    ("y", true),
    ("both", true),
];

/// `asperity bench tangential`: one line per mean pressure and solve, `kernel n seed
/// threads mean_pressure area_fraction solve precision applications stiffness_ratio
/// cpu_median_s cpu_min_s cpu_max_s median_over_normal`, and after each pressure the
/// largest relative difference between the `f64` and the `mixed` stiffnesses. Each round
/// times the normal frozen-set CG first (its solution is the tangential CGs' start), then
/// the six tangential solves, the first of them one further in every round;
/// `stiffness_ratio` is `k/k_n` (`both`: `(k_x + k_y)/(2 k_n)`), `applications` the
/// operator applications (`both`: `x+y`).
fn tangential(args: &BenchArgs) -> Result<()> {
    use asperity::bem::tangential::TangentialStiffness;
    let poisson = args.poisson.unwrap_or(0.3);
    for &p in &args.pressures {
        anyhow::ensure!(
            p.is_finite() && p > 0.0,
            "--pressures must be positive, got {p}"
        );
    }
    let mut solver = tangential_surface_solver(args)?;
    let mut double = TangentialStiffness::new(&solver, poisson)?.with_single_precision(false);
    let mut mixed = TangentialStiffness::new(&solver, poisson)?;
    for &pressure in &args.pressures {
        let (summary, _) = solver.solve(Control::MeanPressure(pressure))?;
        let mut normal = (Vec::new(), 0, 0.0);
        let mut solves = [(); 6].map(|_| (Vec::new(), String::new(), 0.0));
        for round in 0..args.repeat {
            let cpu = cpu_seconds();
            let (k_n, info) = solver.frozen_set_stiffness()?;
            normal.0.push(cpu_seconds() - cpu);
            (normal.1, normal.2) = (info.operator_applications, k_n);
            for v in 0..TANGENTIAL_SOLVES.len() {
                let which = (round + v) % TANGENTIAL_SOLVES.len();
                let (what, single) = TANGENTIAL_SOLVES[which];
                let operators = if single { &mut mixed } else { &mut double };
                let cpu = cpu_seconds();
                let (k, applications) = tangential_solve(operators, &solver, what)?;
                solves[which].0.push(cpu_seconds() - cpu);
                (solves[which].1, solves[which].2) = (applications, k);
            }
        }
        let (k_n, normal_median) = (normal.2, median_spread(&mut normal.0).0);
        let line = |solve: &str,
                    precision: &str,
                    applications: &str,
                    k: f64,
                    times: &mut Vec<f64>| {
            let (median, min, max) = median_spread(times);
            println!(
                "kernel=tangential n={} seed={} threads={} mean_pressure={pressure} \
                 area_fraction={:.4} solve={solve} precision={precision} applications={applications} \
                 stiffness_ratio={:.6} cpu_median_s={median:.4} cpu_min_s={min:.4} cpu_max_s={max:.4} \
                 median_over_normal={:.3}",
                args.n,
                args.seed,
                rayon::current_num_threads(),
                summary.area_fraction,
                k / k_n,
                median / normal_median,
            );
        };
        line("normal", "f64", &normal.1.to_string(), k_n, &mut normal.0);
        for (i, (times, applications, k)) in solves.iter_mut().enumerate() {
            let (what, single) = TANGENTIAL_SOLVES[i];
            line(
                what,
                if single { "mixed" } else { "f64" },
                applications,
                *k,
                times,
            );
        }
        let agree = (0..3)
            .map(|i| (solves[i + 3].2 / solves[i].2 - 1.0).abs())
            .fold(0.0f64, f64::max);
        println!(
            "kernel=tangential n={} mean_pressure={pressure} mixed_vs_f64_max_relative={agree:.2e}",
            args.n
        );
    }
    Ok(())
}

/// `bench tangential`'s surface (H, roll-off 4 unless given, unit rms slope, the seed) on a
/// free half-space with E* = 1, in a contact solver with the default parameters.
fn tangential_surface_solver(args: &BenchArgs) -> Result<ContactSolver> {
    let rolloff = LongWavelength::RollOff {
        q0: args.rolloff.unwrap_or(4.0),
    };
    let psd = Psd::new(args.hurst, rolloff, None)?;
    let spec = SurfaceSpec::new(args.n, args.n, 1.0, psd, Normalisation::RmsSlope(1.0))?;
    let surface = SurfaceGenerator::new(&spec)?.try_generate(args.seed)?;
    let half_space = HalfSpace {
        modulus: 1.0,
        boundary: Boundary::Free,
    };
    Ok(ContactSolver::new(
        &surface,
        half_space,
        SolverParams::default(),
    )?)
}

/// One of `bench tangential`'s solves (`x`, `y` or `both`): the stiffness (`both`: the mean
/// of `k_x` and `k_y`) and the operator applications (`both`: `x+y`).
fn tangential_solve(
    operators: &mut asperity::bem::tangential::TangentialStiffness,
    solver: &ContactSolver,
    what: &str,
) -> Result<(f64, String)> {
    use asperity::elastic::Direction;
    Ok(match what {
        "x" | "y" => {
            let d = if what == "x" {
                Direction::X
            } else {
                Direction::Y
            };
            let (k, info) = operators.solve_along(solver, d)?;
            (k, info.operator_applications.to_string())
        }
        _ => {
            let t = operators.solve(solver)?;
            let a = t.info_x.operator_applications;
            (
                0.5 * (t.x + t.y),
                format!("{a}+{}", t.info_y.operator_applications),
            )
        }
    })
}

/// Median, minimum and maximum of some timings (seconds).
fn median_spread(times: &mut [f64]) -> (f64, f64, f64) {
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], times[0], times[times.len() - 1])
}
