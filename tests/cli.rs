//! The `fisheye` binary end to end, as a user runs it.

mod common;

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

/// `fisheye render` writes the colour image with the mask in alpha, and names what it did.
#[test]
fn render_writes_a_masked_png_and_reports() {
    let path = std::env::temp_dir().join(format!("fisheye-render-{}.png", std::process::id()));
    let out = path.to_str().unwrap();
    let args = ["render", "builtin:default", "--size", "96x64", "--out", out];
    let text = stdout(&fisheye(&args, ""));
    // Compilation is reported apart from the timed trace.
    let needles = [
        "adapter:",
        "triangles",
        "kernels compiled and first dispatch: ",
        "bytes a stored triangle (geometry 48, BVH ",
        "ms on the GPU (after compilation)",
        "primary rays",
        "wrote",
    ];
    for needle in needles {
        assert!(text.contains(needle), "{needle} missing from:\n{text}");
    }
    let image = image::open(&path).unwrap().to_rgba8();
    assert_eq!(image.dimensions(), (96, 64));
    // The default lens is a 180° circle of radius 0.66 half-widths: corners masked, centre lit.
    assert_eq!(image.get_pixel(0, 0)[3], 0);
    let centre = image.get_pixel(48, 32);
    assert_eq!(centre[3], 255);
    assert!(
        centre[0] > 0 || centre[1] > 0 || centre[2] > 0,
        "the centre is black"
    );
    std::fs::remove_file(path).unwrap();

    let output = fisheye(&["render", "builtin:nope"], "");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && stderr.contains("no built-in scene \"nope\""),
        "{stderr}"
    );
}

/// The RGBA of an OpenEXR file as the exr crate reads it: `(R, G, B, A)` as f32 per pixel,
/// and whether the file held half floats.
fn exr_rgba(path: &std::path::Path) -> (Vec<[f32; 4]>, bool) {
    use exr::prelude::FlatSamples;
    let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    let channels = &image.layer_data[0].channel_data.list;
    let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
    assert_eq!(names, ["A", "B", "G", "R"], "{}", path.display());
    let half = matches!(channels[0].sample_data, FlatSamples::F16(_));
    let values: Vec<Vec<f32>> = channels
        .iter()
        .map(|c| match &c.sample_data {
            FlatSamples::F16(v) => v.iter().map(|h| h.to_f32()).collect(),
            FlatSamples::F32(v) => v.clone(),
            FlatSamples::U32(_) => panic!("{}: integer colour", path.display()),
        })
        .collect();
    let rgba = (0..values[0].len())
        .map(|i| [values[3][i], values[2][i], values[1][i], values[0][i]])
        .collect();
    (rgba, half)
}

