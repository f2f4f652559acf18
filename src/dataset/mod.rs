//! Synthetic fisheye datasets: a rig of calibrated cameras moved along a trajectory, every
//! camera rendered at every pose with its ground truth, split into shards that machines
//! render independently and that resume after a kill.
//!
//! ## Frames and conventions
//! A trajectory's pose is `T_world_body`. A camera's pose in the scene is
//! `T_scene_camera = T_scene_world · T_world_body · T_body_rig · T_rig_camera`, where
//! `T_scene_world` says how the trajectory's world sits in the scene (identity, or `z-up` for
//! the usual robotics world whose z axis points up in a y-up scene), `T_body_rig` where the
//! rig sits on the body, and `T_rig_camera` comes from the rig's calibration (see
//! [`crate::lens::calib::read_rig`]; identity for a lone camera). Camera frames are OpenCV's.
//!
//! ## Shards
//! Shard `I/N` renders the poses `[I·P/N, (I+1)·P/N)` of `P`: contiguous, disjoint, covering
//! every pose, and the same on every machine. Every file is written to a temporary name and
//! renamed, so a frame whose files all exist is complete and a rerun skips it.

pub mod flow;
pub mod imu;
pub mod labels;
pub mod readout;
pub mod smooth;
pub mod trajectory;

#[cfg(feature = "cli")]
mod between;
#[cfg(feature = "cli")]
mod files;
#[cfg(feature = "cli")]
mod run;
#[cfg(feature = "cli")]
pub use between::{Between, FlowFile};
#[cfg(feature = "cli")]
pub use files::{ArrayFile, merge};
#[cfg(feature = "cli")]
pub use run::{Dataset, Progress, RunReport, Submission};

use std::ops::Range;

use glam::DAffine3;

use crate::scene::Camera;

/// The look-at camera with the pose `T_scene_camera` (an OpenCV camera frame): the eye at its
/// origin, looking along its z axis, with "up" its -y axis, so that [`Camera::rotation`]
/// gives back the transform's rotation (rolled cameras included).
pub fn camera_from_transform(scene_from_camera: &DAffine3) -> Camera {
    let m = scene_from_camera.matrix3;
    let position = scene_from_camera.translation;
    Camera {
        position,
        look_at: position + m.z_axis,
        up: -m.y_axis,
    }
}

/// One shard of a dataset's poses: `index` of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// Which shard, from 0.
    pub index: usize,
    /// How many shards.
    pub count: usize,
}

impl Shard {
    /// The whole dataset as one shard.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// The poses of `poses` this shard renders (see the module docs).
    pub fn poses(&self, poses: usize) -> Range<usize> {
        let at = |i: usize| (i as u128 * poses as u128 / self.count as u128) as usize;
        at(self.index)..at(self.index + 1)
    }
}

impl std::str::FromStr for Shard {
    type Err = String;

    /// `I/N` with `0 ≤ I < N`.
    fn from_str(text: &str) -> Result<Self, String> {
        let bad = || format!("{text:?}: a shard is I/N, shard I (from 0) of N");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count {
            return Err(format!(
                "{text:?}: shard {index} of {count} does not exist; shards are numbered 0 to \
                 N-1"
            ));
        }
        Ok(Shard { index, count })
    }
}

/// The file name stem of a frame: its index (six digits) and its time stamp.
pub fn frame_stem(index: usize, stamp: &str) -> String {
    format!("{index:06}_{stamp}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Any number of shards cuts any number of poses into contiguous, disjoint ranges that
    /// cover them all, their sizes differing by at most one.
    #[test]
    fn shards_cover_every_pose_once() {
        for poses in [0, 1, 7, 100, 1001] {
            for count in 1..=9 {
                let ranges: Vec<Range<usize>> = (0..count)
                    .map(|index| Shard { index, count }.poses(poses))
                    .collect();
                assert_eq!(ranges[0].start, 0);
                assert_eq!(ranges[count - 1].end, poses);
                for pair in ranges.windows(2) {
                    assert_eq!(pair[0].end, pair[1].start);
                }
                let sizes: Vec<usize> = ranges.iter().map(|r| r.len()).collect();
                let (least, most) = (sizes.iter().min(), sizes.iter().max());
                assert!(most.unwrap() - least.unwrap() <= 1, "{sizes:?}");
            }
        }
        assert_eq!("2/4".parse::<Shard>(), Ok(Shard { index: 2, count: 4 }));
        for bad in ["4/4", "1/0", "x/2", "3", "-1/2"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    /// A rolled, pitched and yawed camera comes back from its look-at form with the same
    /// rotation, to rounding.
    #[test]
    fn look_at_cameras_keep_any_rotation() {
        use glam::{DQuat, DVec3, EulerRot};
        for (yaw, pitch, roll) in [(0.0, 0.0, 0.0), (0.3, -0.2, 0.9), (2.5, 1.2, -2.8)] {
            let q = DQuat::from_euler(EulerRot::YXZ, yaw, pitch, roll);
            let t = DAffine3::from_rotation_translation(q, DVec3::new(1.0, -2.0, 3.0));
            let camera = camera_from_transform(&t);
            assert_eq!(camera.position, t.translation);
            let worst = (camera.rotation() - t.matrix3)
                .to_cols_array()
                .into_iter()
                .fold(0.0f64, |a, e| a.max(e.abs()));
            assert!(worst < 1e-14, "rotation off by {worst:e}");
        }
    }
}
