//! Drawing a chart whose series is an [`Image`] (a height map, a contact map): the cells
//! in their colours on axes of the image's extent with equal scales, its scale bar in the
//! lower left and, for values on the Viridis map, a colour bar on the right.

use anyhow::{anyhow, Result};
use asperity_app::figure::map::{ImageColors, ScaleBar};
use asperity_app::figure::{Chart, Image};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::rgb;
use asperity_app::figure::tick_label;

/// The most cells drawn along a side in an SVG (larger images are drawn in blocks of the
/// nearest cell, keeping the file a few MB at most); a PNG draws every cell.
const SVG_CELLS: usize = 128;

/// Width of the colour bar's panel in SVG units.
const BAR_WIDTH: u32 = 150;

/// The image of `chart`, if it has one.
pub(super) fn image_of(chart: &Chart) -> Option<&Image> {
    chart.series.iter().find_map(|s| s.image.as_ref())
}

/// The colour of one cell (`None`: left white).
fn cell_color(colors: &ImageColors, v: f64) -> Option<RGBColor> {
    if !v.is_finite() {
        return None;
    }
    match colors {
        ImageColors::Viridis { low, high, .. } => {
            let t = if high > low {
                (v - low) / (high - low)
            } else {
                0.5
            };
            Some(ViridisRGB::get_color(t.clamp(0.0, 1.0) as f32))
        }
        ImageColors::Categories { colors } => {
            let k = v.max(0.0) as usize;
            let index = match (k, colors.len()) {
                (_, 0) => return None,
                (0, _) | (_, 1) => 0,
                (k, n) => 1 + (k - 1) % (n - 1),
            };
            Some(rgb(colors[index]))
        }
    }
}

/// Draws `chart` (with `image`) on `root`; `scale` as for line charts.
pub(super) fn render<DB: DrawingBackend>(
    chart: &Chart,
    image: &Image,
    root: &DrawingArea<DB, Shift>,
    scale: u32,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("plotting '{}': {e}", chart.title);
    root.fill(&WHITE).map_err(err)?;
    let px = |v: u32| v * scale;
    let (width, _) = root.dim_in_pixel();
    let bar = matches!(image.colors, ImageColors::Viridis { .. });
    let (main, side) = if bar {
        let (main, side) = root.split_horizontally(width.saturating_sub(px(BAR_WIDTH)));
        (main, Some(side))
    } else {
        (root.clone(), None)
    };
    let main = with_aspect(&main, image.extent, scale);
    let (ex, ey) = image.extent;
    let mut plot = ChartBuilder::on(&main)
        .caption(&chart.title, ("sans-serif", px(20)))
        .margin(px(15))
        .x_label_area_size(px(50))
        .y_label_area_size(px(80))
        .build_cartesian_2d(0.0..ex, 0.0..ey)
        .map_err(err)?;
    plot.configure_mesh()
        .disable_mesh()
        .x_desc(&chart.x_label)
        .y_desc(&chart.y_label)
        .x_label_formatter(&|v| tick_label(*v, ex))
        .y_label_formatter(&|v| tick_label(*v, ey))
        .x_labels(5)
        .y_labels(5)
        .label_style(("sans-serif", px(15)))
        .axis_desc_style(("sans-serif", px(18)))
        .axis_style(BLACK.stroke_width(scale))
        .draw()
        .map_err(err)?;
    let block = if scale == 1 {
        image.rows.max(image.cols).div_ceil(SVG_CELLS).max(1)
    } else {
        1
    };
    let (dx, dy) = (ex / image.cols as f64, ey / image.rows as f64);
    let mut cells = Vec::new();
    for r in (0..image.rows).step_by(block) {
        for c in (0..image.cols).step_by(block) {
            let v = image.values[r * image.cols + c];
            if let Some(color) = cell_color(&image.colors, v) {
                let (x0, y0) = (c as f64 * dx, r as f64 * dy);
                let x1 = ((c + block) as f64 * dx).min(ex);
                let y1 = ((r + block) as f64 * dy).min(ey);
                cells.push(Rectangle::new([(x0, y0), (x1, y1)], color.filled()));
            }
        }
    }
    plot.draw_series(cells).map_err(err)?;
    if let Some(bar) = &image.scale_bar {
        draw_scale_bar(&mut plot, bar, image.extent, scale).map_err(err)?;
    }
    if let (Some(side), ImageColors::Viridis { low, high, label }) = (side, &image.colors) {
        colour_bar(&side, (*low, *high), label, scale).map_err(err)?;
    }
    Ok(())
}

