//! What each way of making a lens image costs: the methods ([`Method`]) set up on one scene and
//! lens ([`Renderer`]), frames timed per pass by GPU timestamps and by the wall clock
//! ([`FrameTime`]), camera paths to time them along ([`camera_path`]) and the statistics the
//! thesis reports ([`FrameStats`]). `fisheye bench` and `fisheye compare` are built on it;
//! [`crate::compare`] measures the error.

use glam::DVec3;
use serde::Serialize;

use crate::cube::{CubeMap, CubeMethod, CubeSettings, CubeSpans};
use crate::error::{Error, Result};
use crate::gpu::{GpuContext, Queries};
use crate::lens::LensCamera;
use crate::lens::gpu::DirectionSource;
use crate::raster::RasterMethod;
pub use crate::renderer::Method;
use crate::renderer::Path;
use crate::scene::{Camera, Scene};
use crate::trace::{GpuScene, RenderOptions, RenderOutput, Traversal};

impl Method {
    /// The passes a frame of this method is timed in, in order.
    pub fn passes(&self) -> &'static [Pass] {
        match self {
            Method::Rt | Method::Rq => &[Pass::Trace],
            Method::Cube(CubeMethod::Raster(RasterMethod::Deferred)) => {
                &[Pass::Faces, Pass::Lighting, Pass::Sampler]
            }
            Method::Cube(_) => &[Pass::Faces, Pass::Sampler],
        }
    }
}

/// One configuration measured: a method and, for cube maps, the face size; for direct
/// methods, the rays per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Setup {
    /// The method.
    pub method: Method,
    /// Face size in texels of a cube-map method; ignored by direct ray tracing.
    pub cube_size: u32,
    /// Rays per pixel of a direct method (a square, see [`crate::trace::sampling`]); 1 for
    /// cube maps, whose resampler takes one bilinear sample a pixel.
    pub spp: u32,
}

impl Setup {
    /// A direct method at `spp` rays per pixel, or a cube method at face size `cube_size`.
    pub fn direct(method: Method, spp: u32) -> Setup {
        Setup {
            method,
            cube_size: 0,
            spp,
        }
    }

    /// `rt@16spp`, `rq@1spp`, or the cube method and face size: `cube-forward@512`.
    pub fn label(&self) -> String {
        match self.method {
            Method::Cube(_) => format!("{}@{}", self.method.name(), self.cube_size),
            _ => format!("{}@{}spp", self.method.name(), self.spp),
        }
    }

    /// The face size of a cube-map setup.
    pub fn cube_size(&self) -> Option<u32> {
        self.method.cube().map(|_| self.cube_size)
    }

    /// The rays per pixel of a direct setup.
    pub fn spp(&self) -> Option<u32> {
        self.method.cube().is_none().then_some(self.spp)
    }

    /// Every setup of `methods`: direct methods once per rays-per-pixel count of `spps`, cube
    /// methods once per face size.
    pub fn all(methods: &[Method], cube_sizes: &[u32], spps: &[u32]) -> Vec<Setup> {
        methods
            .iter()
            .flat_map(|&method| match method {
                Method::Cube(_) => cube_sizes
                    .iter()
                    .map(|&cube_size| Setup {
                        method,
                        cube_size,
                        spp: 1,
                    })
                    .collect::<Vec<_>>(),
                _ => spps.iter().map(|&spp| Setup::direct(method, spp)).collect(),
            })
            .collect()
    }
}

/// A timed part of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Pass {
    /// Direct ray tracing of the lens image.
    Trace,
    /// Rendering the cube's faces (traced, forward, the deferred G-buffer, or multiview).
    Faces,
    /// The deferred faces' lighting pass.
    Lighting,
    /// Resampling the cube into the lens image.
    Sampler,
}

impl Pass {
    /// Lower-case name, as reports print it.
    pub fn name(&self) -> &'static str {
        match self {
            Pass::Trace => "trace",
            Pass::Faces => "faces",
            Pass::Lighting => "lighting",
            Pass::Sampler => "sampler",
        }
    }
}

