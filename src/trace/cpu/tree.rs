//! The reference's binary BVH (built by median splits, walked in f64) and the f32 maps of
//! instances, as the GPU applies them.

//! The f64 reference tracer, the ground truth for the GPU's.
//!
//! It sees exactly the data the GPU sees (camera-relative vertices, lights and camera axes
//! rounded to f32 once, then promoted), shades with the same Whitted model, but computes in
//! f64 and finds hits with its own binary BVHs (median splits; independent of obvhs), itself
//! tested against brute force: one over the world's triangles, one per mesh, and one over the
//! instances that place meshes, whose rays it maps into the mesh's space with the f32 maps the
//! GPU gets. Rays come from the f64 lens reference.

use glam::{DMat3, DVec3};

pub(super) enum Node {
    Leaf {
        lo: DVec3,
        hi: DVec3,
        first: u32,
        count: u32,
    },
    Inner {
        lo: DVec3,
        hi: DVec3,
        left: u32,
        right: u32,
    },
}

/// A binary BVH (median splits) over boxes named by ids.
pub(super) struct Tree {
    pub(super) nodes: Vec<Node>,
    pub(super) order: Vec<u32>,
}

impl Tree {
    /// The tree over `ids`, whose boxes `bounds` gives.
    pub(super) fn new(ids: Vec<u32>, bounds: &dyn Fn(u32) -> (DVec3, DVec3)) -> Self {
        let mut tree = Self {
            nodes: Vec::new(),
            order: ids,
        };
        if !tree.order.is_empty() {
            tree.build(0, tree.order.len(), bounds);
        }
        tree
    }

    /// Builds the subtree over `order[first..first + count]`, returns its node index.
    pub(super) fn build(
        &mut self,
        first: usize,
        count: usize,
        bounds: &dyn Fn(u32) -> (DVec3, DVec3),
    ) -> u32 {
        let (lo, hi) = self.order[first..first + count]
            .iter()
            .map(|&i| bounds(i))
            .fold(
                (DVec3::INFINITY, DVec3::NEG_INFINITY),
                |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
            );
        let index = self.nodes.len() as u32;
        if count <= 4 {
            self.nodes.push(Node::Leaf {
                lo,
                hi,
                first: first as u32,
                count: count as u32,
            });
            return index;
        }
        let axis = (hi - lo).max_position();
        let centroid = |i: &u32| {
            let (a, b) = bounds(*i);
            (a + b)[axis]
        };
        self.order[first..first + count].sort_by(|a, b| centroid(a).total_cmp(&centroid(b)));
        self.nodes.push(Node::Leaf {
            lo,
            hi,
            first: 0,
            count: 0,
        });
        let half = count / 2;
        let left = self.build(first, half, bounds);
        let right = self.build(first + half, count - half, bounds);
        self.nodes[index as usize] = Node::Inner {
            lo,
            hi,
            left,
            right,
        };
        index
    }

    /// Calls `visit` with each id whose leaf box the ray reaches before `limit()`, until it
    /// returns true.
    pub(super) fn walk(
        &self,
        origin: DVec3,
        dir: DVec3,
        tmin: f64,
        limit: &dyn Fn() -> f64,
        visit: &mut dyn FnMut(u32) -> bool,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = DVec3::ONE / dir;
        let mut stack = vec![0u32];
        while let Some(index) = stack.pop() {
            match self.nodes[index as usize] {
                Node::Leaf {
                    lo,
                    hi,
                    first,
                    count,
                } => {
                    if !box_hit(lo, hi, origin, inv, tmin, limit()) {
                        continue;
                    }
                    for &id in &self.order[first as usize..(first + count) as usize] {
                        if visit(id) {
                            return;
                        }
                    }
                }
                Node::Inner {
                    lo,
                    hi,
                    left,
                    right,
                } => {
                    if box_hit(lo, hi, origin, inv, tmin, limit()) {
                        stack.extend([left, right]);
                    }
                }
            }
        }
    }
}

pub(super) fn box_hit(
    lo: DVec3,
    hi: DVec3,
    origin: DVec3,
    inv: DVec3,
    tmin: f64,
    tmax: f64,
) -> bool {
    let a = (lo - origin) * inv;
    let b = (hi - origin) * inv;
    let near = a.min(b).max_element().max(tmin);
    let far = a.max(b).min_element().min(tmax);
    // f64 rounding is ~1e-16 relative: a relative pad of 1e-12 is conservative.
    near <= far * (1.0 + 1e-12) + 1e-300
}

/// An affine map read from the rows the GPU gets.
#[derive(Clone, Copy)]
pub(super) struct Affine {
    pub(super) m: DMat3,
    pub(super) t: DVec3,
}

impl Affine {
    pub(super) fn from_rows(rows: [[f32; 4]; 3]) -> Self {
        let row = |r: [f32; 4]| DVec3::new(r[0].into(), r[1].into(), r[2].into());
        Self {
            m: DMat3::from_cols(row(rows[0]), row(rows[1]), row(rows[2])).transpose(),
            t: DVec3::new(rows[0][3].into(), rows[1][3].into(), rows[2][3].into()),
        }
    }
}
