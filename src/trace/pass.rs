//! The trace kernel for one lens, image size and scene ([`TracePass`]): its pipeline, its
//! frame uniforms (one slot a view) and its outputs, traced in bands of rows where the image's
//! outputs exceed one storage binding.

use super::gpu_scene::{frame_for, view_frame};
use super::options::surface_constants;
use super::{GpuScene, Motion, PixelFilter, RenderOutput, Sampling, Tent, sampling};
use crate::error::{Error, Result};
use crate::gpu::{GpuContext, bind_group_at, dispatch_over_image, storage_entry, uniform_entry};
use crate::lens::LensCamera;
use crate::lens::gpu::{DirectionSource, LensRays, lens_constants, params_buffer};
use crate::scene::Camera;
use crate::shader;
use crate::shared::{Frame, TRACE_STORAGE_BUFFERS};
use glam::{DMat3, DVec3};
use std::sync::OnceLock;

/// Bytes between the frame uniforms of a [`TracePass`]'s views: the frame rounded up to
/// wgpu's default (and largest) `min_uniform_buffer_offset_alignment`, 256.
const FRAME_SLOT: u64 = size_of::<Frame>().div_ceil(256) as u64 * 256;

/// `frame` for each band of output rows `(first row, rows)`: its dispatch starts at the
/// band's first row, and its outputs hold rows from there on (one band from row 0: the frame
/// itself).
fn band_frames(bands: &[(u32, u32)], frame: Frame) -> Vec<Frame> {
    bands
        .iter()
        .map(|&(first, _)| {
            let mut band = frame;
            band.offset = [0, first, 0, first];
            band
        })
        .collect()
}

/// The trace kernel for one lens, image size and scene: owns its pipeline, its frame bind
/// group (group 0) and its outputs; records one frame per [`TracePass::encode`].
pub struct TracePass {
    /// The kernel, specialised to the lens, the direction source and the scene's features:
    /// made with the pass, or at its first frame for a pass whose outputs other kernels write
    /// ([`TracePass::deferred`]).
    pipeline: OnceLock<wgpu::ComputePipeline>,
    /// What the kernel is made with: the device, group 0's layout, the direction source.
    device: wgpu::Device,
    layout: wgpu::BindGroupLayout,
    source: DirectionSource,
    /// One bind group per view, each with its slot of `frame`.
    bind_groups: Vec<wgpu::BindGroup>,
    /// The outputs the kernel writes: the whole image's, or one band's.
    colour: wgpu::Buffer,
    geometry: wgpu::Buffer,
    ids: wgpu::Buffer,
    frame: wgpu::Buffer,
    /// The lens parameters and the direction table (where directions are read from one), for
    /// kernels that share the trace kernel's group 0 (`AdaptivePass`).
    lens: wgpu::Buffer,
    table: Option<wgpu::Buffer>,
    /// The camera's glass (zeros without: `GLASS` is off then).
    glass: wgpu::Buffer,
    constants: Vec<(&'static str, f64)>,
    samples_per_side: u32,
    camera: LensCamera,
    /// The bands of rows traced one after another, `(first row, rows)`: one for an image
    /// whose outputs fit one storage binding.
    bands: Vec<(u32, u32)>,
    /// With several bands, the whole image's outputs, each band copied in after its dispatch.
    whole: Option<[wgpu::Buffer; 3]>,
    /// The tent filter, where set ([`TracePass::set_filter`]): the colour output is then its.
    tent: Option<Tent>,
}

impl TracePass {
    /// Creates the pipeline (specialised to the lens, direction source and the scene's
    /// features) and the output buffers; with [`DirectionSource::Table`] also computes the
    /// direction table once.
    pub fn new(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
    ) -> Result<Self> {
        Self::with_views(ctx, camera, scene, source, 1, 1)
    }

