//! `asperity surface` / `asperity line` and Python's `surface()` / `line()`: the request
//! ([`SurfaceRequest`]), its validation into the library's spec and seed, the check that the
//! generated heights are representable, and the one sidecar both front ends write.

use asperity::input::short_number;
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::stats::Summary;
use asperity::surface::{LineSpec, Normalisation, SurfaceSpec};
use serde::{Deserialize, Serialize};
use serde_json::json;

use crate::refusal::{count, Param, Refusal, RequestError};

/// The parameters of `asperity surface` and `asperity line`, as each front end names them.
pub mod params {
    use crate::refusal::Param;

    /// Points along x.
    pub const N: Param = Param::new("--n", "n");
    /// Points along y.
    pub const M: Param = Param::new("--m", "m");
    /// The Hurst exponent.
    pub const HURST: Param = Param::new("--hurst", "hurst");
    /// The roll-off.
    pub const ROLLOFF: Param = Param::new("--rolloff", "rolloff");
    /// The long-wavelength cut-off.
    pub const CUTOFF: Param = Param::new("--cutoff", "cutoff");
    /// The short-wavelength cut-off.
    pub const SHORT_CUTOFF: Param = Param::new("--short-cutoff", "short_cutoff");
    /// The rms height.
    pub const RMS_HEIGHT: Param = Param::new("--rms-height", "rms_height");
    /// The rms slope.
    pub const RMS_SLOPE: Param = Param::new("--rms-slope", "rms_slope");
    /// The side length.
    pub const SIZE: Param = Param::new("--size", "size");
    /// The random seed.
    pub const SEED: Param = Param::new("--seed", "seed");
}

use params::*;

/// Parses a random seed: a whole number from 0 to `u64::MAX`, written as such (`1.5`,
/// `-1` or `1e3` are refused, not rounded).
pub fn parse_seed(text: &str) -> Result<u64, Refusal> {
    text.trim().parse::<u64>().map_err(|_| {
        Refusal::of(SEED).text(format!(
            " must be a whole number from 0 to {}, got {}",
            u64::MAX,
            asperity::input::clip(text)
        ))
    })
}

/// The grid's counts as a front end holds them, signed (a flag's text, a Python int):
/// `n` and a surface's `m` ([`count`]: a negative one refused as `--n must be at least 1,
/// got -16` by both front ends; 0 and 1 by the library's rule on the grid).
///
/// ```
/// use asperity_app::surface::grid;
/// use asperity_app::Names;
///
/// assert_eq!(grid(64, Some(32)).unwrap(), (64, Some(32)));
/// let refusal = grid(64, Some(-3)).unwrap_err();
/// assert_eq!(refusal.words(Names::Flags), "--m must be at least 1, got -3");
/// assert_eq!(grid(-16, None).unwrap_err().words(Names::Keywords), "n must be at least 1, got -16");
/// ```
pub fn grid(n: i128, m: Option<i128>) -> Result<(usize, Option<usize>), Refusal> {
    Ok((count(N, n)?, m.map(|m| count(M, m)).transpose()?))
}

/// A surface or line request, as given.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceRequest {
    /// Points along x.
    pub n: usize,
    /// Points along y (a surface; default `n`); `None` for a line.
    pub m: Option<usize>,
    /// H.
    pub hurst: f64,
    /// q0·L/2π of a roll-off.
    pub rolloff: Option<f64>,
    /// q0·L/2π of a cut-off.
    pub cutoff: Option<f64>,
    /// q1·L/2π (surfaces only).
    pub short_cutoff: Option<f64>,
    /// Scale to this rms height.
    pub rms_height: Option<f64>,
    /// Scale to this rms slope.
    pub rms_slope: Option<f64>,
    /// L along x.
    pub size: f64,
    /// The seed, as written (see [`parse_seed`]).
    pub seed: String,
}

/// The side length L when none is given: of a generated surface or line, and of a plain
/// array with no sidecar (`--size`, `size=`).
pub const DEFAULT_SIZE: f64 = 1.0;

impl Default for SurfaceRequest {
    /// 256 points, H = 0.8, no cut-offs, unit rms height, L = 1, seed 0.
    fn default() -> Self {
        SurfaceRequest {
            n: 256,
            m: None,
            hurst: 0.8,
            rolloff: None,
            cutoff: None,
            short_cutoff: None,
            rms_height: None,
            rms_slope: None,
            size: DEFAULT_SIZE,
            seed: "0".into(),
        }
    }
}

