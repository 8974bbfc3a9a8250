//! `asperity stats` and Python's `stats()` / `psd()`: the statistics of a surface or line —
//! rms height, slope and curvature, the (radially averaged) PSD and its power-law fit, and
//! for a measured topography the ISO 25178 / ISO 4287 parameters — computed by one path
//! ([`compute`]) for both front ends, rectangular pixels included, with one rule for the
//! PSD fit range ([`fit_range`]).

use asperity::fit::{power_law_fit, PowerLawFit};
use asperity::surface::stats::{
    line_psd, line_summary, radial_psd_2d, surface_summary, PsdBin, Summary,
};
use asperity::surface::window::{windowed_line, windowed_map, Window};
use asperity::surface::{Line, Surface};
use asperity::topography::stats as topo_stats;
use asperity::topography::Heights;
use ndarray::{ArrayD, Ix1, Ix2};
use serde::Serialize;

use crate::refusal::{Param, Refusal, RequestError};

pub mod analysis;

/// The parameters of `asperity stats`.
pub mod params {
    use crate::refusal::Param;

    /// The lower end of the PSD fit range, as q·L/2π.
    pub const FIT_FROM: Param = Param::new("--fit-from", "fit_from");
    /// The upper end of the PSD fit range, as q·L/2π.
    pub const FIT_TO: Param = Param::new("--fit-to", "fit_to");
    /// The window applied before the PSD's FFT.
    pub const WINDOW: Param = Param::new("--window", "window");
    /// The PSD's normalisation.
    pub const CONVENTION: Param = Param::new("--psd-convention", "convention");
}

use params::*;

/// The lower end of the PSD fit range when nothing else sets it, as q·L/2π: the ring at 1
/// (one wavelength per side) holds the fewest modes and the window's edge.
pub const DEFAULT_FIT_FROM: f64 = 2.0;

/// The window when none is named (`--window`, `window=`): none, the scan is one period.
pub const DEFAULT_WINDOW: &str = "none";

/// The PSD's normalisation when none is named (`--psd-convention`, `convention=`).
pub const DEFAULT_CONVENTION: &str = "asperity";

/// A stats request: the ends of the PSD fit range, as given (`None`: the defaults of
/// [`fit_range`]), the window and the PSD's normalisation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct StatsRequest {
    /// Lower end, q·L/2π.
    pub fit_from: Option<f64>,
    /// Upper end, q·L/2π.
    pub fit_to: Option<f64>,
    /// The window of the PSD (the statistics are of the heights as they are).
    #[serde(default)]
    pub window: Window,
    /// The normalisation the PSD is reported in.
    #[serde(default)]
    pub convention: PsdConvention,
}

/// How a PSD is normalised. asperity's (the library's, the generators'): `Σ_q C2D(q)
/// (2π)²/A = rms²` over the modes of a map, `Σ_q C1D(q) 2π/L = rms²` over both signs of q
/// along a line, so that `∫ C2D d²q = rms²` and `∫ C1D dq = rms²` (Persson's convention).
/// SurfaceTopography's: `C2D = |h̃(q)|²/A` and `C1D = |h̃(q)|²/L` with `h̃` the
/// continuous Fourier transform, so that `∫ C d^dq/(2π)^d = rms²`: the same spectrum times
/// `(2π)²` on a map and `2π` along a line.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PsdConvention {
    /// asperity's: `∫ C d^dq = rms²`.
    #[default]
    Asperity,
    /// SurfaceTopography's: `∫ C d^dq / (2π)^d = rms²`.
    SurfaceTopography,
}

impl PsdConvention {
    /// The convention named `name` (`asperity` or `surface-topography`), or why not.
    pub fn parse(name: &str) -> Result<Self, Refusal> {
        match name {
            "asperity" => Ok(PsdConvention::Asperity),
            "surface-topography" => Ok(PsdConvention::SurfaceTopography),
            _ => Err(Refusal::of(CONVENTION).text(format!(
                " must be asperity or surface-topography, got {:?}",
                asperity::input::clip(name)
            ))),
        }
    }

