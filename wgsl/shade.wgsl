// Whitted shading of BVH hits: lights through shadow rays, mirror reflection and refraction
// with Fresnel, iterated with an explicit stack of pending rays. Features a scene does not use
// are switched off by overrides, so their code is dead.
#import bvh
#import surface

override HAS_TRANSLUCENT: bool;

// MIN_WEIGHT and GRAZING_COSINE come from `fisheye_rt::shared` (the reference uses them too).

// `dir` kept on the `side` of the geometric surface `geometric` faces (1: the side the ray
// came from, for reflections; -1: the other, for refractions), at least GRAZING_COSINE off
// it: bent to graze the surface where it would cross it (see `shared::GRAZING_COSINE`).
fn keep_side(dir: vec3<f32>, geometric: vec3<f32>, side: f32) -> vec3<f32> {
    let c = side * dot(dir, geometric);
    if c >= GRAZING_COSINE {
        return dir;
    }
    return normalize(dir + side * (GRAZING_COSINE - c) * geometric);
}

// Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing
// Gems, ch. 6): move p off its surface along the normal n by a few ulp of p's magnitude, or by
// a fixed tiny distance near the origin, so a secondary ray never re-hits its own surface at
// any scene scale.
fn offset_origin(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let of_i = vec3<i32>(256.0 * n);
    let p_i = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(of_i, -of_i, p < vec3<f32>(0.0)));
    return select(p_i, p + (1.0 / 65536.0) * n, abs(p) < vec3<f32>(1.0 / 32.0));
}

struct Pending {
    origin: vec3<f32>,
    depth: u32,
    dir: vec3<f32>,
    weight: vec3<f32>,
}

// How the direction of the primary ray being traced changes a pixel right (column 0) and a
// pixel down (column 1) on the image, or a sample's spacing where a pixel has several (world
// space, not normalized): the ray generators set it (`set_spread`, `pixel.wgsl`) and `shade` filters the
// textures its primary hit shows at that footprint (Igehy, "Tracing Ray Differentials",
// SIGGRAPH 1999). Zero: the finest level, as for secondary rays.
var<private> primary_spread: mat2x3<f32>;

// Where `hit` of `ray` moves on its triangle's plane as the ray's direction moves by
// `primary_spread`'s columns (Igehy's transfer of a ray differential to a surface).
fn hit_footprint(ray: Ray, hit: Hit) -> mat2x3<f32> {
    let n = hit_face_normal(hit);
    let facing = dot(ray.dir, n);
    let x = primary_spread[0];
    let y = primary_spread[1];
    return hit.t * mat2x3<f32>(x - (dot(x, n) / facing) * ray.dir, y - (dot(y, n) / facing) * ray.dir);
}

// What a primary ray sees, and its first hit.
struct Traced {
    colour: vec3<f32>,
    // The primary ray's closest hit.
    hit: Hit,
    // World-space shading normal at the primary hit (zero on a miss).
    normal: vec3<f32>,
    // Scene triangle of the primary hit, NO_HIT on a miss.
    triangle: u32,
}

// What a ray that hits nothing sees: no colour, no hit.
fn missed() -> Traced {
    return Traced(vec3<f32>(0.0), Hit(0.0, 0.0, 0.0, NO_HIT, 0u), vec3<f32>(0.0), NO_HIT);
}

// A primary ray's closest hit and its surface, unshaded (colour zero): the ground truth at a
// pixel's centre when its colour comes from several samples.
fn first_hit(primary: Ray) -> Traced {
    var out = missed();
    let hit = bvh_trace(primary, false);
    if hit.slot != NO_HIT {
        let s = surface_at(primary, hit, 0.0);
        out.hit = hit;
        out.normal = s.normal;
        out.triangle = s.triangle;
    }
    return out;
}

// The diffuse surface whose lights `shade` is gathering, a shadow ray at a time: what
// `reflected` needs of it, the weight its light takes in the pixel, the light gathered so far
// (ambient first), the next light to look at and, while a shadow ray is under way toward it,
// that ray's state. Through partially transparent diffuse surfaces a shadow ray goes on past
// each (nearest first, up to MAX_SHADOW_LAYERS of them), its transmittance the product of
// their (1 - opacity); through opaque scenes it stops at any hit.
struct Lighting {
    surface: Surface,
    view: vec3<f32>,
    weight: vec3<f32>,
    gathered: vec3<f32>,
    origin: vec3<f32>,
    next: u32,
    incident: Incident,
    shadow_origin: vec3<f32>,
    remaining: f32,
    transmittance: f32,
    layer: u32,
    shadowing: bool,
}

// Moves `l` on to its next shadow ray: the lights the surface faces, but for those nothing
// stands between its triangle and (`Surface::unshadowed`), whose light it gathers at once.
// False once every light is looked at.
fn next_shadow_ray(l: ptr<function, Lighting>) -> bool {
    for (; (*l).next < shading.light_count; (*l).next++) {
        let i = (*l).next;
        let light = incident((*l).surface, (*l).origin, light_at(i));
        if !light.lit {
            continue;
        }
        if i < UNSHADOWED_LIGHTS && ((*l).surface.unshadowed & (1u << i)) != 0u {
            (*l).gathered += reflected((*l).surface, (*l).view, light, 1.0);
            continue;
        }
        (*l).incident = light;
        (*l).shadow_origin = (*l).origin;
        (*l).remaining = light.distance;
        (*l).transmittance = 1.0;
        (*l).layer = 0u;
        return true;
    }
    return false;
}