    /// As [`TracePass::new`], with `spp` rays per pixel (a square; see [`sampling`]): the
    /// colour is their mean over those the lens covers, its `w` the covered share.
    pub fn supersampled(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
        spp: u32,
    ) -> Result<Self> {
        let side = sampling::samples_per_side(spp)?;
        Self::with_views(ctx, camera, scene, source, 1, side)
    }

    /// As [`TracePass::new`], with `views` camera poses (numbered from 0) that can be set
    /// before one submission and traced in it, as the faces of a cube map are, and
    /// `samples_per_side`² rays per pixel.
    pub fn with_views(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
        views: u32,
        samples_per_side: u32,
    ) -> Result<Self> {
        let pass = Self::outputs(ctx, camera, scene, source, views, samples_per_side)?;
        ctx.checked("creating the trace kernel", || {
            pass.pipeline(scene);
        })?;
        Ok(pass)
    }

    /// As [`TracePass::supersampled`], with the kernel made at the first frame that traces
    /// (if one ever does) rather than now: for passes whose own kernels write this one's
    /// outputs (adaptive sampling's), which compiling the kernel too would only slow.
    pub(crate) fn deferred(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
        spp: u32,
    ) -> Result<Self> {
        let side = sampling::samples_per_side(spp)?;
        Self::outputs(ctx, camera, scene, source, 1, side)
    }

