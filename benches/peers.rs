//! The peer benchmark: the same rays cast by the project's traversal on the GPU
//! (`RayCast`, timestamp queries) and by Embree 3 on the CPU (`fisheye_rt::peer`), in one run:
//! a fisheye's primary rays, shadow rays from their hits to a light, and one diffuse bounce
//! (incoherent rays). Embree runs its single-ray API on every core (the baseline) and its
//! 8-wide packets (the ceiling); each figure is the median of `FRAMES` timed runs after one
//! untimed. The agreement columns compare the answers (same triangle; same occlusion).
//!
//! `cargo bench --bench peers --features peer-embree` (`FRAMES`, default 5; `SIZE`, default
//! 1024x768; `LENS`, default samyang-7.5mm; `SCENES`, space-separated, default the shared
//! scanned statues, the Sibenik interior and the few-detailed tori).

use fisheye_rt::gpu::{GpuContext, Queries, median};
use fisheye_rt::lens::{ImageSize, LensCamera, parse_spec};
use fisheye_rt::peer::{Agreement, Embree, Workload, light, with_embree};
use fisheye_rt::scene;
use fisheye_rt::trace::cast::{CastRay, NO_HIT, RayCast};
use fisheye_rt::trace::{GpuScene, RenderOptions};
use glam::DVec3;

fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Median milliseconds of `frames` runs of `run` after one untimed.
fn cpu_ms(frames: usize, mut run: impl FnMut()) -> f64 {
    run();
    let samples: Vec<f64> = (0..frames)
        .map(|_| {
            let started = std::time::Instant::now();
            run();
            started.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    median(&samples)
}

struct Bench<'a> {
    ctx: &'a GpuContext,
    queries: &'a Queries,
    gpu_scene: &'a GpuScene,
    embree: &'a Embree<'a>,
    threads: usize,
    frames: usize,
}

impl Bench<'_> {
    /// GPU milliseconds of one cast of `rays`, and its answers.
    fn ours(
        &self,
        rays: &[CastRay],
        any_hit: bool,
    ) -> (f64, Vec<fisheye_rt::trace::cast::CastHit>) {
        let cast = RayCast::new(self.ctx, self.gpu_scene, any_hit).unwrap();
        let batch = cast.upload(self.ctx, rays).unwrap();
        let samples = self
            .queries
            .time_frames(self.ctx, 1, self.frames, |_, encoder, writes| {
                cast.encode(encoder, self.gpu_scene, &batch, Some(writes));
            })
            .unwrap();
        (median(&samples), cast.read(self.ctx, &batch).unwrap())
    }

    /// What our traversal did for `rays`, from a counting pass (untimed): node groups and
    /// triangles a ray, and how busy the lanes of 8 consecutive rays were (the work of the
    /// eight over eight times the busiest one's: lavapipe runs 8 invocations to a SIMD
    /// register).
    fn work(&self, spec: &str, what: &str, rays: &[CastRay], any_hit: bool) {
        let cast = RayCast::counting(self.ctx, self.gpu_scene, any_hit).unwrap();
        let (_, work) = cast.cast_counting(self.ctx, self.gpu_scene, rays).unwrap();
        let steps: Vec<f64> = work
            .iter()
            .map(|w| f64::from(w.nodes + w.triangles))
            .collect();
        let busiest: f64 = steps
            .chunks(8)
            .map(|g| 8.0 * g.iter().copied().fold(0.0, f64::max))
            .sum();
        let mean = |f: fn(&fisheye_rt::trace::cast::CastWork) -> u32| {
            work.iter().map(|w| f64::from(f(w))).sum::<f64>() / work.len().max(1) as f64
        };
        eprintln!(
            "{spec} {what}: {:.1} node groups and {:.1} triangles a ray; lanes of 8 {:.0}% busy",
            mean(|w| w.nodes),
            mean(|w| w.triangles),
            100.0 * steps.iter().sum::<f64>() / busiest.max(1.0)
        );
    }

    fn row(&self, spec: &str, what: &str, rays: &[CastRay], shadow: bool) {
        self.work(spec, what, rays, shadow);
        let (ours_ms, ours) = self.ours(rays, shadow);
        let rate = |ms: f64| rays.len() as f64 / ms * 1e-3;
        let (single_ms, packet_ms, agreement) = if shadow {
            let mut theirs = Vec::new();
            let ms = cpu_ms(self.frames, || {
                theirs = self.embree.occluded1(rays, self.threads)
            });
            let blocked: Vec<bool> = ours.iter().map(|h| h.triangle != NO_HIT).collect();
            (ms, None, Agreement::of_occlusion(&blocked, &theirs))
        } else {
            let mut theirs = Vec::new();
            let ms = cpu_ms(self.frames, || {
                theirs = self.embree.intersect1(rays, self.threads)
            });
            let packets = cpu_ms(self.frames, || {
                std::hint::black_box(self.embree.intersect8(rays, self.threads));
            });
            (ms, Some(packets), Agreement::of(&ours, &theirs))
        };
        let hit = ours.iter().filter(|h| h.triangle != NO_HIT).count() as f64 / rays.len() as f64;
        let packets = packet_ms.map_or("—".to_string(), |ms| {
            format!("{:.2} ({:.2}x)", rate(ms), rate(ours_ms) / rate(ms))
        });
        println!(
            "| {spec} | {what} | {} | {:.0}% | {:.2} | {:.2} | {:.2}x | {packets} | {:.3}% |",
            rays.len(),
            100.0 * hit,
            rate(ours_ms),
            rate(single_ms),
            rate(ours_ms) / rate(single_ms),
            100.0 * agreement.triangle,
        );
    }
}

