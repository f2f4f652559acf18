//! Scene files (TOML): the ones shipped in `scenes/` load and render as the reference does;
//! placement, overrides, lights, camera paths and relative paths do what the format says; bad
//! files are errors naming the file, key and line.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_agrees, both, camera, real_scene};
use fisheye_rt::scene::file::load_scene_file;
use fisheye_rt::scene::{Light, Surface, face_normal};
use glam::{DVec3, Vec3};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fisheye-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(&path, text).unwrap();
    path
}

/// Every scene file in `scenes/` (they read the models beside them) loads without warnings, has
/// a camera path, puts its camera where it sees the scene, and renders as the reference does.
#[test]
fn shipped_scene_files_render_as_the_reference_does() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    let names: Vec<_> = files
        .iter()
        .map(|f| f.file_stem().unwrap().to_owned())
        .collect();
    for expected in [
        "sibenik",
        "cornell-box",
        "cornell-sphere",
        "bunny",
        "buddha",
    ] {
        assert!(
            names.iter().any(|n| n == expected),
            "scenes/{expected}.toml is missing"
        );
    }
    for file in files {
        let loaded = load_scene_file(&file)
            .unwrap_or_else(|e| panic!("{e} (the models ship in scenes/; see its README)"));
        let name = file.file_name().unwrap().to_string_lossy();
        // Sibenik has 8 triangles with collinear corners, dropped with a warning; nothing
        // else of the shipped scenes warns.
        assert!(
            loaded.warnings.iter().all(|w| w.contains("of zero area")),
            "{name}: {:?}",
            loaded.warnings
        );
        let scene = loaded.scene;
        assert!(scene.camera_path.len() >= 2, "{name}: no camera path");
        let (gpu, cpu) = both(&scene, &camera("equidistant:f=0.45,fov=180", 64, 48));
        let (rays, hits) = gpu.counts();
        assert!(hits * 4 >= rays, "{name}: only {hits} of {rays} rays hit");
        assert_agrees(&name, &gpu, &cpu, real_scene(gpu.ids.len()));
    }
}

/// Scale, then rotation about x, y, z (degrees), then translation; normals follow, and a
/// mirroring scale keeps the faces' outward side.
#[test]
fn meshes_are_placed_as_the_file_says() {
    let dir = temp_dir("placement");
    let file = write(
        &dir,
        "place.toml",
        r#"
        [[mesh]]
        shape = "box"
        scale = [2.0, 1.0, 4.0]
        rotation = [0.0, 90.0, 0.0]
        translation = [10.0, 20.0, 30.0]

        [[mesh]]
        shape = "box"
        scale = [-1.0, 1.0, 1.0]
        translation = [0.0, 5.0, 0.0]
        material = { surface = "mirror", specular = [0.5, 0.5, 0.5] }
        "#,
    );
    let scene = load_scene_file(&file).unwrap().scene;
    assert_eq!(scene.len(), 24);
    let (lo, hi) = fisheye_rt::scene::bounds(&scene.triangles[..12]).unwrap();
    // 90° about y takes x to -z and z to x: the 2 × 1 × 4 box becomes 4 × 1 × 2.
    let close = |a: DVec3, b: DVec3| (a - b).abs().max_element() < 1e-12;
    assert!(close(lo, DVec3::new(8.0, 19.5, 29.0)), "{lo}");
    assert!(close(hi, DVec3::new(12.0, 20.5, 31.0)), "{hi}");
    for (t, centre) in [
        (0..12, DVec3::new(10.0, 20.0, 30.0)),
        (12..24, DVec3::new(0.0, 5.0, 0.0)),
    ] {
        for i in t {
            let tri = scene.triangles[i];
            let middle = (tri[0] + tri[1] + tri[2]) / 3.0;
            assert!(
                face_normal(&tri).dot(middle - centre) > 0.0,
                "triangle {i} faces inward"
            );
        }
    }
    let mirror = &scene.materials[scene.material_of[12] as usize];
    assert_eq!(
        (mirror.surface, mirror.specular),
        (Surface::Mirror, Vec3::splat(0.5))
    );
    // No camera: the scene is framed like a bare OBJ, from the front of its bounds.
    let (lo, hi) = scene.bounds().unwrap();
    assert!(scene.camera.position.z > hi.z && scene.camera.look_at == (lo + hi) / 2.0);
}

