// How adaptive sampling (`adaptive.wgsl`'s `classify`) judges and makes its interpolation
// between traced lattice points: how far a straight line between two of them may be off, and
// the Catmull-Rom spline that replaces it.
#import colour

// How far linear interpolation between samples `a` and `b` may be off, in displayed colour,
// judged from the samples beside them along the same line (`before` a, `after` b, where the
// flags say they exist on the same surface): the larger second difference at either end,
// which is zero along a linear change and the full step at a step (the error of linear
// interpolation grows with the second derivative: |f - lerp| <= h² max|f''| / 8); with no
// sample beside either end, the difference between the ends.
fn bend(before: vec3<f32>, a: vec3<f32>, b: vec3<f32>, after: vec3<f32>, has: vec2<bool>) -> f32 {
    if !any(has) {
        return largest(abs(b - a));
    }
    var worst = 0.0;
    if has.x {
        worst = largest(abs(before - 2.0 * a + b));
    }
    if has.y {
        worst = max(worst, largest(abs(a - 2.0 * b + after)));
    }
    return worst;
}

// The weights of the points at -1, 0, 1 and 2 for a point at `t` in [0, 1] on the Catmull-Rom
// spline through them: Keys's cubic convolution with a = -1/2 ("Cubic convolution
// interpolation for digital image processing", 1981), which reproduces quadratics, so its
// error falls as h³ where linear interpolation's falls as h²; its slope is continuous across
// the blocks' edges, where bilinear interpolation's kinks (which ꟻLIP sees as edges).
fn catmull_rom(t: f32) -> vec4<f32> {
    let t2 = t * t;
    let t3 = t2 * t;
    return 0.5 * vec4<f32>(-t3 + 2.0 * t2 - t, 3.0 * t3 - 5.0 * t2 + 2.0, -3.0 * t3 + 4.0 * t2 + t, t3 - t2);
}

// The spline with weights `w` through `a`, `b`, `c`, `d`, an end it may not pass through (`has`
// false) replaced by the line through the middle two continued (2b - c, as Keys does past an
// image's edge): with neither end, it is the linear interpolation between `b` and `c`.
fn spline(w: vec4<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, d: vec3<f32>, has: vec2<bool>) -> vec3<f32> {
    let before = select(2.0 * b - c, a, has.x);
    let after = select(2.0 * c - b, d, has.y);
    return w.x * before + w.y * b + w.z * c + w.w * after;
}
