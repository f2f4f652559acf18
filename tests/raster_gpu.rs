//! The rasterized cube faces against the traced ones, texel for texel: equal on diffuse,
//! unshadowed surfaces; shadow maps against shadow rays; the three raster methods against each
//! other; what mirrors and glass show; and only the reachable parts rendered.

mod common;

use common::{camera, ctx, on_id_edge};
use fisheye_rt::cube::{Coverage, CubeMap, CubeMethod, CubeSettings, FACES, bordered, face_camera};
use fisheye_rt::lens::ImageSize;
use fisheye_rt::lens::gpu::DirectionSource;
use fisheye_rt::raster::RasterMethod;
use fisheye_rt::scene::{Camera, Light, Material, MeshBuilder, Scene, builtin, checker};
use fisheye_rt::trace::{GpuScene, RenderOptions, RenderOutput, TracePass};
use glam::{DVec3, Vec2, Vec3};

const METHODS: [RasterMethod; 3] = [
    RasterMethod::Forward,
    RasterMethod::Deferred,
    RasterMethod::SinglePass,
];

/// Every face of the cube, whole, as the tracer renders it for `CubeMethod::Traced`: colour
/// and ids, in [`FACES`] order.
fn traced_faces(gpu_scene: &GpuScene, pose: &Camera, size: u32) -> Vec<RenderOutput> {
    let cam = face_camera(size).unwrap();
    let pass = TracePass::new(ctx(), &cam, gpu_scene, DirectionSource::Computed).unwrap();
    FACES
        .iter()
        .map(|face| {
            pass.set_view(
                ctx(),
                gpu_scene,
                0,
                pose.position,
                pose.rotation() * face.rotation(),
                [0, 0],
            );
            let mut encoder = ctx().device.create_command_encoder(&Default::default());
            pass.encode(&mut encoder, gpu_scene, None);
            ctx().queue.submit([encoder.finish()]);
            pass.read(ctx()).unwrap()
        })
        .collect()
}

/// Every face of the cube, whole, rasterized by `method` (a 360° lens reaches all six).
fn raster_faces(
    gpu_scene: &GpuScene,
    pose: &Camera,
    size: u32,
    method: RasterMethod,
) -> Vec<[f32; 4]> {
    let settings = CubeSettings {
        coverage: Coverage::WholeFaces,
        ..CubeSettings::new(size, CubeMethod::Raster(method))
    };
    let all_round = camera("equidistant:f=0.2,fov=360", 64, 64);
    let cube = CubeMap::new(ctx(), &all_round, gpu_scene, &settings).unwrap();
    assert!(cube.regions().iter().all(Option::is_some));
    cube.render(ctx(), gpu_scene, pose).unwrap();
    cube.texels(ctx()).unwrap()
}

/// Per texel of every face away from the traced ids' edges (where the two may see different
/// triangles, by the rasterizer's coverage rules against the ray's edge test): the largest
/// colour difference relative to the traced colour's brightest channel (floored at 0.05).
/// Also returns the share of texels left out.
fn differences(traced: &[RenderOutput], raster: &[[f32; 4]], size: u32) -> (Vec<f64>, f64) {
    let side = bordered(size) as usize;
    let face_size = ImageSize::new(side as u32, side as u32).unwrap();
    let mut out = Vec::new();
    let mut skipped = 0;
    for (f, face) in traced.iter().enumerate() {
        for i in 0..side * side {
            if on_id_edge(&face.ids, face_size, i) {
                skipped += 1;
                continue;
            }
            let (t, r) = (face.colour[i], raster[f * side * side + i]);
            assert!(r.iter().all(|c| c.is_finite()), "face {f} texel {i}: {r:?}");
            let scale = f64::from(t[0].max(t[1]).max(t[2])).max(0.05);
            let e = (0..3)
                .map(|k| f64::from((t[k] - r[k]).abs()))
                .fold(0.0, f64::max);
            out.push(e / scale);
        }
    }
    (out, skipped as f64 / (6 * side * side) as f64)
}

/// Inside a textured sphere (smooth normals) with a point light: every surface is diffuse and
/// every point sees the light, so a rasterizer can shade it exactly as the tracer does.
fn diffuse_unshadowed() -> Scene {
    let mut b = MeshBuilder::new();
    let texture = b.texture(checker(
        "walls",
        64,
        8,
        [200, 60, 40],
        [40, 160, 220],
        Some([250; 3]),
    ));
    let mut walls = Material::diffuse("walls", Vec3::splat(0.9));
    walls.diffuse_texture = Some(texture);
    walls.specular = Vec3::splat(0.2);
    walls.shininess = 20.0;
    let walls = b.material(walls);
    b.sphere(DVec3::ZERO, 5.0, 16, 8, true, walls);
    let lights = vec![Light::Point {
        position: DVec3::new(-1.0, 1.5, 1.0),
        intensity: Vec3::splat(12.0),
    }];
    let camera = Camera {
        position: DVec3::new(0.5, 0.3, -0.2),
        look_at: DVec3::new(1.0, 0.1, 2.0),
        up: DVec3::Y,
    };
    b.finish(lights, Vec3::splat(0.3), Vec3::splat(0.05), camera)
}