/// Exposure, tone curves and the colour files, against their formulas: one render written
/// as float and half EXR (read by the exr crate: linear radiance times 2^EV, alpha the
/// coverage) and as 8- and 16-bit PNG (sRGB of the tone curve of the exposed radiance). The
/// default render clips almost no pixel where clamping clips the lamp's surroundings.
#[test]
fn render_exposes_tone_maps_and_writes_png_or_exr() {
    let dir = std::env::temp_dir().join(format!("fisheye-cli-tone-{}", std::process::id()));
    let base = ["render", "builtin:default", "--size", "96x64", "--spp", "4"];
    let write = |name: &str, extra: &[&str]| {
        let path = dir.join(name);
        let args = [&base[..], &["-o", path.to_str().unwrap()], extra].concat();
        let text = stdout(&fisheye(&args, ""));
        assert!(text.contains("wrote"), "{text}");
        path
    };
    let (float, half) = exr_rgba(&write("float.exr", &["--bits", "32", "--exposure", "-1"]));
    assert!(!half);
    // The radiance: renders are bit-identical reruns, and 2^-1 is exact in floats.
    let radiance: Vec<[f32; 4]> = float
        .iter()
        .map(|c| [c[0] * 2.0, c[1] * 2.0, c[2] * 2.0, c[3]])
        .collect();
    assert_eq!(radiance[0][3], 0.0, "a masked corner is transparent");
    assert_eq!(radiance[48 + 32 * 96][3], 1.0, "the centre is covered");
    assert!(radiance.iter().all(|c| (0.0..=1.0).contains(&c[3])));
    let edge = radiance.iter().filter(|c| c[3] > 0.0 && c[3] < 1.0).count();
    assert!(
        edge > 20,
        "{edge} pixels partly covered at the image circle's edge"
    );
    let (halves, half) = exr_rgba(&write("half.exr", &["--exposure", "2"]));
    assert!(half, "EXR is half float by default");
    for (h, r) in halves.iter().zip(&radiance) {
        let expected = [r[0] * 4.0, r[1] * 4.0, r[2] * 4.0, r[3]];
        let expected = expected.map(|v| exr::prelude::f16::from_f32(v).to_f32());
        assert_eq!(*h, expected);
    }

    // The published formulas, written here apart from the library's.
    let srgb = |x: f32| {
        if x <= 0.0031308 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        }
    };
    let aces = |x: f32| (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let clamp = |x: f32| x.clamp(0.0, 1.0);
    type Curve<'a> = &'a dyn Fn(f32) -> f32;
    let cases: [(&str, &[&str], Curve, f32, f32); 3] = [
        ("default.png", &[], &aces, 1.0, 255.0),
        (
            "clamp.png",
            &["--tone", "clamp", "--exposure", "0.5"],
            &clamp,
            0.5f32.exp2(),
            255.0,
        ),
        (
            "deep.png",
            &["--bits", "16", "--exposure", "-1.5"],
            &aces,
            (-1.5f32).exp2(),
            65535.0,
        ),
    ];
    let mut clipped = Vec::new();
    for (name, extra, curve, scale, max) in cases {
        let image = image::open(write(name, extra)).unwrap().to_rgba16();
        let mut worst = 0.0f32;
        let mut white = 0;
        for (pixel, r) in image.pixels().zip(&radiance) {
            // The 8-bit image reads as 16 bits scaled by 257.
            let read = pixel.0.map(|v| f32::from(v) * max / 65535.0);
            if r[3] == 0.0 {
                assert_eq!(
                    read, [0.0; 4],
                    "{name}: masked pixels are transparent black"
                );
                continue;
            }
            for k in 0..3 {
                let expected = (srgb(curve(r[k] * scale)) * max).round();
                worst = worst.max((read[k] - expected).abs());
            }
            assert_eq!(
                read[3],
                (r[3] * max).round(),
                "{name}: alpha is the coverage"
            );
            white += usize::from((0..3).any(|k| read[k] == max));
        }
        // One step for rounding (the library's powf and this one may differ in the last bit).
        assert!(worst <= 1.0, "{name}: off by {worst} steps of {max}");
        clipped.push(white);
    }
    let covered = radiance.iter().filter(|c| c[3] > 0.0).count();
    let share = |n: usize| n as f64 / covered as f64;
    assert!(
        share(clipped[0]) < 0.002 && share(clipped[1]) > 0.03,
        "clipped: {:.2}% with the default ACES, {:.2}% clamped at +0.5 EV",
        100.0 * share(clipped[0]),
        100.0 * share(clipped[1])
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// A colour file the tool cannot write is refused before anything is rendered, with one
/// message and no file; a failure while writing leaves no file either.
#[test]
fn refused_outputs_cost_no_rendering_and_leave_no_file() {
    let dir = std::env::temp_dir().join(format!("fisheye-cli-refused-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("folder.png")).unwrap();
    std::fs::write(dir.join("plain.txt"), "a file, not a folder").unwrap();
    std::os::unix::fs::symlink("/dev/full", dir.join("full.png")).unwrap();
    type Case<'a> = (&'a str, &'a [&'a str], &'a str, bool);
    let cases: [Case; 9] = [
        ("x.jpg", &[], "use one of those extensions", false),
        ("x", &[], "use one of those extensions", false),
        ("x.exr", &["--bits", "8"], "8 bits a channel", false),
        ("x.png", &["--bits", "32"], "32 bits a channel", false),
        ("folder.png", &[], "a folder, not a regular file", false),
        (
            "full.png",
            &[],
            "a symbolic link, not a regular file",
            false,
        ),
        (
            "x.png",
            &["--outputs", "range", "--format", "exr"],
            "x.range.exr: a folder",
            false,
        ),
        (
            "x.png",
            &["--exposure", "inf"],
            "finite number of stops",
            false,
        ),
        // Rendered, then the folder cannot be made: still no file.
        ("plain.txt/x.png", &[], "plain.txt: File exists", true),
    ];
    std::fs::create_dir_all(dir.join("x.range.exr")).unwrap();
    let before: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    for (name, extra, needle, renders) in cases {
        let out = dir.join(name);
        let render = [
            "render",
            "--size",
            "32x24",
            "--spp",
            "1",
            "-o",
            out.to_str().unwrap(),
        ];
        let args = [&render[..], extra].concat();
        let output = fisheye(&args, "");
        let stderr = String::from_utf8_lossy(&output.stderr);
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {stderr}");
        assert_eq!(stderr.matches(needle).count(), 1, "{args:?}: {stderr:?}");
        assert_eq!(stdout.contains("adapter:"), renders, "{args:?}: {stdout}");
        let after: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        assert_eq!(after, before, "{args:?} left a file");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

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
/// camera rotation the renderer and the reference share).
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
        "range,normal,id,direction,mask",
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
    for (name, npy) in [
        ("view.normal.exr", &normal),
        ("view.direction.exr", &direction),
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
/// errors.
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
        ] {
            let output = fisheye(&[&args[..], extra].concat(), "");
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert!(
                !output.status.success() && stderr.contains(wanted),
                "{method}: {stderr}"
            );
        }
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

#[test]
fn bench_and_compare_write_their_reports_into_a_new_folder() {
    let dir = std::env::temp_dir().join("fisheye-cli-study");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let run = |args: &[&str]| {
        let output = Command::new(env!("CARGO_BIN_EXE_fisheye"))
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&output.stdout).into_owned();
        let errors = String::from_utf8_lossy(&output.stderr).into_owned();
        (output.status.success(), text, errors)
    };
    let common = [
        "--size",
        "32x24",
        "--method",
        "rt,cube-forward",
        "--cube-size",
        "16",
        "--spp",
        "1,4",
    ];
    // No --out: a new numbered folder each time.
    let mut args = vec!["bench", "builtin:few-detailed", "--frames", "2"];
    args.extend(common);
    let (ok, text, errors) = run(&args);
    assert!(ok, "{errors}");
    assert!(text.contains("| rectilinear:f=1 | rt@4spp |"), "{text}");
    assert!(text.contains("Fisheye overhead"), "{text}");
    for file in ["bench.json", "bench.md", "fps.canon-8-15mm@8mm.png"] {
        assert!(dir.join("fisheye-bench-1").join(file).is_file(), "{file}");
    }
    let (ok, _, errors) = run(&args);
    assert!(ok && dir.join("fisheye-bench-2").is_dir(), "{errors}");

    let mut args = vec![
        "compare",
        "--frames",
        "1",
        "--reference-spp",
        "16",
        "-o",
        "cmp",
    ];
    args.extend(common);
    let (ok, text, errors) = run(&args);
    assert!(ok, "{errors}");
    assert!(text.contains("| ꟻLIP |"), "{text}");
    assert!(text.contains("- canon-8-15mm@8mm, MSE (least: "), "{text}");
    for file in [
        "compare.json",
        "compare.md",
        "tradeoff.canon-8-15mm@8mm.png",
        "tradeoff-flip.canon-8-15mm@8mm.png",
        "canon-8-15mm@8mm.cube-forward@16.error.png",
        "rectilinear_f_1.reference.png",
    ] {
        assert!(dir.join("cmp").join(file).is_file(), "{file}");
    }

    // Bad input names the problem.
    let (ok, _, errors) = run(&["bench", "builtin:grid", "--path", "walk", "--frames", "1"]);
    assert!(!ok && errors.contains("no camera path"), "{errors}");
    let (ok, _, errors) = run(&["compare", "--cube-size", "0"]);
    assert!(!ok && errors.contains("--cube-size 0"), "{errors}");
    let (ok, _, errors) = run(&["compare", "--reference-spp", "300"]);
    assert!(
        !ok && errors.contains("--reference-spp 300: 300 samples"),
        "{errors}"
    );
    let (ok, _, errors) = run(&["bench", "--spp", "1,3"]);
    assert!(!ok && errors.contains("--spp 3: 3 samples"), "{errors}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--calib`: a Kalibr file drives `lens unproject`/`project` (f64 and GPU agree with the
/// library's reading of it), `lens convert` writes it in another format that reads back the
/// same, and `render` renders at the calibration's resolution; wrong uses are clear errors.
#[test]
fn calibration_files_drive_lens_and_render() {
    let dir = std::env::temp_dir().join(format!("fisheye-cli-calib-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let kalibr = dir.join("camchain.yaml");
    std::fs::write(
        &kalibr,
        "cam0:\n  camera_model: ds\n  intrinsics: [-0.18, 0.59, 40.0, 39.5, 47.5, 35.5]\n  \
         distortion_model: none\n  resolution: [96, 72]\ncam1:\n  camera_model: pinhole\n  \
         intrinsics: [60, 60, 47.5, 35.5]\n  distortion_model: equidistant\n  \
         distortion_coeffs: [0.01, -0.002, 0, 0]\n  resolution: [96, 72]\n",
    )
    .unwrap();
    let path = kalibr.to_str().unwrap();
    let library = fisheye_rt::lens::calib::read(&kalibr).unwrap();
    for (index, camera) in library.iter().enumerate() {
        let cam = LensCamera::new(camera.lens, camera.size);
        let pixels = [
            DVec2::new(48.0, 36.0),
            DVec2::new(10.25, 60.5),
            DVec2::new(0.5, 0.5),
        ];
        let input: String = pixels
            .iter()
            .map(|p| format!("{} {}\n", p.x, p.y))
            .collect();
        let index = index.to_string();
        for gpu in [false, true] {
            let mut args = vec![
                "lens",
                "unproject",
                "--calib",
                path,
                "--calib-camera",
                &index,
            ];
            if gpu {
                args.push("--gpu");
            }
            let text = stdout(&fisheye(&args, &input));
            for (line, p) in text.lines().zip(pixels) {
                let want = cam.unproject(p).unwrap();
                let got = DVec3::from_slice(&numbers(line));
                assert!(
                    (got - want).length() < 1e-5,
                    "{index} gpu={gpu}: {p} → {got} vs {want}"
                );
            }
            let dirs: String = pixels
                .iter()
                .map(|&p| cam.unproject(p).unwrap())
                .map(|d| format!("{} {} {}\n", d.x, d.y, d.z))
                .collect();
            args[1] = "project";
            let text = stdout(&fisheye(&args, &dirs));
            for (line, p) in text.lines().zip(pixels) {
                let got = DVec2::from_slice(&numbers(line));
                assert!(
                    got.distance(p) < 1e-3,
                    "{index} gpu={gpu}: {p} came back as {got}"
                );
            }
        }
    }
    let json = dir.join("basalt.json");
    let text = stdout(&fisheye(
        &[
            "lens",
            "convert",
            "--calib",
            path,
            "--format",
            "basalt",
            "-o",
            json.to_str().unwrap(),
        ],
        "",
    ));
    assert!(text.contains("basalt"), "{text}");
    assert_eq!(fisheye_rt::lens::calib::read(&json).unwrap()[0], library[0]);

    // A classic lens converts to its exact calibrated equivalent: the 180° canon preset is
    // Kannala–Brandt with k = 0 and f W/2 pixels of focal length.
    let kalibr = dir.join("canon.yaml");
    let args = [
        "lens",
        "convert",
        "--lens",
        "canon-8-15mm@8mm",
        "--size",
        "512x384",
    ];
    let out = ["--format", "kalibr", "-o", kalibr.to_str().unwrap()];
    let text = stdout(&fisheye(&[&args[..], &out].concat(), ""));
    assert!(text.contains("is exactly kb:fx=107.52"), "{text}");
    let back = fisheye_rt::lens::calib::read(&kalibr).unwrap()[0];
    assert_eq!(
        back.lens.model(),
        CalibratedModel::KannalaBrandt { k: [0.0; 4] }
    );
    assert_eq!(back.lens.intrinsics().fx, 0.42 * 256.0);

    let png = dir.join("ds.png");
    let text = stdout(&fisheye(
        &[
            "render",
            "builtin:default",
            "--calib",
            path,
            "-o",
            png.to_str().unwrap(),
        ],
        "",
    ));
    assert!(text.contains("at 96x72"), "{text}");
    let image = image::open(&png).unwrap();
    assert_eq!((image.width(), image.height()), (96, 72));

    // compare (and bench, which shares its setup) measures the calibrated camera at its
    // resolution, beside the pinhole.
    let cmp = dir.join("cmp");
    let text = stdout(&fisheye(
        &[
            "compare",
            "builtin:grid",
            "--calib",
            path,
            "--method",
            "rt",
            "--frames",
            "1",
            "--spp",
            "1",
            "--reference-spp",
            "4",
            "-o",
            cmp.to_str().unwrap(),
        ],
        "",
    ));
    assert!(text.contains(&format!("| {path} | rt@1spp |")), "{text}");
    assert!(text.contains("| rectilinear:f=1 | rt@1spp |"), "{text}");
    let report = std::fs::read_to_string(cmp.join("compare.md")).unwrap();
    assert!(report.contains("96x72"), "{report}");

    for (args, needle) in [
        (
            vec!["render", "--calib", path, "--size", "10x10"],
            "cannot be used with",
        ),
        (
            vec!["lens", "unproject", "--calib", path, "--calib-camera", "2"],
            "holds 2 camera(s)",
        ),
        (vec!["lens", "project"], "give a lens"),
        (
            vec![
                "lens",
                "convert",
                "--lens",
                "orthographic:f=0.66",
                "--format",
                "kalibr",
                "-o",
                "x",
            ],
            "kalibr calibration format cannot express ucm",
        ),
        (
            vec![
                "lens",
                "unproject",
                "--lens",
                "kb:fx=300,cx=1,cy=1,k1=-0.3,fov=180",
            ],
            "stops increasing",
        ),
    ] {
        let output = fisheye(&args, "");
        assert!(!output.status.success(), "{args:?} succeeded");
        let message = String::from_utf8_lossy(&output.stderr);
        assert!(message.contains(needle), "{args:?}: {message}");
    }
    let clipped = fisheye(
        &["lens", "unproject", "--lens", "kb:fx=300,cx=1,cy=1,k1=-0.3"],
        "",
    );
    assert!(String::from_utf8_lossy(&clipped.stderr).contains("warning: kb: the mapping stops"));
    // The same lens on an image that ends before the clip (its corners at θd 0.3, the turn at
    // 0.70): nothing to warn about.
    let unseen = fisheye(
        &[
            "lens",
            "unproject",
            "--lens",
            "kb:fx=300,cx=1,cy=1,k1=-0.3",
            "--size",
            "64x64",
        ],
        "",
    );
    assert!(
        unseen.status.success() && unseen.stderr.is_empty(),
        "{unseen:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `validate` writes its report, overlays, point lists and plot, passes a right lens (from a
/// spec or a calibration file), and exits non-zero, naming the lens, when one fails.
#[test]
fn validate_reports_and_fails_loudly() {
    let dir = std::env::temp_dir().join(format!("fisheye-cli-validate-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("v");
    let output = Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .args([
            "validate",
            "--lens",
            "samyang-7.5mm",
            "--size",
            "320x320",
            "-o",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let text = stdout(&output);
    assert!(text.contains("| samyang-7.5mm | 320x320 |"), "{text}");
    for file in [
        "validate.json",
        "validate.md",
        "overlay.samyang-7.5mm.png",
        "points.samyang-7.5mm.csv",
        "errors.png",
    ] {
        assert!(out.join(file).is_file(), "{file}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("validate.json")).unwrap()).unwrap();
    let lens = &json["lenses"][0];
    assert_eq!(lens["passed"], true);
    assert!(lens["checked"].as_u64().unwrap() > 50);
    assert_eq!(lens["checked"], lens["matched"]);
    let overlay = image::open(out.join("overlay.samyang-7.5mm.png")).unwrap();
    assert_eq!((overlay.width(), overlay.height()), (960, 960));
    let csv = std::fs::read_to_string(out.join("points.samyang-7.5mm.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        1 + lens["projected"].as_u64().unwrap() as usize
    );

    // A calibration file: its camera at its resolution, named by the file.
    let spec = CalibratedModel::EXAMPLES[1];
    let calibration = fisheye_rt::lens::calib::Calibration {
        lens: match parse_spec(spec).unwrap() {
            fisheye_rt::lens::Lens::Calibrated(lens) => lens,
            _ => unreachable!("{spec} is calibrated"),
        },
        size: ImageSize::new(512, 512).unwrap(),
    };
    let file = dir.join("ds.json");
    let text =
        fisheye_rt::lens::calib::write(&calibration, fisheye_rt::lens::calib::CalibFormat::Basalt)
            .unwrap();
    std::fs::write(&file, text).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .args(["validate", "--calib"])
        .arg(&file)
        .arg("-o")
        .arg(dir.join("c"))
        .output()
        .unwrap();
    let text = stdout(&output);
    assert!(
        text.contains("ds.json | 512x512 |") && text.contains("| yes |"),
        "{text}"
    );

    // Too small an image to check a single corner: a failure, named.
    let output = Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .args([
            "validate",
            "--lens",
            "equidistant:f=0.3",
            "--size",
            "48x48",
            "-o",
        ])
        .arg(dir.join("f"))
        .output()
        .unwrap();
    let errors = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(
        errors.contains("1 of 1 lens(es) failed validation: equidistant:f=0.3"),
        "{errors}"
    );
    assert!(dir.join("f").join("validate.md").is_file());
    let output = fisheye(&["validate", "--supersample", "0"], "");
    let errors = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && errors.contains("--supersample 0"),
        "{errors}"
    );
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

/// An instanced scene: `render` reports the scene's triangles, those stored and the instances;
/// the rasterized cube map draws a flattened copy where one fits, and where it does not the
/// error says why and which path draws instances.
#[test]
fn render_reports_instances_and_rasterizes_them_flattened() {
    let dir = std::env::temp_dir().join(format!("fisheye-instances-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("forest.png");
    let args = [
        "render",
        "builtin:instances",
        "--size",
        "64x48",
        "--spp",
        "1",
        "--out",
        out.to_str().unwrap(),
    ];
    let text = stdout(&fisheye(&args, ""));
    assert!(
        text.contains("100000002 triangles (100002 stored, 1000 instances)"),
        "{text}"
    );
    let mut raster = args.to_vec();
    raster.extend(["--method", "cube-forward", "--cube-size", "32"]);
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
