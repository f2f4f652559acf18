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

    /// Times `frames` frames of one pass after `warmup` untimed ones: `encode(frame, encoder,
    /// writes)` records frame number `frame` (counting the warm-up) with the given timestamp
    /// writes on its pass. Returns each timed frame's GPU milliseconds.
    pub fn time_frames(
        &self,
        ctx: &GpuContext,
        warmup: usize,
        frames: usize,
        mut encode: impl FnMut(usize, &mut wgpu::CommandEncoder, wgpu::ComputePassTimestampWrites<'_>),
    ) -> Result<Vec<f64>> {
        let mut samples = Vec::with_capacity(frames);
        for frame in 0..warmup + frames {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            encode(frame, &mut encoder, self.writes(0));
            self.resolve(&mut encoder);
            ctx.queue.submit([encoder.finish()]);
            let ns = self.read_ns(ctx)?[0];
            if frame >= warmup {
                samples.push(ns * 1e-6);
            }
        }
        Ok(samples)
    }
}

/// The median of some samples (the upper one of an even count); NaN if there are none.
pub fn median(samples: &[f64]) -> f64 {
    let mut v = samples.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}
