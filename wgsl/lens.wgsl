// Lens models, the f32 twin of src/lens/: pixel → ray direction and direction → pixel.
// Conventions (see src/lens/camera.rs): normalized coordinates have half-width 1 and y up;
// directions are camera space, x right, y down, z forward; pixels have a top-left origin.
#import math
#import calibrated

// Mirrors `fisheye_rt::lens::gpu::LensParams` (a test checks the layouts agree).
struct LensParams {
    // Focal length, normalized units.
    f: f32,
    // General form: u = k1·r/f, θ = atan(u)/rate or asin(u)/rate.
    k1_over_f: f32,
    rate: f32,
    // Image radius of the domain edge (f32 max when unbounded), for continuous points.
    r_max: f32,
    // Largest θ a direction may have, for projection.
    theta_max: f32,
    width: u32,
    height: u32,
    // Pixel (i, j) has a ray iff (2i+1-W)² + (H-2j-1)² ≤ mask_limit: exact, as on the CPU.
    mask_limit: u32,
    // Calibrated models (wgsl/calibrated.wgsl): fx, fy, cx, cy in pixels; r_max and theta_max
    // above bound their domain, in model coordinates.
    intrinsics: vec4<f32>,
    // The model's parameters, packed per kind (see wgsl/calibrated.wgsl).
    coefficients: array<vec4<f32>, 2>,
    // Scaramuzza's affine stretch (c, d, e).
    affine: vec4<f32>,
}

// Whether LENS_KIND is a calibrated model (they follow the classic kinds).
fn lens_is_calibrated() -> bool {
    return LENS_KIND >= LENS_KANNALA_BRANDT;
}

// Which mapping (a LENS_* id) and which direction formula (a FORMULA_* id) a pipeline runs.
override LENS_KIND: u32;
override DIRECTION_FORMULA: u32;

// The odd integers (2i+1-W, H-2j-1): the pixel centre in units of half a pixel.
fn lens_pixel_units(lens: LensParams, pixel: vec2<u32>) -> vec2<i32> {
    return vec2<i32>(
        i32(2u * pixel.x + 1u) - i32(lens.width),
        i32(lens.height) - i32(2u * pixel.y + 1u),
    );
}

fn lens_pixel_inside(lens: LensParams, pixel: vec2<u32>) -> bool {
    let n = lens_pixel_units(lens, pixel);
    // |n| < 2^15 per side (MAX_IMAGE_SIDE), so the sum fits in 31 bits.
    return u32(n.x * n.x + n.y * n.y) <= lens.mask_limit;
}

// Normalized coordinates of a pixel centre: one rounding per coordinate.
fn lens_pixel_normalized(lens: LensParams, pixel: vec2<u32>) -> vec2<f32> {
    return vec2<f32>(lens_pixel_units(lens, pixel)) / f32(lens.width);
}

// Normalized coordinates of a continuous pixel position.
fn lens_normalized(lens: LensParams, p: vec2<f32>) -> vec2<f32> {
    let w = f32(lens.width);
    return vec2<f32>(2.0 * p.x / w - 1.0, (f32(lens.height) - 2.0 * p.y) / w);
}

// θ(r), the inverse mapping, for r inside the domain.
fn lens_theta(lens: LensParams, r: f32) -> f32 {
    let f = lens.f;
    switch LENS_KIND {
        case LENS_RECTILINEAR: { return atan_pos(r / f); }
        case LENS_STEREOGRAPHIC: { return 2.0 * atan_pos(r / (2.0 * f)); }
        case LENS_EQUISOLID: { return 2.0 * asin_pos(min(r / (2.0 * f), 1.0)); }
        case LENS_ORTHOGRAPHIC: { return asin_pos(min(r / f, 1.0)); }
        case LENS_GENERAL_TAN: { return atan_pos(lens.k1_over_f * r) / lens.rate; }
        case LENS_GENERAL_SIN: { return asin_pos(min(lens.k1_over_f * r, 1.0)) / lens.rate; }
        case LENS_EQUIDISTANT, default: { return r / f; }
    }
}