    /// The pass's buffers and bind groups, its kernel not yet made (`TracePass::pipeline`).
    fn outputs(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
        views: u32,
        samples_per_side: u32,
    ) -> Result<Self> {
        ctx.check_image(camera.size)?;
        let pixels = camera.size.pixels() as u64;
        let bands = output_bands(ctx, camera.size, views)?;
        // Rows in the largest band: what the kernel's outputs hold.
        let band_pixels = u64::from(camera.size.width) * u64::from(bands[0].1);
        let needed = TRACE_STORAGE_BUFFERS + source.storage_buffers();
        check_storage_buffers(ctx, scene, needed, "the trace kernel")?;
        let table = LensRays::for_source(ctx, camera, source)?;
        ctx.checked("creating the trace pass", || {
            let device = &ctx.device;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.trace.frame"),
                entries: &shared_entries(source),
            });
            let constants = trace_constants(camera, scene, samples_per_side);
            let output = |label: &str, bytes: u64, usage: wgpu::BufferUsages| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | usage,
                    mapped_at_creation: false,
                })
            };
            let none = wgpu::BufferUsages::empty();
            let colour = output("fisheye.trace.colour", 16 * band_pixels, none);
            let geometry = output("fisheye.trace.geometry", 16 * band_pixels, none);
            let ids = output("fisheye.trace.ids", 4 * band_pixels, none);
            let whole = (bands.len() > 1).then(|| {
                let into = wgpu::BufferUsages::COPY_DST;
                [
                    output("fisheye.trace.colour.whole", 16 * pixels, into),
                    output("fisheye.trace.geometry.whole", 16 * pixels, into),
                    output("fisheye.trace.ids.whole", 4 * pixels, into),
                ]
            });
            // A slot per view, or per band (each band's frame starts at its first row).
            let frames = match bands.len() {
                1 => vec![scene.frame; views as usize],
                _ => band_frames(&bands, scene.frame),
            };
            let slots = frame_slots(&frames);
            let frame = crate::gpu::buffer_init(
                device,
                "fisheye.trace.frame",
                &slots,
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            );
            let table = table.map(|t| t.directions);
            let lens = params_buffer(device, camera);
            let glass = glass_buffer(device, camera);
            let bind_groups = (0..frames.len() as u64)
                .map(|view| {
                    let slot = wgpu::BufferBinding {
                        buffer: &frame,
                        offset: view * FRAME_SLOT,
                        size: wgpu::BufferSize::new(size_of::<Frame>() as u64),
                    };
                    let resources = [
                        lens.as_entire_binding(),
                        wgpu::BindingResource::Buffer(slot),
                        colour.as_entire_binding(),
                        geometry.as_entire_binding(),
                        ids.as_entire_binding(),
                        glass.as_entire_binding(),
                    ];
                    let table = table.as_ref().map(|t| t.as_entire_binding());
                    bind_group_at(
                        device,
                        "fisheye.trace.frame",
                        &layout,
                        numbered_shared(resources, table),
                    )
                })
                .collect();
            Self {
                pipeline: OnceLock::new(),
                device: device.clone(),
                layout,
                source,
                bind_groups,
                colour,
                geometry,
                ids,
                frame,
                lens,
                table,
                glass,
                constants,
                samples_per_side,
                camera: *camera,
                bands,
                whole,
                tent: None,
            }
        })
    }

    /// The kernel for `scene` (the pass's own), made at its first use.
    fn pipeline(&self, scene: &GpuScene) -> &wgpu::ComputePipeline {
        self.pipeline.get_or_init(|| {
            let mut layouts = vec![&self.layout, &scene.layout];
            let file = match &scene.ray_query {
                Some(rq) => {
                    layouts.push(&rq.layout);
                    "trace_rq"
                }
                None => "trace",
            };
            let composed = (&scene.arrays, self.source.swaps());
            let constants = &self.constants;
            shader::scene_pipeline(&self.device, file, composed, "main", constants, &layouts)
        })
    }

    /// Moves the camera to `pose` for the frames encoded from now on (a camera path). The scene
    /// stays where it was uploaded, relative to its own camera, so poses far from it lose the
    /// precision that relative upload buys; paths through a scene are fine.
    pub fn set_pose(&self, ctx: &GpuContext, scene: &GpuScene, pose: &Camera) {
        let frames = band_frames(&self.bands, frame_for(scene.origin, pose));
        ctx.queue
            .write_buffer(&self.frame, 0, &frame_slots(&frames));
    }

    /// As [`TracePass::set_pose`] for view number `view` (see [`TracePass::with_views`]), with
    /// the camera-to-world rotation given (columns: the camera's right, down and forward axes
    /// in world space), and the first pixel that [`TracePass::encode_region`] traces.
    pub fn set_view(
        &self,
        ctx: &GpuContext,
        scene: &GpuScene,
        view: u32,
        eye: DVec3,
        rotation: DMat3,
        offset: [u32; 2],
    ) {
        let frame = view_frame(scene.origin, eye, rotation, offset);
        ctx.queue.write_buffer(
            &self.frame,
            u64::from(view) * FRAME_SLOT,
            bytemuck::bytes_of(&frame),
        );
    }

    /// Records a move of the camera to `pose` into `encoder`, for the frames recorded after
    /// it: a copy of the frame from a new buffer, so frames recorded into one encoder may each
    /// have their own pose (see [`TracePass::set_pose`] for precision).
    pub fn encode_pose(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pose: &Camera,
    ) {
        self.encode_frame(device, encoder, frame_for(scene.origin, pose));
    }

    /// As [`TracePass::encode_pose`] for a camera moving by `motion` while the frame is read
    /// out and exposed, as the camera's [`crate::lens::Shutter`] says (at the stamp for a
    /// global shutter exposed for an instant). Errors where the motion's knots are bad.
    pub fn encode_motion(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        motion: &Motion,
    ) -> Result<()> {
        let frame = motion.frame(scene.origin, &self.camera.shutter)?;
        self.encode_frame(device, encoder, frame);
        Ok(())
    }

    fn encode_frame(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        frame: Frame,
    ) {
        let slots = frame_slots(&band_frames(&self.bands, frame));
        let staging = crate::gpu::buffer_init(
            device,
            "fisheye.trace.pose",
            &slots,
            wgpu::BufferUsages::COPY_SRC,
        );
        encoder.copy_buffer_to_buffer(&staging, 0, &self.frame, 0, slots.len() as u64);
    }

    /// The override constants of the trace kernel (lens, surfaces, direction source,
    /// samples per pixel side): kernels that trace as it does are specialised the same way.
    pub(crate) fn constants(&self) -> &[(&'static str, f64)] {
        &self.constants
    }

    /// Group 0's shared bindings as `wgsl/pixel.wgsl` declares them (lens, table where there
    /// is one, the first view's frame, colour, geometry, ids, glass), each with its binding,
    /// for kernels that trace as this pass does. Only for an image traced in one band.
    pub(crate) fn shared_bindings(&self) -> Vec<(u32, wgpu::BindingResource<'_>)> {
        let resources = [
            self.lens.as_entire_binding(),
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &self.frame,
                offset: 0,
                size: wgpu::BufferSize::new(size_of::<Frame>() as u64),
            }),
            self.colour.as_entire_binding(),
            self.geometry.as_entire_binding(),
            self.ids.as_entire_binding(),
            self.glass.as_entire_binding(),
        ];
        let table = self.table.as_ref().map(|t| t.as_entire_binding());
        numbered_shared(resources, table)
    }

    /// The colour output of the last frame (as [`RenderOutput::colour`]), for passes that
    /// read it on the GPU.
    pub fn colour_buffer(&self) -> &wgpu::Buffer {
        self.buffers()[0]
    }

    /// The colour, geometry and id outputs of the last frame (as [`RenderOutput`] reads them):
    /// the colour filtered where a filter is set ([`TracePass::encode_filter`] writes it).
    /// For an image traced in bands these are larger than one storage binding: bind a range.
    pub fn buffers(&self) -> [&wgpu::Buffer; 3] {
        let [colour, geometry, ids] = match &self.whole {
            Some([colour, geometry, ids]) => [colour, geometry, ids],
            None => [&self.colour, &self.geometry, &self.ids],
        };
        let colour = self.tent.as_ref().map_or(colour, Tent::colour_buffer);
        [colour, geometry, ids]
    }

    /// Makes each frame's colour output as `filter` says from now on (recorded by
    /// [`TracePass::encode_filter`] after the frame's rays, or after adaptive sampling's
    /// stages, which trace into this pass's outputs). The tent changes frames of one ray a
    /// pixel (at most, for adaptive sampling) alone: with more, each pixel keeps its samples'
    /// mean. It reads the whole image in one binding: refused for an image traced in bands.
    pub fn set_filter(&mut self, ctx: &GpuContext, filter: PixelFilter) -> Result<()> {
        self.tent = match filter {
            PixelFilter::Box => None,
            _ if !filter.applies_to(Sampling::Uniform(self.samples_per_side.pow(2))) => None,
            PixelFilter::Tent if self.bands.len() > 1 => {
                return Err(Error::Limit(format!(
                    "the tent filter of a {} image: its outputs exceed one storage binding of \
                     this device; use a smaller image or --filter box",
                    self.camera.size
                )));
            }
            PixelFilter::Tent => Some(Tent::new(ctx, self.camera.size, &self.colour)?),
        };
        Ok(())
    }

    /// The filter each frame's colour goes through (the box where pixels take more rays).
    pub fn filter(&self) -> PixelFilter {
        match self.tent {
            Some(_) => PixelFilter::Tent,
            None => PixelFilter::Box,
        }
    }

    /// Records the filter of the frame's colours, after its rays (nothing with the box
    /// filter: the kernels' means are the colours), optionally timed.
    pub fn encode_filter(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        if let Some(tent) = &self.tent {
            tent.encode(encoder, timestamp_writes);
        }
    }

    /// The side of the grid of samples each pixel takes.
    pub fn samples_per_side(&self) -> u32 {
        self.samples_per_side
    }

    /// The image size.
    pub fn size(&self) -> crate::lens::ImageSize {
        self.camera.size
    }

    /// How many bands of rows a frame is traced in: 1 unless the image's outputs exceed one
    /// storage binding.
    pub fn bands(&self) -> usize {
        self.bands.len()
    }

    /// Records one frame, optionally timed: one dispatch, or one per band, each band's
    /// outputs copied into the whole image's after it (the timestamps span them all).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let Some(whole) = &self.whole else {
            self.encode_region(encoder, scene, 0, self.camera.size, timestamp_writes);
            return;
        };
        let width = self.camera.size.width;
        let last = self.bands.len() - 1;
        for (band, &(first, rows)) in self.bands.iter().enumerate() {
            let writes = timestamp_writes
                .as_ref()
                .filter(|_| band == 0 || band == last)
                .map(|w| wgpu::ComputePassTimestampWrites {
                    query_set: w.query_set,
                    beginning_of_pass_write_index: w
                        .beginning_of_pass_write_index
                        .filter(|_| band == 0),
                    end_of_pass_write_index: w.end_of_pass_write_index.filter(|_| band == last),
                });
            let extent = crate::lens::ImageSize::new(width, rows).expect("a band has rows");
            self.encode_region(encoder, scene, band as u32, extent, writes);
            let pixels = u64::from(width) * u64::from(rows);
            let from = u64::from(width) * u64::from(first);
            for (out, into, bytes) in [
                (&self.colour, &whole[0], 16),
                (&self.geometry, &whole[1], 16),
                (&self.ids, &whole[2], 4),
            ] {
                encoder.copy_buffer_to_buffer(out, 0, into, from * bytes, pixels * bytes);
            }
        }
    }

    /// Records a frame of view `view` of only the `extent` pixels from the offset given to
    /// [`TracePass::set_view`] (the whole image from a zero offset); the other pixels keep what
    /// they had.
    pub fn encode_region(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        view: u32,
        extent: crate::lens::ImageSize,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let mut groups = vec![&self.bind_groups[view as usize], &scene.bind_group];
        if let Some(rq) = &scene.ray_query {
            groups.push(&rq.bind_group);
        }
        dispatch_over_image(
            encoder,
            "fisheye.trace",
            self.pipeline(scene),
            &groups,
            extent,
            timestamp_writes,
        );
    }

    /// Traces one frame, reporting a GPU error as `what` failing, and reads it back.
    pub fn trace(&self, ctx: &GpuContext, scene: &GpuScene, what: &str) -> Result<RenderOutput> {
        ctx.checked(what, || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, scene, None);
            self.encode_filter(&mut encoder, None);
            ctx.queue.submit([encoder.finish()]);
        })?;
        self.read(ctx)
    }

    /// Reads the last frame's outputs back.
    pub fn read(&self, ctx: &GpuContext) -> Result<RenderOutput> {
        let [colour, geometry, ids] = self.buffers();
        Ok(RenderOutput {
            size: self.camera.size,
            colour: ctx.read_buffer(colour)?,
            geometry: ctx.read_buffer(geometry)?,
            ids: ctx.read_buffer(ids)?,
        })
    }
}

