// Writes the trace pass's colour output into a caller's texture, one invocation per pixel:
// linear radiance for float formats, sRGB-encoded and clamped (as the PNG) for 8-bit ones;
// alpha is the lens mask. The texture's format below is rewritten to the caller's at pipeline
// creation (`fisheye_rt::renderer`).
#import colour

// The colour output: linear RGB, w = 1 where the pixel has a ray, all zero where masked.
@group(0) @binding(0) var<storage, read> colour: array<vec4<f32>>;
@group(0) @binding(1) var target_texture: texture_storage_2d<rgba32float, write>;

// Whether the texture stores display values (an 8-bit format) rather than radiance.
override ENCODE_SRGB: bool;

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(target_texture);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    var c = colour[id.y * size.x + id.x];
    if ENCODE_SRGB {
        c = vec4<f32>(shown(c.rgb), c.w);
    }
    textureStore(target_texture, id.xy, c);
}
