// Adaptive sampling's sample-tracing kernel (steps 4 and 5 of `adaptive.wgsl`'s header): the
// listed pixels' 2 × 2 estimating samples (MODE_ESTIMATE) and their supersampling
// (MODE_SAMPLES).
#import adaptive

// Invocations that trace one listed pixel's samples side by side in `trace_samples`: as many
// as it takes samples, at most a workgroup's (WORKGROUP_1D / SAMPLE_LANES pixels a workgroup).
override SAMPLE_LANES: u32 = 1u;
// The samples that MODE_SAMPLES takes over from MODE_ESTIMATE: its 2 × 2, which are the first
// of the SAMPLES_PER_SIDE² where that pattern is the nested one (`sample_offset`), else 0.
override REUSED: u32 = 0u;
// Each invocation's last sample, for its pixel's first lane to add up.
var<workgroup> lane_radiance: array<vec4<f32>, WORKGROUP_1D>;
// How much of the difference between an estimated pixel's centre ray and its 2 × 2 samples'
// mean counts against the threshold: the centre is a fifth sample, and one sample lies
// about twice as far from a mean of four as a half of two does (for independent samples of
// spread σ, √(1 + 1/4)·σ against σ/2), so a half of its difference weighs about as much as
// a half's. Used only to decide; the colour stays the four samples' mean.
const CENTRE_SHARE: f32 = 0.5;

// Traces the listed pixels' samples, LIST_MODE's MODE_SAMPLES (SAMPLES_PER_SIDE² each) or
// MODE_ESTIMATE (ADAPTIVE_ESTIMATE_SIDE²), SAMPLE_LANES invocations a pixel (the layout
// `fisheye_rt::trace::SampleLanes` picks for the device): lane j traces samples j,
// j + SAMPLE_LANES, ..., and the pixel's first lane adds them to its sums in sample order, as
// `samples` does in one invocation, so the colour is the same bit for bit. With one lane, each
// invocation adds its pixel's samples itself (`add_samples`), with no barriers. Supersampling
// starts from the estimate's REUSED samples, in the same order.
@compute @workgroup_size(WORKGROUP_1D)
fn trace_samples(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let estimate = LIST_MODE == MODE_ESTIMATE;
    let side = select(SAMPLES_PER_SIDE, ADAPTIVE_ESTIMATE_SIDE, estimate);
    let count = side * side;
    let per_group = WORKGROUP_1D / SAMPLE_LANES;
    let lane = local % SAMPLE_LANES;
    let slot = local / SAMPLE_LANES;
    let i = atomicLoad(&work[ADAPTIVE_FIRST]) + (group.y * groups.x + group.x) * per_group + slot;
    let listed = slot < per_group && i < atomicLoad(&work[ADAPTIVE_END]);
    var index = 0u;
    if listed {
        index = atomicLoad(&work[ADAPTIVE_HEADER + i]);
    }
    let pixel = vec2<u32>(index % lens.width, index / lens.width);
    // Supersampling goes on from the estimate's samples where it reuses them.
    let reused = select(0u, REUSED, LIST_MODE == MODE_SAMPLES);
    // An estimated pixel's colour is still its centre ray's (every listed pixel was traced
    // there).
    var centre = vec4<f32>(0.0);
    if listed && estimate {
        centre = colour_out[index];
    }
    var sums = SampleSums();
    if listed && reused > 0u {
        sums = sums_of(colour_out[index], reused);
    }
    let before = sums.covered;
    if SAMPLE_LANES == 1u {
        if !listed {
            return;
        }
        add_samples(&sums, reused, pixel, index, side);
    } else {
        // Every invocation runs every round and its barriers, listed or not.
        for (var first = reused; first < count; first += SAMPLE_LANES) {
            var c = vec4<f32>(0.0);
            if listed && first + lane < count {
                c = sample_radiance(pixel, index, first + lane, side);
            }
            lane_radiance[local] = c;
            workgroupBarrier();
            if listed && lane == 0u {
                for (var j = 0u; j < min(SAMPLE_LANES, count - first); j++) {
                    add_sample(&sums, first + j, side, lane_radiance[local + j]);
                }
            }
            workgroupBarrier();
        }
        if !listed || lane != 0u {
            return;
        }
    }
    let s = sampled(sums, count);
    colour_out[index] = s.colour;
    add_rays(index, sums.covered - before);
    // Dammertz et al. (2010) estimate a pixel's error by how far the mean of half its samples
    // lies from the mean of all: here in displayed colour, the largest over three halves (their
    // interleaved half alone holds a sample either side of an edge along an axis at 2 × 2).
    // Beside them the centre ray the pixel already has, which sees what passes between the
    // 2 × 2 samples (a detail narrower than a quarter pixel at its centre): CENTRE_SHARE of
    // its difference from their mean.
    var worst = 0.0;
    for (var h = 0u; estimate && h < 3u; h++) {
        worst = max(worst, largest(abs(shown(s.colour.rgb) - shown(s.halves[h]))));
    }
    if estimate && centre.w > 0.0 {
        worst = max(worst, CENTRE_SHARE * largest(abs(shown(s.colour.rgb) - shown(centre.rgb))));
    }
    if estimate && worst >= adaptive.threshold {
        set_key(index, ADAPTIVE_KEY_MORE);
    }
}
