//! The interactive viewer (`examples/viewer/`), run as a user runs it but under Xvfb: its
//! window, after a few frames, shows what the library renders. `cargo test` builds the example
//! next to this test's binary; `xvfb-run` comes from the `xvfb` package (which
//! `.ci/install-lavapipe` installs).

use std::path::PathBuf;
use std::process::Command;

use fisheye_rt::cube::{CubeMap, CubeMethod, CubeSettings};
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::{ImageSize, LensCamera, parse_spec};
use fisheye_rt::scene::builtin;
use fisheye_rt::trace::{Adaptive, GpuScene, PixelFilter, RenderOptions, colour_image, render};

/// The viewer example's binary, beside this test's (`target/<profile>/examples/viewer`).
fn viewer() -> PathBuf {
    let deps = std::env::current_exe()
        .unwrap()
        .parent()
        .unwrap()
        .to_path_buf();
    let exe = deps.parent().unwrap().join("examples").join("viewer");
    assert!(
        exe.exists(),
        "{} is missing: `cargo test` builds the examples",
        exe.display()
    );
    exe
}

/// Runs the viewer under Xvfb for `frames` frames and returns the last.
fn screenshot(args: &[&str], frames: u32) -> image::RgbaImage {
    let out = std::env::temp_dir().join(format!(
        "fisheye-viewer-{}-{}.png",
        std::process::id(),
        args.join("_").replace(['/', ':', ','], "-")
    ));
    let result = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 640x480x24"])
        .arg(viewer())
        .args(args)
        .arg("--frames")
        .arg(frames.to_string())
        .arg("--screenshot")
        .arg(&out)
        .output()
        .unwrap_or_else(|e| {
            panic!("xvfb-run: {e} (install the xvfb package; .ci/install-lavapipe does)")
        });
    assert!(
        result.status.success(),
        "the viewer failed: {}",
        String::from_utf8_lossy(&result.stderr)
    );
    let image = image::open(&out).unwrap().to_rgba8();
    std::fs::remove_file(&out).unwrap();
    image
}

/// Compares the window's pixels with the library's 8-bit image (masked pixels black): the
/// window gets either the library's own sRGB values or half floats its surface encodes, so a
/// channel may be a level or two off. Pixels the lens covers in part (several rays a pixel)
/// are drawn over black, blended in the surface's encoding: they are left out.
fn assert_shows(what: &str, window: &image::RgbaImage, expected: &image::RgbaImage) {
    assert_shows_one_of(what, window, &[expected]);
}

/// As `assert_shows`, where each pixel may be any of `expected`'s (the nearest counts).
fn assert_shows_one_of(what: &str, window: &image::RgbaImage, expected: &[&image::RgbaImage]) {
    for image in expected {
        assert_eq!(window.dimensions(), image.dimensions(), "{what}");
    }
    let mut worst = 0;
    let mut total = 0u64;
    for (i, w) in window.pixels().enumerate() {
        let (x, y) = (i as u32 % window.width(), i as u32 / window.width());
        let mut nearest: Option<(u8, u64)> = None;
        for image in expected {
            let e = image.get_pixel(x, y);
            if e[3] != 0 && e[3] != 255 {
                continue;
            }
            let d = |k: usize| w[k].abs_diff(if e[3] == 0 { 0 } else { e[k] });
            let (largest, sum) =
                (0..3).fold((0, 0), |(m, s), k| (m.max(d(k)), s + u64::from(d(k))));
            if nearest.is_none_or(|(m, _)| largest < m) {
                nearest = Some((largest, sum));
            }
        }
        if let Some((largest, sum)) = nearest {
            worst = worst.max(largest);
            total += sum;
        }
    }
    let mean = total as f64 / (3 * window.len() / 4) as f64;
    eprintln!("{what}: largest channel difference {worst}, mean {mean:.3}");
    assert!(
        worst <= 2 && mean < 0.25,
        "{what}: largest {worst}, mean {mean}"
    );
}

