//! Plots: line charts (linear or log–log) as PNG and SVG, and grey-scale height maps.
//!
//! Fonts are embedded (DejaVu Sans), so plotting works on machines without fontconfig.
//! Files are written through [`StagedOutputs`]: rendered to a temporary file beside the
//! target and renamed only once every output of the command (a PNG and its SVG, or an
//! image beside an array) was written.

use std::path::Path;
use std::sync::Once;

use anyhow::{anyhow, Result};
use asperity::io::StagedOutputs;
use ndarray::ArrayView2;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use asperity_app::figure::tick_label;
use asperity_app::figure::Color as SeriesColor;
pub use asperity_app::figure::{Chart, Series, Style};

mod image;

/// A colour from the Viridis map for `t ∈ [0, 1]` (ordered families such as H values).
pub fn ordered_color(t: f64) -> SeriesColor {
    SeriesColor::Ordered(t)
}

/// The colour plotters draws for `color`.
fn rgb(color: SeriesColor) -> RGBColor {
    match color {
        SeriesColor::Rgb(r, g, b) => RGBColor(r, g, b),
        SeriesColor::Ordered(t) => ViridisRGB::get_color(t.clamp(0.0, 1.0) as f32),
    }
}

/// Writing a [`Chart`] (defined once for the CLI and Python in [`asperity_app::figure`])
/// as PNG and SVG files.
pub trait ChartFiles {
    /// Writes the chart as PNG and SVG, both or neither.
    fn save(&self, png: &Path, svg: &Path, force: bool) -> Result<()>;
    /// Stages the chart as the outputs `png` and `svg` of `staged` (renamed into place
    /// with the others on commit).
    fn stage(&self, staged: &mut StagedOutputs, png: &Path, svg: &Path) -> Result<()>;
}

/// A chart being drawn (the drawing code's view of a [`Chart`]).
struct Drawn<'a>(&'a Chart);

impl std::ops::Deref for Drawn<'_> {
    type Target = Chart;
    fn deref(&self) -> &Chart {
        self.0
    }
}

/// The size of one chart in SVG units; a PNG is drawn at [`PNG_SCALE`] times that, with
/// fonts, lines and markers scaled alike, so that it stays sharp in print.
const SIZE: (u32, u32) = (900, 650);

/// Pixels per SVG unit in PNG files.
const PNG_SCALE: u32 = 2;

fn scaled(size: (u32, u32), scale: u32) -> (u32, u32) {
    (size.0 * scale, size.1 * scale)
}

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        for family in ["sans-serif", "serif", "monospace"] {
            let _ =
                plotters::style::register_font(family, FontStyle::Normal, dejavu::sans::regular());
            let _ = plotters::style::register_font(family, FontStyle::Bold, dejavu::sans::bold());
        }
    });
}

/// `1e-3`, `0.25`, `120`: short tick labels that read well on log axes.
/// Ticks of a log axis from `lo` to `hi` (`0 < lo < hi`): powers of ten (every second,
/// third, … one where there are many decades); where fewer than four fall in the range,
/// also 2 and 5 times them, then every whole multiple; on a range too short even for
/// that, five points evenly spaced in log, rounded to a tenth of the range's magnitude.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let mantissa_sets: [&[f64]; 3] = [
        &[1.0],
        &[1.0, 2.0, 5.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    ];
    for mantissas in mantissa_sets {
        let ticks: Vec<f64> = (first..=last)
            .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| (lo * (1.0 - 1e-12)..=hi * (1.0 + 1e-12)).contains(v))
            .collect();
        if ticks.len() >= 4 {
            let step = ticks.len().div_ceil(12);
            return ticks.into_iter().step_by(step).collect();
        }
    }
    (0..5)
        .map(|i| {
            let v = lo * (hi / lo).powf((0.5 + i as f64) / 5.0);
            let scale = 10f64.powi((hi - lo).log10().floor() as i32 - 1);
            (v / scale).round() * scale
        })
        .collect()
}

