//! [`Series`] and [`Panel`]: what one plot shows, and how a panel is drawn on its area.

use crate::coord::Axis;
use crate::style::{series_style, Dash, SeriesStyle};
use crate::ticks::{Scale, Ticks, MAX_TICKS};
use plotters::backend::DrawingBackend;
use plotters::chart::ChartBuilder;
use plotters::coord::Shift;
use plotters::drawing::{DrawingArea, DrawingAreaErrorKind};
use plotters::element::{Circle, DashedPathElement, PathElement};
use plotters::style::{Color, FontStyle, IntoFont, RGBColor, ShapeStyle, TextStyle};

/// One named line of `(x, y)` points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// The points, in drawing order; a point the axes cannot show (not finite, or not positive
    /// on a log axis) breaks the line.
    pub points: Vec<(f64, f64)>,
}

/// One plot: a title, two axes, its series and their legend.
#[derive(Debug, Clone, Copy)]
pub struct Panel<'a> {
    pub(crate) title: &'a str,
    pub(crate) series: &'a [Series],
    pub(crate) x: (&'a str, Scale),
    pub(crate) y: (&'a str, Scale),
    pub(crate) markers: bool,
}

impl<'a> Panel<'a> {
    /// A panel titled `title` showing `series`, on linear axes without labels, lines only.
    #[must_use]
    pub fn new(title: &'a str, series: &'a [Series]) -> Self {
        Self {
            title,
            series,
            x: ("", Scale::Linear),
            y: ("", Scale::Linear),
            markers: false,
        }
    }

    /// The x axis's label and scale.
    #[must_use]
    pub fn x_axis(self, label: &'a str, scale: Scale) -> Self {
        Self {
            x: (label, scale),
            ..self
        }
    }

    /// The y axis's label and scale.
    #[must_use]
    pub fn y_axis(self, label: &'a str, scale: Scale) -> Self {
        Self {
            y: (label, scale),
            ..self
        }
    }

    /// Marks every point with a dot as well (for sweeps of a few points).
    #[must_use]
    pub fn with_markers(self) -> Self {
        Self {
            markers: true,
            ..self
        }
    }

    /// The title.
    #[must_use]
    pub fn title(&self) -> &str {
        self.title
    }

    /// The series.
    #[must_use]
    pub fn series(&self) -> &[Series] {
        self.series
    }

    /// True when both axes can show `(x, y)`.
    fn shows(&self, (x, y): (f64, f64)) -> bool {
        self.x.1.drawable(x) && self.y.1.drawable(y)
    }

    /// The points of `series` both axes can show, in runs broken where one cannot.
    fn runs<'s>(&self, series: &'s Series) -> impl Iterator<Item = &'s [(f64, f64)]> + use<'s, '_> {
        series
            .points
            .split(|&p| !self.shows(p))
            .filter(|run| !run.is_empty())
    }

    /// The laid-out axes: each over the points the other axis can show too.
    fn axes(&self) -> (Ticks, Ticks) {
        let shown = || {
            self.series
                .iter()
                .flat_map(|s| s.points.iter())
                .filter(|&&p| self.shows(p))
        };
        (
            Ticks::new(self.x.1, shown().map(|p| p.0)),
            Ticks::new(self.y.1, shown().map(|p| p.1)),
        )
    }

    /// Draws the panel's title, axes and series on `area` (its legend is drawn beside it).
    pub(crate) fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (x, y) = self.axes();
        let mut chart = ChartBuilder::on(area)
            .caption(
                self.title,
                ("sans-serif", font_size(TITLE_PX))
                    .into_font()
                    .style(FontStyle::Bold),
            )
            .margin(MARGIN_PX)
            .x_label_area_size(X_LABEL_AREA_PX)
            .y_label_area_size(Y_LABEL_AREA_PX)
            .build_cartesian_2d(Axis(x), Axis(y))?;
        chart
            .configure_mesh()
            .x_desc(self.x.0)
            .y_desc(self.y.0)
            .x_labels(MAX_TICKS)
            .y_labels(MAX_TICKS)
            .label_style(text(LABEL_PX))
            .axis_desc_style(text(LABEL_PX))
            .draw()?;
        for (i, series) in self.series.iter().enumerate() {
            let Some(style) = series_style(i) else {
                continue;
            };
            for run in self.runs(series) {
                if self.markers {
                    chart.draw_series(
                        run.iter()
                            .map(|&p| Circle::new(p, MARKER_PX, colour(style).filled())),
                    )?;
                }
                match style.dash {
                    Dash::Solid => {
                        chart.draw_series([PathElement::new(run.to_vec(), line(style))])?
                    }
                    Dash::Dashed { on, off } => chart.draw_series([DashedPathElement::new(
                        run.iter().copied(),
                        on,
                        off,
                        line(style),
                    )])?,
                };
            }
        }
        Ok(())
    }
}

/// Rendered size of the title, pixels.
const TITLE_PX: f64 = 14.0;
/// Rendered size of tick labels, axis labels and legend entries, pixels.
pub(crate) const LABEL_PX: f64 = 12.0;
/// Space around a panel's plot, pixels.
const MARGIN_PX: u32 = 8;
/// Height of the area below the plot for tick labels and the x axis's label, pixels.
const X_LABEL_AREA_PX: u32 = 42;
/// Width of the area left of the plot for tick labels and the y axis's label, pixels.
const Y_LABEL_AREA_PX: u32 = 76;
/// Width of a series' line, pixels.
const LINE_PX: u32 = 2;
/// Radius of a point's dot, pixels.
pub(crate) const MARKER_PX: u32 = 3;

/// The font size to ask plotters for, so that the SVG's text is `px` pixels high (its SVG
/// backend writes `size / 1.24`).
pub(crate) fn font_size(px: f64) -> f64 {
    px * 1.24
}

/// Sans-serif text `px` pixels high.
pub(crate) fn text(px: f64) -> TextStyle<'static> {
    ("sans-serif", font_size(px)).into()
}

/// The colour of `style`.
pub(crate) fn colour(style: SeriesStyle) -> RGBColor {
    let [r, g, b] = style.colour;
    RGBColor(r, g, b)
}

/// The line of `style`.
pub(crate) fn line(style: SeriesStyle) -> ShapeStyle {
    colour(style).stroke_width(LINE_PX)
}
