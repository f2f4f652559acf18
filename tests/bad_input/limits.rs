//! Limits: sizes beyond the adapter, textures beyond a binding, values beyond f32, special
//! and oversized files.

use super::*;

/// Images, cube faces and shadow maps beyond what the adapter allows, and 0, are errors with
/// the limit; so is a bounce depth beyond the kernels' stack.
#[test]
fn sizes_beyond_the_adapter_are_errors_with_the_limit() {
    let ctx = common::ctx();
    let limits = ctx.device.limits();
    let max = limits.max_texture_dimension_2d;
    let scene = fisheye_rt::scene::builtin::scene("default").unwrap();
    let options = RenderOptions::default();
    let gpu_scene = GpuScene::new(ctx, &scene, &options).unwrap();
    let pass = |w: u32, h: u32| {
        let camera = common::camera("equidistant:f=0.5", w, h);
        TracePass::new(ctx, &camera, &gpu_scene, DirectionSource::Computed).map(|_| ())
    };
    let message = error_of(pass(max + 1, 8));
    assert!(
        message.contains(&format!("{}x8", max + 1))
            && message.contains(&format!("2D texture limit of {max}")),
        "{message}"
    );
    // Within the texture limit, but its outputs (16 bytes a pixel) are beyond one storage
    // binding: on an adapter whose bindings stop at 1 MiB and 4 KiB (the grid's texture left
    // off: 4/3 MiB with its mip levels), 256² fits in one dispatch and 257² is
    // traced in two bands of rows (tested bit for bit in `trace_gpu`), while a traced cube
    // map, whose six faces share one pass, is refused with the numbers.
    let small = fisheye_rt::gpu::GpuContext::with_binding_limit((1 << 20) + 4096).unwrap();
    let mut grid = fisheye_rt::scene::builtin::scene("grid").unwrap();
    for m in &mut grid.materials {
        m.diffuse_texture = None;
    }
    let small_scene = GpuScene::new(&small, &grid, &options).unwrap();
    let on_small = |side: u32| {
        let camera = common::camera("equidistant:f=0.5", side, side);
        TracePass::new(&small, &camera, &small_scene, DirectionSource::Computed).unwrap()
    };
    assert_eq!(on_small(256).bands(), 1);
    assert_eq!(on_small(257).bands(), 2);
    let traced = fisheye_rt::cube::CubeSettings::new(300, fisheye_rt::cube::CubeMethod::Traced);
    let lens = common::camera("equidistant:f=0.5", 64, 64);
    let message = error_of(fisheye_rt::cube::CubeMap::new(
        &small,
        &lens,
        &small_scene,
        &traced,
    ));
    assert!(
        message.contains("needs a storage buffer of")
            && message.contains("limit of 1.00 MiB per binding"),
        "{message}"
    );
    let camera = common::camera("equidistant:f=0.5", 16, 16);
    for (size, method) in [
        (0, fisheye_rt::cube::CubeMethod::Traced),
        (max, fisheye_rt::cube::CubeMethod::Traced),
        (
            max,
            fisheye_rt::cube::CubeMethod::Raster(fisheye_rt::raster::RasterMethod::Forward),
        ),
    ] {
        let settings = fisheye_rt::cube::CubeSettings::new(size, method);
        let message = error_of(fisheye_rt::cube::CubeMap::new(
            ctx, &camera, &gpu_scene, &settings,
        ));
        assert!(
            message.contains(&format!("cube face size {size}"))
                && message.contains(&format!("limit of {max}")),
            "{message}"
        );
    }
    let mut shadowless = fisheye_rt::cube::CubeSettings::new(
        16,
        fisheye_rt::cube::CubeMethod::Raster(fisheye_rt::raster::RasterMethod::Forward),
    );
    shadowless.shadow_size = 0;
    let message = error_of(fisheye_rt::cube::CubeMap::new(
        ctx,
        &camera,
        &gpu_scene,
        &shadowless,
    ));
    assert!(message.contains("shadow map size 0"), "{message}");
    let deep = RenderOptions {
        max_depth: 9,
        ..RenderOptions::default()
    };
    let message = error_of(GpuScene::new(ctx, &scene, &deep));
    assert!(
        message.contains("max depth 9 is above the limit of 8"),
        "{message}"
    );
}

