//! What the fuzz targets run, and what `tests/fuzz_corpus.rs` replays from `fuzz/corpus/`.
//!
//! Each function feeds bytes to one parser of user input, through the same entry point the
//! command line uses, and checks what comes back: an error, or a value that holds up (finite
//! geometry, lenses whose rays are unit vectors and whose printed spec parses again). A panic
//! anywhere is a failure.
#![allow(dead_code)]

use std::io::{Error, ErrorKind, Result};
use std::path::Path;

use fisheye_rt::bvh::{BvhQuality, SceneBvh};
use fisheye_rt::dataset::trajectory::{self, TrajectoryFormat};
use fisheye_rt::input::InputKind;
use fisheye_rt::lens::calib::{self, CalibFormat};
use fisheye_rt::lens::{ImageSize, Lens, LensCamera, parse_spec};
use fisheye_rt::scene::Scene;
use fisheye_rt::scene::file::load_scene_file_from;
use fisheye_rt::scene::obj::load_obj_from;
use fisheye_rt::trace::gpu_lights;

/// The OBJ every mesh of a fuzzed scene file names: one triangle with a material.
const TRIANGLE_OBJ: &[u8] = b"mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
const TRIANGLE_MTL: &[u8] = b"newmtl m\nKd 0.5 0.5 0.5\nillum 4\n";

fn not_found(path: &Path) -> Error {
    Error::new(
        ErrorKind::NotFound,
        format!("{} is not in the input", path.display()),
    )
}

/// Paths under `/dev/` go to the disk, as they would from the command line: a fuzzed
/// `mtllib /dev/zero` must be refused (a device), not read for ever.
fn special(path: &Path, kind: InputKind) -> Option<Result<Vec<u8>>> {
    path.starts_with("/dev")
        .then(|| fisheye_rt::scene::disk(path, kind))
}

/// The bytes up to the first NUL are an OBJ file; the bytes after it are every MTL file the
/// OBJ names. Textures are missing. Paths under `/dev/` are read from the disk.
pub fn obj(data: &[u8]) {
    let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let (obj, mtl) = (&data[..split], data.get(split + 1..).unwrap_or(&[]));
    let read = |path: &Path, kind: InputKind| -> Result<Vec<u8>> {
        special(path, kind).unwrap_or_else(|| match kind {
            InputKind::Obj => Ok(obj.to_vec()),
            InputKind::Mtl => Ok(mtl.to_vec()),
            _ => Err(not_found(path)),
        })
    };
    if let Ok(loaded) = load_obj_from(Path::new("fuzz.obj"), &read) {
        check_scene(&loaded.scene);
    }
}

/// The bytes are a scene file; every OBJ it names is one triangle (or, under `/dev/`, read
/// from the disk).
pub fn scene_file(data: &[u8]) {
    let read = |path: &Path, kind: InputKind| -> Result<Vec<u8>> {
        special(path, kind).unwrap_or_else(|| match kind {
            InputKind::SceneFile => Ok(data.to_vec()),
            InputKind::Obj => Ok(TRIANGLE_OBJ.to_vec()),
            InputKind::Mtl => Ok(TRIANGLE_MTL.to_vec()),
            _ => Err(not_found(path)),
        })
    };
    if let Ok(loaded) = load_scene_file_from(Path::new("fuzz.toml"), &read) {
        check_scene(&loaded.scene);
    }
}

/// The bytes, as text, are a lens spec.
pub fn lens_spec(data: &[u8]) {
    if let Ok(lens) = parse_spec(&String::from_utf8_lossy(data)) {
        check_lens(lens);
    }
}

/// The bytes, as text, are a calibration file, read in every format. A calibration that
/// reads and can be written in that format reads back from what was written.
pub fn calibration(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    for (_, format) in CalibFormat::ALL {
        // A rig's cameras sit where rigid transforms put them.
        for camera in calib::parse_rig(&text, format).into_iter().flatten() {
            check_rigid(&camera.body_from_camera);
        }
        let Ok(cameras) = calib::parse(&text, format) else {
            continue;
        };
        for camera in cameras {
            check_lens(camera.lens.into());
            if let Ok(written) = calib::write(&camera, format) {
                let again = calib::parse(&written, format).unwrap_or_else(|e| {
                    panic!("{format:?} wrote what it cannot read ({e}):\n{written}")
                });
                assert_eq!(again.len(), 1, "{written}");
                assert_eq!(again[0].size, camera.size, "{written}");
                assert_eq!(again[0].lens.model().name(), camera.lens.model().name());
            }
        }
    }
}

