//! Calibration files: read and write the camera intrinsics of OpenCV, Kalibr and Basalt.
//!
//! - **OpenCV** `cv::FileStorage` YAML or XML with the keys of OpenCV's camera-calibration
//!   sample (`samples/cpp/calibration.cpp`): `image_width`, `image_height`, `fisheye_model`
//!   (1: `cv::fisheye`, i.e. Kannala–Brandt with `distortion_coefficients` k1..k4; otherwise
//!   the pinhole radial-tangential model, k1, k2, p1, p2[, k3]), `camera_matrix` (3×3, no
//!   skew) and `distortion_coefficients`, as `opencv-matrix` nodes.
//! - **Kalibr** camchain YAML: per camera `camera_model` (`pinhole`, `omni` (Mei's unified
//!   model, intrinsics `[xi, fu, fv, pu, pv]`), `ds` (`[xi, alpha, fu, fv, pu, pv]`), `eucm`
//!   (`[alpha, beta, fu, fv, pu, pv]`)), `distortion_model` (`equidistant` (Kannala–Brandt),
//!   `radtan`, `fov`, `none`), `intrinsics`, `distortion_coeffs` and `resolution`, and a
//!   rolling shutter's `line_delay` (seconds) where it has one.
//! - **Basalt** calibration JSON: `value0.intrinsics[i].camera_type` (`kb4`, `ds`, `eucm`,
//!   `ucm`, `fov`, `pinhole`) with named `intrinsics`, and `value0.resolution[i]`.
//!
//! All three put the centre of the top-left pixel at (0, 0); this project puts it at
//! (0.5, 0.5), so the principal point is shifted by half a pixel on the way in and out.

mod calibration;
mod formats;
mod write;

pub use calibration::{CalibFormat, Calibration};
use formats::*;
/// YAML as the calibration readers parse it, for the other Kalibr files (`imu.yaml`).
pub(crate) use formats::{load_yaml, yaml_number};
pub use write::{float_text, write};

use std::path::Path;

use glam::DAffine3;
use roxmltree::Document;
use yaml_rust2::Yaml;

use super::json::Json;
use crate::error::LensError;

/// Reads every camera of a calibration file (format detected from its content).
pub fn read(path: &Path) -> Result<Vec<Calibration>, LensError> {
    let bytes = crate::input::read(path, crate::input::InputKind::Calibration)
        .map_err(|e| bad_file(path)(format!("cannot read it: {e}")))?;
    read_from(path, bytes)
}

/// As [`read`], from the file's contents (`path` names it in errors): for a caller that has
/// the bytes, as a web page does.
pub fn read_from(path: &Path, bytes: Vec<u8>) -> Result<Vec<Calibration>, LensError> {
    let (text, format) = text_of(path, bytes)?;
    let cameras = parse(&text, format).map_err(bad_file(path))?;
    if cameras.is_empty() {
        return Err(bad_file(path)("it holds no camera".into()));
    }
    Ok(cameras)
}

/// A camera of a rig: its calibration and where it sits on the rig's body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigCamera {
    /// The camera's lens and image size.
    pub calibration: Calibration,
    /// `T_body_camera`: camera coordinates (OpenCV's frame) to the rig body's.
    pub body_from_camera: DAffine3,
}

/// Reads every camera of a calibration file with its pose on the rig:
/// - Kalibr: the body is the IMU where `cam0` has `T_cam_imu` (then a camera's own `T_cam_imu`
///   places it), else `cam0`; a camera without `T_cam_imu` is placed by `T_cn_cnm1` from the
///   one before it.
/// - Basalt: `value0.T_imu_cam` (`px, py, pz, qx, qy, qz, qw` per camera); the body is the IMU.
/// - OpenCV: one camera, the body itself.
///
/// A file with several cameras and no extrinsics is refused, naming what is missing.
pub fn read_rig(path: &Path) -> Result<Vec<RigCamera>, LensError> {
    let (text, format) = read_text(path)?;
    let rig = parse_rig(&text, format).map_err(bad_file(path))?;
    if rig.is_empty() {
        return Err(bad_file(path)("it holds no camera".into()));
    }
    Ok(rig)
}