/// A scene whose triangles cross the adapter's storage-binding limit (128 MiB on lavapipe and
/// by default; 1 MiB here, forced) is split across two bindings rather than refused (as many
/// as fit, then one more: one binding, then two; rendered bit for bit in `instancing_gpu`),
/// while one whose textures cross it is refused before the BVH is built, with the MiB and the
/// limit.
#[test]
fn textures_beyond_one_storage_binding_are_refused_with_the_numbers() {
    let limit = 1 << 20;
    let ctx = &fisheye_rt::gpu::GpuContext::with_binding_limit(limit).unwrap();
    let camera = Camera {
        position: DVec3::new(0.0, 0.0, 5.0),
        look_at: DVec3::ZERO,
        up: DVec3::Y,
    };
    // 48 bytes a triangle (`GpuTriangle`): as many as fit, then one more.
    let scene = |count: u64| {
        let mut b = MeshBuilder::new();
        let m = b.material(Material::diffuse("grey", Vec3::splat(0.8)));
        for i in 0..count {
            let x = (i % 4096) as f64;
            let y = (i / 4096) as f64;
            let p = DVec3::new(x, y, 0.0);
            b.triangle([p, p + DVec3::X, p + DVec3::Y], None, None, m);
        }
        b.finish(Vec::new(), Vec3::ONE, Vec3::ZERO, camera)
    };
    let count = limit / 48 + 1;
    let chunks = |count| {
        let gpu = GpuScene::new(ctx, &scene(count), &RenderOptions::default()).unwrap();
        gpu.arrays.triangles.chunks
    };
    assert_eq!((chunks(count - 1), chunks(count)), (1, 2));
    let limit_mib = format!("{:.0} MiB", limit as f64 / f64::from(1 << 20));

    // Textures: one square texture of just over the limit in RGBA8 texels.
    let side = ((limit / 4) as f64).sqrt() as u32 + 1;
    let mut b = MeshBuilder::new();
    let texture = b.texture(Texture {
        name: "huge".into(),
        width: side,
        height: side,
        rgba: vec![128; 4 * (side as usize).pow(2)],
    });
    let m = b.material(Material {
        diffuse_texture: Some(texture),
        ..Material::diffuse("textured", Vec3::ONE)
    });
    b.quad(
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::X * 2.0,
        DVec3::Y * 2.0,
        glam::Vec2::ONE,
        m,
    );
    let scene = b.finish(Vec::new(), Vec3::ONE, Vec3::ZERO, camera);
    let message = error_of(GpuScene::new(ctx, &scene, &RenderOptions::default()));
    assert!(
        message.contains("1 textures take") && message.contains(&limit_mib),
        "{message}"
    );
}

