//! The error-against-time plot (PNG, plotters): log–log, one curve per
//! setting, dashed where the setting is biased, the Pareto front drawn
//! under the curves as a thick grey line with black rings.

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

/// Plot size in pixels.
const SIZE: (u32, u32) = (960, 640);

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
    let name = report.scene.file_name().map_or_else(
        || report.scene.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let mut chart = ChartBuilder::on(&root)
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
        .map_err(e)?
        .label("Pareto front")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(9)));

    for (i, c) in curves.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        // The scene as written, drawn first, stands out.
        let style = colour.stroke_width(if i == 0 { 4 } else { 2 });
        let data: Vec<(f64, f64)> = c.points.iter().map(|p| (p.time, p.metrics.rmse)).collect();
        let biased = c.is_biased();
        let label = if biased {
            format!("{} (biased)", c.setting.label())
        } else {
            c.setting.label()
        };
        let legend = move |(x, y): (i32, i32)| PathElement::new(vec![(x, y), (x + 24, y)], style);
        if biased {
            chart
                .draw_series(DashedLineSeries::new(data.iter().copied(), 8, 5, style))
                .map_err(e)?
                .label(label)
                .legend(legend);
        } else {
            chart
                .draw_series(LineSeries::new(data.iter().copied(), style))
                .map_err(e)?
                .label(label)
                .legend(legend);
        }
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
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)
}
