//! Flow against closed forms on scenes whose frames are made here by ray casting in f64
//! (spheres and planes; no GPU): a pure rotation for every lens family, a sideways slide past
//! a plane, and forward against backward flow with an occluder and a rolling shutter.

use glam::{DQuat, DVec2};

use super::*;
use crate::lens::calib::Calibration;
use crate::lens::{CalibratedModel, ImageSize, Lens, Readout, Shutter, parse_spec};

/// A scene as a ray caster: the distance and normal of the first hit, if any.
type Caster = dyn Fn(DVec3, DVec3) -> Option<(f64, DVec3)>;

/// The frame `camera` moving by `motion` sees of `cast`: each pixel's centre ray from the
/// camera at its line's time, as the kernels trace it.
fn frame(camera: &LensCamera, motion: &Motion, cast: &Caster) -> RenderOutput {
    let directions = camera.directions();
    let w = camera.size.width as usize;
    let mut output = RenderOutput {
        size: camera.size,
        colour: vec![[0.0; 4]; directions.len()],
        geometry: vec![[0.0; 4]; directions.len()],
        ids: vec![NO_HIT; directions.len()],
    };
    for (i, d) in directions.iter().enumerate() {
        let Some(d) = d else { continue };
        let t = camera.line_time((i % w) as u32, (i / w) as u32);
        let pose = motion.camera_at(t);
        if let Some((range, normal)) = cast(pose.translation, pose.matrix3 * *d) {
            output.geometry[i] = [
                normal.x as f32,
                normal.y as f32,
                normal.z as f32,
                range as f32,
            ];
            output.ids[i] = 0;
        }
    }
    output
}

/// Two frames of one camera: its rays, its motions over each, and what it saw.
struct Pair<'a> {
    camera: &'a LensCamera,
    directions: Vec<Option<DVec3>>,
    motions: [Motion; 2],
    outputs: [RenderOutput; 2],
}

impl<'a> Pair<'a> {
    /// `camera` moving by each of `motions` over `cast`.
    fn new(camera: &'a LensCamera, motions: [Motion; 2], cast: &Caster) -> Self {
        let outputs = motions.each_ref().map(|m| frame(camera, m, cast));
        Self {
            camera,
            directions: camera.directions(),
            motions,
            outputs,
        }
    }

    /// Frame `k` as flow reads it.
    fn seen(&self, k: usize) -> Seen<'_> {
        Seen {
            camera: self.camera,
            motion: &self.motions[k],
            output: &self.outputs[k],
            directions: &self.directions,
            time: 0.0,
            movers: None,
        }
    }
}

/// A sphere of radius `r` about `centre`, seen from inside.
fn sphere(centre: DVec3, r: f64) -> Box<Caster> {
    Box::new(move |o, d| {
        let oc = o - centre;
        let b = oc.dot(d);
        let t = -b + (b * b - oc.length_squared() + r * r).sqrt();
        let p = oc + d * t;
        Some((t, -p / r))
    })
}

/// The rectangle z = `z`, |x| ≤ `half.x`, |y| ≤ `half.y` (facing -z).
fn wall(z: f64, half: DVec2) -> Box<Caster> {
    Box::new(move |o, d| {
        let t = (z - o.z) / d.z;
        let p = o + d * t;
        (t > 0.0 && p.x.abs() <= half.x && p.y.abs() <= half.y).then_some((t, DVec3::NEG_Z))
    })
}

/// The nearer hit of two scenes.
fn nearer(a: Box<Caster>, b: Box<Caster>) -> Box<Caster> {
    Box::new(move |o, d| match (a(o, d), b(o, d)) {
        (Some(x), Some(y)) => Some(if x.0 <= y.0 { x } else { y }),
        (x, y) => x.or(y),
    })
}

/// A camera standing at `eye` turned by `turn` (camera to world).
fn standing(eye: DVec3, turn: DQuat) -> Motion {
    Motion {
        knots: vec![(0.0, DAffine3::from_rotation_translation(turn, eye))],
        body_from_camera: DAffine3::IDENTITY,
    }
}

