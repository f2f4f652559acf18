//! `RayCast` (arbitrary rays through the tracer's traversal) against the f64 reference's
//! traversal of the same f32 scene data: closest hits and any hits, on a flat scene and on an
//! instanced one.

mod common;

use common::{camera, ctx};
use fisheye_rt::scene::{Scene, builtin};
use fisheye_rt::trace::cast::{CastRay, NO_HIT, RayCast, light};
use fisheye_rt::trace::cpu::Reference;
use fisheye_rt::trace::{GpuScene, RenderOptions};
use glam::DVec3;

/// Casts a camera's rays from the eye (closest hits) and, from each hit, a ray towards a light
/// (any hit), and compares both with the reference: the same triangle on all
/// but rays grazing an edge (at most 0.5%, as for real scenes in `tests/common/mod.rs`),
/// distances to 1e-5 where the triangle is the same, and the same occlusion on all but 0.5%.
fn agrees_with_the_reference(name: &str, scene: &Scene) {
    let gpu_scene = GpuScene::new(ctx(), scene, &RenderOptions::default()).unwrap();
    let reference = Reference::new(scene, 0);
    let rotation = scene.camera.rotation();
    let dirs: Vec<DVec3> = camera("samyang-7.5mm", 96, 72)
        .directions()
        .into_iter()
        .flatten()
        .map(|d| (rotation * d).as_vec3().as_dvec3())
        .collect();
    let rays: Vec<CastRay> = dirs
        .iter()
        .map(|d| CastRay {
            origin: [0.0; 3],
            tmin: 0.0,
            dir: d.as_vec3().to_array(),
            tmax: f32::MAX,
        })
        .collect();
    let closest = RayCast::new(ctx(), &gpu_scene, false).unwrap();
    let hits = closest.cast(ctx(), &gpu_scene, &rays).unwrap();
    let (mut differ, mut hit, mut distance) = (0, 0, 0.0f64);
    let mut shadow_rays = Vec::new();
    let light = light(scene);
    for (d, h) in dirs.iter().zip(&hits) {
        let r = reference.trace(DVec3::ZERO, *d, 0.0, f64::INFINITY, false);
        match r {
            Some(r) if r.triangle == h.triangle => {
                hit += 1;
                distance = distance.max((f64::from(h.t) - r.t).abs() / r.t);
                let p = (*d * r.t * (1.0 - 1e-4)).as_vec3();
                shadow_rays.push(CastRay {
                    origin: p.to_array(),
                    tmin: 0.0,
                    dir: (light - p).to_array(),
                    tmax: 1.0,
                });
            }
            None if h.triangle == NO_HIT => {}
            _ => differ += 1,
        }
    }
    eprintln!("{name}: {hit} hits, {differ} differ, distance {distance:.1e}");
    assert!(hit > dirs.len() / 4, "{name}: {hit} hits");
    assert!(differ <= dirs.len() / 200, "{name}: {differ} differ");
    assert!(distance <= 1e-5, "{name}: distance {distance:e}");
    let any = RayCast::new(ctx(), &gpu_scene, true).unwrap();
    let shadows = any.cast(ctx(), &gpu_scene, &shadow_rays).unwrap();
    let mut blocked = 0;
    let mut disagree = 0;
    for (ray, h) in shadow_rays.iter().zip(&shadows) {
        let o = glam::Vec3::from(ray.origin).as_dvec3();
        let d = glam::Vec3::from(ray.dir).as_dvec3();
        let r = reference.trace(o, d, 0.0, 1.0, true);
        blocked += usize::from(r.is_some());
        disagree += usize::from(r.is_some() != (h.triangle != NO_HIT));
    }
    eprintln!(
        "{name}: {blocked} of {} shadow rays blocked, {disagree} disagree",
        shadows.len()
    );
    assert!(
        disagree <= shadow_rays.len() / 200,
        "{name}: {disagree} disagree"
    );
    assert!(
        blocked > 0 && blocked < shadow_rays.len(),
        "{name}: {blocked} blocked"
    );
}

#[test]
fn cast_rays_match_the_reference() {
    agrees_with_the_reference("default room", &builtin::scene("default").unwrap());
    agrees_with_the_reference("few instances", &builtin::scene("instances-few").unwrap());
}

