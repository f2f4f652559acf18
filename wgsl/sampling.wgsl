// Where a pixel's samples go: an s × s grid of strata, one jittered sample in each, the jitter
// from a hash of the pixel and the sample, so every render is the same (Mitchell 1987 and
// Pharr, Jakob and Humphreys, "Physically Based Rendering", 4th ed., section 8.5: jittered
// stratified sampling). The Rust twin is `fisheye_rt::trace::sampling`; the GPU and the f64
// reference are compared over the same samples.

// The pcg2d hash of Jarzynski and Olano ("Hash Functions for GPU Rendering", JCGT 9(3),
// 2020): a PCG-style LCG step on each lane, mixed across lanes, twice.
fn pcg2d(seed: vec2<u32>) -> vec2<u32> {
    var v = seed * 1664525u + 1013904223u;
    v.x += v.y * 1664525u;
    v.y += v.x * 1664525u;
    v = v ^ (v >> vec2<u32>(16u));
    v.x += v.y * 1664525u;
    v.y += v.x * 1664525u;
    v = v ^ (v >> vec2<u32>(16u));
    return v;
}

// Sample `k` of the `side` × `side` samples of pixel `index` (row-major): its offset from the
// pixel's top-left corner, in [0, 1)². One sample sits at the centre.
fn sample_offset(index: u32, k: u32, side: u32) -> vec2<f32> {
    if side == 1u {
        return vec2<f32>(0.5);
    }
    // 24 bits of each hash lane, exactly representable in f32.
    let jitter = vec2<f32>(pcg2d(vec2<u32>(index, k)) >> vec2<u32>(8u)) * (1.0 / 16777216.0);
    let stratum = vec2<f32>(f32(k % side), f32(k / side));
    return (stratum + jitter) / f32(side);
}
