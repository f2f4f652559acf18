//! Arbitrary rays cast into a scene on the GPU ([`RayCast`]): the tracer's own traversal
//! (`wgsl/bvh.wgsl`, through `wgsl/cast.wgsl`) without lens or shading, for rays the caller
//! makes (shadow rays, bounces, a peer's rays in the peer benchmark).

use glam::{DVec3, Vec3};

use super::GpuScene;
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::scene::{Light, Scene};
use crate::shader;
use crate::shared::WORKGROUP_1D;
pub use crate::shared::{CastRay, NO_HIT};

/// Where shadow rays of cast tests and the peer benchmark go, relative to the scene's camera
/// (the upload origin): the scene's first point light, else a point above the middle of its
/// bounds, as high as they are wide.
pub fn light(scene: &Scene) -> Vec3 {
    let at = scene
        .lights
        .iter()
        .find_map(|l| match l {
            Light::Point { position, .. } => Some(*position),
            _ => None,
        })
        .unwrap_or_else(|| {
            let (lo, hi) = scene.bounds().unwrap_or_default();
            (lo + hi) / 2.0 + DVec3::Y * (hi - lo).length()
        });
    (at - scene.camera.position).as_vec3()
}

/// What a cast ray found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CastHit {
    /// Distance along the ray's direction (its tmax on a miss).
    pub t: f32,
    /// The scene triangle hit (as ids name it), [`NO_HIT`] on a miss.
    pub triangle: u32,
    /// Barycentric weights of the triangle's corners 1 and 2.
    pub uv: [f32; 2],
}

/// The work one cast ray took, from a counting pass ([`RayCast::counting`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CastWork {
    /// Node groups the traversal expanded (each one node of obvhs's CWBVH, its eight
    /// children's boxes tested), the root's included: at least one a ray.
    pub nodes: u32,
    /// Triangles tested.
    pub triangles: u32,
}

/// The cast kernel for one scene: closest hits, or any hit (shadow rays).
pub struct RayCast {
    pipeline: wgpu::ComputePipeline,
    /// Whether it also counts each ray's work (`COUNT_WORK` in `wgsl/bvh.wgsl`).
    counts: bool,
}

/// Rays uploaded for [`RayCast::encode`], and where their hits (and work) go.
pub struct CastBatch {
    bind_group: wgpu::BindGroup,
    hits: wgpu::Buffer,
    work: wgpu::Buffer,
    count: u32,
}

impl RayCast {
    /// The kernel for `scene` (specialised to its instancing), finding the closest hit or,
    /// with `any_hit`, any hit.
    pub fn new(ctx: &GpuContext, scene: &GpuScene, any_hit: bool) -> Result<Self> {
        Self::build(ctx, scene, any_hit, false)
    }

    /// As [`RayCast::new`], counting each ray's work too ([`RayCast::read_work`]): the same
    /// hits, from a kernel that does a little more than the one [`RayCast::new`] makes, so
    /// time that one.
    pub fn counting(ctx: &GpuContext, scene: &GpuScene, any_hit: bool) -> Result<Self> {
        Self::build(ctx, scene, any_hit, true)
    }

