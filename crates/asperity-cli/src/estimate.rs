//! The up-front run time of a BEM study on this machine, before it starts (issue 7's
//! estimate; docs/bem.md, "Estimating a BEM study"): per-iteration costs measured at each
//! N on one thread, the iteration counts of a whole sample measured at two small probe
//! sizes for every H and carried to N by the power law through them. A study with a
//! Poisson's ratio adds the tangential CGs of every load (`k_x` and `k_y`, counted at the
//! probes and timed per iteration at N as the normal ones are). Used by `asperity study`,
//! `asperity reproduce` and `asperity bench bem-estimate`.

use std::time::Instant;

use anyhow::Result;
use asperity::bem::tangential::TangentialStiffness;
use asperity::bem::{ContactSolver, Control, HalfSpace, SolveError, SolverParams};
use asperity::elastic::Boundary;
use asperity::memory;
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

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

/// The counts of one study sample (seed 1): the 24 loads solved in turn with warm starts,
/// the stiffness after each, up to the first load past the sweep's end if any.
#[derive(Clone, Copy)]
struct SampleCounts {
    /// Solver iterations of the loads the BCCG solved.
    solve: f64,
    /// Operator applications of the loads solved directly (small contact sets, whose
    /// stiffness takes no CG iteration): each costs about a frozen-set CG iteration.
    direct: f64,
    /// Frozen-set CG iterations.
    cg: f64,
    /// Operator applications of the tangential CGs (`k_x` and `k_y`, their warm starts
    /// included; none without a Poisson's ratio).
    tangential: f64,
}

fn sample_iterations(n: usize, hurst: f64, study: &BemStudy) -> Result<SampleCounts> {
    let surface = study_surface(n, hurst, study.rolloff)?;
    let mut solver = ContactSolver::new(&surface, FREE, SolverParams::default())?;
    let mut tangential = (study.poisson)
        .map(|nu| TangentialStiffness::new(&solver, nu))
        .transpose()?;
    let mut counts = SampleCounts {
        solve: 0.0,
        direct: 0.0,
        cg: 0.0,
        tangential: 0.0,
    };
    for p in study_pressures(n) {
        let (summary, info) = solver.solve(Control::MeanPressure(p))?;
        let (_, stiffness) = solver.frozen_set_stiffness()?;
        if stiffness.iterations == 0 {
            counts.direct += info.operator_applications as f64;
        } else {
            counts.solve += info.iterations as f64;
        }
        counts.cg += stiffness.iterations as f64;
        if let Some(t) = tangential.as_mut() {
            let t = t.solve(&solver)?;
            counts.tangential +=
                (t.info_x.operator_applications + t.info_y.operator_applications) as f64;
        }
        if asperity::study::samplers::sweep_ends_after(study.sweep_end, summary.area_fraction) {
            break;
        }
    }
    Ok(counts)
}

/// Seconds per solver iteration and per frozen-set CG iteration on an `n × n` grid: solves
/// and stiffness CGs cut off after a few iterations (their `NoConvergence` carries the
/// count; one that converges earlier counts its own iterations), timed; the minimum of three.
/// The CG runs on the contact set of a loose solve at p̄ = 0.05 E* (about 10 % contact: a
/// set too large for the direct solve of small sets, whose loads cost next to nothing);
/// the solve is a step of a study's sweep, warm from the load below.
fn iteration_costs(n: usize) -> Result<(f64, f64)> {
    // The ratio of successive loads of a sample at N = 128 (24 loads from 0.05/N² to 0.2).
    const SWEEP_RATIO: f64 = 1.62;
    const CUT: usize = 12;
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
    // p̄ = 0.05 E* (about 10 % contact), higher on grids so small that its contact set is
    // solved directly (`bem/iterations/bccg/small_set.rs`: no CG iteration to time).
    let mut load = 0.05;
    solver.set_params(loose)?;
    while load < 0.4 {
        solver.reset();
        solver.solve(Control::MeanPressure(load))?;
        if solver.frozen_set_stiffness()?.1.iterations > 0 {
            break;
        }
        load *= 2.0;
    }
    let (mut solve, mut cg) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..3 {
        solver.set_params(loose)?;
        solver.reset();
        solver.solve(Control::MeanPressure(load))?;
        solver.set_params(cut)?;
        let start = Instant::now();
        let result = solver
            .frozen_set_stiffness()
            .map(|(_, info)| info.iterations);
        cg = cg.min(per_iteration(result, start)?);
        // A step of the study's sweep: a warm solve from the state below, with the
        // tangent of its stiffness.
        solver.set_params(loose)?;
        solver.reset();
        solver.solve(Control::MeanPressure(load / SWEEP_RATIO))?;
        solver.frozen_set_stiffness()?;
        solver.set_params(cut)?;
        let start = Instant::now();
        let result = solver
            .solve(Control::MeanPressure(load))
            .map(|(_, info)| info.iterations);
        solve = solve.min(per_iteration(result, start)?);
    }
    Ok((solve, cg))
}

