//! The cube-map path: six faces around the camera, rendered by the tracer or the rasterizer,
//! then resampled through the lens ([`CubeMap`]).
//!
//! The cube lives in the camera's space (x right, y down, z forward). Each face is a 90° view
//! with its own right, down and forward axes, all ±1 permutations of the camera's, so the face
//! coordinates of a direction are exact component selections: on the +z face
//! `uv = (d.xy / d.z + 1) / 2`. The geometry (which face and where, the bordered faces and
//! their lookup) is in [`faces`], which the rasterizer reads too.

pub mod faces;

use glam::{Vec2, Vec3};

pub use faces::{
    MOST_TAPS, Region, bordered, bordered_focal, face_camera, face_regions, face_uv, resample,
    resample_taps, resampled_directions, sample_bordered, texels_across,
};

use crate::error::{Error, Result};
use crate::gpu::{
    GpuContext, Span, bind_buffers, bind_group, bind_group_at, dispatch_over_image, layer_view,
    storage_entry, texture_array, uniform_entry,
};
use crate::lens::gpu::{DirectionSource, lens_constants, params_buffer};
use crate::lens::{ImageSize, LensCamera};
use crate::raster::{RasterFaces, RasterMethod};
use crate::scene::Camera;
use crate::shader;
pub use crate::shared::{FACES, Face, wgsl_faces};
use crate::trace::{GpuScene, TracePass};

/// How much of each face [`CubeMap`] renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coverage {
    /// Only the part of each face the lens can reach ([`face_regions`] of the directions the
    /// resampler reads, [`resampled_directions`]).
    Reachable,
    /// Every texel of every face the lens reaches (to compare).
    WholeFaces,
}

/// How the cube's faces are rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CubeMethod {
    /// By the tracer, as 90° pinhole views: compared with the direct fisheye render, this
    /// isolates the error of cube-map resampling alone.
    Traced,
    /// By the rasterizer ([`crate::raster`]).
    Raster(RasterMethod),
}

impl CubeMethod {
    /// Every method, in the order of `fisheye render --method`'s names.
    pub const ALL: [CubeMethod; 4] = [
        Self::Traced,
        Self::Raster(RasterMethod::Forward),
        Self::Raster(RasterMethod::Deferred),
        Self::Raster(RasterMethod::SinglePass),
    ];

    /// The name on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Traced => "cube-rt",
            Self::Raster(RasterMethod::Forward) => "cube-forward",
            Self::Raster(RasterMethod::Deferred) => "cube-deferred",
            Self::Raster(RasterMethod::SinglePass) => "cube-single",
        }
    }
}

/// How [`CubeMap`] renders its faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CubeSettings {
    /// Inner texels per face side.
    pub size: u32,
    /// What renders the faces.
    pub method: CubeMethod,
    /// How much of each face.
    pub coverage: Coverage,
    /// Texels per side of each shadow-map layer (rasterized faces only).
    pub shadow_size: u32,
}

impl CubeSettings {
    /// Faces of `size` by `method`, only where the lens reaches, shadow maps of 2048².
    pub fn new(size: u32, method: CubeMethod) -> Self {
        Self {
            size,
            method,
            coverage: Coverage::Reachable,
            shadow_size: 2048,
        }
    }
}

enum Faces {
    Traced(Box<TracedFaces>),
    Raster(Box<RasterFaces>),
}

/// The tracer's half of the cube-map path: one bordered face at a time through the face
/// camera, each copied into its layer of the cube.
struct TracedFaces {
    pass: TracePass,
    store: wgpu::ComputePipeline,
    /// Per face: the trace pass's colour output and that face's layer of the cube.
    store_groups: Vec<wgpu::BindGroup>,
    side: u32,
}

impl TracedFaces {
    fn new(ctx: &GpuContext, scene: &GpuScene, size: u32, cube: &wgpu::Texture) -> Result<Self> {
        let camera = face_camera(size)?;
        let pass = TracePass::with_views(ctx, &camera, scene, DirectionSource::Computed, 6, 1)?;
        ctx.checked("creating the traced cube faces", || {
            let device = &ctx.device;
            let store = shader::compute_pipeline(device, "cube_store", "main", &[], &[]);
            let layout = store.get_bind_group_layout(0);
            let store_groups = (0..6)
                .map(|face| {
                    let layer = layer_view(cube, Some(face));
                    bind_group(
                        device,
                        "fisheye.cube_store",
                        &layout,
                        [
                            pass.colour_buffer().as_entire_binding(),
                            wgpu::BindingResource::TextureView(&layer),
                        ],
                    )
                })
                .collect();
            Self {
                pass,
                store,
                store_groups,
                side: bordered(size),
            }
        })
    }

