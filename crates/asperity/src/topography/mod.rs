//! Measured topographies: instrument files read into heights in metres, physical sizes per
//! axis, channels and a mask of undefined points.
//!
//! Conventions (the same as the rest of the crate): an areal channel is a row-major grid
//! indexed `(row, col) = (y, x)`; pixels may be rectangular (`Δx = size_x / cols`,
//! `Δy = size_y / rows`). Heights are in metres, positive up; a point the instrument marks
//! as undefined (missing measurement) is `NaN`. SurfaceTopography's arrays are indexed
//! `[x, y]`; ours are their transpose.
//!
//! Each instrument format is one file of this module with one entry point,
//! `read(bytes: &[u8]) -> Result<Reading>`, that parses untrusted bytes without panicking,
//! and a content test `sniff(bytes: &[u8]) -> bool`. [`read_file`] picks the format by
//! content first (magic bytes, then each format's `sniff`, then the shape of a text file)
//! and by the file's extension second, chooses a channel and returns a [`Topography`]:
//! heights, sizes per axis and where they came from ([`Provenance`]). Cleaning (levelling,
//! filling undefined points) is explicit: [`level`], [`inpaint`], and [`clean`], which
//! records each step; [`stats`] gives the ISO 25178 parameters.

use std::path::{Path, PathBuf};

use ndarray::{Array1, Array2};
use serde::{Deserialize, Serialize};

use crate::{Error, Result};

pub(crate) mod al3d;
#[cfg(test)]
mod audit;
pub mod bandwidth;
pub(crate) mod bcr;
pub(crate) mod bytes;
pub(crate) mod datx;
pub(crate) mod di;
pub(crate) mod frt;
pub(crate) mod gwy;
pub(crate) mod hdf5;
pub(crate) mod ibw;
pub mod inpaint;
pub(crate) mod jpk;
pub mod level;
pub(crate) mod lext;
pub(crate) mod metropro;
pub(crate) mod mi;
pub(crate) mod mnt;
pub(crate) mod netcdf;
pub(crate) mod nid;
pub(crate) mod nms;
pub(crate) mod opd;
pub(crate) mod opdx;
pub(crate) mod park;
pub mod patches;
pub(crate) mod plu;
pub(crate) mod sdf;
pub mod stats;
pub(crate) mod sur;
#[cfg(test)]
mod testkit;
pub(crate) mod text;
pub(crate) mod tiff;
pub(crate) mod tmd;
pub(crate) mod vk;
pub(crate) mod wsxm;
pub mod x3p;
pub(crate) mod xlsx;
pub(crate) mod xyz;
pub(crate) mod zipped;
pub(crate) mod zon;

/// The heights of one channel: a map or a line profile.
#[derive(Debug, Clone, PartialEq)]
pub enum Heights {
    /// A map, `(rows, cols) = (ny, nx)`, metres, NaN where undefined.
    Areal(Array2<f64>),
    /// A line profile along x, metres, NaN where undefined.
    Profile(Array1<f64>),
}

impl Heights {
    /// A line (an array of one dimension) or a map (two, in standard layout) from an array
    /// read from a file; any other number of dimensions comes back as the error.
    pub fn from_array(array: ndarray::ArrayD<f64>) -> std::result::Result<Heights, usize> {
        match array.ndim() {
            1 => Ok(Heights::Profile(array.into_dimensionality().expect("1D"))),
            2 => Ok(Heights::Areal(
                array
                    .into_dimensionality::<ndarray::Ix2>()
                    .expect("2D")
                    .as_standard_layout()
                    .into_owned(),
            )),
            d => Err(d),
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        match self {
            Heights::Areal(h) => h.len(),
            Heights::Profile(h) => h.len(),
        }
    }

    /// Whether there are no points (never, for a reader's result).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The grid's shape: `[rows, cols]` for a map, `[n]` for a profile.
    pub fn shape(&self) -> Vec<usize> {
        match self {
            Heights::Areal(h) => vec![h.nrows(), h.ncols()],
            Heights::Profile(h) => vec![h.len()],
        }
    }

    /// All values, row-major.
    pub fn values(&self) -> Box<dyn Iterator<Item = f64> + '_> {
        match self {
            Heights::Areal(h) => Box::new(h.iter().copied()),
            Heights::Profile(h) => Box::new(h.iter().copied()),
        }
    }

    /// Number of undefined (NaN) points.
    pub fn undefined_count(&self) -> usize {
        // One loop per layout, not through `values`' boxed iterator: this is counted on
        // every import (twice), a pass over the whole map.
        match self {
            Heights::Areal(h) => h.iter().filter(|v| v.is_nan()).count(),
            Heights::Profile(h) => h.iter().filter(|v| v.is_nan()).count(),
        }
    }
}

/// One channel of a file (AFM files hold several: height, amplitude, phase, ...).
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The channel's name as the file gives it (e.g. `Height`, `ZSensor`), or a
    /// descriptive default when the file names none.
    pub name: String,
    /// The values, converted to metres for a height channel.
    pub heights: Heights,
    /// Physical size along x and y in metres (`[x, y]`; y is `None` for a profile), or
    /// `None` where the file carries no size.
    pub size: [Option<f64>; 2],
    /// The file's own unit of the values (e.g. `µm`), `None` where the file gives none;
    /// then the values are the file's raw numbers.
    pub unit: Option<String>,
    /// Whether the channel holds heights (a topography); the default channel is the first
    /// such one.
    pub is_height: bool,
}

/// What a reader found in a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    /// The format's short name (e.g. `x3p`, `sur`, `di`).
    pub format: &'static str,
    /// Every channel the file holds, in file order (at least one).
    pub channels: Vec<Channel>,
}

/// A reader's error (before the file's path is known).
pub(crate) fn bad(format: &'static str, reason: impl Into<String>) -> Error {
    Error::BadTopography {
        format,
        reason: reason.into(),
    }
}

