//! OBJ import against an independent reading: a tiny hand-written OBJ/MTL (a textured quad
//! with smooth normals, triangles by negative and by normal-only indices, three materials) is
//! read by the loader and by the test-only parser below, which must agree on every triangle's
//! corners, UVs, normals and material. Then the quad's texture, whose four quadrants have four
//! colours, must show each colour where OBJ's convention puts it (`vt 0 1` is the image's
//! top-left corner), on the GPU and in the reference, at pixels computed from the camera
//! conventions alone.

mod common;

use std::collections::HashMap;
use std::path::Path;

use common::{camera, ctx};
use fisheye_rt::scene::Camera;
use fisheye_rt::scene::obj::load_obj;
use fisheye_rt::trace::cpu::Reference;
use fisheye_rt::trace::{RenderOptions, render};
use glam::{DVec3, Vec2, Vec3};

const OBJ: &str = "\
# A textured quad facing +z at z = -3, smooth normals leaning outwards on its right half.
mtllib tiny.mtl
v -1 -1 -3
v 1 -1 -3
v 1 1 -3
v -1 1 -3
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
vn 0.6 0 0.8
o quad
usemtl textured
f 1/1/1 2/2/2 3/3/2 4/4/1
o red
usemtl red
v 1.5 -1 -3
v 2.5 -1 -3
v 2 0 -3
f -3 -2 -1
o blue
usemtl blue
v -2.5 -1 -3
v -1.5 -1 -3
v -2 0 -3
f 8//1 9//1 10//2
";

const MTL: &str = "\
newmtl textured
Kd 1 1 1
map_Kd quadrants.png
newmtl red
Kd 0.8 0.1 0.1
newmtl blue
Kd 0.1 0.2 0.9
";

/// The texture's quadrants, as the image stores them (row 0 at the top).
const TOP_LEFT: [u8; 3] = [255, 0, 0];
const TOP_RIGHT: [u8; 3] = [0, 255, 0];
const BOTTOM_LEFT: [u8; 3] = [0, 0, 255];
const BOTTOM_RIGHT: [u8; 3] = [255, 255, 255];

/// One triangle as the test-only parser reads it.
#[derive(Debug)]
struct Triangle {
    corners: [DVec3; 3],
    uvs: Option<[Vec2; 3]>,
    normals: Option<[Vec3; 3]>,
    material: String,
}

/// Reads `v`, `vt`, `vn`, `usemtl` and `f` (1-based or negative indices, polygons split into a
/// fan from their first corner); nothing else.
fn parse_obj(text: &str) -> Vec<Triangle> {
    let (mut v, mut vt, mut vn) = (Vec::new(), Vec::new(), Vec::new());
    let mut material = String::new();
    let mut out = Vec::new();
    let numbers =
        |words: &[&str]| -> Vec<f64> { words.iter().map(|w| w.parse().unwrap()).collect() };
    let index = |word: &str, count: usize| -> usize {
        let i: i64 = word.parse().unwrap();
        if i < 0 {
            (count as i64 + i) as usize
        } else {
            i as usize - 1
        }
    };
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first() {
            Some(&"v") => {
                let n = numbers(&words[1..]);
                v.push(DVec3::new(n[0], n[1], n[2]));
            }
            Some(&"vt") => {
                let n = numbers(&words[1..]);
                vt.push(Vec2::new(n[0] as f32, n[1] as f32));
            }
            Some(&"vn") => {
                let n = numbers(&words[1..]);
                vn.push(Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32));
            }
            Some(&"usemtl") => material = words[1].to_string(),
            Some(&"f") => {
                let corners: Vec<(usize, Option<usize>, Option<usize>)> = words[1..]
                    .iter()
                    .map(|c| {
                        let parts: Vec<&str> = c.split('/').collect();
                        let get = |k: usize, count: usize| {
                            parts
                                .get(k)
                                .filter(|p| !p.is_empty())
                                .map(|p| index(p, count))
                        };
                        (index(parts[0], v.len()), get(1, vt.len()), get(2, vn.len()))
                    })
                    .collect();
                for k in 1..corners.len() - 1 {
                    let c = [corners[0], corners[k], corners[k + 1]];
                    out.push(Triangle {
                        corners: c.map(|c| v[c.0]),
                        uvs: c[0].1.map(|_| c.map(|c| vt[c.1.unwrap()])),
                        normals: c[0].2.map(|_| c.map(|c| vn[c.2.unwrap()])),
                        material: material.clone(),
                    });
                }
            }
            _ => {}
        }
    }
    out
}

/// `newmtl` and `Kd` of an MTL file.
fn parse_mtl(text: &str) -> HashMap<String, Vec3> {
    let mut out = HashMap::new();
    let mut name = String::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first() {
            Some(&"newmtl") => name = words[1].to_string(),
            Some(&"Kd") => {
                let n: Vec<f32> = words[1..].iter().map(|w| w.parse().unwrap()).collect();
                out.insert(name.clone(), Vec3::new(n[0], n[1], n[2]));
            }
            _ => {}
        }
    }
    out
}

