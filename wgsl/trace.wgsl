// Traces the primary rays of every pixel through the lens and shades them Whitted-style; one
// invocation per pixel, dispatched over the image in WORKGROUP_2D × WORKGROUP_2D tiles.
// The same kernel serves every lens, pinhole included: only ray generation differs.
//
// With SAMPLES_PER_SIDE = s > 1 the colour is the mean radiance of s² samples inside the
// pixel (`sampling.wgsl`; a box filter), and w the share of them the lens covers; the
// ground truth (geometry, id) stays the single ray through the pixel's centre. With GLASS the
// colour is traced through a prescription's surfaces instead (`glass_radiance`), and the
// ground truth is its fitted model's centre ray.
#import pixel

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
    // The samples make the colour where there are several (or the glass), also in a pixel
    // whose centre the lens masks but whose samples it may not; the centre (the glass's
    // fitted model's) gives the ground truth, its hit alone. Each kernel calls the tracer
    // from as few places as it can: every call is compiled anew (lavapipe takes seconds).
    let sampled = GLASS || SAMPLES_PER_SIDE > 1u;
    var traced = missed();
    if ray.w != 0.0 {
        if sampled {
            traced = first_hit(centre_ray(pixel, ray.xyz));
        } else {
            traced = shade_centre(pixel, ray.xyz);
        }
    }
    var colour = vec4<f32>(traced.colour, select(0.0, 1.0, ray.w != 0.0));
    if sampled && (ray.w != 0.0 || !GLASS) {
        colour = supersampled(pixel, index);
    }
    colour_out[stored] = colour;
    geometry_out[stored] = geometry_of(traced);
    ids_out[stored] = traced.triangle;
}
