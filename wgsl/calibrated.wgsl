// Calibrated camera models, the f32 twin of src/lens/calibrated/: see there for the
// formulas, their sources and the validity domains. Model coordinates m are
// ((u - cx)/fx, (v - cy)/fy) (Scaramuzza: then through the inverse of its affine stretch);
// lens.r_max and lens.theta_max bound the domain, as the f64 reference computed them.
//
// lens.coefficients, per LENS_KIND:
//   KANNALA_BRANDT    [0] = (k1, k2, k3, k4)
//   DOUBLE_SPHERE     [0] = (ξ, α)
//   EXTENDED_UNIFIED  [0] = (α, β); the unified model is β = 1
//   FOV_MODEL         [0] = (w, 2 tan(w/2))
//   SCARAMUZZA        [0] = (a0, a1, a2, a3), [1].x = a4; lens.affine = (c, d, e)
//   FTHETA            [0] = (k1, k2, k3, k4), [1].x = k5
//   RADTAN            [0] = (k1, k2, k3), [1] = (p1, p2); r_max bounds the undistorted radius
#import math
#import lens

fn cal_model_coordinates(lens: LensParams, p: vec2<f32>) -> vec2<f32> {
    let q = (p - lens.intrinsics.zw) / lens.intrinsics.xy;
    if LENS_KIND == LENS_SCARAMUZZA {
        let a = lens.affine;
        let det = a.x - a.y * a.z;
        return vec2<f32>((q.x - a.y * q.y) / det, (a.x * q.y - a.z * q.x) / det);
    }
    return q;
}

fn cal_pixel(lens: LensParams, m: vec2<f32>) -> vec2<f32> {
    var q = m;
    if LENS_KIND == LENS_SCARAMUZZA {
        let a = lens.affine;
        q = vec2<f32>(a.x * m.x + a.y * m.y, a.z * m.x + m.y);
    }
    return lens.intrinsics.xy * q + lens.intrinsics.zw;
}

// x(1 + k.x x² + k.y x⁴ + k.z x⁶ + k.w x⁸) and its derivative: Kannala–Brandt's θd(θ), and
// radial-tangential's radial part (k.w = 0).
fn cal_odd_poly(k: vec4<f32>, x: f32) -> vec2<f32> {
    let z = x * x;
    let inner = 1.0 + z * (k.x + z * (k.y + z * (k.z + z * k.w)));
    let slope = 1.0 + z * (3.0 * k.x + z * (5.0 * k.y + z * (7.0 * k.z + z * 9.0 * k.w)));
    return vec2<f32>(x * inner, slope);
}

// c0 + c1 x + c2 x² + c3 x³ + c4 x⁴ and its derivative, for c = (c0..c3) and c4.
fn cal_quartic(c: vec4<f32>, c4: f32, x: f32) -> vec2<f32> {
    let value = c.x + x * (c.y + x * (c.z + x * (c.w + x * c4)));
    let slope = c.y + x * (2.0 * c.z + x * (3.0 * c.w + x * 4.0 * c4));
    return vec2<f32>(value, slope);
}

// f-theta's θ(r)/r = k1 + k2 r + … + k5 r⁴ and θ'(r).
fn cal_ftheta(lens: LensParams, r: f32) -> vec3<f32> {
    let k = lens.coefficients[0];
    let q = cal_quartic(k, lens.coefficients[1].x, r);
    // θ = r·q(r): θ' = q + r q'.
    return vec3<f32>(q.x, r * q.x, q.x + r * q.y);
}

// h(x) and h'(x) of the root the iterative models solve for (see `cal_solve`): Kannala–Brandt
// and radial-tangential θd(x) - goal; f-theta θ(x) - goal; Scaramuzza
// x cos θ + f(x) sin θ for the direction's (sin θ, cos θ) = sc.
fn cal_h(lens: LensParams, x: f32, goal: f32) -> vec2<f32> {
    switch LENS_KIND {
        case LENS_SCARAMUZZA: {
            // θ(x) = atan2(x, -f(x)): θ' = (x f' - f)/(x² + f²).
            let f = cal_quartic(lens.coefficients[0], lens.coefficients[1].x, x);
            return vec2<f32>(atan2_pos(x, -f.x) - goal, (x * f.y - f.x) / (x * x + f.x * f.x));
        }
        case LENS_FTHETA: {
            let t = cal_ftheta(lens, x);
            return vec2<f32>(t.y - goal, t.z);
        }
        case LENS_RADTAN: {
            let k = vec4<f32>(lens.coefficients[0].xyz, 0.0);
            return cal_odd_poly(k, x) - vec2<f32>(goal, 0.0);
        }
        default: {
            return cal_odd_poly(lens.coefficients[0], x) - vec2<f32>(goal, 0.0);
        }
    }
}

