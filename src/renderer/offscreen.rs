//! Rendering frames in submissions of their own, for tools: an [`Offscreen`] renders one
//! [`Setup`] (a method, and its face size or rays per pixel) of a lens on scenes uploaded once
//! ([`SceneSet`]), waits for the GPU, times each pass ([`FrameTime`], by timestamp queries
//! where the adapter has them) and reads the outputs back. `fisheye render`, `bench` and
//! `compare` are built on it; an application that records frames into its own encoder uses
//! [`super::Renderer`].

use serde::Serialize;

use super::{Method, Path, Spans};
use crate::cube::{CubeMap, CubeMethod, CubeSettings, CubeSpans};
use crate::error::Result;
use crate::gpu::{GpuContext, Queries};
use crate::lens::LensCamera;
use crate::lens::gpu::DirectionSource;
use crate::raster::RasterMethod;
use crate::scene::{Camera, Scene};
use crate::trace::{
    ALL_STAGES, AdaptiveSpans, GpuScene, PixelFilter, RenderOptions, RenderOutput, Sampling, Stage,
    Traversal, stages_for,
};

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
/// methods, how many rays a pixel takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    /// The method.
    pub method: Method,
    /// Face size in texels of a cube-map method; ignored by direct ray tracing.
    pub cube_size: u32,
    /// Rays per pixel of a direct method, uniform or adaptive (see [`Sampling`]); one for
    /// cube maps, whose resampler takes one bilinear sample a pixel.
    pub sampling: Sampling,
    /// How a direct method's pixels are made from its rays; the box for cube maps.
    pub filter: PixelFilter,
}

impl Setup {
    /// A direct method at `spp` rays per pixel, or a cube method at face size `cube_size`.
    pub fn direct(method: Method, spp: u32) -> Setup {
        Self::sampled(method, Sampling::Uniform(spp))
    }

    /// A direct method sampled as `sampling` says.
    pub fn sampled(method: Method, sampling: Sampling) -> Setup {
        Setup {
            method,
            cube_size: 0,
            sampling,
            filter: PixelFilter::Box,
        }
    }

    /// This direct setup with its pixels made as `filter` says: the box where the filter
    /// would change no pixel ([`PixelFilter::applies_to`]), so that no setup is measured twice.
    pub fn filtered(self, filter: PixelFilter) -> Setup {
        let filter = match filter.applies_to(self.sampling) {
            true => filter,
            false => PixelFilter::Box,
        };
        Setup { filter, ..self }
    }

    /// A cube method at face size `cube_size`.
    pub fn cube(method: Method, cube_size: u32) -> Setup {
        Setup {
            method,
            cube_size,
            sampling: Sampling::Uniform(1),
            filter: PixelFilter::Box,
        }
    }

    /// `rt@16spp`, `rt@auto:0.02`, `rq@1spp`, `rt@1spp+tent` (the tent filter), or the cube
    /// method and face size: `cube-forward@512`.
    pub fn label(&self) -> String {
        let method = self.method.name();
        match (self.method, self.filter) {
            (Method::Cube(_), _) => format!("{method}@{}", self.cube_size),
            (_, PixelFilter::Box) => format!("{method}@{}", self.sampling.label()),
            (_, filter) => format!("{method}@{}+{}", self.sampling.label(), filter.name()),
        }
    }

    /// The face size of a cube-map setup.
    pub fn cube_size(&self) -> Option<u32> {
        self.method.cube().map(|_| self.cube_size)
    }

    /// The most rays per pixel of a direct setup.
    pub fn spp(&self) -> Option<u32> {
        self.method
            .cube()
            .is_none()
            .then_some(self.sampling.max_spp())
    }

    /// The threshold of an adaptive direct setup.
    pub fn threshold(&self) -> Option<f32> {
        self.method
            .cube()
            .is_none()
            .then(|| self.sampling.threshold())
            .flatten()
    }

