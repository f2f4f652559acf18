//! GPU faults surface as errors: a device lost before or between the steps of a frame, a
//! failed allocation caught by the error scopes, and the same run twice is bit-identical.
//! Each test makes its own device, because losing it is the point.

use fisheye_rt::Error;
use fisheye_rt::cube::{CubeMap, CubeMethod, CubeSettings};
use fisheye_rt::gpu::{GpuContext, GpuJob};
use fisheye_rt::raster::RasterMethod;
use fisheye_rt::scene::builtin;
use fisheye_rt::trace::{Adaptive, AdaptivePass, GpuScene, RenderOptions, TracePass, render};

mod common;

fn lost(result: fisheye_rt::Result<impl Sized>, step: &str) {
    match result {
        Err(Error::DeviceLost(reason)) => assert!(reason.contains("Destroyed"), "{step}: {reason}"),
        Err(other) => panic!("{step}: expected a lost device, got: {other}"),
        Ok(_) => panic!("{step}: succeeded on a lost device"),
    }
}

/// A device lost at any step (scene upload, pass creation, a frame, a cube map by each
/// method) is reported as lost by the next step, which does nothing; nothing panics.
#[test]
fn a_lost_device_is_an_error_at_every_step() {
    let scene = builtin::scene("default").unwrap();
    let camera = common::camera("equidistant:f=0.5", 32, 24);
    let options = RenderOptions::default();

    let ctx = GpuContext::new().unwrap();
    ctx.device.destroy();
    lost(render(&ctx, &scene, &camera, &options), "render");

    let ctx = GpuContext::new().unwrap();
    let gpu_scene = GpuScene::new(&ctx, &scene, &options).unwrap();
    let pass = TracePass::new(&ctx, &camera, &gpu_scene, options.directions).unwrap();
    ctx.device.destroy();
    lost(pass.trace(&ctx, &gpu_scene, "a frame"), "a frame");
    lost(
        TracePass::new(&ctx, &camera, &gpu_scene, options.directions),
        "creating a pass",
    );
    let adaptive = Adaptive {
        threshold: 0.02,
        ground_truth: true,
        every_pixel: false,
    };
    lost(
        AdaptivePass::new(&ctx, &camera, &gpu_scene, options.directions, 16, adaptive),
        "creating adaptive sampling's passes",
    );
    for method in [
        CubeMethod::Traced,
        CubeMethod::Raster(RasterMethod::Forward),
        CubeMethod::Raster(RasterMethod::Deferred),
    ] {
        let settings = CubeSettings::new(16, method);
        lost(
            CubeMap::new(&ctx, &camera, &gpu_scene, &settings),
            method.name(),
        );
    }
}

/// An allocation the device refuses (here a buffer past its size limit) is caught by the
/// error scopes and named, not left to wgpu's default handler, which panics.
#[test]
fn refused_allocations_are_errors_naming_the_step() {
    let ctx = GpuContext::new().unwrap();
    let result = ctx.checked("allocating a huge buffer", || huge_buffer(&ctx));
    refused_and_survived(&ctx, result, "allocating a huge buffer");
}

/// A buffer past the device's size limit: a validation error where it is made.
fn huge_buffer(ctx: &GpuContext) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fisheye.test.huge"),
        size: ctx.device.limits().max_buffer_size + 4,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    })
}

/// `result`, of work that made a [`huge_buffer`], is its refusal, named as made `during`, and
/// the device survives it: the next step works.
fn refused_and_survived<T>(ctx: &GpuContext, result: fisheye_rt::Result<T>, during: &str) {
    match result {
        Err(Error::Gpu {
            during: named,
            message,
        }) => {
            assert_eq!(named, during);
            assert!(!message.is_empty());
        }
        Err(other) => panic!("wrong error: {other}"),
        Ok(_) => panic!("a buffer past max_buffer_size was created"),
    }
    let scene = builtin::scene("default").unwrap();
    let camera = common::camera("equidistant:f=0.5", 16, 16);
    render(ctx, &scene, &camera, &RenderOptions::default()).unwrap();
}

/// Work run side by side (`checked_each`, as adaptive sampling makes its kernels) gives its
/// values in order, and an error in one job, on a thread of its own, is caught by that
/// thread's error scopes (wgpu's are per thread) and named: not left to escape as an
/// uncaught error that would fail every later step.
#[test]
fn side_by_side_work_is_checked_on_its_own_thread() {
    let ctx = GpuContext::new().unwrap();
    let device = &ctx.device;
    let jobs: Vec<GpuJob<'_, u64>> = (1..=4u64)
        .map(|n| -> GpuJob<'_, u64> {
            Box::new(move || {
                let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("fisheye.test.small"),
                    size: 4 * n,
                    usage: wgpu::BufferUsages::STORAGE,
                    mapped_at_creation: false,
                });
                buffer.size()
            })
        })
        .collect();
    assert_eq!(
        ctx.checked_each("small buffers", jobs).unwrap(),
        [4, 8, 12, 16]
    );

    let jobs: Vec<GpuJob<'_, Option<wgpu::Buffer>>> = vec![
        Box::new(|| None),
        Box::new(|| Some(huge_buffer(&ctx))),
        Box::new(|| None),
    ];
    let result = ctx.checked_each("making buffers side by side", jobs);
    refused_and_survived(&ctx, result, "making buffers side by side");
}
