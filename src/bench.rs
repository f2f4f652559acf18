//! What measurements need beside the frames ([`crate::renderer::Offscreen`] renders and times
//! them): camera paths to time frames along ([`camera_path`]), the statistics the thesis
//! reports ([`FrameStats`]), the memory in use ([`Memory`]) and the machine ([`Machine`]).
//! `fisheye bench` and `fisheye compare` are built on it; [`crate::compare`] measures the
//! error.

use glam::DVec3;
use serde::Serialize;

use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::scene::{Camera, Scene};

/// Memory in use, for long runs: the process's resident set and the device memory wgpu's
/// allocator holds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Memory {
    /// Resident set size in MiB (`VmRSS` of `/proc/self/status`; `None` off Linux). On a CPU
    /// driver it includes the "device" memory.
    pub resident_mib: Option<f64>,
    /// Device memory allocated through wgpu's allocator, in MiB (`None` where the backend
    /// gives no allocator report).
    pub gpu_mib: Option<f64>,
}

impl Memory {
    /// The memory in use now.
    pub fn now(ctx: &GpuContext) -> Memory {
        let resident_mib = std::fs::read_to_string("/proc/self/status")
            .ok()
            .and_then(|status| {
                let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
                let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
                Some(kib / 1024.0)
            });
        let gpu_mib = ctx
            .device
            .generate_allocator_report()
            .map(|r| r.total_allocated_bytes as f64 / 1_048_576.0);
        Memory {
            resident_mib,
            gpu_mib,
        }
    }
}

/// Which camera path to time frames along.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathKind {
    /// The scene's own keyframes (scene files' `[[camera.path]]`; the built-in scenes' walks).
    Walk,
    /// A full circle around the camera's look-at point, at the camera's height and distance:
    /// for open scenes (it passes through the walls of a room).
    Orbit,
}

/// `frames` poses along `kind`'s path in `scene`: the keyframes' ends included, equally
/// spaced in the path parameter. A walk needs the scene to have keyframes.
pub fn camera_path(scene: &Scene, kind: PathKind, frames: usize) -> Result<Vec<Camera>> {
    let s = |k: usize| k as f64 / frames.saturating_sub(1).max(1) as f64;
    match kind {
        PathKind::Walk => {
            if scene.camera_path.is_empty() {
                return Err(Error::Scene(
                    "this scene has no camera path (keyframes); use the orbit path".into(),
                ));
            }
            Ok((0..frames).map(|k| scene.camera_on_path(s(k))).collect())
        }
        PathKind::Orbit => {
            let c = scene.camera;
            let offset = c.position - c.look_at;
            let radius = offset.x.hypot(offset.z);
            if radius < 1e-9 {
                return Err(Error::Scene(
                    "the camera looks straight up or down: no orbit around its look-at point"
                        .into(),
                ));
            }
            let start = offset.z.atan2(offset.x);
            Ok((0..frames)
                .map(|k| {
                    let a = start + std::f64::consts::TAU * s(k);
                    let position =
                        c.look_at + DVec3::new(radius * a.cos(), offset.y, radius * a.sin());
                    Camera { position, ..c }
                })
                .collect())
        }
    }
}

/// Frame-time statistics of one setup, as the thesis's Table 1 (mean frame rate) and more.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameStats {
    /// Number of frames.
    pub frames: usize,
    /// Frames per second over the whole run: frames / total time.
    pub mean_fps: f64,
    /// Variance of the per-frame rate (1000 / ms), in fps².
    pub fps_variance: f64,
    /// Slowest frame's rate.
    pub min_fps: f64,
    /// Fastest frame's rate.
    pub max_fps: f64,
    /// Median frame time, ms.
    pub p50_ms: f64,
    /// 99th-percentile frame time (nearest rank), ms.
    pub p99_ms: f64,
}

impl FrameStats {
    /// The statistics of frame times in ms; `None` for no frames.
    pub fn of(ms: &[f64]) -> Option<Self> {
        if ms.is_empty() {
            return None;
        }
        let n = ms.len() as f64;
        let fps: Vec<f64> = ms.iter().map(|t| 1e3 / t).collect();
        let mean = fps.iter().sum::<f64>() / n;
        let mut sorted = ms.to_vec();
        sorted.sort_by(f64::total_cmp);
        // Nearest rank: the smallest value with at least p of the samples at or below it.
        let rank = |p: f64| sorted[((p * n).ceil() as usize).clamp(1, ms.len()) - 1];
        Some(Self {
            frames: ms.len(),
            mean_fps: 1e3 * n / ms.iter().sum::<f64>(),
            fps_variance: fps.iter().map(|f| (f - mean).powi(2)).sum::<f64>() / n,
            min_fps: 1e3 / sorted[ms.len() - 1],
            max_fps: 1e3 / sorted[0],
            p50_ms: rank(0.5),
            p99_ms: rank(0.99),
        })
    }
}