/// `area` less margins that give its plot (the area less the caption, the label areas
/// and the outer margin, as [`render`] lays them out) the aspect of `extent`.
fn with_aspect<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (ex, ey): (f64, f64),
    scale: u32,
) -> DrawingArea<DB, Shift> {
    let (w, h) = area.dim_in_pixel();
    let s = scale as f64;
    // Margins 2 × 15, label areas 80 (y) and 50 (x), the caption about 1.5 × its 20.
    let plot_w = (w as f64 - 30.0 * s - 80.0 * s).max(1.0);
    let plot_h = (h as f64 - 30.0 * s - 50.0 * s - 30.0 * s).max(1.0);
    let aspect = ex / ey;
    if plot_w / plot_h > aspect {
        let extra = (plot_w - plot_h * aspect) / 2.0;
        area.margin(0, 0, extra as i32, extra as i32)
    } else {
        let extra = (plot_h - plot_w / aspect) / 2.0;
        area.margin(extra as i32, extra as i32, 0, 0)
    }
}

/// The scale bar: a black bar with its length above it on a white box, lower left.
fn draw_scale_bar<DB, X, Y>(
    plot: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    bar: &ScaleBar,
    (ex, ey): (f64, f64),
    scale: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let (x0, y0) = (0.04 * ex, 0.05 * ey);
    let box_corners = [
        (0.02 * ex, 0.02 * ey),
        (x0 + bar.length + 0.02 * ex, 0.15 * ey),
    ];
    plot.draw_series([Rectangle::new(box_corners, WHITE.mix(0.85).filled())])?;
    let stroke = BLACK.stroke_width(3 * scale);
    plot.draw_series([PathElement::new(
        vec![(x0, y0), (x0 + bar.length, y0)],
        stroke,
    )])?;
    let font = ("sans-serif", 15 * scale)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Bottom));
    let at = (x0 + bar.length / 2.0, y0);
    plot.draw_series([
        EmptyElement::at(at) + Text::new(bar.label.clone(), (0, -(4 * scale as i32)), font)
    ])?;
    Ok(())
}

/// The colour bar of values `low..high` on the Viridis map, labelled `label`.
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (low, high): (f64, f64),
    label: &str,
    scale: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let px = |v: u32| v * scale;
    let (low, high) = if high > low {
        (low, high)
    } else {
        (low - 0.5, low + 0.5)
    };
    let mut bar = ChartBuilder::on(area)
        .margin(px(10))
        .margin_top(px(60))
        .margin_bottom(px(65))
        .set_label_area_size(LabelAreaPosition::Right, px(95))
        .build_cartesian_2d(0.0..1.0, low..high)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_labels(6)
        .y_label_formatter(&|v| tick_label(*v, high - low))
        .label_style(("sans-serif", px(14)))
        .axis_desc_style(("sans-serif", px(16)))
        .axis_style(BLACK.stroke_width(scale))
        .draw()?;
    let steps = 128;
    let step = (high - low) / steps as f64;
    bar.draw_series((0..steps).map(|i| {
        let y = low + i as f64 * step;
        let color = ViridisRGB::get_color((i as f32 + 0.5) / steps as f32);
        Rectangle::new([(0.0, y), (1.0, y + step)], color.filled())
    }))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use asperity_app::figure::Color;

    #[test]
    fn cells_take_their_colours_by_map_or_category() {
        let viridis = ImageColors::Viridis {
            low: 0.0,
            high: 2.0,
            label: String::new(),
        };
        assert_eq!(cell_color(&viridis, f64::NAN), None);
        assert_eq!(cell_color(&viridis, 0.0), Some(ViridisRGB::get_color(0.0)));
        assert_eq!(cell_color(&viridis, 9.0), Some(ViridisRGB::get_color(1.0)));
        let colors = vec![Color::Rgb(255, 255, 255), Color::RED, Color::BLUE];
        let categories = ImageColors::Categories { colors };
        assert_eq!(cell_color(&categories, 0.0), Some(RGBColor(255, 255, 255)));
        assert_eq!(cell_color(&categories, 1.0), Some(RGBColor(255, 0, 0)));
        assert_eq!(cell_color(&categories, 2.0), Some(RGBColor(0, 0, 255)));
        assert_eq!(cell_color(&categories, 3.0), Some(RGBColor(255, 0, 0)));
    }
}
