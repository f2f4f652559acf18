//! The library embedded in an application: the test makes its own device and queue (as a
//! winit or Bevy app would), records several frames with different poses into one encoder,
//! writing the application's textures, submits once, and finds each texture bit for bit what
//! the one-call render (or the trace pass at that pose) gives.

use fisheye_rt::gpu::GpuContext;
use fisheye_rt::lens::{ImageSize, LensCamera, parse_spec};
use fisheye_rt::renderer::Renderer;
use fisheye_rt::scene::{Camera, Scene, builtin};
use fisheye_rt::trace::{Adaptive, GpuScene, PixelFilter, RenderOptions, TracePass, render};
use glam::DVec3;

/// The default adapter, found the plain wgpu way.
fn adapter() -> wgpu::Adapter {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
    pollster::block_on(instance.request_adapter(&Default::default()))
        .expect("these tests need a GPU adapter (or lavapipe)")
}

/// A device and queue made the plain wgpu way, with no optional features and `limits`.
fn device_with(limits: wgpu::Limits) -> (wgpu::Device, wgpu::Queue) {
    let adapter = adapter();
    let descriptor = wgpu::DeviceDescriptor {
        required_limits: limits,
        ..Default::default()
    };
    pollster::block_on(adapter.request_device(&descriptor)).unwrap()
}

/// A device with the limits the renderer documents.
fn own_device() -> (wgpu::Device, wgpu::Queue) {
    device_with(fisheye_rt::renderer::required_limits())
}

