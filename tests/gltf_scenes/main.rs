//! glTF 2.0 loading: files written here (JSON by hand with serde_json, binary data laid out
//! here) checked against what the spec says they hold: node transforms, primitive modes and
//! accessor forms, material mappings, lights, cameras, buffer containers, and bad files; and a
//! glTF twin of an OBJ scene rendering the same triangles on the GPU.

mod animation;
#[path = "../common/mod.rs"]
mod common;
mod files;
mod labels;

use std::path::{Path, PathBuf};

use base64::Engine;
use fisheye_rt::scene::gltf::load_gltf;
use fisheye_rt::scene::{Light, Surface};
use fisheye_rt::trace::{RenderOptions, render};
use glam::{DQuat, DVec3, Vec3};
use serde_json::{Value, json};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fisheye-gltf-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A glTF document under construction: one binary buffer, its views and accessors.
#[derive(Default)]
struct Doc {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    nodes: Vec<Value>,
    extra: serde_json::Map<String, Value>,
}

impl Doc {
    /// A view of `bytes` (4-byte aligned).
    /// A unit cube (12 triangles, `material` if given) and a floor square (2), as meshes.
    fn cube_and_floor(&mut self, material: Option<usize>) -> (usize, usize) {
        let corners: Vec<[f32; 3]> = (0..8)
            .map(|k| [(k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32])
            .collect();
        let faces: [u32; 36] = [
            0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4,
            6, 1, 3, 5, 3, 7, 5,
        ];
        let positions = self.positions(&corners);
        let indices = self.indices(&faces, 5123);
        let mut primitive = json!({"attributes": {"POSITION": positions}, "indices": indices});
        if let Some(m) = material {
            primitive["material"] = json!(m);
        }
        let cube = self.mesh(vec![primitive]);
        let floor_positions = self.positions(&[
            [-6.0, 0.0, -12.0],
            [6.0, 0.0, -12.0],
            [6.0, 0.0, 2.0],
            [-6.0, 0.0, 2.0],
        ]);
        let floor_indices = self.indices(&[0, 2, 1, 0, 3, 2], 5121);
        let floor = self.mesh(vec![json!({"attributes": {"POSITION": floor_positions},
            "indices": floor_indices})]);
        (cube, floor)
    }

    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    fn accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn positions(&mut self, points: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = points
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&bytes);
        let lo = (0..3).map(|k| points.iter().map(|p| p[k]).fold(f32::MAX, f32::min));
        let hi = (0..3).map(|k| points.iter().map(|p| p[k]).fold(f32::MIN, f32::max));
        self.accessor(
            json!({"bufferView": view, "componentType": 5126, "count": points.len(),
            "type": "VEC3", "min": lo.collect::<Vec<_>>(), "max": hi.collect::<Vec<_>>()}),
        )
    }

