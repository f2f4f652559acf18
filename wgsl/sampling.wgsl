// Where a pixel's samples go: side² of them on a rotated grid, one in each of the side × side
// strata and one in each row and each column of the side² × side² cells that cut the pixel,
// each at its cell's centre; which of 2·side such arrangements a pixel takes comes from a hash
// of the pixel, so every render is the same. 4 × 4 samples are a nested pattern instead
// (NESTED_SAMPLES), whose first four are the 2 × 2 pattern. The Rust twin is `fisheye_rt::trace::sampling`
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

// Sample `k` of the `side` × `side` samples of pixel `index` (row-major by stratum, but for
// the nested pattern's: see `nested_offset`): its offset from the pixel's top-left corner, in
// (0, 1)². With one sample, the centre.
fn sample_offset(index: u32, k: u32, side: u32) -> vec2<f32> {
    let h = pcg2d(vec2<u32>(index, 0u));
    if side == NESTED_SIDE || 2u * side == NESTED_SIDE {
        return nested_offset(k, h);
    }
    let stratum = vec2<u32>(k % side, k / side);
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

// Entry `j` of NESTED_SAMPLES in the arrangement that hash `h` picks, in 48ths of a pixel:
// transposed or not, mirrored left to right or not, moved (wrapping around) by a quarter of a
// pixel along the diagonal 0 to 3 times and by half a pixel across or not.
fn nested_point(j: u32, h: vec2<u32>) -> vec2<u32> {
    var p = NESTED_SAMPLES[j];
    if (h.x & 2u) != 0u {
        p = p.yx;
    }
    if (h.x & 1u) != 0u {
        p.x = NESTED_UNITS - p.x;
    }
    let quarter = NESTED_UNITS / 4u;
    let diagonal = quarter * (h.y % 4u);
    let across = 2u * quarter * (h.y / 4u % 2u);
    return (p + vec2<u32>(diagonal + across, diagonal)) % NESTED_UNITS;
}

// Sample `k` of the nested pattern in the arrangement that hash `h` picks: the first four are
// the 2 × 2 samples, in the order of their 2 × 2 strata (row-major), then the others in
// NESTED_SAMPLES's order.
fn nested_offset(k: u32, h: vec2<u32>) -> vec2<f32> {
    var p = nested_point(k, h);
    if k < 4u {
        let half = NESTED_UNITS / 2u;
        for (var j = 0u; j < 4u; j++) {
            let q = nested_point(j, h);
            if q.x / half + 2u * (q.y / half) == k {
                p = q;
            }
        }
    }
    return vec2<f32>(p) / f32(NESTED_UNITS);
}
