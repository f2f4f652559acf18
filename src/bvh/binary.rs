//! A binary BVH over boxes named by ids, built by median splits and walked in f64: the f64
//! reference tracer's (`trace::cpu`, independent of obvhs's), which also finds the triangles
//! near a volume ([`Tree::any`], for [`super::unshadowed`]).

use glam::DVec3;

enum Node {
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
pub(crate) struct Tree {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

impl Tree {
    /// The tree over `ids`, whose boxes `bounds` gives.
    pub(crate) fn new(ids: Vec<u32>, bounds: &dyn Fn(u32) -> (DVec3, DVec3)) -> Self {
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
    fn build(&mut self, first: usize, count: usize, bounds: &dyn Fn(u32) -> (DVec3, DVec3)) -> u32 {
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
    pub(crate) fn walk(
        &self,
        origin: DVec3,
        dir: DVec3,
        tmin: f64,
        limit: &dyn Fn() -> f64,
        visit: &mut dyn FnMut(u32) -> bool,
    ) {
        let inv = DVec3::ONE / dir;
        self.any(
            &|lo, hi| box_hit(lo, hi, origin, inv, tmin, limit()),
            None,
            visit,
        );
    }

    /// Whether `visit` returns true for an id whose leaf `reach` admits (a box it may meet),
    /// down inner nodes `reach` admits; it stops at the first. With a point `near`, of two
    /// children the one whose box's centre is nearer it is visited first.
    pub(crate) fn any(
        &self,
        reach: &dyn Fn(DVec3, DVec3) -> bool,
        near: Option<DVec3>,
        visit: &mut dyn FnMut(u32) -> bool,
    ) -> bool {
        // Depth-first, at most a node a level and its sibling waiting: 64 levels hold any
        // tree of median splits.
        let mut stack = [0u32; 64];
        let mut waiting = usize::from(!self.nodes.is_empty());
        while waiting > 0 {
            waiting -= 1;
            match self.nodes[stack[waiting] as usize] {
                Node::Leaf {
                    lo,
                    hi,
                    first,
                    count,
                } => {
                    let ids = &self.order[first as usize..(first + count) as usize];
                    if reach(lo, hi) && ids.iter().any(|&id| visit(id)) {
                        return true;
                    }
                }
                Node::Inner {
                    lo,
                    hi,
                    left,
                    right,
                } => {
                    if reach(lo, hi) {
                        // The second pushed is the first visited.
                        let (later, sooner) = match near {
                            Some(p)
                                if self.centre(left).distance_squared(p)
                                    < self.centre(right).distance_squared(p) =>
                            {
                                (right, left)
                            }
                            _ => (left, right),
                        };
                        stack[waiting] = later;
                        stack[waiting + 1] = sooner;
                        waiting += 2;
                    }
                }
            }
        }
        false
    }

    /// The centre of node `index`'s box.
    fn centre(&self, index: u32) -> DVec3 {
        match self.nodes[index as usize] {
            Node::Leaf { lo, hi, .. } | Node::Inner { lo, hi, .. } => (lo + hi) * 0.5,
        }
    }
}

fn box_hit(lo: DVec3, hi: DVec3, origin: DVec3, inv: DVec3, tmin: f64, tmax: f64) -> bool {
    let a = (lo - origin) * inv;
    let b = (hi - origin) * inv;
    let near = a.min(b).max_element().max(tmin);
    let far = a.max(b).min_element().min(tmax);
    // f64 rounding is ~1e-16 relative: a relative pad of 1e-12 is conservative.
    near <= far * (1.0 + 1e-12) + 1e-300
}
