//! The lens demo: a picture of what a lens does to the sphere of directions (a 10° grid and
//! rings every 30° off the axis), rendered on the GPU. It is also the frame whose cost
//! [`DirectionSource::Computed`] and [`DirectionSource::Table`] are benchmarked on.

use crate::error::Result;
use crate::gpu::{GpuContext, dispatch_over_image, storage_entry, uniform_entry};
use crate::lens::LensCamera;
use crate::lens::gpu::{DirectionSource, LensRays, lens_constants, params_buffer};
use crate::shader;
use crate::split::SceneArrays;

/// The demo pass for one camera: owns its pipeline, layout, output and (for the table
/// source) the direction table, computed once at creation.
pub struct LensDemo {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    pixels: wgpu::Buffer,
    camera: LensCamera,
}

impl LensDemo {
    /// Creates the pass; with [`DirectionSource::Table`] also computes the table (one
    /// [`LensRays`] dispatch, submitted here, not per frame).
    pub fn new(ctx: &GpuContext, camera: &LensCamera, source: DirectionSource) -> Result<Self> {
        ctx.check_image(camera.size)?;
        let bytes = 4 * camera.size.pixels() as u64;
        ctx.check_binding("the demo image", bytes)?;
        let table = LensRays::for_source(ctx, camera, source)?;
        ctx.checked("creating the lens demo", || {
            let device = &ctx.device;
            // The lens (wgsl/primary.wgsl), the table where directions are read from one
            // (wgsl/primary_table.wgsl), the pixels (wgsl/lens_demo.wgsl).
            let mut entries = vec![uniform_entry(0), storage_entry(2, false)];
            entries.extend(table.is_some().then(|| storage_entry(1, true)));
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.lens_demo"),
                entries: &entries,
            });
            let pipeline = shader::scene_pipeline(
                device,
                "lens_demo",
                (&SceneArrays::default(), source.swaps()),
                "main",
                &lens_constants(camera),
                &[&layout],
            );
            let pixels = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fisheye.lens_demo.pixels"),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let params = params_buffer(device, camera);
            let resources = [
                (0, params.as_entire_binding()),
                (2, pixels.as_entire_binding()),
            ];
            let table = table
                .as_ref()
                .map(|t| (1, t.directions.as_entire_binding()));
            let bind_group = crate::gpu::bind_group_at(
                device,
                "fisheye.lens_demo",
                &layout,
                resources.into_iter().chain(table),
            );
            Self {
                pipeline,
                bind_group,
                pixels,
                camera: *camera,
            }
        })
    }

    /// Records one frame, optionally timed.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        dispatch_over_image(
            encoder,
            "fisheye.lens_demo",
            &self.pipeline,
            &[&self.bind_group],
            self.camera.size,
            timestamp_writes,
        );
    }

    /// Renders one frame and reads it back.
    pub fn render(&self, ctx: &GpuContext) -> Result<image::RgbaImage> {
        ctx.checked("rendering the lens demo", || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, None);
            ctx.queue.submit([encoder.finish()]);
        })?;
        let pixels: Vec<u32> = ctx.read_buffer(&self.pixels)?;
        let bytes = bytemuck::cast_slice::<u32, u8>(&pixels).to_vec();
        let size = self.camera.size;
        Ok(image::RgbaImage::from_raw(size.width, size.height, bytes)
            .expect("the pixel buffer holds width × height RGBA8 pixels"))
    }
}
