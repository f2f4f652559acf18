//! Writing a calibration in OpenCV's, Kalibr's or Basalt's format.

use super::calibration::{CalibFormat, Calibration};
use crate::error::LensError;
use crate::lens::calibrated::CalibratedModel;

/// A finite number as calibration files write it: the shortest digits that read back to the
/// same f64 (Rust's `{:e}`), with a decimal point and a signed exponent (`2.3e+2`,
/// `1.0e-5`), the form every reader takes as a float: YAML 1.1 (PyYAML, so Kalibr) reads
/// `2.3e2` as a string, as it needs both; JSON and OpenCV take either.
pub fn float_text(x: f64) -> String {
    let text = format!("{x:e}");
    let (mantissa, exponent) = text.split_once('e').expect("{:e} has an exponent");
    let point = if mantissa.contains('.') { "" } else { ".0" };
    let sign = if exponent.starts_with('-') { "" } else { "+" };
    format!("{mantissa}{point}e{sign}{exponent}")
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
    if calibration.line_delay > 0.0 && format != CalibFormat::Kalibr {
        return Err(LensError::Unsupported {
            format: format.name(),
            model: "a rolling shutter (line_delay: only Kalibr camchains hold one)",
        });
    }
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
            let line_delay = match calibration.line_delay {
                d if d > 0.0 => format!("  line_delay: {}\n", float_text(d)),
                _ => String::new(),
            };
            Ok(format!(
                "cam0:\n  camera_model: {camera_model}\n  intrinsics: [{}]\n  distortion_model: \
                 {distortion}\n  distortion_coeffs: [{}]\n  resolution: [{w}, {h}]\n{line_delay}",
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
