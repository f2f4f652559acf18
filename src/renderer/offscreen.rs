//! Rendering frames in submissions of their own, for tools: an [`Offscreen`] renders one
//! [`Setup`] (a method, and its face size or rays per pixel) of a lens on scenes uploaded once
//! ([`SceneSet`]), waits for the GPU, times each pass ([`FrameTime`], by timestamp queries
//! where the adapter has them) and reads the outputs back. `fisheye render`, `bench` and
//! `compare` are built on it; an application that records frames into its own encoder uses
//! [`super::Renderer`].

use serde::Serialize;

use super::{Method, Path};
use crate::cube::{CubeMap, CubeMethod, CubeSettings, CubeSpans};
use crate::error::Result;
use crate::gpu::{GpuContext, Queries};
use crate::lens::LensCamera;
use crate::lens::gpu::DirectionSource;
use crate::raster::RasterMethod;
use crate::scene::{Camera, Scene};
use crate::trace::{GpuScene, RenderOptions, RenderOutput, Traversal};

impl Method {
    /// The passes a frame of this method is timed in, in order.
    pub fn passes(&self) -> &'static [Pass] {
        match self {
            Method::Rt | Method::Rq => &[Pass::Trace],
            Method::Cube(CubeMethod::Raster(RasterMethod::Deferred)) => {
                &[Pass::Faces, Pass::Lighting, Pass::Sampler]
            }
            Method::Cube(_) => &[Pass::Faces, Pass::Sampler],
        }
    }
}

/// One configuration measured: a method and, for cube maps, the face size; for direct
/// methods, the rays per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Setup {
    /// The method.
    pub method: Method,
    /// Face size in texels of a cube-map method; ignored by direct ray tracing.
    pub cube_size: u32,
    /// Rays per pixel of a direct method (a square, see [`crate::trace::sampling`]); 1 for
    /// cube maps, whose resampler takes one bilinear sample a pixel.
    pub spp: u32,
}

impl Setup {
    /// A direct method at `spp` rays per pixel, or a cube method at face size `cube_size`.
    pub fn direct(method: Method, spp: u32) -> Setup {
        Setup {
            method,
            cube_size: 0,
            spp,
        }
    }

    /// `rt@16spp`, `rq@1spp`, or the cube method and face size: `cube-forward@512`.
    pub fn label(&self) -> String {
        match self.method {
            Method::Cube(_) => format!("{}@{}", self.method.name(), self.cube_size),
            _ => format!("{}@{}spp", self.method.name(), self.spp),
        }
    }

    /// The face size of a cube-map setup.
    pub fn cube_size(&self) -> Option<u32> {
        self.method.cube().map(|_| self.cube_size)
    }

    /// The rays per pixel of a direct setup.
    pub fn spp(&self) -> Option<u32> {
        self.method.cube().is_none().then_some(self.spp)
    }

    /// Every setup of `methods`: direct methods once per rays-per-pixel count of `spps`, cube
    /// methods once per face size.
    pub fn all(methods: &[Method], cube_sizes: &[u32], spps: &[u32]) -> Vec<Setup> {
        methods
            .iter()
            .flat_map(|&method| match method {
                Method::Cube(_) => cube_sizes
                    .iter()
                    .map(|&cube_size| Setup {
                        method,
                        cube_size,
                        spp: 1,
                    })
                    .collect::<Vec<_>>(),
                _ => spps.iter().map(|&spp| Setup::direct(method, spp)).collect(),
            })
            .collect()
    }
}

/// A timed part of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Pass {
    /// Direct ray tracing of the lens image.
    Trace,
    /// Rendering the cube's faces (traced, forward, the deferred G-buffer, or multiview).
    Faces,
    /// The deferred faces' lighting pass.
    Lighting,
    /// Resampling the cube into the lens image.
    Sampler,
}

impl Pass {
    /// Lower-case name, as reports print it.
    pub fn name(&self) -> &'static str {
        match self {
            Pass::Trace => "trace",
            Pass::Faces => "faces",
            Pass::Lighting => "lighting",
            Pass::Sampler => "sampler",
        }
    }
}

