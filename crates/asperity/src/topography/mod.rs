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
//! `read(bytes: &[u8]) -> Result<Reading>`, that parses untrusted bytes without panicking.

use ndarray::{Array1, Array2};

/// The heights of one channel: a map or a line profile.
#[derive(Debug, Clone, PartialEq)]
pub enum Heights {
    /// A map, `(rows, cols) = (ny, nx)`, metres, NaN where undefined.
    Areal(Array2<f64>),
    /// A line profile along x, metres, NaN where undefined.
    Profile(Array1<f64>),
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

pub(crate) mod al3d;
pub(crate) mod bytes;
pub(crate) mod di;
pub(crate) mod frt;
pub(crate) mod metropro;
pub(crate) mod opd;
pub(crate) mod plu;
pub(crate) mod sur;
#[cfg(test)]
mod testkit;
pub(crate) mod tmd;
pub(crate) mod wsxm;