fn main() {
    let frames: usize = env("FRAMES", 5);
    let size: ImageSize = env("SIZE", ImageSize::new(1024, 768).unwrap());
    let lens: String = env("LENS", "samyang-7.5mm".to_string());
    let scenes: String = env(
        "SCENES",
        "scenes/bunny.toml scenes/buddha.toml scenes/sibenik.toml builtin:few-detailed".to_string(),
    );
    std::env::set_current_dir(env!("CARGO_MANIFEST_DIR")).unwrap();
    let ctx = GpuContext::new().expect("a GPU adapter");
    let queries = Queries::new(&ctx, 1).expect("this benchmark needs timestamp queries");
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let camera = LensCamera::new(parse_spec(&lens).unwrap(), size);
    let directions: Vec<DVec3> = camera.directions().into_iter().flatten().collect();
    println!("ours: {} (GPU time, timestamps)", ctx.adapter_name());
    println!(
        "Embree 3 on {threads} threads of this CPU; {lens} at {size}; medians of {frames} runs\n"
    );
    println!(
        "| scene | rays | count | hit | ours M rays/s | Embree rtcIntersect1 M rays/s | ours / Embree | Embree 8-wide packets M rays/s (ours / it) | same triangle |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for spec in scenes.split_whitespace() {
        let scene = match scene::load(spec) {
            Ok(l) => l.scene,
            Err(e) => {
                eprintln!("skipping {spec}: {e}");
                continue;
            }
        };
        let gpu_scene = GpuScene::new(&ctx, &scene, &RenderOptions::default()).unwrap();
        with_embree(&scene, |embree, build| {
            eprintln!(
                "{spec}: {} triangles; Embree built in {:.0} ms, obvhs in {:.0} ms",
                scene.len(),
                build * 1e3,
                gpu_scene.bvh_build_time.as_secs_f64() * 1e3
            );
            // Memory: ours as uploaded, Embree's as its build grew this process.
            let per = |bytes: u64| bytes as f64 / scene.len().max(1) as f64;
            let ours = gpu_scene.bytes;
            eprintln!(
                "{spec}: bytes a triangle: ours {:.1} (geometry {:.1}, BVH {:.1}); Embree's \
                 build grew resident memory by {} (its vertex and index buffers, 60 more, \
                 not counted)",
                per(ours.geometry + ours.bvh),
                per(ours.geometry),
                per(ours.bvh),
                embree
                    .build_resident
                    .map_or("an unknown amount".into(), |b| format!("{:.1}", per(b)))
            );
            let work = Workload::new(
                embree,
                &directions,
                scene.camera.rotation(),
                light(&scene),
                threads,
            );
            let bench = Bench {
                ctx: &ctx,
                queries: &queries,
                gpu_scene: &gpu_scene,
                embree,
                threads,
                frames,
            };
            bench.row(spec, "primary", &work.primary, false);
            bench.row(spec, "shadow", &work.shadow, true);
            bench.row(spec, "bounce", &work.bounce, false);
        })
        .unwrap();
    }
}