// The root of h in [0, hi] (h(0) ≤ 0 ≤ h(hi)) by the guarded Newton iteration of
// src/lens/calibrated/mod.rs: every iteration narrows the bracket at the iterate and, if
// that did not halve it, at its midpoint; the next iterate is Newton's step from the one of
// them with the smaller |h| when strictly inside the bracket, else the midpoint. Tolerance
// hi·2⁻²², so NEWTON_STEPS iterations suffice.
fn cal_solve(lens: LensParams, goal: f32, hi_in: f32, x0: f32) -> f32 {
    var lo = 0.0;
    var hi = hi_in;
    let tol = hi_in * 2.384185791015625e-7;
    var x = clamp(x0, lo, hi);
    for (var i = 0u; i < NEWTON_STEPS; i++) {
        let before = hi - lo;
        var h = cal_h(lens, x, goal);
        if h.x == 0.0 {
            return x;
        }
        if h.x < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        if hi - lo > 0.5 * before {
            let mid = 0.5 * (lo + hi);
            let hm = cal_h(lens, mid, goal);
            if hm.x == 0.0 {
                return mid;
            }
            if hm.x < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
            if abs(hm.x) < abs(h.x) {
                x = mid;
                h = hm;
            }
        }
        let newton = x - h.x / h.y;
        if abs(newton - x) <= tol {
            return clamp(newton, lo, hi);
        }
        let inside = newton > lo && newton < hi;
        if hi - lo <= tol {
            break;
        }
        x = select(0.5 * (lo + hi), newton, inside);
    }
    return 0.5 * (lo + hi);
}

// Radial-tangential distortion of an undistorted point x: xy the distorted point, zw unused;
// the Jacobian is returned by `cal_radtan_jacobian`.
fn cal_radtan(lens: LensParams, x: vec2<f32>) -> vec2<f32> {
    let k = lens.coefficients[0];
    let p = lens.coefficients[1];
    let r2 = dot(x, x);
    let radial = 1.0 + r2 * (k.x + r2 * (k.y + r2 * k.z));
    let xy = x.x * x.y;
    return vec2<f32>(
        x.x * radial + 2.0 * p.x * xy + p.y * (r2 + 2.0 * x.x * x.x),
        x.y * radial + p.x * (r2 + 2.0 * x.y * x.y) + 2.0 * p.y * xy,
    );
}

fn cal_radtan_jacobian(lens: LensParams, x: vec2<f32>) -> mat2x2<f32> {
    let k = lens.coefficients[0];
    let p = lens.coefficients[1];
    let r2 = dot(x, x);
    let radial = 1.0 + r2 * (k.x + r2 * (k.y + r2 * k.z));
    let dradial = k.x + r2 * (2.0 * k.y + 3.0 * r2 * k.z);
    let cross = 2.0 * x.x * x.y * dradial + 2.0 * p.x * x.x + 2.0 * p.y * x.y;
    return mat2x2<f32>(
        vec2<f32>(radial + 2.0 * x.x * x.x * dradial + 2.0 * p.x * x.y + 6.0 * p.y * x.x, cross),
        vec2<f32>(cross, radial + 2.0 * x.y * x.y * dradial + 6.0 * p.x * x.y + 2.0 * p.y * x.x),
    );
}

// The unit direction of model coordinates m with radius r ≤ r_max.
fn cal_direction(lens: LensParams, m: vec2<f32>, r: f32) -> vec3<f32> {
    let c = lens.coefficients[0];
    let r2 = r * r;
    switch LENS_KIND {
        case LENS_DOUBLE_SPHERE: {
            let xi = c.x;
            let alpha = c.y;
            let mz = (1.0 - alpha * alpha * r2)
                / (alpha * sqrt(max(1.0 - (2.0 * alpha - 1.0) * r2, 0.0)) + 1.0 - alpha);
            let k = (mz * xi + sqrt(mz * mz + (1.0 - xi * xi) * r2)) / (mz * mz + r2);
            return normalize(vec3<f32>(k * m, k * mz - xi));
        }
        case LENS_EXTENDED_UNIFIED: {
            let alpha = c.x;
            let beta = c.y;
            let mz = (1.0 - beta * alpha * alpha * r2)
                / (alpha * sqrt(max(1.0 - (2.0 * alpha - 1.0) * beta * r2, 0.0)) + 1.0 - alpha);
            return normalize(vec3<f32>(m, mz));
        }
        case LENS_FOV_MODEL: {
            // (m sin(w r)/(2 tan(w/2) r), cos(w r)), with sin(x)/x exact at 0.
            let sc = sinc_cos(c.x * r);
            return normalize(vec3<f32>(m * (c.x * sc.x / c.y), sc.y));
        }
        case LENS_SCARAMUZZA: {
            let f = cal_quartic(c, lens.coefficients[1].x, r);
            return normalize(vec3<f32>(m, -f.x));
        }
        case LENS_FTHETA: {
            // sin θ / r = (θ/r)·sinc θ: no division, exact at the centre.
            let t = cal_ftheta(lens, r);
            let sc = sinc_cos(t.y);
            return vec3<f32>(m * (t.x * sc.x), sc.y);
        }
        default: {
            // Kannala–Brandt: θ from θd(θ) = r; θ/r → 1 at the centre.
            let theta = cal_solve(lens, r, lens.theta_max, r);
            var ratio = 1.0;
            if r > 0.0 {
                ratio = theta / r;
            }
            let sc = sinc_cos(theta);
            return vec3<f32>(m * (ratio * sc.x), sc.y);
        }
    }
}

