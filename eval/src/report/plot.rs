//! The plot of one stage: error against seconds (log scale), one panel per metric, one
//! point per setting labelled with its value, the Pareto front drawn through its points,
//! the default setting ringed, peers' points in their own colour. Drawn with `plotters`
//! as SVG (text left to the viewer's fonts) and as PNG (text rasterised with a system
//! font found at run time; without one, no PNG is drawn and the caller is told).

use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{Better, PeerPoint, Report, Row, pareto_front};
use crate::{EvalError, Result};

/// Pixels per panel.
const PANEL: (u32, u32) = (560, 400);

/// Fonts tried for the PNG's text, in order.
const FONT_FILES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

/// Registers a system font for the text of the plots, once; `false` when none exists.
pub fn fonts_available() -> bool {
    static FOUND: OnceLock<bool> = OnceLock::new();
    *FOUND.get_or_init(|| {
        FONT_FILES.iter().any(|path| {
            let Ok(bytes) = std::fs::read(path) else {
                return false;
            };
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok()
        })
    })
}

pub(crate) fn plot_error(e: impl std::fmt::Display) -> EvalError {
    EvalError::Plot(e.to_string())
}

/// Panels laid out side by side, at most three per row.
fn layout(metrics: usize) -> (usize, usize) {
    let columns = metrics.clamp(1, 3);
    (columns, metrics.div_ceil(columns).max(1))
}

/// The size of a stage's plot, pixels.
pub fn size(report: &Report, stage: &str) -> (u32, u32) {
    let (c, r) = layout(report.metrics(stage).len());
    (PANEL.0 * c as u32, PANEL.1 * r as u32)
}

/// A stage's plot as SVG text.
pub fn svg(report: &Report, stage: &str) -> Result<String> {
    svg_of(size(report, stage), |root| draw(root, report, stage))
}

/// A stage's plot as PNG bytes, or `None` without a font for its text.
pub fn png(report: &Report, stage: &str) -> Result<Option<Vec<u8>>> {
    png_of(size(report, stage), |root| draw(root, report, stage))
}

/// What `draw` draws on a `size` canvas, as SVG text (fonts left to the viewer).
pub(crate) fn svg_of(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend, Shift>) -> Result<()>,
) -> Result<String> {
    fonts_available();
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, size).into_drawing_area();
        draw(&root)?;
        root.present().map_err(plot_error)?;
    }
    Ok(out)
}

/// What `draw` draws on a `size` canvas, as PNG bytes; `None` without a system font
/// for its text.
pub(crate) fn png_of(
    (w, h): (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend, Shift>) -> Result<()>,
) -> Result<Option<Vec<u8>>> {
    if !fonts_available() {
        return Ok(None);
    }
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        draw(&root)?;
        root.present().map_err(plot_error)?;
    }
    let img = image::RgbImage::from_raw(w, h, rgb)
        .ok_or_else(|| plot_error("the bitmap has the wrong size"))?;
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(plot_error)?;
    Ok(Some(bytes))
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    report: &Report,
    stage: &str,
) -> Result<()> {
    root.fill(&WHITE).map_err(plot_error)?;
    let metrics = report.metrics(stage);
    let (columns, rows) = layout(metrics.len());
    let panels = root.split_evenly((rows, columns));
    for (panel, metric) in panels.iter().zip(&metrics) {
        let series = report.series(stage, metric);
        let peers: Vec<&PeerPoint> = report
            .peers
            .iter()
            .filter(|p| p.stage == stage && p.metric == *metric)
            .collect();
        draw_panel(panel, stage, metric, &series, &peers)?;
    }
    Ok(())
}

