//! How each series of a panel is drawn: a colour and a dash pattern, never the same pair twice
//! in one legend.

/// Line colours (matplotlib's `tab10`), as RGB.
pub const COLOURS: [[u8; 3]; 10] = [
    [0x1f, 0x77, 0xb4],
    [0xff, 0x7f, 0x0e],
    [0x2c, 0xa0, 0x2c],
    [0xd6, 0x27, 0x28],
    [0x94, 0x67, 0xbd],
    [0x8c, 0x56, 0x4b],
    [0xe3, 0x77, 0xc2],
    [0x7f, 0x7f, 0x7f],
    [0xbc, 0xbd, 0x22],
    [0x17, 0xbe, 0xcf],
];

/// A line's dash pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dash {
    /// Unbroken.
    Solid,
    /// Dashes and gaps of these lengths, pixels.
    Dashed {
        /// Length of a dash.
        on: u32,
        /// Length of a gap.
        off: u32,
    },
}

/// Dash patterns, taken in turn once every colour has been used with the one before.
pub const DASHES: [Dash; 3] = [
    Dash::Solid,
    Dash::Dashed { on: 8, off: 4 },
    Dash::Dashed { on: 2, off: 3 },
];

/// Most series one panel can hold: one per colour and dash pair.
pub const MAX_SERIES: usize = COLOURS.len() * DASHES.len();

/// How one series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SeriesStyle {
    /// Its colour, RGB.
    pub colour: [u8; 3],
    /// Its dash pattern.
    pub dash: Dash,
}

/// The style of the `i`-th series of a panel: colours in turn, solid; then each colour again
/// with the next dash pattern. Distinct for every `i < MAX_SERIES`; `None` past it.
#[must_use]
pub fn series_style(i: usize) -> Option<SeriesStyle> {
    (i < MAX_SERIES).then(|| SeriesStyle {
        colour: COLOURS[i % COLOURS.len()],
        dash: DASHES[i / COLOURS.len()],
    })
}

#[cfg(test)]
mod tests {
    use super::{series_style, MAX_SERIES};

    #[test]
    fn no_two_series_of_a_legend_share_a_colour_and_dash() {
        let styles: Vec<_> = (0..MAX_SERIES).filter_map(series_style).collect();
        assert_eq!(styles.len(), MAX_SERIES);
        for (i, a) in styles.iter().enumerate() {
            for b in &styles[i + 1..] {
                assert!(a != b, "{a:?} is used twice");
            }
        }
        assert_eq!(series_style(MAX_SERIES), None);
    }

    #[test]
    fn the_first_ten_series_are_solid_in_ten_colours() {
        let styles: Vec<_> = (0..10).filter_map(series_style).collect();
        assert!(styles.iter().all(|s| s.dash == super::Dash::Solid));
        for (i, a) in styles.iter().enumerate() {
            assert!(styles[i + 1..].iter().all(|b| b.colour != a.colour));
        }
    }
}
