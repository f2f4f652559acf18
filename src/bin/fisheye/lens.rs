//! `fisheye lens ...`: list, project, unproject, fit, convert and draw lens models.

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Subcommand;
use fisheye_rt::demo::LensDemo;
use fisheye_rt::gpu::{GpuContext, Queries};
use fisheye_rt::lens::calib::{self, CalibFormat, Calibration};
use fisheye_rt::lens::fit::calibrated_equivalent;
use fisheye_rt::lens::glass::{FitModel, GlassLens, camera_for};
use fisheye_rt::lens::gpu::DirectionSource;
use fisheye_rt::lens::points;
use fisheye_rt::lens::{
    CalibratedLens, CalibratedModel, ImageSize, LensModel, PRESET_FOV_DEGREES, PRESETS, parse_spec,
};
use fisheye_rt::report;
use fisheye_rt::trace::{save_png, write_file};
use glam::{DVec2, DVec3};

use crate::args::{CameraArgs, Format, PointArgs};

#[derive(Subcommand)]
pub(crate) enum LensCommand {
    /// List the lens models and the presets.
    List,
    /// Read `px py` lines on stdin (continuous pixel coordinates, origin at the top-left
    /// corner of the image) and write the unit direction `dx dy dz` (x right, y down, z
    /// forward) or `none` for each (outside the image or the lens's field). A line that is
    /// not two numbers fails the whole batch, naming its line, before anything is written.
    Unproject(PointArgs),
    /// Read `dx dy dz` lines on stdin and write the pixel `px py` each lands on, or `none`
    /// (outside the lens's field or the image). A line that is not three numbers fails the
    /// whole batch, naming its line, before anything is written.
    Project(PointArgs),
    /// Fit the thesis's classic mappings (equidistant, equisolid, orthographic,
    /// stereographic) to a calibrated lens over the angles its image shows, and print each
    /// one's focal length and radial residual in pixels, best first.
    Fit(CameraArgs),
    /// Write a lens (--lens SPEC at --size, or --calib FILE) as a calibration file: OpenCV
    /// YAML or XML, a Kalibr camchain or Basalt JSON. A classic lens is written as its exact
    /// calibrated equivalent, or a fitted Kannala–Brandt model with its residual printed.
    Convert {
        #[command(flatten)]
        camera: CameraArgs,
        /// The output format.
        #[arg(long, value_enum)]
        format: Format,
        /// The file to write.
        #[arg(long, short)]
        out: PathBuf,
    },
    /// Print a lens's figures: its field of view and image circle for any spec; for a
    /// prescription (`prescription:FILE[,sensor=MM][,fstop=N][,focus=METRES]`) also its paraxial focal
    /// lengths (effective, and back from the rear vertex), f-number, entrance pupil and
    /// sensor.
    Info {
        /// The lens spec (see `fisheye lens list`), or `prescription:FILE[,sensor=MM][,fstop=N][,focus=METRES]`
        /// for a table of glass surfaces in pbrt's format.
        spec: String,
        /// Image size in pixels, WIDTHxHEIGHT, for the figures in pixels.
        #[arg(long, default_value = "1024x768")]
        size: ImageSize,
        /// Write JSON (figures a lens has no physical scale for are null).
        #[arg(long)]
        json: bool,
    },
    /// Draw what lenses do to the sphere of directions (10° grid, rings every 30° off the
    /// axis), one PNG per lens.
    Demo {
        /// Lens specs to draw (repeatable); by default one of each model and every preset.
        #[arg(long)]
        lens: Vec<String>,
        /// Image size in pixels, WIDTHxHEIGHT.
        #[arg(long, default_value = "1024x768")]
        size: ImageSize,
        /// Folder to write the PNGs into.
        #[arg(long, short, default_value = "fisheye-demo")]
        out: PathBuf,
    },
}

