// The tent filter (`fisheye_rt::trace::Tent`, `PixelFilter::Tent`) of a frame of one ray a
// pixel at most (uniform sampling at one ray, adaptive sampling at one ray at most, whose other
// pixels are interpolated between such rays): each pixel becomes the mean over its square of
// the bilinear interpolation through its own and its eight neighbours' centres.
// Along one axis the bilinear interpolant's mean over [-1/2, 1/2] weighs the pixel's own value
// 3/4 and each neighbour's 1/8 (the integrals of the tent 1 - |x| over the square); the 3 × 3
// weights are their products: the quadratic B-spline (the box convolved with the tent) at
// whole-pixel offsets. Neighbours the lens masks are left out and the weights renormalised, so
// nothing from outside the image circle leaks in. Everything is in linear radiance, before any
// tone curve; masked pixels stay masked.

// The traced colours (linear RGB, w = the share of the pixel the lens covers).
@group(0) @binding(0) var<storage, read> traced: array<vec4<f32>>;
// The filtered colours.
@group(0) @binding(1) var<storage, read_write> filtered: array<vec4<f32>>;

override WIDTH: u32;
override HEIGHT: u32;

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= WIDTH || id.y >= HEIGHT {
        return;
    }
    let index = id.y * WIDTH + id.x;
    let own = traced[index];
    if own.w == 0.0 {
        filtered[index] = own;
        return;
    }
    var side = array<f32, 3>(0.125, 0.75, 0.125);
    var sum = vec3<f32>(0.0);
    var weights = 0.0;
    for (var dy = 0u; dy < 3u; dy++) {
        for (var dx = 0u; dx < 3u; dx++) {
            // Unsigned: a neighbour left of column 0 wraps past WIDTH and is skipped.
            let x = id.x + dx - 1u;
            let y = id.y + dy - 1u;
            if x >= WIDTH || y >= HEIGHT {
                continue;
            }
            let c = traced[y * WIDTH + x];
            if c.w > 0.0 {
                let w = side[dx] * side[dy];
                sum += w * c.rgb;
                weights += w;
            }
        }
    }
    filtered[index] = vec4<f32>(sum / weights, own.w);
}