fn write_files(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("tiny.obj"), OBJ).unwrap();
    std::fs::write(dir.join("tiny.mtl"), MTL).unwrap();
    let texture = image::RgbImage::from_fn(4, 4, |x, y| {
        image::Rgb(match (x < 2, y < 2) {
            (true, true) => TOP_LEFT,
            (false, true) => TOP_RIGHT,
            (true, false) => BOTTOM_LEFT,
            (false, false) => BOTTOM_RIGHT,
        })
    });
    texture.save(dir.join("quadrants.png")).unwrap();
}

#[test]
fn obj_import_matches_an_independent_reading() {
    let dir = std::env::temp_dir().join(format!("fisheye-obj-import-{}", std::process::id()));
    write_files(&dir);
    let loaded = load_obj(&dir.join("tiny.obj")).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let mut scene = loaded.scene;
    let expected = parse_obj(OBJ);
    let colours = parse_mtl(MTL);
    assert_eq!(scene.len(), expected.len());
    assert_eq!(expected.len(), 4);
    for e in &expected {
        // The loader may order meshes its own way: find the triangle by its corners.
        let i = scene
            .triangles
            .iter()
            .position(|t| *t == e.corners)
            .unwrap_or_else(|| panic!("{e:?} is not in the scene: {:?}", scene.triangles));
        let material = &scene.materials[scene.material_of[i] as usize];
        assert_eq!(material.name, e.material, "material of {e:?}");
        assert_eq!(
            material.diffuse, colours[&e.material],
            "Kd of {}",
            e.material
        );
        assert_eq!(
            material.diffuse_texture.is_some(),
            e.material == "textured",
            "texture of {}",
            e.material
        );
        if let Some(uvs) = e.uvs {
            assert_eq!(scene.uvs.as_ref().unwrap()[i], uvs, "UVs of {e:?}");
        }
        match e.normals {
            Some(normals) => assert_eq!(scene.normals.as_ref().unwrap()[i], normals),
            // Without vertex normals a triangle gets its face normal at every corner.
            None => {
                let [a, b, c] = e.corners;
                let n = (b - a).cross(c - a).normalize().as_vec3();
                assert_eq!(scene.normals.as_ref().unwrap()[i], [n; 3], "{e:?}");
            }
        }
    }

    // Lit by the ambient term alone, a surface shows Kd times its texture: the texture's
    // quadrants at their UVs, and the two coloured triangles.
    scene.lights.clear();
    scene.ambient = Vec3::ONE;
    scene.sky = Vec3::ZERO;
    scene.camera = Camera {
        position: DVec3::ZERO,
        look_at: -DVec3::Z,
        up: DVec3::Y,
    };
    let (w, h) = (97, 97);
    let cam = camera("rectilinear:f=0.5", w, h);
    let gpu = render(ctx(), &scene, &cam, &RenderOptions::default()).unwrap();
    let cpu = Reference::new(&scene, 0).render(&cam);
    let linear = |c: [u8; 3]| Vec3::from_array(c.map(|x| if x == 255 { 1.0 } else { 0.0 }));
    for (world, colour, what) in [
        // The quad spans x, y in [-1, 1], UV (0, 0) at (-1, -1): UV (0.25, 0.75) is the top-left
        // quadrant's centre, and so on.
        (
            DVec3::new(-0.5, 0.5, -3.0),
            linear(TOP_LEFT),
            "top-left quadrant",
        ),
        (
            DVec3::new(0.5, 0.5, -3.0),
            linear(TOP_RIGHT),
            "top-right quadrant",
        ),
        (
            DVec3::new(-0.5, -0.5, -3.0),
            linear(BOTTOM_LEFT),
            "bottom-left quadrant",
        ),
        (
            DVec3::new(0.5, -0.5, -3.0),
            linear(BOTTOM_RIGHT),
            "bottom-right quadrant",
        ),
        (DVec3::new(2.0, -0.6, -3.0), colours["red"], "red triangle"),
        (
            DVec3::new(-2.0, -0.6, -3.0),
            colours["blue"],
            "blue triangle",
        ),
    ] {
        // Camera space is (x, -y, -z) here; rectilinear f = 0.5: x_n = f x / z, y_n = -f y / z
        // (y up), and pixel position (x_n + 1) W / 2, H / 2 - y_n W / 2.
        let (x_n, y_n) = (0.5 * world.x / -world.z, 0.5 * world.y / -world.z);
        let px = ((x_n + 1.0) * f64::from(w) / 2.0).floor() as usize;
        let py = (f64::from(h) / 2.0 - y_n * f64::from(w) / 2.0).floor() as usize;
        let i = py * w as usize + px;
        for (out, renderer) in [(&gpu, "GPU"), (&cpu, "reference")] {
            let c = Vec3::from_slice(&out.colour[i][..3]);
            assert!(
                (c - colour).abs().max_element() < 1e-5,
                "{renderer}: the {what} at pixel ({px}, {py}) shows {c}, not {colour}"
            );
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}
