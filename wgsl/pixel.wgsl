// What every per-pixel tracing kernel shares (`trace.wgsl`, `adaptive.wgsl`): the outputs,
// and a pixel's supersampled colour. Group 0's bindings 3 to 5; the lens (binding 0) and, where
// directions are read from a table, the table (binding 1) come from `primary.wgsl`, the frame
// (binding 2) from `frame.wgsl`, the glass (binding 6, zero without) from `glass.wgsl`.
#import primary
#import sampling
#import glass
#import shade
#import frame

override SAMPLES_PER_SIDE: u32 = 1u;
// Whether the colour is traced through a prescription's glass (`glass`), sample by sample,
// and in how many channels apart (3 where it disperses: a ray each for red, green and blue).
override GLASS: bool = false;
override GLASS_CHANNELS: u32 = 1u;

// Linear RGB radiance; w = 1 where the pixel has a ray, all zero where masked.
@group(0) @binding(3) var<storage, read_write> colour_out: array<vec4<f32>>;
// World-space shading normal and distance of the primary hit; zero on a miss or mask.
@group(0) @binding(4) var<storage, read_write> geometry_out: array<vec4<f32>>;
// Scene triangle of the primary hit; NO_HIT on a miss or mask.
@group(0) @binding(5) var<storage, read_write> ids_out: array<u32>;

// A pixel's samples: the mean radiance of those that have a ray (a box filter) with the
// share that do in w, and the means of three halves of them (`SampleSums`: Dammertz et al.'s
// error estimate compares a half's mean with the whole's).
struct Sampled {
    colour: vec4<f32>,
    halves: array<vec3<f32>, 3>,
}

// Running sums over a pixel's samples, added in sample order (`add_sample`), wherever the
// samples were traced: one invocation (`samples`) or several side by side
// (`adaptive.wgsl`'s `trace_samples`) give the same bits. Besides all of them, three halves
// of the strata: those of one colour of a checkerboard, the first half of the rows, and the
// first half of the columns.
struct SampleSums {
    sum: vec3<f32>,
    covered: u32,
    half_sums: array<vec3<f32>, 3>,
    half_covered: vec3<u32>,
}

// Sets `primary_spread` for the ray along camera-space direction `d` through image point `p`
// of the camera placed `at`, whose pixel's samples are `step` pixels apart (1 for one a pixel,
// 1/side for side² samples): `lens_steps` turned with the camera. Only where the scene has
// textures to filter.
fn set_spread(at: Placement, p: vec2<f32>, d: vec3<f32>, step: f32) {
    if HAS_TEXTURES {
        primary_spread = at.axes * lens_steps(lens, p, d, step);
    }
}

// Sample `k` of the `side`² samples (`sample_offset`) of pixel `pixel` (index `index`): its
// radiance with w = 1, or all zero where the lens masks it. Through a prescription's glass,
// the film sample's ray through its point of the exit pupil (`glass_radiance`), in a pixel
// that the fitted model's centre ray, which gives the mask and the ground truth, does not mask.
fn sample_radiance(pixel: vec2<u32>, index: u32, k: u32, side: u32) -> vec4<f32> {
    if GLASS {
        if primary_ray(pixel).w == 0.0 {
            return vec4<f32>(0.0);
        }
        return vec4<f32>(glass_radiance(pixel, index, k, side), 1.0);
    }
    let p = vec2<f32>(pixel) + sample_offset(index, k, side);
    let d = lens_unproject(lens, p);
    if d.w == 0.0 {
        return vec4<f32>(0.0);
    }
    let at = camera_at(sample_time(pixel, index, k, side * side));
    set_spread(at, p, d.xyz, 1.0 / f32(side));
    return vec4<f32>(shade(placed_ray(at, vec3<f32>(0.0), d.xyz)).colour, 1.0);
}

