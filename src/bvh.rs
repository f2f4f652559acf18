//! The scene's BVH: obvhs builds a compressed 8-wide BVH (CWBVH, Ylitie, Karras and Laine
//! 2017) on the CPU; we flatten it and the triangles, camera-relative in f32, into the storage
//! buffers `wgsl/bvh.wgsl` traverses.

use std::time::Duration;

use bytemuck::Zeroable;
use glam::{DAffine3, DMat3, DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::node::CwBvhNode;

use crate::clock::Stopwatch;
use crate::error::{Error, Result};
use crate::scene::Scene;
pub(crate) mod binary;
mod stages;
mod sweep;
pub mod unshadowed;

pub use crate::shared::{GpuInstance, GpuTriangle, TRAVERSAL_STACK};
use crate::shared::{InstanceKnot, KNOT_VEC4S};
pub use sweep::{MAX_INSTANCE_KNOTS, SPLITS};

/// The widest extent, in scene units from the camera, of a scene the BVH is built for. obvhs
/// computes surface areas in f32, and past about 1e19 they overflow and its build panics
/// (measured: a chain of triangles doubling in distance up to 2^69 units); 1e18 leaves room
/// for its sums of areas. No f32 geometry is meaningful across such a span anyway: at 1e18 a
/// coordinate's ulp is 1e11.
pub const MAX_EXTENT: f64 = 1e18;

/// obvhs's build presets, fastest build first.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BvhQuality {
    /// PLOC with the smallest search, one primitive per leaf.
    Fastest,
    /// PLOC, small search.
    VeryFast,
    /// PLOC with a little reinsertion.
    #[default]
    Fast,
    /// More search and reinsertion.
    Medium,
    /// Spatial pre-splits and the widest search.
    Slow,
}

impl BvhQuality {
    /// Every preset, for benchmarks.
    pub const ALL: [BvhQuality; 5] = [
        Self::Fastest,
        Self::VeryFast,
        Self::Fast,
        Self::Medium,
        Self::Slow,
    ];

    /// The preset called `name` (as [`BvhQuality::name`] gives it).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|q| q.name() == name)
    }

    /// The name on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Fastest => "fastest",
            Self::VeryFast => "very-fast",
            Self::Fast => "fast",
            Self::Medium => "medium",
            Self::Slow => "slow",
        }
    }

    fn params(&self) -> BvhBuildParams {
        match self {
            Self::Fastest => BvhBuildParams::fastest_build(),
            Self::VeryFast => BvhBuildParams::very_fast_build(),
            Self::Fast => BvhBuildParams::fast_build(),
            Self::Medium => BvhBuildParams::medium_build(),
            Self::Slow => BvhBuildParams::slow_build(),
        }
    }
}

// The element sizes the scene's arrays are split by (`split`, which reads nothing of the crate)
// are these structs'.
const _: () = assert!(std::mem::size_of::<CwBvhNode>() as u64 == crate::split::NODE_BYTES);
const _: () = assert!(std::mem::size_of::<GpuTriangle>() as u64 == crate::split::TRIANGLE_BYTES);

/// A built BVH with its triangles in leaf order, ready to upload.
///
/// A flat scene has one BVH over its triangles, camera-relative. An instanced scene has two
/// levels in the same buffers: a top-level BVH over instances (its nodes first, root 0), whose
/// leaves name [`GpuInstance`]s, each pointing at the BVH of its mesh (nodes and triangles in
/// mesh space, stored once however many instances use it); the scene's world triangles are one
/// more instance, camera-relative under the identity.
pub struct SceneBvh {
    /// CWBVH nodes (80 bytes each; WGSL reads each as five `vec4<u32>`). Never empty: an empty
    /// scene gets one node with no children, which every ray misses.
    pub nodes: Vec<CwBvhNode>,
    /// Triangles in the order leaves reference them (a pre-split triangle appears more than
    /// once). Never empty (a zero triangle stands in for none).
    pub triangles: Vec<GpuTriangle>,
    /// Instances in the order the top level's leaves reference them; empty for a flat scene.
    pub instances: Vec<GpuInstance>,
    /// The world position subtracted from every world vertex (the camera position).
    pub origin: DVec3,
    /// Deepest node (root = 1) of the deepest BVH (either level).
    pub depth: u32,
    /// Time obvhs spent building.
    pub build_time: Duration,
    /// The lights found to reach whole triangles ([`unshadowed::search`]; a flat scene's).
    pub unshadowed: unshadowed::Unshadowed,
    /// What the top level is built from, where instances move: [`TopLevel::build`] rebuilds
    /// it for each time, into the first [`TopLevel::reserved`] nodes.
    pub top: Option<TopLevel>,
}

