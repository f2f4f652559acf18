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
        // An empty FISHEYE_FONT (`FISHEYE_FONT= cmd`) is no choice of font.
        let wanted = std::env::var_os("FISHEYE_FONT")
            .filter(|v| !v.is_empty())
            .map(PathBuf::from);
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

/// A point of the time-against-error plot (filled when on the Pareto front).
pub struct TradeOff {
    /// Its label beside the point (the colour tells the method).
    pub label: String,
    /// The method's name, which picks the colour.
    pub method: &'static str,
    /// What a frame costs it: milliseconds, or rays and texels.
    pub cost: f64,
    /// Error (MSE).
    pub error: f64,
    /// Whether it is on the Pareto front.
    pub pareto: bool,
}

/// A colour per method name (the order of [`crate::renderer::Method::ALL`]).
fn method_colour(method: &str) -> RGBColor {
    let index = crate::renderer::Method::ALL
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

/// A tick label with three significant figures at most and no trailing zeros; below 0.01
/// in scientific notation.
fn tick(v: f64) -> String {
    if v.abs() < 0.01 && v != 0.0 {
        return format!("{v:.0e}");
    }
    let decimals = (2 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
    let text = format!("{v:.decimals$}");
    match text.contains('.') {
        true => text.trim_end_matches('0').trim_end_matches('.').to_string(),
        false => text,
    }
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

/// Tick values for a log axis over `lo..hi`: 1, 2 and 5 times powers of ten, or every
/// integer multiple where that gives fewer than four, or only the powers where it gives more
/// than twelve.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let within = |mantissas: &[f64]| -> Vec<f64> {
        let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (first..=last)
            // Divided for negative powers: 6 / 1e4 is the double nearest 0.0006.
            .flat_map(|k| {
                mantissas.iter().map(move |m| match k {
                    0.. => m * 10f64.powi(k),
                    _ => m / 10f64.powi(-k),
                })
            })
            .filter(|v| (lo..=hi).contains(v))
            .collect()
    };
    let nice = within(&[1.0, 2.0, 5.0]);
    if nice.len() < 4 {
        within(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    } else if nice.len() > 12 {
        within(&[1.0])
    } else {
        nice
    }
}

/// Where each of `labels` (anchored at pixel points, `width` pixels wide) goes: the first of
/// several offsets around its point whose box overlaps no label placed before it and no
/// point, else the first offset.
fn place_labels(anchors: &[(i32, i32)], widths: &[i32], height: i32) -> Vec<(i32, i32)> {
    let offsets = |w: i32| {
        [
            (9, -height - 4),
            (9, 4),
            (-w - 9, -height - 4),
            (-w - 9, 4),
            (9, -height / 2),
            (-w - 9, -height / 2),
            (-w / 2, -height - 12),
            (-w / 2, 12),
        ]
    };
    let overlaps = |a: (i32, i32, i32, i32), b: (i32, i32, i32, i32)| {
        a.0 < b.0 + b.2 && b.0 < a.0 + a.2 && a.1 < b.1 + b.3 && b.1 < a.1 + a.3
    };
    let dots: Vec<(i32, i32, i32, i32)> = anchors
        .iter()
        .map(|&(x, y)| (x - 7, y - 7, 14, 14))
        .collect();
    let mut placed: Vec<(i32, i32, i32, i32)> = Vec::new();
    anchors
        .iter()
        .zip(widths)
        .map(|(&(x, y), &w)| {
            let boxes = offsets(w).map(|(dx, dy)| (x + dx, y + dy, w, height));
            let free = boxes
                .iter()
                .find(|b| !placed.iter().chain(&dots).any(|o| overlaps(**b, *o)))
                .unwrap_or(&boxes[0]);
            placed.push(*free);
            (free.0 - x, free.1 - y)
        })
        .collect()
}

/// Cost per frame (x, log: `cost_label` says which) against error (y, log), a labelled point
/// per setup coloured by method (filled where it is on the Pareto front), and each family's
/// lower envelope as a line (`envelopes`: direct RT first, then the cube maps, then direct
/// RT's uniform sampling alone).
pub fn cost_against_error(
    path: &Path,
    title: &str,
    cost_label: &str,
    error_label: &str,
    points: &[TradeOff],
    envelopes: &[Series],
) -> Result<()> {
    write_png(path, |root| {
        let (x0, x1) = log_bounds(points.iter().map(|p| p.cost));
        let (y0, y1) = log_bounds(points.iter().map(|p| p.error));
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FAMILY, 22))
            .margin(14)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(
                (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
                (y0..y1).log_scale().with_key_points(log_ticks(y0, y1)),
            )?;
        chart
            .configure_mesh()
            .x_desc(cost_label)
            .y_desc(error_label)
            .label_style((FAMILY, 15))
            .light_line_style(WHITE)
            .bold_line_style(RGBColor(225, 225, 225))
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()?;
        let family_colours = [
            method_colour("rt"),
            RGBColor(90, 90, 90),
            RGBColor(160, 190, 230),
        ];
        for (series, &colour) in envelopes.iter().zip(&family_colours) {
            let line: Vec<(f64, f64)> = series
                .points
                .iter()
                .map(|&(t, e)| (t, e.max(1e-12)))
                .collect();
            chart
                .draw_series(DashedLineSeries::new(line, 7, 4, colour.stroke_width(2)))?
                .label(series.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
        }
        let anchors: Vec<(i32, i32)> = points
            .iter()
            .map(|p| chart.backend_coord(&(p.cost, p.error.max(1e-12))))
            .collect();
        // About 7 pixels a character at 13 px.
        let widths: Vec<i32> = points
            .iter()
            .map(|p| 7 * p.label.chars().count() as i32)
            .collect();
        let offsets = place_labels(&anchors, &widths, 13);
        let mut methods: Vec<&str> = Vec::new();
        for (p, &(dx, dy)) in points.iter().zip(&offsets) {
            let colour = method_colour(p.method);
            let style = if p.pareto {
                colour.filled()
            } else {
                colour.stroke_width(2)
            };
            let series = chart.draw_series(std::iter::once(
                EmptyElement::at((p.cost, p.error.max(1e-12)))
                    + Circle::new((0, 0), 6, style)
                    + Text::new(p.label.clone(), (dx, dy), (FAMILY, 13)),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Log axes get 4 to 12 readable ticks over any span, short labels.
    #[test]
    fn log_axes_get_readable_ticks() {
        assert_eq!(log_ticks(6.0, 400.0), [10.0, 20.0, 50.0, 100.0, 200.0]);
        // Less than a decade: every multiple.
        let narrow = log_ticks(3.1e-4, 1.3e-3);
        assert_eq!(narrow, [4e-4, 5e-4, 6e-4, 7e-4, 8e-4, 9e-4, 1e-3]);
        // Many decades: the powers alone.
        assert_eq!(log_ticks(1e-9, 1.0).len(), 10);
        let labels: Vec<String> = [10.0, 2.5, 0.02, 0.125, 5e-3, 1500.0].map(tick).to_vec();
        assert_eq!(labels, ["10", "2.5", "0.02", "0.125", "5e-3", "1500"]);
    }

    /// Labels of crowded points are moved until no two overlap each other or a point.
    #[test]
    fn crowded_labels_do_not_overlap() {
        let anchors = [(100, 100), (104, 101), (108, 99), (300, 300)];
        let widths = [21, 21, 35, 14];
        let offsets = place_labels(&anchors, &widths, 13);
        let boxes: Vec<(i32, i32, i32, i32)> = anchors
            .iter()
            .zip(&offsets)
            .zip(&widths)
            .map(|((&(x, y), &(dx, dy)), &w)| (x + dx, y + dy, w, 13))
            .collect();
        for (i, a) in boxes.iter().enumerate() {
            for b in &boxes[i + 1..] {
                let apart =
                    a.0 >= b.0 + b.2 || b.0 >= a.0 + a.2 || a.1 >= b.1 + b.3 || b.1 >= a.1 + a.3;
                assert!(apart, "{a:?} overlaps {b:?}");
            }
        }
        // A lone point keeps the first place: above and to the right.
        assert_eq!(offsets[3], (9, -17));
    }
}