/// Group 0's entries that every kernel tracing a pixel binds, as `wgsl/primary.wgsl` (or
/// `wgsl/primary_table.wgsl`) and `wgsl/pixel.wgsl` declare them: the lens, the direction
/// table where `source` reads one, the frame, the colour, geometry and id outputs, the glass.
pub(crate) fn shared_entries(source: DirectionSource) -> Vec<wgpu::BindGroupLayoutEntry> {
    let table = (source == DirectionSource::Table).then(|| storage_entry(1, true));
    let entries = [
        uniform_entry(0),
        uniform_entry(2),
        storage_entry(3, false),
        storage_entry(4, false),
        storage_entry(5, false),
        uniform_entry(6),
    ];
    let mut entries = entries.to_vec();
    entries.extend(table);
    entries
}

/// The resources of [`shared_entries`] with their bindings: `resources` (lens, frame, colour,
/// geometry, ids, glass) and the table, if any, at 1.
fn numbered_shared<'a>(
    resources: [wgpu::BindingResource<'a>; 6],
    table: Option<wgpu::BindingResource<'a>>,
) -> Vec<(u32, wgpu::BindingResource<'a>)> {
    let bindings = [0, 2, 3, 4, 5, 6].into_iter().zip(resources);
    bindings.chain(table.map(|t| (1, t))).collect()
}

