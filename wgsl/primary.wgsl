// Primary ray directions for per-pixel kernels: the lens (binding 0 of group 0), evaluated per
// pixel. Where a kernel reads the direction table instead (`DirectionSource::Table`), the
// pipeline is composed with `primary_table.wgsl` in this file's place, which adds the table
// as binding 1: a kernel that computes its directions binds no table. Kernels that import
// this put their own bindings from 2 on.
#import lens

@group(0) @binding(0) var<uniform> lens: LensParams;

// The camera-space ray of pixel `pixel` (w = 1), or all zero where the lens masks it.
fn primary_ray(pixel: vec2<u32>) -> vec4<f32> {
    return lens_pixel_ray(lens, pixel);
}
