//! Trace throughput of the software-traversal Whitted tracer on the built-in scenes and the
//! shared real scenes, through the default 180° fisheye and a pinhole of the same image size,
//! the camera moving along each scene file's path (built-in scenes: their fixed camera).
//! GPU time from timestamp queries, median of `FRAMES` frames after one warm-up, one run.
//! A second table compares the software traversal with hardware ray queries (where the
//! adapter has them), with both build times; a third traces two scenes with each BVH preset,
//! to choose the default by measurement; a fourth measures instancing: the cost of the second
//! level against the same scene flattened, and the thousand-instance scene.
//!
//! `cargo bench --bench trace` (`FRAMES`, default 8; `SIZE`, default 1024x768; `TABLES`, a
//! comma-separated choice of `scenes`, `rq`, `presets`, `instancing`, default all of them).

use fisheye_rt::bvh::BvhQuality;
use fisheye_rt::gpu::{GpuContext, Queries, median};
use fisheye_rt::lens::gpu::DirectionSource;
use fisheye_rt::lens::{ImageSize, LensCamera, parse_spec};
use fisheye_rt::scene::{self, Scene};
use fisheye_rt::trace::{GpuScene, RenderOptions, TracePass, Traversal};

const SCENES: [&str; 7] = [
    "builtin:default",
    "builtin:many-small",
    "builtin:few-detailed",
    "scenes/sibenik.toml",
    "scenes/cornell-sphere.toml",
    "scenes/bunny.toml",
    "scenes/buddha.toml",
];

/// The 180° fisheye `fisheye render` uses by default, and a pinhole with a 90° horizontal field.
const LENSES: [(&str, &str); 2] = [
    ("fisheye", "canon-8-15mm@8mm"),
    ("pinhole", "rectilinear:f=1"),
];

struct Measured {
    ms: f64,
    rays: usize,
    hits: usize,
}

/// Median GPU time of a frame of `scene` through `spec`, along its camera path.
fn measure(
    ctx: &GpuContext,
    queries: &Queries,
    scene: &Scene,
    gpu_scene: &GpuScene,
    spec: &str,
    size: ImageSize,
    frames: usize,
) -> Measured {
    let camera = LensCamera::new(parse_spec(spec).unwrap(), size);
    let pass = TracePass::new(ctx, &camera, gpu_scene, DirectionSource::Computed).unwrap();
    let samples = queries
        .time_frames(ctx, 1, frames, |frame, encoder, writes| {
            let s = frame.saturating_sub(1) as f64 / (frames - 1).max(1) as f64;
            pass.set_pose(ctx, gpu_scene, &scene.camera_on_path(s));
            pass.encode(encoder, gpu_scene, Some(writes));
        })
        .expect("timestamps read back");
    let (rays, hits) = pass.read(ctx).unwrap().counts();
    Measured {
        ms: median(&samples),
        rays,
        hits,
    }
}

