//! Lens models: classic radial mappings and calibrated camera models, the camera that puts
//! one on an image, specs, presets and calibration files.
//!
//! The Rust code here is the f64 reference; `wgsl/lens.wgsl` and `wgsl/calibrated.wgsl` are
//! its f32 twin that the GPU runs (see [`gpu`]), tested against it pixel by pixel.

pub mod calib;
mod calibrated;
mod camera;
pub mod fit;
pub mod glass;
pub mod glass_gpu;
pub mod gpu;
mod json;
mod model;
pub mod points;
pub mod prescription;
mod shutter;
mod spec;
pub mod twin;

pub use calibrated::{CalibratedLens, CalibratedModel, Intrinsics, newton_bound, solve};
pub use camera::{DirectionFormula, ImageSize, LensCamera, MAX_IMAGE_SIDE};
pub(crate) use model::Family;
pub use model::{ClassicLens, Lens, LensModel};
pub use shutter::{Readout, Shutter};
pub use spec::{PRESET_FOV_DEGREES, PRESETS, Preset, parse_spec};

#[cfg(test)]
mod tests;
