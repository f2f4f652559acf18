//! Rendering inside an application's own frame loop: a [`Renderer`] is made on the caller's
//! `wgpu::Device` and `Queue`, records each frame into the caller's `CommandEncoder`, and
//! writes the image into the caller's texture, with no submission, no wait and no copy to the
//! CPU. The scene is uploaded once; moving the camera between frames records an 80-byte copy.
//!
//! ```no_run
//! # fn main() -> Result<(), fisheye_rt::Error> {
//! use fisheye_rt::lens::{parse_spec, ImageSize, LensCamera};
//! use fisheye_rt::renderer::Renderer;
//! use fisheye_rt::scene::builtin;
//! use fisheye_rt::trace::RenderOptions;
//! # let (device, queue): (wgpu::Device, wgpu::Queue) = unimplemented!();
//! // `device` and `queue` are the application's own, created with (at least)
//! // `fisheye_rt::renderer::required_limits()`.
//! let scene = builtin::scene("default").expect("a built-in scene");
//! let camera = LensCamera::new(parse_spec("samyang-7.5mm")?, ImageSize::new(640, 480)?);
//! let format = wgpu::TextureFormat::Rgba16Float;
//! let renderer = Renderer::new(&device, &queue, &scene, &camera, &RenderOptions::default(), format)?;
//! let target = device.create_texture(&wgpu::TextureDescriptor {
//!     label: Some("fisheye view"),
//!     size: wgpu::Extent3d { width: 640, height: 480, depth_or_array_layers: 1 },
//!     mip_level_count: 1,
//!     sample_count: 1,
//!     dimension: wgpu::TextureDimension::D2,
//!     format,
//!     usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
//!     view_formats: &[],
//! });
//! let mut encoder = device.create_command_encoder(&Default::default());
//! renderer.encode(&mut encoder, &scene.camera, &target)?; // a frame, into `target`
//! // ... the application's own passes read `target`, then it submits when it likes:
//! queue.submit([encoder.finish()]);
//! # Ok(()) }
//! ```

mod offscreen;

pub use offscreen::{FrameTime, Offscreen, Pass, SceneSet, Setup};

use crate::cube::{CubeMap, CubeMethod, CubeSettings, CubeSpans};
use std::sync::Mutex;

use crate::error::{Error, Result};
use crate::gpu::{GpuContext, bind_group, dispatch_over_image, storage_entry};
use crate::lens::LensCamera;
use crate::lens::gpu::DirectionSource;
use crate::raster::RasterMethod;
use crate::scene::{Camera, Scene};
use crate::shader;
use crate::shared::{ADAPTIVE_STORAGE_BUFFERS, TRACE_STORAGE_BUFFERS};
use crate::trace::{
    Adaptive, AdaptivePass, AdaptiveSpans, GpuScene, PixelFilter, RenderOptions, RenderOutput,
    TracePass, Traversal,
};

/// The limits a device needs for the renderer: wgpu's downlevel defaults, with the storage
/// buffers the trace kernel binds and one more, for the direction table or adaptive
/// sampling's work buffer (both together bind one more again): 8, WebGPU's default. Ask for
/// these (or the adapter's own) when creating the device; ray queries also need
/// `Features::EXPERIMENTAL_RAY_QUERY` and the adapter's acceleration-structure limits.
pub fn required_limits() -> wgpu::Limits {
    wgpu::Limits {
        max_storage_buffers_per_shader_stage: TRACE_STORAGE_BUFFERS + ADAPTIVE_STORAGE_BUFFERS,
        ..wgpu::Limits::downlevel_defaults()
    }
}

/// A way of making the lens image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Direct ray tracing of the lens's rays, software BVH traversal.
    Rt,
    /// Direct ray tracing with the adapter's hardware ray queries.
    Rq,
    /// A cube map, rendered as the method says, then resampled.
    Cube(CubeMethod),
}

impl Method {
    /// Every method, in the order reports list them.
    pub const ALL: [Method; 6] = [
        Method::Rt,
        Method::Rq,
        Method::Cube(CubeMethod::Traced),
        Method::Cube(CubeMethod::Raster(RasterMethod::Forward)),
        Method::Cube(CubeMethod::Raster(RasterMethod::Deferred)),
        Method::Cube(CubeMethod::Raster(RasterMethod::SinglePass)),
    ];

