//! One module per subcommand; each exposes its clap `Args` and a `run` function.

pub mod bem;
pub mod bem_adhesion;
pub mod bem_path;
pub mod bench;
pub mod contact;
pub mod contact_adhesion;
pub mod contact_path;
pub mod fields_nc;
pub mod figures;
pub mod import;
pub mod mdr;
pub mod mdr_slip;
pub mod measured;
pub mod persson;
pub mod reproduce;
pub mod setting;
pub mod stats;
pub mod study;
pub mod surface;

use crate::cli::{Cli, Command};

/// Runs the parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Surface(args) => surface::run_surface(&args),
        Command::Line(args) => surface::run_line(&args),
        Command::Stats(args) => {
            args.measured.check()?;
            stats::run(&args)
        }
        Command::Bem(args) => {
            args.measured.check()?;
            bem::run(&args)
        }
        Command::Mdr(args) => {
            args.measured.check()?;
            mdr::run(&args)
        }
        Command::Study(args) => study::run(&args),
        Command::Import(args) => {
            args.measured.check()?;
            import::run(&args)
        }
        Command::Contact(args) => {
            args.measured.check()?;
            contact::run(&args)
        }
        Command::Persson(args) => {
            args.measured.check()?;
            persson::run(&args)
        }
        Command::Bench(args) => bench::run(&args),
        Command::Reproduce(args) => reproduce::run(&args),
    }
}
