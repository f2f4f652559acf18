//! OBJ/MTL scenes: the third-party scenes in `scenes/`, their materials, the framing of bare
//! OBJs, and bad files.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_agrees, both, camera, ctx, real_scene, shared};
use fisheye_rt::scene::Surface;
use fisheye_rt::scene::obj::load_obj;
use fisheye_rt::trace::{RenderOptions, render};
use glam::Vec3;

fn material<'a>(
    scene: &'a fisheye_rt::scene::Scene,
    name: &str,
) -> &'a fisheye_rt::scene::Material {
    scene.materials.iter().find(|m| m.name == name).unwrap()
}

#[test]
fn cornell_box_materials_come_from_the_mtl() {
    let original = load_obj(&shared("cornell_box/CornellBox-Original.obj")).unwrap();
    assert!(original.warnings.is_empty(), "{:?}", original.warnings);
    assert_eq!(original.scene.len(), 36);
    assert_eq!(
        material(&original.scene, "light").emission,
        Vec3::new(17.0, 12.0, 4.0)
    );
    assert_eq!(
        material(&original.scene, "leftWall").diffuse,
        Vec3::new(0.63, 0.065, 0.05)
    );

    let spheres = load_obj(&shared("cornell_box/CornellBox-Sphere.obj"))
        .unwrap()
        .scene;
    let mirror = material(&spheres, "leftSphere");
    assert_eq!(
        (mirror.surface, mirror.specular),
        (Surface::Mirror, Vec3::splat(0.95))
    );
    let glass = material(&spheres, "rightSphere");
    assert_eq!(glass.surface, Surface::Glass);
    assert_eq!((glass.ior, glass.transmission), (2.5, Vec3::splat(0.1)));
    assert!(
        spheres.normals.is_some(),
        "the sphere box has vertex normals"
    );
}

/// The Cornell box with a mirror and a glass sphere, GPU against the reference.
#[test]
fn cornell_spheres_match_the_reference() {
    let scene = load_obj(&shared("cornell_box/CornellBox-Sphere.obj"))
        .unwrap()
        .scene;
    let (gpu, cpu) = both(&scene, &camera("equisolid:f=0.6", 128, 96));
    // Measured: 2,099 of 12,288 pixels see the box.
    assert!(gpu.counts().1 > 1500);
    assert_agrees("Cornell spheres", &gpu, &cpu, real_scene(gpu.ids.len()));
}

