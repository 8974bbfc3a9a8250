//! The figures of a map: a surface's heights with a scale bar and a colour bar
//! (`asperity surface --plot`, `asperity.plot.surface`) and a contact set with its
//! 4-connected patches coloured (`asperity contact --map`, `asperity.plot.contact_map`).

use asperity::topography::patches::label_patches;
use ndarray::ArrayView2;
use serde::Serialize;

use super::{Chart, Color, Series, Style};

/// The most cells a figure's image holds along a side: a larger grid is sampled at every
/// `⌈side/MAX_IMAGE_SIDE⌉`-th point (nearest, no averaging), about the resolution a
/// printed figure shows.
pub const MAX_IMAGE_SIDE: usize = 512;

/// The colours of an image's cells.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ImageColors {
    /// A value's place between `low` and `high` on the Viridis map, with a colour bar
    /// labelled `label`; a missing value (NaN, `null`) is left white.
    Viridis {
        /// The value drawn at the map's start.
        low: f64,
        /// The value drawn at the map's end.
        high: f64,
        /// The colour bar's label.
        label: String,
    },
    /// Whole numbers as categories: 0 is `colors[0]`, `k ≥ 1` is
    /// `colors[1 + (k − 1) mod (colors.len() − 1)]` (patch labels: free surface white,
    /// patches cycling through the rest).
    Categories {
        /// The background, then the cycle.
        colors: Vec<Color>,
    },
}

/// A bar of a round length in the lower left of an image.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScaleBar {
    /// Its length in the axes' unit.
    pub length: f64,
    /// Written beside it (the length with its unit).
    pub label: String,
}

/// A grid of values drawn over `[0, extent.0] × [0, extent.1]`, row 0 at the bottom
/// (y = 0), column 0 on the left.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Image {
    /// Rows of cells.
    pub rows: usize,
    /// Columns of cells.
    pub cols: usize,
    /// The cells, row-major.
    pub values: Vec<f64>,
    /// The image's size along x and y, in the axes' units.
    pub extent: (f64, f64),
    /// How values become colours.
    pub colors: ImageColors,
    /// A scale bar, or none.
    pub scale_bar: Option<ScaleBar>,
}

impl Image {
    /// `grid` sampled to at most [`MAX_IMAGE_SIDE`] cells a side.
    fn sampled(grid: ArrayView2<f64>, extent: (f64, f64), colors: ImageColors) -> Self {
        let (rows, cols) = grid.dim();
        let step = rows.max(cols).div_ceil(MAX_IMAGE_SIDE).max(1);
        let kept = grid.slice(ndarray::s![..;step, ..;step]);
        Image {
            rows: kept.nrows(),
            cols: kept.ncols(),
            values: kept.iter().copied().collect(),
            extent,
            colors,
            scale_bar: None,
        }
    }
}

/// The largest 1, 2 or 5 × 10ᵏ not above `length` (`length > 0`), the nearest double to
/// its decimal (`5e-6`, not `5 × 1e-6`).
pub fn round_length(length: f64) -> f64 {
    let k = length.log10().floor() as i32;
    // m·10ᵏ as one correctly rounded operation on exact integers.
    let times = |m: f64| {
        if k >= 0 {
            m * 10f64.powi(k)
        } else {
            m / 10f64.powi(-k)
        }
    };
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(times)
        .find(|&v| v <= length * (1.0 + 1e-12))
        .unwrap_or_else(|| times(1.0))
}

/// A length for a label: in m, mm, µm, nm or pm where `metres`, else as a plain number.
pub fn length_label(length: f64, metres: bool) -> String {
    let short = asperity::input::short_number;
    if !metres {
        return short(length);
    }
    let units = [("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9)];
    let (unit, scale) = units
        .into_iter()
        .find(|&(_, scale)| length >= scale * (1.0 - 1e-12))
        .unwrap_or(("pm", 1e-12));
    format!("{} {unit}", short(((length / scale) * 1e9).round() / 1e9))
}

/// A scale bar of a round length about a fifth of the width `x`.
fn scale_bar(x: f64, metres: bool) -> ScaleBar {
    let length = round_length(x / 5.0);
    ScaleBar {
        length,
        label: length_label(length, metres),
    }
}

/// Where a map lies and what it is called.
#[derive(Debug, Clone, Copy)]
pub struct MapFigure<'a> {
    /// The name in the title (a file name, or what the caller calls it).
    pub name: &'a str,
    /// The map's size along x and y.
    pub size: (f64, f64),
    /// Lengths in metres (a measured surface); otherwise in the surface's own unit.
    pub metres: bool,
}

impl MapFigure<'_> {
    fn chart(&self, title: String, image: Image) -> Chart {
        let unit = if self.metres { " [m]" } else { "" };
        Chart {
            title,
            x_label: format!("x{unit}"),
            y_label: format!("y{unit}"),
            log_x: false,
            log_y: false,
            series: vec![Series::image(image)],
        }
    }
}

/// The height map (rows along y, row 0 at y = 0) on the Viridis map with a colour bar of
/// the heights and a scale bar; undefined heights (NaN) left white.
pub fn surface_chart(heights: ArrayView2<f64>, figure: MapFigure<'_>) -> Chart {
    let finite = heights.iter().copied().filter(|v| v.is_finite());
    let low = finite.clone().fold(f64::INFINITY, f64::min);
    let high = finite.fold(f64::NEG_INFINITY, f64::max);
    let (low, high) = if low.is_finite() {
        (low, high)
    } else {
        (0.0, 1.0)
    };
    let label = if figure.metres {
        "height [m]"
    } else {
        "height"
    };
    let colors = ImageColors::Viridis {
        low,
        high,
        label: label.into(),
    };
    let mut image = Image::sampled(heights, figure.size, colors);
    image.scale_bar = Some(scale_bar(figure.size.0, figure.metres));
    let (rows, cols) = heights.dim();
    let title = format!(
        "{}: heights ({rows}×{cols}, {} × {})",
        figure.name,
        length_label(figure.size.0, figure.metres),
        length_label(figure.size.1, figure.metres)
    );
    figure.chart(title, image)
}

