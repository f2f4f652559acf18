// The viewer's last step: copies the renderer's image (already in the surface's encoding:
// linear for an sRGB surface, sRGB-encoded for a plain one) onto the window, one fragment
// per pixel, masked pixels black. Drawn as one triangle covering the window.

@group(0) @binding(0) var image: texture_2d<f32>;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // (-1, -1), (3, -1), (-1, 3): a triangle whose inside holds the whole clip square.
    let x = f32(i32(i & 1u) * 4 - 1);
    let y = f32(i32(i >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(image, vec2<i32>(position.xy), 0);
    return vec4<f32>(c.rgb * c.a, 1.0);
}
