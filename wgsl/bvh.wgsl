// CWBVH traversal with closest-hit and any-hit queries, written for this project after the
// algorithm of Ylitie, Karras and Laine 2017 ("Efficient Incoherent Ray Traversal on GPUs
// Through Compressed Wide BVHs") and obvhs's node encoding. Robust by construction: child
// boxes are tested conservatively (padded by a bound on every rounding, after Ize 2013,
// "Robust BVH Ray Traversal"), and triangles watertightly (Woop, Benthin and Wald 2013).
#import triangles

// Mirrors `obvhs::cwbvh::node::CwBvhNode` (80 bytes) as five vec4<u32> per node:
// [0] p.xyz (f32 bits), e.x | e.y << 8 | e.z << 16 | imask << 24
// [1] child_base_idx, primitive_base_idx, child_meta[0..4], child_meta[4..8]
// [2] child_min_x[0..8], child_max_x[0..8]   (two words each)
// [3] child_min_y, child_max_y
// [4] child_min_z, child_max_z
// read by `node_word(node, word)` from `bvh_nodes` (group 1, binding 0) and, in a scene too
// large for one binding, its further chunks (see `fisheye_rt::split`).

// 4 ulp: covers the roundings of the slab test and of obvhs's quantization.
const BOX_PAD: f32 = 4.0 * 1.1920929e-7;
// Edge functions this close to zero (relative to their products) count as zero, so a point
// on a shared edge is inside both triangles even where the driver fuses multiply-adds.
const EDGE_BAND: f32 = 2.0 * 1.1920929e-7;

// Whether the traversal counts its work (the ray-cast kernel's counting pass): node groups
// expanded (`node_hits` calls) and triangles tested, per invocation.
override COUNT_WORK: bool = false;
var<private> work_nodes: u32;
var<private> work_triangles: u32;

// Woop et al.'s per-ray shear: kz is the dominant axis, (kx, ky) keep the winding.
struct Shear {
    k: vec3<u32>,
    s: vec3<f32>,
}

fn ray_shear(dir: vec3<f32>) -> Shear {
    let a = abs(dir);
    var kz = 2u;
    if a.x > a.y && a.x > a.z {
        kz = 0u;
    } else if a.y > a.z {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    if dir[kz] < 0.0 {
        let swap = kx;
        kx = ky;
        ky = swap;
    }
    return Shear(vec3<u32>(kx, ky, kz), vec3<f32>(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]));
}

// a·d - b·c with results within EDGE_BAND of zero snapped to zero.
fn edge(a: f32, d: f32, b: f32, c: f32) -> f32 {
    let p = a * d;
    let q = b * c;
    let e = p - q;
    return select(e, 0.0, abs(e) <= EDGE_BAND * (abs(p) + abs(q)));
}

// Watertight ray/triangle test; returns (t, u, v, 1) on a hit within (tmin, tmax], else 0.
fn triangle_hit(slot: u32, ray: Ray, sh: Shear) -> vec4<f32> {
    let tri = triangle_at(slot);
    let a = tri.v0 - ray.origin;
    let b = tri.v1 - ray.origin;
    let c = tri.v2 - ray.origin;
    let ax = a[sh.k.x] - sh.s.x * a[sh.k.z];
    let ay = a[sh.k.y] - sh.s.y * a[sh.k.z];
    let bx = b[sh.k.x] - sh.s.x * b[sh.k.z];
    let by = b[sh.k.y] - sh.s.y * b[sh.k.z];
    let cx = c[sh.k.x] - sh.s.x * c[sh.k.z];
    let cy = c[sh.k.y] - sh.s.y * c[sh.k.z];
    let u = edge(cx, by, cy, bx);
    let v = edge(ax, cy, ay, cx);
    let w = edge(bx, ay, by, ax);
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return vec4<f32>(0.0);
    }
    let det = u + v + w;
    if det == 0.0 {
        return vec4<f32>(0.0);
    }
    let inv = 1.0 / det;
    let t = (u * a[sh.k.z] + v * b[sh.k.z] + w * c[sh.k.z]) * sh.s.z * inv;
    // tmax is inclusive so that the caller can break exact ties (see bvh_trace). The test is
    // on t itself, the value the caller compares: testing t·det against tmax·det instead would
    // reject a duplicate whose t rounds to exactly the current hit's.
    if !(t > ray.tmin && t <= ray.tmax) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(t, v * inv, w * inv, 1.0);
}

// A node's child boxes as seen by one ray: slab distances are `q * scale + near` for the
// near planes and `q * scale + far` for the far ones, q a child's quantized plane (0..=255);
// `near` and `far` hold the rounding pad, so each box is tested conservatively.
struct NodeSlabs {
    scale: vec3<f32>,
    near: vec3<f32>,
    far: vec3<f32>,
    tmin: f32,
    tmax: f32,
}