// The direction through continuous pixel position p: xyz, w = 1; all zero outside the domain.
fn cal_unproject(lens: LensParams, p: vec2<f32>) -> vec4<f32> {
    let m = cal_model_coordinates(lens, p);
    if LENS_KIND == LENS_RADTAN {
        // Newton's method in 2D (as the reference), from the radial part's inverse.
        let r = length(m);
        var x = m;
        if r > 0.0 {
            x = m * (cal_solve(lens, r, lens.r_max, r) / r);
        }
        for (var i = 0u; i < 4u; i++) {
            let j = cal_radtan_jacobian(lens, x);
            x -= inverse2(j) * (cal_radtan(lens, x) - m);
        }
        let residual = length(cal_radtan(lens, x) - m);
        if length(x) <= lens.r_max && residual <= 1e-5 * (1.0 + length(m)) {
            return vec4<f32>(normalize(vec3<f32>(x, 1.0)), 1.0);
        }
        return vec4<f32>(0.0);
    }
    let r = length(m);
    // `<=` is false for NaN: non-finite input has no ray.
    if !(r <= lens.r_max) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(cal_direction(lens, m, r), 1.0);
}

fn inverse2(j: mat2x2<f32>) -> mat2x2<f32> {
    let det = determinant(j);
    return mat2x2<f32>(vec2<f32>(j[1].y, -j[0].y), vec2<f32>(-j[1].x, j[0].x)) * (1.0 / det);
}

// Where direction d lands: xy the continuous pixel position, z = 1; all zero outside the
// domain (not checked against the image; `lens_project` does that).
fn cal_project(lens: LensParams, dir: vec3<f32>) -> vec3<f32> {
    let d = normalize(dir);
    let rho = length(d.xy);
    let theta = atan2_pos(rho, d.z);
    if !(theta <= lens.theta_max) {
        return vec3<f32>(0.0);
    }
    let c = lens.coefficients[0];
    // q = r/ρ, so that m = q·d.xy; r0 the radius where ρ = 0 (θ = 0 or π: azimuth 0).
    var q: f32;
    var r0: f32;
    switch LENS_KIND {
        case LENS_RADTAN: {
            if !(d.z > 0.0) {
                return vec3<f32>(0.0);
            }
            let x = d.xy / d.z;
            if !(length(x) <= lens.r_max) {
                return vec3<f32>(0.0);
            }
            return vec3<f32>(cal_pixel(lens, cal_radtan(lens, x)), 1.0);
        }
        case LENS_DOUBLE_SPHERE: {
            let xi = c.x;
            let alpha = c.y;
            let d2 = sqrt(rho * rho + (xi + d.z) * (xi + d.z));
            q = 1.0 / (alpha * d2 + (1.0 - alpha) * (xi + d.z));
            r0 = 0.0;
        }
        case LENS_EXTENDED_UNIFIED: {
            let alpha = c.x;
            let e = sqrt(c.y * rho * rho + d.z * d.z);
            q = 1.0 / (alpha * e + (1.0 - alpha) * d.z);
            r0 = 0.0;
        }
        case LENS_FOV_MODEL: {
            let rd = atan2_pos(c.y * rho, d.z) / c.x;
            q = c.y / c.x;
            if rho > 0.0 {
                q = rd / rho;
            }
            r0 = rd;
        }
        case LENS_SCARAMUZZA, LENS_FTHETA: {
            let r = cal_solve(lens, theta, lens.r_max, lens.r_max * theta / lens.theta_max);
            q = r / max(rho, 1e-30);
            r0 = r;
        }
        default: {
            let r = cal_odd_poly(c, theta).x;
            q = r / max(rho, 1e-30);
            r0 = r;
        }
    }
    var m = vec2<f32>(r0, 0.0);
    if rho > 0.0 {
        m = q * d.xy;
    }
    return vec3<f32>(cal_pixel(lens, m), 1.0);
}
