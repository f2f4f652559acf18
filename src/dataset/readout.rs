//! A frame's cameras in time: where a rolling shutter or an exposure spreads a frame's rays
//! over an interval around its stamp, each camera's [`Motion`] over that interval from the
//! trajectory, and the frames whose interval reaches past the trajectory's ends (skipped:
//! poses are never extrapolated).

use glam::DAffine3;

use super::smooth::Spline;
use super::trajectory::{Pose, pose_at};
use crate::lens::LensCamera;
use crate::shared::MAX_KNOTS;
use crate::trace::Motion;

/// Why a frame cannot be rendered with a camera's shutter.
#[derive(Clone, Debug, PartialEq)]
pub enum Unrenderable {
    /// Its readout and exposure reach before the first stamp or after the last: skipped.
    Outside(String),
    /// They span more of the trajectory's poses than a frame holds: an error.
    Crowded(String),
}

/// A trajectory as a function of time: slerp and lerp between its stamps, or its smooth
/// spline where an IMU is simulated.
#[derive(Clone, Copy, Debug)]
pub enum Track<'a> {
    /// Between the stamps ([`pose_at`]).
    Stamps(&'a [Pose]),
    /// The cumulative cubic B-spline through them.
    Smooth(&'a Spline),
}

impl Track<'_> {
    /// `T_world_body` at `t` seconds, `None` outside the path's span.
    pub fn pose_at(&self, t: f64) -> Option<DAffine3> {
        match self {
            Track::Stamps(stamps) => pose_at(stamps, t),
            Track::Smooth(spline) => spline.at(t).map(|m| m.pose),
        }
    }

    /// The first and last times the path has a pose.
    pub fn span(&self) -> (f64, f64) {
        match self {
            Track::Stamps(stamps) => (
                stamps.first().map_or(0.0, |p| p.seconds),
                stamps.last().map_or(0.0, |p| p.seconds),
            ),
            Track::Smooth(spline) => spline.span(),
        }
    }

    /// The times strictly between `a` and `b` where a frame's knots go: the stamps, between
    /// which the kernels' slerp is exact; on the spline, an eighth of its step apart.
    fn between(&self, a: f64, b: f64) -> Vec<f64> {
        match self {
            Track::Stamps(stamps) => {
                let lo = stamps.partition_point(|p| p.seconds <= a);
                let hi = stamps.partition_point(|p| p.seconds < b);
                stamps[lo..hi.max(lo)].iter().map(|p| p.seconds).collect()
            }
            Track::Smooth(spline) => {
                let pieces = ((b - a) / (spline.step() / 8.0)).ceil().max(1.0) as usize;
                (1..pieces)
                    .map(|k| a + (b - a) * k as f64 / pieces as f64)
                    .collect()
            }
        }
    }
}

