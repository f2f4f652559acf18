//! The scene as a hardware acceleration structure, for [`Traversal::RayQuery`]: one bottom
//! level over the BVH's own triangle buffers (its corners are the vertices, three per slot;
//! one geometry per chunk of the triangles, so a hit's geometry and primitive indices give
//! its slot) and a top level with that one instance.
//!
//! [`Traversal::RayQuery`]: super::Traversal::RayQuery

use std::time::Duration;

use crate::clock::Stopwatch;

use crate::error::{Error, Result};
use crate::gpu::{GpuContext, bind_group};
use crate::split::Split;

/// A scene's acceleration structure and the bind group (`@group(2)` of `wgsl/bvh_rq.wgsl`)
/// that exposes it.
pub struct RayQueryScene {
    pub(crate) layout: wgpu::BindGroupLayout,
    pub(crate) bind_group: wgpu::BindGroup,
    /// Wall time of the driver's build (bottom and top level), submission to completion.
    pub build_time: Duration,
    _structures: (Option<wgpu::Blas>, wgpu::Tlas),
}

impl RayQueryScene {
    /// Whether the device can hold `triangles` in one bottom level, with a clear error if not.
    pub(crate) fn check(ctx: &GpuContext, triangles: u64) -> Result<()> {
        if !ctx.has(wgpu::Features::EXPERIMENTAL_RAY_QUERY) {
            return Err(Error::MissingFeature {
                what: "ray-query traversal",
                feature: "EXPERIMENTAL_RAY_QUERY",
                adapter: ctx.adapter_info().name,
            });
        }
        let limit = ctx.device.limits().max_blas_primitive_count;
        if triangles > u64::from(limit) {
            return Err(Error::Limit(format!(
                "{triangles} triangles: this adapter's acceleration structures hold at most \
                 {limit} per bottom level"
            )));
        }
        Ok(())
    }

    /// Builds the structures over `triangles` (the scene's triangle buffers, with
    /// `BLAS_INPUT`, holding `count` triangles split as `split` says) and waits for the build.
    pub(crate) fn new(
        ctx: &GpuContext,
        triangles: &[wgpu::Buffer],
        split: &Split,
        count: usize,
    ) -> Self {
        let device = &ctx.device;
        let sizes: Vec<wgpu::BlasTriangleGeometrySizeDescriptor> = split
            .ranges(count)
            .into_iter()
            .map(|range| wgpu::BlasTriangleGeometrySizeDescriptor {
                vertex_format: wgpu::VertexFormat::Float32x3,
                vertex_count: 3 * range.len() as u32,
                index_format: None,
                index_count: None,
                flags: wgpu::AccelerationStructureGeometryFlags::OPAQUE,
            })
            .collect();
        let flags = wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE;
        let mut tlas = device.create_tlas(&wgpu::CreateTlasDescriptor {
            label: Some("fisheye.scene.tlas"),
            max_instances: 1,
            flags,
            update_mode: wgpu::AccelerationStructureUpdateMode::Build,
        });
        // An empty scene has no bottom level, and an empty top level.
        let blas = (count > 0).then(|| {
            device.create_blas(
                &wgpu::CreateBlasDescriptor {
                    label: Some("fisheye.scene.blas"),
                    flags,
                    update_mode: wgpu::AccelerationStructureUpdateMode::Build,
                },
                wgpu::BlasGeometrySizeDescriptors::Triangles {
                    descriptors: sizes.clone(),
                },
            )
        });
        let identity = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        if let Some(blas) = &blas {
            tlas[0] = Some(wgpu::TlasInstance::new(blas, identity, 0, 0xff));
        }
        let started = Stopwatch::start();
        let mut encoder = device.create_command_encoder(&Default::default());
        let entries: Vec<wgpu::BlasBuildEntry<'_>> = blas
            .iter()
            .map(|blas| wgpu::BlasBuildEntry {
                blas,
                geometry: wgpu::BlasGeometries::TriangleGeometries(
                    sizes
                        .iter()
                        .zip(triangles)
                        .map(|(size, buffer)| wgpu::BlasTriangleGeometry {
                            size,
                            vertex_buffer: buffer,
                            first_vertex: 0,
                            // `GpuTriangle` is three vec4s whose xyz are the corners.
                            vertex_stride: 16,
                            index_buffer: None,
                            first_index: None,
                            transform_buffer: None,
                            transform_buffer_offset: None,
                        })
                        .collect(),
                ),
            })
            .collect();
        encoder.build_acceleration_structures(&entries, [&tlas]);
        ctx.queue.submit([encoder.finish()]);
        // Errors (a lost device) surface at the caller's next wait.
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        let build_time = started.elapsed();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fisheye.scene.acceleration"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::AccelerationStructure {
                    vertex_return: false,
                },
                count: None,
            }],
        });
        let bind_group = bind_group(
            device,
            "fisheye.scene.acceleration",
            &layout,
            [tlas.as_binding()],
        );
        Self {
            layout,
            bind_group,
            build_time,
            _structures: (blas, tlas),
        }
    }
}
