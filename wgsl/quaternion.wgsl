// Unit quaternions (x, y, z, w) as rotations: products, turning vectors, and Shoemake's slerp,
// for a moving camera (`wgsl/frame.wgsl`) and moving instances (`wgsl/triangles.wgsl`).
#import math

// The quaternion product a b (rotation b, then a).
fn quat_mul(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(a.w * b.xyz + b.w * a.xyz + cross(a.xyz, b.xyz), a.w * b.w - dot(a.xyz, b.xyz));
}

// `v` turned by the unit quaternion `q`.
fn quat_rotate(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    let t = 2.0 * cross(q.xyz, v);
    return v + q.w * t + cross(q.xyz, t);
}

// Shoemake's slerp from `a` to `b` at `s` on the shortest arc, as a (a⁻¹ b)^s: the relative
// turn's half angle φ = atan2(|v|, w) taken to s φ, through atanc and sinc so that it stays
// exact as the turn vanishes.
fn slerp(a: vec4<f32>, b: vec4<f32>, s: f32) -> vec4<f32> {
    var r = quat_mul(vec4<f32>(-a.xyz, a.w), b);
    if r.w < 0.0 {
        r = -r;
    }
    let v = length(r.xyz);
    // φ / |v|.
    let per = select(atan2_pos(v, r.w) / v, atanc(v / r.w) / r.w, r.w > v);
    let sc = sinc_cos(s * per * v);
    return normalize(quat_mul(a, vec4<f32>(r.xyz * (sc.x * s * per), sc.y)));
}
