//! The lens on the GPU: the parameters WGSL reads, the ids of its specialisations, and two
//! passes: [`LensRays`] (the direction of every pixel: the direction table) and
//! [`LensPoints`] (project or unproject arbitrary points).

use glam::{DVec2, DVec3, Vec2, Vec3};

use super::DirectionFormula;
use super::{CalibratedModel, Family, Lens, LensCamera, LensModel};
use crate::error::Result;
use crate::gpu::{GpuContext, dispatch_over_image};
use crate::shader;
pub use crate::shared::{DirectionSource, LensKind, LensParams, NEWTON_STEPS, NEWTON_TOLERANCE};
use crate::shared::{FORMULA_STABLE, FORMULA_THESIS, WORKGROUP_1D};

impl LensKind {
    /// The code path of a lens.
    pub fn of(lens: &Lens) -> Self {
        let model = match lens {
            Lens::Classic(lens) => lens.model(),
            Lens::Calibrated(lens) => {
                return match lens.model() {
                    CalibratedModel::KannalaBrandt { .. } => Self::KannalaBrandt,
                    CalibratedModel::DoubleSphere { .. } => Self::DoubleSphere,
                    CalibratedModel::Unified { .. } | CalibratedModel::ExtendedUnified { .. } => {
                        Self::ExtendedUnified
                    }
                    CalibratedModel::Fov { .. } => Self::FovModel,
                    CalibratedModel::Scaramuzza { .. } => Self::Scaramuzza,
                    CalibratedModel::FTheta { .. } => Self::FTheta,
                    CalibratedModel::RadTan { .. } => Self::RadTan,
                };
            }
        };
        match model {
            LensModel::Rectilinear => Self::Rectilinear,
            LensModel::Stereographic => Self::Stereographic,
            LensModel::Equidistant => Self::Equidistant,
            LensModel::Equisolid => Self::Equisolid,
            LensModel::Orthographic => Self::Orthographic,
            LensModel::General { .. } => match model.general_form().0 {
                Family::Tan => Self::GeneralTan,
                Family::Linear => Self::Equidistant,
                Family::Sin => Self::GeneralSin,
            },
        }
    }
}

/// The id WGSL's `DIRECTION_FORMULA` override takes for a formula.
fn formula_id(formula: DirectionFormula) -> u32 {
    match formula {
        DirectionFormula::Stable => FORMULA_STABLE,
        DirectionFormula::Thesis => FORMULA_THESIS,
    }
}

/// A calibrated model's parameters as WGSL reads them (`wgsl/calibrated.wgsl` documents each
/// kind's packing), with derived constants precomputed in f64.
fn calibrated_coefficients(model: CalibratedModel) -> ([[f64; 4]; 2], [f64; 4]) {
    match model {
        CalibratedModel::KannalaBrandt { k } => ([k, [0.0; 4]], [0.0; 4]),
        CalibratedModel::DoubleSphere { xi, alpha } => {
            ([[xi, alpha, 0.0, 0.0], [0.0; 4]], [0.0; 4])
        }
        CalibratedModel::Unified { alpha } => ([[alpha, 1.0, 0.0, 0.0], [0.0; 4]], [0.0; 4]),
        CalibratedModel::ExtendedUnified { alpha, beta } => {
            ([[alpha, beta, 0.0, 0.0], [0.0; 4]], [0.0; 4])
        }
        CalibratedModel::Fov { w } => ([[w, 2.0 * (0.5 * w).tan(), 0.0, 0.0], [0.0; 4]], [0.0; 4]),
        CalibratedModel::Scaramuzza { a, c, d, e } => (
            [[a[0], a[1], a[2], a[3]], [a[4], 0.0, 0.0, 0.0]],
            [c, d, e, 0.0],
        ),
        CalibratedModel::FTheta { k } => {
            ([[k[0], k[1], k[2], k[3]], [k[4], 0.0, 0.0, 0.0]], [0.0; 4])
        }
        CalibratedModel::RadTan { k, p } => {
            ([[k[0], k[1], k[2], 0.0], [p[0], p[1], 0.0, 0.0]], [0.0; 4])
        }
    }
}