/// Seconds per iteration of a tangential CG (Cerruti's operator, Poisson's ratio
/// `poisson`) on an `n × n` grid, as [`iteration_costs`] times the normal CG's: on the
/// contact set at p̄ = 0.05 E*, warm from the normal frozen-set solution as in a study,
/// cut off after a few iterations of `k_x`; the minimum of three.
fn tangential_iteration_cost(n: usize, poisson: f64) -> Result<f64> {
    const CUT: usize = 12;
    let surface = study_surface(n, 0.8, None)?;
    let loose = SolverParams {
        tolerance: 1e-4,
        ..SolverParams::default()
    };
    let mut solver = ContactSolver::new(&surface, FREE, loose)?;
    let mut tangential = TangentialStiffness::new(&solver, poisson)?;
    solver.solve(Control::MeanPressure(0.05))?;
    solver.frozen_set_stiffness()?;
    solver.set_params(SolverParams {
        stiffness_max_iterations: CUT,
        ..loose
    })?;
    let mut cost = f64::INFINITY;
    for _ in 0..3 {
        let start = Instant::now();
        let iterations = match tangential.solve(&solver) {
            Ok(t) => t.info_x.operator_applications + t.info_y.operator_applications,
            Err(SolveError::NoConvergence { iterations, .. }) => iterations,
            Err(e) => return Err(e.into()),
        };
        anyhow::ensure!(
            iterations > 0,
            "the tangential cost probe at N = {n} took no iteration"
        );
        cost = cost.min(start.elapsed().as_secs_f64() / iterations as f64);
    }
    Ok(cost)
}

/// The probe sizes for a study on grids up to `sizes`' largest: 32² and 64² (a second or
/// two per H) up to 256², 128² and 256² up to 512², 256² and 512² above (a few seconds per
/// H). The direct solve of small sets and the rings (512² and up) make the counts grow
/// more slowly with N than the small probes show: a 1024² sample (H = 1, 2026-11-24) was
/// estimated 2.12× too long from 64² and 128², 1.45× from 128² and 256², 1.14× from 256²
/// and 512²; a 512² sample 1.53× from 64² and 128², 1.13× from 128² and 256²
/// (docs/bem.md, "Estimating a BEM study").
///
/// An α study's sweep (`sweep_end`, near 10 % contact) starts at 64² and 128² instead: at
/// 32² it solves nearly every load directly (the small-set limit there is about 80 points,
/// 8 %), so the power law through 32² and 64² says nothing of larger grids. Measured on a
/// 256² α study (3 H × 8 samples, 5.9 s): estimated 49 s from 32² and 64², 5.7 s from 64²
/// and 128², 5.4 s from 128² and 256².
pub fn probes_for(sizes: &[usize], sweep_end: Option<f64>) -> (usize, usize) {
    match (sizes.iter().copied().max().unwrap_or(0), sweep_end) {
        (0..=256, None) => (32, 64),
        (0..=256, Some(_)) => (64, 128),
        (257..=512, _) => (128, 256),
        _ => (256, 512),
    }
}

/// `count(n)` from counts at two probe sizes by the power law through them (exponent
/// clamped at ≥ 0; a count below one, as of a sample that the direct solve of small sets
/// did whole, taken as one for it); the measured count at a probe size itself.
fn extrapolate(count: (f64, f64), probes: (usize, usize), n: usize) -> f64 {
    if n == probes.0 {
        return count.0;
    }
    let ratio = count.1.max(1.0) / count.0.max(1.0);
    let slope = (ratio.ln() / (probes.1 as f64 / probes.0 as f64).ln()).max(0.0);
    count.1 * (n as f64 / probes.1 as f64).powf(slope)
}

