//! Shared by the GPU tracer tests: one device, and the comparison of a GPU render with the
//! f64 reference under the tolerances stated in `tests/trace_gpu.rs`.
#![allow(dead_code)]

use std::sync::OnceLock;

use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::{ImageSize, LensCamera, parse_spec};
use fisheye_rt::scene::Scene;
use fisheye_rt::trace::{NO_HIT, RenderOptions, RenderOutput, cpu::Reference, render};

pub fn ctx() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| GpuContext::new().expect("these tests need a GPU adapter (or lavapipe)"))
}

pub fn camera(spec: &str, w: u32, h: u32) -> LensCamera {
    LensCamera::new(parse_spec(spec).unwrap(), ImageSize::new(w, h).unwrap())
}

/// Whether pixel `i` of the reference's id image borders a different id.
pub fn on_id_edge(ids: &[u32], size: ImageSize, i: usize) -> bool {
    let (w, h) = (size.width as usize, size.height as usize);
    let (x, y) = (i % w, i / w);
    let neighbours = [
        (x > 0).then(|| i - 1),
        (x + 1 < w).then(|| i + 1),
        (y > 0).then(|| i - w),
        (y + 1 < h).then(|| i + w),
    ];
    neighbours.into_iter().flatten().any(|j| ids[j] != ids[i])
}

pub struct Agreement {
    pub id_mismatches: usize,
    pub mean_colour_error: f64,
    pub colour_outliers: usize,
}

/// Compares a GPU render with the reference under the module's tolerances.
pub fn assert_agrees(name: &str, gpu: &RenderOutput, cpu: &RenderOutput) -> Agreement {
    let n = gpu.ids.len();
    let mut mismatches = 0;
    let mut distance_errors = Vec::new();
    let mut colour_sum = 0.0;
    let mut outliers = 0;
    let mut compared = 0;
    for i in 0..n {
        assert_eq!(gpu.valid(i), cpu.valid(i), "{name}: masks differ at {i}");
        assert!(
            gpu.colour[i].iter().all(|c| c.is_finite()),
            "{name}: non-finite colour at {i}"
        );
        if gpu.ids[i] != cpu.ids[i] {
            assert!(
                on_id_edge(&cpu.ids, cpu.size, i) || on_id_edge(&gpu.ids, gpu.size, i),
                "{name}: ids differ inside a surface at pixel {i}: gpu {} cpu {}",
                gpu.ids[i],
                cpu.ids[i]
            );
            mismatches += 1;
            continue;
        }
        if !gpu.valid(i) {
            continue;
        }
        if gpu.ids[i] != NO_HIT {
            let (a, b) = (f64::from(gpu.geometry[i][3]), f64::from(cpu.geometry[i][3]));
            distance_errors.push((a - b).abs() / b);
        }
        let e = (0..3)
            .map(|k| f64::from((gpu.colour[i][k] - cpu.colour[i][k]).abs()))
            .fold(0.0, f64::max);
        colour_sum += e;
        compared += 1;
        if e > 0.02 {
            outliers += 1;
        }
    }
    distance_errors.sort_by(f64::total_cmp);
    let p999 = distance_errors
        .get(distance_errors.len() * 999 / 1000)
        .copied()
        .unwrap_or(0.0);
    let max = distance_errors.last().copied().unwrap_or(0.0);
    let mean = colour_sum / compared.max(1) as f64;
    eprintln!(
        "{name}: {mismatches}/{n} ids differ (on edges), distance p99.9 {p999:.1e} max {max:.1e}, \
         colour mean {mean:.1e}, {outliers} outliers"
    );
    assert!(mismatches * 100 <= n, "{name}: {mismatches} ids differ");
    assert!(
        p999 <= 1e-5 && max <= 1e-3,
        "{name}: distances {p999:e} / {max:e}"
    );
    assert!(mean <= 2e-3, "{name}: mean colour error {mean}");
    assert!(
        outliers * 100 <= compared,
        "{name}: {outliers} colour outliers"
    );
    Agreement {
        id_mismatches: mismatches,
        mean_colour_error: mean,
        colour_outliers: outliers,
    }
}

/// Asserts that every pixel whose primary ray hit shows `expected` to within `tolerance` (per
/// channel); returns how many hit.
pub fn assert_every_hit_is(
    out: &RenderOutput,
    expected: glam::Vec3,
    tolerance: f32,
    what: &str,
) -> usize {
    let mut hits = 0;
    for (i, id) in out.ids.iter().enumerate() {
        if *id == NO_HIT {
            continue;
        }
        hits += 1;
        let c = glam::Vec3::from_slice(&out.colour[i][..3]);
        assert!(
            (c - expected).abs().max_element() <= tolerance,
            "{what}: pixel {i} shows {c}, not {expected}"
        );
    }
    hits
}

pub fn both(scene: &Scene, cam: &LensCamera) -> (RenderOutput, RenderOutput) {
    let options = RenderOptions::default();
    let gpu = render(ctx(), scene, cam, &options).unwrap();
    let cpu = Reference::new(scene, options.max_depth).render(cam);
    (gpu, cpu)
}