    /// The passes a frame of this setup is timed in, in order (an adaptive frame's stages, as
    /// [`crate::trace::stages_for`] lists them).
    /// A filtered direct setup's filter is a pass of its own, last.
    pub fn passes(&self, ground_truth: bool) -> Vec<Pass> {
        let adaptive = self.sampling.options(ground_truth).1;
        let mut passes = match adaptive.filter(|_| self.method.cube().is_none()) {
            None => self.method.passes().to_vec(),
            Some(options) => {
                let spp = self.sampling.max_spp();
                let side = crate::trace::sampling::samples_per_side(spp).unwrap_or(1);
                stages_for(side, options)
                    .into_iter()
                    .flat_map(|stage| Pass::listing(stage).into_iter().chain([Pass::of(stage)]))
                    .collect()
            }
        };
        if self.method.cube().is_none() && self.filter != PixelFilter::Box {
            passes.push(Pass::Filter);
        }
        passes
    }

    /// Every setup of `methods`: direct methods once per sampling of `samplings` and filter
    /// of `filters`, a filter that changes nothing under a sampling counting as the box
    /// ([`PixelFilter::applies_to`]: the tent only at one ray a pixel at most), cube methods
    /// once per face size.
    pub fn all(
        methods: &[Method],
        cube_sizes: &[u32],
        samplings: &[Sampling],
        filters: &[PixelFilter],
    ) -> Vec<Setup> {
        methods
            .iter()
            .flat_map(|&method| match method {
                Method::Cube(_) => cube_sizes
                    .iter()
                    .map(|&size| Setup::cube(method, size))
                    .collect::<Vec<_>>(),
                _ => samplings
                    .iter()
                    .flat_map(|&sampling| {
                        // A filter that changes nothing here is the box: measured once.
                        let setup = Setup::sampled(method, sampling);
                        let mut filtered: Vec<Setup> =
                            filters.iter().map(|&f| setup.filtered(f)).collect();
                        filtered.dedup_by_key(|s| s.filter);
                        filtered
                    })
                    .collect(),
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
    /// Adaptive sampling's first rays, one per block corner.
    Coarse,
    /// Adaptive sampling's rays through the midpoints of blocks whose corners disagree.
    Midpoints,
    /// Adaptive sampling's rays through the pixels of half-blocks whose corners disagree.
    Refine,
    /// Adaptive sampling's 2 × 2 samples of pixels whose colour differs from a neighbour's,
    /// and the error estimate that picks those which take every sample.
    Estimate,
    /// Adaptive sampling's supersampling of the pixels picked.
    Supersample,
    /// Adaptive sampling's first hits of interpolated pixels, for the ground truth.
    Truth,
    /// Classifying blocks, interpolating those whose corners agree and listing the others'
    /// midpoints (before [`Pass::Midpoints`]).
    #[serde(rename = "midpoint-list")]
    MidpointList,
    /// Classifying the refined blocks' half-blocks, listing the pixels of those to refine
    /// and interpolating the others (before [`Pass::Refine`]).
    #[serde(rename = "refine-list")]
    RefineList,
    /// Listing the pixels whose colour bends (before [`Pass::Estimate`]).
    #[serde(rename = "estimate-list")]
    EstimateList,
    /// Listing the pixels to supersample (before [`Pass::Supersample`]).
    #[serde(rename = "supersample-list")]
    SupersampleList,
    /// Listing the interpolated pixels (before [`Pass::Truth`]).
    #[serde(rename = "truth-list")]
    TruthList,
    /// The tent filter of a direct frame's one-ray pixels ([`PixelFilter::Tent`]).
    Filter,
}

impl Pass {
    /// The pass that times an adaptive stage.
    pub fn of(stage: Stage) -> Pass {
        match stage {
            Stage::Coarse => Pass::Coarse,
            Stage::Midpoints => Pass::Midpoints,
            Stage::Refine => Pass::Refine,
            Stage::Estimate => Pass::Estimate,
            Stage::Supersample => Pass::Supersample,
            Stage::Truth => Pass::Truth,
        }
    }

    /// The pass that times an adaptive stage's listing of its pixels, the bookkeeping before
    /// its rays; none for the coarse stage, which traces the block corners with no list.
    pub fn listing(stage: Stage) -> Option<Pass> {
        match stage {
            Stage::Coarse => None,
            Stage::Midpoints => Some(Pass::MidpointList),
            Stage::Refine => Some(Pass::RefineList),
            Stage::Estimate => Some(Pass::EstimateList),
            Stage::Supersample => Some(Pass::SupersampleList),
            Stage::Truth => Some(Pass::TruthList),
        }
    }

    /// Lower-case name, as reports print it.
    pub fn name(&self) -> &'static str {
        match self {
            Pass::Trace => "trace",
            Pass::Faces => "faces",
            Pass::Lighting => "lighting",
            Pass::Sampler => "sampler",
            Pass::Coarse => "coarse",
            Pass::Midpoints => "midpoints",
            Pass::Refine => "refine",
            Pass::Estimate => "estimate",
            Pass::Supersample => "supersample",
            Pass::Truth => "truth",
            Pass::MidpointList => "midpoint list",
            Pass::RefineList => "refine list",
            Pass::EstimateList => "estimate list",
            Pass::SupersampleList => "supersample list",
            Pass::TruthList => "truth list",
            Pass::Filter => "filter",
        }
    }

    /// The time of adaptive sampling's listing passes (the bookkeeping: compaction, the
    /// neighbour tests, interpolation) among a frame's `passes` timed `ms`, and its share of
    /// them all; `None` where none lists (uniform sampling, cube maps).
    pub fn bookkeeping(passes: &[Pass], ms: &[f64]) -> Option<(f64, f64)> {
        let mut listing = passes
            .iter()
            .zip(ms)
            .filter(|(pass, _)| ALL_STAGES.iter().any(|&s| Pass::listing(s) == Some(**pass)))
            .map(|(_, &ms)| ms)
            .peekable();
        listing.peek()?;
        let spent: f64 = listing.sum();
        let all: f64 = ms.iter().sum();
        Some((spent, if all > 0.0 { spent / all } else { 0.0 }))
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
                GpuScene::for_rasterizer(
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
    passes: Vec<Pass>,
    queries: Option<Queries>,
    /// The rays of a uniformly sampled frame: the pixels the lens gives a ray, times spp (0
    /// for other paths, which count their own or none).
    uniform_rays: u64,
    /// The rays of an adaptive frame's coarse stage: the lattice points (or pixels) the lens
    /// gives a ray (0 for other paths).
    coarse_rays: u64,
}

/// How long one frame took.
#[derive(Clone, Debug, Serialize)]
pub struct FrameTime {
    /// Milliseconds from setting the pose to the GPU finishing the frame, on the CPU's clock.
    pub wall_ms: f64,
    /// GPU milliseconds per pass, in [`Offscreen::passes`] order; `None` without timestamp
    /// queries.
    pub passes_ms: Option<Vec<f64>>,
    /// Rays each pass traced, in the same order, for direct tracing: a uniform frame's are
    /// the pixels the lens gives a ray times spp, an adaptive coarse stage's the lattice
    /// points (or pixels) it gives one, and a later stage's its pixels listed times their
    /// samples ([`crate::trace::AdaptivePass::read_stage_rays`], which counts the few the
    /// lens masks at its rim too); `None` through a cube map.
    pub passes_rays: Option<Vec<u64>>,
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
            false,
        )
    }

    /// As [`Offscreen::new`], with direct tracing's primary rays from `directions`; with
    /// `ground_truth`, adaptive sampling also traces the first hits of the pixels it
    /// interpolates (see [`crate::trace::Adaptive::ground_truth`]).
    pub fn with_directions(
        ctx: &GpuContext,
        camera: &LensCamera,
        scenes: &SceneSet,
        setup: Setup,
        shadow_size: u32,
        directions: DirectionSource,
        ground_truth: bool,
    ) -> Result<Self> {
        let (spp, adaptive) = setup.sampling.options(ground_truth);
        let rays = (directions, spp, adaptive, setup.filter);
        let scene = scenes.for_method(setup.method);
        let cube = match setup.method {
            Method::Cube(method) => Some(CubeSettings {
                shadow_size,
                ..CubeSettings::new(setup.cube_size, method)
            }),
            _ => None,
        };
        let path = Path::new(ctx, camera, scene, rays, cube.as_ref())?;
        let passes = setup.passes(ground_truth);
        let queries = Queries::new(ctx, passes.len() as u32);
        // A uniformly traced frame's rays and an adaptive frame's coarse stage's are counted
        // from the lens (an f64 evaluation a pixel, once): the centres it covers. The coarse
        // stage's invocations at masked lattice points trace nothing.
        let (uniform_rays, coarse_rays) = match &path {
            Path::Direct(_) => {
                let covered = camera.directions().iter().filter(|d| d.is_some()).count();
                (covered as u64 * u64::from(spp), 0)
            }
            Path::Adaptive(pass) => {
                let covered = pass.coarse_pixels();
                let covered = covered.filter(|&[x, y]| camera.pixel_direction(x, y).is_some());
                (0, covered.count() as u64)
            }
            Path::Cube(_) => (0, 0),
        };
        Ok(Self {
            path,
            setup,
            passes,
            queries,
            uniform_rays,
            coarse_rays,
        })
    }

    /// The setup.
    pub fn setup(&self) -> Setup {
        self.setup
    }

    /// The passes a frame is timed in, in [`FrameTime::passes_ms`] order.
    pub fn passes(&self) -> &[Pass] {
        &self.passes
    }

    /// The rays each pixel's colour took in the last frame, row-major: the spp map of adaptive
    /// sampling (see [`crate::trace::AdaptivePass::read_rays`]); `None` for other setups,
    /// whose pixels all take the setup's rays.
    pub fn rays_per_pixel(&self, ctx: &GpuContext) -> Result<Option<Vec<u32>>> {
        match &self.path {
            Path::Adaptive(pass) => pass.read_rays(ctx).map(Some),
            _ => Ok(None),
        }
    }

    /// Renders one frame from `pose` in one submission, waits for the GPU to finish it, and
    /// returns its times.
    pub fn frame(&self, ctx: &GpuContext, scenes: &SceneSet, pose: &Camera) -> Result<FrameTime> {
        let scene = scenes.for_method(self.setup.method);
        let q = self.queries.as_ref();
        let started = crate::clock::Stopwatch::start();
        ctx.checked("rendering a frame", || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            let index = |p: Pass| self.passes.iter().position(|&x| x == p).map(|i| i as u32);
            let span = |p: Pass| index(p).and_then(|i| q.map(|q| q.span(i)));
            let writes = |p: Pass| index(p).and_then(|i| q.map(|q| q.writes(i)));
            let spans = Spans {
                trace: writes(Pass::Trace),
                filter: writes(Pass::Filter),
                adaptive: AdaptiveSpans {
                    lists: ALL_STAGES.map(|stage| Pass::listing(stage).and_then(writes)),
                    stages: ALL_STAGES.map(|stage| writes(Pass::of(stage))),
                },
                cube: CubeSpans {
                    faces: span(Pass::Faces),
                    lighting: span(Pass::Lighting),
                    sampler: span(Pass::Sampler),
                },
            };
            self.path.encode(ctx, &mut encoder, scene, pose, spans);
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
        let mut passes_rays = match &self.path {
            Path::Direct(_) => Some(vec![self.uniform_rays]),
            // Listing traces nothing; each stage's rays are its tracing pass's.
            Path::Adaptive(pass) => Some(
                pass.read_stage_rays(ctx)?
                    .into_iter()
                    .flat_map(|(stage, rays)| {
                        let rays = if stage == Stage::Coarse {
                            self.coarse_rays
                        } else {
                            rays
                        };
                        Pass::listing(stage).map(|_| 0).into_iter().chain([rays])
                    })
                    .collect(),
            ),
            Path::Cube(_) => None,
        };
        // The filter traces nothing.
        if let Some(rays) = passes_rays
            .as_mut()
            .filter(|_| self.passes.contains(&Pass::Filter))
        {
            rays.push(0);
        }
        Ok(FrameTime {
            wall_ms,
            passes_ms,
            passes_rays,
        })
    }

    /// Compiles the frame's kernels before anything is timed (lavapipe, like many drivers,
    /// compiles a pipeline at its first dispatch) with the least work that runs each: one
    /// workgroup of a traced frame, or a whole cube-map frame (whose passes each need their
    /// first draw or dispatch). Returns the wall milliseconds it took: compilation, mostly.
    pub fn warm_up(&self, ctx: &GpuContext, scenes: &SceneSet, pose: &Camera) -> Result<f64> {
        let started = crate::clock::Stopwatch::start();
        match &self.path {
            Path::Direct(pass) => {
                let scene = scenes.for_method(self.setup.method);
                let one = crate::lens::ImageSize::new(1, 1).expect("1x1 is a size");
                ctx.checked("compiling the kernels", || {
                    let mut encoder = ctx.device.create_command_encoder(&Default::default());
                    pass.encode_pose(&ctx.device, &mut encoder, scene, pose);
                    pass.encode_region(&mut encoder, scene, 0, one, None);
                    pass.encode_filter(&mut encoder, None);
                    ctx.queue.submit([encoder.finish()]);
                })?;
                ctx.wait()?;
            }
            // Each stage's kernels run only once its predecessors listed pixels.
            Path::Adaptive(_) | Path::Cube(_) => {
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
            _ => None,
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
        let samplings = [1, 16].map(Sampling::Uniform);
        let filters = PixelFilter::ALL;
        let mut setups = Setup::all(
            &[Method::Rt, Method::ALL[3]],
            &[512, 1024],
            &samplings,
            &filters,
        );
        setups.push(Setup::sampled(
            Method::Rt,
            Sampling::parse("auto:0.05").unwrap(),
        ));
        let labels: Vec<String> = setups.iter().map(Setup::label).collect();
        // The tent changes nothing at 16 rays a pixel, nor a cube map: no second setup.
        let wanted = [
            "rt@1spp",
            "rt@1spp+tent",
            "rt@16spp",
            "cube-forward@512",
            "cube-forward@1024",
            "rt@auto:0.05",
        ];
        assert_eq!(labels, wanted);
        // The tent alone still measures 16 rays, with the box (the same pixels).
        let tent_only = Setup::all(&[Method::Rt], &[], &samplings, &[PixelFilter::Tent]);
        let labels: Vec<String> = tent_only.iter().map(Setup::label).collect();
        assert_eq!(labels, ["rt@1spp+tent", "rt@16spp"]);
    }

    #[test]
    fn bookkeeping_is_the_listing_passes_share() {
        let passes = [
            Pass::Coarse,
            Pass::MidpointList,
            Pass::Midpoints,
            Pass::RefineList,
            Pass::Refine,
            Pass::Filter,
        ];
        let ms = [0.5, 1.0, 0.75, 0.5, 1.25, 1.0];
        let (spent, share) = Pass::bookkeeping(&passes, &ms).unwrap();
        assert_eq!(spent, 1.5);
        assert_eq!(share, 0.3);
        // Every stage's listing counts, and no tracing pass does.
        for stage in ALL_STAGES {
            let passes: Vec<Pass> = [Some(Pass::of(stage)), Pass::listing(stage)]
                .into_iter()
                .flatten()
                .collect();
            let ms = [3.0, 2.0];
            let found = Pass::bookkeeping(&passes, &ms[..passes.len()]);
            assert_eq!(
                found.map(|(spent, _)| spent),
                Pass::listing(stage).map(|_| 2.0)
            );
        }
        assert_eq!(
            Pass::bookkeeping(&[Pass::Trace, Pass::Filter], &[4.0, 1.0]),
            None
        );
        assert_eq!(
            Pass::bookkeeping(&[Pass::Faces, Pass::Sampler], &[4.0, 1.0]),
            None
        );
    }
}
