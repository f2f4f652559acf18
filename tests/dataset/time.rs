//! Datasets in time: frames between the stamps, a rolling shutter, and flow through the lens.

use super::*;

/// `--frame-rate` renders frames between the file's stamps: two poses a second apart (a move
/// of 2 m along x and a quarter turn about z) at 4 Hz give five frames, the middle one at the
/// midpoint turned 45°, each with its files; the plan records the rate. A rate that is not a
/// positive number is refused naming the option.
#[test]
fn a_frame_rate_renders_poses_between_the_stamps() {
    let dir = temp_dir("frame-rate");
    let trajectory = dir.join("two.tum");
    let half = std::f64::consts::FRAC_PI_4;
    std::fs::write(
        &trajectory,
        format!(
            "0 0 0 1 0 0 0 1\n1 2 0 1 0 0 {} {}\n",
            half.sin(),
            half.cos()
        ),
    )
    .unwrap();
    let out = dir.join("set");
    let args = |rate: &str| {
        let mut command = fisheye();
        command
            .args(["dataset", "render", "--lens", "equidistant:f=0.6"])
            .args(["--size", "32x24", "--spp", "1"])
            .arg(format!("--frame-rate={rate}"))
            .arg("--trajectory")
            .arg(&trajectory)
            .arg("-o")
            .arg(&out);
        command
    };
    let said = succeed(&mut args("4"));
    assert!(
        said.contains("5 poses") && said.contains("at 4 Hz"),
        "{said}"
    );
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
    assert_eq!(plan["trajectory"]["frame_rate"], 4.0);
    let frames = plan["frames"].as_array().unwrap();
    let stamps: Vec<&str> = frames
        .iter()
        .map(|f| f["stamp"].as_str().unwrap())
        .collect();
    assert_eq!(
        stamps,
        ["0.000000", "0.250000", "0.500000", "0.750000", "1.000000"]
    );
    let rows: Vec<Vec<f64>> = serde_json::from_value(frames[2]["T_world_body"].clone()).unwrap();
    let (s, c) = half.sin_cos();
    let expected = [
        [c, -s, 0.0, 1.0],
        [s, c, 0.0, 0.0],
        [0.0, 0.0, 1.0, 1.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    for (row, want) in rows.iter().zip(expected) {
        for (v, w) in row.iter().zip(want) {
            assert!((v - w).abs() < 1e-12, "{rows:?}");
        }
    }
    for frame in frames {
        for view in frame["views"].as_array().unwrap() {
            for file in view["files"].as_object().unwrap().values() {
                assert!(out.join(file.as_str().unwrap()).is_file(), "{file}");
            }
        }
    }
    for bad in ["0", "-2", "nan"] {
        let output = args(bad).output().unwrap();
        let message = String::from_utf8_lossy(&output.stderr);
        assert!(
            !output.status.success() && message.contains("--frame-rate"),
            "{bad}: {message}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--line-delay` reads a frame's rows over time (Kalibr's convention): under a body turning
/// 1 rad/s about z, written as three stamps, each row's `direction` array is the lens's ray
/// turned by the yaw at the frame's stamp plus row × line delay (within f32 rounding, 1e-6),
/// across the stamp inside the readout. Frames whose readout reaches past the last stamp
/// are skipped with a warning naming them, and the plan (so the manifest) lists them without
/// files; a negative delay is refused naming the option. A rig's camchain gives its camera's
/// line delay unless `--line-delay` overrides it.
#[test]
fn a_rolling_shutter_times_each_row_and_skips_frames_past_the_last_stamp() {
    let dir = temp_dir("rolling");
    let trajectory = dir.join("yaw.tum");
    let pose = |t: f64| {
        let (s, c) = (t / 2.0).sin_cos();
        format!("{t} 0 0 1 0 0 {s} {c}\n")
    };
    std::fs::write(&trajectory, [0.0, 0.5, 1.0].map(pose).concat()).unwrap();
    let out = dir.join("set");
    let (line_delay, spec) = (0.01, "equidistant:f=0.6");
    let args = |delay: f64| {
        let mut command = fisheye();
        command
            .args(["dataset", "render", "--lens", spec, "--size", "32x24"])
            .args(["--spp", "1", "--frame-rate", "5", "--outputs", "direction"])
            .arg(format!("--line-delay={delay}"))
            .arg("--trajectory")
            .arg(&trajectory)
            .arg("-o")
            .arg(&out);
        command
    };
    let said = succeed(&mut args(line_delay));
    // A 24-row readout takes 0.23 s: frames at 0.8 s and 1.0 s reach past 1.0 s.
    for stem in ["000004_0.800000", "000005_1.000000"] {
        assert!(
            said.contains(&format!("warning: frame {stem} is skipped")),
            "{said}"
        );
    }
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(plan["skipped_frames"], serde_json::json!([4, 5]));
    assert_eq!(plan["cameras"][0]["shutter"]["line_delay"], line_delay);
    let frames = plan["frames"].as_array().unwrap();
    assert!(
        frames[4]["skipped"]
            .as_str()
            .unwrap()
            .contains("never extrapolated")
    );
    assert!(
        frames[4]["views"][0]["files"]
            .as_object()
            .unwrap()
            .is_empty()
    );
    let camera = fisheye_rt::lens::LensCamera::new(
        fisheye_rt::lens::parse_spec(spec).unwrap(),
        fisheye_rt::lens::ImageSize::new(32, 24).unwrap(),
    );
    for (p, stamp) in [(0, 0.0), (2, 0.4)] {
        let file = frames[p]["views"][0]["files"]["direction"]
            .as_str()
            .unwrap();
        let bytes = std::fs::read(out.join(file)).unwrap();
        let directions: Vec<f32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
        let mut worst = 0.0f64;
        for y in 0..24 {
            let yaw = glam::DMat3::from_rotation_z(stamp + f64::from(y) * line_delay);
            for x in 0..32 {
                let Some(d) = camera.pixel_direction(x, y) else {
                    continue;
                };
                let i = 3 * (y * 32 + x) as usize;
                let got = DVec3::new(
                    f64::from(directions[i]),
                    f64::from(directions[i + 1]),
                    f64::from(directions[i + 2]),
                );
                worst = worst.max((got - yaw * d).length());
            }
        }
        assert!(worst < 1e-6, "frame {p}: directions off by {worst:e}");
    }
    let output = args(-1.0).output().unwrap();
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && message.contains("--line-delay"),
        "{message}"
    );
    // A camchain's line_delay is its camera's, unless --line-delay overrides it.
    let rig = small_rig(&dir);
    let text = std::fs::read_to_string(&rig).unwrap();
    std::fs::write(
        &rig,
        text.replacen("cam0:\n", "cam0:\n  line_delay: 1.0e-4\n", 1),
    )
    .unwrap();
    for (given, cam0, skipped) in [(None, 1e-4, 1), (Some("--line-delay=0"), 0.0, 0)] {
        let out = dir.join(format!("rig-{cam0}"));
        let mut command = fisheye();
        command
            .args([
                "dataset",
                "render",
                "--rig",
                &rig,
                "--t-scene-world",
                "z-up",
            ])
            .args(["--spp", "1", "--frame-rate", "2", "--trajectory"])
            .arg(&trajectory)
            .args(given)
            .arg("-o")
            .arg(&out);
        succeed(&mut command);
        let plan: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
        assert_eq!(plan["cameras"][0]["shutter"]["line_delay"], cam0);
        assert_eq!(plan["cameras"][1]["shutter"]["line_delay"], 0.0);
        let listed = plan["skipped_frames"].as_array().unwrap().len();
        assert_eq!(listed, skipped, "{given:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--outputs flow,flow-backward,scene-flow` along a body turning 1 rad/s about the camera's
/// axis (a pure rotation, frames 0.2 s apart): each frame's flow is the lens's image of each
/// pixel's direction turned by -0.2 rad, minus the pixel's centre (within 1e-4 px: ranges are
/// f32), whatever the depth; backward flow is the same turn the other way; nearly every pixel
/// that lands is seen (all but some beside the scene's depth steps); scene flow is the hit
/// turned about the eye. The last frame has no next frame (its flow is NaN, none valid) and
/// the first no previous. Two shards write the same bytes as one process: each traces its
/// neighbours' frames for flow without writing them.
#[test]
fn flow_through_the_lens_follows_a_pure_rotation_and_shards_agree() {
    let dir = temp_dir("flow");
    let trajectory = dir.join("yaw.tum");
    let pose = |t: f64| {
        let (s, c) = (t / 2.0).sin_cos();
        format!("{t} 0 1.5 0 0 0 {s} {c}\n")
    };
    std::fs::write(&trajectory, [0.0, 1.0].map(pose).concat()).unwrap();
    let spec = "equidistant:f=0.6";
    let render = |out: &Path, shard: &str| {
        let mut command = fisheye();
        command
            .args([
                "dataset", "render", "--lens", spec, "--size", "32x24", "--spp", "1",
            ])
            .args([
                "--frame-rate",
                "5",
                "--outputs",
                "flow,flow-backward,scene-flow,range",
            ])
            .args(["--shard", shard, "--trajectory"])
            .arg(&trajectory)
            .arg("-o")
            .arg(out);
        succeed(&mut command);
    };
    let whole = dir.join("whole");
    render(&whole, "0/1");
    let sharded = dir.join("sharded");
    render(&sharded, "0/2");
    render(&sharded, "1/2");
    succeed(fisheye().args(["dataset", "merge"]).arg(&sharded));
    assert_eq!(files(&whole), files(&sharded));
    let camera = fisheye_rt::lens::LensCamera::new(
        fisheye_rt::lens::parse_spec(spec).unwrap(),
        fisheye_rt::lens::ImageSize::new(32, 24).unwrap(),
    );
    let load = |name: &str| -> Vec<f32> {
        let bytes = std::fs::read(whole.join("cam0").join(name)).unwrap();
        npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap()
    };
    let loaded = |name: &str| -> Vec<u8> {
        let bytes = std::fs::read(whole.join("cam0").join(name)).unwrap();
        npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap()
    };
    let stem = "000002_0.400000";
    let (forward, backward) = (
        load(&format!("{stem}.flow.npy")),
        load(&format!("{stem}.flow_backward.npy")),
    );
    let valid = loaded(&format!("{stem}.flow_valid.npy"));
    let (range, moved) = (
        load(&format!("{stem}.range.npy")),
        load(&format!("{stem}.scene_flow.npy")),
    );
    let (mut landed, mut seen) = (0, 0);
    for y in 0..24u32 {
        for x in 0..32u32 {
            let Some(d) = camera.pixel_direction(x, y) else {
                continue;
            };
            let i = (y * 32 + x) as usize;
            if range[i] == 0.0 {
                // No hit: nothing to follow.
                let none = [forward[2 * i], backward[2 * i], moved[3 * i]];
                assert!(none.iter().all(|v| v.is_nan()), "pixel {i} has no hit");
                continue;
            }
            let centre = glam::DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            for (flow, turn) in [(&forward, -0.2), (&backward, 0.2)] {
                let got = glam::DVec2::new(flow[2 * i].into(), flow[2 * i + 1].into());
                match camera.project(glam::DMat3::from_rotation_z(turn) * d) {
                    Some(p) => assert!((got - (p - centre)).length() < 1e-4, "pixel {i}: {got}"),
                    None => assert!(got.x.is_nan(), "pixel {i}: {got}"),
                }
            }
            let hit = d * f64::from(range[i]);
            let wanted = glam::DMat3::from_rotation_z(-0.2) * hit - hit;
            let got = DVec3::new(
                moved[3 * i].into(),
                moved[3 * i + 1].into(),
                moved[3 * i + 2].into(),
            );
            assert!(
                (got - wanted).length() < 1e-5 * hit.length().max(1.0),
                "pixel {i}: {got}"
            );
            if !forward[2 * i].is_nan() {
                landed += 1;
                seen += usize::from(valid[i]);
            }
        }
    }
    assert!(
        landed > 400 && seen * 100 >= landed * 95,
        "{seen} of {landed} seen"
    );
    let last = load("000005_1.000000.flow.npy");
    assert!(last.iter().all(|v| v.is_nan()));
    assert!(
        loaded("000005_1.000000.flow_valid.npy")
            .iter()
            .all(|&v| v == 0)
    );
    assert!(
        load("000000_0.000000.flow_backward.npy")
            .iter()
            .all(|v| v.is_nan())
    );
    let output = fisheye()
        .args([
            "render",
            "--lens",
            spec,
            "--size",
            "32x24",
            "--outputs",
            "flow",
            "-o",
        ])
        .arg(dir.join("one.png"))
        .output()
        .unwrap();
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && message.contains("dataset render --outputs flow"),
        "{message}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--imu 400` writes EuRoC's `imu0/data.csv` from the trajectory's spline, which the frames
/// follow too: the noise-free gyro integrated between two frames' times turns the first
/// frame's `T_world_body` into the second's (within 1e-5 rad over 0.1 s of 2.5 ms steps); the
/// readings start a spline step after the first stamp, 400 a second, stamped in integer
/// nanoseconds; the frames outside the spline are skipped; the camchain beside them puts each
/// camera where the rig does (read back as a rig); with `--imu-noise` the readings differ
/// from the noise-free ones, and a rate that is not the noise's update_rate is refused.
#[test]
fn an_imu_reads_the_spline_the_frames_follow() {
    let dir = temp_dir("imu");
    let out = dir.join("set");
    let noise = dir.join("imu.yaml");
    std::fs::write(
        &noise,
        "accelerometer_noise_density: 2.0e-3\naccelerometer_random_walk: 3.0e-3\n\
         gyroscope_noise_density: 1.7e-4\ngyroscope_random_walk: 1.9e-5\nupdate_rate: 400.0\n",
    )
    .unwrap();
    let args = |rate: &str| {
        let mut command = fisheye();
        command
            .args([
                "dataset",
                "render",
                "--trajectory",
                &repo("scenes/dataset/room-loop.tum"),
            ])
            .args([
                "--rig",
                &small_rig(&dir),
                "--t-scene-world",
                "z-up",
                "--spp",
                "1",
            ])
            .args(["--imu", rate, "--imu-noise"])
            .arg(&noise)
            .arg("-o")
            .arg(&out);
        command
    };
    succeed(&mut args("400"));
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(plan["skipped_frames"], serde_json::json!([0, 99]));
    let read = |name: &str| -> Vec<Vec<f64>> {
        let text = std::fs::read_to_string(out.join(name)).unwrap();
        assert!(text.starts_with("#timestamp [ns],w_RS_S_x [rad s^-1]"));
        text.lines()
            .skip(1)
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect()
    };
    let (clean, noisy) = (read("imu0/data_noise_free.csv"), read("imu0/data.csv"));
    assert_eq!(clean.len(), noisy.len());
    // From 0.05 s to 9.85 s (a spline step in from the 0 s and 9.9 s stamps), both ends.
    assert_eq!(clean.len(), 3921);
    assert_eq!((clean[0][0], clean[1][0]), (50_000_000.0, 52_500_000.0));
    assert!(
        clean
            .iter()
            .zip(&noisy)
            .all(|(c, n)| c[1] != n[1] && c[0] == n[0])
    );
    let rotation = |k: usize| {
        let rows: Vec<Vec<f64>> =
            serde_json::from_value(plan["frames"][k]["T_world_body"].clone()).unwrap();
        glam::DQuat::from_mat3(&glam::DMat3::from_cols_array_2d(&[
            [rows[0][0], rows[1][0], rows[2][0]],
            [rows[0][1], rows[1][1], rows[2][1]],
            [rows[0][2], rows[1][2], rows[2][2]],
        ]))
    };
    for k in [1, 40, 97] {
        // Frame k at 0.1 k s; readings at 0.05 + n / 400 s.
        let first = 40 * k - 20;
        let mut turned = rotation(k);
        for pair in clean[first..=first + 40].windows(2) {
            let rate = |s: &[f64]| DVec3::new(s[1], s[2], s[3]);
            let dt = (pair[1][0] - pair[0][0]) * 1e-9;
            turned *= glam::DQuat::from_scaled_axis((rate(&pair[0]) + rate(&pair[1])) * 0.5 * dt);
        }
        let off = (rotation(k + 1).inverse() * turned)
            .to_scaled_axis()
            .length();
        assert!(off < 1e-5, "frames {k} to {}: {off:e} rad", k + 1);
    }
    let rig = read_rig(&out.join("camchain-imucam.yaml")).unwrap();
    let original = read_rig(Path::new(&small_rig(&dir))).unwrap();
    assert_eq!(rig.len(), original.len());
    for (a, b) in rig.iter().zip(&original) {
        assert!(a.body_from_camera.abs_diff_eq(b.body_from_camera, 1e-12));
    }
    let output = args("200").output().unwrap();
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && message.contains("update_rate is 400 Hz"),
        "{message}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
