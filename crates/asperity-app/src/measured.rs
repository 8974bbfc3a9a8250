//! A measured file in every command and in Python's `read_topography`: the options
//! (channel, size, levelling, filling) as a request ([`MeasuredRequest`]), and one call
//! ([`open`]) that reads the file with the library's readers and cleans it as asked, with
//! the warnings both front ends give (a tilt left in place, a file with no unit).

use std::path::Path;

use asperity::topography::level::Detrend;
use asperity::topography::{self, ChannelChoice, Fill, Levelling, ReadOptions, Topography};
use serde::{Deserialize, Serialize};

use crate::refusal::{Refusal, RequestError};

/// The parameters of a measured file.
pub mod params {
    use crate::refusal::Param;

    /// The levelling.
    pub const DETREND: Param = Param::new("--detrend", "detrend");
    /// The filling of undefined points.
    pub const FILL: Param = Param::new("--fill", "fill");
    /// The channel.
    pub const CHANNEL: Param = Param::new("--channel", "channel");
}

use params::*;

/// The levellings by name, as both front ends spell them.
pub const DETRENDS: [&str; 7] = [
    "none",
    "mean",
    "plane",
    "poly2",
    "poly3",
    "lines",
    "line-means",
];

/// How to read and clean a measured file.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MeasuredRequest {
    /// A channel's name or 0-based index (`None`: the first height channel).
    pub channel: Option<String>,
    /// Sizes `[x, y]` in metres, overriding the file's (`y` `None`: square pixels).
    pub size: Option<[Option<f64>; 2]>,
    /// One of [`DETRENDS`]; `None`: no levelling chosen (a tilt is warned about).
    pub detrend: Option<String>,
    /// `harmonic` or `refuse`; `None`: the front end's default (see [`open`]).
    pub fill: Option<String>,
}

/// The levelling named `name`, or why not.
pub fn parse_detrend(name: &str) -> Result<Levelling, Refusal> {
    Ok(Levelling::By(match name {
        "none" => return Ok(Levelling::None),
        "mean" => Detrend::Mean,
        "plane" => Detrend::Polynomial(1),
        "poly2" => Detrend::Polynomial(2),
        "poly3" => Detrend::Polynomial(3),
        "lines" => Detrend::RowLines,
        "line-means" => Detrend::RowMeans,
        _ => {
            return Err(Refusal::of(DETREND).text(format!(
                " must be one of {}, got {:?}",
                DETRENDS.join(", "),
                asperity::input::clip(name)
            )))
        }
    }))
}

/// The filling named `name`, or why not.
pub fn parse_fill(name: &str) -> Result<Fill, Refusal> {
    match name {
        "harmonic" => Ok(Fill::Harmonic),
        "refuse" => Ok(Fill::Refuse),
        _ => Err(Refusal::of(FILL).text(format!(
            " must be harmonic (Laplace inpainting) or refuse, got {:?}",
            asperity::input::clip(name)
        ))),
    }
}

/// What a warning is about (Python gives each its own category).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WarningKind {
    /// The surface looks tilted and no levelling was chosen.
    Unlevelled,
    /// The file gives no unit: its numbers are taken as metres.
    NoUnit,
}

/// A warning about an opened file, in words that name the parameter that would avoid it.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// What it is about.
    pub kind: WarningKind,
    /// The words (the front end prefixes the file).
    pub words: Refusal,
}

/// A topography read and cleaned, with its warnings.
#[derive(Debug, Clone)]
pub struct Opened {
    /// The heights, sizes and provenance (the cleaning recorded).
    pub topography: Topography,
    /// What the user should know.
    pub warnings: Vec<Warning>,
}

impl MeasuredRequest {
    /// The library's options, levelling and filling, or why not; `unfilled` is the
    /// filling when none is named.
    fn plan(
        &self,
        unfilled: Option<Fill>,
    ) -> Result<(ReadOptions, Levelling, Option<Fill>), Refusal> {
        let levelling = match &self.detrend {
            Some(name) => parse_detrend(name)?,
            None => Levelling::Unchosen,
        };
        let fill = match &self.fill {
            Some(name) => Some(parse_fill(name)?),
            None => unfilled,
        };
        let options = ReadOptions {
            channel: self
                .channel
                .as_deref()
                .map(|c| c.parse::<ChannelChoice>().unwrap_or_else(|e| match e {})),
            size: self.size,
            ..ReadOptions::default()
        };
        Ok((options, levelling, fill))
    }
}

/// Reads `path` (any format the library reads) and cleans it as `request` says: the one
/// call by which a measured file becomes a [`Topography`] in both front ends.
/// Undefined points with no filling named get `unfilled`: `None` refuses them as "no
/// filling was chosen" (the CLI), [`Fill::Keep`] keeps them as NaN (Python).
pub fn open(
    path: &Path,
    request: &MeasuredRequest,
    unfilled: Option<Fill>,
) -> Result<Opened, RequestError> {
    let (options, levelling, fill) = request.plan(unfilled)?;
    let library = |e| RequestError::Invalid(Box::new(e));
    let mut topography = topography::read_file(path, &options).map_err(library)?;
    let tilts = topography::clean(&mut topography, levelling, fill).map_err(library)?;
    let mut warnings: Vec<Warning> = tilts
        .into_iter()
        .map(|w| Warning {
            kind: WarningKind::Unlevelled,
            words: Refusal::saying(format!("{w} (choose "))
                .param(DETREND)
                .text(")"),
        })
        .collect();
    if topography.provenance.unit.is_none() && topography.provenance.format != "npy" {
        warnings.push(Warning {
            kind: WarningKind::NoUnit,
            words: Refusal::saying("the file gives no unit; its numbers are used as metres"),
        });
    }
    Ok(Opened {
        topography,
        warnings,
    })
}

/// The provenance record written to sidecars and printed by `stats --json`.
pub fn record(t: &Topography) -> serde_json::Value {
    serde_json::json!({
        "source": t.provenance.source,
        "format": t.provenance.format,
        "channel": t.provenance.channel,
        "channel_index": t.provenance.channel_index,
        "channels": t.provenance.channels,
        "file_unit": t.provenance.file_unit,
        "unit": t.provenance.unit.clone().unwrap_or_else(|| "m (assumed: the file gives none)".into()),
        "shape": t.heights.shape(),
        "sizes": t.sizes,
        "size_source": t.provenance.size_source,
        "cleaning": t.provenance.cleaning,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;

    #[test]
    fn levellings_and_fillings_are_named_alike() {
        for name in DETRENDS {
            parse_detrend(name).unwrap();
        }
        assert_eq!(
            parse_detrend("tilt").unwrap_err().words(Names::Keywords),
            "detrend must be one of none, mean, plane, poly2, poly3, lines, line-means, got \"tilt\""
        );
        assert_eq!(
            parse_fill("zero").unwrap_err().words(Names::Flags),
            "--fill must be harmonic (Laplace inpainting) or refuse, got \"zero\""
        );
    }
}
