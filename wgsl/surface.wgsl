// Surfaces and their lighting, shared by the tracer (`shade.wgsl`) and the rasterizer
// (`raster.wgsl`): materials, textures, lights, the surface at a hit, Blinn-Phong reflection of
// one light and the Fresnel split at glass. How light reaches a point (shadow rays or shadow
// maps) and what mirrors and glass see are the callers'.
#import triangles

// Mirrors `fisheye_rt::trace::GpuMaterial` (80 bytes).
struct Material {
    diffuse: vec3<f32>,
    surface: u32,
    specular: vec3<f32>,
    shininess: f32,
    emission: vec3<f32>,
    ior: f32,
    transmission: vec3<f32>,
    // The diffuse texture's first texel in `texels`, NO_TEXTURE if none.
    texture: u32,
    // The fraction of light a diffuse surface stops (MTL `d`); the rest passes straight on.
    opacity: f32,
    texture_width: u32,
    texture_height: u32,
    // Its mip levels (`fisheye_rt::trace::mip_levels`), level 0 included, one after
    // another from `texture`.
    texture_levels: u32,
}

// Mirrors `fisheye_rt::trace::GpuLight` (32 bytes): a point light (position) or a directional
// one (the direction light travels); colour is intensity or irradiance.
struct Light {
    vector: vec3<f32>,
    kind: u32,
    colour: vec3<f32>,
    // The light's first layer in the rasterizer's shadow maps (six for a point light).
    shadow_layer: u32,
}

// Mirrors `fisheye_rt::trace::Shading` (48 bytes).
struct Shading {
    // Radiance of escaping rays.
    sky: vec3<f32>,
    light_count: u32,
    // Whitted's ambient term.
    ambient: vec3<f32>,
    // Secondary rays nest at most this deep (≤ MAX_DEPTH_LIMIT).
    max_depth: u32,
    // Where the lights and the materials begin in `records` (vec4s).
    lights_at: u32,
    materials_at: u32,
    pad: vec2<u32>,
}

// Per scene triangle: three vertex normals (xyz) when SMOOTH_NORMALS, then three UV pairs
// packed in two vec4 when TEXTURES; see `fisheye_rt::trace::shading_vertices`. `vertex_at`
// reads them from `vertex_data` (group 1, binding 3) and its further chunks, if any.
@group(1) @binding(4) var<uniform> shading: Shading;

// The scene's lights, materials and texels are in `records` (`triangles.wgsl`), where
// `shading` says: light `i` in LIGHT_VEC4S vec4s, laid out as `Light`.
fn light_at(i: u32) -> Light {
    let k = shading.lights_at + LIGHT_VEC4S * i;
    let a = records[k];
    let b = records[k + 1u];
    return Light(bitcast<vec3<f32>>(a.xyz), a.w, bitcast<vec3<f32>>(b.xyz), b.w);
}

// Material `i`, in MATERIAL_VEC4S vec4s laid out as `Material`.
fn material_at(i: u32) -> Material {
    let k = shading.materials_at + MATERIAL_VEC4S * i;
    let v = array<vec4<u32>, 5>(records[k], records[k + 1u], records[k + 2u], records[k + 3u],
        records[k + 4u]);
    return Material(bitcast<vec3<f32>>(v[0].xyz), v[0].w, bitcast<vec3<f32>>(v[1].xyz),
        bitcast<f32>(v[1].w), bitcast<vec3<f32>>(v[2].xyz), bitcast<f32>(v[2].w),
        bitcast<vec3<f32>>(v[3].xyz), v[3].w, bitcast<f32>(v[4].x), v[4].y, v[4].z, v[4].w);
}

override HAS_MIRRORS: bool;
override HAS_GLASS: bool;
override HAS_TEXTURES: bool;
override SMOOTH_NORMALS: bool;

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

// Texel (x, y), an RGBA8 sRGB word in `records`, of the texture whose first texel (as a word
// of `records`), width and height are `info`'s x, y, z.
fn texel(info: vec3<u32>, x: i32, y: i32) -> vec3<f32> {
    // Repeat wrapping.
    let w = i32(info.y);
    let h = i32(info.z);
    let xi = u32(((x % w) + w) % w);
    let yi = u32(((y % h) + h) % h);
    let word = info.x + yi * info.y + xi;
    return srgb_to_linear(unpack4x8unorm(records[word >> 2u][word & 3u]).rgb);
}