    fn floats(&mut self, values: &[f32], kind: &str, count: usize) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessor(
            json!({"bufferView": view, "componentType": 5126, "count": count, "type": kind}),
        )
    }

    /// Indices as u8 (5121), u16 (5123) or u32 (5125).
    fn indices(&mut self, indices: &[u32], component: u32) -> usize {
        let bytes: Vec<u8> = match component {
            5121 => indices.iter().map(|&i| i as u8).collect(),
            5123 => indices
                .iter()
                .flat_map(|&i| (i as u16).to_le_bytes())
                .collect(),
            _ => indices.iter().flat_map(|&i| i.to_le_bytes()).collect(),
        };
        let view = self.view(&bytes);
        self.accessor(json!({"bufferView": view, "componentType": component,
            "count": indices.len(), "type": "SCALAR"}))
    }

    fn mesh(&mut self, primitives: Vec<Value>) -> usize {
        self.meshes.push(json!({"primitives": primitives}));
        self.meshes.len() - 1
    }

    fn node(&mut self, node: Value) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    /// The JSON, with the buffer at `uri` (`None`: the GLB's binary chunk).
    fn json(&self, uri: Option<String>, roots: &[usize]) -> Value {
        let mut buffer = json!({"byteLength": self.bin.len()});
        if let Some(uri) = uri {
            buffer["uri"] = json!(uri);
        }
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "fisheye-rt tests"},
            "scene": 0,
            "scenes": [{"nodes": roots}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [buffer],
        });
        if !self.materials.is_empty() {
            doc["materials"] = json!(self.materials);
        }
        for (k, v) in &self.extra {
            doc[k] = v.clone();
        }
        doc
    }

    /// Writes `name.gltf` with an embedded (data URI) buffer.
    fn write_embedded(&self, dir: &Path, name: &str, roots: &[usize]) -> PathBuf {
        let data = base64::engine::general_purpose::STANDARD.encode(&self.bin);
        let uri = format!("data:application/octet-stream;base64,{data}");
        let path = dir.join(format!("{name}.gltf"));
        std::fs::write(&path, self.json(Some(uri), roots).to_string()).unwrap();
        path
    }

    /// Writes `name.gltf` and `name.bin`.
    fn write_external(&self, dir: &Path, name: &str, roots: &[usize]) -> PathBuf {
        std::fs::write(dir.join(format!("{name} data.bin")), &self.bin).unwrap();
        let path = dir.join(format!("{name}.gltf"));
        let uri = format!("{name}%20data.bin");
        std::fs::write(&path, self.json(Some(uri), roots).to_string()).unwrap();
        path
    }

    /// Writes `name.glb`: header, JSON chunk, BIN chunk (glTF 2.0 §4.4).
    fn write_glb(&self, dir: &Path, name: &str, roots: &[usize]) -> PathBuf {
        let mut text = self.json(None, roots).to_string().into_bytes();
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + text.len() + 8 + bin.len();
        let mut out = Vec::new();
        out.extend(b"glTF");
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((text.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(&text);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&bin);
        let path = dir.join(format!("{name}.glb"));
        std::fs::write(&path, out).unwrap();
        path
    }
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

fn close(a: DVec3, b: DVec3) -> bool {
    a.abs_diff_eq(b, 1e-12)
}

/// A parent's TRS (translated, turned 90° about y) and a child's matrix (scaled by 2, moved 1
/// along its parent's x) place a triangle where the transforms composed by hand do, in every
/// container (embedded, external buffer with an escaped name, GLB); both nodes use one mesh,
/// so it is stored once and placed by two instances.
#[test]
fn node_transforms_compose_in_every_container() {
    let dir = temp_dir("hierarchy");
    let mut doc = Doc::default();
    let positions = doc.positions(&TRIANGLE);
    let mesh = doc.mesh(vec![json!({"attributes": {"POSITION": positions}})]);
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let child = doc.node(json!({"mesh": mesh,
        "matrix": [2, 0, 0, 0,  0, 2, 0, 0,  0, 0, 2, 0,  1, 0, 0, 1]}));
    let parent = doc.node(json!({"mesh": mesh, "children": [child],
        "translation": [1, 2, 3], "rotation": [0, s, 0, s]}));
    // Rotation 90° about y: x → -z, z → x.
    let turn = |p: DVec3| DVec3::new(p.z, p.y, -p.x);
    let t = DVec3::new(1.0, 2.0, 3.0);
    let corners = TRIANGLE.map(|c| Vec3::from(c).as_dvec3());
    let expected_parent = corners.map(|c| t + turn(c));
    let expected_child = corners.map(|c| t + turn(DVec3::X + 2.0 * c));
    for path in [
        doc.write_embedded(&dir, "embedded", &[parent]),
        doc.write_external(&dir, "external", &[parent]),
        doc.write_glb(&dir, "binary", &[parent]),
    ] {
        let loaded = load_gltf(&path, None).unwrap_or_else(|e| panic!("{e}"));
        // Two nodes use the mesh: it is stored once and placed twice.
        assert_eq!(loaded.scene.triangles.len(), 1);
        assert_eq!(loaded.scene.instances.len(), 2);
        let flat = loaded.scene.flattened(usize::MAX).unwrap();
        let triangles = &flat.triangles;
        assert_eq!(triangles.len(), 2, "{}", path.display());
        for (got, want) in triangles.iter().zip([expected_parent, expected_child]) {
            for (g, w) in got.iter().zip(want) {
                assert!(close(*g, w), "{}: {g} is not {w}", path.display());
            }
        }
    }
}

/// A unit square as triangles with u8, u16 and u32 indices, as a strip and as a fan, gives the
/// same two triangles facing the same way; positions from a sparse accessor (zeros, with
/// the corners substituted) give them too; points are skipped with a warning.
#[test]
fn strips_fans_index_types_and_sparse_accessors_give_the_same_triangles() {
    let dir = temp_dir("modes");
    let square = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let mut doc = Doc::default();
    let positions = doc.positions(&square);
    let mut primitives = Vec::new();
    for component in [5121, 5123, 5125] {
        let indices = doc.indices(&[0, 1, 2, 0, 2, 3], component);
        primitives.push(json!({"attributes": {"POSITION": positions}, "indices": indices}));
    }
    // Strip 1 2 0 3: (1, 2, 0), then (2, 0, 3) reversed to (0, 2, 3) as the odd one.
    let strip = doc.indices(&[1, 2, 0, 3], 5123);
    primitives.push(json!({"attributes": {"POSITION": positions}, "indices": strip, "mode": 5}));
    let fan = doc.indices(&[0, 1, 2, 3], 5123);
    primitives.push(json!({"attributes": {"POSITION": positions}, "indices": fan, "mode": 6}));
    // Sparse: four zero positions with all four replaced.
    let zeros = doc.view(&[0u8; 48]);
    let which = doc.view(&[0u8, 1, 2, 3]);
    let values: Vec<u8> = square
        .iter()
        .flatten()
        .flat_map(|v: &f32| v.to_le_bytes())
        .collect();
    let values = doc.view(&values);
    let sparse = doc.accessor(
        json!({"bufferView": zeros, "componentType": 5126, "count": 4,
        "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0],
        "sparse": {"count": 4, "indices": {"bufferView": which, "componentType": 5121},
                   "values": {"bufferView": values}}}),
    );
    let plain = doc.indices(&[0, 1, 2, 0, 2, 3], 5125);
    primitives.push(json!({"attributes": {"POSITION": sparse}, "indices": plain}));
    primitives.push(json!({"attributes": {"POSITION": positions}, "mode": 0}));
    let mesh = doc.mesh(primitives);
    let root = doc.node(json!({"mesh": mesh}));
    let path = doc.write_glb(&dir, "modes", &[root]);
    let loaded = load_gltf(&path, None).unwrap_or_else(|e| panic!("{e}"));
    let triangles = &loaded.scene.triangles;
    assert_eq!(triangles.len(), 6 * 2, "6 primitives of 2 triangles");
    let facing = |t: &[DVec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]).normalize();
    for t in triangles {
        assert!(close(facing(t), DVec3::Z), "a triangle faces {}", facing(t));
    }
    // Each primitive covers the square: its two triangles' areas sum to 1.
    for pair in triangles.chunks(2) {
        let area: f64 = pair
            .iter()
            .map(|t| (t[1] - t[0]).cross(t[2] - t[0]).length() / 2.0)
            .sum();
        assert!((area - 1.0).abs() < 1e-12, "{pair:?}");
    }
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("points and lines not rendered")),
        "{:?}",
        loaded.warnings
    );
}

