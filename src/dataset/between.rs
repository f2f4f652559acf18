//! Ground truth between a frame and its neighbours, as `dataset render --outputs` names it
//! ([`Between`]): optical flow to the next frame and from the previous one with their
//! covisibility masks, and scene flow, written in the arrays' format or, for optical flow,
//! Middlebury's `.flo` or KITTI's PNG ([`FlowFile`]).

use std::path::Path;

use super::files::ArrayFile;
use super::flow::files::{write_flo, write_kitti};
use super::flow::{Seen, optical_flow, scene_flow};
use crate::error::Result;
use crate::trace::{Values, write_exr, write_npy};

/// An output made from two frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Between {
    /// Forward optical flow to the next frame, and where the next frame sees the point.
    Flow,
    /// Backward optical flow to the previous frame, and where it sees the point.
    FlowBackward,
    /// How each pixel's hit moves in the camera's frame by the next frame.
    SceneFlow,
}

/// The files optical flow is written in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FlowFile {
    /// The ground-truth arrays' format (NPY, H×W×2 float32; or OpenEXR's R and G).
    #[default]
    Arrays,
    /// Middlebury's `.flo`.
    Flo,
    /// KITTI's 16-bit PNG.
    Kitti,
}

impl Between {
    /// The output's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Flow => "flow",
            Self::FlowBackward => "flow-backward",
            Self::SceneFlow => "scene-flow",
        }
    }

    /// The files it writes beside a frame's image, `(what, file)`: `stem` and the suffixes
    /// `.flow.npy` and `.flow_valid.npy`, `.flow_backward...`, `.scene_flow.npy` (or the
    /// formats' extensions).
    pub fn files(self, stem: &str, arrays: ArrayFile, flow: FlowFile) -> Vec<(String, String)> {
        let ext = arrays.extension();
        let flow_ext = match flow {
            FlowFile::Arrays => ext,
            FlowFile::Flo => "flo",
            FlowFile::Kitti => "png",
        };
        let named = |what: &str, ext: &str| (what.to_string(), format!("{stem}.{what}.{ext}"));
        match self {
            Self::Flow => vec![named("flow", flow_ext), named("flow_valid", ext)],
            Self::FlowBackward => vec![
                named("flow_backward", flow_ext),
                named("flow_backward_valid", ext),
            ],
            Self::SceneFlow => vec![named("scene_flow", ext)],
        }
    }

    /// Writes this output of frame `seen` into `folder` as [`Between::files`] names them
    /// (`files`), with its previous and next frames where there are.
    pub fn write(
        self,
        folder: &Path,
        files: &[(String, String)],
        seen: &Seen,
        (previous, next): (Option<&Seen>, Option<&Seen>),
        (arrays, flow_file): (ArrayFile, FlowFile),
    ) -> Result<()> {
        let size = seen.camera.size;
        let array = |name: &str, file: &str, values: Values| match arrays {
            ArrayFile::Npy => write_npy(&folder.join(file), size, values),
            ArrayFile::Exr => write_exr(&folder.join(file), size, name, values),
        };
        if self == Self::SceneFlow {
            let moved = scene_flow(seen, next);
            let flat = moved.into_iter().flatten().collect();
            return array(&files[0].0, &files[0].1, Values::F32(3, flat));
        }
        let other = if self == Self::Flow { next } else { previous };
        let (flow, valid) = optical_flow(seen, other);
        let (name, file) = (&files[0].0, &files[0].1);
        match flow_file {
            FlowFile::Arrays => array(
                name,
                file,
                Values::F32(2, flow.iter().flatten().copied().collect()),
            )?,
            FlowFile::Flo => write_flo(&folder.join(file), size, &flow)?,
            FlowFile::Kitti => write_kitti(&folder.join(file), size, &flow, &valid)?,
        }
        array(&files[1].0, &files[1].1, Values::U8(valid))
    }
}
