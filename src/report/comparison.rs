//! `fisheye compare` as a library call: every setup's time and error (MSE and ꟻLIP) against
//! a many-ray reference, and the verdict of direct ray tracing against the cube maps at equal
//! error (each a family: RT over rays per pixel, cube maps over face sizes); written as JSON,
//! a Markdown table, error maps and time-against-error plots.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use serde::Serialize;

use super::{
    Progress, Run, Study, check_frames, file_stem, machine_lines, sig, speed_ratio, write_report,
};
use crate::compare::{ImageError, error_map, flip_error, image_error, pareto_front};
use crate::error::Result;
use crate::gpu::median;
use crate::lens::ImageSize;
use crate::renderer::Method;
use crate::renderer::{FrameTime, Setup};
use crate::scene::Camera;
use crate::threads;
use crate::trace::{colour_image, save_png};

mod verdicts;
pub use verdicts::{Ceiling, CompareEntry, Level, Metric, RayLevel, Verdict};
use verdicts::{ceiling, verdict};

/// What `fisheye compare` measured.
#[derive(Serialize)]
pub struct CompareReport {
    /// Where and on what it ran.
    #[serde(flatten)]
    pub run: Run,
    /// The camera pose compared at.
    pub pose: String,
    /// Rays per pixel of the reference.
    pub reference_spp: u32,
    /// Timed frames per setup (medians are reported), in rounds of a frame of each setup of
    /// a lens (see [`compare`]), after a quarter of a second of untimed rounds.
    pub frames: usize,
    /// How errors are measured.
    pub method_note: &'static str,
    /// One entry per lens and setup.
    pub entries: Vec<CompareEntry>,
    /// Per lens and metric, RT against the cube maps.
    pub verdicts: Vec<Verdict>,
    /// Per lens with both families, the most RT can be faster at the coarsest cube's error.
    pub ceilings: Vec<Ceiling>,
    /// Setups the adapter could not run, and why.
    pub skipped: Vec<String>,
}

const COMPARE_NOTE: &str = "The reference is direct ray tracing with many stratified rays \
    per pixel, averaged with the same box filter as every RT setup's. Errors are over the \
    pixels valid in both images, on displayed values (clamped to [0, 1], sRGB-encoded): MSE \
    per channel, PSNR = 10 log10(1 / MSE), and mean ꟻLIP (NVIDIA's perceptual difference, \
    0 to 1, at 67 pixels per degree). Mask agreement is the fraction of all pixels whose lens \
    mask matches the reference's. Errors within 5% count as equal on the Pareto front.";

/// Untimed rounds (a frame of each setup of a lens) before the timed ones: at least one
/// (lavapipe compiles a pipeline at its first dispatch), and more until they fill this many
/// milliseconds of wall time. A GPU lowers its clocks while idle, as it is while pipelines
/// compile, and takes a while under load to raise them again: on an H200 after one untimed
/// frame a setup, 4 rays a pixel timed slower than 16 and neighbouring setups' medians moved
/// tenfold.
const WARM_UP: Duration = Duration::from_millis(250);

/// Runs `frame` once, then again until `least` has passed since the first began; returns how
/// many times it ran.
fn warm_up(least: Duration, mut frame: impl FnMut() -> Result<()>) -> Result<usize> {
    let start = Instant::now();
    let mut frames = 0;
    while frames == 0 || start.elapsed() < least {
        frame()?;
        frames += 1;
    }
    Ok(frames)
}

/// The setups (of `n`) in the order round `r` times them: each once, from setup `r` on
/// (wrapping round), so that any `n` rounds in a row time each setup once in every place.
fn round_order(r: usize, n: usize) -> impl Iterator<Item = usize> {
    (0..n).map(move |k| (r + k) % n)
}

