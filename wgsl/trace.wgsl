// Traces the primary ray of every pixel through the lens and shades it Whitted-style; one
// invocation per pixel, dispatched over the image in WORKGROUP_2D × WORKGROUP_2D tiles.
// The same kernel serves every lens, pinhole included: only ray generation differs.
#import primary
#import shade

// Mirrors `fisheye_rt::trace::Frame`: the camera-to-world rotation's columns (camera x right,
// y down, z forward) and the eye. The scene is uploaded relative to its own camera, so the eye
// is at the origin unless a camera path moved it.
struct Frame {
    right: vec4<f32>,
    down: vec4<f32>,
    forward: vec4<f32>,
    eye: vec4<f32>,
    // The pixel of the first invocation (xy), for dispatches over a part of the image.
    offset: vec4<u32>,
}

@group(0) @binding(2) var<uniform> frame: Frame;
// Linear RGB radiance; w = 1 where the pixel has a ray, all zero where masked.
@group(0) @binding(3) var<storage, read_write> colour_out: array<vec4<f32>>;
// World-space shading normal and distance of the primary hit; zero on a miss or mask.
@group(0) @binding(4) var<storage, read_write> geometry_out: array<vec4<f32>>;
// Scene triangle of the primary hit; NO_HIT on a miss or mask.
@group(0) @binding(5) var<storage, read_write> ids_out: array<u32>;

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = id.xy + frame.offset.xy;
    if pixel.x >= lens.width || pixel.y >= lens.height {
        return;
    }
    let index = pixel.y * lens.width + pixel.x;
    let ray = primary_ray(pixel);
    if ray.w == 0.0 {
        colour_out[index] = vec4<f32>(0.0);
        geometry_out[index] = vec4<f32>(0.0);
        ids_out[index] = NO_HIT;
        return;
    }
    let dir = frame.right.xyz * ray.x + frame.down.xyz * ray.y + frame.forward.xyz * ray.z;
    let traced = shade(Ray(frame.eye.xyz, dir, 0.0, 3.0e38));
    colour_out[index] = vec4<f32>(traced.colour, 1.0);
    if traced.triangle == NO_HIT {
        geometry_out[index] = vec4<f32>(0.0);
    } else {
        geometry_out[index] = vec4<f32>(traced.normal, traced.hit.t);
    }
    ids_out[index] = traced.triangle;
}
