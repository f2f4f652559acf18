// Colours as a viewer sees them: the sRGB transfer function, and a linear colour clamped and
// encoded as the PNGs hold it (what `fisheye compare` measures error on).

// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1]; the CPU twin is
// `fisheye_rt::trace::linear_to_srgb`.
fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.0031308 {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

// A linear colour as displayed: clamped to [0, 1], sRGB-encoded.
fn shown(c: vec3<f32>) -> vec3<f32> {
    let v = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    return vec3<f32>(linear_to_srgb(v.r), linear_to_srgb(v.g), linear_to_srgb(v.b));
}

// A colour's largest channel: adaptive sampling's measure of a difference in displayed
// colour against its threshold.
fn largest(v: vec3<f32>) -> f32 {
    return max(v.x, max(v.y, v.z));
}
