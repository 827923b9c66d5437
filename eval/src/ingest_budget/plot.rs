//! The ingest budget's plot: for each component taken from the truth, the dB it gains
//! over the field as ingested (left) and its share of the squared error (right), one bar
//! at the captured views and one at quad centres. SVG always; PNG where a system font
//! exists for its text (as the other plots, [`crate::report::plot`]).

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{Component, IngestBudgetReport, PlaceScore};
use crate::report::plot::{plot_error, png_of, svg_of};
use crate::{EvalError, Result};

/// Pixels per panel.
const PANEL: (u32, u32) = (460, 380);

fn size() -> (u32, u32) {
    (2 * PANEL.0, PANEL.1)
}

/// The plot as SVG text.
pub fn svg(report: &IngestBudgetReport) -> Result<String> {
    svg_of(size(), |root| draw(root, report))
}

/// The plot as PNG bytes, or `None` without a font for its text.
pub fn png(report: &IngestBudgetReport) -> Result<Option<Vec<u8>>> {
    png_of(size(), |root| draw(root, report))
}

type Measure = fn(&PlaceScore) -> f64;

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    report: &IngestBudgetReport,
) -> Result<()> {
    root.fill(&WHITE).map_err(plot_error)?;
    let rows: Vec<_> = report
        .rows
        .iter()
        .filter(|r| r.component != Component::Ingested)
        .collect();
    if rows.is_empty() {
        return Err(EvalError::Plot("the budget has no component".into()));
    }
    let names: Vec<&str> = rows.iter().map(|r| r.component.name()).collect();
    let panels = root.split_evenly((1, 2));
    let measures: [(&str, Measure); 2] = [
        ("PSNR gained over the ingested field (dB)", |p| p.gain_db),
        ("share of the ingested field's squared error (%)", |p| {
            100.0 * p.share_of_squared_error
        }),
    ];
    for (panel, (label, measure)) in panels.iter().zip(measures) {
        let values: Vec<[f64; 2]> = rows
            .iter()
            .map(|r| [measure(&r.captured), measure(&r.quad_centres)])
            .collect();
        let finite = values.iter().flatten().copied().filter(|v| v.is_finite());
        let lo = finite.clone().fold(0.0, f64::min);
        let hi = finite.fold(0.0, f64::max);
        let pad = 0.05 * (hi - lo).max(1e-3);
        let n = rows.len();
        let mut chart = ChartBuilder::on(panel)
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(120)
            .build_cartesian_2d(lo - pad..hi + pad, 0.0..n as f64)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .x_desc(label)
            .y_labels(n)
            .y_label_formatter(&|y| {
                let i = n as f64 - 1.0 - y.floor();
                names
                    .get(i.max(0.0) as usize)
                    .filter(|_| (y.fract() - 0.5).abs() < 0.26)
                    .map_or(String::new(), |s| s.to_string())
            })
            .draw()
            .map_err(plot_error)?;
        let places = [("captured views", BLUE), ("quad centres", RED)];
        for (k, (place, colour)) in places.into_iter().enumerate() {
            let bars = values.iter().enumerate().filter_map(move |(i, v)| {
                let top = (n - 1 - i) as f64 + 0.5 + if k == 0 { 0.35 } else { 0.0 };
                v[k].is_finite().then(|| {
                    Rectangle::new([(0.0, top - 0.35), (v[k], top)], colour.mix(0.7).filled())
                })
            });
            chart
                .draw_series(bars)
                .map_err(plot_error)?
                .label(place)
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 12, y + 5)], colour.filled())
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .label_font(("sans-serif", 12))
            .draw()
            .map_err(plot_error)?;
    }
    Ok(())
}
