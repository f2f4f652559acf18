//! `fisheye bench` as a library call: frames timed along a path for every setup and lens,
//! written as JSON, a Markdown table and fps plots.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use super::{
    Progress, Run, Study, check_frames, file_stem, is_pinhole, machine_lines, sig, write_report,
};
use crate::bench::{FrameStats, Memory, PathKind, camera_path};
use crate::error::Result;
use crate::gpu::median;
use crate::plot;
use crate::renderer::{FrameTime, Pass};

/// One setup's frames along the path.
#[derive(Serialize)]
pub struct BenchEntry {
    /// Lens name.
    pub lens: String,
    /// Setup label (`rt@1spp`, `cube-forward@512`).
    pub setup: String,
    /// Method name.
    pub method: &'static str,
    /// Cube face size, `None` for direct methods.
    pub cube_size: Option<u32>,
    /// Rays per pixel of a direct method, `None` for cube maps.
    pub spp: Option<u32>,
    /// The timed passes, in the order of each frame's `passes_ms`.
    pub passes: Vec<Pass>,
    /// Statistics of the GPU time per frame (the sum of the passes), if timestamps exist.
    pub gpu: Option<FrameStats>,
    /// Statistics of the wall time per frame.
    pub wall: FrameStats,
    /// Median GPU ms of each pass.
    pub pass_median_ms: Option<Vec<f64>>,
    /// Median GPU nanoseconds per ray of each pass that traces rays (`None` where it traced
    /// none, and for cube maps or without timestamps): what a ray costs in each stage of
    /// adaptive sampling against a uniform frame's.
    pub pass_median_ns_per_ray: Option<Vec<Option<f64>>>,
    /// Every timed frame.
    pub frames: Vec<FrameTime>,
    /// Memory in use before the first timed frame (after the warm-up).
    pub memory_start: Memory,
    /// Memory in use after the last frame: equal to the start's in a run that leaks nothing.
    pub memory_end: Memory,
}

impl BenchEntry {
    /// The statistics plots and tables use: GPU time where timed, else wall time.
    pub fn stats(&self) -> &FrameStats {
        self.gpu.as_ref().unwrap_or(&self.wall)
    }
}

/// What `fisheye bench` measured.
#[derive(Serialize)]
pub struct BenchReport {
    /// Where and on what it ran.
    #[serde(flatten)]
    pub run: Run,
    /// The camera path.
    pub path: String,
    /// Untimed frames rendered first, per setup.
    pub warmup: usize,
    /// How the numbers were taken.
    pub method_note: &'static str,
    /// One entry per lens and setup.
    pub entries: Vec<BenchEntry>,
    /// Setups the adapter could not run, and why.
    pub skipped: Vec<String>,
}

const BENCH_NOTE: &str = "Per frame: the pose is set, all passes are recorded into one command \
    buffer and submitted, and the CPU waits for the GPU to finish (wall time). GPU time is the \
    sum of the timed passes' timestamp spans. Shadow maps of rasterized faces are rendered \
    once per scene (the lights do not move) and are not in the frame time.";