impl ChartFiles for Chart {
    fn save(&self, png: &Path, svg: &Path, force: bool) -> Result<()> {
        let mut staged = StagedOutputs::new([png, svg], force)?;
        self.stage(&mut staged, png, svg)?;
        staged.commit()?;
        Ok(())
    }

    fn stage(&self, staged: &mut StagedOutputs, png: &Path, svg: &Path) -> Result<()> {
        register_fonts();
        stage_png(staged, png, scaled(SIZE, PNG_SCALE), |root| {
            Drawn(self).render(root, PNG_SCALE)
        })?;
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, SIZE).into_drawing_area();
            Drawn(self).render(&root, 1)?;
            root.present().map_err(|e| {
                anyhow!("rendering {}: {}", svg.display(), in_words(&e.to_string()))
            })?;
        }
        staged.write_bytes(svg, text.as_bytes())?;
        Ok(())
    }
}

impl Drawn<'_> {
    /// Whether a log axis can show `(x, y)`.
    fn shows(&self, (x, y): (f64, f64)) -> bool {
        x.is_finite() && y.is_finite() && (!self.log_x || x > 0.0) && (!self.log_y || y > 0.0)
    }

    /// Every point the axes must hold: the series and the ends of their intervals.
    fn extent(&self) -> Vec<(f64, f64)> {
        let mut pts: Vec<(f64, f64)> = Vec::new();
        for s in &self.series {
            pts.extend(s.points.iter().copied().filter(|&p| self.shows(p)));
            for (&(x, _), &(lo, hi)) in s.points.iter().zip(s.interval.iter().flatten()) {
                pts.extend([(x, lo), (x, hi)].into_iter().filter(|&p| self.shows(p)));
            }
        }
        pts
    }

    fn bounds(&self) -> Result<((f64, f64), (f64, f64))> {
        if let Some(image) = image::image_of(self) {
            return Ok(((0.0, image.extent.0), (0.0, image.extent.1)));
        }
        let pts = self.extent();
        if self
            .series
            .iter()
            .all(|s| !s.points.iter().any(|&p| self.shows(p)))
        {
            return Err(anyhow!("nothing to plot in '{}'", self.title));
        }
        let span = |vals: Vec<f64>, log: bool, right: f64| {
            let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if log {
                let (lo, hi) = if hi <= lo {
                    (lo / 2.0, hi * 2.0)
                } else {
                    (lo, hi)
                };
                let pad = (hi / lo).powf(0.04);
                (lo / pad, hi * pad * (hi / lo).powf(right))
            } else {
                let (lo, hi) = if hi <= lo {
                    (lo - 1.0, hi + 1.0)
                } else {
                    (lo, hi)
                };
                let pad = 0.04 * (hi - lo);
                (lo - pad, hi + pad + right * (hi - lo))
            }
        };
        // Room on the right for the tags written beside the last points.
        let right = if self.series.iter().any(|s| s.tag.is_some()) {
            0.12
        } else {
            0.0
        };
        Ok((
            span(pts.iter().map(|p| p.0).collect(), self.log_x, right),
            span(pts.iter().map(|p| p.1).collect(), self.log_y, 0.0),
        ))
    }

    /// The corner of the plot whose quarter holds the least of the drawing (points, the
    /// segments between them, interval ends), for the legend.
    fn emptiest_corner(&self) -> SeriesLabelPosition {
        let Ok(((x0, x1), (y0, y1))) = self.bounds() else {
            return SeriesLabelPosition::UpperLeft;
        };
        let unit = |v: f64, lo: f64, hi: f64, log: bool| {
            if log {
                (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
            } else {
                (v - lo) / (hi - lo)
            }
        };
        let place = |(x, y): (f64, f64)| (unit(x, x0, x1, self.log_x), unit(y, y0, y1, self.log_y));
        let mut marks: Vec<(f64, f64)> = self.extent().into_iter().map(place).collect();
        // A line of two points crosses the quarters between them: sample it.
        for s in self.series.iter().filter(|s| s.style != Style::Points) {
            let shown: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|&p| self.shows(p))
                .map(place)
                .collect();
            for w in shown.windows(2) {
                marks.extend((1..10).map(|i| {
                    let t = i as f64 / 10.0;
                    (
                        w[0].0 + t * (w[1].0 - w[0].0),
                        w[0].1 + t * (w[1].1 - w[0].1),
                    )
                }));
            }
        }
        let mut counts = [0usize; 4]; // upper left, upper right, lower left, lower right
        for (u, v) in marks {
            // The legend box covers about 40 % of the width and height.
            let (left, right, top, bottom) = (u < 0.4, u > 0.6, v > 0.6, v < 0.4);
            counts[0] += (left && top) as usize;
            counts[1] += (right && top) as usize;
            counts[2] += (left && bottom) as usize;
            counts[3] += (right && bottom) as usize;
        }
        let positions = [
            SeriesLabelPosition::UpperLeft,
            SeriesLabelPosition::UpperRight,
            SeriesLabelPosition::LowerLeft,
            SeriesLabelPosition::LowerRight,
        ];
        let best = (0..4).min_by_key(|&i| counts[i]).unwrap_or(0);
        positions[best].clone()
    }

    /// Draws the chart on `root`; `scale` multiplies fonts, margins, lines and markers
    /// (1 for SVG, [`PNG_SCALE`] for PNG).
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, scale: u32) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        if let Some(picture) = image::image_of(self) {
            return image::render(self, picture, root, scale);
        }
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let ((x0, x1), (y0, y1)) = self.bounds()?;
        // Log axes get their own ticks: plotters' own leave a short range with one label.
        let log_axis = |lo: f64, hi: f64| {
            let ticks = log_ticks(lo, hi);
            (lo..hi)
                .log_scale()
                .with_key_points(ticks.clone())
                .with_light_points(ticks)
        };
        // The spans that round a tick near 0 to `0` (none on a log axis).
        let span = |log: bool, lo: f64, hi: f64| if log { 0.0 } else { hi - lo };
        let spans = (span(self.log_x, x0, x1), span(self.log_y, y0, y1));
        match (self.log_x, self.log_y) {
            (true, true) => self.draw(root, scale, spans, log_axis(x0, x1), log_axis(y0, y1)),
            (true, false) => self.draw(root, scale, spans, log_axis(x0, x1), y0..y1),
            (false, true) => self.draw(root, scale, spans, x0..x1, log_axis(y0, y1)),
            (false, false) => self.draw(root, scale, spans, x0..x1, y0..y1),
        }
    }

    fn draw<DB, X, Y>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: u32,
        (x_span, y_span): (f64, f64),
        x: X,
        y: Y,
    ) -> Result<()>
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let err =
            |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("plotting '{}': {e}", self.title);
        let px = |v: u32| v * scale;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", px(22)))
            .margin(px(15))
            .x_label_area_size(px(50))
            .y_label_area_size(px(80))
            .build_cartesian_2d(x, y)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .x_label_formatter(&|v| tick_label(*v, x_span))
            .y_label_formatter(&|v| tick_label(*v, y_span))
            .label_style(("sans-serif", px(15)))
            .axis_desc_style(("sans-serif", px(18)))
            .bold_line_style(BLACK.mix(0.1).stroke_width(scale))
            .axis_style(BLACK.stroke_width(scale))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        let colors: Vec<RGBColor> = (0..self.series.len()).map(|i| self.color_of(i)).collect();
        // Intervals first, so that every line and marker stays on top of every band.
        for (s, &color) in self.series.iter().zip(&colors) {
            self.draw_interval(&mut chart, s, color, scale)
                .map_err(err)?;
        }
        for (s, &color) in self.series.iter().zip(&colors) {
            self.draw_series(&mut chart, s, color, scale).map_err(err)?;
        }
        if self.series.iter().any(|s| !s.label.is_empty()) {
            chart
                .configure_series_labels()
                .position(self.emptiest_corner())
                .margin(px(10))
                .legend_area_size(px(30))
                .label_font(("sans-serif", px(14)))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.stroke_width(scale))
                .draw()
                .map_err(err)?;
        }
        Ok(())
    }

    fn color_of(&self, i: usize) -> RGBColor {
        self.series[i].color.map(rgb).unwrap_or_else(|| {
            let c = Palette99::pick(i).to_rgba();
            RGBColor(c.0, c.1, c.2)
        })
    }

    /// The interval of `s`: error bars with caps on markers, a translucent band (broken
    /// where an end cannot be shown) under a line.
    fn draw_interval<DB, X, Y>(
        &self,
        chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
        s: &Series,
        color: RGBColor,
        scale: u32,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
    where
        DB: DrawingBackend,
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        let Some(interval) = &s.interval else {
            return Ok(());
        };
        let spans = s
            .points
            .iter()
            .zip(interval)
            .filter(|(&(x, _), &(lo, hi))| self.shows((x, lo)) && self.shows((x, hi)));
        if matches!(s.style, Style::Points | Style::LinePoints) {
            let bar = lighter(color).stroke_width(scale + scale / 2);
            let cap = 4 * scale as i32;
            for (&(x, _), &(lo, hi)) in spans {
                chart.draw_series([PathElement::new(vec![(x, lo), (x, hi)], bar)])?;
                for end in [lo, hi] {
                    chart.draw_series([EmptyElement::at((x, end))
                        + PathElement::new(vec![(-cap, 0), (cap, 0)], bar)])?;
                }
            }
            return Ok(());
        }
        // Runs of drawable intervals; a gap is left open, not bridged.
        let mut runs: Vec<Vec<(f64, f64, f64)>> = vec![Vec::new()];
        for (i, (&(x, _), &(lo, hi))) in s.points.iter().zip(interval).enumerate() {
            if self.shows((x, lo)) && self.shows((x, hi)) {
                runs.last_mut().expect("one run").push((x, lo, hi));
            } else if i > 0 && !runs.last().expect("one run").is_empty() {
                runs.push(Vec::new());
            }
        }
        for run in runs.into_iter().filter(|r| r.len() >= 2) {
            let outline: Vec<(f64, f64)> = run
                .iter()
                .map(|&(x, _, hi)| (x, hi))
                .chain(run.iter().rev().map(|&(x, lo, _)| (x, lo)))
                .collect();
            chart.draw_series([Polygon::new(outline, color.mix(0.2).filled())])?;
        }
        Ok(())
    }

    /// The line or markers of `s`, its legend entry and its tag.
    fn draw_series<'a, DB, X, Y>(
        &self,
        chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
        s: &Series,
        color: RGBColor,
        scale: u32,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
    where
        DB: DrawingBackend + 'a,
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|&p| self.shows(p))
            .collect();
        let line = color.stroke_width(2 * scale);
        let radius = 3 * scale as i32;
        let dots = |pts: Vec<(f64, f64)>| {
            pts.into_iter()
                .map(move |p| Circle::new(p, radius, color.filled()))
        };
        let (dash, gap) = (8 * scale, 6 * scale);
        let anno = match s.style {
            Style::Line => chart.draw_series(LineSeries::new(pts.clone(), line))?,
            Style::Dashed => {
                chart.draw_series(DashedLineSeries::new(pts.clone(), dash, gap, line))?
            }
            Style::Points => chart.draw_series(dots(pts.clone()))?,
            Style::LinePoints => {
                chart.draw_series(LineSeries::new(pts.clone(), line))?;
                chart.draw_series(dots(pts.clone()))?
            }
            Style::Arrows => {
                let pairs: Vec<[(f64, f64); 2]> = s
                    .points
                    .chunks_exact(2)
                    .filter(|p| self.shows(p[0]) && self.shows(p[1]))
                    .map(|p| [p[0], p[1]])
                    .collect();
                for [tail, head] in &pairs {
                    let (t, h) = (chart.backend_coord(tail), chart.backend_coord(head));
                    chart
                        .draw_series([EmptyElement::at(*head)
                            + PathElement::new(arrow_head(t, h, scale), line)])?;
                }
                chart.draw_series(
                    pairs
                        .into_iter()
                        .map(|p| PathElement::new(p.to_vec(), line)),
                )?
            }
            // Drawn by `image::render`, never here.
            Style::Image => return Ok(()),
        };
        if !s.label.is_empty() {
            let (width, dashed) = (24 * scale as i32, s.style == Style::Dashed);
            anno.label(s.label.clone()).legend(move |(x, y)| {
                // A dashed series shows two dashes, a solid one a line.
                let gap = if dashed { width / 4 } else { 0 };
                let stroke = color.stroke_width(2 * scale);
                let half = (width - gap) / 2;
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (half, 0)], stroke)
                    + PathElement::new(vec![(half + gap, 0), (width, 0)], stroke)
            });
        }
        if let (Some(tag), Some(&last)) = (&s.tag, pts.last()) {
            let font = ("sans-serif", 14 * scale)
                .into_font()
                .color(&color)
                .pos(Pos::new(HPos::Left, VPos::Center));
            chart.draw_series([
                EmptyElement::at(last) + Text::new(tag.clone(), (6 * scale as i32, 0), font)
            ])?;
        }
        Ok(())
    }
}

