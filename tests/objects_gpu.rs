//! Moving instances on the GPU: the scene uploaded once, its meshes' BVHs built once, and only
//! the top level rebuilt for each time (`GpuScene::place_at`), render what a scene posed at
//! that time and flattened on the CPU in f64 renders.

mod common;

use common::{camera, ctx};
use fisheye_rt::lens::{LensCamera, Readout, Shutter};
use fisheye_rt::scene::animation::{Animation, Factor, Interpolation, Keys, Trs};
use fisheye_rt::scene::{Camera, Light, Material, MeshBuilder, Scene};
use fisheye_rt::trace::{FramePass, GpuScene, Motion, NO_HIT, RenderOptions, RenderOutput, render};
use glam::{DAffine3, DQuat, DVec3, Vec3};

/// A floor, a box keyed to slide 3 units along x and turn a quarter about y over 2 s, a
/// second box keyed to shrink to nothing at 1 s and grow back by 2 s (hidden at 1 s), and a
/// still instance of the same box beside them.
pub fn moving_boxes() -> Scene {
    let mut b = MeshBuilder::new();
    let grey = b.material(Material::diffuse("grey", Vec3::splat(0.6)));
    let red = b.material(Material::diffuse("red", Vec3::new(0.8, 0.2, 0.2)));
    b.quad(
        DVec3::new(-8.0, 0.0, -12.0),
        DVec3::new(16.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 14.0),
        glam::Vec2::ONE,
        grey,
    );
    let first = b.len();
    b.cuboid(DVec3::splat(-0.5), DVec3::splat(0.5), red);
    let cube = b.mesh_since(first);
    let linear = |times: &[f64]| (times.to_vec(), Interpolation::Linear);
    let (times, interpolation) = linear(&[0.0, 2.0]);
    let slide = Trs {
        translation: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
        scale: DVec3::ONE,
        translation_keys: Some(Keys {
            times: times.clone(),
            values: vec![DVec3::new(-2.0, 0.5, -4.0), DVec3::new(1.0, 0.5, -4.0)],
            interpolation,
        }),
        rotation_keys: Some(Keys {
            times,
            values: vec![
                DQuat::IDENTITY,
                DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2),
            ],
            interpolation,
        }),
        scale_keys: None,
    };
    b.object("slider", "box");
    assert!(b.place_moving(
        cube,
        Animation {
            factors: vec![Factor::Keyed(slide)]
        }
    ));
    let pulse = Trs {
        translation: DVec3::new(2.5, 0.5, -6.0),
        rotation: DQuat::IDENTITY,
        scale: DVec3::ONE,
        translation_keys: None,
        rotation_keys: None,
        scale_keys: Some(Keys {
            times: vec![0.0, 1.0, 2.0],
            values: vec![DVec3::ONE, DVec3::ZERO, DVec3::splat(1.5)],
            interpolation: Interpolation::Linear,
        }),
    };
    b.object("pulse", "box");
    assert!(b.place_moving(
        cube,
        Animation {
            factors: vec![Factor::Keyed(pulse)]
        }
    ));
    b.object("still", "box");
    assert!(b.place(
        cube,
        DAffine3::from_translation(DVec3::new(-3.0, 0.5, -7.0))
    ));
    let camera = Camera {
        position: DVec3::new(0.0, 2.0, 1.0),
        look_at: DVec3::new(0.0, 0.5, -5.0),
        up: DVec3::Y,
    };
    let sun = Light::Directional {
        direction: DVec3::new(0.3, -1.0, -0.4),
        irradiance: Vec3::splat(2.0),
    };
    b.finish(vec![sun], Vec3::splat(0.2), Vec3::splat(0.1), camera)
}

/// A frame of `pass` on `gpu_scene`, still at the scene's camera, stamped at scene time `t`
/// (its rays spread as the pass's camera's shutter says).
fn at_time(
    gpu_scene: &GpuScene,
    scene: &Scene,
    pass: &(FramePass, LensCamera),
    t: f64,
) -> RenderOutput {
    let (pass, camera) = pass;
    let window = camera.exposure_span();
    gpu_scene.place_at(ctx(), scene, t, window).unwrap();
    let mut encoder = ctx().device.create_command_encoder(&Default::default());
    let still = Motion::still(&scene.camera);
    pass.encode_motion(&ctx().device, &mut encoder, gpu_scene, &still)
        .unwrap();
    ctx().queue.submit([encoder.finish()]);
    pass.trace_pass().read(ctx()).unwrap()
}

