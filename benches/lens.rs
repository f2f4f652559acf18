//! Ray generation: evaluating the lens per pixel every frame against reading the thesis's
//! direction table (computed once per lens and size), on the frame of `fisheye lens demo`.
//! GPU time from timestamp queries, median of `FRAMES` frames after a warm-up, one run.
//!
//! `cargo bench --bench lens` (set `FRAMES` to change the count).

use fisheye_rt::demo::LensDemo;
use fisheye_rt::gpu::{GpuContext, Queries, median};
use fisheye_rt::lens::gpu::{DirectionSource, LensRays};
use fisheye_rt::lens::{ImageSize, LensCamera, parse_spec};

/// Median GPU milliseconds of `frames` frames recorded by `encode`, after one warm-up frame.
fn time(
    ctx: &GpuContext,
    queries: &Queries,
    frames: usize,
    encode: impl Fn(&mut wgpu::CommandEncoder, wgpu::ComputePassTimestampWrites<'_>),
) -> f64 {
    let samples = queries
        .time_frames(ctx, 1, frames, |_, e, t| encode(e, t))
        .expect("timestamps read back");
    median(&samples)
}

fn main() {
    let frames: usize = std::env::var("FRAMES")
        .ok()
        .and_then(|f| f.parse().ok())
        .unwrap_or(15);
    let ctx = GpuContext::new().expect("a GPU adapter");
    let queries = Queries::new(&ctx, 1).expect("this benchmark needs timestamp queries");
    println!("adapter: {}", ctx.adapter_name());
    println!("median GPU ms of {frames} frames (one warm-up excluded)\n");
    println!("| lens | size | build table | frame, computed | frame, table | table / computed |");
    println!("|---|---|---:|---:|---:|---:|");
    let lenses = [
        "equisolid:f=0.5",
        "equidistant:f=0.3",
        "general:f=0.5,k1=0.7,k2=0.7",
        "samyang-7.5mm",
    ];
    for size in [
        ImageSize::new(1920, 1080).unwrap(),
        ImageSize::new(3840, 2160).unwrap(),
    ] {
        for spec in lenses {
            let camera = LensCamera::new(parse_spec(spec).unwrap(), size);
            let rays = LensRays::new(&ctx, &camera).unwrap();
            let build = time(&ctx, &queries, frames, |e, t| rays.encode(e, Some(t)));
            let computed = LensDemo::new(&ctx, &camera, DirectionSource::Computed).unwrap();
            let table = LensDemo::new(&ctx, &camera, DirectionSource::Table).unwrap();
            let c = time(&ctx, &queries, frames, |e, t| computed.encode(e, Some(t)));
            let t = time(&ctx, &queries, frames, |e, t| table.encode(e, Some(t)));
            println!(
                "| {spec} | {size} | {build:.2} | {c:.2} | {t:.2} | {:.2} |",
                t / c
            );
        }
    }
}
