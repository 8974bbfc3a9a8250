//! What a figure shows, defined once for every front end: the CLI draws these charts with
//! plotters (PNG/SVG, or their JSON with `--plot FILE.json`), the Python package with
//! matplotlib (`asperity.plot`). A [`Chart`] is data only — title, axis labels and scales,
//! series with their styles, colours, intervals and tags — so that both front ends show the
//! same curves, theory lines, labels and intervals.
//!
//! The builders: [`sweep`] (a load sweep's k(F) and A/A₀(F)), [`contact`] (an SI contact
//! sweep's k(F), A(F) and mean gap), [`path`] (a load path's
//! loading–unloading loop), [`mdr`] (an MDR curve's F(d) and k(F)), [`adhesion`] (an adhesive loop with its arrows and pull-offs), [`study`] (α(H), α(N) and the ensemble k(F) of a study),
//! [`psd`] (a PSD with its fitted power law), [`analysis`] (the surface analyses of
//! `asperity stats`: ACFs, scale-dependent slope and curvature, variable-bandwidth rms
//! height, bearing-area curve, distributions), [`map`] (a height map with scale and colour
//! bars, a contact set with its patches: a series that is an [`Image`]).

pub mod adhesion;
pub mod analysis;
pub mod contact;
pub mod map;
pub mod mdr;
pub mod path;
pub mod psd;
pub mod study;
pub mod sweep;

pub use map::Image;

use serde::Serialize;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Style {
    /// A solid line.
    Line,
    /// A dashed line (theory curves, asymptotes).
    Dashed,
    /// Markers only (data points).
    Points,
    /// A solid line with markers.
    LinePoints,
    /// The series' [`Image`] (it has no points).
    Image,
    /// Arrows: the points in pairs, each an arrow from the first (tail) to the second
    /// (head), in the series' colour (the way a loop was travelled).
    Arrows,
}

/// A series' colour.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Color {
    /// An sRGB colour.
    Rgb(u8, u8, u8),
    /// A position `t ∈ [0, 1]` on the Viridis map, for ordered families (H values, N).
    Ordered(f64),
}

impl Color {
    /// Black: the theory curves.
    pub const BLACK: Color = Color::Rgb(0, 0, 0);
    /// Red.
    pub const RED: Color = Color::Rgb(255, 0, 0);
    /// Blue (pure, as plotters' `BLUE`).
    pub const BLUE: Color = Color::Rgb(0, 0, 255);
    /// Grey: reference lines.
    pub const GREY: Color = Color::Rgb(120, 120, 120);
}

/// One labelled series of `(x, y)` points.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Series {
    /// Legend text (empty: no legend entry).
    pub label: String,
    /// The points; on log axes, points with non-positive coordinates are not drawn, nor
    /// non-finite ones (a missing value is NaN, `null` in JSON).
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub style: Style,
    /// Colour; `None` lets the renderer pick from its palette by position.
    pub color: Option<Color>,
    /// An interval `(low, high)` per point, drawn in a lighter shade of the colour: error
    /// bars on markers, a band under a line. Ends a log axis cannot show are left out.
    pub interval: Option<Vec<(f64, f64)>>,
    /// Text written beside the last point, in the series' colour (names a line in place
    /// of a legend entry).
    pub tag: Option<String>,
    /// A grid of values drawn as coloured cells ([`Style::Image`]; left out of the JSON
    /// when absent).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub image: Option<Image>,
}

impl Series {
    /// A series with the renderer's palette colour.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Self {
        Series {
            label: label.into(),
            points,
            style,
            color: None,
            interval: None,
            tag: None,
            image: None,
        }
    }

    /// Sets the interval of each point (same length as the points).
    pub fn interval(mut self, interval: Vec<(f64, f64)>) -> Self {
        debug_assert_eq!(interval.len(), self.points.len());
        self.interval = Some(interval);
        self
    }

    /// Sets the text written beside the last point.
    pub fn tag(mut self, tag: impl Into<String>) -> Self {
        self.tag = Some(tag.into());
        self
    }

    /// Sets the colour.
    pub fn color(mut self, color: Color) -> Self {
        self.color = Some(color);
        self
    }
}

