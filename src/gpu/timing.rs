//! Timestamp queries around compute passes, for benchmarks.

use super::GpuContext;
use crate::error::Result;

/// A set of begin/end timestamp pairs, one pair per timed pass.
pub struct Queries {
    set: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    passes: u32,
    period_ns: f64,
}

impl Queries {
    /// Room for `passes` timed passes; `None` if the device has no timestamp queries.
    pub fn new(ctx: &GpuContext, passes: u32) -> Option<Self> {
        let period_ns = f64::from(ctx.timestamp_period()?);
        let set = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("fisheye.timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: 2 * passes,
        });
        let resolved = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fisheye.timestamps.resolved"),
            size: 16 * u64::from(passes),
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Some(Self {
            set,
            resolved,
            passes,
            period_ns,
        })
    }

    /// The timestamp writes that time compute pass number `pass`.
    pub fn writes(&self, pass: u32) -> wgpu::ComputePassTimestampWrites<'_> {
        assert!(pass < self.passes, "timed pass {pass} of {}", self.passes);
        wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(2 * pass),
            end_of_pass_write_index: Some(2 * pass + 1),
        }
    }

    /// Resolves every timestamp; encode after the timed passes.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..2 * self.passes, &self.resolved, 0);
    }

    /// The duration of each timed pass in nanoseconds, once the resolve has been submitted.
    pub fn read_ns(&self, ctx: &GpuContext) -> Result<Vec<f64>> {
        let ticks: Vec<u64> = ctx.read_buffer(&self.resolved)?;
        Ok(ticks
            .chunks_exact(2)
            .map(|pair| pair[1].wrapping_sub(pair[0]) as f64 * self.period_ns)
            .collect())
    }
}