    /// The factor from asperity's PSD of a `dims`-dimensional grid to this convention's.
    pub fn factor(self, dims: usize) -> f64 {
        match self {
            PsdConvention::Asperity => 1.0,
            PsdConvention::SurfaceTopography => std::f64::consts::TAU.powi(dims as i32),
        }
    }
}

/// The window named `name` (`none` or `hann`), or why not.
pub fn parse_window(name: &str) -> Result<Window, Refusal> {
    match name {
        "none" => Ok(Window::None),
        "hann" => Ok(Window::Hann),
        _ => Err(Refusal::of(WINDOW).text(format!(
            " must be none or hann, got {:?}",
            asperity::input::clip(name)
        ))),
    }
}

impl StatsRequest {
    /// Refuses an end that is no positive number, or a range the two leave empty.
    pub fn validate(&self) -> Result<(), Refusal> {
        fit_bound(FIT_FROM, self.fit_from)?;
        fit_bound(FIT_TO, self.fit_to)?;
        if let (Some(from), Some(to)) = (self.fit_from, self.fit_to) {
            if from >= to {
                return Err(Refusal::saying("invalid PSD fit range: ")
                    .param(FIT_FROM)
                    .text(format!(" {from} must be below "))
                    .param(FIT_TO)
                    .text(format!(" {to}")));
            }
        }
        Ok(())
    }
}

fn fit_bound(param: Param, value: Option<f64>) -> Result<(), Refusal> {
    match value {
        Some(v) if !(v.is_finite() && v > 0.0) => {
            Err(Refusal::saying("invalid ").param(param).text(format!(
                ": must be a positive number of wavelengths per side, got {}",
                crate::refusal::number(v)
            )))
        }
        _ => Ok(()),
    }
}

/// What a generated surface's spec (its sidecar, or a Python `Surface`'s metadata) says of
/// its spectrum: the side length and the spectrum's limits (as q·L/2π).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SpectrumHints {
    /// L along x.
    pub size: Option<f64>,
    /// Roll-off (`true`) or cut-off (`false`) wavenumber q0.
    pub long_wavelength: Option<(bool, f64)>,
    /// Short cut-off q1.
    pub short_cutoff: Option<f64>,
}

impl SpectrumHints {
    /// The hints of a generator's sidecar (`{"spec": {"size", "psd": {...}}}`); anything
    /// else (an import record) gives none.
    pub fn from_sidecar(value: &serde_json::Value) -> Self {
        let spec = &value["spec"];
        let long = &spec["psd"]["long_wavelength"];
        let positive = |v: &serde_json::Value| v.as_f64().filter(|x| x.is_finite() && *x > 0.0);
        SpectrumHints {
            size: positive(&spec["size"]),
            long_wavelength: match (long["kind"].as_str(), positive(&long["q0"])) {
                (Some("roll_off"), Some(q0)) => Some((true, q0)),
                (Some("cut_off"), Some(q0)) => Some((false, q0)),
                _ => None,
            },
            short_cutoff: positive(&spec["psd"]["short_cutoff"]),
        }
    }
}

/// What the statistics are computed from.
#[derive(Debug, Clone)]
pub enum StatsSource {
    /// Heights on square pixels (a generated surface or line, a plain `.npy`, a numpy
    /// array): side `size` along x, with what its spec says of its spectrum.
    Grid {
        /// A line (1D) or a surface (2D, rows along y).
        heights: ArrayD<f64>,
        /// L along x.
        size: f64,
        /// The spectrum's limits from its spec, which set the default fit range.
        hints: SpectrumHints,
    },
    /// A measured topography: a size per axis (pixels may be rectangular); adds the ISO
    /// parameters.
    Measured {
        /// The heights (levelled and filled as asked).
        heights: Heights,
        /// `[x]` for a profile, `[x, y]` for a map.
        sizes: Vec<f64>,
    },
}

