// Where a pixel's samples go: side² of them on a rotated grid, one in each of the side × side
// strata and one in each row and each column of the side² × side² cells that cut the pixel,
// each at its cell's centre; which of 2·side such arrangements a pixel takes comes from a hash
// of the pixel, so every render is the same. The Rust twin is `fisheye_rt::trace::sampling`
// (it says why this pattern); the GPU and the f64 reference are compared over the same samples.

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

// Sample `k` of the `side` × `side` samples of pixel `index` (row-major by stratum): its
// offset from the pixel's top-left corner, in (0, 1)². With one sample, the centre.
fn sample_offset(index: u32, k: u32, side: u32) -> vec2<f32> {
    let stratum = vec2<u32>(k % side, k / side);
    let h = pcg2d(vec2<u32>(index, 0u));
    // The lattice moved up h.y strata (wrapping around), and mirrored left to right where h.x
    // is odd: the stratum's cell on one of its diagonals.
    let shift = h.y % side;
    var cell = vec2<u32>((stratum.y + side - stratum.x + shift) % side);
    if (h.x & 1u) == 1u {
        let r = (stratum.y + stratum.x + shift) % side;
        cell = vec2<u32>(side - 1u - r, r);
    }
    return (vec2<f32>(stratum * side + cell) + 0.5) / f32(side * side);
}
