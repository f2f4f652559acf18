//! The tent filter ([`super::PixelFilter::Tent`]) on the GPU: one pass after a frame's rays,
//! from the trace kernel's colour output into a colour buffer of its own, so that the traced
//! colours stay as the kernels wrote them (adaptive sampling's stages, and progressive
//! refinement's steps, read their neighbours' traced colours). `wgsl/tent.wgsl` says how.

use crate::error::Result;
use crate::gpu::{GpuContext, bind_buffers, dispatch_over_image, storage_entry};
use crate::lens::ImageSize;
use crate::shader;

/// The tent filter of one image size: its kernel, and the filtered colours it writes.
pub struct Tent {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    filtered: wgpu::Buffer,
    size: ImageSize,
}

impl Tent {
    /// The filter of `traced` (an image of `size`'s colours, as the trace kernel writes them,
    /// in one storage binding).
    pub fn new(ctx: &GpuContext, size: ImageSize, traced: &wgpu::Buffer) -> Result<Self> {
        ctx.checked("creating the tent filter", || {
            let device = &ctx.device;
            let filtered = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fisheye.tent.filtered"),
                size: 16 * size.pixels() as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fisheye.tent"),
                entries: &[storage_entry(0, true), storage_entry(1, false)],
            });
            let constants = [
                ("WIDTH", f64::from(size.width)),
                ("HEIGHT", f64::from(size.height)),
            ];
            let pipeline = shader::compute_pipeline(device, "tent", "main", &constants, &[&layout]);
            let group = bind_buffers(device, "fisheye.tent", &layout, &[traced, &filtered]);
            Self {
                pipeline,
                group,
                filtered,
                size,
            }
        })
    }

    /// Records the filter of the colours traced so far, optionally timed.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        dispatch_over_image(
            encoder,
            "fisheye.tent",
            &self.pipeline,
            &[&self.group],
            self.size,
            timestamp_writes,
        );
    }

    /// The filtered colours (as [`super::RenderOutput::colour`]).
    pub fn colour_buffer(&self) -> &wgpu::Buffer {
        &self.filtered
    }
}
