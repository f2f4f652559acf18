// Primary ray directions for per-pixel kernels: the lens (binding 0) and the direction table
// (binding 1) of group 0, evaluated per pixel or read from the table as the DIRECTION_SOURCE
// override says. Kernels that import this put their own bindings from 2 on.
#import lens

override DIRECTION_SOURCE: u32;

@group(0) @binding(0) var<uniform> lens: LensParams;
// The direction table of `lens_rays.wgsl`; read only when DIRECTION_SOURCE is DIRECTIONS_TABLE.
@group(0) @binding(1) var<storage, read> table: array<vec4<f32>>;

// The camera-space ray of pixel `pixel` (w = 1), or all zero where the lens masks it.
fn primary_ray(pixel: vec2<u32>) -> vec4<f32> {
    if DIRECTION_SOURCE == DIRECTIONS_TABLE {
        return table[pixel.y * lens.width + pixel.x];
    }
    return lens_pixel_ray(lens, pixel);
}