/// An arrow's head drawn at its tip, pointing from the pixel `t` to the pixel `h`: the
/// pixel offsets from the tip of two strokes of 10 pixels (at scale 1) 25° either side of
/// the shaft, barb, tip, barb (none for an arrow of no length on screen).
fn arrow_head(t: (i32, i32), h: (i32, i32), scale: u32) -> Vec<(i32, i32)> {
    let (dx, dy) = ((h.0 - t.0) as f64, (h.1 - t.1) as f64);
    let length = dx.hypot(dy);
    if length == 0.0 {
        return Vec::new();
    }
    let (ux, uy) = (dx / length, dy / length);
    let barb = 10.0 * scale as f64;
    let (cos, sin) = (25f64.to_radians().cos(), 25f64.to_radians().sin());
    let side = |s: f64| {
        // The shaft's backward direction turned by ±25°.
        let (bx, by) = (-ux * cos - s * uy * sin, -uy * cos + s * ux * sin);
        ((barb * bx).round() as i32, (barb * by).round() as i32)
    };
    vec![side(1.0), (0, 0), side(-1.0)]
}

/// `color` blended halfway to white: intervals drawn beside the line they belong to.
fn lighter(color: RGBColor) -> RGBColor {
    let mix = |c: u8| ((c as u16 + 255) / 2) as u8;
    RGBColor(mix(color.0), mix(color.1), mix(color.2))
}