/// A duration for a person: seconds below 2 minutes, minutes below 2 hours, else hours.
pub fn human_duration(seconds: f64) -> String {
    let minutes = seconds / 60.0;
    if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else if minutes < 120.0 {
        format!("{minutes:.0} min")
    } else {
        format!("{:.1} h", minutes / 60.0)
    }
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
    /// The contact fraction past which a sample stops loading
    /// ([`asperity::study::StudySpec::sweep_end`]); `None`: every load.
    pub sweep_end: Option<f64>,
    /// Samples of `(N, H)` already checkpointed (not computed again), if any: see
    /// [`held_samples`].
    pub stored: &'a [HeldSamples],
    /// Poisson's ratio of a study that computes the tangential stiffness at every load
    /// ([`asperity::study::StudySpec::poisson`]), if any.
    pub poisson: Option<f64>,
}

/// Samples of one task of a study already in its checkpoints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeldSamples {
    /// Grid size.
    pub n: usize,
    /// Hurst exponent.
    pub hurst: f64,
    /// Samples stored (at most the study's count).
    pub samples: usize,
}

/// The estimate of the samples of the BEM study `spec` not yet stored in its folder `dir`
/// (its roll-off and sweep, at the probes of [`probes_for`]), with the number stored.
pub fn estimate_study(
    spec: &asperity::study::StudySpec,
    dir: &std::path::Path,
) -> Result<(StudyEstimate, usize)> {
    let stored = held_samples(dir, spec);
    let study = BemStudy {
        sizes: &spec.sizes,
        samples: spec.samples,
        hursts: &spec.hursts,
        rolloff: spec.rolloff,
        sweep_end: spec.sweep_end,
        stored: &stored,
        poisson: spec.poisson,
    };
    let estimate = estimate_bem_seconds(&study, probes_for(&spec.sizes, spec.sweep_end))?;
    Ok((estimate, stored.iter().map(|s| s.samples).sum()))
}

/// The samples of `spec`'s tasks already stored in the study folder `dir` (none when the
/// folder holds no study or another one: the estimate is then for the whole study).
pub fn held_samples(dir: &std::path::Path, spec: &asperity::study::StudySpec) -> Vec<HeldSamples> {
    let Ok(store) = asperity::study::StudyDir::read(dir) else {
        return Vec::new();
    };
    spec.tasks()
        .into_iter()
        .filter_map(|task| {
            let samples = store.samples_held(task, spec.samples).ok()?;
            Some(HeldSamples {
                n: task.n,
                hurst: task.hurst,
                samples,
            })
        })
        .collect()
}

impl BemStudy<'_> {
    /// Samples of `(n, hurst)` still to compute.
    fn samples_left(&self, n: usize, hurst: f64) -> usize {
        let stored = self
            .stored
            .iter()
            .find(|s| s.n == n && s.hurst == hurst)
            .map_or(0, |s| s.samples);
        self.samples.saturating_sub(stored)
    }
}

/// The estimate of one grid size (`asperity bench bem-estimate`).
pub struct SizeEstimate {
    pub n: usize,
    pub solve_iterations: f64,
    pub direct_applications: f64,
    pub cg_iterations: f64,
    /// Operator applications of the tangential CGs of one sample (0 without ν).
    pub tangential_applications: f64,
    pub solve_iteration_s: f64,
    pub cg_iteration_s: f64,
    /// Seconds per tangential CG iteration (0 without ν).
    pub tangential_iteration_s: f64,
    pub seconds: f64,
}

/// The estimated wall time of a BEM study on this machine, per N and in all.
pub struct StudyEstimate {
    pub per_size: Vec<SizeEstimate>,
    pub seconds: f64,
    pub lanes: usize,
}

