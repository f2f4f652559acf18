//! The GPU tracer against the f64 reference tracer, and its hard cases, by readback. The
//! tolerances, and why they are what they are, are in `tests/common/mod.rs`.

#[path = "../common/mod.rs"]
mod common;
mod frames;
mod shading;

use common::{SYNTHETIC, assert_agrees, assert_every_hit_is, both, camera, ctx};
use fisheye_rt::scene::{Camera, Light, Material, MeshBuilder, builtin};
use fisheye_rt::trace::{NO_HIT, RenderOptions, cpu::Reference, render};
use glam::{DVec3, Vec2, Vec3};

#[test]
fn builtin_scenes_match_the_reference() {
    for (name, spec) in [
        ("default", "equidistant:f=0.42,fov=180"),
        ("default", "rectilinear:f=0.8"),
        ("grid", "samyang-7.5mm"),
        ("many-small", "equidistant:f=0.3"),
        // Calibrated cameras: TUM-VI's Kannala–Brandt lens and a double sphere, at this size.
        (
            "default",
            "kb:fx=47.7,cx=63.5,cy=47.5,k1=0.0034824,k2=0.00071503,k3=-0.0020532,k4=0.00020294",
        ),
        ("grid", "ds:fx=40,fy=39,cx=63.5,cy=47.5,xi=-0.18,alpha=0.59"),
    ] {
        let scene = builtin::scene(name).unwrap();
        let (gpu, cpu) = both(&scene, &camera(spec, 128, 96));
        let (valid, hits) = gpu.counts();
        assert!(hits > valid / 3, "{name}: only {hits} hits of {valid}");
        assert_agrees(&format!("{name} through {spec}"), &gpu, &cpu, SYNTHETIC);
    }
}

#[test]
fn reference_bvh_matches_brute_force() {
    let scene = builtin::scene("default").unwrap();
    let reference = Reference::new(&scene, 0);
    let cam = camera("equidistant:f=0.25", 48, 48);
    let rotation = scene.camera.rotation();
    let mut hits = 0;
    for dir in cam.directions().into_iter().flatten() {
        let d = rotation * dir;
        let a = reference.trace(DVec3::ZERO, d, 0.0, f64::INFINITY, false);
        let b = reference.trace_brute_force(DVec3::ZERO, d);
        assert_eq!(a.map(|h| h.triangle), b.map(|h| h.triangle));
        hits += usize::from(a.is_some());
    }
    assert!(hits > 1000);
}

/// A camera inside a closed tessellated sphere hits on every pixel inside the image circle:
/// no ray leaks through a shared edge or vertex. At the centre, rays pass exactly through the
/// pole vertices where 64 triangles meet (the camera looks straight up).
#[test]
fn closed_sphere_does_not_leak() {
    for (centre, look) in [
        (DVec3::ZERO, DVec3::Y),
        (DVec3::new(0.13, -0.21, 0.07), -DVec3::Z),
    ] {
        let mut b = MeshBuilder::new();
        let m = b.material(Material::diffuse("inside", Vec3::splat(0.5)));
        b.sphere(DVec3::ZERO, 1.0, 64, 32, true, m);
        let scene = b.finish(
            Vec::new(),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::ONE,
            Camera {
                position: centre,
                look_at: centre + look,
                up: DVec3::X,
            },
        );
        // A 360° field, every direction (θ up to 180°, a circle of radius 0.4π half-widths);
        // odd size: the centre ray is the optical axis itself.
        let cam = camera("equidistant:f=0.4", 161, 161);
        let out = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
        let (valid, hits) = out.counts();
        assert!(valid > 15_000);
        assert_eq!(hits, valid, "{} rays leaked from {centre}", valid - hits);
    }
}

