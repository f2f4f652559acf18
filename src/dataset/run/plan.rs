//! The plan of a dataset (`plan.json`): everything it is, frame by frame, with each camera's
//! calibration in this project's and OpenCV's conventions.

use serde_json::{Value, json};

use super::{CAMCHAIN, Dataset};
use crate::dataset::between::FlowFile;
use crate::dataset::files::LAYOUT;
use crate::dataset::imu::IMU_FILES;
use crate::dataset::labels::LABEL_MAP;
use crate::error::Result;
use crate::lens::calib::{CalibFormat, Calibration, float_text};
use crate::lens::{CalibratedModel, Lens};
use crate::pose::rows;
use crate::trace::{ColourFile, Tone};

impl Dataset {
    /// The plan: everything the dataset is, frame by frame, as JSON (deterministic bytes).
    pub fn plan(&self) -> Result<String> {
        let cameras: Vec<Value> = (0..self.cameras.len())
            .map(|c| self.camera_json(c))
            .collect::<Result<_>>()?;
        let skipped = self.skipped()?;
        let frames: Vec<Value> = (0..self.poses.len())
            .map(|p| {
                let pose = &self.poses[p];
                let views: Vec<Value> = (0..self.cameras.len())
                    .map(|c| {
                        let files: serde_json::Map<String, Value> = self
                            .files(p, c)
                            .into_iter()
                            .filter(|_| skipped[p].is_none())
                            .map(|(what, file)| (what, Value::String(file)))
                            .collect();
                        json!({
                            "camera": Self::camera_name(c),
                            "T_scene_camera": rows(&self.scene_from_camera(p, c)),
                            "files": files,
                        })
                    })
                    .collect();
                let mut frame = json!({
                    "index": p,
                    "stamp": pose.stamp,
                    "seconds": pose.seconds,
                    "T_world_body": rows(&pose.world_from_body),
                    "views": views,
                });
                if let Some(why) = &skipped[p] {
                    frame["skipped"] = json!(why);
                }
                frame
            })
            .collect();
        let skipped_frames: Vec<usize> = (0..self.poses.len())
            .filter(|&p| skipped[p].is_some())
            .collect();
        let (file, display) = self.colour;
        let plan = json!({
            "layout": LAYOUT,
            "tool": format!("fisheye-rt {}", env!("CARGO_PKG_VERSION")),
            "scene": self.scene_name,
            "trajectory": {
                "file": self.trajectory.0.display().to_string(),
                "format": self.trajectory.1.name(),
                "frame_rate": self.trajectory.2,
                "poses": self.poses.len(),
            },
            "conventions": {
                "transforms": "T_a_b maps coordinates in frame b to frame a, as 4x4 row-major \
                               matrices; T_scene_camera = T_scene_world T_world_body T_body_rig \
                               T_rig_camera",
                "camera": "OpenCV: x right, y down, z forward",
                "pixels": "intrinsics put the top-left pixel's corner at (0, 0) (this \
                           project's convention); opencv.camera_matrix puts its centre there",
                "arrays": "range: metres to the first hit along the pixel centre's ray (0 where \
                           none); normal: world unit normal; id: scene triangle (4294967295 for \
                           none); direction: world unit ray; mask: 1 where the lens has a ray; \
                           depth: metres along the camera's z axis to that hit (negative behind \
                           the camera's plane, 0 where none); point: that hit in the camera's \
                           frame, metres (range times the pixel's camera-frame unit ray); \
                           spp: the rays the pixel's colour took (0 where adaptive sampling \
                           interpolated it from its neighbours, or the lens covers none of it)",
                "time": "a camera's shutter (cameras[].shutter): line v (the OpenCV row v read \
                         top to bottom, Kalibr's convention; other orders as readout says) is \
                         read at the frame's stamp + v line_delay, and exposed for \
                         exposure_time centred on that time; T_scene_camera is the pose at the \
                         stamp; the arrays follow each pixel's centre ray at its line's time. \
                         Frames whose readout or exposure reach past the trajectory's stamps \
                         are skipped (poses are never extrapolated) and say why",
                "flow": "flow: pixels (x right, y down) from each pixel's centre to where its \
                         centre ray's hit lands in the next frame (flow_backward: the previous), \
                         through the lens and the rolling shutter; NaN where it has no hit or \
                         does not land (.flo: 1e10; kitti: 0, blue 0). flow_valid: 1 where that \
                         frame sees the point there (its range at the nearest pixel within the \
                         spread of a pixel's footprint). scene_flow: metres, how the hit moves \
                         in the camera's frame by the next frame, NaN where none. A hit on a \
                         moving object moves with it. The last frame has no next (and the \
                         first no previous)",
                "objects": "moving objects (glTF animations, scene-file keys) are placed at \
                            scene time = a ray's time - the trajectory's first stamp; every ray \
                            sees them at its own time (rolling shutter, exposure)",
            },
            "T_scene_world": rows(&self.scene_from_world),
            "T_body_rig": rows(&self.body_from_rig),
            "render": {
                "method": "rt",
                "spp": self.options.spp,
                "sampling": self.options.sampling().to_string(),
                "filter": self.options.filter.name(),
                "max_depth": self.options.max_depth,
                "bvh": self.options.bvh.name(),
                "colour": match file {
                    ColourFile::Png8 => "8-bit sRGB PNG",
                    ColourFile::Png16 => "16-bit sRGB PNG",
                    ColourFile::ExrHalf => "half-float linear OpenEXR",
                    ColourFile::ExrFloat => "float linear OpenEXR",
                },
                "exposure": display.exposure,
                "tone": match display.tone {
                    Tone::Aces => "aces",
                    Tone::Clamp => "clamp",
                },
                "outputs": self.outputs.0.iter().map(|c| c.name())
                    .chain(self.labels.iter().map(|l| l.name()))
                    .chain(self.spp_map.then_some("spp"))
                    .chain(self.between.0.iter().map(|b| b.name()))
                    .collect::<Vec<_>>(),
                "flow_files": match self.between.1 {
                    FlowFile::Arrays => self.outputs.1.extension(),
                    FlowFile::Flo => "flo",
                    FlowFile::Kitti => "kitti png",
                },
                "arrays": self.outputs.1.extension(),
            },
            "cameras": cameras,
            "labels": (!self.labels.is_empty()).then_some(LABEL_MAP),
            "imu": self.imu.as_ref().map(|imu| {
                let (first, last) = imu.spline.span();
                json!({
                    "files": {"data": IMU_FILES[0], "noise_free": IMU_FILES[1]},
                    "layout": "EuRoC imu0/data.csv: timestamp [ns], angular rate (rad/s), \
                               specific force (m/s^2), in the IMU's frame: the body's",
                    "rate": imu.rate,
                    "noise": imu.noise.map(|n| json!({
                        "accelerometer_noise_density": n.accelerometer_noise_density,
                        "accelerometer_random_walk": n.accelerometer_random_walk,
                        "gyroscope_noise_density": n.gyroscope_noise_density,
                        "gyroscope_random_walk": n.gyroscope_random_walk,
                        "update_rate": n.update_rate,
                    })),
                    "seed": imu.seed,
                    "gravity": imu.gravity.to_array(),
                    "spline": {
                        "kind": "uniform cumulative cubic B-spline on SO(3) x R^3; the frames' \
                                 T_world_body follow it too",
                        "step": imu.spline.step(),
                        "span": [first, last],
                    },
                    "camchain": self.camchain().map(|_| CAMCHAIN),
                })
            }),
            "skipped_frames": skipped_frames,
            "frames": frames,
        });
        Ok(serde_json::to_string_pretty(&plan).expect("JSON values serialise") + "\n")
    }

