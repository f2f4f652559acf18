//! A camera moving while its frame is read out and exposed (`wgsl/frame.wgsl`): a rolling
//! shutter turns each line by its own time, an exposure smears an edge by the distance it
//! moves, and a camera standing still renders the same whatever its shutter.

mod common;

use common::{camera, ctx};
use fisheye_rt::dataset::camera_from_transform;
use fisheye_rt::lens::{LensCamera, Readout, Shutter};
use fisheye_rt::scene::{Camera, Material, MeshBuilder, Scene, builtin};
use fisheye_rt::trace::{FramePass, GpuScene, Motion, NO_HIT, RenderOptions, RenderOutput};
use glam::{DAffine3, DMat3, DVec3, Vec2, Vec3};

/// One frame of `camera` on `scene` moving by `motion`.
fn moving(
    scene: &Scene,
    camera: &LensCamera,
    options: &RenderOptions,
    motion: &Motion,
) -> RenderOutput {
    let gpu_scene = GpuScene::new(ctx(), scene, options).unwrap();
    let pass = FramePass::new(ctx(), camera, &gpu_scene, options).unwrap();
    let mut encoder = ctx().device.create_command_encoder(&Default::default());
    pass.encode_motion(&ctx().device, &mut encoder, &gpu_scene, motion)
        .unwrap();
    ctx().queue.submit([encoder.finish()]);
    pass.trace_pass().read(ctx()).unwrap()
}

/// A camera at `eye` turning about the world's `axis` at `rate` rad/s from `start` (its
/// camera-to-world rotation at time 0), as knots every 10 ms over `seconds`.
fn turning(eye: DVec3, start: DMat3, axis: DVec3, rate: f64, seconds: f64) -> Motion {
    let steps = (seconds / 0.01).round() as usize;
    Motion {
        knots: (0..=steps)
            .map(|k| {
                let t = seconds * k as f64 / steps as f64;
                (
                    t,
                    DAffine3::from_rotation_translation(
                        glam::DQuat::from_axis_angle(axis, rate * t),
                        eye,
                    ),
                )
            })
            .collect(),
        body_from_camera: DAffine3::from_mat3(start),
    }
}

/// Under a constant yaw, a rolling-shutter frame's row v is the row v of a still frame taken
/// with the camera turned by rate × v × line delay (Kalibr's convention), for a fisheye and a
/// calibrated lens, read in two orders: ids equal but for a few pixels on id edges (f32
/// slerp and the still pose's f32 rotation differ by about 1e-6 rad), ranges within 1e-4
/// relative. Three quarters down the readout, the line is not the stamp's.
#[test]
fn a_rolling_shutter_turns_each_line_by_its_time() {
    let scene = builtin::scene("default").unwrap();
    let start = scene.camera.rotation();
    let (eye, up) = (scene.camera.position, DVec3::Y);
    let options = RenderOptions::default();
    for (spec, readout) in [
        ("equidistant:f=0.45,fov=180", Readout::TopToBottom),
        ("samyang-7.5mm", Readout::RightToLeft),
    ] {
        let still = camera(spec, 96, 72);
        let size = still.size;
        let shutter = Shutter::new(1e-3, 0.0, readout).unwrap();
        let rolling = still.with_shutter(shutter);
        // 3 rad/s over a 96-line readout: 16° across the frame.
        let motion = turning(eye, start, up, 3.0, 0.1);
        let frame = moving(&scene, &rolling, &options, &motion);
        let lines = match readout {
            Readout::TopToBottom | Readout::BottomToTop => size.height,
            _ => size.width,
        };
        let mut compared = 0;
        for line in [lines / 4, lines / 2, 3 * lines / 4] {
            // The line's pixels, and the still frame at its time.
            let pixels: Vec<usize> = (0..size.pixels())
                .filter(|&i| {
                    let (x, y) = (
                        (i % size.width as usize) as u32,
                        (i / size.width as usize) as u32,
                    );
                    let t = rolling.line_time(x, y);
                    (t - f64::from(line) * 1e-3).abs() < 1e-9
                })
                .collect();
            let t = f64::from(line) * 1e-3;
            let pose = camera_from_transform(&motion.camera_at(t));
            let turned = moving(&scene, &still, &options, &Motion::still(&pose));
            let at_stamp = moving(&scene, &still, &options, &Motion::still(&scene.camera));
            let mut mismatched = 0;
            let mut differs_from_stamp = 0;
            for &i in &pixels {
                if frame.ids[i] != turned.ids[i] {
                    assert!(
                        common::on_id_edge(&turned.ids, size, i),
                        "{spec}: line {line}, pixel {i} off an id edge"
                    );
                    mismatched += 1;
                    continue;
                }
                let stamp_range = at_stamp.geometry[i][3];
                let moved = (frame.geometry[i][3] - stamp_range).abs() > 1e-3 * stamp_range;
                if frame.ids[i] != at_stamp.ids[i] || moved {
                    differs_from_stamp += 1;
                }
                if frame.ids[i] != NO_HIT {
                    let (a, b) = (frame.geometry[i][3], turned.geometry[i][3]);
                    assert!(
                        ((a - b) / b).abs() < 1e-4,
                        "{spec}: line {line}, pixel {i}: range {a} against {b}"
                    );
                    compared += 1;
                }
            }
            assert!(
                mismatched <= 3,
                "{spec}: line {line}: {mismatched} ids differ"
            );
            if line == 3 * lines / 4 {
                assert!(differs_from_stamp > 10, "{spec}: line {line} did not turn");
            }
        }
        assert!(compared > 150, "{spec}: {compared} pixels compared");
    }
}

