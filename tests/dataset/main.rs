//! `fisheye dataset`: a four-camera rig along the example 100-pose trajectory, rendered in one
//! process and in four shards at once (one stopped at a set point midway, one killed from
//! outside, a half-written file and a partial pose planted, then resumed), must give the same
//! bytes; every camera must see what
//! `fisheye render` sees from the same pose worked out by hand; rigs read from Kalibr and
//! Basalt files sit where their extrinsics say; the Python loader example reads the result.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use fisheye_rt::lens::calib::read_rig;

mod objects;
mod time;
use glam::{DAffine3, DVec3};

fn fisheye() -> Command {
    Command::new(env!("CARGO_BIN_EXE_fisheye"))
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fisheye-dataset-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn repo(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(path)
        .to_string_lossy()
        .into_owned()
}

/// The example rig (`scenes/dataset/surround-rig.yaml`) at 96×72 pixels (its intrinsics
/// scaled by 0.15 about the image corner, so the lens covers the same field).
fn small_rig(dir: &Path) -> String {
    let text = std::fs::read_to_string(repo("scenes/dataset/surround-rig.yaml"))
        .unwrap()
        .replace("[150.0, 150.0, 319.5, 239.5]", "[22.5, 22.5, 47.5, 35.5]")
        .replace("[640, 480]", "[96, 72]");
    let path = dir.join("rig.yaml");
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

fn succeed(command: &mut Command) -> String {
    let output = command.output().unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(output.status.success(), "{command:?} failed:\n{text}");
    text
}

/// Every file under `dir` but the shards' run records, by relative path, with its bytes.
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<(PathBuf, Vec<u8>)>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let relative = path.strip_prefix(root).unwrap().to_path_buf();
            if relative.starts_with("shards") {
                continue;
            }
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                out.push((relative, std::fs::read(&path).unwrap()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Complete images of camera 3 (the last written of a pose) among poses `range`.
fn written(dir: &Path, range: std::ops::Range<usize>) -> usize {
    std::fs::read_dir(dir.join("cam3"))
        .map(|entries| {
            entries
                .flatten()
                .filter_map(|e| {
                    let name = e.file_name().to_string_lossy().into_owned();
                    let index = name.strip_suffix(".png")?.split('_').next()?.parse().ok()?;
                    range.contains(&index).then_some(())
                })
                .count()
        })
        .unwrap_or(0)
}

/// The done-when of the datasets issue: a 4-camera rig along a 100-pose trajectory, from one
/// command and from 4 shards (one killed midway and resumed), byte for byte the same; the
/// merge refuses while a pose is incomplete; no temporary file is left; the Python loader
/// reads the dataset and reprojects every hit point onto its pixel with the manifest's OpenCV
/// calibration and poses.
#[test]
fn a_rig_along_a_trajectory_gives_the_same_bytes_in_one_process_or_in_resumed_shards() {
    let dir = temp_dir("shards");
    let rig = small_rig(&dir);
    let trajectory = repo("scenes/dataset/room-loop.tum");
    let common = |out: &Path| {
        let mut c = fisheye();
        c.args([
            "dataset",
            "render",
            "--trajectory",
            &trajectory,
            "--rig",
            &rig,
        ])
        .args(["--t-scene-world", "z-up", "--spp", "4"])
        .args(["--outputs", "range,normal,id,direction,mask,depth,point"])
        .arg("-o")
        .arg(out);
        c
    };
    let one = dir.join("one");
    let text = succeed(&mut common(&one));
    assert!(text.contains("rendered 100 poses (400 images"), "{text}");
    assert!(one.join("manifest.json").is_file());

    // Four shards at once: shard 1 is killed (SIGKILL, sent to itself) once it has
    // written 9 images (two poses and one camera of a third), whatever the machine's speed;
    // shard 2 is killed from here once it has written a pose, if it is still running then.
    let sharded = dir.join("sharded");
    let mut children: Vec<std::process::Child> = (0..4)
        .map(|i| {
            let mut c = common(&sharded);
            c.args(["--shard", &format!("{i}/4")])
                .stdout(Stdio::null())
                .stderr(Stdio::null());
            if i == 1 {
                c.env("FISHEYE_INJECT_FAULT", "kill-after-images:9");
            }
            c.spawn().unwrap()
        })
        .collect();
    let started = Instant::now();
    while written(&sharded, 50..75) < 1 {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "shard 2 wrote nothing"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    children[2].kill().unwrap();
    let stopped = children[1].wait().unwrap();
    assert!(!stopped.success(), "shard 1 was not stopped");
    children[2].wait().unwrap();
    for i in [0, 3] {
        assert!(children[i].wait().unwrap().success(), "shard {i}");
    }
    assert_eq!(
        written(&sharded, 25..50),
        2,
        "shard 1 stopped after 2 poses of camera 3"
    );
    // What else a kill leaves: a half-written file (a temporary name) and a pose with some
    // of its files; planted so that resuming must deal with both whatever the kill's timing.
    let leftover = sharded.join("cam0/.000030_3.0.png.4242.tmp");
    std::fs::write(&leftover, b"half a PNG").unwrap();
    std::fs::remove_file(sharded.join("cam2/000026_2.6.range.npy")).ok();
    let refused = fisheye()
        .args(["dataset", "merge"])
        .arg(&sharded)
        .output()
        .unwrap();
    let why = String::from_utf8_lossy(&refused.stderr);
    assert!(
        !refused.status.success() && why.contains("incomplete"),
        "{why}"
    );
    let text = succeed(common(&sharded).args(["--shard", "1/4", "--resume"]));
    assert!(text.contains("skipped as complete"), "{text}");
    // Shard 2 again, killed or not: a rerun finishes it (or finds nothing left to do).
    succeed(common(&sharded).args(["--shard", "2/4"]));
    assert!(!leftover.exists(), "the half-written file was not removed");
    succeed(fisheye().args(["dataset", "merge"]).arg(&sharded));

    let (a, b) = (files(&one), files(&sharded));
    let names = |f: &[(PathBuf, Vec<u8>)]| f.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b), "the two runs wrote different files");
    // 4 cameras × 100 poses × (PNG + 7 arrays), the plan and the manifest.
    assert_eq!(a.len(), 4 * 100 * 8 + 2);
    for ((path, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "{} differs between the runs", path.display());
    }
    assert!(
        a.iter()
            .all(|(p, _)| !p.to_string_lossy().ends_with(".tmp"))
    );

    let output = Command::new("python3")
        .arg(repo("examples/load_dataset.py"))
        .arg(&one)
        .output()
        .expect("python3 runs (numpy and Pillow: .ci/install-lavapipe)");
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(text.contains("100 frames, 4 cameras, 400 images"), "{text}");
    // f32 directions, ranges and points: 1e-7 relative, a few 1e-6 px at 22.5 px a radian.
    // The camera-frame points are projected as they are, with no pose: they check the depth
    // and point arrays' frame (the loader also checks them against the range).
    for what in ["hit points", "camera-frame points"] {
        let px: f64 = text
            .split(&format!("{what} reproject to their pixels within "))
            .nth(1)
            .and_then(|t| t.split_whitespace().next())
            .and_then(|t| t.parse().ok())
            .unwrap_or_else(|| panic!("no reprojection error of {what} in {text}"));
        assert!(px < 1e-3, "{what} reproject {px} px from their pixels");
    }
}

/// Each camera of the rig at two poses sees what `fisheye render` sees through the same
/// calibration from the eye and look-at point worked out here by hand from the rig's
/// drawing (front, left, back and right of a body whose x is forward and z up, in a z-up world
/// turned y-up): the same triangle ids at all but the pixels where the scene's upload origin
/// (the trajectory's first camera against each render's own) rounds a ray onto the other side
/// of an edge.
#[test]
fn every_camera_sees_what_render_sees_from_its_pose_worked_out_by_hand() {
    let dir = temp_dir("orientation");
    let rig = small_rig(&dir);
    // Two level poses: (position, yaw), z up.
    let poses = [
        (DVec3::new(3.2, 0.0, 1.5), 90f64),
        (DVec3::new(-0.5, -2.5, 1.2), 200.0),
    ];
    let tum: String = poses
        .iter()
        .enumerate()
        .map(|(i, (p, yaw))| {
            let half = yaw.to_radians() / 2.0;
            format!(
                "{i}.0 {} {} {} 0 0 {} {}\n",
                p.x,
                p.y,
                p.z,
                half.sin(),
                half.cos()
            )
        })
        .collect();
    let trajectory = dir.join("two.tum");
    std::fs::write(&trajectory, tum).unwrap();
    let out = dir.join("set");
    succeed(
        fisheye()
            .args([
                "dataset",
                "render",
                "--rig",
                &rig,
                "--t-scene-world",
                "z-up",
            ])
            .args(["--spp", "1", "--outputs", "id", "--trajectory"])
            .arg(&trajectory)
            .arg("-o")
            .arg(&out),
    );
    // z-up world to the y-up scene.
    let scene = |v: DVec3| DVec3::new(v.x, v.z, -v.y);
    for (p, &(position, yaw)) in poses.iter().enumerate() {
        let (s, c) = yaw.to_radians().sin_cos();
        let forward = DVec3::new(c, s, 0.0);
        let left = DVec3::new(-s, c, 0.0);
        let mounts = [
            (0.5 * forward, forward),
            (0.3 * left, left),
            (-0.5 * forward, -forward),
            (-0.3 * left, -left),
        ];
        for (camera, (offset, look)) in mounts.into_iter().enumerate() {
            let eye = scene(position + offset);
            let at = scene(position + offset + look);
            let pose = format!("{},{},{}:{},{},{}", eye.x, eye.y, eye.z, at.x, at.y, at.z);
            let image = dir.join(format!("render-{p}-{camera}.png"));
            succeed(
                fisheye()
                    .args([
                        "render",
                        "--calib",
                        &rig,
                        "--calib-camera",
                        &camera.to_string(),
                    ])
                    .args(["--camera", &pose, "--spp", "1", "--outputs", "id", "-o"])
                    .arg(&image),
            );
            let ids = |path: PathBuf| -> Vec<u32> {
                let bytes = std::fs::read(&path).unwrap();
                npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap()
            };
            let rendered = ids(image.with_extension("id.npy"));
            let set = ids(out.join(format!("cam{camera}/00000{p}_{p}.0.id.npy")));
            let same = rendered.iter().zip(&set).filter(|(a, b)| a == b).count();
            assert!(
                same as f64 >= 0.999 * set.len() as f64,
                "pose {p}, cam{camera}: {same} of {} pixels see the same triangle",
                set.len()
            );
        }
    }
}

fn assert_pose(t: &DAffine3, forward: DVec3, position: DVec3, what: &str) {
    let z = t.transform_vector3(DVec3::Z);
    let y = t.transform_vector3(DVec3::Y);
    assert!(
        z.abs_diff_eq(forward, 1e-12),
        "{what}: looks along {z}, not {forward}"
    );
    assert!(y.abs_diff_eq(-DVec3::Z, 1e-12), "{what}: its down is {y}");
    assert!(
        t.translation.abs_diff_eq(position, 1e-12),
        "{what}: at {}, not {position}",
        t.translation
    );
}

/// The example Kalibr rig (cam0 by T_cam_imu, the rest chained by T_cn_cnm1) and a Basalt
/// rig (T_imu_cam) put each camera where the drawing does; rigs without extrinsics, or with a
/// transform that is not rigid, are refused naming the camera.
#[test]
fn rigs_put_each_camera_where_their_extrinsics_say() {
    let rig = read_rig(Path::new(&repo("scenes/dataset/surround-rig.yaml"))).unwrap();
    let mounts = [
        (DVec3::X, DVec3::new(0.5, 0.0, 0.0)),
        (DVec3::Y, DVec3::new(0.0, 0.3, 0.0)),
        (-DVec3::X, DVec3::new(-0.5, 0.0, 0.0)),
        (-DVec3::Y, DVec3::new(0.0, -0.3, 0.0)),
    ];
    assert_eq!(rig.len(), 4);
    for (n, (camera, (forward, position))) in rig.iter().zip(mounts).enumerate() {
        assert_pose(
            &camera.body_from_camera,
            forward,
            position,
            &format!("cam{n}"),
        );
    }

    let dir = temp_dir("rigs");
    // Basalt: two cameras, the second turned 90° about the body's z (qz = sin 45°) and 0.2 m
    // to the left; the first at the body's origin looking along x (camera z = body x).
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let intrinsics = r#"{"camera_type": "kb4", "intrinsics": {"fx": 100, "fy": 100, "cx": 63.5, "cy": 47.5, "k1": 0, "k2": 0, "k3": 0, "k4": 0}}"#;
    // Camera z along body x, camera y along -z (so camera x along -y).
    let q0 = glam::DQuat::from_mat3(&glam::DMat3::from_cols(-DVec3::Y, -DVec3::Z, DVec3::X));
    let cam0 = format!(
        r#"{{"px": 0, "py": 0, "pz": 0, "qx": {}, "qy": {}, "qz": {}, "qw": {}}}"#,
        q0.x, q0.y, q0.z, q0.w
    );
    // Turned a further 90° about body z: q = (0, 0, s, s) · q0.
    let q1 = glam::DQuat::from_xyzw(0.0, 0.0, s, s) * q0;
    let cam1 = format!(
        r#"{{"px": 0, "py": 0.2, "pz": 0, "qx": {}, "qy": {}, "qz": {}, "qw": {}}}"#,
        q1.x, q1.y, q1.z, q1.w
    );
    let basalt = format!(
        r#"{{"value0": {{"T_imu_cam": [{cam0}, {cam1}], "intrinsics": [{intrinsics}, {intrinsics}], "resolution": [[128, 96], [128, 96]]}}}}"#
    );
    let path = dir.join("basalt.json");
    std::fs::write(&path, basalt).unwrap();
    let rig = read_rig(&path).unwrap();
    assert_pose(
        &rig[0].body_from_camera,
        DVec3::X,
        DVec3::ZERO,
        "basalt cam0",
    );
    assert_pose(
        &rig[1].body_from_camera,
        DVec3::Y,
        DVec3::new(0.0, 0.2, 0.0),
        "basalt cam1",
    );

    let kalibr = std::fs::read_to_string(repo("scenes/dataset/surround-rig.yaml")).unwrap();
    let refused = [
        (
            kalibr.replacen("  T_cn_cnm1:", "  T_other:", 1),
            "cam1: no T_cn_cnm1",
        ),
        (
            kalibr.replacen("[0.0, 0.0, 1.0, 0.5]", "[0.0, 0.0, 2.0, 0.5]", 1),
            "cam1: T_cn_cnm1: the rotation",
        ),
    ];
    for (text, wanted) in refused {
        let path = dir.join("bad.yaml");
        std::fs::write(&path, text).unwrap();
        let error = read_rig(&path).unwrap_err().to_string();
        assert!(error.contains(wanted), "{error:?} lacks {wanted:?}");
    }
}

/// `--spp auto:...` renders a dataset adaptively (here with `--filter tent`): its ids are
/// uniform sampling's, byte for byte (the hits of interpolated pixels are traced, never
/// interpolated, and the filter touches colour alone), its images are not, and the plan says
/// which sampling and filter made them.
#[test]
fn adaptive_datasets_keep_exact_ground_truth() {
    let dir = temp_dir("adaptive");
    let trajectory = repo("scenes/dataset/room-loop.tum");
    let render = |spp: &str, filter: &str, out: &Path| {
        succeed(
            fisheye()
                .args(["dataset", "render", "--trajectory", &trajectory])
                .args(["--lens", "samyang-7.5mm", "--size", "64x48", "--spp", spp])
                .args(["--filter", filter])
                .args(["--outputs", "id", "--shard", "0/25", "-o"])
                .arg(out),
        )
    };
    let (auto, uniform) = (dir.join("auto"), dir.join("uniform"));
    render("auto:0.05:1", "tent", &auto);
    render("4", "box", &uniform);
    let (auto_files, uniform_files) = (files(&auto), files(&uniform));
    let names = |f: &[(PathBuf, Vec<u8>)]| f.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>();
    assert_eq!(names(&auto_files), names(&uniform_files));
    let mut ids = 0;
    let mut images_differ = false;
    for ((path, a), (_, u)) in auto_files.iter().zip(&uniform_files) {
        let name = path.to_string_lossy();
        if name.ends_with(".id.npy") {
            assert_eq!(a, u, "{name}");
            ids += 1;
        } else if name.ends_with(".png") {
            images_differ |= a != u;
        }
    }
    assert_eq!(ids, 4, "four poses' ids");
    assert!(images_differ, "adaptive sampling made other images");
    let plan: serde_json::Value =
        serde_json::from_slice(&std::fs::read(auto.join("plan.json")).unwrap()).unwrap();
    assert_eq!(plan["render"]["sampling"], "auto:0.05:1");
    assert_eq!(plan["render"]["spp"], 1);
    assert_eq!(plan["render"]["filter"], "tent");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--outputs spp` writes each image's spp map beside it. Adaptive sampling's add up, over the
/// shard's images, to the rays its run record counts; they are 0 in the image's corners,
/// outside the 180° lens's circle, and at some pixels whose centres it covers
/// (interpolated), more than 1 at others (supersampled), and at most MAX + 1 (the centre
/// ray the estimate adds to MAX). Uniform sampling's, as OpenEXR, are its rays at every
/// pixel whose centre the lens covers and 0 in the corners. The plan lists the output.
#[test]
fn a_datasets_spp_maps_count_its_rays() {
    let dir = temp_dir("spp");
    let trajectory = repo("scenes/dataset/room-loop.tum");
    let render = |spp: &str, format: &str, out: &Path| {
        succeed(
            fisheye()
                .args(["dataset", "render", "--trajectory", &trajectory])
                .args([
                    "--lens",
                    "canon-8-15mm@8mm",
                    "--size",
                    "64x48",
                    "--spp",
                    spp,
                ])
                .args(["--outputs", "mask,spp", "--format", format])
                .args(["--shard", "0/20", "-o"])
                .arg(out),
        )
    };
    let (auto, uniform) = (dir.join("auto"), dir.join("uniform"));
    render("auto:0.1:4", "npy", &auto);
    render("4", "exr", &uniform);
    let npy = |path: &Path| -> Vec<u32> {
        let bytes = std::fs::read(path).unwrap();
        let file = npyz::NpyFile::new(&bytes[..]).unwrap();
        assert_eq!(file.shape(), &[48, 64], "{}", path.display());
        file.into_vec().unwrap()
    };
    let (mut rays, mut maps, mut interpolated, mut supersampled) = (0u64, 0, 0, 0);
    for (path, _) in files(&auto) {
        let Some(stem) = path.to_str().unwrap().strip_suffix(".spp.npy") else {
            continue;
        };
        let counts = npy(&auto.join(&path));
        let mask: Vec<u8> = {
            let bytes = std::fs::read(auto.join(format!("{stem}.mask.npy"))).unwrap();
            npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap()
        };
        assert_eq!(
            (counts[0], counts[64 * 48 - 1]),
            (0, 0),
            "{stem}: the corners"
        );
        for (&n, &m) in counts.iter().zip(&mask) {
            assert!(n <= 5, "{stem}: {n} rays, past MAX + 1");
            interpolated += usize::from(m == 1 && n == 0);
            supersampled += usize::from(n > 1);
        }
        rays += counts.iter().map(|&n| u64::from(n)).sum::<u64>();
        maps += 1;
    }
    assert_eq!(maps, 5, "one map an image of the shard's 5 poses");
    assert!(
        interpolated > 0 && supersampled > 0,
        "{interpolated} {supersampled}"
    );
    let record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(auto.join("shards/0-of-20.json")).unwrap()).unwrap();
    assert_eq!(record["rays"].as_u64(), Some(rays));
    let plan: serde_json::Value =
        serde_json::from_slice(&std::fs::read(auto.join("plan.json")).unwrap()).unwrap();
    assert_eq!(
        plan["render"]["outputs"],
        serde_json::json!(["mask", "spp"])
    );

    let channel_y = |path: PathBuf| -> Vec<f32> {
        let image = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
        let channel = &image.layer_data[0].channel_data.list[0];
        assert_eq!(channel.name.to_string(), "Y", "{}", path.display());
        let exr::prelude::FlatSamples::F32(values) = &channel.sample_data else {
            panic!("{}: not float", path.display());
        };
        values.clone()
    };
    let (counts, mask) = (
        channel_y(uniform.join("cam0/000000_0.0.spp.exr")),
        channel_y(uniform.join("cam0/000000_0.0.mask.exr")),
    );
    assert_eq!(counts.len(), 64 * 48);
    assert_eq!((counts[0], counts[64 * 48 - 1]), (0.0, 0.0), "the corners");
    for (n, m) in counts.iter().zip(&mask) {
        assert!(*n == 0.0 || *n == 4.0, "{n} rays");
        if *m == 1.0 {
            assert_eq!(*n, 4.0);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--outputs instance,semantic` names each pixel's object and class: an OBJ with objects
/// `chair` and `table` side by side in front of the camera gives, in every frame, the
/// chair's instance id on the left of the image and the table's on the right (as its hit's
/// triangle says: ids 0-1 are the chair's, 2-3 the table's), classes by the same names, and
/// `labels.json` naming both; `render` refuses the outputs, pointing to `dataset render`.
#[test]
fn segmentation_names_each_pixels_object_and_class() {
    let dir = temp_dir("labels");
    let obj = dir.join("room.obj");
    std::fs::write(
        &obj,
        "o chair\nv -2 -1 3\nv 0 -1 3\nv 0 1 3\nv -2 1 3\nf 1 2 3\nf 1 3 4\n\
         o table\nv 0 -1 3\nv 2 -1 3\nv 2 1 3\nv 0 1 3\nf 5 6 7\nf 5 7 8\n",
    )
    .unwrap();
    let trajectory = dir.join("still.tum");
    std::fs::write(&trajectory, "0 0 0 0 0 0 0 1\n1 0 0 0.1 0 0 0 1\n").unwrap();
    let out = dir.join("set");
    succeed(
        fisheye()
            .arg("dataset")
            .arg("render")
            .arg(&obj)
            .args([
                "--lens",
                "equidistant:f=0.6",
                "--size",
                "32x24",
                "--spp",
                "1",
            ])
            .args(["--outputs", "id,instance,semantic", "--trajectory"])
            .arg(&trajectory)
            .arg("-o")
            .arg(&out),
    );
    let labels: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("labels.json")).unwrap()).unwrap();
    let id_of = |name: &str| {
        labels["instances"]
            .as_array()
            .unwrap()
            .iter()
            .find(|o| o["name"] == name)
            .unwrap_or_else(|| panic!("no {name} in {labels}"))
            .clone()
    };
    let (chair, table) = (id_of("chair"), id_of("table"));
    let class_name = |o: &serde_json::Value| {
        labels["classes"][o["class_id"].as_u64().unwrap() as usize]["name"].clone()
    };
    assert_eq!(
        (class_name(&chair), class_name(&table)),
        ("chair".into(), "table".into())
    );
    let load = |name: String| -> Vec<u32> {
        let bytes = std::fs::read(out.join("cam0").join(name)).unwrap();
        npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap()
    };
    for stem in ["000000_0", "000001_1"] {
        let (ids, instance, semantic) = (
            load(format!("{stem}.id.npy")),
            load(format!("{stem}.instance.npy")),
            load(format!("{stem}.semantic.npy")),
        );
        let mut sides = [0, 0];
        for (i, &id) in ids.iter().enumerate() {
            let object = match id {
                0 | 1 => &chair,
                2 | 3 => &table,
                _ => {
                    assert_eq!((instance[i], semantic[i]), (u32::MAX, u32::MAX));
                    continue;
                }
            };
            assert_eq!(
                u64::from(instance[i]),
                object["id"].as_u64().unwrap(),
                "pixel {i}"
            );
            assert_eq!(u64::from(semantic[i]), object["class_id"].as_u64().unwrap());
            let left = i % 32 < 16;
            sides[usize::from(!left)] += 1;
            assert_eq!(left, id < 2, "pixel {i}: id {id}");
        }
        assert!(sides[0] > 20 && sides[1] > 20, "{stem}: {sides:?}");
    }
    let output = fisheye()
        .args(["render", "--lens", "equidistant:f=0.6", "--size", "32x24"])
        .args(["--outputs", "instance", "-o"])
        .arg(dir.join("one.png"))
        .output()
        .unwrap();
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success() && message.contains("dataset render --outputs instance"));
    std::fs::remove_dir_all(&dir).unwrap();
}