/// A mesh's BVH placed in the top level.
#[derive(Clone, Debug)]
struct Placed {
    /// The instance placing it (an index into the scene's); `None` for the world's own
    /// triangles.
    instance: Option<usize>,
    /// Its root node (after the top level's reserved nodes).
    root: u32,
    /// The scene triangle id of its first triangle.
    id_base: u32,
    /// Its first stored triangle.
    first: u32,
    /// Its bounds in its own space (the world's, for the world's triangles).
    bounds: (DVec3, DVec3),
}

/// The top level of an instanced scene: the meshes' BVHs as placed, and the nodes reserved
/// for it at the start of the nodes buffer. Instances (moving ones at some time) are boxed
/// and a CWBVH built over them; the meshes' BVHs stay as built.
#[derive(Clone, Debug)]
pub struct TopLevel {
    placed: Vec<Placed>,
    /// Nodes reserved for the top level (a CWBVH over n boxes has at most n nodes).
    pub reserved: usize,
    quality: BvhQuality,
}

/// One level's BVH as obvhs built it, with its triangles or instances in leaf order.
struct Level<T> {
    nodes: Vec<CwBvhNode>,
    leaves: Vec<T>,
    depth: u32,
}

/// `corners` rounded to f32 after subtracting `origin`, checked to be finite there; `first`
/// numbers them in messages.
fn rounded(corners: &[[DVec3; 3]], origin: DVec3, first: usize) -> Result<Vec<[Vec3A; 3]>> {
    let rounded: Vec<[Vec3A; 3]> = corners
        .iter()
        .map(|t| t.map(|p| (p - origin).as_vec3().into()))
        .collect();
    // Finite in f64 is not enough: the GPU's f32 (and an acceleration structure, where a
    // non-finite vertex is undefined behaviour) must hold every corner too.
    if let Some(i) = rounded
        .iter()
        .position(|t| !t.iter().all(|p| p.is_finite()))
    {
        let show = |t: [DVec3; 3]| {
            t.map(|p| format!("({:e}, {:e}, {:e})", p.x, p.y, p.z))
                .join(", ")
        };
        let space = if origin == DVec3::ZERO {
            "in its mesh's space".to_string()
        } else {
            format!(
                "in the world, {} from the camera",
                show(corners[i].map(|p| p - origin))
            )
        };
        return Err(Error::Scene(format!(
            "triangle {} lies beyond the f32 range the GPU computes in (magnitudes up to {:e}): \
             its corners are {} {space}",
            first + i,
            f32::MAX,
            show(corners[i]),
        )));
    }
    check_extent(rounded.iter().flatten().copied())?;
    Ok(rounded)
}

/// Refuses points farther than [`MAX_EXTENT`] from the origin, before obvhs would panic.
fn check_extent(points: impl Iterator<Item = Vec3A>) -> Result<()> {
    let extent = points.fold(0.0f32, |e, p| e.max(p.abs().max_element()));
    if f64::from(extent) > MAX_EXTENT {
        return Err(Error::Scene(format!(
            "the scene reaches {extent:e} units from the camera; the BVH is built in f32 \
             for scenes within {MAX_EXTENT:e}"
        )));
    }
    Ok(())
}

/// Runs `build`, adding its time to `build_time`, and checks the BVH's depth.
fn build_level(
    build: impl FnOnce() -> obvhs::cwbvh::CwBvh,
    build_time: &mut Duration,
) -> Result<(Vec<CwBvhNode>, Vec<u32>, u32)> {
    let started = Stopwatch::start();
    let cwbvh = build();
    *build_time += started.elapsed();
    let depth = node_depth(&cwbvh.nodes, 0);
    if depth > TRAVERSAL_STACK {
        return Err(Error::Limit(format!(
            "the BVH is {depth} levels deep; the GPU traversal stack holds {TRAVERSAL_STACK}"
        )));
    }
    Ok((cwbvh.nodes, cwbvh.primitive_indices, depth))
}

