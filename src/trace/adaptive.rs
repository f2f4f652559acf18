//! Adaptive sampling ([`AdaptivePass`]): a first pass of one ray per
//! [`ADAPTIVE_BLOCK`]² pixels (or one through every pixel: [`Adaptive::every_pixel`]), then
//! rays only where neighbouring samples disagree (the blocks' midpoints, then each pixel of
//! the half-blocks that still disagree), up to the uniform
//! supersampling of [`super::sampling`] where colours still differ; every pass on the
//! GPU, with no read-back between them. `wgsl/adaptive.wgsl` says how each pass decides.

use super::pass::{TracePass, check_storage_buffers, shared_entries};
use super::{Adaptive, GpuScene, RenderOutput, SampleLanes};
use crate::error::{Error, Result};
use crate::gpu::{GpuContext, GpuJob, bind_group_at, storage_entry, uniform_entry};
use crate::lens::LensCamera;
use crate::lens::gpu::DirectionSource;
use crate::scene::Camera;
use crate::shader;
use crate::shared::{
    ADAPTIVE_BLOCK, ADAPTIVE_COUNT, ADAPTIVE_HEADER, ADAPTIVE_KEY_MORE, ADAPTIVE_MODE,
    ADAPTIVE_STORAGE_BUFFERS, ADAPTIVE_STRIP, AdaptiveParams, MODE_CENTRE, MODE_EVERY_PIXEL,
    MODE_LATTICE, TRACE_STORAGE_BUFFERS, WORKGROUP_1D, WORKGROUP_2D,
};

/// Two corners' shading normals further apart than this (about 25°) are not one smooth
/// stretch of surface: their block is traced.
const NORMAL_COSINE: f32 = 0.9;
/// A corner's hit further than this share of the range from another corner's tangent plane is
/// behind a depth step: their block is traced.
const PLANE_DISTANCE: f32 = 0.01;

mod stages;

pub use stages::{ALL_STAGES, Stage, stages_for};
use stages::{lattice_points, list_mode, listed_at, reused_samples, sample_lanes, samples_at};

/// A kernel of a stage the frame runs, which [`AdaptivePass`] made with the pass (it makes
/// only those: see its `builders`).
fn made(kernel: &Option<wgpu::ComputePipeline>) -> &wgpu::ComputePipeline {
    kernel
        .as_ref()
        .expect("the kernels of the stages a frame runs are made with the pass")
}