/// A ray through the shared vertex of a flat fan hits it (odd image: the centre pixel's ray is
/// the axis, through the vertex).
#[test]
fn ray_through_shared_fan_vertex_hits() {
    let mut b = MeshBuilder::new();
    let m = b.material(Material::diffuse("fan", Vec3::ONE));
    let centre = DVec3::new(0.0, 0.0, -2.0);
    let n = 7;
    for k in 0..n {
        let angle = |k: u32| std::f64::consts::TAU * f64::from(k) / f64::from(n) + 0.3;
        let p = |k: u32| centre + DVec3::new(angle(k).cos(), angle(k).sin(), 0.0);
        b.triangle([centre, p(k), p(k + 1)], None, None, m);
    }
    let scene = b.finish(
        Vec::new(),
        Vec3::ZERO,
        Vec3::ONE,
        Camera {
            position: DVec3::ZERO,
            look_at: centre,
            up: DVec3::Y,
        },
    );
    let cam = camera("rectilinear:f=4", 33, 33);
    let out = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    let centre_pixel = 16 * 33 + 16;
    assert_ne!(
        out.ids[centre_pixel], NO_HIT,
        "the ray through the fan's vertex missed"
    );
    assert!((out.geometry[centre_pixel][3] - 2.0).abs() < 1e-6);
}

/// Translating the whole scene (camera and lights too) by 1e5 units renders the same image.
#[test]
fn far_from_origin_renders_the_same() {
    let scene = builtin::scene("default").unwrap();
    let mut moved = scene.clone();
    let shift = DVec3::new(1e5, -2e5, 1.5e5);
    for t in &mut moved.triangles {
        *t = t.map(|p| p + shift);
    }
    for l in &mut moved.lights {
        if let Light::Point { position, .. } = l {
            *position += shift;
        }
    }
    moved.camera.position += shift;
    moved.camera.look_at += shift;
    let cam = camera("equidistant:f=0.42,fov=180", 96, 72);
    let a = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    let b = render(ctx(), &moved, &cam, &RenderOptions::default()).unwrap();
    // Positions become camera-relative in f64 before they are rounded to f32, so the shift
    // changes them by at most an ulp: the two renders agree as the GPU and the reference do.
    assert_agrees("shifted by 1e5", &b, &a, SYNTHETIC);
}

#[test]
fn empty_one_triangle_and_degenerate_scenes() {
    let camera_pose = Camera {
        position: DVec3::ZERO,
        look_at: -DVec3::Z,
        up: DVec3::Y,
    };
    let sky = Vec3::new(0.3, 0.5, 0.7);
    let cam = camera("stereographic:f=0.4", 64, 48);

    // Empty: every ray sees the sky, no id, nothing masked wrongly.
    let empty = MeshBuilder::new().finish(Vec::new(), sky, Vec3::ONE, camera_pose);
    let out = render(ctx(), &empty, &cam, &RenderOptions::default()).unwrap();
    assert!(out.ids.iter().all(|&id| id == NO_HIT));
    for (i, c) in out.colour.iter().enumerate() {
        assert!(out.valid(i));
        assert_eq!(Vec3::from_slice(&c[..3]), sky);
    }

    // One triangle, and zero-area ones (repeated and collinear corners) that must never hit.
    let mut b = MeshBuilder::new();
    let m = b.material(Material::diffuse("tri", Vec3::ONE));
    b.triangle(
        [
            DVec3::new(-1.0, -1.0, -2.0),
            DVec3::new(1.0, -1.0, -2.0),
            DVec3::new(0.0, 1.0, -2.0),
        ],
        None,
        None,
        m,
    );
    let p = DVec3::new(0.0, 0.0, -1.5);
    b.triangle([p, p, p], None, None, m);
    b.triangle([p, p + DVec3::X, p + 2.0 * DVec3::X], None, None, m);
    b.triangle([p - DVec3::Y, p, p + DVec3::Y], None, None, m);
    let scene = b.finish(Vec::new(), sky, Vec3::ONE, camera_pose);
    let (gpu, cpu) = both(&scene, &camera("rectilinear:f=1", 64, 48));
    assert!(
        gpu.ids.iter().all(|&id| id == 0 || id == NO_HIT),
        "a degenerate triangle was hit"
    );
    assert!(gpu.ids.iter().filter(|&&id| id == 0).count() > 200);
    // Flat, unlit but for the ambient term: every compared colour is exact.
    assert_eq!(assert_agrees("one triangle", &gpu, &cpu, SYNTHETIC), 0.0);
}