/// On diffuse, unshadowed surfaces the rasterized faces equal the traced ones: both shade with
/// the same WGSL at the same texel centres, and differ only in how they find the point (the
/// rasterizer's interpolated barycentrics against the ray's intersection, both f32).
#[test]
fn raster_faces_equal_traced_faces_on_diffuse_unshadowed_surfaces() {
    let scene = diffuse_unshadowed();
    assert!(scene.materials.iter().all(|m| m.opacity == 1.0));
    let gpu_scene = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
    let size = 64;
    let traced = traced_faces(&gpu_scene, &scene.camera, size);
    for method in METHODS {
        let raster = raster_faces(&gpu_scene, &scene.camera, size, method);
        let (diff, skipped) = differences(&traced, &raster, size);
        let worst = diff.iter().copied().fold(0.0, f64::max);
        let mean = diff.iter().sum::<f64>() / diff.len() as f64;
        eprintln!(
            "{method:?}: {} texels compared ({:.1}% on id edges left out), relative colour \
             difference mean {mean:.2e}, largest {worst:.2e}",
            diff.len(),
            100.0 * skipped
        );
        // The sphere's 256 triangles are about 10 texels across on these faces, so about a
        // third of the texels border another triangle; that still leaves over 15,000.
        assert!(skipped < 0.5, "{method:?}: {skipped}");
        // Measured: mean 2.3e-5, largest 7.3e-5 (f32 rounding of the hit point and the
        // texture lookup); 2e-4 leaves room for other drivers' rounding, and is far below
        // any shading difference (a missed light or texture is > 1e-1).
        assert!(worst < 2e-4, "{method:?}: {worst}");
    }
}

/// A floor with a box and a ball on it under one light, seen from above.
fn shadowed(light: Light) -> Scene {
    let mut b = MeshBuilder::new();
    let grey = b.material(Material::diffuse("grey", Vec3::splat(0.7)));
    let red = b.material(Material::diffuse("red", Vec3::new(0.8, 0.2, 0.1)));
    b.quad(
        DVec3::new(-10.0, 0.0, -10.0),
        DVec3::new(0.0, 0.0, 20.0),
        DVec3::new(20.0, 0.0, 0.0),
        Vec2::ONE,
        grey,
    );
    // A floating slab (a large, sharp shadow) and a ball (a round one, and self-shadowing).
    b.cuboid(DVec3::new(-2.0, 1.5, -2.0), DVec3::new(2.0, 1.8, 2.0), red);
    b.sphere(DVec3::new(3.0, 1.0, 1.0), 1.0, 24, 12, false, red);
    let camera = Camera {
        position: DVec3::new(0.0, 2.5, -4.0),
        look_at: DVec3::new(0.5, 0.0, 1.0),
        up: DVec3::Y,
    };
    b.finish(vec![light], Vec3::splat(0.3), Vec3::splat(0.1), camera)
}

/// Shadow maps against shadow rays, for a sun and for a point light: the faces agree except
/// along shadow edges, which the maps soften (2×2 filtering) and shift (the normal offset) by
/// about a texel, while a real share of the floor is in shadow.
#[test]
fn shadow_maps_agree_with_shadow_rays_but_at_shadow_edges() {
    let lights = [
        Light::Directional {
            direction: DVec3::new(1.0, -1.0, 0.3),
            irradiance: Vec3::splat(2.0),
        },
        Light::Point {
            position: DVec3::new(-3.0, 5.0, -2.0),
            intensity: Vec3::splat(40.0),
        },
    ];
    let size = 64;
    for light in lights {
        let scene = shadowed(light);
        let gpu_scene = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
        let traced = traced_faces(&gpu_scene, &scene.camera, size);
        // The floor in shadow shows its ambient term alone: 0.7 × 0.1.
        let in_shadow = traced
            .iter()
            .flat_map(|f| &f.colour)
            .filter(|c| (c[0] - 0.07).abs() < 1e-5 && (c[1] - 0.07).abs() < 1e-5)
            .count();
        let texels = 6 * bordered(size) * bordered(size);
        let shadow_share = in_shadow as f64 / f64::from(texels);
        for method in METHODS {
            let raster = raster_faces(&gpu_scene, &scene.camera, size, method);
            let (diff, _) = differences(&traced, &raster, size);
            let off = diff.iter().filter(|&&e| e > 0.02).count() as f64 / diff.len() as f64;
            eprintln!(
                "{light:?}, {method:?}: {:.1}% of the texels in shadow; {:.2}% of the \
                 texels compared differ by more than 2%",
                100.0 * shadow_share,
                100.0 * off
            );
            // Without shadows the raster faces would differ on every shadowed texel.
            assert!(shadow_share > 0.01, "{shadow_share}");
            assert!(off < 0.1 * shadow_share, "{method:?}: {off}");
        }
    }
}

