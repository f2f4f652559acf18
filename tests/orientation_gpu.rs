//! Which way the world faces in an image, checked without the code under test: squares placed
//! at known camera-space positions (world axes written out by hand for each pose), rendered
//! on the GPU through a pinhole and a fisheye, must show up at the pixel the README's
//! conventions put them (x right, y down, z forward; pixel centres at i + 0.5; normalized
//! coordinates with the half-width at 1 and y up), computed here from those formulas alone.
//! The reference tracer and `fisheye validate` share `Camera::rotation()` with the renderer,
//! so a mirrored or rolled world would pass every comparison between them; not this one.

mod common;

use common::{camera, ctx};
use fisheye_rt::scene::{Camera, Material, MeshBuilder};
use fisheye_rt::trace::{NO_HIT, RenderOptions, render};
use glam::{DVec2, DVec3, Vec2, Vec3};

/// A pose with its camera axes in the world, written out by hand.
struct Pose {
    camera: Camera,
    right: DVec3,
    down: DVec3,
    forward: DVec3,
}

fn poses() -> Vec<(&'static str, Pose)> {
    let level = |up: DVec3| Pose {
        camera: Camera {
            position: DVec3::ZERO,
            look_at: -DVec3::Z,
            up,
        },
        right: DVec3::X,
        down: -DVec3::Y,
        forward: -DVec3::Z,
    };
    vec![
        // Looking down -z with +y up: +x is to the right.
        ("level", level(DVec3::Y)),
        // An up vector not perpendicular to the view is made so; the pose is the same.
        ("level, tilted up vector", level(DVec3::new(0.0, 1.0, 0.7))),
        // Looking along +x with +z up (a z-up world): +y is to the left.
        (
            "z up",
            Pose {
                camera: Camera {
                    position: DVec3::new(5.0, 2.0, 1.0),
                    look_at: DVec3::new(6.0, 2.0, 1.0),
                    up: DVec3::Z,
                },
                right: -DVec3::Y,
                down: -DVec3::Z,
                forward: DVec3::X,
            },
        ),
        // Rolled a quarter turn: looking down -z with +x up, so +y is to the left.
        (
            "rolled",
            Pose {
                camera: Camera {
                    position: DVec3::new(-1.0, 0.5, 2.0),
                    look_at: DVec3::new(-1.0, 0.5, 1.0),
                    up: DVec3::X,
                },
                right: -DVec3::Y,
                down: -DVec3::X,
                forward: -DVec3::Z,
            },
        ),
    ]
}

/// Camera-space centres (x right, y down, z forward) of the squares, one colour each: right of
/// the axis, above it, lower left, and (for the wide fisheye) behind the camera's plane.
const SQUARES: [[f64; 3]; 4] = [
    [1.0, 0.0, 3.0],
    [0.0, -1.0, 3.0],
    [-0.7, 0.9, 3.0],
    [2.0, 0.3, -0.5],
];

/// Where the README's conventions put camera-space point `c`: the continuous pixel position,
/// or `None` outside the lens's field.
fn expected_pixel(lens: &str, c: DVec3, width: f64, height: f64) -> Option<DVec2> {
    let (x_n, y_n) = match lens {
        // rectilinear:f=1: (x_n, y_n) = f (x, -y) / z.
        "rectilinear:f=1" => {
            if c.z <= 0.0 {
                return None;
            }
            (c.x / c.z, -c.y / c.z)
        }
        // equidistant:f=0.4,fov=220: r = f θ along the azimuth of (x, -y).
        "equidistant:f=0.4,fov=220" => {
            let rho = c.x.hypot(c.y);
            let theta = rho.atan2(c.z);
            if theta > 110f64.to_radians() {
                return None;
            }
            let r = 0.4 * theta;
            (r * c.x / rho, -r * c.y / rho)
        }
        _ => unreachable!(),
    };
    // x_n = 2 px / W - 1 and y_n = (H/W)(1 - 2 py / H) at continuous pixel positions.
    Some(DVec2::new(
        (x_n + 1.0) * width / 2.0,
        height / 2.0 - y_n * width / 2.0,
    ))
}

#[test]
fn squares_appear_where_the_conventions_put_them() {
    let (width, height) = (96, 72);
    for (pose_name, pose) in poses() {
        let mut b = MeshBuilder::new();
        let half = 0.25;
        let materials: Vec<u32> = SQUARES
            .iter()
            .enumerate()
            .map(|(k, c)| {
                let m = b.material(Material::diffuse(&format!("square {k}"), Vec3::ONE));
                let c = DVec3::from_array(*c);
                let centre =
                    pose.camera.position + c.x * pose.right + c.y * pose.down + c.z * pose.forward;
                // Facing the camera's origin: spanned by the camera's right and down axes
                // turned to the square's direction (for the squares in front, just those axes).
                let towards = (centre - pose.camera.position).normalize();
                let u = pose.down.cross(towards).normalize() * 2.0 * half;
                let v = towards.cross(u).normalize() * 2.0 * half;
                b.quad(centre - 0.5 * (u + v), u, v, Vec2::ONE, m);
                m
            })
            .collect();
        let scene = b.finish(Vec::new(), Vec3::ZERO, Vec3::ONE, pose.camera);
        for lens in ["rectilinear:f=1", "equidistant:f=0.4,fov=220"] {
            let out = render(
                ctx(),
                &scene,
                &camera(lens, width, height),
                &RenderOptions::default(),
            )
            .unwrap();
            for (k, c) in SQUARES.iter().enumerate() {
                let what = format!("{pose_name}, {lens}, square {k} at {c:?}");
                let expected = expected_pixel(
                    lens,
                    DVec3::from_array(*c),
                    f64::from(width),
                    f64::from(height),
                );
                let pixels: Vec<DVec2> = (0..out.ids.len())
                    .filter(|&i| {
                        out.ids[i] != NO_HIT
                            && scene.material_of[out.ids[i] as usize] == materials[k]
                    })
                    .map(|i| {
                        let (x, y) = (i % width as usize, i / width as usize);
                        DVec2::new(x as f64 + 0.5, y as f64 + 0.5)
                    })
                    .collect();
                let Some(expected) = expected else {
                    assert!(pixels.is_empty(), "{what}: seen outside the field");
                    continue;
                };
                assert!(pixels.len() >= 4, "{what}: {} pixels", pixels.len());
                // The pixel holding the point shows the square, and the square's pixels are
                // centred on it (a square a few pixels wide, sampled at pixel centres, is
                // centred to within half a pixel, plus a little fisheye distortion).
                let (x, y) = (expected.x.floor() as usize, expected.y.floor() as usize);
                let id = out.ids[y * width as usize + x];
                assert!(
                    id != NO_HIT && scene.material_of[id as usize] == materials[k],
                    "{what}: pixel ({x}, {y}) does not show it"
                );
                let centroid = pixels.iter().sum::<DVec2>() / pixels.len() as f64;
                assert!(
                    centroid.distance(expected) <= 0.6,
                    "{what}: centred on {centroid}, expected {expected}"
                );
            }
        }
    }
}
