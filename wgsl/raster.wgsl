// The rasterized cube faces: the scene's triangles drawn by vertex pulling (three vertices per
// BVH slot, no vertex buffer), shaded forward in the fragment shader or deferred through a
// G-buffer and a compute pass, and the shadow maps that stand in for shadow rays.
//
// Shading is `surface.wgsl`'s, as the tracer's. What a rasterizer cannot do, it does not:
// lights are seen through shadow maps (filtered 2×2, so shadow edges are softened by about a
// texel), mirrors and glass reflect and transmit the sky instead of casting rays, and partially
// transparent surfaces are drawn opaque.
#import surface
#import cube

// Mirrors `fisheye_rt::raster::Views` (496 bytes).
struct Views {
    // Per face: scene space (relative to the scene's origin) to clip space, depth reversed.
    clip: array<mat4x4<f32>, 6>,
    // Per face: the texels x0, y0 (inclusive), x1, y1 (exclusive) of the bordered face that are
    // rendered; empty for faces that are not.
    regions: array<vec4<u32>, 6>,
    // The eye in scene space (xyz).
    eye: vec4<f32>,
}

// Mirrors `fisheye_rt::raster::ShadowView` (80 bytes): one layer of the shadow maps.
struct ShadowView {
    // Scene space to the layer's clip space; depth is reversed (larger is nearer the light).
    clip: mat4x4<f32>,
    // x: a texel's width in scene units, at unit distance from a point light (whose faces
    // span 90°) or anywhere in a directional light's orthographic map.
    texel: vec4<f32>,
}

@group(0) @binding(0) var<uniform> views: Views;
// The deferred G-buffer: BVH slot + 1 (0 where nothing was drawn), the barycentrics u, v
// and the texture's level of detail, as bits.
@group(0) @binding(1) var gbuffer: texture_2d_array<u32>;
// The cube's bordered faces, which the deferred lighting writes (forward passes draw into
// them as colour attachments).
@group(0) @binding(2) var cube_out: texture_storage_2d_array<rgba32float, write>;

@group(2) @binding(0) var<storage, read> shadow_views: array<ShadowView>;
@group(2) @binding(1) var shadow_map: texture_depth_2d_array;
@group(2) @binding(2) var shadow_sampler: sampler_comparison;

struct Varyings {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) slot: u32,
    // The barycentric weights of the triangle's v1 and v2 (perspective-correct).
    @location(1) bary: vec2<f32>,
    @location(2) world: vec3<f32>,
}

// Vertex `vertex` of a draw of the whole scene: corner `vertex % 3` of BVH slot `vertex / 3`.
fn corner(vertex: u32) -> vec3<f32> {
    let tri = triangle_at(vertex / 3u);
    switch vertex % 3u {
        case 0u: {
            return tri.v0;
        }
        case 1u: {
            return tri.v1;
        }
        default: {
            return tri.v2;
        }
    }
}

fn face_vertex(vertex: u32, face: u32) -> Varyings {
    let p = corner(vertex);
    let c = vertex % 3u;
    let bary = vec2<f32>(f32(c == 1u), f32(c == 2u));
    return Varyings(views.clip[face] * vec4<f32>(p, 1.0), vertex / 3u, bary, p);
}

fn in_region(face: u32, texel: vec2<u32>) -> bool {
    let r = views.regions[face];
    return all(texel >= r.xy) && all(texel < r.zw);
}

// One face per draw: the instance index is the face.
@vertex
fn face_vs(@builtin(vertex_index) vertex: u32, @builtin(instance_index) face: u32) -> Varyings {
    return face_vertex(vertex, face);
}

// Shadow maps, depth only: one layer per draw, the instance index is the layer.
@vertex
fn shadow_vs(@builtin(vertex_index) vertex: u32, @builtin(instance_index) layer: u32) -> @builtin(position) vec4<f32> {
    return shadow_views[layer].clip * vec4<f32>(corner(vertex), 1.0);
}

