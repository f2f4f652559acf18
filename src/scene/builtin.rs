//! Built-in procedural scenes that need no files.

use glam::{DVec3, Vec2, Vec3};

use super::mesh::checker;
use super::{Camera, Light, Material, MeshBuilder, Scene};

/// The names `builtin:NAME` accepts, with what each shows.
pub const SCENES: [(&str, &str); 7] = [
    (
        "default",
        "a room with checker floor and grid walls, a mirror and a glass sphere, shadows and many small objects",
    ),
    (
        "grid",
        "a black-and-white calibration checkerboard on the inside of a cube around the camera, for lens validation",
    ),
    (
        "many-small",
        "4,000 small boxes on a plane under the sun (ray tracing's good case)",
    ),
    (
        "few-detailed",
        "three tori of 200,000 triangles each (ray tracing's hard case)",
    ),
    (
        "instances",
        "1,000 instances of one 100,000-triangle torus on a plane: 100M triangles, 100k stored",
    ),
    (
        "instances-few",
        "the first 20 of those instances (2M triangles), small enough to flatten for comparison",
    ),
    (
        "terrain",
        "10M triangles of rolling hills seen from a drone (a 2,237 x 2,237 heightfield): a scene beyond one storage binding",
    ),
];

/// The built-in scene called `name`, or `None`.
pub fn scene(name: &str) -> Option<Scene> {
    match name {
        "default" => Some(room()),
        "grid" => Some(grid()),
        "many-small" => Some(many_small()),
        "few-detailed" => Some(few_detailed()),
        "instances" => Some(instances(1000)),
        "instances-few" => Some(instances(20)),
        "terrain" => Some(terrain(TERRAIN_SIDE)),
        _ => None,
    }
}

