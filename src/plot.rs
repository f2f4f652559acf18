//! PNG plots of the reports (plotters, drawing into a buffer that the `image` crate writes):
//! frame rate along the camera path, time against error with the Pareto front, and the lens
//! validation's error against field angle.
//!
//! Text needs a TrueType font, read at run time: `$FISHEYE_FONT`, else DejaVu Sans or Liberation
//! Sans where Linux distributions put them (Debian: `fonts-dejavu-core`), else Arial on
//! macOS and Windows. Without one the plots are skipped with a warning; the numbers are in
//! the reports' JSON and Markdown either way.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::prelude::*;

use crate::error::{Error, Result};

const WIDTH: u32 = 1100;
const HEIGHT: u32 = 700;
const FAMILY: &str = "sans-serif";

/// Where fonts usually are; the first that exists is used.
const FONT_CANDIDATES: [&str; 6] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// The font plots use, loaded and registered once; `Err` says why there is none.
pub fn font() -> std::result::Result<&'static Path, String> {
    static FONT: OnceLock<std::result::Result<PathBuf, String>> = OnceLock::new();
    FONT.get_or_init(|| {
        let wanted = std::env::var_os("FISHEYE_FONT").map(PathBuf::from);
        let path = match &wanted {
            Some(p) => p.clone(),
            None => FONT_CANDIDATES
                .iter()
                .map(PathBuf::from)
                .find(|p| p.is_file())
                .ok_or_else(|| {
                    "no TrueType font found for the plots' text: set FISHEYE_FONT to a .ttf \
                     file, or install one (Debian: apt-get install fonts-dejavu-core)"
                        .to_string()
                })?,
        };
        let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        // plotters keeps fonts for the life of the process.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        plotters::style::register_font(FAMILY, FontStyle::Normal, bytes)
            .map_err(|_| format!("{}: not a TrueType or OpenType font", path.display()))?;
        Ok(path)
    })
    .as_ref()
    .map(PathBuf::as_path)
    .map_err(Clone::clone)
}

/// Draws `WIDTH × HEIGHT` pixels with `draw` and writes them to `path` as PNG.
fn write_png(
    path: &Path,
    draw: impl FnOnce(
        &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
    ) -> std::result::Result<(), Box<dyn std::error::Error>>,
) -> Result<()> {
    font().map_err(|message| Error::Plot {
        path: path.to_path_buf(),
        message,
    })?;
    let mut rgb = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE)
            .map_err(Into::into)
            .and_then(|()| draw(&root))
            .and_then(|()| root.present().map_err(Into::into))
            .map_err(|e| Error::Plot {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
    }
    let image = image::RgbImage::from_raw(WIDTH, HEIGHT, rgb).expect("a full buffer");
    crate::trace::write_atomically(path, |temporary| {
        image
            .save_with_format(temporary, image::ImageFormat::Png)
            .map_err(|reason| Error::Image {
                path: path.to_path_buf(),
                reason,
            })
    })
}

/// A named line of `(x, y)` points.
pub struct Series {
    /// Legend text.
    pub label: String,
    /// The points, in x order.
    pub points: Vec<(f64, f64)>,
}

/// A point of the time-against-error plot.
pub struct TradeOff {
    /// Its label beside the point (the colour tells the method).
    pub label: String,
    /// The method's name, which picks the colour.
    pub method: &'static str,
    /// Milliseconds per frame.
    pub ms: f64,
    /// Error (MSE).
    pub error: f64,
    /// Whether it is on the Pareto front.
    pub pareto: bool,
}

/// A colour per method name (the order of [`crate::bench::Method::ALL`]).
fn method_colour(method: &str) -> RGBColor {
    let index = crate::bench::Method::ALL
        .iter()
        .position(|m| m.name() == method)
        .unwrap_or(0);
    [
        RGBColor(214, 39, 40),
        RGBColor(255, 127, 14),
        RGBColor(31, 119, 180),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
        RGBColor(23, 190, 207),
    ][index]
}

/// Bounds of `values` padded by a factor on a log axis (values clamped positive).
fn log_bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .map(|v| v.max(1e-12))
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return (0.1, 10.0);
    }
    (lo / 1.6, hi * 1.6)
}

/// The series' legend, boxed in the upper right corner.
fn legend<'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, CT>,
) -> std::result::Result<(), Box<dyn std::error::Error>> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FAMILY, 13))
        .draw()?;
    Ok(())
}