impl SurfaceRequest {
    /// The spectrum and normalisation, or why not (the one-of rules).
    fn spectrum(&self) -> Result<(Psd, Normalisation), RequestError> {
        let long = match (self.rolloff, self.cutoff) {
            (Some(_), Some(_)) => {
                return Err(at_most_one(ROLLOFF, CUTOFF)
                    .text(" (a roll-off keeps the power below q0 flat, a cut-off removes it)")
                    .into())
            }
            (Some(q0), None) => LongWavelength::RollOff { q0 },
            (None, Some(q0)) => LongWavelength::CutOff { q0 },
            (None, None) => LongWavelength::None,
        };
        let normalisation = match (self.rms_height, self.rms_slope) {
            (Some(_), Some(_)) => return Err(at_most_one(RMS_HEIGHT, RMS_SLOPE).into()),
            (_, Some(s)) => Normalisation::RmsSlope(s),
            (Some(h), None) => Normalisation::RmsHeight(h),
            (None, None) => Normalisation::default(),
        };
        let psd = Psd::new(self.hurst, long, self.short_cutoff).map_err(invalid)?;
        Ok((psd, normalisation))
    }

    /// A surface's spec and seed, or why not.
    pub fn surface(&self) -> Result<(SurfaceSpec, u64), RequestError> {
        let seed = parse_seed(&self.seed)?;
        let (psd, normalisation) = self.spectrum()?;
        let rows = self.m.unwrap_or(self.n);
        let spec =
            SurfaceSpec::new(rows, self.n, self.size, psd, normalisation).map_err(invalid)?;
        Ok((spec, seed))
    }

    /// A line's spec and seed, or why not (a line has no short cut-off).
    pub fn line(&self) -> Result<(LineSpec, u64), RequestError> {
        let seed = parse_seed(&self.seed)?;
        let (psd, normalisation) = self.spectrum()?;
        let spec = LineSpec::new(self.n, self.size, psd, normalisation).map_err(invalid)?;
        Ok((spec, seed))
    }
}

fn at_most_one(a: Param, b: Param) -> Refusal {
    Refusal::saying("give at most one of ")
        .param(a)
        .text(" and ")
        .param(b)
}

/// A library error about the request (its own words, which name the parameter).
fn invalid(source: asperity::Error) -> RequestError {
    RequestError::Invalid(Box::new(source))
}

/// Refuses a generated profile that float64 cannot represent: heights that underflow to
/// zero or into the subnormal range, where they keep only a few bits (a tiny rms height),
/// or slopes that overflow (a tiny size), naming the inputs.
pub fn ensure_usable(summary: &Summary, size: f64) -> Result<(), Refusal> {
    if !(summary.rms_height.is_finite() && summary.rms_height >= f64::MIN_POSITIVE) {
        return Err(Refusal::saying(format!(
            "the generated heights are not representable (rms height {}): ",
            short_number(summary.rms_height)
        ))
        .param(RMS_HEIGHT)
        .text(" or ")
        .param(RMS_SLOPE)
        .text(" with ")
        .param(SIZE)
        .text(format!(
            " {} is beyond the range of float64",
            short_number(size)
        )));
    }
    if !(summary.rms_slope.is_finite() && summary.rms_slope > 0.0) {
        return Err(Refusal::saying(format!(
            "the generated slopes are not representable (rms slope {}): ",
            short_number(summary.rms_slope)
        ))
        .param(SIZE)
        .text(format!(
            " {} is too small for float64 slopes",
            short_number(size)
        )));
    }
    Ok(())
}

/// The sidecar `FILE.npy.json` of a generated surface or line (`kind`), the one both front
/// ends write: the generator, the shape, the seed, the spec and the statistics.
pub fn sidecar(
    kind: &str,
    shape: &[usize],
    seed: u64,
    spec: &impl Serialize,
    stats: &Summary,
) -> serde_json::Value {
    json!({
        "kind": kind,
        "generator": format!("asperity {}", env!("CARGO_PKG_VERSION")),
        "shape": shape,
        "seed": seed,
        "spec": spec,
        "stats": stats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;

    #[test]
    fn seeds_are_whole_numbers_not_rounded() {
        assert_eq!(parse_seed("7"), Ok(7));
        assert_eq!(parse_seed("18446744073709551615"), Ok(u64::MAX));
        for text in ["1.5", "-1", "1e3", "", "True"] {
            let err = parse_seed(text).unwrap_err().words(Names::Keywords);
            assert!(
                err.starts_with("seed must be a whole number from 0 to 18446744073709551615"),
                "{text}: {err}"
            );
        }
    }

    #[test]
    fn one_of_rules_name_both_parameters() {
        let request = SurfaceRequest {
            rolloff: Some(2.0),
            cutoff: Some(2.0),
            ..SurfaceRequest::default()
        };
        let err = request.surface().unwrap_err().words(Names::Flags);
        assert!(
            err.starts_with("give at most one of --rolloff and --cutoff"),
            "{err}"
        );
        let request = SurfaceRequest {
            rms_height: Some(1.0),
            rms_slope: Some(1.0),
            ..SurfaceRequest::default()
        };
        let err = request.line().unwrap_err().words(Names::Keywords);
        assert_eq!(err, "give at most one of rms_height and rms_slope");
    }
}
