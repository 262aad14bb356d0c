//! [`Axis`]: a laid-out [`Ticks`] as a plotters coordinate, so that plotters draws the grid,
//! ticks and labels this crate chose.

use crate::ticks::Ticks;
use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};
use std::ops::Range;

/// One axis of a panel, for plotters: values map through the ticks' scale; the bold grid
/// lines are the labelled ticks, the light ones the minor ticks.
pub struct Axis(pub Ticks);

impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let span = f64::from(limit.1) - f64::from(limit.0);
        (f64::from(limit.0) + self.0.fraction(*value) * span).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.0.minor().to_vec()
        } else {
            self.0.major()
        }
    }

    fn range(&self) -> Range<f64> {
        let (lo, hi) = self.0.bounds();
        lo..hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format_ext(&self, value: &f64) -> String {
        self.0.label(*value)
    }
}
