//! The readers of each calibration format: OpenCV's YAML and XML `FileStorage`, Kalibr's
//! camchain YAML, Basalt's JSON; each gives a [`Calibration`] or says what is wrong.

use super::calibration::Calibration;
use crate::lens::calibrated::{CalibratedLens, CalibratedModel, Intrinsics};
use crate::lens::camera::ImageSize;
use crate::lens::json::Json;
use yaml_rust2::{Yaml, YamlLoader};

/// A node of an OpenCV file, whatever the syntax: a scalar's text or a matrix's data.
pub(super) enum Node {
    Text(String),
    List(Vec<Option<f64>>),
}

pub(super) fn numbers(text: &str) -> Vec<Option<f64>> {
    text.split_whitespace().map(|t| t.parse().ok()).collect()
}

pub(crate) fn load_yaml(text: &str) -> Result<Yaml, String> {
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

pub(crate) fn yaml_number(node: &Yaml) -> Option<f64> {
    match node {
        Yaml::Real(text) | Yaml::String(text) => text.trim().parse().ok(),
        Yaml::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

pub(super) fn yaml_node(node: &Yaml) -> Option<Node> {
    match node {
        Yaml::Hash(_) => Some(Node::List(
            node["data"].as_vec()?.iter().map(yaml_number).collect(),
        )),
        Yaml::BadValue | Yaml::Null => None,
        other => Some(Node::Text(yaml_number(other)?.to_string())),
    }
}

/// An OpenCV calibration from its nodes by key.
pub(super) fn opencv(get: impl Fn(&str) -> Option<Node>) -> Result<Calibration, String> {
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
    Ok(Calibration {
        lens,
        size,
        line_delay: 0.0,
    })
}

pub(super) fn opencv_intrinsics(fx: f64, fy: f64, cx: f64, cy: f64) -> Intrinsics {
    Intrinsics {
        fx,
        fy,
        cx: cx + 0.5,
        cy: cy + 0.5,
    }
}

pub(super) fn image_size(width: f64, height: f64) -> Result<ImageSize, String> {
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
pub(super) fn kalibr(camera: &Yaml) -> Result<Calibration, String> {
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
    // A rolling shutter's line delay, seconds (Kalibr's rolling-shutter models write it).
    let line_delay = match &camera["line_delay"] {
        Yaml::BadValue | Yaml::Null => 0.0,
        v => match yaml_number(v) {
            Some(d) if d.is_finite() && d >= 0.0 => d,
            _ => {
                return Err(format!(
                    "line_delay {v:?} is not a number of seconds of 0 or more"
                ));
            }
        },
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
    Ok(Calibration {
        lens,
        size,
        line_delay,
    })
}

/// One camera of a Basalt calibration.
pub(super) fn basalt(camera: &Json, resolution: Option<&Json>) -> Result<Calibration, String> {
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
    Ok(Calibration {
        lens,
        size,
        line_delay: 0.0,
    })
}