/// A small deterministic hash (SplitMix64's finaliser) for placing objects.
fn hash(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// A uniform number in [0, 1) from `(seed, k)`.
fn unit(seed: u64, k: u64) -> f64 {
    (hash(seed.wrapping_mul(0x1000_0000_01b3) ^ k) >> 11) as f64 / (1u64 << 53) as f64
}

fn colour(seed: u64) -> Vec3 {
    Vec3::new(
        0.2 + 0.7 * unit(seed, 1) as f32,
        0.2 + 0.7 * unit(seed, 2) as f32,
        0.2 + 0.7 * unit(seed, 3) as f32,
    )
}

fn room() -> Scene {
    let mut b = MeshBuilder::new();
    let floor_tex = b.texture(checker(
        "checker",
        256,
        8,
        [200, 200, 190],
        [60, 60, 70],
        Some([30, 30, 30]),
    ));
    let wall_tex = b.texture(checker(
        "grid",
        256,
        4,
        [225, 215, 190],
        [215, 205, 180],
        Some([80, 80, 90]),
    ));
    let floor = b.material(Material {
        diffuse_texture: Some(floor_tex),
        ..Material::diffuse("floor", Vec3::ONE)
    });
    let wall = b.material(Material {
        diffuse_texture: Some(wall_tex),
        ..Material::diffuse("wall", Vec3::ONE)
    });
    let ceiling = b.material(Material::diffuse("ceiling", Vec3::splat(0.8)));
    let lamp = b.material(Material {
        emission: Vec3::new(6.0, 5.6, 5.0),
        ..Material::diffuse("lamp", Vec3::ZERO)
    });
    let mirror = b.material(Material::mirror("mirror", Vec3::splat(0.9)));
    let glass = b.material(Material::glass("glass", 1.5));
    let shiny = b.material(Material {
        specular: Vec3::splat(0.5),
        shininess: 60.0,
        ..Material::diffuse("red", Vec3::new(0.75, 0.15, 0.12))
    });

    let (w, h) = (10.0, 4.0);
    let lo = DVec3::new(-w / 2.0, 0.0, -w / 2.0);
    // Inward-facing walls, textured with one cell per metre-ish.
    let tile = Vec2::splat(w as f32 / 2.5);
    b.quad(lo, DVec3::Z * w, DVec3::X * w, tile, floor);
    b.quad(
        lo + DVec3::Y * h,
        DVec3::X * w,
        DVec3::Z * w,
        Vec2::ONE,
        ceiling,
    );
    let wall_uv = Vec2::new(w as f32 / 2.5, h as f32 / 2.5);
    b.quad(lo, DVec3::X * w, DVec3::Y * h, wall_uv, wall); // back (-z)
    b.quad(
        lo + DVec3::new(w, 0.0, w),
        -DVec3::X * w,
        DVec3::Y * h,
        wall_uv,
        wall,
    ); // front
    b.quad(
        lo + DVec3::Z * w,
        -DVec3::Z * w,
        DVec3::Y * h,
        wall_uv,
        wall,
    ); // left
    b.quad(lo + DVec3::X * w, DVec3::Z * w, DVec3::Y * h, wall_uv, wall); // right
    // A glowing panel under the ceiling.
    b.quad(
        DVec3::new(-1.0, h - 0.01, -1.0),
        DVec3::X * 2.0,
        DVec3::Z * 2.0,
        Vec2::ONE,
        lamp,
    );

    b.sphere(DVec3::new(-1.6, 1.0, -2.2), 1.0, 64, 32, false, mirror);
    b.sphere(DVec3::new(1.5, 0.8, -1.4), 0.8, 64, 32, false, glass);
    b.cuboid(
        DVec3::new(2.6, 0.0, -3.8),
        DVec3::new(3.6, 1.4, -2.8),
        shiny,
    );

    // Many small objects: a ring of little boxes and spheres around the room.
    let small: Vec<u32> = (0..8)
        .map(|k| b.material(Material::diffuse("small", colour(k))))
        .collect();
    for k in 0..240u64 {
        let angle = std::f64::consts::TAU * unit(k, 10);
        let radius = 2.6 + 1.8 * unit(k, 11);
        let centre = DVec3::new(radius * angle.cos(), 0.0, radius * angle.sin());
        let size = 0.06 + 0.12 * unit(k, 12);
        let material = small[(k % 8) as usize];
        if k % 3 == 0 {
            b.sphere(centre + DVec3::Y * size, size, 12, 6, false, material);
        } else {
            let half = DVec3::new(size, 0.0, size);
            b.cuboid(
                centre - half,
                centre + half + DVec3::Y * 2.0 * size,
                material,
            );
        }
    }

    let lights = vec![
        Light::Point {
            position: DVec3::new(0.0, 3.2, 0.5),
            intensity: Vec3::new(7.0, 6.6, 6.0),
        },
        Light::Point {
            position: DVec3::new(-3.5, 2.5, 3.5),
            intensity: Vec3::new(2.0, 2.2, 3.0),
        },
    ];
    let camera = Camera {
        position: DVec3::new(0.0, 1.5, 2.5),
        look_at: DVec3::new(0.0, 1.2, -3.0),
        up: DVec3::Y,
    };
    let mut room = b.finish(lights, Vec3::new(0.6, 0.7, 0.9), Vec3::splat(0.06), camera);
    // A walk into the room at eye height, above the small objects: towards the mirror, past
    // the glass sphere, to the box in the corner.
    room.camera_path = walk(&[
        ([0.0, 1.5, 2.5], [0.0, 1.2, -3.0]),
        ([0.5, 1.5, 1.2], [-1.6, 1.0, -2.2]),
        ([-0.4, 1.5, 0.2], [1.5, 0.8, -1.4]),
        ([0.2, 1.6, -0.6], [3.1, 0.7, -3.3]),
    ]);
    room
}

/// Half the side of the `grid` scene's cube, centred on its camera.
const GRID_HALF_SIDE: f64 = 5.0;
/// Texels per side of the `grid` scene's texture.
const GRID_TEXELS: u32 = 512;
/// Checker cells per side of a face of the `grid` scene.
pub const GRID_CELLS: u32 = 16;

/// The `grid` scene's six inner cube faces as `(corner, u, v)`: the points
/// `corner + s·u + t·v` with texture coordinates `(s, t)`, s, t ∈ [0, 1], facing `u × v`
/// (inwards).
fn grid_faces() -> [(DVec3, DVec3, DVec3); 6] {
    let lo = DVec3::splat(-GRID_HALF_SIDE);
    let e = 2.0 * GRID_HALF_SIDE;
    let (x, y, z) = (DVec3::X * e, DVec3::Y * e, DVec3::Z * e);
    [
        (lo, x, y),
        (lo + x + z, -x, y),
        (lo + z, -z, y),
        (lo + x, z, y),
        (lo, z, x),
        (lo + y, x, z),
    ]
}

/// A corner of the `grid` scene's checkerboard, where four cells meet: a point whose position
/// in the image a lens model predicts exactly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridCorner {
    /// Which cube face (0 to 5).
    pub face: usize,
    /// The cell edge along the face's v axis it is on (0 to [`GRID_CELLS`]), counted along u.
    pub a: u32,
    /// The cell edge along the face's u axis it is on, counted against v (0 to
    /// [`GRID_CELLS`]).
    pub b: u32,
    /// World position.
    pub world: DVec3,
    /// World displacement to the next corner along u (to `a + 1`).
    pub step_a: DVec3,
    /// World displacement to the next corner against v (to `b + 1`).
    pub step_b: DVec3,
    /// Whether it is on the cube's edge (`a` or `b` is 0 or [`GRID_CELLS`]), where the
    /// faces fold and the image of its cells is not locally flat.
    pub fold: bool,
}