/// Metres per unit for the length units instruments write (`µm`, `um`, `nm`,
/// `Micrometer`, `Å`, ...), case as written; `None` for anything else.
pub(crate) fn unit_to_metres(unit: &str) -> Option<f64> {
    let u = unit
        .trim()
        .trim_matches(|c| c == '[' || c == ']' || c == '(' || c == ')');
    let factor = match u {
        "m" | "meter" | "metre" | "Meter" | "Metre" | "meters" | "metres" => 1.0,
        "cm" => 1e-2,
        "mm" | "Millimeter" | "millimeter" | "millimetre" => 1e-3,
        "µm" | "μm" | "um" | "micron" | "microns" | "Micrometer" | "micrometer" | "micrometre" => {
            1e-6
        }
        "nm" | "Nanometer" | "nanometer" | "nanometre" => 1e-9,
        "Å" | "Angstrom" | "angstrom" | "A" => 1e-10,
        "pm" => 1e-12,
        _ => return None,
    };
    Some(factor)
}

/// The one spelling used in provenance records for a unit [`unit_to_metres`] knows.
pub(crate) fn canonical_unit(unit: &str) -> String {
    match unit_to_metres(unit) {
        Some(1.0) => "m".into(),
        Some(1e-2) => "cm".into(),
        Some(1e-3) => "mm".into(),
        Some(1e-6) => "µm".into(),
        Some(1e-9) => "nm".into(),
        Some(1e-10) => "Å".into(),
        Some(1e-12) => "pm".into(),
        _ => unit.trim().to_string(),
    }
}

/// A binary format: its name, the extensions it is written with, its content test and its
/// reader.
struct Format {
    name: &'static str,
    extensions: &'static [&'static str],
    sniff: fn(&[u8]) -> bool,
    read: fn(&[u8]) -> Result<Reading>,
}

/// The formats recognised by content, in the order they are tried.
const FORMATS: &[Format] = &[
    Format {
        name: "x3p",
        extensions: &["x3p"],
        sniff: x3p::sniff,
        read: x3p::read,
    },
    Format {
        name: "mitutoyo",
        extensions: &["xlsx"],
        sniff: xlsx::sniff,
        read: xlsx::read,
    },
    Format {
        name: "gwy",
        extensions: &["gwy"],
        sniff: gwy::sniff,
        read: gwy::read,
    },
    Format {
        name: "hdf5",
        extensions: &["h5", "hdf5", "hdf", "datx"],
        sniff: hdf5::sniff,
        read: hdf5::read,
    },
    Format {
        name: "netcdf",
        extensions: &["nc"],
        sniff: netcdf::sniff,
        read: netcdf::read,
    },
    Format {
        name: "sdf",
        extensions: &["sdf"],
        sniff: sdf::sniff,
        read: sdf::read,
    },
    Format {
        name: "jpk",
        extensions: &["jpk", "jpk-qi-image"],
        sniff: jpk::sniff,
        read: jpk::read,
    },
    Format {
        name: "jpk-qi-data",
        extensions: &["jpk-qi-data"],
        sniff: jpk::sniff_qi_data,
        read: jpk::read_qi_data,
    },
    Format {
        name: "park",
        extensions: &["tiff", "tif"],
        sniff: park::sniff,
        read: park::read,
    },
    Format {
        name: "lext",
        extensions: &["lext"],
        sniff: lext::sniff,
        read: lext::read,
    },
    Format {
        name: "zon",
        extensions: &["zon"],
        sniff: zon::sniff,
        read: zon::read,
    },
    Format {
        name: "nms",
        extensions: &["nms"],
        sniff: nms::sniff,
        read: nms::read,
    },
    Format {
        name: "vk",
        extensions: &["vk3", "vk4", "vk6", "vk7"],
        sniff: vk::sniff,
        read: vk::read,
    },
    // The instrument formats, before any text detection (DI and WSxM headers are text);
    // PLU last, its only signature being a date.
    Format {
        name: "sur",
        extensions: &["sur"],
        sniff: sur::sniff,
        read: sur::read,
    },
    Format {
        name: "opd",
        extensions: &["opd"],
        sniff: opd::sniff,
        read: opd::read,
    },
    Format {
        name: "opdx",
        extensions: &["opdx"],
        sniff: opdx::sniff,
        read: opdx::read,
    },
    Format {
        name: "di",
        extensions: &["spm", "di"],
        sniff: di::sniff,
        read: di::read,
    },
    Format {
        name: "al3d",
        extensions: &["al3d"],
        sniff: al3d::sniff,
        read: al3d::read,
    },
    Format {
        name: "metropro",
        extensions: &["dat"],
        sniff: metropro::sniff,
        read: metropro::read,
    },
    Format {
        name: "frt",
        extensions: &["frt"],
        sniff: frt::sniff,
        read: frt::read,
    },
    Format {
        name: "wsxm",
        extensions: &["stp", "top", "tom", "cur"],
        sniff: wsxm::sniff,
        read: wsxm::read,
    },
    Format {
        name: "tmd",
        extensions: &["tmd"],
        sniff: tmd::sniff,
        read: tmd::read,
    },
    Format {
        name: "bcr",
        extensions: &["bcr", "bcrf"],
        sniff: bcr::sniff,
        read: bcr::read,
    },
    Format {
        name: "ibw",
        extensions: &["ibw"],
        sniff: ibw::sniff,
        read: ibw::read,
    },
    Format {
        name: "mi",
        extensions: &["mi"],
        sniff: mi::sniff,
        read: mi::read,
    },
    Format {
        name: "nid",
        extensions: &["nid"],
        sniff: nid::sniff,
        read: nid::read,
    },
    Format {
        name: "mnt",
        extensions: &["mnt"],
        sniff: mnt::sniff,
        read: mnt::read,
    },
    Format {
        name: "plu",
        extensions: &["plu", "apx"],
        sniff: plu::sniff,
        read: plu::read,
    },
];