/// A camera standing still renders the same bits whether or not its shutter rolls: with one
/// knot at rest, every ray's pose is the stamp's exactly.
#[test]
fn a_still_camera_renders_alike_with_any_shutter() {
    let scene = builtin::scene("default").unwrap();
    let still = camera("samyang-7.5mm", 64, 48);
    let options = RenderOptions {
        spp: 4,
        ..RenderOptions::default()
    };
    let motion = Motion::still(&scene.camera);
    let global = moving(&scene, &still, &options, &motion);
    let rolling = still.with_shutter(Shutter::new(1e-3, 0.02, Readout::TopToBottom).unwrap());
    let moving_shutter = moving(&scene, &rolling, &options, &motion);
    assert_eq!(global.ids, moving_shutter.ids);
    assert_eq!(global.geometry, moving_shutter.geometry);
    assert_eq!(global.colour, moving_shutter.colour);
}

/// A plane `distance` ahead of a camera at the origin looking along +z, emitting 1 where
/// x < 0 and nothing where x > 0.
fn edge(distance: f64) -> Scene {
    let mut b = MeshBuilder::new();
    let white = b.material(Material {
        emission: Vec3::ONE,
        ..Material::diffuse("white", Vec3::ZERO)
    });
    let black = b.material(Material::diffuse("black", Vec3::ZERO));
    let side = 1000.0;
    for (x, material) in [(-side, white), (0.0, black)] {
        b.quad(
            DVec3::new(x, -side, distance),
            DVec3::new(side, 0.0, 0.0),
            DVec3::new(0.0, 2.0 * side, 0.0),
            Vec2::ONE,
            material,
        );
    }
    let camera = Camera {
        position: DVec3::ZERO,
        look_at: DVec3::Z,
        up: DVec3::NEG_Y,
    };
    b.finish(vec![], Vec3::ZERO, Vec3::ZERO, camera)
}

/// The width, px, of the ramp a vertical edge makes along each row: from the spread of the
/// profile's differences, whose variance is w²/12 for a ramp of width w, plus 1/12 for the
/// pixel's own box (16 × 16 samples integrate it).
fn ramp_width(output: &RenderOutput) -> Vec<f64> {
    let (w, h) = (output.size.width as usize, output.size.height as usize);
    (0..h)
        .map(|y| {
            let row: Vec<f64> = (0..w)
                .map(|x| f64::from(output.colour[y * w + x][1]))
                .collect();
            let d: Vec<f64> = row.windows(2).map(|p| p[0] - p[1]).collect();
            let total: f64 = d.iter().sum();
            let mean = d.iter().enumerate().map(|(i, v)| i as f64 * v).sum::<f64>() / total;
            let var = d
                .iter()
                .enumerate()
                .map(|(i, v)| (i as f64 - mean).powi(2) * v)
                .sum::<f64>()
                / total;
            (12.0 * var - 1.0).max(0.0).sqrt()
        })
        .collect()
}