/// Every corner of the `grid` scene's checkerboard, face by face: those on the cube's edges
/// (see [`GridCorner::fold`]) once per face they are on.
///
/// Cell edges are texel boundaries, `32k` of 512, which the bilinear filter of
/// `wgsl/surface.wgsl` (texel centres at `(i + ½)/512`) turns into ramps one texel wide
/// centred on texture coordinate `k/16`; texel rows run from the top (`t = 1`) down, so edge
/// `b` along v is at `t = 1 - b/16`. A corner's image is symmetric about it under a half
/// turn (the diagonal cells have one colour): that is what `fisheye validate`'s detector
/// relies on.
pub fn grid_corners() -> Vec<GridCorner> {
    let step = 1.0 / f64::from(GRID_CELLS);
    let mut out = Vec::new();
    for (face, (corner, u, v)) in grid_faces().into_iter().enumerate() {
        for b in 0..=GRID_CELLS {
            for a in 0..=GRID_CELLS {
                out.push(GridCorner {
                    face,
                    a,
                    b,
                    world: corner + u * (f64::from(a) * step) + v * (1.0 - f64::from(b) * step),
                    step_a: u * step,
                    step_b: -v * step,
                    fold: a % GRID_CELLS == 0 || b % GRID_CELLS == 0,
                });
            }
        }
    }
    out
}

fn grid() -> Scene {
    let mut b = MeshBuilder::new();
    let tex = b.texture(checker(
        "calibration",
        GRID_TEXELS,
        GRID_CELLS,
        [240, 240, 240],
        [10, 10, 10],
        None,
    ));
    let wall = b.material(Material {
        diffuse_texture: Some(tex),
        ..Material::diffuse("grid", Vec3::ONE)
    });
    for (corner, u, v) in grid_faces() {
        b.quad(corner, u, v, Vec2::ONE, wall);
    }
    let camera = Camera {
        position: DVec3::ZERO,
        look_at: -DVec3::Z,
        up: DVec3::Y,
    };
    // Lit evenly by ambient light alone: the grid's contrast is all in its texture.
    b.finish(Vec::new(), Vec3::ZERO, Vec3::ONE, camera)
}

fn outdoor_lights() -> Vec<Light> {
    vec![Light::Directional {
        direction: DVec3::new(-0.4, -1.0, -0.3).normalize(),
        irradiance: Vec3::new(2.6, 2.4, 2.1),
    }]
}

