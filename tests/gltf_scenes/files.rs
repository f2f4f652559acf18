//! Bad files, scene files placing glTF meshes, a glTF twin of an OBJ, instancing.

use super::*;

/// Bad files are errors naming the file and the object; none panics.
#[test]
fn bad_gltf_files_name_the_object() {
    let dir = temp_dir("bad");
    let mut doc = Doc::default();
    let positions = doc.positions(&TRIANGLE);
    let indices = doc.indices(&[0, 1, 7], 5123);
    let mesh = doc.mesh(vec![
        json!({"attributes": {"POSITION": positions}, "indices": indices}),
    ]);
    let root = doc.node(json!({"mesh": mesh}));
    let out_of_range = doc.write_glb(&dir, "index", &[root]);
    let missing = dir.join("missing.gltf");
    std::fs::write(
        &missing,
        doc.json(Some("nowhere.bin".into()), &[root]).to_string(),
    )
    .unwrap();
    let device = dir.join("device.gltf");
    std::fs::write(
        &device,
        doc.json(Some("/dev/zero".into()), &[root]).to_string(),
    )
    .unwrap();
    let short = dir.join("short.gltf");
    let mut json = doc.json(Some("short.bin".into()), &[root]);
    json["buffers"][0]["byteLength"] = json!(doc.bin.len() + 100);
    std::fs::write(dir.join("short.bin"), &doc.bin).unwrap();
    std::fs::write(&short, json.to_string()).unwrap();
    let base64 = dir.join("base64.gltf");
    let uri = "data:application/octet-stream,AAAA".to_string();
    std::fs::write(&base64, doc.json(Some(uri), &[root]).to_string()).unwrap();
    let broken = dir.join("broken.gltf");
    std::fs::write(
        &broken,
        "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{\"mesh\": 4}]}",
    )
    .unwrap();
    // Children shared between parents, 40 levels deep: 2^40 paths to the leaf, refused
    // after a bounded walk instead of traversed.
    let mut shared = Doc::default();
    let positions = shared.positions(&TRIANGLE);
    let mesh = shared.mesh(vec![json!({"attributes": {"POSITION": positions}})]);
    let mut below = shared.node(json!({"mesh": mesh}));
    for _ in 0..40 {
        let beside = shared.node(json!({"children": [below], "mesh": mesh}));
        below = shared.node(json!({"children": [beside, below]}));
    }
    let lattice = shared.write_glb(&dir, "lattice", &[below]);
    // A cycle (0 -> 1 -> 2 -> 1) is named as one, with the node that closes it.
    let mut looped = Doc::default();
    let positions = looped.positions(&TRIANGLE);
    let mesh = looped.mesh(vec![json!({"attributes": {"POSITION": positions}})]);
    let root = looped.node(json!({"children": [1]}));
    looped.node(json!({"children": [2], "mesh": mesh}));
    looped.node(json!({"children": [1]}));
    let cycle = looped.write_glb(&dir, "cycle", &[root]);
    let truncated = dir.join("truncated.glb");
    let whole = std::fs::read(&out_of_range).unwrap();
    std::fs::write(&truncated, &whole[..whole.len() / 2]).unwrap();
    let cases = [
        (
            &out_of_range,
            "index 7 in accessors[1] is beyond its 3 vertices",
        ),
        (&missing, "buffers[0]"),
        (&device, "a device"),
        (&short, "not the"),
        (&base64, "not base64"),
        (&broken, "not valid glTF"),
        (&truncated, "not valid glTF"),
        (&lattice, "children shared between parents"),
        (
            &cycle,
            "nodes[2] lists nodes[1] as a child, which is its own ancestor: the hierarchy has a \
             cycle (nodes[1] -> nodes[2] -> nodes[1])",
        ),
    ];
    for (path, wanted) in cases {
        let error = match load_gltf(path, None) {
            Ok(_) => panic!("{} loaded", path.display()),
            Err(e) => e.to_string(),
        };
        assert!(error.contains(wanted), "{error:?} lacks {wanted:?}");
        assert!(
            error.contains(&*path.file_name().unwrap().to_string_lossy()),
            "{error}"
        );
    }
    let error = load_gltf(&out_of_range, Some(3)).err().expect("no scene 3");
    assert!(error.to_string().contains("no scene 3"), "{error}");
}