/// The BVH of stored triangles `first..first + corners.len()` (rounded as given).
fn triangle_level(
    scene: &Scene,
    corners: &[[Vec3A; 3]],
    first: usize,
    quality: BvhQuality,
    build_time: &mut Duration,
) -> Result<Level<GpuTriangle>> {
    let tris: Vec<obvhs::triangle::Triangle> = corners
        .iter()
        .map(|t| obvhs::triangle::Triangle {
            v0: t[0],
            v1: t[1],
            v2: t[2],
        })
        .collect();
    // From triangles, so that the slow preset's spatial pre-splits apply.
    let (nodes, order, depth) = build_level(
        || stages::over_triangles(&tris, quality.params()),
        build_time,
    )?;
    let leaves = order
        .iter()
        .map(|&i| {
            let t = &corners[i as usize];
            let stored = first + i as usize;
            GpuTriangle {
                v0: t[0].into(),
                triangle: stored as u32,
                v1: t[1].into(),
                material: scene.material_of[stored],
                v2: t[2].into(),
                unshadowed: 0,
            }
        })
        .collect();
    Ok(Level {
        nodes,
        leaves,
        depth,
    })
}

/// Rows `[m | t]` of an affine map, rounded to f32.
fn rows(m: DMat3, t: DVec3) -> [[f32; 4]; 3] {
    let r = m.transpose();
    [r.x_axis, r.y_axis, r.z_axis]
        .map(|row| row.as_vec3())
        .into_iter()
        .zip(t.as_vec3().to_array())
        .map(|(row, w)| [row.x, row.y, row.z, w])
        .collect::<Vec<_>>()
        .try_into()
        .expect("three rows")
}

/// An instance placing the mesh whose BVH starts at node `root` by `transform` (world, not
/// camera-relative), for a scene relative to `origin`.
pub(crate) fn gpu_instance(
    transform: DAffine3,
    origin: DVec3,
    root: u32,
    id_base: u32,
    first: u32,
) -> GpuInstance {
    let m = transform.matrix3;
    let inverse = m.inverse();
    let normal = rows(inverse.transpose(), DVec3::ZERO);
    GpuInstance {
        to_mesh: rows(inverse, inverse * (origin - transform.translation)),
        to_world: rows(m, transform.translation - origin),
        normal_x: [normal[0][0], normal[0][1], normal[0][2]],
        root,
        normal_y: [normal[1][0], normal[1][1], normal[1][2]],
        id_base,
        normal_z: [normal[2][0], normal[2][1], normal[2][2]],
        first,
        motion: [0, 0, u32::from(crate::scene::shows(&transform)), 0],
    }
}