impl LensParams {
    /// The parameters of a camera, rounded to f32.
    pub fn new(camera: &LensCamera) -> Self {
        let lens = camera.lens;
        let narrow = |v: [f64; 4]| v.map(|x| x as f32);
        let mut params = Self {
            f: 0.0,
            k1_over_f: 0.0,
            rate: 0.0,
            r_max: lens.r_max().min(f64::from(f32::MAX)) as f32,
            theta_max: lens.theta_max() as f32,
            width: camera.size.width,
            height: camera.size.height,
            mask_limit: camera.mask_limit(),
            intrinsics: [0.0; 4],
            coefficients: [[0.0; 4]; 2],
            affine: [0.0; 4],
        };
        match lens {
            Lens::Classic(lens) => {
                let (_, k1, rate) = lens.model().general_form();
                let f = lens.focal_length();
                params.f = f as f32;
                params.k1_over_f = (k1 / f) as f32;
                params.rate = rate as f32;
            }
            Lens::Calibrated(lens) => {
                let i = lens.intrinsics();
                let (coefficients, affine) = calibrated_coefficients(lens.model());
                params.intrinsics = narrow([i.fx, i.fy, i.cx, i.cy]);
                params.coefficients = coefficients.map(narrow);
                params.affine = narrow(affine);
            }
        }
        params
    }
}

/// The override constants that specialise a lens kernel to a camera's model and formula.
pub fn lens_constants(camera: &LensCamera) -> [(&'static str, f64); 2] {
    [
        ("LENS_KIND", f64::from(LensKind::of(&camera.lens) as u32)),
        ("DIRECTION_FORMULA", f64::from(formula_id(camera.formula))),
    ]
}

/// The uniform buffer holding a camera's [`LensParams`].
pub(crate) fn params_buffer(device: &wgpu::Device, camera: &LensCamera) -> wgpu::Buffer {
    crate::gpu::buffer_init(
        device,
        "fisheye.lens.params",
        bytemuck::bytes_of(&LensParams::new(camera)),
        wgpu::BufferUsages::UNIFORM,
    )
}

/// A `vec4<f32>` per-element result with `w` (or `z`) as the validity flag, to `Option`.
fn flagged(v: [f32; 4], flag: f32) -> bool {
    flag == 1.0 && v.iter().all(|c| c.is_finite())
}

/// Computes the ray direction of every pixel centre: the direction table, one `vec4<f32>` per
/// pixel (xyz the direction, w = 1; zeros where masked), made once per lens and image size.
pub struct LensRays {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The table, row-major; usable as a storage binding by later passes.
    pub directions: wgpu::Buffer,
    camera: LensCamera,
}

impl LensRays {
    /// Creates the pipeline and the table buffer; errors if the table exceeds a storage
    /// binding of this adapter.
    pub fn new(ctx: &GpuContext, camera: &LensCamera) -> Result<Self> {
        let bytes = 16 * camera.size.pixels() as u64;
        ctx.check_binding("the direction table", bytes)?;
        ctx.checked("creating the lens-rays pass", || {
            let device = &ctx.device;
            let pipeline =
                shader::compute_pipeline(device, "lens_rays", "main", &lens_constants(camera), &[]);
            let directions = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fisheye.lens_rays.directions"),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let params = params_buffer(device, camera);
            let bind_group = crate::gpu::bind_buffers(
                device,
                "fisheye.lens_rays",
                &pipeline.get_bind_group_layout(0),
                &[&params, &directions],
            );
            Self {
                pipeline,
                bind_group,
                directions,
                camera: *camera,
            }
        })
    }

    /// The table a kernel reading directions from `source` needs: for
    /// [`DirectionSource::Table`] it is computed here, once (the pass is submitted); for
    /// [`DirectionSource::Computed`] there is none.
    pub fn for_source(
        ctx: &GpuContext,
        camera: &LensCamera,
        source: DirectionSource,
    ) -> Result<Option<Self>> {
        if source == DirectionSource::Computed {
            return Ok(None);
        }
        let rays = Self::new(ctx, camera)?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        rays.encode(&mut encoder, None);
        ctx.queue.submit([encoder.finish()]);
        Ok(Some(rays))
    }

    /// Records the pass, optionally timed.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        dispatch_over_image(
            encoder,
            "fisheye.lens_rays",
            &self.pipeline,
            &[&self.bind_group],
            self.camera.size,
            timestamp_writes,
        );
    }

    /// Runs the pass and reads the table back: per pixel, row-major, `None` where masked.
    pub fn compute(&self, ctx: &GpuContext) -> Result<Vec<Option<Vec3>>> {
        ctx.checked("computing ray directions", || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, None);
            ctx.queue.submit([encoder.finish()]);
        })?;
        let raw: Vec<[f32; 4]> = ctx.read_buffer(&self.directions)?;
        Ok(Self::decode(&raw))
    }

    /// The directions in the table's contents, as [`LensRays::compute`] gives them (for a
    /// caller that reads the table back itself, as a web page must).
    pub fn decode(raw: &[[f32; 4]]) -> Vec<Option<Vec3>> {
        raw.iter()
            .map(|v| flagged(*v, v[3]).then(|| Vec3::new(v[0], v[1], v[2])))
            .collect()
    }
}

