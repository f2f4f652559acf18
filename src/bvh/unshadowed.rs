//! The lights that reach every point of a triangle: found once per scene, so that shading
//! skips the shadow rays whose answer is known (the rasterized cube maps' shadow maps are
//! likewise made once per scene, for lights that do not move).
//!
//! A point light reaches every point of triangle T unless some other triangle meets the
//! tetrahedron spanned by T and the light (the union of the segments from T's points to it);
//! a directional light, the prism T swept towards it past the scene's bounds. Each other
//! triangle is tested against that volume by the separating axis theorem (Gottschalk, Lin and
//! Manocha, "OBBTree", SIGGRAPH 1996; Akenine-Möller, "Fast 3D Triangle-Box Overlap
//! Testing", 2001, for the set of axes: each shape's face normals and the cross products of
//! their edges), found through a binary BVH whose boxes the volume's planes cull. A triangle
//! counts as in the way unless a plane separates it from the volume, or it only touches the
//! volume (within f64 rounding: a wall rising from T's edge on the light's side), or it lies
//! on or behind T's own plane (a coplanar neighbour, the rest of a convex mesh): a shadow ray
//! leaves T's surface along its normal (`offset_origin` in `wgsl/shade.wgsl`), so neither can
//! stop it. Scenes whose triangles instances place (and may move) get no such lights.

use glam::DVec3;

use super::binary::Tree;
use crate::scene::{Light, Scene};
use crate::shared::{GpuTriangle, UNSHADOWED_LIGHTS};

/// What [`search`] found in a scene, and what it took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Unshadowed {
    /// The (world triangle, light) pairs looked at.
    pub pairs: u64,
    /// How many of them are open: the light reaches every point of the triangle.
    pub open: u64,
    /// The search's wall-clock time.
    pub time: std::time::Duration,
}

/// [`unshadowed_lights`] of `scene`, counted and timed.
pub fn search(scene: &Scene) -> (Vec<u32>, Unshadowed) {
    let started = crate::clock::Stopwatch::start();
    let lights = unshadowed_lights(scene);
    let most = UNSHADOWED_LIGHTS as usize;
    let looked = scene
        .lights
        .len()
        .min(most)
        .saturating_sub(usize::from(scene.headlight.is_some_and(|h| h < most)));
    let summary = Unshadowed {
        pairs: if scene.is_instanced() {
            0
        } else {
            (lights.len() * looked) as u64
        },
        open: lights.iter().map(|m| u64::from(m.count_ones())).sum(),
        time: started.elapsed(),
    };
    (lights, summary)
}

/// Sets each of a flat `scene`'s BVH triangles' [`GpuTriangle::unshadowed`] from
/// [`search`], and returns what that found.
pub fn mark(scene: &Scene, leaves: &mut [GpuTriangle]) -> Unshadowed {
    let (lights, found) = search(scene);
    for t in leaves {
        t.unshadowed = lights[t.triangle as usize];
    }
    found
}

/// For each of `scene`'s world triangles, the lights (bit `k` for light `k` below
/// [`UNSHADOWED_LIGHTS`]) that no other triangle stands between any point of it and: never the
/// headlight, which moves with the camera, and none in an instanced scene.
pub fn unshadowed_lights(scene: &Scene) -> Vec<u32> {
    let triangles = &scene.triangles[..scene.world_triangles];
    let mut lights = vec![0u32; triangles.len()];
    if scene.is_instanced() || scene.lights.is_empty() {
        return lights;
    }
    let Some((lo, hi)) = crate::scene::bounds(triangles) else {
        return lights;
    };
    // A directional light's prism reaches past every triangle.
    let reach = 2.0 * (hi - lo).length() + 1.0;
    let corners = |i: u32| triangles[i as usize];
    let tree = Tree::new((0..triangles.len() as u32).collect(), &|i| {
        let [a, b, c] = corners(i);
        (a.min(b).min(c), a.max(b).max(c))
    });
    let threads = if cfg!(target_arch = "wasm32") {
        1
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    };
    let chunk = lights.len().div_ceil(threads).max(1);
    let classify = |first: usize, out: &mut [u32]| {
        for (j, mask) in out.iter_mut().enumerate() {
            let i = (first + j) as u32;
            for (k, light) in scene
                .lights
                .iter()
                .take(UNSHADOWED_LIGHTS as usize)
                .enumerate()
            {
                if scene.headlight == Some(k) {
                    continue;
                }
                let Some(volume) = Volume::between(corners(i), light, reach) else {
                    continue;
                };
                let blocked = tree.any(&|lo, hi| volume.may_meet_box(lo, hi), &mut |other| {
                    other != i && volume.meets(corners(other))
                });
                if !blocked {
                    *mask |= 1 << k;
                }
            }
        }
    };
    if threads == 1 {
        classify(0, &mut lights);
    } else {
        std::thread::scope(|s| {
            for (c, out) in lights.chunks_mut(chunk).enumerate() {
                s.spawn(move || classify(c * chunk, out));
            }
        });
    }
    lights
}