fn many_small() -> Scene {
    let mut b = MeshBuilder::new();
    let ground = b.material(Material::diffuse("ground", Vec3::new(0.45, 0.5, 0.4)));
    b.quad(
        DVec3::new(-30.0, 0.0, -30.0),
        DVec3::Z * 60.0,
        DVec3::X * 60.0,
        Vec2::ONE,
        ground,
    );
    let palette: Vec<u32> = (0..16)
        .map(|k| b.material(Material::diffuse("box", colour(100 + k))))
        .collect();
    for k in 0..4000u64 {
        let centre = DVec3::new(50.0 * unit(k, 1) - 25.0, 0.0, 50.0 * unit(k, 2) - 25.0);
        let half = DVec3::new(0.1 + 0.2 * unit(k, 3), 0.0, 0.1 + 0.2 * unit(k, 4));
        let height = 0.2 + 1.2 * unit(k, 5);
        b.cuboid(
            centre - half,
            centre + half + DVec3::Y * height,
            palette[(k % 16) as usize],
        );
    }
    let mut scene = outdoors(b, DVec3::new(0.0, 1.7, 0.0), DVec3::new(0.0, 1.2, -10.0));
    // Straight ahead above the boxes (at most 1.4 high), turning right halfway.
    scene.camera_path = walk(&[
        ([0.0, 1.7, 0.0], [0.0, 1.2, -10.0]),
        ([0.0, 1.7, -6.0], [0.0, 1.2, -16.0]),
        ([3.0, 1.7, -10.0], [13.0, 1.2, -10.0]),
    ]);
    scene
}

/// Keyframes of (eye, look-at) pairs, y up.
fn walk(keys: &[([f64; 3], [f64; 3])]) -> Vec<Camera> {
    keys.iter()
        .map(|&(position, look_at)| Camera {
            position: DVec3::from(position),
            look_at: DVec3::from(look_at),
            up: DVec3::Y,
        })
        .collect()
}

/// An outdoor scene: the sun and sky of [`outdoor_lights`], a camera at `position` looking at
/// `look_at`.
fn outdoors(b: MeshBuilder, position: DVec3, look_at: DVec3) -> Scene {
    let camera = Camera {
        position,
        look_at,
        up: DVec3::Y,
    };
    b.finish(
        outdoor_lights(),
        Vec3::new(0.55, 0.7, 0.95),
        Vec3::splat(0.15),
        camera,
    )
}

fn few_detailed() -> Scene {
    let mut b = MeshBuilder::new();
    let ground = b.material(Material::diffuse("ground", Vec3::new(0.5, 0.5, 0.45)));
    b.quad(
        DVec3::new(-20.0, 0.0, -20.0),
        DVec3::Z * 40.0,
        DVec3::X * 40.0,
        Vec2::ONE,
        ground,
    );
    for (k, x) in [-3.2, 0.0, 3.2].into_iter().enumerate() {
        let m = b.material(Material {
            specular: Vec3::splat(0.4),
            shininess: 40.0,
            ..Material::diffuse("torus", colour(200 + k as u64))
        });
        // 500 × 200 × 2 = 200,000 triangles each.
        b.torus(DVec3::new(x, 1.0, -4.0), 1.1, 0.45, 500, 200, m);
    }
    let mut scene = outdoors(b, DVec3::new(0.0, 1.6, 1.0), DVec3::new(0.0, 1.0, -4.0));
    // Up to the middle torus (outer radius 1.55 around z = -4) and along the row.
    scene.camera_path = walk(&[
        ([0.0, 1.6, 1.0], [0.0, 1.0, -4.0]),
        ([0.0, 1.4, -1.2], [0.0, 1.0, -4.0]),
        ([-2.0, 1.4, -1.6], [3.2, 1.0, -4.0]),
    ]);
    scene
}

/// Quads a side of the built-in terrain: 2 × 2237² = 10,008,338 triangles.
const TERRAIN_SIDE: usize = 2237;

/// The terrain's height at `(x, z)`: seven waves of falling amplitude, each along its own
/// direction with its own phase, from the hash (rolling hills up to about 35 m).
fn terrain_height(x: f64, z: f64) -> f64 {
    (0..7u64)
        .map(|k| {
            let angle = std::f64::consts::TAU * unit(k, 11);
            let wavelength = 400.0 / 1.9f64.powi(k as i32);
            let along = x * angle.cos() + z * angle.sin();
            let phase = std::f64::consts::TAU * unit(k, 12);
            wavelength / 25.0 * (std::f64::consts::TAU * along / wavelength + phase).sin()
        })
        .sum()
}

