//! `fisheye compare` as a library call: every setup's time and error (MSE and ꟻLIP) against
//! a many-ray reference, and the verdict of direct ray tracing against the cube maps at equal
//! error (each a family: RT over rays per pixel, cube maps over face sizes); written as JSON,
//! a Markdown table, error maps and time-against-error plots.

use std::fmt::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

use serde::Serialize;

use super::{Progress, Run, Study, file_stem, machine_lines, sig, speed_ratio, write_report};
use crate::compare::{Envelope, ImageError, error_map, flip_error, image_error, pareto_front};
use crate::error::Result;
use crate::gpu::median;
use crate::plot;
use crate::renderer::Method;
use crate::renderer::{FrameTime, Setup};
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
    /// Rays per pixel of a direct method (the most, for adaptive sampling), `None` for cube
    /// maps.
    pub spp: Option<u32>,
    /// Adaptive sampling's threshold, `None` for uniform sampling and cube maps.
    pub threshold: Option<f32>,
    /// The pixel filter of a direct method (`box` or `tent`), `None` for cube maps.
    pub filter: Option<&'static str>,
    /// The rays the last frame's colour took per pixel the lens covers, on average: adaptive
    /// sampling's measured count; `spp` for uniform sampling; `None` for cube maps.
    pub rays_per_pixel: Option<f64>,
    /// Median GPU ms per frame, if timestamps exist.
    pub gpu_ms: Option<f64>,
    /// Median wall ms per frame.
    pub wall_ms: f64,
    /// MSE, PSNR and the rest against the reference.
    pub error: ImageError,
    /// Mean ꟻLIP against the reference.
    pub flip: f64,
    /// Whether no other setup on this lens is as fast and as close to the reference in MSE
    /// (errors within [`crate::compare::EQUAL_ERROR`] count as equal).
    pub pareto: bool,
    /// The same in ꟻLIP.
    pub pareto_flip: bool,
}

impl CompareEntry {
    /// GPU time where timed, else wall time.
    pub fn ms(&self) -> f64 {
        self.gpu_ms.unwrap_or(self.wall_ms)
    }

    /// The error `metric` measures.
    pub fn error_in(&self, metric: Metric) -> f64 {
        match metric {
            Metric::Mse => self.error.mse,
            Metric::Flip => self.flip,
        }
    }
}

/// An error measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Metric {
    /// Mean squared error of displayed values.
    #[serde(rename = "MSE")]
    Mse,
    /// Mean ꟻLIP.
    #[serde(rename = "FLIP")]
    Flip,
}

impl Metric {
    /// As tables print it.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Mse => "MSE",
            Metric::Flip => "ꟻLIP",
        }
    }
}

/// Direct RT's time at one cube-map setup's error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Level {
    /// The cube-map setup on its family's envelope.
    pub cube: String,
    /// Its error (the level).
    pub error: f64,
    /// Its ms per frame.
    pub cube_ms: f64,
    /// The ms per frame direct RT needs for that error (its envelope, interpolated), `None`
    /// if RT does not reach it.
    pub rt_ms: Option<f64>,
    /// `cube_ms / rt_ms`: how many times faster RT is (the goal is at least 4).
    pub speedup: Option<f64>,
}

/// Direct RT against the cube maps at equal error on one lens, in one metric: at the error
/// of every cube-map setup on its family's lower envelope, the time RT's family needs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    /// Lens name.
    pub lens: String,
    /// The error measure.
    pub metric: Metric,
    /// One per cube-map setup on the envelope, fastest first.
    pub levels: Vec<Level>,
    /// The least speed-up over the levels both families reach.
    pub least_speedup: Option<f64>,
    /// When RT reaches less error than any cube map: its least error and that setup.
    pub rt_only: Option<(f64, String)>,
}

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
    /// Timed frames per setup (medians are reported), after a quarter of a second of untimed ones.
    pub frames: usize,
    /// How errors are measured.
    pub method_note: &'static str,
    /// One entry per lens and setup.
    pub entries: Vec<CompareEntry>,
    /// Per lens and metric, RT against the cube maps.
    pub verdicts: Vec<Verdict>,
    /// Setups the adapter could not run, and why.
    pub skipped: Vec<String>,
}

