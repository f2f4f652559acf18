//! The ray tracer: a scene on the GPU ([`GpuScene`], built and uploaded once), the trace pass
//! for a lens and image size ([`TracePass`], or [`AdaptivePass`] to spend rays where the image
//! needs them; [`FramePass`] is either, as the options say), and [`render`], which does both
//! in one call.
//! `cpu` holds the f64 reference the GPU output is tested against; `cast` casts arbitrary rays
//! with the same traversal.

mod adaptive;
pub mod cast;
pub mod cpu;
mod display;
mod frame;
mod gpu_scene;
mod mip;
mod motion;
mod options;
mod output;
mod pass;
mod ray_query;
pub mod sampling;
mod tent;

use glam::DVec3;

pub use adaptive::{ALL_STAGES, AdaptivePass, AdaptiveSpans, Stage, stages_for};
pub use display::{
    ColourFile, Display, KEY, MASKED_RGB, Tone, auto_exposure, check_writable,
    check_writable_folder, colour_image, colour_image_with, linear_to_srgb, refuse_non_regular,
    save_png, write_atomically, write_colour, write_file,
};
pub use frame::FramePass;
pub use gpu_scene::{GpuScene, SceneBytes, gpu_lights, shading_vertices};
pub use mip::{mip_level_count, mip_levels};
pub use motion::{Motion, moving_directions};
pub use options::{
    Adaptive, PixelFilter, RenderOptions, SampleLanes, Sampling, Traversal, surface_constants,
    surface_id,
};
pub use output::{
    Channel, PixelRays, RenderOutput, Values, spp_key, spp_picture, write_exr, write_npy,
    write_rays_map,
};
pub use pass::TracePass;
pub use ray_query::RayQueryScene;
pub use tent::Tent;

pub use crate::shared::{
    Frame, GpuLight, GpuMaterial, LIGHT_KINDS, MAX_DEPTH_LIMIT, MAX_SHADOW_LAYERS, NO_HIT,
    NO_TEXTURE, Shading,
};

use crate::error::Result;
use crate::gpu::GpuContext;
use crate::lens::LensCamera;
use crate::scene::Scene;

/// The world-space direction of every pixel's ray (f64 lens model, rotated by the pose),
/// row-major, `None` where the lens masks the pixel.
pub fn world_directions(camera: &LensCamera, pose: &crate::scene::Camera) -> Vec<Option<DVec3>> {
    rotated(&camera.directions(), pose)
}

/// Camera-frame directions (as [`LensCamera::directions`] gives them, made once per camera)
/// turned into world space by `pose`.
pub fn rotated(directions: &[Option<DVec3>], pose: &crate::scene::Camera) -> Vec<Option<DVec3>> {
    let rotation = pose.rotation();
    directions.iter().map(|d| d.map(|d| rotation * d)).collect()
}

/// Renders `scene` through `camera` in one call: builds and uploads the scene, traces one
/// frame and reads it back.
pub fn render(
    ctx: &GpuContext,
    scene: &Scene,
    camera: &LensCamera,
    options: &RenderOptions,
) -> Result<RenderOutput> {
    let gpu_scene = GpuScene::new(ctx, scene, options)?;
    FramePass::new(ctx, camera, &gpu_scene, options)?.trace(
        ctx,
        &gpu_scene,
        &scene.camera,
        "tracing",
    )
}
