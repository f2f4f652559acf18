//! Trajectories: the poses `T_world_body` of a moving body, in the text formats datasets ship.
//!
//! - **TUM** (the TUM RGB-D benchmark's `groundtruth.txt`): `timestamp tx ty tz qx qy qz qw`
//!   per line, seconds and metres, separated by spaces; `#` starts a comment.
//! - **KITTI** (the odometry benchmark's `poses/NN.txt`): twelve numbers per line, the rows of a
//!   3×4 `[R | t]`; no time stamps, so frame `i` is at `i / fps` seconds.
//! - **EuRoC** (the MAV dataset's `state_groundtruth_estimate0/data.csv` or any CSV of its
//!   layout): `timestamp [ns], p_x, p_y, p_z, q_w, q_x, q_y, q_z[, more columns]` separated by
//!   commas; lines starting with `#` are headers. Note the quaternion's `w` comes first.
//!
//! A trajectory is a function of time between its first and last stamps ([`pose_at`]): poses
//! at other times, as another frame rate needs them ([`resample`]), are interpolated between
//! the stamps around them, never extrapolated past either end.

use std::path::Path;

use glam::{DAffine3, DVec3};

use crate::error::{Error, Result};
use crate::pose::{interpolate, rigid, rigid_from_rows, rotation_from_quaternion};

/// A trajectory file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrajectoryFormat {
    /// `timestamp tx ty tz qx qy qz qw`.
    Tum,
    /// The 12 numbers of a 3×4 `[R | t]` a line.
    Kitti,
    /// `timestamp_ns, px, py, pz, qw, qx, qy, qz, ...`, comma-separated.
    Euroc,
}

impl TrajectoryFormat {
    /// Every format with its name.
    pub const ALL: [(&'static str, TrajectoryFormat); 3] = [
        ("tum", Self::Tum),
        ("kitti", Self::Kitti),
        ("euroc", Self::Euroc),
    ];

    /// The format's name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, f)| *f == self)
            .map_or("", |(n, _)| n)
    }

    /// The format of a file's text: EuRoC where the first data line has commas, else TUM for
    /// 8 numbers and KITTI for 12.
    pub fn detect(text: &str) -> Option<Self> {
        let line = data_lines(text).next()?.1;
        if line.contains(',') {
            return Some(Self::Euroc);
        }
        match line.split_whitespace().count() {
            8 => Some(Self::Tum),
            12 => Some(Self::Kitti),
            _ => None,
        }
    }
}

/// One pose of a trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    /// The time stamp as the file writes it (TUM's seconds, EuRoC's nanoseconds), or the
    /// seconds made from the frame rate (KITTI, six decimals): digits and at most one point,
    /// fit for a file name.
    pub stamp: String,
    /// The time in seconds.
    pub seconds: f64,
    /// `T_world_body`: body coordinates to world coordinates.
    pub world_from_body: DAffine3,
}

/// Reads a trajectory file, bounded as [`crate::input::InputKind::Trajectory`]; the format is
/// detected from the text unless given. Errors name the file and the line.
pub fn read(
    path: &Path,
    format: Option<TrajectoryFormat>,
    fps: f64,
) -> Result<(TrajectoryFormat, Vec<Pose>)> {
    let bad = |message: String| Error::Dataset {
        path: path.to_path_buf(),
        message,
    };
    let bytes = crate::input::read(path, crate::input::InputKind::Trajectory)
        .map_err(|e| bad(format!("cannot read the trajectory: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        bad(format!(
            "not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ))
    })?;
    let format = match format.or_else(|| TrajectoryFormat::detect(&text)) {
        Some(f) => f,
        None => {
            return Err(bad(
                "not a trajectory this tool reads: TUM (8 numbers a line), KITTI (12) or EuRoC \
                 CSV (comma-separated, timestamp then position and w-first quaternion)"
                    .into(),
            ));
        }
    };
    let poses =
        parse(&text, format, fps).map_err(|e| bad(format!("{} trajectory: {e}", format.name())))?;
    if poses.is_empty() {
        return Err(bad("the trajectory holds no pose".into()));
    }
    Ok((format, poses))
}

/// The lines holding data, numbered from 1: not blank, not comments (`#`), and for EuRoC not
/// its header.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
}