/// The segments from a triangle's points to a light: a tetrahedron, or a prism for a
/// directional light.
struct Volume {
    /// Its corners: the triangle's, then the light or the triangle's far copy.
    corners: [DVec3; 6],
    count: usize,
    /// Its bounding box, grown by `margin`.
    lo: DVec3,
    hi: DVec3,
    /// The triangle's plane: its unit normal towards the light, and its offset.
    base: (DVec3, f64),
    /// The side faces' planes: unit normals pointing out of the volume, and their offsets.
    sides: [(DVec3, f64); 3],
    /// Edge directions (the triangle's, then those towards the light).
    edges: [DVec3; 6],
    edge_count: usize,
    /// How far (in scene units) a box must lie outside the volume's planes to be culled by
    /// them: far above rounding at the volume's size.
    margin: f64,
    /// How far a triangle may reach into the volume, or in front of its base, and count as
    /// touching it, not meeting it: f64 rounding of shared corners and edges at the
    /// triangle's magnitude, far below f32's and below any shadow ray's offset from its
    /// surface.
    touch: f64,
}

impl Volume {
    /// The volume between `triangle` and `light`, or `None` where the triangle is degenerate
    /// or the light lies in its plane (no point of it is lit then).
    fn between(triangle: [DVec3; 3], light: &Light, reach: f64) -> Option<Self> {
        let [a, b, c] = triangle;
        let (toward, far) = match *light {
            Light::Point { position, .. } => (position - a, None),
            Light::Directional { direction, .. } => {
                let to = -direction.normalize() * reach;
                (to, Some(to))
            }
        };
        let normal = (b - a).cross(c - a);
        let height = normal.dot(toward);
        if !height.is_finite() || height.abs() <= 1e-12 * normal.length() * toward.length() {
            return None;
        }
        let base = normal.normalize() * height.signum();
        let magnitude = a.abs().max(b.abs()).max(c.abs()).max_element();
        let margin = 1e-6 * (magnitude + toward.length());
        let (corners, count, edges, edge_count) = match far {
            None => {
                let l = a + toward;
                (
                    [a, b, c, l, l, l],
                    4,
                    [b - a, c - b, a - c, l - a, l - b, l - c],
                    6,
                )
            }
            Some(d) => (
                [a, b, c, a + d, b + d, c + d],
                6,
                [b - a, c - b, a - c, d, d, d],
                4,
            ),
        };
        // Each side face through an edge of the triangle and the light (or the sweep),
        // turned away from the triangle's third corner.
        let side = |p: DVec3, q: DVec3, opposite: DVec3| {
            let towards = if far.is_some() {
                toward
            } else {
                a + toward - p
            };
            let n = (q - p).cross(towards).normalize_or_zero();
            let n = if n.dot(opposite - p) > 0.0 { -n } else { n };
            (n, n.dot(p))
        };
        let (lo, hi) = corners[..count]
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), &p| {
                (l.min(p), h.max(p))
            });
        Some(Self {
            corners,
            count,
            lo: lo - margin,
            hi: hi + margin,
            base: (base, base.dot(a)),
            sides: [side(a, b, c), side(b, c, a), side(c, a, b)],
            edges,
            edge_count,
            margin,
            touch: 1e-10 * magnitude.max(1.0),
        })
    }

    /// Whether a box may hold a triangle that [`Volume::meets`] (false only where the
    /// volume's box or one of its side planes puts the whole box outside, or the base plane
    /// puts it on or behind).
    fn may_meet_box(&self, lo: DVec3, hi: DVec3) -> bool {
        if self.lo.cmpgt(hi).any() || self.hi.cmplt(lo).any() {
            return false;
        }
        // The box's corner farthest along `n` (the largest `n · x`), and nearest.
        let farthest = |n: DVec3| DVec3::select(n.cmpge(DVec3::ZERO), hi, lo);
        let nearest = |n: DVec3| DVec3::select(n.cmpge(DVec3::ZERO), lo, hi);
        let (base, offset) = self.base;
        base.dot(farthest(base)) - offset > self.touch
            && self
                .sides
                .iter()
                .all(|&(n, d)| n.dot(nearest(n)) - d <= self.margin)
    }

    /// Whether triangle `other` may meet the volume away from its base plane.
    fn meets(&self, other: [DVec3; 3]) -> bool {
        // On or behind the base plane: a shadow ray leaves from in front of it.
        let (base, offset) = self.base;
        if other.iter().all(|&p| base.dot(p) - offset <= self.touch) {
            return false;
        }
        // Outside a side face (or touching it).
        if self
            .sides
            .iter()
            .any(|&(n, d)| other.iter().all(|&p| n.dot(p) - d >= -self.touch))
        {
            return false;
        }
        let corners = &self.corners[..self.count];
        let apart = |axis: DVec3| {
            let length = axis.length();
            if length < 1e-30 {
                return false;
            }
            let span = |points: &[DVec3]| {
                points
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                        let d = axis.dot(*p);
                        (l.min(d), h.max(d))
                    })
            };
            let (vlo, vhi) = span(corners);
            let (olo, ohi) = span(&other);
            let touch = self.touch * length;
            olo >= vhi - touch || ohi <= vlo + touch
        };
        let other_edges = [
            other[1] - other[0],
            other[2] - other[1],
            other[0] - other[2],
        ];
        if apart(other_edges[0].cross(other_edges[1])) {
            return false;
        }
        !self.edges[..self.edge_count]
            .iter()
            .any(|&e| other_edges.iter().any(|&f| apart(e.cross(f))))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Material, MeshBuilder};
    use glam::{Vec2, Vec3};

    /// A scene of `quads` (each two triangles, corners in order around it), lit by `lights`.
    fn scene(quads: &[[DVec3; 4]], lights: Vec<Light>) -> Scene {
        let mut b = MeshBuilder::new();
        let grey = b.material(Material::diffuse("grey", Vec3::splat(0.5)));
        for q in quads {
            b.quad(q[0], q[1] - q[0], q[3] - q[0], Vec2::ONE, grey);
        }
        let camera = Camera {
            position: DVec3::new(0.0, 1.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        };
        b.finish(lights, Vec3::ZERO, Vec3::ZERO, camera)
    }

    fn point(x: f64, y: f64, z: f64) -> Light {
        Light::Point {
            position: DVec3::new(x, y, z),
            intensity: Vec3::ONE,
        }
    }

    /// A level square at height `y`, `half` from its centre (x, z) to its sides.
    fn square(x: f64, y: f64, z: f64, half: f64) -> [DVec3; 4] {
        [
            DVec3::new(x - half, y, z - half),
            DVec3::new(x - half, y, z + half),
            DVec3::new(x + half, y, z + half),
            DVec3::new(x + half, y, z - half),
        ]
    }

    #[test]
    fn a_floor_under_a_lamp_is_open_where_nothing_hangs_between() {
        // Two floor tiles (coplanar neighbours) under a lamp, a small board hanging over the
        // middle of the first: both of its triangles see the board in the way, the second
        // tile's do not, and the board sees nothing above it.
        let tiles = [square(0.0, 0.0, 0.0, 1.0), square(2.0, 0.0, 0.0, 1.0)];
        let board = square(0.0, 1.0, 0.0, 0.2);
        let s = scene(&[tiles[0], tiles[1], board], vec![point(0.0, 3.0, 0.0)]);
        assert_eq!(unshadowed_lights(&s), [0, 0, 1, 1, 1, 1]);
    }

    #[test]
    fn what_lies_behind_or_beside_the_volume_does_not_shadow() {
        // A tile under a lamp, a wall rising 0.5 beyond the tile's edge, a slab below.
        let tile = square(0.0, 0.0, 0.0, 1.0);
        let wall = [
            DVec3::new(1.5, 0.0, -1.0),
            DVec3::new(1.5, 2.0, -1.0),
            DVec3::new(1.5, 2.0, 1.0),
            DVec3::new(1.5, 0.0, 1.0),
        ];
        let below = square(0.0, -0.5, 0.0, 3.0);
        let s = scene(&[tile, wall, below], vec![point(0.0, 2.0, 0.0)]);
        let open = unshadowed_lights(&s);
        // The tile: the slab is behind its plane, the wall beyond the segments to the lamp.
        assert_eq!(&open[..2], [1, 1], "the tile");
        // The wall: its segments to the lamp stay at y >= 0 and meet the tile's plane only at
        // its foot, beyond the tile; the slab lies below them all.
        assert_eq!(&open[2..4], [1, 1], "the wall");
        assert_eq!(&open[4..], [0, 0], "the slab under the tile");
    }

    #[test]
    fn a_directional_light_is_blocked_by_anything_up_its_beam() {
        let tile = square(0.0, 0.0, 0.0, 1.0);
        let cloud = square(3.0, 10.0, 0.0, 1.0);
        let sun = |x: f64| Light::Directional {
            direction: DVec3::new(x, -1.0, 0.0).normalize(),
            irradiance: Vec3::ONE,
        };
        // Straight down the cloud is off to the side; slanted 0.3 across a unit down, the
        // beam to the tile comes through it.
        let s = scene(&[tile, cloud], vec![sun(0.0), sun(-0.3)]);
        let open = unshadowed_lights(&s);
        assert_eq!(
            &open[..2],
            [0b01, 0b01],
            "only the vertical sun reaches all the tile"
        );
        assert_eq!(&open[2..], [0b11, 0b11], "nothing is above the cloud");
    }

    #[test]
    fn the_headlight_and_instanced_scenes_get_none() {
        let mut s = scene(&[square(0.0, 0.0, 0.0, 1.0)], vec![point(0.0, 2.0, 0.0)]);
        assert_eq!(unshadowed_lights(&s), [1, 1]);
        s.headlight = Some(0);
        assert_eq!(
            unshadowed_lights(&s),
            [0, 0],
            "the headlight moves with the camera"
        );
        s.headlight = None;
        s.instances.push(crate::scene::Instance {
            first: 0,
            count: 2,
            transform: glam::DAffine3::IDENTITY,
            object: 0,
            animation: None,
        });
        assert_eq!(unshadowed_lights(&s), [0, 0]);
    }

    /// Every (triangle, light) pair found open is: shadow rays from points inside the
    /// triangle to the light, cast by the f64 reference tracer (its own traversal), meet
    /// nothing (on two built-in scenes and Šibenik cathedral, whose three lamps hang among
    /// columns and carvings). And the search finds a good share of their pairs open.
    #[test]
    fn no_shadow_ray_from_an_open_pair_meets_a_triangle() {
        let sibenik = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/sibenik.toml");
        for name in ["builtin:default", "builtin:many-small", sibenik] {
            let scene = crate::scene::load(name).expect("a scene").scene;
            let (open, found) = search(&scene);
            assert!(found.open * 5 > found.pairs, "{name}: {found:?}");
            let reference = crate::trace::cpu::Reference::new(&scene, 0);
            let origin = scene.camera.position;
            let mut cast = 0;
            for (t, &mask) in open.iter().enumerate().step_by(7) {
                let [a, b, c] = scene.triangles[t].map(|p| p - origin);
                for (k, light) in scene.lights.iter().enumerate() {
                    if mask & (1 << k) == 0 {
                        continue;
                    }
                    for [u, v] in [[0.34, 0.33], [0.6, 0.2], [0.2, 0.6], [0.15, 0.15]] {
                        let p = a + (b - a) * u + (c - a) * v;
                        let (to, distance) = match *light {
                            Light::Point { position, .. } => {
                                let d = position - origin - p;
                                (d.normalize(), d.length())
                            }
                            Light::Directional { direction, .. } => (-direction.normalize(), 1e30),
                        };
                        let n = (b - a).cross(c - a).normalize();
                        let n = if n.dot(to) > 0.0 { n } else { -n };
                        let from = p + n * 1e-6 * (1.0 + p.length());
                        let hit = reference.trace(from, to, 0.0, distance, true);
                        assert!(hit.is_none(), "{name}: triangle {t}, light {k}: {hit:?}");
                        cast += 1;
                    }
                }
            }
            assert!(cast > 1000, "{name}: {cast} rays");
        }
    }
}