/// A bare OBJ in its own units (the bunny is 0.15 m tall, 0.1 m off the origin) is framed:
/// every corner of its bounding box is in front of the camera and inside a 180° image.
#[test]
fn bare_obj_is_framed_whatever_its_units() {
    let loaded = load_obj(&shared("scanned/stanford-bunny.obj")).unwrap();
    let scene = loaded.scene;
    assert_eq!(scene.len(), 69_451);
    let (lo, hi) = scene.bounds().unwrap();
    let to_camera = scene.camera.rotation().transpose();
    let cam = camera("canon-8-15mm@8mm", 256, 192);
    for k in 0..8 {
        let corner = glam::DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        let dir = to_camera * (corner - scene.camera.position);
        assert!(dir.z > 0.0, "corner {corner} is behind the camera");
        assert!(
            cam.project(dir).is_some(),
            "corner {corner} is outside the image"
        );
    }
    let out = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    // Measured: about 1,700 of 49,152 pixels.
    assert!(
        out.counts().1 > 1000,
        "the bunny covers too little of the image"
    );
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn bad_obj_files_are_errors_or_warnings_naming_the_problem() {
    let dir = std::env::temp_dir().join(format!("fisheye-obj-test-{}", std::process::id()));
    // A missing file names itself.
    let missing = dir.join("missing.obj");
    let message = load_obj(&missing).err().unwrap().to_string();
    assert!(
        message.contains("missing.obj") && message.contains("cannot read the file"),
        "{message}"
    );

    // A face that indexes a vertex that does not exist.
    let bad = write(&dir, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    let message = load_obj(&bad).err().unwrap().to_string();
    assert!(message.contains("bad.obj"), "{message}");

    // A missing MTL and a missing texture warn and fall back; non-finite vertices are dropped
    // with a warning naming the mesh.
    write(
        &dir,
        "tex.mtl",
        "newmtl t\nKd 0.5 0.5 0.5\nmap_Kd nowhere.png\n",
    );
    let obj = write(
        &dir,
        "warn.obj",
        "mtllib tex.mtl\no good\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl t\nf 1 2 3\n\
         o broken\nv nan 0 0\nv 1 1 0\nv 0 1 1\nf 4 5 6\n",
    );
    let loaded = load_obj(&obj).unwrap();
    assert_eq!(loaded.scene.len(), 1);
    let text = loaded.warnings.join("\n");
    assert!(
        text.contains("nowhere.png") && text.contains("using Kd"),
        "{text}"
    );
    assert!(
        text.contains("\"broken\"") && text.contains("non-finite"),
        "{text}"
    );
    assert_eq!(material(&loaded.scene, "t").diffuse_texture, None);

    let no_mtl = write(
        &dir,
        "nomtl.obj",
        "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let loaded = load_obj(&no_mtl).unwrap();
    assert!(
        loaded.warnings.join("\n").contains("MTL"),
        "{:?}",
        loaded.warnings
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// A bare OBJ's headlight follows the camera: seen from behind, the bunny is lit by the
/// light at the eye (it faces every visible surface), not left a dark silhouette by a
/// headlight still at the automatic camera in front.
#[test]
fn the_headlight_follows_the_camera() {
    use fisheye_rt::scene::{Camera, Light};
    let mut scene = load_obj(&shared("scanned/stanford-bunny.obj"))
        .unwrap()
        .scene;
    let (lo, hi) = scene.bounds().unwrap();
    let centre = (lo + hi) / 2.0;
    let behind = Camera {
        position: 2.0 * centre - scene.camera.position,
        look_at: centre,
        up: glam::DVec3::Y,
    };
    let mut stale = scene.clone();
    stale.camera = behind;
    scene.set_camera(behind);
    assert!(matches!(
        scene.lights[scene.headlight.unwrap()],
        Light::Point { position, .. } if position == behind.position
    ));
    let brightness = |scene: &fisheye_rt::scene::Scene| {
        let out = render(
            ctx(),
            scene,
            &camera("rectilinear:f=1", 64, 48),
            &Default::default(),
        )
        .unwrap();
        let hits: Vec<f32> = (0..out.ids.len())
            .filter(|&i| out.ids[i] != fisheye_rt::trace::NO_HIT)
            .map(|i| out.colour[i][..3].iter().sum::<f32>() / 3.0)
            .collect();
        assert!(hits.len() > 300, "{} pixels see the bunny", hits.len());
        hits.iter().sum::<f32>() / hits.len() as f32
    };
    let (followed, left) = (brightness(&scene), brightness(&stale));
    eprintln!(
        "mean radiance from behind: {followed:.3} with the headlight at the eye, {left:.3} without"
    );
    assert!(followed > 2.0 * left, "{followed} vs {left}");
}

/// A bare OBJ framed for a lens: its bounding sphere fills `FRAME_FILL` of the picture, for
/// lenses from a 90° rectilinear to a 360° equidistant (which stops at `WIDEST_FRAMING`) and
/// a calibrated one. Measured through
/// the lens's f64 pixel directions, apart from the framing's own projections: along the row
/// and column through the sphere's centre, the share of the lit pixels (those inside the
/// picture) whose rays meet the sphere.
#[test]
fn bare_objs_fill_the_same_share_of_every_lens() {
    use fisheye_rt::scene::{FRAME_FILL, WIDEST_FRAMING};
    use fisheye_rt::trace::world_directions;
    use glam::DVec3;
    let loaded = load_obj(&shared("scanned/stanford-bunny.obj"))
        .unwrap()
        .scene;
    let (lo, hi) = loaded.framed.expect("a bare OBJ's camera is placed for it");
    let centre = (lo + hi) / 2.0;
    let radius = (hi - lo).length() / 2.0;
    let lenses = [
        "canon-8-15mm@8mm",
        "samyang-7.5mm",
        "rectilinear:f=1",
        "stereographic:f=0.4",
        "equidistant:f=0.6",
        "equidistant:f=0.3",
        "orthographic:f=1.54",
        "kb:fx=190.978,fy=190.973,cx=254.932,cy=256.897,k1=0.0034824,k2=0.00071503,\
         k3=-0.0020532,k4=0.00020294",
    ];
    for spec in lenses {
        let size = if spec.starts_with("kb") {
            (512, 512)
        } else {
            (320, 240)
        };
        let lens = camera(spec, size.0, size.1);
        let mut scene = loaded.clone();
        let angle = scene.frame_for(&lens).expect("framed");
        let eye = scene.camera.position;
        assert_eq!(scene.camera.look_at, centre);
        // The sphere as seen from the eye: the cone of half-angle asin(R / distance).
        let seen = (radius / eye.distance(centre)).asin();
        assert!((seen - angle).abs() < 1e-9, "{spec}: {seen} vs {angle}");
        let Some(fisheye_rt::scene::Light::Point {
            position,
            intensity,
        }) = scene.headlight.map(|i| scene.lights[i])
        else {
            panic!("a headlight")
        };
        assert_eq!(position, eye);
        let irradiance = f64::from(intensity.x) / eye.distance_squared(centre);
        assert!((irradiance - 0.6).abs() < 1e-5, "{spec}: {irradiance}");

        let directions = world_directions(&lens, &scene.camera);
        let axis = (centre - eye).normalize();
        let meets = |d: DVec3| d.angle_between(axis) <= seen;
        // The pixel whose ray is nearest the sphere's centre, then outwards from it.
        let (w, h) = (size.0 as i64, size.1 as i64);
        let nearest = (0..directions.len())
            .filter_map(|i| directions[i].map(|d| (i, d.angle_between(axis))))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap()
            .0 as i64;
        let (ci, cj) = (nearest % w, nearest / w);
        let mut shares = Vec::new();
        for (di, dj) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            let (mut lit, mut inside) = (0, 0);
            let (mut i, mut j) = (ci, cj);
            while (0..w).contains(&i) && (0..h).contains(&j) {
                match directions[(j * w + i) as usize] {
                    Some(d) => {
                        lit += 1;
                        inside += usize::from(meets(d));
                    }
                    None => break,
                }
                i += di;
                j += dj;
            }
            shares.push((inside as f64 / lit as f64, lit));
        }
        // The tightest direction is at the fill, to a pixel; the others within it. A lens
        // past 200° would need the eye inside the sphere: it stops at the widest framing.
        let (widest, lit) = shares
            .iter()
            .copied()
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap();
        let pixel = 1.5 / lit as f64;
        let message = format!("{spec}: the sphere fills {shares:?} of the picture along its axes");
        if angle == WIDEST_FRAMING.to_radians() {
            assert!(
                spec == "equidistant:f=0.3" && widest < FRAME_FILL,
                "{message}"
            );
        } else {
            assert!((widest - FRAME_FILL).abs() <= pixel, "{message}");
        }
    }
}
