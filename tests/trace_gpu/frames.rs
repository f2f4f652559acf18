//! Frames: poses, reruns, deep BVHs, supersampling, bands, tables and bytes.

use super::*;

/// Primary rays read from the direction table render the same frame as rays computed per
/// pixel: the table holds what the lens kernel computes (measured: identical; contraction may
/// differ between the two kernels by an ulp, so they are held to the reference's tolerance).
#[test]
fn direction_table_renders_the_same_frame() {
    use fisheye_rt::lens::gpu::DirectionSource;
    let scene = builtin::scene("default").unwrap();
    let cam = camera("samyang-7.5mm", 96, 72);
    let computed = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    let options = RenderOptions {
        directions: DirectionSource::Table,
        ..RenderOptions::default()
    };
    let table = render(ctx(), &scene, &cam, &options).unwrap();
    assert_agrees("direction table", &table, &computed, SYNTHETIC);
    assert!(table.counts().1 > 5000);
}

/// A camera path moves the eye without uploading the scene again: a pose set on a pass renders
/// what a scene uploaded for that pose renders.
#[test]
fn camera_pose_set_on_a_pass_matches_a_fresh_upload() {
    use fisheye_rt::trace::{GpuScene, TracePass};
    let mut scene = builtin::scene("default").unwrap();
    let pose = Camera {
        position: scene.camera.position + DVec3::new(0.7, -0.3, 0.5),
        look_at: scene.camera.look_at + DVec3::new(-1.0, 0.5, 0.0),
        up: DVec3::Y,
    };
    let cam = camera("equidistant:f=0.45,fov=180", 96, 72);
    let options = RenderOptions::default();
    let gpu_scene = GpuScene::new(ctx(), &scene, &options).unwrap();
    let pass = TracePass::new(ctx(), &cam, &gpu_scene, options.directions).unwrap();
    pass.set_pose(ctx(), &gpu_scene, &pose);
    let mut encoder = ctx().device.create_command_encoder(&Default::default());
    pass.encode(&mut encoder, &gpu_scene, None);
    ctx().queue.submit([encoder.finish()]);
    let moved = pass.read(ctx()).unwrap();
    scene.camera = pose;
    let fresh = render(ctx(), &scene, &cam, &options).unwrap();
    assert_agrees("moved camera", &moved, &fresh, SYNTHETIC);
}

/// The same scene, lens and adapter give bit-identical outputs run to run, with the scene
/// uploaded afresh each time, and on a device of its own as a new process would make (the BVH
/// build is deterministic, traversal has no races, and the samples of several rays per pixel
/// are hashed from the pixel, not drawn from a random source).
#[test]
fn renders_are_bit_identical_run_to_run() {
    let scene = builtin::scene("default").unwrap();
    let cam = camera("samyang-7.5mm", 96, 72);
    let own_device = fisheye_rt::gpu::GpuContext::new().unwrap();
    let bits = |o: &fisheye_rt::trace::RenderOutput| -> Vec<u32> {
        let floats = o
            .colour
            .iter()
            .chain(&o.geometry)
            .flatten()
            .map(|x| x.to_bits());
        floats.chain(o.ids.iter().copied()).collect()
    };
    for spp in [1, 16] {
        let options = RenderOptions {
            spp,
            ..RenderOptions::default()
        };
        let first = render(ctx(), &scene, &cam, &options).unwrap();
        let second = render(ctx(), &scene, &cam, &options).unwrap();
        let third = render(&own_device, &scene, &cam, &options).unwrap();
        assert_eq!(bits(&first), bits(&second), "{spp} rays");
        assert_eq!(bits(&first), bits(&third), "{spp} rays");
    }
}

