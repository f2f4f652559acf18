// Whitted shading of BVH hits: materials, textures, lights with shadow rays, mirror
// reflection and refraction with Fresnel, iterated with an explicit stack of pending rays.
// Features a scene does not use are switched off by overrides, so their code is dead.
#import bvh

// Mirrors `fisheye_rt::trace::GpuMaterial` (80 bytes).
struct Material {
    diffuse: vec3<f32>,
    surface: u32,
    specular: vec3<f32>,
    shininess: f32,
    emission: vec3<f32>,
    ior: f32,
    transmission: vec3<f32>,
    // Index into texture_info, NO_TEXTURE if none.
    texture: u32,
    // The fraction of light a diffuse surface stops (MTL `d`); the rest passes straight on.
    opacity: f32,
    pad: array<u32, 3>,
}

// Mirrors `fisheye_rt::trace::GpuLight` (32 bytes): a point light (position) or a directional
// one (the direction light travels); colour is intensity or irradiance.
struct Light {
    vector: vec3<f32>,
    kind: u32,
    colour: vec3<f32>,
    pad: u32,
}

// Mirrors `fisheye_rt::trace::Shading` (32 bytes).
struct Shading {
    // Radiance of escaping rays.
    sky: vec3<f32>,
    light_count: u32,
    // Whitted's ambient term.
    ambient: vec3<f32>,
    // Secondary rays nest at most this deep (≤ MAX_DEPTH_LIMIT).
    max_depth: u32,
}

@group(1) @binding(2) var<storage, read> materials: array<Material>;
@group(1) @binding(3) var<storage, read> lights: array<Light>;
// Per scene triangle: three vertex normals (xyz) when SMOOTH_NORMALS, then three UV pairs
// packed in two vec4 when TEXTURES; see `fisheye_rt::trace::shading_vertices`.
@group(1) @binding(4) var<storage, read> vertex_data: array<vec4<f32>>;
// Per texture: first texel, width, height, unused.
@group(1) @binding(5) var<storage, read> texture_info: array<vec4<u32>>;
// RGBA8 sRGB texels of every texture.
@group(1) @binding(6) var<storage, read> texels: array<u32>;
@group(1) @binding(7) var<uniform> shading: Shading;

override HAS_MIRRORS: bool;
override HAS_GLASS: bool;
override HAS_TEXTURES: bool;
override SMOOTH_NORMALS: bool;
override HAS_TRANSLUCENT: bool;

// Rays whose weight falls below this are not traced (the CPU reference prunes alike).
const MIN_WEIGHT: f32 = 1e-3;

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

fn texel(info: vec4<u32>, x: i32, y: i32) -> vec3<f32> {
    // Repeat wrapping.
    let w = i32(info.y);
    let h = i32(info.z);
    let xi = u32(((x % w) + w) % w);
    let yi = u32(((y % h) + h) % h);
    return srgb_to_linear(unpack4x8unorm(texels[info.x + yi * info.y + xi]).rgb);
}

// Bilinear filtering in linear space, repeat wrapping, v = 0 at the bottom (OBJ convention).
fn sample_texture(index: u32, uv: vec2<f32>) -> vec3<f32> {
    let info = texture_info[index];
    let size = vec2<f32>(f32(info.y), f32(info.z));
    let st = vec2<f32>(uv.x, 1.0 - uv.y) * size - 0.5;
    let base = floor(st);
    let f = st - base;
    let x = i32(base.x);
    let y = i32(base.y);
    let top = mix(texel(info, x, y), texel(info, x + 1, y), f.x);
    let bottom = mix(texel(info, x, y + 1), texel(info, x + 1, y + 1), f.x);
    return mix(top, bottom, f.y);
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

// Everything shading needs about a hit.
struct Surface {
    position: vec3<f32>,
    // Geometric normal, facing the incoming ray.
    geometric: vec3<f32>,
    // Shading normal, on the same side as `geometric`.
    normal: vec3<f32>,
    // Whether the ray hit the triangle's front (counter-clockwise) side.
    front: bool,
    material: Material,
    triangle: u32,
}

fn surface_at(ray: Ray, hit: Hit) -> Surface {
    let tri = bvh_triangles[hit.slot];
    let triangle = tri.triangle;
    var material = materials[tri.material];
    let w = 1.0 - hit.u - hit.v;
    // From the barycentrics rather than o + t·d: on the triangle to within its rounding.
    let position = w * tri.v0 + hit.u * tri.v1 + hit.v * tri.v2;
    var geometric = normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
    let front = dot(geometric, ray.dir) < 0.0;
    if !front {
        geometric = -geometric;
    }
    var normal = geometric;
    var stride = 0u;
    if SMOOTH_NORMALS {
        stride = 3u;
    }
    if HAS_TEXTURES {
        stride += 2u;
    }
    let base = triangle * stride;
    if SMOOTH_NORMALS {
        let n = normalize(w * vertex_data[base].xyz + hit.u * vertex_data[base + 1u].xyz
            + hit.v * vertex_data[base + 2u].xyz);
        // Keep the interpolated normal on the side the ray came from.
        normal = select(-n, n, dot(n, geometric) >= 0.0);
    }
    if HAS_TEXTURES && material.texture != NO_TEXTURE {
        var uv_base = base;
        if SMOOTH_NORMALS {
            uv_base += 3u;
        }
        let a = vertex_data[uv_base];
        let b = vertex_data[uv_base + 1u];
        let uv = w * a.xy + hit.u * a.zw + hit.v * b.xy;
        material.diffuse *= sample_texture(material.texture, uv);
    }
    return Surface(position, geometric, normal, front, material, triangle);
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
        let tri = bvh_triangles[hit.slot];
        let m = materials[tri.material];
        transmittance *= 1.0 - m.opacity;
        if m.surface != SURFACE_DIFFUSE || transmittance < MIN_WEIGHT || layer == MAX_SHADOW_LAYERS {
            return 0.0;
        }
        let p = (1.0 - hit.u - hit.v) * tri.v0 + hit.u * tri.v1 + hit.v * tri.v2;
        let n = normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
        o = offset_origin(p, select(-n, n, dot(n, to_light) > 0.0));
        remaining -= hit.t;
    }
    return 0.0;
}

