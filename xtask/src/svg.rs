//! A minimal SVG line plot, enough for the demo's figures without a plotting dependency.

use std::fmt::Write;

/// One named line of `(x, y)` points.
pub struct Series {
    /// Legend text.
    pub name: String,
    /// The points, in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// Axis scaling.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Linear.
    Linear,
    /// Base-10 logarithmic; points at or below zero are dropped.
    Log,
}

/// Plot geometry, pixels.
const W: f64 = 720.0;
const H: f64 = 360.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 170.0;
const TOP: f64 = 30.0;
const BOTTOM: f64 = 45.0;
const COLOURS: [&str; 6] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
];

/// An SVG document with one panel per `(title, y label, y scale, series)`, stacked vertically,
/// sharing the x label.
pub fn panels(x_label: &str, panels: &[(&str, &str, Scale, &[Series])]) -> String {
    let total_h = H * panels.len() as f64;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{W}\" height=\"{total_h}\" \
         font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    for (i, (title, y_label, scale, series)) in panels.iter().enumerate() {
        panel(
            &mut s,
            H * i as f64,
            title,
            x_label,
            y_label,
            *scale,
            series,
        );
    }
    s.push_str("</svg>\n");
    s
}

/// Maps a y value through the scale, `None` where it cannot be drawn.
fn scaled(y: f64, scale: Scale) -> Option<f64> {
    match scale {
        Scale::Linear => y.is_finite().then_some(y),
        Scale::Log => (y > 0.0 && y.is_finite()).then(|| y.log10()),
    }
}

fn panel(
    s: &mut String,
    y0: f64,
    title: &str,
    x_label: &str,
    y_label: &str,
    scale: Scale,
    series: &[Series],
) {
    let pts = || series.iter().flat_map(|r| r.points.iter());
    let xs = pts().map(|p| p.0);
    let ys = pts().filter_map(|p| scaled(p.1, scale));
    let (x_min, x_max) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    let (mut y_min, mut y_max) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
        (a.min(y), b.max(y))
    });
    if y_max.partial_cmp(&y_min) != Some(std::cmp::Ordering::Greater) {
        y_min -= 1.0;
        y_max += 1.0;
    }
    let x_span = if x_max > x_min { x_max - x_min } else { 1.0 };
    let (pw, ph) = (W - LEFT - RIGHT, H - TOP - BOTTOM);
    let px = |x: f64| LEFT + (x - x_min) / x_span * pw;
    let py = |y: f64| y0 + TOP + (y_max - y) / (y_max - y_min) * ph;

    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"{}\" font-weight=\"bold\">{title}</text>",
        LEFT,
        y0 + 18.0
    );
    let _ = writeln!(
        s,
        "<rect x=\"{LEFT}\" y=\"{}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\" stroke=\"black\"/>",
        y0 + TOP
    );
    for k in 0..=4 {
        let f = f64::from(k) / 4.0;
        let (x, y) = (x_min + f * x_span, y_min + f * (y_max - y_min));
        let y_text = match scale {
            Scale::Linear => format!("{y:.3}"),
            Scale::Log => format!("1e{y:.1}"),
        };
        let _ = writeln!(
            s,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{x:.3}</text>",
            px(x),
            y0 + H - BOTTOM + 16.0
        );
        let _ = writeln!(
            s,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{y_text}</text>",
            LEFT - 4.0,
            py(y) + 4.0
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{x_label}</text>",
        LEFT + pw / 2.0,
        y0 + H - 8.0
    );
    let _ = writeln!(
        s,
        "<text transform=\"translate(14 {}) rotate(-90)\" text-anchor=\"middle\">{y_label}</text>",
        y0 + TOP + ph / 2.0
    );
    for (i, r) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let path: Vec<String> = r
            .points
            .iter()
            .filter_map(|&(x, y)| scaled(y, scale).map(|y| format!("{:.1},{:.1}", px(x), py(y))))
            .collect();
        let _ = writeln!(
            s,
            "<polyline fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.2\" points=\"{}\"/>",
            path.join(" ")
        );
        let ly = y0 + TOP + 16.0 * (i as f64 + 1.0);
        let _ = writeln!(
            s,
            "<line x1=\"{}\" y1=\"{ly}\" x2=\"{}\" y2=\"{ly}\" stroke=\"{colour}\" stroke-width=\"2\"/>\
             <text x=\"{}\" y=\"{}\">{}</text>",
            W - RIGHT + 10.0,
            W - RIGHT + 30.0,
            W - RIGHT + 35.0,
            ly + 4.0,
            r.name
        );
    }
}
