// `primary.wgsl` for a kernel that reads its primary ray directions from the direction table
// of `lens_rays.wgsl`, computed once (`DirectionSource::Table`): the same lens binding, the
// table as binding 1 of group 0.
#import lens

@group(0) @binding(0) var<uniform> lens: LensParams;
@group(0) @binding(1) var<storage, read> table: array<vec4<f32>>;

// The camera-space ray of pixel `pixel` (w = 1), or all zero where the lens masks it.
fn primary_ray(pixel: vec2<u32>) -> vec4<f32> {
    return table[pixel.y * lens.width + pixel.x];
}
