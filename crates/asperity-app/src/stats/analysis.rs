//! The analyses of `asperity stats` beyond its summary (`--bearing-area`, `--acf`,
//! `--acf-2d`, `--variable-bandwidth`, the scale-dependent slope and curvature, the height,
//! slope and curvature distributions) and Python's `asperity.analysis`: each a two-column
//! table computed here once, from the same [`StatsSource`] as the statistics, so that the
//! CLI's CSV and Python's arrays hold the same numbers.

use asperity::topography::bandwidth::{variable_bandwidth_area, variable_bandwidth_profile};
use asperity::topography::stats as topo;
use asperity::topography::Heights;
use ndarray::{Array2, Axis, Ix1, Ix2};

use super::StatsSource;
use crate::refusal::{Param, Refusal, RequestError};

/// One analysis: a table of two columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Analysis {
    /// The bearing-area (Abbott–Firestone) curve: material ratio, height.
    BearingArea,
    /// The height-difference ACF along x: distance, acf.
    Acf,
    /// The radially averaged 2-D height-difference ACF of a map: distance, acf.
    Acf2d,
    /// The variable-bandwidth rms height: bandwidth, rms_height.
    VariableBandwidth,
    /// The scale-dependent rms slope along x: distance, slope.
    ScaleDependentSlope,
    /// The scale-dependent rms curvature along x: distance, curvature.
    ScaleDependentCurvature,
    /// The height distribution: height, density.
    HeightDistribution,
    /// The distribution of the slopes along x: slope, density.
    SlopeDistribution,
    /// The distribution of the curvatures along x: curvature, density.
    CurvatureDistribution,
}

/// Rows of the bearing-area table: material ratios 0, 0.01, ..., 1.
pub const BEARING_POINTS: usize = 101;

impl Analysis {
    /// Every analysis, in the order of `asperity stats --help`.
    pub const ALL: [Analysis; 9] = [
        Analysis::BearingArea,
        Analysis::Acf,
        Analysis::Acf2d,
        Analysis::VariableBandwidth,
        Analysis::ScaleDependentSlope,
        Analysis::ScaleDependentCurvature,
        Analysis::HeightDistribution,
        Analysis::SlopeDistribution,
        Analysis::CurvatureDistribution,
    ];

    /// Its option of `asperity stats` (`--acf-2d`) and its name in Python (`acf_2d`).
    pub fn param(self) -> Param {
        match self {
            Analysis::BearingArea => Param::new("--bearing-area", "bearing_area"),
            Analysis::Acf => Param::new("--acf", "acf"),
            Analysis::Acf2d => Param::new("--acf-2d", "acf_2d"),
            Analysis::VariableBandwidth => Param::new("--variable-bandwidth", "variable_bandwidth"),
            Analysis::ScaleDependentSlope => {
                Param::new("--scale-dependent-slope", "scale_dependent_slope")
            }
            Analysis::ScaleDependentCurvature => {
                Param::new("--scale-dependent-curvature", "scale_dependent_curvature")
            }
            Analysis::HeightDistribution => {
                Param::new("--height-distribution", "height_distribution")
            }
            Analysis::SlopeDistribution => Param::new("--slope-distribution", "slope_distribution"),
            Analysis::CurvatureDistribution => {
                Param::new("--curvature-distribution", "curvature_distribution")
            }
        }
    }

    /// The names of its two columns (the CSV header).
    pub fn columns(self) -> [&'static str; 2] {
        match self {
            Analysis::BearingArea => ["material_ratio", "height"],
            Analysis::Acf | Analysis::Acf2d => ["distance", "acf"],
            Analysis::VariableBandwidth => ["bandwidth", "rms_height"],
            Analysis::ScaleDependentSlope => ["distance", "slope"],
            Analysis::ScaleDependentCurvature => ["distance", "curvature"],
            Analysis::HeightDistribution => ["height", "density"],
            Analysis::SlopeDistribution => ["slope", "density"],
            Analysis::CurvatureDistribution => ["curvature", "density"],
        }
    }

    /// The analysis whose Python name is `name`, or why not.
    pub fn parse(name: &str) -> Result<Self, Refusal> {
        Analysis::ALL
            .into_iter()
            .find(|a| a.param().keyword == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Analysis::ALL.iter().map(|a| a.param().keyword).collect();
                Refusal::saying(format!(
                    "unknown analysis {:?}: expected one of {}",
                    asperity::input::clip(name),
                    names.join(", ")
                ))
            })
    }
}

/// A table of two columns, row by row.
pub type Rows = Vec<(f64, f64)>;

