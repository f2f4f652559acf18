//! A calibration as files hold it ([`Calibration`]: a lens and its image size) and the
//! formats they come in ([`CalibFormat`]).

use crate::lens::{CalibratedLens, ImageSize, LensCamera, Shutter};

/// One calibrated camera of a file: its lens and the image size it was calibrated at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// The lens (principal point in this project's convention).
    pub lens: CalibratedLens,
    /// The calibration's image size.
    pub size: ImageSize,
    /// Seconds between two rows' readouts of a rolling shutter (Kalibr's `line_delay`, which
    /// only its camchains hold); 0 for a global shutter.
    pub line_delay: f64,
}

impl Calibration {
    /// The camera it describes: its lens at its image size, with its rolling shutter's line
    /// delay (a global shutter where it has none).
    pub fn camera(&self) -> LensCamera {
        LensCamera::new(self.lens, self.size).with_shutter(Shutter {
            line_delay: self.line_delay,
            ..Shutter::GLOBAL
        })
    }
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