/// Runs `frames` frames of every setup on every lens along `path`, after `warmup` untimed
/// frames each (`frames` 0 is an error).
pub fn bench(
    study: &Study<'_>,
    path: PathKind,
    frames: usize,
    warmup: usize,
    progress: &mut dyn FnMut(Progress<'_>),
) -> Result<BenchReport> {
    check_frames(frames)?;
    let poses = camera_path(study.scene, path, frames)?;
    let (setups, mut skipped) = study.runnable();
    let mut runs = Vec::new();
    for lens in study.lenses {
        for &setup in &setups {
            match Study::cannot(lens, &setup) {
                Some(why) => skipped.push(why),
                None => runs.push((lens, setup)),
            }
        }
    }
    let total = runs.len() * (frames + warmup);
    let mut done = 0;
    let mut entries = Vec::new();
    for (lens, setup) in runs {
        let what = format!("{} {}", lens.name, setup.label());
        progress(Progress {
            done,
            total,
            what: &what,
        });
        let renderer = study.renderer(lens, setup)?;
        let mut timed = Vec::with_capacity(frames);
        let mut memory_start = None;
        // The warm-up frames at the path's first pose, then the path.
        for k in 0..warmup + frames {
            if k == warmup {
                memory_start = Some(Memory::now(study.ctx));
            }
            let pose = &poses[k.saturating_sub(warmup)];
            let time = renderer.frame(study.ctx, study.scenes, pose)?;
            if k >= warmup {
                timed.push(time);
            }
            done += 1;
            progress(Progress {
                done,
                total,
                what: &what,
            });
        }
        let memory_start = memory_start.expect("at least one timed frame");
        let wall: Vec<f64> = timed.iter().map(|t| t.wall_ms).collect();
        let gpu: Option<Vec<f64>> = timed.iter().map(FrameTime::gpu_ms).collect();
        let passes = renderer.passes().to_vec();
        let pass_median_ms = timed
            .iter()
            .map(|t| t.passes_ms.clone())
            .collect::<Option<Vec<_>>>()
            .map(|per_frame| {
                (0..passes.len())
                    .map(|p| median(&per_frame.iter().map(|f| f[p]).collect::<Vec<_>>()))
                    .collect()
            });
        let pass_median_ns_per_ray = timed
            .iter()
            .map(|t| t.passes_ms.clone().zip(t.passes_rays.clone()))
            .collect::<Option<Vec<_>>>()
            .map(|per_frame| {
                (0..passes.len())
                    .map(|p| {
                        let ns: Vec<f64> = per_frame
                            .iter()
                            .filter(|(_, rays)| rays[p] > 0)
                            .map(|(ms, rays)| ms[p] * 1e6 / rays[p] as f64)
                            .collect();
                        (!ns.is_empty()).then(|| median(&ns))
                    })
                    .collect()
            });
        entries.push(BenchEntry {
            lens: lens.name.clone(),
            setup: setup.label(),
            method: setup.method.name(),
            cube_size: setup.cube_size(),
            spp: setup.spp(),
            passes,
            gpu: gpu.as_deref().and_then(FrameStats::of),
            wall: FrameStats::of(&wall).expect("at least one frame"),
            pass_median_ms,
            pass_median_ns_per_ray,
            frames: timed,
            memory_start,
            memory_end: Memory::now(study.ctx),
        });
    }
    Ok(BenchReport {
        run: study.run(),
        path: format!("{path:?} ({frames} frames)").to_lowercase(),
        warmup,
        method_note: BENCH_NOTE,
        entries,
        skipped,
    })
}

impl BenchReport {
    /// The Markdown table: a row per lens and setup, then the fisheye overhead of direct RT.
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "# fisheye bench: {} ({} triangles), {}, path {}, {} warm-up frames\n\n{}\n{}\n\n",
            self.run.scene,
            self.run.triangles,
            self.run.size,
            self.path,
            self.warmup,
            machine_lines(&self.run.machine),
            self.method_note
        );
        let clock = if self.entries.iter().all(|e| e.gpu.is_some()) {
            "GPU"
        } else {
            "wall"
        };
        let _ = writeln!(
            md,
            "| lens | setup | mean fps ({clock}) | fps variance | min fps | max fps | p50 ms | p99 ms | wall mean fps | median ms per pass (ns per ray; adaptive sampling's listing passes together, and their share) |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---|"
        );
        for e in &self.entries {
            let s = e.stats();
            let passes = match &e.pass_median_ms {
                Some(ms) => {
                    let timed: Vec<String> = e
                        .passes
                        .iter()
                        .zip(ms)
                        .enumerate()
                        .map(|(k, (p, ms))| {
                            let per_ray = e.pass_median_ns_per_ray.as_ref().and_then(|n| n[k]);
                            match per_ray {
                                Some(ns) => {
                                    format!("{} {} ({} ns/ray)", p.name(), sig(*ms), sig(ns))
                                }
                                None => format!("{} {}", p.name(), sig(*ms)),
                            }
                        })
                        .collect();
                    let listing =
                        Pass::bookkeeping(&e.passes, ms).map_or(String::new(), |(spent, share)| {
                            format!("; listing {} ({:.0} %)", sig(spent), 100.0 * share)
                        });
                    timed.join(", ") + &listing
                }
                None => "untimed".into(),
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {passes} |",
                e.lens,
                e.setup,
                sig(s.mean_fps),
                sig(s.fps_variance),
                sig(s.min_fps),
                sig(s.max_fps),
                sig(s.p50_ms),
                sig(s.p99_ms),
                sig(e.wall.mean_fps),
            );
        }
        md.push_str("\nMemory before the first timed frame and after the last (resident set; device memory wgpu's allocator holds):\n\n");
        let mib = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{v:.1}"));
        for e in &self.entries {
            let _ = writeln!(
                md,
                "- {} {}: resident {} → {} MiB, GPU {} → {} MiB",
                e.lens,
                e.setup,
                mib(e.memory_start.resident_mib),
                mib(e.memory_end.resident_mib),
                mib(e.memory_start.gpu_mib),
                mib(e.memory_end.gpu_mib)
            );
        }
        let overheads = self.fisheye_overheads();
        if !overheads.is_empty() {
            md.push_str(
                "\nFisheye overhead of direct ray tracing (median frame time over the pinhole's; goal ≤ 1.05):\n\n",
            );
            for (lens, ratio) in overheads {
                let _ = writeln!(md, "- {lens}: {ratio:.3}");
            }
        }
        for s in &self.skipped {
            let _ = writeln!(md, "\nSkipped: {s}");
        }
        md
    }

    /// Per non-pinhole lens, direct RT's median frame time over the pinhole lens's (the
    /// lens named `pinhole` or starting `rectilinear`), at the fewest rays per pixel measured.
    pub fn fisheye_overheads(&self) -> Vec<(String, f64)> {
        let Some(label) = self
            .entries
            .iter()
            .filter(|e| e.method == "rt")
            .min_by_key(|e| e.spp)
            .map(|e| e.setup.clone())
        else {
            return Vec::new();
        };
        let rt = |lens: &str| {
            self.entries
                .iter()
                .find(|e| e.lens == lens && e.setup == label)
                .map(|e| e.stats().p50_ms)
        };
        let Some(pinhole) = self
            .entries
            .iter()
            .find(|e| is_pinhole(&e.lens))
            .and_then(|e| rt(&e.lens))
        else {
            return Vec::new();
        };
        let mut lenses: Vec<&str> = self.entries.iter().map(|e| e.lens.as_str()).collect();
        lenses.dedup();
        lenses
            .into_iter()
            .filter(|l| !is_pinhole(l))
            .filter_map(|l| Some((l.to_string(), rt(l)? / pinhole)))
            .collect()
    }

    /// Writes `bench.json`, `bench.md` and one `fps.LENS.png` per lens into `out`; returns
    /// the plots' warning when they could not be drawn.
    pub fn write(&self, out: &Path) -> Result<Option<String>> {
        let lenses = self.entries.iter().map(|e| e.lens.as_str());
        write_report(out, "bench", self, &self.markdown(), lenses, |lens| {
            let series: Vec<plot::Series> = self
                .entries
                .iter()
                .filter(|e| e.lens == lens)
                .map(|e| plot::Series {
                    label: e.setup.clone(),
                    points: e
                        .frames
                        .iter()
                        .enumerate()
                        .map(|(k, f)| (k as f64, 1e3 / f.gpu_ms().unwrap_or(f.wall_ms)))
                        .collect(),
                })
                .collect();
            let title = format!(
                "{}: {lens}, {} ({})",
                self.run.scene, self.run.size, self.run.machine.adapter
            );
            plot::fps_along_path(
                &out.join(format!("fps.{}.png", file_stem(lens))),
                &title,
                "frames per second (GPU time)",
                &series,
            )
        })
    }
}