/// The statistics of a surface or line, as both front ends report them.
#[derive(Debug, Clone)]
pub struct Statistics {
    /// rms height, slope and curvature.
    pub summary: Summary,
    /// The PSD's bins (rings for a surface).
    pub bins: Vec<PsdBin>,
    /// The shape.
    pub dims: Vec<usize>,
    /// L along x: the unit of q·L/2π.
    pub size: f64,
    /// The ISO 25178 / 4287 parameters (measured topographies).
    pub iso: Option<serde_json::Value>,
    /// The fit range and where its ends come from.
    pub plan: FitPlan,
    /// The power law over the range (`None`: no range, or fewer than 2 bins with power).
    pub fit: Option<PowerLawFit>,
    /// `H = −(slope + d)/2` (d = 2 for a surface, 1 for a line).
    pub hurst: Option<f64>,
    /// The last ring, q·L/2π.
    pub nyquist: f64,
}

impl Statistics {
    /// The wavelengths per side `q·L/2π` of a wavenumber.
    pub fn wavenumber(&self, q: f64) -> f64 {
        q * self.size / std::f64::consts::TAU
    }
}

/// The statistics of `source` with the fit range of `request`: validated, computed, checked
/// finite, fitted. A refusal of the data starts with `subject` (the file, or `heights`).
pub fn compute(
    request: &StatsRequest,
    source: StatsSource,
    subject: &str,
) -> Result<Statistics, RequestError> {
    request.validate()?;
    let about = |r: Refusal| RequestError::from(Refusal::saying(format!("{subject}: ")).join(&r));
    let (hints, inputs) = match source {
        StatsSource::Grid {
            heights,
            size,
            hints,
        } => (hints, grid_inputs(heights, size, request.window, about)?),
        StatsSource::Measured { heights, sizes } => (
            SpectrumHints::default(),
            measured_inputs(heights, &sizes, request.window)?,
        ),
    };
    let mut inputs = inputs;
    let factor = request.convention.factor(inputs.dims.len());
    inputs.bins.iter_mut().for_each(|b| b.psd *= factor);
    ensure_finite(&inputs.summary, &inputs.bins).map_err(about)?;
    let ring = |q: f64| (q * inputs.size / std::f64::consts::TAU).round();
    let nyquist = inputs.bins.last().map_or(0.0, |b| ring(b.q));
    let plan = fit_range(request, &hints, nyquist)?;
    let fit = plan.range.and_then(|(from, to)| {
        let (q, c): (Vec<f64>, Vec<f64>) = inputs
            .bins
            .iter()
            .filter(|b| (from..=to).contains(&ring(b.q)) && b.psd > 0.0)
            .map(|b| (b.q, b.psd))
            .unzip();
        power_law_fit(&q, &c).ok()
    });
    // C2D ∝ q^(-2H-2), C1D ∝ q^(-2H-1): H = -(slope + d)/2.
    let d = inputs.dims.len() as f64;
    let hurst = fit.map(|f| -(f.exponent + d) / 2.0);
    Ok(Statistics {
        summary: inputs.summary,
        bins: inputs.bins,
        dims: inputs.dims,
        size: inputs.size,
        iso: inputs.iso,
        plan,
        fit,
        hurst,
        nyquist,
    })
}

struct Inputs {
    summary: Summary,
    bins: Vec<PsdBin>,
    dims: Vec<usize>,
    size: f64,
    iso: Option<serde_json::Value>,
}

/// A library error about the array, in its words (the caller names the file).
fn words(source: asperity::Error) -> Refusal {
    Refusal::saying(source.to_string())
}

fn library(source: asperity::Error) -> RequestError {
    RequestError::Invalid(Box::new(source))
}