const COMPARE_NOTE: &str = "The reference is direct ray tracing with many stratified rays \
    per pixel, averaged with the same box filter as every RT setup's. Errors are over the \
    pixels valid in both images, on displayed values (clamped to [0, 1], sRGB-encoded): MSE \
    per channel, PSNR = 10 log10(1 / MSE), and mean ꟻLIP (NVIDIA's perceptual difference, \
    0 to 1, at 67 pixels per degree). Mask agreement is the fraction of all pixels whose lens \
    mask matches the reference's. Errors within 5% count as equal on the Pareto front.";

/// Untimed frames before each setup's timed ones: at least one (lavapipe compiles a pipeline
/// at its first dispatch), and more until they fill this many milliseconds of wall time. A GPU
/// lowers its clocks while idle, as it is while the next setup's pipelines compile, and takes
/// a while under load to raise them again: on an H200 after one untimed frame, 4 rays a pixel
/// timed slower than 16 and neighbouring setups' medians moved tenfold.
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

/// Times `frames` frames of every setup at `pose` on every lens, measures each image's error
/// against direct ray tracing at `reference_spp` rays per pixel, and writes the reference's
/// image and each setup's error map into `out`.
pub fn compare(
    study: &Study<'_>,
    pose: &Camera,
    frames: usize,
    reference_spp: u32,
    out: &Path,
    progress: &mut dyn FnMut(Progress<'_>),
) -> Result<CompareReport> {
    let (setups, mut skipped) = study.runnable();
    let frames = frames.max(1);
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
        for &setup in setups {
            let what = format!("{} {}", lens.name, setup.label());
            let renderer = study.renderer(lens, setup)?;
            progress(Progress {
                done,
                total,
                what: &what,
            });
            warm_up(WARM_UP, || {
                renderer.frame(study.ctx, study.scenes, pose).map(drop)
            })?;
            done += 1;
            let mut times = Vec::with_capacity(frames);
            for _ in 0..frames {
                progress(Progress {
                    done,
                    total,
                    what: &what,
                });
                times.push(renderer.frame(study.ctx, study.scenes, pose)?);
                done += 1;
            }
            let colour = renderer.colour(study.ctx)?;
            let covered = colour.iter().filter(|c| c[3] > 0.0).count().max(1) as f64;
            let rays_per_pixel = match renderer.rays_per_pixel(study.ctx)? {
                Some(map) => Some(map.iter().map(|&n| f64::from(n)).sum::<f64>() / covered),
                None => setup.spp().map(f64::from),
            };
            save_png(
                &error_map(size, &reference, &colour),
                &out.join(format!("{stem}.{}.error.png", file_stem(&setup.label()))),
            )?;
            let gpu: Option<Vec<f64>> = times.iter().map(FrameTime::gpu_ms).collect();
            let wall: Vec<f64> = times.iter().map(|t| t.wall_ms).collect();
            entries.push(CompareEntry {
                lens: lens.name.clone(),
                setup: setup.label(),
                method: setup.method.name(),
                cube_size: setup.cube_size(),
                spp: setup.spp(),
                threshold: setup.threshold(),
                filter: setup.cube_size().is_none().then(|| setup.filter.name()),
                rays_per_pixel,
                gpu_ms: gpu.map(|g| median(&g)),
                wall_ms: median(&wall),
                error: image_error(&reference, &colour),
                flip: flip_error(size, &reference, &colour),
                pareto: false,
                pareto_flip: false,
            });
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
        skipped,
    })
}

/// The lower envelope of the entries `family` picks, in `metric`.
fn envelope<'a>(
    entries: impl IntoIterator<Item = &'a CompareEntry>,
    metric: Metric,
    family: fn(&CompareEntry) -> bool,
) -> Envelope {
    let points: Vec<(f64, f64)> = entries
        .into_iter()
        .filter(|e| family(e))
        .map(|e| (e.ms(), e.error_in(metric)))
        .collect();
    Envelope::of(&points)
}

