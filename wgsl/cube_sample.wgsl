// The cube-map path's resampling pass: for each fisheye pixel with a ray, the lens direction
// (same lens code as the tracer), its face and UV, and a bilinear sample of the bordered faces.
#import primary
#import cube

// Linear RGB; w = 1 where the pixel has a ray, all zero where masked (as the tracer writes).
@group(0) @binding(3) var<storage, read_write> colour_out: array<vec4<f32>>;

// Inner texels per face side.
override CUBE_SIZE: u32;

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
    colour_out[index] = vec4<f32>(cube_sample(hit.face, hit.uv, CUBE_SIZE).rgb, 1.0);
}