/// Parses a trajectory's text; errors say the line. `fps` times KITTI's poses.
pub fn parse(text: &str, format: TrajectoryFormat, fps: f64) -> Result<Vec<Pose>, String> {
    if format == TrajectoryFormat::Kitti && !(fps.is_finite() && fps > 0.0) {
        return Err(format!("the frame rate {fps} is not a positive number"));
    }
    let mut poses: Vec<Pose> = Vec::new();
    let mut previous_line = 0;
    for (index, (line, content)) in data_lines(text).enumerate() {
        let pose = pose(content, format, index, fps).map_err(|e| format!("line {line}: {e}"))?;
        // Frames are named by their stamps and rendered in order: a repeated stamp would
        // overwrite a frame, an earlier one reorder the sequence.
        if let Some(last) = poses.last()
            && pose.seconds <= last.seconds
        {
            let how = if pose.seconds == last.seconds {
                "repeats"
            } else {
                "comes before"
            };
            return Err(format!(
                "line {line}: the time stamp {} {how} line {previous_line}'s {}; a \
                 trajectory's stamps must increase",
                pose.stamp, last.stamp
            ));
        }
        poses.push(pose);
        previous_line = line;
    }
    Ok(poses)
}

/// One data line's pose.
fn pose(line: &str, format: TrajectoryFormat, index: usize, fps: f64) -> Result<Pose, String> {
    let fields: Vec<&str> = match format {
        TrajectoryFormat::Euroc => line.split(',').map(str::trim).collect(),
        _ => line.split_whitespace().collect(),
    };
    let wanted = match format {
        TrajectoryFormat::Tum => 8,
        TrajectoryFormat::Kitti => 12,
        TrajectoryFormat::Euroc => 8,
    };
    let enough = match format {
        TrajectoryFormat::Euroc => fields.len() >= wanted,
        _ => fields.len() == wanted,
    };
    if !enough {
        return Err(format!(
            "{} fields; a {} pose has {wanted}{}",
            fields.len(),
            format.name(),
            if format == TrajectoryFormat::Euroc {
                " or more"
            } else {
                ""
            }
        ));
    }
    let numbers: Vec<f64> = fields[..wanted]
        .iter()
        .map(|f| match f.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("{f:?} is not a finite number")),
        })
        .collect::<Result<_, _>>()?;
    let n = &numbers;
    let (stamp, seconds, world_from_body) = match format {
        TrajectoryFormat::Tum => {
            let rotation = rotation_from_quaternion(n[4], n[5], n[6], n[7])?;
            let t = rigid(rotation, DVec3::new(n[1], n[2], n[3]));
            (stamp_text(fields[0])?, n[0], t)
        }
        TrajectoryFormat::Euroc => {
            let rotation = rotation_from_quaternion(n[5], n[6], n[7], n[4])?;
            let t = rigid(rotation, DVec3::new(n[1], n[2], n[3]));
            (stamp_text(fields[0])?, n[0] * 1e-9, t)
        }
        TrajectoryFormat::Kitti => {
            let rows: Vec<Vec<f64>> = n.chunks(4).map(<[f64]>::to_vec).collect();
            let seconds = index as f64 / fps;
            (format!("{seconds:.6}"), seconds, rigid_from_rows(&rows)?)
        }
    };
    Ok(Pose {
        stamp,
        seconds,
        world_from_body,
    })
}

/// The most frames [`resample`] makes.
pub const MAX_FRAMES: usize = 10_000_000;

