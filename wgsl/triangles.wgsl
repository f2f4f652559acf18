// The scene's triangles in BVH order (group 1, binding 1), and the ray and hit types that the
// tracer, the shading code and the rasterizer share.

// Mirrors `fisheye_rt::bvh::GpuTriangle` (48 bytes): camera-relative corners, the scene
// triangle it came from and its material.
struct BvhTriangle {
    v0: vec3<f32>,
    triangle: u32,
    v1: vec3<f32>,
    material: u32,
    v2: vec3<f32>,
    pad: u32,
}

@group(1) @binding(1) var<storage, read> bvh_triangles: array<BvhTriangle>;

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
    tmin: f32,
    tmax: f32,
}

struct Hit {
    t: f32,
    // Barycentric weights of v1 and v2 (v0's is 1 - u - v).
    u: f32,
    v: f32,
    // Index into bvh_triangles, NO_HIT if none.
    slot: u32,
}

// The point of `hit` on its triangle, from the barycentrics (on the triangle to within its
// rounding, unlike o + t·d).
fn hit_position(hit: Hit) -> vec3<f32> {
    let tri = bvh_triangles[hit.slot];
    return (1.0 - hit.u - hit.v) * tri.v0 + hit.u * tri.v1 + hit.v * tri.v2;
}