// Whether the child in byte `shift / 8` of the near and far plane words is hit. Called with a
// constant shift, so the byte unpacking folds to one or two instructions a plane.
fn child_hit(near_q: vec3<u32>, far_q: vec3<u32>, shift: u32, s: NodeSlabs) -> bool {
    let lo = vec3<f32>(vec3<i32>((near_q >> vec3<u32>(shift)) & vec3<u32>(0xffu)));
    let hi = vec3<f32>(vec3<i32>((far_q >> vec3<u32>(shift)) & vec3<u32>(0xffu)));
    let near = lo * s.scale + s.near;
    let far = hi * s.scale + s.far;
    return max(max(near.x, near.y), max(near.z, s.tmin)) <= min(min(far.x, far.y), min(far.z, s.tmax));
}

// The hit bits of the child in byte `shift / 8` of a meta word, decoded four at a time.
fn child_bits(counts: u32, bit_index: u32, shift: u32) -> u32 {
    return ((counts >> shift) & 0xffu) << ((bit_index >> shift) & 0xffu);
}

// The hit mask of the four children of one meta word (children 4j..4j+3 for j = `half`):
// obvhs's child meta bytes decoded four at a time (after Ylitie et al.'s listing): an
// internal child sets bit 24 + its slot ^ oct_inv, a leaf its primitive bits. The near and
// far planes are picked per axis from the direction's sign once for the four.
fn quad_hits(n: array<vec4<u32>, 5>, half: u32, negative: vec3<bool>, oct_inv: u32, s: NodeSlabs) -> u32 {
    let child_meta = n[1][2u + half];
    let inner = child_meta & (child_meta << 1u) & 0x10101010u;
    let bit_index = (child_meta ^ ((inner >> 4u) * oct_inv)) & 0x1f1f1f1fu;
    let counts = (child_meta >> 5u) & 0x07070707u;
    let lo = vec3<u32>(n[2][half], n[3][half], n[4][half]);
    let hi = vec3<u32>(n[2][2u + half], n[3][2u + half], n[4][2u + half]);
    let near_q = select(lo, hi, negative);
    let far_q = select(hi, lo, negative);
    return select(0u, child_bits(counts, bit_index, 0u), child_hit(near_q, far_q, 0u, s))
        | select(0u, child_bits(counts, bit_index, 8u), child_hit(near_q, far_q, 8u, s))
        | select(0u, child_bits(counts, bit_index, 16u), child_hit(near_q, far_q, 16u, s))
        | select(0u, child_bits(counts, bit_index, 24u), child_hit(near_q, far_q, 24u, s));
}

// Tests a node's eight children; returns obvhs's hit mask: internal children in the top byte
// (ordered by octant), leaf primitives in the low 24 bits.
fn node_hits(index: u32, ray: Ray, inv_dir: vec3<f32>, oct_inv: u32, tmax: f32) -> u32 {
    let n = array<vec4<u32>, 5>(
        node_word(index, 0u),
        node_word(index, 1u),
        node_word(index, 2u),
        node_word(index, 3u),
        node_word(index, 4u),
    );
    let p = bitcast<vec3<f32>>(n[0].xyz);
    let e = bitcast<vec3<f32>>(((vec3<u32>(n[0].w) >> vec3<u32>(0u, 8u, 16u)) & vec3<u32>(0xffu))
        << vec3<u32>(23u));
    let rel = p - ray.origin;
    let offset = rel * inv_dir;
    // A bound on the absolute rounding error of every slab distance of this node.
    let pad = BOX_PAD * (abs(rel) + 256.0 * e) * abs(inv_dir);
    let s = NodeSlabs(e * inv_dir, offset - pad, offset + pad, ray.tmin, tmax);
    let negative = inv_dir < vec3<f32>(0.0);
    return quad_hits(n, 0u, negative, oct_inv, s) | quad_hits(n, 1u, negative, oct_inv, s);
}

// 1/d with zero components replaced by a tiny value of the same sign, so slab distances stay
// finite (a ray parallel to a slab is inside it iff its origin is).
fn safe_inverse(d: vec3<f32>) -> vec3<f32> {
    let tiny = vec3<f32>(1e-30);
    return 1.0 / select(d, select(tiny, -tiny, d < vec3<f32>(0.0)), abs(d) < tiny);
}

// obvhs's octant code of a direction: 7 minus its octant, the traversal order's key.
fn octant_inverse(dir: vec3<f32>) -> u32 {
    return select(4u, 0u, dir.x < 0.0) | select(2u, 0u, dir.y < 0.0) | select(1u, 0u, dir.z < 0.0);
}

// A walk down one BVH: the node group being expanded (child base; hit mask in the top byte,
// imask in the low byte), the leaf group to test (first slot, primitive mask), and the node
// groups left for later.
struct Walk {
    nodes: vec2<u32>,
    leaves: vec2<u32>,
    depth: u32,
    stack: array<vec2<u32>, TRAVERSAL_STACK>,
}