/// The pose at `seconds` (the poses' clock): between the stamps around it, the translation
/// interpolated linearly and the rotation by spherical linear interpolation
/// ([`crate::pose::interpolate`]: the shortest arc at constant angular velocity), exact at
/// the stamps. Continuous, with a velocity that jumps at the
/// stamps, as the piecewise-constant motion a sampled trajectory implies. `None` before the
/// first stamp and after the last: poses are never extrapolated.
pub fn pose_at(poses: &[Pose], seconds: f64) -> Option<DAffine3> {
    let (first, last) = (poses.first()?, poses.last()?);
    if !(first.seconds..=last.seconds).contains(&seconds) {
        return None;
    }
    // The first pose after `seconds`: the pose before it and it bracket the time.
    let after = poses.partition_point(|p| p.seconds <= seconds);
    if after == poses.len() {
        return Some(last.world_from_body);
    }
    let (a, b) = (&poses[after - 1], &poses[after]);
    let s = (seconds - a.seconds) / (b.seconds - a.seconds);
    if s == 0.0 {
        return Some(a.world_from_body);
    }
    Some(interpolate(&a.world_from_body, &b.world_from_body, s))
}

/// The poses at `hz` frames a second from the first stamp, up to the last (never past it), by
/// [`pose_at`]. Frame `k` is at the first stamp plus `k / hz` seconds; its stamp is written in
/// the file's unit: EuRoC's integer nanoseconds, others' seconds with six decimals.
pub fn resample(poses: &[Pose], format: TrajectoryFormat, hz: f64) -> Result<Vec<Pose>, String> {
    if !(hz.is_finite() && hz > 0.0) {
        return Err(format!("the frame rate {hz} Hz is not a positive number"));
    }
    let (Some(first), Some(last)) = (poses.first(), poses.last()) else {
        return Ok(Vec::new());
    };
    // Frames whose times reach the last stamp, allowing for the rounding of k / hz.
    let span = (last.seconds - first.seconds) * hz;
    let count = (span * (1.0 + 1e-12)).floor() + 1.0;
    if count > MAX_FRAMES as f64 {
        return Err(format!(
            "{count} frames at {hz} Hz over {:.3} s: at most {MAX_FRAMES}",
            last.seconds - first.seconds
        ));
    }
    let first_ns: Option<u128> = (format == TrajectoryFormat::Euroc)
        .then(|| first.stamp.parse().ok())
        .flatten();
    (0..count as usize)
        .map(|k| {
            let offset = k as f64 / hz;
            let seconds = (first.seconds + offset).min(last.seconds);
            let stamp = match first_ns {
                Some(ns) => (ns + (offset * 1e9).round() as u128).to_string(),
                None => format!("{seconds:.6}"),
            };
            let world_from_body =
                pose_at(poses, seconds).ok_or_else(|| format!("no pose at {seconds} s"))?;
            Ok(Pose {
                stamp,
                seconds,
                world_from_body,
            })
        })
        .collect()
}