/// Axis ranges with a margin: seconds on a log scale, errors linear.
fn ranges(series: &[&Row], peers: &[&PeerPoint]) -> ((f64, f64), (f64, f64)) {
    let points = series
        .iter()
        .map(|r| (r.seconds, r.error))
        .chain(peers.iter().map(|p| (p.seconds, p.error)));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in points {
        x0 = x0.min(x.max(1e-6));
        x1 = x1.max(x.max(1e-6));
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        return ((-3.0, 0.0), (0.0, 1.0));
    }
    let pad = ((y1 - y0) * 0.12).max(y1.abs() * 0.02).max(1e-3);
    // Seconds are drawn as their base-10 logarithm on a linear axis (ticks at any range).
    ((x0.log10() - 0.2, x1.log10() + 0.2), (y0 - pad, y1 + pad))
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    stage: &str,
    metric: &str,
    series: &[&Row],
    peers: &[&PeerPoint],
) -> Result<()> {
    let ((x0, x1), (y0, y1)) = ranges(series, peers);
    // Labels of points in the right third of the panel go to their left (about 6 px per
    // character at this size), so that they stay inside it.
    let label_dx = |text: &str, seconds: f64| {
        if lg(seconds) > x0 + 0.66 * (x1 - x0) {
            -8 - 6 * text.chars().count() as i32
        } else {
            6
        }
    };
    let timed = series.first().map_or("", |r| r.timed.as_str());
    let mut chart = ChartBuilder::on(area)
        .caption(format!("{stage}: {metric}"), ("sans-serif", 17))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc(format!("seconds ({timed}, log scale)"))
        .y_desc(metric)
        .x_labels(8)
        .x_label_formatter(&|x| seconds_label(10f64.powf(*x)))
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(plot_error)?;
    let front: Vec<(f64, f64)> = pareto_front(series)
        .into_iter()
        .map(|i| (lg(series[i].seconds), series[i].error))
        .collect();
    let accent = RGBColor(200, 60, 40);
    chart
        .draw_series(LineSeries::new(front, accent.stroke_width(2)))
        .map_err(plot_error)?
        .label("Pareto front")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], accent.stroke_width(2)));
    let ours = RGBColor(30, 90, 170);
    chart
        .draw_series(series.iter().enumerate().map(|(i, r)| {
            // Neighbouring settings' labels alternate above and below their points.
            let dy = if i % 2 == 0 { -14 } else { 4 };
            EmptyElement::at((lg(r.seconds), r.error))
                + Circle::new((0, 0), 4, ours.filled())
                + Text::new(
                    r.value.clone(),
                    (label_dx(&r.value, r.seconds), dy),
                    ("sans-serif", 11),
                )
        }))
        .map_err(plot_error)?
        .label("settings")
        .legend(move |(x, y)| Circle::new((x + 8, y), 4, ours.filled()));
    chart
        .draw_series(
            series
                .iter()
                .filter(|r| r.default)
                .map(|r| Circle::new((lg(r.seconds), r.error), 9, accent.stroke_width(2))),
        )
        .map_err(plot_error)?
        .label("default")
        .legend(move |(x, y)| Circle::new((x + 8, y), 6, accent.stroke_width(2)));
    if !peers.is_empty() {
        let peer = RGBColor(40, 150, 70);
        chart
            .draw_series(peers.iter().map(|p| {
                EmptyElement::at((lg(p.seconds), p.error))
                    + TriangleMarker::new((0, 0), 6, peer.filled())
                    + Text::new(
                        p.method.clone(),
                        (label_dx(&p.method, p.seconds), 4),
                        ("sans-serif", 11),
                    )
            }))
            .map_err(plot_error)?
            .label("peers")
            .legend(move |(x, y)| TriangleMarker::new((x + 8, y), 5, peer.filled()));
    }
    // The legend goes in the corner settings leave empty: slow and poor (upper right for
    // errors, lower right for scores).
    let corner = match Better::of(metric) {
        Better::Higher => SeriesLabelPosition::LowerRight,
        Better::Lower => SeriesLabelPosition::UpperRight,
    };
    chart
        .configure_series_labels()
        .position(corner)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .label_font(("sans-serif", 11))
        .draw()
        .map_err(plot_error)?;
    Ok(())
}

/// Where a time sits on the x axis: its base-10 logarithm (times below a microsecond are
/// drawn at one).
fn lg(seconds: f64) -> f64 {
    seconds.max(1e-6).log10()
}

/// A tick's time with the digits it needs.
fn seconds_label(s: f64) -> String {
    if s >= 10.0 {
        format!("{s:.0}")
    } else if s >= 0.1 {
        format!("{s:.2}")
    } else {
        format!("{s:.1e}")
    }
}
/// Whether `--plot PATH` asks for a PNG (`Some(true)`) or an SVG (`Some(false)`);
/// `None` without `--plot`; any other extension is refused.
pub fn plot_format(plot: Option<&std::path::Path>) -> Result<Option<bool>> {
    let Some(p) = plot else {
        return Ok(None);
    };
    match p.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("svg") => Ok(Some(false)),
        Some(e) if e.eq_ignore_ascii_case("png") => Ok(Some(true)),
        _ => {
            let allowed = "a .svg or .png file";
            Err(frf_core::BadArgument::new("--plot", p.display(), allowed).into())
        }
    }
}

/// Writes a budget's plot to `path` (PNG or SVG, atomically) and its Markdown table
/// beside it (`.md`).
pub fn write_plot(
    path: &std::path::Path,
    png: bool,
    draw_png: &dyn Fn() -> Result<Option<Vec<u8>>>,
    draw_svg: &dyn Fn() -> Result<String>,
    markdown: &str,
) -> Result<()> {
    use frf_core::atomic::write_bytes_atomic;
    let bytes = if png {
        draw_png()?.ok_or_else(|| {
            EvalError::Plot("no system font for the plot's text: draw it as .svg".into())
        })?
    } else {
        draw_svg()?.into_bytes()
    };
    write_bytes_atomic(path, &bytes)?;
    write_bytes_atomic(&path.with_extension("md"), markdown.as_bytes())?;
    Ok(())
}