/// The tables of `wanted` (in its order), from the heights as they are (levelled and filled
/// as the source was opened; undefined points left out where the analysis allows); the ACF
/// is computed once for both `Acf` and `ScaleDependentSlope`.
pub fn analyse(source: &StatsSource, wanted: &[Analysis]) -> Result<Vec<Rows>, RequestError> {
    let mut acf: Option<Rows> = None;
    let mut out = Vec::with_capacity(wanted.len());
    for &analysis in wanted {
        let rows = match analysis {
            Analysis::Acf | Analysis::ScaleDependentSlope => {
                if acf.is_none() {
                    acf = Some(acf_along_x(source)?);
                }
                let acf = acf.as_deref().unwrap_or_default();
                match analysis {
                    Analysis::Acf => acf.to_vec(),
                    _ => topo::scale_dependent_slope(acf),
                }
            }
            Analysis::BearingArea => {
                topo::bearing_area_curve(values(source), BEARING_POINTS).map_err(library)?
            }
            Analysis::Acf2d => radial_acf(source)?,
            Analysis::VariableBandwidth => variable_bandwidth(source)?,
            Analysis::ScaleDependentCurvature => {
                let (rows, dx) = rows_along_x(source)?;
                topo::scale_dependent_curvature(rows.view(), dx).map_err(library)?
            }
            Analysis::HeightDistribution
            | Analysis::SlopeDistribution
            | Analysis::CurvatureDistribution => distribution(source, analysis)?,
        };
        out.push(rows);
    }
    Ok(out)
}

/// The heights, undefined ones included.
fn values(source: &StatsSource) -> Box<dyn Iterator<Item = f64> + '_> {
    match source {
        StatsSource::Grid { heights, .. } => Box::new(heights.iter().copied()),
        StatsSource::Measured { heights, .. } => heights.values(),
    }
}

/// The heights as rows along x (a line is one row) and the spacing Δx.
fn rows_along_x(source: &StatsSource) -> Result<(Array2<f64>, f64), RequestError> {
    let (rows, size_x) = match source {
        StatsSource::Grid { heights, size, .. } => {
            let rows = match heights.ndim() {
                1 => grid(heights.view().into_dimensionality::<Ix1>())?
                    .insert_axis(Axis(0))
                    .to_owned(),
                _ => grid(heights.view().into_dimensionality::<Ix2>())?.to_owned(),
            };
            (rows, *size)
        }
        StatsSource::Measured { heights, sizes } => match heights {
            Heights::Areal(h) => (h.clone(), sizes[0]),
            Heights::Profile(p) => (p.clone().insert_axis(Axis(0)), sizes[0]),
        },
    };
    let dx = size_x / rows.ncols() as f64;
    Ok((rows, dx))
}

/// A grid's heights as a line or a map, or why not.
fn grid<T>(view: Result<T, ndarray::ShapeError>) -> Result<T, RequestError> {
    view.map_err(|_| Refusal::saying("heights: expected a line (1D) or a map (2D)").into())
}

/// The height-difference ACF along x as `(distance, A)`: a line is one row.
fn acf_along_x(source: &StatsSource) -> Result<Rows, RequestError> {
    let (rows, dx) = rows_along_x(source)?;
    let acf = topo::height_difference_acf(rows.view()).map_err(library)?;
    Ok(acf.into_iter().map(|(k, a)| (k as f64 * dx, a)).collect())
}

/// The radially averaged 2-D height-difference ACF of a map as `(distance, A)`; a profile
/// is refused.
fn radial_acf(source: &StatsSource) -> Result<Rows, RequestError> {
    let (map, dx, dy) = match source {
        StatsSource::Grid { heights, size, .. } if heights.ndim() == 2 => {
            let map = grid(heights.view().into_dimensionality::<Ix2>())?;
            let dx = *size / map.ncols() as f64;
            (map.to_owned(), dx, dx)
        }
        StatsSource::Measured {
            heights: Heights::Areal(h),
            sizes,
        } => (
            h.clone(),
            sizes[0] / h.ncols() as f64,
            sizes[1] / h.nrows() as f64,
        ),
        _ => {
            return Err(Refusal::of(Analysis::Acf2d.param())
                .text(" needs a map; for a profile use ")
                .param(Analysis::Acf.param())
                .into())
        }
    };
    topo::radial_height_difference_acf(map.view(), dx, dy).map_err(library)
}

