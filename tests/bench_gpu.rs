//! `fisheye bench` and `fisheye compare` as library calls: every method's frame is timed per
//! pass, the errors are measured against references whose exact relations to the methods
//! are known, and the reports write what they claim.

mod common;

use common::{camera, ctx};
use fisheye_rt::bench::PathKind;
use fisheye_rt::compare::{image_error, supersampled};
use fisheye_rt::renderer::{Method, Offscreen, Pass, SceneSet, Setup};
use fisheye_rt::report::{self, LensRun, Study};
use fisheye_rt::scene::builtin;
use fisheye_rt::trace::{PixelFilter, RenderOptions, Sampling, render};

/// Direct methods at one ray per pixel, cube methods at `sizes`.
fn setups(methods: &[Method], sizes: &[u32]) -> Vec<Setup> {
    Setup::all(methods, sizes, &[Sampling::Uniform(1)], &[PixelFilter::Box])
}

#[test]
fn every_method_times_each_of_its_passes_and_renders_what_render_does() {
    let scene = builtin::scene("default").unwrap();
    let cam = camera("canon-8-15mm@8mm", 48, 36);
    let all = setups(&Method::ALL, &[24]);
    let scenes = SceneSet::new(ctx(), &scene, &RenderOptions::default(), &all).unwrap();
    for setup in all {
        let renderer = Offscreen::new(ctx(), &cam, &scenes, setup, 256).unwrap();
        // The warm-up compiles the kernels; the frame after it is the one compared below.
        assert!(renderer.warm_up(ctx(), &scenes, &scene.camera).unwrap() > 0.0);
        let time = renderer.frame(ctx(), &scenes, &scene.camera).unwrap();
        let passes = time.passes_ms.expect("lavapipe has timestamp queries");
        assert_eq!(
            passes.len(),
            setup.method.passes().len(),
            "{}",
            setup.label()
        );
        assert!(
            passes.iter().all(|ms| ms.is_finite() && *ms > 0.0),
            "{}: {passes:?}",
            setup.label()
        );
        // The GPU cannot spend longer on a frame than the wall clock waited for it (1%
        // allowance for the two clocks' rates).
        let gpu: f64 = passes.iter().sum();
        assert!(
            gpu <= time.wall_ms * 1.01,
            "{}: {gpu} > {}",
            setup.label(),
            time.wall_ms
        );
        if setup.method == Method::Rt {
            // The timed frame is the same image `trace::render` makes.
            let colour = renderer.colour(ctx()).unwrap();
            let once = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
            assert_eq!(colour, once.colour);
            // One ray for each pixel the lens gives one.
            let covered = once.counts().0 as u64;
            assert_eq!(time.passes_rays, Some(vec![covered]));
        }
        if setup.method.cube().is_some() {
            assert_eq!(time.passes_rays, None, "{}", setup.label());
        }
    }
}