/// Each glTF material becomes the Whitted material the README's table gives.
#[test]
fn materials_map_as_the_readme_says() {
    let dir = temp_dir("materials");
    let mut doc = Doc::default();
    let positions = doc.positions(&TRIANGLE);
    let uvs = doc.floats(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], "VEC2", 3);
    // A 2×1 PNG: red, green.
    let mut png = Vec::new();
    image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 255, 0, 255])
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let png = base64::engine::general_purpose::STANDARD.encode(&png);
    doc.extra.insert(
        "images".into(),
        json!([{"uri": format!("data:image/png;base64,{png}")}]),
    );
    doc.extra.insert("textures".into(), json!([{"source": 0}]));
    doc.extra.insert(
        "extensionsUsed".into(),
        json!([
            "KHR_materials_transmission",
            "KHR_materials_ior",
            "KHR_materials_emissive_strength",
            "EXT_fancy"
        ]),
    );
    doc.materials = vec![
        json!({"name": "plastic", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1.0, 1.0],
            "metallicFactor": 0.0, "roughnessFactor": 0.5}}),
        json!({"name": "chrome", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.7, 1.0],
            "metallicFactor": 1.0, "roughnessFactor": 0.1}}),
        json!({"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 1.0, 0.9, 1.0]},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                           "KHR_materials_ior": {"ior": 1.33}}}),
        json!({"name": "lamp", "emissiveFactor": [1.0, 0.5, 0.25],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}}),
        json!({"name": "cut", "alphaMode": "MASK", "alphaCutoff": 0.6,
            "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5]}}),
        json!({"name": "veil", "alphaMode": "BLEND",
            "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.3]}}),
        json!({"name": "printed", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
            "normalTexture": {"index": 0}}),
    ];
    let primitives = (0..7)
        .map(|m| json!({"attributes": {"POSITION": positions, "TEXCOORD_0": uvs}, "material": m}))
        .collect();
    let mesh = doc.mesh(primitives);
    let root = doc.node(json!({"mesh": mesh}));
    let path = doc.write_embedded(&dir, "materials", &[root]);
    let loaded = load_gltf(&path, None).unwrap_or_else(|e| panic!("{e}"));
    let m = |name: &str| {
        loaded
            .scene
            .materials
            .iter()
            .find(|m| m.name == name)
            .unwrap_or_else(|| panic!("no material {name}"))
            .clone()
    };
    let plastic = m("plastic");
    assert_eq!(plastic.surface, Surface::Diffuse);
    assert_eq!(plastic.diffuse, Vec3::new(0.5, 0.25, 1.0));
    assert_eq!(plastic.specular, Vec3::splat(0.04));
    // α = 0.5² = 0.25: 2/α² - 2 = 30.
    assert!(
        (plastic.shininess - 30.0).abs() < 1e-4,
        "{}",
        plastic.shininess
    );
    let chrome = m("chrome");
    assert_eq!(chrome.surface, Surface::Mirror);
    assert_eq!(chrome.specular, Vec3::new(0.9, 0.8, 0.7));
    let glass = m("glass");
    assert_eq!(glass.surface, Surface::Glass);
    assert_eq!(
        (glass.ior, glass.transmission),
        (1.33, Vec3::new(0.9, 1.0, 0.9))
    );
    assert_eq!(m("lamp").emission, Vec3::new(4.0, 2.0, 1.0));
    assert_eq!(m("cut").opacity, 0.0);
    assert_eq!(m("veil").opacity, 0.3);
    let printed = m("printed");
    let texture = &loaded.scene.textures[printed.diffuse_texture.expect("a texture") as usize];
    assert_eq!((texture.width, texture.height), (2, 1));
    assert_eq!(&texture.rgba[..8], &[255, 0, 0, 255, 0, 255, 0, 255]);
    // glTF's v runs down the image, the shaders' up: v = 0 becomes 1.
    let uv = loaded.scene.uvs.as_ref().expect("UVs")[0];
    assert_eq!(uv[0].y, 1.0);
    assert_eq!(uv[2].y, 0.0);
    for warned in ["normal textures", "the extension EXT_fancy"] {
        assert!(
            loaded.warnings.iter().any(|w| w.contains(warned)),
            "no warning about {warned}: {:?}",
            loaded.warnings
        );
    }
}

/// Lights and cameras come from their nodes' world transforms; a spot light lights as a point
/// (warned); the first camera is the scene's, every camera is in `cameras`; without lights a
/// headlight and a sun are added.
#[test]
fn lights_and_cameras_come_from_their_nodes() {
    let dir = temp_dir("lights");
    let mut doc = Doc::default();
    let positions = doc.positions(&TRIANGLE);
    let mesh = doc.mesh(vec![json!({"attributes": {"POSITION": positions}})]);
    doc.extra
        .insert("extensionsUsed".into(), json!(["KHR_lights_punctual"]));
    doc.extra.insert(
        "extensions".into(),
        json!({"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1.0, 0.5, 0.5], "intensity": 683.0},
            {"type": "directional", "intensity": 1366.0},
            {"type": "spot", "intensity": 10.0, "spot": {"outerConeAngle": 0.5}}]}}),
    );
    doc.extra.insert(
        "cameras".into(),
        json!([{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}]),
    );
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let point = doc.node(json!({"translation": [1, 2, 3],
        "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    let sun = doc.node(json!({"rotation": [-s, 0, 0, s],
        "extensions": {"KHR_lights_punctual": {"light": 1}}}));
    let spot = doc.node(json!({"extensions": {"KHR_lights_punctual": {"light": 2}}}));
    // A camera 5 up and 10 back, turned 180° about y: it looks along +z.
    let camera =
        doc.node(json!({"camera": 0, "translation": [0, 5, -10], "rotation": [0, 1, 0, 0]}));
    let group = doc.node(json!({"children": [point, sun, spot, camera], "translation": [0, 0, 0]}));
    let shape = doc.node(json!({"mesh": mesh}));
    let path = doc.write_embedded(&dir, "lit", &[shape, group]);
    let loaded = load_gltf(&path, None).unwrap_or_else(|e| panic!("{e}"));
    let scene = &loaded.scene;
    assert_eq!(scene.lights.len(), 3);
    assert_eq!(
        scene.lights[0],
        Light::Point {
            position: DVec3::new(1.0, 2.0, 3.0),
            intensity: Vec3::new(1.0, 0.5, 0.5),
        }
    );
    let Light::Directional {
        direction,
        irradiance,
    } = scene.lights[1]
    else {
        panic!("the sun is {:?}", scene.lights[1]);
    };
    // -90° about x takes -z (the light's travel) to -y: straight down.
    let down = DQuat::from_xyzw(-s, 0.0, 0.0, s) * DVec3::NEG_Z;
    assert!(direction.abs_diff_eq(down, 1e-12) && down.abs_diff_eq(DVec3::NEG_Y, 1e-12));
    assert_eq!(irradiance, Vec3::splat(2.0));
    assert!(matches!(scene.lights[2], Light::Point { .. }));
    assert!(loaded.warnings.iter().any(|w| w.contains("spot lights")));
    assert_eq!(scene.cameras.len(), 1);
    let cam = scene.camera;
    assert!(close(cam.position, DVec3::new(0.0, 5.0, -10.0)));
    assert!(close(cam.look_at - cam.position, DVec3::Z));
    assert!(close(cam.up, DVec3::Y));
    // Without lights, a headlight and a sun.
    let unlit = doc.write_embedded(&dir, "unlit", &[shape]);
    assert_eq!(load_gltf(&unlit, None).unwrap().scene.lights.len(), 2);
}
