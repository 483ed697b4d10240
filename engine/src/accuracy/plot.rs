//! The error-against-time plot (PNG, plotters): log–log, one curve per
//! setting, each with its own pair of colour and dash pattern, the Pareto
//! front drawn under the curves as a thick grey line with black rings. The
//! legend stands beside the axes, not over them; with more than
//! [`LABEL_ALL_UP_TO`] curves it names only the scene as written and the
//! settings on the Pareto front (the others are in the CSV).

use super::Report;
use super::report::pareto_front;
use plotters::prelude::*;
use std::path::Path;

/// The printable ASCII glyphs of DejaVu Sans (licence beside the file).
static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans-subset.ttf");

/// Curve colours, cycled.
const COLOURS: [RGBColor; 14] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 128),
    RGBColor(128, 128, 0),
    RGBColor(0, 128, 128),
    RGBColor(128, 0, 0),
];

/// Dash patterns (dash, gap in pixels; `None`: solid), cycled alongside
/// the colours: their counts (14 and 3) have no common factor, so the
/// first 42 curves each get their own pair.
const DASHES: [Option<(u32, u32)>; 3] = [None, Some((10, 6)), Some((3, 4))];

/// Plot size in pixels: the axes, then the legend's column.
const SIZE: (u32, u32) = (1240, 640);

/// Width of the legend's column.
const LEGEND_WIDTH: u32 = 300;

/// Curves up to which every one is named in the legend.
pub const LABEL_ALL_UP_TO: usize = 8;

/// Colour and dash of curve `i`.
fn curve_style(i: usize) -> (RGBColor, Option<(u32, u32)>) {
    (COLOURS[i % COLOURS.len()], DASHES[i % DASHES.len()])
}

/// The curves the legend names: all of them when few, else the scene as
/// written and those with a point on the Pareto front.
pub fn labelled(report: &Report) -> Vec<usize> {
    let curves = &report.curves;
    if curves.len() <= LABEL_ALL_UP_TO {
        return (0..curves.len()).collect();
    }
    let front = pareto_front(curves);
    (0..curves.len())
        .filter(|&c| c == 0 || front.iter().any(|&(f, _)| f == c))
        .collect()
}

fn register_font() -> Result<(), String> {
    static DONE: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
            .map_err(|_| "the embedded plot font is not a valid font".to_string())
    })
    .clone()
}

/// Bounds of `values` widened by a margin on a log scale.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return 0.1..1.0;
    }
    let (lo, hi) = if hi / lo < 1.5 {
        (lo / 1.5, hi * 1.5)
    } else {
        (lo, hi)
    };
    lo / 1.15..hi * 1.15
}

/// Draws `report` into the PNG file `path`.
pub fn draw(report: &Report, path: &Path) -> Result<(), String> {
    register_font()?;
    let curves = &report.curves;
    let points = || curves.iter().flat_map(|c| c.points.iter());
    let x = log_range(points().map(|p| p.time));
    let y = log_range(points().map(|p| p.metrics.rmse));
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let (axes, legend) = root.split_horizontally(SIZE.0 - LEGEND_WIDTH);
    let name = report.scene.file_name().map_or_else(
        || report.scene.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let mut chart = ChartBuilder::on(&axes)
        .caption(format!("{name}: RMSE against time"), ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(46)
        .y_label_area_size(80)
        .build_cartesian_2d(x.log_scale(), y.log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("time (s): extract + render, log scale")
        .y_desc("RMSE against the reference, log scale")
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&|v| format!("{v:.2e}"))
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(e)?;

    let front: Vec<(f64, f64)> = pareto_front(curves)
        .into_iter()
        .map(|(c, p)| {
            let m = &curves[c].points[p];
            (m.time, m.metrics.rmse)
        })
        .collect();
    let grey = RGBColor(190, 190, 190);
    chart
        .draw_series(LineSeries::new(front.iter().copied(), grey.stroke_width(9)))
        .map_err(e)?;

    for (i, c) in curves.iter().enumerate() {
        let (colour, dash) = curve_style(i);
        // The scene as written, drawn first, stands out.
        let style = colour.stroke_width(if i == 0 { 4 } else { 2 });
        let data: Vec<(f64, f64)> = c.points.iter().map(|p| (p.time, p.metrics.rmse)).collect();
        match dash {
            None => chart
                .draw_series(LineSeries::new(data.iter().copied(), style))
                .map(drop),
            Some((size, gap)) => chart
                .draw_series(DashedLineSeries::new(
                    data.iter().copied(),
                    size,
                    gap,
                    style,
                ))
                .map(drop),
        }
        .map_err(e)?;
        chart
            .draw_series(data.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(e)?;
    }
    chart
        .draw_series(
            front
                .iter()
                .map(|&p| Circle::new(p, 6, BLACK.stroke_width(2))),
        )
        .map_err(e)?;
    draw_legend(&legend, report).map_err(e)?;
    root.present().map_err(e)
}

/// The legend's column: the Pareto front, then a line sample and the
/// label of each named curve, and how many are left unnamed.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    report: &Report,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = ("sans-serif", 14).into_font();
    let row = 20;
    let (x0, mut y) = (8, 48);
    let grey = RGBColor(190, 190, 190);
    area.draw(&PathElement::new(
        vec![(x0, y), (x0 + 30, y)],
        grey.stroke_width(9),
    ))?;
    area.draw(&Circle::new((x0 + 15, y), 6, BLACK.stroke_width(2)))?;
    area.draw(&Text::new("Pareto front", (x0 + 40, y - 7), font.clone()))?;
    let shown = labelled(report);
    for &i in &shown {
        y += row;
        let c = &report.curves[i];
        let (colour, dash) = curve_style(i);
        let style = colour.stroke_width(if i == 0 { 4 } else { 2 });
        let (size, gap) = dash.unwrap_or((30, 0));
        let mut x = x0;
        while x < x0 + 30 {
            let end = (x + size as i32).min(x0 + 30);
            area.draw(&PathElement::new(vec![(x, y), (end, y)], style))?;
            x = end + gap as i32;
        }
        let label = if c.is_biased() {
            format!("{} (biased)", c.setting.label())
        } else {
            c.setting.label()
        };
        area.draw(&Text::new(label, (x0 + 40, y - 7), font.clone()))?;
    }
    let hidden = report.curves.len() - shown.len();
    if hidden > 0 {
        y += row + 6;
        let note = format!("{hidden} more settings, off the front:");
        area.draw(&Text::new(note, (x0, y - 7), font.clone()))?;
        area.draw(&Text::new(
            "see accuracy.csv",
            (x0, y + row - 7),
            font.clone(),
        ))?;
    }
    Ok(())
}