/// The scene on the GPU as each method needs it: the software BVH, and the driver's
/// acceleration structure when a ray-query method is set up.
pub struct SceneSet {
    /// The scene with the software BVH.
    pub software: GpuScene,
    /// The scene with a ray-query acceleration structure, if asked for.
    pub ray_query: Option<GpuScene>,
    /// An instanced scene flattened for the rasterizer, if a setup rasterizes it.
    pub flat: Option<GpuScene>,
}

impl SceneSet {
    /// Uploads `scene` for the traversals `setups` need.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        options: &RenderOptions,
        setups: &[Setup],
    ) -> Result<Self> {
        let software = GpuScene::new(
            ctx,
            scene,
            &RenderOptions {
                traversal: Traversal::Software,
                ..*options
            },
        )?;
        let ray_query = setups
            .iter()
            .any(|s| s.method == Method::Rq)
            .then(|| {
                let options = RenderOptions {
                    traversal: Traversal::RayQuery,
                    ..*options
                };
                GpuScene::new(ctx, scene, &options)
            })
            .transpose()?;
        let rasterizes = |s: &Setup| matches!(s.method, Method::Cube(CubeMethod::Raster(_)));
        let flat = (scene.is_instanced() && setups.iter().any(rasterizes))
            .then(|| {
                let options = RenderOptions {
                    traversal: Traversal::Software,
                    ..*options
                };
                GpuScene::new(
                    ctx,
                    &scene.flattened(crate::scene::MAX_FLATTENED)?,
                    &options,
                )
            })
            .transpose()?;
        Ok(Self {
            software,
            ray_query,
            flat,
        })
    }

    /// The scene `method` renders.
    pub fn for_method(&self, method: Method) -> &GpuScene {
        match (method, &self.ray_query, &self.flat) {
            (Method::Rq, Some(rq), _) => rq,
            (Method::Cube(CubeMethod::Raster(_)), _, Some(flat)) => flat,
            _ => &self.software,
        }
    }
}

/// One setup ready to render frames of one lens: its pipelines, buffers and timestamp queries.
pub struct Renderer {
    path: Path,
    setup: Setup,
    queries: Option<Queries>,
}

/// How long one frame took.
#[derive(Clone, Debug, Serialize)]
pub struct FrameTime {
    /// Milliseconds from setting the pose to the GPU finishing the frame, on the CPU's clock.
    pub wall_ms: f64,
    /// GPU milliseconds per pass, in [`Method::passes`] order; `None` without timestamp
    /// queries.
    pub passes_ms: Option<Vec<f64>>,
}

impl FrameTime {
    /// The frame's GPU time (the sum of its passes), if timed.
    pub fn gpu_ms(&self) -> Option<f64> {
        self.passes_ms.as_ref().map(|p| p.iter().sum())
    }
}

impl Renderer {
    /// Sets `setup` up for `camera` on the scenes (the shadow maps of rasterized faces are
    /// `shadow_size`² and rendered here, once: the lights do not move).
    pub fn new(
        ctx: &GpuContext,
        camera: &LensCamera,
        scenes: &SceneSet,
        setup: Setup,
        shadow_size: u32,
    ) -> Result<Self> {
        Self::with_directions(
            ctx,
            camera,
            scenes,
            setup,
            shadow_size,
            DirectionSource::Computed,
        )
    }

    /// As [`Renderer::new`], with direct tracing's primary rays from `directions`.
    pub fn with_directions(
        ctx: &GpuContext,
        camera: &LensCamera,
        scenes: &SceneSet,
        setup: Setup,
        shadow_size: u32,
        directions: DirectionSource,
    ) -> Result<Self> {
        let rays = (directions, setup.spp);
        let scene = scenes.for_method(setup.method);
        let cube = match setup.method {
            Method::Cube(method) => Some(CubeSettings {
                shadow_size,
                ..CubeSettings::new(setup.cube_size, method)
            }),
            _ => None,
        };
        let path = Path::new(ctx, camera, scene, rays, cube.as_ref())?;
        let queries = Queries::new(ctx, setup.method.passes().len() as u32);
        Ok(Self {
            path,
            setup,
            queries,
        })
    }