/// A trajectory in every format: an error, or poses with finite, rigid transforms and time
/// stamps fit for file names.
pub fn trajectory(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    for (_, format) in TrajectoryFormat::ALL {
        for pose in trajectory::parse(&text, format, 10.0).into_iter().flatten() {
            check_rigid(&pose.world_from_body);
            assert!(pose.seconds.is_finite(), "{pose:?}");
            let name_safe = pose.stamp.chars().all(|c| c.is_ascii_digit() || c == '.');
            assert!(name_safe && !pose.stamp.is_empty(), "{pose:?}");
        }
    }
}

/// A transform that is a rotation (orthonormal, right-handed, to rounding) and a finite
/// translation.
fn check_rigid(t: &glam::DAffine3) {
    let m = t.matrix3;
    let off = (m.transpose() * m - glam::DMat3::IDENTITY)
        .to_cols_array()
        .into_iter()
        .fold(0.0f64, |a, e| a.max(e.abs()));
    assert!(off < 1e-12, "not orthonormal ({off:e}): {t:?}");
    assert!(
        (m.determinant() - 1.0).abs() < 1e-12,
        "not a rotation: {t:?}"
    );
    assert!(t.translation.is_finite(), "{t:?}");
}

/// A loaded scene is what the renderer may take: triangles with finite corners, finite
/// materials and camera, and a BVH that builds (or an error saying why it cannot).
fn check_scene(scene: &Scene) {
    assert!(!scene.is_empty(), "an empty scene loaded");
    for t in &scene.triangles {
        assert!(
            t.iter().all(|p| p.is_finite()),
            "a non-finite corner loaded: {t:?}"
        );
    }
    for uvs in scene.uvs.iter().flatten() {
        assert!(
            uvs.iter().all(|uv| uv.is_finite()),
            "a non-finite UV: {uvs:?}"
        );
    }
    for m in &scene.materials {
        let colours = [m.diffuse, m.specular, m.emission, m.transmission];
        assert!(
            colours.iter().all(|c| c.is_finite()) && m.opacity.is_finite() && m.ior.is_finite(),
            "material {:?} is not finite: {m:?}",
            m.name
        );
    }
    let c = &scene.camera;
    assert!(c.position.is_finite() && c.look_at.is_finite() && c.up.is_finite());
    let _ = SceneBvh::build(scene, c.position, BvhQuality::Fast, true);
    if let Ok((lights, _)) = gpu_lights(scene, c.position) {
        for l in lights {
            assert!(
                l.vector.iter().chain(&l.colour).all(|x| x.is_finite()),
                "{l:?}"
            );
        }
    }
}

/// A lens's pixels map to unit directions or to none, and the spec it prints parses again.
fn check_lens(lens: Lens) {
    let camera = LensCamera::new(lens, ImageSize::new(9, 7).unwrap());
    for d in camera.directions().into_iter().flatten() {
        assert!(
            d.is_finite() && (d.length() - 1.0).abs() < 1e-9,
            "{lens}: direction {d}"
        );
    }
    if let Err(e) = parse_spec(&lens.to_string()) {
        panic!("the spec {lens} that a lens prints does not parse: {e}");
    }
}

/// The bytes are a glTF file (JSON or GLB); every other file it names is missing, except
/// paths under `/dev/`, read from the disk. A scene that loads holds up.
pub fn gltf(data: &[u8]) {
    let path = Path::new("fuzz.glb");
    let read = |p: &Path, kind: InputKind| -> Result<Vec<u8>> {
        if p == path {
            return Ok(data.to_vec());
        }
        special(p, kind).unwrap_or_else(|| Err(not_found(p)))
    };
    for scene in [None, Some(1)] {
        if let Ok(loaded) = fisheye_rt::scene::gltf::load_gltf_from(path, &read, scene) {
            check_scene(&loaded.scene);
        }
    }
}
