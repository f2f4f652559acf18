// The scene's triangles in BVH order (group 1, binding 1) and its instances (binding 8), and
// the ray and hit types that the tracer, the shading code and the rasterizer share.

// Mirrors `fisheye_rt::bvh::GpuTriangle` (48 bytes): corners (camera-relative, or in their
// mesh's space in an instanced scene), the stored triangle it came from and its material.
struct BvhTriangle {
    v0: vec3<f32>,
    triangle: u32,
    v1: vec3<f32>,
    material: u32,
    v2: vec3<f32>,
    pad: u32,
}

// `triangle_at(slot)` reads them from `bvh_triangles` (group 1, binding 1) and, in a scene
// too large for one binding, its further chunks (see `fisheye_rt::split`).
#import scene_arrays

// Mirrors `fisheye_rt::bvh::GpuInstance` (144 bytes): a mesh placed in the world.
struct Instance {
    // Camera-relative world to mesh space, rows [3×3 | translation].
    to_mesh: array<vec4<f32>, 3>,
    // Mesh space to camera-relative world.
    to_world: array<vec4<f32>, 3>,
    // Rows of the normal matrix (inverse transpose of to_world's 3×3), then the node the mesh's
    // BVH starts at, the scene triangle id of its first triangle here, its first stored one.
    normal_x: vec3<f32>,
    root: u32,
    normal_y: vec3<f32>,
    id_base: u32,
    normal_z: vec3<f32>,
    first: u32,
}

@group(1) @binding(8) var<storage, read> instances: array<Instance>;

// Whether the scene places meshes by instances (a two-level BVH; see `wgsl/bvh.wgsl`).
override INSTANCED: bool = false;

fn affine(rows: array<vec4<f32>, 3>, p: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(rows[0].xyz, p), dot(rows[1].xyz, p), dot(rows[2].xyz, p))
        + vec3<f32>(rows[0].w, rows[1].w, rows[2].w);
}

fn linear(rows: array<vec4<f32>, 3>, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(rows[0].xyz, v), dot(rows[1].xyz, v), dot(rows[2].xyz, v));
}

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
    // Index into the triangles (`triangle_at`), NO_HIT if none.
    slot: u32,
    // Index into instances (instanced scenes only).
    instance: u32,
}

// The scene triangle a BVH slot is in a given instance (as ids name it).
fn scene_triangle(slot: u32, instance: u32) -> u32 {
    let stored = triangle_at(slot).triangle;
    if INSTANCED {
        let i = instances[instance];
        return i.id_base + stored - i.first;
    }
    return stored;
}

// A normal of the hit's triangle in mesh space, in the world (not normalized).
fn world_normal(hit: Hit, n: vec3<f32>) -> vec3<f32> {
    if INSTANCED {
        let i = instances[hit.instance];
        return vec3<f32>(dot(i.normal_x, n), dot(i.normal_y, n), dot(i.normal_z, n));
    }
    return n;
}

// The geometric normal of the hit's triangle in the world, its corners' winding on the same
// side as a flattened copy's (not normalized).
fn hit_face_normal(hit: Hit) -> vec3<f32> {
    let tri = triangle_at(hit.slot);
    return world_normal(hit, cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
}

// The point of `hit` on its triangle, camera-relative, from the barycentrics (on the triangle
// to within its rounding, unlike o + t·d).
fn hit_position(hit: Hit) -> vec3<f32> {
    let tri = triangle_at(hit.slot);
    let p = (1.0 - hit.u - hit.v) * tri.v0 + hit.u * tri.v1 + hit.v * tri.v2;
    if INSTANCED {
        return affine(instances[hit.instance].to_world, p);
    }
    return p;
}
