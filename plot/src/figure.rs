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

#[cfg(test)]
mod tests {
    use super::svg;
    use crate::{Error, Panel, Scale, Series, MAX_SERIES};

    /// `n` straight lines named `s0`, `s1`, ...
    fn lines(n: usize) -> Vec<Series> {
        (0..n)
            .map(|i| Series {
                name: format!("s{i}"),
                points: vec![(0.0, i as f64), (10.0, i as f64 + 1.0)],
            })
            .collect()
    }

    #[test]
    fn text_is_written_as_svg_text_without_fonts() -> Result<(), Error> {
        let series = lines(3);
        let panel = Panel::new("Three lines", &series)
            .x_axis("t (s)", Scale::Linear)
            .y_axis("y <m>", Scale::Linear);
        let doc = svg(&[panel, panel], 600, 300)?;
        assert!(doc.starts_with("<svg") && doc.trim_end().ends_with("</svg>"));
        for text in [
            "Three lines",
            "t (s)",
            "y &lt;m&gt;",
            "s0",
            "s2",
            "\n10\n",
            "\n0\n",
        ] {
            assert!(doc.contains(text), "`{text}` missing");
        }
        Ok(())
    }

    #[test]
    fn a_panel_holds_as_many_series_as_there_are_styles() {
        let full = lines(MAX_SERIES);
        assert!(svg(&[Panel::new("full", &full)], 900, 700).is_ok());
        let over = lines(MAX_SERIES + 1);
        assert_eq!(
            svg(&[Panel::new("over", &over)], 900, 700),
            Err(Error::TooManySeries {
                panel: "over".into(),
                count: MAX_SERIES + 1,
                max: MAX_SERIES
            })
        );
        assert_eq!(svg(&[], 900, 700), Err(Error::NoPanels));
    }

    #[test]
    fn points_a_log_axis_cannot_show_break_the_line() -> Result<(), Error> {
        let series = [Series {
            name: "gap".into(),
            points: vec![
                (1.0, 1e-3),
                (2.0, 1e-2),
                (3.0, 0.0),
                (4.0, 1e-1),
                (5.0, 1.0),
            ],
        }];
        let doc = svg(
            &[Panel::new("log", &series).y_axis("y", Scale::Log)],
            600,
            300,
        )?;
        // Two runs of two points each: two line paths in the series' colour (#1F77B4) and its
        // legend swatch.
        assert_eq!(doc.matches("stroke=\"#1F77B4\"").count(), 3);
        assert!(doc.contains("\n1e-3\n") && doc.contains("\n1\n"));
        Ok(())
    }
}
