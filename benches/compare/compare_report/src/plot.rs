//! One PNG per scene: its panels on log-log axes, one colour per series, one marker shape per
//! engine, the Pareto front of each trade-off panel as a black staircase, and a legend column.

use crate::pareto::{self, Point};
use crate::scenes::{Metric, Panel};
use plotters::coord::{CoordTranslate, Shift};
use plotters::drawing::DrawingAreaErrorKind;
use plotters::prelude::*;
use std::path::Path;

/// The bundled font (`DejaVu` Sans, as the runner's plots use), registered as `sans-serif`.
static FONT: &[u8] = include_bytes!("../../../../runner/assets/fonts/DejaVuSans.ttf");
/// Pixel size of one panel.
const PANEL: (u32, u32) = (560, 420);
/// Width of the legend column (px).
const LEGEND_WIDTH: u32 = 470;
/// Height of one legend row (px).
const LEGEND_ROW: i32 = 22;

/// Registers the bundled font once; `false` if it could not be parsed.
fn register_font() -> bool {
    /// The outcome of the first registration.
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()
    })
}

/// Draws `panels` (each with its points) and the legend of `series` into the PNG at `path`.
///
/// # Errors
/// When the font cannot be loaded or the picture cannot be drawn or written.
pub fn draw(
    path: &Path,
    title: &str,
    panels: &[(&Panel, Vec<Point>)],
    series: &[String],
) -> Result<(), Box<dyn std::error::Error>> {
    if !register_font() {
        return Err("the bundled font could not be loaded".into());
    }
    let cols = panels.len().clamp(1, 3) as u32;
    let rows = (panels.len() as u32).div_ceil(cols).max(1);
    let legend_height = 60 + LEGEND_ROW as u32 * series.len() as u32;
    let height = (40 + rows * PANEL.1).max(legend_height);
    let root =
        BitMapBackend::new(path, (cols * PANEL.0 + LEGEND_WIDTH, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 24))?;
    let (grid, legend) = root.split_horizontally(cols * PANEL.0);
    let (grid, _) = grid.split_vertically(rows * PANEL.1);
    for ((panel, points), area) in panels
        .iter()
        .zip(grid.split_evenly((rows as usize, cols as usize)))
    {
        draw_panel(&area, panel, points, series)?;
    }
    draw_legend(
        &legend,
        series,
        panels.iter().any(|(p, _)| p.is_trade_off()),
    )?;
    root.present()?;
    Ok(())
}

/// Distinct, saturated colours (none black, which draws the front), cycled.
const COLOURS: [(u8, u8, u8); 20] = [
    (31, 119, 180),
    (214, 39, 40),
    (44, 160, 44),
    (255, 127, 14),
    (148, 103, 189),
    (23, 190, 207),
    (140, 86, 75),
    (227, 119, 194),
    (188, 189, 34),
    (127, 127, 127),
    (0, 0, 128),
    (128, 0, 0),
    (0, 128, 128),
    (218, 165, 32),
    (199, 21, 133),
    (85, 107, 47),
    (106, 90, 205),
    (210, 105, 30),
    (46, 139, 87),
    (70, 130, 180),
];

/// The colour of a series: its place in the scene's list.
fn colour(series: &[String], name: &str) -> RGBColor {
    let index = series.iter().position(|s| s == name).unwrap_or(0);
    let (r, g, b) = COLOURS[index % COLOURS.len()];
    RGBColor(r, g, b)
}

/// Draws a marker at `at`: a disc for this crate, a cross for pybullet, a triangle for
/// `MuJoCo`, a square for rapier's built-in soft bodies.
fn put<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    engine: &str,
    at: CT::From,
    color: RGBColor,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    CT::From: Clone,
{
    let base = EmptyElement::at(at);
    match engine {
        pareto::OURS => area.draw(&(base + Circle::new((0, 0), 5, color.filled()))),
        "pybullet" => area.draw(&(base + Cross::new((0, 0), 5, color.stroke_width(2)))),
        "mujoco" => area.draw(&(base + TriangleMarker::new((0, 0), 6, color.filled()))),
        _ => area.draw(&(base + Rectangle::new([(-4, -4), (4, 4)], color.filled()))),
    }
}

/// The smallest ratio between the ends of an axis: a narrower log axis crowds its labels.
const MIN_AXIS_RATIO: f64 = 100.0;

/// The log range covering the positive `values` with a margin, at least [`MIN_AXIS_RATIO`]
/// wide (widened about its geometric centre).
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (0.1, 10.0);
    }
    let (lo, hi) = (lo / 1.6, hi * 1.6);
    let widen = (MIN_AXIS_RATIO / (hi / lo)).max(1.0).sqrt();
    (lo / widen, hi * widen)
}

/// One panel: axes, the front (trade-off panels) or each series' curve (scaling), the points.
fn draw_panel(
    area: &DrawingArea<BitMapBackend, Shift>,
    panel: &Panel,
    points: &[Point],
    series: &[String],
) -> Result<(), Box<dyn std::error::Error>> {
    // Zero values (an exact result) are drawn at the bottom edge.
    let (y0, y1) = log_range(points.iter().map(|p| p.y));
    let y_of = |p: &Point| p.y.max(y0);
    let (x0, x1) = log_range(points.iter().map(|p| p.x));
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc(panel.x.label())
        .y_desc(panel.y.label())
        .x_labels(8)
        .y_labels(8)
        .label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 13))
        .y_label_formatter(&|v| axis_number(panel.y, *v))
        .x_label_formatter(&|v| axis_number(panel.x, *v))
        .draw()?;
    if points.is_empty() {
        return Ok(());
    }
    if panel.is_trade_off() {
        let front = pareto::front(points);
        let mut stairs = Vec::new();
        for (i, p) in front.iter().enumerate() {
            stairs.push((p.x, y_of(p)));
            let next_x = front.get(i + 1).map_or(x1, |q| q.x);
            stairs.push((next_x, y_of(p)));
        }
        chart.draw_series(LineSeries::new(stairs, BLACK.stroke_width(1)))?;
    } else {
        for name in series {
            let mut curve: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| &p.case.series == name)
                .map(|p| (p.x, y_of(p)))
                .collect();
            curve.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart.draw_series(LineSeries::new(curve, colour(series, name).stroke_width(1)))?;
        }
    }
    for p in points {
        let color = colour(series, &p.case.series);
        put(chart.plotting_area(), &p.case.engine, (p.x, y_of(p)), color)?;
    }
    Ok(())
}

/// An axis tick: percent for errors, powers of ten below 1e-3, plain numbers otherwise.
fn axis_number(metric: Metric, v: f64) -> String {
    match metric {
        Metric::AbsError => format!("{}%", pareto::sig(100.0 * v)),
        _ if v < 1e-3 => format!("{v:.0e}"),
        _ => pareto::sig(v),
    }
}

/// The legend column: one row per series, then how to read the plot.
fn draw_legend(
    area: &DrawingArea<BitMapBackend, Shift>,
    series: &[String],
    trade_off: bool,
) -> Result<(), Box<dyn std::error::Error>> {
    let note = if trade_off {
        "lower-left is better; black: Pareto front"
    } else {
        "lower is better"
    };
    area.draw(&Text::new(note, (10, 10), ("sans-serif", 15)))?;
    for (i, name) in series.iter().enumerate() {
        let y = 44 + LEGEND_ROW * i as i32;
        let engine = name.split_whitespace().next().unwrap_or("");
        put(area, engine, (18, y), colour(series, name))?;
        area.draw(&Text::new(name.as_str(), (34, y - 8), ("sans-serif", 14)))?;
    }
    Ok(())
}