/// Times `frames` frames of every setup at `pose` on every lens, measures each image's error
/// against direct ray tracing at `reference_spp` rays per pixel, and writes the reference's
/// image and each setup's error map into `out`.
///
/// A lens's setups are made first (each renders a frame, which compiles its pipelines), then
/// timed in rounds, a frame of each in turn (`round_order`): a machine whose speed drifts
/// while it runs slows every setup alike, so their ratios hold. Timed one setup after
/// another, they did not: lavapipe's speed moves by up to 1.5× from one minute to the next,
/// and four runs in a row of one small `compare` put its least ratio between 1.42× slower and
/// 1.50× faster (the book's Speed against error). Every setup of a lens is held at once:
/// their memory adds up. `frames` 0 is an error.
pub fn compare(
    study: &Study<'_>,
    pose: &Camera,
    frames: usize,
    reference_spp: u32,
    out: &Path,
    progress: &mut dyn FnMut(Progress<'_>),
) -> Result<CompareReport> {
    check_frames(frames)?;
    let (setups, mut skipped) = study.runnable();
    // Each lens's setups, less those it cannot run (listed with why).
    let per_lens: Vec<Vec<Setup>> = study
        .lenses
        .iter()
        .map(|lens| {
            setups
                .iter()
                .filter(|setup| match Study::cannot(lens, setup) {
                    Some(why) => {
                        skipped.push(why);
                        false
                    }
                    None => true,
                })
                .copied()
                .collect()
        })
        .collect();
    let total: usize = per_lens.iter().map(|s| s.len() * (frames + 1) + 1).sum();
    let mut done = 0;
    let mut entries = Vec::new();
    let mut verdicts = Vec::new();
    let mut ceilings = Vec::new();
    for (lens, setups) in study.lenses.iter().zip(&per_lens) {
        let size = lens.camera.size;
        let stem = file_stem(&lens.name);
        let what = format!("{} reference, {reference_spp} rays per pixel", lens.name);
        progress(Progress {
            done,
            total,
            what: &what,
        });
        let reference = study.renderer(lens, Setup::direct(Method::Rt, reference_spp))?;
        reference.frame(study.ctx, study.scenes, pose)?;
        let reference = reference.colour(study.ctx)?;
        save_png(
            &colour_image(size, &reference),
            &out.join(format!("{stem}.reference.png")),
        )?;
        done += 1;
        let first = entries.len();
        let mut renderers = Vec::with_capacity(setups.len());
        for &setup in setups {
            let what = format!("{} {}", lens.name, setup.label());
            progress(Progress {
                done,
                total,
                what: &what,
            });
            let renderer = study.renderer(lens, setup)?;
            renderer.frame(study.ctx, study.scenes, pose)?;
            renderers.push(renderer);
            done += 1;
        }
        // Round `r`: a frame of each setup in turn (`round_order`), as (setup, its time).
        let round = |r: usize| -> Result<Vec<(usize, FrameTime)>> {
            round_order(r, renderers.len())
                .map(|i| Ok((i, renderers[i].frame(study.ctx, study.scenes, pose)?)))
                .collect()
        };
        if !renderers.is_empty() {
            let mut rounds = 0;
            warm_up(WARM_UP, || {
                rounds += 1;
                round(rounds).map(drop)
            })?;
        }
        let mut times = vec![Vec::with_capacity(frames); setups.len()];
        for r in 0..frames {
            let what = format!("{} round {} of {frames}", lens.name, r + 1);
            progress(Progress {
                done,
                total,
                what: &what,
            });
            for (i, time) in round(r)? {
                times[i].push(time);
            }
            done += setups.len();
        }
        // Each setup's last frame is read back and measured against the reference, a group
        // of setups at a time on every thread at once (ꟻLIP takes about half a second for a
        // 1024×768 image on one core); a group holds as many images as there are threads, and
        // no more than MEASURED_AT_ONCE.
        let what = format!("{} errors against the reference", lens.name);
        progress(Progress {
            done,
            total,
            what: &what,
        });
        let group_size = threads::available().min(MEASURED_AT_ONCE);
        let mut timed = setups.iter().zip(&renderers).zip(times);
        loop {
            let mut group = Vec::new();
            for ((&setup, renderer), times) in timed.by_ref().take(group_size) {
                let colour = renderer.colour(study.ctx)?;
                let covered = colour.iter().filter(|c| c[3] > 0.0).count().max(1) as f64;
                let rays_per_pixel = match renderer.rays_per_pixel(study.ctx)? {
                    Some(map) => Some(map.iter().map(|&n| f64::from(n)).sum::<f64>() / covered),
                    None => setup.spp().map(f64::from),
                };
                let samples = match renderer.cube() {
                    Some(cube) => cube.texels_rendered() as f64,
                    None => rays_per_pixel.unwrap_or(0.0) * covered,
                };
                let error_path =
                    out.join(format!("{stem}.{}.error.png", file_stem(&setup.label())));
                group.push(Measured {
                    setup,
                    times,
                    rays_per_pixel,
                    samples,
                    colour,
                    error_path,
                    errors: None,
                });
            }
            if group.is_empty() {
                break;
            }
            threads::in_parts(&mut group, |_, part| {
                for m in part {
                    m.measure(size, &reference);
                }
            });
            for m in group {
                entries.push(m.entry(&lens.name)?);
            }
        }
        let lens_entries = &mut entries[first..];
        for metric in [Metric::Mse, Metric::Flip] {
            let points: Vec<(f64, f64)> = lens_entries
                .iter()
                .map(|e| (e.ms(), e.error_in(metric)))
                .collect();
            for (e, on) in lens_entries.iter_mut().zip(pareto_front(&points)) {
                match metric {
                    Metric::Mse => e.pareto = on,
                    Metric::Flip => e.pareto_flip = on,
                }
            }
            verdicts.extend(verdict(&lens.name, lens_entries, metric));
        }
        ceilings.extend(ceiling(&lens.name, lens_entries));
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
        reference_spp,
        frames,
        method_note: COMPARE_NOTE,
        entries,
        verdicts,
        ceilings,
        skipped,
    })
}

