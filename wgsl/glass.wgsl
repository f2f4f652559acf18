// Lens prescriptions per ray: the f32 twin of `Prescription::trace_from_film` (src/lens/
// prescription.rs), and the rays a film point sends through the glass toward its exit pupil
// (src/lens/glass_gpu.rs says how they are drawn and weighted). Lens frame: mm, z from the
// front vertex toward the film. The glass is group 0's binding 6 wherever it is imported.
#import math
#import sampling

// Mirrors `fisheye_rt::lens::glass_gpu::GlassParams` (a test checks the layouts agree).
struct GlassParams {
    // Surfaces, pupil bins, channels traced apart (3 where the glass disperses, else 1).
    counts: vec4<u32>,
    // The film's z, the rear vertex's z, the film's mm per pixel, the film radius the bins span.
    film: vec4<f32>,
    // The weights' normalisation per channel (red, green, blue), metres per mm.
    scale: vec4<f32>,
    // Per surface, front to back: radius (0: the stop), vertex z, squared half aperture.
    surfaces: array<vec4<f32>, GLASS_SURFACES>,
    // Per surface: the index behind it in the red, green and blue channels.
    indices: array<vec4<f32>, GLASS_SURFACES>,
    // Per radial bin: the ellipse on the rear vertex's plane that holds the exit pupil seen
    // from a film point on the +x axis (centre x, centre y, semi-axes x and y; 0: none).
    pupil: array<vec4<f32>, PUPIL_BINS>,
    // Per bin, at its inner edge on the film (2 × bin) and its outer edge (2 × bin + 1): the
    // share of its ellipse whose rays get through, per channel (red, green, blue).
    shares: array<vec4<f32>, 2u * PUPIL_BINS>,
}

// The most points of the ellipse a sample draws before it counts as stopped (a point whose
// ray the glass stops is drawn again): where a share p of the ellipse gets through, all of
// them stop with chance (1 - p)^GLASS_TRIES (under 3e-4 for p ≥ 0.4), for which the weight
// of the rays that get through makes up.
const GLASS_TRIES: u32 = 16u;

@group(0) @binding(6) var<uniform> glass: GlassParams;

// A ray in the lens frame, and whether it got through.
struct LensRay {
    origin: vec3<f32>,
    direction: vec3<f32>,
    passed: bool,
}

// Where the ray from `o` along unit `d` (vertex frame, d.z > 0) meets the surface of
// `radius` (0: the plane z = 0): xyz the unit normal facing the light, w the distance; w < 0
// on a miss. The vertex's cap by the stable form of the quadratic, as the f64 reference.
fn glass_intersect(o: vec3<f32>, d: vec3<f32>, radius: f32) -> vec4<f32> {
    let miss = vec4<f32>(0.0, 0.0, 0.0, -1.0);
    if d.z <= 0.0 {
        return miss;
    }
    if radius == 0.0 {
        let t = -o.z / d.z;
        return select(vec4<f32>(0.0, 0.0, -1.0, t), miss, t < 0.0);
    }
    // t² + 2bt + c = 0, c free of the R² that would cancel.
    let b = dot(o, d) - radius * d.z;
    let c = dot(o, o) - 2.0 * radius * o.z;
    let discriminant = b * b - c;
    if discriminant < 0.0 {
        return miss;
    }
    let sign_b = select(-1.0, 1.0, b >= 0.0);
    let q = -(b + sign_b * sqrt(discriminant));
    var t = 0.0;
    if sign_b == select(-1.0, 1.0, radius >= 0.0) {
        t = q;
    } else if q != 0.0 {
        t = c / q;
    }
    if t < 0.0 {
        return miss;
    }
    let p = o + t * d;
    return vec4<f32>(normalize(vec3<f32>(p.x / radius, p.y / radius, p.z / radius - 1.0)), t);
}

// Snell's law: unit `d` through a surface of unit `normal` (either side), `eta` the ratio of
// the indices before and after; w = 0 on total internal reflection.
fn glass_refract(d: vec3<f32>, normal: vec3<f32>, eta: f32) -> vec4<f32> {
    let n = select(normal, -normal, dot(normal, d) > 0.0);
    let cos_i = -dot(n, d);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(normalize(eta * d + (eta * cos_i - sqrt(k)) * n), 1.0);
}