    fn build(ctx: &GpuContext, scene: &GpuScene, any_hit: bool, counts: bool) -> Result<Self> {
        ctx.checked("creating the ray-cast pass", || {
            let constants = [
                ("ANY_HIT", f64::from(u8::from(any_hit))),
                ("INSTANCED", f64::from(u8::from(scene.features.instanced))),
                ("MOVING", f64::from(u8::from(scene.features.moving))),
                ("COUNT_WORK", f64::from(u8::from(counts))),
            ];
            let layout = ctx
                .device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("fisheye.cast"),
                    entries: &[
                        crate::gpu::storage_entry(0, true),
                        crate::gpu::storage_entry(1, false),
                        crate::gpu::storage_entry(2, false),
                    ],
                });
            Self {
                pipeline: shader::scene_pipeline(
                    &ctx.device,
                    "cast",
                    (&scene.arrays, &[]),
                    "main",
                    &constants,
                    &[&layout, &scene.layout],
                ),
                counts,
            }
        })
    }

    /// Uploads `rays` (origins relative to the scene's [`GpuScene::origin`]); refuses more
    /// than one dispatch or one storage binding holds.
    pub fn upload(&self, ctx: &GpuContext, rays: &[CastRay]) -> Result<CastBatch> {
        let limits = ctx.device.limits();
        let most = u64::from(limits.max_compute_workgroups_per_dimension) * u64::from(WORKGROUP_1D);
        if rays.len() as u64 > most {
            return Err(crate::error::Error::Limit(format!(
                "{} rays in one cast; one dispatch takes at most {most}",
                rays.len()
            )));
        }
        ctx.check_binding("the cast rays", std::mem::size_of_val(rays) as u64)?;
        let zero = [bytemuck::Zeroable::zeroed()];
        let data: &[CastRay] = if rays.is_empty() { &zero } else { rays };
        ctx.checked("uploading the cast rays", || {
            let device = &ctx.device;
            let input = crate::gpu::buffer_init(
                device,
                "fisheye.cast.rays",
                bytemuck::cast_slice(data),
                wgpu::BufferUsages::STORAGE,
            );
            let hits = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fisheye.cast.hits"),
                size: input.size() / 2,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            // 8 bytes a ray, written only by a counting pass (one ray's worth for a plain
            // pass, which binds it but never writes it).
            let work = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fisheye.cast.work"),
                size: if self.counts { input.size() / 4 } else { 8 },
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let bind_group = crate::gpu::bind_buffers(
                device,
                "fisheye.cast",
                &self.pipeline.get_bind_group_layout(0),
                &[&input, &hits, &work],
            );
            CastBatch {
                bind_group,
                hits,
                work,
                count: rays.len() as u32,
            }
        })
    }

    /// Records the cast of `batch` into `encoder`, timed by `timestamps` if given.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        batch: &CastBatch,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("fisheye.cast"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &batch.bind_group, &[]);
        pass.set_bind_group(1, &scene.bind_group, &[]);
        pass.dispatch_workgroups(batch.count.div_ceil(WORKGROUP_1D), 1, 1);
    }

    /// The hits of `batch`, once its cast has been submitted.
    pub fn read(&self, ctx: &GpuContext, batch: &CastBatch) -> Result<Vec<CastHit>> {
        let raw: Vec<[f32; 4]> = ctx.read_buffer(&batch.hits)?;
        Ok(raw
            .into_iter()
            .take(batch.count as usize)
            .map(|h| CastHit {
                t: h[0],
                triangle: h[1].to_bits(),
                uv: [h[2], h[3]],
            })
            .collect())
    }

    /// The work each ray of `batch` took, once its cast has been submitted; an error for a
    /// pass that does not count ([`RayCast::new`]'s).
    pub fn read_work(&self, ctx: &GpuContext, batch: &CastBatch) -> Result<Vec<CastWork>> {
        if !self.counts {
            return Err(crate::error::Error::Option(
                "this ray-cast pass does not count its work; make it with RayCast::counting".into(),
            ));
        }
        let raw: Vec<[u32; 2]> = ctx.read_buffer(&batch.work)?;
        Ok(raw
            .into_iter()
            .take(batch.count as usize)
            .map(|[nodes, triangles]| CastWork { nodes, triangles })
            .collect())
    }

    /// Uploads, casts and reads back `rays` in one call.
    pub fn cast(
        &self,
        ctx: &GpuContext,
        scene: &GpuScene,
        rays: &[CastRay],
    ) -> Result<Vec<CastHit>> {
        let batch = self.submit(ctx, scene, rays)?;
        self.read(ctx, &batch)
    }

    /// As [`RayCast::cast`], with each ray's work, for a counting pass.
    pub fn cast_counting(
        &self,
        ctx: &GpuContext,
        scene: &GpuScene,
        rays: &[CastRay],
    ) -> Result<(Vec<CastHit>, Vec<CastWork>)> {
        let batch = self.submit(ctx, scene, rays)?;
        Ok((self.read(ctx, &batch)?, self.read_work(ctx, &batch)?))
    }

    /// Uploads `rays` and submits their cast.
    fn submit(&self, ctx: &GpuContext, scene: &GpuScene, rays: &[CastRay]) -> Result<CastBatch> {
        let batch = self.upload(ctx, rays)?;
        ctx.checked("casting rays", || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, scene, &batch, None);
            ctx.queue.submit([encoder.finish()]);
        })?;
        Ok(batch)
    }
}