    /// Points each face's view at `pose` and records, face after face, the trace of its
    /// region and the copy into its layer (one span over all of them).
    fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pose: &Camera,
        regions: &[Option<Region>; 6],
        span: Option<Span<'_>>,
    ) {
        let rotation = pose.rotation();
        let reached: Vec<(usize, Region)> = regions
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.map(|r| (i, r)))
            .collect();
        let side = ImageSize::new(self.side, self.side).expect("a face");
        for (k, &(i, r)) in reached.iter().enumerate() {
            let view = i as u32;
            let face = rotation * FACES[i].rotation();
            self.pass
                .set_view(ctx, scene, view, pose.position, face, [r.x0, r.y0]);
            let extent = ImageSize::new(r.x1 - r.x0, r.y1 - r.y0).expect("a non-empty region");
            let (first, last) = (k == 0, k + 1 == reached.len());
            let writes = span.and_then(|s| s.compute(first, false));
            self.pass
                .encode_region(encoder, scene, view, extent, writes);
            dispatch_over_image(
                encoder,
                "fisheye.cube_store",
                &self.store,
                &[&self.store_groups[i]],
                side,
                span.and_then(|s| s.compute(false, last)),
            );
        }
    }
}

/// Timestamp spans of a cube-map frame (see [`CubeMap::encode`]); any may be `None`.
#[derive(Clone, Copy, Default)]
pub struct CubeSpans<'a> {
    /// Rendering the faces: tracing them, or their raster passes (for deferred faces, the
    /// G-buffer passes).
    pub faces: Option<Span<'a>>,
    /// The deferred faces' lighting pass (written only by [`RasterMethod::Deferred`]).
    pub lighting: Option<Span<'a>>,
    /// Resampling the cube into the lens image.
    pub sampler: Option<Span<'a>>,
}

/// The cube-map path: renders each face the lens can reach (by the tracer or the rasterizer,
/// plus a one-texel border), then a compute pass resamples the cube into the lens image.
pub struct CubeMap {
    regions: [Option<Region>; 6],
    faces: Faces,
    cube: wgpu::Texture,
    sampler: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    colour: wgpu::Buffer,
    camera: LensCamera,
}

