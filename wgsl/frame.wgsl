// The frame a per-pixel kernel traces (group 0, binding 2), and the camera at each ray's time.
// Without MOTION the camera is still: its axes and eye are the frame's. With MOTION (a rolling
// shutter, an exposure or both: `fisheye_rt::lens::Shutter`) the frame holds the camera's pose
// in a moving body and the body's poses at knots in time; a ray's time is its line's readout
// (Kalibr's convention: line v at the frame's stamp + v · line delay) plus, with an exposure,
// its sample's stratum of it (centred on the line's time). Between knots the body turns by
// Shoemake's slerp and moves linearly, as `fisheye_rt::pose::interpolate` does in f64.
#import math
#import quaternion
#import primary
#import triangles
#import sampling

override MOTION: bool = false;

// Mirrors `fisheye_rt::shared::Knot`: the body's rotation (a unit quaternion x, y, z, w), and
// its origin relative to the scene's (xyz) at w seconds from the frame's stamp.
struct Knot {
    rotation: vec4<f32>,
    position: vec4<f32>,
}

// Mirrors `fisheye_rt::shared::Frame`: the camera-to-world rotation's columns (camera x right,
// y down, z forward) and the eye, in the world or (MOTION) in the moving body. The scene is
// uploaded relative to its own camera, so a still eye is at the origin unless a camera path
// moved it.
struct Frame {
    right: vec4<f32>,
    down: vec4<f32>,
    forward: vec4<f32>,
    eye: vec4<f32>,
    // The pixel of the first invocation (xy), for dispatches over a part of the image; w:
    // the first image row the outputs hold (a band of rows; 0 for a whole image).
    offset: vec4<u32>,
    // MOTION: the knots in use (x) and the readout order (y, READOUT_*).
    motion: vec4<u32>,
    // MOTION: seconds between two lines' readouts (x) and the exposure in seconds (y).
    shutter: vec4<f32>,
    knots: array<Knot, MAX_KNOTS>,
}

@group(0) @binding(2) var<uniform> frame: Frame;

// Where the camera is at one time: its camera-to-world rotation and its eye.
struct Placement {
    axes: mat3x3<f32>,
    eye: vec3<f32>,
}

// The ray from the camera placed `at`, leaving camera-space point `origin` along camera-space
// direction `d`.
fn placed_ray(at: Placement, origin: vec3<f32>, d: vec3<f32>) -> Ray {
    return Ray(at.eye + at.axes * origin, at.axes * d, 0.0, 3.0e38);
}

// The camera at `t` seconds from the frame's stamp.
fn camera_at(t: f32) -> Placement {
    // What the ray traced next meets is placed at its time too.
    scene_time = t;
    let axes = mat3x3<f32>(frame.right.xyz, frame.down.xyz, frame.forward.xyz);
    if !MOTION {
        return Placement(axes, frame.eye.xyz);
    }
    // The last knot at or before t (the first where t precedes them all), by bisection.
    var lo = 0u;
    var hi = frame.motion.x;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if frame.knots[mid].position.w <= t {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let a = frame.knots[lo];
    var q = a.rotation;
    var p = a.position.xyz;
    if lo + 1u < frame.motion.x {
        let b = frame.knots[lo + 1u];
        let s = clamp((t - a.position.w) / (b.position.w - a.position.w), 0.0, 1.0);
        q = slerp(a.rotation, b.rotation, s);
        p = mix(a.position.xyz, b.position.xyz, s);
    }
    let turned = mat3x3<f32>(quat_rotate(q, axes[0]), quat_rotate(q, axes[1]), quat_rotate(q, axes[2]));
    return Placement(turned, p + quat_rotate(q, frame.eye.xyz));
}

// The readout time of pixel `pixel`'s line, seconds from the frame's stamp (0 when still).
fn line_time(pixel: vec2<u32>) -> f32 {
    if !MOTION {
        return 0.0;
    }
    var line = pixel.y;
    switch frame.motion.y {
        case READOUT_UP: {
            line = lens.height - 1u - pixel.y;
        }
        case READOUT_RIGHT: {
            line = pixel.x;
        }
        case READOUT_LEFT: {
            line = lens.width - 1u - pixel.x;
        }
        default: {}
    }
    return f32(line) * frame.shutter.x;
}

// Sample `k` of the `count` of pixel `index`: its exposure stratum, a permutation of the
// samples hashed from the pixel (so time is not tied to where the sample sits in the pixel).
// A bijection of the next power of two above `count` (xor, odd multiply and xorshift steps,
// each invertible there), walked until it lands below `count` (cycle walking: Black and
// Rogaway, "Ciphers with Arbitrary Finite Domains", CT-RSA 2002), is one of [0, count).
fn stratum(k: u32, count: u32, seed: vec2<u32>) -> u32 {
    let bits = 32u - countLeadingZeros(max(count, 2u) - 1u);
    let mask = (1u << bits) - 1u;
    var i = k;
    loop {
        i = ((i ^ seed.x) * (seed.y | 1u)) & mask;
        i ^= i >> ((bits + 1u) / 2u);
        i = (i * 0x2c1b3c6du + 0x297a2d39u) & mask;
        i ^= i >> ((bits + 2u) / 3u);
        if i < count {
            break;
        }
    }
    return i;
}

// The time of sample `k` of the `count` of pixel `pixel` (index `index`): its line's, plus
// with an exposure a jittered point of its stratum, the exposure centred on the line's time.
fn sample_time(pixel: vec2<u32>, index: u32, k: u32, count: u32) -> f32 {
    let t = line_time(pixel);
    if !MOTION || frame.shutter.y <= 0.0 {
        return t;
    }
    let seed = pcg2d(vec2<u32>(index, 0xffffffffu));
    let jitter = f32(pcg2d(vec2<u32>(k, index)).x >> 8u) * (1.0 / 16777216.0);
    let share = (f32(stratum(k, count, seed)) + jitter) / f32(count);
    return t + frame.shutter.y * (share - 0.5);
}

// The ray through camera-space direction `d` from the eye at pixel `pixel`'s line time: the
// pixel's centre ray, which the ground truth follows.
fn centre_ray(pixel: vec2<u32>, d: vec3<f32>) -> Ray {
    return placed_ray(camera_at(line_time(pixel)), vec3<f32>(0.0), d);
}
