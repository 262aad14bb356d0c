//! [`svg`]: panels stacked into one SVG document, each with its legend at its right.

use crate::error::Error;
use crate::legend;
use crate::panel::Panel;
use crate::style::MAX_SERIES;
use plotters::backend::SVGBackend;
use plotters::drawing::{DrawingAreaErrorKind, IntoDrawingArea};
use plotters::style::WHITE;

/// An SVG document `width` pixels wide with `panels` stacked top to bottom, each
/// `panel_height` pixels high.
///
/// # Errors
/// [`Error::NoPanels`]; [`Error::TooManySeries`] when a panel has more series than
/// [`MAX_SERIES`] (its legend could not tell them apart); [`Error::Backend`] when drawing fails.
pub fn svg(panels: &[Panel<'_>], width: u32, panel_height: u32) -> Result<String, Error> {
    if panels.is_empty() {
        return Err(Error::NoPanels);
    }
    if let Some(p) = panels.iter().find(|p| p.series().len() > MAX_SERIES) {
        return Err(Error::TooManySeries {
            panel: p.title().to_string(),
            count: p.series().len(),
            max: MAX_SERIES,
        });
    }
    let legend_width = legend::width(panels);
    let height = panel_height.saturating_mul(u32::try_from(panels.len()).unwrap_or(u32::MAX));
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(backend)?;
        for (area, panel) in root.split_evenly((panels.len(), 1)).iter().zip(panels) {
            let (plot, legend) = area.split_horizontally(width.saturating_sub(legend_width));
            panel.draw(&plot).map_err(backend)?;
            legend::draw(panel, &legend).map_err(backend)?;
        }
        root.present().map_err(backend)?;
    }
    Ok(out)
}

/// A drawing error as this crate's.
fn backend<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> Error {
    Error::Backend(e.to_string())
}