// The fraction of `light` (arriving along `to_light`) that reaches `s`, from the shadow maps,
// filtered over 2×2 texels by the comparison sampler. The point is first moved off its surface
// along the normal by its texel's footprint, more where the light grazes the surface (normal
// offset, Holbein 2011), so that a lit surface does not shadow itself.
fn shadow_visibility(light: Light, s: Surface, to_light: vec3<f32>) -> f32 {
    var texel = shadow_views[light.shadow_layer].texel.x;
    if light.kind == LIGHT_POINT {
        let d = abs(s.position - light.vector);
        texel *= max(d.x, max(d.y, d.z));
    }
    let cos_l = clamp(dot(s.geometric, to_light), 0.05, 1.0);
    let tan_l = sqrt(1.0 - cos_l * cos_l) / cos_l;
    let p = s.position + s.geometric * (texel * (1.0 + min(tan_l, 4.0)));
    var layer = light.shadow_layer;
    if light.kind == LIGHT_POINT {
        layer += cube_face_uv(p - light.vector).face;
    }
    let clip = shadow_views[layer].clip * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / clip.w;
    let uv = vec2<f32>(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y);
    return textureSampleCompareLevel(shadow_map, shadow_sampler, uv, layer, ndc.z);
}

// The radiance the eye sees at the barycentrics `bary` of BVH slot `slot`, at `world`, where
// its texture (if any) is filtered at level of detail `lod` (`texture_lod`).
fn raster_shade(slot: u32, bary: vec2<f32>, world: vec3<f32>, lod: f32) -> vec3<f32> {
    let dir = normalize(world - views.eye.xyz);
    let s = surface_at(Ray(views.eye.xyz, dir, 0.0, 3.0e38), Hit(0.0, bary.x, bary.y, slot, 0u), lod);
    var colour = s.material.emission;
    if HAS_MIRRORS && s.material.surface == SURFACE_MIRROR {
        return colour + s.material.specular * shading.sky;
    }
    if HAS_GLASS && s.material.surface == SURFACE_GLASS {
        let r = glass_interface(s, dir).reflectance;
        return colour + (r + (1.0 - r) * s.material.transmission) * shading.sky;
    }
    colour += s.material.diffuse * shading.ambient;
    for (var i = 0u; i < shading.light_count; i++) {
        let l = light_at(i);
        let light = incident(s, s.position, l);
        if !light.lit {
            continue;
        }
        let visible = shadow_visibility(l, s, light.to_light);
        if visible > 0.0 {
            colour += reflected(s, dir, light, visible);
        }
    }
    return colour;
}

// The level of detail of the texture a fragment shows: its footprint is how its point moves
// to the next texel right and down, the screen-space derivatives of its position, as the
// tracer's ray differentials give its hits (`hit_footprint`).
fn fragment_lod(in: Varyings) -> f32 {
    if !HAS_TEXTURES {
        return 0.0;
    }
    return texture_lod(Hit(0.0, in.bary.x, in.bary.y, in.slot, 0u), mat2x3<f32>(dpdx(in.world), dpdy(in.world)));
}

// Forward: lighting in the fragment shader.
@fragment
fn forward_fs(in: Varyings) -> @location(0) vec4<f32> {
    return vec4<f32>(raster_shade(in.slot, in.bary, in.world, fragment_lod(in)), 1.0);
}

// Deferred, first pass: what each texel sees, and its texture's level of detail, to be lit in
// `deferred_lighting`.
@fragment
fn gbuffer_fs(in: Varyings) -> @location(0) vec4<u32> {
    let lod = fragment_lod(in);
    return vec4<u32>(in.slot + 1u, bitcast<u32>(in.bary.x), bitcast<u32>(in.bary.y), bitcast<u32>(lod));
}

// Deferred, second pass: lights the visible surface of every rendered texel (the sky where
// nothing was drawn) into the cube's faces. One invocation per texel, z is the face.
@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn deferred_lighting(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_region(id.z, id.xy) {
        return;
    }
    let g = textureLoad(gbuffer, id.xy, id.z, 0);
    var colour = shading.sky;
    if g.x != 0u {
        let hit = Hit(0.0, bitcast<f32>(g.y), bitcast<f32>(g.z), g.x - 1u, 0u);
        colour = raster_shade(hit.slot, vec2<f32>(hit.u, hit.v), hit_position(hit), bitcast<f32>(g.w));
    }
    textureStore(cube_out, id.xy, id.z, vec4<f32>(colour, 1.0));
}