impl SceneBvh {
    /// Builds the BVH of `scene` relative to `origin`; for a flat scene that rays shade
    /// (`shaded`), with the lights that reach whole triangles ([`unshadowed`]).
    pub fn build(scene: &Scene, origin: DVec3, quality: BvhQuality, shaded: bool) -> Result<Self> {
        let world = rounded(&scene.triangles[..scene.world_triangles], origin, 0)?;
        let mut build_time = Duration::ZERO;
        let mut unshadowed = unshadowed::Unshadowed::default();
        if scene.is_empty() {
            return Ok(Self {
                nodes: vec![CwBvhNode::default()],
                triangles: vec![GpuTriangle::zeroed()],
                instances: Vec::new(),
                origin,
                depth: 1,
                build_time,
                unshadowed,
                top: None,
            });
        }
        if !scene.is_instanced() {
            let mut level = triangle_level(scene, &world, 0, quality, &mut build_time)?;
            if shaded {
                unshadowed = unshadowed::mark(scene, &mut level.leaves);
            }
            return Ok(Self {
                nodes: level.nodes,
                triangles: level.leaves,
                instances: Vec::new(),
                origin,
                depth: level.depth,
                build_time,
                unshadowed,
                top: None,
            });
        }
        // The bottom level: the world's triangles, then each mesh once.
        let mut nodes = Vec::new();
        let mut triangles = Vec::new();
        let mut depth = 0;
        let mut append = |level: Level<GpuTriangle>, nodes: &mut Vec<CwBvhNode>| {
            let (node_base, slot_base) = (nodes.len() as u32, triangles.len() as u32);
            nodes.extend(level.nodes.into_iter().map(|mut n| {
                n.child_base_idx += node_base;
                n.primitive_base_idx += slot_base;
                n
            }));
            triangles.extend(level.leaves);
            depth = depth.max(level.depth);
            node_base
        };
        let mut placed: Vec<Placed> = Vec::new();
        if let Some(bounds) = crate::scene::bounds(&scene.triangles[..scene.world_triangles]) {
            let level = triangle_level(scene, &world, 0, quality, &mut build_time)?;
            placed.push(Placed {
                instance: None,
                root: append(level, &mut nodes),
                id_base: 0,
                first: 0,
                bounds,
            });
        }
        let mut roots = std::collections::HashMap::new();
        let mut id_base = scene.world_triangles as u32;
        for (index, instance) in scene.instances.iter().enumerate() {
            let base = id_base;
            id_base += instance.count;
            let first = instance.first as usize;
            let mesh = &scene.triangles[first..first + instance.count as usize];
            // A fixed instance that shows nothing is left out; a moving one may show later.
            let moving = instance.animation.is_some();
            let Some(bounds) = crate::scene::bounds(mesh).filter(|_| moving || instance.visible())
            else {
                continue;
            };
            let root = match roots.get(&instance.first) {
                Some(&root) => root,
                None => {
                    let corners = rounded(mesh, DVec3::ZERO, first)?;
                    let level = triangle_level(scene, &corners, first, quality, &mut build_time)?;
                    let root = append(level, &mut nodes);
                    roots.insert(instance.first, root);
                    root
                }
            };
            placed.push(Placed {
                instance: Some(index),
                root,
                id_base: base,
                first: instance.first,
                bounds,
            });
        }
        let mut top = TopLevel {
            // Room for any time's top level where instances move; else exactly this one's.
            reserved: if scene.moves() { placed.len() + 1 } else { 0 },
            placed,
            quality,
        };
        let placements: Vec<DAffine3> = scene.instances.iter().map(|i| i.transform).collect();
        let built = top.build(&placements, origin)?;
        build_time += built.build_time;
        if !scene.moves() {
            top.reserved = built.nodes.len();
        }
        for n in &mut nodes {
            n.child_base_idx += top.reserved as u32;
        }
        let mut all = built.nodes;
        all.resize(top.reserved, CwBvhNode::default());
        all.extend(nodes);
        Ok(Self {
            nodes: all,
            triangles,
            instances: built.instances,
            origin,
            depth: depth.max(built.depth),
            build_time,
            unshadowed,
            top: scene.moves().then_some(top),
        })
    }
}

/// A top level as [`TopLevel::build`] makes it.
pub struct BuiltTop {
    /// Its nodes (at most [`TopLevel::reserved`] where instances move).
    pub nodes: Vec<CwBvhNode>,
    /// Its instances in leaf order.
    pub instances: Vec<GpuInstance>,
    /// Moving instances' knots, where a frame spans time: they start at vec4
    /// [`TopLevel::knots_at`] of the instances' buffer.
    pub knots: Vec<InstanceKnot>,
    /// Its depth.
    pub depth: u32,
    /// obvhs's time.
    pub build_time: Duration,
}

/// Where an instance is over a frame.
enum Place {
    /// Still, by this placement.
    Fixed(DAffine3),
    /// Moving, by these knots.
    Swept(sweep::Swept),
}

impl TopLevel {
    /// The top level over the scene's instances placed by `placements` (one per instance of
    /// the scene it was made for: [`Scene::placements_at`]), camera-relative to `origin`.
    /// Instances placed to show nothing are left out.
    pub fn build(&self, placements: &[DAffine3], origin: DVec3) -> Result<BuiltTop> {
        let places = placements.iter().map(|&m| Place::Fixed(m)).collect();
        self.build_from(places, origin)
    }

