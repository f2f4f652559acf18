// Traces the primary rays of every pixel through the lens and shades them Whitted-style; one
// invocation per pixel, dispatched over the image in WORKGROUP_2D × WORKGROUP_2D tiles.
// The same kernel serves every lens, pinhole included: only ray generation differs.
//
// With SAMPLES_PER_SIDE = s > 1 the colour is the mean radiance of s² jittered stratified
// samples inside the pixel (a box filter), and w the share of them the lens covers; the
// ground truth (geometry, id) stays the single ray through the pixel's centre.
#import primary
#import sampling
#import shade

override SAMPLES_PER_SIDE: u32 = 1u;

// Mirrors `fisheye_rt::trace::Frame`: the camera-to-world rotation's columns (camera x right,
// y down, z forward) and the eye. The scene is uploaded relative to its own camera, so the eye
// is at the origin unless a camera path moved it.
struct Frame {
    right: vec4<f32>,
    down: vec4<f32>,
    forward: vec4<f32>,
    eye: vec4<f32>,
    // The pixel of the first invocation (xy), for dispatches over a part of the image; w:
    // the first image row the outputs hold (a band of rows; 0 for a whole image).
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
    // The pixel's index in the image (its samples' hash), and in the outputs.
    let index = pixel.y * lens.width + pixel.x;
    let stored = index - frame.offset.w * lens.width;
    let ray = primary_ray(pixel);
    if ray.w == 0.0 {
        colour_out[stored] = vec4<f32>(0.0);
        if SAMPLES_PER_SIDE > 1u {
            colour_out[stored] = supersampled(pixel, index);
        }
        geometry_out[stored] = vec4<f32>(0.0);
        ids_out[stored] = NO_HIT;
        return;
    }
    let centre = Ray(frame.eye.xyz, world(ray.xyz), 0.0, 3.0e38);
    var traced: Traced;
    if SAMPLES_PER_SIDE > 1u {
        // The samples make the colour; the centre gives the ground truth, its hit alone.
        traced = first_hit(centre);
        colour_out[stored] = supersampled(pixel, index);
    } else {
        traced = shade(centre);
        colour_out[stored] = vec4<f32>(traced.colour, 1.0);
    }
    if traced.triangle == NO_HIT {
        geometry_out[stored] = vec4<f32>(0.0);
    } else {
        geometry_out[stored] = vec4<f32>(traced.normal, traced.hit.t);
    }
    ids_out[stored] = traced.triangle;
}

// A camera-space direction in the world.
fn world(d: vec3<f32>) -> vec3<f32> {
    return frame.right.xyz * d.x + frame.down.xyz * d.y + frame.forward.xyz * d.z;
}

// The mean radiance of the pixel's samples that have a ray, and the share that do (w).
fn supersampled(pixel: vec2<u32>, index: u32) -> vec4<f32> {
    let count = SAMPLES_PER_SIDE * SAMPLES_PER_SIDE;
    var sum = vec3<f32>(0.0);
    var covered = 0u;
    for (var k = 0u; k < count; k++) {
        let p = vec2<f32>(pixel) + sample_offset(index, k, SAMPLES_PER_SIDE);
        let d = lens_unproject(lens, p);
        if d.w != 0.0 {
            sum += shade(Ray(frame.eye.xyz, world(d.xyz), 0.0, 3.0e38)).colour;
            covered += 1u;
        }
    }
    if covered == 0u {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(sum / f32(covered), f32(covered) / f32(count));
}
