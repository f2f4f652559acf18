//! A camera that moves while a frame is read out and exposed ([`Motion`]): its pose in a
//! moving body, and the body's poses at times around the frame's stamp, which the kernels
//! interpolate at each ray's time as [`crate::pose::interpolate`] does (`wgsl/frame.wgsl`).

use glam::{DAffine3, DQuat, DVec3};

use super::gpu_scene::view_frame;
use crate::error::{Error, Result};
use crate::lens::{LensCamera, Shutter};
use crate::pose::interpolate;
use crate::scene::Camera;
use crate::shared::{Frame, Knot, MAX_KNOTS};

/// A camera's motion over one frame: `T_scene_camera(t) = body(t) · body_from_camera`, where
/// `body(t)` is interpolated between `knots` (seconds from the frame's stamp, increasing, and
/// `T_scene_body` there) and held at the ends.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// `(seconds from the stamp, T_scene_body)`, at least one, in increasing time.
    pub knots: Vec<(f64, DAffine3)>,
    /// `T_body_camera` (an OpenCV camera frame).
    pub body_from_camera: DAffine3,
}

impl Motion {
    /// A camera at `pose` throughout.
    pub fn still(pose: &Camera) -> Self {
        Self {
            knots: vec![(0.0, DAffine3::from_translation(pose.position))],
            body_from_camera: DAffine3::from_mat3(pose.rotation()),
        }
    }

    /// `T_scene_camera` at `t` seconds from the stamp (the f64 reference of the kernels'
    /// `camera_at`).
    pub fn camera_at(&self, t: f64) -> DAffine3 {
        let after = self.knots.partition_point(|(time, _)| *time <= t);
        let body = match (after.checked_sub(1), self.knots.get(after)) {
            (Some(i), Some(b)) => {
                let a = &self.knots[i];
                interpolate(&a.1, &b.1, (t - a.0) / (b.0 - a.0))
            }
            (Some(i), None) => self.knots[i].1,
            (None, _) => self.knots[0].1,
        };
        body * self.body_from_camera
    }

    /// The frame the kernels read for a scene uploaded relative to `origin`, through a
    /// camera with `shutter`: the camera at the stamp where rays are all at once, else the
    /// knots. Errors where the knots are empty, out of order or more than [`MAX_KNOTS`].
    pub(crate) fn frame(&self, origin: DVec3, shutter: &Shutter) -> Result<Frame> {
        let bad = |message: String| Error::Option(format!("the camera's motion: {message}"));
        if self.knots.is_empty() || self.knots.len() > MAX_KNOTS {
            return Err(bad(format!(
                "{} poses over one frame; a frame takes 1 to {MAX_KNOTS}",
                self.knots.len()
            )));
        }
        if let Some(pair) = self
            .knots
            .windows(2)
            .find(|p| p[0].0.partial_cmp(&p[1].0) != Some(std::cmp::Ordering::Less))
        {
            return Err(bad(format!(
                "the pose at {} s follows one at {} s; times must increase",
                pair[1].0, pair[0].0
            )));
        }
        // The camera in the body where it moves, else in the world relative to the origin
        // at the stamp (one knot at rest).
        let (mut frame, knots) = if shutter.moves() && self.knots.len() > 1 {
            let camera = self.body_from_camera;
            let frame = view_frame(DVec3::ZERO, camera.translation, camera.matrix3, [0, 0]);
            (frame, &self.knots[..])
        } else {
            let at = self.camera_at(0.0);
            (
                view_frame(origin, at.translation, at.matrix3, [0, 0]),
                &[][..],
            )
        };
        frame.shutter = [shutter.line_delay as f32, shutter.exposure as f32, 0.0, 0.0];
        frame.motion = [knots.len().max(1) as u32, shutter.readout.id(), 0, 0];
        for (knot, (t, body)) in frame.knots.iter_mut().zip(knots) {
            let q = DQuat::from_mat3(&body.matrix3).normalize().as_quat();
            let p = (body.translation - origin).as_vec3();
            *knot = Knot {
                rotation: q.to_array(),
                position: [p.x, p.y, p.z, *t as f32],
            };
        }
        Ok(frame)
    }
}

