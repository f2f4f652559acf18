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

mod commands;
#[path = "../common/mod.rs"]
mod common;
mod limits;

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

/// Every test the book's "Bad input" table (`docs/src/limits.md`) names exists (a Rust test,
/// or one of the Python package's), so the table cannot drift from the tests.
#[test]
fn the_readme_table_names_tests_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let page = std::fs::read_to_string(root.join("docs/src/limits.md")).unwrap();
    let section = page.split("\n## ").next().unwrap();
    /// Every file ending in `ext` under `dir`, appended to `out`.
    fn sources(dir: &Path, ext: &str, out: &mut String) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                sources(&path, ext, out);
            } else if path.extension().is_some_and(|e| e == ext) {
                out.push_str(&std::fs::read_to_string(path).unwrap());
            }
        }
    }
    let mut sources_text = String::new();
    sources(&root.join("tests"), "rs", &mut sources_text);
    sources(&root.join("src"), "rs", &mut sources_text);
    sources(&root.join("python/tests"), "py", &mut sources_text);
    let sources = sources_text;
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
                sources.contains(&format!("fn {name}("))
                    || sources.contains(&format!("def {name}(")),
                "the book names a test {name} that does not exist"
            );
        }
    }
    assert!(rows >= 20, "the table has {rows} rows");
}