/// Every lens family: classic mappings and each calibrated model, at 64 × 64 or so.
fn every_family() -> Vec<LensCamera> {
    let size = ImageSize::new(64, 48).unwrap();
    let mut cameras: Vec<LensCamera> = [
        "equidistant:f=0.45,fov=180",
        "stereographic:f=0.5",
        "equisolid:f=0.6",
        "orthographic:f=0.7",
        "rectilinear:f=1.2",
    ]
    .iter()
    .map(|spec| LensCamera::new(parse_spec(spec).unwrap(), size))
    .collect();
    for (spec, (w, h)) in CalibratedModel::EXAMPLES
        .iter()
        .zip(CalibratedModel::EXAMPLE_SIZES)
    {
        let Lens::Calibrated(lens) = parse_spec(spec).unwrap() else {
            unreachable!("{spec} is calibrated")
        };
        let small = Calibration {
            lens: lens.scaled(0.125, 0.125),
            size: ImageSize::new(w / 8, h / 8).unwrap(),
            line_delay: 0.0,
        };
        cameras.push(LensCamera::new(small.lens, small.size));
    }
    cameras
}

/// Under a pure rotation the flow does not depend on depth: inside spheres of radius 2 and 50
/// about the eye it is, for every lens family, the lens's image of each pixel's direction
/// turned by the rotation (to 1e-4 px: ranges are f32), and every pixel that lands is seen.
#[test]
fn a_pure_rotation_moves_each_pixel_by_the_lens_mapping_of_the_turned_ray() {
    let eye = DVec3::new(0.3, -0.2, 1.0);
    let (a, b) = (
        DQuat::from_rotation_y(0.1),
        DQuat::from_rotation_y(0.1)
            * DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.15),
    );
    for camera in every_family() {
        let directions = camera.directions();
        let mut flows = Vec::new();
        for radius in [2.0, 50.0] {
            let scene = sphere(eye, radius);
            let pair = Pair::new(&camera, [standing(eye, a), standing(eye, b)], &scene);
            flows.push(optical_flow(&pair.seen(0), Some(&pair.seen(1))));
        }
        let name = camera.lens.to_string();
        let mut landed = 0;
        for (i, d) in directions.iter().enumerate() {
            let Some(d) = d else { continue };
            let turned = (b.inverse() * a) * *d;
            let wanted = camera
                .project(turned)
                .map(|p| p - Seen::centre_of(&camera, i));
            for (flow, valid) in &flows {
                let v = flow[i];
                match wanted {
                    Some(w) => {
                        let got = DVec2::new(v[0].into(), v[1].into());
                        assert!(
                            (got - w).length() < 1e-4,
                            "{name}: pixel {i}: {got} against {w}"
                        );
                        assert_eq!(valid[i], 1, "{name}: pixel {i} lands but is not seen");
                    }
                    None => assert!(v[0].is_nan() && valid[i] == 0, "{name}: pixel {i}"),
                }
            }
            landed += usize::from(wanted.is_some());
        }
        assert!(landed > 500, "{name}: {landed} pixels land");
    }
}

/// A pinhole sliding sideways by Δ past a plane at depth Z moves every pixel by -f·Δ/Z:
/// -3 px for each of two depths' planes (f = 60 px; Δ = 0.1 m at 2 m, 0.5 m at 10 m), and
/// the scene flow is -Δ along x everywhere.
#[test]
fn a_sideways_slide_past_a_plane_moves_pixels_by_focal_length_times_slide_over_depth() {
    let camera = LensCamera::new(
        parse_spec("rectilinear:f=1.5").unwrap(),
        ImageSize::new(80, 60).unwrap(),
    );
    let f = 1.5 * 40.0;
    for (depth, slide) in [(2.0, 0.1), (10.0, 0.5)] {
        let scene = wall(depth, DVec2::splat(1e3));
        let motions = [
            standing(DVec3::ZERO, DQuat::IDENTITY),
            standing(DVec3::new(slide, 0.0, 0.0), DQuat::IDENTITY),
        ];
        let pair = Pair::new(&camera, motions, &scene);
        let (flow, valid) = optical_flow(&pair.seen(0), Some(&pair.seen(1)));
        let moved = scene_flow(&pair.seen(0), Some(&pair.seen(1)));
        let wanted = -f * slide / depth;
        let mut landed = 0;
        for i in 0..flow.len() {
            if flow[i][0].is_nan() {
                continue;
            }
            landed += 1;
            assert!(
                (f64::from(flow[i][0]) - wanted).abs() < 1e-4,
                "pixel {i}: {:?}",
                flow[i]
            );
            assert!(flow[i][1].abs() < 1e-4 && valid[i] == 1, "pixel {i}");
            let m = DVec3::from_array(moved[i].map(f64::from));
            assert!(
                (m - DVec3::new(-slide, 0.0, 0.0)).length() < 1e-5,
                "pixel {i}: {m}"
            );
        }
        // All but the columns that slide out of the image land.
        assert!(landed >= 60 * 76, "{landed} pixels land");
    }
}

