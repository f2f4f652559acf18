//! What `fisheye validate` writes: the Markdown and JSON report, the corners of each lens as
//! CSV, the overlays, and the plot of error against field angle.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use glam::DVec2;

use super::{BOUND_PX, LensValidation};
use crate::bench::Machine;
use crate::error::Result;
use crate::lens::LensCamera;
use crate::plot;
use crate::report::{file_stem, machine_lines, write_json, write_text};
use crate::trace::{colour_image, save_png};

/// `fisheye validate`'s report.
#[derive(Serialize)]
pub struct ValidationReport {
    /// The machine.
    pub machine: Machine,
    /// The detector's Gaussian, pixels.
    pub sigma_px: f64,
    /// Closest line spacing checked, pixels.
    pub min_spacing_px: f64,
    /// The pass bound, pixels.
    pub bound_px: f64,
    /// Per lens.
    pub lenses: Vec<LensValidation>,
    /// Per lens, its image (for the overlays).
    #[serde(skip)]
    pub images: Vec<(LensCamera, Vec<[f32; 4]>)>,
}

/// Length of an error's arrow in an overlay, per pixel of error: [`BOUND_PX`] draws 12 px.
const ARROW_SCALE: f64 = 12.0 / BOUND_PX;

impl ValidationReport {
    /// Whether every lens passed.
    pub fn passed(&self) -> bool {
        self.lenses.iter().all(|l| l.passed)
    }

    /// The Markdown table: a row per lens.
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "# fisheye validate: the grid scene through each lens\n\n{}\n\
             The `grid` checkerboard rendered from a fixed off-centre pose, N×N rays per pixel \
             averaged (column SS); corners detected with a σ = {} px Gaussian; checked where \
             parallel cell edges are at least {} px apart and cross at 60° or more, and the \
             detector's window is inside the image's valid pixels. A lens passes when every \
             checked corner is found within {} px of the f64 projection's prediction and \
             nothing else is found among them.\n\n",
            machine_lines(&self.machine),
            self.sigma_px,
            self.min_spacing_px,
            self.bound_px,
        );
        md.push_str(
            "| lens | size | SS | in image | checked | found | stray | rms px | p95 px | max px | mean shift px | max θ checked | pass |\n\
             |---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|:-:|\n",
        );
        for l in &self.lenses {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | ({:+.4}, {:+.4}) | {:.1}° | {} |",
                l.lens,
                l.size,
                l.supersample,
                l.projected,
                l.checked,
                l.matched,
                l.stray,
                l.rms_px,
                l.p95_px,
                l.max_px,
                l.mean_px[0],
                l.mean_px[1],
                l.max_theta_deg,
                if l.passed { "yes" } else { "**no**" }
            );
        }
        let _ = write!(
            md,
            "\nOverlays (`overlay.LENS.png`, the image at twice its size or more): a cross at each \
             checked prediction, green within half the bound, orange within it, red beyond; \
             its error drawn from it {} times magnified; magenta circles: checked corners \
             not found; blue circles: stray detections; grey dots: corners not checked. \
             `points.LENS.csv` lists every corner.\n",
            ARROW_SCALE
        );
        md
    }

    /// Writes `validate.json`, `validate.md`, and per lens `overlay.LENS.png` and
    /// `points.LENS.csv`, then `errors.png` (error against field angle); returns why the plot
    /// is missing, if there is no font for it.
    pub fn write(&self, out: &Path) -> Result<Option<String>> {
        write_json(&out.join("validate.json"), self)?;
        write_text(&out.join("validate.md"), &self.markdown())?;
        for (l, (camera, colour)) in self.lenses.iter().zip(&self.images) {
            let stem = file_stem(&l.lens);
            save_png(
                &overlay(l, camera, colour)?,
                &out.join(format!("overlay.{stem}.png")),
            )?;
            write_text(&out.join(format!("points.{stem}.csv")), &points_csv(l))?;
        }
        if let Err(why) = plot::font() {
            return Ok(Some(why));
        }
        let series: Vec<plot::Series> = self
            .lenses
            .iter()
            .map(|l| plot::Series {
                // The model's name, without a spec's parameters.
                label: l.lens.split(':').next().unwrap_or(&l.lens).to_string(),
                points: l
                    .points
                    .iter()
                    .filter_map(|p| Some((p.prediction.theta.to_degrees(), p.error()?.length())))
                    .collect(),
            })
            .collect();
        plot::error_against_angle(
            &out.join("errors.png"),
            &format!(
                "grid corners: detected − predicted ({})",
                self.machine.adapter
            ),
            &series,
            self.bound_px,
        )?;
        Ok(None)
    }
}

