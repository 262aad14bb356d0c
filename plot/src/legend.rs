//! A panel's legend, in a column at its right: one row per series, its line (and dot) beside its
//! name.

use crate::panel::{colour, line, text, Panel, LABEL_PX, MARKER_PX};
use crate::style::{series_style, Dash};
use plotters::backend::DrawingBackend;
use plotters::coord::Shift;
use plotters::drawing::{DrawingArea, DrawingAreaErrorKind};
use plotters::element::{Circle, DashedPathElement, PathElement, Text};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::Color;

/// Length of the line drawn beside each name, pixels.
const SWATCH_PX: i32 = 30;
/// Space left of the line and between the line and the name, pixels.
const GAP_PX: i32 = 6;
/// Where the first row starts, pixels from the top (level with the plot's top).
const TOP_PX: i32 = 36;
/// Tallest row, pixels.
const ROW_PX: i32 = 18;
/// Average width of a character of the legend's text, as a fraction of its height.
const CHAR_WIDTH: f64 = 0.6;

/// The width of a legend column wide enough for every name of `panels`, pixels.
pub fn width(panels: &[Panel<'_>]) -> u32 {
    let longest = panels
        .iter()
        .flat_map(|p| p.series().iter())
        .map(|s| s.name.chars().count())
        .max()
        .unwrap_or(0);
    let text = (longest as f64 * CHAR_WIDTH * LABEL_PX).ceil() as u32;
    text + (SWATCH_PX + 3 * GAP_PX).unsigned_abs()
}

/// Draws the legend of `panel` on `area`.
pub fn draw<DB: DrawingBackend>(
    panel: &Panel<'_>,
    area: &DrawingArea<DB, Shift>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let series = panel.series();
    let (_, height) = area.dim_in_pixel();
    let rows = i32::try_from(series.len().max(1)).unwrap_or(i32::MAX);
    let room = i32::try_from(height).unwrap_or(i32::MAX) - TOP_PX;
    let row = (room / rows).clamp(1, ROW_PX);
    for ((i, s), style) in series
        .iter()
        .enumerate()
        .filter_map(|(i, s)| Some(((i, s), series_style(i)?)))
    {
        let y = TOP_PX + row * i32::try_from(i).unwrap_or(0) + row / 2;
        let swatch = [(GAP_PX, y), (GAP_PX + SWATCH_PX, y)];
        match style.dash {
            Dash::Solid => area.draw(&PathElement::new(swatch, line(style)))?,
            Dash::Dashed { on, off } => {
                area.draw(&DashedPathElement::new(swatch, on, off, line(style)))?;
            }
        }
        if panel.markers {
            let centre = (GAP_PX + SWATCH_PX / 2, y);
            area.draw(&Circle::new(centre, MARKER_PX, colour(style).filled()))?;
        }
        let at = (2 * GAP_PX + SWATCH_PX, y);
        let style = text(LABEL_PX).pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(s.name.as_str(), at, style))?;
    }
    Ok(())
}
