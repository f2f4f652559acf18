//! Lens models: radial mappings, the camera that puts one on an image, specs and presets.
//!
//! The Rust code here is the f64 reference; `wgsl/lens.wgsl` is its f32 twin that the GPU runs
//! (see [`gpu`]), tested against it pixel by pixel.

mod camera;
pub mod gpu;
mod model;
mod spec;

pub use camera::{DirectionFormula, ImageSize, LensCamera, MAX_IMAGE_SIDE};
pub(crate) use model::Family;
pub use model::{Lens, LensModel};
pub use spec::{PRESET_FOV_DEGREES, PRESETS, Preset, parse_spec};

#[cfg(test)]
mod tests;