/// The scene on the GPU as each method needs it: the software BVH, and the driver's
/// acceleration structure when a ray-query method is set up.
pub struct SceneSet {
    /// The scene with the software BVH.
    pub software: GpuScene,
    /// The scene with a ray-query acceleration structure, if asked for.
    pub ray_query: Option<GpuScene>,
    /// An instanced scene flattened for the rasterizer, if a setup rasterizes it.
    pub flat: Option<GpuScene>,
}

impl SceneSet {
    /// Uploads `scene` for the traversals `setups` need.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        options: &RenderOptions,
        setups: &[Setup],
    ) -> Result<Self> {
        let software = GpuScene::new(
            ctx,
            scene,
            &RenderOptions {
                traversal: Traversal::Software,
                ..*options
            },
        )?;
        let ray_query = setups
            .iter()
            .any(|s| s.method == Method::Rq)
            .then(|| {
                let options = RenderOptions {
                    traversal: Traversal::RayQuery,
                    ..*options
                };
                GpuScene::new(ctx, scene, &options)
            })
            .transpose()?;
        let rasterizes = |s: &Setup| matches!(s.method, Method::Cube(CubeMethod::Raster(_)));
        let flat = (scene.is_instanced() && setups.iter().any(rasterizes))
            .then(|| {
                let options = RenderOptions {
                    traversal: Traversal::Software,
                    ..*options
                };
                GpuScene::new(
                    ctx,
                    &scene.flattened(crate::scene::MAX_FLATTENED)?,
                    &options,
                )
            })
            .transpose()?;
        Ok(Self {
            software,
            ray_query,
            flat,
        })
    }

    /// The scene `method` renders.
    pub fn for_method(&self, method: Method) -> &GpuScene {
        match (method, &self.ray_query, &self.flat) {
            (Method::Rq, Some(rq), _) => rq,
            (Method::Cube(CubeMethod::Raster(_)), _, Some(flat)) => flat,
            _ => &self.software,
        }
    }
}

/// One setup ready to render frames of one lens in submissions of its own: its pipelines,
/// buffers and timestamp queries.
pub struct Offscreen {
    path: Path,
    setup: Setup,
    queries: Option<Queries>,
}

/// How long one frame took.
#[derive(Clone, Debug, Serialize)]
pub struct FrameTime {
    /// Milliseconds from setting the pose to the GPU finishing the frame, on the CPU's clock.
    pub wall_ms: f64,
    /// GPU milliseconds per pass, in [`Method::passes`] order; `None` without timestamp
    /// queries.
    pub passes_ms: Option<Vec<f64>>,
}

impl FrameTime {
    /// The frame's GPU time (the sum of its passes), if timed.
    pub fn gpu_ms(&self) -> Option<f64> {
        self.passes_ms.as_ref().map(|p| p.iter().sum())
    }
}

impl Offscreen {
    /// Sets `setup` up for `camera` on the scenes (the shadow maps of rasterized faces are
    /// `shadow_size`² and rendered here, once: the lights do not move).
    pub fn new(
        ctx: &GpuContext,
        camera: &LensCamera,
        scenes: &SceneSet,
        setup: Setup,
        shadow_size: u32,
    ) -> Result<Self> {
        Self::with_directions(
            ctx,
            camera,
            scenes,
            setup,
            shadow_size,
            DirectionSource::Computed,
        )
    }

    /// As [`Offscreen::new`], with direct tracing's primary rays from `directions`.
    pub fn with_directions(
        ctx: &GpuContext,
        camera: &LensCamera,
        scenes: &SceneSet,
        setup: Setup,
        shadow_size: u32,
        directions: DirectionSource,
    ) -> Result<Self> {
        let rays = (directions, setup.spp);
        let scene = scenes.for_method(setup.method);
        let cube = match setup.method {
            Method::Cube(method) => Some(CubeSettings {
                shadow_size,
                ..CubeSettings::new(setup.cube_size, method)
            }),
            _ => None,
        };
        let path = Path::new(ctx, camera, scene, rays, cube.as_ref())?;
        let queries = Queries::new(ctx, setup.method.passes().len() as u32);
        Ok(Self {
            path,
            setup,
            queries,
        })
    }