/// A chart: title, axis labels, axis scales and series.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Chart {
    /// Caption above the plot.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The series, drawn in order.
    pub series: Vec<Series>,
}

/// A tick's label, short: `0`, `0.25`, `250`, `2.5e6`, `-1e-7`. `span` is the axis'
/// range (its largest less its least value; 0 on a log axis): a value within
/// [`ZERO_TICK`]·`span` of 0 is the rounding of a tick at zero (`-2.7e-20` on an axis from
/// −1 to 1) and reads `0`.
pub fn tick_label(v: f64, span: f64) -> String {
    let a = v.abs();
    if v == 0.0 || a <= ZERO_TICK * span.abs() {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        let e = a.log10().floor() as i32;
        let m = v / 10f64.powi(e);
        if (m - m.round()).abs() < 1e-9 {
            format!("{}e{e}", m.round())
        } else {
            format!("{m:.1}e{e}")
        }
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// A tick within this share of its axis' range from 0 is labelled `0` ([`tick_label`]).
pub const ZERO_TICK: f64 = 1e-12;

/// `charts` as JSON (`{"format": "asperity-figure/1", "charts": [...]}`), what
/// `--plot FILE.json` writes and what the Python package renders; a missing value (NaN) is
/// `null`.
pub fn to_json(charts: &[Chart]) -> serde_json::Value {
    serde_json::json!({ "format": FORMAT, "charts": charts })
}

/// The format tag of [`to_json`].
pub const FORMAT: &str = "asperity-figure/1";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short_and_zero_is_zero() {
        assert_eq!(tick_label(0.001, 1.0), "0.001");
        assert_eq!(tick_label(1e-5, 1e-4), "1e-5");
        assert_eq!(tick_label(250.0, 1e3), "250");
        assert_eq!(tick_label(2.5e6, 1e7), "2.5e6");
        assert_eq!(tick_label(2.0000000000000004e-5, 1e-4), "2e-5");
        assert_eq!(tick_label(-1e-7, 1e-6), "-1e-7");
        assert_eq!(tick_label(0.30000000000000004, 1.0), "0.3");
        // A tick at zero on an axis crossing it, off by rounding: 0.
        assert_eq!(tick_label(-2.7e-20, 2.0), "0");
        assert_eq!(tick_label(1.5e-13, 1.0), "0");
        // Small values that are the axis' own scale keep their digits; a log axis (span 0)
        // never rounds to 0.
        assert_eq!(tick_label(-2.7e-20, 1e-19), "-2.7e-20");
        assert_eq!(tick_label(1e-20, 0.0), "1e-20");
    }

    #[test]
    fn a_chart_round_trips_through_json_with_missing_values_as_null() {
        let chart = Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: true,
            log_y: false,
            series: vec![
                Series::new("a", vec![(1.0, 2.0), (2.0, f64::NAN)], Style::LinePoints)
                    .color(Color::Ordered(0.5))
                    .interval(vec![(1.5, 2.5), (f64::NAN, f64::NAN)])
                    .tag("H = 0.5"),
                Series::new("", vec![(1.0, 1.0)], Style::Dashed).color(Color::BLACK),
            ],
        };
        let json = to_json(std::slice::from_ref(&chart));
        assert_eq!(json["format"], FORMAT);
        let first = &json["charts"][0]["series"][0];
        assert_eq!(first["points"][1][1], serde_json::Value::Null);
        assert_eq!(first["color"]["ordered"], 0.5);
        assert_eq!(json["charts"][0]["series"][1]["color"]["rgb"][0], 0);
        assert_eq!(first["style"], "line_points");
    }
}
