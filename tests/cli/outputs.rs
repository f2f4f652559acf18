//! `fisheye render`: ground truth arrays, scene files and poses, cube maps, ray queries.

use super::*;

fn npy<T: npyz::Deserialize>(path: &std::path::Path) -> (Vec<u64>, Vec<T>) {
    let bytes = std::fs::read(path).unwrap();
    let file = npyz::NpyFile::new(&bytes[..]).unwrap();
    let shape = file.shape().to_vec();
    (shape, file.into_vec().unwrap())
}

/// `--outputs` writes ground truth through the lens as NPY, consistent across channels and
/// with the PNG's mask, and equal to the f64 reference's: ids, ranges and normals under the
/// tolerances of `tests/common/mod.rs`, and directions that, walked for the written range from
/// the camera, land on the written triangle in the world (which checks their frame without the
/// camera rotation the renderer and the reference share); and camera-frame points that,
/// turned by the scene camera's pose, are those walks, and whose z is the depth.
#[test]
fn render_writes_ground_truth_arrays() {
    let dir = std::env::temp_dir().join(format!("fisheye-npy-{}", std::process::id()));
    let png = dir.join("view.png");
    let args = [
        "render",
        "builtin:default",
        "--lens",
        "canon-8-15mm@8mm",
        "--size",
        "64x48",
        "--out",
        png.to_str().unwrap(),
        "--outputs",
        "range,normal,id,direction,mask,depth,point",
    ];
    stdout(&fisheye(&args, ""));
    let (shape, range) = npy::<f32>(&dir.join("view.range.npy"));
    assert_eq!(shape, [48, 64]);
    let (shape, normal) = npy::<f32>(&dir.join("view.normal.npy"));
    assert_eq!(shape, [48, 64, 3]);
    let (_, ids) = npy::<u32>(&dir.join("view.id.npy"));
    let (shape, direction) = npy::<f32>(&dir.join("view.direction.npy"));
    assert_eq!(shape, [48, 64, 3]);
    let (_, mask) = npy::<u8>(&dir.join("view.mask.npy"));
    let (shape, depth) = npy::<f32>(&dir.join("view.depth.npy"));
    assert_eq!(shape, [48, 64]);
    let (shape, point) = npy::<f32>(&dir.join("view.point.npy"));
    assert_eq!(shape, [48, 64, 3]);
    // The point is the hit in the camera's frame: turned by the scene camera's pose it is
    // the written direction walked for the written range; its z is the depth.
    let rotation = fisheye_rt::scene::builtin::scene("default")
        .unwrap()
        .camera
        .rotation();
    // The PNG's alpha is the lens's coverage of each pixel (16 rays a pixel by default); the
    // mask is its centre's. A pixel the lens covers whole has its centre inside (the image
    // circle is convex, and the centre lies among the samples), and one whose centre is
    // inside is covered at least in part (the circle's radius is 21 pixels here); partial
    // coverage is rare: only along the circle's edge.
    let image = image::open(&png).unwrap().to_rgba8();
    let partial = image.pixels().filter(|p| p[3] != 0 && p[3] != 255).count();
    assert!(
        partial > 0 && partial < 300,
        "{partial} pixels partly covered"
    );
    for (i, alpha) in image.pixels().map(|p| p[3]).enumerate() {
        assert!(alpha != 255 || mask[i] == 1, "mask at {i}: alpha {alpha}");
        assert!(mask[i] == 0 || alpha > 0, "mask at {i}: alpha {alpha}");
        let d = &direction[3 * i..3 * i + 3];
        let n = &normal[3 * i..3 * i + 3];
        let length = |v: &[f32]| v.iter().map(|x| x * x).sum::<f32>().sqrt();
        if mask[i] == 1 {
            assert!((length(d) - 1.0).abs() < 1e-6, "direction at {i}");
        } else {
            assert_eq!(length(d), 0.0);
            assert_eq!(ids[i], u32::MAX);
        }
        let p = glam::DVec3::from_array(std::array::from_fn(|k| f64::from(point[3 * i + k])));
        let walked =
            glam::DVec3::from_array(std::array::from_fn(|k| f64::from(d[k]))) * f64::from(range[i]);
        assert!(
            (rotation * p - walked).length() <= 1e-5 * f64::from(range[i]),
            "point at {i}: {p} turned is not {walked}"
        );
        assert_eq!(point[3 * i + 2], depth[i], "depth at {i}");
        // The default room is closed: every ray hits, at a positive range, with a unit normal.
        if ids[i] != u32::MAX {
            assert!(
                range[i] > 0.0 && (length(n) - 1.0).abs() < 1e-5,
                "hit at {i}"
            );
        } else {
            assert_eq!(range[i], 0.0);
        }
    }
    assert!(mask.iter().filter(|&&m| m == 1).count() > 500);
    check_against_the_reference(&range, &normal, &ids, &direction);

    // The same arrays as OpenEXR: every value bit for bit, in the documented channels.
    let args = [&args[..], &["--format", "exr"]].concat();
    stdout(&fisheye(&args, ""));
    let exr = |name: &str| {
        let image = exr::prelude::read_all_flat_layers_from_file(dir.join(name)).unwrap();
        let layer = &image.layer_data[0];
        assert_eq!((layer.size.0, layer.size.1), (64, 48), "{name}: image size");
        layer
            .channel_data
            .list
            .iter()
            .map(|c| (c.name.to_string(), c.sample_data.clone()))
            .collect::<Vec<_>>()
    };
    use exr::prelude::FlatSamples;
    let floats = |samples: &FlatSamples| match samples {
        FlatSamples::F32(v) => v.clone(),
        _ => panic!("expected f32 samples"),
    };
    let range_exr = exr("view.range.exr");
    assert_eq!(range_exr[0].0, "Y");
    assert_eq!(floats(&range_exr[0].1), range);
    let id_exr = exr("view.id.exr");
    assert!(matches!(&id_exr[0].1, FlatSamples::U32(v) if *v == ids));
    let mask_exr = exr("view.mask.exr");
    let mask_f: Vec<f32> = mask.iter().map(|&m| f32::from(m)).collect();
    assert_eq!(floats(&mask_exr[0].1), mask_f);
    assert_eq!(floats(&exr("view.depth.exr")[0].1), depth);
    for (name, npy) in [
        ("view.normal.exr", &normal),
        ("view.direction.exr", &direction),
        ("view.point.exr", &point),
    ] {
        let channels = exr(name);
        // EXR lists channels alphabetically: B, G, R.
        let names: Vec<&str> = channels.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(names, ["B", "G", "R"], "{name}");
        for (k, (_, samples)) in channels.iter().rev().enumerate() {
            let component: Vec<f32> = npy.iter().skip(k).step_by(3).copied().collect();
            assert_eq!(floats(samples), component, "{name} component {k}");
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// The arrays of `render_writes_ground_truth_arrays` against the f64 reference.
fn check_against_the_reference(range: &[f32], normal: &[f32], ids: &[u32], direction: &[f32]) {
    use fisheye_rt::trace::cpu::Reference;
    let scene = fisheye_rt::scene::builtin::scene("default").unwrap();
    let cam = LensCamera::new(
        parse_spec("canon-8-15mm@8mm").unwrap(),
        ImageSize::new(64, 48).unwrap(),
    );
    let reference = Reference::new(&scene, 5).render(&cam);
    let tolerance = common::SYNTHETIC;
    let vector = |v: &[f32]| DVec3::new(v[0].into(), v[1].into(), v[2].into());
    let mut hits = 0;
    for i in 0..ids.len() {
        assert_eq!(ids[i], reference.ids[i], "id at pixel {i}");
        if ids[i] == u32::MAX {
            continue;
        }
        hits += 1;
        let expected = f64::from(reference.geometry[i][3]);
        let error = (f64::from(range[i]) - expected).abs() / expected;
        assert!(error <= tolerance.distance, "range at {i}: {error:e}");
        let (n, m) = (vector(&normal[3 * i..]), vector(&reference.geometry[i]));
        let angle = n.cross(m).length().atan2(n.dot(m));
        assert!(angle <= tolerance.normal, "normal at {i}: {angle:e} rad");
        // Walk the ray and find the point on the triangle's plane, inside its corners.
        let p = scene.camera.position + vector(&direction[3 * i..]) * f64::from(range[i]);
        let [a, b, c] = scene.triangles[ids[i] as usize];
        let plane = (b - a).cross(c - a).normalize();
        let off = (p - a).dot(plane).abs();
        assert!(
            off <= tolerance.distance * f64::from(range[i]),
            "pixel {i}: {off:e} off its triangle's plane"
        );
        let area = |x: DVec3, y: DVec3, z: DVec3| (y - x).cross(z - x).dot(plane);
        let total = area(a, b, c);
        for w in [area(p, b, c), area(a, p, c), area(a, b, p)] {
            assert!(
                w / total >= -1e-4,
                "pixel {i}: outside its triangle ({})",
                w / total
            );
        }
    }
    assert!(hits > 500);
}

/// A scene file renders from the command line; `--camera` replaces its pose with an explicit
/// one (the same pose renders the same bytes) or a point on its camera path.
#[test]
fn render_takes_scene_files_and_camera_poses() {
    let dir = std::env::temp_dir().join(format!("fisheye-pose-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/cornell-box.toml");
    let png = |name: &str, camera: Option<&str>| {
        let path = dir.join(name);
        let mut args = vec![
            "render",
            scene,
            "--size",
            "48x32",
            "--out",
            path.to_str().unwrap(),
        ];
        if let Some(c) = camera {
            args.extend(["--camera", c]);
        }
        stdout(&fisheye(&args, ""));
        std::fs::read(path).unwrap()
    };
    let own = png("own.png", None);
    assert_eq!(own, png("same.png", Some("0,1,0.95:0,1,0")));
    // Negative coordinates are coordinates, not flags: the same pose, looked at from the
    // other side of the eye's x = 0 plane, is a different picture.
    assert_ne!(own, png("negative.png", Some("-0.3,1,0.95:-0.1,1,-1")));
    assert_eq!(own, png("start.png", Some("path:0")));
    assert_ne!(own, png("middle.png", Some("path:0.5")));
    for (camera, wanted) in [
        ("path:2", "S must be a number in [0, 1]"),
        ("1,2:3,4,5", "expected X,Y,Z:LX,LY,LZ"),
        ("1,2,3:1,2,3", "two different finite points"),
    ] {
        let output = fisheye(&["render", scene, "--camera", camera], "");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            !output.status.success() && stderr.contains(wanted),
            "{camera}: {stderr}"
        );
    }
    let output = fisheye(&["render", "builtin:grid", "--camera", "path:0.5"], "");
    assert!(String::from_utf8_lossy(&output.stderr).contains("no camera path"));
    std::fs::remove_dir_all(dir).unwrap();
}

/// Every `--method cube-*` renders through a cube map, names the faces it rendered, and writes
/// a PNG with the same mask as the direct render, close to it; bad combinations are clear
/// errors, and so are options of the other family (`--spp`, `--filter` with a cube map,
/// `--cube-size` with direct tracing), which would otherwise be ignored.
#[test]
fn render_through_a_cube_map() {
    let dir = std::env::temp_dir().join(format!("fisheye-cube-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (direct, cube) = (dir.join("direct.png"), dir.join("cube.png"));
    // One ray a pixel, as the cube map resamples: the same mask.
    stdout(&fisheye(
        &[
            "render",
            "--size",
            "64x48",
            "--spp",
            "1",
            "-o",
            direct.to_str().unwrap(),
        ],
        "",
    ));
    let a = image::open(&direct).unwrap().to_rgba8();
    for method in ["cube-rt", "cube-forward", "cube-deferred", "cube-single"] {
        let args = ["render", "--size", "64x48", "--method", method];
        let text = stdout(&fisheye(
            &[
                &args[..],
                &["--cube-size", "32", "--shadow-size", "256"],
                &["-o", cube.to_str().unwrap()],
            ]
            .concat(),
            "",
        ));
        assert!(
            text.contains(&format!(
                "({method}): 5 faces of 32² texels (+x -x +y -y +z)"
            )),
            "{text}"
        );
        let b = image::open(&cube).unwrap().to_rgba8();
        assert!(
            a.pixels().zip(b.pixels()).all(|(p, q)| p[3] == q[3]),
            "{method}: masks differ"
        );
        // The same room: the mean displayed difference is small even where the rasterizer
        // shows the sky in the mirror and glass balls (measured 0.01 to 0.03).
        let mean = a
            .pixels()
            .zip(b.pixels())
            .map(|(p, q)| (0..3).map(|k| f64::from(p[k].abs_diff(q[k]))).sum::<f64>())
            .sum::<f64>()
            / (3.0 * 255.0 * f64::from(a.width() * a.height()));
        assert!(mean < 0.06, "{method}: mean difference {mean}");
        for (extra, wanted) in [
            (
                &["--outputs", "range", "-o", cube.to_str().unwrap()][..],
                "use --method rt",
            ),
            (&["--cube-size", "0"][..], "cube face size 0"),
            (
                &["--filter", "tent"][..],
                "--filter applies to direct tracing",
            ),
            (&["--filter", "gauss"][..], "box"),
            (
                &["--spp", "auto"][..],
                "--spp auto:0.02 applies to direct tracing",
            ),
        ] {
            let output = fisheye(&[&args[..], extra].concat(), "");
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert!(
                !output.status.success() && stderr.contains(wanted),
                "{method}: {stderr}"
            );
        }
    }
    // A face size is the cube maps': given to direct tracing it is refused, not ignored.
    for method in ["rt", "rq"] {
        let args = [
            "render",
            "--size",
            "64x48",
            "--method",
            method,
            "--cube-size",
            "32",
        ];
        let output = fisheye(&args, "");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            !output.status.success()
                && stderr.contains("--cube-size 32 applies to the cube-map methods"),
            "{method}: {stderr}"
        );
    }
    let output = fisheye(
        &["render", "--method", "cube-forward", "--shadow-size", "0"],
        "",
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && stderr.contains("shadow map size 0"),
        "{stderr}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--method rq` traces with hardware ray queries: it reports the acceleration structure's
/// build and gives the software traversal's image but at a few edge pixels.
#[test]
fn render_with_ray_queries() {
    let dir = std::env::temp_dir().join(format!("fisheye-rq-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (software, hardware) = (dir.join("rt.png"), dir.join("rq.png"));
    for (method, out) in [("rt", &software), ("rq", &hardware)] {
        let text = stdout(&fisheye(
            &[
                "render",
                "--size",
                "64x48",
                "--method",
                method,
                "-o",
                out.to_str().unwrap(),
            ],
            "",
        ));
        assert_eq!(
            text.contains("acceleration structure built by the driver in"),
            method == "rq",
            "{text}"
        );
    }
    let (a, b) = (
        image::open(&software).unwrap().to_rgba8(),
        image::open(&hardware).unwrap().to_rgba8(),
    );
    let differing = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (0..4).any(|k| p[k].abs_diff(q[k]) > 2))
        .count();
    assert!(
        differing * 50 < a.pixels().len(),
        "{differing} pixels differ"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// An instanced scene: `render` reports the scene's triangles, those stored and the instances;
/// the rasterized cube map draws a flattened copy where one fits, and where it does not the
/// error says why and which path draws instances.
#[test]
fn render_reports_instances_and_rasterizes_them_flattened() {
    let dir = std::env::temp_dir().join(format!("fisheye-instances-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("forest.png");
    let scene = [
        "render",
        "builtin:instances",
        "--size",
        "64x48",
        "--out",
        out.to_str().unwrap(),
    ];
    let text = stdout(&fisheye(&[&scene[..], &["--spp", "1"]].concat(), ""));
    assert!(
        text.contains("100000002 triangles (100002 stored, 1000 instances)"),
        "{text}"
    );
    let mut raster = [
        &scene[..],
        &["--method", "cube-forward", "--cube-size", "32"],
    ]
    .concat();
    let output = fisheye(&raster, "");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success()
            && stderr.contains("makes 100000002 triangles, more than the 50000000")
            && stderr.contains("only the BVH traversal draws instances"),
        "{stderr}"
    );
    raster[1] = "builtin:instances-few";
    stdout(&fisheye(&raster, ""));
    assert!(out.exists());
}
