//! `fisheye render` of glTF files: the default scene or `--gltf-scene N`, the file's camera or
//! `--camera gltf:N`, and errors for scenes and cameras that are not there.

use std::process::Command;

use base64::Engine;

/// A glTF file of two scenes (a triangle in front of the origin; the same triangle far to the
/// side) and two cameras (at the origin looking down -z at the triangle; turned away).
fn write_gltf(dir: &std::path::Path) -> std::path::PathBuf {
    let corners: [f32; 9] = [-1.0, -1.0, -3.0, 1.0, -1.0, -3.0, 0.0, 1.0, -3.0];
    let bytes: Vec<u8> = corners.iter().flat_map(|v| v.to_le_bytes()).collect();
    let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0,
  "scenes": [{{"nodes": [0, 2, 3]}}, {{"nodes": [1, 2]}}],
  "nodes": [{{"mesh": 0}}, {{"mesh": 0, "translation": [100, 0, 0]}}, {{"camera": 0}},
            {{"camera": 0, "rotation": [0, 1, 0, 0]}}],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 1.0, "znear": 0.1}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                  "min": [-1, -1, -3], "max": [1, 1, -3]}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
  "buffers": [{{"byteLength": 36, "uri": "data:application/octet-stream;base64,{data}"}}]}}"#
    );
    let path = dir.join("two.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

/// The share of pixels whose ray hits the triangle, from the id array `render` writes.
fn hit_share(args: &[&str], dir: &std::path::Path) -> Result<f64, String> {
    let out = dir.join("view.png");
    let output = Command::new(env!("CARGO_BIN_EXE_fisheye"))
        .arg("render")
        .args(args)
        .args(["--size", "32x24", "--spp", "1", "--outputs", "id", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    if !output.status.success() {
        return Err(String::from_utf8_lossy(&output.stderr).into_owned());
    }
    let bytes = std::fs::read(out.with_extension("id.npy")).unwrap();
    let ids: Vec<u32> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
    Ok(ids.iter().filter(|&&i| i != u32::MAX).count() as f64 / ids.len() as f64)
}

#[test]
fn render_takes_gltf_scenes_and_cameras() {
    let dir = std::env::temp_dir().join(format!("fisheye-gltf-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = write_gltf(&dir);
    let file = file.to_str().unwrap();
    let lens = ["--lens", "equidistant:f=0.5"];
    // The file's first camera looks at the triangle; the second is turned away from it.
    let seen = hit_share(&[file, lens[0], lens[1]], &dir).unwrap();
    assert!(seen > 0.02, "the triangle covers {seen} of the image");
    let away = hit_share(&[file, lens[0], lens[1], "--camera", "gltf:1"], &dir).unwrap();
    assert_eq!(away, 0.0);
    // Scene 1 has the triangle 100 units to the side: not in front of camera 0.
    let other = hit_share(&[file, lens[0], lens[1], "--gltf-scene", "1"], &dir).unwrap();
    assert_eq!(other, 0.0);
    let error = hit_share(&[file, "--camera", "gltf:5"], &dir).unwrap_err();
    assert!(error.contains("has 2 camera(s)"), "{error}");
    let error = hit_share(&[file, "--gltf-scene", "2"], &dir).unwrap_err();
    assert!(error.contains("no scene 2"), "{error}");
    std::fs::remove_dir_all(dir).unwrap();
}