/// The image format of a plot file, chosen by its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// `.png`: a 1800×1300 (per panel) bitmap: 900×650 at twice the scale.
    Png,
    /// `.svg`: vector graphics.
    Svg,
    /// `.json`: what the figure shows, as data ([`asperity_app::figure::to_json`]), to
    /// draw it elsewhere (the Python package draws the same JSON with matplotlib).
    Json,
}

impl ImageFormat {
    /// The format of `path` from its extension (`.png` or `.svg`, any case); anything else
    /// is refused, with `flag` (the option that named the file) in the message.
    pub fn from_path(path: &Path, flag: &str) -> Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("svg") => Ok(ImageFormat::Svg),
            Some("json") => Ok(ImageFormat::Json),
            _ => Err(anyhow!(
                "{flag} {}: the image format follows the extension, which must be .png or .svg \
                 (or .json for the figure as data)",
                path.display()
            )),
        }
    }
}

/// Renders `charts` side by side (one 900×650 panel each, twice that in pixels in a PNG) into the staged output `path`
/// (declared there by the caller, who commits it with the other outputs), as PNG or SVG
/// by its extension (see [`ImageFormat::from_path`]).
pub fn stage_charts(staged: &mut StagedOutputs, path: &Path, charts: &[Chart]) -> Result<()> {
    if charts.is_empty() {
        return Err(anyhow!("{}: no chart to draw", path.display()));
    }
    for chart in charts {
        if Drawn(chart).bounds().is_err() {
            return Err(anyhow!(
                "nothing to show in '{}': no point with {} values",
                chart.title,
                if chart.log_x || chart.log_y {
                    "finite, positive (log axes)"
                } else {
                    "finite"
                }
            ));
        }
    }
    register_fonts();
    let size = (SIZE.0 * charts.len() as u32, SIZE.1);
    fn draw<DB: DrawingBackend>(
        root: &DrawingArea<DB, Shift>,
        charts: &[Chart],
        scale: u32,
    ) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        for (chart, panel) in charts.iter().zip(root.split_evenly((1, charts.len()))) {
            Drawn(chart).render(&panel, scale)?;
        }
        Ok(())
    }
    match ImageFormat::from_path(path, "plot")? {
        ImageFormat::Png => stage_png(staged, path, scaled(size, PNG_SCALE), |root| {
            draw(root, charts, PNG_SCALE)
        }),
        ImageFormat::Json => {
            let json = asperity_app::figure::to_json(charts);
            staged.write_json(path, &json)?;
            Ok(())
        }
        ImageFormat::Svg => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
                draw(&root, charts, 1)?;
                root.present().map_err(|e| {
                    anyhow!("rendering {}: {}", path.display(), in_words(&e.to_string()))
                })?;
            }
            staged.write_bytes(path, text.as_bytes())?;
            Ok(())
        }
    }
}