/// What a rasterizer shows where the tracer would cast rays: a mirror reflects the sky tinted
/// by its colour, glass reflects and transmits it by Fresnel's split (at normal incidence,
/// `R = ((n - 1) / (n + 1))²`).
#[test]
fn mirrors_and_glass_show_the_sky() {
    let sky = Vec3::new(0.2, 0.4, 0.8);
    let tint = Vec3::new(0.9, 0.8, 0.5);
    let ior = 1.5f32;
    let r = ((ior - 1.0) / (ior + 1.0)).powi(2);
    let mut tinted_glass = Material::glass("glass", ior);
    tinted_glass.transmission = Vec3::new(0.5, 1.0, 1.0);
    let expected_glass = sky * (Vec3::splat(r) + (1.0 - r) * tinted_glass.transmission);
    for (material, expected) in [
        (Material::mirror("mirror", tint), tint * sky),
        (tinted_glass, expected_glass),
    ] {
        let mut b = MeshBuilder::new();
        let m = b.material(material);
        // A wall facing the camera, filling the front face.
        b.quad(
            DVec3::new(-50.0, -50.0, 5.0),
            DVec3::new(100.0, 0.0, 0.0),
            DVec3::new(0.0, 100.0, 0.0),
            Vec2::ONE,
            m,
        );
        let camera = Camera {
            position: DVec3::ZERO,
            look_at: DVec3::Z,
            up: DVec3::Y,
        };
        let scene = b.finish(Vec::new(), sky, Vec3::splat(0.5), camera);
        let gpu_scene = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
        let size = 16;
        let side = bordered(size) as usize;
        for method in METHODS {
            let texels = raster_faces(&gpu_scene, &scene.camera, size, method);
            // The front face's centre texel: half a texel off the axis (0.7°).
            let centre = texels[(4 * side + side / 2) * side + side / 2];
            let e = (Vec3::from_slice(&centre[..3]) - expected)
                .abs()
                .max_element();
            assert!(e < 1e-4, "{method:?}: {centre:?} vs {expected}");
            // The back face sees the sky itself.
            let back = texels[(5 * side + side / 2) * side + side / 2];
            assert_eq!(Vec3::from_slice(&back[..3]), sky);
        }
    }
}

/// The three raster methods draw identical faces, bit for bit (the same coverage, and the same
/// shading code on the same interpolated inputs), on the default room, with everything it
/// has: textures, smooth normals, mirrors, glass, shadows from two lights.
#[test]
fn forward_deferred_and_single_pass_agree() {
    let scene = builtin::scene("default").unwrap();
    let gpu_scene = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
    let size = 48;
    let forward = raster_faces(&gpu_scene, &scene.camera, size, RasterMethod::Forward);
    for method in [RasterMethod::Deferred, RasterMethod::SinglePass] {
        let other = raster_faces(&gpu_scene, &scene.camera, size, method);
        let differing = forward
            .iter()
            .zip(&other)
            .filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits))
            .count();
        assert_eq!(
            differing, 0,
            "{method:?}: {differing} texels differ from Forward's"
        );
    }
}

/// Faces the lens cannot reach are not drawn, and of the others only the part the sampler
/// reads (by scissor; per view in the single pass): the image is bit for bit the one made
/// from whole faces. A narrow lens needs the front face alone.
#[test]
fn only_the_reachable_parts_of_faces_are_rasterized() {
    let scene = builtin::scene("default").unwrap();
    let gpu_scene = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
    for (spec, faces) in [("equidistant:f=0.45,fov=180", 5), ("rectilinear:f=2", 1)] {
        let cam = camera(spec, 64, 48);
        for method in METHODS {
            let render = |coverage| {
                let settings = CubeSettings {
                    coverage,
                    shadow_size: 512,
                    ..CubeSettings::new(32, CubeMethod::Raster(method))
                };
                let cube = CubeMap::new(ctx(), &cam, &gpu_scene, &settings).unwrap();
                assert_eq!(cube.regions().iter().flatten().count(), faces);
                let colour = cube.render(ctx(), &gpu_scene, &scene.camera).unwrap();
                colour
                    .iter()
                    .flatten()
                    .map(|x| x.to_bits())
                    .collect::<Vec<_>>()
            };
            assert_eq!(
                render(Coverage::Reachable),
                render(Coverage::WholeFaces),
                "{spec}, {method:?}"
            );
        }
    }
}