/// A heightfield of `side` × `side` quads over a square kilometre, two triangles each, in
/// three materials by height (meadow, rock, snow), with a drone camera 80 m above the middle
/// looking ahead and down.
fn terrain(side: usize) -> Scene {
    let mut b = MeshBuilder::new();
    let bands = [
        (
            -1e9,
            b.material(Material::diffuse("meadow", Vec3::new(0.1, 0.2, 0.05))),
        ),
        (
            8.0,
            b.material(Material::diffuse("rock", Vec3::new(0.22, 0.19, 0.16))),
        ),
        (
            20.0,
            b.material(Material::diffuse("snow", Vec3::splat(0.8))),
        ),
    ];
    let step = 1000.0 / side as f64;
    let at = |i: usize, j: usize| {
        let (x, z) = (i as f64 * step - 500.0, j as f64 * step - 500.0);
        DVec3::new(x, terrain_height(x, z), z)
    };
    let mut row: Vec<DVec3> = (0..=side).map(|i| at(i, 0)).collect();
    for j in 0..side {
        let next: Vec<DVec3> = (0..=side).map(|i| at(i, j + 1)).collect();
        for i in 0..side {
            let [a, b1, c, d] = [row[i], row[i + 1], next[i], next[i + 1]];
            let height = (a.y + b1.y + c.y + d.y) / 4.0;
            let material = bands
                .iter()
                .rev()
                .find(|(h, _)| height >= *h)
                .expect("a band")
                .1;
            b.triangle([a, c, b1], None, None, material);
            b.triangle([b1, c, d], None, None, material);
        }
        row = next;
    }
    let ground = terrain_height(0.0, 0.0);
    outdoors(
        b,
        DVec3::new(0.0, ground + 80.0, 0.0),
        DVec3::new(0.0, ground, -100.0),
    )
}