    /// The setup.
    pub fn setup(&self) -> Setup {
        self.setup
    }

    /// Renders one frame from `pose` in one submission, waits for the GPU to finish it, and
    /// returns its times.
    pub fn frame(&self, ctx: &GpuContext, scenes: &SceneSet, pose: &Camera) -> Result<FrameTime> {
        let scene = scenes.for_method(self.setup.method);
        let q = self.queries.as_ref();
        let started = std::time::Instant::now();
        ctx.checked("rendering a frame", || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            let passes = self.setup.method.passes();
            let index = |p: Pass| passes.iter().position(|&x| x == p).map(|i| i as u32);
            let span = |p: Pass| index(p).and_then(|i| q.map(|q| q.span(i)));
            let spans = CubeSpans {
                faces: span(Pass::Faces),
                lighting: span(Pass::Lighting),
                sampler: span(Pass::Sampler),
            };
            let trace = index(Pass::Trace).and_then(|i| q.map(|q| q.writes(i)));
            self.path
                .encode(ctx, &mut encoder, scene, pose, trace, spans);
            if let Some(q) = q {
                q.resolve(&mut encoder);
            }
            ctx.queue.submit([encoder.finish()]);
        })?;
        ctx.wait()?;
        let wall_ms = started.elapsed().as_secs_f64() * 1e3;
        let passes_ms = match q {
            Some(q) => Some(q.read_ns(ctx)?.into_iter().map(|ns| ns * 1e-6).collect()),
            None => None,
        };
        Ok(FrameTime { wall_ms, passes_ms })
    }

    /// Compiles the frame's kernels before anything is timed (lavapipe, like many drivers,
    /// compiles a pipeline at its first dispatch) with the least work that runs each: one
    /// workgroup of a traced frame, or a whole cube-map frame (whose passes each need their
    /// first draw or dispatch). Returns the wall milliseconds it took: compilation, mostly.
    pub fn warm_up(&self, ctx: &GpuContext, scenes: &SceneSet, pose: &Camera) -> Result<f64> {
        let started = std::time::Instant::now();
        match &self.path {
            Path::Direct(pass) => {
                let scene = scenes.for_method(self.setup.method);
                let one = crate::lens::ImageSize::new(1, 1).expect("1x1 is a size");
                ctx.checked("compiling the kernels", || {
                    let mut encoder = ctx.device.create_command_encoder(&Default::default());
                    pass.encode_pose(&ctx.device, &mut encoder, scene, pose);
                    pass.encode_region(&mut encoder, scene, 0, one, None);
                    ctx.queue.submit([encoder.finish()]);
                })?;
                ctx.wait()?;
            }
            Path::Cube(_) => {
                self.frame(ctx, scenes, pose)?;
            }
        }
        Ok(started.elapsed().as_secs_f64() * 1e3)
    }

    /// The lens image's linear colours of the last frame (as [`RenderOutput::colour`]).
    pub fn colour(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>> {
        Ok(self.output(ctx)?.colour)
    }

    /// The last frame's outputs: all of them for direct tracing, the colour alone (geometry
    /// zero, ids `NO_HIT`) through a cube map.
    pub fn output(&self, ctx: &GpuContext) -> Result<RenderOutput> {
        self.path.read(ctx)
    }

    /// The cube map, for a cube-map setup.
    pub fn cube(&self) -> Option<&CubeMap> {
        match &self.path {
            Path::Cube(cube) => Some(cube),
            Path::Direct(_) => None,
        }
    }
}

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
    fn setups_and_names_round_trip() {
        for m in Method::ALL {
            assert_eq!(Method::from_name(m.name()), Some(m));
        }
        let setups = Setup::all(&[Method::Rt, Method::ALL[3]], &[512, 1024], &[1, 16]);
        let labels: Vec<String> = setups.iter().map(Setup::label).collect();
        let wanted = [
            "rt@1spp",
            "rt@16spp",
            "cube-forward@512",
            "cube-forward@1024",
        ];
        assert_eq!(labels, wanted);
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