/// Timestamp writes for the stages of one frame, each but the first in two compute passes:
/// the listing of its pixels (the bookkeeping), then the tracing of the list; the coarse
/// stage traces the lattice in one pass, with no list. `None` leaves a pass untimed.
#[derive(Default)]
pub struct AdaptiveSpans<'a> {
    /// The listing pass of each [`Stage`], in order (the coarse stage's is never written).
    pub lists: [Option<wgpu::ComputePassTimestampWrites<'a>>; 6],
    /// The tracing pass of each [`Stage`], in order.
    pub stages: [Option<wgpu::ComputePassTimestampWrites<'a>>; 6],
}

/// Adaptive sampling of one lens, image size and scene: the trace kernel's outputs and frame
/// (a [`TracePass`] at the largest sample count, whose buffers it writes), the work buffer
/// (the work list, then the per-pixel state: rays taken, what the centre saw) and the list's
/// indirect dispatch.
pub struct AdaptivePass {
    trace: TracePass,
    options: Adaptive,
    /// The work buffer's header for the coarse stage, which `trace_list` traces with no list
    /// (its points are known): `MODE_LATTICE` or `MODE_EVERY_PIXEL`.
    coarse: wgpu::Buffer,
    /// The kernels that list the later stages' pixels: classify (the blocks), midpoints,
    /// classify (the half-blocks), select_pixels, more, untraced. Here and below, only the
    /// kernels of the stages a frame runs are made (`None` the others'): a tracing kernel
    /// takes a driver most of a second to compile on lavapipe.
    builders: [Option<wgpu::ComputePipeline>; 6],
    /// The tracing kernel of each listed [`Stage`] (all but the coarse, in order, see
    /// [`listed_at`]): `trace_list` or `trace_samples`.
    trace_lists: [Option<wgpu::ComputePipeline>; 5],
    /// The kernels that size each listed [`Stage`]'s tracing dispatch over its whole list,
    /// then supersampling's over the next slice of it (progressive refinement,
    /// [`AdaptivePass::encode_step`]).
    args: [Option<wgpu::ComputePipeline>; 6],
    group: wgpu::BindGroup,
    args_group: wgpu::BindGroup,
    work: wgpu::Buffer,
    dispatch: wgpu::Buffer,
    /// The length of each stage's list in the last frame, in [`ALL_STAGES`] order (0 for a
    /// stage not run, and for the coarse stage, which has none), copied from the work
    /// buffer's header after each listed stage.
    listed: wgpu::Buffer,
    params: AdaptiveParams,
}

impl AdaptivePass {
    /// Creates the kernels (those of the stages its frames run, [`stages_for`]) and buffers
    /// for `camera` on `scene`, with at most `spp` samples a pixel (a square, as uniform
    /// sampling takes them), its samples spread over invocations as suits the device
    /// ([`SampleLanes::for_device`]). Refuses an image whose outputs do not fit one storage
    /// binding, and a device with too few storage buffers per stage.
    pub fn new(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
        spp: u32,
        options: Adaptive,
    ) -> Result<Self> {
        let lanes = SampleLanes::for_device(&ctx.device);
        Self::with_lanes(ctx, camera, scene, source, spp, options, lanes)
    }

    /// As [`AdaptivePass::new`], with the samples spread over invocations as `lanes` says.
    pub fn with_lanes(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        source: DirectionSource,
        spp: u32,
        options: Adaptive,
        lanes: SampleLanes,
    ) -> Result<Self> {
        if !(options.threshold >= 0.0 && options.threshold.is_finite()) {
            return Err(Error::Option(format!(
                "adaptive sampling's threshold {}: it is a displayed-colour difference, 0 or \
                 more (0.02 is 2 % of full scale)",
                options.threshold
            )));
        }
        let trace = TracePass::deferred(ctx, camera, scene, source, spp)?;
        if trace.bands() > 1 {
            return Err(Error::Limit(format!(
                "adaptive sampling of a {} image: its outputs exceed one storage binding of \
                 this device; use a smaller image or uniform sampling (--spp N)",
                camera.size
            )));
        }
        let needed = TRACE_STORAGE_BUFFERS + source.storage_buffers() + ADAPTIVE_STORAGE_BUFFERS;
        check_storage_buffers(ctx, scene, needed, "adaptive sampling")
            .map_err(|e| Error::Limit(format!("{e}; use uniform sampling (--spp N)")))?;
        let (width, height) = (camera.size.width, camera.size.height);
        let pixels = camera.size.pixels() as u64;
        // A progressive step supersamples at most as many pixels as take one ray each, at
        // the most samples a pixel: about one ray per pixel per frame.
        let samples = trace.samples_per_side().pow(2) as usize;
        let slice = (camera.size.pixels() / samples).max(1) as u32;
        let params = AdaptiveParams {
            threshold: options.threshold,
            normal_cosine: NORMAL_COSINE,
            plane_distance: PLANE_DISTANCE,
            _pad0: 0,
            lattice: [width, height].map(|n| lattice_points(n, ADAPTIVE_BLOCK)),
            blocks: [width, height].map(|n| n.div_ceil(ADAPTIVE_BLOCK)),
            half_lattice: [width, height].map(|n| lattice_points(n, ADAPTIVE_BLOCK / 2)),
            halves: [width, height].map(|n| n.div_ceil(ADAPTIVE_BLOCK / 2)),
        };
        let blocks = u64::from(params.blocks[0]) * u64::from(params.blocks[1]);
        ctx.checked("creating the adaptive passes", || {
            let device = &ctx.device;
            let buffer = |label: &str, bytes: u64, usage: wgpu::BufferUsages| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE | usage,
                    mapped_at_creation: false,
                })
            };
            // The header, a list with room for every pixel, two words of state a pixel, a
            // word a block.
            let work = buffer(
                "fisheye.adaptive.work",
                4 * (u64::from(ADAPTIVE_HEADER) + 3 * pixels + blocks),
                wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            );
            let listed = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fisheye.adaptive.listed"),
                size: 4 * ALL_STAGES.len() as u64,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let dispatch = buffer(
                "fisheye.adaptive.dispatch",
                12,
                wgpu::BufferUsages::INDIRECT,
            );
            let uniform = crate::gpu::buffer_init(
                device,
                "fisheye.adaptive.params",
                bytemuck::bytes_of(&params),
                wgpu::BufferUsages::UNIFORM,
            );
            // Group 0 as wgsl/pixel.wgsl and wgsl/adaptive.wgsl declare it.
            let mut entries = shared_entries(source);
            entries.extend([storage_entry(7, false), uniform_entry(8)]);
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.adaptive"),
                entries: &entries,
            });
            let resources = trace.shared_bindings().into_iter().chain([
                (7, work.as_entire_binding()),
                (8, uniform.as_entire_binding()),
            ]);
            let group = bind_group_at(device, "fisheye.adaptive", &layout, resources);
            let mut layouts = vec![&layout, &scene.layout];
            let file = match &scene.ray_query {
                Some(rq) => {
                    layouts.push(&rq.layout);
                    "adaptive_rq"
                }
                None => "adaptive",
            };
            // The listers but `classify` are in wgsl/adaptive_lists.wgsl and the sample tracer
            // in wgsl/adaptive_samples.wgsl, which import wgsl/adaptive.wgsl; with ray queries
            // they are composed as adaptive_rq.wgsl composes that.
            let mut import_swaps = source.swaps().to_vec();
            if scene.ray_query.is_some() {
                import_swaps.push(("bvh", "bvh_rq"));
            }
            let side = trace.samples_per_side();
            let stages = stages_for(side, options);
            let runs = |stage: Stage| stages.contains(&stage);
            let in_file = |(file, swaps): (&str, &[(&str, &str)]),
                           entry: &str,
                           overrides: &[(&'static str, u32)]| {
                let mut constants = trace.constants().to_vec();
                constants.extend(overrides.iter().map(|&(name, v)| (name, f64::from(v))));
                let composed = (&scene.arrays, swaps);
                shader::scene_pipeline(device, file, composed, entry, &constants, &layouts)
            };
            let kernel = |entry: &str, mode: u32, level: u32| {
                let overrides = [("LIST_MODE", mode), ("LEVEL", level)];
                in_file((file, source.swaps()), entry, &overrides)
            };
            let lister = |entry: &str| in_file(("adaptive_lists", &import_swaps), entry, &[]);
            let sampler = |stage: Stage| {
                let overrides = [
                    ("LIST_MODE", list_mode(stage)),
                    ("SAMPLE_LANES", sample_lanes(stage, side, options, lanes)),
                    ("REUSED", reused_samples(side, options)),
                ];
                in_file(
                    ("adaptive_samples", &import_swaps),
                    "trace_samples",
                    &overrides,
                )
            };
            // `select_pixels` lists the estimate's pixels, or supersampling's where there is
            // no estimate; `more` supersampling's after one (every frame that estimates also
            // supersamples).
            let (estimates, supersamples) = (runs(Stage::Estimate), runs(Stage::Supersample));
            let builders = [
                runs(Stage::Midpoints).then(|| kernel("classify", MODE_CENTRE, 0)),
                runs(Stage::Midpoints).then(|| lister("midpoints")),
                runs(Stage::Refine).then(|| kernel("classify", MODE_CENTRE, 1)),
                supersamples.then(|| lister("select_pixels")),
                estimates.then(|| lister("more")),
                runs(Stage::Truth).then(|| lister("untraced")),
            ];
            // The tracing kernels, each most of a second's compiling on lavapipe, made side by
            // side, by the modes of wgsl/adaptive.wgsl: centres (shared by the stages that
            // trace them, the coarse stage's too), estimates, samples, first hits.
            let jobs: Vec<GpuJob<'_, _>> = vec![
                Box::new(|| Some(kernel("trace_list", list_mode(Stage::Midpoints), 0))),
                Box::new(|| estimates.then(|| sampler(Stage::Estimate))),
                Box::new(|| supersamples.then(|| sampler(Stage::Supersample))),
                Box::new(|| {
                    runs(Stage::Truth).then(|| kernel("trace_list", list_mode(Stage::Truth), 0))
                }),
            ];
            let tracers = ctx.checked_each("compiling the adaptive passes' kernels", jobs)?;
            let [centres, estimate, samples, truth] =
                <[_; 4]>::try_from(tracers).expect("a kernel for each job");
            let trace_lists = [centres.clone(), centres, estimate, samples, truth];
            let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.adaptive.args"),
                entries: &[storage_entry(0, false), storage_entry(1, false)],
            });
            let args_kernel = |slice: u32, stage: Stage| {
                let per_group = WORKGROUP_1D / sample_lanes(stage, side, options, lanes);
                let constants = [
                    ("SLICE", f64::from(slice)),
                    ("PER_GROUP", f64::from(per_group)),
                ];
                shader::compute_pipeline(
                    device,
                    "adaptive_args",
                    "main",
                    &constants,
                    &[&args_layout],
                )
            };
            // The stages that trace centres share one: a pixel a lane.
            let centres = args_kernel(0, Stage::Refine);
            let args = [
                runs(Stage::Midpoints).then(|| centres.clone()),
                runs(Stage::Refine).then(|| centres.clone()),
                estimates.then(|| args_kernel(0, Stage::Estimate)),
                supersamples.then(|| args_kernel(0, Stage::Supersample)),
                runs(Stage::Truth).then_some(centres),
                supersamples.then(|| args_kernel(slice, Stage::Supersample)),
            ];
            let args_group = crate::gpu::bind_buffers(
                device,
                "fisheye.adaptive.args",
                &args_layout,
                &[&work, &dispatch],
            );
            let mut header = [0u32; ADAPTIVE_HEADER as usize];
            header[ADAPTIVE_MODE as usize] = if options.every_pixel {
                MODE_EVERY_PIXEL
            } else {
                MODE_LATTICE
            };
            let coarse = crate::gpu::buffer_init(
                device,
                "fisheye.adaptive.coarse",
                bytemuck::cast_slice(&header),
                wgpu::BufferUsages::COPY_SRC,
            );
            Ok(Self {
                trace,
                options,
                coarse,
                builders,
                trace_lists,
                args,
                group,
                args_group,
                work,
                dispatch,
                listed,
                params,
            })
        })?
    }

    /// Makes each frame's colour output as `filter` says from now on: the tent filter with
    /// one ray a pixel at most, each pixel then one ray or interpolated (see
    /// [`TracePass::set_filter`]). Callers record it after a frame's stages
    /// ([`TracePass::encode_filter`]).
    pub fn set_filter(&mut self, ctx: &GpuContext, filter: super::PixelFilter) -> Result<()> {
        self.trace.set_filter(ctx, filter)
    }

    /// The settings.
    pub fn options(&self) -> Adaptive {
        self.options
    }

    /// The trace pass whose outputs the adaptive passes write (its pose, its buffers).
    pub fn trace_pass(&self) -> &TracePass {
        &self.trace
    }

    /// Moves the camera to `pose` for the frames encoded from now on (see
    /// [`TracePass::set_pose`]).
    pub fn set_pose(&self, ctx: &GpuContext, scene: &GpuScene, pose: &Camera) {
        self.trace.set_pose(ctx, scene, pose);
    }

    /// Records a move of the camera to `pose` (see [`TracePass::encode_pose`]).
    pub fn encode_pose(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pose: &Camera,
    ) {
        self.trace.encode_pose(device, encoder, scene, pose);
    }

    /// The stages a frame runs, in order (see [`stages_for`]).
    pub fn stages(&self) -> Vec<Stage> {
        stages_for(self.trace.samples_per_side(), self.options)
    }

    /// Records one frame, timed by `spans`: the coarse stage one compute pass (`trace_list`
    /// over its points), each later stage two (a kernel lists pixels; then a one-invocation
    /// kernel sizes the dispatch, and `trace_list` or `trace_samples` traces them).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        spans: AdaptiveSpans<'_>,
    ) {
        let stages = self.stages();
        encoder.clear_buffer(&self.listed, 0, None);
        let writes = spans.lists.into_iter().zip(spans.stages);
        for (stage, (list, trace)) in ALL_STAGES.into_iter().zip(writes) {
            if stage == Stage::Coarse {
                self.encode_coarse(encoder, scene, trace);
            } else if stages.contains(&stage) {
                self.encode_stage(encoder, scene, stage, list, Some(trace));
            }
        }
    }

    /// Records the coarse stage, a compute pass timed by `writes`: a ray through each
    /// lattice point (or pixel), an invocation each in tiles, by the centres' kernel with no
    /// list (the points are known: the header says which, `coarse`).
    fn encode_coarse(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let header = 4 * u64::from(ADAPTIVE_HEADER);
        encoder.copy_buffer_to_buffer(&self.coarse, 0, &self.work, 0, header);
        // A tile of WORKGROUP_2D² points a workgroup (WORKGROUP_1D invocations), in rows of
        // at most 65535 workgroups, as `wgsl/adaptive_args.wgsl` sizes a list's dispatch.
        const _: () = assert!(WORKGROUP_1D == WORKGROUP_2D * WORKGROUP_2D);
        let [w, h] = self.coarse_points();
        let groups = w.div_ceil(WORKGROUP_2D) * h.div_ceil(WORKGROUP_2D);
        let rows = groups.div_ceil(65535).max(1);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("fisheye.adaptive.coarse"),
            timestamp_writes: writes,
        });
        pass.set_pipeline(made(&self.trace_lists[listed_at(Stage::Midpoints)]));
        for (index, group) in self.groups(scene).into_iter().enumerate() {
            pass.set_bind_group(index as u32, group, &[]);
        }
        pass.dispatch_workgroups(groups.div_ceil(rows), rows, 1);
    }

    /// The pixels whose centres the coarse stage traces, row by row: the lattice's (where
    /// `lattice_pixel` in `wgsl/adaptive.wgsl` puts them), or every pixel.
    pub fn coarse_pixels(&self) -> impl Iterator<Item = [u32; 2]> {
        let (size, [w, h]) = (self.trace.size(), self.coarse_points());
        let every = self.options.every_pixel;
        let spacing = if every { 1 } else { ADAPTIVE_BLOCK };
        let at = move |i: u32, n: u32| (i * spacing).min(n - 1);
        (0..h).flat_map(move |y| (0..w).map(move |x| [at(x, size.width), at(y, size.height)]))
    }

    /// The points the coarse stage traces, across and down: the lattice, or every pixel.
    fn coarse_points(&self) -> [u32; 2] {
        let size = self.trace.size();
        if self.options.every_pixel {
            [size.width, size.height]
        } else {
            self.params.lattice
        }
    }

    /// Records a compute pass timed by `writes` that runs `kernels` one after another with
    /// the adaptive bind groups, each an invocation for each of `size`'s points in 2D
    /// workgroups.
    fn dispatch_2d(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        label: &str,
        kernels: &[&wgpu::ComputePipeline],
        [w, h]: [u32; 2],
        writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: writes,
        });
        for (index, group) in self.groups(scene).into_iter().enumerate() {
            pass.set_bind_group(index as u32, group, &[]);
        }
        for kernel in kernels {
            pass.set_pipeline(kernel);
            pass.dispatch_workgroups(w.div_ceil(WORKGROUP_2D), h.div_ceil(WORKGROUP_2D), 1);
        }
    }

    /// Records step `step` of a progressive frame, which shows a picture at once and sharpens
    /// it step by step, ending with the frame [`AdaptivePass::encode`] makes, bit for bit:
    /// - step 0 is the frame below one ray per pixel: the coarse and refining stages (and the
    ///   ground truth's, where asked for), as `--spp auto:T:1` makes it but for the pixels
    ///   that frame interpolates beside edges, which a frame that may supersample traces (with
    ///   [`Adaptive::every_pixel`], a ray through every pixel);
    /// - step 1 runs the estimating stage, where there is one, and lists the pixels to
    ///   supersample;
    /// - each later step supersamples the next part of that list: as many pixels as take one
    ///   ray each at the most samples a pixel, so about one ray per pixel, until the list is
    ///   done (a step after that records an empty dispatch).
    ///
    /// Steps build on the ones before them for the same pose: record step 0 after every move
    /// of the camera, and the others in order.
    pub fn encode_step(&self, encoder: &mut wgpu::CommandEncoder, scene: &GpuScene, step: u32) {
        let stages = self.stages();
        match step {
            0 => {
                encoder.clear_buffer(&self.listed, 0, None);
                self.encode_coarse(encoder, scene, None);
                for stage in [Stage::Midpoints, Stage::Refine, Stage::Truth] {
                    if stages.contains(&stage) {
                        self.encode_stage(encoder, scene, stage, None, Some(None));
                    }
                }
            }
            1 => {
                if stages.contains(&Stage::Estimate) {
                    self.encode_stage(encoder, scene, Stage::Estimate, None, Some(None));
                }
                if stages.contains(&Stage::Supersample) {
                    self.encode_stage(encoder, scene, Stage::Supersample, None, None);
                }
            }
            _ => {
                if stages.contains(&Stage::Supersample) {
                    let mut pass = encoder.begin_compute_pass(&Default::default());
                    self.trace_listed(&mut pass, scene, Stage::Supersample, true);
                }
            }
        }
    }

    /// Records `stage` (any but the coarse): its list made afresh in a compute pass timed by
    /// `list`, then, where `trace` is given, traced whole in a second pass timed by it (else
    /// listed only, for progressive steps to trace part by part).
    fn encode_stage(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        stage: Stage,
        list: Option<wgpu::ComputePassTimestampWrites<'_>>,
        trace: Option<Option<wgpu::ComputePassTimestampWrites<'_>>>,
    ) {
        let size = self.trace.size();
        let [classify, midpoints, classify_halves, select, more, untraced] = &self.builders;
        // The listers of each stage: the midpoints' decide the blocks first; supersampling
        // lists the pixels the estimate marked where there is an estimating stage (the coarse
        // stage lists nothing and never comes here: `encode_coarse`).
        // The per-pixel listers look at ADAPTIVE_STRIP pixels an invocation, side by side.
        let pixels = [size.width.div_ceil(ADAPTIVE_STRIP), size.height];
        let (listers, points) = match stage {
            Stage::Coarse | Stage::Midpoints => (vec![classify, midpoints], self.params.blocks),
            Stage::Refine => (vec![classify_halves], self.params.halves),
            Stage::Estimate => (vec![select], pixels),
            Stage::Supersample if self.stages().contains(&Stage::Estimate) => (vec![more], pixels),
            Stage::Supersample => (vec![select], pixels),
            Stage::Truth => (vec![untraced], pixels),
        };
        let listers: Vec<_> = listers.into_iter().map(made).collect();
        encoder.clear_buffer(&self.work, 0, Some(4 * u64::from(ADAPTIVE_HEADER)));
        let label = "fisheye.adaptive.list";
        self.dispatch_2d(encoder, scene, label, &listers, points, list);
        if let Some(writes) = trace {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("fisheye.adaptive.trace"),
                timestamp_writes: writes,
            });
            self.trace_listed(&mut pass, scene, stage, false);
        }
        let count = 4 * u64::from(ADAPTIVE_COUNT);
        encoder.copy_buffer_to_buffer(&self.work, count, &self.listed, 4 * stage as u64, 4);
    }

    /// Records the sizing of `stage`'s tracing dispatch over its whole list, or with `sliced`
    /// over the next slice of it, then the tracing.
    fn trace_listed(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        scene: &GpuScene,
        stage: Stage,
        sliced: bool,
    ) {
        let args = if sliced {
            self.args.len() - 1
        } else {
            listed_at(stage)
        };
        pass.set_pipeline(made(&self.args[args]));
        pass.set_bind_group(0, &self.args_group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(made(&self.trace_lists[listed_at(stage)]));
        for (index, group) in self.groups(scene).into_iter().enumerate() {
            pass.set_bind_group(index as u32, group, &[]);
        }
        pass.dispatch_workgroups_indirect(&self.dispatch, 0);
    }

    /// The bind groups of the listing and tracing kernels, in order.
    fn groups<'a>(&'a self, scene: &'a GpuScene) -> Vec<&'a wgpu::BindGroup> {
        let mut groups = vec![&self.group, &scene.bind_group];
        if let Some(rq) = &scene.ray_query {
            groups.push(&rq.bind_group);
        }
        groups
    }

    /// The rays each stage of the last frame traced, in [`AdaptivePass::stages`] order: the
    /// lattice points at the coarse stage, then the pixels each stage listed times the samples
    /// each takes there (1 at the midpoint, refining and ground truth's stages, where the last
    /// traces first hits alone; 2 × 2 estimating; all of them supersampling), counting samples
    /// the lens masks (which cost a lens evaluation, not a ray) as rays. After progressive
    /// steps, supersampling's are the pixels listed, whether or not their slices are traced
    /// yet.
    pub fn read_stage_rays(&self, ctx: &GpuContext) -> Result<Vec<(Stage, u64)>> {
        let listed: Vec<u32> = ctx.read_buffer(&self.listed)?;
        let side = self.trace.samples_per_side();
        Ok(self
            .stages()
            .into_iter()
            .map(|stage| {
                let [w, h] = self.coarse_points();
                let pixels = match stage {
                    Stage::Coarse => w * h,
                    _ => listed[stage as usize],
                };
                (
                    stage,
                    u64::from(pixels) * u64::from(samples_at(stage, side, self.options)),
                )
            })
            .collect())
    }

    /// Traces one frame, reporting a GPU error as `what` failing, and reads it back.
    pub fn trace(&self, ctx: &GpuContext, scene: &GpuScene, what: &str) -> Result<RenderOutput> {
        ctx.checked(what, || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, scene, AdaptiveSpans::default());
            self.trace.encode_filter(&mut encoder, None);
            ctx.queue.submit([encoder.finish()]);
        })?;
        self.trace.read(ctx)
    }

    /// The rays each pixel's colour took in the last frame, row-major (the spp map): 0 for a
    /// pixel interpolated between its block's or half-block's corners or masked, 1 for its
    /// centre alone, and one more for each sample that the lens covers of a pixel's 2 × 2
    /// estimating samples and of those its supersampling takes beyond any it reuses (so at
    /// most 1 + 16 with 16 samples, 1 + 4 + 64 with 64).
    pub fn read_rays(&self, ctx: &GpuContext) -> Result<Vec<u32>> {
        Ok(self
            .read_states(ctx)?
            .into_iter()
            .map(|[rays, _]| rays)
            .collect())
    }

    /// Whether each pixel demanded every sample in the last frame, row-major: its 2 × 2
    /// estimating samples disagreed, or a neighbour is brighter than the display shows. Those
    /// pixels take every sample, and so does each estimated pixel beside one of them whose
    /// centre sees another surface.
    pub fn read_demanding(&self, ctx: &GpuContext) -> Result<Vec<bool>> {
        let states = self.read_states(ctx)?;
        Ok(states
            .into_iter()
            .map(|[_, key]| key == ADAPTIVE_KEY_MORE)
            .collect())
    }

    /// Each pixel's state in the work buffer: its rays, then what its centre saw.
    fn read_states(&self, ctx: &GpuContext) -> Result<Vec<[u32; 2]>> {
        let pixels = self.trace.size().pixels() as u64;
        let first = 4 * (u64::from(ADAPTIVE_HEADER) + pixels);
        ctx.read_buffer_range(&self.work, first, 8 * pixels)
    }
}