/// No ray, and more rays than one dispatch holds, are handled: an empty cast returns nothing,
/// an oversized one is an error naming the limit.
#[test]
fn empty_and_oversized_casts() {
    let scene = builtin::scene("grid").unwrap();
    let gpu_scene = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
    let cast = RayCast::new(ctx(), &gpu_scene, false).unwrap();
    assert!(cast.cast(ctx(), &gpu_scene, &[]).unwrap().is_empty());
    let most = ctx().device.limits().max_compute_workgroups_per_dimension as usize * 64;
    let ray = CastRay {
        origin: [0.0; 3],
        tmin: 0.0,
        dir: [0.0, 0.0, 1.0],
        tmax: 1.0,
    };
    let message = cast
        .upload(ctx(), &vec![ray; most + 1])
        .err()
        .expect("refused")
        .to_string();
    assert!(message.contains("one dispatch takes at most"), "{message}");
}

/// A counting pass finds the very hits of the plain one and counts what a ray can do: at least
/// the root's node group and at most every node group once; at most every stored triangle
/// once. Exactly: a ray that leaves a one-triangle scene behind it expands the root and tests
/// nothing, one that hits it expands the root and tests its triangle. A plain pass refuses
/// to read work.
#[test]
fn a_counting_pass_counts_nodes_and_triangles() {
    use fisheye_rt::scene::{Camera, Material, MeshBuilder};
    let room = builtin::scene("default").unwrap();
    let gpu_room = GpuScene::new(ctx(), &room, &RenderOptions::default()).unwrap();
    let rotation = room.camera.rotation();
    let rays: Vec<CastRay> = camera("samyang-7.5mm", 64, 48)
        .directions()
        .into_iter()
        .flatten()
        .map(|d| CastRay {
            origin: [0.0; 3],
            tmin: 0.0,
            dir: (rotation * d).as_vec3().to_array(),
            tmax: f32::MAX,
        })
        .collect();
    let plain = RayCast::new(ctx(), &gpu_room, false).unwrap();
    let (hits, work) = RayCast::counting(ctx(), &gpu_room, false)
        .unwrap()
        .cast_counting(ctx(), &gpu_room, &rays)
        .unwrap();
    assert!(hits == plain.cast(ctx(), &gpu_room, &rays).unwrap());
    let (nodes, triangles) = (gpu_room.bvh_nodes as u32, gpu_room.triangles);
    for w in &work {
        assert!((1..=nodes).contains(&w.nodes), "{w:?} of {nodes} nodes");
        assert!(w.triangles <= triangles, "{w:?} of {triangles} triangles");
    }
    let mean = |f: fn(&fisheye_rt::trace::cast::CastWork) -> u32| {
        work.iter().map(f).sum::<u32>() as f64 / work.len() as f64
    };
    eprintln!(
        "default room: {:.1} node groups and {:.1} triangles a ray",
        mean(|w| w.nodes),
        mean(|w| w.triangles)
    );
    assert!(mean(|w| w.triangles) >= 1.0, "the closed room is hit");

    let mut b = MeshBuilder::new();
    let grey = b.material(Material::diffuse("grey", glam::Vec3::splat(0.8)));
    b.triangle(
        [
            DVec3::new(-1.0, -1.0, -2.0),
            DVec3::new(1.0, -1.0, -2.0),
            DVec3::new(0.0, 1.0, -2.0),
        ],
        None,
        None,
        grey,
    );
    let camera_at = Camera {
        position: DVec3::ZERO,
        look_at: -DVec3::Z,
        up: DVec3::Y,
    };
    let one = b.finish(Vec::new(), glam::Vec3::ONE, glam::Vec3::ZERO, camera_at);
    let gpu_one = GpuScene::new(ctx(), &one, &RenderOptions::default()).unwrap();
    let ray = |z: f32| CastRay {
        origin: [0.0; 3],
        tmin: 0.0,
        dir: [0.0, 0.0, z],
        tmax: f32::MAX,
    };
    let (hits, work) = RayCast::counting(ctx(), &gpu_one, false)
        .unwrap()
        .cast_counting(ctx(), &gpu_one, &[ray(-1.0), ray(1.0)])
        .unwrap();
    assert_eq!(hits[0].triangle, 0);
    assert_eq!(hits[1].triangle, NO_HIT);
    let w = |nodes, triangles| fisheye_rt::trace::cast::CastWork { nodes, triangles };
    assert_eq!(work, [w(1, 1), w(1, 0)]);
    let batch = plain.upload(ctx(), &rays).unwrap();
    let message = plain
        .read_work(ctx(), &batch)
        .expect_err("refused")
        .to_string();
    assert!(message.contains("RayCast::counting"), "{message}");
}