/// A drawing error in words. Plotters prints its bitmap errors with `{:?}` (e.g.
/// `ImageError(IoError(Os { code: 28, kind: StorageFull, message: "No space left on
/// device" }))`): the message inside is kept, not the Debug text.
fn in_words(text: &str) -> String {
    for key in ["message: \"", "error: \""] {
        if let Some(rest) = text.find(key).map(|i| &text[i + key.len()..]) {
            if let Some(end) = rest.find('"') {
                return rest[..end].to_string();
            }
        }
    }
    if let Some(rest) = text.find("kind: ").map(|i| &text[i + 6..]) {
        let end = rest.find([',', ' ', '}']).unwrap_or(rest.len());
        return format!("input/output error ({})", &rest[..end]);
    }
    if text.contains('{') || text.contains("Error(") {
        return "the image could not be encoded or written".into();
    }
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Renders a `size` PNG with `draw` into the staged output `path` (a temporary file until
/// the outputs are committed).
fn stage_png<F>(staged: &mut StagedOutputs, path: &Path, size: (u32, u32), draw: F) -> Result<()>
where
    F: FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<()>,
{
    staged.write_file_with(path, Some("png"), |tmp: &Path| -> Result<()> {
        let root = BitMapBackend::new(tmp, size).into_drawing_area();
        draw(&root)?;
        root.present()
            .map_err(|e| anyhow!("rendering {}: {}", path.display(), in_words(&e.to_string())))?;
        Ok(())
    })
}

/// Grey-scale image of a height map (black low, white high), one pixel per grid point
/// (grids above 2048 points a side are subsampled), like the paper's Fig. 6. Staged into
/// `staged` (declared there by the caller, who commits it with the other outputs).
pub fn greyscale_png(
    staged: &mut StagedOutputs,
    path: &Path,
    heights: ArrayView2<f64>,
) -> Result<()> {
    let (rows, cols) = heights.dim();
    let step = rows.max(cols).div_ceil(2048).max(1);
    let (w, h) = (cols.div_ceil(step) as u32, rows.div_ceil(step) as u32);
    let lo = heights.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let range = if hi > lo { hi - lo } else { 1.0 };
    stage_png(staged, path, (w, h), |root| {
        for r in 0..h as usize {
            for c in 0..w as usize {
                let v = ((heights[[r * step, c * step]] - lo) / range * 255.0).round() as u8;
                root.draw_pixel((c as i32, r as i32), &RGBColor(v, v, v))
                    .map_err(|e| {
                        anyhow!("rendering {}: {}", path.display(), in_words(&e.to_string()))
                    })?;
            }
        }
        Ok(())
    })
}

/// A row of grey-scale height maps with captions (like the paper's Fig. 6), PNG and SVG.
/// Each map is shown at `tile` units a side (nearest-neighbour sampling; [`PNG_SCALE`]
/// pixels a unit in the PNG).
pub fn greyscale_panel(
    png: &Path,
    svg: &Path,
    maps: &[(String, ArrayView2<f64>)],
    tile: u32,
    force: bool,
) -> Result<()> {
    register_fonts();
    let mut staged = StagedOutputs::new([png, svg], force)?;
    let caption_height = 30;
    let size = (
        maps.len() as u32 * (tile + 10) + 10,
        tile + caption_height + 10,
    );
    let (ps, panel) = (
        PNG_SCALE,
        Panel {
            tile,
            caption: caption_height,
            block: 1,
            scale: 1,
        },
    );
    let png_panel = Panel {
        tile: tile * ps,
        caption: caption_height * ps,
        scale: ps,
        ..panel
    };
    stage_png(&mut staged, png, scaled(size, ps), |root| {
        png_panel.draw(root, maps)
    })?;
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        // One SVG rectangle per 4x4 block keeps the file small.
        Panel { block: 4, ..panel }.draw(&root, maps)?;
        root.present()
            .map_err(|e| anyhow!("rendering {}: {}", svg.display(), in_words(&e.to_string())))?;
    }
    staged.write_bytes(svg, text.as_bytes())?;
    staged.commit()?;
    Ok(())
}

/// The layout of [`greyscale_panel`] in one backend's units.
#[derive(Debug, Clone, Copy)]
struct Panel {
    /// Side of one map.
    tile: u32,
    /// Height of the captions' row.
    caption: u32,
    /// Side of the squares the maps are drawn with.
    block: u32,
    /// Multiplies gaps and fonts.
    scale: u32,
}

impl Panel {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        maps: &[(String, ArrayView2<f64>)],
    ) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("drawing panel: {e}");
        let (tile, block, gap) = (self.tile, self.block, 10 * self.scale as i32);
        root.fill(&WHITE).map_err(err)?;
        for (i, (title, heights)) in maps.iter().enumerate() {
            let x0 = gap + i as i32 * (tile as i32 + gap);
            let font = ("sans-serif", 18 * self.scale).into_font();
            root.draw(&Text::new(title.clone(), (x0, gap / 2), font))
                .map_err(err)?;
            let (rows, cols) = heights.dim();
            let lo = heights.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let range = if hi > lo { hi - lo } else { 1.0 };
            for py in (0..tile).step_by(block as usize) {
                for px in (0..tile).step_by(block as usize) {
                    let r = (py as usize * rows / tile as usize).min(rows - 1);
                    let c = (px as usize * cols / tile as usize).min(cols - 1);
                    let v = ((heights[[r, c]] - lo) / range * 255.0).round() as u8;
                    let (x, y) = (x0 + px as i32, self.caption as i32 + py as i32);
                    root.draw(&Rectangle::new(
                        [(x, y), (x + block as i32, y + block as i32)],
                        RGBColor(v, v, v).filled(),
                    ))
                    .map_err(err)?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod words_tests {
    use super::in_words;

    #[test]
    fn debug_formatted_backend_errors_become_words() {
        let full = r#"Drawing backend error: ImageError(IoError(Os { code: 28, kind: StorageFull, message: "No space left on device" }))"#;
        assert_eq!(in_words(full), "No space left on device");
        let custom = r#"ImageError(IoError(Custom { kind: Other, error: "disk quota exceeded" }))"#;
        assert_eq!(in_words(custom), "disk quota exceeded");
        assert_eq!(
            in_words("InvalidBuffer { x: 1 }"),
            "the image could not be encoded or written"
        );
        assert_eq!(in_words("plain words"), "plain words");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_label_every_axis() {
        // Many decades: powers of ten, thinned to at most 12.
        assert_eq!(log_ticks(1e-7, 2e-1).len(), 7);
        assert_eq!(log_ticks(1e-30, 1e0).len(), 11);
        // About a decade: 1, 2, 5 steps.
        let t = log_ticks(0.03, 1.1);
        assert_eq!(t, [0.05, 0.1, 0.2, 0.5, 1.0]);
        // Less than a decade: every whole multiple.
        assert_eq!(log_ticks(2.5, 9.5).len(), 7);
        // A sliver: five rounded points inside the range.
        let t = log_ticks(1.02, 1.05);
        assert_eq!(t.len(), 5);
        assert!(t.iter().all(|v| (1.02..=1.05).contains(v)), "{t:?}");
    }

    #[test]
    fn plot_format_follows_the_extension() {
        let format = |p: &str| ImageFormat::from_path(Path::new(p), "--plot");
        assert_eq!(format("a/k.png").unwrap(), ImageFormat::Png);
        assert_eq!(format("K.SVG").unwrap(), ImageFormat::Svg);
        assert_eq!(format("k.json").unwrap(), ImageFormat::Json);
        for bad in ["k.jpg", "k", "k.png.csv"] {
            let err = format(bad).unwrap_err().to_string();
            assert!(err.contains(".png or .svg") && err.contains(bad), "{err}");
        }
    }

    #[test]
    fn staged_charts_are_png_or_svg_side_by_side() {
        let dir = tempfile::tempdir().unwrap();
        let chart = Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: true,
            log_y: true,
            series: vec![Series::new(
                "s",
                vec![(1.0, 2.0), (10.0, 30.0)],
                Style::LinePoints,
            )],
        };
        let (png, svg) = (dir.path().join("c.png"), dir.path().join("c.svg"));
        let mut staged = StagedOutputs::new([&png, &svg], false).unwrap();
        stage_charts(&mut staged, &png, &[chart.clone(), chart.clone()]).unwrap();
        stage_charts(&mut staged, &svg, &[chart]).unwrap();
        staged.commit().unwrap();
        let decoder = ::png::Decoder::new(std::fs::File::open(&png).unwrap());
        let info = decoder.read_info().unwrap().info().clone();
        assert_eq!(
            (info.width, info.height),
            (2 * PNG_SCALE * SIZE.0, PNG_SCALE * SIZE.1)
        );
        assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn intervals_widen_the_axes_except_where_a_log_axis_cannot_show_them() {
        let chart = |style| Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: true,
            log_y: true,
            series: vec![Series::new("s", vec![(1.0, 2.0), (10.0, 3.0)], style)
                .interval(vec![(1.0, 4.0), (-1.0, 50.0)])],
        };
        for style in [Style::Points, Style::Line] {
            let ((_, _), (y0, y1)) = Drawn(&chart(style)).bounds().unwrap();
            // The low end -1 cannot sit on a log axis; 1 and 50 widen it.
            assert!(y0 < 1.0 && y0 > 0.5 && y1 > 50.0 && y1 < 100.0, "{y0} {y1}");
            let dir = tempfile::tempdir().unwrap();
            let (png, svg) = (dir.path().join("c.png"), dir.path().join("c.svg"));
            chart(style).save(&png, &svg, false).unwrap();
        }
        // A tag leaves room on the right of the last point.
        let tagged = Series::new("", vec![(0.0, 0.0), (1.0, 1.0)], Style::Line).tag("H = 1");
        let chart = Chart {
            log_x: false,
            log_y: false,
            series: vec![tagged],
            ..chart(Style::Line)
        };
        let ((_, x1), _) = Drawn(&chart).bounds().unwrap();
        assert!(x1 > 1.1, "{x1}");
    }

    #[test]
    fn chart_writes_png_and_svg_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let chart = Chart {
            title: "test".into(),
            x_label: "F".into(),
            y_label: "k".into(),
            log_x: true,
            log_y: true,
            series: vec![
                Series::new(
                    "data",
                    (1..20).map(|i| (i as f64, (i as f64).powf(0.5))).collect(),
                    Style::LinePoints,
                ),
                Series::new(
                    "theory",
                    vec![(1.0, 1.0), (20.0, 20f64.sqrt())],
                    Style::Dashed,
                ),
            ],
        };
        let (png, svg) = (dir.path().join("c.png"), dir.path().join("c.svg"));
        chart.save(&png, &svg, false).unwrap();
        assert!(std::fs::metadata(&png).unwrap().len() > 1000);
        assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
        assert!(
            chart.save(&png, &svg, false).is_err(),
            "no overwrite without force"
        );
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            2,
            "no temporary files left"
        );
    }
}
