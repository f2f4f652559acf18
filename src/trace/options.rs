//! What a render is asked for ([`RenderOptions`]: depth, BVH preset, ray directions,
//! traversal, rays per pixel) and the constants that specialise the kernels to a scene's
//! surfaces.

use crate::bvh::BvhQuality;
use crate::lens::gpu::DirectionSource;
use crate::scene::{Features, Surface};

/// The WGSL id of a surface kind.
pub fn surface_id(surface: Surface) -> u32 {
    match surface {
        Surface::Diffuse => crate::shared::SURFACE_DIFFUSE,
        Surface::Mirror => crate::shared::SURFACE_MIRROR,
        Surface::Glass => crate::shared::SURFACE_GLASS,
    }
}

/// How to render.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// Deepest reflection/refraction (0: primary rays and shadows only).
    pub max_depth: u32,
    /// BVH build preset.
    pub bvh: BvhQuality,
    /// Where primary ray directions come from.
    pub directions: DirectionSource,
    /// How rays find their hits.
    pub traversal: Traversal,
    /// Rays per pixel (a square: jittered stratified samples, box-filtered; see
    /// [`super::sampling`]). Ground-truth outputs stay the one ray through the pixel's centre.
    pub spp: u32,
}

/// How the tracer's rays find their hits; lens and shading code are the same for both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Traversal {
    /// The obvhs CWBVH, traversed in WGSL (`wgsl/bvh.wgsl`): runs on any adapter.
    #[default]
    Software,
    /// Hardware ray queries over an acceleration structure built by the driver
    /// (`wgsl/bvh_rq.wgsl`); needs `Features::EXPERIMENTAL_RAY_QUERY`.
    RayQuery,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            max_depth: 5,
            bvh: BvhQuality::default(),
            directions: DirectionSource::Computed,
            traversal: Traversal::Software,
            spp: 1,
        }
    }
}

/// The overrides of `wgsl/surface.wgsl` for a scene's features: code for what the scene does
/// not use is dead.
pub fn surface_constants(f: Features) -> [(&'static str, f64); 5] {
    let flag = |b: bool| f64::from(u8::from(b));
    [
        ("HAS_MIRRORS", flag(f.mirrors)),
        ("HAS_GLASS", flag(f.glass)),
        ("HAS_TEXTURES", flag(f.textures)),
        ("SMOOTH_NORMALS", flag(f.smooth_normals)),
        ("INSTANCED", flag(f.instanced)),
    ]
}
