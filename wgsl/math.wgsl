// Trigonometry with a known f32 error bound on every driver: WGSL only promises sin/cos to 2^-11
// absolute, so lens code uses these instead of the builtins (`fisheye info` measures both).
// Range reductions and minimax coefficients are Cephes's single-precision ones (S. Moshier,
// Cephes Math Library: sinf.c, atanf.c, asinf.c); their stated accuracy is about 1-2 ulp.

const PI: f32 = 3.14159265358979;
const HALF_PI: f32 = 1.57079632679490;
const QUARTER_PI: f32 = 0.785398163397448;

// sin(x)/x and cos(x) for |x| ≤ π/4: odd and even minimax polynomials in z = x².
fn sinc_poly(z: f32) -> f32 {
    return 1.0 + z * ((-1.9515295891e-4 * z + 8.3321608736e-3) * z - 1.6666654611e-1);
}

fn cos_poly(z: f32) -> f32 {
    return 1.0 - 0.5 * z
        + z * z * ((2.443315711809948e-5 * z - 1.388731625493765e-3) * z + 4.166664568298827e-2);
}

// (sin x, cos x) for 0 ≤ x ≤ 2π·4 or so. Cody-Waite reduction by π/2 in three parts, so the
// reduced argument keeps f32 accuracy.
fn sin_cos(x: f32) -> vec2<f32> {
    let q = floor(x / HALF_PI + 0.5);
    // π/2 = DP1 + DP2 + DP3 with DP1, DP2 short enough that q·DPi is exact.
    let y = ((x - q * 1.5703125) - q * 4.837512969970703125e-4) - q * 7.54978995489188216e-8;
    let z = y * y;
    let s = y * sinc_poly(z);
    let c = cos_poly(z);
    switch u32(q) & 3u {
        case 0u: { return vec2<f32>(s, c); }
        case 1u: { return vec2<f32>(c, -s); }
        case 2u: { return vec2<f32>(-s, -c); }
        default: { return vec2<f32>(-c, s); }
    }
}

// (sin(x)/x, cos x) for x ≥ 0, exact at 0 (sinc(0) = 1) and relative-accurate for small x.
fn sinc_cos(x: f32) -> vec2<f32> {
    if x <= QUARTER_PI {
        let z = x * x;
        return vec2<f32>(sinc_poly(z), cos_poly(z));
    }
    let sc = sin_cos(x);
    return vec2<f32>(sc.x / x, sc.y);
}

// atan(x)/x for 0 ≤ x ≤ tan(π/8), a polynomial in z = x².
fn atanc_poly(z: f32) -> f32 {
    return 1.0 + z * (((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z
        - 3.33329491539e-1);
}

// atan(x) for x ≥ 0 (any magnitude).
fn atan_pos(x: f32) -> f32 {
    if x > 2.414213562373095 {
        let t = -1.0 / x;
        return HALF_PI + t * atanc_poly(t * t);
    }
    if x > 0.4142135623730950 {
        let t = (x - 1.0) / (x + 1.0);
        return QUARTER_PI + t * atanc_poly(t * t);
    }
    return x * atanc_poly(x * x);
}

// atan(x)/x for x ≥ 0, exact at 0.
fn atanc(x: f32) -> f32 {
    if x <= 0.4142135623730950 {
        return atanc_poly(x * x);
    }
    return atan_pos(x) / x;
}

// atan2(y, x) for y ≥ 0, in [0, π]; the quotient taken is always ≤ 1.
fn atan2_pos(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    var t: f32;
    if y <= ax {
        t = atan_pos(y / ax);
    } else {
        t = HALF_PI - atan_pos(ax / y);
    }
    if x < 0.0 {
        t = PI - t;
    }
    return t;
}

// asin(x)/x for 0 ≤ x ≤ 1/2, a polynomial in z = x².
fn asinc_poly(z: f32) -> f32 {
    return 1.0 + z * ((((4.2163199048e-2 * z + 2.4181311049e-2) * z + 4.5470025998e-2) * z
        + 7.4953002686e-2) * z + 1.6666752422e-1);
}

// asin(x) for 0 ≤ x ≤ 1; above 1/2 through asin(x) = π/2 - 2 asin(sqrt((1 - x)/2)).
fn asin_pos(x: f32) -> f32 {
    if x > 0.5 {
        let s = sqrt(0.5 * (1.0 - x));
        return HALF_PI - 2.0 * s * asinc_poly(s * s);
    }
    return x * asinc_poly(x * x);
}

// asin(x)/x for 0 ≤ x ≤ 1, exact at 0.
fn asinc(x: f32) -> f32 {
    if x <= 0.5 {
        return asinc_poly(x * x);
    }
    return asin_pos(x) / x;
}
