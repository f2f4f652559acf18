//! The `fisheye` binary end to end, as a user runs it.

#[path = "../common/mod.rs"]
mod common;
mod lens_info;
mod outputs;
mod render;
mod studies;

use std::io::Write;
use std::process::{Command, Output, Stdio};

use fisheye_rt::lens::{CalibratedModel, ImageSize, LensCamera, PRESETS, parse_spec};
use glam::{DVec2, DVec3};

fn fisheye(args: &[&str], stdin: &str) -> Output {
    fisheye_with_env(args, stdin, &[])
}

fn fisheye_with_env(args: &[&str], stdin: &str, env: &[(&str, &str)]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .args(args)
        .envs(env.iter().copied())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the fisheye binary runs");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

fn stdout(output: &Output) -> String {
    assert!(
        output.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout.clone()).unwrap()
}

fn numbers(line: &str) -> Vec<f64> {
    line.split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect()
}

#[test]
fn lens_list_names_every_model_and_preset() {
    let text = stdout(&fisheye(&["lens", "list"], ""));
    for name in fisheye_rt::lens::LensModel::NAMES {
        assert!(text.contains(name), "{name} missing");
    }
    for preset in PRESETS {
        assert!(text.contains(preset.name), "{} missing", preset.name);
    }
    for ((name, _), example) in CalibratedModel::NAMES.iter().zip(CalibratedModel::EXAMPLES) {
        assert!(
            text.contains(name) && text.contains(example),
            "{name} missing"
        );
    }
}

#[test]
fn unproject_writes_directions_or_none() {
    let args = [
        "lens",
        "unproject",
        "--lens",
        "canon-8-15mm@8mm",
        "--size",
        "1024x768",
    ];
    let input = "512 384\n# a comment\n\n600.25 300.5\n0 0\n";
    let text = stdout(&fisheye(&args, input));
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(numbers(lines[0]), [0.0, 0.0, 1.0]);
    let camera = LensCamera::new(
        parse_spec("canon-8-15mm@8mm").unwrap(),
        ImageSize::new(1024, 768).unwrap(),
    );
    let reference = camera.unproject(DVec2::new(600.25, 300.5)).unwrap();
    let got = DVec3::from_slice(&numbers(lines[1]));
    assert!(got.distance(reference) < 1e-8, "{got} vs {reference}");
    // The corner lies outside this lens's 180° circle.
    assert_eq!(lines[2], "none");

    // The same through the WGSL code.
    let gpu_args = [&args[..], &["--gpu"]].concat();
    let gpu = stdout(&fisheye(&gpu_args, input));
    let gpu_lines: Vec<&str> = gpu.lines().collect();
    assert_eq!(gpu_lines[2], "none");
    let got = DVec3::from_slice(&numbers(gpu_lines[1]));
    assert!(got.distance(reference) < 1e-6, "{got} vs {reference}");

    // A pinhole maps every pixel, in the image or not; outside it there is no ray, on either
    // path, as `project` answers `none` there. The image's far corner is still in it.
    let pinhole = [
        "lens",
        "unproject",
        "--lens",
        "rectilinear:f=1",
        "--size",
        "64x48",
    ];
    for args in [pinhole.to_vec(), [&pinhole[..], &["--gpu"]].concat()] {
        let text = stdout(&fisheye(&args, "-5 -5\n64 48\n64.5 10\n10 -0.1\n"));
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 4, "{text}");
        assert_eq!([lines[0], lines[2], lines[3]], ["none"; 3], "{args:?}");
        assert_eq!(numbers(lines[1]).len(), 3, "{args:?}");
    }
}

#[test]
fn project_writes_pixels_or_none() {
    for gpu in [false, true] {
        let mut args = vec![
            "lens",
            "project",
            "--lens",
            "equisolid:f=0.5",
            "--size",
            "640x480",
        ];
        if gpu {
            args.push("--gpu");
        }
        let text = stdout(&fisheye(&args, "0 0 1\n0 0 -1\n1 0 0\n"));
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(numbers(lines[0]), [320.0, 240.0], "gpu: {gpu}");
        // Straight back: equisolid maps it to r = 2f = 1, the right edge (azimuth 0).
        let back = numbers(lines[1]);
        assert!((back[0] - 640.0).abs() < 1e-3 && (back[1] - 240.0).abs() < 1e-3);
        // 90° to the right: r = 2f sin 45° = 0.7071 half-widths.
        let right = numbers(lines[2]);
        assert!(
            (right[0] - 320.0 * (1.0 + 0.5f64.sqrt())).abs() < 1e-3,
            "{right:?}"
        );
    }
}

#[test]
fn bad_input_is_a_clear_error() {
    let cases: [(&[&str], &str, &str); 5] = [
        (
            &["lens", "unproject", "--lens", "equisolid:f=-2"],
            "",
            "f = -2",
        ),
        (
            &["lens", "unproject", "--lens", "nope:f=1"],
            "",
            "unknown model or preset",
        ),
        (
            &["lens", "unproject", "--lens", "equisolid:f=1"],
            "1 2\n3 four\n",
            "line 2",
        ),
        (
            &["lens", "project", "--lens", "equisolid:f=1"],
            "1 2\n",
            "expected 3 numbers",
        ),
        (
            &[
                "lens",
                "unproject",
                "--lens",
                "equisolid:f=1",
                "--size",
                "0x10",
            ],
            "",
            "width must be",
        ),
    ];
    for (args, input, needle) in cases {
        let output = fisheye(args, input);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{args:?} should fail");
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} lacks {needle:?}"
        );
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    }
}