// The direction at normalized coordinates n inside the domain, stable formulation:
// d = (s·x, -s·y, cos θ) with s = sin θ / r written per model so that nothing cancels or
// divides by zero at the centre. The algebraic models need no trigonometry at all.
fn lens_direction_stable(lens: LensParams, n: vec2<f32>) -> vec3<f32> {
    let f = lens.f;
    let r2 = dot(n, n);
    var s: f32;
    var c: f32;
    switch LENS_KIND {
        case LENS_RECTILINEAR: {
            // d ∝ (x, y, f)
            let inv = inverseSqrt(r2 + f * f);
            s = inv;
            c = f * inv;
        }
        case LENS_STEREOGRAPHIC: {
            // t = tan(θ/2) = r/2f: sin θ = 2t/(1+t²), cos θ = (1-t²)/(1+t²)
            let t2 = r2 / (4.0 * f * f);
            let inv = 1.0 / (1.0 + t2);
            s = inv / f;
            c = (1.0 - t2) * inv;
        }
        case LENS_EQUISOLID: {
            // σ = sin(θ/2) = r/2f: sin θ = 2σ sqrt(1-σ²), cos θ = 1 - 2σ²
            let s2 = r2 / (4.0 * f * f);
            s = sqrt(max(1.0 - s2, 0.0)) / f;
            c = 1.0 - 2.0 * s2;
        }
        case LENS_ORTHOGRAPHIC: {
            // sin θ = r/f
            s = 1.0 / f;
            c = sqrt(max(1.0 - r2 / (f * f), 0.0));
        }
        case LENS_GENERAL_TAN: {
            // θ/r = atanc(u)·(k1/f)/rate
            let u = lens.k1_over_f * sqrt(r2);
            let sc = sinc_cos(atan_pos(u) / lens.rate);
            s = sc.x * atanc(u) * lens.k1_over_f / lens.rate;
            c = sc.y;
        }
        case LENS_GENERAL_SIN: {
            let u = min(lens.k1_over_f * sqrt(r2), 1.0);
            let sc = sinc_cos(asin_pos(u) / lens.rate);
            s = sc.x * asinc(u) * lens.k1_over_f / lens.rate;
            c = sc.y;
        }
        case LENS_EQUIDISTANT, default: {
            // θ = r/f, sin θ / r = sinc(θ)/f
            let sc = sinc_cos(sqrt(r2) / f);
            s = sc.x / f;
            c = sc.y;
        }
    }
    return vec3<f32>(s * n.x, -s * n.y, c);
}

