//! [`Error`]: why a figure could not be drawn.

use std::fmt;

/// Why a figure could not be drawn.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Error {
    /// A panel has more series than there are distinct colour and dash pairs.
    TooManySeries {
        /// The panel's title.
        panel: String,
        /// Its number of series.
        count: usize,
        /// The most a panel can hold ([`MAX_SERIES`](crate::MAX_SERIES)).
        max: usize,
    },
    /// The figure has no panel.
    NoPanels,
    /// The drawing backend failed.
    Backend(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooManySeries { panel, count, max } => write!(
                f,
                "panel `{panel}` has {count} series: at most {max} have distinct colours and dashes"
            ),
            Self::NoPanels => f.write_str("a figure needs at least one panel"),
            Self::Backend(why) => write!(f, "drawing failed: {why}"),
        }
    }
}

impl std::error::Error for Error {}