#[test]
fn info_reports_adapter_features_and_precision() {
    let text = stdout(&fisheye(&["info"], ""));
    for needle in [
        "adapter:",
        "timestamp queries",
        "ray query",
        "asin",
        "builtin",
    ] {
        assert!(text.contains(needle), "{needle} missing from:\n{text}");
    }
}

/// `info --scene` builds and uploads the scene and says what it takes: the grid's twelve
/// triangles (two a face of its cube), 48 bytes of geometry each (`GpuTriangle`), and the
/// limits a split scene meets.
#[test]
fn info_reports_a_scenes_bytes_per_triangle() {
    let text = stdout(&fisheye(&["info", "--scene", "builtin:grid"], ""));
    for needle in [
        "storage buffers a stage",
        "scene: builtin:grid, 12 triangles;",
        "bytes a stored triangle (geometry 48, BVH",
    ] {
        assert!(text.contains(needle), "{needle} missing from:\n{text}");
    }
    assert!(!text.contains("split across"), "{text}");
}

#[test]
fn demo_writes_one_png_per_lens() {
    let dir = std::env::temp_dir().join(format!("fisheye-demo-test-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let args = [
        "lens",
        "demo",
        "--lens",
        "canon-8-15mm@8mm",
        "--lens",
        "rectilinear:f=1",
        "--size",
        "96x64",
        "--out",
        out,
    ];
    stdout(&fisheye(&args, ""));
    for name in ["canon-8-15mm@8mm.png", "rectilinear_f_1.png"] {
        let image = image::open(dir.join(name)).unwrap().to_rgba8();
        assert_eq!(image.dimensions(), (96, 64));
        // Not blank: more than one colour.
        let first = image.get_pixel(0, 0);
        assert!(image.pixels().any(|p| p != first), "{name} is one colour");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Adapter selection errors say what exists or what to install, and exit non-zero.
#[test]
fn adapter_errors_are_clear() {
    // A backend this platform lacks has no adapter: the message says what to install.
    let absent = if cfg!(target_vendor = "apple") {
        "dx12"
    } else {
        "metal"
    };
    let cases = [
        (
            ("WGPU_ADAPTER_NAME", "no-such-gpu"),
            "matches no adapter; available:",
        ),
        (
            ("WGPU_BACKEND", absent),
            "apt-get install mesa-vulkan-drivers",
        ),
    ];
    for (env, needle) in cases {
        let output = fisheye_with_env(&["info"], "", &[env]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{env:?} should fail");
        assert!(stderr.contains(needle), "{env:?}: {stderr:?}");
    }
}

/// A lost device, a malformed OBJ line and an image beyond the adapter each end the command
/// with a non-zero status and the message, and write no image.
#[test]
fn faults_and_bad_files_exit_non_zero_with_the_message() {
    let dir = std::env::temp_dir().join(format!("fisheye-cli-faults-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("bad.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n").unwrap();
    let out = dir.join("out.png");
    let (obj, out) = (obj.to_str().unwrap(), out.to_str().unwrap());
    let lost = ("FISHEYE_INJECT_FAULT", "device-lost");
    // One pixel wider than this adapter's textures (or than 32768, which any size is below).
    let info = stdout(&fisheye(&["info"], ""));
    let max: u32 = info
        .lines()
        .find_map(|l| l.trim().strip_prefix("max 2D texture side"))
        .and_then(|v| v.trim().parse().ok())
        .expect("info reports the texture limit");
    let wide = format!("{}x8", max + 1);
    let wide_error = format!("image size \"{wide}\"");
    type Case<'a> = (&'a [&'a str], &'a [(&'a str, &'a str)], &'a str);
    let cases: [Case; 6] = [
        (
            &["render", "-o", out],
            &[lost],
            "the GPU device was lost: Destroyed",
        ),
        (
            &["render", "--method", "cube-forward", "-o", out],
            &[lost],
            "device was lost",
        ),
        (&["info"], &[lost], "device was lost"),
        (
            &["render", obj, "-o", out],
            &[],
            "bad.obj: line 4: face vertex \"x\"",
        ),
        (&["render", "--size", &wide, "-o", out], &[], &wide_error),
        (
            &["render", "--camera", "1,2:3", "-o", out],
            &[],
            "expected X,Y,Z:LX,LY,LZ",
        ),
    ];
    for (args, env, needle) in cases {
        let output = fisheye_with_env(args, "", env);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} lacks {needle:?}"
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(
            !std::path::Path::new(out).exists(),
            "{args:?} wrote an image"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--pixel-origin opencv` puts pixel centres at whole numbers, as OpenCV does: the same
/// rays as the project's convention half a pixel on, both ways, on both paths; and the
/// image's edge moves with it (-0.4 is inside, -0.6 is not).
#[test]
fn pixel_origin_opencv_shifts_by_half_a_pixel() {
    let lens = ["--lens", "samyang-7.5mm", "--size", "64x48"];
    for gpu in [&[][..], &["--gpu"]] {
        let run = |command: &str, origin: &str, input: &str| {
            let args = [
                &["lens", command][..],
                &lens,
                gpu,
                &["--pixel-origin", origin],
            ]
            .concat();
            stdout(&fisheye(&args, input))
        };
        assert_eq!(
            run("unproject", "opencv", "0 0\n10 20\n"),
            run("unproject", "corner", "0.5 0.5\n10.5 20.5\n")
        );
        let centre = numbers(run("project", "opencv", "0 0 1\n").trim());
        assert_eq!(centre, [31.5, 23.5]);
        let edge = run("unproject", "opencv", "-0.4 10\n-0.6 10\n");
        let lines: Vec<&str> = edge.lines().collect();
        assert!(lines[0] != "none" && lines[1] == "none", "{edge}");
    }
}
