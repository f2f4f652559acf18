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
//!   `radtan`, `fov`, `none`), `intrinsics`, `distortion_coeffs` and `resolution`.
//! - **Basalt** calibration JSON: `value0.intrinsics[i].camera_type` (`kb4`, `ds`, `eucm`,
//!   `ucm`, `fov`, `pinhole`) with named `intrinsics`, and `value0.resolution[i]`.
//!
//! All three put the centre of the top-left pixel at (0, 0); this project puts it at
//! (0.5, 0.5), so the principal point is shifted by half a pixel on the way in and out.

use std::path::Path;

use glam::DAffine3;
use roxmltree::Document;
use yaml_rust2::{Yaml, YamlLoader};

use super::calibrated::{CalibratedLens, CalibratedModel, Intrinsics};
use super::camera::ImageSize;
use super::json::Json;
use crate::error::LensError;

/// One calibrated camera of a file: its lens and the image size it was calibrated at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// The lens (principal point in this project's convention).
    pub lens: CalibratedLens,
    /// The calibration's image size.
    pub size: ImageSize,
}

/// A calibration file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CalibFormat {
    /// OpenCV `cv::FileStorage` YAML.
    OpenCvYaml,
    /// OpenCV `cv::FileStorage` XML.
    OpenCvXml,
    /// Kalibr camchain YAML.
    Kalibr,
    /// Basalt calibration JSON.
    Basalt,
}

impl CalibFormat {
    /// Every format, with the names `fisheye lens convert --format` takes.
    pub const ALL: [(&'static str, CalibFormat); 4] = [
        ("opencv-yaml", Self::OpenCvYaml),
        ("opencv-xml", Self::OpenCvXml),
        ("kalibr", Self::Kalibr),
        ("basalt", Self::Basalt),
    ];

    /// The format's name.
    pub fn name(&self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, f)| f == self)
            .map_or("", |(n, _)| n)
    }

    /// The format a file's text is in: XML by its first tag, JSON by its first brace, and
    /// YAML by its keys (`camera_matrix`: OpenCV, `camera_model`: Kalibr).
    pub fn detect(text: &str) -> Option<Self> {
        let start = text.trim_start();
        if start.starts_with('<') {
            Some(Self::OpenCvXml)
        } else if start.starts_with('{') {
            Some(Self::Basalt)
        } else if text.contains("camera_matrix") {
            Some(Self::OpenCvYaml)
        } else if text.contains("camera_model") {
            Some(Self::Kalibr)
        } else {
            None
        }
    }
}