// Bilinear filtering in linear space, repeat wrapping, v = 0 at the bottom (OBJ convention),
// of the texture level whose first texel, width and height are `info`'s x, y, z.
fn bilinear(info: vec3<u32>, uv: vec2<f32>) -> vec3<f32> {
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

// The vec4s of `vertex_data` a stored triangle has (vertex normals, UVs).
fn shading_stride() -> u32 {
    return select(0u, 3u, SMOOTH_NORMALS) + select(0u, 2u, HAS_TEXTURES);
}

// Stored triangle `triangle`'s corners' UVs (with textures): corner 0's in the first vec4's
// xy, 1's in its zw, 2's in the second's xy.
fn uv_corners(triangle: u32) -> array<vec4<f32>, 2> {
    let at = triangle * shading_stride() + select(0u, 3u, SMOOTH_NORMALS);
    return array<vec4<f32>, 2>(vertex_at(at), vertex_at(at + 1u));
}

// The level after the one whose first texel, width and height are `info`'s x, y, z: it
// follows that one's texels, half its size (rounded down, at least 1).
fn next_level(info: vec3<u32>) -> vec3<u32> {
    return vec3<u32>(info.x + info.y * info.z, max(info.y / 2u, 1u), max(info.z / 2u, 1u));
}

// Material `m`'s texture at `uv`, filtered trilinearly at level of detail `lod` (log2 of the
// footprint's size in level-0 texels, `texture_lod`): bilinear in the two levels around it,
// blended (OpenGL 4.6, 8.14). Level 0 alone at lod <= 0, the last level beyond it.
fn sample_texture(m: Material, uv: vec2<f32>, lod: f32) -> vec3<f32> {
    let last = f32(m.texture_levels - 1u);
    let l = clamp(lod, 0.0, last);
    let k = u32(floor(l));
    var info = vec3<u32>(m.texture, m.texture_width, m.texture_height);
    for (var i = 0u; i < k; i++) {
        info = next_level(info);
    }
    let near = bilinear(info, uv);
    let f = l - f32(k);
    if f == 0.0 {
        return near;
    }
    return mix(near, bilinear(next_level(info), uv), f);
}

// The level of detail of the texture of the triangle `hit` is on, where a pixel's step right
// and down moves the hit by `footprint`'s columns (world space; zero: the finest level): log2
// of the side of the square with the footprint's area in level-0 texels. The steps become
// barycentric ones through the triangle's dual basis, then texel ones through its UVs. (A
// GPU sampler takes the longer step instead, OpenGL 4.6 §8.14.1, which blurs more across a
// slanted footprint: against the box-filtered reference the area measured 6 % less MSE and 4 %
// less ꟻLIP at one ray a pixel on Šibenik through the Samyang.) 0 without a texture.
fn texture_lod(hit: Hit, footprint: mat2x3<f32>) -> f32 {
    let tri = triangle_at(hit.slot);
    let m = material_at(tri.material);
    if !HAS_TEXTURES || m.texture == NO_TEXTURE {
        return 0.0;
    }
    var steps = footprint;
    if INSTANCED {
        let to_mesh = hit_instance(hit).to_mesh;
        steps = mat2x3<f32>(linear(to_mesh, steps[0]), linear(to_mesh, steps[1]));
    }
    let e1 = tri.v1 - tri.v0;
    let e2 = tri.v2 - tri.v0;
    let n = cross(e1, e2);
    let dual = mat2x3<f32>(cross(e2, n), cross(n, e1)) * (1.0 / dot(n, n));
    let corners = uv_corners(tri.triangle);
    let a = corners[0];
    let b = corners[1];
    let size = vec2<f32>(f32(m.texture_width), f32(m.texture_height));
    // Texels per unit of u and of v.
    let along = mat2x2<f32>((a.zw - a.xy) * size, (b.xy - a.xy) * size);
    let x = along * vec2<f32>(dot(dual[0], steps[0]), dot(dual[1], steps[0]));
    let y = along * vec2<f32>(dot(dual[0], steps[1]), dot(dual[1], steps[1]));
    let area = abs(x.x * y.y - x.y * y.x);
    return select(0.0, 0.5 * log2(area), area > 1.0);
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
    // The scene triangle (as ids name it).
    triangle: u32,
    // The lights that reach every point of it (`BvhTriangle::unshadowed`).
    unshadowed: u32,
}

// A vertex normal of the hit's triangle in the world, unit length.
fn vertex_normal(hit: Hit, n: vec3<f32>) -> vec3<f32> {
    if INSTANCED {
        return normalize(world_normal(hit, n));
    }
    return n;
}

// The surface at `hit` of `ray`, its texture (if any) filtered at level of detail `lod`
// (`texture_lod`).
fn surface_at(ray: Ray, hit: Hit, lod: f32) -> Surface {
    let tri = triangle_at(hit.slot);
    var material = material_at(tri.material);
    let w = 1.0 - hit.u - hit.v;
    let position = hit_position(hit);
    var geometric = normalize(hit_face_normal(hit));
    let front = dot(geometric, ray.dir) < 0.0;
    if !front {
        geometric = -geometric;
    }
    var normal = geometric;
    let base = tri.triangle * shading_stride();
    if SMOOTH_NORMALS {
        // Each vertex normal in the world before interpolation, as a flattened copy has it.
        let n = normalize(w * vertex_normal(hit, vertex_at(base).xyz)
            + hit.u * vertex_normal(hit, vertex_at(base + 1u).xyz)
            + hit.v * vertex_normal(hit, vertex_at(base + 2u).xyz));
        // Keep the interpolated normal on the side the ray came from.
        normal = select(-n, n, dot(n, geometric) >= 0.0);
    }
    if HAS_TEXTURES && material.texture != NO_TEXTURE {
        let corners = uv_corners(tri.triangle);
        let a = corners[0];
        let b = corners[1];
        let uv = w * a.xy + hit.u * a.zw + hit.v * b.xy;
        material.diffuse *= sample_texture(material, uv, lod);
    }
    return Surface(position, geometric, normal, front, material, scene_triangle(hit.slot, hit.instance),
        tri.unshadowed);
}

// A light as it arrives at a point: the unit vector towards it, its distance (3e38 for a
// directional light) and its irradiance there if nothing is in the way. `lit` is false where it
// arrives from behind the surface (by the shading or the geometric normal).
struct Incident {
    to_light: vec3<f32>,
    distance: f32,
    irradiance: vec3<f32>,
    lit: bool,
}

fn incident(s: Surface, origin: vec3<f32>, light: Light) -> Incident {
    var i: Incident;
    if light.kind == LIGHT_POINT {
        let d = light.vector - origin;
        i.distance = length(d);
        i.to_light = d / i.distance;
        i.irradiance = light.colour / (i.distance * i.distance);
    } else {
        i.to_light = -light.vector;
        i.distance = 3.0e38;
        i.irradiance = light.colour;
    }
    i.lit = dot(s.normal, i.to_light) > 0.0 && dot(s.geometric, i.to_light) > 0.0;
    return i;
}

// Blinn-Phong: the radiance towards a viewer looking along `view` of a lit surface, scaled by
// the fraction `visible` of the light that reaches it.
fn reflected(s: Surface, view: vec3<f32>, light: Incident, visible: f32) -> vec3<f32> {
    let irradiance = light.irradiance * visible;
    let half_vector = normalize(light.to_light - view);
    let highlight = s.material.specular
        * pow(max(dot(s.normal, half_vector), 0.0), s.material.shininess);
    return irradiance * (s.material.diffuse * dot(s.normal, light.to_light) + highlight);
}

// Unpolarised Fresnel reflectance of a dielectric interface.
fn fresnel(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

// A ray along `dir` meeting glass: the Fresnel reflectance and the refracted direction
// (zero under total internal reflection, where the reflectance is 1). Entering through the
// front face, or leaving through the back.
struct Interface {
    reflectance: f32,
    refracted: vec3<f32>,
}

fn glass_interface(s: Surface, dir: vec3<f32>) -> Interface {
    var eta = 1.0 / s.material.ior;
    if !s.front {
        eta = s.material.ior;
    }
    let cos_i = -dot(dir, s.normal);
    let sin2_t = eta * eta * max(1.0 - cos_i * cos_i, 0.0);
    if sin2_t >= 1.0 {
        return Interface(1.0, vec3<f32>(0.0));
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let refracted = normalize(eta * dir + (eta * cos_i - cos_t) * s.normal);
    return Interface(fresnel(cos_i, cos_t, 1.0 / eta), refracted);
}
