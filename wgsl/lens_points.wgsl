// Unprojects arbitrary pixel positions, or projects arbitrary directions, one invocation per
// point in WORKGROUP_1D-wide groups (`fisheye lens --gpu` and the round-trip tests).
#import lens

@group(0) @binding(0) var<uniform> lens: LensParams;
// unproject: xy a continuous pixel position; project: xyz a direction.
@group(0) @binding(1) var<storage, read> points: array<vec4<f32>>;
// unproject: xyz the direction, w = 1 (zero if none); project: xy the pixel, z = 1 (zero if none).
@group(0) @binding(2) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(WORKGROUP_1D)
fn unproject(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&points) {
        return;
    }
    results[id.x] = lens_unproject(lens, points[id.x].xy);
}

@compute @workgroup_size(WORKGROUP_1D)
fn project(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&points) {
        return;
    }
    results[id.x] = vec4<f32>(lens_project(lens, points[id.x].xyz), 0.0);
}