/// An adaptive frame is timed in two passes a stage after the first, the listing
/// (bookkeeping, no rays) and the tracing, and counts each stage's rays: the block corners
/// first (one pass: they need no list), then at least the rays its spp map counts (which
/// leaves out the samples the lens masks).
#[test]
fn adaptive_frames_time_listing_and_tracing_apart_and_count_their_rays() {
    use fisheye_rt::renderer::Pass;
    let scene = builtin::scene("default").unwrap();
    let cam = camera("canon-8-15mm@8mm", 48, 36);
    let setup = Setup::sampled(Method::Rt, Sampling::parse("auto:0.05:4").unwrap());
    let scenes = SceneSet::new(ctx(), &scene, &RenderOptions::default(), &[setup]).unwrap();
    let renderer = Offscreen::new(ctx(), &cam, &scenes, setup, 256).unwrap();
    let passes = [
        Pass::Coarse,
        Pass::MidpointList,
        Pass::Midpoints,
        Pass::RefineList,
        Pass::Refine,
        Pass::SupersampleList,
        Pass::Supersample,
    ];
    assert_eq!(renderer.passes(), passes);
    renderer.warm_up(ctx(), &scenes, &scene.camera).unwrap();
    let time = renderer.frame(ctx(), &scenes, &scene.camera).unwrap();
    let ms = time.passes_ms.expect("lavapipe has timestamp queries");
    assert!(ms.iter().all(|ms| ms.is_finite() && *ms > 0.0), "{ms:?}");
    let rays = time.passes_rays.expect("a traced frame");
    assert_eq!(rays.len(), passes.len());
    assert!(
        rays.iter().skip(1).step_by(2).all(|&n| n == 0),
        "listing traces nothing: {rays:?}"
    );
    // The bookkeeping `bench` and `render` report is those listing passes' time together.
    let (spent, share) = Pass::bookkeeping(&passes, &ms).unwrap();
    let listed: f64 = ms.iter().skip(1).step_by(2).sum();
    assert!((spent - listed).abs() < 1e-9, "{spent} against {listed}");
    assert!(share > 0.0 && share < 1.0, "{share}");
    // The block corners the lens covers: every 4th pixel along each axis and the last (the
    // 180° circle masks the image's corners, and the coarse stage traces nothing there).
    let corners = |n: u32| (0..n).filter(move |&i| i % 4 == 0 || i == n - 1);
    let lattice = corners(36)
        .flat_map(|y| corners(48).map(move |x| (x, y)))
        .filter(|&(x, y)| cam.pixel_direction(x, y).is_some())
        .count() as u64;
    assert!(lattice < 13 * 10, "{lattice} of 130 corners covered");
    assert_eq!(rays[0], lattice);
    let map: u64 = renderer
        .rays_per_pixel(ctx())
        .unwrap()
        .expect("an adaptive frame")
        .iter()
        .map(|&n| u64::from(n))
        .sum();
    let counted: u64 = rays.iter().sum();
    assert!(
        counted >= map && map > lattice,
        "{counted} counted, {map} in the map"
    );
    // Starting from every pixel, the first stage traces the centres the lens covers: those
    // of a uniform frame of one ray a pixel.
    let every = Setup::sampled(Method::Rt, Sampling::parse("auto:0.05:4:1").unwrap());
    let scenes = SceneSet::new(ctx(), &scene, &RenderOptions::default(), &[every]).unwrap();
    let renderer = Offscreen::new(ctx(), &cam, &scenes, every, 256).unwrap();
    renderer.warm_up(ctx(), &scenes, &scene.camera).unwrap();
    let time = renderer.frame(ctx(), &scenes, &scene.camera).unwrap();
    let once = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    let rays = time.passes_rays.expect("a traced frame");
    assert_eq!(rays[0], once.counts().0 as u64);
    assert!(rays[0] < 48 * 36);
}

/// A study of `setups` on one lens, the built-in scene `name`.
fn study_on<'a>(
    scene: &'a fisheye_rt::scene::Scene,
    scenes: &'a SceneSet,
    lenses: &'a [LensRun],
    setups: &'a [Setup],
) -> Study<'a> {
    Study {
        ctx: ctx(),
        scene,
        scene_name: "test".into(),
        scenes,
        lenses,
        setups,
        shadow_size: 512,
    }
}