#[test]
fn the_viewer_shows_the_scene_under_xvfb() {
    let scene = builtin::scene("default").unwrap();
    let size = ImageSize::new(160, 120).unwrap();
    let lens = "canon-8-15mm@8mm";
    let camera = LensCamera::new(parse_spec(lens).unwrap(), size);
    let ctx = GpuContext::new().unwrap();
    let options = RenderOptions::default();
    let args = ["builtin:default", "--lens", lens, "--size", "160x120"];

    let traced = render(&ctx, &scene, &camera, &options).unwrap().to_image();
    assert_shows(
        "rt",
        &screenshot(&[&args[..], &["--spp", "1"]].concat(), 4),
        &traced,
    );
    let four = RenderOptions { spp: 4, ..options };
    let traced = render(&ctx, &scene, &camera, &four).unwrap().to_image();
    let window = screenshot(&[&args[..], &["--spp", "4"]].concat(), 4);
    assert_shows("rt at 4 rays a pixel", &window, &traced);
    let tent = RenderOptions {
        filter: PixelFilter::Tent,
        ..options
    };
    let traced = render(&ctx, &scene, &camera, &tent).unwrap().to_image();
    let window = screenshot(&[&args[..], &["--spp", "1+tent"]].concat(), 4);
    assert_shows("rt at one ray through the tent filter", &window, &traced);
    // Adaptive sampling, the viewer's default, through the embedding `Renderer` it draws
    // with: its first frame is the one below a ray a pixel (but for pixels beside edges that
    // frame interpolates, there traced: one ray a pixel's colour), and a still camera's
    // frames sharpen into the whole adaptive frame (2 steps, then a sixteenth of the pixels
    // at 16 samples each frame, at least).
    let adaptive = |spp: u32| RenderOptions {
        spp,
        adaptive: Some(Adaptive {
            threshold: Adaptive::DEFAULT_THRESHOLD,
            ground_truth: false,
            every_pixel: false,
        }),
        ..options
    };
    let coarse = render(&ctx, &scene, &camera, &adaptive(1))
        .unwrap()
        .to_image();
    let one_ray = render(&ctx, &scene, &camera, &options).unwrap().to_image();
    assert_shows_one_of(
        "rt, adaptive, first frame",
        &screenshot(&args, 1),
        &[&coarse, &one_ray],
    );
    let whole = render(&ctx, &scene, &camera, &adaptive(16))
        .unwrap()
        .to_image();
    assert_shows("rt, adaptive, still", &screenshot(&args, 20), &whole);

    // Through a cube map of the size the viewer picks: half the image's longer side.
    let gpu_scene = GpuScene::new(&ctx, &scene, &options).unwrap();
    let settings = CubeSettings::new(80, CubeMethod::Traced);
    let cube = CubeMap::new(&ctx, &camera, &gpu_scene, &settings).unwrap();
    let colour = cube.render(&ctx, &gpu_scene, &scene.camera).unwrap();
    let window = screenshot(&[&args[..], &["--method", "cube-rt"]].concat(), 4);
    assert_shows("cube-rt", &window, &colour_image(size, &colour));

    // Through a prescription's glass, adaptively as through any lens: a still camera's
    // frames sharpen into the whole adaptive frame.
    let spec = format!(
        "prescription:{}/lenses/fisheye-10mm.dat",
        env!("CARGO_MANIFEST_DIR")
    );
    let glass = fisheye_rt::lens::glass::camera_for(&spec, size).unwrap();
    let traced = render(&ctx, &scene, &glass, &adaptive(16))
        .unwrap()
        .to_image();
    let window = screenshot(
        &["builtin:default", "--lens", &spec, "--size", "160x120"],
        20,
    );
    assert_shows("rt through glass, adaptive, still", &window, &traced);
}

/// A moving scene (`scenes/dataset/sliding.toml`: a box sliding and turning over a second)
/// with `--time 0.8`, paused there, shows the scene posed at 0.8 s (`Scene::at`), which is not
/// the scene as loaded (the box stands elsewhere at 0 s).
#[test]
fn the_viewer_shows_a_moving_scene_at_its_time() {
    let path = format!("{}/scenes/dataset/sliding.toml", env!("CARGO_MANIFEST_DIR"));
    let scene = fisheye_rt::scene::load(&path).unwrap().scene;
    let lens = "canon-8-15mm@8mm";
    let camera = LensCamera::new(parse_spec(lens).unwrap(), ImageSize::new(160, 120).unwrap());
    let ctx = GpuContext::new().unwrap();
    let options = RenderOptions {
        spp: 4,
        ..RenderOptions::default()
    };
    let at = |t: f64| {
        render(&ctx, &scene.at(t), &camera, &options)
            .unwrap()
            .to_image()
    };
    let args = [&path, "--lens", lens, "--size", "160x120", "--spp", "4"];
    let window = screenshot(&[&args[..], &["--time", "0.8"]].concat(), 4);
    assert_shows("sliding.toml at 0.8 s", &window, &at(0.8));
    let loaded = at(0.0);
    let moved = window
        .pixels()
        .zip(loaded.pixels())
        .filter(|(w, e)| e[3] == 255 && (0..3).any(|k| w[k].abs_diff(e[k]) > 8))
        .count();
    assert!(moved > 200, "{moved} pixels show the box moved");
}
