// Casts arbitrary rays into the scene's BVH, one invocation per ray in WORKGROUP_1D-wide
// groups: the closest hit, or with ANY_HIT any hit (shadow rays). The same traversal the
// tracer runs, without shading; for `RayCast`, the peer benchmark and its test.
#import bvh

override ANY_HIT: bool = false;

// Mirrors `fisheye_rt::trace::CastRay` (32 bytes): origin relative to the scene's upload
// origin, direction (any length: t is measured along it), and the interval (tmin, tmax].
struct CastRay {
    origin: vec3<f32>,
    tmin: f32,
    dir: vec3<f32>,
    tmax: f32,
}

@group(0) @binding(0) var<storage, read> rays: array<CastRay>;
// Per ray: t, the scene triangle (as bits; NO_HIT on a miss), and the barycentrics u, v.
@group(0) @binding(1) var<storage, read_write> hits: array<vec4<f32>>;
// Per ray, with COUNT_WORK: the node groups expanded and the triangles tested.
@group(0) @binding(2) var<storage, read_write> work: array<vec2<u32>>;

@compute @workgroup_size(WORKGROUP_1D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&rays) {
        return;
    }
    let r = rays[id.x];
    let hit = bvh_trace(Ray(r.origin, r.dir, r.tmin, r.tmax), ANY_HIT);
    var triangle = NO_HIT;
    if hit.slot != NO_HIT {
        triangle = scene_triangle(hit.slot, hit.instance);
    }
    hits[id.x] = vec4<f32>(hit.t, bitcast<f32>(triangle), hit.u, hit.v);
    if COUNT_WORK {
        work[id.x] = vec2<u32>(work_nodes, work_triangles);
    }
}
