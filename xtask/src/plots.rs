//! The demo's figures: panels of lines against one x axis, drawn by `lagrange-plot` and written
//! under `target/lagrange-demo/`.

use crate::cmd::project_root;
use lagrange_plot::{Panel, Scale, Series};

/// Width of a figure, pixels.
const WIDTH: u32 = 820;
/// Height of each of its panels, pixels.
const PANEL_HEIGHT: u32 = 360;

/// Writes `target/lagrange-demo/<name>`: one panel per `(title, y label, y scale, series)`,
/// stacked, each over a linear x axis labelled `x_label`; prints where.
pub fn write(
    name: &str,
    x_label: &str,
    panels: &[(&str, &str, Scale, &[Series])],
) -> Result<(), String> {
    let panels: Vec<Panel<'_>> = panels
        .iter()
        .map(|&(title, y_label, scale, series)| {
            Panel::new(title, series)
                .x_axis(x_label, Scale::Linear)
                .y_axis(y_label, scale)
        })
        .collect();
    let doc = lagrange_plot::svg(&panels, WIDTH, PANEL_HEIGHT).map_err(|e| e.to_string())?;
    let dir = project_root().join("target").join("lagrange-demo");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let path = dir.join(name);
    std::fs::write(&path, doc).map_err(|e| e.to_string())?;
    println!("Plot: {}", path.display());
    Ok(())
}
