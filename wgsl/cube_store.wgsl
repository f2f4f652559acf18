// Traced cube faces into the cube: copies a face pass's colour output into that face's layer
// of the cube texture (texels outside the rendered region carry nothing the sampler reads).

@group(0) @binding(0) var<storage, read> face_colour: array<vec4<f32>>;
@group(0) @binding(1) var face_out: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let side = textureDimensions(face_out).x;
    if id.x >= side || id.y >= side {
        return;
    }
    textureStore(face_out, id.xy, face_colour[id.y * side + id.x]);
}