/// A tick label with three significant figures at most.
fn tick(v: f64) -> String {
    let decimals = (2 - v.abs().max(1e-12).log10().floor() as i32).clamp(0, 6) as usize;
    format!("{v:.decimals$}")
}

/// Frame rate (y) against frame number along the path (x), one line per series.
pub fn fps_along_path(path: &Path, title: &str, y_label: &str, series: &[Series]) -> Result<()> {
    write_png(path, |root| {
        let frames = series.iter().map(|s| s.points.len()).max().unwrap_or(1);
        let top = series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1))
            .fold(0.0, f64::max);
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FAMILY, 22))
            .margin(14)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..(frames.max(2) - 1) as f64, 0.0..top.max(1e-9) * 1.08)?;
        chart
            .configure_mesh()
            .x_desc("frame along the camera path")
            .y_desc(y_label)
            .label_style((FAMILY, 15))
            .light_line_style(WHITE)
            .x_label_formatter(&|v| format!("{v:.0}"))
            .draw()?;
        for (k, s) in series.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(
                    s.points.iter().copied(),
                    colour.stroke_width(2),
                ))?
                .label(s.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
        }
        legend(&mut chart)
    })
}

/// Time per frame (x, log) against error (y, log), a labelled point per setup coloured by
/// method, the Pareto front joined by a dashed black line.
pub fn time_against_error(
    path: &Path,
    title: &str,
    error_label: &str,
    points: &[TradeOff],
) -> Result<()> {
    write_png(path, |root| {
        let (x0, x1) = log_bounds(points.iter().map(|p| p.ms));
        let (y0, y1) = log_bounds(points.iter().map(|p| p.error));
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FAMILY, 22))
            .margin(14)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("GPU ms per frame (log)")
            .y_desc(error_label)
            .label_style((FAMILY, 15))
            .light_line_style(WHITE)
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()?;
        let mut front: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.pareto)
            .map(|p| (p.ms, p.error.max(1e-12)))
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        // A staircase: each front point holds its error until the next, faster-to-better one.
        let stairs: Vec<(f64, f64)> = front
            .windows(2)
            .flat_map(|w| [w[0], (w[1].0, w[0].1)])
            .chain(front.last().copied())
            .collect();
        chart
            .draw_series(DashedLineSeries::new(stairs, 6, 4, BLACK.stroke_width(1)))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
        let mut methods: Vec<&str> = Vec::new();
        for p in points {
            let colour = method_colour(p.method);
            let style = if p.pareto {
                colour.filled()
            } else {
                colour.stroke_width(2)
            };
            let series = chart.draw_series(std::iter::once(
                EmptyElement::at((p.ms, p.error.max(1e-12)))
                    + Circle::new((0, 0), 6, style)
                    + Text::new(p.label.clone(), (8, -16), (FAMILY, 13)),
            ))?;
            if !methods.contains(&p.method) {
                methods.push(p.method);
                series
                    .label(p.method)
                    .legend(move |(x, y)| Circle::new((x + 10, y), 6, colour.filled()));
            }
        }
        legend(&mut chart)
    })
}

/// Error (y, log) against field angle (x, degrees), a dot per point and a colour per series,
/// with the pass bound as a dashed red line.
pub fn error_against_angle(path: &Path, title: &str, series: &[Series], bound: f64) -> Result<()> {
    write_png(path, |root| {
        let all = || series.iter().flat_map(|s| s.points.iter().copied());
        let x1 = all().map(|p| p.0).fold(90.0, f64::max) * 1.02;
        // Room above the bound for the legend.
        let (y0, y1) = log_bounds(all().map(|p| p.1).chain([bound, bound * 60.0]));
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FAMILY, 22))
            .margin(14)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..x1, (y0..y1).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("angle from the optical axis (degrees)")
            .y_desc("detected − predicted position (px, log)")
            .label_style((FAMILY, 15))
            .light_line_style(WHITE)
            .y_labels(8)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()?;
        chart
            .draw_series(DashedLineSeries::new(
                [(0.0, bound), (x1, bound)],
                8,
                5,
                RED.stroke_width(2),
            ))?
            .label(format!("bound {bound} px"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
        for (k, s) in series.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            chart
                .draw_series(
                    s.points
                        .iter()
                        .map(|&(x, y)| Circle::new((x, y.max(1e-12)), 2, colour.filled())),
                )?
                .label(s.label.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.filled()));
        }
        legend(&mut chart)
    })
}