    /// The setup.
    pub fn setup(&self) -> Setup {
        self.setup
    }

    /// Renders one frame from `pose` in one submission, waits for the GPU to finish it, and
    /// returns its times.
    pub fn frame(&self, ctx: &GpuContext, scenes: &SceneSet, pose: &Camera) -> Result<FrameTime> {
        let scene = scenes.for_method(self.setup.method);
        let q = self.queries.as_ref();
        let started = std::time::Instant::now();
        ctx.checked("rendering a frame", || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            let passes = self.setup.method.passes();
            let index = |p: Pass| passes.iter().position(|&x| x == p).map(|i| i as u32);
            let span = |p: Pass| index(p).and_then(|i| q.map(|q| q.span(i)));
            let spans = CubeSpans {
                faces: span(Pass::Faces),
                lighting: span(Pass::Lighting),
                sampler: span(Pass::Sampler),
            };
            let trace = index(Pass::Trace).and_then(|i| q.map(|q| q.writes(i)));
            self.path
                .encode(ctx, &mut encoder, scene, pose, trace, spans);
            if let Some(q) = q {
                q.resolve(&mut encoder);
            }
            ctx.queue.submit([encoder.finish()]);
        })?;
        ctx.wait()?;
        let wall_ms = started.elapsed().as_secs_f64() * 1e3;
        let passes_ms = match q {
            Some(q) => Some(q.read_ns(ctx)?.into_iter().map(|ns| ns * 1e-6).collect()),
            None => None,
        };
        Ok(FrameTime { wall_ms, passes_ms })
    }

    /// Compiles the frame's kernels before anything is timed (lavapipe, like many drivers,
    /// compiles a pipeline at its first dispatch) with the least work that runs each: one
    /// workgroup of a traced frame, or a whole cube-map frame (whose passes each need their
    /// first draw or dispatch). Returns the wall milliseconds it took: compilation, mostly.
    pub fn warm_up(&self, ctx: &GpuContext, scenes: &SceneSet, pose: &Camera) -> Result<f64> {
        let started = std::time::Instant::now();
        match &self.path {
            Path::Direct(pass) => {
                let scene = scenes.for_method(self.setup.method);
                let one = crate::lens::ImageSize::new(1, 1).expect("1x1 is a size");
                ctx.checked("compiling the kernels", || {
                    let mut encoder = ctx.device.create_command_encoder(&Default::default());
                    pass.encode_pose(&ctx.device, &mut encoder, scene, pose);
                    pass.encode_region(&mut encoder, scene, 0, one, None);
                    ctx.queue.submit([encoder.finish()]);
                })?;
                ctx.wait()?;
            }
            Path::Cube(_) => {
                self.frame(ctx, scenes, pose)?;
            }
        }
        Ok(started.elapsed().as_secs_f64() * 1e3)
    }

    /// The lens image's linear colours of the last frame (as [`RenderOutput::colour`]).
    pub fn colour(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>> {
        Ok(self.output(ctx)?.colour)
    }

    /// The last frame's outputs: all of them for direct tracing, the colour alone (geometry
    /// zero, ids `NO_HIT`) through a cube map.
    pub fn output(&self, ctx: &GpuContext) -> Result<RenderOutput> {
        self.path.read(ctx)
    }

    /// The cube map, for a cube-map setup.
    pub fn cube(&self) -> Option<&CubeMap> {
        match &self.path {
            Path::Cube(cube) => Some(cube),
            Path::Direct(_) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn setups_and_names_round_trip() {
        for m in Method::ALL {
            assert_eq!(Method::from_name(m.name()), Some(m));
        }
        let setups = Setup::all(&[Method::Rt, Method::ALL[3]], &[512, 1024], &[1, 16]);
        let labels: Vec<String> = setups.iter().map(Setup::label).collect();
        let wanted = [
            "rt@1spp",
            "rt@16spp",
            "cube-forward@512",
            "cube-forward@1024",
        ];
        assert_eq!(labels, wanted);
    }
}
