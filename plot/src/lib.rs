//! SVG line plots for lagrange's demo and bench, on plotters' SVG backend (no system fonts:
//! text is written as SVG `<text>` for the viewer to set).
//!
//! - Ticks a reader can use: 1, 2 or 5 x 10^k on linear axes, decades labelled `1e-6` on log
//!   axes ([`Ticks`]).
//! - No two series of a legend share a colour and dash pattern ([`series_style`]); a panel
//!   holds at most [`MAX_SERIES`].
//!
//! ```
//! use lagrange_plot::{svg, Panel, Scale, Series};
//!
//! let decay = [Series {
//!     name: "exp(-t)".into(),
//!     points: (0..=50).map(|i| f64::from(i) / 10.0).map(|t| (t, (-t).exp())).collect(),
//! }];
//! let panel = Panel::new("Decay", &decay)
//!     .x_axis("t (s)", Scale::Linear)
//!     .y_axis("x", Scale::Log);
//! let doc = svg(&[panel], 640, 360)?;
//! assert!(doc.contains("exp(-t)") && doc.contains("1e-2"));
//! # Ok::<(), lagrange_plot::Error>(())
//! ```

mod coord;
mod error;
mod figure;
mod legend;
mod panel;
mod style;
mod ticks;

pub use error::Error;
pub use figure::svg;
pub use panel::{Panel, Series};
pub use style::{series_style, Dash, SeriesStyle, COLOURS, DASHES, MAX_SERIES};
pub use ticks::{Scale, Ticks, MAX_TICKS};