/// Every direct setup (`rt`, `rq`; uniform and adaptive): RT's family in the verdict.
fn is_rt(e: &CompareEntry) -> bool {
    e.cube_size.is_none()
}

/// The direct setups that sample every pixel alike, each pixel its own rays' mean.
fn is_uniform(e: &CompareEntry) -> bool {
    is_rt(e) && e.threshold.is_none() && e.filter == Some("box")
}

fn is_cube(e: &CompareEntry) -> bool {
    e.cube_size.is_some()
}

/// RT's family against the cube maps' at the errors of the cube setups on their envelope;
/// `None` without both families.
fn verdict(lens: &str, entries: &[CompareEntry], metric: Metric) -> Option<Verdict> {
    let rt = envelope(entries, metric, is_rt);
    let cubes = envelope(entries, metric, is_cube);
    let (rt_best, cube_best) = (rt.best()?, cubes.best()?);
    let name_of = |family: fn(&CompareEntry) -> bool, (t, e): (f64, f64)| {
        entries
            .iter()
            .find(|x| family(x) && x.ms() == t && x.error_in(metric) == e)
            .map_or(String::new(), |x| x.setup.clone())
    };
    let levels: Vec<Level> = cubes
        .points
        .iter()
        .map(|&(cube_ms, error)| {
            let rt_ms = rt.time_to_reach(error);
            Level {
                cube: name_of(is_cube, (cube_ms, error)),
                error,
                cube_ms,
                rt_ms,
                speedup: rt_ms.map(|t| cube_ms / t),
            }
        })
        .collect();
    let least_speedup = levels
        .iter()
        .filter_map(|l| l.speedup)
        .min_by(f64::total_cmp);
    Some(Verdict {
        lens: lens.to_string(),
        metric,
        levels,
        least_speedup,
        rt_only: (rt_best.1 < cube_best.1).then(|| (rt_best.1, name_of(is_rt, rt_best))),
    })
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
            "# fisheye compare: {} ({} triangles), {}, {}\n\n{}\n{} Reference: {} rays per pixel. Times are medians of {} frames, after {} ms of untimed ones.\n\n",
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
            "| lens | setup | ms / frame | MSE | PSNR (dB) | ꟻLIP | mask agreement | Pareto (MSE) | Pareto (ꟻLIP) |\n|---|---|---:|---:|---:|---:|---:|:-:|:-:|\n",
        );
        let dot = |on: bool| if on { "●" } else { "" };
        for e in &self.entries {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.2e} | {:.1} | {:.4} | {:.4} | {} | {} |",
                e.lens,
                e.setup,
                sig(e.ms()),
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
        for s in &self.skipped {
            let _ = writeln!(md, "\nSkipped: {s}");
        }
        md
    }

    /// Writes `compare.json`, `compare.md` and per lens `tradeoff.LENS.png` (MSE) and
    /// `tradeoff-flip.LENS.png` into `out`; returns the plots' warning when they could not be
    /// drawn.
    pub fn write(&self, out: &Path) -> Result<Option<String>> {
        let lenses = self.entries.iter().map(|e| e.lens.as_str());
        write_report(out, "compare", self, &self.markdown(), lenses, |lens| {
            for (metric, file, axis) in [
                (Metric::Mse, "tradeoff", "MSE against the reference (log)"),
                (
                    Metric::Flip,
                    "tradeoff-flip",
                    "mean ꟻLIP against the reference (log)",
                ),
            ] {
                self.plot(out, lens, metric, file, axis)?;
            }
            Ok(())
        })
    }

    fn plot(&self, out: &Path, lens: &str, metric: Metric, file: &str, axis: &str) -> Result<()> {
        let entries: Vec<&CompareEntry> = self.entries.iter().filter(|e| e.lens == lens).collect();
        let points: Vec<plot::TradeOff> = entries
            .iter()
            .map(|e| plot::TradeOff {
                label: match e.cube_size {
                    Some(size) => size.to_string(),
                    // `16spp`, `auto:0.1`: the sampling, after the method's name.
                    None => e
                        .setup
                        .split_once('@')
                        .map_or(&*e.setup, |(_, s)| s)
                        .to_string(),
                },
                method: e.method,
                ms: e.ms(),
                error: e.error_in(metric),
                pareto: match metric {
                    Metric::Mse => e.pareto,
                    Metric::Flip => e.pareto_flip,
                },
            })
            .collect();
        let family = |pick| envelope(entries.iter().copied(), metric, pick).points;
        let envelopes = [
            plot::Series {
                label: "direct RT, uniform and adaptive".into(),
                points: family(is_rt),
            },
            plot::Series {
                label: "cube maps over face sizes".into(),
                points: family(is_cube),
            },
            plot::Series {
                label: "direct RT, uniform rays, box filter".into(),
                points: family(is_uniform),
            },
        ];
        let title = format!(
            "{}: {lens}, {} ({})",
            self.run.scene, self.run.size, self.run.machine.adapter
        );
        plot::time_against_error(
            &out.join(format!("{file}.{}.png", file_stem(lens))),
            &title,
            axis,
            &points,
            &envelopes,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The warm-up runs at least one frame, and frames until its time has passed: frames of
    /// at least 5 ms fill 20 ms in no fewer than 4. A frame's error ends it.
    #[test]
    fn the_warm_up_runs_frames_until_its_time_has_passed() {
        assert_eq!(warm_up(Duration::ZERO, || Ok(())).unwrap(), 1);
        let start = Instant::now();
        let frames = warm_up(Duration::from_millis(20), || {
            std::thread::sleep(Duration::from_millis(5));
            Ok(())
        })
        .unwrap();
        assert!(frames >= 4, "{frames} frames");
        assert!(start.elapsed() >= Duration::from_millis(20));
        let mut calls = 0;
        let failed = warm_up(Duration::from_secs(60), || {
            calls += 1;
            Err(crate::error::Error::Option("no adapter".into()))
        });
        assert!(failed.is_err() && calls == 1);
    }

    /// A setup (`rt@Nspp` or `cube-rt@SIZE`) with a time (GPU, else wall), an MSE and a ꟻLIP.
    fn entry(setup: &str, gpu_ms: Option<f64>, wall_ms: f64, mse: f64) -> CompareEntry {
        let error = ImageError {
            mse,
            psnr_db: -10.0 * mse.log10(),
            max_abs: mse.sqrt(),
            mask_agreement: 1.0,
            compared: 1,
        };
        let (method, after) = setup.split_once('@').unwrap();
        let (cube_size, spp) = match after.strip_suffix("spp") {
            Some(spp) => (None, Some(spp.parse().unwrap())),
            None => (Some(after.parse().unwrap()), None),
        };
        CompareEntry {
            lens: "lens".into(),
            setup: setup.into(),
            method: if method == "rt" { "rt" } else { "cube-rt" },
            cube_size,
            spp,
            threshold: None,
            filter: cube_size.is_none().then_some("box"),
            rays_per_pixel: spp.map(f64::from),
            gpu_ms,
            wall_ms,
            error,
            flip: mse.sqrt(),
            pareto: false,
            pareto_flip: false,
        }
    }

    /// RT at 1, 4 and 16 rays per pixel: 10, 40, 160 ms for MSE 4e-3, 1e-3, 2.5e-4 (4x the
    /// time for a quarter of the error), against cube maps whose errors fall slower.
    fn family() -> Vec<CompareEntry> {
        vec![
            entry("rt@1spp", Some(10.0), 50.0, 4e-3),
            entry("rt@4spp", Some(40.0), 90.0, 1e-3),
            entry("rt@16spp", Some(160.0), 200.0, 2.5e-4),
            entry("cube-rt@64", Some(5.0), 1.0, 8e-3),
            entry("cube-rt@128", Some(40.0), 1.0, 2e-3),
            // Dominated by 128: off the envelope, and no level of its own.
            entry("cube-rt@192", Some(60.0), 1.0, 3e-3),
            entry("cube-rt@256", Some(200.0), 1.0, 5e-4),
        ]
    }

    /// The verdict's levels are the cube setups on their envelope; at each, RT's time comes
    /// from its own envelope: its fastest setup above RT's 1-ray error, log-log interpolation
    /// between its setups otherwise.
    #[test]
    fn the_verdict_compares_the_families_at_the_cubes_errors() {
        let v = verdict("lens", &family(), Metric::Mse).unwrap();
        let cubes: Vec<&str> = v.levels.iter().map(|l| l.cube.as_str()).collect();
        assert_eq!(cubes, ["cube-rt@64", "cube-rt@128", "cube-rt@256"]);
        // 8e-3: RT's 1 ray is good enough, 10 ms; 5 ms of cube map is 0.5x.
        assert_eq!(v.levels[0].rt_ms, Some(10.0));
        assert_eq!(v.levels[0].speedup, Some(0.5));
        // 2e-3 lies halfway (in log) between 4e-3 and 1e-3: 20 ms, so 40 / 20 = 2x.
        assert!((v.levels[1].rt_ms.unwrap() - 20.0).abs() < 1e-9);
        assert!((v.levels[1].speedup.unwrap() - 2.0).abs() < 1e-9);
        // 5e-4 halfway between 1e-3 and 2.5e-4: 80 ms, 2.5x.
        assert!((v.levels[2].speedup.unwrap() - 2.5).abs() < 1e-9);
        assert_eq!(v.least_speedup, Some(0.5));
        // RT goes lower than any cube map.
        assert_eq!(v.rt_only, Some((2.5e-4, "rt@16spp".to_string())));
        assert_eq!(v.metric, Metric::Mse);

        // Without RT's 16 rays, the 256 cube's error is one only the cube maps reach.
        let mut fewer = family();
        fewer.remove(2);
        let v = verdict("lens", &fewer, Metric::Mse).unwrap();
        assert_eq!((v.levels[2].rt_ms, v.levels[2].speedup), (None, None));
        assert_eq!(v.rt_only, None);

        // Wall times where nothing has timestamps; no verdict without both families.
        let walls = [
            entry("rt@1spp", None, 8.0, 0.01),
            entry("cube-rt@64", None, 4.0, 0.01),
        ];
        let v = verdict("lens", &walls, Metric::Mse).unwrap();
        assert_eq!(v.levels[0].speedup, Some(0.5));
        assert!(verdict("lens", &walls[1..], Metric::Mse).is_none());
        assert!(verdict("lens", &walls[..1], Metric::Mse).is_none());
    }

    /// The report says each level, what only one family reaches, and the least speed-up.
    #[test]
    fn the_markdown_states_every_level() {
        let entries = family();
        let verdicts = vec![verdict("lens", &entries, Metric::Mse).unwrap()];
        let report = CompareReport {
            run: Run {
                machine: crate::bench::Machine {
                    adapter: "a".into(),
                    driver: "d".into(),
                    cpu: "c".into(),
                    cpus: 2,
                    date: "2026-11-23".into(),
                },
                scene: "s".into(),
                triangles: 1,
                size: "8x8".into(),
            },
            pose: "p".into(),
            reference_spp: 256,
            frames: 1,
            method_note: COMPARE_NOTE,
            entries,
            verdicts,
            skipped: Vec::new(),
        };
        let md = report.markdown();
        assert!(md.contains("| lens | rt@4spp | 40.0 | 1.00e-3 |"), "{md}");
        assert!(md.contains("- lens, MSE (least: 2.00x slower): at cube-rt@64's MSE 8.00e-3 (5.00 ms) RT needs 10.0 ms: 2.00x slower; at cube-rt@128's MSE 2.00e-3 (40.0 ms) RT needs 20.0 ms: 2.00x faster"), "{md}");
        assert!(
            md.contains("only RT reaches below the cube maps' best, down to 2.50e-4 (rt@16spp)")
        );
    }
}