/// Square pixels of side `size / cols`; `about` names the array in a refusal of it.
fn grid_inputs(
    heights: ArrayD<f64>,
    size: f64,
    window: Window,
    about: impl Fn(Refusal) -> RequestError,
) -> Result<Inputs, RequestError> {
    let (summary, bins, dims) = match heights.ndim() {
        1 => {
            let h = heights.into_dimensionality::<Ix1>().expect("1D");
            let line = Line::new(h, size).map_err(library)?;
            let bins = windowed_line_psd(&line, window)?;
            (line_summary(&line), bins, vec![line.len()])
        }
        2 => {
            let h = heights.into_dimensionality::<Ix2>().expect("2D");
            let surface = Surface::new(h, size).map_err(library)?;
            let (r, c) = surface.dim();
            let bins = match window {
                Window::None => radial_psd_2d(&surface),
                _ => windowed_surface(&surface, window).and_then(|w| radial_psd_2d(&w)),
            }
            .map_err(|e| about(words(e)))?;
            (surface_summary(&surface), bins, vec![r, c])
        }
        d => {
            return Err(about(Refusal::saying(format!(
                "expected a 1D line or 2D surface, found {d} dimensions"
            ))))
        }
    };
    Ok(Inputs {
        summary,
        bins,
        dims,
        size,
        iso: None,
    })
}

/// The PSD of a line with `window` (none: the library's own PSD, bit for bit).
fn windowed_line_psd(line: &Line, window: Window) -> Result<Vec<PsdBin>, RequestError> {
    if window == Window::None {
        return Ok(line_psd(line));
    }
    let w = windowed_line(line.heights().view(), window);
    Ok(line_psd(&Line::new(w, line.size()).map_err(library)?))
}

/// A surface's heights with `window` (on its sizes per axis).
fn windowed_surface(surface: &Surface, window: Window) -> asperity::Result<Surface> {
    let view = surface.heights().view();
    let w = windowed_map(view, surface.size(), surface.size_y(), window);
    Surface::with_sizes(w, surface.size(), surface.size_y())
}

/// A measured line or map with its ISO parameters; square pixels as [`grid_inputs`] (bit
/// for bit), rectangular ones with a spacing per axis.
fn measured_inputs(
    heights: Heights,
    sizes: &[f64],
    window: Window,
) -> Result<Inputs, RequestError> {
    let dims = heights.shape();
    match heights {
        Heights::Profile(h) => {
            let line = Line::new(h, sizes[0]).map_err(library)?;
            let iso =
                topo_stats::profile(line.heights().view(), line.spacing()).map_err(library)?;
            Ok(Inputs {
                summary: line_summary(&line),
                bins: windowed_line_psd(&line, window)?,
                dims,
                size: line.size(),
                iso: Some(serde_json::to_value(iso).expect("serialises")),
            })
        }
        Heights::Areal(h) => {
            let surface = Surface::with_sizes(h, sizes[0], sizes[1]).map_err(library)?;
            let (dx, dy) = (surface.spacing(), surface.spacing_y());
            let view = surface.heights().view();
            let iso = topo_stats::areal(view, dx, dy).map_err(library)?;
            let windowed = match window {
                Window::None => None,
                _ => Some(windowed_surface(&surface, window).map_err(library)?),
            };
            let spectrum = windowed.as_ref().unwrap_or(&surface);
            let (summary, bins) = if surface.has_square_pixels() {
                let bins = radial_psd_2d(spectrum).map_err(library)?;
                (surface_summary(&surface), bins)
            } else {
                let summary = Summary {
                    rms_height: iso.sq,
                    rms_slope: topo_stats::rms_slope_forward(view, dx, dy),
                    rms_curvature: topo_stats::rms_curvature(view, dx, dy),
                };
                let spectrum_view = spectrum.heights().view();
                let bins = topo_stats::radial_psd(spectrum_view, surface.size(), surface.size_y())
                    .map_err(library)?;
                (summary, bins)
            };
            Ok(Inputs {
                summary,
                bins,
                dims,
                size: surface.size(),
                iso: Some(serde_json::to_value(iso).expect("serialises")),
            })
        }
    }
}