/// A scene file places a glTF file's meshes as it places an OBJ's (`[[mesh]] path`), and
/// says that the file's lights and cameras are not used there.
#[test]
fn scene_files_place_gltf_meshes() {
    let dir = temp_dir("scene-file");
    let mut doc = Doc::default();
    let positions = doc.positions(&TRIANGLE);
    let mesh = doc.mesh(vec![json!({"attributes": {"POSITION": positions}})]);
    let root = doc.node(json!({"mesh": mesh, "translation": [0, 0, 1]}));
    doc.extra.insert(
        "cameras".into(),
        json!([{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}]),
    );
    let camera = doc.node(json!({"camera": 0}));
    doc.write_glb(&dir, "part", &[root, camera]);
    let file = dir.join("scene.toml");
    std::fs::write(
        &file,
        "[[mesh]]\npath = \"part.glb\"\ntranslation = [10.0, 0.0, 0.0]\n\n[[light]]\n\
         type = \"point\"\nposition = [0.0, 5.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\n",
    )
    .unwrap();
    let loaded = fisheye_rt::scene::load(file.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    let t = loaded.scene.triangles[0];
    assert!(close(t[1], DVec3::new(11.0, 0.0, 1.0)), "{t:?}");
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("lights and cameras are not used")),
        "{:?}",
        loaded.warnings
    );
}