// Direct light at a diffuse surface: ambient, then each light through a shadow ray.
fn direct_light(s: Surface, view: vec3<f32>) -> vec3<f32> {
    var colour = s.material.diffuse * shading.ambient;
    let origin = offset_origin(s.position, s.geometric);
    for (var i = 0u; i < shading.light_count; i++) {
        let light = lights[i];
        var to_light: vec3<f32>;
        var distance: f32;
        var irradiance: vec3<f32>;
        if light.kind == LIGHT_POINT {
            let d = light.vector - origin;
            distance = length(d);
            to_light = d / distance;
            irradiance = light.colour / (distance * distance);
        } else {
            to_light = -light.vector;
            distance = 3.0e38;
            irradiance = light.colour;
        }
        let cos_light = dot(s.normal, to_light);
        if cos_light <= 0.0 || dot(s.geometric, to_light) <= 0.0 {
            continue;
        }
        let transmittance = shadow_transmittance(origin, to_light, distance);
        if transmittance == 0.0 {
            continue;
        }
        irradiance *= transmittance;
        let half_vector = normalize(to_light - view);
        let highlight = s.material.specular
            * pow(max(dot(s.normal, half_vector), 0.0), s.material.shininess);
        colour += irradiance * (s.material.diffuse * cos_light + highlight);
    }
    return colour;
}

// Unpolarised Fresnel reflectance of a dielectric interface.
fn fresnel(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

struct Pending {
    origin: vec3<f32>,
    depth: u32,
    dir: vec3<f32>,
    weight: vec3<f32>,
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

// Whitted's recursion as a loop over a stack of pending rays (depth-first; a binary tree of
// depth MAX_DEPTH_LIMIT needs one more entry than its depth).
fn shade(primary: Ray) -> Traced {
    var out = Traced(vec3<f32>(0.0), Hit(0.0, 0.0, 0.0, NO_HIT), vec3<f32>(0.0), NO_HIT);
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
        let s = surface_at(ray, hit);
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
                let dir = reflect(ray.dir, s.normal);
                stack[count] = Pending(offset_origin(s.position, s.geometric), ray_in.depth + 1u, dir, weight);
                count += 1u;
            }
        } else if HAS_GLASS && s.material.surface == SURFACE_GLASS {
            // Entering through the front face, or leaving through the back.
            var eta = 1.0 / s.material.ior;
            if !s.front {
                eta = s.material.ior;
            }
            let cos_i = -dot(ray.dir, s.normal);
            let sin2_t = eta * eta * max(1.0 - cos_i * cos_i, 0.0);
            var reflectance = 1.0;
            if sin2_t < 1.0 {
                let cos_t = sqrt(1.0 - sin2_t);
                reflectance = fresnel(cos_i, cos_t, 1.0 / eta);
                let weight = ray_in.weight * (1.0 - reflectance) * s.material.transmission;
                if children && max(weight.x, max(weight.y, weight.z)) >= MIN_WEIGHT {
                    let dir = normalize(eta * ray.dir + (eta * cos_i - cos_t) * s.normal);
                    stack[count] = Pending(offset_origin(s.position, -s.geometric), ray_in.depth + 1u, dir, weight);
                    count += 1u;
                }
            }
            let weight = ray_in.weight * reflectance;
            if children && max(weight.x, max(weight.y, weight.z)) >= MIN_WEIGHT {
                let dir = reflect(ray.dir, s.normal);
                stack[count] = Pending(offset_origin(s.position, s.geometric), ray_in.depth + 1u, dir, weight);
                count += 1u;
            }
        } else {
            out.colour += surface_weight * direct_light(s, ray.dir);
        }
    }
    return out;
}
