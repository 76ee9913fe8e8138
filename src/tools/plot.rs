//! What every hooke chart shares: the bundled font (titles and labels render on a machine
//! without system fonts), axes with their units and light grid lines, and the legend box.
//! The `hooke` command's plots and the examples' pictures are drawn with these.

use plotters::coord::Shift;
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::prelude::*;

const FONT: &[u8] = include_bytes!("../../assets/fonts/FiraSans-Regular.ttf");

/// The error of a chart: plotters' drawing errors and file errors, boxed.
pub type PlotResult<T = ()> = Result<T, Box<dyn std::error::Error>>;

/// Registers the bundled Fira Sans as "sans-serif" (registering again is harmless).
///
/// # Errors
/// If the font does not load.
pub fn register_fonts() -> PlotResult {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| "the bundled font did not load")?;
    Ok(())
}

/// A white drawing area of `size` pixels with `title` across its top.
///
/// # Errors
/// If the file cannot be written or the title drawn.
pub fn titled_png<'a>(
    path: &'a std::path::Path,
    size: (u32, u32),
    title: &str,
) -> PlotResult<DrawingArea<BitMapBackend<'a>, Shift>> {
    register_fonts()?;
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    Ok(root.titled(title, ("sans-serif", 22))?)
}

/// Draws the axes of a 2D chart with their descriptions (name and unit, e.g. `"t (s)"`), tick
/// labels and light grid lines.
///
/// # Errors
/// If plotters fails to draw.
pub fn axes<'a, DB, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    x_desc: &str,
    y_desc: &str,
) -> PlotResult
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged + ValueFormatter<X::ValueType>,
    Y: Ranged + ValueFormatter<Y::ValueType>,
{
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(("sans-serif", 12))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// Draws the legend of the series drawn with labels: upper right, on a white box.
///
/// # Errors
/// If plotters fails to draw.
pub fn legend<'a, DB, CT>(chart: &mut ChartContext<'a, DB, CT>) -> PlotResult
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    CT: CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 12))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(())
}