impl CubeMap {
    /// The cube for `camera` on `scene`, rendered as `settings` say.
    pub fn new(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        settings: &CubeSettings,
    ) -> Result<Self> {
        if camera.glass.is_some() {
            return Err(Error::Option(
                "a cube map resamples by direction and cannot trace a prescription's glass: \
                 give rays=fit in the lens spec to render its fitted model through a cube map"
                    .into(),
            ));
        }
        if camera.shutter.moves() {
            return Err(Error::Option(
                "a cube map's faces are each one instant: a rolling shutter or an exposure is \
                 traced directly (method rt or rq)"
                    .into(),
            ));
        }
        let size = settings.size;
        let max = ctx.device.limits().max_texture_dimension_2d;
        if size == 0 || bordered(size) > max {
            return Err(Error::Limit(format!(
                "cube face size {size}: must be between 1 and {} (the adapter's limit of {max}, \
                 less the two-texel border)",
                max - 2
            )));
        }
        ctx.check_image(camera.size)?;
        let side = bordered(size);
        ctx.check_binding(
            "the cube-map colour output",
            16 * camera.size.pixels() as u64,
        )?;
        let mut regions = face_regions(resampled_directions(camera, size), size);
        if settings.coverage == Coverage::WholeFaces {
            for r in regions.iter_mut().flatten() {
                *r = Region {
                    x0: 0,
                    y0: 0,
                    x1: side,
                    y1: side,
                };
            }
        }
        // A texture array, not a storage buffer: no binding-size limit on the faces.
        let cube = ctx.checked("creating the cube faces", || {
            texture_array(
                &ctx.device,
                "fisheye.cube.faces",
                side,
                6,
                wgpu::TextureFormat::Rgba32Float,
                wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_SRC,
            )
        })?;
        let faces = match settings.method {
            CubeMethod::Traced => {
                Faces::Traced(Box::new(TracedFaces::new(ctx, scene, size, &cube)?))
            }
            CubeMethod::Raster(method) => Faces::Raster(Box::new(RasterFaces::new(
                ctx,
                scene,
                size,
                regions,
                method,
                settings.shadow_size,
                &cube,
            )?)),
        };
        ctx.checked("creating the cube-map sampler", || {
            let device = &ctx.device;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.cube_sample"),
                // The lens as wgsl/primary.wgsl declares it, faces, output.
                entries: &[
                    uniform_entry(0),
                    wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2Array,
                            multisampled: false,
                        },
                        count: None,
                    },
                    storage_entry(3, false),
                ],
            });
            let [kind, formula] = lens_constants(camera);
            let constants = [kind, formula, ("MOST_TAPS", f64::from(MOST_TAPS))];
            let sampler =
                shader::compute_pipeline(device, "cube_sample", "main", &constants, &[&layout]);
            let buffer = |label: &str, bytes: u64, usage: wgpu::BufferUsages| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes,
                    usage,
                    mapped_at_creation: false,
                })
            };
            use wgpu::BufferUsages as U;
            let colour = buffer(
                "fisheye.cube.colour",
                16 * camera.size.pixels() as u64,
                U::STORAGE | U::COPY_SRC,
            );
            let lens = params_buffer(device, camera);
            let faces_view = layer_view(&cube, None);
            let bind_group = bind_group_at(
                device,
                "fisheye.cube_sample",
                &layout,
                [
                    (0, lens.as_entire_binding()),
                    (2, wgpu::BindingResource::TextureView(&faces_view)),
                    (3, colour.as_entire_binding()),
                ],
            );
            Self {
                regions,
                faces,
                cube,
                sampler,
                bind_group,
                colour,
                camera: *camera,
            }
        })
    }

    /// The rendered part of each face (in [`FACES`] order), `None` for faces the lens never
    /// reaches.
    pub fn regions(&self) -> [Option<Region>; 6] {
        self.regions
    }

    /// The texels its faces render a frame: those of every face's rendered part.
    pub fn texels_rendered(&self) -> u64 {
        self.regions
            .iter()
            .flatten()
            .map(|r| u64::from(r.x1 - r.x0) * u64::from(r.y1 - r.y0))
            .sum()
    }

    /// The rasterized faces' shadow maps (`None` for traced faces).
    pub fn shadow_maps(&self) -> Option<&crate::raster::ShadowMaps> {
        match &self.faces {
            Faces::Traced(_) => None,
            Faces::Raster(r) => Some(r.shadows()),
        }
    }

    /// Whether a frame has a deferred lighting pass (timed by [`CubeSpans::lighting`]).
    pub fn has_lighting_pass(&self) -> bool {
        matches!(&self.faces, Faces::Raster(r) if r.method() == RasterMethod::Deferred)
    }

    /// Points the cube at `pose` and records a frame into `encoder`: the reachable faces (or
    /// parts), then the resampling into the lens image. Submit `encoder` before the next call.
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pose: &Camera,
        spans: CubeSpans<'_>,
    ) {
        match &self.faces {
            Faces::Traced(faces) => {
                faces.encode(ctx, encoder, scene, pose, &self.regions, spans.faces)
            }
            Faces::Raster(faces) => {
                faces.set_pose(ctx, scene, pose);
                faces.encode(encoder, scene, spans.faces, spans.lighting);
            }
        }
        dispatch_over_image(
            encoder,
            "fisheye.cube_sample",
            &self.sampler,
            &[&self.bind_group],
            self.camera.size,
            spans.sampler.and_then(|s| s.compute(true, true)),
        );
    }

    /// The lens camera the cube is resampled for.
    pub fn camera(&self) -> &LensCamera {
        &self.camera
    }

    /// The lens image's colour output (as
    /// [`RenderOutput::colour`](crate::trace::RenderOutput::colour)), for passes that read it
    /// on the GPU.
    pub fn colour_buffer(&self) -> &wgpu::Buffer {
        &self.colour
    }

    /// The lens image's colours of the last submitted frame (as
    /// [`RenderOutput::colour`](crate::trace::RenderOutput::colour)).
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>> {
        ctx.read_buffer(&self.colour)
    }

    /// Renders one frame from `pose` in one submission and reads the lens image back (as
    /// [`CubeMap::read`]).
    pub fn render(
        &self,
        ctx: &GpuContext,
        scene: &GpuScene,
        pose: &Camera,
    ) -> Result<Vec<[f32; 4]>> {
        ctx.checked("rendering the cube map", || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(ctx, &mut encoder, scene, pose, CubeSpans::default());
            ctx.queue.submit([encoder.finish()]);
        })?;
        self.read(ctx)
    }

    /// The faces of the last render: `6 × (size + 2)²` texels, row-major per face (texels
    /// outside the regions hold nothing meaningful).
    pub fn texels(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>> {
        ctx.read_texture(&self.cube)
    }
}

/// Runs `wgsl/cube.wgsl`'s face selection on the GPU for each direction.
pub fn face_uv_gpu(ctx: &GpuContext, directions: &[Vec3]) -> Result<Vec<(u32, Vec2)>> {
    let input: Vec<[f32; 4]> = directions.iter().map(|d| [d.x, d.y, d.z, 0.0]).collect();
    ctx.check_binding("the probe directions", 16 * input.len() as u64)?;
    let out = ctx.checked("probing cube faces", || {
        let device = &ctx.device;
        let pipeline = shader::compute_pipeline(device, "cube_probe", "main", &[], &[]);
        let points = crate::gpu::buffer_init(
            device,
            "fisheye.cube_probe.directions",
            bytemuck::cast_slice(&input),
            wgpu::BufferUsages::STORAGE,
        );
        let results = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fisheye.cube_probe.results"),
            size: points.size(),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind_group = bind_buffers(
            device,
            "fisheye.cube_probe",
            &pipeline.get_bind_group_layout(0),
            &[&points, &results],
        );
        crate::gpu::submit_over_elements(ctx, &pipeline, &bind_group, input.len());
        results
    })?;
    let raw: Vec<[f32; 4]> = ctx.read_buffer(&out)?;
    Ok(raw
        .into_iter()
        .map(|v| (v[0].to_bits(), Vec2::new(v[1], v[2])))
        .collect())
}