#[test]
fn compare_measures_both_families_against_the_many_ray_reference() {
    // A 90° pinhole on a 64-pixel-wide image, and a traced cube of 64-texel faces: every
    // pixel centre is a texel centre of the front face, so the resampled image is RT's one
    // ray per pixel up to f32 rounding. At a quarter of the size the cube must be worse.
    let scene = builtin::scene("few-detailed").unwrap();
    let lenses = [LensRun {
        name: "pinhole".into(),
        camera: camera("rectilinear:f=1", 64, 48),
    }];
    let traced = Method::Cube(fisheye_rt::cube::CubeMethod::Traced);
    let all = Setup::all(
        &[Method::Rt, traced],
        &[16, 64],
        &[1, 4, 16].map(Sampling::Uniform),
        &PixelFilter::ALL,
    );
    let labels: Vec<String> = all.iter().map(Setup::label).collect();
    // The tent only where it changes pixels: one ray a pixel, not 4 or 16, nor cube maps.
    let wanted = [
        "rt@1spp",
        "rt@1spp+tent",
        "rt@4spp",
        "rt@16spp",
        "cube-rt@16",
        "cube-rt@64",
    ];
    assert_eq!(labels, wanted);
    assert_eq!(all[1].passes(false), [Pass::Trace, Pass::Filter]);
    let scenes = SceneSet::new(ctx(), &scene, &RenderOptions::default(), &all).unwrap();
    let colour = |setup: Setup| {
        let renderer = Offscreen::new(ctx(), &lenses[0].camera, &scenes, setup, 512).unwrap();
        renderer.frame(ctx(), &scenes, &scene.camera).unwrap();
        renderer.colour(ctx()).unwrap()
    };
    let one_ray = colour(all[0]);
    assert!(image_error(&one_ray, &colour(all[5])).mse < 1e-9);

    let out = std::env::temp_dir().join("fisheye-test-compare");
    let _ = std::fs::remove_dir_all(&out);
    let study = study_on(&scene, &scenes, &lenses, &all);
    // No frame to take a median of is refused before any work, as `bench` refuses it.
    for refused in [
        report::compare(&study, &scene.camera, 0, 16, &out, &mut |_| {}).err(),
        report::bench(&study, PathKind::Walk, 0, 1, &mut |_| {}).err(),
    ] {
        let message = refused.expect("0 frames are refused").to_string();
        assert!(message.contains("frames 0"), "{message}");
    }
    assert!(!out.exists(), "a refused compare wrote {}", out.display());
    // A reference of 16 rays: the same rays as the 16-ray setup's, so that one has no error.
    let report = report::compare(&study, &scene.camera, 1, 16, &out, &mut |_| {}).unwrap();
    let entry = |label: &str| report.entries.iter().find(|e| e.setup == label).unwrap();
    let exact = entry("rt@16spp");
    assert_eq!((exact.error.mse, exact.flip), (0.0, 0.0));
    // Error falls with rays per pixel, in both metrics, and the 1-ray image is RT's own.
    let (one, four) = (entry("rt@1spp"), entry("rt@4spp"));
    assert!(one.error.mse > four.error.mse && four.error.mse > 0.0);
    assert!(one.flip > four.flip && four.flip > 0.0);
    // The tent filter brings one ray nearer the reference (the reason for it; its pixels are
    // `tests/tent_gpu.rs`'s).
    assert!(entry("rt@1spp+tent").error.mse < one.error.mse);
    let matched = entry("cube-rt@64");
    assert!((matched.error.mse - one.error.mse).abs() < 1e-6 * one.error.mse);
    assert!(entry("cube-rt@16").error.mse > 2.0 * matched.error.mse);
    for e in &report.entries {
        assert_eq!(e.error.mask_agreement, 1.0, "{}", e.setup);
        assert_eq!(e.error.compared, 64 * 48, "{}", e.setup);
        assert!((0.0..=1.0).contains(&e.flip), "{}", e.setup);
    }
    // The fastest setup is always on both Pareto fronts.
    let fastest = report
        .entries
        .iter()
        .min_by(|a, b| a.ms().total_cmp(&b.ms()))
        .unwrap();
    assert!(fastest.pareto && fastest.pareto_flip);
    // Samples a frame: RT's rays per pixel times its 64 × 48 pixels; the traced cube's texels,
    // at least the 64 × 48 under the pixel centres (each one a texel centre), and no more than
    // the front face and a border row or column of each neighbour (the resampler's footprint).
    for (label, rays) in [
        ("rt@1spp", 1),
        ("rt@1spp+tent", 1),
        ("rt@4spp", 4),
        ("rt@16spp", 16),
    ] {
        assert_eq!(entry(label).samples, f64::from(rays * 64 * 48), "{label}");
    }
    let texels = matched.samples;
    assert!(
        (64.0 * 48.0..=64.0 * 64.0 + 4.0 * 64.0).contains(&texels),
        "{texels}"
    );
    assert!(entry("cube-rt@16").samples <= 16.0 * 16.0 + 4.0 * 16.0);
    // A verdict per metric; the 16-ray setup's zero error is one only RT reaches. (How the
    // levels are computed is `report`'s unit test, on set numbers.) In samples: at each traced
    // cube's error, no less than one ray's, RT needs its fewest rays, 64 × 48.
    assert_eq!(report.verdicts.len(), 2);
    for v in &report.verdicts {
        assert!(!v.levels.is_empty());
        assert_eq!(v.rt_only, Some((0.0, "rt@16spp".to_string())));
        assert!(!v.rays.is_empty());
        for l in &v.rays {
            assert_eq!(l.rt_rays, Some(64.0 * 48.0), "{}", l.cube);
            assert_eq!(l.fewer, Some(entry(&l.cube).samples / (64.0 * 48.0)));
        }
    }
    // The ceiling: the fastest cube map's frame over RT's fastest, which no least exceeds.
    assert_eq!(report.ceilings.len(), 1);
    let ceiling = &report.ceilings[0];
    let fastest = |cube: bool| {
        report
            .entries
            .iter()
            .filter(|e| e.cube_size.is_some() == cube)
            .map(|e| e.ms())
            .fold(f64::INFINITY, f64::min)
    };
    assert_eq!(
        (ceiling.cube_ms, ceiling.rt_ms),
        (fastest(true), fastest(false))
    );
    assert_eq!(entry(&ceiling.cube).ms(), ceiling.cube_ms);
    for v in &report.verdicts {
        assert!(
            v.least_speedup.unwrap() <= ceiling.ratio,
            "{v:?} {ceiling:?}"
        );
    }
    // The reference, error maps and both plots were written.
    assert_eq!(report.write(&out).unwrap(), None, "plots need a font");
    for file in [
        "pinhole.reference.png",
        "pinhole.rt@1spp.error.png",
        "pinhole.cube-rt@16.error.png",
    ] {
        let img = image::open(out.join(file)).unwrap();
        assert_eq!((img.width(), img.height()), (64, 48), "{file}");
    }
    for plot in [
        "tradeoff.pinhole.png",
        "tradeoff-flip.pinhole.png",
        "rays.pinhole.png",
        "rays-flip.pinhole.png",
    ] {
        let img = image::open(out.join(plot)).unwrap();
        assert_eq!((img.width(), img.height()), (1100, 700), "{plot}");
    }
}

