// Traversal by hardware ray queries (wgpu's EXPERIMENTAL_RAY_QUERY), in place of `bvh.wgsl`'s
// software traversal: the same `bvh_trace`. The acceleration structure is built over the very
// triangle buffers the software traversal reads (its corners as vertices, three per BVH slot,
// no index buffer; a geometry per chunk), so a hit's geometry and primitive indices give its
// slot.
enable wgpu_ray_query;
#import triangles

@group(2) @binding(0) var scene_structure: acceleration_structure;

// The closest hit along `ray` in (tmin, tmax), or with `any_hit` whichever the hardware finds
// first (for shadow rays). Exact ties go wherever the hardware puts them.
fn bvh_trace(ray: Ray, any_hit: bool) -> Hit {
    var flags = RAY_FLAG_FORCE_OPAQUE;
    if any_hit {
        flags |= RAY_FLAG_TERMINATE_ON_FIRST_HIT;
    }
    var query: ray_query;
    rayQueryInitialize(&query, scene_structure, RayDesc(flags, 0xffu, ray.tmin, ray.tmax, ray.origin, ray.dir));
    while rayQueryProceed(&query) {
    }
    let hit = rayQueryGetCommittedIntersection(&query);
    if hit.kind != RAY_QUERY_INTERSECTION_TRIANGLE {
        return Hit(0.0, 0.0, 0.0, NO_HIT, 0u);
    }
    let slot = (hit.geometry_index << TRIANGLE_CHUNK_SHIFT) | hit.primitive_index;
    return Hit(hit.t, hit.barycentrics.x, hit.barycentrics.y, slot, 0u);
}