/// A time stamp's text, kept for file names: digits with at most one decimal point.
fn stamp_text(field: &str) -> Result<String, String> {
    let digits = field.chars().filter(char::is_ascii_digit).count();
    let points = field.chars().filter(|&c| c == '.').count();
    if digits == 0 || points > 1 || digits + points != field.len() {
        return Err(format!(
            "the time stamp {field:?} is not written as plain digits (e.g. 1305031102.175304)"
        ));
    }
    Ok(field.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same two poses written in each format read back the same, with the formats'
    /// quaternion orders and time units.
    #[test]
    fn the_three_formats_give_the_same_poses() {
        // 90° about z (x to y), then 180° about x.
        let tum = "# timestamp tx ty tz qx qy qz qw\n\
                   1.5 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n\
                   \n\
                   1.6 -1 0 0.5 1 0 0 0\n";
        let euroc = "#timestamp [ns],p_x,p_y,p_z,q_w,q_x,q_y,q_z,v_x\n\
                     1500000000,1,2,3,0.7071067811865476,0,0,0.7071067811865476,9\n\
                     1600000000,-1,0,0.5,0,1,0,0,9\n";
        let kitti = "0 -1 0 1 1 0 0 2 0 0 1 3\n1 0 0 -1 0 -1 0 0 0 0 -1 0.5\n";
        for (text, format) in [
            (tum, TrajectoryFormat::Tum),
            (euroc, TrajectoryFormat::Euroc),
            (kitti, TrajectoryFormat::Kitti),
        ] {
            assert_eq!(TrajectoryFormat::detect(text), Some(format));
            let poses = parse(text, format, 10.0).unwrap();
            assert_eq!(poses.len(), 2, "{format:?}");
            let a = poses[0].world_from_body;
            assert!(a.translation.abs_diff_eq(DVec3::new(1.0, 2.0, 3.0), 0.0));
            assert!(a.transform_vector3(DVec3::X).abs_diff_eq(DVec3::Y, 1e-15));
            let b = poses[1].world_from_body;
            assert!(b.transform_vector3(DVec3::Y).abs_diff_eq(-DVec3::Y, 1e-15));
            assert!(b.transform_vector3(DVec3::Z).abs_diff_eq(-DVec3::Z, 1e-15));
        }
        let tum = parse(tum, TrajectoryFormat::Tum, 1.0).unwrap();
        assert_eq!((tum[0].stamp.as_str(), tum[0].seconds), ("1.5", 1.5));
        let euroc = parse(euroc, TrajectoryFormat::Euroc, 1.0).unwrap();
        assert_eq!(euroc[1].stamp, "1600000000");
        assert!((euroc[1].seconds - 1.6).abs() < 1e-15);
        let kitti = parse(kitti, TrajectoryFormat::Kitti, 10.0).unwrap();
        assert_eq!(kitti[1].stamp, "0.100000");
    }

    /// Bad lines are refused with their line number and what is wrong.
    #[test]
    fn bad_lines_name_their_line() {
        let cases = [
            (
                "0 0 0 0 0 0 0 1\n0 0 0\n",
                TrajectoryFormat::Tum,
                "line 2: 3 fields",
            ),
            (
                "0 0 0 0 0 0 0 2\n",
                TrajectoryFormat::Tum,
                "line 1: the quaternion",
            ),
            (
                "# c\n1e9 0 0 0 0 0 0 1\n",
                TrajectoryFormat::Tum,
                "line 2: the time stamp",
            ),
            (
                "0 0 0 nan 0 0 0 1\n",
                TrajectoryFormat::Tum,
                "\"nan\" is not a finite",
            ),
            (
                "1 0 0 0 0 1 0 0 0 0 -1 0\n",
                TrajectoryFormat::Kitti,
                "determinant",
            ),
            (
                "1,0,0\n",
                TrajectoryFormat::Euroc,
                "3 fields; a euroc pose has 8 or more",
            ),
            (
                "# stamps\n1.5 0 0 0 0 0 0 1\n\n1.50 0 0 0 0 0 0 1\n",
                TrajectoryFormat::Tum,
                "line 4: the time stamp 1.50 repeats line 2's 1.5; a trajectory's stamps must \
                 increase",
            ),
            (
                "20,0,0,0,1,0,0,0\n30,0,0,0,1,0,0,0\n25,0,0,0,1,0,0,0\n",
                TrajectoryFormat::Euroc,
                "line 3: the time stamp 25 comes before line 2's 30",
            ),
        ];
        for (text, format, wanted) in cases {
            let error = parse(text, format, 10.0).unwrap_err();
            assert!(error.contains(wanted), "{error:?} lacks {wanted:?}");
        }
        assert!(
            parse("", TrajectoryFormat::Kitti, 0.0)
                .unwrap_err()
                .contains("frame rate")
        );
    }

    /// Between stamps the pose moves on: halfway between a pose and one turned 90° about z and
    /// moved by (2, 0, 0), it is turned 45° and moved by (1, 0, 0); at the stamps it is exactly
    /// theirs; outside them there is none. A turn written with the other sign of quaternion
    /// takes the short way.
    #[test]
    fn poses_between_stamps_are_interpolated_and_never_extrapolated() {
        let tum = "1.0 0 0 0 0 0 0 1\n\
                   2.0 2 0 0 0 0 0.7071067811865476 0.7071067811865476\n\
                   3.0 2 0 0 0 0 -0.7071067811865476 -0.7071067811865476\n";
        let poses = parse(tum, TrajectoryFormat::Tum, 1.0).unwrap();
        for p in &poses {
            assert_eq!(pose_at(&poses, p.seconds), Some(p.world_from_body));
        }
        let half = pose_at(&poses, 1.5).unwrap();
        assert!(half.translation.abs_diff_eq(DVec3::X, 1e-15));
        let turned = half.transform_vector3(DVec3::X);
        let eighth = std::f64::consts::FRAC_PI_4;
        assert!(turned.abs_diff_eq(DVec3::new(eighth.cos(), eighth.sin(), 0.0), 1e-15));
        // The same rotation written as -q: no turn between the second and third stamps.
        let still = pose_at(&poses, 2.5).unwrap();
        assert!(still.abs_diff_eq(poses[1].world_from_body, 1e-15));
        assert_eq!(pose_at(&poses, 0.999), None);
        assert_eq!(pose_at(&poses, 3.001), None);
    }

    /// Resampled at 4 Hz, two seconds of poses give nine frames, a quarter second apart, the
    /// last at the last stamp and none past it; stamps keep the file's unit (EuRoC's integer
    /// nanoseconds, counted from its first stamp exactly).
    #[test]
    fn resampling_makes_frames_at_the_rate_up_to_the_last_stamp() {
        let euroc = "1403636579763555584,0,0,0,1,0,0,0\n\
                     1403636581763555584,4,0,0,1,0,0,0\n";
        let poses = parse(euroc, TrajectoryFormat::Euroc, 1.0).unwrap();
        let frames = resample(&poses, TrajectoryFormat::Euroc, 4.0).unwrap();
        assert_eq!(frames.len(), 9);
        assert_eq!(frames[1].stamp, "1403636580013555584");
        assert_eq!(frames[8].stamp, "1403636581763555584");
        for (k, f) in frames.iter().enumerate() {
            let x = f.world_from_body.translation.x;
            assert!((x - k as f64 * 0.5).abs() < 1e-5, "frame {k} at x = {x}");
        }
        // 3 Hz over 2 s: 0, 1/3, ..., 2 (seven frames), the last exactly the last stamp's.
        let tum = "10 0 0 0 0 0 0 1\n12 0 0 6 0 0 0 1\n";
        let poses = parse(tum, TrajectoryFormat::Tum, 1.0).unwrap();
        let frames = resample(&poses, TrajectoryFormat::Tum, 3.0).unwrap();
        let stamps: Vec<&str> = frames.iter().map(|f| f.stamp.as_str()).collect();
        assert_eq!(stamps[..2], ["10.000000", "10.333333"]);
        assert_eq!(stamps.last(), Some(&"12.000000"));
        assert_eq!(frames.len(), 7);
        // 2.5 Hz: 0, 0.4, ..., 2.0 s: six frames, none past the last stamp.
        assert_eq!(
            resample(&poses, TrajectoryFormat::Tum, 2.5).unwrap().len(),
            6
        );
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(
                resample(&poses, TrajectoryFormat::Tum, bad)
                    .unwrap_err()
                    .contains("Hz")
            );
        }
        assert!(
            resample(&poses, TrajectoryFormat::Tum, 1e7)
                .unwrap_err()
                .contains("at most")
        );
    }
}
