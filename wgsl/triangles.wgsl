// The scene's triangles in BVH order (group 1, binding 1) and its records (binding 2: the
// instances, with moving ones' knots, then what `surface.wgsl` reads), and the ray and hit
// types that the tracer, the shading code and the rasterizer share.

// Mirrors `fisheye_rt::bvh::GpuTriangle` (48 bytes): corners (camera-relative, or in their
// mesh's space in an instanced scene), the stored triangle it came from, its material, and
// the lights no other triangle stands between any point of it and (bit k for light k).
struct BvhTriangle {
    v0: vec3<f32>,
    triangle: u32,
    v1: vec3<f32>,
    material: u32,
    v2: vec3<f32>,
    unshadowed: u32,
}

// `triangle_at(slot)` reads them from `bvh_triangles` (group 1, binding 1) and, in a scene
// too large for one binding, its further chunks (see `fisheye_rt::split`).
#import scene_arrays
#import quaternion

// Mirrors `fisheye_rt::bvh::GpuInstance` (160 bytes): a mesh placed in the world.
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
    // A moving instance's knots (x: the vec4 they start at in `records`, y: how many;
    // with fewer than 2 the fields above place it), and whether it shows (z: 1, or 0 where its
    // placement flattens it).
    motion: vec4<u32>,
}

// The scene's records: first the instances as `Instance`s of INSTANCE_VEC4S vec4s each, then
// moving instances' knots,
// KNOT_VEC4S each (`fisheye_rt::shared::InstanceKnot`): the rotation of the placement's polar
// decomposition M = R·A (a unit quaternion), its translation (camera-relative) and time
// (seconds from the frame's stamp) in w, then symmetric A's xx, yy, zz, xy and xz, yz.
// Then the lights, the materials and the textures' texels (`surface.wgsl`): all the trace
// kernel reads of a scene but its nodes, triangles and vertices, in one binding, so that it
// binds no more than the 8 storage buffers WebGPU gives a stage. Read as words, floats
// bitcast, so that no float load touches the bits of a u32 field.
@group(1) @binding(2) var<storage, read> records: array<vec4<u32>>;

// The vec4 of floats at `k` in `records`.
fn record(k: u32) -> vec4<f32> {
    return bitcast<vec4<f32>>(records[k]);
}

// The scene time of the ray being traced, seconds from the frame's stamp: the camera sets it
// as it places each primary ray (`camera_at`); secondary rays keep it.
var<private> scene_time: f32 = 0.0;

// The instance of the last hit `bvh_trace` found, placed at its time (MOVING only: reading
// a moving instance again would place it again).
var<private> hit_placed: Instance;

// Instance `k` where it is at `scene_time`.
fn instance_at(k: u32) -> Instance {
    var i = stored_instance(k);
    if MOVING && i.motion.y > 1u {
        place_moving(&i, scene_time);
    }
    return i;
}

// The instance of `hit`, the last hit traced.
fn hit_instance(hit: Hit) -> Instance {
    if MOVING {
        return hit_placed;
    }
    return stored_instance(hit.instance);
}

// Instance `k` as stored.
fn stored_instance(k: u32) -> Instance {
    let b = k * INSTANCE_VEC4S;
    return Instance(
        array<vec4<f32>, 3>(record(b), record(b + 1u), record(b + 2u)),
        array<vec4<f32>, 3>(record(b + 3u), record(b + 4u), record(b + 5u)),
        record(b + 6u).xyz, records[b + 6u].w,
        record(b + 7u).xyz, records[b + 7u].w,
        record(b + 8u).xyz, records[b + 8u].w,
        records[b + 9u],
    );
}

// Places moving instance `i` at time `t` between its knots (held at the first and last):
// R by slerp, A and the translation linearly, as `fisheye_rt::bvh` bounds them.
fn place_moving(i: ptr<function, Instance>, t: f32) {
    let first = (*i).motion.x;
    // The last knot at or before t (the first where t precedes them all), by bisection.
    var lo = 0u;
    var hi = (*i).motion.y;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if record(first + mid * KNOT_VEC4S + 1u).w <= t {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let a = first + lo * KNOT_VEC4S;
    var q = record(a);
    var p = record(a + 1u).xyz;
    var diagonal = record(a + 2u);
    var off = record(a + 3u).xy;
    if lo + 1u < (*i).motion.y {
        let b = a + KNOT_VEC4S;
        let ta = record(a + 1u).w;
        let s = clamp((t - ta) / (record(b + 1u).w - ta), 0.0, 1.0);
        q = slerp(q, record(b), s);
        p = mix(p, record(b + 1u).xyz, s);
        diagonal = mix(diagonal, record(b + 2u), s);
        off = mix(off, record(b + 3u).xy, s);
    }
    let sym = mat3x3<f32>(
        vec3<f32>(diagonal.x, diagonal.w, off.x),
        vec3<f32>(diagonal.w, diagonal.y, off.y),
        vec3<f32>(off.x, off.y, diagonal.z),
    );
    let rotation = mat3x3<f32>(
        quat_rotate(q, vec3<f32>(1.0, 0.0, 0.0)),
        quat_rotate(q, vec3<f32>(0.0, 1.0, 0.0)),
        quat_rotate(q, vec3<f32>(0.0, 0.0, 1.0)),
    );
    let m = rotation * sym;
    // M⁻¹'s rows by cross products of M's columns over the determinant.
    let det = dot(m[0], cross(m[1], m[2]));
    let inv = array<vec3<f32>, 3>(cross(m[1], m[2]) / det, cross(m[2], m[0]) / det, cross(m[0], m[1]) / det);
    (*i).to_world = array<vec4<f32>, 3>(
        vec4<f32>(m[0].x, m[1].x, m[2].x, p.x),
        vec4<f32>(m[0].y, m[1].y, m[2].y, p.y),
        vec4<f32>(m[0].z, m[1].z, m[2].z, p.z),
    );
    (*i).to_mesh = array<vec4<f32>, 3>(
        vec4<f32>(inv[0], -dot(inv[0], p)),
        vec4<f32>(inv[1], -dot(inv[1], p)),
        vec4<f32>(inv[2], -dot(inv[2], p)),
    );
    // The normal matrix M⁻ᵀ: its rows are M⁻¹'s columns.
    (*i).normal_x = vec3<f32>(inv[0].x, inv[1].x, inv[2].x);
    (*i).normal_y = vec3<f32>(inv[0].y, inv[1].y, inv[2].y);
    (*i).normal_z = vec3<f32>(inv[0].z, inv[1].z, inv[2].z);
    (*i).motion.z = select(0u, 1u, det != 0.0 && abs(det) < 3.0e38);
}

// Whether the scene places meshes by instances (a two-level BVH; see `wgsl/bvh.wgsl`).
override INSTANCED: bool = false;

// Whether some instance moves (within a frame, where its knots say so).
override MOVING: bool = false;

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
        // Its id base and first stored triangle, which do not move.
        let b = instance * INSTANCE_VEC4S;
        return records[b + 7u].w + stored - records[b + 8u].w;
    }
    return stored;
}

// A normal of the hit's triangle in mesh space, in the world (not normalized).
fn world_normal(hit: Hit, n: vec3<f32>) -> vec3<f32> {
    if INSTANCED {
        let i = hit_instance(hit);
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
        return affine(hit_instance(hit).to_world, p);
    }
    return p;
}