/// Values that f64 holds but the GPU's f32 cannot, which would reach the image as infinities
/// or NaN, are errors naming them: an MTL colour, a scene-file colour, a light far from the
/// camera.
#[test]
fn values_beyond_f32_are_errors_naming_them() {
    let dir = temp_dir("f32");
    write(&dir, "m.mtl", b"newmtl m\nKs 1e39 1 1\n");
    let obj = format!("mtllib m.mtl\n{TRIANGLE}f 1 2 3\n");
    let path = write(&dir, "a.obj", obj.as_bytes());
    let message = error_of(load_obj(&path));
    assert!(
        message.contains("m.mtl: line 2: `Ks`: \"1e39\" is beyond the f32 range"),
        "{message}"
    );
    write(&dir, "t.obj", format!("{TRIANGLE}f 1 2 3\n").as_bytes());
    let file = write(
        &dir,
        "s.toml",
        b"sky = [1e39, 0.0, 0.0]\n[[mesh]]\npath = \"t.obj\"\n",
    );
    let message = error_of(load_scene_file(&file));
    assert!(
        message.contains("sky") && message.contains("f32 range"),
        "{message}"
    );
    let file = write(
        &dir,
        "l.toml",
        b"[[mesh]]\npath = \"t.obj\"\n[[light]]\ntype = \"point\"\n\
          position = [1e39, 0.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\n",
    );
    let scene = load_scene_file(&file).unwrap().scene;
    let message = error_of(GpuScene::new(
        common::ctx(),
        &scene,
        &RenderOptions::default(),
    ));
    assert!(
        message.contains("light 1") && message.contains("f32 range"),
        "{message}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// Runs the CLI with its address space capped at `MIB` MiB (so that reading an endless
/// file would fail, not eat the machine) and kills it after a minute (so that a blocking read
/// fails the test instead of hanging it): the exit status and stderr.
fn fisheye_bounded(args: &[&str], env: &[(&str, &str)]) -> (Option<i32>, String) {
    use std::os::unix::process::CommandExt;
    const MIB: u64 = 100;
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_fisheye"));
    command
        .args(args)
        .envs(env.iter().copied())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped());
    // SAFETY: setrlimit is async-signal-safe, as a pre_exec closure must be.
    unsafe {
        command.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: MIB << 20,
                rlim_max: MIB << 20,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let mut child = command.spawn().unwrap();
    let started = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > std::time::Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("{args:?} still running after a minute");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    (output.status.code(), stderr)
}

/// Endless, special and oversized inputs: each is refused before it is read, with an error
/// naming the file and what it is (once), by a process held to 100 MiB of address space that
/// never gets to the GPU; budgets come from `FISHEYE_MAX_INPUT_MIB`.
#[test]
fn special_and_oversized_inputs_are_refused_within_bounds() {
    let dir = temp_dir("special");
    let at = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let mkfifo = |name: &str| {
        let status = std::process::Command::new("mkfifo")
            .arg(at(name))
            .status()
            .unwrap();
        assert!(status.success());
    };
    mkfifo("pipe.obj");
    mkfifo("pipe.toml");
    let triangle = format!("{TRIANGLE}f 1 2 3\n");
    write(
        &dir,
        "zero-mtl.obj",
        format!("mtllib /dev/zero\n{triangle}").as_bytes(),
    );
    write(&dir, "zero.mtl", b"newmtl m\nKd 1 1 1\nmap_Kd /dev/zero\n");
    let textured = format!("mtllib zero.mtl\nusemtl m\nvt 0 0\n{triangle}");
    write(&dir, "zero-texture.obj", textured.as_bytes());
    let light = "[[light]]\ntype = \"sun\"\ndirection = [0, -1, 0]\nirradiance = [1, 1, 1]\n";
    let scene = format!("[[mesh]]\npath = \"/dev/zero\"\n{light}");
    write(&dir, "zero-mesh.toml", scene.as_bytes());
    // 29 × 65,536 bytes (1.8 MiB) of comments and a triangle.
    let big = format!(
        "{}{triangle}",
        "# padding to make it larger.\n".repeat(65_536)
    );
    write(&dir, "big.obj", big.as_bytes());
    let one_mib = [("FISHEYE_MAX_INPUT_MIB", "1")];
    type Case<'a> = (Vec<String>, &'a [(&'a str, &'a str)], &'a str);
    let render = |extra: &[&str]| {
        let mut args = vec!["render".to_string(), "-o".into(), at("out.png")];
        args.extend(extra.iter().map(|s| s.to_string()));
        args
    };
    let cases: Vec<Case> = vec![
        (
            render(&[&at("pipe.obj")]),
            &[],
            "pipe.obj: cannot read the file: a named pipe, not a regular file",
        ),
        (
            render(&[&at("pipe.toml")]),
            &[],
            "pipe.toml: a named pipe, not a regular file",
        ),
        (render(&[&at("zero-mtl.obj")]), &[], "/dev/zero: the MTL of"),
        (
            render(&[&at("zero-texture.obj")]),
            &[],
            "/dev/zero: texture of material m: a device, not a regular file",
        ),
        (
            render(&[&at("zero-mesh.toml")]),
            &[],
            "/dev/zero: cannot read the file: a device, not a regular file",
        ),
        (
            render(&["--calib", "/dev/zero"]),
            &[],
            "/dev/zero: cannot read it: a device, not a regular file",
        ),
        (
            render(&[&at("big.obj")]),
            &one_mib,
            "big.obj: cannot read the file: 1.8 MiB, over the 1.0 MiB budget for OBJ files \
             (FISHEYE_MAX_INPUT_MIB sets it, in MiB)",
        ),
        (
            render(&[&at("big.obj")]),
            &[("FISHEYE_MAX_INPUT_MIB", "lots")],
            "FISHEYE_MAX_INPUT_MIB=\"lots\": give the budget as a whole number of MiB",
        ),
    ];
    for (args, env, needle) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, stderr) = fisheye_bounded(&args, env);
        assert_eq!(code, Some(1), "{args:?}: {stderr}");
        assert_eq!(stderr.matches(needle).count(), 1, "{args:?}: {stderr:?}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(!Path::new(&at("out.png")).exists(), "{args:?}");
    }
    // Within the budget the same file renders.
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .args([
            "render",
            &at("big.obj"),
            "--size",
            "16x12",
            "--spp",
            "1",
            "-o",
        ])
        .arg(at("out.png"))
        .env("FISHEYE_MAX_INPUT_MIB", "3")
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    std::fs::remove_dir_all(dir).unwrap();
}