/// Reads every camera of a calibration file (format detected from its content).
pub fn read(path: &Path) -> Result<Vec<Calibration>, LensError> {
    let (text, format) = read_text(path)?;
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
    let bad = bad_file(path);
    let bytes = crate::input::read(path, crate::input::InputKind::Calibration)
        .map_err(|e| bad(format!("cannot read it: {e}")))?;
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

/// A node of an OpenCV file, whatever the syntax: a scalar's text or a matrix's data.
enum Node {
    Text(String),
    List(Vec<Option<f64>>),
}

/// A finite number as calibration files write it: the shortest digits that read back to the
/// same f64 (Rust's `{:e}`), with a decimal point and a signed exponent (`2.3e+2`,
/// `1.0e-5`), the form every reader takes as a float: YAML 1.1 (PyYAML, so Kalibr) reads
/// `2.3e2` as a string, as it needs both; JSON and OpenCV take either.
fn float_text(x: f64) -> String {
    let text = format!("{x:e}");
    let (mantissa, exponent) = text.split_once('e').expect("{:e} has an exponent");
    let point = if mantissa.contains('.') { "" } else { ".0" };
    let sign = if exponent.starts_with('-') { "" } else { "+" };
    format!("{mantissa}{point}e{sign}{exponent}")
}

fn numbers(text: &str) -> Vec<Option<f64>> {
    text.split_whitespace().map(|t| t.parse().ok()).collect()
}

fn load_yaml(text: &str) -> Result<Yaml, String> {
    let docs = YamlLoader::load_from_str(text).map_err(|e| {
        let m = e.marker();
        format!(
            "not valid YAML at line {}, column {}: {}",
            m.line(),
            m.col() + 1,
            e.info()
        )
    })?;
    docs.into_iter()
        .next()
        .ok_or_else(|| "the file is empty".into())
}

fn yaml_number(node: &Yaml) -> Option<f64> {
    match node {
        Yaml::Real(text) | Yaml::String(text) => text.trim().parse().ok(),
        Yaml::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

fn yaml_node(node: &Yaml) -> Option<Node> {
    match node {
        Yaml::Hash(_) => Some(Node::List(
            node["data"].as_vec()?.iter().map(yaml_number).collect(),
        )),
        Yaml::BadValue | Yaml::Null => None,
        other => Some(Node::Text(yaml_number(other)?.to_string())),
    }
}

/// An OpenCV calibration from its nodes by key.
fn opencv(get: impl Fn(&str) -> Option<Node>) -> Result<Calibration, String> {
    let scalar = |key: &str| -> Result<f64, String> {
        match get(key) {
            Some(Node::Text(t)) => t
                .parse()
                .map_err(|_| format!("{key} = {t:?} is not a number")),
            Some(Node::List(_)) => Err(format!("{key} should be a number, not a matrix")),
            None => Err(format!("{key} is missing")),
        }
    };
    let list = |key: &str| -> Result<Vec<f64>, String> {
        match get(key) {
            Some(Node::List(v)) => v
                .into_iter()
                .map(|x| x.ok_or_else(|| format!("{key} holds something that is not a number")))
                .collect(),
            _ => Err(format!("{key} is missing (an opencv-matrix)")),
        }
    };
    let size = image_size(scalar("image_width")?, scalar("image_height")?)?;
    let fisheye = get("fisheye_model").is_some() && scalar("fisheye_model")? != 0.0;
    let k = list("camera_matrix")?;
    if k.len() != 9 {
        return Err(format!("camera_matrix has {} entries, not 9", k.len()));
    }
    if k[1] != 0.0 || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0 {
        return Err("camera_matrix must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)".into());
    }
    let intrinsics = opencv_intrinsics(k[0], k[4], k[2], k[5]);
    let d = list("distortion_coefficients")?;
    let model = if fisheye {
        let [k1, k2, k3, k4] = d[..] else {
            return Err(format!(
                "a cv::fisheye calibration has 4 distortion_coefficients, not {}",
                d.len()
            ));
        };
        CalibratedModel::KannalaBrandt {
            k: [k1, k2, k3, k4],
        }
    } else {
        if !matches!(d.len(), 4 | 5 | 8 | 12 | 14) {
            return Err(format!(
                "distortion_coefficients has {} entries (OpenCV writes 4, 5, 8, 12 or 14)",
                d.len()
            ));
        }
        if d.iter().skip(5).any(|&c| c != 0.0) {
            return Err(
                "rational (k4-k6), thin-prism (s1-s4) and tilt coefficients are not supported"
                    .into(),
            );
        }
        CalibratedModel::RadTan {
            k: [d[0], d[1], d.get(4).copied().unwrap_or(0.0)],
            p: [d[2], d[3]],
        }
    };
    let lens = CalibratedLens::new(model, intrinsics).map_err(|e| e.to_string())?;
    Ok(Calibration { lens, size })
}

fn opencv_intrinsics(fx: f64, fy: f64, cx: f64, cy: f64) -> Intrinsics {
    Intrinsics {
        fx,
        fy,
        cx: cx + 0.5,
        cy: cy + 0.5,
    }
}

fn image_size(width: f64, height: f64) -> Result<ImageSize, String> {
    let side = |v: f64, name: &str| {
        if v.fract() == 0.0 && v >= 1.0 && v <= f64::from(u32::MAX) {
            Ok(v as u32)
        } else {
            Err(format!(
                "the image {name} {v} is not a positive whole number"
            ))
        }
    };
    ImageSize::new(side(width, "width")?, side(height, "height")?).map_err(|e| e.to_string())
}

/// One camera of a Kalibr camchain.
fn kalibr(camera: &Yaml) -> Result<Calibration, String> {
    let text = |key: &str| {
        camera[key]
            .as_str()
            .ok_or_else(|| format!("{key} is missing"))
    };
    let list = |key: &str| -> Result<Vec<f64>, String> {
        camera[key]
            .as_vec()
            .ok_or_else(|| format!("{key} is missing (a list)"))?
            .iter()
            .map(|v| yaml_number(v).ok_or_else(|| format!("{key} holds a non-number")))
            .collect()
    };
    let resolution = list("resolution")?;
    let [w, h] = resolution[..] else {
        return Err("resolution should be [width, height]".into());
    };
    let size = image_size(w, h)?;
    let camera_model = text("camera_model")?;
    let distortion = camera["distortion_model"].as_str().unwrap_or("none");
    let i = list("intrinsics")?;
    let d = if distortion == "none" {
        Vec::new()
    } else {
        list("distortion_coeffs")?
    };
    let expect = |n: usize, what: &str, v: &[f64]| {
        if v.len() == n {
            Ok(())
        } else {
            Err(format!("{what} should have {n} values, not {}", v.len()))
        }
    };
    let (model, intrinsics) = match (camera_model, distortion) {
        ("pinhole", _) => {
            expect(4, "pinhole intrinsics [fu, fv, pu, pv]", &i)?;
            let intr = opencv_intrinsics(i[0], i[1], i[2], i[3]);
            let model = match distortion {
                "equidistant" => {
                    expect(4, "equidistant distortion_coeffs", &d)?;
                    CalibratedModel::KannalaBrandt {
                        k: [d[0], d[1], d[2], d[3]],
                    }
                }
                "radtan" => {
                    expect(4, "radtan distortion_coeffs", &d)?;
                    CalibratedModel::RadTan {
                        k: [d[0], d[1], 0.0],
                        p: [d[2], d[3]],
                    }
                }
                "fov" => {
                    expect(1, "fov distortion_coeffs", &d)?;
                    CalibratedModel::Fov { w: d[0] }
                }
                "none" => CalibratedModel::RadTan {
                    k: [0.0; 3],
                    p: [0.0; 2],
                },
                other => return Err(format!("unknown distortion_model {other:?}")),
            };
            (model, intr)
        }
        ("omni", "none") => {
            expect(5, "omni intrinsics [xi, fu, fv, pu, pv]", &i)?;
            let xi = i[0];
            if !(xi.is_finite() && xi >= 0.0) {
                return Err(format!("omni xi = {xi} must be ≥ 0"));
            }
            // Mei's ξ form to the α form: α = ξ/(1+ξ), f = γ/(1+ξ).
            let intr = opencv_intrinsics(i[1] / (1.0 + xi), i[2] / (1.0 + xi), i[3], i[4]);
            (
                CalibratedModel::Unified {
                    alpha: xi / (1.0 + xi),
                },
                intr,
            )
        }
        ("ds", "none") => {
            expect(6, "ds intrinsics [xi, alpha, fu, fv, pu, pv]", &i)?;
            (
                CalibratedModel::DoubleSphere {
                    xi: i[0],
                    alpha: i[1],
                },
                opencv_intrinsics(i[2], i[3], i[4], i[5]),
            )
        }
        ("eucm", "none") => {
            expect(6, "eucm intrinsics [alpha, beta, fu, fv, pu, pv]", &i)?;
            (
                CalibratedModel::ExtendedUnified {
                    alpha: i[0],
                    beta: i[1],
                },
                opencv_intrinsics(i[2], i[3], i[4], i[5]),
            )
        }
        ("omni" | "ds" | "eucm", other) => {
            return Err(format!(
                "{camera_model} with distortion_model {other:?} is not supported (only none)"
            ));
        }
        (other, _) => return Err(format!("unknown camera_model {other:?}")),
    };
    let lens = CalibratedLens::new(model, intrinsics).map_err(|e| e.to_string())?;
    Ok(Calibration { lens, size })
}

/// One camera of a Basalt calibration.
fn basalt(camera: &Json, resolution: Option<&Json>) -> Result<Calibration, String> {
    let kind = camera["camera_type"]
        .as_str()
        .ok_or("camera_type is missing")?;
    let values = &camera["intrinsics"];
    let get = |key: &str| {
        values[key]
            .as_f64()
            .ok_or_else(|| format!("intrinsics.{key} is missing"))
    };
    let size = match resolution.and_then(Json::as_array) {
        Some([w, h]) => image_size(
            w.as_f64().ok_or("resolution width is not a number")?,
            h.as_f64().ok_or("resolution height is not a number")?,
        )?,
        _ => return Err("resolution should be [width, height]".into()),
    };
    let intrinsics = opencv_intrinsics(get("fx")?, get("fy")?, get("cx")?, get("cy")?);
    let model = match kind {
        "kb4" => CalibratedModel::KannalaBrandt {
            k: [get("k1")?, get("k2")?, get("k3")?, get("k4")?],
        },
        "ds" => CalibratedModel::DoubleSphere {
            xi: get("xi")?,
            alpha: get("alpha")?,
        },
        "eucm" => CalibratedModel::ExtendedUnified {
            alpha: get("alpha")?,
            beta: get("beta")?,
        },
        "ucm" => CalibratedModel::Unified {
            alpha: get("alpha")?,
        },
        "fov" => CalibratedModel::Fov { w: get("w")? },
        "pinhole" => CalibratedModel::RadTan {
            k: [0.0; 3],
            p: [0.0; 2],
        },
        other => return Err(format!("camera_type {other:?} is not supported")),
    };
    let lens = CalibratedLens::new(model, intrinsics).map_err(|e| e.to_string())?;
    Ok(Calibration { lens, size })
}

/// Writes a calibration in a format; errors when the format cannot express the model or a
/// field-of-view limit (which none of these formats has).
pub fn write(calibration: &Calibration, format: CalibFormat) -> Result<String, LensError> {
    let lens = &calibration.lens;
    let model = lens.model();
    let unsupported = || LensError::Unsupported {
        format: format.name(),
        model: model.name(),
    };
    if lens.max_fov().is_some() {
        return Err(LensError::Unsupported {
            format: format.name(),
            model: "a lens with a field-of-view limit (fov=)",
        });
    }
    let i = lens.intrinsics();
    let (fx, fy, cx, cy) = (i.fx, i.fy, i.cx - 0.5, i.cy - 0.5);
    let (w, h) = (calibration.size.width, calibration.size.height);
    let join = |v: &[f64]| v.iter().map(|&x| float_text(x)).collect::<Vec<_>>();
    match format {
        CalibFormat::OpenCvYaml | CalibFormat::OpenCvXml => {
            let (fisheye, d) = match model {
                CalibratedModel::KannalaBrandt { k } => (1, k.to_vec()),
                CalibratedModel::RadTan { k, p } => (0, vec![k[0], k[1], p[0], p[1], k[2]]),
                _ => return Err(unsupported()),
            };
            let matrix = [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0];
            Ok(if format == CalibFormat::OpenCvYaml {
                let node = |name: &str, rows: usize, cols: usize, data: &[f64]| {
                    format!(
                        "{name}: !!opencv-matrix\n   rows: {rows}\n   cols: {cols}\n   dt: d\n   \
                         data: [ {} ]\n",
                        join(data).join(", ")
                    )
                };
                format!(
                    "%YAML:1.0\n---\nimage_width: {w}\nimage_height: {h}\nfisheye_model: \
                     {fisheye}\n{}{}",
                    node("camera_matrix", 3, 3, &matrix),
                    node("distortion_coefficients", d.len(), 1, &d)
                )
            } else {
                let node = |name: &str, rows: usize, cols: usize, data: &[f64]| {
                    format!(
                        "<{name} type_id=\"opencv-matrix\">\n  <rows>{rows}</rows>\n  \
                         <cols>{cols}</cols>\n  <dt>d</dt>\n  <data>\n    {}</data></{name}>\n",
                        join(data).join(" ")
                    )
                };
                format!(
                    "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>{w}</image_width>\n\
                     <image_height>{h}</image_height>\n<fisheye_model>{fisheye}</fisheye_model>\n\
                     {}{}</opencv_storage>\n",
                    node("camera_matrix", 3, 3, &matrix),
                    node("distortion_coefficients", d.len(), 1, &d)
                )
            })
        }
        CalibFormat::Kalibr => {
            let (camera_model, intrinsics, distortion, coeffs) = match model {
                CalibratedModel::KannalaBrandt { k } => {
                    ("pinhole", vec![fx, fy, cx, cy], "equidistant", k.to_vec())
                }
                CalibratedModel::RadTan { k, p } if k[2] == 0.0 => (
                    "pinhole",
                    vec![fx, fy, cx, cy],
                    "radtan",
                    vec![k[0], k[1], p[0], p[1]],
                ),
                CalibratedModel::Fov { w } => ("pinhole", vec![fx, fy, cx, cy], "fov", vec![w]),
                CalibratedModel::Unified { alpha } if alpha < 1.0 => {
                    // α form to Mei's ξ form: ξ = α/(1-α), γ = f(1+ξ).
                    let xi = alpha / (1.0 - alpha);
                    let s = 1.0 + xi;
                    ("omni", vec![xi, fx * s, fy * s, cx, cy], "none", vec![])
                }
                CalibratedModel::DoubleSphere { xi, alpha } => {
                    ("ds", vec![xi, alpha, fx, fy, cx, cy], "none", vec![])
                }
                CalibratedModel::ExtendedUnified { alpha, beta } => {
                    ("eucm", vec![alpha, beta, fx, fy, cx, cy], "none", vec![])
                }
                _ => return Err(unsupported()),
            };
            Ok(format!(
                "cam0:\n  camera_model: {camera_model}\n  intrinsics: [{}]\n  distortion_model: \
                 {distortion}\n  distortion_coeffs: [{}]\n  resolution: [{w}, {h}]\n",
                join(&intrinsics).join(", "),
                join(&coeffs).join(", ")
            ))
        }
        CalibFormat::Basalt => {
            let (kind, extra): (&str, Vec<(&str, f64)>) = match model {
                CalibratedModel::KannalaBrandt { k } => (
                    "kb4",
                    vec![("k1", k[0]), ("k2", k[1]), ("k3", k[2]), ("k4", k[3])],
                ),
                CalibratedModel::DoubleSphere { xi, alpha } => {
                    ("ds", vec![("xi", xi), ("alpha", alpha)])
                }
                CalibratedModel::ExtendedUnified { alpha, beta } => {
                    ("eucm", vec![("alpha", alpha), ("beta", beta)])
                }
                CalibratedModel::Unified { alpha } => ("ucm", vec![("alpha", alpha)]),
                CalibratedModel::Fov { w } => ("fov", vec![("w", w)]),
                CalibratedModel::RadTan { k, p } if k == [0.0; 3] && p == [0.0; 2] => {
                    ("pinhole", vec![])
                }
                _ => return Err(unsupported()),
            };
            let values: Vec<String> = [("fx", fx), ("fy", fy), ("cx", cx), ("cy", cy)]
                .into_iter()
                .chain(extra)
                .map(|(key, value)| format!("          \"{key}\": {}", float_text(value)))
                .collect();
            Ok(format!(
                "{{\n  \"value0\": {{\n    \"intrinsics\": [\n      {{\n        \"camera_type\": \
                 \"{kind}\",\n        \"intrinsics\": {{\n{}\n        }}\n      }}\n    ],\n    \
                 \"resolution\": [\n      [\n        {w},\n        {h}\n      ]\n    ]\n  }}\n}}\n",
                values.join(",\n")
            ))
        }
    }
}