/// The up-front estimate of a BEM study's wall time (`asperity bench bem-estimate`), iteration counts measured
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
        let small = sample_iterations(probes.0, hurst, study)?;
        let large = sample_iterations(probes.1, hurst, study)?;
        counts.push((small, large));
    }
    let mut per_size = Vec::with_capacity(study.sizes.len());
    for &n in study.sizes {
        let (c_solve, c_cg) = one_thread.install(|| iteration_costs(n))?;
        let c_tangential = match study.poisson {
            Some(nu) => one_thread.install(|| tangential_iteration_cost(n, nu))?,
            None => 0.0,
        };
        // Counts of one sample, summed over H; and seconds of the samples left per lane.
        let (mut solve, mut direct, mut cg, mut tangential, mut seconds) =
            (0.0, 0.0, 0.0, 0.0, 0.0);
        for (&hurst, (small, large)) in study.hursts.iter().zip(&counts) {
            let carried = |count: fn(&SampleCounts) -> f64| {
                extrapolate((count(small), count(large)), probes, n)
            };
            let (solve_h, direct_h, cg_h) = (
                carried(|c| c.solve),
                carried(|c| c.direct),
                carried(|c| c.cg),
            );
            let tangential_h = match study.poisson {
                Some(_) => carried(|c| c.tangential),
                None => 0.0,
            };
            let per_lane = study.samples_left(n, hurst).div_ceil(lanes) as f64;
            (solve, direct, cg) = (solve + solve_h, direct + direct_h, cg + cg_h);
            tangential += tangential_h;
            seconds += per_lane
                * (solve_h * c_solve + (direct_h + cg_h) * c_cg + tangential_h * c_tangential);
        }
        per_size.push(SizeEstimate {
            n,
            solve_iterations: solve,
            direct_applications: direct,
            cg_iterations: cg,
            tangential_applications: tangential,
            solve_iteration_s: c_solve,
            cg_iteration_s: c_cg,
            tangential_iteration_s: c_tangential,
            seconds,
        });
    }
    let seconds = per_size.iter().map(|s| s.seconds).sum();
    Ok(StudyEstimate {
        per_size,
        seconds,
        lanes,
    })
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
        // No iteration at the smaller probe (its sample solved directly): from one.
        assert!((extrapolate((0.0, 8.0), probes, 256) - 64.0).abs() < 1e-9);
        assert_eq!(extrapolate((0.0, 0.0), probes, 256), 0.0);
    }

    /// Issue 37: a study with a Poisson's ratio also solves `k_x` and `k_y` at every load;
    /// its estimate said 6 min for a run of about 15 before it counted them.
    #[test]
    fn the_estimate_grows_by_the_tangential_cgs_when_poisson_is_set() {
        let study = |poisson| BemStudy {
            sizes: &[64],
            samples: 2,
            hursts: &[0.8],
            rolloff: Some(4.0),
            sweep_end: None,
            stored: &[],
            poisson,
        };
        let plain = estimate_bem_seconds(&study(None), (32, 64)).unwrap();
        let with = estimate_bem_seconds(&study(Some(0.3)), (32, 64)).unwrap();
        let (p, t) = (&plain.per_size[0], &with.per_size[0]);
        assert_eq!(
            (p.tangential_applications, p.tangential_iteration_s),
            (0.0, 0.0)
        );
        // The normal counts are the same; each direction takes about the normal CG's
        // iterations, and the CGs of small sets that the normal stiffness solves directly.
        assert_eq!(
            (p.solve_iterations, p.direct_applications, p.cg_iterations),
            (t.solve_iterations, t.direct_applications, t.cg_iterations)
        );
        assert!(
            t.tangential_applications > t.cg_iterations,
            "{}",
            t.tangential_applications
        );
        assert!(t.tangential_iteration_s > 0.0);
        let per_lane = 2usize.div_ceil(with.lanes) as f64;
        let normal = per_lane
            * (t.solve_iterations * t.solve_iteration_s
                + (t.direct_applications + t.cg_iterations) * t.cg_iteration_s);
        let tangential = per_lane * t.tangential_applications * t.tangential_iteration_s;
        assert!((t.seconds - normal - tangential).abs() <= 1e-12 * t.seconds);
        assert!(t.seconds > normal && tangential > 0.0);
    }

    #[test]
    fn durations_read_in_the_unit_that_fits() {
        assert_eq!(human_duration(42.4), "42 s");
        assert_eq!(human_duration(418.3), "7 min");
        assert_eq!(human_duration(7199.0), "120 min");
        assert_eq!(human_duration(15103.0), "4.2 h");
    }

    #[test]
    fn larger_studies_probe_larger_grids() {
        assert_eq!(probes_for(&[64, 128], None), (32, 64));
        assert_eq!(probes_for(&[256], None), (32, 64));
        assert_eq!(probes_for(&[256], Some(0.08)), (64, 128));
        assert_eq!(probes_for(&[256, 512], None), (128, 256));
        assert_eq!(probes_for(&[256, 512], Some(0.08)), (128, 256));
        assert_eq!(probes_for(&[128, 1024], None), (256, 512));
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