fn main() {
    let frames: usize = std::env::var("FRAMES")
        .ok()
        .and_then(|f| f.parse().ok())
        .unwrap_or(8);
    let size: ImageSize = std::env::var("SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(ImageSize::new(1024, 768).unwrap());
    let tables = std::env::var("TABLES").unwrap_or("scenes,rq,presets,instancing".into());
    let table = |name: &str| tables.split(',').any(|t| t == name);
    std::env::set_current_dir(env!("CARGO_MANIFEST_DIR")).unwrap();
    let ctx = GpuContext::new().expect("a GPU adapter");
    let queries = Queries::new(&ctx, 1).expect("this benchmark needs timestamp queries");
    println!("adapter: {}", ctx.adapter_name());
    println!(
        "{size}, median GPU ms of {frames} frames along the camera path (one warm-up excluded)\n"
    );
    let options = RenderOptions::default();
    let mut loaded = Vec::new();
    let needs_scenes = table("scenes") || table("rq") || table("presets");
    if table("scenes") {
        println!(
            "| scene | triangles | lens | ms / frame | M primary rays/s | hit | time per ray, fisheye / pinhole |"
        );
        println!("|---|---:|---|---:|---:|---:|---:|");
    }
    for spec in SCENES.iter().filter(|_| needs_scenes) {
        let scene = match scene::load(spec) {
            Ok(l) => l.scene,
            Err(e) => {
                eprintln!("skipping {spec}: {e}");
                continue;
            }
        };
        if !table("scenes") {
            loaded.push((spec, scene));
            continue;
        }
        let gpu_scene = GpuScene::new(&ctx, &scene, &options).unwrap();
        let results: Vec<Measured> = LENSES
            .iter()
            .map(|(_, lens)| measure(&ctx, &queries, &scene, &gpu_scene, lens, size, frames))
            .collect();
        for ((name, _), m) in LENSES.iter().zip(&results) {
            // The fisheye leaves the image's corners dark, so compare time per ray.
            let per_ray = |m: &Measured| m.ms / m.rays.max(1) as f64;
            let ratio = if *name == "fisheye" {
                format!("{:.2}", per_ray(m) / per_ray(&results[1]))
            } else {
                String::new()
            };
            println!(
                "| {spec} | {} | {name} | {:.1} | {:.2} | {:.0}% | {ratio} |",
                scene.len(),
                m.ms,
                m.rays as f64 / m.ms * 1e-3,
                100.0 * m.hits as f64 / m.rays.max(1) as f64,
            );
        }
        loaded.push((spec, scene));
    }

    if table("rq") && ctx.has(wgpu::Features::EXPERIMENTAL_RAY_QUERY) {
        println!(
            "\nTraversal: the software CWBVH against hardware ray queries, fisheye, same run\n"
        );
        println!(
            "| scene | obvhs build ms | AS build ms | software M rays/s | ray query M rays/s | ray query / software |"
        );
        println!("|---|---:|---:|---:|---:|---:|");
        for (spec, scene) in &loaded {
            let software = GpuScene::new(&ctx, scene, &options).unwrap();
            let rq_options = RenderOptions {
                traversal: Traversal::RayQuery,
                ..options
            };
            let hardware = GpuScene::new(&ctx, scene, &rq_options).unwrap();
            let rate = |gpu_scene: &GpuScene| {
                let m = measure(&ctx, &queries, scene, gpu_scene, LENSES[0].1, size, frames);
                m.rays as f64 / m.ms * 1e-3
            };
            let (a, b) = (rate(&software), rate(&hardware));
            let built = hardware.ray_query.as_ref().expect("built").build_time;
            println!(
                "| {spec} | {:.0} | {:.0} | {a:.2} | {b:.2} | {:.2} |",
                software.bvh_build_time.as_secs_f64() * 1e3,
                built.as_secs_f64() * 1e3,
                b / a
            );
        }
    }

    if table("presets") {
        println!("\nBVH presets: build time (CPU) and fisheye frame time (GPU)\n");
        println!("| scene | preset | build ms | nodes | ms / frame |");
        println!("|---|---|---:|---:|---:|");
    }
    for (spec, scene) in loaded.iter().filter(|(s, _)| {
        table("presets") && (**s == "builtin:few-detailed" || **s == "scenes/sibenik.toml")
    }) {
        for bvh in BvhQuality::ALL {
            let options = RenderOptions { bvh, ..options };
            let gpu_scene = GpuScene::new(&ctx, scene, &options).unwrap();
            let m = measure(&ctx, &queries, scene, &gpu_scene, LENSES[0].1, size, frames);
            println!(
                "| {spec} | {} | {:.0} | {} | {:.1} |",
                bvh.name(),
                gpu_scene.bvh_build_time.as_secs_f64() * 1e3,
                gpu_scene.bvh_nodes,
                m.ms
            );
        }
    }

    if !table("instancing") {
        return;
    }
    println!(
        "\nInstancing: the two-level BVH against the same scene flattened, fisheye, same run\n"
    );
    println!(
        "| scene | triangles | stored | instances | device MiB | build ms | ms / frame | M primary rays/s |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for (spec, flatten) in [
        ("builtin:instances-few", false),
        ("builtin:instances-few", true),
        ("builtin:instances", false),
    ] {
        let mut scene = scene::load(spec).unwrap().scene;
        if flatten {
            scene = scene.flattened(usize::MAX).unwrap();
        }
        let gpu_scene = GpuScene::new(&ctx, &scene, &options).unwrap();
        let m = measure(
            &ctx,
            &queries,
            &scene,
            &gpu_scene,
            LENSES[0].1,
            size,
            frames,
        );
        let bytes = gpu_scene.bytes;
        println!(
            "| {spec}{} | {} | {} | {} | {:.1} | {:.0} | {:.1} | {:.2} |",
            if flatten { " (flattened)" } else { "" },
            scene.len(),
            scene.triangles.len(),
            scene.instances.len(),
            (bytes.geometry + bytes.bvh + bytes.shading) as f64 / f64::from(1 << 20),
            gpu_scene.bvh_build_time.as_secs_f64() * 1e3,
            m.ms,
            m.rays as f64 / m.ms * 1e-3
        );
    }
}