/// The first bytes of a NumPy `.npy` file.
const NPY_MAGIC: &[u8] = b"\x93NUMPY";

/// Which channel to read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ChannelChoice {
    /// The channel with this name (exact, else the only one that matches ignoring case).
    Name(String),
    /// The channel at this 0-based position in the file.
    Index(usize),
}

impl std::str::FromStr for ChannelChoice {
    type Err = std::convert::Infallible;
    /// A whole number is an index, anything else a name.
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        Ok(match s.trim().parse::<usize>() {
            Ok(i) => ChannelChoice::Index(i),
            Err(_) => ChannelChoice::Name(s.to_string()),
        })
    }
}

/// Options of [`read_file`].
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// The channel; `None`: the first height channel.
    pub channel: Option<ChannelChoice>,
    /// Physical sizes `[x, y]` in metres (`y` ignored for a profile; `None` for y: the
    /// pixels are square), overriding the file's; required where the file carries none.
    pub size: Option<[Option<f64>; 2]>,
    /// Largest file accepted, in bytes.
    pub max_bytes: u64,
}

/// Default [`ReadOptions::max_bytes`]: 4 GiB.
pub const DEFAULT_MAX_BYTES: u64 = 4 << 30;

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            channel: None,
            size: None,
            max_bytes: DEFAULT_MAX_BYTES,
        }
    }
}

/// Where a topography came from and what was done to it (written to sidecars).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// The file read.
    pub source: PathBuf,
    /// The format's short name.
    pub format: String,
    /// The channel's name and its 0-based index in the file.
    pub channel: String,
    /// See `channel`.
    pub channel_index: usize,
    /// The names of all channels in the file.
    pub channels: Vec<String>,
    /// The file's own unit of the heights (`None`: the file gives none and the heights are
    /// its raw numbers); the heights here are in metres when it is a length unit.
    pub file_unit: Option<String>,
    /// The unit of the heights and sizes held: `m`, or `None` where the file gives no unit.
    pub unit: Option<String>,
    /// Where the sizes come from: `file` or `given`.
    pub size_source: String,
    /// Cleaning steps applied, in order (levelling, filling, resampling).
    pub cleaning: Vec<String>,
}

/// A measured topography: heights (NaN where undefined), sizes per axis, provenance.
#[derive(Debug, Clone, PartialEq)]
pub struct Topography {
    /// The heights.
    pub heights: Heights,
    /// Physical sizes: `[x]` for a profile, `[x, y]` for a map.
    pub sizes: Vec<f64>,
    /// Where it came from and what was done to it.
    pub provenance: Provenance,
}

impl Topography {
    /// Pixel spacing per axis (`[Δx]` or `[Δx, Δy]`).
    pub fn spacings(&self) -> Vec<f64> {
        match &self.heights {
            Heights::Areal(h) => vec![
                self.sizes[0] / h.ncols() as f64,
                self.sizes[1] / h.nrows() as f64,
            ],
            Heights::Profile(h) => vec![self.sizes[0] / h.len() as f64],
        }
    }

    /// Whether each point is undefined (NaN), row-major, in the heights' shape.
    pub fn mask(&self) -> Vec<bool> {
        self.heights.values().map(f64::is_nan).collect()
    }

    /// The map as a [`crate::surface::Surface`] (sizes per axis); fails for a profile
    /// or with undefined points.
    pub fn to_surface(&self) -> Result<crate::surface::Surface> {
        let Heights::Areal(h) = &self.heights else {
            return Err(Error::invalid(
                "topography",
                format!(
                    "{} holds a line profile, not a map",
                    self.provenance.source.display()
                ),
            ));
        };
        self.ensure_defined()?;
        crate::surface::Surface::with_sizes(h.clone(), self.sizes[0], self.sizes[1])
    }

    /// The profile as a [`crate::surface::Line`]; fails for a map or with undefined points.
    pub fn to_line(&self) -> Result<crate::surface::Line> {
        let Heights::Profile(h) = &self.heights else {
            return Err(Error::invalid(
                "topography",
                format!(
                    "{} holds a map, not a line profile",
                    self.provenance.source.display()
                ),
            ));
        };
        self.ensure_defined()?;
        crate::surface::Line::new(h.clone(), self.sizes[0])
    }

    fn ensure_defined(&self) -> Result<()> {
        match self.heights.undefined_count() {
            0 => Ok(()),
            n => Err(Error::invalid(
                "topography",
                format!(
                    "{} has {n} undefined points of {}; fill them (harmonic inpainting) first",
                    self.provenance.source.display(),
                    self.heights.len()
                ),
            )),
        }
    }
}

/// How the cleaning of [`clean`] treats undefined points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fill {
    /// Harmonic (Laplace) inpainting ([`inpaint`]).
    Harmonic,
    /// Refuse a topography with undefined points, giving their count.
    Refuse,
    /// Keep undefined points undefined (NaN): what uses the heights next refuses them.
    Keep,
}

/// The levelling [`clean`] applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Levelling {
    /// None chosen: the heights are kept, with a warning when they look tilted.
    Unchosen,
    /// Explicitly none (recorded; no tilt check).
    None,
    /// This levelling.
    By(level::Detrend),
}