#[test]
fn the_supersampled_reference_averages_sub_pixel_rays() {
    let scene = builtin::scene("default").unwrap();
    let cam = camera("samyang-7.5mm", 40, 30);
    let rt = setups(&[Method::Rt], &[]);
    let scenes = SceneSet::new(ctx(), &scene, &RenderOptions::default(), &rt).unwrap();
    let centres = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    // One ray per pixel is the reference itself.
    let one = supersampled(
        ctx(),
        &scenes.software,
        &cam,
        &scene.camera,
        1,
        &centres.colour,
    );
    assert_eq!(one.unwrap(), centres.colour);
    // 3 × 3: the middle sub-ray is the pixel centre, so each pixel is the mean of a 3× image's
    // block, computed here from that image independently.
    let fine_cam = camera("samyang-7.5mm", 120, 90);
    let fine = render(ctx(), &scene, &fine_cam, &RenderOptions::default()).unwrap();
    let three = supersampled(
        ctx(),
        &scenes.software,
        &cam,
        &scene.camera,
        3,
        &centres.colour,
    )
    .unwrap();
    for (p, got) in three.iter().enumerate() {
        assert_eq!(got[3], centres.colour[p][3], "the mask is the centres'");
        if got[3] != 1.0 {
            continue;
        }
        let (i, j) = (p % 40, p / 40);
        let block: Vec<[f32; 4]> = (0..9)
            .map(|k| fine.colour[(3 * j + k / 3) * 120 + 3 * i + k % 3])
            .filter(|c| c[3] == 1.0)
            .collect();
        for c in 0..3 {
            let mean = block.iter().map(|b| f64::from(b[c])).sum::<f64>() / block.len() as f64;
            assert!((f64::from(got[c]) - mean).abs() < 1e-6, "pixel {p}");
        }
    }
    assert!(image_error(&centres.colour, &three).mse > 0.0);
}

