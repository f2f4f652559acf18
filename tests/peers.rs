//! The peer check (feature `peer-embree`): Embree and the project's traversal (`RayCast`)
//! answer the peer benchmark's rays the same way, primary, shadow and bounce rays, on a
//! shared scanned mesh and on an instanced scene; and Embree's packets answer as its single
//! rays do. The benchmark's agreement column rests on this.

mod common;

use common::{camera, ctx};
use fisheye_rt::peer::{Agreement, Workload, light, with_embree};
use fisheye_rt::scene::{Scene, builtin};
use fisheye_rt::trace::cast::{NO_HIT, RayCast};
use fisheye_rt::trace::{GpuScene, RenderOptions};
use glam::DVec3;

/// Both tracers cast the same f32 rays into the same f32 triangles, so they differ only where
/// a ray passes within rounding of an edge (each breaks such ties its own way) or grazes a
/// surface: at most 0.5% of the rays may name another triangle (the bound of real scenes in
/// `tests/common/mod.rs`), at most 0.1% another hit-or-miss, and distances agree to 1e-5
/// where the triangle is the same (both compute t in f32).
fn agree(name: &str, scene: &Scene, distance: f64) {
    let gpu_scene = GpuScene::new(ctx(), scene, &RenderOptions::default()).unwrap();
    let lens = camera("samyang-7.5mm", 128, 96);
    let directions: Vec<DVec3> = lens.directions().into_iter().flatten().collect();
    let closest = RayCast::new(ctx(), &gpu_scene, false).unwrap();
    let any = RayCast::new(ctx(), &gpu_scene, true).unwrap();
    with_embree(scene, |embree, _| {
        let work = Workload::new(
            embree,
            &directions,
            scene.camera.rotation(),
            light(scene),
            2,
        );
        assert!(
            work.shadow.len() > work.primary.len() / 5,
            "{name}: few hits"
        );
        for (what, rays) in [("primary", &work.primary), ("bounce", &work.bounce)] {
            let ours = closest.cast(ctx(), &gpu_scene, rays).unwrap();
            let theirs = embree.intersect1(rays, 2);
            let a = Agreement::of(&ours, &theirs);
            eprintln!("{name} {what}: {a:?}");
            assert!(a.triangle >= 0.995, "{name} {what}: {a:?}");
            assert!(a.hit_or_miss >= 0.999, "{name} {what}: {a:?}");
            assert!(a.distance <= distance, "{name} {what}: {a:?}");
            let packets = embree.intersect8(rays, 2);
            assert_eq!(
                Agreement::of(&packets, &theirs).triangle,
                1.0,
                "{name} {what}"
            );
        }
        let ours: Vec<bool> = any
            .cast(ctx(), &gpu_scene, &work.shadow)
            .unwrap()
            .iter()
            .map(|h| h.triangle != NO_HIT)
            .collect();
        let theirs = embree.occluded1(&work.shadow, 2);
        let blocked = theirs.iter().filter(|&&b| b).count();
        assert!(
            blocked > 0 && blocked < theirs.len(),
            "{name}: {blocked} blocked"
        );
        let a = Agreement::of_occlusion(&ours, &theirs);
        eprintln!("{name} shadow: {a:?}");
        assert!(a.hit_or_miss >= 0.995, "{name} shadow: {a:?}");
    })
    .unwrap();
}

#[test]
fn embree_and_the_traversal_answer_the_same_rays_alike() {
    // Both compute t in f32 from the same triangles: measured at most 3.2e-6.
    agree("bunny", &common::scene("scenes/bunny.toml"), 1e-5);
    // Embree gets the instances flattened, whose corners are rounded once in the world, where
    // the traversal maps rays into the mesh by an f32 map: a few 1e-7 of the 30 m reach, which
    // a bounce of half a metre sees as 2.5e-5 (measured).
    agree("instances", &builtin::scene("instances-few").unwrap(), 1e-4);
}