fn texture(device: &wgpu::Device, size: ImageSize, format: wgpu::TextureFormat) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("the application's view"),
        size: wgpu::Extent3d {
            width: size.width,
            height: size.height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// A built-in scene and a camera through `lens` at `width`×`height`.
fn view(scene: &str, lens: &str, width: u32, height: u32) -> (Scene, LensCamera) {
    let camera = LensCamera::new(
        parse_spec(lens).unwrap(),
        ImageSize::new(width, height).unwrap(),
    );
    (builtin::scene(scene).unwrap(), camera)
}

/// Asserts two images are equal bit for bit, saying how many pixels differ if not.
fn assert_same(what: &str, a: &[[f32; 4]], b: &[[f32; 4]]) {
    assert_eq!(a.len(), b.len(), "{what}: sizes");
    let bits = |c: &[f32; 4]| c.map(f32::to_bits);
    let differing = a.iter().zip(b).filter(|(x, y)| bits(x) != bits(y)).count();
    assert_eq!(
        differing,
        0,
        "{what}: {differing} of {} pixels differ",
        a.len()
    );
}

/// Asserts each pixel of `a` is, bit for bit, either `b`'s or `c`'s, and some are `c`'s
/// alone.
fn assert_each_of(what: &str, a: &[[f32; 4]], b: &[[f32; 4]], c: &[[f32; 4]]) {
    assert!(a.len() == b.len() && a.len() == c.len(), "{what}: sizes");
    let bits = |x: &[f32; 4]| x.map(f32::to_bits);
    let mut from_c = 0;
    for (i, ((x, y), z)) in a.iter().zip(b).zip(c).enumerate() {
        if bits(x) != bits(y) {
            assert_eq!(bits(x), bits(z), "{what}: pixel {i} is neither");
            from_c += 1;
        }
    }
    assert!(from_c > 0, "{what}: every pixel is the first image's");
}

#[test]
fn frames_recorded_into_the_callers_encoder_and_texture_match_the_one_call_render() {
    let (device, queue) = own_device();
    let (scene, camera) = view("default", "samyang-7.5mm", 96, 72);
    let options = RenderOptions::default();
    let format = wgpu::TextureFormat::Rgba32Float;
    let renderer = Renderer::new(&device, &queue, &scene, &camera, &options, format).unwrap();
    let home = scene.camera;
    let moved = Camera {
        position: home.position + DVec3::new(0.6, -0.2, 0.4),
        look_at: home.look_at + DVec3::new(-0.8, 0.3, 0.0),
        up: DVec3::Y,
    };
    // The last target is the one the renderer offers.
    let targets: Vec<wgpu::Texture> = (0..3)
        .map(|i| match i {
            2 => renderer.target_texture(&device),
            _ => texture(&device, camera.size, format),
        })
        .collect();
    let mut encoder = device.create_command_encoder(&Default::default());
    for (pose, target) in [home, moved, home].iter().zip(&targets) {
        renderer.encode(&mut encoder, pose, target).unwrap();
    }
    queue.submit([encoder.finish()]);

    // The library's own conveniences on the same device, for the expected images.
    let ctx = GpuContext::from_device(&device, &queue);
    let at_home = render(&ctx, &scene, &camera, &options).unwrap();
    let gpu_scene = GpuScene::new(&ctx, &scene, &options).unwrap();
    let pass = TracePass::new(&ctx, &camera, &gpu_scene, options.directions).unwrap();
    pass.set_pose(&ctx, &gpu_scene, &moved);
    let at_moved = pass.trace(&ctx, &gpu_scene, "tracing").unwrap();
    // The trace pass's buffers hold the last frame's outputs.
    let [colour, _, ids] = renderer.outputs().expect("a traced frame");
    assert_same(
        "the last frame's colour buffer",
        &ctx.read_buffer(colour).unwrap(),
        &at_home.colour,
    );
    assert_eq!(ctx.read_buffer::<u32>(ids).unwrap(), at_home.ids);
    let read_back = renderer.read_back().unwrap();
    assert_same("the read-back colour", &read_back.colour, &at_home.colour);
    assert_eq!(read_back.ids, at_home.ids);
    assert_eq!(read_back.geometry, at_home.geometry);
    let read = |t: &wgpu::Texture| ctx.read_texture(t).unwrap();
    assert_same("the first frame", &read(&targets[0]), &at_home.colour);
    assert_same("the moved frame", &read(&targets[1]), &at_moved.colour);
    assert_same("the third frame", &read(&targets[2]), &at_home.colour);
    assert_ne!(at_home.colour, at_moved.colour);
}

/// Through a cube map (traced and rasterized faces), one frame a submission: the caller's
/// texture holds what the library's own cube-map render gives, bit for bit.
#[test]
fn cube_map_frames_match_the_cube_map_render() {
    use fisheye_rt::cube::{CubeMap, CubeMethod, CubeSettings};
    use fisheye_rt::raster::RasterMethod;
    let (device, queue) = own_device();
    let (scene, camera) = view("default", "canon-8-15mm@8mm", 64, 48);
    let options = RenderOptions::default();
    let format = wgpu::TextureFormat::Rgba32Float;
    let ctx = GpuContext::from_device(&device, &queue);
    let gpu_scene = GpuScene::new(&ctx, &scene, &options).unwrap();
    for method in [
        CubeMethod::Traced,
        CubeMethod::Raster(RasterMethod::Forward),
    ] {
        let settings = CubeSettings {
            shadow_size: 256,
            ..CubeSettings::new(32, method)
        };
        let renderer = Renderer::through_cube(
            &device, &queue, &scene, &camera, &options, &settings, format,
        )
        .unwrap();
        assert!(renderer.outputs().is_none());
        let target = texture(&device, camera.size, format);
        let mut encoder = device.create_command_encoder(&Default::default());
        renderer
            .encode(&mut encoder, &scene.camera, &target)
            .unwrap();
        queue.submit([encoder.finish()]);
        let expected = CubeMap::new(&ctx, &camera, &gpu_scene, &settings)
            .unwrap()
            .render(&ctx, &gpu_scene, &scene.camera)
            .unwrap();
        assert_same(
            method.name(),
            &ctx.read_texture(&target).unwrap(),
            &expected,
        );
        let read_back = renderer.read_back().unwrap();
        assert_same(method.name(), &read_back.colour, &expected);
        assert!(
            read_back
                .ids
                .iter()
                .all(|&id| id == fisheye_rt::trace::NO_HIT)
        );
    }
}

/// An 8-bit target holds what the PNG holds: sRGB-encoded, clamped, alpha the mask (the GPU's
/// `pow` may round the last bit differently from Rust's, so a channel may differ by one).
#[test]
fn an_8_bit_target_holds_the_png_values() {
    let (device, queue) = own_device();
    let (scene, camera) = view("default", "canon-8-15mm@8mm", 64, 48);
    let options = RenderOptions::default();
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let renderer = Renderer::new(&device, &queue, &scene, &camera, &options, format).unwrap();
    let target = texture(&device, camera.size, format);
    let mut encoder = device.create_command_encoder(&Default::default());
    renderer
        .encode(&mut encoder, &scene.camera, &target)
        .unwrap();
    queue.submit([encoder.finish()]);
    let ctx = GpuContext::from_device(&device, &queue);
    let texels = ctx.read_texture_bytes(&target).unwrap();
    let png = render(&ctx, &scene, &camera, &options).unwrap().to_image();
    let mut masked = 0;
    for (i, (t, p)) in texels.chunks_exact(4).zip(png.pixels()).enumerate() {
        assert_eq!(t[3], p[3], "alpha (the mask) at {i}");
        if p[3] == 0 {
            masked += 1;
            continue;
        }
        for k in 0..3 {
            assert!(t[k].abs_diff(p[k]) <= 1, "pixel {i}: {t:?} vs {:?}", p.0);
        }
    }
    assert!(masked > 0 && masked < texels.len() / 4);
}

/// A device one storage buffer short of the documented limits (wgpu's defaults have 8) is
/// refused, naming the limit; with them, the trace pipeline is created (the other tests).
#[test]
fn a_device_below_the_required_limits_is_refused_naming_the_limit() {
    let mut limits = fisheye_rt::renderer::required_limits();
    limits.max_storage_buffers_per_shader_stage -= 1;
    let (device, queue) = device_with(limits);
    let (scene, camera) = view("grid", "equidistant:f=0.4", 32, 24);
    let format = wgpu::TextureFormat::Rgba16Float;
    let options = RenderOptions::default();
    let message = Renderer::new(&device, &queue, &scene, &camera, &options, format)
        .err()
        .expect("refused")
        .to_string();
    let needs = fisheye_rt::renderer::required_limits().max_storage_buffers_per_shader_stage;
    let said = format!(
        "max_storage_buffers_per_shader_stage is {}, the renderer needs {needs}",
        needs - 1
    );
    assert!(message.contains(&said), "{message}");
}

/// A scene split across storage bindings needs one more storage buffer per chunk beyond each
/// array's first: on a device with exactly the trace kernel's storage buffers (and bindings
/// of 1 MiB and 4 KiB, so that the grid's 12 triangles take one and a scene of 30,000
/// triangles two; the grid's texture left off) the first uploads and the second is refused with the chunks, the buffers
/// and the limit; a device with one storage buffer more uploads it.
#[test]
fn split_scenes_need_the_storage_buffers_they_name() {
    use fisheye_rt::scene::{Material, MeshBuilder};
    let mut limits = fisheye_rt::renderer::required_limits();
    limits.max_storage_buffers_per_shader_stage = fisheye_rt::shared::TRACE_STORAGE_BUFFERS;
    limits.max_storage_buffer_binding_size = (1 << 20) + 4096;
    let options = RenderOptions::default();
    let mut b = MeshBuilder::new();
    let grey = b.material(Material::diffuse("grey", glam::Vec3::splat(0.8)));
    for i in 0..30_000 {
        let p = DVec3::new(f64::from(i % 200), f64::from(i / 200), -10.0);
        b.triangle([p, p + DVec3::X, p + DVec3::Y], None, None, grey);
    }
    let camera = Camera {
        position: DVec3::new(100.0, 75.0, 50.0),
        look_at: DVec3::new(100.0, 75.0, -10.0),
        up: DVec3::Y,
    };
    let large = b.finish(Vec::new(), glam::Vec3::ONE, glam::Vec3::ZERO, camera);
    let (device, queue) = device_with(limits.clone());
    let ctx = GpuContext::from_device(&device, &queue);
    let mut grid = builtin::scene("grid").unwrap();
    for m in &mut grid.materials {
        m.diffuse_texture = None;
    }
    assert!(
        !GpuScene::new(&ctx, &grid, &options)
            .unwrap()
            .arrays
            .is_split()
    );
    let message = GpuScene::new(&ctx, &large, &options)
        .err()
        .expect("refused")
        .to_string();
    let has = fisheye_rt::shared::TRACE_STORAGE_BUFFERS;
    let over = format!(
        "would bind {} storage buffers, above the device's limit of {has} per shader stage",
        has + 1
    );
    for wanted in [
        "30000 triangles are too many for this device",
        "storage bindings of at most 1.00 MiB",
        "take 1, 2 and 1 bindings",
        &over,
    ] {
        assert!(message.contains(wanted), "{message:?} lacks {wanted:?}");
    }
    limits.max_storage_buffers_per_shader_stage += 1;
    let (device, queue) = device_with(limits);
    let ctx = GpuContext::from_device(&device, &queue);
    let split = GpuScene::new(&ctx, &large, &options).unwrap();
    assert_eq!(split.arrays.triangles.chunks, 2);
}

/// Textures the renderer cannot write are errors that say what it writes.
#[test]
fn unwritable_targets_are_errors_naming_what_is_wanted() {
    let (device, queue) = own_device();
    let (scene, camera) = view("grid", "equidistant:f=0.4", 32, 24);
    let options = RenderOptions::default();
    let message = Renderer::new(
        &device,
        &queue,
        &scene,
        &camera,
        &options,
        wgpu::TextureFormat::Bgra8UnormSrgb,
    )
    .err()
    .expect("refused")
    .to_string();
    assert!(
        message.contains("Bgra8UnormSrgb") && message.contains("Rgba16Float"),
        "{message}"
    );
    let format = wgpu::TextureFormat::Rgba16Float;
    let renderer = Renderer::new(&device, &queue, &scene, &camera, &options, format).unwrap();
    let wrong_size = texture(&device, ImageSize::new(33, 24).unwrap(), format);
    let wrong_format = texture(&device, camera.size, wgpu::TextureFormat::Rgba32Float);
    let mut encoder = device.create_command_encoder(&Default::default());
    for (target, wanted) in [(&wrong_size, "33x24x1"), (&wrong_format, "Rgba32Float")] {
        let message = renderer
            .encode(&mut encoder, &scene.camera, target)
            .expect_err("refused")
            .to_string();
        assert!(
            message.contains(wanted) && message.contains("32x24 Rgba16Float"),
            "{message}"
        );
    }
}

/// Progressive frames (`Renderer::encode_progressive`): the first at a pose is the adaptive
/// frame below one ray a pixel (with the pixels beside edges that it interpolates traced:
/// there one ray a pixel's colour), frames at the same pose sharpen it into the whole
/// adaptive frame, and a move starts again; frames with uniform sampling are whole from the
/// first, and so are adaptive frames of one ray at most, through the tent filter too.
#[test]
fn progressive_frames_sharpen_while_still_and_restart_on_a_move() {
    let (device, queue) = own_device();
    let (scene, camera) = view("default", "samyang-7.5mm", 64, 48);
    let format = wgpu::TextureFormat::Rgba32Float;
    let sampled = |spp: u32, adaptive: bool| RenderOptions {
        spp,
        adaptive: adaptive.then_some(Adaptive {
            threshold: Adaptive::DEFAULT_THRESHOLD,
            ground_truth: false,
            every_pixel: false,
        }),
        ..RenderOptions::default()
    };
    let ctx = GpuContext::from_device(&device, &queue);
    let image = |options: &RenderOptions| render(&ctx, &scene, &camera, options).unwrap().colour;
    let home = scene.camera;
    let moved = Camera {
        position: home.position + DVec3::new(0.3, 0.0, 0.2),
        ..home
    };
    let tent = |options: RenderOptions| RenderOptions {
        filter: PixelFilter::Tent,
        ..options
    };
    let one_ray = image(&sampled(1, false));
    for (options, first, last) in [
        (sampled(16, true), sampled(1, true), sampled(16, true)),
        (
            tent(sampled(1, true)),
            tent(sampled(1, true)),
            tent(sampled(1, true)),
        ),
        (sampled(4, false), sampled(4, false), sampled(4, false)),
    ] {
        let renderer = Renderer::new(&device, &queue, &scene, &camera, &options, format).unwrap();
        let target = renderer.target_texture(&device);
        let frame = |pose: &Camera| {
            let mut encoder = device.create_command_encoder(&Default::default());
            renderer
                .encode_progressive(&mut encoder, pose, &target)
                .unwrap();
            queue.submit([encoder.finish()]);
            ctx.read_texture(&target).unwrap()
        };
        for _ in 0..3 {
            frame(&moved);
        }
        let what = "the first frame after a move";
        if options.spp > 1 && options.adaptive.is_some() {
            assert_each_of(what, &frame(&home), &image(&first), &one_ray);
        } else {
            assert_same(what, &frame(&home), &image(&first));
        }
        // Each still frame supersamples a sixteenth of the pixels at 16 samples, at least:
        // 2 steps and 16 slices cover every pixel.
        let mut still = Vec::new();
        for _ in 0..18 {
            still = frame(&home);
        }
        assert_same("the still frames' end", &still, &image(&last));
        assert_same("a frame after that", &frame(&home), &still);
    }
}

/// Each kernel binds what it says, and runs where the device gives that many storage buffers
/// a stage: on a device with the trace kernel's 7, uniform sampling runs and adaptive
/// sampling and the direction table are refused, naming 8; on one with WebGPU's default 8
/// (the renderer's required limits) both run, with the images they make on a device with
/// every storage buffer lavapipe has, bit for bit.
#[test]
fn every_kernel_runs_within_the_storage_buffers_it_names() {
    use fisheye_rt::lens::gpu::DirectionSource;
    use fisheye_rt::shared::{ADAPTIVE_STORAGE_BUFFERS, TRACE_STORAGE_BUFFERS};
    let (scene, camera) = view("default", "samyang-7.5mm", 48, 36);
    let adaptive = RenderOptions {
        spp: 4,
        adaptive: Some(Adaptive {
            threshold: Adaptive::DEFAULT_THRESHOLD,
            ground_truth: true,
            every_pixel: false,
        }),
        ..RenderOptions::default()
    };
    let table = RenderOptions {
        directions: DirectionSource::Table,
        ..RenderOptions::default()
    };
    let on = |buffers: u32, options: &RenderOptions| {
        let (device, queue) = device_with(wgpu::Limits {
            max_storage_buffers_per_shader_stage: buffers,
            ..fisheye_rt::renderer::required_limits()
        });
        let ctx = GpuContext::from_device(&device, &queue);
        render(&ctx, &scene, &camera, options).map_err(|e| e.to_string())
    };
    let fewest = TRACE_STORAGE_BUFFERS;
    assert!(on(fewest, &RenderOptions::default()).is_ok());
    for (options, kernel) in [
        (&adaptive, "adaptive sampling"),
        (&table, "the trace kernel"),
    ] {
        let message = on(fewest, options).expect_err("refused");
        let said = format!("{kernel} binds 8 storage buffers, above this device's limit of 7");
        assert!(message.contains(&said), "{message}");
    }
    assert_eq!(TRACE_STORAGE_BUFFERS + ADAPTIVE_STORAGE_BUFFERS, 8);
    let most = adapter().limits().max_storage_buffers_per_shader_stage;
    assert!(most > 8, "lavapipe gives more than WebGPU's default");
    for options in [&adaptive, &table] {
        let small = on(8, options).unwrap();
        let large = on(most, options).unwrap();
        assert_same("colour", &small.colour, &large.colour);
        assert_eq!(small.ids, large.ids);
    }
}

/// Marks around work whose passes take no timestamp writes of their own
/// (`Queries::mark`, as the web page times a frame the renderer records) span at least the
/// time the work's pass gives by its own timestamps, and at most the time from submission to
/// completion.
#[test]
fn marks_around_a_frame_span_its_passes() {
    use fisheye_rt::gpu::Queries;
    use fisheye_rt::lens::gpu::DirectionSource;
    let adapter = adapter();
    let descriptor = wgpu::DeviceDescriptor {
        required_features: wgpu::Features::TIMESTAMP_QUERY,
        required_limits: fisheye_rt::renderer::required_limits(),
        ..Default::default()
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor)).unwrap();
    let ctx = GpuContext::from_device(&device, &queue);
    let (scene, camera) = view("default", "samyang-7.5mm", 96, 72);
    let gpu_scene = GpuScene::new(&ctx, &scene, &RenderOptions::default()).unwrap();
    let pass =
        TracePass::supersampled(&ctx, &camera, &gpu_scene, DirectionSource::Computed, 4).unwrap();
    let queries = Queries::new(&ctx, 2).expect("lavapipe has timestamp queries");
    for _ in 0..3 {
        let mut encoder = device.create_command_encoder(&Default::default());
        queries.mark(&mut encoder, 0, true);
        pass.encode(&mut encoder, &gpu_scene, Some(queries.writes(1)));
        queries.mark(&mut encoder, 0, false);
        queries.resolve(&mut encoder);
        let started = std::time::Instant::now();
        queue.submit([encoder.finish()]);
        let ns = queries.read_ns(&ctx).unwrap();
        let wall = started.elapsed().as_nanos() as f64;
        let (marked, own) = (ns[0], ns[1]);
        assert!(
            own > 0.0 && marked >= own,
            "marks {marked} ns, the pass {own} ns"
        );
        assert!(
            marked <= wall,
            "marks {marked} ns, {wall} ns from submission"
        );
    }
}