// Film sample `k` of pixel `pixel`'s `side`² (`sample_offset`, toward `pupil_offset`'s point
// of the exit pupil) through the glass: its ray's radiance times its weight (`glass_sample`:
// zero only where the glass lets no ray through from there), so that the mean over a pixel's
// samples darkens with vignetting and spreads an out-of-focus point as the glass does. Where the glass disperses, red, green and
// blue are traced apart, each giving its channel.
fn glass_radiance(pixel: vec2<u32>, index: u32, k: u32, side: u32) -> vec3<f32> {
    let centre = 0.5 * vec2<f32>(f32(lens.width), f32(lens.height));
    let p = vec2<f32>(pixel) + sample_offset(index, k, side) - centre;
    let u = pupil_offset(index, k, side);
    let at = camera_at(sample_time(pixel, index, k, side * side));
    var radiance = vec3<f32>(0.0);
    for (var c = 0u; c < GLASS_CHANNELS; c++) {
        // One channel of three, or green's indices for all.
        let s = glass_sample(p, u, select(1u, c, GLASS_CHANNELS == 3u));
        if s.weight > 0.0 {
            let ray = placed_ray(at, s.origin, s.direction);
            // Channel c's part alone, or every channel without dispersion.
            let part = (vec3<u32>(0u, 1u, 2u) == vec3<u32>(c)) | vec3<bool>(GLASS_CHANNELS == 1u);
            radiance += select(vec3<f32>(0.0), s.weight * shade(ray).colour, part);
        }
    }
    return radiance;
}

// Adds sample `k` of `side`², `sample_radiance`'s `c`, to `sums`.
fn add_sample(sums: ptr<function, SampleSums>, k: u32, side: u32, c: vec4<f32>) {
    if c.w == 0.0 {
        return;
    }
    (*sums).sum += c.rgb;
    (*sums).covered += 1u;
    let stratum = vec2<u32>(k % side, k / side);
    let halves = vec3<bool>(
        (stratum.x + stratum.y) % 2u == 0u,
        2u * stratum.y < side,
        2u * stratum.x < side,
    );
    for (var h = 0u; h < 3u; h++) {
        if halves[h] {
            (*sums).half_sums[h] += c.rgb;
            (*sums).half_covered[h] += 1u;
        }
    }
}

// What `count` samples summed in `sums` make (a half none of whose samples has a ray takes
// the mean of all).
fn sampled(sums: SampleSums, count: u32) -> Sampled {
    var out = Sampled();
    if sums.covered == 0u {
        return out;
    }
    let mean = sums.sum / f32(sums.covered);
    out.colour = vec4<f32>(mean, f32(sums.covered) / f32(count));
    for (var h = 0u; h < 3u; h++) {
        let n = sums.half_covered[h];
        out.halves[h] = select(mean, sums.half_sums[h] / f32(max(n, 1u)), n > 0u);
    }
    return out;
}

// The sums of `count` samples whose mean and share with a ray `sampled` made `colour`: exact
// where 1, 2 or 4 of them have a ray (a power of two), without their halves.
fn sums_of(colour: vec4<f32>, count: u32) -> SampleSums {
    var sums = SampleSums();
    sums.covered = u32(round(colour.w * f32(count)));
    sums.sum = colour.rgb * f32(sums.covered);
    return sums;
}

// Adds samples `first` to `side`² − 1 of pixel `pixel` (index `index`) to `sums`, in order,
// in one invocation.
fn add_samples(sums: ptr<function, SampleSums>, first: u32, pixel: vec2<u32>, index: u32, side: u32) {
    for (var k = first; k < side * side; k++) {
        add_sample(sums, k, side, sample_radiance(pixel, index, k, side));
    }
}

// The `side`² samples of pixel `pixel` (index `index`), in one invocation.
fn samples(pixel: vec2<u32>, index: u32, side: u32) -> Sampled {
    var sums = SampleSums();
    add_samples(&sums, 0u, pixel, index, side);
    return sampled(sums, side * side);
}

// The pixel's SAMPLES_PER_SIDE² samples: their mean radiance, and the share with a ray (w);
// through the glass, its image irradiance (the mean of its samples' weighted radiance).
fn supersampled(pixel: vec2<u32>, index: u32) -> vec4<f32> {
    return samples(pixel, index, SAMPLES_PER_SIDE).colour;
}

// Shades pixel `pixel`'s centre ray (`centre_ray`), along camera-space direction `d`.
fn shade_centre(pixel: vec2<u32>, d: vec3<f32>) -> Traced {
    let at = camera_at(line_time(pixel));
    set_spread(at, vec2<f32>(pixel) + 0.5, d, 1.0);
    return shade(placed_ray(at, vec3<f32>(0.0), d));
}

// The ground truth of a primary hit: normal and distance, zero on a miss.
fn geometry_of(traced: Traced) -> vec4<f32> {
    if traced.triangle == NO_HIT {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(traced.normal, traced.hit.t);
}
