//! Persson's theory beside a committed BEM study (docs/persson.md): regenerates every
//! sample surface of the study from its seed, computes Persson's predictions from that
//! surface's own PSD at the BEM's loads, and writes the sample-mean BEM and Persson values
//! side by side.
//!
//! `cargo run --release -p asperity --example persson_compare -- STUDY_DIR OUT.csv`
//! (STUDY_DIR holds study.json and checkpoint/bem_*.json, e.g. docs/results/fig2_1024).
//! Columns: n, hurst, pressure (= force: L = 1, E* = 1), samples, area_bem, area_persson,
//! stiffness_bem, stiffness_persson (interfacial, K·A₀), stiffness_persson_series (in
//! series with the bulk: the BEM's k of free boundaries includes the half-space under the
//! nominal area, which alone is a flat punch of k ≈ 2E*√(A₀/π), the circle of equal area;
//! the square's is about 1 % stiffer), gap_persson, rms_gradient_spectral (mean over
//! samples; the BEM surfaces have unit rms slope by forward differences), u0_persson,
//! kappa_bem_spectral = area_bem·ḡ/p, kappa_bem_fd = area_bem/p (ḡ_fd = 1).

use std::error::Error;
use std::fmt::Write as _;

use asperity::persson::{Persson, PerssonParams};
use asperity::spectrum::{LongWavelength, Psd};
use asperity::study::{sample_seed, Method, Task};
use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};
use serde_json::Value;

type Res<T> = Result<T, Box<dyn Error>>;

/// The sample curves of one checkpoint: per sample, (force, stiffness, fraction) points.
fn sample_curves(checkpoint: &Value) -> Vec<Vec<(f64, f64, f64)>> {
    let samples = checkpoint["content"]["samples"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    samples
        .iter()
        .map(|s| {
            s["points"]
                .as_array()
                .map(|points| {
                    points
                        .iter()
                        .map(|p| {
                            let f = |k: &str| p[k].as_f64().unwrap_or(f64::NAN);
                            (f("force"), f("stiffness"), f("fraction"))
                        })
                        .collect()
                })
                .unwrap_or_default()
        })
        .collect()
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let (dir, out) = match args.as_slice() {
        [_, dir, out] => (dir, out),
        _ => return Err("usage: persson_compare STUDY_DIR OUT.csv".into()),
    };
    let study: Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{dir}/study.json"))?)?;
    let seed = study["spec"]["seed"]
        .as_u64()
        .ok_or("study.json: no seed")?;
    let rolloff = study["spec"]["rolloff"].as_f64();
    let mut csv = String::from("n,hurst,pressure,samples,area_bem,area_persson,stiffness_bem,stiffness_persson,stiffness_persson_series,gap_persson,rms_gradient_spectral,u0_persson,kappa_bem_spectral,kappa_bem_fd\n");
    let mut paths: Vec<_> = std::fs::read_dir(format!("{dir}/checkpoint"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    paths.sort();
    for path in paths {
        let checkpoint: Value = serde_json::from_str(&std::fs::read_to_string(&path)?)?;
        let identity = &checkpoint["identity"];
        let n = identity["n"].as_u64().ok_or("checkpoint: no n")? as usize;
        let hurst = identity["hurst"].as_f64().ok_or("checkpoint: no hurst")?;
        eprintln!("{}: N = {n}, H = {hurst}", path.display());
        compare_task(
            &mut csv,
            seed,
            rolloff,
            n,
            hurst,
            &sample_curves(&checkpoint),
        )?;
    }
    std::fs::write(out, csv)?;
    Ok(())
}

fn compare_task(
    csv: &mut String,
    seed: u64,
    rolloff: Option<f64>,
    n: usize,
    hurst: f64,
    curves: &[Vec<(f64, f64, f64)>],
) -> Res<()> {
    let long = rolloff.map_or(LongWavelength::None, |q0| LongWavelength::RollOff { q0 });
    let spec = SurfaceSpec::new(
        n,
        n,
        1.0,
        Psd::new(hurst, long, None)?,
        Normalisation::RmsSlope(1.0),
    )?;
    let mut generator = SurfaceGenerator::new(&spec)?;
    let task = Task { n, hurst };
    let loads = curves.iter().map(Vec::len).min().unwrap_or(0);
    let m = curves.len() as f64;
    // Sums over samples, per load: area, stiffness (BEM) and area, stiffness, gap (Persson).
    let mut sums = vec![[0.0f64; 6]; loads];
    let (mut g_sum, mut u0_sum) = (0.0, 0.0);
    for (i, curve) in curves.iter().enumerate() {
        let surface = generator.try_generate(sample_seed(seed, Method::Bem, task, i))?;
        let theory = Persson::from_surface(&surface, PerssonParams::default())?;
        g_sum += theory.rms_gradient();
        u0_sum += theory.u0();
        for (row, &(force, stiffness, fraction)) in sums.iter_mut().zip(curve) {
            let point = theory.predict(force)?;
            let values = [
                force,
                fraction,
                stiffness,
                point.area_fraction,
                point.contact_stiffness,
                point.mean_gap,
            ];
            for (s, v) in row.iter_mut().zip(values) {
                *s += v;
            }
        }
    }
    let (g, u0) = (g_sum / m, u0_sum / m);
    for row in &sums {
        let [p, a_bem, k_bem, a_p, k_p, gap_p] = row.map(|v| v / m);
        let k_punch = 2.0 * (1.0 / std::f64::consts::PI).sqrt(); // E* = 1, A₀ = 1
        let k_series = 1.0 / (1.0 / k_p + 1.0 / k_punch);
        writeln!(
            csv,
            "{n},{hurst},{p:e},{},{a_bem:e},{a_p:e},{k_bem:e},{k_p:e},{k_series:e},{gap_p:e},{g:e},{u0:e},{:e},{:e}",
            curves.len(),
            a_bem * g / p,
            a_bem / p
        )?;
    }
    Ok(())
}
