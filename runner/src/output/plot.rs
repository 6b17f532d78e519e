//! Line plots of a probe's value against simulated time, as PNG, through plotters with the
//! bundled font.

use super::{OutputError, font};
use plotters::prelude::*;
use std::path::Path;

/// A named quantity sampled over simulated time.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeSeries {
    /// What is measured, e.g. `"tip displacement"`.
    pub name: String,
    /// The unit of the values, e.g. `"m"`.
    pub unit: String,
    /// `(time (s), value (unit))` pairs in time order.
    pub samples: Vec<(f64, f64)>,
}

/// Plots `series` against time into the PNG file `path`, `size` pixels wide and high, with the
/// axes labelled `time (s)` and `<name> (<unit>)`.
///
/// # Errors
/// [`OutputError::Picture`] if the plot cannot be drawn or written (also when the bundled font
/// cannot be loaded, as axis labels need it).
pub fn plot_series(path: &Path, series: &TimeSeries, size: (u32, u32)) -> Result<(), OutputError> {
    if !font::register() {
        return Err(OutputError::picture(path)(
            "the bundled font could not be loaded",
        ));
    }
    draw(path, series, size).map_err(OutputError::picture(path))
}

fn draw(
    path: &Path,
    series: &TimeSeries,
    size: (u32, u32),
) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    let finite = || {
        series
            .samples
            .iter()
            .filter(|(t, v)| t.is_finite() && v.is_finite())
    };
    let (t0, t1) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (t, _)| {
        (lo.min(*t), hi.max(*t))
    });
    let (v0, v1) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (_, v)| {
        (lo.min(*v), hi.max(*v))
    });
    let (t0, t1) = padded(t0, t1, 0.0);
    let (v0, v1) = padded(v0, v1, 0.05);
    let mut chart = ChartBuilder::on(&root)
        .caption(&series.name, ("sans-serif", 24))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(t0..t1, v0..v1)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc(format!("{} ({})", series.name, series.unit))
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()?;
    chart.draw_series(LineSeries::new(finite().copied(), BLUE.stroke_width(2)))?;
    root.present()?;
    Ok(())
}

/// The spread, relative to the values' size, below which a series is drawn as a constant: a
/// conserved quantity (a free body's momentum) varies by round-off of about 1e-15 of its size,
/// which a range fitted to it would magnify into noise across the whole plot.
const CONSTANT_SPREAD: f64 = 1e-10;

/// The range `lo..hi` widened by `fraction` of its length on each side, or, for values equal
/// to within [`CONSTANT_SPREAD`], to a range as wide as their size around them (and `0..1` when
/// there are no values).
fn padded(lo: f64, hi: f64, fraction: f64) -> (f64, f64) {
    if lo.partial_cmp(&hi).is_none_or(|o| o.is_gt()) {
        (0.0, 1.0)
    } else if hi - lo <= CONSTANT_SPREAD * lo.abs().max(hi.abs()) {
        let middle = 0.5 * (lo + hi);
        let half = 0.5 * middle.abs().max(1e-9);
        (middle - half, middle + half)
    } else {
        let pad = (hi - lo) * fraction;
        (lo - pad, hi + pad)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether two ranges agree to 1e-12.
    fn close((a0, a1): (f64, f64), (b0, b1): (f64, f64)) -> bool {
        (a0 - b0).abs() < 1e-12 && (a1 - b1).abs() < 1e-12
    }

    #[test]
    fn values_equal_to_round_off_get_the_range_of_a_constant() {
        assert!(close(padded(0.42, 0.42, 0.05), (0.21, 0.63)));
        assert!(close(
            padded(0.42 - 1e-15, 0.42 + 1e-15, 0.05),
            (0.21, 0.63)
        ));
        // A real change is fitted.
        assert!(close(padded(0.41, 0.42, 0.05), (0.4095, 0.4205)));
        assert!(close(padded(0.0, 0.0, 0.05), (-5e-10, 5e-10)));
        assert_eq!(padded(f64::INFINITY, f64::NEG_INFINITY, 0.05), (0.0, 1.0));
    }
}
