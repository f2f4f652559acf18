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
//! stop it. Scenes whose triangles instances place (and may move) get no such lights. The
//! search's time grows with triangles times lights, so it stops at [`SEARCH_PAIRS`] pairs: a
//! scan of millions of triangles loads without it and traces every shadow ray.

use glam::DVec3;

use super::binary::Tree;
use crate::scene::{Light, Scene};
use crate::shared::{GpuTriangle, UNSHADOWED_LIGHTS};

/// The most (triangle, light) pairs the search looks at in one scene (2^20): about 3 s of
/// two cores at 2.5 to 3 µs a pair, some five times what building the BVH of a million
/// triangles takes on them; in WebAssembly, which searches on one thread, 2^18. Lights are
/// searched in order while their pairs fit; a scene of more triangles searches none.
pub const SEARCH_PAIRS: u64 = if cfg!(target_arch = "wasm32") {
    1 << 18
} else {
    1 << 20
};

/// What [`search`] found in a scene, and what it took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Unshadowed {
    /// The (world triangle, light) pairs looked at.
    pub pairs: u64,
    /// How many of them are open: the light reaches every point of the triangle.
    pub open: u64,
    /// The lights that could have been searched but were not: their pairs would have taken
    /// the search past [`SEARCH_PAIRS`].
    pub unsearched: usize,
    /// The search's wall-clock time.
    pub time: std::time::Duration,
}

/// For each of `scene`'s world triangles, the lights (bit `k` for light `k` below
/// [`UNSHADOWED_LIGHTS`]) that no other triangle stands between any point of it and, counted
/// and timed: never the headlight, which moves with the camera, none in an instanced scene,
/// and only the lights whose pairs fit in [`SEARCH_PAIRS`].
pub fn search(scene: &Scene) -> (Vec<u32>, Unshadowed) {
    search_within(scene, SEARCH_PAIRS)
}

/// [`search`] with at most `budget` pairs.
fn search_within(scene: &Scene, budget: u64) -> (Vec<u32>, Unshadowed) {
    let started = crate::clock::Stopwatch::start();
    let (searched, unsearched) = searched_lights(scene, budget);
    let lights = unshadowed_lights(scene, &searched);
    let summary = Unshadowed {
        pairs: (scene.world_triangles * searched.len()) as u64,
        open: lights.iter().map(|m| u64::from(m.count_ones())).sum(),
        unsearched,
        time: started.elapsed(),
    };
    (lights, summary)
}