/// Refuses a kernel that binds `needed` storage buffers beside the scene's extra chunks on a
/// device with fewer a shader stage, naming `kernel`.
pub(crate) fn check_storage_buffers(
    ctx: &GpuContext,
    scene: &GpuScene,
    needed: u32,
    kernel: &str,
) -> Result<()> {
    let needed = needed + scene.arrays.extra_bindings();
    let has = ctx.device.limits().max_storage_buffers_per_shader_stage;
    if needed > has {
        return Err(Error::Limit(format!(
            "{kernel} binds {needed} storage buffers, above this device's limit of {has} per \
             shader stage"
        )));
    }
    Ok(())
}

/// The uniform of `camera`'s glass, zeros where it has none (`GLASS` is off then).
fn glass_buffer(device: &wgpu::Device, camera: &LensCamera) -> wgpu::Buffer {
    let params = camera.glass.unwrap_or_else(bytemuck::Zeroable::zeroed);
    crate::gpu::buffer_init(
        device,
        "fisheye.trace.glass",
        bytemuck::bytes_of(&params),
        wgpu::BufferUsages::UNIFORM,
    )
}

/// The overrides of a kernel that traces `camera`'s rays in `scene` as the trace kernel does.
fn trace_constants(
    camera: &LensCamera,
    scene: &GpuScene,
    samples_per_side: u32,
) -> Vec<(&'static str, f64)> {
    let mut constants = lens_constants(camera).to_vec();
    constants.extend(surface_constants(scene.features));
    constants.extend([
        ("SAMPLES_PER_SIDE", f64::from(samples_per_side)),
        (
            "HAS_TRANSLUCENT",
            f64::from(u8::from(scene.features.translucent)),
        ),
        ("GLASS", f64::from(u8::from(camera.glass.is_some()))),
        ("MOTION", f64::from(u8::from(camera.shutter.moves()))),
        (
            "GLASS_CHANNELS",
            f64::from(camera.glass.map_or(1, |g| g.counts[2])),
        ),
    ]);
    constants
}