/// With a rolling shutter and a camera turning and moving past a wall with a panel in front:
/// forward flow from one frame and backward flow from the next agree on covisible pixels
/// (following one then the other returns within a pixel, as the landing and the nearest
/// pixel's centre are within √2/2 px; 10,681 pixels), and flow_valid matches visibility cast
/// in the scene itself (a ray from the second camera to the hit meets nothing nearer) except
/// where the landing's pixel borders a step in range (measured: 21 such pixels, against 65
/// the panel hides).
#[test]
fn forward_and_backward_flow_agree_where_both_frames_see_the_point() {
    let camera = LensCamera::new(
        parse_spec("equidistant:f=0.5,fov=180").unwrap(),
        ImageSize::new(160, 120).unwrap(),
    )
    .with_shutter(Shutter::new(2e-4, 0.0, Readout::TopToBottom).unwrap());
    let scene = nearer(
        wall(6.0, DVec2::splat(50.0)),
        wall(3.0, DVec2::new(1.0, 0.8)),
    );
    // The body over both frames: 0.4 rad/s about y, 12 m/s along x; frames 50 ms apart.
    let body = |t: f64| {
        DAffine3::from_rotation_translation(
            DQuat::from_rotation_y(0.4 * t),
            DVec3::new(12.0 * t, 0.0, 0.0),
        )
    };
    let over = |stamp: f64| Motion {
        knots: [0.0, 0.02].map(|t| (t, body(stamp + t))).to_vec(),
        body_from_camera: DAffine3::IDENTITY,
    };
    let motions = [over(0.0), over(0.05)];
    let pair = Pair::new(&camera, motions, &scene);
    let seen = |k: usize| pair.seen(k);
    let (forward, forward_valid) = optical_flow(&seen(0), Some(&seen(1)));
    let (backward, backward_valid) = optical_flow(&seen(1), Some(&seen(0)));
    let w = 160;
    let (mut compared, mut disagree, mut occluded) = (0, 0, 0);
    for i in 0..forward.len() {
        if forward_valid[i] == 0 {
            continue;
        }
        let landing =
            Seen::centre_of(&camera, i) + DVec2::new(forward[i][0].into(), forward[i][1].into());
        let q = (landing.y.floor() as usize) * w + landing.x.floor() as usize;
        if backward_valid[q] == 0 {
            continue;
        }
        compared += 1;
        let back =
            Seen::centre_of(&camera, q) + DVec2::new(backward[q][0].into(), backward[q][1].into());
        assert!(
            (back - Seen::centre_of(&camera, i)).length() < 1.0,
            "pixel {i} returns to {back}"
        );
    }
    // Visibility cast in the scene against flow_valid: they may differ only where the
    // landing's pixel borders a step in range (an edge of the panel).
    let (from, to) = (seen(0), seen(1));
    let range = |q: usize| f64::from(pair.outputs[1].geometry[q][3]);
    let beside_edge = |q: usize| {
        let (x, y) = ((q % w) as i64, (q / w) as i64);
        (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
            .any(|(nx, ny)| {
                let inside = (0..w as i64).contains(&nx) && (0..120).contains(&ny);
                inside && (range((ny * w as i64 + nx) as usize) - range(q)).abs() > 0.1 * range(q)
            })
    };
    for (i, valid) in forward_valid.iter().enumerate() {
        let Some((tracked, _, _)) = from.hit(i) else {
            continue;
        };
        let Some((pixel, pose, point)) = to.land(&tracked) else {
            continue;
        };
        let ray = point - pose.translation;
        let hit = scene(pose.translation, ray.normalize()).map_or(f64::INFINITY, |h| h.0);
        let visible = hit >= ray.length() * (1.0 - 1e-6);
        occluded += usize::from(!visible);
        if visible != (*valid == 1) {
            disagree += 1;
            let q = to.nearest(pixel).unwrap();
            assert!(
                beside_edge(q),
                "pixel {i}: visible {visible}, away from any edge"
            );
        }
    }
    assert!(compared > 3000, "{compared} pixels compared");
    assert!(
        occluded > 50,
        "{occluded} pixels occluded: the panel hides too few"
    );
    assert!(
        disagree < occluded,
        "{disagree} disagree, {occluded} occluded"
    );
}