/// The lights of a flat `scene` that the search looks at (none in an instanced one; below
/// [`UNSHADOWED_LIGHTS`], not the headlight, in order while their pairs fit in `budget`),
/// and how many others it could have looked at.
fn searched_lights(scene: &Scene, budget: u64) -> (Vec<usize>, usize) {
    if scene.is_instanced() {
        return (Vec::new(), 0);
    }
    let candidates = (0..scene.lights.len().min(UNSHADOWED_LIGHTS as usize))
        .filter(|&k| scene.headlight != Some(k))
        .collect::<Vec<_>>();
    let fit = budget / (scene.world_triangles as u64).max(1);
    let searched = candidates.len().min(fit as usize);
    (candidates[..searched].to_vec(), candidates.len() - searched)
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

/// For each of `scene`'s world triangles, those of the `searched` lights that reach every
/// point of it.
fn unshadowed_lights(scene: &Scene, searched: &[usize]) -> Vec<u32> {
    let triangles = &scene.triangles[..scene.world_triangles];
    let mut lights = vec![0u32; triangles.len()];
    if searched.is_empty() {
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
    crate::threads::in_parts(&mut lights, |first, out| {
        // Each light's last blocker, tried first: neighbouring triangles (a mesh's are
        // stored together) are often blocked by the same one.
        let mut last = vec![None; searched.len()];
        for (j, mask) in out.iter_mut().enumerate() {
            let i = (first + j) as u32;
            for (&k, last) in searched.iter().zip(&mut last) {
                let Some(volume) = Volume::between(corners(i), &scene.lights[k], reach) else {
                    continue;
                };
                let previous = *last;
                let mut blocks = |other: u32| {
                    let found = other != i && volume.meets(corners(other));
                    if found {
                        *last = Some(other);
                    }
                    found
                };
                if let Some(other) = previous
                    && blocks(other)
                {
                    continue;
                }
                // The triangles in the leaves along the segment from the centroid to the
                // light (a ray's walk, cheaper than the volume's): among them any that the
                // segment passes through, which meets the volume unless it only touches it.
                let (centroid, spine) = volume.spine();
                let mut on_spine = false;
                tree.walk(centroid, spine, 0.0, &|| 1.0, &mut |other| {
                    on_spine = blocks(other);
                    on_spine
                });
                // Then the volume's, nearest the triangle first (the rest of its mesh).
                let blocked = on_spine
                    || tree.any(
                        &|lo, hi| volume.may_meet_box(lo, hi),
                        Some(centroid),
                        &mut blocks,
                    );
                if !blocked {
                    *mask |= 1 << k;
                }
            }
        }
    });
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

    /// The triangle's centroid, and the segment from it to the light (or past the scene
    /// towards a directional one).
    fn spine(&self) -> (DVec3, DVec3) {
        let [a, b, c, far] = [0, 1, 2, 3].map(|k| self.corners[k]);
        let centroid = (a + b + c) / 3.0;
        // The fourth corner is the light, or the first corner's far copy.
        let end = if self.count == 6 {
            far - a + centroid
        } else {
            far
        };
        (centroid, end - centroid)
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
        assert_eq!(search(&s).0, [0, 0, 1, 1, 1, 1]);
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
        let open = search(&s).0;
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
        let open = search(&s).0;
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
        assert_eq!(search(&s).0, [1, 1]);
        s.headlight = Some(0);
        assert_eq!(search(&s).0, [0, 0], "the headlight moves with the camera");
        s.headlight = None;
        s.instances.push(crate::scene::Instance {
            first: 0,
            count: 2,
            transform: glam::DAffine3::IDENTITY,
            object: 0,
            animation: None,
        });
        assert_eq!(search(&s).0, [0, 0]);
    }

    #[test]
    fn lights_are_searched_in_order_while_their_pairs_fit() {
        // A tile (two triangles) under three lamps with nothing between: 2 pairs a light.
        let lamps = vec![
            point(0.0, 2.0, 0.0),
            point(1.0, 2.0, 0.0),
            point(0.0, 2.0, 1.0),
        ];
        let mut s = scene(&[square(0.0, 0.0, 0.0, 1.0)], lamps);
        let (open, found) = search_within(&s, 6);
        assert_eq!(open, [0b111, 0b111]);
        assert_eq!((found.pairs, found.open, found.unsearched), (6, 6, 0));
        let (open, found) = search_within(&s, 5);
        assert_eq!(open, [0b011, 0b011], "the third lamp's pairs do not fit");
        assert_eq!((found.pairs, found.open, found.unsearched), (4, 4, 1));
        // The headlight takes no share; a budget under one light's pairs searches none.
        s.headlight = Some(0);
        assert_eq!(search_within(&s, 5).0, [0b110, 0b110]);
        let (open, found) = search_within(&s, 1);
        assert_eq!(open, [0, 0]);
        assert_eq!((found.pairs, found.unsearched), (0, 2));
    }

    /// The search's shortcuts (the tree's culling, the last blocker, the centroid's ray, the
    /// order of its walk) change nothing: on a cloud of random triangles over a floor, under a
    /// lamp and a sun, it finds exactly what testing every other triangle finds.
    #[test]
    fn the_search_finds_what_testing_every_triangle_finds() {
        // splitmix64 (Steele, Lea and Flood, 2014), mapped to [0, 1).
        let mut state = 7u64;
        let mut unit = || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            (z ^ (z >> 31)) as f64 / 2f64.powi(64)
        };
        let mut b = MeshBuilder::new();
        let grey = b.material(Material::diffuse("grey", Vec3::splat(0.5)));
        b.quad(
            DVec3::new(-3.0, 0.0, -3.0),
            DVec3::Z * 6.0,
            DVec3::X * 6.0,
            Vec2::ONE,
            grey,
        );
        for _ in 0..600 {
            let centre = DVec3::new(6.0 * unit() - 3.0, 3.0 * unit(), 6.0 * unit() - 3.0);
            let mut corner = || centre + DVec3::new(unit(), unit(), unit()) * 0.6 - 0.3;
            let corners = [corner(), corner(), corner()];
            b.triangle(corners, None, None, grey);
        }
        let sun = Light::Directional {
            direction: DVec3::new(0.3, -1.0, 0.2).normalize(),
            irradiance: Vec3::ONE,
        };
        let camera = Camera {
            position: DVec3::new(0.0, 1.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        };
        let s = b.finish(
            vec![point(0.5, 5.0, 0.0), sun],
            Vec3::ZERO,
            Vec3::ZERO,
            camera,
        );
        let (bounds_lo, bounds_hi) = crate::scene::bounds(&s.triangles).expect("triangles");
        let reach = 2.0 * (bounds_hi - bounds_lo).length() + 1.0;
        let every = (0..s.triangles.len())
            .map(|i| {
                (0..2)
                    .filter(|&k| {
                        Volume::between(s.triangles[i], &s.lights[k], reach).is_some_and(|v| {
                            (0..s.triangles.len()).all(|j| j == i || !v.meets(s.triangles[j]))
                        })
                    })
                    .fold(0, |mask, k| mask | 1 << k)
            })
            .collect::<Vec<u32>>();
        let (open, found) = search(&s);
        assert_eq!(open, every);
        // Neither all open nor all blocked, for either light.
        for k in 0..2 {
            let lit = every.iter().filter(|&&m| m & 1 << k != 0).count();
            assert!(lit > 20 && lit < every.len() - 20, "light {k}: {lit} open");
        }
        assert_eq!(found.pairs, 2 * every.len() as u64);
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
