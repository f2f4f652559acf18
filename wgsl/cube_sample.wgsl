// The cube-map path's resampling pass: for each fisheye pixel with a ray, the lens direction
// (same lens code as the tracer), its face and UV, and the faces' bilinear reconstruction
// averaged over the pixel's square: n × n lookups at the centres of an n × n grid of the
// square, n the face texels across the pixel rounded, from 1 (one lookup, at the centre,
// where face texels are no finer than the pixel) to MOST_TAPS. The tracer's pixels are box
// filters of the scene; so, through its own texels, is the cube's: faces finer than the
// pixels are not aliased by one lookup a pixel. The grid's directions are the centre's moved
// along the lens's steps a pixel on (`lens_steps`), to first order: the lens is evaluated
// three times a pixel, not n² times.
#import primary
#import cube

// Lookups across a pixel, at most.
override MOST_TAPS: u32;

// The six bordered faces: (size + 2)² texels each, linear RGB (w unused by sampling).
@group(0) @binding(2) var cube_faces: texture_2d_array<f32>;

// Linear RGB; w = 1 where the pixel has a ray, all zero where masked (as the tracer writes).
@group(0) @binding(3) var<storage, read_write> colour_out: array<vec4<f32>>;

// Texels across a face, its border left out.
fn face_texels() -> f32 {
    return f32(textureDimensions(cube_faces).x - 2u);
}

// Bilinear lookup at `uv` of `face`: its texels have a one-texel border holding samples just
// past each edge, so the four texels read always exist.
fn cube_sample(face: u32, uv: vec2<f32>) -> vec4<f32> {
    let side = textureDimensions(cube_faces).x;
    let st = uv * face_texels() + 0.5;
    let base = floor(st);
    let f = st - base;
    let x = min(u32(max(base.x, 0.0)), side - 2u);
    let y = min(u32(max(base.y, 0.0)), side - 2u);
    let top = mix(textureLoad(cube_faces, vec2<u32>(x, y), face, 0),
        textureLoad(cube_faces, vec2<u32>(x + 1u, y), face, 0), f.x);
    let bottom = mix(textureLoad(cube_faces, vec2<u32>(x, y + 1u), face, 0),
        textureLoad(cube_faces, vec2<u32>(x + 1u, y + 1u), face, 0), f.x);
    return mix(top, bottom, f.y);
}

// Texels across the pixel whose ray is `d` and whose neighbours' are `steps` away, on the face
// `d` falls on: the longer of the pixel's two sides there, in texels.
fn texels_across(face: u32, d: vec3<f32>, steps: mat2x3<f32>) -> f32 {
    let m = CUBE_FACES[face];
    let at = vec2<f32>(dot(d, m[0]), dot(d, m[1])) / dot(d, m[2]);
    var longest = 0.0;
    for (var axis = 0u; axis < 2u; axis++) {
        let q = d + steps[axis];
        let moved = vec2<f32>(dot(q, m[0]), dot(q, m[1])) / dot(q, m[2]) - at;
        longest = max(longest, length(moved));
    }
    // Face coordinates span [-1, 1]: half the face's texels a unit.
    return longest * 0.5 * face_texels();
}

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= lens.width || id.y >= lens.height {
        return;
    }
    let index = id.y * lens.width + id.x;
    let ray = primary_ray(id.xy);
    if ray.w == 0.0 {
        colour_out[index] = vec4<f32>(0.0);
        return;
    }
    let hit = cube_face_uv(ray.xyz);
    let steps = lens_steps(lens, vec2<f32>(id.xy) + 0.5, ray.xyz, 1.0);
    let n = clamp(u32(round(texels_across(hit.face, ray.xyz, steps))), 1u, MOST_TAPS);
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < n; j++) {
        for (var i = 0u; i < n; i++) {
            let o = (vec2<f32>(f32(i), f32(j)) + 0.5) / f32(n) - 0.5;
            let at = cube_face_uv(ray.xyz + steps * o);
            sum += cube_sample(at.face, at.uv).rgb;
        }
    }
    colour_out[index] = vec4<f32>(sum / f32(n * n), 1.0);
}