/// The most setups' frames `compare` holds at once while it measures them (a 3840×2160
/// frame's colour alone takes 133 MB, and ꟻLIP makes images of its own as large).
const MEASURED_AT_ONCE: usize = 16;

/// A setup's last frame, read back, and its errors against the reference once measured.
struct Measured {
    setup: Setup,
    times: Vec<FrameTime>,
    rays_per_pixel: Option<f64>,
    samples: f64,
    colour: Vec<[f32; 4]>,
    /// Where its error map goes.
    error_path: PathBuf,
    /// Its MSE and the rest, and its mean ꟻLIP, once `measure` has run (or why the error
    /// map could not be written).
    errors: Option<Result<(ImageError, f64)>>,
}

impl Measured {
    /// Measures the frame against `reference` and writes its error map.
    fn measure(&mut self, size: ImageSize, reference: &[[f32; 4]]) {
        let written = save_png(&error_map(size, reference, &self.colour), &self.error_path);
        self.errors = Some(written.map(|()| {
            (
                image_error(reference, &self.colour),
                flip_error(size, reference, &self.colour),
            )
        }));
    }

    /// The report's entry for it on lens `lens` (not yet marked on the Pareto fronts).
    fn entry(self, lens: &str) -> Result<CompareEntry> {
        let (error, flip) = self.errors.expect("measured before its entry is made")?;
        let gpu: Option<Vec<f64>> = self.times.iter().map(FrameTime::gpu_ms).collect();
        let wall: Vec<f64> = self.times.iter().map(|t| t.wall_ms).collect();
        let setup = self.setup;
        Ok(CompareEntry {
            lens: lens.to_string(),
            setup: setup.label(),
            method: setup.method.name(),
            cube_size: setup.cube_size(),
            spp: setup.spp(),
            threshold: setup.threshold(),
            filter: setup.cube_size().is_none().then(|| setup.filter.name()),
            rays_per_pixel: self.rays_per_pixel,
            samples: self.samples,
            gpu_ms: gpu.map(|g| median(&g)),
            wall_ms: median(&wall),
            error,
            flip,
            pareto: false,
            pareto_flip: false,
        })
    }
}

/// A count of rays or texels to three significant figures, in thousands (k) or millions (M)
/// above a thousand.
fn count(n: f64) -> String {
    if n >= 1e6 {
        format!("{} M", sig(n / 1e6))
    } else if n >= 1e3 {
        format!("{} k", sig(n / 1e3))
    } else {
        sig(n)
    }
}

/// A frame's time over its rays or texels, in ns (what one costs, bookkeeping and resampling
/// included); a dash for a frame that takes none.
fn per_sample_ns(ms: f64, samples: f64) -> String {
    if samples > 0.0 {
        sig(ms * 1e6 / samples)
    } else {
        "—".into()
    }
}

/// How many times fewer rays RT traces than the cube texels (`ratio` = texels / rays).
fn rays_ratio(ratio: f64) -> String {
    if ratio >= 1.0 {
        format!("{ratio:.2}x fewer")
    } else {
        format!("{:.2}x more", 1.0 / ratio)
    }
}

/// An error in the tables: MSE in scientific notation, ꟻLIP with four decimals.
fn error_text(metric: Metric, e: f64) -> String {
    match metric {
        Metric::Mse => format!("{e:.2e}"),
        Metric::Flip => format!("{e:.4}"),
    }
}