/// The motion of `camera` (at `body_from_camera` on the body) over the frame at `seconds`:
/// the body's poses `T_scene_world · T_world_body(t)` along `track` at the start and end of
/// the camera's readout and exposure ([`LensCamera::exposure_span`]) and at the times
/// between where the path needs knots, times counted from `seconds`. A camera whose rays
/// are all at the stamp gets the one pose there.
pub fn frame_motion(
    track: Track,
    seconds: f64,
    camera: &LensCamera,
    scene_from_world: &DAffine3,
    body_from_camera: DAffine3,
) -> Result<Motion, Unrenderable> {
    let (first, last) = camera.exposure_span();
    let body = |t: f64| track.pose_at(seconds + t).map(|p| *scene_from_world * p);
    let (Some(start), Some(end)) = (body(first), body(last)) else {
        let (a, b) = track.span();
        return Err(Unrenderable::Outside(format!(
            "its readout and exposure, {:.6} s to {:.6} s, reach past the trajectory's \
             poses ({a:.6} s to {b:.6} s), and poses are never extrapolated",
            seconds + first,
            seconds + last
        )));
    };
    if last <= first {
        return Ok(Motion {
            knots: vec![(0.0, start)],
            body_from_camera,
        });
    }
    let inside = track
        .between(seconds + first, seconds + last)
        .into_iter()
        .filter_map(|t| Some((t - seconds, *scene_from_world * track.pose_at(t)?)));
    let knots: Vec<(f64, DAffine3)> = std::iter::once((first, start))
        .chain(inside)
        .chain(std::iter::once((last, end)))
        .collect();
    if knots.len() > MAX_KNOTS {
        return Err(Unrenderable::Crowded(format!(
            "its readout and exposure ({:.6} s) span {} poses of the trajectory; a frame \
             holds at most {MAX_KNOTS}: resample the trajectory more coarsely",
            last - first,
            knots.len()
        )));
    }
    Ok(Motion {
        knots,
        body_from_camera,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::trajectory::{TrajectoryFormat, parse};
    use crate::lens::{ImageSize, Readout, Shutter, parse_spec};
    use glam::DVec3;

    fn camera(line_delay: f64, exposure: f64) -> LensCamera {
        let size = ImageSize::new(8, 11).unwrap();
        LensCamera::new(parse_spec("equidistant:f=0.45,fov=180").unwrap(), size)
            .with_shutter(Shutter::new(line_delay, exposure, Readout::TopToBottom).unwrap())
    }

    /// A 10-line readout 0.1 s a line over stamps a quarter second apart: knots at the
    /// readout's ends and the stamps between, each the trajectory's pose there; the camera at
    /// each line's time as the trajectory puts it; frames reaching past either end refused
    /// as outside; a frame spanning too many stamps refused as crowded.
    #[test]
    fn knots_follow_the_trajectory_over_the_readout() {
        let tum: String = (0..=8)
            .map(|k| format!("{} {} 0 0 0 0 0 1\n", f64::from(k) * 0.25, k * k))
            .collect();
        let trajectory = parse(&tum, TrajectoryFormat::Tum, 1.0).unwrap();
        let rolling = camera(0.1, 0.0);
        let offset = DAffine3::from_translation(DVec3::Y);
        let motion = frame_motion(
            Track::Stamps(&trajectory),
            0.6,
            &rolling,
            &DAffine3::IDENTITY,
            offset,
        )
        .unwrap();
        let times: Vec<f64> = motion.knots.iter().map(|k| k.0).collect();
        let wanted = [0.0, 0.15, 0.4, 0.65, 0.9, 1.0];
        assert_eq!(times.len(), wanted.len());
        for (t, w) in times.iter().zip(wanted) {
            assert!((t - w).abs() < 1e-12, "{times:?}");
        }
        for line in 0..11 {
            let t = rolling.line_time(0, line);
            let truth = pose_at(&trajectory, 0.6 + t).unwrap() * offset;
            assert!(motion.camera_at(t).abs_diff_eq(truth, 1e-12), "line {line}");
        }
        for seconds in [1.1, -0.01] {
            let outside = frame_motion(
                Track::Stamps(&trajectory),
                seconds,
                &rolling,
                &DAffine3::IDENTITY,
                offset,
            );
            assert!(
                matches!(outside, Err(Unrenderable::Outside(_))),
                "{seconds}"
            );
        }
        // An exposure of 0.2 s centred on the stamp reaches 0.1 s before the first.
        let exposed = camera(0.0, 0.2);
        let early = frame_motion(
            Track::Stamps(&trajectory),
            0.05,
            &exposed,
            &DAffine3::IDENTITY,
            offset,
        );
        assert!(matches!(early, Err(Unrenderable::Outside(_))));
        let dense: String = (0..=200)
            .map(|k| format!("{} 0 0 0 0 0 0 1\n", f64::from(k) * 0.01))
            .collect();
        let dense = parse(&dense, TrajectoryFormat::Tum, 1.0).unwrap();
        let crowded = frame_motion(
            Track::Stamps(&dense),
            0.0,
            &rolling,
            &DAffine3::IDENTITY,
            offset,
        );
        assert!(matches!(crowded, Err(Unrenderable::Crowded(m)) if m.contains("at most 64")));
        let still = camera(0.0, 0.0);
        let one = frame_motion(
            Track::Stamps(&trajectory),
            0.6,
            &still,
            &DAffine3::IDENTITY,
            offset,
        )
        .unwrap();
        assert_eq!(one.knots.len(), 1);
    }
}