/// The frames' bytes, each in its `FRAME_SLOT`.
fn frame_slots(frames: &[Frame]) -> Vec<u8> {
    frames
        .iter()
        .flat_map(|frame| {
            let mut slot = bytemuck::bytes_of(frame).to_vec();
            slot.resize(FRAME_SLOT as usize, 0);
            slot
        })
        .collect()
}

/// The bands of rows `(first row, rows)` a trace of `size` is dispatched in: one where the
/// colour and geometry outputs (16 bytes a pixel) fit one storage binding, else as many rows
/// a band as fit (only for a single view; a cube map's faces fit or are refused). The whole
/// image's outputs must still fit one buffer.
fn output_bands(
    ctx: &GpuContext,
    size: crate::lens::ImageSize,
    views: u32,
) -> Result<Vec<(u32, u32)>> {
    let limits = ctx.device.limits();
    let (width, height) = (size.width, size.height);
    let pixels = size.pixels() as u64;
    let row = 16 * u64::from(width);
    let rows = (limits.max_storage_buffer_binding_size / row).min(u64::from(height)) as u32;
    if rows == height {
        return Ok(vec![(0, height)]);
    }
    if views > 1 || rows == 0 {
        ctx.check_binding("the colour output", 16 * pixels)?;
    }
    if 16 * pixels > limits.max_buffer_size {
        return Err(Error::Limit(format!(
            "a {size} image's colour output needs a buffer of {:.1} MiB, above this adapter's \
             limit of {:.1} MiB per buffer; use a smaller image",
            (16 * pixels) as f64 / f64::from(1 << 20),
            limits.max_buffer_size as f64 / f64::from(1 << 20)
        )));
    }
    Ok((0..height)
        .step_by(rows as usize)
        .map(|first| (first, rows.min(height - first)))
        .collect())
}