    /// The top level of `scene` (the scene it was made for) over a frame at scene time
    /// `stamp` whose rays span `window` seconds from it ([`crate::lens::LensCamera::
    /// exposure_span`]): still instances placed, moving ones by knots over the window
    /// (where it is an instant, placed at it).
    pub fn build_over(
        &self,
        scene: &Scene,
        stamp: f64,
        window: (f64, f64),
        origin: DVec3,
    ) -> Result<BuiltTop> {
        if window.0 == window.1 {
            return self.build(&scene.placements_at(stamp + window.0), origin);
        }
        let mut boxes = vec![None; scene.instances.len()];
        for p in &self.placed {
            if let Some(i) = p.instance {
                boxes[i] = Some(p.bounds);
            }
        }
        let places = scene
            .instances
            .iter()
            .zip(boxes)
            .map(
                |(instance, mesh_box)| match (instance.animation, mesh_box) {
                    (Some(a), Some(mesh_box)) => {
                        let animation = &scene.animations[a as usize];
                        Place::Swept(sweep::sweep(animation, stamp, window, mesh_box, origin))
                    }
                    _ => Place::Fixed(instance.transform),
                },
            )
            .collect();
        self.build_from(places, origin)
    }

    /// The vec4 of the instances' buffer moving instances' knots start at.
    pub fn knots_at(&self) -> u32 {
        self.reserved as u32 * crate::shared::INSTANCE_VEC4S
    }

    /// The most knots a frame's moving instances take.
    pub fn knot_capacity(&self, scene: &Scene) -> usize {
        let moving = scene.instances.iter().filter(|i| i.animation.is_some());
        moving.count() * sweep::MAX_INSTANCE_KNOTS
    }

    fn build_from(&self, places: Vec<Place>, origin: DVec3) -> Result<BuiltTop> {
        let world = Place::Fixed(DAffine3::from_translation(origin));
        // Each shown mesh, with its placement (where still) and its camera-relative box.
        let shown: Vec<(&Placed, &Place, (DVec3, DVec3))> = self
            .placed
            .iter()
            .filter_map(|p| {
                let place = p.instance.map_or(&world, |i| &places[i]);
                let bounds = match (p.instance, place) {
                    (None, _) => Some((p.bounds.0 - origin, p.bounds.1 - origin)),
                    (Some(_), Place::Fixed(m)) => crate::scene::shows(m).then(|| {
                        let (lo, hi) = crate::scene::placed_box(p.bounds, *m);
                        (lo - origin, hi - origin)
                    }),
                    (Some(_), Place::Swept(swept)) => swept.bounds,
                };
                bounds.map(|b| (p, place, b))
            })
            .collect();
        // Padded for the roundings of the f32 transforms (a relative 1e-5 of the box's reach
        // is hundreds of ulp).
        let boxes: Vec<obvhs::aabb::Aabb> = shown
            .iter()
            .map(|&(_, _, (lo, hi))| {
                let pad = DVec3::splat(1e-5 * lo.abs().max(hi.abs()).max_element());
                obvhs::aabb::Aabb {
                    min: (lo - pad).as_vec3().into(),
                    max: (hi + pad).as_vec3().into(),
                }
            })
            .collect();
        check_extent(boxes.iter().flat_map(|b| [b.min, b.max]))?;
        let mut build_time = Duration::ZERO;
        if boxes.is_empty() {
            return Ok(BuiltTop {
                nodes: vec![CwBvhNode::default()],
                instances: Vec::new(),
                knots: Vec::new(),
                depth: 1,
                build_time,
            });
        }
        let (top, order, depth) = build_level(
            || stages::over_boxes(&boxes, self.quality.params()),
            &mut build_time,
        )?;
        if self.reserved > 0 && top.len() > self.reserved {
            return Err(Error::Limit(format!(
                "the top level over {} instances took {} nodes, more than the {} reserved",
                boxes.len(),
                top.len(),
                self.reserved
            )));
        }
        let shift = self.reserved.max(top.len()) as u32;
        let mut knots = Vec::new();
        let instances = order
            .iter()
            .map(|&i| {
                let (p, place, _) = shown[i as usize];
                let root = p.root + shift;
                match place {
                    Place::Fixed(m) => gpu_instance(*m, origin, root, p.id_base, p.first),
                    Place::Swept(swept) => {
                        let start = self.knots_at() + knots.len() as u32 * KNOT_VEC4S;
                        knots.extend_from_slice(&swept.knots);
                        let mut instance = gpu_instance(
                            DAffine3::from_translation(origin),
                            origin,
                            root,
                            p.id_base,
                            p.first,
                        );
                        instance.motion = [start, swept.knots.len() as u32, 1, 0];
                        instance
                    }
                }
            })
            .collect();
        Ok(BuiltTop {
            nodes: top,
            instances,
            knots,
            depth,
            build_time,
        })
    }
}