    /// The rig as a Kalibr camchain on the IMU (the body): each camera's calibration (a
    /// classic lens as its calibrated equivalent) with `T_cam_imu` and a zero
    /// `timeshift_cam_imu`; `None` where a camera's model has no Kalibr form.
    pub(super) fn camchain(&self) -> Option<String> {
        let mut text = String::new();
        for c in 0..self.cameras.len() {
            let camera = self.lens_camera(c);
            let lens = match camera.lens {
                Lens::Calibrated(lens) => lens,
                Lens::Classic(_) => crate::lens::fit::calibrated_equivalent(&camera).ok()?.lens,
            };
            let calibration = Calibration {
                lens,
                size: camera.size,
                line_delay: camera.shutter.line_delay,
            };
            let one = crate::lens::calib::write(&calibration, CalibFormat::Kalibr).ok()?;
            let cam_imu = (self.body_from_rig * self.cameras[c].1).inverse();
            text += &one.replacen("cam0:", &format!("cam{c}:"), 1);
            text += "  T_cam_imu:\n";
            for row in rows(&cam_imu) {
                let row: Vec<String> = row.iter().map(|&v| float_text(v)).collect();
                text += &format!("  - [{}]\n", row.join(", "));
            }
            text += "  timeshift_cam_imu: 0.0\n";
        }
        Some(text)
    }

    /// A camera's calibration in the project's and OpenCV's conventions, and its rig pose.
    fn camera_json(&self, c: usize) -> Result<Value> {
        let camera = self.lens_camera(c);
        let (lens, equivalent) = match camera.lens {
            Lens::Calibrated(lens) => (lens, Value::Null),
            Lens::Classic(_) => {
                let e = crate::lens::fit::calibrated_equivalent(&camera)?;
                let note = json!({
                    "lens": camera.lens.to_string(),
                    "exact": e.exact,
                    "residual_px": e.residual_px,
                });
                (e.lens, note)
            }
        };
        let i = lens.intrinsics();
        let model = lens.model();
        let parameters: serde_json::Map<String, Value> = model
            .parameters()
            .into_iter()
            .map(|(k, v)| (k.to_string(), json!(v)))
            .collect();
        let (cv_model, distortion) = match model {
            CalibratedModel::KannalaBrandt { k } => (json!("cv::fisheye"), json!(k)),
            CalibratedModel::RadTan { k, p } => (
                json!("cv::calibrateCamera"),
                json!([k[0], k[1], p[0], p[1], k[2]]),
            ),
            _ => (Value::Null, Value::Null),
        };
        let (cx, cy) = (i.cx - 0.5, i.cy - 0.5);
        Ok(json!({
            "name": Self::camera_name(c),
            "width": camera.size.width,
            "height": camera.size.height,
            "lens": camera.lens.to_string(),
            "model": model.name(),
            "intrinsics": {"fx": i.fx, "fy": i.fy, "cx": i.cx, "cy": i.cy},
            "parameters": parameters,
            "max_fov_degrees": lens.max_fov().map(f64::to_degrees),
            "calibrated_equivalent_of": equivalent,
            "opencv": {
                "model": cv_model,
                "camera_matrix": [[i.fx, 0.0, cx], [0.0, i.fy, cy], [0.0, 0.0, 1.0]],
                "distortion_coefficients": distortion,
            },
            "T_rig_camera": rows(&self.cameras[c].1),
            "shutter": {
                "line_delay": camera.shutter.line_delay,
                "exposure_time": camera.shutter.exposure,
                "readout": camera.shutter.readout.name(),
            },
        }))
    }
}