/// Every corner of one lens as CSV.
fn points_csv(l: &LensValidation) -> String {
    let mut csv = String::from(
        "face,a,b,theta_deg,spacing_px,checked,predicted_x,predicted_y,detected_x,detected_y,error_px\n",
    );
    for p in &l.points {
        let q = &p.prediction;
        let (dx, dy, e) = match p.detected {
            Some(d) => (
                d.x.to_string(),
                d.y.to_string(),
                d.distance(q.pixel).to_string(),
            ),
            None => Default::default(),
        };
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{dx},{dy},{e}",
            q.corner.face,
            q.corner.a,
            q.corner.b,
            q.theta.to_degrees(),
            q.spacing,
            q.checked,
            q.pixel.x,
            q.pixel.y
        );
    }
    csv
}

/// The image enlarged to about 1000 px wide (at least 2x) with the predictions and errors
/// drawn over it (see [`ValidationReport::markdown`] for the legend).
fn overlay(
    l: &LensValidation,
    camera: &LensCamera,
    colour: &[[f32; 4]],
) -> Result<image::RgbaImage> {
    use plotters::prelude::*;
    let image = colour_image(camera.size, colour);
    let zoom = (1000 / camera.size.width).clamp(2, 8);
    let (w, h) = (camera.size.width * zoom, camera.size.height * zoom);
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            rgb.extend_from_slice(&image.get_pixel(x / zoom, y / zoom).0[..3]);
        }
    }
    let z = f64::from(zoom);
    let at = |p: DVec2| ((p.x * z).round() as i32, (p.y * z).round() as i32);
    {
        let area = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        let draw = || -> std::result::Result<(), Box<dyn std::error::Error>> {
            let grey = RGBColor(150, 150, 150);
            for p in &l.points {
                let q = &p.prediction;
                if !q.checked {
                    area.draw(&Circle::new(at(q.pixel), 1, grey.filled()))?;
                    continue;
                }
                let Some(e) = p.error() else {
                    area.draw(&Circle::new(at(q.pixel), 5, MAGENTA.stroke_width(2)))?;
                    continue;
                };
                let c = if e.length() <= BOUND_PX / 2.0 {
                    RGBColor(0, 170, 0)
                } else if e.length() <= BOUND_PX {
                    RGBColor(255, 140, 0)
                } else {
                    RED
                };
                area.draw(&Cross::new(at(q.pixel), 3, c.stroke_width(1)))?;
                let tip = q.pixel + e * ARROW_SCALE / z;
                area.draw(&PathElement::new(
                    vec![at(q.pixel), at(tip)],
                    c.stroke_width(2),
                ))?;
            }
            for d in &l.strays {
                area.draw(&Circle::new(at(*d), 5, BLUE.stroke_width(2)))?;
            }
            area.present()?;
            Ok(())
        };
        draw().map_err(|e| crate::error::Error::Plot {
            path: format!("overlay.{}.png", file_stem(&l.lens)).into(),
            message: e.to_string(),
        })?;
    }
    let rgb = image::RgbImage::from_raw(w, h, rgb).expect("a full buffer");
    Ok(image::DynamicImage::ImageRgb8(rgb).to_rgba8())
}
