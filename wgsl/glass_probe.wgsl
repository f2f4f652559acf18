// Traces arbitrary rays from the film's side out through a prescription, one invocation per
// ray in WORKGROUP_1D-wide groups: the GPU twin held to `Prescription::trace_from_film` by
// the tests.
// Binding 6: the glass (`glass.wgsl`).
#import glass

// Per ray: its origin (w: the channel, 0 red, 1 green, 2 blue), then its unit direction
// (lens frame, mm).
@group(0) @binding(0) var<storage, read> rays: array<vec4<f32>>;
// Per ray: where it leaves the front surface (w = 1 if it got through, else 0), then its
// direction there.
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(WORKGROUP_1D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if 2u * i + 1u >= arrayLength(&rays) {
        return;
    }
    let out = glass_trace(rays[2u * i].xyz, rays[2u * i + 1u].xyz, u32(rays[2u * i].w));
    results[2u * i] = vec4<f32>(out.origin, select(0.0, 1.0, out.passed));
    results[2u * i + 1u] = vec4<f32>(out.direction, 0.0);
}

// Points on the exit pupil (`pupil_offset`) of pixels 0, 1, ..., PUPIL_PROBE_SAMPLES of them
// a pixel, an invocation each: its 16 (4 × 4, nested), then its 2 × 2, in results' xy.
const PUPIL_PROBE_SAMPLES: u32 = 20u;

@compute @workgroup_size(WORKGROUP_1D)
fn pupil(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&results) {
        return;
    }
    let pixel = i / PUPIL_PROBE_SAMPLES;
    let k = i % PUPIL_PROBE_SAMPLES;
    var u = vec2<f32>(0.0);
    if k < 16u {
        u = pupil_offset(pixel, k, 4u);
    } else {
        u = pupil_offset(pixel, k - 16u, 2u);
    }
    results[i] = vec4<f32>(u, 0.0, 0.0);
}