/// `fisheye lens info`: a prescription's figures, in millimetres and at `size`'s pixels; a
/// model's field and image circle, in the image's normalized units (half its width is 1)
/// and pixels.
pub(crate) fn info(spec: &str, size: ImageSize, json: bool) -> Result<()> {
    let width = f64::from(size.width);
    let (values, text) = if GlassLens::is_spec(spec) {
        let glass = GlassLens::parse(spec)?;
        let f = glass.figures();
        let fitted = glass.fitted(size);
        let kb = fitted
            .as_ref()
            .ok()
            .and_then(|f| f.camera.lens.calibrated())
            .map(|c| c.model().parameters());
        let fit_note = match &fitted {
            Ok(f) => format!(
                "the chief rays fitted at {size}, within {:.3} px over {:.2}°: what --lens \
                 renders",
                f.residual_px,
                f.fov().to_degrees()
            ),
            Err(e) => format!("no fit: {e}"),
        };
        let p = &glass.prescription;
        // Millimetres on the film per pixel.
        let pitch = glass.sensor_mm / width;
        let values = serde_json::json!({
            "spec": spec,
            "surfaces": p.surfaces().len(),
            "stop_surface": p.stop() + 1,
            "efl_mm": f.efl_mm,
            "bfl_mm": f.bfl_mm,
            "f_number": f.f_number,
            "entrance_pupil_diameter_mm": 2.0 * f.pupil_radius_mm,
            "entrance_pupil_position_mm": f.pupil_position_mm,
            "fov_deg": f.fov_deg,
            "image_circle_mm": f.image_circle_mm,
            "film_mm": glass.film_mm,
            "sensor_mm": glass.sensor_mm,
            "size": size.to_string(),
            "pixel_um": pitch * 1e3,
            "efl_px": f.efl_mm / pitch,
            "image_circle_px": f.image_circle_mm / pitch,
            "kannala_brandt": fitted.as_ref().ok().map(|f| serde_json::json!({
                "parameters": kb.iter().flatten().map(|(k, v)| (k.to_string(), serde_json::json!(v)))
                    .collect::<serde_json::Map<String, serde_json::Value>>(),
                "residual_px": f.residual_px,
                "fov_deg": f.fov().to_degrees(),
            })),
        });
        let text = [
            format!(
                "{spec}: {} surfaces, the stop at surface {}",
                p.surfaces().len(),
                p.stop() + 1
            ),
            row(
                "efl_mm",
                format!("{:.4}", f.efl_mm),
                "effective focal length, paraxial",
            ),
            row(
                "bfl_mm",
                format!("{:.4}", f.bfl_mm),
                "back focal length, from the rear vertex",
            ),
            row("f_number", format!("{:.3}", f.f_number), ""),
            row(
                "entrance pupil",
                format!("{:.4} mm across", 2.0 * f.pupil_radius_mm),
                &format!("{:.4} mm behind the front vertex", f.pupil_position_mm),
            ),
            row(
                "fov_deg",
                format!("{:.2}", f.fov_deg),
                "the full field any ray gets through",
            ),
            row("image_circle_mm", format!("{:.4}", f.image_circle_mm), ""),
            row(
                "film_mm",
                format!("{:.4}", glass.film_mm),
                "the film behind the rear vertex, at the focus",
            ),
            row(
                "sensor_mm",
                format!("{:.4}", glass.sensor_mm),
                "the image's width on the film",
            ),
            row(
                &format!("at {size}"),
                format!("{:.3} µm pixels", pitch * 1e3),
                &format!(
                    "efl {:.1} px, image circle {:.1} px",
                    f.efl_mm / pitch,
                    f.image_circle_mm / pitch
                ),
            ),
            row(
                "kannala-brandt",
                kb.iter()
                    .flatten()
                    .map(|(k, v)| format!("{k}={v:.6}"))
                    .collect::<Vec<_>>()
                    .join(","),
                &fit_note,
            ),
        ]
        .join("\n");
        (values, text)
    } else {
        let lens = parse_spec(spec)?;
        let fov = 2.0 * lens.theta_max().to_degrees();
        // Normalized units: half the image's width is 1.
        let circle = 2.0 * lens.r_max();
        let values = serde_json::json!({
            "spec": spec,
            "model": lens.name(),
            "efl_mm": null,
            "bfl_mm": null,
            "f_number": null,
            "fov_deg": fov,
            "image_circle": circle,
            "size": size.to_string(),
            "image_circle_px": circle * width / 2.0,
        });
        let text = [
            format!(
                "{spec}: the {} model, a mapping of directions to the image with no physical \
                 scale (no focal lengths in mm, no f-number)",
                lens.name()
            ),
            row("fov_deg", format!("{fov:.2}"), ""),
            row(
                "image_circle",
                format!("{circle:.4}"),
                "normalized: half the image's width is 1",
            ),
            row(
                &format!("at {size}"),
                format!("image circle {:.1} px", circle * width / 2.0),
                "",
            ),
        ]
        .join("\n");
        (values, text)
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&values)?);
    } else {
        println!("{text}");
    }
    Ok(())
}

/// A line of `lens info`: the name, the value, and a note in brackets where there is one.
fn row(name: &str, value: String, note: &str) -> String {
    match note {
        "" => format!("  {name:<17} {value}"),
        note => format!("  {name:<17} {value}   ({note})"),
    }
}

