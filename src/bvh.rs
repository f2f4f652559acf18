//! The scene's BVH: obvhs builds a compressed 8-wide BVH (CWBVH, Ylitie, Karras and Laine
//! 2017) on the CPU; we flatten it and the triangles, camera-relative in f32, into the storage
//! buffers `wgsl/bvh.wgsl` traverses.

use std::time::{Duration, Instant};

use bytemuck::Zeroable;
use glam::{DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::node::CwBvhNode;

use crate::error::{Error, Result};
use crate::scene::Scene;
pub use crate::shared::{GpuTriangle, TRAVERSAL_STACK};

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

const _: () = assert!(std::mem::size_of::<CwBvhNode>() == 80);

/// A built BVH with its triangles in leaf order, ready to upload.
pub struct SceneBvh {
    /// CWBVH nodes (80 bytes each; WGSL reads each as five `vec4<u32>`). Never empty: an empty
    /// scene gets one node with no children, which every ray misses.
    pub nodes: Vec<CwBvhNode>,
    /// Triangles in the order leaves reference them (a pre-split triangle appears more than
    /// once). Never empty (a zero triangle stands in for none).
    pub triangles: Vec<GpuTriangle>,
    /// The world position subtracted from every vertex (the camera position).
    pub origin: DVec3,
    /// Deepest node (root = 1).
    pub depth: u32,
    /// Time obvhs spent building.
    pub build_time: Duration,
}

impl SceneBvh {
    /// Builds the BVH of `scene` relative to `origin`.
    pub fn build(scene: &Scene, origin: DVec3, quality: BvhQuality) -> Result<Self> {
        let rounded: Vec<[Vec3A; 3]> = scene
            .triangles
            .iter()
            .map(|t| t.map(|p| (p - origin).as_vec3().into()))
            .collect();
        // Finite in f64 is not enough: the GPU's f32 (and an acceleration structure, where a
        // non-finite vertex is undefined behaviour) must hold every corner too.
        if let Some(i) = rounded
            .iter()
            .position(|t| !t.iter().all(|p| p.is_finite()))
        {
            let corners = |t: [DVec3; 3]| {
                t.map(|p| format!("({:e}, {:e}, {:e})", p.x, p.y, p.z))
                    .join(", ")
            };
            return Err(Error::Scene(format!(
                "triangle {i} lies beyond the f32 range the GPU computes in (magnitudes up to \
                 {:e}): its corners are {} in the world, {} from the camera",
                f32::MAX,
                corners(scene.triangles[i]),
                corners(scene.triangles[i].map(|p| p - origin))
            )));
        }
        let extent = rounded
            .iter()
            .flatten()
            .fold(0.0f32, |e, p| e.max(p.abs().max_element()));
        if f64::from(extent) > MAX_EXTENT {
            return Err(Error::Scene(format!(
                "the scene reaches {extent:e} units from the camera; the BVH is built in f32 \
                 for scenes within {MAX_EXTENT:e}"
            )));
        }
        if rounded.is_empty() {
            return Ok(Self {
                nodes: vec![CwBvhNode::default()],
                triangles: vec![GpuTriangle::zeroed()],
                origin,
                depth: 1,
                build_time: Duration::ZERO,
            });
        }
        let tris: Vec<obvhs::triangle::Triangle> = rounded
            .iter()
            .map(|t| obvhs::triangle::Triangle {
                v0: t[0],
                v1: t[1],
                v2: t[2],
            })
            .collect();
        let started = Instant::now();
        let mut core = Duration::ZERO;
        let cwbvh =
            obvhs::cwbvh::builder::build_cwbvh_from_tris(&tris, quality.params(), &mut core);
        let build_time = started.elapsed();
        let triangles = cwbvh
            .primitive_indices
            .iter()
            .map(|&i| {
                let t = &rounded[i as usize];
                GpuTriangle {
                    v0: t[0].into(),
                    triangle: i,
                    v1: t[1].into(),
                    material: scene.material_of[i as usize],
                    v2: t[2].into(),
                    pad: 0,
                }
            })
            .collect();
        let depth = node_depth(&cwbvh.nodes, 0);
        if depth > TRAVERSAL_STACK {
            return Err(Error::Limit(format!(
                "the BVH is {depth} levels deep; the GPU traversal stack holds {TRAVERSAL_STACK}"
            )));
        }
        Ok(Self {
            nodes: cwbvh.nodes,
            triangles,
            origin,
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
        let message = SceneBvh::build(&scene, scene.camera.position, BvhQuality::Fast)
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
            SceneBvh::build(&scene, scene.camera.position, BvhQuality::Fast).map(|b| b.depth)
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