/// Levels and fills undefined points (`fill`), recording each step in the provenance,
/// including an explicit "no levelling". Returns warnings for what was not asked for: a
/// surface that looks tilted when no levelling was chosen ([`Levelling::Unchosen`]).
/// Undefined points with no `fill` chosen are refused with their count, as with
/// [`Fill::Refuse`]: nothing is changed silently.
pub fn clean(
    topography: &mut Topography,
    levelling: Levelling,
    fill: Option<Fill>,
) -> Result<Vec<String>> {
    let mut warnings = Vec::new();
    let undefined = topography.heights.undefined_count();
    if undefined == topography.heights.len() {
        return Err(Error::invalid(
            "topography",
            format!(
                "{}: every point is undefined",
                topography.provenance.source.display()
            ),
        ));
    }
    if undefined > 0 && !matches!(fill, Some(Fill::Harmonic | Fill::Keep)) {
        let how = if fill.is_none() {
            "no filling was chosen"
        } else {
            "filling was refused"
        };
        return Err(Error::invalid(
            "topography",
            format!(
                "{}: {undefined} of {} points are undefined and {how}; fill them by harmonic inpainting",
                topography.provenance.source.display(),
                topography.heights.len()
            ),
        ));
    }
    let spacings = topography.spacings();
    match levelling {
        Levelling::By(d) => {
            level::detrend(&mut topography.heights, d)?;
            topography.provenance.cleaning.push(d.describe());
        }
        Levelling::None => topography.provenance.cleaning.push("no levelling".into()),
        Levelling::Unchosen => {
            if let Some(w) = level::tilt_warning(&topography.heights) {
                warnings.push(w);
            }
        }
    }
    if undefined > 0 && fill == Some(Fill::Harmonic) {
        let filled = inpaint::fill_harmonic(&mut topography.heights, &spacings)?;
        topography.provenance.cleaning.push(format!(
            "filled {filled} undefined points by harmonic (Laplace) inpainting"
        ));
    }
    Ok(warnings)
}

fn bad_file(path: &Path, reason: impl Into<String>) -> Error {
    Error::BadArrayFile {
        path: path.to_path_buf(),
        reason: one_line(&reason.into()),
    }
}

/// An error message as one line of at most [`MAX_REASON`] characters: control characters
/// (a corrupt header's line breaks) become spaces, the rest is cut with `…`.
fn one_line(reason: &str) -> String {
    let flat: String = reason
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    match flat.char_indices().nth(MAX_REASON) {
        Some((i, _)) => format!("{}…", &flat[..i]),
        None => flat,
    }
}

/// The longest error message about a file's content, in characters.
const MAX_REASON: usize = 400;

/// Infinite heights are undefined points (NaN), whatever the reader: no reader passes an
/// infinity on.
fn infinities_undefined(reading: &mut Reading) {
    for c in &mut reading.channels {
        match &mut c.heights {
            Heights::Areal(h) => h.mapv_inplace(|v| if v.is_finite() { v } else { f64::NAN }),
            Heights::Profile(h) => h.mapv_inplace(|v| if v.is_finite() { v } else { f64::NAN }),
        }
    }
}

