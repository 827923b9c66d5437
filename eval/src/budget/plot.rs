//! The budget's plot: subject PSNR against the fraction of the way to the next view, one
//! panel per direction (along a row, along a column, toward the quad's centre), one line
//! per method, every line starting from the captured views at 0. SVG always; PNG where a
//! system font exists for its text (as the report's plots, [`crate::report::plot`]).

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{BudgetRow, Direction};
use crate::report::plot::{plot_error, png_of, svg_of};
use crate::{EvalError, Result};

/// Pixels per panel.
const PANEL: (u32, u32) = (420, 360);
/// Directions drawn, one panel each.
const PANELS: [Direction; 3] = [Direction::Row, Direction::Column, Direction::Centre];

fn size() -> (u32, u32) {
    (PANEL.0 * PANELS.len() as u32, PANEL.1)
}

/// The plot as SVG text.
pub fn svg(rows: &[BudgetRow]) -> Result<String> {
    svg_of(size(), |root| draw(root, rows))
}

/// The plot as PNG bytes, or `None` without a font for its text.
pub fn png(rows: &[BudgetRow]) -> Result<Option<Vec<u8>>> {
    png_of(size(), |root| draw(root, rows))
}

/// Per method, its points `(fraction, PSNR)` along `direction`, the captured views first.
fn series(rows: &[BudgetRow], direction: Direction) -> Vec<(String, Vec<(f64, f64)>)> {
    let Some(captured) = rows.iter().find(|r| r.direction == Direction::Captured) else {
        return Vec::new();
    };
    captured
        .methods
        .iter()
        .map(|m| {
            let mut points = vec![(0.0, m.psnr_subject)];
            for r in rows.iter().filter(|r| r.direction == direction) {
                if let Some(s) = r.method(&m.name) {
                    points.push((r.beta.max(r.gamma) as f64, s.psnr_subject));
                }
            }
            (m.name.clone(), points)
        })
        .collect()
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, rows: &[BudgetRow]) -> Result<()> {
    root.fill(&WHITE).map_err(plot_error)?;
    let all: Vec<f64> = rows
        .iter()
        .flat_map(|r| r.methods.iter().map(|m| m.psnr_subject))
        .filter(|v| v.is_finite())
        .collect();
    if all.is_empty() {
        return Err(EvalError::Plot("the budget has no finite score".into()));
    }
    let lo = all.iter().copied().fold(f64::INFINITY, f64::min).floor() - 1.0;
    let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max).ceil() + 1.0;
    let panels = root.split_evenly((1, PANELS.len()));
    for (panel, &direction) in panels.iter().zip(&PANELS) {
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("along a {}", direction.name())
                    .replace("a centre", "diagonal, to the quad centre"),
                ("sans-serif", 18),
            )
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(48)
            .build_cartesian_2d(0.0..0.8, lo..hi)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("fraction of the way to the next view")
            .y_desc("subject PSNR (dB)")
            .draw()
            .map_err(plot_error)?;
        for (i, (name, points)) in series(rows, direction).into_iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?
                .label(name)
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(plot_error)?;
        }
        if direction == Direction::Row {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::LowerLeft)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.mix(0.3))
                .label_font(("sans-serif", 12))
                .draw()
                .map_err(plot_error)?;
        }
    }
    Ok(())
}
