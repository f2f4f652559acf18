// Ray directions of every pixel centre (the direction table); one invocation per pixel,
// dispatched over the image in WORKGROUP_2D × WORKGROUP_2D tiles.
#import lens

@group(0) @binding(0) var<uniform> lens: LensParams;
// One vec4 per pixel, row-major: xyz the unit direction, w = 1; all zero where masked.
@group(0) @binding(1) var<storage, read_write> directions: array<vec4<f32>>;

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= lens.width || id.y >= lens.height {
        return;
    }
    directions[id.y * lens.width + id.x] = lens_pixel_ray(lens, id.xy);
}