/// A moving scene (`scenes/dataset/sliding.toml`: a box sliding and turning over a second):
/// after `Renderer::place_at(t)` frames show what the one-call render draws of the scene
/// posed at `t` (`Scene::at`), bit for bit, directly and through a traced cube map, and the
/// box moves between 0.2 s and 0.8 s; a progressive frame after a place starts again (the
/// first frame at an unchanged pose is a new renderer's first), and placing at the same time
/// again lets refinement go on (the next frame sharpens it); a rasterized cube map, which
/// draws the scene flattened once, refuses it, saying what places moving instances.
#[test]
fn frames_placed_at_a_time_show_the_scene_posed_then() {
    use fisheye_rt::cube::{CubeMap, CubeMethod, CubeSettings};
    use fisheye_rt::raster::RasterMethod;
    let (device, queue) = own_device();
    let ctx = GpuContext::from_device(&device, &queue);
    let path = format!("{}/scenes/dataset/sliding.toml", env!("CARGO_MANIFEST_DIR"));
    let scene = fisheye_rt::scene::load(&path).unwrap().scene;
    assert_eq!(scene.key_span(), Some((0.0, 1.0)), "the keys' times");
    let camera = LensCamera::new(
        parse_spec("equidistant:f=0.5,fov=180").unwrap(),
        ImageSize::new(64, 48).unwrap(),
    );
    let format = wgpu::TextureFormat::Rgba32Float;
    let options = RenderOptions {
        spp: 4,
        ..RenderOptions::default()
    };
    let draw = |renderer: &Renderer, progressive: bool| {
        let target = renderer.target_texture(&device);
        let mut encoder = device.create_command_encoder(&Default::default());
        if progressive {
            renderer.encode_progressive(&mut encoder, &scene.camera, &target)
        } else {
            renderer.encode(&mut encoder, &scene.camera, &target)
        }
        .unwrap();
        queue.submit([encoder.finish()]);
        ctx.read_texture(&target).unwrap()
    };
    let renderer = Renderer::new(&device, &queue, &scene, &camera, &options, format).unwrap();
    let mut frames = Vec::new();
    for t in [0.2, 0.8] {
        renderer.place_at(&scene, t).unwrap();
        let expected = render(&ctx, &scene.at(t), &camera, &options)
            .unwrap()
            .colour;
        let frame = draw(&renderer, false);
        assert_same(&format!("rt at {t} s"), &frame, &expected);
        frames.push(frame);
    }
    let moved = frames[0].iter().zip(&frames[1]).filter(|(a, b)| a != b);
    assert!(moved.count() > 100, "the box moved between 0.2 and 0.8 s");

    let settings = CubeSettings::new(32, CubeMethod::Traced);
    let cube = Renderer::through_cube(
        &device, &queue, &scene, &camera, &options, &settings, format,
    )
    .unwrap();
    cube.place_at(&scene, 0.8).unwrap();
    let posed = scene.at(0.8);
    let gpu_scene = GpuScene::new(&ctx, &posed, &options).unwrap();
    let expected = CubeMap::new(&ctx, &camera, &gpu_scene, &settings)
        .unwrap()
        .render(&ctx, &gpu_scene, &scene.camera)
        .unwrap();
    assert_same("cube-rt at 0.8 s", &draw(&cube, false), &expected);

    let adaptive = RenderOptions {
        spp: 16,
        adaptive: Some(Adaptive {
            threshold: Adaptive::DEFAULT_THRESHOLD,
            ground_truth: false,
            every_pixel: false,
        }),
        ..RenderOptions::default()
    };
    let renderer = Renderer::new(&device, &queue, &scene, &camera, &adaptive, format).unwrap();
    renderer.place_at(&scene, 0.2).unwrap();
    for _ in 0..4 {
        draw(&renderer, true);
    }
    renderer.place_at(&scene, 0.8).unwrap();
    let after_place = draw(&renderer, true);
    let fresh = Renderer::new(&device, &queue, &scene, &camera, &adaptive, format).unwrap();
    fresh.place_at(&scene, 0.8).unwrap();
    assert_same(
        "the first frame after a place",
        &after_place,
        &draw(&fresh, true),
    );
    renderer.place_at(&scene, 0.8).unwrap();
    let placed_again = draw(&renderer, true);
    assert!(
        placed_again != after_place,
        "the same time placed again restarted the refinement"
    );

    let raster = CubeSettings::new(32, CubeMethod::Raster(RasterMethod::Forward));
    let flat = Renderer::through_cube(&device, &queue, &scene, &camera, &options, &raster, format)
        .unwrap();
    let error = flat.place_at(&scene, 0.5).unwrap_err().to_string();
    assert!(
        error.contains("flattened once") && error.contains("traced cube map"),
        "{error}"
    );
}
