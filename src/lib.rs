//! # fisheye-rt
//!
//! Renders images through fisheye and other wide-angle lenses by ray tracing in wgpu compute
//! shaders, on any GPU (or on Mesa's lavapipe without one).
//!
//! - [`lens`]: lens models, classic and calibrated (the f64 reference and the specs, presets
//!   and calibration files users name them by), and their WGSL twin on the GPU
//!   ([`lens::gpu`]).
//! - [`gpu`]: the one place that creates the adapter and device.
//! - [`shared`]: what the GPU and Rust share (ids, limits, workgroup sizes, `repr(C)`
//!   structs), read by everything and reading nothing.
//! - [`shader`]: how WGSL files are assembled into modules; [`split`]: the scene's arrays
//!   split across as many storage bindings as they need.
//! - [`scene`], [`bvh`], [`trace`]: scenes (built-in, OBJ, glTF and scene files), the CWBVH,
//!   and the GPU tracer with its f64 reference.
//! - [`renderer`]: a [`renderer::Renderer`] renders on the caller's device into the caller's
//!   texture and encoder; a [`renderer::Offscreen`] renders frames in submissions of its own,
//!   times them and reads them back (what the `fisheye` tool's commands are built on).
//! - [`pose`], [`dataset`]: rigid transforms, trajectories (TUM, KITTI, EuRoC) and synthetic
//!   datasets of a camera rig along them, in shards.
//! - `peer` (feature `peer-embree`): Embree 3 casting the same rays, for the peer benchmark.
//! - [`cube`], [`raster`]: the cube-map path (faces ray traced or rasterized, then resampled),
//!   to compare with direct ray tracing.
//!
//! Rendering a scene through a lens takes a few lines (this example runs in the tests, on
//! lavapipe when there is no GPU):
//!
//! ```
//! use fisheye_rt::gpu::GpuContext;
//! use fisheye_rt::lens::{parse_spec, ImageSize, LensCamera};
//! use fisheye_rt::scene::builtin;
//! use fisheye_rt::trace::{render, RenderOptions, NO_HIT};
//!
//! # fn main() -> Result<(), fisheye_rt::Error> {
//! let scene = builtin::scene("default").expect("a built-in scene"); // or scene::obj::load_obj
//! let camera = LensCamera::new(parse_spec("samyang-7.5mm")?, ImageSize::new(64, 48)?);
//! let ctx = GpuContext::new()?; // the one place a device is made
//! let frame = render(&ctx, &scene, &camera, &RenderOptions::default())?;
//! let png = frame.to_image(); // sRGB, alpha = the lens's validity mask; png.save(path) writes it
//! assert_eq!(png.dimensions(), (64, 48));
//! // Per pixel: linear radiance, the primary hit's normal and range, its triangle id.
//! assert_eq!(frame.ids.len(), 64 * 48);
//! assert!(frame.ids.iter().all(|&id| id != NO_HIT)); // the room is closed
//! # Ok(()) }
//! ```

#![warn(missing_docs)]

pub mod bvh;
mod clock;
pub mod cube;
pub mod dataset;
mod error;
pub mod gpu;
pub mod input;
pub mod lens;
pub mod pose;
pub mod precision;
pub mod raster;
pub mod renderer;
pub mod scene;
pub mod shader;
pub mod shared;
pub mod split;
mod threads;
pub mod trace;

// The tools of the `fisheye` command (the default `cli` feature).
#[cfg(feature = "cli")]
pub mod bench;
#[cfg(feature = "cli")]
pub mod compare;
#[cfg(feature = "cli")]
pub mod demo;
#[cfg(feature = "cli")]
pub mod plot;
#[cfg(feature = "cli")]
pub mod report;
#[cfg(feature = "cli")]
pub mod validate;

// Embree as the peer of the benchmark (the `peer-embree` feature).
#[cfg(feature = "peer-embree")]
pub mod peer;

pub use error::{Error, LensError, Result};

/// The README's Rust examples, compiled and run as doctests so they stay true.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

/// The book's Rust examples ("Embedding in Rust"), compiled and run as doctests; `tests/docs.rs`
/// checks that every page with Rust in it is included here.
#[doc = include_str!("../docs/src/embedding.md")]
#[cfg(doctest)]
pub struct EmbeddingDoctests;
