//! `fisheye render`: the colour image, its exposure and tone curve, refused outputs.

use super::*;

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

/// A colour file the tool cannot write is refused before anything is rendered (no device is
/// made), with one message and no file.
#[test]
fn refused_outputs_cost_no_rendering_and_leave_no_file() {
    let dir = std::env::temp_dir().join(format!("fisheye-cli-refused-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("folder.png")).unwrap();
    std::fs::write(dir.join("plain.txt"), "a file, not a folder").unwrap();
    std::os::unix::fs::symlink("/dev/full", dir.join("full.png")).unwrap();
    type Case<'a> = (&'a str, &'a [&'a str], &'a str);
    let cases: [Case; 9] = [
        ("x.jpg", &[], "use one of those extensions"),
        ("x", &[], "use one of those extensions"),
        ("x.exr", &["--bits", "8"], "8 bits a channel"),
        ("x.png", &["--bits", "32"], "32 bits a channel"),
        ("folder.png", &[], "a folder, not a regular file"),
        ("full.png", &[], "a symbolic link, not a regular file"),
        (
            "x.png",
            &["--outputs", "range", "--format", "exr"],
            "x.range.exr: a folder",
        ),
        ("x.png", &["--exposure", "inf"], "finite number of stops"),
        // A folder that cannot be made (a file is in its way): refused before the device.
        (
            "plain.txt/x.png",
            &[],
            "x.png: cannot be written (File exists",
        ),
    ];
    std::fs::create_dir_all(dir.join("x.range.exr")).unwrap();
    let before: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    for (name, extra, needle) in cases {
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
        // 2 is clap's status for a value its parser refuses (`--exposure inf`).
        let code = output.status.code();
        assert!(matches!(code, Some(1 | 2)), "{args:?}: {code:?} {stderr}");
        assert_eq!(stderr.matches(needle).count(), 1, "{args:?}: {stderr:?}");
        assert!(
            !stdout.contains("adapter:"),
            "{args:?} made a device: {stdout}"
        );
        let after: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        assert_eq!(after, before, "{args:?} left a file");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A bare mesh (lit by the headlight and sun the tool adds) is exposed automatically in a
/// PNG: the float EXR written with `--exposure auto` holds radiance whose log-average
/// luminance (Reinhard et al. 2002, computed here from the file) is the key, 0.18; the
/// default PNG is that exposure's, byte for byte; a scene with its own lights keeps 0 EV.
#[test]
fn bare_meshes_are_exposed_automatically() {
    let dir = std::env::temp_dir().join(format!("fisheye-cli-auto-{}", std::process::id()));
    let obj = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/scanned/stanford-bunny.obj"
    );
    let run = |scene: &str, name: &str, extra: &[&str]| {
        let path = dir.join(name);
        let base = ["render", scene, "--size", "64x48", "--spp", "1", "-o"];
        let args = [&base[..], &[path.to_str().unwrap()], extra].concat();
        (stdout(&fisheye(&args, "")), path)
    };
    let (said, exr) = run(obj, "auto.exr", &["--exposure", "auto", "--bits", "32"]);
    assert!(said.contains("exposure: auto"), "{said}");
    let (rgba, _) = exr_rgba(&exr);
    let logs: Vec<f64> = rgba
        .iter()
        .filter(|c| c[3] > 0.0)
        .map(|c| {
            let l = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
            // δ is 1e-4 of the unexposed radiance, scaled by the exposure with it.
            f64::from(l).ln()
        })
        .collect();
    let log_average = (logs.iter().sum::<f64>() / logs.len() as f64).exp();
    // Every covered pixel sees the sky or the bunny (no black), so δ moves it by < 0.1%.
    assert!((log_average / 0.18 - 1.0).abs() < 2e-3, "{log_average}");
    let (said, default) = run(obj, "default.png", &[]);
    assert!(said.contains("exposure: auto"), "{said}");
    let (_, auto) = run(obj, "auto.png", &["--exposure", "auto"]);
    assert_eq!(
        std::fs::read(default).unwrap(),
        std::fs::read(auto).unwrap()
    );
    let (said, _) = run("builtin:default", "lit.png", &[]);
    assert!(
        !said.contains("exposure: auto") && said.contains("exposure +0.00 EV"),
        "{said}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--spp auto` renders adaptively, says how many rays it spent and in which passes, and
/// `--outputs spp` draws them: transparent outside the image circle, darkest where pixels
/// were interpolated, brightest on edges; the id array beside it stays exact. A malformed
/// `--spp` is refused with what it accepts.
#[test]
fn adaptive_render_writes_its_spp_map() {
    let dir = std::env::temp_dir().join(format!("fisheye-adaptive-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("room.png");
    let args = [
        "render",
        "--size",
        "96x72",
        "--spp",
        "auto:0.05",
        "--outputs",
        "spp,id",
        "-o",
        out.to_str().unwrap(),
    ];
    let text = stdout(&fisheye(&args, ""));
    for needle in [
        "trace (rt@auto:0.05)",
        "rays for their colour",
        "coarse",
        "midpoints",
        "refine",
        "truth",
        "room.spp.png (dark violet 0 (interpolated), blue 1.1, teal 3.2, green 7.7, yellow 17 rays a pixel)",
    ] {
        assert!(text.contains(needle), "{needle} missing from:\n{text}");
    }
    let map = image::open(dir.join("room.spp.png")).unwrap().to_rgba8();
    assert_eq!(map.dimensions(), (96, 72));
    assert_eq!(map.get_pixel(0, 0)[3], 0, "a masked corner is transparent");
    let brightness = |p: &image::Rgba<u8>| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]);
    let shown: Vec<u32> = map
        .pixels()
        .filter(|p| p[3] == 255)
        .map(brightness)
        .collect();
    let (least, most) = (shown.iter().min().unwrap(), shown.iter().max().unwrap());
    assert!(
        most > &(least + 300),
        "one colour from {least} to {most}: nothing was refined"
    );
    assert!(dir.join("room.id.npy").is_file());
    // The counts beside the picture: they add up to the rays the command reports, and the
    // picture draws a pixel with none dark violet and one with the most yellow.
    let bytes = std::fs::read(dir.join("room.spp.npy")).unwrap();
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    assert_eq!(npy.shape(), [72, 96]);
    let counts: Vec<u32> = npy.into_vec().unwrap();
    let reported: u64 = text
        .split(" rays for their colour")
        .next()
        .and_then(|head| head.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no count in:\n{text}"));
    assert_eq!(counts.iter().map(|&n| u64::from(n)).sum::<u64>(), reported);
    let most = *counts.iter().max().unwrap();
    assert_eq!(most, 17, "16 samples after the centre's ray");
    for (pixel, &n) in map.pixels().zip(&counts) {
        if pixel[3] == 255 && (n == 0 || n == most) {
            let expected = if n == 0 { [68, 1, 84] } else { [253, 231, 37] };
            assert_eq!(pixel.0[..3], expected, "{n} rays");
        }
    }
    // As OpenEXR: the same counts, a scalar in `Y`.
    let exr_args = [&args[..], &["--format", "exr"]].concat();
    stdout(&fisheye(&exr_args, ""));
    let image = exr::prelude::read_all_flat_layers_from_file(dir.join("room.spp.exr")).unwrap();
    let channel = &image.layer_data[0].channel_data.list[0];
    assert_eq!(channel.name.to_string(), "Y");
    let exr::prelude::FlatSamples::F32(values) = &channel.sample_data else {
        panic!("expected f32 samples")
    };
    let as_floats: Vec<f32> = counts.iter().map(|&n| n as f32).collect();
    assert_eq!(values, &as_floats);
    let refused = fisheye(
        &["render", "--spp", "auto:x", "-o", out.to_str().unwrap()],
        "",
    );
    let message = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(
        message.contains("auto[:THRESHOLD[:MAX[:LEAST]]]") && !message.contains("panicked"),
        "{message}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}