fn node_depth(nodes: &[CwBvhNode], index: usize) -> u32 {
    let node = &nodes[index];
    (0..8)
        .filter(|&c| !node.is_leaf(c))
        .map(|c| node_depth(nodes, node.child_node_index(c) as usize))
        .max()
        .unwrap_or(0)
        + 1
}

#[cfg(test)]
mod tests {
    use std::mem::{offset_of, size_of};

    use glam::Vec3;

    use super::*;
    use crate::scene::{Camera, Material, MeshBuilder};

    /// A corner that f64 holds but f32 cannot is refused with the triangle named, before it
    /// could reach the GPU (or an acceleration structure, where it is undefined behaviour).
    #[test]
    fn corners_beyond_f32_are_refused() {
        let mut b = MeshBuilder::new();
        let m = b.material(Material::diffuse("grey", Vec3::ONE));
        b.triangle([DVec3::ZERO, DVec3::X, DVec3::Y], None, None, m);
        b.triangle(
            [DVec3::ZERO, DVec3::X, DVec3::new(0.0, 1e39, 0.0)],
            None,
            None,
            m,
        );
        let camera = Camera {
            position: DVec3::new(0.0, 0.0, -1.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        };
        let scene = b.finish(Vec::new(), Vec3::ZERO, Vec3::ZERO, camera);
        let message = SceneBvh::build(&scene, scene.camera.position, BvhQuality::Fast, false)
            .err()
            .expect("refused")
            .to_string();
        assert!(
            message.contains("triangle 1") && message.contains("f32 range"),
            "{message}"
        );
    }

    /// A scene wider than [`MAX_EXTENT`] is refused before obvhs, which would panic on it; a
    /// scene just inside builds.
    #[test]
    fn scenes_beyond_the_extent_are_refused() {
        let chain = |last: i32| {
            let mut b = MeshBuilder::new();
            let m = b.material(Material::diffuse("grey", Vec3::ONE));
            for k in 0..=last {
                let x = 2f64.powi(k);
                let s = 0.1 * x;
                let corners = [
                    DVec3::new(x, 0.0, 0.0),
                    DVec3::new(x + s, 0.0, 0.0),
                    DVec3::new(x, s, 0.0),
                ];
                b.triangle(corners, None, None, m);
            }
            let camera = Camera {
                position: DVec3::ZERO,
                look_at: DVec3::X,
                up: DVec3::Y,
            };
            let scene = b.finish(Vec::new(), Vec3::ZERO, Vec3::ZERO, camera);
            SceneBvh::build(&scene, scene.camera.position, BvhQuality::Fast, false).map(|b| b.depth)
        };
        // 2^69 (with its 10% triangle) panicked inside obvhs; 2^58 is within 1e18.
        let message = chain(69).expect_err("refused").to_string();
        assert!(
            message.contains("6.4") && message.contains("1e18"),
            "{message}"
        );
        assert!(chain(58).is_ok());
    }

    /// `wgsl/bvh.wgsl` reads obvhs's 80-byte node as five `vec4<u32>`, words as documented
    /// there: these offsets pin that reading to obvhs's struct.
    #[test]
    fn cwbvh_node_words_match_the_wgsl_reading() {
        use obvhs::cwbvh::node::CwBvhNode as N;
        assert_eq!(size_of::<N>(), 80);
        let words = [
            (offset_of!(N, p), 0),
            (offset_of!(N, e), 3),
            (offset_of!(N, imask), 3),
            (offset_of!(N, child_base_idx), 4),
            (offset_of!(N, primitive_base_idx), 5),
            (offset_of!(N, child_meta), 6),
            (offset_of!(N, child_min_x), 8),
            (offset_of!(N, child_max_x), 10),
            (offset_of!(N, child_min_y), 12),
            (offset_of!(N, child_max_y), 14),
            (offset_of!(N, child_min_z), 16),
            (offset_of!(N, child_max_z), 18),
        ];
        for (offset, word) in words {
            assert_eq!(offset / 4, word);
        }
        // e's three bytes, then imask as the word's top byte.
        assert_eq!(offset_of!(N, imask), 15);
    }
}