/// OBJ paths resolve against the scene file's folder, not the working directory; material
/// overrides change only the fields they name; lights, sky, ambient and the camera path are
/// read; the path interpolates between keyframes.
#[test]
fn paths_overrides_lights_and_camera_path() {
    let dir = temp_dir("overrides");
    write(
        &dir,
        "models/tri.mtl",
        "newmtl lamp\nKd 0.5 0.5 0.5\nKs 0.2 0.2 0.2\nd 0.5\nnewmtl pane\nKd 1 1 1\nTr 0.25\n",
    );
    write(
        &dir,
        "models/tri.obj",
        "mtllib tri.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl lamp\nf 1 2 3\nusemtl pane\nf 1 3 4\n",
    );
    let file = write(
        &dir,
        "scenes/one.toml",
        r#"
        sky = [0.1, 0.2, 0.3]
        ambient = [0.0, 0.0, 0.0]

        [camera]
        position = [0.0, 0.0, 5.0]
        look_at = [0.0, 0.0, 0.0]

        [[camera.path]]
        position = [0.0, 0.0, 5.0]
        look_at = [0.0, 0.0, 0.0]

        [[camera.path]]
        position = [4.0, 0.0, 5.0]
        look_at = [0.0, 2.0, 0.0]

        [[camera.path]]
        position = [4.0, 4.0, 5.0]
        look_at = [0.0, 2.0, 0.0]

        [[mesh]]
        path = "../models/tri.obj"

        [[material]]
        name = "lamp"
        emission = [5.0, 4.0, 3.0]

        [[light]]
        type = "point"
        position = [1.0, 2.0, 3.0]
        intensity = [4.0, 4.0, 4.0]

        [[light]]
        type = "sun"
        direction = [0.0, -1.0, 0.0]
        irradiance = [0.5, 0.5, 0.5]
        "#,
    );
    let scene = load_scene_file(&file).unwrap().scene;
    let lamp = scene.materials.iter().find(|m| m.name == "lamp").unwrap();
    assert_eq!(lamp.emission, Vec3::new(5.0, 4.0, 3.0));
    assert_eq!(
        (lamp.diffuse, lamp.specular),
        (Vec3::splat(0.5), Vec3::splat(0.2))
    );
    // MTL opacity: `d` directly, `Tr` as 1 - Tr.
    assert_eq!(lamp.opacity, 0.5);
    let pane = scene.materials.iter().find(|m| m.name == "pane").unwrap();
    assert_eq!(pane.opacity, 0.75);
    assert_eq!(
        (scene.sky, scene.ambient),
        (Vec3::new(0.1, 0.2, 0.3), Vec3::ZERO)
    );
    assert_eq!(scene.lights.len(), 2);
    assert!(
        matches!(scene.lights[0], Light::Point { position, .. } if position == DVec3::new(1.0, 2.0, 3.0))
    );
    assert!(matches!(scene.lights[1], Light::Directional { .. }));
    assert_eq!(scene.camera_path.len(), 3);
    // Halfway along three keyframes is the middle one; a quarter is halfway to it.
    assert_eq!(
        scene.camera_on_path(0.5).position,
        DVec3::new(4.0, 0.0, 5.0)
    );
    let quarter = scene.camera_on_path(0.25);
    assert_eq!(
        (quarter.position, quarter.look_at),
        (DVec3::new(2.0, 0.0, 5.0), DVec3::new(0.0, 1.0, 0.0))
    );
    assert_eq!(
        scene.camera_on_path(1.0).position,
        DVec3::new(4.0, 4.0, 5.0)
    );
}

