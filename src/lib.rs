//! # fisheye-rt
//!
//! Renders images through fisheye and other wide-angle lenses by ray tracing in wgpu compute
//! shaders, on any GPU (or on Mesa's lavapipe without one).
//!
//! - [`lens`]: lens models (the f64 reference and the specs and presets users name them by)
//!   and their WGSL twin on the GPU ([`lens::gpu`]).
//! - [`gpu`]: the one place that creates the adapter and device.
//! - [`shader`]: how WGSL files are assembled into modules.
//!
//! ```no_run
//! use fisheye_rt::{gpu::GpuContext, lens::{parse_spec, ImageSize, LensCamera}, lens::gpu::LensRays};
//! # fn main() -> Result<(), fisheye_rt::Error> {
//! let camera = LensCamera::new(parse_spec("samyang-7.5mm")?, ImageSize::new(1024, 768)?);
//! let ctx = GpuContext::new()?;
//! let directions = LensRays::new(&ctx, &camera)?.compute(&ctx)?; // one Option<Vec3> per pixel
//! assert_eq!(directions.len(), 1024 * 768);
//! # Ok(()) }
//! ```

pub mod bvh;
pub mod demo;
mod error;
pub mod gpu;
pub mod lens;
pub mod precision;
pub mod scene;
pub mod shader;
pub mod trace;

pub use error::{Error, LensError, Result};

/// The README's Rust examples, compiled as doctests so they stay true.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
