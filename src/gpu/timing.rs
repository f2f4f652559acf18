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

    /// The timestamp writes that time compute pass number `pass` on its own.
    pub fn writes(&self, pass: u32) -> wgpu::ComputePassTimestampWrites<'_> {
        self.span(pass)
            .compute(true, true)
            .expect("a pass that begins and ends the span")
    }

    /// Timed span number `span`, which may cover several passes.
    pub fn span(&self, span: u32) -> Span<'_> {
        assert!(span < self.passes, "timed span {span} of {}", self.passes);
        Span {
            set: &self.set,
            index: span,
        }
    }

    /// Records an empty compute pass that writes span `span`'s beginning (`first`) or its
    /// end, to time work recorded between two marks whose passes take no timestamp writes of
    /// their own (a frame recorded by [`crate::renderer::Renderer`]). Timestamps are written
    /// as the GPU reaches them in order, the end once the work before it is done (Vulkan's
    /// `vkCmdWriteTimestamp`); WebGPU leaves their relation to other passes to the
    /// implementation, and browsers quantise them.
    pub fn mark(&self, encoder: &mut wgpu::CommandEncoder, span: u32, first: bool) {
        encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("fisheye.timestamps.mark"),
            timestamp_writes: self.span(span).compute(first, !first),
        });
    }

    /// Resolves every timestamp; encode after the timed passes.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..2 * self.passes, &self.resolved, 0);
    }

    /// The resolved timestamps (`QUERY_RESOLVE | COPY_SRC`): copy them to a buffer of one's
    /// own to read them without blocking, and give them to [`Queries::durations_ns`].
    pub fn resolved(&self) -> &wgpu::Buffer {
        &self.resolved
    }

    /// The duration of each timed pass in nanoseconds, once the resolve has been submitted.
    pub fn read_ns(&self, ctx: &GpuContext) -> Result<Vec<f64>> {
        let ticks: Vec<u64> = ctx.read_buffer(&self.resolved)?;
        Ok(self.durations_ns(&ticks))
    }

    /// The duration of each timed span in nanoseconds from the resolved timestamps `ticks`.
    pub fn durations_ns(&self, ticks: &[u64]) -> Vec<f64> {
        ticks
            .chunks_exact(2)
            .map(|pair| pair[1].wrapping_sub(pair[0]) as f64 * self.period_ns)
            .collect()
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

/// One timed span of consecutive passes, compute or render: its first pass writes the
/// beginning timestamp and its last pass the end, so the span's time includes any gaps between
/// its passes.
#[derive(Clone, Copy)]
pub struct Span<'a> {
    set: &'a wgpu::QuerySet,
    index: u32,
}

impl<'a> Span<'a> {
    /// The beginning and end query indices a pass writes, `None` for a pass in the middle.
    fn indices(self, first: bool, last: bool) -> Option<(Option<u32>, Option<u32>)> {
        (first || last).then_some((
            first.then_some(2 * self.index),
            last.then_some(2 * self.index + 1),
        ))
    }

    /// The writes of a compute pass in the span: the `first` pass begins it, the `last` ends
    /// it (one pass may be both).
    pub fn compute(self, first: bool, last: bool) -> Option<wgpu::ComputePassTimestampWrites<'a>> {
        let (begin, end) = self.indices(first, last)?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: self.set,
            beginning_of_pass_write_index: begin,
            end_of_pass_write_index: end,
        })
    }

    /// As [`Span::compute`], for a render pass.
    pub fn render(self, first: bool, last: bool) -> Option<wgpu::RenderPassTimestampWrites<'a>> {
        let (begin, end) = self.indices(first, last)?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set: self.set,
            beginning_of_pass_write_index: begin,
            end_of_pass_write_index: end,
        })
    }
}

/// The median of some samples (the upper one of an even count); NaN if there are none.
pub fn median(samples: &[f64]) -> f64 {
    let mut v = samples.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}