/// A glTF twin of the Cornell box (its triangles and base colours written here from the
/// OBJ's own scene, in order, each material a rough dielectric) renders the same triangle at
/// every pixel, the same distances, and colours within the 4% Phong lobe that glTF's
/// dielectric F0 adds.
#[test]
fn a_gltf_twin_renders_the_triangles_its_obj_renders() {
    let dir = temp_dir("twin");
    let obj =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_box/CornellBox-Original.obj");
    let original = fisheye_rt::scene::obj::load_obj(&obj).unwrap().scene;
    let mut doc = Doc::default();
    let corners: Vec<[f32; 3]> = original
        .triangles
        .iter()
        .flatten()
        .map(|p| p.as_vec3().to_array())
        .collect();
    let positions = doc.positions(&corners);
    let mut primitives = Vec::new();
    for (t, &m) in original.material_of.iter().enumerate() {
        let indices = doc.indices(&[3 * t as u32, 3 * t as u32 + 1, 3 * t as u32 + 2], 5125);
        primitives.push(
            json!({"attributes": {"POSITION": positions}, "indices": indices,
            "material": m}),
        );
    }
    doc.materials = original
        .materials
        .iter()
        .map(|m| json!({"name": m.name, "emissiveFactor": m.emission.to_array(),
            "pbrMetallicRoughness": {"baseColorFactor": [m.diffuse.x, m.diffuse.y, m.diffuse.z, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 1.0}}))
        .collect();
    let mesh = doc.mesh(primitives);
    let root = doc.node(json!({"mesh": mesh}));
    let path = doc.write_glb(&dir, "cornell", &[root]);
    let mut twin = load_gltf(&path, None).unwrap().scene;
    assert_eq!(
        twin.triangles,
        original
            .triangles
            .iter()
            .map(|t| t.map(|p| p.as_vec3().as_dvec3()))
            .collect::<Vec<_>>()
    );
    twin.camera = original.camera;
    twin.lights = original.lights.clone();
    let camera = common::camera("samyang-7.5mm", 96, 72);
    let ctx = common::ctx();
    let options = RenderOptions::default();
    let a = render(ctx, &original, &camera, &options).unwrap();
    let b = render(ctx, &twin, &camera, &options).unwrap();
    assert_eq!(a.ids, b.ids);
    for (x, y) in a.geometry.iter().zip(&b.geometry) {
        assert!(
            (x[3] - y[3]).abs() <= 1e-5 * x[3].max(1.0),
            "range {} against {}",
            x[3],
            y[3]
        );
    }
    let mut worst = 0.0f32;
    for (x, y) in a.colour.iter().zip(&b.colour) {
        for k in 0..3 {
            worst = worst.max((x[k] - y[k]).abs());
        }
    }
    // glTF's dielectric F0 of 0.04 adds a Phong lobe (exponent 1) that the OBJ's `Ks 0`
    // lacks: at most 0.04 of a surface's irradiance, which the lamp makes about 1.2 on the
    // ceiling beside it (0.048 measured).
    assert!(worst < 0.055, "colours differ by {worst}");
}

/// Meshes that several nodes use are stored once and placed by instances, a mesh one node uses
/// is placed in the world; the instanced scene renders as its flattened copy (the same scene
/// triangle at every pixel off the ids' edges, colours as close as `tests/instancing_gpu.rs`
/// holds them), on the GPU and in the reference, mirrored node included. Scene files instance
/// entries that name the same file with the same material, and copy one with another
/// material.
#[test]
fn shared_meshes_are_instanced() {
    use fisheye_rt::scene::{Camera, Scene};
    use fisheye_rt::trace::cpu::Reference;
    let dir = temp_dir("instances");
    let mut doc = Doc::default();
    doc.materials.push(json!({"pbrMetallicRoughness":
        {"baseColorFactor": [0.8, 0.3, 0.2, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}));
    let (cube, floor) = doc.cube_and_floor(Some(0));
    let mut roots = vec![doc.node(json!({"mesh": floor}))];
    for (t, extra) in [
        ([-2.0, 0.0, -4.0], json!({})),
        (
            [0.5, 0.0, -5.0],
            json!({"rotation": [0.0, 0.38268343, 0.0, 0.9238795]}),
        ),
        ([2.5, 0.0, -4.0], json!({"scale": [-1.0, 1.5, 1.0]})),
    ] {
        let mut node = json!({"mesh": cube, "translation": t});
        for (k, v) in extra.as_object().unwrap() {
            node[k] = v.clone();
        }
        roots.push(doc.node(node));
    }
    let path = doc.write_glb(&dir, "cubes", &roots);
    let mut scene = load_gltf(&path, None)
        .unwrap_or_else(|e| panic!("{e}"))
        .scene;
    assert_eq!((scene.world_triangles, scene.triangles.len()), (2, 14));
    assert_eq!(scene.instances.len(), 3);
    assert_eq!(scene.len(), 2 + 3 * 12);
    scene.set_camera(Camera {
        position: DVec3::new(0.0, 2.5, 3.0),
        look_at: DVec3::new(0.0, 0.5, -4.0),
        up: DVec3::Y,
    });
    let flat = scene.flattened(usize::MAX).unwrap();
    let cam = common::camera("equidistant:f=0.5,fov=180", 128, 96);
    let pixels = 128 * 96;
    let gpu = |s: &Scene| render(common::ctx(), s, &cam, &RenderOptions::default()).unwrap();
    let cpu = |s: &Scene| Reference::new(s, 5).render(&cam);
    for (what, a, b) in [
        ("GPU", gpu(&scene), gpu(&flat)),
        ("reference", cpu(&scene), cpu(&flat)),
    ] {
        common::assert_agrees(what, &a, &b, common::real_scene(pixels));
        for k in 0..3 {
            let ids = 2 + 12 * k..2 + 12 * (k + 1);
            assert!(a.ids.iter().any(|id| ids.contains(id)), "{what}: cube {k}");
        }
    }

    // A scene file: the same glTF twice, and once with a material of its own.
    let file = dir.join("scene.toml");
    std::fs::write(
        &file,
        "[[mesh]]\npath = \"cubes.glb\"\n\n[[mesh]]\npath = \"cubes.glb\"\n\
         translation = [0.0, 0.0, -20.0]\n\n\
         [[mesh]]\npath = \"cubes.glb\"\ntranslation = [0.0, 0.0, 20.0]\n\
         material = { diffuse = [0.1, 0.1, 0.9] }\n\n[[light]]\ntype = \"sun\"\n\
         direction = [0.0, -1.0, 0.0]\nirradiance = [1.0, 1.0, 1.0]\n",
    )
    .unwrap();
    let loaded = fisheye_rt::scene::load(file.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    let s = &loaded.scene;
    // The glTF's own cubes are instanced, so each entry loads it again: its floor is copied
    // into the world three times, its cube stored three times and placed nine times.
    assert_eq!(
        (s.world_triangles, s.triangles.len(), s.instances.len()),
        (6, 42, 9)
    );
    assert_eq!(s.len(), 3 * (2 + 3 * 12));
    let placed = s.flattened(usize::MAX).unwrap();
    let lowest = |k: usize| {
        placed.triangles[k]
            .iter()
            .fold(f64::INFINITY, |z, p| z.min(p.z))
    };
    // The floors (the world's triangles, first) moved by their entries' translations.
    for (k, z) in [(0, -12.0), (2, -32.0), (4, 8.0)] {
        assert!((lowest(k) - z).abs() < 1e-9, "floor {k}: {}", lowest(k));
    }

    // The same OBJ twice is one mesh placed twice; with another material, a copy.
    let obj = dir.join("tri.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(
        &file,
        "[[mesh]]\npath = \"tri.obj\"\n\n[[mesh]]\npath = \"tri.obj\"\n\
         translation = [2.0, 0.0, 0.0]\n\n[[mesh]]\npath = \"tri.obj\"\n\
         material = { diffuse = [0.1, 0.1, 0.9] }\n\n[[light]]\ntype = \"sun\"\n\
         direction = [0.0, -1.0, 0.0]\nirradiance = [1.0, 1.0, 1.0]\n",
    )
    .unwrap();
    let s = fisheye_rt::scene::load(file.to_str().unwrap())
        .unwrap_or_else(|e| panic!("{e}"))
        .scene;
    assert_eq!(
        (s.world_triangles, s.triangles.len(), s.instances.len()),
        (1, 2, 2)
    );
    let flat = s.flattened(usize::MAX).unwrap();
    // Ids: the copy (world) first, then the instances in entry order.
    assert!(close(flat.triangles[0][1], DVec3::X));
    assert!(close(flat.triangles[1][1], DVec3::X));
    assert!(close(flat.triangles[2][1], DVec3::new(3.0, 0.0, 0.0)));
}

/// The repository's glTF example, written by another tool (trimesh, `scenes/gltf/make.py`):
/// its two shared meshes are stored once and placed by the 20 nodes that use them (8 columns
/// of a 24-sided cylinder, 12 tori of 32 × 12 quads), with the floor and the ball in world
/// space; no warning, and no lights of its own (the headlight and the sun are added).
#[test]
fn the_example_gltf_file_is_instanced() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/gltf/pavilion.glb");
    let loaded = load_gltf(&path, None).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let scene = loaded.scene;
    assert_eq!(scene.instances.len(), 20);
    // A capped cylinder of 24 sections: 4 × 24 triangles; a torus: 2 × 32 × 12.
    let (column, torus) = (4 * 24, 2 * 32 * 12);
    let world = scene.world_triangles;
    assert_eq!(scene.triangles.len() - world, column + torus);
    assert_eq!(scene.len(), world + 8 * column + 12 * torus);
    assert!(scene.headlight.is_some());
}