/// Projects or unprojects arbitrary points with the WGSL lens code.
pub struct LensPoints {
    unproject: wgpu::ComputePipeline,
    project: wgpu::ComputePipeline,
    params: wgpu::Buffer,
}

impl LensPoints {
    /// Creates both pipelines for a camera.
    pub fn new(ctx: &GpuContext, camera: &LensCamera) -> Result<Self> {
        ctx.checked("creating the lens-points pass", || {
            let constants = lens_constants(camera);
            Self {
                unproject: shader::compute_pipeline(
                    &ctx.device,
                    "lens_points",
                    "unproject",
                    &constants,
                    &[],
                ),
                project: shader::compute_pipeline(
                    &ctx.device,
                    "lens_points",
                    "project",
                    &constants,
                    &[],
                ),
                params: params_buffer(&ctx.device, camera),
            }
        })
    }

    /// The direction through each continuous pixel position (f32), `None` where it has none.
    pub fn unproject(&self, ctx: &GpuContext, pixels: &[DVec2]) -> Result<Vec<Option<Vec3>>> {
        let input: Vec<[f32; 4]> = pixels
            .iter()
            .map(|p| [p.x as f32, p.y as f32, 0.0, 0.0])
            .collect();
        let raw = self.run(ctx, &self.unproject, &input)?;
        Ok(raw
            .into_iter()
            .map(|v| flagged(v, v[3]).then(|| Vec3::new(v[0], v[1], v[2])))
            .collect())
    }

    /// The pixel position where each direction lands (f32), `None` where it lands nowhere.
    pub fn project(&self, ctx: &GpuContext, dirs: &[DVec3]) -> Result<Vec<Option<Vec2>>> {
        let input: Vec<[f32; 4]> = dirs
            .iter()
            .map(|d| [d.x as f32, d.y as f32, d.z as f32, 0.0])
            .collect();
        let raw = self.run(ctx, &self.project, &input)?;
        Ok(raw
            .into_iter()
            .map(|v| flagged(v, v[2]).then(|| Vec2::new(v[0], v[1])))
            .collect())
    }

    fn run(
        &self,
        ctx: &GpuContext,
        pipeline: &wgpu::ComputePipeline,
        input: &[[f32; 4]],
    ) -> Result<Vec<[f32; 4]>> {
        let limits = ctx.device.limits();
        // Each chunk fits one storage binding and one dispatch.
        let chunk = (limits.max_storage_buffer_binding_size as usize / 16)
            .min(limits.max_compute_workgroups_per_dimension as usize * WORKGROUP_1D as usize);
        let mut out = Vec::with_capacity(input.len());
        for part in input.chunks(chunk) {
            let results = ctx.checked("running the lens-points pass", || {
                let device = &ctx.device;
                let points = crate::gpu::buffer_init(
                    device,
                    "fisheye.lens_points.points",
                    bytemuck::cast_slice(part),
                    wgpu::BufferUsages::STORAGE,
                );
                let results = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("fisheye.lens_points.results"),
                    size: points.size(),
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                let bind_group = crate::gpu::bind_buffers(
                    device,
                    "fisheye.lens_points",
                    &pipeline.get_bind_group_layout(0),
                    &[&self.params, &points, &results],
                );
                crate::gpu::submit_over_elements(ctx, pipeline, &bind_group, part.len());
                results
            })?;
            out.extend(ctx.read_buffer::<[f32; 4]>(&results)?);
        }
        Ok(out)
    }
}