/// Refuses statistics that overflow float64 (heights near 1e308 square to infinity).
fn ensure_finite(summary: &Summary, bins: &[PsdBin]) -> Result<(), Refusal> {
    let values = [summary.rms_height, summary.rms_slope]
        .into_iter()
        .chain(summary.rms_curvature)
        .chain(bins.iter().flat_map(|b| [b.q, b.psd]));
    if values.into_iter().any(|v| !v.is_finite()) {
        return Err(Refusal::saying(
            "its statistics overflow float64 (squares of its heights or slopes exceed \
             1.8e308); rescale the heights",
        ));
    }
    Ok(())
}

/// The PSD fit range, and what the output says about it.
#[derive(Debug, Clone, PartialEq)]
pub struct FitPlan {
    /// Rings `from ..= to` (as q·L/2π); `None` when the default range is empty.
    pub range: Option<(f64, f64)>,
    /// A clamped upper end, or why there is no range.
    pub note: Option<Refusal>,
    /// Where the ends come from, e.g. `the sidecar's roll-off q0 = 6 to Nyquist`.
    pub origin: Refusal,
}

/// The PSD slope is fitted over the rings (bins) `κ = from ..= to`, `κ = round(q·L/2π)`.
/// By default: from [`DEFAULT_FIT_FROM`], or from the roll-off q0 (the knee, as the paper
/// fits), or from the first ring wholly above a cut-off q0 (q0 + 1 for a whole q0: the ring
/// at q0 is half empty); up to the last ring wholly below a short cut-off q1 (q1 − 1),
/// else Nyquist (`nyquist`, the last ring). An upper end beyond Nyquist is clamped to it.
/// A range left empty by the defaults (a roll-off at or above Nyquist, a tiny grid) gives
/// no fit and a note; one made empty by a given end is refused, naming it.
pub fn fit_range(
    request: &StatsRequest,
    hints: &SpectrumHints,
    nyquist: f64,
) -> Result<FitPlan, Refusal> {
    let (default_from, from_why) = default_from(hints);
    let UpperEnd {
        to,
        given: to_given,
        why: to_why,
        note,
    } = upper_end(request, hints, nyquist);
    let from = request.fit_from.unwrap_or(default_from);
    let from_why = match request.fit_from {
        Some(_) => Refusal::of(FIT_FROM),
        None => from_why,
    };
    let origin = Refusal::saying("from ")
        .join(&from_why)
        .text(" to ")
        .join(&to_why);
    if from <= to {
        return Ok(FitPlan {
            range: Some((from, to)),
            note,
            origin,
        });
    }
    match (request.fit_from, to_given) {
        (Some(f), _) => Err(Refusal::saying("invalid ")
            .param(FIT_FROM)
            .text(format!(
                " {f}: the PSD fit range would be empty, its upper end is {to} ("
            ))
            .join(&to_why)
            .text("); give a smaller ")
            .param(FIT_FROM)),
        (None, true) => Err(Refusal::saying("invalid ")
            .param(FIT_TO)
            .text(format!(
                " {to}: the PSD fit range would be empty, its lower end is {from} ("
            ))
            .join(&from_why)
            .text("); give a larger ")
            .param(FIT_TO)
            .text(" or a smaller ")
            .param(FIT_FROM)),
        (None, false) => Ok(FitPlan {
            range: None,
            note: Some(
                Refusal::saying(format!(
                    "no PSD fit: the default range is empty, from {from} ("
                ))
                .join(&from_why)
                .text(format!(") to {to} ("))
                .join(&to_why)
                .text("); set ")
                .param(FIT_FROM)
                .text(" and ")
                .param(FIT_TO),
            ),
            origin,
        }),
    }
}

/// The upper end of the fit range, whether it was given (and not clamped), where it comes
/// from, and the note of a clamped one.
struct UpperEnd {
    to: f64,
    given: bool,
    why: Refusal,
    note: Option<Refusal>,
}

