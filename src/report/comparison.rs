//! `fisheye compare` as a library call: every setup's error against direct ray tracing and a
//! supersampled reference, with its time, and RT's verdict against the cube maps; written as
//! JSON, a Markdown table, error maps and time-against-error plots.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use super::{Progress, Run, Study, file_stem, machine_lines, sig, speed_ratio, write_report};
use crate::bench::{FrameTime, Setup};
use crate::compare::{ImageError, error_map, image_error, pareto_front, supersampled};
use crate::error::Result;
use crate::gpu::median;
use crate::plot;
use crate::renderer::Method;
use crate::scene::Camera;
use crate::trace::{colour_image, save_png};

/// One setup's time and error on one lens.
#[derive(Serialize)]
pub struct CompareEntry {
    /// Lens name.
    pub lens: String,
    /// Setup label.
    pub setup: String,
    /// Method name.
    pub method: &'static str,
    /// Cube face size, `None` for direct methods.
    pub cube_size: Option<u32>,
    /// Median GPU ms per frame, if timestamps exist.
    pub gpu_ms: Option<f64>,
    /// Median wall ms per frame.
    pub wall_ms: f64,
    /// Error against direct ray tracing at the same pixel centres.
    pub error: ImageError,
    /// Error against the supersampled reference.
    pub error_supersampled: ImageError,
    /// Whether no other setup on this lens is both faster and closer to the supersampled
    /// reference.
    pub pareto: bool,
}

impl CompareEntry {
    /// GPU time where timed, else wall time.
    pub fn ms(&self) -> f64 {
        self.gpu_ms.unwrap_or(self.wall_ms)
    }
}

/// Direct ray tracing against the fastest cube-map setting at least as accurate, on one lens.
#[derive(Serialize)]
pub struct Verdict {
    /// Lens name.
    pub lens: String,
    /// Direct RT's ms per frame.
    pub rt_ms: f64,
    /// Direct RT's MSE against the supersampled reference.
    pub rt_mse: f64,
    /// The fastest cube-map setup with an MSE no larger, if any.
    pub cube: Option<String>,
    /// Its ms per frame over RT's: the speed-up of RT (the goal is at least 4).
    pub speedup: Option<f64>,
    /// The most accurate cube-map setup, when none is as accurate as RT.
    pub best_cube: Option<String>,
}

/// What `fisheye compare` measured.
#[derive(Serialize)]
pub struct CompareReport {
    /// Where and on what it ran.
    #[serde(flatten)]
    pub run: Run,
    /// The camera pose compared at.
    pub pose: String,
    /// Rays per pixel side of the supersampled reference.
    pub supersample: u32,
    /// Timed frames per setup (medians are reported), after one untimed.
    pub frames: usize,
    /// How errors are measured.
    pub method_note: &'static str,
    /// One entry per lens and setup.
    pub entries: Vec<CompareEntry>,
    /// Per lens, RT against the cube maps.
    pub verdicts: Vec<Verdict>,
    /// Setups the adapter could not run, and why.
    pub skipped: Vec<String>,
}

const COMPARE_NOTE: &str = "Errors are over the pixels valid in both images, on displayed \
    values (clamped to [0, 1], sRGB-encoded): MSE per channel, PSNR = 10 log10(1 / MSE). The \
    first reference is direct ray tracing at the same pixel centres; the supersampled one \
    averages N x N stratified rays per pixel. Mask agreement is the fraction of all pixels \
    whose lens mask matches the reference's.";