/// The variable-bandwidth analysis as `(bandwidth, rms height)`: a checkerboard of planes
/// on a map, of lines on a profile.
fn variable_bandwidth(source: &StatsSource) -> Result<Rows, RequestError> {
    let out = match source {
        StatsSource::Grid { heights, size, .. } => match heights.ndim() {
            1 => {
                let line = grid(heights.view().into_dimensionality::<Ix1>())?;
                variable_bandwidth_profile(line.insert_axis(Axis(0)), *size)
            }
            _ => {
                let map = grid(heights.view().into_dimensionality::<Ix2>())?;
                // Square pixels: L_y = L_x · rows / cols.
                let size_y = *size * map.nrows() as f64 / map.ncols() as f64;
                variable_bandwidth_area(map, [*size, size_y])
            }
        },
        StatsSource::Measured { heights, sizes } => match heights {
            Heights::Areal(h) => variable_bandwidth_area(h.view(), [sizes[0], sizes[1]]),
            Heights::Profile(p) => {
                variable_bandwidth_profile(p.view().insert_axis(Axis(0)), sizes[0])
            }
        },
    }
    .map_err(library)?;
    Ok(out.iter().map(|b| (b.bandwidth, b.rms_height)).collect())
}

/// The bins of the distributions: ⌊√n⌋ for n values, at least 10 and at most 100.
fn distribution_bins(n: usize) -> usize {
    ((n as f64).sqrt() as usize).clamp(10, 100)
}

/// The height, slope or curvature distribution as `(value, density)`: the heights, or the
/// slopes and curvatures along x within each row.
fn distribution(source: &StatsSource, analysis: Analysis) -> Result<Rows, RequestError> {
    let (rows, dx) = rows_along_x(source)?;
    let (values, name) = match analysis {
        Analysis::HeightDistribution => {
            let heights = rows.iter().copied().filter(|v| !v.is_nan()).collect();
            (heights, "height")
        }
        Analysis::SlopeDistribution => (
            topo::slopes_and_curvatures_along_x(rows.view(), dx).0,
            "slope",
        ),
        _ => (
            topo::slopes_and_curvatures_along_x(rows.view(), dx).1,
            "curvature",
        ),
    };
    let bins = distribution_bins(values.len());
    topo::distribution(values, bins)
        .map_err(|e| Refusal::saying(format!("the {name} distribution: {e}")).into())
}

fn library(source: asperity::Error) -> RequestError {
    RequestError::Invalid(Box::new(source))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refusal::Names;
    use ndarray::{Array1, ArrayD};

    fn ramp_line() -> StatsSource {
        // h = i on 64 points of spacing 1/16: the slope is 16 everywhere.
        let h = Array1::from_iter((0..64).map(|i| i as f64));
        StatsSource::Grid {
            heights: h.into_dyn(),
            size: 4.0,
            hints: Default::default(),
        }
    }

    #[test]
    fn every_analysis_has_a_name_that_parses_back_and_two_columns() {
        for a in Analysis::ALL {
            assert_eq!(Analysis::parse(a.param().keyword), Ok(a));
            assert_eq!(a.param().flag[2..].replace('-', "_"), a.param().keyword);
        }
        let words = Analysis::parse("acf2d").unwrap_err().words(Names::Keywords);
        assert!(words.starts_with("unknown analysis \"acf2d\": expected one of bearing_area, acf,"));
    }

    #[test]
    fn the_slope_is_drawn_from_the_acf_computed_once() {
        let source = ramp_line();
        let both = [Analysis::ScaleDependentSlope, Analysis::Acf];
        let tables = analyse(&source, &both).unwrap();
        // A(r) = ½ (16 r)² on the ramp (from FFTs: to rounding): √(2A)/r = 16.
        assert_eq!(tables[1][0].0, 0.0);
        assert!(tables[1][0].1.abs() < 1e-9);
        assert!((tables[1][3].1 - 0.5 * (3.0f64).powi(2)).abs() < 1e-9);
        assert!(tables[0].iter().all(|&(_, s)| (s - 16.0).abs() < 1e-9));
        // Each alone gives the same rows.
        assert_eq!(analyse(&source, &[Analysis::Acf]).unwrap()[0], tables[1]);
    }

    #[test]
    fn a_profile_has_no_2d_acf_in_either_front_ends_words() {
        let refused = analyse(&ramp_line(), &[Analysis::Acf2d]).unwrap_err();
        assert_eq!(
            refused.words(Names::Flags),
            "--acf-2d needs a map; for a profile use --acf"
        );
        assert_eq!(
            refused.words(Names::Keywords),
            "acf_2d needs a map; for a profile use acf"
        );
        let cube = StatsSource::Grid {
            heights: ArrayD::zeros(vec![2, 2, 2]),
            size: 1.0,
            hints: Default::default(),
        };
        assert!(analyse(&cube, &[Analysis::HeightDistribution]).is_err());
    }

    #[test]
    fn a_distribution_of_no_width_is_refused_by_name() {
        let flat = StatsSource::Grid {
            heights: ArrayD::zeros(vec![8, 8]),
            size: 1.0,
            hints: Default::default(),
        };
        let refused = analyse(&flat, &[Analysis::HeightDistribution]).unwrap_err();
        assert!(refused
            .words(Names::Flags)
            .starts_with("the height distribution: "));
    }
}
