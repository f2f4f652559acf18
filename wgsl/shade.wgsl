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

// The fraction of a light's irradiance that reaches `origin`: 0 or 1 through opaque scenes;
// through partially transparent diffuse surfaces the product of their (1 - opacity), nearest
// first, up to MAX_SHADOW_LAYERS of them.
fn shadow_transmittance(origin: vec3<f32>, to_light: vec3<f32>, distance: f32) -> f32 {
    if !HAS_TRANSLUCENT {
        return select(1.0, 0.0, bvh_trace(Ray(origin, to_light, 0.0, distance), true).slot != NO_HIT);
    }
    var o = origin;
    var remaining = distance;
    var transmittance = 1.0;
    for (var layer = 0u; layer <= MAX_SHADOW_LAYERS; layer++) {
        let hit = bvh_trace(Ray(o, to_light, 0.0, remaining), false);
        if hit.slot == NO_HIT {
            return transmittance;
        }
        let tri = triangle_at(hit.slot);
        let m = material_at(tri.material);
        transmittance *= 1.0 - m.opacity;
        if m.surface != SURFACE_DIFFUSE || transmittance < MIN_WEIGHT || layer == MAX_SHADOW_LAYERS {
            return 0.0;
        }
        let n = hit_face_normal(hit);
        o = offset_origin(hit_position(hit), select(-n, n, dot(n, to_light) > 0.0));
        remaining -= hit.t;
    }
    return 0.0;
}

// Direct light at a diffuse surface: ambient, then each light through a shadow ray, but for
// the lights nothing stands between the surface's triangle and (`Surface::unshadowed`).
fn direct_light(s: Surface, view: vec3<f32>) -> vec3<f32> {
    var colour = s.material.diffuse * shading.ambient;
    let origin = offset_origin(s.position, s.geometric);
    for (var i = 0u; i < shading.light_count; i++) {
        let light = incident(s, origin, light_at(i));
        if !light.lit {
            continue;
        }
        var transmittance = 1.0;
        if i >= UNSHADOWED_LIGHTS || (s.unshadowed & (1u << i)) == 0u {
            transmittance = shadow_transmittance(origin, light.to_light, light.distance);
        }
        if transmittance > 0.0 {
            colour += reflected(s, view, light, transmittance);
        }
    }
    return colour;
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

// A primary ray's closest hit and its surface, unshaded (colour zero): the ground truth at a
// pixel's centre when its colour comes from several samples.
fn first_hit(primary: Ray) -> Traced {
    var out = Traced(vec3<f32>(0.0), Hit(0.0, 0.0, 0.0, NO_HIT, 0u), vec3<f32>(0.0), NO_HIT);
    let hit = bvh_trace(primary, false);
    if hit.slot != NO_HIT {
        let s = surface_at(primary, hit, 0.0);
        out.hit = hit;
        out.normal = s.normal;
        out.triangle = s.triangle;
    }
    return out;
}

// Whitted's recursion as a loop over a stack of pending rays (depth-first; a binary tree of
// depth MAX_DEPTH_LIMIT needs one more entry than its depth).
fn shade(primary: Ray) -> Traced {
    var out = Traced(vec3<f32>(0.0), Hit(0.0, 0.0, 0.0, NO_HIT, 0u), vec3<f32>(0.0), NO_HIT);
    var stack: array<Pending, MAX_DEPTH_LIMIT + 1u>;
    stack[0] = Pending(primary.origin, 0u, primary.dir, vec3<f32>(1.0));
    var count = 1u;
    while count > 0u {
        count -= 1u;
        let ray_in = stack[count];
        let ray = Ray(ray_in.origin, ray_in.dir, 0.0, 3.0e38);
        let hit = bvh_trace(ray, false);
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
            out.colour += surface_weight * direct_light(s, ray.dir);
        }
    }
    return out;
}
