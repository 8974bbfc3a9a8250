//! The samplers behind each [`Method`]: the force–stiffness curve of one realisation.
//!
//! * **BEM**: an N×N surface (unit rms slope, the study's H and roll-off), free boundaries,
//!   E* = 1, solved by Polonsky–Keer under load control at log-spaced mean pressures with
//!   warm starts; the stiffness at each load by the frozen contact set.
//!   The pressures span `0.05/N²` to `0.2` E*: with the area–load law `A/A0 ≈ 2 p/(E* ḡ)`
//!   (ḡ = 1) this runs from below one pixel in contact to roughly 30–40 % contact.

use super::{
    run_task, CurvePoint, Method, ProgressFn, SampleCurve, Sampler, StudyDir, StudySpec, Task,
    TaskResult,
};
use crate::bem::{ContactSolver, Control, HalfSpace, SolverParams};
use crate::spectrum::{LongWavelength, Psd};
use crate::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};
use crate::{Error, Result};

fn psd_of(spec: &StudySpec, task: Task) -> Result<Psd> {
    let long = spec
        .rolloff
        .map_or(LongWavelength::None, |q0| LongWavelength::RollOff { q0 });
    Psd::new(task.hurst, long, None)
}

/// BEM sampler: see the module docs.
#[derive(Debug, Clone)]
pub struct BemSampler {
    surface: SurfaceSpec,
    mean_pressures: Vec<f64>,
    params: SolverParams,
}

impl BemSampler {
    /// Load levels per sample.
    pub const LOADS: usize = 24;

    /// The sampler of `task` in `spec`.
    pub fn new(spec: &StudySpec, task: Task) -> Result<Self> {
        let surface = SurfaceSpec::new(
            task.n,
            task.n,
            1.0,
            psd_of(spec, task)?,
            Normalisation::RmsSlope(1.0),
        )?;
        let (lo, hi) = (0.05 / (task.n * task.n) as f64, 0.2f64);
        let mean_pressures = (0..Self::LOADS)
            .map(|i| (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (Self::LOADS - 1) as f64).exp())
            .collect();
        Ok(BemSampler {
            surface,
            mean_pressures,
            params: SolverParams::default(),
        })
    }
}

impl Sampler for BemSampler {
    type Worker = SurfaceGenerator;

    fn worker(&self) -> Result<SurfaceGenerator> {
        SurfaceGenerator::new(&self.surface)
    }

    fn sample(&self, generator: &mut SurfaceGenerator, seed: u64) -> Result<SampleCurve> {
        let surface = generator.try_generate(seed)?;
        let bem_error =
            |e: crate::bem::SolveError| Error::invalid("bem", format!("seed {seed}: {e}"));
        let mut solver =
            ContactSolver::new(&surface, HalfSpace::default(), self.params).map_err(bem_error)?;
        let points_total = self.surface.rows * self.surface.cols;
        let mut points = Vec::with_capacity(self.mean_pressures.len());
        for &p in &self.mean_pressures {
            let (summary, _) = solver.solve(Control::MeanPressure(p)).map_err(bem_error)?;
            let (stiffness, _) = solver.frozen_set_stiffness().map_err(bem_error)?;
            points.push(CurvePoint {
                fraction: summary.area_fraction,
                force: summary.force,
                stiffness,
            });
        }
        Ok(SampleCurve {
            points_total,
            points,
        })
    }
}

/// Runs (or resumes) `task` with the sampler of `spec.method`.
pub fn run_any_task(
    spec: &StudySpec,
    task: Task,
    store: &StudyDir,
    progress: &ProgressFn,
) -> Result<TaskResult> {
    match spec.method {
        Method::Bem => run_task(spec, task, &BemSampler::new(spec, task)?, store, progress),
        Method::Mdr => Err(Error::invalid("method", "MDR sampler not wired yet")),
    }
}
