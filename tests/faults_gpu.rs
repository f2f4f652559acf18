//! GPU faults surface as errors: a device lost before or between the steps of a frame, a
//! failed allocation caught by the error scopes, and the same run twice is bit-identical.
//! Each test makes its own device, because losing it is the point.

use fisheye_rt::Error;
use fisheye_rt::cube::{CubeMap, CubeMethod, CubeSettings};
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::raster::RasterMethod;
use fisheye_rt::scene::builtin;
use fisheye_rt::trace::{GpuScene, RenderOptions, TracePass, render};

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
    let size = ctx.device.limits().max_buffer_size + 4;
    let result = ctx.checked("allocating a huge buffer", || {
        ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fisheye.test.huge"),
            size,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        })
    });
    match result {
        Err(Error::Gpu { during, message }) => {
            assert_eq!(during, "allocating a huge buffer");
            assert!(!message.is_empty());
        }
        Err(other) => panic!("wrong error: {other}"),
        Ok(_) => panic!("a buffer past max_buffer_size was created"),
    }
    // The device survives it: the next step works.
    let scene = builtin::scene("default").unwrap();
    let camera = common::camera("equidistant:f=0.5", 16, 16);
    render(&ctx, &scene, &camera, &RenderOptions::default()).unwrap();
}
