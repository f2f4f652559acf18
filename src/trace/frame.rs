//! A frame's passes as the render options say: uniform sampling ([`TracePass`]) or adaptive
//! sampling ([`AdaptivePass`]), behind one type for the callers that take either and only
//! want frames and their outputs: [`super::render`], `dataset render`, the Python package.

use super::{
    AdaptivePass, AdaptiveSpans, GpuScene, Motion, RenderOptions, RenderOutput, TracePass,
};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::lens::LensCamera;
use crate::scene::Camera;

/// The passes of one lens, image size and sampling on one scene.
pub enum FramePass {
    /// Every pixel the same rays (`RenderOptions::spp`).
    Uniform(Box<TracePass>),
    /// Rays where the image needs them (`RenderOptions::adaptive`).
    Adaptive(Box<AdaptivePass>),
}

impl FramePass {
    /// The passes `options` asks for (its directions, `spp`, `adaptive` and `filter`) through
    /// `camera`.
    pub fn new(
        ctx: &GpuContext,
        camera: &LensCamera,
        scene: &GpuScene,
        options: &RenderOptions,
    ) -> Result<Self> {
        let (source, spp) = (options.directions, options.spp);
        Ok(match options.adaptive {
            Some(adaptive) => {
                let mut pass = AdaptivePass::new(ctx, camera, scene, source, spp, adaptive)?;
                pass.set_filter(ctx, options.filter)?;
                FramePass::Adaptive(Box::new(pass))
            }
            None => {
                let mut pass = TracePass::supersampled(ctx, camera, scene, source, spp)?;
                pass.set_filter(ctx, options.filter)?;
                FramePass::Uniform(Box::new(pass))
            }
        })
    }

    /// The trace pass whose buffers hold the outputs.
    pub fn trace_pass(&self) -> &TracePass {
        match self {
            FramePass::Uniform(pass) => pass,
            FramePass::Adaptive(pass) => pass.trace_pass(),
        }
    }

    /// Records a frame seen from `pose`.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pose: &Camera,
    ) {
        self.trace_pass().encode_pose(device, encoder, scene, pose);
        self.encode_passes(encoder, scene);
    }

    /// Records a frame seen by a camera moving by `motion` (see
    /// [`TracePass::encode_motion`]).
    pub fn encode_motion(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        motion: &Motion,
    ) -> Result<()> {
        self.trace_pass()
            .encode_motion(device, encoder, scene, motion)?;
        self.encode_passes(encoder, scene);
        Ok(())
    }

    fn encode_passes(&self, encoder: &mut wgpu::CommandEncoder, scene: &GpuScene) {
        match self {
            FramePass::Uniform(pass) => pass.encode(encoder, scene, None),
            FramePass::Adaptive(pass) => pass.encode(encoder, scene, AdaptiveSpans::default()),
        }
        self.trace_pass().encode_filter(encoder, None);
    }

    /// Traces one frame from `pose`, reporting a GPU error as `what` failing, and reads it
    /// back.
    pub fn trace(
        &self,
        ctx: &GpuContext,
        scene: &GpuScene,
        pose: &Camera,
        what: &str,
    ) -> Result<RenderOutput> {
        ctx.checked(what, || {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode(&ctx.device, &mut encoder, scene, pose);
            ctx.queue.submit([encoder.finish()]);
        })?;
        self.trace_pass().read(ctx)
    }

    /// The rays each pixel's colour took in the last frame, row-major (the spp map):
    /// counted by adaptive sampling (read back); under uniform sampling `spp` at each pixel
    /// with a ray in `output` (that frame's outputs).
    pub fn rays_map(&self, ctx: &GpuContext, output: &RenderOutput) -> Result<Vec<u32>> {
        match self {
            FramePass::Uniform(pass) => Ok(output.uniform_rays(pass.samples_per_side().pow(2))),
            FramePass::Adaptive(pass) => pass.read_rays(ctx),
        }
    }
}
