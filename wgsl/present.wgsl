// Writes the trace pass's colour output into a caller's texture, one invocation per pixel:
// linear radiance for float formats, sRGB-encoded and clamped (as the PNG) for 8-bit ones;
// alpha is the lens mask. The texture's format below is rewritten to the caller's at pipeline
// creation (`fisheye_rt::renderer`).

// The colour output: linear RGB, w = 1 where the pixel has a ray, all zero where masked.
@group(0) @binding(0) var<storage, read> colour: array<vec4<f32>>;
@group(0) @binding(1) var target_texture: texture_storage_2d<rgba32float, write>;

// Whether the texture stores display values (an 8-bit format) rather than radiance.
override ENCODE_SRGB: bool;

// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1]; the CPU twin is
// `fisheye_rt::trace::linear_to_srgb`.
fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.0031308 {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(target_texture);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    var c = colour[id.y * size.x + id.x];
    if ENCODE_SRGB {
        let v = clamp(c.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
        c = vec4<f32>(linear_to_srgb(v.r), linear_to_srgb(v.g), linear_to_srgb(v.b), c.w);
    }
    textureStore(target_texture, id.xy, c);
}