impl CompareReport {
    /// The Markdown table: a row per lens and setup, then the verdicts.
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "# fisheye compare: {} ({} triangles), {}, {}\n\n{}\n{} Reference: {} rays per pixel. Times are medians of {} frames a setup, timed in rounds (a frame of each setup in turn, so that a drift in the machine's speed slows all alike), after {} ms of untimed rounds.\n\n",
            self.run.scene,
            self.run.triangles,
            self.run.size,
            self.pose,
            machine_lines(&self.run.machine),
            self.method_note,
            self.reference_spp,
            self.frames,
            WARM_UP.as_millis()
        );
        md.push_str(
            "| lens | setup | ms / frame | rays or texels | ns / ray or texel | MSE | PSNR (dB) | ꟻLIP | mask agreement | Pareto (MSE) | Pareto (ꟻLIP) |\n|---|---|---:|---:|---:|---:|---:|---:|---:|:-:|:-:|\n",
        );
        let dot = |on: bool| if on { "●" } else { "" };
        for e in &self.entries {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.2e} | {:.1} | {:.4} | {:.4} | {} | {} |",
                e.lens,
                e.setup,
                sig(e.ms()),
                count(e.samples),
                per_sample_ns(e.ms(), e.samples),
                e.error.mse,
                e.error.psnr_db,
                e.flip,
                e.error.mask_agreement,
                dot(e.pareto),
                dot(e.pareto_flip)
            );
        }
        md.push_str(
            "\nDirect RT against the cube maps at equal error: at each cube-map setup on its \
             family's lower envelope, the time RT's family (over rays per pixel) needs for that \
             error, interpolated in log time against log error (goal: RT at least 4x faster at \
             every error both reach):\n\n",
        );
        for v in &self.verdicts {
            let metric = v.metric.name();
            let mut parts: Vec<String> = v
                .levels
                .iter()
                .map(|l| match (l.rt_ms, l.speedup) {
                    (Some(rt), Some(s)) => format!(
                        "at {}'s {metric} {} ({} ms) RT needs {} ms: {}",
                        l.cube,
                        error_text(v.metric, l.error),
                        sig(l.cube_ms),
                        sig(rt),
                        speed_ratio(s)
                    ),
                    _ => format!(
                        "{}'s {metric} {} ({} ms) only the cube map reaches",
                        l.cube,
                        error_text(v.metric, l.error),
                        sig(l.cube_ms)
                    ),
                })
                .collect();
            if let Some((e, setup)) = &v.rt_only {
                parts.push(format!(
                    "only RT reaches below the cube maps' best, down to {} ({setup})",
                    error_text(v.metric, *e)
                ));
            }
            let least = v.least_speedup.map_or("no error both reach".into(), |s| {
                format!("least: {}", speed_ratio(s))
            });
            let _ = writeln!(md, "- {}, {metric} ({least}): {}", v.lens, parts.join("; "));
        }
        if !self.ceilings.is_empty() {
            md.push_str(
                "\nThe most RT can be faster at the error of the cube maps' fastest setup, \
                 whatever its sampling reaches there: that setup's time over RT's fastest frame \
                 (at any error). No least speed-up above can exceed it; under 4, only cheaper RT \
                 frames can meet the goal:\n\n",
            );
        }
        for c in &self.ceilings {
            let _ = writeln!(
                md,
                "- {}: {} ({} ms) over {} ({} ms): at most {}",
                c.lens,
                c.cube,
                sig(c.cube_ms),
                c.rt,
                sig(c.rt_ms),
                speed_ratio(c.ratio)
            );
        }
        if self.verdicts.iter().any(|v| !v.rays.is_empty()) {
            md.push_str(
                "\nIn samples, against the traced cube (`cube-rt`), whose face texels are rays \
                 shaded by the same kernels as RT's: at each traced cube setup on its envelope \
                 in texels against error, the primary rays RT's family needs for that error, \
                 interpolated in log rays against log error. Where a ray costs the same in both, \
                 this is the speed-up RT's sampling allows, on any GPU: the 4x goal needs at \
                 least 4x fewer rays.\n\n",
            );
        }
        for v in self.verdicts.iter().filter(|v| !v.rays.is_empty()) {
            let metric = v.metric.name();
            let parts: Vec<String> = v
                .rays
                .iter()
                .map(|l| {
                    let at = format!(
                        "{}'s {metric} {} ({} texels)",
                        l.cube,
                        error_text(v.metric, l.error),
                        count(l.texels)
                    );
                    match (l.rt_rays, l.fewer) {
                        (Some(r), Some(f)) => {
                            format!("at {at} RT needs {} rays: {}", count(r), rays_ratio(f))
                        }
                        _ => format!("{at} only the cube map reaches"),
                    }
                })
                .collect();
            let least = v.least_fewer.map_or("no error both reach".into(), |f| {
                format!("least: {}", rays_ratio(f))
            });
            let _ = writeln!(md, "- {}, {metric} ({least}): {}", v.lens, parts.join("; "));
        }
        for s in &self.skipped {
            let _ = writeln!(md, "\nSkipped: {s}");
        }
        md
    }

    /// Writes `compare.json`, `compare.md` and per lens and metric the plots of time against
    /// error (`tradeoff.LENS.png`, `tradeoff-flip.LENS.png`) and, with traced cubes, of rays
    /// against error (`rays.LENS.png`, `rays-flip.LENS.png`) into `out`; returns the plots'
    /// warning when they could not be drawn.
    pub fn write(&self, out: &Path) -> Result<Option<String>> {
        let lenses = self.entries.iter().map(|e| e.lens.as_str());
        write_report(out, "compare", self, &self.markdown(), lenses, |lens| {
            self.plots(out, lens)
        })
    }
}

mod plots;
#[cfg(test)]
mod tests;