// Takes the hit of `l`'s shadow ray: true while the ray goes on (past a partially
// transparent diffuse surface); else its light, dimmed by what it passed, is gathered.
fn shadow_goes_on(l: ptr<function, Lighting>, hit: Hit) -> bool {
    if hit.slot != NO_HIT {
        if !HAS_TRANSLUCENT {
            (*l).transmittance = 0.0;
        } else {
            let m = material_at(triangle_at(hit.slot).material);
            (*l).transmittance *= 1.0 - m.opacity;
            if m.surface != SURFACE_DIFFUSE || (*l).transmittance < MIN_WEIGHT
                || (*l).layer == MAX_SHADOW_LAYERS {
                (*l).transmittance = 0.0;
            } else {
                let n = hit_face_normal(hit);
                let to_light = (*l).incident.to_light;
                (*l).shadow_origin = offset_origin(hit_position(hit), select(-n, n, dot(n, to_light) > 0.0));
                (*l).remaining -= hit.t;
                (*l).layer += 1u;
                return true;
            }
        }
    }
    if (*l).transmittance > 0.0 {
        (*l).gathered += reflected((*l).surface, (*l).view, (*l).incident, (*l).transmittance);
    }
    (*l).next += 1u;
    return false;
}

// Whitted's recursion as a loop over a stack of pending rays (depth-first; a binary tree of
// depth MAX_DEPTH_LIMIT needs one more entry than its depth), each diffuse surface's shadow
// rays traced before the next pending ray. Every ray, shadow rays too, is traced at the one
// `bvh_trace` call: a GPU compiles each call site's traversal anew (lavapipe takes seconds
// for each), and lanes tracing different kinds of ray still share its iterations.
fn shade(primary: Ray) -> Traced {
    var out = missed();
    var stack: array<Pending, MAX_DEPTH_LIMIT + 1u>;
    stack[0] = Pending(primary.origin, 0u, primary.dir, vec3<f32>(1.0));
    var count = 1u;
    var l: Lighting;
    var lighting = false;
    loop {
        if lighting && !l.shadowing {
            l.shadowing = next_shadow_ray(&l);
            if !l.shadowing {
                out.colour += l.weight * l.gathered;
                lighting = false;
            }
        }
        var ray: Ray;
        var ray_in: Pending;
        if l.shadowing {
            ray = Ray(l.shadow_origin, l.incident.to_light, 0.0, l.remaining);
        } else if count > 0u {
            count -= 1u;
            ray_in = stack[count];
            ray = Ray(ray_in.origin, ray_in.dir, 0.0, 3.0e38);
        } else {
            break;
        }
        let hit = bvh_trace(ray, l.shadowing && !HAS_TRANSLUCENT);
        if l.shadowing {
            l.shadowing = shadow_goes_on(&l, hit);
            continue;
        }
        if hit.slot == NO_HIT {
            out.colour += ray_in.weight * shading.sky;
            continue;
        }
        var lod = 0.0;
        if HAS_TEXTURES && ray_in.depth == 0u {
            lod = texture_lod(hit, hit_footprint(ray, hit));
        }
        let s = surface_at(ray, hit, lod);
        if ray_in.depth == 0u {
            out.hit = hit;
            out.normal = s.normal;
            out.triangle = s.triangle;
        }
        let children = ray_in.depth < shading.max_depth;
        var surface_weight = ray_in.weight;
        if HAS_TRANSLUCENT && s.material.surface == SURFACE_DIFFUSE && s.material.opacity < 1.0 {
            // The rest of the light passes straight through.
            let through = surface_weight * (1.0 - s.material.opacity);
            if children && max(through.x, max(through.y, through.z)) >= MIN_WEIGHT {
                stack[count] = Pending(offset_origin(s.position, -s.geometric), ray_in.depth + 1u, ray.dir, through);
                count += 1u;
            }
            surface_weight *= s.material.opacity;
        }
        out.colour += surface_weight * s.material.emission;
        if HAS_MIRRORS && s.material.surface == SURFACE_MIRROR {
            let weight = ray_in.weight * s.material.specular;
            if children && max(weight.x, max(weight.y, weight.z)) >= MIN_WEIGHT {
                let dir = keep_side(reflect(ray.dir, s.normal), s.geometric, 1.0);
                stack[count] = Pending(offset_origin(s.position, s.geometric), ray_in.depth + 1u, dir, weight);
                count += 1u;
            }
        } else if HAS_GLASS && s.material.surface == SURFACE_GLASS {
            let glass = glass_interface(s, ray.dir);
            let reflectance = glass.reflectance;
            if reflectance < 1.0 {
                let weight = ray_in.weight * (1.0 - reflectance) * s.material.transmission;
                if children && max(weight.x, max(weight.y, weight.z)) >= MIN_WEIGHT {
                    let dir = keep_side(glass.refracted, s.geometric, -1.0);
                    stack[count] = Pending(offset_origin(s.position, -s.geometric), ray_in.depth + 1u, dir, weight);
                    count += 1u;
                }
            }
            let weight = ray_in.weight * reflectance;
            if children && max(weight.x, max(weight.y, weight.z)) >= MIN_WEIGHT {
                let dir = keep_side(reflect(ray.dir, s.normal), s.geometric, 1.0);
                stack[count] = Pending(offset_origin(s.position, s.geometric), ray_in.depth + 1u, dir, weight);
                count += 1u;
            }
        } else {
            // Direct light: ambient, then each light through a shadow ray (the iterations
            // that follow).
            l.surface = s;
            l.view = ray.dir;
            l.weight = surface_weight;
            l.gathered = s.material.diffuse * shading.ambient;
            l.origin = offset_origin(s.position, s.geometric);
            l.next = 0u;
            lighting = true;
        }
    }
    return out;
}
