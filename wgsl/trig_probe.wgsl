// Evaluates the WGSL builtins and our math.wgsl functions side by side at given arguments,
// one invocation per argument, so the host can measure both against f64 on this adapter.
#import math

@group(0) @binding(0) var<storage, read> args: array<f32>;
// Per argument x: builtin sin, cos, atan, asin, then ours, in that order.
@group(0) @binding(1) var<storage, read_write> values: array<array<f32, 8>>;

@compute @workgroup_size(WORKGROUP_1D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&args) {
        return;
    }
    let x = args[id.x];
    let sc = sin_cos(x);
    // asin is defined on [0, 1]: probe it at x/8 (the host feeds x in [0, 8]).
    values[id.x] = array<f32, 8>(
        sin(x), cos(x), atan(x), asin(x / 8.0),
        sc.x, sc.y, atan_pos(x), asin_pos(x / 8.0),
    );
}