/// Each bad file is an error that names the file and what is wrong (with the line, where the
/// TOML parser knows it).
#[test]
fn bad_scene_files_are_clear_errors() {
    let dir = temp_dir("bad-scenes");
    write(&dir, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let cases: [(&str, &[&str]); 13] = [
        (
            // Two entries of one mesh, the second scaled so small that its determinant
            // underflows: an instance cannot invert it.
            "[[mesh]]\npath = \"tri.obj\"\n[[mesh]]\npath = \"tri.obj\"\nscale = 1e-200\n",
            &["mesh 2", "flattens the mesh"],
        ),
        (
            "[camera]\npositon = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\n",
            &["unknown field `positon`", "line 2"],
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\nscael = 2.0\n",
            &["unknown field `scael`", "line 3"],
        ),
        (
            "colour = 1\n[[mesh]]\npath = \"tri.obj\"\n",
            &["unknown field `colour`"],
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\n[[light]]\ntype = \"spot\"\n",
            &["spot", "line 4"],
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\nscale = \"big\"\n",
            &["a number or an [x, y, z] array", "line 3"],
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\nscale = 0.0\n",
            &["mesh 1.scale", "non-zero"],
        ),
        (
            "[[mesh]]\npath = \"missing.obj\"\n",
            &["missing.obj", "cannot read the file"],
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\nshape = \"box\"\n",
            &["mesh 1", "exactly one of path and shape"],
        ),
        (
            "sky = [nan, 0.0, 0.0]\n[[mesh]]\npath = \"tri.obj\"\n",
            &["sky", "finite"],
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\n[[material]]\nname = \"gold\"\ndiffuse = [1.0, 0.8, 0.0]\n",
            &["\"gold\" matches no material", "default"],
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\nmaterial = { opacity = 1.5 }\n",
            &["mesh 1.material.opacity = 1.5", "[0, 1]"],
        ),
        (
            "[camera]\nposition = [1.0, 2.0, 3.0]\nlook_at = [1.0, 2.0, 3.0]\n[[mesh]]\npath = \"tri.obj\"\n",
            &["camera", "same point"],
        ),
    ];
    for (i, (text, wanted)) in cases.iter().enumerate() {
        let file = write(&dir, &format!("bad{i}.toml"), text);
        let message = match load_scene_file(&file) {
            Ok(_) => panic!("case {i} loaded:\n{text}"),
            Err(e) => e.to_string(),
        };
        assert!(
            message.contains(&format!("bad{i}.toml")) || message.contains("missing.obj"),
            "case {i}: {message}"
        );
        for w in *wanted {
            assert!(message.contains(w), "case {i}: {message:?} lacks {w:?}");
        }
    }
    let empty = write(&dir, "empty.toml", "sky = [0.0, 0.0, 0.0]\n");
    assert!(
        load_scene_file(&empty)
            .err()
            .unwrap()
            .to_string()
            .contains("no [[mesh]]")
    );
    let missing = load_scene_file(&dir.join("nowhere.toml"))
        .err()
        .unwrap()
        .to_string();
    assert!(missing.contains("nowhere.toml"), "{missing}");
    // A scene that nothing lights loads, with a warning saying so.
    let dark = write(
        &dir,
        "dark.toml",
        "sky = [0.0, 0.0, 0.0]\nambient = [0.0, 0.0, 0.0]\n[[mesh]]\npath = \"tri.obj\"\n",
    );
    assert!(
        load_scene_file(&dark)
            .unwrap()
            .warnings
            .join("")
            .contains("nothing lights")
    );
    // One lit by its sky and ambient term alone renders flat: a warning says so, and what to
    // add; a light silences it.
    let flat = write(&dir, "flat.toml", "[[mesh]]\npath = \"tri.obj\"\n");
    let warnings = load_scene_file(&flat).unwrap().warnings.join("");
    assert!(
        warnings.contains("no [[light]]") && warnings.contains("renders flat"),
        "{warnings}"
    );
    let lit = write(
        &dir,
        "lit.toml",
        "[[mesh]]\npath = \"tri.obj\"\n[[light]]\ntype = \"sun\"\ndirection = [0.0, -1.0, 0.0]\nirradiance = [1.0, 1.0, 1.0]\n",
    );
    assert!(load_scene_file(&lit).unwrap().warnings.is_empty());
    std::fs::remove_dir_all(dir).unwrap();
}

/// `[[mesh.key]]` moves a mesh: two boxes of one shape, one keyed (translation and rotation
/// given, scale left to the mesh's 0.5) and one still, are one stored mesh placed twice; the
/// keyed one is where linear interpolation (slerp for the rotation) of its keys puts it, held
/// outside them. Keys out of order are an error naming the mesh.
#[test]
fn keyed_meshes_move() {
    use glam::{DAffine3, DQuat};
    let dir = temp_dir("scene-keys");
    let path = write(
        &dir,
        "keyed.toml",
        r#"
[[mesh]]
shape = "box"
scale = 0.5
translation = [0.0, 0.0, -4.0]
[[mesh.key]]
time = 1.0
translation = [-2.0, 0.0, -4.0]
[[mesh.key]]
time = 3.0
translation = [2.0, 1.0, -4.0]
rotation = [0.0, 90.0, 0.0]

[[mesh]]
shape = "box"
scale = 0.5
translation = [3.0, 0.0, -6.0]

[[light]]
type = "sun"
direction = [0.0, -1.0, -1.0]
irradiance = [1.0, 1.0, 1.0]
"#,
    );
    let scene = load_scene_file(&path).unwrap().scene;
    assert_eq!(scene.instances.len(), 2);
    assert_eq!(scene.triangles.len(), 12, "one box stored");
    assert!(scene.moves());
    let placed = |t: f64, degrees: f64| {
        let x = -2.0 + 4.0 * ((t - 1.0) / 2.0).clamp(0.0, 1.0);
        let y = ((t - 1.0) / 2.0).clamp(0.0, 1.0);
        DAffine3::from_scale_rotation_translation(
            DVec3::splat(0.5),
            DQuat::from_rotation_y(degrees.to_radians()),
            DVec3::new(x, y, -4.0),
        )
    };
    let still = DAffine3::from_scale_rotation_translation(
        DVec3::splat(0.5),
        DQuat::IDENTITY,
        DVec3::new(3.0, 0.0, -6.0),
    );
    for (t, degrees) in [
        (0.0, 0.0),
        (1.0, 0.0),
        (1.5, 22.5),
        (2.0, 45.0),
        (3.0, 90.0),
        (9.0, 90.0),
    ] {
        let at = scene.placements_at(t);
        assert!(
            at[0].abs_diff_eq(placed(t, degrees), 1e-12),
            "t {t}: {:?}",
            at[0]
        );
        assert!(at[1].abs_diff_eq(still, 1e-12));
    }
    let bad = write(
        &dir,
        "unordered.toml",
        "[[mesh]]\nshape = \"box\"\n[[mesh.key]]\ntime = 2.0\n[[mesh.key]]\ntime = 1.0\n",
    );
    let message = load_scene_file(&bad).err().expect("refused").to_string();
    assert!(
        message.contains("mesh 1") && message.contains("key times must increase"),
        "{message}"
    );
}

/// The book's moving-objects example is the file the README renders.
#[test]
fn the_books_sliding_scene_is_the_shipped_one() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let book = std::fs::read_to_string(root.join("docs/src/scenes.md")).unwrap();
    let block = book
        .split("```toml,file=sliding.toml\n")
        .nth(1)
        .and_then(|rest| rest.split("```\n").next())
        .expect("the book shows sliding.toml");
    let shipped = std::fs::read_to_string(root.join("scenes/dataset/sliding.toml")).unwrap();
    assert_eq!(block, shipped);
    let scene = load_scene_file(&root.join("scenes/dataset/sliding.toml"))
        .unwrap()
        .scene;
    assert!(scene.moves());
}
