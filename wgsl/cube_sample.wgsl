// The cube-map path's resampling pass: for each fisheye pixel with a ray, the lens direction
// (same lens code as the tracer), its face and UV, and a bilinear sample of the bordered faces.
#import primary
#import cube

// The six bordered faces: (size + 2)² texels each, linear RGB (w unused by sampling).
@group(0) @binding(2) var cube_faces: texture_2d_array<f32>;

// Linear RGB; w = 1 where the pixel has a ray, all zero where masked (as the tracer writes).
@group(0) @binding(3) var<storage, read_write> colour_out: array<vec4<f32>>;

// Bilinear lookup at `uv` of `face`: its texels have a one-texel border holding samples just
// past each edge, so the four texels read always exist.
fn cube_sample(face: u32, uv: vec2<f32>) -> vec4<f32> {
    let side = textureDimensions(cube_faces).x;
    let st = uv * f32(side - 2u) + 0.5;
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
    colour_out[index] = vec4<f32>(cube_sample(hit.face, hit.uv).rgb, 1.0);
}