/// Reads a topography file: only regular files up to `options.max_bytes`; the format by
/// content first and extension second; the channel chosen by `options.channel` (default:
/// the first height channel); sizes from `options.size`, else from the file, refused when
/// neither gives one. `.npy` files are read by [`crate::io::read_npy`]; their sizes come
/// from `options.size`, else from an asperity sidecar. No cleaning is done (see [`clean`]).
pub fn read_file(path: &Path, options: &ReadOptions) -> Result<Topography> {
    use std::io::{Read, Seek};
    // Every input is opened by one rule, in one wording (a FIFO is refused, not waited on).
    let (file, length) = crate::input::open_regular(path)?;
    if length > options.max_bytes {
        return Err(bad_file(
            path,
            format!(
                "{length} bytes is more than the {} bytes allowed for a topography file",
                options.max_bytes
            ),
        ));
    }
    // The file's bytes, the decoded values and a working copy: about 3× the file for
    // binary formats; text holds ~3 values per 2 bytes at worst (e.g. `1 2 3`).
    crate::memory::ensure_fits(
        &format!("reading {}", path.display()),
        length.checked_mul(16),
    )?;
    let mut file = file.take(options.max_bytes + 1);
    let mut head = [0u8; 8];
    let head_len = file.read(&mut head).map_err(|e| Error::io(path, e))?;
    if head[..head_len].starts_with(NPY_MAGIC) {
        return read_npy_topography(path, options);
    }
    if head[..head_len].starts_with(b"PK\x03\x04") {
        // An X3P archive is read from the file, never held whole (its payload streamed).
        if let Some(reading) = x3p::read_from_file(file.get_ref()) {
            let mut reading = reading.map_err(|e| bad_file(path, e.to_string()))?;
            infinities_undefined(&mut reading);
            return topography_from(path, reading, Vec::new(), options);
        }
    }
    let mut file = file.into_inner();
    file.seek(std::io::SeekFrom::Start(0))
        .map_err(|e| Error::io(path, e))?;
    let mut bytes = Vec::with_capacity(length as usize);
    file.take(options.max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > options.max_bytes {
        return Err(bad_file(path, "grew beyond its size limit while read"));
    }
    let (reading, notes) =
        detect_and_read_owned(path, bytes).map_err(|e| bad_file(path, e.to_string()))?;
    topography_from(path, reading, notes, options)
}

/// [`detect_and_read`] of bytes the reader may keep: an HDF5 file (`.h5`, `.datx`) is
/// given to its decoder without a copy, and its bytes dropped before its maps are
/// transposed (a 4096² map: two 128 MiB buffers at a time instead of four).
fn detect_and_read_owned(path: &Path, bytes: Vec<u8>) -> Result<(Reading, Vec<String>)> {
    let first = FORMATS.iter().find(|f| (f.sniff)(&bytes));
    if first.is_some_and(|f| f.name == hdf5::FORMAT) {
        let mut reading = hdf5::read_owned(bytes)?;
        infinities_undefined(&mut reading);
        return Ok((reading, Vec::new()));
    }
    detect_and_read(path, &bytes)
}

/// Reads `bytes` in the format found by content, else by the extension of `path`;
/// infinite heights made undefined.
fn detect_and_read(path: &Path, bytes: &[u8]) -> Result<(Reading, Vec<String>)> {
    let (mut reading, notes) = detect_and_read_raw(path, bytes)?;
    infinities_undefined(&mut reading);
    Ok((reading, notes))
}

fn detect_and_read_raw(path: &Path, bytes: &[u8]) -> Result<(Reading, Vec<String>)> {
    if let Some(f) = FORMATS.iter().find(|f| (f.sniff)(bytes)) {
        return Ok(((f.read)(bytes)?, Vec::new()));
    }
    if let Some(text) = text::without_bom(bytes) {
        // The same file without its byte-order mark, as UTF-8 (no mark any more).
        return detect_and_read_raw(path, &text?);
    }
    if text::sniff(bytes) {
        return read_text(bytes);
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if let Some(f) = FORMATS
        .iter()
        .find(|f| f.extensions.contains(&ext.as_str()))
    {
        // Content did not match the format the extension names: its reader says why.
        return Ok(((f.read)(bytes)?, Vec::new()));
    }
    let known: Vec<&str> = FORMATS.iter().map(|f| f.name).collect();
    Err(bad(
        "topography",
        format!(
            "unknown format (neither {}, nor a text height matrix, x-y-z list or x-z profile, nor .npy)",
            known.join(", ")
        ),
    ))
}

/// A text file: a matrix (with or without a Gwyddion-style header), an x y z list or an
/// x z profile, told apart by [`text::kind`].
fn read_text(bytes: &[u8]) -> Result<(Reading, Vec<String>)> {
    match text::kind(bytes)? {
        text::TextKind::Matrix => Ok((text::read(bytes)?, Vec::new())),
        // Never re-read as a matrix what is no list of coordinates: a layout the reader
        // is not sure of is refused, saying what it saw.
        text::TextKind::Columns => xyz::read_with_notes(bytes),
    }
}

/// The chosen channel of a reading, as a [`Topography`] with its sizes.
fn topography_from(
    path: &Path,
    reading: Reading,
    notes: Vec<String>,
    options: &ReadOptions,
) -> Result<Topography> {
    let names: Vec<String> = reading.channels.iter().map(|c| c.name.clone()).collect();
    let index = choose_channel(&reading.channels, options.channel.as_ref())
        .map_err(|reason| bad_file(path, reason))?;
    let channel = reading
        .channels
        .into_iter()
        .nth(index)
        .expect("index checked");
    let profile = matches!(channel.heights, Heights::Profile(_));
    let (sizes, size_source) =
        sizes_for(&channel, options.size, profile).map_err(|reason| bad_file(path, reason))?;
    let unit = channel
        .unit
        .as_deref()
        .and_then(unit_to_metres)
        .map(|_| "m".to_string());
    Ok(Topography {
        heights: channel.heights,
        sizes,
        provenance: Provenance {
            source: path.to_path_buf(),
            format: reading.format.to_string(),
            channel: channel.name,
            channel_index: index,
            channels: names,
            file_unit: channel.unit,
            unit,
            size_source: size_source.to_string(),
            cleaning: notes,
        },
    })
}

/// The index of the chosen channel, or why there is none.
fn choose_channel(
    channels: &[Channel],
    choice: Option<&ChannelChoice>,
) -> std::result::Result<usize, String> {
    let list = || {
        channels
            .iter()
            .enumerate()
            .map(|(i, c)| format!("{i}: {}", c.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match choice {
        None => channels
            .iter()
            .position(|c| c.is_height)
            .ok_or_else(|| format!("no height channel among {}; choose one", list())),
        Some(ChannelChoice::Index(i)) if *i < channels.len() => Ok(*i),
        Some(ChannelChoice::Index(i)) => Err(format!(
            "no channel {i}: the file holds {} ({})",
            channels.len(),
            list()
        )),
        Some(ChannelChoice::Name(name)) => {
            // Exact matches first; else matches ignoring case. One is the channel; several
            // are refused (never the first taken silently), listed with their indices.
            let matching = |same: &dyn Fn(&str) -> bool| -> Vec<usize> {
                (0..channels.len())
                    .filter(|&i| same(&channels[i].name))
                    .collect()
            };
            let mut found = matching(&|c| c == name);
            if found.is_empty() {
                found = matching(&|c| c.eq_ignore_ascii_case(name));
            }
            match found[..] {
                [i] => Ok(i),
                [] => Err(format!(
                    "no channel named {name:?}; the file holds {}",
                    list()
                )),
                _ => Err(ambiguous(channels, name, &found)),
            }
        }
    }
}

/// Why the name `name`, matching the channels `found`, chooses none: the candidates with
/// their indices, and how to pick one (both front ends take an index where a name goes).
fn ambiguous(channels: &[Channel], name: &str, found: &[usize]) -> String {
    let listed = |sep: &str, f: &dyn Fn(usize) -> String| {
        found.iter().map(|&i| f(i)).collect::<Vec<_>>().join(sep)
    };
    format!(
        "{} channels are named {name:?} ({}): choose one by its 0-based index, channel {}",
        found.len(),
        listed(", ", &|i| format!("{i}: {}", channels[i].name)),
        listed(" or ", &|i| i.to_string()),
    )
}

/// Sizes per axis from the options, else the file; with only x given for a map, y follows
/// from square pixels.
fn sizes_for(
    channel: &Channel,
    given: Option<[Option<f64>; 2]>,
    profile: bool,
) -> std::result::Result<(Vec<f64>, &'static str), String> {
    let valid = |v: f64| crate::is_positive_finite(v);
    let shape = channel.heights.shape();
    let (sizes, source) = match given {
        Some([Some(x), y]) => {
            let y = match (profile, y) {
                (true, _) => None,
                (false, Some(y)) => Some(y),
                (false, None) => Some(x * shape[0] as f64 / shape[1] as f64),
            };
            ([Some(x), y], "given")
        }
        _ => (channel.size, "file"),
    };
    let needed = if profile { 1 } else { 2 };
    let sizes: Vec<f64> = sizes[..needed].iter().map_while(|s| *s).collect();
    if sizes.len() < needed {
        return Err("the file carries no physical size: give the size (x, and y for a map)".into());
    }
    if let Some(bad) = sizes.iter().find(|s| !valid(**s)) {
        return Err(format!(
            "physical size {bad} ({source}) is not positive and finite"
        ));
    }
    Ok((sizes, source))
}

/// A `.npy` array as a topography: sizes from the options, else from an asperity sidecar
/// (`sizes` of an import, or `spec.size` of a generated surface with square pixels).
fn read_npy_topography(path: &Path, options: &ReadOptions) -> Result<Topography> {
    let array = crate::io::read_npy(path)?;
    let heights = Heights::from_array(array).map_err(|d| {
        bad_file(
            path,
            format!("expected a 1D line or 2D map, found {d} dimensions"),
        )
    })?;
    let mut sidecar = npy_sidecar(path);
    if let (Heights::Areal(h), [Some(x), None], true) =
        (&heights, sidecar.sizes, sidecar.square_pixels)
    {
        // A generated surface records its side along x; its pixels are square.
        sidecar.sizes[1] = Some(x * h.nrows() as f64 / h.ncols() as f64);
    }
    let channel = Channel {
        name: "heights".into(),
        heights,
        size: sidecar.sizes,
        unit: sidecar.unit.clone(),
        is_height: true,
    };
    let profile = matches!(channel.heights, Heights::Profile(_));
    let (sizes, source) =
        sizes_for(&channel, options.size, profile).map_err(|r| bad_file(path, r))?;
    Ok(Topography {
        heights: channel.heights,
        sizes,
        provenance: Provenance {
            source: path.to_path_buf(),
            format: "npy".into(),
            channel: "heights".into(),
            channel_index: 0,
            channels: vec!["heights".into()],
            file_unit: sidecar.unit.clone(),
            unit: sidecar.unit,
            size_source: if source == "file" { "sidecar" } else { source }.into(),
            cleaning: sidecar.cleaning,
        },
    })
}

struct NpySidecar {
    sizes: [Option<f64>; 2],
    /// The sidecar of a generated surface: one side, square pixels.
    square_pixels: bool,
    unit: Option<String>,
    cleaning: Vec<String>,
}

fn npy_sidecar(path: &Path) -> NpySidecar {
    let mut out = NpySidecar {
        sizes: [None, None],
        square_pixels: false,
        unit: None,
        cleaning: Vec::new(),
    };
    let Ok(text) = std::fs::read_to_string(crate::io::sidecar_path(path)) else {
        return out;
    };
    let Ok(value) = serde_json::from_str::<serde_json::Value>(&text) else {
        return out;
    };
    if let Some(sizes) = value["sizes"].as_array() {
        out.sizes = [
            sizes.first().and_then(|v| v.as_f64()),
            sizes.get(1).and_then(|v| v.as_f64()),
        ];
        out.unit = value["unit"].as_str().map(str::to_string);
        if let Some(steps) = value["cleaning"].as_array() {
            out.cleaning = steps
                .iter()
                .filter_map(|s| s.as_str().map(str::to_string))
                .collect();
        }
    } else if let Some(size) = value["spec"]["size"].as_f64() {
        out.sizes = [Some(size), None];
        out.square_pixels = true;
    }
    out
}

#[cfg(test)]
pub(crate) mod test_files {
    //! The real instrument files of `shared/topographies` and their reference readings.

    use std::path::PathBuf;

    use ndarray::ArrayD;
    use ndarray_npy::ReadNpyExt;

    /// `shared/topographies` and where it is looked for: [`super::testkit::set_dir`].
    pub fn folder() -> Option<PathBuf> {
        super::testkit::set_dir("topographies")
    }

    /// The reference heights (SurfaceTopography's, `[x, y]`, metres, NaN undefined).
    pub fn reference(dir: &std::path::Path, name: &str) -> ArrayD<f64> {
        let file = std::fs::File::open(dir.join(format!("{name}.reference.npy"))).unwrap();
        ArrayD::<f64>::read_npy(file).unwrap()
    }

    /// The reference JSON record.
    pub fn record(dir: &std::path::Path, name: &str) -> serde_json::Value {
        let text = std::fs::read_to_string(dir.join(format!("{name}.reference.json"))).unwrap();
        serde_json::from_str(&text).unwrap()
    }

    /// Asserts `a` = `b` to `rel` relative (of the larger magnitude), NaN where NaN.
    pub fn assert_close(a: f64, b: f64, rel: f64, what: &str) {
        if a.is_nan() || b.is_nan() {
            assert!(a.is_nan() && b.is_nan(), "{what}: {a} vs {b}");
            return;
        }
        let scale = a.abs().max(b.abs());
        assert!((a - b).abs() <= rel * scale, "{what}: {a} vs {b}");
    }

    /// Truncations and seeded bit flips of `bytes`: each must give `Ok` or `Err`, never a
    /// panic (the fuzz-style property test of every reader).
    pub fn fuzz(bytes: &[u8], read: impl Fn(&[u8]) -> crate::Result<super::Reading>) {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(11);
        let start = std::time::Instant::now();
        let mut cuts: Vec<usize> = (0..bytes.len().min(64)).collect();
        cuts.extend((0..64).map(|_| rng.random_range(0..bytes.len().max(1))));
        for cut in cuts {
            let _ = read(&bytes[..cut.min(bytes.len())]);
        }
        // 300 corrupted copies within 5 s; `ASPERITY_FUZZ_MS` (milliseconds) runs as many
        // as fit in that time instead, for a longer run by hand (as `testkit`'s loops).
        let (tries, budget) = match std::env::var("ASPERITY_FUZZ_MS")
            .ok()
            .and_then(|v| v.parse().ok())
        {
            Some(ms) => (usize::MAX, std::time::Duration::from_millis(ms)),
            None => (300, std::time::Duration::from_secs(5)),
        };
        let mut copy = bytes.to_vec();
        let mut done = 0;
        for _ in 0..tries {
            if start.elapsed() > budget || copy.is_empty() {
                break;
            }
            done += 1;
            copy.copy_from_slice(bytes);
            for _ in 0..rng.random_range(1..8) {
                // Flips concentrated in the header, where the sizes live.
                let limit = if rng.random_bool(0.7) {
                    copy.len().min(2048)
                } else {
                    copy.len()
                };
                let i = rng.random_range(0..limit);
                copy[i] ^= 1 << rng.random_range(0..8);
            }
            if let Ok(r) = read(&copy) {
                assert!(!r.channels.is_empty());
                for c in &r.channels {
                    assert!(!c.heights.is_empty());
                }
            }
        }
        eprintln!("{done} corrupted copies read without a panic");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_converted_to_metres() {
        assert_eq!(unit_to_metres("µm"), Some(1e-6));
        assert_eq!(unit_to_metres("um"), Some(1e-6));
        assert_eq!(unit_to_metres("Micrometer"), Some(1e-6));
        assert_eq!(unit_to_metres("nm"), Some(1e-9));
        assert_eq!(unit_to_metres("V"), None);
        assert_eq!(canonical_unit("um"), "µm");
    }

    #[test]
    fn channel_choice_by_name_index_and_default() {
        let ch = |name: &str, is_height| Channel {
            name: name.into(),
            heights: Heights::Profile(Array1::zeros(2)),
            size: [Some(1.0), None],
            unit: None,
            is_height,
        };
        let channels = vec![
            ch("Amplitude", false),
            ch("Height", true),
            ch("Phase", false),
        ];
        assert_eq!(choose_channel(&channels, None), Ok(1));
        let name = ChannelChoice::Name("phase".into());
        assert_eq!(choose_channel(&channels, Some(&name)), Ok(2));
        assert_eq!(
            "2".parse::<ChannelChoice>().unwrap(),
            ChannelChoice::Index(2)
        );
        let err = choose_channel(&channels, Some(&ChannelChoice::Index(3))).unwrap_err();
        assert!(err.contains("0: Amplitude"), "{err}");
        assert!(choose_channel(&channels[..1], None).is_err());
        // A name two channels share is refused with both indices, exactly or ignoring
        // case; an exact match among case variants is the one meant.
        let twice = vec![
            ch("Height", true),
            ch("Deflection", false),
            ch("Height", true),
            ch("HEIGHT", false),
        ];
        let name = ChannelChoice::Name("Height".into());
        let err = choose_channel(&twice, Some(&name)).unwrap_err();
        assert_eq!(
            err,
            "2 channels are named \"Height\" (0: Height, 2: Height): choose one by its \
             0-based index, channel 0 or 2"
        );
        let name = ChannelChoice::Name("height".into());
        let err = choose_channel(&twice, Some(&name)).unwrap_err();
        assert!(err.starts_with("3 channels are named"), "{err}");
        let name = ChannelChoice::Name("HEIGHT".into());
        assert_eq!(choose_channel(&twice, Some(&name)), Ok(3));
        assert_eq!(
            choose_channel(&twice, Some(&ChannelChoice::Index(2))),
            Ok(2)
        );
    }

    #[test]
    fn a_file_without_size_is_refused_unless_given() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.txt");
        std::fs::write(&path, "1 2 3 4\n5 6 7 8\n9 10 11 12\n").unwrap();
        let err = read_file(&path, &ReadOptions::default()).unwrap_err();
        assert!(err.to_string().contains("no physical size"), "{err}");
        let options = ReadOptions {
            size: Some([Some(4e-6), None]),
            ..ReadOptions::default()
        };
        let t = read_file(&path, &options).unwrap();
        assert_eq!(t.sizes, vec![4e-6, 3e-6]); // square pixels
        assert_eq!(t.provenance.size_source, "given");
        assert_eq!(t.provenance.unit, None);
    }

    #[test]
    fn a_generated_surface_reads_back_with_both_sizes() {
        // `asperity surface` records `spec.size` along x; its pixels are square, so y
        // follows (a 16 x 32 map of side 2 is 2 x 1).
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.npy");
        let heights = Array2::from_shape_fn((16, 32), |(r, c)| (r * 32 + c) as f64);
        crate::io::write_npy_2d(&path, false, &heights).unwrap();
        let sidecar = serde_json::json!({"kind": "surface", "spec": {"size": 2.0}});
        crate::io::write_json(&crate::io::sidecar_path(&path), false, &sidecar).unwrap();
        let t = read_file(&path, &ReadOptions::default()).unwrap();
        assert_eq!(t.sizes, vec![2.0, 1.0]);
        assert_eq!(t.provenance.size_source, "sidecar");
        assert_eq!(t.heights, Heights::Areal(heights));
    }

    #[test]
    fn only_regular_files_within_the_cap() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_file(dir.path(), &ReadOptions::default()).unwrap_err();
        assert!(
            err.to_string().contains("is a folder, not a regular file"),
            "{err}"
        );
        #[cfg(unix)]
        {
            // A FIFO is refused at once, not waited on, in the words of every input.
            let fifo = dir.path().join("f.txt");
            let made = std::process::Command::new("mkfifo").arg(&fifo).status();
            assert!(made.unwrap().success());
            let err = read_file(&fifo, &ReadOptions::default()).unwrap_err();
            let once = crate::input::open_regular(&fifo).unwrap_err();
            assert_eq!(err.to_string(), once.to_string());
            assert!(
                err.to_string().contains("is a FIFO, socket or device"),
                "{err}"
            );
        }
        let path = dir.path().join("big.txt");
        std::fs::write(&path, "1 2 3 4\n5 6 7 8\n").unwrap();
        let options = ReadOptions {
            max_bytes: 4,
            ..ReadOptions::default()
        };
        let err = read_file(&path, &options).unwrap_err();
        assert!(err.to_string().contains("allowed"), "{err}");
        let path = dir.path().join("junk.bin");
        std::fs::write(&path, [0u8, 1, 2, 3, 255, 254]).unwrap();
        let err = read_file(&path, &ReadOptions::default()).unwrap_err();
        assert!(err.to_string().contains("unknown format"), "{err}");
        assert_eq!(err.to_string().lines().count(), 1);
    }

    #[test]
    fn cleaning_is_explicit_and_recorded() {
        let tilted = Array2::from_shape_fn((16, 16), |(r, c)| {
            1e-7 * c as f64 + 1e-9 * ((r * 5 + c * 3) as f64).sin()
        });
        let topography = |h: Array2<f64>| Topography {
            heights: Heights::Areal(h),
            sizes: vec![1e-6, 1e-6],
            provenance: Provenance {
                source: "t".into(),
                format: "test".into(),
                channel: "h".into(),
                channel_index: 0,
                channels: vec!["h".into()],
                file_unit: Some("m".into()),
                unit: Some("m".into()),
                size_source: "file".into(),
                cleaning: Vec::new(),
            },
        };
        let mut t = topography(tilted.clone());
        assert_eq!(clean(&mut t, Levelling::Unchosen, None).unwrap().len(), 1);
        assert!(t.provenance.cleaning.is_empty());
        let mut t = topography(tilted.clone());
        assert!(clean(&mut t, Levelling::None, None).unwrap().is_empty());
        assert_eq!(t.provenance.cleaning, ["no levelling"]);
        let mut holed = tilted;
        holed[(3, 4)] = f64::NAN;
        holed[(9, 9)] = f64::NAN;
        let mut t = topography(holed.clone());
        let err = clean(&mut t, Levelling::By(level::Detrend::Polynomial(1)), None).unwrap_err();
        assert!(
            err.to_string().contains("2 of 256 points are undefined"),
            "{err}"
        );
        assert!(clean(&mut t, Levelling::None, Some(Fill::Refuse)).is_err());
        let by = Levelling::By(level::Detrend::Polynomial(1));
        let warnings = clean(&mut t, by, Some(Fill::Harmonic)).unwrap();
        assert!(warnings.is_empty());
        assert_eq!(
            t.provenance.cleaning.len(),
            2,
            "{:?}",
            t.provenance.cleaning
        );
        assert_eq!(t.heights.undefined_count(), 0);
    }

    #[test]
    fn detection_by_content_not_extension() {
        // An X3P file named .txt is still read as X3P.
        let dir = tempfile::tempdir().unwrap();
        let h = Array2::from_shape_fn((3, 4), |(r, c)| (r * 4 + c) as f64 * 1e-9);
        let path = dir.path().join("scan.txt");
        std::fs::write(&path, x3p::to_bytes(h.view(), [4e-6, 3e-6]).unwrap()).unwrap();
        let t = read_file(&path, &ReadOptions::default()).unwrap();
        assert_eq!(t.provenance.format, "x3p");
        assert_eq!(t.heights, Heights::Areal(h));
        // A truncated .x3p is reported by the X3P reader (extension second).
        let path = dir.path().join("cut.x3p");
        std::fs::write(&path, b"PK\x05").unwrap();
        let err = read_file(&path, &ReadOptions::default()).unwrap_err();
        assert!(err.to_string().contains("x3p"), "{err}");
    }
}

#[cfg(test)]
mod shared_sets {
    //! The binary files of `shared/topographies-2` read like SurfaceTopography 1.27.1's
    //! reference, one test per file (the text and X3P files are tested beside their
    //! readers).
    use super::testkit::{check_shared, Expect};

    fn check(name: &str) {
        check_shared("topographies-2", name, Expect::default());
    }

    #[test]
    fn di_2_height_height_deflection() {
        check("di-2.di");
    }

    #[test]
    fn di_3_zsensor_first_of_four() {
        check("di-3.di");
    }

    #[test]
    fn di_4_zsensor_amplitude_phase() {
        check("di-4.di");
    }

    #[test]
    fn di_5_zsensor_peak_force_error() {
        check("di-5.di");
    }

    #[test]
    fn di_6_two_heights_phase_amplitude() {
        check("di-6.di");
    }

    #[test]
    fn frt_1_with_undefined_points() {
        check("frt-1.frt");
    }

    #[test]
    fn sur_3_with_undefined_points() {
        check("sur-3.sur");
    }

    #[test]
    fn wsxm_top_1() {
        check("top-1.top");
    }
}

#[cfg(test)]
mod every_shared_file {
    //! Every real file of the three shared sets is recognised and read (each reader's own
    //! test checks it against the reference, and `audit` compares every file field by
    //! field; this one catches a file no reader claims).

    #[test]
    fn every_file_of_the_shared_sets_is_read() {
        let mut read = 0;
        let mut failed = Vec::new();
        for set in ["topographies", "topographies-2", "topographies-3"] {
            let Some(dir) = super::testkit::set_dir(set) else {
                return;
            };
            let mut names: Vec<String> = std::fs::read_dir(&dir)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
                .filter(|n| !n.contains(".reference") && n != "README.md")
                .collect();
            names.sort();
            for name in names {
                let path = dir.join(&name);
                let bytes = std::fs::read(&path).unwrap();
                match super::detect_and_read(&path, &bytes) {
                    Ok(_) => read += 1,
                    Err(e) => failed.push(format!("{set}/{name}: {e}")),
                }
            }
        }
        assert!(failed.is_empty(), "not read: {failed:#?}");
        // 16 + 21 + 8 files in the three sets.
        assert_eq!(read, 45);
    }
}