    /// The name `fisheye render --method` takes: `rt`, `rq`, `cube-rt`, `cube-forward`, ...
    pub fn name(&self) -> &'static str {
        match self {
            Method::Rt => "rt",
            Method::Rq => "rq",
            Method::Cube(m) => m.name(),
        }
    }

    /// The method called `name` (as [`Method::name`] writes it).
    pub fn from_name(name: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The cube-map method, `None` for direct tracing.
    pub fn cube(&self) -> Option<CubeMethod> {
        match self {
            Method::Cube(m) => Some(*m),
            _ => None,
        }
    }

    /// The BVH traversal the method's scene needs.
    pub fn traversal(&self) -> Traversal {
        match self {
            Method::Rq => Traversal::RayQuery,
            _ => Traversal::Software,
        }
    }

    /// The device feature the method needs that `ctx` lacks, by name, if any (setting the
    /// method up then fails with [`Error::MissingFeature`]).
    pub fn missing_feature(&self, ctx: &GpuContext) -> Option<&'static str> {
        let (feature, name) = match self {
            Method::Rq => (wgpu::Features::EXPERIMENTAL_RAY_QUERY, "ray queries"),
            Method::Cube(CubeMethod::Raster(RasterMethod::SinglePass)) => {
                (wgpu::Features::MULTIVIEW, "multiview")
            }
            _ => return None,
        };
        (!ctx.has(feature)).then_some(name)
    }
}

/// The texture formats a [`Renderer`] writes, with their WGSL names: linear radiance in the
/// float formats, sRGB-encoded display values (as the PNG) in `Rgba8Unorm`; alpha is the lens
/// mask (1 where a pixel has a ray, 0 where not). Storage textures cannot be sRGB formats, so
/// the encoding is done in the kernel.
pub const TARGET_FORMATS: [(wgpu::TextureFormat, &str); 3] = [
    (wgpu::TextureFormat::Rgba8Unorm, "rgba8unorm"),
    (wgpu::TextureFormat::Rgba16Float, "rgba16float"),
    (wgpu::TextureFormat::Rgba32Float, "rgba32float"),
];

/// How a frame is made, set up for one lens on one scene: the one dispatch that
/// [`Renderer`] and the `fisheye` tool's commands (`render`, `bench`, `compare`) share.
pub(crate) enum Path {
    /// Tracing the lens's rays (software traversal or ray queries, as the scene was built).
    Direct(Box<TracePass>),
    /// Tracing them where the image needs them (adaptive sampling).
    Adaptive(Box<AdaptivePass>),
    /// Through a cube map (faces traced or rasterized, then resampled).
    Cube(Box<CubeMap>),
}

/// How a frame's passes are timed: a traced frame's one pass, an adaptive frame's stages, a
/// traced frame's filter, a cube map's passes.
#[derive(Default)]
pub(crate) struct Spans<'a> {
    pub(crate) trace: Option<wgpu::ComputePassTimestampWrites<'a>>,
    pub(crate) filter: Option<wgpu::ComputePassTimestampWrites<'a>>,
    pub(crate) adaptive: AdaptiveSpans<'a>,
    pub(crate) cube: CubeSpans<'a>,
}

impl Path {
    /// Direct tracing with `directions` and `spp` rays per pixel (adaptively where `adaptive`
    /// says), its colours made as `filter` says, or a cube map made as `cube` says.
    pub(crate) fn new(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        (directions, spp, adaptive, filter): (DirectionSource, u32, Option<Adaptive>, PixelFilter),
        cube: Option<&CubeSettings>,
    ) -> Result<Self> {
        Ok(match (cube, adaptive) {
            (Some(settings), _) => {
                Path::Cube(Box::new(CubeMap::new(ctx, camera, scene, settings)?))
            }
            (None, Some(adaptive)) => {
                let mut pass = AdaptivePass::new(ctx, camera, scene, directions, spp, adaptive)?;
                pass.set_filter(ctx, filter)?;
                Path::Adaptive(Box::new(pass))
            }
            (None, None) => {
                let mut pass = TracePass::supersampled(ctx, camera, scene, directions, spp)?;
                pass.set_filter(ctx, filter)?;
                Path::Direct(Box::new(pass))
            }
        })
    }

