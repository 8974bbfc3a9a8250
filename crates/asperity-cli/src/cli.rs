//! The command-line contract (`shared/CLI.md`): one subcommand per task.

use clap::{Parser, Subcommand};

use crate::commands;

/// Contact mechanics of randomly rough surfaces: self-affine surface synthesis, FFT
/// boundary elements and the method of dimensionality reduction (Pohrt & Popov).
#[derive(Debug, Parser)]
#[command(name = "asperity", version, about, long_about = None, arg_required_else_help = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Generate a self-affine rough surface (2D) as .npy with a JSON sidecar.
    Surface(commands::surface::SurfaceArgs),
    /// Generate a self-affine rough line (1D, C1D = π q C2D) as .npy with a JSON sidecar.
    Line(commands::surface::LineArgs),
    /// Statistics of a surface or line: rms height, slope, curvature, PSD and its slope.
    Stats(commands::stats::StatsArgs),
    /// Solve the 3D contact of a rigid rough indenter on an elastic half-space (BEM).
    Bem(commands::bem::BemArgs),
    /// Method of dimensionality reduction: force and stiffness of a 1D spring foundation.
    Mdr(commands::mdr::MdrArgs),
    /// Ensemble studies: α(H, N) sweeps and mean k(F) curves, checkpointed and resumable.
    Study(commands::study::StudyArgs),
    /// Read a measured topography (X3P, SDF, text, x y z, profiles, ...) into .npy + sidecar or X3P.
    Import(commands::import::ImportArgs),
    /// Contact area, mean gap, stiffness and patches of a measured surface against load (SI units).
    Contact(commands::contact::ContactArgs),
    /// Persson's theory from a surface's own PSD: contact area, mean gap, stiffness vs pressure.
    Persson(commands::persson::PerssonArgs),
    /// Time a library kernel (for comparisons with other tools; see bench/).
    Bench(commands::bench::BenchArgs),
    /// Regenerate a figure of the paper or the book chapter.
    Reproduce(commands::reproduce::ReproduceArgs),
}
