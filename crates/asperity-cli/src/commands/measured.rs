//! Surface and line arguments in every command: the shared options (`--channel`,
//! `--detrend`, `--fill`, `--size`) turned into the front-end layer's request, opened by its
//! one call ([`asperity_app::argument::open`]). Warnings (a tilt left in place) go to stderr.

use std::path::Path;

use anyhow::{Context, Result};
use asperity::topography::Topography;
use asperity_app::argument::{open, Arrays, Input};
use asperity_app::measured::{parse_detrend, parse_fill, MeasuredRequest};
use asperity_app::Names;

pub use asperity_app::measured::record;

/// Options for reading a measured file (ignored for `.npy` made by asperity, except
/// `--size`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct MeasuredArgs {
    /// Channel of a measured file, by name or 0-based index (a name that several channels
    /// share is refused, listing their indices) [default: the first height channel].
    #[arg(long, value_name = "NAME|INDEX")]
    pub channel: Option<String>,
    /// Levelling of a measured file: none, mean, plane (least-squares mean plane), poly2,
    /// poly3 (polynomial of degree 2, 3 in x and y), lines (each scan line's least-squares
    /// line), line-means (each scan line's mean). Without it a tilted surface is used as
    /// it is, with a warning.
    #[arg(long, value_name = "HOW")]
    pub detrend: Option<String>,
    /// Undefined points of a measured file: harmonic (Laplace inpainting) or refuse (an
    /// error with their count, also the default).
    #[arg(long, value_name = "HOW")]
    pub fill: Option<String>,
}

impl MeasuredArgs {
    /// Refuses a levelling or filling that is none of the names, whether or not the
    /// surface turns out to be a measured file.
    pub fn check(&self) -> Result<()> {
        let named = |r: asperity_app::Refusal| anyhow::anyhow!(r.words(Names::Flags));
        if let Some(name) = &self.detrend {
            parse_detrend(name).map_err(named)?;
        }
        if let Some(name) = &self.fill {
            parse_fill(name).map_err(named)?;
        }
        Ok(())
    }
}

/// Parses `--size X[,Y]` (metres for a measured file): the numbers here, their rule
/// (one or two, positive and finite) in the front-end layer's words
/// ([`asperity_app::argument::sizes`], Python's `size=` too).
pub fn parse_size(text: &str) -> Result<[Option<f64>; 2]> {
    let values = (text.split(','))
        .map(|part| {
            (part.trim().parse::<f64>())
                .with_context(|| format!("invalid --size {text}: {part:?} is not a number"))
        })
        .collect::<Result<Vec<f64>>>()?;
    asperity_app::argument::sizes(&values).map_err(|r| anyhow::anyhow!(r.words(Names::Flags)))
}

/// Opens a surface or line argument by the front-end layer's one call
/// ([`asperity_app::argument::open`]): a measured file (or an imported `.npy`) read and
/// cleaned as the options say (undefined points without `--fill` are refused), a plain
/// `.npy` as `arrays` says; prints the warnings to stderr. `size` is `--size`, parsed.
pub fn open_argument(
    path: &Path,
    args: &MeasuredArgs,
    size: Option<[Option<f64>; 2]>,
    arrays: Arrays<'_>,
) -> Result<Input> {
    let request = MeasuredRequest {
        channel: args.channel.clone(),
        size,
        detrend: args.detrend.clone(),
        fill: args.fill.clone(),
    };
    let input = open(path, &request, arrays, None).map_err(crate::request::refused)?;
    for w in &input.warnings {
        eprintln!(
            "warning: {}: {}",
            path.display(),
            w.words.words(Names::Flags)
        );
    }
    Ok(input)
}

/// Reads `path` (any supported format, a `.npy` included) through the measured reader, as
/// [`open_argument`] does; `size` is `--size` as given.
pub fn load(path: &Path, args: &MeasuredArgs, size: Option<&str>) -> Result<Topography> {
    let size = size.map(parse_size).transpose()?;
    Ok(open_argument(path, args, size, Arrays::Measured)?.topography)
}