/// `count` triangles nested about one axis, each 2% larger and 2 mm farther than the last:
/// obvhs builds them into a chain (the smallest deepest), about one level per seven triangles
/// (obvhs 0.4's `fast` preset gives 227 of them 32 levels).
fn nested_triangles(count: i32) -> fisheye_rt::scene::Scene {
    let mut b = MeshBuilder::new();
    let m = b.material(Material::diffuse("nested", Vec3::ONE));
    for k in 0..count {
        let (s, z) = (1.02f64.powi(k), 0.002 * f64::from(k));
        let corners = [
            DVec3::new(-s, -s, z),
            DVec3::new(s, -s, z),
            DVec3::new(0.0, s, z),
        ];
        b.triangle(corners, None, None, m);
    }
    b.finish(
        Vec::new(),
        Vec3::ZERO,
        Vec3::ONE,
        Camera {
            position: DVec3::new(0.1, 0.2, -1.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        },
    )
}

/// A BVH exactly as deep as the traversal stack renders as the reference does (a ray near
/// the axis walks the whole chain to the smallest triangle); one level deeper is refused,
/// never traversed wrongly.
#[test]
fn bvh_as_deep_as_the_stack_renders_and_deeper_is_refused() {
    use fisheye_rt::bvh::{BvhQuality, SceneBvh, TRAVERSAL_STACK};
    let full = nested_triangles(227);
    let depth = |scene: &fisheye_rt::scene::Scene| {
        SceneBvh::build(scene, scene.camera.position, BvhQuality::Fast, false).map(|b| b.depth)
    };
    assert_eq!(depth(&full).unwrap(), TRAVERSAL_STACK);
    let (gpu, cpu) = both(&full, &camera("rectilinear:f=0.8", 64, 48));
    assert!(gpu.counts().1 == 64 * 48, "every ray hits a triangle");
    assert_agrees("a BVH as deep as the stack", &gpu, &cpu, SYNTHETIC);
    let ids: std::collections::HashSet<_> = gpu.ids.iter().collect();
    assert!(ids.len() > 20, "{} triangles seen", ids.len());

    // Depth is not monotonic in the count (obvhs's clustering); 229 gives one level more.
    let message = depth(&nested_triangles(229))
        .expect_err("refused")
        .to_string();
    assert!(
        message.contains(&format!("{} levels deep", TRAVERSAL_STACK + 1))
            && message.contains(&format!("holds {TRAVERSAL_STACK}")),
        "{message}"
    );
}

/// Several rays per pixel: the GPU places and shades the same samples (`sample_offset`) as
/// the f64 reference (the WGSL hash and its Rust twin agree), reruns are bit-identical, the
/// colour's w is the share of the pixel the lens covers (between 0 and 1 only along the image
/// circle's edge), and the ground truth stays the centre ray's.
#[test]
fn supersampled_renders_match_the_reference() {
    let scene = builtin::scene("default").unwrap();
    let cam = camera("canon-8-15mm@8mm", 64, 48);
    let options = RenderOptions {
        spp: 16,
        ..RenderOptions::default()
    };
    let gpu = render(ctx(), &scene, &cam, &options).unwrap();
    let cpu = Reference::new(&scene, options.max_depth).render_samples(&cam, 4);
    assert_agrees("16 rays per pixel", &gpu, &cpu, SYNTHETIC);
    let again = render(ctx(), &scene, &cam, &options).unwrap();
    assert!(gpu.colour == again.colour && gpu.ids == again.ids);
    let single = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    assert_eq!(gpu.ids, single.ids, "the ground truth is the centre ray's");
    assert_eq!(gpu.geometry, single.geometry);
    // Coverage: full inside the circle, partial on its edge (and only there), none outside.
    let partial: Vec<usize> = (0..gpu.colour.len())
        .filter(|&i| gpu.colour[i][3] > 0.0 && gpu.colour[i][3] < 1.0)
        .collect();
    assert!(partial.len() > 20, "{} edge pixels", partial.len());
    for &i in &partial {
        let (x, y) = ((i % 64) as f64 + 0.5, (i / 64) as f64 + 0.5);
        let r = (x - 32.0).hypot(y - 24.0);
        // The 180° circle has a radius of 0.66 half-widths: 21.1 px.
        assert!((r - 21.1).abs() < 1.0, "partial coverage at radius {r}");
        assert_eq!(gpu.colour[i][3] * 16.0, (gpu.colour[i][3] * 16.0).round());
    }
}

/// The samples' rotated grid converges faster than independent random samples would:
/// against a 256-ray reference, the error (MSE of the displayed values) falls with the rays
/// per pixel N at least as N^-1.15 from 4 to 64 (stratification predicts N^-1.5 where edges
/// dominate, Mitchell 1996; independent samples give N^-1).
#[test]
fn supersampling_converges_at_the_stratified_rate() {
    let scene = builtin::scene("default").unwrap();
    let cam = camera("samyang-7.5mm", 64, 48);
    let image = |spp| {
        let options = RenderOptions {
            spp,
            ..RenderOptions::default()
        };
        render(ctx(), &scene, &cam, &options).unwrap().to_image()
    };
    let reference = image(256);
    let mse = |spp| {
        let im = image(spp);
        let n = im.len() as f64;
        im.iter()
            .zip(reference.iter())
            .map(|(a, b)| (f64::from(*a) - f64::from(*b)).powi(2) / (255.0 * 255.0))
            .sum::<f64>()
            / n
    };
    let errors: Vec<(u32, f64)> = [1, 4, 16, 64].into_iter().map(|s| (s, mse(s))).collect();
    let slope = (errors[3].1 / errors[1].1).ln() / 16f64.ln();
    eprintln!("MSE against 256 rays: {errors:?}; slope from 4 to 64: {slope:.2}");
    assert!(errors.windows(2).all(|w| w[1].1 < w[0].1), "{errors:?}");
    assert!(slope < -1.15, "{errors:?}: slope {slope:.2}");
}

/// An image whose outputs exceed one storage binding is traced in bands of rows, each copied
/// into the whole image's outputs, and is bit for bit the image traced in one dispatch: on an
/// adapter whose bindings stop at 1 MiB and 4 KiB (forced; the grid's texture, 4/3 MiB with its
/// mip levels, left off), 512x300 takes bands of 128, 128 and 44 rows. Checked at one and at four rays per pixel (the samples are hashed from the pixel's
/// index in the whole image), through `render`; a timed frame is `bench_gpu`'s
/// `banded_frames_are_timed_whole`.
#[test]
fn images_beyond_one_binding_are_traced_in_bands_bit_identically() {
    use fisheye_rt::lens::gpu::DirectionSource;
    use fisheye_rt::trace::{GpuScene, TracePass};
    let small = fisheye_rt::gpu::GpuContext::with_binding_limit((1 << 20) + 4096).unwrap();
    let mut scene = builtin::scene("grid").unwrap();
    for m in &mut scene.materials {
        m.diffuse_texture = None;
    }
    let cam = camera("equidistant:f=0.5", 512, 300);
    let gpu_scene = GpuScene::new(&small, &scene, &RenderOptions::default()).unwrap();
    let pass = TracePass::new(&small, &cam, &gpu_scene, DirectionSource::Computed).unwrap();
    assert_eq!(pass.bands(), 3);
    for spp in [1, 4] {
        let options = RenderOptions {
            spp,
            ..RenderOptions::default()
        };
        let banded = render(&small, &scene, &cam, &options).unwrap();
        let whole = render(ctx(), &scene, &cam, &options).unwrap();
        assert!(banded.colour == whole.colour, "{spp} rays: colour");
        assert!(banded.geometry == whole.geometry, "{spp} rays: geometry");
        assert!(banded.ids == whole.ids, "{spp} rays: ids");
        assert!(banded.counts().1 > 1000, "the grid is in view");
    }
}

/// The device bytes a scene reports are what its buffers hold: 48 bytes a triangle (three
/// `vec4<f32>`), 80 a BVH node (obvhs's `CwBvhNode`), and shading data and textures where the
/// default room has them (normals, UVs and its checker texture).
#[test]
fn scene_bytes_count_what_the_buffers_hold() {
    use fisheye_rt::trace::GpuScene;
    let scene = builtin::scene("default").unwrap();
    let gpu = GpuScene::new(ctx(), &scene, &RenderOptions::default()).unwrap();
    assert_eq!(gpu.bytes.geometry, 48 * u64::from(gpu.triangles));
    assert_eq!(gpu.bytes.bvh, 80 * gpu.bvh_nodes as u64);
    assert!(gpu.bytes.shading >= 48 * u64::from(gpu.triangles));
    assert!(gpu.bytes.textures > 0);
    let all = gpu.bytes.geometry + gpu.bytes.bvh + gpu.bytes.shading;
    assert_eq!(
        gpu.bytes.per_triangle(gpu.triangles),
        all as f64 / f64::from(gpu.triangles)
    );
}
