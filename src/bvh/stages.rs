//! obvhs's CWBVH build, stage by stage: its `build_cwbvh*` helpers time themselves with
//! `std::time::Instant`, which panics in a web page (wasm32-unknown-unknown), so the stages
//! are called here in the helpers' order (optional spatial pre-splits of triangles' boxes,
//! PLOC, reinsertion, conversion to a compressed wide BVH with ordered children), the time
//! kept by the caller.

use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::ploc::PlocBuilder;
use obvhs::triangle::Triangle;
use obvhs::{Boundable, splits::split_aabbs_preset};

/// The CWBVH over `triangles`, with their boxes split where `params.pre_split` says (a
/// triangle may then sit in several leaves).
pub(super) fn over_triangles(triangles: &[Triangle], params: BvhBuildParams) -> CwBvh {
    let indices: Vec<u32> = (0..triangles.len() as u32).collect();
    if !params.pre_split || triangles.is_empty() {
        return finish(ploc(triangles, indices, &params), &params, false);
    }
    let mut boxes: Vec<Aabb> = triangles.iter().map(Triangle::aabb).collect();
    let largest = boxes.iter().map(Aabb::half_area).fold(0.0, f32::max);
    let mean = boxes.iter().map(Aabb::half_area).sum::<f32>() / boxes.len() as f32;
    let mut indices = indices;
    split_aabbs_preset(&mut boxes, &mut indices, triangles, mean, largest);
    finish(ploc(&boxes, indices, &params), &params, true)
}

/// The CWBVH over `primitives`' boxes (no splits).
pub(super) fn over_boxes<T: Boundable>(primitives: &[T], params: BvhBuildParams) -> CwBvh {
    let indices = (0..primitives.len() as u32).collect();
    finish(ploc(primitives, indices, &params), &params, false)
}

fn ploc<T: Boundable>(items: &[T], indices: Vec<u32>, params: &BvhBuildParams) -> Bvh2 {
    PlocBuilder::with_capacity(items.len()).build(
        params.ploc_search_distance,
        items,
        indices,
        params.sort_precision,
        params.search_depth_threshold,
    )
}

fn finish(mut bvh2: Bvh2, params: &BvhBuildParams, split: bool) -> CwBvh {
    bvh2.uses_spatial_splits = split;
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3), true, false)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;
    use std::time::Duration;

    /// Triangles of many sizes, so that the slow preset's pre-splits split some.
    fn triangles() -> Vec<Triangle> {
        (0..400)
            .map(|i| {
                let f = i as f32;
                let o = Vec3A::new((f * 0.37).sin() * 9.0, (f * 0.11).cos() * 5.0, f * 0.05);
                let s = if i % 17 == 0 { 6.0 } else { 0.2 };
                // Big ones long diagonal slivers: small for their boxes.
                Triangle {
                    v0: o,
                    v1: o + Vec3A::new(s, s, s),
                    v2: o + Vec3A::new(s, s + 0.2, s),
                }
            })
            .collect()
    }

    /// The stages give the BVH that obvhs's helpers give, node for node.
    #[test]
    fn stages_build_what_the_helpers_build() {
        let tris = triangles();
        for params in [
            BvhBuildParams::fastest_build(),
            BvhBuildParams::medium_build(),
            BvhBuildParams::slow_build(),
        ] {
            let ours = over_triangles(&tris, params);
            let mut core = Duration::ZERO;
            let theirs = obvhs::cwbvh::builder::build_cwbvh_from_tris(&tris, params, &mut core);
            assert!(ours.nodes == theirs.nodes, "pre_split {}", params.pre_split);
            assert_eq!(ours.primitive_indices, theirs.primitive_indices);
            // The slow preset did split: some triangle sits in more than one leaf.
            assert_eq!(params.pre_split, ours.primitive_indices.len() > tris.len());
            let boxes: Vec<Aabb> = tris.iter().map(Triangle::aabb).collect();
            let ours = over_boxes(&boxes, params);
            let theirs = obvhs::cwbvh::builder::build_cwbvh(&boxes, params, &mut core);
            assert!(ours.nodes == theirs.nodes);
            assert_eq!(ours.primitive_indices, theirs.primitive_indices);
        }
    }
}