/// A camera sliding sideways past a plane during its exposure smears an edge over
/// f · speed · exposure / distance pixels (a pinhole's image moves uniformly): 20 px here,
/// measured from each row's profile within 3 % (measured within 1 %: time is stratified over
/// 256 samples a pixel); with a rolling shutter as well, the same width, the edge sheared row
/// by row by the distance the camera moves in a line's time (within 5 %, measured 1.4 %). An
/// instant's edge is under a pixel wide.
#[test]
fn an_exposure_smears_an_edge_by_the_distance_it_moves() {
    let distance = 10.0;
    let scene = edge(distance);
    let still = camera("rectilinear:f=1.7", 128, 8);
    let size = still.size;
    let f =
        still.project(DVec3::new(0.1, 0.0, 1.0)).unwrap().x - still.project(DVec3::Z).unwrap().x;
    let f = f / 0.1;
    let (exposure, width) = (0.01, 20.0);
    let speed = width * distance / (f * exposure);
    let slide = |t: f64| DAffine3::from_translation(DVec3::new(speed * t, 0.0, 0.0));
    let options = RenderOptions {
        spp: 256,
        ..RenderOptions::default()
    };
    let instant = moving(&scene, &still, &options, &Motion::still(&scene.camera));
    for w in ramp_width(&instant) {
        assert!(w < 1.0, "an instant's edge is {w:.2} px wide");
    }
    for line_delay in [0.0, 2e-4] {
        let exposed =
            still.with_shutter(Shutter::new(line_delay, exposure, Readout::TopToBottom).unwrap());
        let (first, last) = exposed.exposure_span();
        let motion = Motion {
            knots: vec![(first, slide(first)), (last, slide(last))],
            body_from_camera: DAffine3::from_mat3(scene.camera.rotation()),
        };
        let smeared = moving(&scene, &exposed, &options, &motion);
        for (y, w) in ramp_width(&smeared).into_iter().enumerate() {
            assert!(
                (w - width).abs() < 0.03 * width,
                "line delay {line_delay}: row {y}: {w:.2} px, {width} px wanted"
            );
        }
        // The edge's middle on row y: where it was at the row's time, shifted left.
        let row = |y: usize| -> f64 {
            let w = size.width as usize;
            (0..w)
                .map(|x| f64::from(smeared.colour[y * w + x][1]))
                .sum()
        };
        let shear = row(0) - row(size.height as usize - 1);
        let wanted = f * speed * line_delay * f64::from(size.height - 1) / distance;
        assert!(
            (shear - wanted).abs() < 0.05 * wanted.max(1.0),
            "line delay {line_delay}: rows sheared by {shear:.2} px, {wanted:.2} wanted"
        );
    }
}

/// Adaptive sampling moves the camera as uniform sampling does: at threshold 0, through a
/// rolling shutter with an exposure on a turning camera, it gives uniform sampling's bits
/// (every sample at the same time from the same pose), ground truth included.
#[test]
fn adaptive_sampling_at_threshold_zero_is_uniform_sampling_in_motion() {
    use fisheye_rt::trace::Adaptive;
    let scene = builtin::scene("default").unwrap();
    let shutter = Shutter::new(5e-4, 0.01, Readout::TopToBottom).unwrap();
    let rolling = camera("samyang-7.5mm", 61, 46).with_shutter(shutter);
    let motion = turning(
        scene.camera.position,
        scene.camera.rotation(),
        DVec3::Y,
        2.0,
        0.05,
    );
    let motion = Motion {
        knots: motion
            .knots
            .iter()
            .map(|&(t, pose)| (t - 0.005, pose))
            .collect(),
        ..motion
    };
    let uniform = RenderOptions {
        spp: 16,
        ..RenderOptions::default()
    };
    let adaptive = RenderOptions {
        adaptive: Some(Adaptive {
            threshold: 0.0,
            ground_truth: true,
            every_pixel: false,
        }),
        ..uniform
    };
    let a = moving(&scene, &rolling, &uniform, &motion);
    let b = moving(&scene, &rolling, &adaptive, &motion);
    assert_eq!(a.colour, b.colour, "colour");
    assert_eq!(a.geometry, b.geometry, "geometry");
    assert_eq!(a.ids, b.ids, "ids");
}