// Traces a ray from the film's side (travelling toward -z) out through every surface, rear
// to front, apertures clipping it, with the indices of `channel` (0 red, 1 green, 2 blue).
fn glass_trace(origin: vec3<f32>, direction: vec3<f32>, channel: u32) -> LensRay {
    var o = origin;
    var d = direction;
    // Mirrored in z, the ray travels toward +z onto a surface of the opposite radius.
    let flip = vec3<f32>(1.0, 1.0, -1.0);
    for (var k = i32(glass.counts.x) - 1; k >= 0; k--) {
        let s = glass.surfaces[k];
        let vertex = vec3<f32>(0.0, 0.0, s.y);
        let local = (o - vertex) * flip;
        let hit = glass_intersect(local, d * flip, -s.x);
        if hit.w < 0.0 {
            return LensRay(o, d, false);
        }
        let p = (local + hit.w * d * flip) * flip;
        if dot(p.xy, p.xy) > s.z {
            return LensRay(o, d, false);
        }
        if s.x != 0.0 {
            let after = glass.indices[k][channel];
            let before = select(1.0, glass.indices[max(k - 1, 0)][channel], k > 0);
            let r = glass_refract(d, hit.xyz * flip, after / before);
            if r.w == 0.0 {
                return LensRay(o, d, false);
            }
            d = r.xyz;
        }
        o = p + vertex;
    }
    return LensRay(o, d, true);
}

// A film sample's ray out of the lens in camera space (x right, y down, z forward; metres
// from the front vertex) and its weight, 0 where the glass blocks it.
struct GlassSample {
    origin: vec3<f32>,
    direction: vec3<f32>,
    weight: f32,
}

// The ray of the film point `offset` pixels from the image's centre (x right, y down) toward
// the point `u` ∈ [0, 1)² of its radial bin's exit-pupil ellipse, in `channel`. Where the
// glass stops it, points drawn from a hash of `u` are tried instead (up to GLASS_TRIES in all),
// and the ray that gets through carries the share of the ellipse that does (`glass.shares`):
// rejection sampling of the pupil, whose expected weight is that of the ellipse's points with
// those stopped counting 0, without their noise.
fn glass_sample(offset: vec2<f32>, u: vec2<f32>, channel: u32) -> GlassSample {
    let none = GlassSample(vec3<f32>(0.0), vec3<f32>(0.0, 0.0, 1.0), 0.0);
    // The image on the film is inverted: the lens frame is the camera's turned half a turn
    // about y (x and z negated), and the film point of a pixel below the centre is above it.
    let xy = vec2<f32>(offset.x, -offset.y) * glass.film.z;
    let r = length(xy);
    let place = r / glass.film.w * f32(glass.counts.y);
    let bin = u32(place);
    if bin >= glass.counts.y {
        return none;
    }
    let e = glass.pupil[bin];
    if e.z <= 0.0 {
        return none;
    }
    let share = mix(glass.shares[2u * bin][channel], glass.shares[2u * bin + 1u][channel], fract(place));
    // The chance that some point of GLASS_TRIES gets through: a ray's weight is divided by it,
    // so that the sample's expected weight is the ellipse's share times its mean over the
    // points that get through, with nothing lost where every try is stopped.
    var missed = 1.0;
    for (var attempt = 0u; attempt < GLASS_TRIES; attempt++) {
        missed *= 1.0 - share;
    }
    let found = 1.0 - missed;
    if found <= 0.0 {
        return none;
    }
    // The bin's ellipse is for a film point on the +x axis: turn it to this one's.
    let c = select(vec2<f32>(1.0, 0.0), xy / r, r > 0.0);
    let film = vec3<f32>(xy, glass.film.x);
    var v = u;
    for (var attempt = 0u; attempt < GLASS_TRIES; attempt++) {
        let q = e.xy + e.zw * concentric_disc(v);
        let target_point = vec3<f32>(q.x * c.x - q.y * c.y, q.x * c.y + q.y * c.x, glass.film.y);
        let d = normalize(target_point - film);
        let out = glass_trace(film, d, channel);
        if out.passed {
            // cos⁴θ · A / z² over the centre's mean, times the share of A that gets through
            // (over the chance that a point was found): the sample's share of the irradiance.
            let z = glass.film.x - glass.film.y;
            let cos2 = d.z * d.z;
            let weight = cos2 * cos2 * PI * e.z * e.w / (z * z) * (share / found) * glass.scale[channel];
            let m = glass.scale.w;
            return GlassSample(
                vec3<f32>(-out.origin.x, out.origin.y, -out.origin.z) * m,
                vec3<f32>(-out.direction.x, out.direction.y, -out.direction.z),
                weight,
            );
        }
        let h = pcg2d(bitcast<vec2<u32>>(v) ^ vec2<u32>(attempt, channel));
        v = vec2<f32>(h >> vec2<u32>(8u)) * (1.0 / 16777216.0);
    }
    return none;
}