    /// Records a frame from `pose`, its passes timed by `spans`.
    pub(crate) fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pose: &Camera,
        spans: Spans<'_>,
    ) {
        match self {
            Path::Direct(pass) => {
                pass.encode_pose(&ctx.device, encoder, scene, pose);
                pass.encode(encoder, scene, spans.trace);
            }
            Path::Adaptive(pass) => {
                pass.encode_pose(&ctx.device, encoder, scene, pose);
                pass.encode(encoder, scene, spans.adaptive);
            }
            Path::Cube(cube) => cube.encode(ctx, encoder, scene, pose, spans.cube),
        }
        if let Some(pass) = self.trace_pass() {
            pass.encode_filter(encoder, spans.filter);
        }
    }

    /// The trace pass whose buffers hold a traced frame's outputs.
    fn trace_pass(&self) -> Option<&TracePass> {
        match self {
            Path::Direct(pass) => Some(pass),
            Path::Adaptive(pass) => Some(pass.trace_pass()),
            Path::Cube(_) => None,
        }
    }

    /// The lens image's colour output (linear RGB, w = the mask).
    pub(crate) fn colour_buffer(&self) -> &wgpu::Buffer {
        match self {
            Path::Direct(pass) => pass.colour_buffer(),
            Path::Adaptive(pass) => pass.trace_pass().colour_buffer(),
            Path::Cube(cube) => cube.colour_buffer(),
        }
    }

    /// The last frame's outputs, read back: every output of a traced frame, the colour alone
    /// (geometry zero, ids `NO_HIT`) through a cube map.
    pub(crate) fn read(&self, ctx: &GpuContext) -> Result<RenderOutput> {
        match self {
            Path::Direct(pass) => pass.read(ctx),
            Path::Adaptive(pass) => pass.trace_pass().read(ctx),
            Path::Cube(cube) => {
                let colour = cube.read(ctx)?;
                Ok(RenderOutput {
                    size: cube.camera().size,
                    geometry: vec![[0.0; 4]; colour.len()],
                    ids: vec![crate::shared::NO_HIT; colour.len()],
                    colour,
                })
            }
        }
    }
}

/// A scene and a lens on the caller's device, ready to record frames into the caller's
/// encoders and textures.
pub struct Renderer {
    ctx: GpuContext,
    scene: GpuScene,
    path: Path,
    present: wgpu::ComputePipeline,
    present_layout: wgpu::BindGroupLayout,
    format: wgpu::TextureFormat,
    camera: LensCamera,
    /// Whether the scene was flattened for a rasterized cube map (its instances then stay
    /// where they were loaded).
    flattened: bool,
    /// Progressive refinement's place: the pose its steps are for and the next step's number
    /// (`None` after a whole frame).
    progress: Mutex<Option<(Camera, u32)>>,
    /// The scene time moving instances were last placed at ([`Renderer::place_at`]).
    placed: Mutex<Option<f64>>,
}