/// The points on the exit pupil (in [0, 1)², before the concentric map) that pixels 0 to
/// `pixels` - 1 take through a prescription's glass (`pupil_offset` in `wgsl/glass.wgsl`,
/// through `wgsl/glass_probe.wgsl`): each pixel's 16 at 4 × 4 samples, then its 4 at 2 × 2.
/// For tests of their strata.
pub fn pupil_points_on_gpu(
    ctx: &crate::gpu::GpuContext,
    pixels: u32,
) -> Result<Vec<[[f32; 2]; 20]>> {
    let count = pixels as usize * 20;
    let results = ctx.checked("drawing points of the exit pupil", || {
        let device = &ctx.device;
        let pipeline = crate::shader::compute_pipeline(device, "glass_probe", "pupil", &[], &[]);
        let results = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fisheye.glass_probe.pupil"),
            size: (count * size_of::<[f32; 4]>()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fisheye.glass_probe.pupil"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 1,
                resource: results.as_entire_binding(),
            }],
        });
        crate::gpu::submit_over_elements(ctx, &pipeline, &group, count);
        results
    })?;
    let out = ctx.read_buffer::<[f32; 4]>(&results)?;
    Ok(out
        .chunks_exact(20)
        .map(|pixel| std::array::from_fn(|k| [pixel[k][0], pixel[k][1]]))
        .collect())
}

/// Traces `rays` (lens frame, from the film's side) out through `glass` in `channel` (0 red,
/// 1 green, 2 blue: the C, d and F lines) with the WGSL twin (`wgsl/glass_probe.wgsl`):
/// where each leaves the front surface, `None` where the glass blocks it. For tests of the
/// twin against [`super::prescription::Prescription::trace_from_film`].
pub fn trace_on_gpu(
    ctx: &crate::gpu::GpuContext,
    glass: &super::glass_gpu::GlassParams,
    rays: &[super::prescription::Ray],
    channel: u32,
) -> Result<Vec<Option<super::prescription::Ray>>> {
    let input: Vec<[f32; 4]> = rays
        .iter()
        .flat_map(|r| {
            let v = |v: DVec3, w: f32| [v.x as f32, v.y as f32, v.z as f32, w];
            [v(r.origin, channel as f32), v(r.direction, 0.0)]
        })
        .collect();
    let results = ctx.checked("tracing rays through the glass", || {
        let device = &ctx.device;
        let pipeline = crate::shader::compute_pipeline(device, "glass_probe", "main", &[], &[]);
        let usage = wgpu::BufferUsages::STORAGE;
        let params = crate::gpu::buffer_init(
            device,
            "fisheye.glass_probe.glass",
            bytemuck::bytes_of(glass),
            wgpu::BufferUsages::UNIFORM,
        );
        let input = crate::gpu::buffer_init(
            device,
            "fisheye.glass_probe.rays",
            bytemuck::cast_slice(&input),
            usage,
        );
        let results = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fisheye.glass_probe.results"),
            size: input.size(),
            usage: usage | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let entries = [(0, &input), (1, &results), (6, &params)].map(|(binding, buffer)| {
            wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fisheye.glass_probe"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        crate::gpu::submit_over_elements(ctx, &pipeline, &group, rays.len());
        results
    })?;
    let out = ctx.read_buffer::<[f32; 4]>(&results)?;
    let v = |a: [f32; 4]| DVec3::new(a[0].into(), a[1].into(), a[2].into());
    Ok(out
        .chunks_exact(2)
        .map(|pair| {
            (pair[0][3] == 1.0).then(|| super::prescription::Ray {
                origin: v(pair[0]),
                direction: v(pair[1]),
            })
        })
        .collect())
}