// The thesis's construction, d = a'·v1 + b'·v2 with v1 the axis and v2 the pinhole ray:
// b' = sqrt(sin²θ / (1 - (v1·v2)²)), a' = cos θ - b'(v1·v2). 0/0 at the centre (we return
// the axis, its limit); f32 loses the small 1 - (v1·v2)² near it. For comparison only.
fn lens_direction_thesis(lens: LensParams, n: vec2<f32>) -> vec3<f32> {
    let sc = sin_cos(lens_theta(lens, length(n)));
    let v2 = normalize(vec3<f32>(n.x, -n.y, 1.0));
    let c = v2.z;
    if c == 1.0 {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let b = sqrt(sc.x * sc.x / (1.0 - c * c));
    return vec3<f32>(0.0, 0.0, sc.y - b * c) + b * v2;
}

fn lens_direction(lens: LensParams, n: vec2<f32>) -> vec3<f32> {
    if DIRECTION_FORMULA == FORMULA_THESIS {
        return lens_direction_thesis(lens, n);
    }
    return lens_direction_stable(lens, n);
}

// Ray direction of pixel (i, j)'s centre; w = 1 with a ray, all zero where masked.
fn lens_pixel_ray(lens: LensParams, pixel: vec2<u32>) -> vec4<f32> {
    if lens_is_calibrated() {
        return cal_unproject(lens, vec2<f32>(pixel) + 0.5);
    }
    if !lens_pixel_inside(lens, pixel) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(lens_direction(lens, lens_pixel_normalized(lens, pixel)), 1.0);
}

// r(θ), the forward mapping, for θ inside the domain.
fn lens_radius(lens: LensParams, theta: f32) -> f32 {
    let f = lens.f;
    switch LENS_KIND {
        case LENS_RECTILINEAR: {
            let sc = sin_cos(theta);
            return f * sc.x / sc.y;
        }
        case LENS_STEREOGRAPHIC: {
            let sc = sin_cos(0.5 * theta);
            return 2.0 * f * sc.x / sc.y;
        }
        case LENS_EQUISOLID: { return 2.0 * f * sin_cos(0.5 * theta).x; }
        case LENS_ORTHOGRAPHIC: { return f * sin_cos(theta).x; }
        case LENS_GENERAL_TAN: {
            let sc = sin_cos(lens.rate * theta);
            return sc.x / sc.y / lens.k1_over_f;
        }
        case LENS_GENERAL_SIN: { return sin_cos(lens.rate * theta).x / lens.k1_over_f; }
        case LENS_EQUIDISTANT, default: { return f * theta; }
    }
}

// Where direction d lands: xy the continuous pixel position, z = 1 if it lands in the image
// (inside the field of view and the image rectangle), all zero otherwise. Past 180° a
// direction has several images; this is the one with θ ≤ π (straight back: azimuth 0).
fn lens_project(lens: LensParams, dir: vec3<f32>) -> vec3<f32> {
    if lens_is_calibrated() {
        return lens_in_image(lens, cal_project(lens, dir));
    }
    let d = normalize(dir);
    let rho = length(d.xy);
    let theta = atan2_pos(rho, d.z);
    if !(theta <= lens.theta_max) {
        return vec3<f32>(0.0);
    }
    var n = vec2<f32>(lens_radius(lens, theta), 0.0);
    if rho > 0.0 {
        // q = r/ρ, closed forms where the model has one (ρ = sin θ for a unit d). Behind
        // the camera 1 + z cancels; there 1/(1 + z) = (1 - z)/ρ² is exact instead.
        var one_plus_z_inv: f32;
        if d.z >= 0.0 {
            one_plus_z_inv = 1.0 / (1.0 + d.z);
        } else {
            one_plus_z_inv = (1.0 - d.z) / (rho * rho);
        }
        var q: f32;
        switch LENS_KIND {
            case LENS_RECTILINEAR: { q = lens.f / d.z; }
            case LENS_STEREOGRAPHIC: { q = 2.0 * lens.f * one_plus_z_inv; }
            case LENS_EQUISOLID: { q = lens.f * sqrt(2.0 * one_plus_z_inv); }
            case LENS_ORTHOGRAPHIC: { q = lens.f; }
            default: { q = lens_radius(lens, theta) / rho; }
        }
        n = vec2<f32>(d.x, -d.y) * q;
    }
    let w = f32(lens.width);
    let h = f32(lens.height);
    return lens_in_image(lens, vec3<f32>((n.x + 1.0) * w / 2.0, (h - n.y * w) / 2.0, 1.0));
}

// A projected point (z = 1 when it has one) kept only when it lands inside the image.
fn lens_in_image(lens: LensParams, p: vec3<f32>) -> vec3<f32> {
    if p.z == 1.0 && p.x >= 0.0 && p.x <= f32(lens.width) && p.y >= 0.0
        && p.y <= f32(lens.height) {
        return p;
    }
    return vec3<f32>(0.0);
}

// The direction through a continuous pixel position: xyz, w = 1; all zero where it has none.
fn lens_unproject(lens: LensParams, p: vec2<f32>) -> vec4<f32> {
    if lens_is_calibrated() {
        return cal_unproject(lens, p);
    }
    let n = lens_normalized(lens, p);
    // `<=` is false for NaN: non-finite input has no ray.
    if length(n) <= lens.r_max {
        return vec4<f32>(lens_direction(lens, n), 1.0);
    }
    return vec4<f32>(0.0);
}

// The change to the lens's direction `d` at image point `p` a `step` on along each axis (x,
// then y), or from the direction a step back where the lens masks the one ahead (zero where
// it masks both): the pixel's footprint as directions (ray differentials, texture filtering;
// the cube map's resampler). One call of the lens in a loop, not four: lavapipe inlines every
// call, and each copy of a calibrated lens costs it memory.
fn lens_steps(lens: LensParams, p: vec2<f32>, d: vec3<f32>, step: f32) -> mat2x3<f32> {
    var steps = mat2x3<f32>();
    var found = vec2<bool>(false);
    // Ahead along x, then y; then back along those the lens masked ahead.
    for (var k = 0u; k < 4u; k++) {
        let axis = k % 2u;
        let back = k >= 2u;
        if found[axis] {
            continue;
        }
        let s = select(step, -step, back) * vec2<f32>(f32(axis == 0u), f32(axis == 1u));
        let q = lens_unproject(lens, p + s);
        if q.w != 0.0 {
            steps[axis] = select(q.xyz - d, d - q.xyz, back);
            found[axis] = true;
        }
    }
    return steps;
}