impl Renderer {
    /// Builds the BVH, uploads `scene` (relative to its camera) and creates the kernels that
    /// trace `camera`'s rays into textures of `format` (one of [`TARGET_FORMATS`]). Errors
    /// name what the device lacks (a feature the options need, a limit the scene or image
    /// exceeds).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        camera: &LensCamera,
        options: &RenderOptions,
        format: wgpu::TextureFormat,
    ) -> Result<Self> {
        Self::build(device, queue, scene, camera, options, None, format)
    }

    /// As [`Renderer::new`], but making each image the way engines do: through a cube map
    /// whose faces `cube` says how to render (traced or rasterized), then resampled. A cube's
    /// pose is written at submission, so record one cube-map frame per submission.
    pub fn through_cube(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        camera: &LensCamera,
        options: &RenderOptions,
        cube: &CubeSettings,
        format: wgpu::TextureFormat,
    ) -> Result<Self> {
        Self::build(device, queue, scene, camera, options, Some(cube), format)
    }

    fn build(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        camera: &LensCamera,
        options: &RenderOptions,
        cube: Option<&CubeSettings>,
        format: wgpu::TextureFormat,
    ) -> Result<Self> {
        let Some((_, wgsl_format)) = TARGET_FORMATS.iter().find(|(f, _)| *f == format) else {
            return Err(Error::Target(format!(
                "textures of format {format:?}; it writes {}",
                format_names()
            )));
        };
        let mut short = Vec::new();
        required_limits().check_limits_with_fail_fn(&device.limits(), false, |name, need, has| {
            short.push(format!("{name} is {has}, the renderer needs {need}"))
        });
        if !short.is_empty() {
            return Err(Error::Limits(short.join("; ")));
        }
        let ctx = GpuContext::from_device(device, queue);
        let rasterizes = cube.is_some_and(|c| matches!(c.method, CubeMethod::Raster(_)));
        let flat;
        let flattened = rasterizes && scene.is_instanced();
        let scene = if flattened {
            flat = scene.flattened(crate::scene::MAX_FLATTENED)?;
            &flat
        } else {
            scene
        };
        let gpu_scene = GpuScene::new(&ctx, scene, options)?;
        let rays = (
            options.directions,
            options.spp,
            options.adaptive,
            options.filter,
        );
        let path = Path::new(&ctx, camera, &gpu_scene, rays, cube)?;
        let (present, present_layout) = ctx.checked("creating the present pass", || {
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.present"),
                entries: &[
                    storage_entry(0, true),
                    wgpu::BindGroupLayoutEntry {
                        binding: 1,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::StorageTexture {
                            access: wgpu::StorageTextureAccess::WriteOnly,
                            format,
                            view_dimension: wgpu::TextureViewDimension::D2,
                        },
                        count: None,
                    },
                ],
            });
            let encode_srgb = f64::from(u8::from(format == wgpu::TextureFormat::Rgba8Unorm));
            let pipeline = shader::compute_pipeline_edited(
                device,
                "present",
                |source| {
                    source.replace(
                        "texture_storage_2d<rgba32float, write>",
                        &format!("texture_storage_2d<{wgsl_format}, write>"),
                    )
                },
                "main",
                &[("ENCODE_SRGB", encode_srgb)],
                &[&layout],
            );
            (pipeline, layout)
        })?;
        Ok(Self {
            ctx,
            scene: gpu_scene,
            path,
            present,
            present_layout,
            format,
            camera: *camera,
            flattened,
            progress: Mutex::new(None),
            placed: Mutex::new(None),
        })
    }

    /// A texture [`Renderer::encode`] can write: the camera's size, the renderer's format,
    /// usable as a storage texture, sampled, and copied from.
    pub fn target_texture(&self, device: &wgpu::Device) -> wgpu::Texture {
        let size = self.camera.size;
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("fisheye.target"),
            size: wgpu::Extent3d {
                width: size.width,
                height: size.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.format,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    }

    /// The scene as uploaded (its BVH statistics, bounds, features).
    pub fn scene(&self) -> &GpuScene {
        &self.scene
    }

    /// Places the scene's moving instances (glTF animations, scene-file keys) at scene time
    /// `time` for the frames submitted from now on, where `fisheye render --time` poses them,
    /// and starts progressive refinement again; `scene` is the one the renderer was made from.
    /// The meshes' BVHs stay as built: only the top level is rebuilt
    /// ([`GpuScene::place_at`]). Nothing to do where nothing moves, or at the time last
    /// placed (refinement goes on), so a caller may place every frame. Refused through ray
    /// queries and rasterized cube maps, which draw the scene flattened once, as loaded.
    pub fn place_at(&self, scene: &Scene, time: f64) -> Result<()> {
        let mut placed = self.placed.lock().unwrap_or_else(|e| e.into_inner());
        if !scene.moves() || *placed == Some(time) {
            return Ok(());
        }
        if self.flattened {
            return Err(Error::Limit(
                "a rasterized cube map draws the scene flattened once, as loaded; moving \
                 instances are placed by the BVH traversal (direct tracing or a traced cube \
                 map)"
                    .into(),
            ));
        }
        self.scene
            .place_at(&self.ctx, scene, time, self.camera.exposure_span())?;
        *placed = Some(time);
        *self.progress.lock().unwrap_or_else(|e| e.into_inner()) = None;
        Ok(())
    }

    /// Records one frame seen from `pose` into `encoder`, written into `target`: a 2D texture
    /// of the camera's size, of the format given to [`Renderer::new`], with
    /// `STORAGE_BINDING` usage. Frames recorded into one encoder may each have their own pose.
    /// Nothing is submitted. Traced frames leave their geometry and ids in the trace pass's
    /// buffers too (see [`Renderer::outputs`]).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pose: &Camera,
        target: &wgpu::Texture,
    ) -> Result<()> {
        *self.progress.lock().unwrap_or_else(|e| e.into_inner()) = None;
        self.record(encoder, target, |encoder| {
            self.path
                .encode(&self.ctx, encoder, &self.scene, pose, Spans::default());
        })
    }

    /// As [`Renderer::encode`], but refining progressively while the camera stays still: with
    /// adaptive sampling ([`RenderOptions::adaptive`]), the first frame at a new `pose` is the
    /// one below one ray per pixel (as `--spp auto:T:1` makes it, but for the pixels beside
    /// edges that it interpolates, there traced), and each frame recorded at the same pose
    /// after it sharpens it for about one ray per pixel, until the image is the one
    /// [`Renderer::encode`] makes, bit for bit (see [`AdaptivePass::encode_step`]); after
    /// that a frame costs next to nothing. Any other pose starts again. Other samplings and
    /// methods make their whole frame at a new pose and leave it as it is while the pose
    /// stays. Record progressive frames in the order they are submitted.
    pub fn encode_progressive(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pose: &Camera,
        target: &wgpu::Texture,
    ) -> Result<()> {
        self.record(encoder, target, |encoder| {
            let (ctx, scene) = (&self.ctx, &self.scene);
            let mut progress = self.progress.lock().unwrap_or_else(|e| e.into_inner());
            let step = match *progress {
                Some((last, next)) if last == *pose => next,
                _ => 0,
            };
            *progress = Some((*pose, step.saturating_add(1)));
            match (&self.path, step) {
                (Path::Adaptive(pass), _) => {
                    if step == 0 {
                        pass.encode_pose(&ctx.device, encoder, scene, pose);
                    }
                    pass.encode_step(encoder, scene, step);
                    pass.trace_pass().encode_filter(encoder, None);
                }
                (_, 0) => self
                    .path
                    .encode(ctx, encoder, scene, pose, Spans::default()),
                _ => {}
            }
        })
    }

    /// Checks `target`, then records `frame` and the copy of its colour into `target`.
    fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::Texture,
        frame: impl FnOnce(&mut wgpu::CommandEncoder),
    ) -> Result<()> {
        let size = self.camera.size;
        let extent = target.size();
        let wanted = (size.width, size.height, 1);
        if (extent.width, extent.height, extent.depth_or_array_layers) != wanted
            || target.format() != self.format
            || !target
                .usage()
                .contains(wgpu::TextureUsages::STORAGE_BINDING)
            || target.dimension() != wgpu::TextureDimension::D2
        {
            return Err(Error::Target(format!(
                "a texture of {}x{}x{} {:?} texels with usage {:?}; it writes a 2D texture of \
                 {size} {:?} texels with STORAGE_BINDING usage",
                extent.width,
                extent.height,
                extent.depth_or_array_layers,
                target.format(),
                target.usage(),
                self.format
            )));
        }
        self.ctx.checked("recording a frame", || {
            frame(encoder);
            let colour = self.path.colour_buffer();
            let view = target.create_view(&Default::default());
            let group = bind_group(
                &self.ctx.device,
                "fisheye.present",
                &self.present_layout,
                [
                    colour.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&view),
                ],
            );
            dispatch_over_image(
                encoder,
                "fisheye.present",
                &self.present,
                &[&group],
                size,
                None,
            );
        })
    }

    /// The trace pass's buffers, as the last recorded frame left them: colour (linear RGB, w
    /// = the mask), geometry (world normal, w = distance) and ids (`u32`, `NO_HIT` on a miss),
    /// row-major, as [`crate::trace::RenderOutput`] reads them; for passes of the caller's own.
    /// `None` through a cube map, which makes colour alone.
    pub fn outputs(&self) -> Option<[&wgpu::Buffer; 3]> {
        self.path.trace_pass().map(TracePass::buffers)
    }

    /// The last submitted frame's outputs, read back to the CPU (waiting for the device): all
    /// of them for a traced frame, the colour alone (geometry zero, ids `NO_HIT`) through a
    /// cube map. For screenshots and tests, not for every frame.
    pub fn read_back(&self) -> Result<RenderOutput> {
        self.path.read(&self.ctx)
    }
}

fn format_names() -> String {
    TARGET_FORMATS
        .iter()
        .map(|(f, _)| format!("{f:?}"))
        .collect::<Vec<_>>()
        .join(", ")
}