/// `count` instances of one 100,000-triangle torus standing on a plane, in rows of 40 across
/// a field 80 m wide, each turned, scaled and coloured by its own hash (the mesh has one
/// material, so colour comes from the scale's spread under the sun).
fn instances(count: u64) -> Scene {
    let mut b = MeshBuilder::new();
    let ground = b.material(Material::diffuse("ground", Vec3::new(0.45, 0.5, 0.4)));
    b.quad(
        DVec3::new(-40.0, 0.0, -60.0),
        DVec3::Z * 62.0,
        DVec3::X * 80.0,
        Vec2::ONE,
        ground,
    );
    let m = b.material(Material {
        specular: Vec3::splat(0.4),
        shininess: 40.0,
        ..Material::diffuse("torus", colour(300))
    });
    let first = b.len();
    // 250 × 200 × 2 = 100,000 triangles, around the y axis, outer radius 0.85.
    b.torus(DVec3::ZERO, 0.6, 0.25, 250, 200, m);
    let mesh = b.mesh_since(first);
    for k in 0..count {
        let (row, column) = ((k / 40) as f64, (k % 40) as f64);
        let scale = 0.7 + 0.6 * unit(k, 1);
        let at = DVec3::new(
            2.0 * column - 39.0 + 0.6 * unit(k, 2),
            0.85 * scale,
            -3.0 - 2.2 * row - 0.6 * unit(k, 3),
        );
        // Stood up on its rim, then turned about the vertical.
        let rotation = glam::DQuat::from_rotation_y(std::f64::consts::TAU * unit(k, 4))
            * glam::DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let placed = b.place(
            mesh,
            glam::DAffine3::from_scale_rotation_translation(DVec3::splat(scale), rotation, at),
        );
        debug_assert!(placed);
    }
    let mut scene = outdoors(b, DVec3::new(0.0, 3.0, 1.5), DVec3::new(0.0, 0.8, -12.0));
    // Over the field, above the tori (at most 2.2 high), then looking along a row.
    scene.camera_path = walk(&[
        ([0.0, 3.0, 1.5], [0.0, 0.8, -12.0]),
        ([0.0, 3.0, -20.0], [0.0, 0.8, -34.0]),
        ([-8.0, 3.0, -24.0], [12.0, 0.8, -24.0]),
    ]);
    scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_scene_builds_and_is_sized_as_documented() {
        // The terrain at full size takes seconds and a gigabyte to build: here at a tenth.
        let small_terrain = || terrain(TERRAIN_SIDE / 10);
        for (name, _) in SCENES {
            let s = match name {
                "terrain" => small_terrain(),
                _ => scene(name).unwrap(),
            };
            assert!(!s.is_empty(), "{name}");
            assert_eq!(s.material_of.len(), s.triangles.len());
            assert!(
                s.material_of
                    .iter()
                    .all(|&m| (m as usize) < s.materials.len())
            );
            let (lo, hi) = s.bounds().unwrap();
            assert!(lo.is_finite() && hi.is_finite());
        }
        assert!(scene("many-small").unwrap().len() >= 4000 * 12);
        assert!(scene("few-detailed").unwrap().len() >= 3 * 200_000);
        // As documented: 100M scene triangles, 100k stored (plus the ground's two).
        let forest = scene("instances").unwrap();
        assert_eq!(
            (forest.len(), forest.triangles.len()),
            (100_000_002, 100_002)
        );
        assert_eq!(scene("instances-few").unwrap().len(), 2_000_002);
        assert_eq!(small_terrain().len(), 2 * (TERRAIN_SIDE / 10).pow(2));
        assert!(2 * TERRAIN_SIDE.pow(2) >= 10_000_000);
        let room = scene("default").unwrap().features();
        assert!(room.mirrors && room.glass && room.textures && room.smooth_normals);
        assert!(scene("no-such").is_none());
    }

    /// Each corner lies on a triangle of the `grid` scene whose interpolated texture
    /// coordinates put it on a texel corner where four texels of alternating colours meet
    /// (the scene's own data, not the formula `grid_corners` uses).
    #[test]
    fn grid_corners_sit_where_four_cells_meet() {
        let s = scene("grid").unwrap();
        let uvs = s.uvs.as_ref().unwrap();
        let texture = &s.textures[0];
        let corners = grid_corners();
        assert_eq!(corners.len(), 6 * 17 * 17);
        assert_eq!(corners.iter().filter(|c| !c.fold).count(), 6 * 15 * 15);
        for c in corners.iter().filter(|c| !c.fold) {
            let (t, bary) = s
                .triangles
                .iter()
                .enumerate()
                .find_map(|(t, [p0, p1, p2])| {
                    let n = (*p1 - *p0).cross(*p2 - *p0);
                    let area = |a: DVec3, b: DVec3| (a - c.world).cross(b - c.world).dot(n);
                    let w = [area(*p1, *p2), area(*p2, *p0), area(*p0, *p1)]
                        .map(|a| a / n.length_squared());
                    let on_plane = (c.world - *p0).dot(n).abs() < 1e-9 * n.length();
                    (on_plane && w.iter().all(|&w| w >= 0.0)).then_some((t, w))
                })
                .unwrap_or_else(|| panic!("{c:?} is on no triangle"));
            let uv = uvs[t]
                .iter()
                .zip(bary)
                .fold(glam::DVec2::ZERO, |sum, (uv, w)| sum + uv.as_dvec2() * w);
            // Texel space with texel edges at integers (rows from the top).
            let size = f64::from(texture.width);
            let st = glam::DVec2::new(uv.x, 1.0 - uv.y) * size;
            assert!((st - st.round()).abs().max_element() < 1e-9, "{c:?}: {st}");
            let texel = |x: f64, y: f64| {
                let k = 4 * (y as usize * texture.width as usize + x as usize);
                texture.rgba[k]
            };
            // The four texels around it, and texels a few away inside the same four cells.
            for d in [0.5, 5.5] {
                let (x, y) = (st.x, st.y);
                let quad = [
                    texel(x - d, y - d),
                    texel(x + d, y - d),
                    texel(x + d, y + d),
                    texel(x - d, y + d),
                ];
                assert!(quad[0] == quad[2] && quad[1] == quad[3] && quad[0] != quad[1]);
                assert!(quad.iter().all(|&v| v == 10 || v == 240), "{c:?}: {quad:?}");
            }
        }
    }
}