/// Times `frames` frames of every setup at `pose` on every lens, measures each image's error
/// against direct ray tracing and a `supersample`² reference, and writes the references'
/// images and each setup's error map into `out`.
pub fn compare(
    study: &Study<'_>,
    pose: &Camera,
    frames: usize,
    supersample: u32,
    out: &Path,
    progress: &mut dyn FnMut(Progress<'_>),
) -> Result<CompareReport> {
    let (setups, skipped) = study.runnable();
    let frames = frames.max(1);
    let total = study.lenses.len() * (setups.len() * (frames + 1) + 2);
    let mut done = 0;
    let mut entries = Vec::new();
    let mut verdicts = Vec::new();
    for lens in study.lenses {
        let size = lens.camera.size;
        let stem = file_stem(&lens.name);
        let what = format!("{} references", lens.name);
        progress(Progress {
            done,
            total,
            what: &what,
        });
        let rt = Setup {
            method: Method::Rt,
            cube_size: 0,
        };
        let reference_renderer = study.renderer(lens, rt)?;
        reference_renderer.frame(study.ctx, study.scenes, pose)?;
        let reference = reference_renderer.colour(study.ctx)?;
        save_png(
            &colour_image(size, &reference),
            &out.join(format!("{stem}.reference.png")),
        )?;
        let fine = supersampled(
            study.ctx,
            &study.scenes.software,
            &lens.camera,
            pose,
            supersample,
            &reference,
        )?;
        save_png(
            &colour_image(size, &fine),
            &out.join(format!("{stem}.supersampled.png")),
        )?;
        done += 2;
        let first = entries.len();
        for &setup in &setups {
            let what = format!("{} {}", lens.name, setup.label());
            // RT is the reference's own renderer: no second pipeline for it.
            let own;
            let renderer = if setup == rt {
                &reference_renderer
            } else {
                own = study.renderer(lens, setup)?;
                &own
            };
            let mut times = Vec::with_capacity(frames);
            for k in 0..=frames {
                progress(Progress {
                    done,
                    total,
                    what: &what,
                });
                let t = renderer.frame(study.ctx, study.scenes, pose)?;
                if k > 0 {
                    times.push(t);
                }
                done += 1;
            }
            let colour = renderer.colour(study.ctx)?;
            save_png(
                &error_map(size, &fine, &colour),
                &out.join(format!("{stem}.{}.error.png", file_stem(&setup.label()))),
            )?;
            let gpu: Option<Vec<f64>> = times.iter().map(FrameTime::gpu_ms).collect();
            let wall: Vec<f64> = times.iter().map(|t| t.wall_ms).collect();
            entries.push(CompareEntry {
                lens: lens.name.clone(),
                setup: setup.label(),
                method: setup.method.name(),
                cube_size: matches!(setup.method, Method::Cube(_)).then_some(setup.cube_size),
                gpu_ms: gpu.map(|g| median(&g)),
                wall_ms: median(&wall),
                error: image_error(&reference, &colour),
                error_supersampled: image_error(&fine, &colour),
                pareto: false,
            });
        }
        let lens_entries = &mut entries[first..];
        let points: Vec<(f64, f64)> = lens_entries
            .iter()
            .map(|e| (e.ms(), e.error_supersampled.mse))
            .collect();
        for (e, on) in lens_entries.iter_mut().zip(pareto_front(&points)) {
            e.pareto = on;
        }
        if let Some(v) = verdict(&lens.name, lens_entries) {
            verdicts.push(v);
        }
    }
    progress(Progress {
        done: total,
        total,
        what: "done",
    });
    Ok(CompareReport {
        run: study.run(),
        pose: format!(
            "eye {:?} looking at {:?}",
            pose.position.to_array(),
            pose.look_at.to_array()
        ),
        supersample,
        frames,
        method_note: COMPARE_NOTE,
        entries,
        verdicts,
        skipped,
    })
}

/// RT against the fastest cube-map setup of no larger error (against the supersampled
/// reference), `None` without an `rt` entry.
fn verdict(lens: &str, entries: &[CompareEntry]) -> Option<Verdict> {
    let rt = entries.iter().find(|e| e.method == "rt")?;
    let rt_mse = rt.error_supersampled.mse;
    let cubes = || entries.iter().filter(|e| e.cube_size.is_some());
    let fastest = cubes()
        .filter(|e| e.error_supersampled.mse <= rt_mse)
        .min_by(|a, b| a.ms().total_cmp(&b.ms()));
    let best = cubes().min_by(|a, b| {
        a.error_supersampled
            .mse
            .total_cmp(&b.error_supersampled.mse)
    });
    Some(Verdict {
        lens: lens.to_string(),
        rt_ms: rt.ms(),
        rt_mse,
        cube: fastest.map(|e| e.setup.clone()),
        speedup: fastest.map(|e| e.ms() / rt.ms()),
        best_cube: fastest
            .is_none()
            .then(|| best.map(|e| e.setup.clone()))
            .flatten(),
    })
}

impl CompareReport {
    /// The Markdown table: a row per lens and setup, then the verdicts.
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "# fisheye compare: {} ({} triangles), {}, {}\n\n{}\n{} Supersampled reference: {}x{} rays per pixel. Times are medians of {} frames.\n\n",
            self.run.scene,
            self.run.triangles,
            self.run.size,
            self.pose,
            machine_lines(&self.run.machine),
            self.method_note,
            self.supersample,
            self.supersample,
            self.frames
        );
        md.push_str(
            "| lens | setup | ms / frame | MSE vs RT | PSNR vs RT (dB) | MSE vs supersampled | PSNR vs supersampled (dB) | mask agreement | Pareto |\n|---|---|---:|---:|---:|---:|---:|---:|:-:|\n",
        );
        for e in &self.entries {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.2e} | {:.1} | {:.2e} | {:.1} | {:.4} | {} |",
                e.lens,
                e.setup,
                sig(e.ms()),
                e.error.mse,
                e.error.psnr_db,
                e.error_supersampled.mse,
                e.error_supersampled.psnr_db,
                e.error.mask_agreement,
                if e.pareto { "●" } else { "" }
            );
        }
        md.push_str("\nDirect RT against the fastest cube-map setting with no larger error (vs the supersampled reference; goal: RT at least 4x faster):\n\n");
        for v in &self.verdicts {
            let line = match (&v.cube, v.speedup) {
                (Some(cube), Some(s)) => format!(
                    "{cube} at {} ms: RT ({} ms, MSE {:.2e}) is {}",
                    sig(v.rt_ms * s),
                    sig(v.rt_ms),
                    v.rt_mse,
                    speed_ratio(s)
                ),
                _ => format!(
                    "no cube-map setting reaches RT's MSE of {:.2e} (the closest: {})",
                    v.rt_mse,
                    v.best_cube.as_deref().unwrap_or("none run")
                ),
            };
            let _ = writeln!(md, "- {}: {line}", v.lens);
        }
        for s in &self.skipped {
            let _ = writeln!(md, "\nSkipped: {s}");
        }
        md
    }

    /// Writes `compare.json`, `compare.md` and one `tradeoff.LENS.png` per lens into `out`;
    /// returns the plots' warning when they could not be drawn.
    pub fn write(&self, out: &Path) -> Result<Option<String>> {
        let lenses = self.entries.iter().map(|e| e.lens.as_str());
        write_report(out, "compare", self, &self.markdown(), lenses, |lens| {
            let points: Vec<plot::TradeOff> = self
                .entries
                .iter()
                .filter(|e| e.lens == lens)
                .map(|e| plot::TradeOff {
                    label: e.cube_size.map_or(e.setup.clone(), |s| s.to_string()),
                    method: e.method,
                    ms: e.ms(),
                    error: e.error_supersampled.mse,
                    pareto: e.pareto,
                })
                .collect();
            let title = format!(
                "{}: {lens}, {} ({})",
                self.run.scene, self.run.size, self.run.machine.adapter
            );
            plot::time_against_error(
                &out.join(format!("tradeoff.{}.png", file_stem(lens))),
                &title,
                "MSE vs supersampled reference (log)",
                &points,
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A setup with a time (GPU, else wall) and an MSE against the supersampled reference.
    fn entry(setup: &str, gpu_ms: Option<f64>, wall_ms: f64, mse: f64) -> CompareEntry {
        let error = ImageError {
            mse,
            psnr_db: -10.0 * mse.log10(),
            max_abs: mse.sqrt(),
            mask_agreement: 1.0,
            compared: 1,
        };
        let (method, cube_size) = match setup.split_once('@') {
            Some((_, size)) => ("cube-rt", Some(size.parse().unwrap())),
            None => ("rt", None),
        };
        CompareEntry {
            lens: "lens".into(),
            setup: setup.into(),
            method,
            cube_size,
            gpu_ms,
            wall_ms,
            error: error.clone(),
            error_supersampled: error,
            pareto: false,
        }
    }

    /// The verdict names the fastest cube setting whose error is no larger than RT's (equal
    /// counts), with its time over RT's; without one, the most accurate cube setting instead;
    /// times are GPU times where there are some.
    #[test]
    fn the_verdict_takes_the_fastest_cube_at_least_as_accurate() {
        let entries = [
            entry("rt", Some(10.0), 50.0, 0.01),
            entry("cube-rt@64", Some(5.0), 1.0, 0.02),
            entry("cube-rt@256", Some(30.0), 1.0, 0.005),
            entry("cube-rt@128", Some(20.0), 1.0, 0.01),
        ];
        let v = verdict("lens", &entries).unwrap();
        assert_eq!((v.rt_ms, v.rt_mse), (10.0, 0.01));
        assert_eq!(v.cube.as_deref(), Some("cube-rt@128"));
        assert_eq!(v.speedup, Some(2.0));
        assert_eq!(v.best_cube, None);

        // RT more accurate than every cube: no speed-up, and the closest cube is named.
        let mut entries = entries;
        entries[0].error_supersampled.mse = 0.001;
        let v = verdict("lens", &entries).unwrap();
        assert_eq!((v.cube, v.speedup), (None, None));
        assert_eq!(v.best_cube.as_deref(), Some("cube-rt@256"));

        // Wall times where nothing has timestamps; no verdict without RT.
        let walls = [
            entry("rt", None, 8.0, 0.01),
            entry("cube-rt@64", None, 4.0, 0.01),
        ];
        let v = verdict("lens", &walls).unwrap();
        assert_eq!(
            (v.cube.as_deref(), v.speedup),
            (Some("cube-rt@64"), Some(0.5))
        );
        assert!(verdict("lens", &walls[1..]).is_none());
    }
}