fn walk_from(root: u32) -> Walk {
    var w: Walk;
    w.nodes = vec2<u32>(root, 0x80000000u);
    w.leaves = vec2<u32>(0u);
    w.depth = 0u;
    return w;
}

// Walks on, nearest child first, until `leaves` holds primitives (true) or no node is left
// (false). Children farther than `tmax` are culled.
fn walk_next(w: ptr<function, Walk>, ray: Ray, inv_dir: vec3<f32>, oct_inv: u32, tmax: f32) -> bool {
    var found = false;
    loop {
        if ((*w).nodes.y & 0xff000000u) == 0u {
            if (*w).depth == 0u {
                break;
            }
            (*w).depth -= 1u;
            (*w).nodes = (*w).stack[(*w).depth];
            continue;
        }
        let hits_imask = (*w).nodes.y;
        let bit = firstLeadingBit(hits_imask);
        (*w).nodes.y = hits_imask & ~(1u << bit);
        if ((*w).nodes.y & 0xff000000u) != 0u {
            (*w).stack[(*w).depth] = (*w).nodes;
            (*w).depth += 1u;
        }
        let slot = (bit - 24u) ^ oct_inv;
        let index = (*w).nodes.x + countOneBits(hits_imask & ~(0xffffffffu << slot));
        if COUNT_WORK {
            work_nodes += 1u;
        }
        let mask = node_hits(index, ray, inv_dir, oct_inv, tmax);
        let header = node_word(index, 1u);
        (*w).nodes = vec2<u32>(header.x, (mask & 0xff000000u) | (node_word(index, 0u).w >> 24u));
        (*w).leaves = vec2<u32>(header.y, mask & 0x00ffffffu);
        if (*w).leaves.y != 0u {
            found = true;
            break;
        }
    }
    return found;
}

// The closest hit (any_hit = false), or any hit (true), in the triangle BVH from node `root`,
// if better than `best`; hits are tagged with `instance` (the ray is in its mesh's space).
fn mesh_trace(root: u32, ray: Ray, any_hit: bool, best: Hit, instance: u32) -> Hit {
    var hit = best;
    let inv_dir = safe_inverse(ray.dir);
    let sh = ray_shear(ray.dir);
    let oct_inv = octant_inverse(ray.dir);
    var w = walk_from(root);
    while walk_next(&w, ray, inv_dir, oct_inv, hit.t) {
        while w.leaves.y != 0u {
            let bit = firstTrailingBit(w.leaves.y);
            w.leaves.y &= w.leaves.y - 1u;
            let slot = w.leaves.x + bit;
            if COUNT_WORK {
                work_triangles += 1u;
            }
            let h = triangle_hit(slot, Ray(ray.origin, ray.dir, ray.tmin, hit.t), sh);
            // Exact ties (duplicated or coplanar overlapping triangles) go to the lower scene
            // triangle, so the result does not depend on the BVH; the reference does the same.
            if h.w != 0.0 && (h.x < hit.t || (hit.slot != NO_HIT && h.x == hit.t
                && scene_triangle(slot, instance) < scene_triangle(hit.slot, hit.instance))) {
                hit = Hit(h.x, h.y, h.z, slot, instance);
                if any_hit {
                    return hit;
                }
            }
        }
    }
    return hit;
}

// The closest hit (any_hit = false), or any hit (true, for shadow rays), in (tmin, tmax].
// An instanced scene walks the top level over instances and, at each instance it reaches,
// its mesh's BVH with the ray mapped into the mesh's space: the direction is mapped without
// normalizing, so distances along it are the world's.
fn bvh_trace(ray: Ray, any_hit: bool) -> Hit {
    let none = Hit(ray.tmax, 0.0, 0.0, NO_HIT, 0u);
    if !INSTANCED {
        return mesh_trace(0u, ray, any_hit, none, 0u);
    }
    var hit = none;
    let inv_dir = safe_inverse(ray.dir);
    let oct_inv = octant_inverse(ray.dir);
    var w = walk_from(0u);
    while walk_next(&w, ray, inv_dir, oct_inv, hit.t) {
        while w.leaves.y != 0u {
            let bit = firstTrailingBit(w.leaves.y);
            w.leaves.y &= w.leaves.y - 1u;
            let k = w.leaves.x + bit;
            let instance = instance_at(k);
            if instance.motion.z == 0u {
                continue;
            }
            let to_mesh = instance.to_mesh;
            let local = Ray(affine(to_mesh, ray.origin), linear(to_mesh, ray.dir), ray.tmin, hit.t);
            hit = mesh_trace(instance.root, local, any_hit, hit, k);
            // Each instance is visited once a trace: the best hit is in k only if k gave it.
            if MOVING && hit.instance == k {
                hit_placed = instance;
            }
            if any_hit && hit.slot != NO_HIT {
                return hit;
            }
        }
    }
    return hit;
}
