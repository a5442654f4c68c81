//! GPU time against error on log scales (`kage sweep`'s `pareto.png`, `kage bench asm`'s
//! `error-time.png`), one series per technique, the Pareto
//! front drawn through the settings nothing beats.
pub mod pick;

use anyhow::{anyhow, Context as _, Result};
use kage::files;
use pick::{pareto_front, Point};
use plotters::coord::combinators::BindKeyPoints;
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

/// The chart's text face: DejaVu Sans from Debian's fonts-dejavu-core, or `$KAGE_CHART_FONT`.
const DEFAULT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
pub(crate) const SIZE: (u32, u32) = (960, 640);
/// DejaVu Sans is 0.7 MiB; the largest fonts (CJK collections) some 30.
const FONT: files::Limit = files::Limit { kind: "a font", bytes: 64 << 20 };

/// Registers the font once per process (plotters keeps fonts for the program's life).
pub(crate) fn font() -> Result<()> {
    static REGISTERED: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            let path = std::env::var("KAGE_CHART_FONT").unwrap_or_else(|_| DEFAULT_FONT.to_string());
            let bytes = files::read(Path::new(&path), FONT).map_err(|e| {
                format!("reading the chart font {path}: {e} (install fonts-dejavu-core, as scripts/deps.sh does, or set KAGE_CHART_FONT to a .ttf file)")
            })?;
            plotters::style::register_font("sans-serif", FontStyle::Normal, Box::leak(bytes.into_boxed_slice()))
                .map_err(|_| format!("{path} is not a TrueType font"))
        })
        .clone()
        .map_err(|e| anyhow!(e))
}

/// What the chart's axes measure: the points' cost (`Point::ms`) and error.
pub struct Axes<'a> {
    pub cost: &'a str,
    pub error: &'a str,
}

/// The axes of a frame-time sweep, with `error` on y.
pub fn frame_time_against(error: &str) -> Axes<'_> {
    Axes { cost: "GPU ms per frame (median)", error }
}

/// Draws `points` (all with a cost and an error above 0) to the PNG at `path`.
pub fn write(path: &Path, title: &str, axes: &Axes, points: &[Point]) -> Result<()> {
    font()?;
    let range = |values: Vec<f64>| {
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(0.0, f64::max);
        (lo / 1.5)..(hi * 1.5)
    };
    let xs = range(points.iter().map(|p| p.ms).collect());
    let ys = range(points.iter().map(|p| p.error).collect());
    let mut pixels = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    draw(&mut pixels, title, axes, points, xs, ys).map_err(|e| anyhow!("drawing {}: {e}", path.display()))?;
    image::RgbImage::from_raw(SIZE.0, SIZE.1, pixels)
        .expect("the buffer holds SIZE.0 × SIZE.1 RGB pixels")
        .save(path)
        .with_context(|| format!("writing {}", path.display()))
}

fn draw(
    pixels: &mut [u8],
    title: &str,
    axes: &Axes,
    points: &[Point],
    xs: std::ops::Range<f64>,
    ys: std::ops::Range<f64>,
) -> std::result::Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::with_buffer(pixels, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            xs.clone().log_scale().with_key_points(ticks(&xs)),
            ys.clone().log_scale().with_key_points(ticks(&ys)),
        )?;
    chart
        .configure_mesh()
        .x_desc(axes.cost)
        .y_desc(axes.error)
        .x_label_formatter(&tick_label)
        .y_label_formatter(&tick_label)
        .label_style(("sans-serif", 14))
        .draw()?;
    let front: Vec<(f64, f64)> =
        pareto_front(points).iter().map(|&i| (points[i].ms, points[i].error)).collect();
    chart
        .draw_series(LineSeries::new(front, BLACK.stroke_width(2)))?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(2)));
    // One series per name, in order of first appearance (rows of several series interleave).
    let mut names: Vec<&str> = Vec::new();
    for p in points {
        if !names.contains(&p.series.as_str()) {
            names.push(&p.series);
        }
    }
    for (i, name) in names.into_iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        let series = points.iter().filter(|p| p.series == name);
        chart
            .draw_series(series.map(|p| {
                EmptyElement::at((p.ms, p.error))
                    + Circle::new((0, 0), 6, colour.filled())
                    + Text::new(p.label.clone(), (8, -16), ("sans-serif", 14))
            }))?
            .label(name)
            .legend(move |(x, y)| Circle::new((x + 10, y), 6, colour.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

/// A tick's value as written: the ticks are one digit times a power of ten, so one significant
/// digit is exact (and hides the float's rounding: 0.009, not 0.009000000000001).
pub(crate) fn tick_label(value: &f64) -> String {
    let exponent = (value.log10() + 1e-9).floor() as i32;
    format!("{value:.*}", (-exponent).max(0) as usize)
}

/// Labelled values of a log axis: 1, 2 and 5 times the powers of ten within `range`, and every
/// digit's where fewer than four of those fall inside (a narrow range).
pub(crate) fn ticks(range: &std::ops::Range<f64>) -> Vec<f64> {
    let within = |mantissas: &[f64]| -> Vec<f64> {
        let (lo, hi) = (range.start.log10().floor() as i32, range.end.log10().ceil() as i32);
        (lo..=hi)
            .flat_map(|e| mantissas.iter().map(move |m| m * 10f64.powi(e)))
            .filter(|v| range.contains(v))
            .collect()
    };
    let coarse = within(&[1.0, 2.0, 5.0]);
    if coarse.len() >= 4 {
        coarse
    } else {
        within(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    }
}