/// Parses a rig's text in a given format (see [`read_rig`]); the error says what is wrong.
pub fn parse_rig(text: &str, format: CalibFormat) -> Result<Vec<RigCamera>, String> {
    let cameras = parse(text, format)?;
    let poses = extrinsics(text, format, cameras.len())?;
    Ok(cameras
        .into_iter()
        .zip(poses)
        .map(|(calibration, body_from_camera)| RigCamera {
            calibration,
            body_from_camera,
        })
        .collect())
}

fn bad_file(path: &Path) -> impl Fn(String) -> LensError {
    let path = path.display().to_string();
    move |reason| LensError::Calibration {
        path: path.clone(),
        reason,
    }
}

/// A calibration file's text and format.
fn read_text(path: &Path) -> Result<(String, CalibFormat), LensError> {
    let bytes = crate::input::read(path, crate::input::InputKind::Calibration)
        .map_err(|e| bad_file(path)(format!("cannot read it: {e}")))?;
    text_of(path, bytes)
}

/// A calibration file's contents as text, and its format.
fn text_of(path: &Path, bytes: Vec<u8>) -> Result<(String, CalibFormat), LensError> {
    let bad = bad_file(path);
    let text = String::from_utf8(bytes).map_err(|e| {
        bad(format!(
            "not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ))
    })?;
    let format = CalibFormat::detect(&text).ok_or_else(|| {
        bad(
            "not a calibration this tool reads (OpenCV YAML/XML with camera_matrix, a Kalibr \
             camchain with camera_model, or Basalt JSON)"
                .into(),
        )
    })?;
    Ok((text, format))
}

/// `T_body_camera` of each of a file's `count` cameras (see [`read_rig`]).
fn extrinsics(text: &str, format: CalibFormat, count: usize) -> Result<Vec<DAffine3>, String> {
    let lone = || {
        if count == 1 {
            Ok(vec![DAffine3::IDENTITY])
        } else {
            Err(format!(
                "{count} cameras without extrinsics: a rig needs each camera's pose"
            ))
        }
    };
    match format {
        CalibFormat::OpenCvYaml | CalibFormat::OpenCvXml => lone(),
        CalibFormat::Kalibr => {
            let doc = load_yaml(text)?;
            let cameras = doc.as_hash().ok_or("expected a mapping of cameras")?;
            let matrix = |camera: &Yaml, key: &str| -> Result<Option<DAffine3>, String> {
                let Some(rows) = camera[key].as_vec() else {
                    return Ok(None);
                };
                let rows: Vec<Vec<f64>> = rows
                    .iter()
                    .map(|row| {
                        row.as_vec()
                            .ok_or(format!("{key} should be a list of rows"))?
                            .iter()
                            .map(|v| yaml_number(v).ok_or(format!("{key} holds a non-number")))
                            .collect()
                    })
                    .collect::<Result<_, _>>()?;
                crate::pose::rigid_from_rows(&rows)
                    .map(Some)
                    .map_err(|e| format!("{key}: {e}"))
            };
            let mut poses: Vec<DAffine3> = Vec::with_capacity(count);
            let mut imu_body = false;
            for (n, (name, camera)) in cameras.iter().enumerate() {
                let name = name.as_str().unwrap_or("?");
                let at = |e: String| format!("{name}: {e}");
                let to_imu = matrix(camera, "T_cam_imu").map_err(at)?;
                if n == 0 {
                    imu_body = to_imu.is_some();
                }
                let pose = match (to_imu.filter(|_| imu_body), poses.last()) {
                    (Some(cam_from_imu), _) => cam_from_imu.inverse(),
                    (None, None) => DAffine3::IDENTITY,
                    (None, Some(previous)) => match matrix(camera, "T_cn_cnm1").map_err(at)? {
                        Some(this_from_previous) => *previous * this_from_previous.inverse(),
                        None if count == 1 => DAffine3::IDENTITY,
                        None => {
                            return Err(at(format!(
                                "no T_cn_cnm1{}: a rig needs each camera's pose relative to \
                                 the one before it",
                                if imu_body { " or T_cam_imu" } else { "" }
                            )));
                        }
                    },
                };
                poses.push(pose);
            }
            Ok(poses)
        }
        CalibFormat::Basalt => {
            let doc = super::json::parse(text).map_err(|e| format!("not valid JSON: {e}"))?;
            let value = doc.get("value0").unwrap_or(&doc);
            let Some(list) = value.get("T_imu_cam").and_then(Json::as_array) else {
                return lone();
            };
            if list.len() != count {
                return Err(format!(
                    "value0.T_imu_cam has {} poses for {count} cameras",
                    list.len()
                ));
            }
            list.iter()
                .enumerate()
                .map(|(i, pose)| {
                    let get = |key: &str| {
                        pose[key]
                            .as_f64()
                            .ok_or_else(|| format!("T_imu_cam[{i}].{key} is missing"))
                    };
                    let rotation = crate::pose::rotation_from_quaternion(
                        get("qx")?,
                        get("qy")?,
                        get("qz")?,
                        get("qw")?,
                    )
                    .map_err(|e| format!("T_imu_cam[{i}]: {e}"))?;
                    let translation = glam::DVec3::new(get("px")?, get("py")?, get("pz")?);
                    Ok(crate::pose::rigid(rotation, translation))
                })
                .collect()
        }
    }
}

/// Parses a calibration's text in a given format; the error says what is wrong.
pub fn parse(text: &str, format: CalibFormat) -> Result<Vec<Calibration>, String> {
    match format {
        CalibFormat::OpenCvYaml => {
            // FileStorage writes a `%YAML:1.0` directive, which YAML 1.2 parsers refuse.
            let body: String = text
                .lines()
                .map(|l| if l.starts_with("%YAML") { "" } else { l })
                .collect::<Vec<_>>()
                .join("\n");
            let doc = load_yaml(&body)?;
            let get = |key: &str| yaml_node(&doc[key]);
            opencv(|key| get(key)).map(|c| vec![c])
        }
        CalibFormat::OpenCvXml => {
            let doc = Document::parse(text).map_err(|e| format!("not valid XML: {e}"))?;
            let root = doc.root_element();
            let get = |key: &str| {
                let node = root.children().find(|n| n.has_tag_name(key))?;
                Some(match node.children().find(|n| n.has_tag_name("data")) {
                    Some(data) => Node::List(numbers(data.text().unwrap_or(""))),
                    None => Node::Text(node.text().unwrap_or("").trim().to_string()),
                })
            };
            opencv(get).map(|c| vec![c])
        }
        CalibFormat::Kalibr => {
            let doc = load_yaml(text)?;
            let cameras = doc
                .as_hash()
                .ok_or("expected a mapping of cameras (cam0: ...)")?;
            cameras
                .iter()
                .map(|(name, camera)| {
                    let name = name.as_str().unwrap_or("?");
                    kalibr(camera).map_err(|e| format!("{name}: {e}"))
                })
                .collect()
        }
        CalibFormat::Basalt => {
            let doc = super::json::parse(text).map_err(|e| format!("not valid JSON: {e}"))?;
            let value = doc.get("value0").unwrap_or(&doc);
            let intrinsics = value["intrinsics"]
                .as_array()
                .ok_or("expected value0.intrinsics, an array of cameras")?;
            let resolutions = value["resolution"]
                .as_array()
                .ok_or("expected value0.resolution, an array of [width, height]")?;
            intrinsics
                .iter()
                .enumerate()
                .map(|(i, camera)| {
                    basalt(camera, resolutions.get(i)).map_err(|e| format!("camera {i}: {e}"))
                })
                .collect()
        }
    }
}
