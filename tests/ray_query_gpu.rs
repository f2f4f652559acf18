//! Hardware ray queries beside the software traversal: only traversal differs, so the images
//! and per-pixel hits must agree but at ties and silhouettes, and both must meet the f64
//! reference under the same tolerances. Mesa 25's lavapipe has ray queries, so CI runs these
//! on the CPU; a missing feature fails rather than skips.

mod common;

use common::{assert_agrees, camera, ctx, on_id_edge, real_scene};
use fisheye_rt::cube::{CubeMap, CubeMethod, CubeSettings};
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::raster::RasterMethod;
use fisheye_rt::scene;
use fisheye_rt::trace::cpu::Reference;
use fisheye_rt::trace::{GpuScene, RenderOptions, Traversal, render};

fn ray_query() -> RenderOptions {
    RenderOptions {
        traversal: Traversal::RayQuery,
        ..RenderOptions::default()
    }
}

#[test]
fn ray_queries_agree_with_software_traversal_and_the_reference() {
    assert!(
        ctx().has(wgpu::Features::EXPERIMENTAL_RAY_QUERY),
        "these tests need ray queries (lavapipe from Mesa 25 has them)"
    );
    for (spec, lens) in [
        ("builtin:default", "canon-8-15mm@8mm"),
        ("builtin:many-small", "samyang-7.5mm"),
        ("builtin:few-detailed", "equidistant:f=0.5,fov=200"),
        ("scenes/cornell-sphere.toml", "canon-8-15mm@15mm"),
    ] {
        let scene = common::scene(spec);
        let cam = camera(lens, 96, 72);
        let software = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
        let hardware = render(ctx(), &scene, &cam, &ray_query()).unwrap();
        let reference = Reference::new(&scene, RenderOptions::default().max_depth).render(&cam);
        let mut differing = 0;
        for i in 0..software.ids.len() {
            assert_eq!(software.valid(i), hardware.valid(i), "{spec}: masks at {i}");
            if software.ids[i] != hardware.ids[i] {
                // Only where two triangles meet in the reference (a tie or a silhouette).
                assert!(
                    on_id_edge(&reference.ids, cam.size, i),
                    "{spec}: pixel {i} hits {} by ray query, {} by software, inside a surface",
                    hardware.ids[i],
                    software.ids[i]
                );
                differing += 1;
            }
        }
        eprintln!(
            "{spec}: {differing} of {} primary hits differ, all on edges",
            software.ids.len()
        );
        // The driver's own triangle test decides edges and ties its own way, for primary and
        // secondary rays alike: the allowance of real scenes (see there).
        let tolerance = real_scene(software.ids.len());
        assert!(differing <= tolerance.id_mismatches, "{spec}: {differing}");
        assert_agrees(
            &format!("{spec} by ray query"),
            &hardware,
            &reference,
            tolerance,
        );
    }
}

/// A device without ray queries (or without multiview) gets an error naming what is missing.
#[test]
fn missing_features_are_named() {
    let limited =
        GpuContext::without(wgpu::Features::EXPERIMENTAL_RAY_QUERY | wgpu::Features::MULTIVIEW)
            .unwrap();
    let scene = scene::builtin::scene("default").unwrap();
    let message = GpuScene::new(&limited, &scene, &ray_query())
        .err()
        .expect("no ray queries")
        .to_string();
    assert!(message.contains("EXPERIMENTAL_RAY_QUERY"), "{message}");
    let gpu_scene = GpuScene::new(&limited, &scene, &RenderOptions::default()).unwrap();
    let settings = CubeSettings::new(16, CubeMethod::Raster(RasterMethod::SinglePass));
    let cam = camera("canon-8-15mm@8mm", 32, 24);
    let message = CubeMap::new(&limited, &cam, &gpu_scene, &settings)
        .err()
        .expect("no multiview")
        .to_string();
    assert!(message.contains("MULTIVIEW"), "{message}");
}