#[test]
fn bench_times_every_frame_of_the_walk_and_writes_its_report() {
    let scene = builtin::scene("default").unwrap();
    let lenses = [
        LensRun {
            name: "canon-8-15mm@8mm".into(),
            camera: camera("canon-8-15mm@8mm", 32, 24),
        },
        LensRun {
            name: "pinhole".into(),
            camera: camera("rectilinear:f=1", 32, 24),
        },
    ];
    let raster = Method::Cube(fisheye_rt::cube::CubeMethod::Raster(
        fisheye_rt::raster::RasterMethod::Deferred,
    ));
    let all = setups(&[Method::Rt, raster], &[16]);
    let scenes = SceneSet::new(ctx(), &scene, &RenderOptions::default(), &all).unwrap();
    let study = study_on(&scene, &scenes, &lenses, &all);
    let mut calls = Vec::new();
    let report = report::bench(&study, PathKind::Walk, 3, 1, &mut |p| {
        calls.push((p.done, p.total))
    })
    .unwrap();
    assert_eq!(report.entries.len(), 4);
    for e in &report.entries {
        assert_eq!(e.frames.len(), 3);
        assert_eq!(e.wall.frames, 3);
        let gpu = e.gpu.as_ref().unwrap();
        assert!(gpu.min_fps <= gpu.mean_fps && gpu.mean_fps <= gpu.max_fps);
        assert_eq!(e.pass_median_ms.as_ref().unwrap().len(), e.passes.len());
        // Memory is sampled around the timed frames: the process's resident set (Linux) and
        // the device memory of wgpu's Vulkan allocator, which holds at least the scene.
        for m in [e.memory_start, e.memory_end] {
            assert!(m.resident_mib.unwrap() > 1.0, "{m:?}");
            assert!(m.gpu_mib.unwrap() > 0.0, "{m:?}");
        }
    }
    // Progress counts every frame, warm-up included, and ends complete.
    assert_eq!(calls.last(), Some(&(16, 16)));
    assert!(calls.windows(2).all(|w| w[0].0 <= w[1].0));
    assert_eq!(report.fisheye_overheads().len(), 1);

    let out = std::env::temp_dir().join("fisheye-test-bench");
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    assert_eq!(report.write(&out).unwrap(), None, "plots need a font");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("bench.json")).unwrap()).unwrap();
    assert_eq!(json["entries"].as_array().unwrap().len(), 4);
    assert!(json["machine"]["date"].as_str().unwrap().starts_with("20"));
    assert!(json["machine"]["driver"].as_str().unwrap().len() > 3);
    let md = std::fs::read_to_string(out.join("bench.md")).unwrap();
    assert!(md.contains("| canon-8-15mm@8mm | cube-deferred@16 |"));
    assert!(md.contains("Fisheye overhead"));
    assert!(md.contains("- pinhole rt@1spp: resident "), "{md}");
    for lens in ["canon-8-15mm@8mm", "pinhole"] {
        let plot = image::open(out.join(format!("fps.{lens}.png"))).unwrap();
        assert_eq!((plot.width(), plot.height()), (1100, 700));
    }
}

/// A frame traced in bands of rows (an image beyond one storage binding; bindings forced down
/// to 1 MiB and 4 KiB; the grid's texture, 4/3 MiB with its mip levels, left off) from a
/// moved pose: its timestamps span every band, and it is the frame traced
/// in one dispatch, bit for bit.
#[test]
fn banded_frames_are_timed_whole() {
    let small = fisheye_rt::gpu::GpuContext::with_binding_limit((1 << 20) + 4096).unwrap();
    let mut scene = builtin::scene("grid").unwrap();
    for m in &mut scene.materials {
        m.diffuse_texture = None;
    }
    let cam = camera("equidistant:f=0.5", 512, 300);
    let setup = Setup::direct(Method::Rt, 1);
    let options = RenderOptions::default();
    let pose = fisheye_rt::scene::Camera {
        position: scene.camera.position + glam::DVec3::new(0.1, 0.0, 0.05),
        ..scene.camera
    };
    let frames = |ctx: &fisheye_rt::gpu::GpuContext| {
        let scenes = SceneSet::new(ctx, &scene, &options, &[setup]).unwrap();
        let renderer = Offscreen::new(ctx, &cam, &scenes, setup, 256).unwrap();
        let time = renderer.frame(ctx, &scenes, &pose).unwrap();
        assert!(time.gpu_ms().unwrap() > 0.0);
        renderer.output(ctx).unwrap()
    };
    let (banded, whole) = (frames(&small), frames(ctx()));
    assert!(banded.colour == whole.colour && banded.ids == whole.ids);
    assert!(banded.counts().1 > 1000, "the grid is in view");
}

