//! Measured topographies in every command: the shared options (`--channel`, `--detrend`,
//! `--fill`, `--size`) and the loading of an instrument file into a levelled, filled
//! surface or line with its provenance. Warnings (a tilt left in place) go to stderr.

use std::path::Path;

use anyhow::{bail, Context, Result};
use asperity::topography::level::Detrend;
use asperity::topography::{self, ChannelChoice, Fill, Levelling, ReadOptions, Topography};

/// Options for reading a measured file (ignored for `.npy` made by asperity, except
/// `--size`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct MeasuredArgs {
    /// Channel of a measured file, by name or 0-based index [default: the first height
    /// channel].
    #[arg(long, value_name = "NAME|INDEX")]
    pub channel: Option<String>,
    /// Levelling of a measured file: none, mean, plane (least-squares mean plane), poly2,
    /// poly3 (polynomial of degree 2, 3 in x and y), lines (each scan line's least-squares
    /// line), line-means (each scan line's mean). Without it a tilted surface is used as
    /// it is, with a warning.
    #[arg(long, value_name = "HOW", value_parser = ["none", "mean", "plane", "poly2", "poly3", "lines", "line-means"])]
    pub detrend: Option<String>,
    /// Undefined points of a measured file: harmonic (Laplace inpainting) or refuse (an
    /// error with their count, also the default).
    #[arg(long, value_name = "HOW", value_parser = ["harmonic", "refuse"])]
    pub fill: Option<String>,
}

/// The `--detrend` choice (`None`: not given; `Some(None)`: `none`).
fn detrend(args: &MeasuredArgs) -> Option<Option<Detrend>> {
    args.detrend.as_deref().map(|d| match d {
        "mean" => Some(Detrend::Mean),
        "plane" => Some(Detrend::Polynomial(1)),
        "poly2" => Some(Detrend::Polynomial(2)),
        "poly3" => Some(Detrend::Polynomial(3)),
        "lines" => Some(Detrend::RowLines),
        "line-means" => Some(Detrend::RowMeans),
        _ => None,
    })
}

/// Parses `--size X[,Y]` (metres for a measured file).
pub fn parse_size(text: &str) -> Result<[Option<f64>; 2]> {
    let parts: Vec<&str> = text.split(',').collect();
    if parts.len() > 2 {
        bail!("invalid --size {text}: give X or X,Y");
    }
    let mut out = [None, None];
    for (slot, part) in out.iter_mut().zip(&parts) {
        let v: f64 = part
            .trim()
            .parse()
            .with_context(|| format!("invalid --size {text}: {part:?} is not a number"))?;
        if !(v.is_finite() && v > 0.0) {
            bail!("invalid --size {text}: sizes must be positive and finite");
        }
        *slot = Some(v);
    }
    Ok(out)
}

/// Whether `path` is a NumPy `.npy` file (by its magic bytes; unreadable files are not).
pub fn is_npy(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 6];
    // Opened as every input is (a FIFO or device is no `.npy`, and opening one must not
    // block); the reader that follows refuses it in words.
    asperity::input::open_regular(path).is_ok_and(|(mut f, _)| f.read_exact(&mut head).is_ok())
        && &head == b"\x93NUMPY"
}

/// Whether the `.npy` at `path` has an import sidecar (with `sizes` per axis): such arrays
/// go through the measured path, which reads both sizes.
pub fn has_import_sidecar(path: &Path) -> bool {
    let sidecar = asperity::io::sidecar_path(path);
    asperity::input::read_text(&sidecar, asperity::input::TEXT_MAX_BYTES)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|v| v["sizes"].is_array())
}

/// Reads `path` (any supported format) and cleans it as the options say; prints the
/// warnings to stderr. `size` is `--size` as given.
pub fn load(path: &Path, args: &MeasuredArgs, size: Option<&str>) -> Result<Topography> {
    let options = ReadOptions {
        channel: args
            .channel
            .as_deref()
            .map(|c| c.parse::<ChannelChoice>().expect("infallible")),
        size: size.map(parse_size).transpose()?,
        ..ReadOptions::default()
    };
    let mut topography = topography::read_file(path, &options)?;
    let fill = match args.fill.as_deref() {
        Some("harmonic") => Some(Fill::Harmonic),
        Some(_) => Some(Fill::Refuse),
        None => None,
    };
    let levelling = match detrend(args) {
        Some(Some(d)) => Levelling::By(d),
        Some(None) => Levelling::None,
        None => Levelling::Unchosen,
    };
    let warnings = topography::clean(&mut topography, levelling, fill)?;
    for w in warnings {
        eprintln!("warning: {}: {w} (choose --detrend)", path.display());
    }
    if topography.provenance.unit.is_none() && topography.provenance.format != "npy" {
        eprintln!(
            "warning: {}: the file gives no unit; its numbers are used as metres",
            path.display()
        );
    }
    Ok(topography)
}

/// The provenance record written to sidecars.
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