pub(crate) fn list() {
    println!("models (spec: NAME:f=F[,fov=DEGREES]; general also takes k1, k2):");
    let general = LensModel::General { k1: 1.0, k2: 1.0 };
    for model in [
        LensModel::Rectilinear,
        LensModel::Stereographic,
        LensModel::Equidistant,
        LensModel::Equisolid,
        LensModel::Orthographic,
        general,
    ] {
        println!("  {:<14} {}", model.name(), model.formula());
    }
    println!(
        "\ncalibrated models (spec: NAME:fx=FX,fy=FY,cx=CX,cy=CY,...[,fov=DEGREES], pixels, \
         OpenCV's centre convention):"
    );
    for ((name, keys), example) in CalibratedModel::NAMES.iter().zip(CalibratedModel::EXAMPLES) {
        println!("  {name:<14} {keys}\n  {:<14} e.g. {example}", "");
    }
    println!("\npresets (limited to {PRESET_FOV_DEGREES}°; spec: NAME[:f=F,fov=DEGREES]):");
    for p in PRESETS {
        println!(
            "  {:<24} {:<13} f={:<6} {}",
            p.name,
            p.model.name(),
            p.f,
            p.description
        );
    }
}

/// Parses stdin: one point per non-empty line, `N` numbers each; `#` starts a comment.
pub(crate) fn read_points<const N: usize>() -> Result<Vec<[f64; N]>> {
    let mut points = Vec::new();
    for (number, line) in std::io::stdin().lock().lines().enumerate() {
        let line = line.context("reading stdin")?;
        let text = line.split('#').next().unwrap_or("").trim();
        if text.is_empty() {
            continue;
        }
        let values: Vec<f64> = text
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()
            .with_context(|| format!("stdin line {}: {text:?} is not numbers", number + 1))?;
        let Ok(point) = <[f64; N]>::try_from(values) else {
            bail!(
                "stdin line {}: expected {N} numbers, got {text:?}",
                number + 1
            );
        };
        points.push(point);
    }
    Ok(points)
}

pub(crate) fn write_lines(lines: impl Iterator<Item = String>) -> Result<()> {
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for line in lines {
        writeln!(out, "{line}")?;
    }
    Ok(out.flush()?)
}

pub(crate) fn unproject(args: &PointArgs) -> Result<()> {
    let camera = args.camera()?;
    let pixels: Vec<DVec2> = read_points::<2>()?.into_iter().map(DVec2::from).collect();
    let ctx = args.gpu.then(GpuContext::new).transpose()?;
    let dirs = points::unproject(&camera, &pixels, args.pixel_origin.into(), ctx.as_ref())?;
    write_lines(dirs.into_iter().map(|d| match d {
        Some(d) => format!("{:.9} {:.9} {:.9}", d.x, d.y, d.z),
        None => "none".into(),
    }))
}

pub(crate) fn project(args: &PointArgs) -> Result<()> {
    let camera = args.camera()?;
    let dirs: Vec<DVec3> = read_points::<3>()?.into_iter().map(DVec3::from).collect();
    let ctx = args.gpu.then(GpuContext::new).transpose()?;
    let pixels = points::project(&camera, &dirs, args.pixel_origin.into(), ctx.as_ref())?;
    write_lines(pixels.into_iter().map(|p| match p {
        Some(p) => format!("{:.6} {:.6}", p.x, p.y),
        None => "none".into(),
    }))
}

pub(crate) fn fit(args: &CameraArgs) -> Result<()> {
    let camera = args.camera()?;
    let Some(lens) = camera.lens.calibrated() else {
        bail!(
            "{} is already a classic lens; fit takes a calibrated one",
            camera.lens
        );
    };
    let angles = fisheye_rt::lens::fit::fitted_angles(lens, camera.size);
    let widest = angles.last().copied().unwrap_or(0.0).to_degrees();
    println!(
        "{} at {}: classic mappings fitted over θ ≤ {widest:.1}° (a {:.1}° field)",
        lens.model().name(),
        camera.size,
        2.0 * widest
    );
    println!(
        "{:<14} {:>10} {:>10} {:>12} {:>12}",
        "model", "f (px)", "f (norm.)", "rms (px)", "max (px)"
    );
    for f in fisheye_rt::lens::fit::fit_classic(lens, camera.size) {
        println!(
            "{:<14} {:>10.3} {:>10.4} {:>12.4} {:>12.4}",
            f.model.name(),
            f.f_pixels,
            f.f_pixels * 2.0 / f64::from(camera.size.width),
            f.rms,
            f.max
        );
    }
    // A prescription's chief rays as each calibrated model, as `model=` fits them.
    if let Some(spec) = args.lens.as_deref().filter(|s| GlassLens::is_spec(s)) {
        let glass = GlassLens::parse(spec)?;
        println!(
            "the traced chief rays fitted as calibrated models (model=NAME in the spec; lens \
             convert writes them):"
        );
        println!("{:<14} {:>12}   model", "model", "max (px)");
        for (name, model) in FitModel::ALL {
            let fitted = GlassLens {
                model,
                ..glass.clone()
            }
            .fitted(camera.size)?;
            println!(
                "{name:<14} {:>12.4}   {}",
                fitted.residual_px, fitted.camera.lens
            );
        }
    }
    Ok(())
}

