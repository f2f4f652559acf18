//! BVH build: obvhs's CWBVH presets (as `--bvh` exposes them) on the built-in scenes and the
//! shared real scenes, in triangles per second, with Criterion. The build includes what the
//! tracer uploads: camera-relative f32 triangles reordered by `primitive_indices`.
//!
//! `cargo bench --bench bvh` (the third-party scenes ship in `scenes/`).

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use fisheye_rt::bvh::{BvhQuality, SceneBvh};
use fisheye_rt::scene::{self, Scene};

fn scenes() -> Vec<(&'static str, Scene)> {
    let mut out = Vec::new();
    for spec in [
        "builtin:many-small",
        "builtin:few-detailed",
        concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/sibenik.toml"),
        concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/bunny.toml"),
    ] {
        let name = spec.rsplit('/').next().unwrap_or(spec);
        let loaded = scene::load(spec).unwrap_or_else(|e| panic!("{name}: {e}"));
        out.push((name, loaded.scene));
    }
    out
}

fn build(c: &mut Criterion) {
    for (name, scene) in scenes() {
        let mut group = c.benchmark_group(format!("bvh build {name}"));
        group
            .throughput(Throughput::Elements(scene.len() as u64))
            .sample_size(10)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(3));
        for quality in BvhQuality::ALL {
            group.bench_with_input(
                BenchmarkId::from_parameter(quality.name()),
                &quality,
                |b, &q| {
                    b.iter(|| {
                        SceneBvh::build(black_box(&scene), scene.camera.position, q, false).unwrap()
                    })
                },
            );
        }
        group.finish();
    }
}

criterion_group!(benches, build);
criterion_main!(benches);
