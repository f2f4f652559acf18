//! Bad input is a clear error naming the file, line or parameter, or a warning where the input
//! can be repaired; never a panic or a silently black image. The README's "Bad input" table
//! lists every case with the test that checks it; the last test here checks that each named
//! test exists.

use std::path::{Path, PathBuf};

use fisheye_rt::lens::gpu::DirectionSource;
use fisheye_rt::lens::parse_spec;
use fisheye_rt::scene::file::load_scene_file;
use fisheye_rt::scene::obj::load_obj;
use fisheye_rt::scene::{Camera, Material, MeshBuilder, Texture};
use fisheye_rt::trace::{GpuScene, RenderOptions, TracePass};
use glam::{DVec3, Vec3};

mod common;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fisheye-bad-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn error_of<T>(result: fisheye_rt::Result<T>) -> String {
    match result {
        Ok(_) => panic!("loaded"),
        Err(e) => e.to_string(),
    }
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// Each malformed OBJ or MTL line is an error naming the file and the line, the MTL colour of
/// one number among them (tobj would panic on it).
#[test]
fn malformed_obj_and_mtl_lines_name_the_file_and_line() {
    let dir = temp_dir("lines");
    let cases: [(&str, &str, &str, &[&str]); 10] = [
        (
            "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n",
            "",
            "a.obj",
            &["line 2", "found 2 values"],
        ),
        (
            "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n",
            "",
            "a.obj",
            &["line 2", "\"x\" is not a number"],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
            "",
            "a.obj",
            &["line 4", "at least 3 vertices"],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
            "",
            "a.obj",
            &["line 4", "index 0"],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -5 -2 -1\n",
            "",
            "a.obj",
            &["line 4", "index -5 reaches back"],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n",
            "",
            "a.obj",
            &["line 4", "index 99 is out of range"],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/7 2/1 3/1\n",
            "",
            "a.obj",
            &["line 5", "texture coordinate index 7"],
        ),
        (
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "newmtl m\nKd 0.5\n",
            "m.mtl",
            &["line 2", "`Kd` takes r g b"],
        ),
        (
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "newmtl m\nNs shiny\n",
            "m.mtl",
            &["line 2", "\"shiny\" is not a number"],
        ),
        (
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "Kd 1 1 1\n",
            "m.mtl",
            &["line 1", "before any `newmtl`"],
        ),
    ];
    for (i, (obj, mtl, file, wanted)) in cases.iter().enumerate() {
        write(&dir, "m.mtl", mtl.as_bytes());
        let path = write(&dir, "a.obj", obj.as_bytes());
        let message = error_of(load_obj(&path));
        assert!(message.contains(file), "case {i}: {message}");
        for w in *wanted {
            assert!(message.contains(w), "case {i}: {message:?} lacks {w:?}");
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// What can be repaired warns and loads: statements that are skipped, a material no MTL
/// defines, triangles of zero area (dropped, naming the mesh), UVs or normals on some faces of
/// a mesh only (that mesh renders without them).
#[test]
fn repairable_input_warns_naming_what_was_done() {
    let dir = temp_dir("warn");
    let obj = format!(
        "hello there\n{TRIANGLE}v 2 0 0\nvt 0 0\no flat\nusemtl ghost\nf 1/1 2/1 3/1\nf 1 2 4\n\
         o mixed\nf 1/1 2/1 3/1\nf 1 3 2\ncurv 0 1 1 2\n\
         vn 0 0 1\no halfsmooth\nf 1//1 2//1 3//1\nf 1 3 4\n\
         vn 0 0 0\no zero\nf 1//2 2//1 3//1\nf 1//1 3//1 4//1\n"
    );
    let path = write(&dir, "w.obj", obj.as_bytes());
    let loaded = load_obj(&path).unwrap();
    assert_eq!(loaded.scene.len(), 7);
    // No mesh kept its partial attributes. A triangle with a zero vertex normal (mesh
    // `zero`, triangle 5) gets its face normal at every corner; its neighbour keeps its own.
    let scene = &loaded.scene;
    assert!(scene.uvs.is_none());
    let normals = scene.normals.as_ref().expect("mesh `zero` has normals");
    let [a, b, c] = scene.triangles[5];
    let face = (b - a).cross(c - a).normalize().as_vec3();
    assert_eq!(normals[5], [face; 3]);
    assert_eq!(normals[6], [glam::Vec3::Z; 3]);
    let warnings = loaded.warnings.join("\n");
    for wanted in [
        "line 1: `hello` skipped: not an OBJ statement",
        "line 14: `curv` skipped: free-form",
        "line 8: usemtl \"ghost\": no MTL defines it; using grey",
        "mesh \"flat\": dropped 1 triangles of zero area",
        "mesh \"mixed\": some faces give texture coordinates and some do not",
        "mesh \"halfsmooth\": some faces give normals and some do not; ignoring its normals",
    ] {
        assert!(warnings.contains(wanted), "{warnings}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A file with nothing to render is an error that says why, not a picture of the sky.
#[test]
fn empty_scenes_are_errors_saying_why() {
    let dir = temp_dir("empty");
    let cases: [(&str, &str); 4] = [
        ("", "no triangles to render"),
        (
            "# only a comment\no nothing\nv 0 0 0\n",
            "no triangles to render",
        ),
        (
            "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n",
            "non-finite vertices",
        ),
        // Collinear corners away from the origin (at the origin, any mix-up of corner
        // differences and sums would look collinear too).
        ("v 1 1 1\nv 2 1 1\nv 3 1 1\nf 1 2 3\n", "of zero area"),
    ];
    for (i, (obj, wanted)) in cases.iter().enumerate() {
        let path = write(&dir, &format!("e{i}.obj"), obj.as_bytes());
        let message = error_of(load_obj(&path));
        assert!(
            message.contains(&format!("e{i}.obj")) && message.contains(wanted),
            "case {i}: {message}"
        );
    }
    write(&dir, "flat.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    let file = write(&dir, "s.toml", b"[[mesh]]\npath = \"flat.obj\"\n");
    let message = error_of(load_scene_file(&file));
    assert!(
        message.contains("s.toml") && message.contains("no triangles to render"),
        "{message}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// Files that are not what they claim: a folder, text that is not UTF-8, an unknown kind.
#[test]
fn unreadable_files_and_unknown_kinds_are_errors() {
    let dir = temp_dir("files");
    let folder = dir.join("folder.obj");
    std::fs::create_dir_all(&folder).unwrap();
    let message = error_of(load_obj(&folder));
    assert!(
        message.contains("folder.obj: cannot read the file: a folder, not a regular file"),
        "{message}"
    );
    let latin1 = write(&dir, "l.toml", b"# caf\xe9\n[[mesh]]\nshape = \"box\"\n");
    let message = error_of(load_scene_file(&latin1));
    assert!(
        message.contains("l.toml") && message.contains("not UTF-8"),
        "{message}"
    );
    let message = error_of(fisheye_rt::scene::load("scene.ply"));
    assert!(
        message.contains("scene.ply") && message.contains("(.obj)"),
        "{message}"
    );
    let message = error_of(fisheye_rt::scene::load("builtin:nope"));
    assert!(message.contains("no built-in scene \"nope\""), "{message}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Lens parameters outside their domain are errors naming the parameter and the range, or the
/// field of view the model reaches.
#[test]
fn lens_parameters_outside_their_domain_name_it() {
    let cases = [
        ("equidistant:f=0", "f = 0: must be finite and > 0"),
        ("equisolid:f=-1", "f = -1"),
        ("stereographic:f=nan", "f = NaN"),
        ("general:f=1,k1=0,k2=0.5", "k1 = 0"),
        ("general:f=1,k1=1,k2=1.5", "k2 = 1.5: must be in [-1, 1]"),
        ("equidistant:f=1,fov=0", "fov = 0"),
        ("equidistant:f=1,fov=400", "must be in (0, 360]"),
        (
            "rectilinear:f=1,fov=180",
            "rectilinear: cannot reach the requested 180° field of view: r grows without bound",
        ),
        (
            "orthographic:f=1,fov=200",
            "cannot reach the requested 200° field of view: its mapping stops increasing at a \
             180.00°",
        ),
        (
            "general:f=1,k1=1,k2=0.9,fov=250",
            "cannot reach the requested 250° field of view",
        ),
        (
            "kb:fx=190,cx=255,cy=255,k1=0.5,k2=-3,k3=0,k4=0,fov=200",
            "kb: cannot reach the requested 200° field of view: its mapping stops increasing",
        ),
        ("ds:fx=158,cx=254,cy=256,xi=0,alpha=1.5", "alpha = 1.5"),
        ("equidistant:f=1,g=2", "takes no parameter \"g\""),
        ("fisheye:f=1", "unknown model or preset"),
    ];
    for (spec, wanted) in cases {
        match parse_spec(spec) {
            Ok(lens) => panic!("{spec} parsed as {lens}"),
            Err(e) => assert!(e.to_string().contains(wanted), "{spec}: {e}"),
        }
    }
    // The edges themselves are reachable.
    for spec in [
        "orthographic:f=1,fov=180",
        "rectilinear:f=1,fov=179.9",
        "equidistant:f=1,fov=360",
    ] {
        parse_spec(spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
    }
}

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
    // binding: on an adapter whose bindings stop at 1 MiB, 256² fits in one dispatch and 257²
    // is traced in two bands of rows (tested bit for bit in `trace_gpu`), while a traced cube
    // map, whose six faces share one pass, is refused with the numbers.
    let small = fisheye_rt::gpu::GpuContext::with_binding_limit(1 << 20).unwrap();
    let grid = fisheye_rt::scene::builtin::scene("grid").unwrap();
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

/// Every test the README's "Bad input" table names exists, so the table cannot drift from the
/// tests.
#[test]
fn the_readme_table_names_tests_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let section = readme
        .split("## Bad input, limits and faults")
        .nth(1)
        .expect("the README has a \"Bad input, limits and faults\" section");
    let section = section.split("\n## ").next().unwrap();
    let mut sources = String::new();
    for dir in [
        "tests",
        "src",
        "src/scene",
        "src/lens",
        "src/trace",
        "src/dataset",
    ] {
        for entry in std::fs::read_dir(root.join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "rs") {
                sources.push_str(&std::fs::read_to_string(path).unwrap());
            }
        }
    }
    let mut rows = 0;
    for line in section.lines().filter(|l| l.starts_with('|')).skip(2) {
        rows += 1;
        let cells: Vec<&str> = line.split('|').collect();
        let tests = cells[cells.len() - 2];
        let names: Vec<&str> = tests
            .split('`')
            .skip(1)
            .step_by(2)
            .map(|t| t.rsplit("::").next().unwrap())
            .collect();
        assert!(!names.is_empty(), "a row names no test: {line}");
        for name in names {
            assert!(
                sources.contains(&format!("fn {name}(")),
                "the README names a test {name} that does not exist"
            );
        }
    }
    assert!(rows >= 20, "the table has {rows} rows");
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

/// The clauses of an error message (split at ": " and "; "), each of which must appear once:
/// a cause repeated in its own context ("X: reason: reason") reads as two failures.
fn repeated_clause(message: &str) -> Option<String> {
    let clauses: Vec<String> = message
        .split(": ")
        .flat_map(|c| c.split("; "))
        .map(|c| c.trim().to_lowercase())
        .filter(|c| c.len() > 3)
        .collect();
    clauses
        .iter()
        .enumerate()
        .find(|(i, c)| clauses[i + 1..].contains(c))
        .map(|(_, c)| c.clone())
}

/// One of each kind of error in the README's bad-input table, from the command line: exit
/// status 1, the problem named, no panic, no image, and no clause said twice (the OS's reason,
/// the file, the parameter).
/// `fisheye dataset render` of `trajectory` through `cameras` (`--lens SPEC` or `--rig FILE`)
/// into `out`, with `extra` arguments.
fn dataset<'a>(
    trajectory: &'a str,
    cameras: &'a str,
    which: &'a str,
    out: &'a str,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let mut args = vec![
        "dataset",
        "render",
        "--trajectory",
        trajectory,
        cameras,
        which,
    ];
    args.extend(["-o", out]);
    args.extend(extra);
    args
}

#[test]
fn every_error_says_each_clause_once() {
    assert_eq!(
        repeated_clause("a.obj: cannot read: No such file: No such file"),
        Some("no such file".into())
    );
    assert_eq!(
        repeated_clause("a.obj: line 4: broken; line 5: broken"),
        Some("broken".into())
    );
    assert_eq!(repeated_clause("a.obj: line 4: face vertex \"x\""), None);

    let dir = temp_dir("once");
    let at = |name: &str| dir.join(name).to_str().unwrap().to_string();
    std::fs::create_dir_all(dir.join("folder.obj")).unwrap();
    std::fs::create_dir_all(dir.join("folder.png")).unwrap();
    let status = std::process::Command::new("mkfifo")
        .arg(at("pipe.obj"))
        .status()
        .unwrap();
    assert!(status.success());
    let files: [(&str, String); 14] = [
        ("bad-face.obj", format!("{TRIANGLE}f 1 2 x\n")),
        ("bad-index.obj", format!("{TRIANGLE}f 1 2 9\n")),
        (
            "bad-mtl.obj",
            format!("mtllib bad.mtl\n{TRIANGLE}f 1 2 3\n"),
        ),
        ("bad.mtl", "newmtl m\nKd 1\n".into()),
        ("empty.obj", TRIANGLE.into()),
        ("text.txt", "hello\n".into()),
        (
            "key.toml",
            "[[mesh]]\npath = \"tri.obj\"\ncolour = 1\n".into(),
        ),
        (
            "scale.toml",
            "[[mesh]]\npath = \"tri.obj\"\nscale = 0.0\n".into(),
        ),
        ("zero.toml", "[[mesh]]\npath = \"/dev/zero\"\n".into()),
        ("tri.obj", format!("{TRIANGLE}f 1 2 3\n")),
        ("calib.yaml", "cam0:\n  camera_model: pinhole\n".into()),
        ("bad.tum", "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1 9\n".into()),
        (
            "two.yaml",
            "cam0:\n  camera_model: pinhole\n  intrinsics: [10, 10, 8, 6]\n  resolution: [16, \
             12]\ncam1:\n  camera_model: pinhole\n  intrinsics: [10, 10, 8, 6]\n  \
             resolution: [16, 12]\n"
                .into(),
        ),
        ("other/plan.json", "{}\n".into()),
    ];
    std::fs::create_dir_all(dir.join("other")).unwrap();
    for (name, text) in &files {
        write(&dir, name, text.as_bytes());
    }
    let out = at("out.png");
    let small = ["--size", "32x24", "--spp", "1"];
    const TUM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/dataset/room-loop.tum");
    const LENS: &str = "equidistant:f=1";
    let (set, other) = (at("set"), at("other"));
    type Case<'a> = (Vec<String>, Vec<(&'a str, &'a str)>, &'a str);
    let cases: Vec<Case> = [
        (
            vec!["render", "/nonexistent/scene.obj"],
            vec![],
            "scene.obj",
        ),
        (vec!["render", &at("folder.obj")], vec![], "a folder"),
        (vec!["render", &at("pipe.obj")], vec![], "a named pipe"),
        (vec!["render", &at("text.txt")], vec![], ".toml"),
        (vec!["render", "builtin:nope"], vec![], "nope"),
        (vec!["render", &at("bad-face.obj")], vec![], "line 4"),
        (vec!["render", &at("bad-index.obj")], vec![], "line 4"),
        (vec!["render", &at("bad-mtl.obj")], vec![], "bad.mtl"),
        (vec!["render", &at("empty.obj")], vec![], "empty.obj"),
        (vec!["render", &at("key.toml")], vec![], "colour"),
        (vec!["render", &at("scale.toml")], vec![], "scale"),
        (vec!["render", &at("zero.toml")], vec![], "a device"),
        (
            vec!["render", &at("tri.obj")],
            vec![("FISHEYE_MAX_INPUT_MIB", "0")],
            "budget",
        ),
        (vec!["render", "--lens", "nope:f=1"], vec![], "nope"),
        (vec!["render", "--lens", "equidistant:f=0"], vec![], "f"),
        (
            vec!["render", "--lens", "rectilinear:f=1,fov=180"],
            vec![],
            "180",
        ),
        (
            vec!["render", "--calib", &at("calib.yaml")],
            vec![],
            "calib.yaml",
        ),
        (vec!["render", "--size", "0x10"], vec![], "0x10"),
        (vec!["render", "--camera", "1,2:3"], vec![], "X,Y,Z"),
        (vec!["render", "--max-depth", "9"], vec![], "max-depth"),
        (vec!["render", "--exposure", "nan"], vec![], "exposure"),
        (vec!["render", "-o", &at("out.jpg")], vec![], "out.jpg"),
        (vec!["render", "-o", "/dev/full"], vec![], "/dev/full"),
        (vec!["render", "-o", &at("folder.png")], vec![], "a folder"),
        (
            vec!["render", "-o", "/proc/nope/x.png"],
            vec![],
            "/proc/nope",
        ),
        // A folder no one may write into: sysfs refuses new files, even to root.
        (
            vec!["render", "-o", "/sys/fisheye.png"],
            vec![],
            "/sys/fisheye.png",
        ),
        (
            vec!["render", "-o", "/sys/fisheye.png", "--outputs", "range"],
            vec![],
            "/sys/fisheye",
        ),
        (
            vec!["compare", "-o", "/sys/fisheye-compare"],
            vec![],
            "/sys/fisheye-compare",
        ),
        (
            vec!["render"],
            vec![("FISHEYE_INJECT_FAULT", "device-lost")],
            "device was lost",
        ),
        (
            dataset(&at("bad.tum"), "--lens", LENS, &set, &[]),
            vec![],
            "line 2: 9 fields",
        ),
        (
            dataset("/dev/zero", "--lens", LENS, &set, &[]),
            vec![],
            "a device",
        ),
        (
            dataset(&at("tri.obj"), "--lens", LENS, &set, &[]),
            vec![],
            "tri.obj: not a trajectory",
        ),
        (
            dataset(TUM, "--rig", &at("two.yaml"), &set, &[]),
            vec![],
            "cam1: no T_cn_cnm1",
        ),
        (
            dataset(TUM, "--lens", LENS, &set, &["--shard", "4/4"]),
            vec![],
            "shard 4 of 4 does not exist",
        ),
        (
            dataset(TUM, "--lens", LENS, &set, &["--t-body-rig", "1,2"]),
            vec![],
            "--t-body-rig \"1,2\" has 2 numbers",
        ),
        (
            dataset(TUM, "--lens", LENS, &set, &["--resume"]),
            vec![],
            "holds no dataset",
        ),
        (
            dataset(TUM, "--lens", LENS, &other, &[]),
            vec![],
            "plan of another dataset",
        ),
        (
            vec!["dataset", "merge", &at("folder.obj")],
            vec![],
            "holds no dataset",
        ),
    ]
    .into_iter()
    .map(|(args, env, needle)| {
        let mut args: Vec<String> = args.into_iter().map(String::from).collect();
        let merge = args.get(1).is_some_and(|a| a == "merge");
        if !args.iter().any(|a| a == "-o") && !merge {
            args.extend(["-o".to_string(), out.clone()]);
        }
        // Small and quick, unless the case sets the size (a calibration brings its own).
        let sized = args
            .iter()
            .any(|a| a == "--calib" || a == "--size" || a == "--rig");
        let keep = if sized { 2 } else { 0 };
        if !merge {
            args.extend(small[keep..].iter().map(|s| s.to_string()));
        }
        (args, env, needle)
    })
    .collect();
    for (args, env, needle) in cases {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_fisheye"))
            .args(&args)
            .envs(env.iter().copied())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        // 2 is clap's status for a value its parser refuses.
        let code = output.status.code();
        assert!(matches!(code, Some(1 | 2)), "{args:?}: {code:?} {stderr}");
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} lacks {needle:?}"
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(!Path::new(&out).exists(), "{args:?} wrote an image");
        for line in stderr.lines().filter(|l| l.starts_with("error")) {
            assert_eq!(repeated_clause(line), None, "{args:?}: {line}");
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}