pub(crate) fn convert(args: &CameraArgs, format: CalibFormat, out: &Path) -> Result<()> {
    let camera = args.camera()?;
    let glass = args.lens.as_deref().filter(|s| GlassLens::is_spec(s));
    let lens = match (camera.lens.calibrated(), glass) {
        (Some(lens), Some(spec)) => {
            // A prescription goes as its chief rays' fitted model, without the lens's field.
            let fitted = GlassLens::parse(spec)?.fitted(camera.size)?;
            println!(
                "{spec}: its chief rays fitted as {}, largest radial residual {:.2e} px; the \
                 {:.1}° field of view is not written (the formats hold none)",
                camera.lens,
                fitted.residual_px,
                fitted.fov().to_degrees()
            );
            CalibratedLens::new(lens.model(), lens.intrinsics())?
        }
        (Some(lens), None) => *lens,
        (None, _) => {
            // A classic lens goes as its calibrated equivalent: exact, or fitted.
            let equivalent = calibrated_equivalent(&camera)?;
            let model = fisheye_rt::lens::Lens::Calibrated(equivalent.lens);
            if equivalent.exact {
                println!(
                    "{} is exactly {model}; largest difference {:.1e} px (rounding)",
                    camera.lens, equivalent.residual_px
                );
            } else {
                println!(
                    "{} has no exact calibrated equivalent: fitted {model}, largest radial \
                     residual {:.2e} px over the angles the image shows",
                    camera.lens, equivalent.residual_px
                );
            }
            // The formats have no field of view: the file holds the mapping alone.
            if let Some(fov) = equivalent.lens.max_fov() {
                println!(
                    "the {:.0}° field of view is not written (the formats hold none): readers \
                     take the model's whole domain",
                    fov.to_degrees()
                );
            }
            CalibratedLens::new(equivalent.lens.model(), equivalent.lens.intrinsics())?
        }
    };
    let text = calib::write(
        &Calibration {
            lens,
            size: camera.size,
            line_delay: camera.shutter.line_delay,
        },
        format,
    )?;
    write_file(out, text.as_bytes())?;
    println!("wrote {} ({})", out.display(), format.name());
    Ok(())
}

/// One representative lens per model, then every preset.
pub(crate) fn default_demo_lenses() -> Vec<String> {
    let mut specs: Vec<String> = [
        "rectilinear:f=0.5",
        "stereographic:f=0.35",
        "equidistant:f=0.3",
        "equisolid:f=0.45",
        "orthographic:f=0.66",
        "general:f=0.4,k1=0.7,k2=0.7",
    ]
    .map(String::from)
    .to_vec();
    specs.extend(PRESETS.iter().map(|p| p.name.to_string()));
    specs
}

pub(crate) fn demo(lenses: Vec<String>, size: ImageSize, out: PathBuf) -> Result<()> {
    let lenses = if lenses.is_empty() {
        default_demo_lenses()
    } else {
        lenses
    };
    // Check every spec before starting the GPU.
    let cameras = lenses
        .iter()
        .map(|spec| Ok((spec, camera_for(spec, size)?)))
        .collect::<Result<Vec<_>>>()?;
    fisheye_rt::trace::check_writable_folder(&out)?;
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_name());
    let queries = Queries::new(&ctx, 1);
    for (spec, camera) in cameras {
        let started = Instant::now();
        let demo = LensDemo::new(&ctx, &camera, DirectionSource::Computed)?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        demo.encode(&mut encoder, queries.as_ref().map(|q| q.writes(0)));
        if let Some(q) = &queries {
            q.resolve(&mut encoder);
        }
        ctx.queue.submit([encoder.finish()]);
        let gpu_ms = match &queries {
            Some(q) => format!("{:.2} ms on the GPU", q.read_ns(&ctx)?[0] * 1e-6),
            None => "no timestamps".into(),
        };
        let image = demo.render(&ctx)?;
        let path = out.join(format!("{}.png", report::file_stem(spec)));
        save_png(&image, &path)?;
        println!(
            "{:<36} -> {} ({gpu_ms}, {:.0} ms in all)",
            camera.lens.to_string(),
            path.display(),
            started.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}