/// A prescription's glass is timed and compared beside its fitted model (`rays=fit`): the
/// glass runs the direct setups, uniform and adaptive, its cube-map setup is skipped and
/// listed saying why,
/// and the fitted model runs every setup, so a frame through the glass and one through its
/// model stand in the same reports.
#[test]
fn a_prescriptions_glass_is_timed_beside_its_fitted_model() {
    let scene = builtin::scene("default").unwrap();
    let size = fisheye_rt::lens::ImageSize::new(32, 24).unwrap();
    let spec = format!(
        "prescription:{}/lenses/fisheye-10mm.dat",
        env!("CARGO_MANIFEST_DIR")
    );
    let lenses = [
        LensRun {
            name: "glass".into(),
            camera: fisheye_rt::lens::glass::camera_for(&spec, size).unwrap(),
        },
        LensRun {
            name: "fit".into(),
            camera: fisheye_rt::lens::glass::camera_for(&format!("{spec},rays=fit"), size).unwrap(),
        },
    ];
    let cube = Method::Cube(fisheye_rt::cube::CubeMethod::Traced);
    let all = Setup::all(
        &[Method::Rt, cube],
        &[16],
        &[Sampling::Uniform(4), Sampling::parse("auto:0.1").unwrap()],
        &[PixelFilter::Box],
    );
    let scenes = SceneSet::new(ctx(), &scene, &RenderOptions::default(), &all).unwrap();
    let study = study_on(&scene, &scenes, &lenses, &all);
    let report = report::bench(&study, PathKind::Walk, 2, 1, &mut |_| {}).unwrap();
    let ran: Vec<(String, String)> = report
        .entries
        .iter()
        .map(|e| (e.lens.clone(), e.setup.clone()))
        .collect();
    let pair = |l: &str, s: &str| (l.to_string(), s.to_string());
    assert_eq!(
        ran,
        [
            pair("glass", "rt@4spp"),
            pair("glass", "rt@auto:0.1"),
            pair("fit", "rt@4spp"),
            pair("fit", "rt@auto:0.1"),
            pair("fit", "cube-rt@16")
        ]
    );
    assert!(
        report
            .skipped
            .iter()
            .any(|s| s.starts_with("glass cube-rt@16: ") && s.contains("rays=fit")),
        "{:?}",
        report.skipped
    );
    assert!(report.entries.iter().all(|e| e.gpu.is_some()));

    // compare runs the same setups against each lens's own many-ray reference (the glass's
    // traced through the glass), and writes its report and plots with the glass's cube map
    // left out; the fitted model gets its verdicts, the glass none (it has no cube map).
    let out = std::env::temp_dir().join("fisheye-test-compare-glass");
    let _ = std::fs::remove_dir_all(&out);
    let compared = report::compare(&study, &scene.camera, 1, 16, &out, &mut |_| {}).unwrap();
    let ran: Vec<(String, String)> = compared
        .entries
        .iter()
        .map(|e| (e.lens.clone(), e.setup.clone()))
        .collect();
    assert_eq!(
        ran,
        [
            pair("glass", "rt@4spp"),
            pair("glass", "rt@auto:0.1"),
            pair("fit", "rt@4spp"),
            pair("fit", "rt@auto:0.1"),
            pair("fit", "cube-rt@16")
        ]
    );
    assert!(
        compared
            .skipped
            .iter()
            .any(|s| s.starts_with("glass cube-rt@16: "))
    );
    assert!(compared.verdicts.iter().all(|v| v.lens == "fit"));
    assert!(compared.entries.iter().all(|e| e.error.mse > 0.0));
    assert_eq!(compared.write(&out).unwrap(), None, "plots need a font");
    assert!(out.join("tradeoff.glass.png").is_file());
}