/// The world-space direction of every pixel's centre ray of `camera` moving by `motion`,
/// each at its line's time ([`LensCamera::line_time`]), row-major, `None` where the lens masks
/// the pixel: `directions` are `camera`'s in its own frame ([`LensCamera::directions`]).
pub fn moving_directions(
    camera: &LensCamera,
    directions: &[Option<DVec3>],
    motion: &Motion,
) -> Vec<Option<DVec3>> {
    let size = camera.size;
    let width = size.width as usize;
    directions
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let (x, y) = ((i % width) as u32, (i / width) as u32);
            let t = camera.line_time(x, y);
            d.map(|d| motion.camera_at(t).matrix3 * d)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body turning at a constant rate about z carries a camera offset from its origin:
    /// halfway between two knots the camera has turned halfway and sits on the arc (not the
    /// chord) between its ends; before the first knot and after the last it is held.
    #[test]
    fn cameras_move_with_their_body_between_knots() {
        let turn = |angle: f64| DAffine3::from_rotation_z(angle);
        let motion = Motion {
            knots: vec![(0.0, turn(0.0)), (2.0, turn(1.0))],
            body_from_camera: DAffine3::from_translation(DVec3::X),
        };
        let half = motion.camera_at(1.0);
        assert!(
            half.translation
                .abs_diff_eq(DVec3::new(0.5f64.cos(), 0.5f64.sin(), 0.0), 1e-12)
        );
        assert_eq!(motion.camera_at(-1.0), motion.camera_at(0.0));
        assert!(
            motion
                .camera_at(3.0)
                .abs_diff_eq(turn(1.0) * motion.body_from_camera, 1e-12)
        );
        let still = Motion::still(&Camera {
            position: DVec3::new(1.0, 2.0, 3.0),
            look_at: DVec3::new(1.0, 2.0, 4.0),
            up: DVec3::NEG_Y,
        });
        assert!(
            still
                .camera_at(5.0)
                .abs_diff_eq(DAffine3::from_translation(DVec3::new(1.0, 2.0, 3.0)), 1e-15)
        );
    }

    /// A still frame puts the camera relative to the origin with one knot at rest; a moving
    /// one keeps the camera in the body and its knots relative to the origin; bad knots are
    /// refused by what is wrong.
    #[test]
    fn frames_hold_a_still_camera_or_the_knots() {
        let rolling = Shutter::new(1e-3, 0.0, crate::lens::Readout::TopToBottom).unwrap();
        let origin = DVec3::new(10.0, 0.0, 0.0);
        let motion = Motion {
            knots: vec![
                (0.0, DAffine3::from_translation(DVec3::new(11.0, 0.0, 0.0))),
                (0.5, DAffine3::from_translation(DVec3::new(12.0, 0.0, 0.0))),
            ],
            body_from_camera: DAffine3::from_translation(DVec3::Y),
        };
        let moving = motion.frame(origin, &rolling).unwrap();
        assert_eq!(moving.motion[0], 2);
        assert_eq!(moving.eye, [0.0, 1.0, 0.0, 0.0]);
        assert_eq!(moving.knots[1].position, [2.0, 0.0, 0.0, 0.5]);
        let still = motion.frame(origin, &Shutter::GLOBAL).unwrap();
        assert_eq!((still.motion[0], still.eye), (1, [1.0, 1.0, 0.0, 0.0]));
        assert_eq!(still.knots[0].rotation, [0.0, 0.0, 0.0, 1.0]);
        let reversed = Motion {
            knots: motion.knots.iter().rev().cloned().collect(),
            ..motion.clone()
        };
        let error = reversed.frame(origin, &rolling).unwrap_err().to_string();
        assert!(error.contains("times must increase"), "{error}");
        let crowded = Motion {
            knots: (0..=MAX_KNOTS)
                .map(|i| (i as f64, DAffine3::IDENTITY))
                .collect(),
            ..motion
        };
        let error = crowded.frame(origin, &rolling).unwrap_err().to_string();
        assert!(error.contains("1 to 64"), "{error}");
    }
}