/// The depth and point arrays put the hit where it is in the camera's frame: a wall 2 units
/// ahead and one 3 units behind, perpendicular to the optical axis, seen through a 270° lens,
/// have depth 2 and -3 at every pixel that sees them (the camera's z: x right, y down, z
/// forward), whatever the angle; the point's length is the range and its z the depth; a miss
/// or a masked pixel is zero.
#[test]
fn depth_and_point_put_walls_where_they_stand() {
    use fisheye_rt::trace::{Channel, PixelRays, Values};
    let mut b = MeshBuilder::new();
    let m = b.material(Material::diffuse("wall", Vec3::ONE));
    let side = DVec3::new(100.0, 0.0, 0.0);
    let up = DVec3::new(0.0, 100.0, 0.0);
    b.quad(DVec3::new(-50.0, -50.0, -2.0), side, up, Vec2::ONE, m);
    b.quad(DVec3::new(-50.0, -50.0, 3.0), side, up, Vec2::ONE, m);
    let pose = Camera {
        position: DVec3::ZERO,
        look_at: DVec3::new(0.0, 0.0, -1.0),
        up: DVec3::Y,
    };
    let scene = b.finish(Vec::new(), Vec3::ONE, Vec3::ONE, pose);
    let (w, h) = (64usize, 48usize);
    let cam = camera("equidistant:f=0.3,fov=270", w as u32, h as u32);
    let out = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    let rays = cam.directions();
    let rays = PixelRays {
        camera: &rays,
        world: &[],
    };
    let (Values::F32(1, depth), Values::F32(3, point)) = (
        out.values(Channel::Depth, rays),
        out.values(Channel::Point, rays),
    ) else {
        panic!("depth is H×W and point H×W×3 floats");
    };
    let (mut ahead, mut behind) = (0, 0);
    for i in 0..w * h {
        let p = Vec3::from_slice(&point[3 * i..3 * i + 3]);
        let range = out.geometry[i][3];
        let Some(d) = rays.camera[i].filter(|_| out.ids[i] != NO_HIT) else {
            assert_eq!((depth[i], p), (0.0, Vec3::ZERO), "pixel {i} sees nothing");
            continue;
        };
        // The range is f32 (a few ulps: 2e-6 of it), along the f32 twin's ray, which lies
        // within a few 1e-7 rad of the f64 direction (the lens twins' tests): a tilt δ moves
        // the hit along a wall by tan θ · δ of its distance (2e-6 rad allowed; the largest
        // error measured is 0.3 of this tolerance).
        let (wall, cos): (f64, f64) = if d.z > 0.0 { (2.0, d.z) } else { (-3.0, -d.z) };
        let tan = (1.0 - cos * cos).sqrt() / cos;
        let tolerance = wall.abs() * (2e-6 + 2e-6 * tan);
        assert!(
            (f64::from(depth[i]) - wall).abs() < tolerance,
            "pixel {i}: depth {} against {wall} (θ {:.1}°)",
            depth[i],
            cos.acos().to_degrees()
        );
        assert_eq!(p.z, depth[i]);
        assert!((p.length() - range).abs() <= 1e-6 * range, "pixel {i}");
        // x right and y down, ahead of the camera and behind it alike.
        let (x, y) = (i % w, i / w);
        assert!(x >= w / 2 || p.x < 0.0, "pixel {i} is left of the centre");
        assert!(y >= h / 2 || p.y < 0.0, "pixel {i} is above the centre");
        if wall > 0.0 { ahead += 1 } else { behind += 1 }
    }
    assert!(
        ahead > 500 && behind > 200,
        "{ahead} ahead, {behind} behind"
    );
}