fn upper_end(request: &StatsRequest, hints: &SpectrumHints, nyquist: f64) -> UpperEnd {
    let end = |to, given, why| UpperEnd {
        to,
        given,
        why,
        note: None,
    };
    match (request.fit_to, hints.short_cutoff) {
        (Some(t), _) if t > nyquist => UpperEnd {
            note: Some(
                Refusal::of(FIT_TO)
                    .text(format!(" {t} is beyond Nyquist ({nyquist}): clamped to it")),
            ),
            ..end(
                nyquist,
                false,
                Refusal::saying("Nyquist; ")
                    .param(FIT_TO)
                    .text(format!(" {t} clamped to it")),
            )
        },
        (Some(t), _) => end(t, true, Refusal::of(FIT_TO)),
        (None, Some(q1)) if (q1 - 0.5).floor() < nyquist => end(
            (q1 - 0.5).floor(),
            false,
            Refusal::saying(format!(
                "the last ring wholly below the sidecar's short cut-off q1 = {q1}"
            )),
        ),
        (None, _) => end(nyquist, false, Refusal::saying("Nyquist")),
    }
}

/// The default lower end and where it comes from.
fn default_from(hints: &SpectrumHints) -> (f64, Refusal) {
    match hints.long_wavelength {
        Some((true, q0)) if q0 > DEFAULT_FIT_FROM => (
            q0,
            Refusal::saying(format!("the sidecar's roll-off q0 = {q0}")),
        ),
        Some((false, q0)) if (q0 + 0.5).ceil() > DEFAULT_FIT_FROM => (
            (q0 + 0.5).ceil(),
            Refusal::saying(format!(
                "the first ring wholly above the sidecar's cut-off q0 = {q0}"
            )),
        ),
        _ => (DEFAULT_FIT_FROM, Refusal::saying("the default lower end")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;

    fn plan(from: Option<f64>, to: Option<f64>, hints: SpectrumHints) -> Result<FitPlan, Refusal> {
        let request = StatsRequest {
            fit_from: from,
            fit_to: to,
            ..StatsRequest::default()
        };
        fit_range(&request, &hints, 64.0)
    }

    #[test]
    fn the_default_range_starts_at_2_or_at_the_spectrums_knee() {
        let none = SpectrumHints::default();
        assert_eq!(plan(None, None, none).unwrap().range, Some((2.0, 64.0)));
        let rolloff = SpectrumHints {
            long_wavelength: Some((true, 6.0)),
            short_cutoff: Some(32.0),
            ..none
        };
        let p = plan(None, None, rolloff).unwrap();
        assert_eq!(p.range, Some((6.0, 31.0)));
        assert_eq!(
            p.origin.words(Names::Keywords),
            "from the sidecar's roll-off q0 = 6 to the last ring wholly below the sidecar's \
             short cut-off q1 = 32"
        );
        let cutoff = SpectrumHints {
            long_wavelength: Some((false, 4.0)),
            ..none
        };
        assert_eq!(plan(None, None, cutoff).unwrap().range, Some((5.0, 64.0)));
    }

    #[test]
    fn ends_are_refused_or_clamped_in_the_front_ends_words() {
        let none = SpectrumHints::default();
        let p = plan(None, Some(100.0), none).unwrap();
        assert_eq!(p.range, Some((2.0, 64.0)));
        assert_eq!(
            p.note.unwrap().words(Names::Flags),
            "--fit-to 100 is beyond Nyquist (64): clamped to it"
        );
        let e = plan(Some(70.0), None, none).unwrap_err();
        assert_eq!(
            e.words(Names::Keywords),
            "invalid fit_from 70: the PSD fit range would be empty, its upper end is 64 \
             (Nyquist); give a smaller fit_from"
        );
        let high = SpectrumHints {
            long_wavelength: Some((true, 80.0)),
            ..none
        };
        let p = plan(None, None, high).unwrap();
        assert_eq!(p.range, None);
        assert!(p
            .note
            .unwrap()
            .words(Names::Flags)
            .starts_with("no PSD fit"));
        let bad = StatsRequest {
            fit_from: Some(-1.0),
            ..StatsRequest::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().words(Names::Keywords),
            "invalid fit_from: must be a positive number of wavelengths per side, got -1"
        );
    }
}
