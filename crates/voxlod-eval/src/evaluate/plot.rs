//! The error-against-triangles chart of an evaluation, as PNG bytes: log–log panels side by
//! side, the two-sided Hausdorff distance and the mean distance (percent of the input's
//! diagonal) and, when measured, the silhouette difference (percent of covered pixels) against
//! the triangle count, one curve per method, drawn with plotters into an RGB
//! buffer and encoded with the image crate (so the caller can write the file atomically).
//!
//! Text needs a TrueType font, which plotters' ab_glyph backend cannot find by itself: the first
//! chart of a process looks for one ([`chart_font`]: `$VOXLOD_FONT`, then DejaVu Sans, Liberation
//! Sans or Arial where Linux, macOS and Windows keep them), reads it once and registers it. With
//! no font (or `VOXLOD_FONT=none`) the chart is drawn without any text, and [`Chart::labelled`]
//! says so: the method of each colour is then only in the report's legend ([`method_colour`]).
//!
//! Cost: drawing and PNG encoding of a 1400 × 600 or 2100 × 600 image, tens of milliseconds.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use image::ImageEncoder;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

use super::results::Evaluation;
use crate::methods::Method;

/// Width of one panel in pixels: the chart is as many panels wide as it has.
pub const PANEL_WIDTH: u32 = 700;
/// Height of the chart in pixels.
pub const HEIGHT: u32 = 600;

/// A drawn chart.
#[derive(Clone, Debug)]
pub struct Chart {
    /// The chart, PNG-encoded.
    pub png: Vec<u8>,
    /// Whether text (titles, axes, legend) is drawn; false when no font was found.
    pub labelled: bool,
    /// The font file used, if any.
    pub font: Option<PathBuf>,
}

/// Why a chart could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// plotters failed to draw.
    #[error("cannot draw the chart: {0}")]
    Draw(String),
    /// The image could not be encoded.
    #[error("cannot encode the chart as PNG: {0}")]
    Encode(String),
    /// There is nothing to draw.
    #[error("no method has a measured level to plot")]
    Empty,
}

/// The colours of the curves, by the method's place in [`Method::ALL`] (the first ten of
/// matplotlib's "tab10" palette, reordered so the voxel pipeline is red).
const PALETTE: [(u8, u8, u8); 10] = [
    (214, 39, 40),
    (255, 127, 14),
    (31, 119, 180),
    (44, 160, 44),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (188, 189, 34),
    (23, 190, 207),
    (127, 127, 127),
];

/// The colour of a method's curve, as `#rrggbb` for the report's legend: by its place in
/// [`Method::ALL`], black for the scene proxy ([`super::PROXY`]), grey for a method of the
/// caller's own.
pub fn method_colour(method: Method) -> (u8, u8, u8) {
    if method == super::PROXY {
        return (0, 0, 0);
    }
    method
        .index()
        .map_or(PALETTE[9], |i| PALETTE[i % (PALETTE.len() - 1)])
}

/// Font files tried, in order, after `$VOXLOD_FONT`.
const FONT_CANDIDATES: [&str; 8] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

const FAMILY: &str = "sans-serif";

/// The font registered for charts, found and loaded on first use (see the module
/// documentation); `None` when there is none.
pub fn chart_font() -> Option<&'static Path> {
    static FONT: OnceLock<Option<PathBuf>> = OnceLock::new();
    FONT.get_or_init(|| {
        let candidates: Vec<PathBuf> = match std::env::var_os("VOXLOD_FONT") {
            Some(v) if v == "none" => return None,
            Some(v) => vec![PathBuf::from(v)],
            None => FONT_CANDIDATES.iter().map(PathBuf::from).collect(),
        };
        candidates.into_iter().find_map(|path| {
            let bytes = std::fs::read(&path).ok()?;
            // plotters keeps fonts for the life of the process; this is read once.
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            plotters::style::register_font(FAMILY, FontStyle::Normal, bytes)
                .ok()
                .map(|_| path)
        })
    })
    .as_deref()
}

/// (triangles, Hausdorff %, mean %, silhouette difference % or NaN) of one level.
type Point = (f64, f64, f64, f64);

/// One curve: a method's points, in triangle order.
struct Series {
    method: Method,
    points: Vec<Point>,
}

/// What a panel plots against the triangle count.
struct Panel {
    label: &'static str,
    value: fn(&Point) -> f64,
}

/// Draws the chart of `evaluation`, titled `title` (the input's name).
pub fn plot_evaluation(evaluation: &Evaluation, title: &str) -> Result<Chart, PlotError> {
    let series: Vec<Series> = evaluation
        .curves
        .iter()
        .filter(|c| !c.points.is_empty())
        .map(|c| {
            let mut points: Vec<Point> = c
                .points
                .iter()
                .map(|p| {
                    (
                        p.triangles as f64,
                        100.0 * p.hausdorff_fraction,
                        100.0 * p.mean_fraction,
                        p.image_difference.map_or(f64::NAN, |d| 100.0 * d.fraction),
                    )
                })
                .collect();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            Series {
                method: c.method,
                points,
            }
        })
        .collect();
    if series.is_empty() {
        return Err(PlotError::Empty);
    }
    let mut panels = vec![
        Panel {
            label: "Hausdorff distance, % of the diagonal",
            value: |p| p.1,
        },
        Panel {
            label: "mean distance, % of the diagonal",
            value: |p| p.2,
        },
    ];
    if series.iter().any(|s| s.points.iter().any(|p| p.3 > 0.0)) {
        panels.push(Panel {
            label: "silhouette difference, % of covered pixels",
            value: |p| p.3,
        });
    }
    let font = chart_font();
    let labelled = font.is_some();
    let width = PANEL_WIDTH * panels.len() as u32;
    let mut rgb = vec![255u8; (width * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, HEIGHT)).into_drawing_area();
        draw(&root, &series, &panels, title, evaluation, labelled).map_err(PlotError::Draw)?;
        root.present().map_err(|e| PlotError::Draw(e.to_string()))?;
    }
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(&rgb, width, HEIGHT, image::ExtendedColorType::Rgb8)
        .map_err(|e| PlotError::Encode(e.to_string()))?;
    Ok(Chart {
        png,
        labelled,
        font: font.map(Path::to_path_buf),
    })
}