/// At five times (before the first key, between keys, at the hidden instant, after the last
/// key) the scene uploaded once and placed for each renders the ids of the scene posed at
/// that time and flattened in f64 (an independent upload with no instances), but for pixels
/// on id edges (f32 transforms against f64 corners), and ranges within 1e-4; the boxes move
/// between the times, and the pulsing box is not seen at 1 s.
#[test]
fn placed_instances_render_as_the_posed_scene() {
    let scene = moving_boxes();
    let cam = camera("equidistant:f=0.5,fov=180", 96, 72);
    let options = RenderOptions::default();
    let gpu_scene = GpuScene::new(ctx(), &scene, &options).unwrap();
    let pass = (
        FramePass::new(ctx(), &cam, &gpu_scene, &options).unwrap(),
        cam,
    );
    let pulse_ids = {
        let world = scene.world_triangles as u32;
        let count = scene.instances[1].count;
        world + count..world + 2 * count
    };
    let mut previous: Option<Vec<u32>> = None;
    for t in [-0.5, 0.0, 0.7, 1.0, 2.5] {
        let placed = at_time(&gpu_scene, &scene, &pass, t);
        let flat = scene.at(t).flattened(usize::MAX).unwrap();
        let reference = render(ctx(), &flat, &cam, &options).unwrap();
        let mut edges = 0;
        for i in 0..placed.ids.len() {
            let (a, b) = (placed.ids[i], reference.ids[i]);
            if a != b {
                assert!(
                    common::on_id_edge(&reference.ids, cam.size, i),
                    "t {t}: pixel {i}"
                );
                edges += 1;
            } else if a != NO_HIT {
                let (ra, rb) = (placed.geometry[i][3], reference.geometry[i][3]);
                assert!(
                    ((ra - rb) / rb).abs() < 1e-4,
                    "t {t}: pixel {i}: {ra} against {rb}"
                );
            }
        }
        assert!(edges <= 4, "t {t}: {edges} pixels differ");
        let pulse_seen = placed.ids.iter().any(|id| pulse_ids.contains(id));
        assert_eq!(
            pulse_seen,
            t != 1.0,
            "t {t}: the pulsing box seen: {pulse_seen}"
        );
        // Before the first key the boxes are where they are at it.
        let before = previous.replace(placed.ids.clone());
        match (before, t) {
            (Some(before), 0.0) => assert_eq!(before, placed.ids, "t {t}"),
            (Some(before), _) => assert_ne!(before, placed.ids, "t {t}: nothing moved"),
            (None, _) => {}
        }
    }
}

/// Through a rolling shutter (5 ms a line) with the camera still, each line sees the moving
/// boxes where they are at its time: line v of the frame stamped at 0.8 s is line v of an
/// instant frame at 0.8 s + 5 ms · v (ids equal but for a few pixels on id edges, ranges
/// within 1e-4), for lines before, at and after the pulsing box's hidden instant (1 s).
#[test]
fn a_rolling_shutter_sees_each_line_at_its_time() {
    let scene = moving_boxes();
    let still = camera("equidistant:f=0.5,fov=180", 96, 72);
    let shutter = Shutter::new(5e-3, 0.0, Readout::TopToBottom).unwrap();
    let rolling = still.with_shutter(shutter);
    let options = RenderOptions::default();
    let gpu_scene = GpuScene::new(ctx(), &scene, &options).unwrap();
    let rolling_pass = (
        FramePass::new(ctx(), &rolling, &gpu_scene, &options).unwrap(),
        rolling,
    );
    let still_pass = (
        FramePass::new(ctx(), &still, &gpu_scene, &options).unwrap(),
        still,
    );
    let frame = at_time(&gpu_scene, &scene, &rolling_pass, 0.8);
    let width = still.size.width as usize;
    let (mut compared, mut edges, mut differs) = (0, 0, 0);
    let at_stamp = at_time(&gpu_scene, &scene, &still_pass, 0.8);
    for line in [6usize, 20, 36, 40, 50, 66] {
        let t = 0.8 + 5e-3 * line as f64;
        let instant = at_time(&gpu_scene, &scene, &still_pass, t);
        for i in line * width..(line + 1) * width {
            if frame.ids[i] != instant.ids[i] {
                assert!(
                    common::on_id_edge(&instant.ids, still.size, i),
                    "line {line}, pixel {i}"
                );
                edges += 1;
                continue;
            }
            if frame.ids[i] != at_stamp.ids[i] {
                differs += 1;
            }
            if frame.ids[i] != NO_HIT {
                let (a, b) = (frame.geometry[i][3], instant.geometry[i][3]);
                assert!(
                    ((a - b) / b).abs() < 1e-4,
                    "line {line}, pixel {i}: {a} against {b}"
                );
                compared += 1;
            }
        }
    }
    assert!(edges <= 6, "{edges} pixels on edges differ");
    assert!(compared > 150, "{compared} pixels compared");
    // The lines late in the readout are not the stamp's.
    assert!(
        differs > 5,
        "{differs} pixels differ from the stamp's frame"
    );
}

