//! Persson's pressure–separation law against the periodic BEM (docs/persson.md): generates
//! rough surfaces with a roll-off and a short-wavelength cut-off, solves the periodic contact
//! at log-spaced mean pressures, records the BEM's mean gap (the mean interfacial separation
//! ū of Persson's theory: with periodic boundaries the displacement has zero mean, so
//! `mean(gap)` is the separation of the two mean planes), its contact fraction and its
//! frozen-set stiffness, and writes them beside Persson's predictions from the same
//! surface's PSD.
//!
//! `cargo run --release -p asperity --example persson_gap -- OUT.csv [N,N,… [SEEDS
//! [ROLLOFF CUTOFF]]]` (default grids 256,512, 8 seeds). Surfaces: H = 0.3 and 0.8, roll-off
//! q_r L/2π = 4, cut-off q_s L/2π = 64 unless given (λ_s = L/64: 4 pixels on 256², 8 on
//! 512², 16 on 1024²; e.g. `1024 4 16 256` keeps λ_r/λ_s = 16 at L/λ_r = 16), unit rms
//! slope (forward differences), L = 1, E* = 1; loads p/E* = 10⁻⁴ … 10⁻¹ (19 points).
//! Columns: n, hurst, seed, pressure, area_bem, gap_bem, stiffness_bem (K = k/A₀, A₀ = 1),
//! iterations, area_persson (κ = √(8/π)), gap_persson and stiffness_persson (γ = 0.45),
//! u0_per_gamma = u₀/γ = √π∫dq q²C w (γ-free), rms_height (spectral), rms_gradient
//! (spectral ḡ). Persson's ū is linear in γ only at low load, so gap_persson is for γ = 0.45.

use std::error::Error;
use std::fmt::Write as _;

use asperity::bem::sweep::{sweep, SweepParams};
use asperity::bem::{ContactSolver, Control, HalfSpace, SolverParams};
use asperity::elastic::Boundary;
use asperity::persson::{Persson, PerssonParams};
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

type Res<T> = Result<T, Box<dyn Error>>;

const HURSTS: [f64; 2] = [0.3, 0.8];
/// The default roll-off `q_r L/2π` and cut-off `q_s L/2π`.
const SPECTRUM: Spectrum = Spectrum {
    rolloff: 4.0,
    cutoff: 64.0,
};
const LOADS: usize = 19;

/// The spectrum's roll-off `q_r L/2π` and short-wavelength cut-off `q_s L/2π`.
#[derive(Clone, Copy)]
struct Spectrum {
    rolloff: f64,
    cutoff: f64,
}
/// Takes each load's mean gap.
struct Gaps(Vec<f64>);

impl asperity::bem::sweep::SweepObserver for Gaps {
    type Error = std::convert::Infallible;

    fn solved(&mut self, _load: usize, solver: &ContactSolver) -> Result<(), Self::Error> {
        self.0.push(solver.gap().mean().unwrap_or(f64::NAN));
        Ok(())
    }
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let out = args
        .get(1)
        .ok_or("usage: persson_gap OUT.csv [N,N,… [SEEDS]]")?;
    let grids: Vec<usize> = match args.get(2) {
        Some(list) => list.split(',').map(str::parse).collect::<Result<_, _>>()?,
        None => vec![256, 512],
    };
    let seeds: u64 = args.get(3).map_or(Ok(8), |s| s.parse())?;
    let spectrum = match (args.get(4), args.get(5)) {
        (Some(rolloff), Some(cutoff)) => Spectrum {
            rolloff: rolloff.parse()?,
            cutoff: cutoff.parse()?,
        },
        _ => SPECTRUM,
    };
    let loads: Vec<f64> = (0..LOADS)
        .map(|i| 10f64.powf(-4.0 + 3.0 * i as f64 / (LOADS - 1) as f64))
        .collect();
    let mut csv = String::from(
        "n,hurst,seed,pressure,area_bem,gap_bem,stiffness_bem,iterations,area_persson,gap_persson,stiffness_persson,u0_per_gamma,rms_height,rms_gradient\n",
    );
    for &n in &grids {
        for hurst in HURSTS {
            for seed in 1..=seeds {
                eprintln!("N = {n}, H = {hurst}, seed {seed}");
                one_surface(&mut csv, (n, hurst, seed), spectrum, &loads)?;
            }
        }
    }
    let tmp = format!("{out}.tmp");
    std::fs::write(&tmp, csv)?;
    std::fs::rename(tmp, out)?;
    Ok(())
}

fn one_surface(
    csv: &mut String,
    (n, hurst, seed): (usize, f64, u64),
    spectrum: Spectrum,
    loads: &[f64],
) -> Res<()> {
    let long = LongWavelength::RollOff {
        q0: spectrum.rolloff,
    };
    let psd = Psd::new(hurst, long, Some(spectrum.cutoff))?;
    let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(1.0))?;
    let surface = SurfaceGenerator::new(&spec)?.try_generate(seed)?;
    let theory = Persson::from_surface(&surface, PerssonParams::default())?;
    let half_space = HalfSpace {
        modulus: 1.0,
        boundary: Boundary::Periodic,
    };
    let mut solver = ContactSolver::new(&surface, half_space, SolverParams::default())?;
    let controls: Vec<Control> = loads.iter().map(|&p| Control::MeanPressure(p)).collect();
    let mut gaps = Gaps(Vec::with_capacity(loads.len()));
    let rows = sweep(&mut solver, &controls, SweepParams::default(), &mut gaps)
        .map_err(|e| format!("N = {n}, H = {hurst}, seed {seed}: {e}"))?;
    let u0_per_gamma = theory.u0() / theory.params().gamma;
    for (row, &gap) in rows.iter().zip(&gaps.0) {
        let p = row.summary.mean_pressure;
        let point = theory.predict(p)?;
        writeln!(
            csv,
            "{n},{hurst},{seed},{p:e},{:e},{gap:e},{:e},{},{:e},{:e},{:e},{u0_per_gamma:e},{:e},{:e}",
            row.summary.area_fraction,
            row.stiffness.ok_or("no stiffness")?,
            row.info.iterations,
            point.area_fraction,
            point.mean_gap,
            point.stiffness,
            theory.rms_height(),
            theory.rms_gradient(),
        )?;
    }
    Ok(())
}
