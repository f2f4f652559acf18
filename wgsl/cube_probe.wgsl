// Face and UV of arbitrary directions, to test `cube_face_uv` against its CPU twin.
#import cube

@group(0) @binding(0) var<storage, read> probe_directions: array<vec4<f32>>;
// face (as f32 bits), u, v, unused.
@group(0) @binding(1) var<storage, read_write> probe_out: array<vec4<f32>>;

@compute @workgroup_size(WORKGROUP_1D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&probe_directions) {
        return;
    }
    let r = cube_face_uv(probe_directions[id.x].xyz);
    probe_out[id.x] = vec4<f32>(bitcast<f32>(r.face), r.uv, 0.0);
}