/// The colours of the patches (after white, the background): ten distinct hues.
pub const PATCH_COLORS: [Color; 10] = [
    Color::Rgb(31, 119, 180),
    Color::Rgb(255, 127, 14),
    Color::Rgb(44, 160, 44),
    Color::Rgb(214, 39, 40),
    Color::Rgb(148, 103, 189),
    Color::Rgb(140, 86, 75),
    Color::Rgb(227, 119, 194),
    Color::Rgb(127, 127, 127),
    Color::Rgb(188, 189, 34),
    Color::Rgb(23, 190, 207),
];

/// The contact set with each 4-connected patch (the rule of the `patches` column) in a
/// colour of its own among [`PATCH_COLORS`], free surface white, the patch count and the
/// share of points in contact in the title, and a scale bar.
pub fn contact_map_chart(set: ArrayView2<bool>, figure: MapFigure<'_>) -> Chart {
    let (labels, sizes) = label_patches(set);
    let in_contact: usize = sizes.iter().sum();
    let share = 100.0 * in_contact as f64 / set.len().max(1) as f64;
    let mut colors = vec![Color::Rgb(255, 255, 255)];
    colors.extend(PATCH_COLORS);
    let labels = labels.mapv(f64::from);
    let mut image = Image::sampled(
        labels.view(),
        figure.size,
        ImageColors::Categories { colors },
    );
    image.scale_bar = Some(scale_bar(figure.size.0, figure.metres));
    let title = format!(
        "{}: {} contact patches, {share:.2} % in contact",
        figure.name,
        sizes.len()
    );
    figure.chart(title, image)
}

impl Series {
    /// A series that is an image (no points; [`Style::Image`]).
    pub fn image(image: Image) -> Self {
        Series {
            image: Some(image),
            ..Series::new("", Vec::new(), Style::Image)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::{array, Array2};

    #[test]
    fn round_lengths_and_their_labels() {
        assert_eq!(round_length(0.2), 0.2);
        assert_eq!(round_length(0.19), 0.1);
        assert_eq!(round_length(7.3e-6), 5e-6);
        assert_eq!(round_length(3.0), 2.0);
        assert_eq!(length_label(5e-6, true), "5 µm");
        assert_eq!(length_label(2e-3, true), "2 mm");
        assert_eq!(length_label(1e-10, true), "100 pm");
        assert_eq!(length_label(0.2, false), "0.2");
        assert_eq!(length_label(0.2, true), "200 mm");
    }

    #[test]
    fn a_surface_chart_holds_its_heights_extent_and_scale() {
        let heights = array![[1.0, 2.0, 3.0], [4.0, f64::NAN, 0.5]];
        let figure = MapFigure {
            name: "s",
            size: (3e-6, 2e-6),
            metres: true,
        };
        let chart = surface_chart(heights.view(), figure);
        let image = chart.series[0].image.as_ref().unwrap();
        assert_eq!((image.rows, image.cols), (2, 3));
        assert_eq!(image.values[3], 4.0);
        assert!(image.values[4].is_nan());
        assert_eq!(image.extent, (3e-6, 2e-6));
        match &image.colors {
            ImageColors::Viridis { low, high, .. } => assert_eq!((*low, *high), (0.5, 4.0)),
            other => panic!("{other:?}"),
        }
        let bar = image.scale_bar.as_ref().unwrap();
        assert_eq!((bar.length, bar.label.as_str()), (5e-7, "500 nm"));
        assert_eq!(chart.x_label, "x [m]");
        assert_eq!(chart.title, "s: heights (2×3, 3 µm × 2 µm)");
    }

    #[test]
    fn large_grids_are_sampled_to_the_images_side() {
        let grid = Array2::from_shape_fn((1030, 700), |(r, c)| (r * 1000 + c) as f64);
        let figure = MapFigure {
            name: "s",
            size: (1.0, 1.0),
            metres: false,
        };
        let image = surface_chart(grid.view(), figure).series[0]
            .image
            .clone()
            .unwrap();
        // step ⌈1030/512⌉ = 3: rows 0, 3, …, 1029; columns 0, 3, …, 699.
        assert_eq!((image.rows, image.cols), (344, 234));
        assert_eq!(image.values[image.cols + 1], 3003.0);
    }

    #[test]
    fn a_contact_map_numbers_its_patches_and_counts_them() {
        let set = array![[true, true, false], [false, false, true]];
        let figure = MapFigure {
            name: "c",
            size: (3.0, 2.0),
            metres: false,
        };
        let chart = contact_map_chart(set.view(), figure);
        assert_eq!(chart.title, "c: 2 contact patches, 50.00 % in contact");
        let image = chart.series[0].image.as_ref().unwrap();
        assert_eq!(image.values, vec![1.0, 1.0, 0.0, 0.0, 0.0, 2.0]);
        let json = super::super::to_json(&[chart]);
        let colors = &json["charts"][0]["series"][0]["image"]["colors"]["categories"]["colors"];
        assert_eq!(colors.as_array().unwrap().len(), 11);
        assert_eq!(json["charts"][0]["series"][0]["style"], "image");
    }
}