/// A log axis range covering `values` with a margin, in whole decades where that is close.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| *v > 0.0 && v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 0.1..1.0;
    }
    if hi <= lo {
        hi = lo * 10.0;
    }
    (lo / 1.5)..(hi * 1.5)
}

fn draw(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    series: &[Series],
    panels: &[Panel],
    title: &str,
    evaluation: &Evaluation,
    labelled: bool,
) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let body = if labelled {
        root.titled(
            &format!(
                "{title} ({} triangles): two-sided distance to the input, {} samples per side{}",
                evaluation.input.triangles,
                evaluation.samples_per_side,
                if evaluation.image_views > 0 {
                    format!("; silhouettes over {} views", evaluation.image_views)
                } else {
                    String::new()
                }
            ),
            (FAMILY, 22),
        )
        .map_err(|e| err(&e))?
    } else {
        root.clone()
    };
    let areas = body.split_evenly((1, panels.len()));
    let x_range = log_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    for (area, panel) in areas.iter().zip(panels) {
        let y_range = log_range(series.iter().flat_map(|s| s.points.iter().map(panel.value)));
        draw_panel(area, series, x_range.clone(), y_range, panel, labelled)?;
    }
    Ok(())
}

fn draw_panel(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    series: &[Series],
    x_range: std::ops::Range<f64>,
    y_range: std::ops::Range<f64>,
    panel: &Panel,
    labelled: bool,
) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let label_area = if labelled { 60 } else { 0 };
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .x_label_area_size(label_area)
        .y_label_area_size(label_area + 10)
        .build_cartesian_2d(x_range.clone().log_scale(), y_range.clone().log_scale())
        .map_err(|e| err(&e))?;
    if labelled {
        chart
            .configure_mesh()
            .x_desc("triangles")
            .y_desc(panel.label)
            .axis_desc_style((FAMILY, 16))
            .label_style((FAMILY, 14))
            .x_label_formatter(&|v| compact_count(*v))
            .y_label_formatter(&|v| compact_percent(*v))
            .draw()
            .map_err(|e| err(&e))?;
    } else {
        // plotters' mesh needs a font even without labels: draw the frame and the decade lines
        // by hand.
        let grey = RGBColor(200, 200, 200);
        let (x0, x1, y0, y1) = (x_range.start, x_range.end, y_range.start, y_range.end);
        let decades = |lo: f64, hi: f64| {
            let first = lo.log10().ceil() as i32;
            let last = hi.log10().floor() as i32;
            (first..=last).map(|k| 10f64.powi(k)).collect::<Vec<_>>()
        };
        let mut lines: Vec<Vec<(f64, f64)>> = decades(x0, x1)
            .into_iter()
            .map(|x| vec![(x, y0), (x, y1)])
            .collect();
        lines.extend(decades(y0, y1).into_iter().map(|y| vec![(x0, y), (x1, y)]));
        chart
            .draw_series(lines.into_iter().map(|l| PathElement::new(l, grey)))
            .map_err(|e| err(&e))?;
        let frame = vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)];
        chart
            .draw_series(std::iter::once(PathElement::new(frame, BLACK)))
            .map_err(|e| err(&e))?;
    }
    for (k, s) in series.iter().enumerate() {
        let (r, g, b) = method_colour(s.method);
        let colour = RGBColor(r, g, b);
        let line: Vec<(f64, f64)> = s
            .points
            .iter()
            .map(|p| (p.0, (panel.value)(p)))
            .filter(|&(_, v)| v > 0.0 && v.is_finite())
            .collect();
        let drawn = chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(|e| err(&e))?;
        if labelled {
            drawn.label(s.method.name()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
            });
        }
        let style = colour.filled();
        // A different marker per method, so the curves stay apart in grey.
        let markers = line.iter().map(|&p| {
            let at = EmptyElement::at(p);
            match k % 4 {
                0 => at + Circle::new((0, 0), 4, style).into_dyn(),
                1 => at + TriangleMarker::new((0, 0), 5, style).into_dyn(),
                2 => at + Cross::new((0, 0), 4, colour.stroke_width(2)).into_dyn(),
                _ => at + Rectangle::new([(-4, -4), (4, 4)], style).into_dyn(),
            }
        });
        chart.draw_series(markers).map_err(|e| err(&e))?;
    }
    if labelled {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FAMILY, 16))
            .draw()
            .map_err(|e| err(&e))?;
    }
    Ok(())
}

/// `1200` as `1.2k`, `3000000` as `3M`.
fn compact_count(v: f64) -> String {
    if v >= 1e6 {
        format!("{}M", trim(v / 1e6))
    } else if v >= 1e3 {
        format!("{}k", trim(v / 1e3))
    } else {
        trim(v)
    }
}

fn compact_percent(v: f64) -> String {
    if v >= 1.0 {
        format!("{}%", trim(v))
    } else {
        format!("{}%", format!("{v:.3}").trim_end_matches('0'))
    }
}

fn trim(v: f64) -> String {
    let s = format!("{v:.1}");
    s.strip_suffix(".0").map(str::to_string).unwrap_or(s)
}