/// The machine a measurement ran on, for the reports.
#[derive(Clone, Debug, Serialize)]
pub struct Machine {
    /// Adapter name, backend and type.
    pub adapter: String,
    /// Driver name and version.
    pub driver: String,
    /// The CPU's model name (from `/proc/cpuinfo` on Linux), else the architecture.
    pub cpu: String,
    /// Logical CPUs available.
    pub cpus: usize,
    /// The UTC date of the run, `YYYY-MM-DD`.
    pub date: String,
}

impl Machine {
    /// This machine and `ctx`'s adapter, today.
    pub fn describe(ctx: &GpuContext) -> Self {
        let info = ctx.adapter_info();
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|text| {
                text.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split_once(':'))
                    .map(|(_, name)| name.trim().to_string())
            })
            .unwrap_or_else(|| std::env::consts::ARCH.to_string());
        let days = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs() / 86_400);
        Self {
            adapter: ctx.adapter_name(),
            driver: format!("{} {}", info.driver, info.driver_info)
                .trim()
                .to_string(),
            cpu,
            cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
            date: civil_date(days as i64),
        }
    }
}

/// `YYYY-MM-DD` of a day counted from 1970-01-01, proleptic Gregorian calendar (Howard
/// Hinnant's `civil_from_days`, from "chrono-Compatible Low-Level Date Algorithms").
fn civil_date(days: i64) -> String {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_stats_follow_their_definitions() {
        // 10, 20, 40 ms: 3 frames in 70 ms.
        let s = FrameStats::of(&[20.0, 10.0, 40.0]).unwrap();
        assert!((s.mean_fps - 3000.0 / 70.0).abs() < 1e-12);
        assert_eq!((s.min_fps, s.max_fps), (25.0, 100.0));
        // Rates 50, 100, 25: mean 175 / 3.
        let mean: f64 = 175.0 / 3.0;
        let var = ((50.0 - mean).powi(2) + (100.0 - mean).powi(2) + (25.0 - mean).powi(2)) / 3.0;
        assert!((s.fps_variance - var).abs() < 1e-9);
        assert_eq!((s.p50_ms, s.p99_ms), (20.0, 40.0));
        // Nearest rank on 100 samples: p99 is the 99th smallest.
        let ms: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = FrameStats::of(&ms).unwrap();
        assert_eq!((s.p50_ms, s.p99_ms), (50.0, 99.0));
        assert!(FrameStats::of(&[]).is_none());
    }

    #[test]
    fn civil_dates_match_known_days() {
        assert_eq!(civil_date(0), "1970-01-01");
        assert_eq!(civil_date(11_016), "2000-02-29");
        assert_eq!(civil_date(20_596), "2026-05-23");
        assert_eq!(civil_date(-1), "1969-12-31");
    }

    #[test]
    fn paths_pass_through_their_keyframes_and_orbits_keep_their_radius() {
        let scene = crate::scene::builtin::scene("few-detailed").unwrap();
        let walk = camera_path(&scene, PathKind::Walk, 5).unwrap();
        assert_eq!(walk[0], scene.camera_path[0]);
        assert_eq!(walk[4], *scene.camera_path.last().unwrap());
        let orbit = camera_path(&scene, PathKind::Orbit, 9).unwrap();
        let c = scene.camera;
        let radius = |p: DVec3| (p - c.look_at).length();
        for pose in &orbit {
            assert!((radius(pose.position) - radius(c.position)).abs() < 1e-12);
            assert_eq!(pose.position.y, c.position.y);
        }
        // A full circle: back where it started, and the halfway pose opposite it.
        assert!((orbit[8].position - c.position).length() < 1e-9);
        let across = orbit[4].position - c.look_at;
        let start = c.position - c.look_at;
        assert!((across.x + start.x).abs() < 1e-9 && (across.z + start.z).abs() < 1e-9);
        let grid = crate::scene::builtin::scene("grid").unwrap();
        assert!(camera_path(&grid, PathKind::Walk, 3).is_err());
    }
}