/// With an exposure of 0.8 s (64 rays a pixel, each at its stratum's time), where the boxes
/// move the frame is the mean of 16 instants spread over the exposure to within sampling
/// noise: a mean absolute difference under a quarter of the still frame's from it (measured:
/// 0.05 against 0.37, a seventh; 64 samples of a pixel covered part of the time err by about
/// 1/8 of the contrast). The ground truth (one ray at each pixel's centre, at the stamp) is the
/// still frame's.
#[test]
fn an_exposure_blurs_moving_instances() {
    let scene = moving_boxes();
    let still = camera("equidistant:f=0.5,fov=180", 96, 72);
    let exposure = 0.8;
    let blurred = still.with_shutter(Shutter::new(0.0, exposure, Readout::TopToBottom).unwrap());
    let options = RenderOptions {
        spp: 64,
        ..RenderOptions::default()
    };
    let gpu_scene = GpuScene::new(ctx(), &scene, &options).unwrap();
    let blur_pass = (
        FramePass::new(ctx(), &blurred, &gpu_scene, &options).unwrap(),
        blurred,
    );
    let still_pass = (
        FramePass::new(ctx(), &still, &gpu_scene, &options).unwrap(),
        still,
    );
    let stamp = 0.6;
    let frame = at_time(&gpu_scene, &scene, &blur_pass, stamp);
    let at_stamp = at_time(&gpu_scene, &scene, &still_pass, stamp);
    assert_eq!(frame.ids, at_stamp.ids);
    let steps = 16;
    let mut mean = vec![[0.0f32; 3]; frame.colour.len()];
    // Pixels some instant sees differently from the stamp: where the boxes move.
    let mut moving = vec![false; frame.colour.len()];
    for k in 0..steps {
        let t = stamp + exposure * ((k as f64 + 0.5) / steps as f64 - 0.5);
        let instant = at_time(&gpu_scene, &scene, &still_pass, t);
        for (i, (m, c)) in mean.iter_mut().zip(&instant.colour).enumerate() {
            for j in 0..3 {
                m[j] += c[j] / steps as f32;
                moving[i] |= (c[j] - at_stamp.colour[i][j]).abs() > 0.02;
            }
        }
    }
    let pixels: Vec<usize> = (0..mean.len()).filter(|&i| moving[i]).collect();
    assert!(pixels.len() > 60, "{} pixels move", pixels.len());
    let difference = |other: &dyn Fn(usize) -> [f32; 3]| {
        let d: f32 = pixels
            .iter()
            .map(|&i| {
                (0..3)
                    .map(|j| (frame.colour[i][j] - other(i)[j]).abs())
                    .sum::<f32>()
            })
            .sum();
        d / pixels.len() as f32
    };
    let blur_error = difference(&|i| mean[i]);
    let still_error = difference(&|i| {
        let c = at_stamp.colour[i];
        [c[0], c[1], c[2]]
    });
    assert!(
        blur_error < 0.25 * still_error,
        "blurred against the instants' mean {blur_error}, against the still frame {still_error}"
    );
}