// The point of the unit disc at `u` ∈ [0, 1)² by Shirley and Chiu's concentric map ("A
// Low Distortion Map Between Disk and Square", JGT 2(3), 1997): uniform, and strata of the
// square stay compact on the disc.
fn concentric_disc(u: vec2<f32>) -> vec2<f32> {
    let s = 2.0 * u - 1.0;
    if s.x == 0.0 && s.y == 0.0 {
        return vec2<f32>(0.0);
    }
    if abs(s.x) > abs(s.y) {
        let phi = 0.25 * PI * s.y / s.x;
        return s.x * vec2<f32>(cos(phi), sin(phi));
    }
    let phi = 0.5 * PI - 0.25 * PI * s.x / s.y;
    return s.y * vec2<f32>(cos(phi), sin(phi));
}

// Sample `k` of a pixel's `side`² samples on the exit pupil, in [0, 1)²: jittered strata,
// turned by a shift hashed from the pixel so that its film and pupil strata do not pair the
// same way in every pixel (the film's are `sample_offset`'s). Nested as the film's are at
// 4 × 4 (NESTED_SIDE): the first four are the 2 × 2 samples, each in a quarter of its own,
// and the other twelve take the twelve cells of the 4 × 4 that those leave, one each, so that
// supersampling can go on from the estimate's samples through the glass too.
fn pupil_offset(index: u32, k: u32, side: u32) -> vec2<f32> {
    if side != NESTED_SIDE || k < 4u {
        return pupil_strata(index, k, select(side, 2u, side == NESTED_SIDE));
    }
    var taken = 0u;
    for (var j = 0u; j < 4u; j++) {
        let cell = vec2<u32>(pupil_strata(index, j, 2u) * f32(NESTED_SIDE));
        taken |= 1u << (cell.y * NESTED_SIDE + cell.x);
    }
    let free = NESTED_SIDE * NESTED_SIDE - 4u;
    let pick = (k - 4u + pcg2d(vec2<u32>(index, 0xfffffffeu)).x) % free;
    // The pick-th cell the 2 × 2 samples left, in row-major order.
    var cell = 0u;
    var seen = 0u;
    for (var c = 0u; c < NESTED_SIDE * NESTED_SIDE; c++) {
        if (taken & (1u << c)) == 0u {
            if seen == pick {
                cell = c;
            }
            seen++;
        }
    }
    let h = pcg2d(vec2<u32>(index, NESTED_SIDE * NESTED_SIDE + k));
    let jitter = vec2<f32>(h >> vec2<u32>(8u)) * (1.0 / 16777216.0);
    return (vec2<f32>(f32(cell % NESTED_SIDE), f32(cell / NESTED_SIDE)) + jitter) / f32(NESTED_SIDE);
}

// Sample `k` of `side`² jittered strata of the pupil, in an order turned by a hash of pixel
// `index`.
fn pupil_strata(index: u32, k: u32, side: u32) -> vec2<f32> {
    let count = side * side;
    let shift = pcg2d(vec2<u32>(index, 0xffffffffu)).x % count;
    let stratum = (k + shift) % count;
    let h = pcg2d(vec2<u32>(index, count + k));
    let jitter = vec2<f32>(h >> vec2<u32>(8u)) * (1.0 / 16777216.0);
    return (vec2<f32>(f32(stratum % side), f32(stratum / side)) + jitter) / f32(side);
}
